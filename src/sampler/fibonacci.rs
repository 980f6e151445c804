//! The Fibonacci numbers, which the Fibonacci lattice's counts and generators follow.

/// The Fibonacci numbers up to 2^63.
pub(crate) fn fibonacci_numbers() -> impl Iterator<Item = u64> {
    std::iter::successors(Some((1u64, 2u64)), |&(a, b)| {
        b.checked_add(a).map(|c| (b, c))
    })
    .map(|(a, _)| a)
}

/// Whether `n` is a Fibonacci number.
pub(crate) fn is_fibonacci(n: usize) -> bool {
    n >= 1 && fibonacci_below(n as u64).is_some()
}

/// `F_{m-1}` if `n = F_m` (with `F_1 = 1, F_2 = 2` so that `1, 2, 3, 5, 8, …`), else `None`.
pub(crate) fn fibonacci_below(n: u64) -> Option<u64> {
    let mut previous = 1;
    for f in fibonacci_numbers() {
        if f == n {
            return Some(previous);
        }
        if f > n {
            return None;
        }
        previous = f;
    }
    None
}

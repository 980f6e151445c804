//! Checks and tolerances shared by the tests. Each tolerance is named once here, with the
//! reasoning that gives its value.
#![allow(dead_code)]

use std::fmt::Debug;

/// Relative rounding error of a sum of up to ~10⁴ double-precision terms of one sign, or of a
/// closed form with a few dozen operations: about `10⁴ · ε = 10⁴ · 1.1e-16 ≈ 1e-12`.
pub const ROUNDING: f64 = 1e-12;

/// Relative error of the double-exponential rule on half-period panels at the library's
/// default tolerance (1e-14 of `∫ f²` per panel): over up to 10⁴ panels the errors add to
/// 1e-10, plus the rounding of the compensated sum; measured 4e-15 on the disk's Parseval
/// integral (`docs/performance.md`).
pub const QUADRATURE: f64 = 1e-9;

/// Standard errors a statistical check allows, so that a correct implementation fails it with
/// probability `P(|Z| > 5) = 5.7e-7` per check: across the few hundred such checks of the
/// suite, about one failure in ten thousand runs.
pub const Z_STRICT: f64 = 5.0;

/// The same for one-sided checks or checks of a single statistic where a looser bound is
/// enough: `P(|Z| > 4) = 6.3e-5`.
pub const Z_LOOSE: f64 = 4.0;

/// Runs `f` on thread pools of 1, 2 and 3 threads and on the global pool, asserts that every
/// result is the same, and returns it: realization `i` of seed `s` must be the same bits on
/// any thread count.
pub fn assert_thread_count_invariant<T: PartialEq + Debug + Send>(f: impl Fn() -> T + Sync) -> T {
    let reference = f();
    for threads in 1..=3 {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        let other = pool.install(&f);
        assert_eq!(reference, other, "result differs on {threads} thread(s)");
    }
    reference
}

/// `|a/b - 1| ≤ tolerance`.
pub fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a / b - 1.0).abs() <= tolerance
}

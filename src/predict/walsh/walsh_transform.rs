//! The fast Walsh–Hadamard transform, shared by the Walsh forms of digital shifts.

use rayon::prelude::*;

/// Elements per parallel task of a transform (a fixed order: the same bits on any
/// number of threads).
const CHUNK: usize = 1 << 12;

/// The Walsh–Hadamard transform in place, `a[κ] ← Σ_c a[c] (−1)^{popcount(κ & c)}` (`a.len()`
/// a power of 2): butterflies of growing span, the short ones within blocks in parallel.
pub(crate) fn walsh_hadamard(a: &mut [f64]) {
    let n = a.len();
    let butterflies = |x: &mut [f64], y: &mut [f64]| {
        for (u, v) in x.iter_mut().zip(y.iter_mut()) {
            let (p, q) = (*u, *v);
            *u = p + q;
            *v = p - q;
        }
    };
    a.par_chunks_mut(CHUNK.min(n)).for_each(|block| {
        let mut h = 1;
        while h < block.len() {
            block.chunks_mut(2 * h).for_each(|pair| {
                let (x, y) = pair.split_at_mut(h);
                butterflies(x, y);
            });
            h *= 2;
        }
    });
    let mut h = CHUNK;
    while h < n {
        a.chunks_mut(2 * h).for_each(|pair| {
            let (x, y) = pair.split_at_mut(h);
            x.par_chunks_mut(CHUNK)
                .zip(y.par_chunks_mut(CHUNK))
                .for_each(|(x, y)| butterflies(x, y));
        });
        h *= 2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast transform against its definition.
    #[test]
    fn the_fast_transform_is_the_walsh_sum() {
        for n in [1usize, 2, 8, 1 << 13] {
            let a: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
            let mut fast = a.clone();
            walsh_hadamard(&mut fast);
            for k in (0..n).step_by((n / 16).max(1)) {
                let direct: f64 = a
                    .iter()
                    .enumerate()
                    .map(|(c, x)| {
                        if (k & c).count_ones() % 2 == 0 {
                            *x
                        } else {
                            -x
                        }
                    })
                    .sum();
                assert!((fast[k] - direct).abs() < 1e-9, "n {n}, k {k}");
            }
        }
    }
}

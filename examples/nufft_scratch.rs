//! The power spectrum of many realizations with one NUFFT plan and one scratch buffer: the
//! transform allocates nothing per realization.
//!
//! Run: `cargo run --release --example nufft_scratch`

use num_complex::Complex64;
use specvar::prelude::*;
use specvar::spectrum::nufft::NufftPlan;

fn main() -> specvar::Result<()> {
    let (n, kmax, realizations) = (4096, 64, 32);
    let plan = NufftPlan::new(2, kmax, n, 1e-10)?;
    let mut scratch = plan.make_scratch();
    let mut sums = vec![Complex64::new(0.0, 0.0); plan.output_len()];
    let mut mean = vec![0.0; plan.output_len()];
    let jitter = Jitter::new(2)?;
    for r in 0..realizations {
        let points = jitter.sample(n, 7, r)?;
        plan.sums_with_scratch(&points, &mut scratch, &mut sums)?;
        for (m, s) in mean.iter_mut().zip(&sums) {
            *m += s.norm_sqr() / n as f64 / realizations as f64;
        }
    }
    // Along the k_0 axis jitter's expected spectrum is 1 - sinc²(π k / 64).
    let side = 2 * kmax + 1;
    for k in [1, 8, 32, 64] {
        let i = (kmax + k) * side + kmax;
        let x = std::f64::consts::PI * k as f64 / 64.0;
        println!(
            "k = ({k:>2}, 0): P = {:.4}, closed form {:.4}",
            mean[i],
            1.0 - (x.sin() / x).powi(2)
        );
    }
    Ok(())
}

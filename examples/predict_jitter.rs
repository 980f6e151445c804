//! Predict jittered sampling's variance on a disk from a spectrum estimated once at N = 4096,
//! and compare it with the closed form and with Monte Carlo.
//!
//! Run: `cargo run --release --example predict_jitter`

use specvar::integrand::Ball;
use specvar::montecarlo::{empirical_variance, McParams};
use specvar::predict::{predict_polar, PolarParams, SpectrumSource};
use specvar::sampler::Jitter;
use specvar::spectrum::{estimate, ClosedForm, SpectrumParams};

fn main() -> specvar::Result<()> {
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
    let jitter = Jitter::new(2)?;
    let params = SpectrumParams {
        kmax: 320,
        realizations: 32,
        ..Default::default()
    };
    let spectrum = estimate(&jitter, 4096, &params)?;
    println!(
        "{:>6} {:>12} {:>12} {:>12} {:>26}",
        "N", "estimated", "closed form", "Monte Carlo", "99% interval"
    );
    for n in [16, 64, 256, 1024] {
        let polar = PolarParams::default();
        let est = predict_polar(
            &disk,
            SpectrumSource::Estimated(&spectrum.radial),
            n,
            &polar,
        )?;
        let closed = predict_polar(&disk, SpectrumSource::Closed(ClosedForm::Jitter), n, &polar)?;
        let mc = empirical_variance(
            &jitter,
            &disk,
            n,
            &McParams {
                patterns: 20000,
                ..Default::default()
            },
        )?;
        println!(
            "{n:>6} {:>12.4e} {:>12.4e} {:>12.4e}   [{:.4e}, {:.4e}]",
            est.variance, closed.variance, mc.variance, mc.ci_low, mc.ci_high
        );
    }
    Ok(())
}

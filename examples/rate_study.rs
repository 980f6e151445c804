//! A rate study: jitter and random on a disk and a Gaussian, N = 16 … 1024, with the
//! theoretical, predicted and Monte Carlo slopes.
//!
//! Run: `cargo run --release --example rate_study`

use specvar::prelude::*;
use specvar::rate::ReferenceSpectrum;

fn main() -> specvar::Result<()> {
    let config = StudyConfig {
        samplers: vec![SamplerKind::Random, SamplerKind::Jitter],
        reference: ReferenceSpectrum {
            n: 4096,
            kmax: 160,
            realizations: 32,
            costly_realizations: 8,
        },
        ..Default::default()
    };
    let study = run_study(&config, &Silent)?;
    println!("N = {:?}", study.config.ns);
    for row in &study.rows {
        println!(
            "{:<7} {:<40} theory {}  predicted {:+.3}  Monte Carlo {:+.3} [{:+.3}, {:+.3}]",
            row.sampler.to_string(),
            row.integrand,
            specvar::rate::theory_text(row.theory_rate, 2),
            row.predicted_rate.slope,
            row.empirical_rate.slope,
            row.empirical_rate.ci.0,
            row.empirical_rate.ci.1
        );
    }
    Ok(())
}

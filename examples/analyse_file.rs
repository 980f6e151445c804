//! Analyse a point-set file from any tool (UTK text or JSON): radial spectrum, low-frequency
//! exponent α, and the predicted variance on a disk if the sampler is scale-invariant.
//!
//! Run: `cargo run --release --example analyse_file -- points.txt`
//! (without an argument it writes and analyses a file of Poisson disk patterns).

use specvar::integrand::Ball;
use specvar::predict::{predict_polar, PolarParams, SpectrumSource};
use specvar::rate::fit_alpha;
use specvar::sampler::{PoissonDisk, Sampler};
use specvar::spectrum::{estimate_from_sets, SpectrumParams};

fn main() -> specvar::Result<()> {
    let path = match std::env::args().nth(1) {
        Some(p) => std::path::PathBuf::from(p),
        None => {
            let sampler = PoissonDisk::new(2)?;
            let sets: Vec<_> = (0..16)
                .map(|r| sampler.sample(1024, 1, r))
                .collect::<Result<_, _>>()?;
            let path = std::env::temp_dir().join("specvar_poisson_1024.txt");
            std::fs::write(&path, specvar::io::write_text(&sets))?;
            path
        }
    };
    let sets = specvar::io::read_file(&path)?;
    let params = SpectrumParams {
        kmax: 96,
        ..Default::default()
    };
    let est = estimate_from_sets(&sets, &params)?;
    let alpha = fit_alpha(&est.radial, 0.0, 0.3)?;
    println!(
        "{}: {} realizations of N = {}",
        path.display(),
        sets.len(),
        est.lattice.n
    );
    println!(
        "P(0+) ≈ {:.4}, α = {:.2} ± {:.2}",
        est.radial.dc_limit, alpha.slope, alpha.stderr
    );
    if sets[0].dimension() == 2 {
        let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
        for n in [64, 256, 1024] {
            let p = predict_polar(
                &disk,
                SpectrumSource::Estimated(&est.radial),
                n,
                &PolarParams::default(),
            )?;
            println!(
                "predicted variance on the disk at N = {n}: {:.4e} ± {:.1e}",
                p.variance, p.spectrum_stderr
            );
        }
    }
    Ok(())
}

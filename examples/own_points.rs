//! Predict the variance for point sets written by another program (UTK text or JSON), and
//! measure it by Monte Carlo on exactly those point sets under random shifts.
//!
//! Run: `cargo run --release --example own_points -- points.txt`
//! (without an argument it writes a file of 64 Latin hypercube patterns of 256 points).

use specvar::montecarlo::{empirical_variances_of_sets, McParams};
use specvar::prelude::*;

fn main() -> specvar::Result<()> {
    let path = match std::env::args().nth(1) {
        Some(p) => std::path::PathBuf::from(p),
        None => {
            let sampler = LatinHypercube::new(2)?;
            let sets: Vec<_> = (0..64)
                .map(|r| sampler.sample(256, 1, r))
                .collect::<Result<_>>()?;
            let path = std::env::temp_dir().join("specvar_lhs_256.txt");
            specvar::output::write_atomic(&path, specvar::io::write_text(&sets).as_bytes())?;
            path
        }
    };
    let sets = specvar::io::read_file(&path)?;
    let d = sets[0].dimension();
    let f = Gaussian::new(0.1, vec![0.5; d], 1.0)?;
    let problem = Problem::from_point_sets(&sets, &f)?;
    let p = predict(&problem, &PredictParams::default())?;
    let params = McParams {
        shifts: 64,
        ..Default::default()
    };
    let mc = &empirical_variances_of_sets(&sets, &[&f], &params, &Silent)?[0];
    println!(
        "{}: {} point sets of N = {}",
        path.display(),
        sets.len(),
        problem.n
    );
    println!(
        "predicted   {:.4e} ± {:.1e} by the {}",
        p.variance,
        p.budget.half_width(2.576),
        p.route
    );
    println!(
        "Monte Carlo {:.4e}, 99% [{:.4e}, {:.4e}]",
        mc.variance, mc.ci_low, mc.ci_high
    );
    Ok(())
}

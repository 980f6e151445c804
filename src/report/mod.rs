//! The reproduction report and the plots it is built from.
//!
//! [`run`] reproduces the seed talk's table in 2D from first principles: it estimates the
//! spectra of random, jitter, Poisson disk and CCVT, predicts the variance of Monte Carlo
//! integration of a disk and a Gaussian over a range of N, measures it by Monte Carlo, fits
//! rates, finds crossovers, and writes everything to a directory with a `report.md` that ties
//! it together. It uses only the public API.

mod ambient;
mod build;
mod illustrate;
mod markdown;

pub use ambient::AoSection;
pub use build::{run, Check, Crossover, RateRow, Report, ReportConfig, SamplerSeries};

use crate::error::Result;
use crate::plot::{line_plot, spectrum_image, Axes, Series, Style};
use crate::spectrum::SpectrumEstimate;
use std::path::Path;

/// Plots a spectrum estimate: the radial curve (with ±2 standard errors) or, for the lattice,
/// the 2D image with DC in the centre (1D: the curve over k; 3D: the slice `k_2 = 0`).
///
/// # Errors
/// An unwritable file.
pub fn plot_spectrum(path: &Path, label: &str, est: &SpectrumEstimate, radial: bool) -> Result<()> {
    let lattice = est.lattice.lattice;
    let title = format!(
        "{label}: N = {}, {} realizations",
        est.lattice.n, est.lattice.realizations
    );
    if radial || lattice.dimension == 1 {
        let (points, bars) = if radial {
            let bins = &est.radial.bins;
            (
                bins.iter().map(|b| (b.nu, b.power)).collect(),
                Some(
                    bins.iter()
                        .map(|b| (b.power - 2.0 * b.stderr, b.power + 2.0 * b.stderr))
                        .collect(),
                ),
            )
        } else {
            let k = lattice.kmax;
            let nu = |i: usize| (i as f64 - k as f64) / est.lattice.n as f64;
            let pts = (k + 1..lattice.len())
                .map(|i| (nu(i), est.lattice.mean[i]))
                .collect();
            (pts, None)
        };
        let series = Series {
            label: label.to_string(),
            points,
            bars,
            style: Style::Line,
            color: 0,
        };
        let axes = Axes {
            title: format!("radial power spectrum, {title}"),
            x_label: "ν = ρ / N^(1/d)".into(),
            y_label: "power".into(),
            log_x: false,
            log_y: false,
        };
        return line_plot(path, &axes, &[series]);
    }
    let side = lattice.side();
    let plane = side * side;
    // 3D: the central plane k_0 = 0 holds k_1, k_2; 2D: the whole lattice.
    let start = if lattice.dimension == 3 {
        lattice.kmax * plane
    } else {
        0
    };
    let mut values = est.lattice.mean[start..start + plane].to_vec();
    // DC (value N) would swamp the scale; show it at the level of its neighbours' maximum.
    let centre = plane / 2;
    values[centre] = 0.0;
    spectrum_image(
        path,
        &format!("power spectrum, {title}"),
        &values,
        side,
        lattice.kmax,
    )
}

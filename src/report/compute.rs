//! Computing the report: configuration in, [`Report`] out, through the same public API a user
//! calls, and no output written.

use super::model::{
    AmbientSection, Check, Crossover, Illustration, Report, ReportConfig, SeriesExtras, Timing,
};
use crate::error::Result;
use crate::integrand::{Gaussian, Integrand};
use crate::montecarlo::{McResult, Z_99};
use crate::predict::{
    predict_lattice, predict_polar, regular_grid_bias, PolarParams, Prediction, SpectrumSource,
};
use crate::progress::Progress;
use crate::rate::{crossover, run_study, Study, StudySeries};
use crate::render::{measured_ratio, run_comparison, TALK_MSE};
use crate::sampler::{Regular, Sampler, SamplerKind};
use crate::spectrum::{estimate, periodogram, Engine, SpectrumParams};
use std::time::Instant;

/// The at-target spectra's seed stream, independent of the study's.
const TARGET_STREAM: u64 = 0x7A;

/// Computes the report.
///
/// # Errors
/// Any failure of the computations (the configuration is checked first by each part).
pub fn compute(config: &ReportConfig, progress: &dyn Progress) -> Result<Report> {
    let mut timings = Vec::new();
    let mut timed = |stage: &str, start: Instant| {
        timings.push(Timing {
            stage: stage.to_string(),
            seconds: start.elapsed().as_secs_f64(),
        })
    };
    let start = Instant::now();
    let study = run_study(&config.study, progress)?;
    timed("rate study: spectra, predictions, Monte Carlo", start);
    let start = Instant::now();
    let extras = extras(config, progress)?;
    timed("closed forms and lattice form at the target N", start);
    let crossovers = crossovers(&study)?;
    let illustration = illustration()?;
    let start = Instant::now();
    let run = run_comparison(&config.ambient, progress)?;
    timed("ambient-occlusion renders", start);
    let ambient = AmbientSection {
        width: config.ambient.width,
        height: config.ambient.height,
        reference_rays: config.ambient.reference_rays,
        patterns: config.ambient.render.patterns,
        power_label: run.power_label,
        spectrum_realizations: config.ambient.spectrum_realizations,
        kmax: config.ambient.pixel_power.kmax,
        rows: run.rows,
        reference: run.reference,
    };
    let mut checks = study_checks(&study, &extras);
    checks.extend(ambient_checks(&ambient));
    Ok(Report {
        config: config.clone(),
        study,
        extras,
        crossovers,
        illustration,
        ambient,
        checks,
        timings,
    })
}

/// Closed-form predictions at every N, and the lattice form from a spectrum estimated at each N
/// up to the target's `max_n` (one estimate per sampler and N serves every integrand).
fn extras(config: &ReportConfig, progress: &dyn Progress) -> Result<Vec<SeriesExtras>> {
    let d = config.study.dimension;
    let fs: Vec<Box<dyn Integrand>> = config
        .study
        .integrands
        .iter()
        .map(|s| s.build(d))
        .collect::<Result<_>>()?;
    let mut out = Vec::new();
    for &kind in &config.study.samplers {
        let sampler = kind.build(d)?;
        let targets: Vec<usize> = config
            .study
            .ns
            .iter()
            .copied()
            .filter(|&n| n <= config.target.max_n)
            .collect();
        let estimates = targets
            .iter()
            .map(|&n| {
                let params = SpectrumParams {
                    kmax: target_kmax(n),
                    realizations: config.target.realizations,
                    seed: config.seed ^ TARGET_STREAM,
                    engine: Engine::Auto,
                    bin_width: 1.0,
                };
                let stage = format!("spectrum of {kind} at N = {n}");
                progress.begin(&stage, 0);
                let e = estimate(sampler.as_ref(), n, &params);
                progress.end();
                e
            })
            .collect::<Result<Vec<_>>>()?;
        for f in &fs {
            let closed = config
                .study
                .ns
                .iter()
                .filter_map(|&n| kind.closed_form(n, d).map(|c| (n, c)))
                .map(|(n, c)| {
                    predict_polar(
                        f.as_ref(),
                        &SpectrumSource::Closed(c),
                        n,
                        &PolarParams::default(),
                    )
                })
                .collect::<Result<Vec<_>>>()?;
            let at_target = targets
                .iter()
                .zip(&estimates)
                .map(|(&n, e)| {
                    predict_lattice(
                        f.as_ref(),
                        &SpectrumSource::Estimated(e),
                        n,
                        e.lattice.lattice.kmax,
                    )
                })
                .collect::<Result<Vec<_>>>()?;
            out.push(SeriesExtras { closed, at_target });
        }
    }
    Ok(out)
}

/// Lattice extent for the spectrum at the target N: `ν` up to 8, at least 48.
fn target_kmax(n: usize) -> usize {
    ((8.0 * (n as f64).sqrt()).ceil() as usize).max(48)
}

/// Jitter against Poisson disk on each integrand, from dense predictions and from Monte Carlo.
fn crossovers(study: &Study) -> Result<Vec<Crossover>> {
    let spectrum = |kind| study.spectra.iter().find(|s| s.sampler == kind);
    let (Some(jitter), Some(poisson)) = (
        spectrum(SamplerKind::Jitter),
        spectrum(SamplerKind::PoissonDisk),
    ) else {
        return Ok(Vec::new());
    };
    let ns = &study.config.ns;
    let (first, last) = (ns[0] as f64, ns[ns.len() - 1] as f64);
    let dense: Vec<f64> = (0..=60)
        .map(|i| first * (last / first).powf(i as f64 / 60.0))
        .collect();
    let d = study.config.dimension;
    let mut out = Vec::new();
    for (j, spec) in study.config.integrands.iter().enumerate() {
        let f = spec.build(d)?;
        let curve = |e| -> Result<Vec<f64>> {
            dense
                .iter()
                .map(|&n| {
                    predict_polar(
                        f.as_ref(),
                        &SpectrumSource::Estimated(e),
                        n.round() as usize,
                        &PolarParams::default(),
                    )
                    .map(|p| p.variance)
                })
                .collect()
        };
        let predicted = crossover(
            &dense,
            &curve(&jitter.estimate)?,
            &curve(&poisson.estimate)?,
        );
        let measured = match (
            study.series_of(SamplerKind::Jitter, j),
            study.series_of(SamplerKind::PoissonDisk, j),
        ) {
            (Some(a), Some(b)) => {
                let xs: Vec<f64> = ns.iter().map(|&n| n as f64).collect();
                crossover(&xs, &mc_values(a), &mc_values(b))
            }
            _ => None,
        };
        out.push(Crossover {
            what: format!("jitter vs Poisson disk, {}", f.label()),
            predicted,
            measured,
        });
    }
    Ok(out)
}

fn mc_values(s: &StudySeries) -> Vec<f64> {
    s.measured.iter().map(|r| r.variance).collect()
}

/// The talk's 1D illustrations: a cell-centred grid of 8 points and a Gaussian of σ = 0.05.
fn illustration() -> Result<Illustration> {
    let grid_n = 8;
    let grid = Regular::new(1)?.sample(grid_n, 0, 0)?;
    let kmax = 48;
    let p = periodogram(&grid, kmax, Engine::Direct)?;
    let grid_spectrum = p
        .iter()
        .enumerate()
        .map(|(i, &v)| (i as i64 - kmax as i64, v))
        .collect();
    let f = Gaussian::new(0.05, vec![0.5], 1.0)?;
    let integrand_spectrum = (0..=240)
        .map(|i| {
            let k = -24.0 + 0.2 * i as f64;
            (k, f.fourier(&[k]).norm_sqr())
        })
        .collect();
    let mut errors = Vec::new();
    for n in [2usize, 3, 4, 5, 6, 8, 10, 12, 16] {
        let b = regular_grid_bias(&f, n)?;
        errors.push((n, b.spectral, b.bias));
    }
    Ok(Illustration {
        grid_n,
        grid_spectrum,
        integrand: f.label(),
        integrand_spectrum,
        errors,
    })
}

/// Every prediction against its Monte Carlo interval, and every predicted rate against the
/// measured one's interval.
fn study_checks(study: &Study, extras: &[SeriesExtras]) -> Vec<Check> {
    let mut checks = Vec::new();
    for (series, extra) in study.series.iter().zip(extras) {
        for (k, r) in series.measured.iter().enumerate() {
            let sources = std::iter::once(("estimated spectrum", &series.predicted[k]))
                .chain(extra.closed.get(k).map(|p| ("closed form", p)))
                .chain(
                    extra
                        .at_target
                        .get(k)
                        .map(|p| ("lattice form at this N", p)),
                );
            for (source, p) in sources {
                checks.push(prediction_check(series, source, p, r));
            }
        }
    }
    for row in &study.rows {
        let (lo, hi) = row.empirical_rate.ci;
        let predicted = row.predicted_rate.slope;
        checks.push(Check {
            what: format!(
                "rate, {} on {}: predicted within the Monte Carlo interval",
                row.sampler, row.integrand
            ),
            pass: predicted >= lo && predicted <= hi,
            detail: format!(
                "predicted {predicted:.3}, Monte Carlo {:.3} [{lo:.3}, {hi:.3}], theory {:.3}",
                row.empirical_rate.slope, row.theory_rate
            ),
        });
    }
    checks
}

fn prediction_check(series: &StudySeries, source: &str, p: &Prediction, r: &McResult) -> Check {
    let inside = p.variance >= r.ci_low && p.variance <= r.ci_high;
    let off = p.variance / r.variance - 1.0;
    // A miss is explained by the prediction's own noise when the prediction's 99% band (from
    // the spectrum estimate) reaches the Monte Carlo interval.
    let band = Z_99 * p.budget.spectrum_noise;
    let explained = p.variance + band >= r.ci_low && p.variance - band <= r.ci_high;
    let why = if inside {
        String::new()
    } else if explained {
        format!(
            "; within the prediction's own 99% band ±{:.1}% from spectrum noise",
            100.0 * band / p.variance
        )
    } else {
        "; NOT explained by the spectrum noise".to_string()
    };
    Check {
        what: format!(
            "{}, {}, N = {}: prediction ({source}) inside the 99% interval",
            series.sampler, series.label, r.n
        ),
        pass: inside,
        detail: format!(
            "predicted {:.4e}, Monte Carlo {:.4e} [{:.4e}, {:.4e}] ({} patterns × {} shifts), off by {:+.2}%{why}",
            p.variance, r.variance, r.ci_low, r.ci_high, r.patterns, r.shifts, 100.0 * off
        ),
    }
}

/// The talk's measured MSE for a sampler.
pub(crate) fn talk_mse(sampler: SamplerKind) -> f64 {
    TALK_MSE
        .iter()
        .find(|t| t.0 == sampler)
        .map_or(f64::NAN, |t| t.1)
}

/// The rendering section's checks: the talk's orderings and each prediction against its
/// measurement.
fn ambient_checks(ao: &AmbientSection) -> Vec<Check> {
    let mut checks = Vec::new();
    if let Some(ratio) = measured_ratio(&ao.rows, SamplerKind::Random, SamplerKind::Jitter) {
        checks.push(Check {
            what: "AO render: jitter's MSE well below random's (ratio > 2)".into(),
            pass: ratio > 2.0,
            detail: format!(
                "random / jitter = {ratio:.2}; the talk's render: {:.2}",
                talk_mse(SamplerKind::Random) / talk_mse(SamplerKind::Jitter)
            ),
        });
    }
    let find = |s: SamplerKind| ao.rows.iter().find(|r| r.sampler == s);
    if let (Some(c), Some(p)) = (find(SamplerKind::Ccvt), find(SamplerKind::PoissonDisk)) {
        let sigma = c.measured.stderr.hypot(p.measured.stderr);
        checks.push(Check {
            what: "AO render: CCVT's MSE below Poisson disk's".into(),
            pass: c.measured.mse < p.measured.mse,
            detail: format!(
                "CCVT {:.3e}, Poisson disk {:.3e} ({:.1}σ apart); Poisson / CCVT = {:.2}, the \
                 talk's: {:.2}",
                c.measured.mse,
                p.measured.mse,
                (p.measured.mse - c.measured.mse) / sigma,
                p.measured.mse / c.measured.mse,
                talk_mse(SamplerKind::PoissonDisk) / talk_mse(SamplerKind::Ccvt)
            ),
        });
    }
    for r in &ao.rows {
        let z = r.z_score();
        checks.push(Check {
            what: format!(
                "AO render, {}: predicted MSE inside the measurement's 99% interval",
                r.sampler
            ),
            pass: z.abs() <= Z_99,
            detail: format!(
                "predicted {:.4e}, measured {:.4e} ± {:.1e} (z = {z:+.2}, predicted / measured \
                 = {:.3})",
                r.predicted.variance,
                r.measured.mse,
                r.measured.stderr,
                r.predicted.variance / r.measured.mse
            ),
        });
    }
    checks
}

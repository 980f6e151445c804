//! Computing the report: configuration in, [`Report`] out, through the same public API a user
//! calls, and no output written.

use super::model::{
    AmbientSection, Check, ClosureConfig, ClosureRow, ClosureTable, Crossover, EdgesConfig,
    EdgesSection, Illustration, PolarComparison, Report, ReportConfig, SeriesExtras, Timing,
};
use crate::anisotropy::{
    edge_rates, variance_against_orientation, OrientationConfig, OrientationRow,
};
use crate::cache::PATTERN_MEMORY;
use crate::crosscheck::beside_monte_carlo;
use crate::error::Result;
use crate::integrand::{Gaussian, Integrand};
use crate::montecarlo::{McParams, McResult, Z_99};
use crate::predict::{
    polar_validity, predict_polar, regular_grid_bias, PolarParams, PredictParams, Prediction,
    SpectrumSource,
};
use crate::progress::{Progress, Silent};
use crate::randomization::Randomization;
use crate::rate::{crossover, fit_low_band, run_study, SamplerSpectrum, Study, StudySeries};
use crate::render::{measured_ratio, run_comparison, talk_mse};
use crate::sampler::{Ccvt, Regular, Sampler, SamplerKind};
use crate::spectrum::{periodogram, Engine};
use rayon::prelude::*;
use std::time::Instant;

/// The closure table's seed streams, independent of the study's.
const CLOSURE_PREDICT_STREAM: u64 = 0xC1;
const CLOSURE_MC_STREAM: u64 = 0xC2;

/// Computes the report.
///
/// # Errors
/// Any failure of the computations (the configuration is checked first by each part).
pub fn compute(config: &ReportConfig, progress: &dyn Progress) -> Result<Report> {
    // The closure table (with the progress shown) runs alongside the rate study, the edges and
    // the renders (silent, one after the other): each is deterministic on its own seeds, and
    // together they keep both cores busy through each other's sequential steps.
    let start = Instant::now();
    let (closure, others) = rayon::join(
        || {
            let table = closure(
                &config.closure,
                config.seed,
                config.cache.as_deref(),
                progress,
            );
            (table, start.elapsed().as_secs_f64())
        },
        || -> Result<_> {
            let study = run_study(&config.study, &Silent)?;
            let study_seconds = start.elapsed().as_secs_f64();
            let edges = edges(&config.edges, config.seed, &Silent)?;
            let edges_seconds = start.elapsed().as_secs_f64();
            let estimators = super::estimators::compute(&config.estimators, config.seed)?;
            let estimators_seconds = start.elapsed().as_secs_f64();
            let coverage = super::coverage::compute(&config.coverage, config.seed)?;
            let coverage_seconds = start.elapsed().as_secs_f64();
            let run = run_comparison(&config.ambient, &Silent)?;
            let seconds = [
                study_seconds,
                edges_seconds,
                estimators_seconds,
                coverage_seconds,
                start.elapsed().as_secs_f64(),
            ];
            Ok((study, edges, estimators, coverage, run, seconds))
        },
    );
    let (closure, closure_seconds) = closure;
    let closure = closure?;
    let (study, edges, estimators, coverage, run, seconds) = others?;
    let [study_seconds, edges_seconds, estimators_seconds, coverage_seconds, ambient_seconds] =
        seconds;
    let extras = extras(&study)?;
    let timings = vec![
        Timing {
            stage: "closure table: every sampler off the talk's setup".into(),
            seconds: closure_seconds,
        },
        Timing {
            stage: "rate study: spectra, predictions, Monte Carlo (alongside the closure table)"
                .into(),
            seconds: study_seconds,
        },
        Timing {
            stage: "edges at any angle: orientation curves and rates (after the rate study, \
                    alongside the closure table)"
                .into(),
            seconds: edges_seconds - study_seconds,
        },
        Timing {
            stage: "the estimator as used: strata and nets shifted and as used (after the \
                    edges, alongside the closure table)"
                .into(),
            seconds: estimators_seconds - edges_seconds,
        },
        Timing {
            stage: "the budgets' coverage: estimated routes against exact truths (after the \
                    estimators, alongside the closure table)"
                .into(),
            seconds: coverage_seconds - estimators_seconds,
        },
        Timing {
            stage: "ambient-occlusion renders (after the coverage, alongside the closure table)"
                .into(),
            seconds: ambient_seconds - coverage_seconds,
        },
    ];
    let crossovers = crossovers(&study);
    let ccvt_low_band = study
        .spectra
        .iter()
        .find(|s| s.sampler == SamplerKind::Ccvt)
        .and_then(|s| fit_low_band(&s.estimate.radial, 0.3).ok())
        .map(|fit| {
            (
                fit,
                Ccvt::new(2).map_or(f64::NAN, |c| c.floor_coefficient()),
            )
        });
    let illustration = illustration()?;
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
    let mut checks = study_checks(&study);
    checks.extend(closure_checks(&closure));
    checks.extend(edge_checks(&edges));
    checks.extend(estimator_checks(&estimators));
    checks.push(coverage_check(&coverage));
    checks.extend(ambient_checks(&ambient));
    Ok(Report {
        config: config.clone(),
        study,
        extras,
        closure,
        crossovers,
        ccvt_low_band,
        illustration,
        edges,
        estimators,
        coverage,
        ambient,
        checks,
        timings,
    })
}

/// The edges' seed stream, independent of the others.
const EDGES_STREAM: u64 = 0xED;

/// Every sampler's orientation curve at N and its rates at the rate angles.
fn edges(config: &EdgesConfig, seed: u64, progress: &dyn Progress) -> Result<EdgesSection> {
    let mut curves = Vec::new();
    let mut rates = Vec::new();
    for &kind in &config.samplers {
        let sampler = kind.build(2)?;
        let curve = OrientationConfig {
            n: config.n,
            angles: config.angles.clone(),
            offset: 0.5,
            trials: config.trials,
            seed: seed ^ EDGES_STREAM,
            predict: PredictParams {
                seed: seed ^ EDGES_STREAM,
                ..config.predict
            },
        };
        curves.push((
            kind,
            variance_against_orientation(sampler.as_ref(), kind, &curve, progress)?,
        ));
        let at_angles = OrientationConfig {
            angles: config.rate_angles.clone(),
            ..curve
        };
        rates.push((
            kind,
            edge_rates(
                sampler.as_ref(),
                kind,
                &config.rate_ns,
                &at_angles,
                progress,
            )?,
        ));
    }
    Ok(EdgesSection { curves, rates })
}

/// The curves' agreement (misses consistent with 1%, none beyond four standard errors) and
/// each predicted rate inside Monte Carlo's 99% interval, widened by its own 99% error.
fn edge_checks(edges: &EdgesSection) -> Vec<Check> {
    let rows: Vec<&OrientationRow> = edges.curves.iter().flat_map(|c| &c.1).collect();
    let misses = rows.iter().filter(|r| !r.agrees()).count();
    let largest = rows.iter().map(|r| r.z.abs()).fold(0.0, f64::max);
    let p = binomial_tail(rows.len(), misses, 0.01);
    let mut checks = vec![Check {
        what: "edges: orientation curves inside Monte Carlo's intervals at the nominal rate".into(),
        pass: p >= 0.01 && largest <= 4.0,
        detail: format!(
            "{misses} misses of {} (expected {:.1}); P(this many or more) = {p:.3}; largest |z| = {largest:.2}",
            rows.len(),
            0.01 * rows.len() as f64
        ),
    }];
    for (kind, rates) in &edges.rates {
        for r in rates {
            let slack = Z_99 * r.predicted.stderr;
            checks.push(Check {
                what: format!(
                    "edges, {kind} at {}°: predicted rate within the Monte Carlo interval",
                    r.angle
                ),
                pass: r.predicted.slope + slack >= r.measured.ci.0
                    && r.predicted.slope - slack <= r.measured.ci.1,
                detail: format!(
                    "predicted {:.3} ± {slack:.3}, Monte Carlo {:.3} [{:.3}, {:.3}]",
                    r.predicted.slope, r.measured.slope, r.measured.ci.0, r.measured.ci.1
                ),
            });
        }
    }
    checks
}

/// The polar form rescaled from each sampler's reference spectrum at every N of its series,
/// where that route is valid (otherwise why not): the route a spectrum tool would take, beside
/// the valid one.
fn extras(study: &Study) -> Result<Vec<SeriesExtras>> {
    let d = study.config.dimension;
    let mut out = Vec::new();
    for spectrum in &study.spectra {
        for spec in &study.config.integrands {
            let f = spec.build(d)?;
            let polar = study
                .config
                .ns
                .iter()
                .map(|&n| polar_comparison(f.as_ref(), spectrum, n, study.config.reference.n))
                .collect();
            out.push(SeriesExtras { polar });
        }
    }
    Ok(out)
}

fn polar_comparison(
    f: &dyn Integrand,
    spectrum: &SamplerSpectrum,
    n: usize,
    n_ref: usize,
) -> PolarComparison {
    let kind = spectrum.sampler;
    let d = f.dimension();
    if !kind.is_scale_invariant_at(n, d) {
        return PolarComparison::Invalid(format!("{kind} is not scale invariant at N = {n}"));
    }
    if n > n_ref {
        return PolarComparison::Invalid(format!("N above the reference N = {n_ref}"));
    }
    let range = 2.0 * (n as f64).powf(-1.0 / d as f64);
    let checked = polar_validity(f, range, n).and_then(|model| {
        let source = SpectrumSource::Estimated(&spectrum.estimate);
        let mut p = predict_polar(f, &source, n, &PolarParams::default())?;
        p.budget.model = model;
        Ok(p)
    });
    match checked {
        Ok(p) => PolarComparison::Valid(p),
        Err(e) => PolarComparison::Invalid(e.to_string()),
    }
}

/// Jitter against Poisson disk on each integrand: where the predicted curves cross and where
/// the measured ones do (each log-log interpolated between the study's N).
fn crossovers(study: &Study) -> Vec<Crossover> {
    let ns: Vec<f64> = study.config.ns.iter().map(|&n| n as f64).collect();
    (0..study.config.integrands.len())
        .filter_map(|j| {
            let a = study.series_of(SamplerKind::Jitter, j)?;
            let b = study.series_of(SamplerKind::PoissonDisk, j)?;
            let predicted =
                |s: &StudySeries| s.predicted.iter().map(|p| p.variance).collect::<Vec<_>>();
            Some(Crossover {
                what: format!("jitter vs Poisson disk, {}", a.label),
                predicted: crossover(&ns, &predicted(a), &predicted(b)),
                measured: crossover(&ns, &mc_values(a), &mc_values(b)),
            })
        })
        .collect()
}

fn mc_values(s: &StudySeries) -> Vec<f64> {
    s.measured.iter().map(|r| r.variance).collect()
}

/// Every sampler × integrand × N of the closure configuration: the default prediction and one
/// Monte Carlo run per sampler and N (all integrands on the same patterns), independent seeds.
fn closure(
    config: &ClosureConfig,
    seed: u64,
    cache: Option<&std::path::Path>,
    progress: &dyn Progress,
) -> Result<ClosureTable> {
    let fs: Vec<Box<dyn Integrand>> = config
        .integrands
        .iter()
        .map(|s| s.build(2))
        .collect::<Result<_>>()?;
    let f_refs: Vec<&dyn Integrand> = fs.iter().map(|f| f.as_ref()).collect();
    let params = PredictParams {
        seed: seed ^ CLOSURE_PREDICT_STREAM,
        ..config.predict
    };
    let mut rows = Vec::new();
    for &kind in &config.samplers {
        let sampler = crate::cache::cached_sampler(kind, 2, cache, PATTERN_MEMORY)?;
        let ns = kind.nearest_counts(&config.ns, 2);
        // The counts run side by side (each is deterministic, and their rows are kept in
        // order): one count's sequential steps overlap another's parallel ones.
        progress.begin(&format!("closure: {kind}"), ns.len() as u64);
        let cells: Vec<Result<Vec<ClosureRow>>> = ns
            .par_iter()
            .map(|&n| {
                let cell =
                    closure_cell(config, &params, seed, (kind, sampler.as_ref()), &f_refs, n);
                progress.advance(1);
                cell
            })
            .collect();
        progress.end();
        for cell in cells {
            rows.extend(cell?);
        }
    }
    let misses = rows.iter().filter(|r| !r.agrees).count();
    Ok(ClosureTable {
        expected_misses: 0.01 * rows.len() as f64,
        binomial_p: binomial_tail(rows.len(), misses, 0.01),
        max_abs_z: rows.iter().map(|r| r.z.abs()).fold(0.0, f64::max),
        misses,
        rows,
    })
}

/// One sampler at one count: Monte Carlo of every integrand on the same patterns, and their
/// default predictions.
fn closure_cell(
    config: &ClosureConfig,
    params: &PredictParams,
    seed: u64,
    (kind, sampler): (SamplerKind, &dyn Sampler),
    integrands: &[&dyn Integrand],
    n: usize,
) -> Result<Vec<ClosureRow>> {
    let mut mc = McParams::pooled(
        kind,
        config.trials,
        seed ^ CLOSURE_MC_STREAM,
        Randomization::Shift,
    );
    mc.budget = config.predict.budget;
    let results = beside_monte_carlo(sampler, integrands, n, &mc, params, ("", &Silent))?;
    Ok(integrands
        .iter()
        .zip(results)
        .map(|(f, (measured, prediction))| {
            let z = prediction.z_beyond_bounds(&measured);
            ClosureRow {
                sampler: kind,
                integrand: f.label(),
                n,
                prediction,
                measured,
                z,
                agrees: z.abs() <= Z_99,
            }
        })
        .collect())
}

/// `P(X ≥ k)` for `X ~ Binomial(n, p)`.
fn binomial_tail(n: usize, k: usize, p: f64) -> f64 {
    let ln_choose =
        |n: usize, i: usize| -> f64 { (1..=i).map(|j| ((n - i + j) as f64 / j as f64).ln()).sum() };
    let below: f64 = (0..k.min(n + 1))
        .map(|i| (ln_choose(n, i) + i as f64 * p.ln() + (n - i) as f64 * (1.0 - p).ln()).exp())
        .sum();
    (1.0 - below).max(0.0)
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
fn study_checks(study: &Study) -> Vec<Check> {
    let mut checks = Vec::new();
    for series in &study.series {
        for (p, r) in series.predicted.iter().zip(&series.measured) {
            checks.push(prediction_check(series, p, r));
        }
    }
    for row in &study.rows {
        let (lo, hi) = row.empirical_rate.ci;
        let predicted = row.predicted_rate.slope;
        // The predicted slope has its own error (from the predictions' budgets).
        let slack = Z_99 * row.predicted_rate.stderr;
        checks.push(Check {
            what: format!(
                "rate, {} on {}: predicted within the Monte Carlo interval",
                row.sampler, row.integrand
            ),
            pass: predicted + slack >= lo && predicted - slack <= hi,
            detail: format!(
                "predicted {predicted:.3} ± {slack:.3}, Monte Carlo {:.3} [{lo:.3}, {hi:.3}], theory {}",
                row.empirical_rate.slope,
                crate::rate::theory_text(row.theory_rate, 3)
            ),
        });
    }
    checks
}

/// The closure table's summary as checks: misses consistent with the nominal 1%, none beyond
/// four combined standard errors.
fn closure_checks(table: &ClosureTable) -> Vec<Check> {
    vec![
        Check {
            what: "closure table: misses consistent with the intervals' nominal 1%".into(),
            pass: table.binomial_p >= 0.01,
            detail: format!(
                "{} misses of {} (expected {:.1}); P(this many or more) = {:.3}",
                table.misses,
                table.rows.len(),
                table.expected_misses,
                table.binomial_p
            ),
        },
        Check {
            what: "closure table: no miss beyond 4 combined standard errors".into(),
            pass: table.max_abs_z <= 4.0,
            detail: format!("largest |z| = {:.2}", table.max_abs_z),
        },
    ]
}

/// The section's checks: its predictions agree with their Monte Carlo at 99%, as many as the
/// nominal rate allows.
fn estimator_checks(section: &super::EstimatorsSection) -> Vec<Check> {
    let rows = section.rows.len();
    let misses = section.rows.iter().filter(|r| r.z.abs() > Z_99).count();
    let p = binomial_tail(rows, misses, 0.01);
    let worst = section.rows.iter().map(|r| r.z.abs()).fold(0.0, f64::max);
    vec![Check {
        what: "the estimator as used: shifted and as-used predictions against Monte Carlo of \
               the same estimator"
            .into(),
        pass: p >= 0.01 && worst <= 4.0,
        detail: format!(
            "{misses} misses of {rows} at 99% (P(this many or more) = {p:.3}); largest |z| = \
             {worst:.2}"
        ),
    }]
}

/// The coverage check: at most [`MAX_MISS_FRACTION`](super::coverage::MAX_MISS_FRACTION) of
/// the estimates miss their exact truth at 99%.
fn coverage_check(section: &super::CoverageSection) -> Check {
    Check {
        what: "the budgets' coverage: estimated predictions against exact truths at 99%".into(),
        pass: section.miss_fraction <= super::coverage::MAX_MISS_FRACTION,
        detail: format!(
            "{} of {} outside their 99% interval ({:.1}%, at most {:.0}% allowed); median \
             half-width {:.1}% of the value",
            section.misses,
            section.rows.len(),
            100.0 * section.miss_fraction,
            100.0 * super::coverage::MAX_MISS_FRACTION,
            100.0 * section.median_relative_width
        ),
    }
}

/// A prediction against its Monte Carlo run: they agree when their difference is within the
/// prediction's bounds plus 2.576 combined standard errors (the prediction's noise and Monte
/// Carlo's).
fn prediction_check(series: &StudySeries, p: &Prediction, r: &McResult) -> Check {
    let z = p.z_beyond_bounds(r);
    Check {
        what: format!(
            "{}, {}, N = {}: prediction ({}) agrees with Monte Carlo at 99%",
            series.sampler, series.label, r.n, p.route
        ),
        pass: z.abs() <= Z_99,
        detail: format!(
            "predicted {:.4e} ± {:.1e}, Monte Carlo {:.4e} [{:.4e}, {:.4e}] ({} patterns × {} shifts), off by {:+.2}%, z = {z:+.2}",
            p.variance,
            p.budget.half_width(Z_99),
            r.variance,
            r.ci_low,
            r.ci_high,
            r.patterns,
            r.shifts,
            100.0 * (p.variance / r.variance - 1.0)
        ),
    }
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
                "predicted {:.4e} (bounds ±{:.1e}), measured {:.4e} ± {:.1e} (z beyond the \
                 bounds = {z:+.2}, predicted / measured = {:.3})",
                r.predicted.variance,
                r.predicted.budget.bounds(),
                r.measured.mse,
                r.measured.stderr,
                r.predicted.variance / r.measured.mse
            ),
        });
    }
    checks
}

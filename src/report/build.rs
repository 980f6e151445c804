//! Computing the report: spectra, predictions, Monte Carlo, rates, crossovers, checks.

use crate::error::{Error, Result};
use crate::integrand::{Ball, Gaussian, Integrand};
use crate::montecarlo::{empirical_variances, McParams, McResult};
use crate::predict::{
    predict_lattice, predict_polar, LatticeSource, PolarParams, Prediction, SpectrumSource,
};
use crate::progress;
use crate::rate::{crossover, fit_alpha, loglog_slope, theory_rate, SlopeFit};
use crate::sampler::{Sampler, SamplerKind};
use crate::spectrum::{estimate, ClosedForm, Engine, SpectrumEstimate, SpectrumParams};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// What the report computes and where it writes.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportConfig {
    /// Output directory.
    pub out: PathBuf,
    /// The short run (about a minute): fewer N, trials and realizations.
    pub quick: bool,
    /// Seed of every random stream.
    pub seed: u64,
}

impl Default for ReportConfig {
    fn default() -> Self {
        Self {
            out: PathBuf::from("report"),
            quick: false,
            seed: 2016,
        }
    }
}

/// The sizes of one run.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    pub ns: Vec<usize>,
    pub reference_n: usize,
    pub kmax: usize,
    pub realizations: usize,
    pub ccvt_realizations: usize,
    /// Realizations of the spectrum estimated at the target N (lattice form).
    pub target_realizations: usize,
    /// The lattice form at the target N is computed up to this N.
    pub target_max_n: usize,
    /// Trials for samplers cheap enough to draw one pattern per trial.
    pub cheap_trials: usize,
    /// (patterns, shifts) for Poisson disk.
    pub poisson_pool: (usize, usize),
    /// (patterns, shifts) for CCVT, by N.
    pub ccvt_pool: fn(usize) -> (usize, usize),
}

impl Plan {
    fn new(quick: bool) -> Self {
        if quick {
            Self {
                ns: vec![16, 64, 256, 1024],
                reference_n: 1024,
                kmax: 160,
                realizations: 32,
                ccvt_realizations: 4,
                target_realizations: 16,
                target_max_n: 64,
                cheap_trials: 4000,
                poisson_pool: (200, 20),
                ccvt_pool: |n| if n <= 256 { (48, 64) } else { (16, 128) },
            }
        } else {
            Self {
                ns: vec![16, 36, 64, 144, 256, 576, 1024, 2304, 4096],
                reference_n: 4096,
                kmax: 320,
                realizations: 256,
                ccvt_realizations: 16,
                target_realizations: 64,
                target_max_n: 256,
                cheap_trials: 20000,
                poisson_pool: (600, 32),
                ccvt_pool: |n| match n {
                    0..=256 => (256, 64),
                    257..=1024 => (64, 256),
                    _ => (24, 512),
                },
            }
        }
    }
}

/// One sampler's spectrum, predictions and Monte Carlo results.
#[derive(Debug, Clone, Serialize)]
pub struct SamplerSeries {
    /// Sampler name.
    pub sampler: String,
    /// The radial spectrum estimated at the reference N.
    pub spectrum: crate::spectrum::RadialSpectrum,
    /// Fitted low-frequency exponent α.
    pub alpha: SlopeFit,
    /// Per integrand (disk, Gaussian): predictions from the estimated spectrum at each N.
    pub predicted: Vec<Vec<Prediction>>,
    /// Per integrand: closed-form predictions (random and jitter only).
    pub closed: Vec<Vec<Prediction>>,
    /// Per integrand: lattice-form predictions from a spectrum estimated at the target N itself
    /// (no scale invariance or radial binning involved), for the smaller N.
    pub at_target: Vec<Vec<Prediction>>,
    /// Per integrand: Monte Carlo at each N.
    pub measured: Vec<Vec<McResult>>,
}

/// A row of the rate table.
#[derive(Debug, Clone, Serialize)]
pub struct RateRow {
    /// Sampler.
    pub sampler: String,
    /// Integrand.
    pub integrand: String,
    /// Dimension.
    pub dimension: usize,
    /// α used by the theory (known, or fitted for CCVT).
    pub alpha: f64,
    /// Theoretical asymptotic rate.
    pub theory_rate: f64,
    /// Whether a log N factor applies.
    pub log_factor: bool,
    /// Log-log slope of the predicted variances over the N range.
    pub predicted_rate: f64,
    /// Log-log slope of the Monte Carlo variances, with its 99% interval.
    pub empirical_rate: SlopeFit,
}

/// Where two samplers' variance curves cross.
#[derive(Debug, Clone, Serialize)]
pub struct Crossover {
    /// Which curves.
    pub what: String,
    /// The N from the predicted curves (dense in N), if they cross in range.
    pub predicted: Option<f64>,
    /// The N from the Monte Carlo points (log-log interpolated), if they cross in range.
    pub measured: Option<f64>,
}

/// One cross-check with its numbers.
#[derive(Debug, Clone, Serialize)]
pub struct Check {
    /// What is checked.
    pub what: String,
    /// Whether it passed.
    pub pass: bool,
    /// The numbers, in words.
    pub detail: String,
}

/// Everything the report computed.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The N values.
    pub ns: Vec<usize>,
    /// Integrand labels, in the order of every per-integrand list.
    pub integrands: Vec<String>,
    /// Per sampler.
    pub samplers: Vec<SamplerSeries>,
    /// The rate table.
    pub rates: Vec<RateRow>,
    /// Crossovers of one sampler's variance curve with another's.
    pub crossovers: Vec<Crossover>,
    /// Every cross-check.
    pub checks: Vec<Check>,
    /// The 1D illustration numbers.
    pub illustration: super::illustrate::Illustration,
    /// Seconds per stage.
    pub timings: Vec<(String, f64)>,
    /// The rendering experiment.
    pub ambient_occlusion: super::ambient::AoSection,
    /// Whether this was the quick run.
    pub quick: bool,
}

pub(crate) const SAMPLERS: [SamplerKind; 4] = [
    SamplerKind::Random,
    SamplerKind::Jitter,
    SamplerKind::PoissonDisk,
    SamplerKind::Ccvt,
];

/// The known low-frequency exponent of a sampler (None: measure it).
fn known_alpha(kind: SamplerKind) -> Option<f64> {
    match kind {
        SamplerKind::Random | SamplerKind::PoissonDisk => Some(0.0),
        SamplerKind::Jitter => Some(2.0),
        _ => None,
    }
}

fn closed_form(kind: SamplerKind) -> Option<ClosedForm> {
    match kind {
        SamplerKind::Random => Some(ClosedForm::WhiteNoise),
        SamplerKind::Jitter => Some(ClosedForm::Jitter),
        _ => None,
    }
}

/// The two integrands of the report: the disk of radius 1/4 and the Gaussian σ = 0.1, centred.
pub(crate) fn integrands() -> Result<Vec<Box<dyn Integrand>>> {
    Ok(vec![
        Box::new(Ball::new(0.25, vec![0.5, 0.5], 1.0)?),
        Box::new(Gaussian::new(0.1, vec![0.5, 0.5], 1.0)?),
    ])
}

/// Runs the report and writes it to `config.out`.
///
/// # Errors
/// An unwritable directory, or any failure of the computations.
pub fn run(config: &ReportConfig) -> Result<Report> {
    std::fs::create_dir_all(&config.out)
        .map_err(|e| Error::Io(format!("{}: {e}", config.out.display())))?;
    let plan = Plan::new(config.quick);
    let fs = integrands()?;
    let f_refs: Vec<&dyn Integrand> = fs.iter().map(|f| f.as_ref()).collect();
    let mut timings = Vec::new();
    let mut samplers = Vec::new();
    let mut estimates = Vec::new();
    for kind in SAMPLERS {
        let start = std::time::Instant::now();
        let sampler = kind.build(2)?;
        let est = spectrum_of(kind, sampler.as_ref(), &plan, config.seed)?;
        timings.push((
            format!("spectrum: {}", kind.name()),
            start.elapsed().as_secs_f64(),
        ));
        let start = std::time::Instant::now();
        let series = series_of(kind, sampler.as_ref(), &est, &f_refs, &plan, config)?;
        timings.push((
            format!("monte carlo: {}", kind.name()),
            start.elapsed().as_secs_f64(),
        ));
        samplers.push(series);
        estimates.push(est);
    }
    let rates = rate_rows(&samplers, &f_refs, &plan)?;
    let crossovers = crossovers(&samplers, &f_refs, &plan)?;
    let mut checks = checks(&samplers, &rates, &f_refs);
    let illustration = super::illustrate::compute()?;
    let start = std::time::Instant::now();
    let ambient_occlusion = super::ambient::run(&config.out.join("ao"), config.quick, config.seed)?;
    timings.push((
        "ambient-occlusion renders".to_string(),
        start.elapsed().as_secs_f64(),
    ));
    checks.extend(super::ambient::checks(&ambient_occlusion));
    let report = Report {
        ns: plan.ns.clone(),
        integrands: f_refs.iter().map(|f| f.label()).collect(),
        samplers,
        rates,
        crossovers,
        checks,
        illustration,
        ambient_occlusion,
        timings,
        quick: config.quick,
    };
    super::markdown::write_all(&config.out, &report, &estimates, &f_refs)?;
    Ok(report)
}

fn spectrum_of(
    kind: SamplerKind,
    sampler: &dyn Sampler,
    plan: &Plan,
    seed: u64,
) -> Result<SpectrumEstimate> {
    let realizations = if kind == SamplerKind::Ccvt {
        plan.ccvt_realizations
    } else {
        plan.realizations
    };
    let bar = progress::spinner(format!(
        "spectrum of {} at N = {} ({realizations} realizations)",
        kind.name(),
        plan.reference_n
    ));
    let params = SpectrumParams {
        kmax: plan.kmax,
        realizations,
        seed,
        engine: Engine::Auto,
        bin_width: 1.0,
    };
    let est = estimate(sampler, plan.reference_n, &params);
    bar.finish_and_clear();
    est
}

fn pool(kind: SamplerKind, plan: &Plan, n: usize) -> (usize, usize) {
    match kind {
        SamplerKind::PoissonDisk => plan.poisson_pool,
        SamplerKind::Ccvt => (plan.ccvt_pool)(n),
        _ => (plan.cheap_trials, 1),
    }
}

fn series_of(
    kind: SamplerKind,
    sampler: &dyn Sampler,
    est: &SpectrumEstimate,
    fs: &[&dyn Integrand],
    plan: &Plan,
    config: &ReportConfig,
) -> Result<SamplerSeries> {
    let alpha = fit_alpha(&est.radial, 0.0, 0.3)?;
    let polar = PolarParams::default();
    let mut predicted = vec![Vec::new(); fs.len()];
    let mut closed = vec![Vec::new(); fs.len()];
    for (j, f) in fs.iter().enumerate() {
        for &n in &plan.ns {
            predicted[j].push(predict_polar(
                *f,
                SpectrumSource::Estimated(&est.radial),
                n,
                &polar,
            )?);
            if let Some(c) = closed_form(kind) {
                closed[j].push(predict_polar(*f, SpectrumSource::Closed(c), n, &polar)?);
            }
        }
    }
    let mut at_target = vec![Vec::new(); fs.len()];
    for &n in plan.ns.iter().filter(|&&n| n <= plan.target_max_n) {
        let params = SpectrumParams {
            kmax: target_kmax(n),
            realizations: plan.target_realizations,
            seed: config.seed ^ 0x7A,
            engine: Engine::Auto,
            bin_width: 1.0,
        };
        let lattice = estimate(sampler, n, &params)?.lattice;
        for (j, f) in fs.iter().enumerate() {
            at_target[j].push(predict_lattice(
                *f,
                LatticeSource::Estimated(&lattice),
                n,
                params.kmax,
            )?);
        }
    }
    let total: usize = plan.ns.iter().map(|&n| pool(kind, plan, n).0).sum();
    let bar = progress::bar(total as u64, format!("monte carlo: {}", kind.name()));
    let mut measured = vec![Vec::new(); fs.len()];
    for &n in &plan.ns {
        let (patterns, shifts) = pool(kind, plan, n);
        let params = McParams {
            patterns,
            shifts,
            seed: config.seed ^ 0x4D43,
            homogenize: true,
        };
        let results = empirical_variances(sampler, fs, n, &params, &|| bar.inc(1))?;
        for (j, r) in results.into_iter().enumerate() {
            measured[j].push(r);
        }
    }
    bar.finish_and_clear();
    Ok(SamplerSeries {
        sampler: kind.name().to_string(),
        spectrum: est.radial.clone(),
        alpha,
        predicted,
        closed,
        at_target,
        measured,
    })
}

/// Lattice extent for the spectrum at the target N: `ν` up to 8, at least 48.
fn target_kmax(n: usize) -> usize {
    ((8.0 * (n as f64).sqrt()).ceil() as usize).max(48)
}

/// Relative standard error of a Monte Carlo variance, from its 99% interval.
fn rel_stderr(r: &McResult) -> f64 {
    (r.ci_high / r.ci_low).ln() / (2.0 * crate::montecarlo::Z_99)
}

fn rate_rows(
    samplers: &[SamplerSeries],
    fs: &[&dyn Integrand],
    plan: &Plan,
) -> Result<Vec<RateRow>> {
    let ns: Vec<f64> = plan.ns.iter().map(|&n| n as f64).collect();
    let mut rows = Vec::new();
    for (s, kind) in samplers.iter().zip(SAMPLERS) {
        for (j, f) in fs.iter().enumerate() {
            let alpha = known_alpha(kind).unwrap_or(s.alpha.slope);
            let (theory, log_factor) = theory_rate(alpha, f.decay_exponent(), 2);
            let pred: Vec<f64> = s.predicted[j].iter().map(|p| p.variance).collect();
            let predicted_rate = loglog_slope(&ns, &pred, None)?.slope;
            let mc: Vec<f64> = s.measured[j].iter().map(|r| r.variance).collect();
            let rel: Vec<f64> = s.measured[j].iter().map(rel_stderr).collect();
            let empirical_rate = loglog_slope(&ns, &mc, Some(&rel))?;
            rows.push(RateRow {
                sampler: s.sampler.clone(),
                integrand: f.label(),
                dimension: 2,
                alpha,
                theory_rate: theory,
                log_factor,
                predicted_rate,
                empirical_rate,
            });
        }
    }
    Ok(rows)
}

/// Jitter against Poisson disk on each integrand, from dense predictions and from Monte Carlo.
fn crossovers(
    samplers: &[SamplerSeries],
    fs: &[&dyn Integrand],
    plan: &Plan,
) -> Result<Vec<Crossover>> {
    let find = |name: &str| samplers.iter().find(|s| s.sampler == name);
    let (Some(jitter), Some(poisson)) = (find("jitter"), find("poisson")) else {
        return Ok(Vec::new());
    };
    let dense: Vec<f64> = (0..=60)
        .map(|i| 16f64 * (plan.ns[plan.ns.len() - 1] as f64 / 16.0).powf(i as f64 / 60.0))
        .collect();
    let polar = PolarParams::default();
    let mut out = Vec::new();
    for (j, f) in fs.iter().enumerate() {
        let curve = |s: &SamplerSeries| -> Result<Vec<f64>> {
            dense
                .iter()
                .map(|&n| {
                    predict_polar(
                        *f,
                        SpectrumSource::Estimated(&s.spectrum),
                        n.round() as usize,
                        &polar,
                    )
                    .map(|p| p.variance)
                })
                .collect()
        };
        let predicted = crossover(&dense, &curve(jitter)?, &curve(poisson)?);
        let ns: Vec<f64> = plan.ns.iter().map(|&n| n as f64).collect();
        let mc = |s: &SamplerSeries| s.measured[j].iter().map(|r| r.variance).collect::<Vec<_>>();
        let measured = crossover(&ns, &mc(jitter), &mc(poisson));
        out.push(Crossover {
            what: format!("jitter vs Poisson disk, {}", f.label()),
            predicted,
            measured,
        });
    }
    Ok(out)
}

fn checks(samplers: &[SamplerSeries], rates: &[RateRow], fs: &[&dyn Integrand]) -> Vec<Check> {
    let mut checks = Vec::new();
    for s in samplers {
        for (j, f) in fs.iter().enumerate() {
            for (k, r) in s.measured[j].iter().enumerate() {
                let sources = std::iter::once(("estimated spectrum", &s.predicted[j][k]))
                    .chain(s.closed[j].get(k).map(|p| ("closed form", p)))
                    .chain(s.at_target[j].get(k).map(|p| ("lattice form at this N", p)));
                for (source, p) in sources {
                    checks.push(prediction_check(&s.sampler, f.label(), source, p, r));
                }
            }
        }
    }
    for row in rates {
        let (lo, hi) = row.empirical_rate.ci;
        checks.push(Check {
            what: format!(
                "rate, {} on {}: predicted within the Monte Carlo interval",
                row.sampler, row.integrand
            ),
            pass: row.predicted_rate >= lo && row.predicted_rate <= hi,
            detail: format!(
                "predicted {:.3}, Monte Carlo {:.3} [{lo:.3}, {hi:.3}], theory {:.3}",
                row.predicted_rate, row.empirical_rate.slope, row.theory_rate
            ),
        });
    }
    checks
}

fn prediction_check(
    sampler: &str,
    integrand: String,
    source: &str,
    p: &Prediction,
    r: &McResult,
) -> Check {
    let inside = p.variance >= r.ci_low && p.variance <= r.ci_high;
    let off = p.variance / r.variance - 1.0;
    // A miss is explained by the prediction's own noise when the prediction's 99% band (from
    // the spectrum estimate) reaches the Monte Carlo interval.
    let band = crate::montecarlo::Z_99 * p.spectrum_stderr;
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
        what: format!("{sampler}, {integrand}, N = {}: prediction ({source}) inside the 99% interval", r.n),
        pass: inside,
        detail: format!(
            "predicted {:.4e}, Monte Carlo {:.4e} [{:.4e}, {:.4e}] ({} patterns × {} shifts), off by {:+.2}%{why}",
            p.variance, r.variance, r.ci_low, r.ci_high, r.patterns, r.shifts, 100.0 * off
        ),
    }
}

/// Writes `text` to `dir/name`.
pub(crate) fn write_text(dir: &Path, name: &str, text: &str) -> Result<()> {
    let path = dir.join(name);
    std::fs::write(&path, text).map_err(|e| Error::Io(format!("{}: {e}", path.display())))
}

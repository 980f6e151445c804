//! Command-line argument types and the actions behind each subcommand.
//!
//! The binary only parses and dispatches; everything printed here is computed by the public
//! library API, so a user can compute the same numbers from Rust.

use crate::error::{Error, Result};
use crate::io;
use crate::sampler::{Homogenized, Sampler, SamplerKind};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `specvar samplers`.
#[derive(Debug, Args)]
pub struct SamplersArgs {
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `specvar sample`.
#[derive(Debug, Args)]
pub struct SampleArgs {
    /// Sampler name (see `specvar samplers`).
    #[arg(long, short = 's')]
    pub sampler: String,
    /// Number of points per realization.
    #[arg(short = 'n')]
    pub n: usize,
    /// Dimension.
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Number of realizations (0, 1, … M-1 of the seed).
    #[arg(long, short = 'm', default_value_t = 1)]
    pub realizations: u64,
    /// Apply a random toroidal shift to each realization.
    #[arg(long)]
    pub homogenize: bool,
    /// Output file (standard output if absent).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
    /// Write JSON instead of UTK text.
    #[arg(long)]
    pub json: bool,
}

/// Builds a sampler by name, homogenized on request.
///
/// # Errors
/// An unknown name or an unsupported dimension.
pub fn build_sampler(name: &str, d: usize, homogenized: bool) -> Result<Box<dyn Sampler>> {
    let inner = SamplerKind::from_name(name)?.build(d)?;
    Ok(if homogenized {
        Box::new(Homogenized::new(inner))
    } else {
        inner
    })
}

/// The sampler table.
pub fn sampler_table() -> String {
    let mut out = format!(
        "{:<8} {:<11} {:<12} {}\n",
        "name", "dimensions", "N", "description"
    );
    for k in SamplerKind::ALL {
        let dims = k.dimensions();
        out.push_str(&format!(
            "{:<8} {:<11} {:<12} {}\n",
            k.name(),
            format!("{}-{}", dims.start(), dims.end()),
            k.count_rule(),
            k.description()
        ));
    }
    out
}

/// `specvar samplers`.
///
/// # Errors
/// Writing to standard output fails.
pub fn samplers(args: &SamplersArgs) -> Result<()> {
    if args.json {
        let rows: Vec<serde_json::Value> = SamplerKind::ALL
            .iter()
            .map(|k| {
                serde_json::json!({
                    "name": k.name(),
                    "min_dimension": k.dimensions().start(),
                    "max_dimension": k.dimensions().end(),
                    "n_rule": k.count_rule(),
                    "description": k.description(),
                })
            })
            .collect();
        println!("{}", serde_json::Value::Array(rows));
    } else {
        print!("{}", sampler_table());
    }
    Ok(())
}

/// `specvar sample`.
///
/// # Errors
/// Bad sampler, dimension or N, or an unwritable output.
pub fn sample(args: &SampleArgs) -> Result<()> {
    if args.realizations == 0 {
        return Err(crate::error::invalid("realizations", 0, "at least 1"));
    }
    let sampler = build_sampler(&args.sampler, args.dimension, args.homogenize)?;
    let sets = (0..args.realizations)
        .map(|r| sampler.sample(args.n, args.seed, r))
        .collect::<Result<Vec<_>>>()?;
    let text = if args.json {
        io::write_json(&sets)? + "\n"
    } else {
        io::write_text(&sets)
    };
    write_output(args.output.as_deref(), &text)
}

/// Writes `text` to a file, or to standard output when `path` is `None`.
///
/// # Errors
/// The file cannot be written.
pub fn write_output(path: Option<&std::path::Path>, text: &str) -> Result<()> {
    match path {
        Some(p) => std::fs::write(p, text).map_err(|e| Error::Io(format!("{}: {e}", p.display()))),
        None => std::io::stdout()
            .write_all(text.as_bytes())
            .map_err(|e| Error::Io(e.to_string())),
    }
}

/// What `specvar` does with no subcommand.
///
/// # Errors
/// As the job it runs.
pub fn default_job() -> Result<()> {
    report(&ReportArgs {
        out: PathBuf::from("report"),
        quick: false,
        seed: 2016,
    })
}

/// Arguments of `specvar spectrum`.
#[derive(Debug, Args)]
pub struct SpectrumArgs {
    /// Sampler name (ignored with --input).
    #[arg(long, short = 's', default_value = "random")]
    pub sampler: String,
    /// Points per pattern (ignored with --input).
    #[arg(short = 'n', default_value_t = 1024)]
    pub n: usize,
    /// Dimension, 1 to 3 (ignored with --input).
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// Realizations to average (ignored with --input: every realization in the file is used).
    #[arg(long, short = 'm', default_value_t = 16)]
    pub realizations: usize,
    /// Largest frequency per axis K: the lattice is (2K+1)^d.
    #[arg(long, default_value_t = 64)]
    pub kmax: usize,
    /// Engine: direct, fast, or auto.
    #[arg(long, default_value = "auto")]
    pub method: String,
    /// Relative tolerance of the fast engine.
    #[arg(long, default_value_t = crate::spectrum::nufft::DEFAULT_TOLERANCE)]
    pub tolerance: f64,
    /// Ring width in |k| for --radial.
    #[arg(long, default_value_t = 1.0)]
    pub bin_width: f64,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output the radial spectrum instead of the lattice.
    #[arg(long)]
    pub radial: bool,
    /// Read point sets (UTK text or JSON) instead of sampling.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// JSON output.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// CSV output.
    #[arg(long)]
    pub csv: bool,
    /// Also write a plot (SVG; the lattice image may be .png).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Output file (standard output if absent).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
}

/// Parses an engine name.
///
/// # Errors
/// An unknown name.
pub fn parse_engine(name: &str, tolerance: f64) -> Result<crate::spectrum::Engine> {
    use crate::spectrum::Engine;
    match name {
        "direct" => Ok(Engine::Direct),
        "fast" => Ok(Engine::Fast { tolerance }),
        "auto" => Ok(Engine::Auto),
        other => Err(crate::error::invalid(
            "method",
            other,
            "direct, fast or auto",
        )),
    }
}

/// `specvar spectrum`.
///
/// # Errors
/// Bad arguments, an unreadable input file, or an unwritable output.
pub fn spectrum(args: &SpectrumArgs) -> Result<()> {
    use crate::spectrum::{estimate, estimate_from_sets, SpectrumParams};
    let params = SpectrumParams {
        kmax: args.kmax,
        realizations: args.realizations,
        seed: args.seed,
        engine: parse_engine(&args.method, args.tolerance)?,
        bin_width: args.bin_width,
    };
    let (est, label) = match &args.input {
        Some(path) => {
            let sets = io::read_file(path)?;
            (
                estimate_from_sets(&sets, &params)?,
                path.display().to_string(),
            )
        }
        None => {
            let sampler = build_sampler(&args.sampler, args.dimension, false)?;
            (
                estimate(sampler.as_ref(), args.n, &params)?,
                args.sampler.clone(),
            )
        }
    };
    if let Some(plot) = &args.plot {
        crate::report::plot_spectrum(plot, &label, &est, args.radial)?;
    }
    let text = if args.radial {
        format_radial(&est.radial, est.lattice.engine.name(), args.json, args.csv)?
    } else {
        format_lattice(&est.lattice, args.json)?
    };
    write_output(args.output.as_deref(), &text)
}

fn format_radial(
    radial: &crate::spectrum::RadialSpectrum,
    method: &str,
    json: bool,
    csv: bool,
) -> Result<String> {
    if json {
        let doc = serde_json::json!({
            "n": radial.n,
            "dimension": radial.dimension,
            "realizations": radial.realizations,
            "method": method,
            "bin_width": radial.bin_width,
            "dc_limit": radial.dc_limit,
            "bins": radial.bins,
        });
        return Ok(doc.to_string() + "\n");
    }
    let sep = if csv { "," } else { " " };
    let mut out = if csv {
        String::from("nu,rho,power,stderr,count,anisotropy_db\n")
    } else {
        format!(
            "# radial spectrum: N = {}, d = {}, {} realizations, {method}; P(0+) ≈ {:.4}\n# nu rho power stderr count anisotropy_db\n",
            radial.n, radial.dimension, radial.realizations, radial.dc_limit
        )
    };
    for b in &radial.bins {
        out.push_str(&format!(
            "{:.6}{sep}{:.4}{sep}{:.6}{sep}{:.3e}{sep}{}{sep}{:.3}\n",
            b.nu, b.rho, b.power, b.stderr, b.count, b.anisotropy_db
        ));
    }
    Ok(out)
}

fn format_lattice(spectrum: &crate::spectrum::LatticeSpectrum, json: bool) -> Result<String> {
    let lattice = spectrum.lattice;
    if json {
        let doc = serde_json::json!({
            "n": spectrum.n,
            "dimension": lattice.dimension,
            "realizations": spectrum.realizations,
            "method": spectrum.engine.name(),
            "kmax": lattice.kmax,
            "shape": vec![lattice.side(); lattice.dimension],
            "order": "row-major, first axis slowest; index i along an axis is frequency i - kmax; the centre is DC (value N)",
            "values": spectrum.mean,
            "stderr": spectrum.stderr,
        });
        return Ok(doc.to_string() + "\n");
    }
    let axes = ["k0", "k1", "k2"];
    let mut out = axes[..lattice.dimension].join(",") + ",power,stderr,dc\n";
    for i in 0..lattice.len() {
        let k = lattice.frequency(i);
        for c in &k[..lattice.dimension] {
            out.push_str(&format!("{c},"));
        }
        out.push_str(&format!(
            "{},{},{}\n",
            spectrum.mean[i],
            spectrum.stderr[i],
            spectrum.is_dc(i)
        ));
    }
    Ok(out)
}

/// The integration problem shared by `predict` and `mc`.
#[derive(Debug, Args)]
pub struct Problem {
    /// Sampler name.
    #[arg(long, short = 's')]
    pub sampler: String,
    /// Integrand: disk, ball or gaussian, with overrides (e.g. disk:r=0.2,a=2).
    #[arg(long, short = 'f', default_value = "disk")]
    pub integrand: String,
    /// Points per pattern.
    #[arg(short = 'n')]
    pub n: usize,
    /// Dimension (1 to 3).
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
}

impl Problem {
    /// The sampler (fixed; the callers homogenize) and the integrand.
    ///
    /// # Errors
    /// An unknown sampler, a bad integrand spec, or an unsupported dimension or N.
    pub fn build(&self) -> Result<(Box<dyn Sampler>, Box<dyn crate::integrand::Integrand>)> {
        let f = crate::integrand::parse_integrand(&self.integrand)?.build(self.dimension)?;
        let sampler = build_sampler(&self.sampler, self.dimension, false)?;
        sampler.check_count(self.n)?;
        Ok((sampler, f))
    }
}

/// Arguments of `specvar predict`.
#[derive(Debug, Args)]
pub struct PredictArgs {
    /// Sampler, integrand, N and dimension.
    #[command(flatten)]
    pub problem: Problem,
    /// Spectrum source: closed (random and jitter only) or estimated.
    #[arg(long, default_value = "estimated")]
    pub spectrum: String,
    /// N at which the spectrum is estimated (scale-invariant samplers serve every N from it).
    #[arg(long)]
    pub reference_n: Option<usize>,
    /// Realizations for the estimate.
    #[arg(long, short = 'm', default_value_t = 32)]
    pub realizations: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `specvar bias`.
#[derive(Debug, Args)]
pub struct BiasArgs {
    /// Sampler (fixed, not homogenized); `regular` uses its exact spectrum.
    #[arg(long, short = 's', default_value = "regular")]
    pub sampler: String,
    /// Integrand spec.
    #[arg(long, short = 'f', default_value = "gaussian")]
    pub integrand: String,
    /// Points.
    #[arg(short = 'n')]
    pub n: usize,
    /// Dimension (1 to 3).
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// Seed and realization of a randomized fixed pattern.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Largest frequency per axis for patterns without a closed-form spectrum.
    #[arg(long, default_value_t = 64)]
    pub kmax: usize,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// The default reference N for estimated spectra: 4096 in 1D and 2D, 32768 in 3D.
pub fn default_reference_n(d: usize) -> usize {
    if d == 3 {
        32768
    } else {
        4096
    }
}

/// The default lattice extent for an estimate at `n_ref`: `ν` up to 5.
pub fn default_kmax(n_ref: usize, d: usize) -> usize {
    (5.0 * (n_ref as f64).powf(1.0 / d as f64)).round() as usize
}

/// `specvar predict`.
///
/// An isotropic integrand gets the polar form (with the spectrum rescaled from a reference N
/// for scale-invariant samplers) and, when the spectrum is at N itself, the lattice form too. A
/// grid integrand is anisotropic: it gets the lattice form with the spectrum at N.
///
/// # Errors
/// Bad arguments.
pub fn predict(args: &PredictArgs) -> Result<()> {
    use crate::predict::{
        predict_lattice, predict_polar, LatticeSource, PolarParams, SpectrumSource,
    };
    use crate::spectrum::{estimate, ClosedForm, Engine, SpectrumParams};
    let (sampler, f) = args.problem.build()?;
    let is_grid = crate::integrand::parse_integrand(&args.problem.integrand)?.kind == "grid";
    let Problem {
        sampler: name,
        n,
        dimension,
        ..
    } = &args.problem;
    let (n, dimension) = (*n, *dimension);
    let closed = match name.as_str() {
        "random" => Some(ClosedForm::WhiteNoise),
        "jitter" => Some(ClosedForm::Jitter),
        _ => None,
    };
    let (main, lattice) = match args.spectrum.as_str() {
        "closed" => {
            let c = closed.ok_or_else(|| {
                crate::error::invalid(
                    "spectrum",
                    format!("closed for {}", name),
                    "closed forms exist for random and jitter; use --spectrum estimated",
                )
            })?;
            let kmax = (8.0 * (n as f64).powf(1.0 / dimension as f64)).ceil() as usize;
            let lattice = predict_lattice(f.as_ref(), LatticeSource::Closed(c), n, kmax.max(64))?;
            if is_grid {
                (lattice, None)
            } else {
                let source = SpectrumSource::Closed(c);
                let polar = predict_polar(f.as_ref(), source, n, &PolarParams::default())?;
                (polar, Some(lattice))
            }
        }
        "estimated" => {
            let default_ref = if is_grid {
                n
            } else {
                default_reference_n(dimension)
            };
            let n_ref = args.reference_n.unwrap_or(default_ref);
            if is_grid && n_ref != n {
                return Err(crate::error::invalid(
                    "reference N",
                    n_ref,
                    format!(
                        "N = {n} for a grid integrand (the lattice form needs the spectrum at N)"
                    ),
                ));
            }
            if n_ref != n && !sampler.is_scale_invariant_at(n) {
                let invariant: Vec<&str> = SamplerKind::ALL
                    .iter()
                    .filter(|k| k.build(2).is_ok_and(|s| s.is_scale_invariant()))
                    .map(|k| k.name())
                    .collect();
                return Err(crate::error::invalid(
                    "sampler",
                    name,
                    format!(
                        "a scale-invariant sampler for a spectrum rescaled from N = {n_ref} \
                         ({}; jitter at N = m^d), or --reference-n {n}",
                        invariant.join(", ")
                    ),
                ));
            }
            sampler.check_count(n_ref)?;
            let params = SpectrumParams {
                kmax: default_kmax(n_ref, dimension),
                realizations: args.realizations,
                seed: args.seed,
                engine: Engine::Auto,
                bin_width: 1.0,
            };
            let progress = crate::progress::spinner(format!(
                "estimating the {} spectrum at N = {n_ref}",
                name
            ));
            let est = estimate(sampler.as_ref(), n_ref, &params)?;
            progress.finish_and_clear();
            let lattice = if n_ref == n {
                let source = LatticeSource::Estimated(&est.lattice);
                Some(predict_lattice(f.as_ref(), source, n, params.kmax)?)
            } else {
                None
            };
            match lattice {
                Some(l) if is_grid => (l, None),
                _ => {
                    let source = SpectrumSource::Estimated(&est.radial);
                    let polar = predict_polar(f.as_ref(), source, n, &PolarParams::default())?;
                    (polar, lattice)
                }
            }
        }
        other => {
            return Err(crate::error::invalid(
                "spectrum",
                other,
                "closed or estimated",
            ))
        }
    };
    print_prediction(&args.problem, f.label(), &main, lattice.as_ref(), args.json);
    Ok(())
}

/// Prints `predict`'s result as text or JSON.
fn print_prediction(
    problem: &Problem,
    integrand: String,
    main: &crate::predict::Prediction,
    lattice: Option<&crate::predict::Prediction>,
    json: bool,
) {
    if json {
        let doc = serde_json::json!({
            "sampler": problem.sampler,
            "integrand": integrand,
            "n": problem.n,
            "dimension": problem.dimension,
            "form": main.form,
            "variance": main.variance,
            "variance_lattice": lattice.map(|l| l.variance),
            "dc_term": main.dc_term,
            "spectrum_source": main.spectrum_source,
            "quadrature_error": main.error_estimate,
            "spectrum_stderr": main.spectrum_stderr,
        });
        println!("{doc}");
        return;
    }
    println!(
        "sampler      {} (homogenized), N = {}, d = {}",
        problem.sampler, problem.n, problem.dimension
    );
    println!("integrand    {integrand}");
    println!("spectrum     {}", main.spectrum_source);
    let (form, error) = match main.form {
        crate::predict::Form::Polar => ("polar form; quadrature error", main.error_estimate),
        crate::predict::Form::Lattice => ("lattice form; truncation bound", main.error_estimate),
    };
    println!(
        "variance     {:.6e} ({form} {error:.1e}, spectrum noise ±{:.1e})",
        main.variance, main.spectrum_stderr
    );
    if main.form == crate::predict::Form::Polar {
        println!("DC term      {:.6e} (already subtracted)", main.dc_term);
    }
    if let Some(l) = lattice {
        println!("lattice form {:.6e}", l.variance);
    }
}

/// `specvar bias`.
///
/// # Errors
/// Bad arguments.
pub fn bias(args: &BiasArgs) -> Result<()> {
    let f = crate::integrand::parse_integrand(&args.integrand)?.build(args.dimension)?;
    // One fixed pattern serves both the spectral bias and the direct check.
    let points =
        build_sampler(&args.sampler, args.dimension, false)?.sample(args.n, args.seed, 0)?;
    let (bias, truncation, method) = if args.sampler == "regular" {
        let (b, t) = crate::predict::regular_grid_bias(f.as_ref(), args.n)?;
        (b, t, "exact regular-grid spectrum")
    } else {
        let b = crate::predict::bias_of_pattern(f.as_ref(), &points, args.kmax)?;
        (b, f64::NAN, "lattice sum over realization 0")
    };
    let mu = crate::montecarlo::estimate_integral(f.as_ref(), &points);
    let direct = mu - f.integral();
    if args.json {
        let doc = serde_json::json!({
            "sampler": args.sampler,
            "integrand": f.label(),
            "n": args.n,
            "dimension": args.dimension,
            "bias": bias,
            "bias_direct": direct,
            "method": method,
            "truncation": if truncation.is_nan() { None } else { Some(truncation) },
        });
        println!("{doc}");
    } else {
        println!(
            "bias of the fixed {} pattern, N = {}, on {}",
            args.sampler,
            args.n,
            f.label()
        );
        println!("from its spectrum ({method}): {bias:.9e}");
        println!("direct (μ_N - I):              {direct:.9e}");
    }
    Ok(())
}

/// Arguments of `specvar report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Output directory.
    #[arg(long, default_value = "report")]
    pub out: PathBuf,
    /// The short run (about a minute).
    #[arg(long)]
    pub quick: bool,
    /// Seed.
    #[arg(long, default_value_t = 2016)]
    pub seed: u64,
}

/// `specvar report`.
///
/// # Errors
/// As [`crate::report::run`].
pub fn report(args: &ReportArgs) -> Result<()> {
    let config = crate::report::ReportConfig {
        out: args.out.clone(),
        quick: args.quick,
        seed: args.seed,
    };
    let start = std::time::Instant::now();
    let report = crate::report::run(&config)?;
    let passed = report.checks.iter().filter(|c| c.pass).count();
    println!(
        "report written to {}/report.md in {:.0} s: {passed} of {} cross-checks passed",
        args.out.display(),
        start.elapsed().as_secs_f64(),
        report.checks.len()
    );
    println!(
        "{:<8} {:<9} {:>7} {:>10} {:>12}",
        "sampler", "integrand", "theory", "predicted", "Monte Carlo"
    );
    for row in &report.rates {
        let name = if row.integrand.starts_with("disk") {
            "disk"
        } else {
            "gaussian"
        };
        println!(
            "{:<8} {:<9} {:>7.2} {:>10.3} {:>12.3}",
            row.sampler, name, row.theory_rate, row.predicted_rate, row.empirical_rate.slope
        );
    }
    for c in report.checks.iter().filter(|c| !c.pass) {
        println!("FAIL {}: {}", c.what, c.detail);
    }
    Ok(())
}

/// Arguments of `specvar mc`.
#[derive(Debug, Args)]
pub struct McArgs {
    /// Sampler, integrand, N and dimension.
    #[command(flatten)]
    pub problem: Problem,
    /// Trials (independent patterns, or patterns × shifts with --shifts).
    #[arg(long, short = 't', default_value_t = 10000)]
    pub trials: usize,
    /// Random shifts per pattern: trials / shifts patterns are drawn (pools for slow samplers).
    #[arg(long, default_value_t = 1)]
    pub shifts: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Use the patterns as drawn, without the random toroidal shift.
    #[arg(long)]
    pub fixed: bool,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// `specvar mc`.
///
/// # Errors
/// Bad arguments.
pub fn mc(args: &McArgs) -> Result<()> {
    use crate::montecarlo::{empirical_variance_with, McParams};
    let (sampler, f) = args.problem.build()?;
    let Problem {
        sampler: name, n, ..
    } = &args.problem;
    let n = *n;
    if args.shifts == 0 || args.trials < 2 * args.shifts {
        return Err(crate::error::invalid(
            "trials",
            args.trials,
            "at least twice --shifts (two patterns)",
        ));
    }
    let params = McParams {
        patterns: args.trials / args.shifts,
        shifts: args.shifts,
        seed: args.seed,
        homogenize: !args.fixed,
    };
    let bar = crate::progress::bar(params.patterns as u64, format!("monte carlo: {}", name));
    let r = empirical_variance_with(sampler.as_ref(), f.as_ref(), n, &params, &|| bar.inc(1))?;
    bar.finish_and_clear();
    if args.json {
        let doc = serde_json::json!({
            "sampler": name,
            "integrand": f.label(),
            "n": n,
            "trials": r.trials,
            "patterns": r.patterns,
            "shifts": r.shifts,
            "homogenized": r.homogenized,
            "variance": r.variance,
            "ci_low": r.ci_low,
            "ci_high": r.ci_high,
            "interval": r.interval,
            "bias": r.bias,
            "bias_stderr": r.bias_stderr,
        });
        println!("{doc}");
    } else {
        println!(
            "{} ({}), N = {}, {} on {}",
            name,
            if r.homogenized {
                "homogenized"
            } else {
                "fixed"
            },
            n,
            if r.shifts > 1 {
                format!("{} patterns × {} shifts", r.patterns, r.shifts)
            } else {
                format!("{} trials", r.trials)
            },
            f.label()
        );
        println!(
            "variance {:.6e}, 99% interval [{:.6e}, {:.6e}] ({:?})",
            r.variance, r.ci_low, r.ci_high, r.interval
        );
        println!("bias     {:.3e} ± {:.1e}", r.bias, r.bias_stderr);
    }
    Ok(())
}

/// Arguments of `specvar rates`.
#[derive(Debug, Args)]
pub struct RatesArgs {
    /// Dimension (1 to 3).
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// Comma-separated samplers (scale-invariant ones: random, jitter, poisson, bridson, ccvt).
    #[arg(long, default_value = "random,jitter,poisson,ccvt")]
    pub samplers: String,
    /// Comma-separated integrand specs.
    #[arg(long, default_value = "disk,gaussian")]
    pub integrands: String,
    /// Smallest and largest N of the fit (N = m^d values in between, log-spaced).
    #[arg(long, num_args = 2, default_values_t = [16, 1024])]
    pub range: Vec<usize>,
    /// Monte Carlo trials per N (pools of 32 shifts for poisson, bridson and ccvt).
    #[arg(long, default_value_t = 4000)]
    pub trials: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// N values `m^d` between `lo` and `hi`, about five, log-spaced.
pub fn rate_ns(lo: usize, hi: usize, d: usize) -> Vec<usize> {
    let (a, b) = ((lo as f64).ln(), (hi as f64).ln());
    let mut ns: Vec<usize> = (0..5)
        .map(|i| {
            let target = (a + (b - a) * i as f64 / 4.0).exp();
            let m = target.powf(1.0 / d as f64).round().max(1.0) as usize;
            m.pow(d as u32)
        })
        .collect();
    ns.dedup();
    ns
}

/// `specvar rates`.
///
/// # Errors
/// Bad arguments.
pub fn rates(args: &RatesArgs) -> Result<()> {
    use crate::montecarlo::{empirical_variance_with, McParams, Z_99};
    use crate::predict::{predict_polar, PolarParams, SpectrumSource};
    use crate::rate::{fit_alpha, loglog_slope, theory_rate};
    use crate::spectrum::{estimate, Engine, SpectrumParams};
    let d = args.dimension;
    let (lo, hi) = (args.range[0], args.range[1]);
    if lo < 1 || hi <= lo {
        return Err(crate::error::invalid(
            "range",
            format!("{lo} {hi}"),
            "two N with 1 ≤ low < high",
        ));
    }
    let ns = rate_ns(lo, hi, d);
    let xs: Vec<f64> = ns.iter().map(|&n| n as f64).collect();
    let mut rows = Vec::new();
    for name in args.samplers.split(',').map(str::trim) {
        let sampler = build_sampler(name, d, false)?;
        let n_ref = default_reference_n(d);
        let params = SpectrumParams {
            kmax: default_kmax(n_ref, d),
            realizations: if name == "ccvt" { 8 } else { 64 },
            seed: args.seed,
            engine: Engine::Auto,
            bin_width: 1.0,
        };
        let spinner = crate::progress::spinner(format!("spectrum of {name} at N = {n_ref}"));
        let est = estimate(sampler.as_ref(), n_ref, &params)?;
        spinner.finish_and_clear();
        let alpha = fit_alpha(&est.radial, 0.0, 0.3)?;
        let known = match name {
            "random" | "poisson" | "bridson" => Some(0.0),
            "jitter" => Some(2.0),
            _ => None,
        };
        for spec in args.integrands.split(',').map(str::trim) {
            let f = crate::integrand::parse_integrand(spec)?.build(d)?;
            let a = known.unwrap_or(alpha.slope);
            let (theory, _) = theory_rate(a, f.decay_exponent(), d);
            let predicted: Vec<f64> = ns
                .iter()
                .map(|&n| {
                    predict_polar(
                        f.as_ref(),
                        SpectrumSource::Estimated(&est.radial),
                        n,
                        &PolarParams::default(),
                    )
                    .map(|p| p.variance)
                })
                .collect::<Result<_>>()?;
            let shifts = if matches!(name, "poisson" | "bridson" | "ccvt") {
                32
            } else {
                1
            };
            let mut mc = Vec::new();
            let mut rel = Vec::new();
            let bar = crate::progress::bar(ns.len() as u64, format!("monte carlo: {name}, {spec}"));
            for &n in &ns {
                let params = McParams {
                    patterns: (args.trials / shifts).max(2),
                    shifts,
                    seed: args.seed,
                    homogenize: true,
                };
                let r = empirical_variance_with(sampler.as_ref(), f.as_ref(), n, &params, &|| {})?;
                rel.push((r.ci_high / r.ci_low).ln() / (2.0 * Z_99));
                mc.push(r.variance);
                bar.inc(1);
            }
            bar.finish_and_clear();
            let empirical = loglog_slope(&xs, &mc, Some(&rel))?;
            rows.push(serde_json::json!({
                "sampler": name,
                "integrand": f.label(),
                "dimension": d,
                "theory_rate": theory,
                "predicted_rate": loglog_slope(&xs, &predicted, None)?.slope,
                "empirical_rate": empirical.slope,
                "empirical_rate_ci": [empirical.ci.0, empirical.ci.1],
                "alpha": a,
                "alpha_fitted": alpha.slope,
                "n_values": ns,
            }));
        }
    }
    if args.json {
        println!("{}", serde_json::json!({ "rows": rows }));
    } else {
        println!("rates r in Var ∝ N^r over N = {ns:?}, d = {d}");
        println!(
            "{:<8} {:<40} {:>7} {:>9} {:>10} {:>19} {:>6}",
            "sampler", "integrand", "theory", "predicted", "empirical", "99% interval", "alpha"
        );
        for r in &rows {
            println!(
                "{:<8} {:<40} {:>7.3} {:>9.3} {:>10.3}   [{:>6.3}, {:>6.3}] {:>6.2}",
                r["sampler"].as_str().unwrap_or(""),
                r["integrand"].as_str().unwrap_or(""),
                r["theory_rate"].as_f64().unwrap_or(f64::NAN),
                r["predicted_rate"].as_f64().unwrap_or(f64::NAN),
                r["empirical_rate"].as_f64().unwrap_or(f64::NAN),
                r["empirical_rate_ci"][0].as_f64().unwrap_or(f64::NAN),
                r["empirical_rate_ci"][1].as_f64().unwrap_or(f64::NAN),
                r["alpha"].as_f64().unwrap_or(f64::NAN),
            );
        }
    }
    Ok(())
}

/// Arguments of `specvar render-ao`.
#[derive(Debug, Args)]
pub struct RenderAoArgs {
    /// Sampler name, or `all` for the comparison run over every 2D sampler.
    #[arg(long, short = 's', default_value = "all")]
    pub sampler: String,
    /// Secondary rays (points) per pixel.
    #[arg(long, default_value_t = 96)]
    pub rays: usize,
    /// Image width in pixels.
    #[arg(long, default_value_t = 128)]
    pub width: usize,
    /// Image height in pixels.
    #[arg(long, default_value_t = 128)]
    pub height: usize,
    /// Independent uniform rays per pixel of the reference (cached in the output directory).
    #[arg(long, default_value_t = 16384)]
    pub reference_rays: usize,
    /// Output directory: images, reference cache, table.
    #[arg(long, default_value = "render")]
    pub out: PathBuf,
    /// Maximum occlusion distance (the room's side is 1).
    #[arg(long, default_value_t = 0.5)]
    pub max_distance: f64,
    /// Distinct patterns per image, each shared by pixels under their own shifts.
    #[arg(long, default_value_t = 1024)]
    pub patterns: usize,
    /// Cells per side of each pixel's visibility grid for the prediction.
    #[arg(long, default_value_t = 64)]
    pub grid: usize,
    /// Largest frequency per axis of the prediction's lattice.
    #[arg(long, default_value_t = 64)]
    pub kmax: usize,
    /// Use every STRIDE-th pixel per axis for the prediction.
    #[arg(long, default_value_t = 1)]
    pub stride: usize,
    /// Realizations of the sampler's spectrum at N for the prediction.
    #[arg(long, default_value_t = 512)]
    pub spectrum_realizations: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// `specvar render-ao`.
///
/// # Errors
/// Bad arguments or unwritable output.
pub fn render_ao(args: &RenderAoArgs) -> Result<()> {
    use crate::render::{
        all_2d_samplers, measured_ratio, run_comparison, write_comparison, ComparisonConfig,
        PixelPowerParams, RenderParams,
    };
    let samplers = if args.sampler == "all" {
        all_2d_samplers()
    } else {
        SamplerKind::from_name(&args.sampler)?.build(2)?;
        vec![args.sampler.clone()]
    };
    let config = ComparisonConfig {
        width: args.width,
        height: args.height,
        samplers,
        render: RenderParams {
            rays: args.rays,
            max_distance: args.max_distance,
            seed: args.seed,
            patterns: args.patterns,
        },
        reference_rays: args.reference_rays,
        pixel_power: PixelPowerParams {
            resolution: args.grid,
            kmax: args.kmax,
            stride: args.stride,
        },
        spectrum_realizations: args.spectrum_realizations,
        cache_dir: args.out.clone(),
    };
    let run = run_comparison(&config)?;
    write_comparison(&args.out, &run.rows, &run.reference)?;
    if args.json {
        let rows: Vec<serde_json::Value> = run
            .rows
            .iter()
            .map(|r| {
                serde_json::json!({
                    "sampler": r.sampler,
                    "rays": r.rays,
                    "mse": r.measured.mse,
                    "mse_stderr": r.measured.stderr,
                    "predicted_mse": r.predicted.variance,
                    "predicted_stderr": r.predicted.spectrum_stderr,
                })
            })
            .collect();
        match rows.as_slice() {
            [one] => println!("{one}"),
            _ => println!("{}", serde_json::Value::Array(rows)),
        }
        return Ok(());
    }
    println!(
        "{} × {} pixels, {} rays per pixel; reference: {} rays per pixel{}",
        args.width,
        args.height,
        args.rays,
        args.reference_rays,
        if run.reference_cached {
            " (cached)"
        } else {
            ""
        }
    );
    println!("prediction: {}", run.power_label);
    print!("{}", crate::render::comparison_table(&run.rows));
    if let Some(r) = measured_ratio(&run.rows, "random", "jitter") {
        println!("random / jitter MSE: {r:.2} (talk: 5.54)");
    }
    println!("images and table in {}", args.out.display());
    Ok(())
}

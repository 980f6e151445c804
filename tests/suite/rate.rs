//! Rates: theory, fits, α, crossovers, and a measured slope against the predicted one.

use specvar::integrand::*;
use specvar::montecarlo::*;
use specvar::predict::*;
use specvar::rate::*;
use specvar::sampler::*;
use specvar::spectrum::*;

#[test]
fn theory_reproduces_the_talks_table() {
    let disk = 3.0;
    let gauss = f64::INFINITY;
    assert_eq!(theory_rate(0.0, disk, 2).0, -1.0);
    assert_eq!(theory_rate(0.0, gauss, 2).0, -1.0);
    assert_eq!(theory_rate(2.0, disk, 2).0, -1.5);
    assert_eq!(theory_rate(2.0, gauss, 2).0, -2.0);
    assert_eq!(theory_rate(4.0, gauss, 2).0, -3.0);
    // Jitter in d dimensions: N^{-1-1/d} on a ball, N^{-1-2/d} on a Gaussian.
    for d in 1..=3 {
        assert!((theory_rate(2.0, d as f64 + 1.0, d).0 - (-1.0 - 1.0 / d as f64)).abs() < 1e-15);
        assert!((theory_rate(2.0, gauss, d).0 - (-1.0 - 2.0 / d as f64)).abs() < 1e-15);
    }
}

#[test]
fn weighted_line_recovers_slopes_and_their_errors() {
    let x: Vec<f64> = (0..8).map(|i| i as f64).collect();
    let y: Vec<f64> = x.iter().map(|x| 3.0 - 1.5 * x).collect();
    let fit = weighted_line(&x, &y, Some(&[0.04; 8])).unwrap();
    assert!((fit.slope + 1.5).abs() < 1e-12 && (fit.intercept - 3.0).abs() < 1e-12);
    // se = σ / √Σ(x - x̄)² with σ = 0.2 and Σ(x - x̄)² = 42.
    assert!((fit.stderr - 0.2 / 42f64.sqrt()).abs() < 1e-15);
    assert!(weighted_line(&[1.0], &[1.0], None).is_err());
    assert!(weighted_line(&[1.0, 1.0], &[1.0, 2.0], None).is_err());
}

#[test]
fn crossover_of_two_power_laws() {
    let ns: Vec<f64> = (0..9).map(|i| 4f64.powi(i)).collect();
    let a: Vec<f64> = ns.iter().map(|n| 1.0 / n).collect();
    let b: Vec<f64> = ns.iter().map(|n| 10.0 / n.powf(1.5)).collect();
    let c = crossover(&ns, &a, &b).unwrap();
    assert!((c - 100.0).abs() < 1e-9, "{c}");
    assert!(crossover(&ns, &a, &a.iter().map(|v| v * 2.0).collect::<Vec<_>>()).is_none());
}

/// A radial spectrum whose rings hold the exact ring means of jitter's closed form at N (no
/// noise), each given a relative standard error `rel`.
fn exact_jitter_rings(n: usize, kmax: usize, rel: f64) -> RadialSpectrum {
    let lattice = Lattice { dimension: 2, kmax };
    let closed = ClosedForm::Jitter.on_lattice(n, 2, kmax);
    let mut rings: Vec<(f64, f64, usize)> = vec![(0.0, 0.0, 0); kmax];
    for i in 0..lattice.len() {
        let r = lattice.radius(i);
        if i == lattice.dc_index() || r >= kmax as f64 {
            continue;
        }
        let ring = &mut rings[r.floor() as usize];
        ring.0 += r;
        ring.1 += closed.power(&lattice.frequency(i)[..2]);
        ring.2 += 1;
    }
    let scale = (n as f64).sqrt();
    let bins = rings
        .iter()
        .filter(|r| r.2 > 0)
        .map(|&(rs, ps, c)| {
            let power = ps / c as f64;
            RadialBin {
                nu: rs / c as f64 / scale,
                rho: rs / c as f64,
                power,
                stderr: rel * power,
                count: c,
                anisotropy_db: f64::NAN,
            }
        })
        .collect();
    RadialSpectrum {
        dimension: 2,
        n,
        realizations: 64,
        bin_width: 1.0,
        bins,
        dc_limit: 0.0,
    }
}

/// On exact ring means the fit's systematic error must be far below the noise a real estimate
/// has: with 1% ring errors the standard error of α is about 0.01, and the bias must be under a
/// tenth of it. A plain log-log line is off by about -0.07 here.
#[test]
fn alpha_fit_has_no_bias_on_exact_jitter_rings() {
    let rings = exact_jitter_rings(4096, 24, 0.01);
    let fit = fit_alpha(&rings, 0.0, 0.3).unwrap();
    assert!((fit.alpha - 2.0).abs() < 0.1 * fit.stderr, "{fit:?}");
    // The amplitude is π²/3 (1 - Π sinc² ≈ π²|ν|²/3).
    let c = std::f64::consts::PI.powi(2) / 3.0;
    assert!((fit.amplitude / c - 1.0).abs() < 0.01, "{fit:?}");
}

/// Over 16 independent estimates of jitter and of white noise (N = 4096, 64 realizations),
/// every 99% interval of α is expected to hold the truth (16 intervals at 1% miss at most one
/// by chance, P(≥ 2 misses) ≈ 1.1%), and the mean of the 16 fits must lie within 3 of its own
/// standard errors (stderr/√16) of the truth: a bias of the old fit's size (−0.07 at a stderr
/// of 0.011) is 25 such errors. The spectra come from the default engine, as a user's do (its
/// error is held to a small fraction of the spectrum's own noise).
#[test]
fn alpha_fit_is_unbiased_and_covers_on_closed_forms() {
    for (sampler, truth) in [
        (Box::new(Jitter::new(2).unwrap()) as Box<dyn Sampler>, 2.0),
        (Box::new(Random::new(2).unwrap()), 0.0),
    ] {
        let fits: Vec<AlphaFit> = (0..16)
            .map(|seed| {
                let params = SpectrumParams {
                    kmax: 24,
                    realizations: 64,
                    seed,
                    engine: Engine::Auto,
                    bin_width: 1.0,
                    budget: Default::default(),
                };
                let est = estimate(sampler.as_ref(), 4096, &params).unwrap();
                fit_alpha(&est.radial, 0.0, 0.3).unwrap()
            })
            .collect();
        let misses = fits
            .iter()
            .filter(|f| !(f.ci.0 <= truth && truth <= f.ci.1))
            .count();
        assert!(
            misses <= 1,
            "{}: {misses} of 16 intervals miss α = {truth}",
            sampler.name()
        );
        let mean = fits.iter().map(|f| f.alpha).sum::<f64>() / 16.0;
        let se = fits.iter().map(|f| f.stderr).sum::<f64>() / 16.0 / 4.0;
        assert!(
            (mean - truth).abs() < 3.0 * se,
            "{}: mean α {mean} ± {se}",
            sampler.name()
        );
    }
}

#[test]
fn measured_jitter_slope_agrees_with_the_predicted_slope() {
    // Over N = 16…1024 the exact (lattice-form) slope is not yet the asymptotic -1.5; the
    // Monte Carlo slope's 99% interval must contain the exact one.
    let f = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let ns = [16usize, 64, 256, 1024];
    let params = McParams {
        patterns: 4000,
        seed: 12,
        ..Default::default()
    };
    let mut mc = Vec::new();
    let mut rel = Vec::new();
    let mut exact = Vec::new();
    for &n in &ns {
        let r = empirical_variance(&Jitter::new(2).unwrap(), &f, n, &params).unwrap();
        rel.push((r.ci_high / r.ci_low).ln() / (2.0 * Z_99));
        mc.push(r.variance);
        exact.push(
            predict_lattice(&f, &SpectrumSource::Closed(ClosedForm::Jitter), n, 400)
                .unwrap()
                .variance,
        );
    }
    let x: Vec<f64> = ns.iter().map(|&n| n as f64).collect();
    let measured = loglog_slope(&x, &mc, Some(&rel)).unwrap();
    let predicted = loglog_slope(&x, &exact, None).unwrap().slope;
    assert!(
        measured.ci.0 <= predicted && predicted <= measured.ci.1,
        "{measured:?} vs {predicted}"
    );
    assert!((predicted + 1.5).abs() < 0.05);
}

/// `specvar rates` and the report both run `run_study`: for the same settings the command
/// line's rows, the library's and the report's are the same numbers.
#[test]
fn rates_command_library_and_report_give_identical_rows() {
    use specvar::progress::Silent;
    use specvar::report::{compute, ReportConfig};
    // The command runs while the library computes the same study.
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_specvar"))
        .args([
            "rates",
            "--samplers",
            "random,jitter",
            "--integrands",
            "disk:r=0.2",
            "--range",
            "16",
            "256",
            "--trials",
            "300",
            "--seed",
            "5",
            "--json",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let config = StudyConfig {
        samplers: vec![SamplerKind::Random, SamplerKind::Jitter],
        integrands: vec!["disk:r=0.2".parse().unwrap()],
        ns: rate_ns(16, 256, 2),
        trials: 300,
        seed: 5,
        ..StudyConfig::in_dimension(2)
    };
    let library = serde_json::to_value(&run_study(&config, &Silent).unwrap().rows).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cli: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(cli["rows"], library);
    let mut report = ReportConfig::quick(5);
    report.study = config;
    report.closure.samplers = vec![SamplerKind::Random];
    report.closure.ns = vec![16];
    report.ambient.width = 4;
    report.ambient.height = 4;
    report.ambient.samplers = vec![SamplerKind::Random];
    // The other sections at their smallest: this test compares the study's rows.
    report.edges.samplers = vec![SamplerKind::Jitter];
    report.edges.angles = vec![0.0];
    report.edges.rate_ns = vec![16, 64];
    report.estimators.samplers = vec![SamplerKind::Jitter];
    report.estimators.ns = vec![16];
    report.coverage.cases.truncate(1);
    report.coverage.integrands.truncate(1);
    report.coverage.ns = vec![16];
    report.ambient.cache_dir = Some(std::env::temp_dir().join("specvar-test-rates-report"));
    let computed = compute(&report, &Silent).unwrap();
    assert_eq!(serde_json::to_value(&computed.study.rows).unwrap(), library);
}

/// A study split into Monte Carlo blocks of any size, run in any order and finished, is the
/// one-call study bit for bit; blocks that miss or repeat patterns are refused.
#[test]
fn a_study_split_into_blocks_is_the_one_call_study() {
    use specvar::progress::Silent;
    let config = StudyConfig {
        samplers: vec![SamplerKind::Random, SamplerKind::Jitter],
        integrands: vec!["gaussian".parse().unwrap(), "disk:r=0.2".parse().unwrap()],
        ns: vec![16, 64],
        trials: 200,
        seed: 11,
        reference: ReferenceSpectrum {
            n: 256,
            kmax: 32,
            realizations: 8,
            costly_realizations: 2,
        },
        ..StudyConfig::in_dimension(2)
    };
    let whole = serde_json::to_string(&run_study(&config, &Silent).unwrap()).unwrap();
    for size in [7, 64, 1000] {
        let blocks = config.mc_blocks(size);
        let mut done: Vec<_> = blocks
            .iter()
            .rev()
            .map(|b| (*b, config.run_mc_block(b, &Silent).unwrap()))
            .collect();
        let split = finish_study(&config, &done, &Silent).unwrap();
        assert_eq!(
            serde_json::to_string(&split).unwrap(),
            whole,
            "blocks of {size}"
        );
        let repeated = done[0].clone();
        done.push(repeated);
        assert!(matches!(
            finish_study(&config, &done, &Silent),
            Err(specvar::Error::Mismatch(_))
        ));
        done.truncate(done.len() - 2);
        assert!(finish_study(&config, &done, &Silent).is_err());
    }
}

/// A study of the estimators as used: each sampler's predictions and Monte Carlo are for its
/// native randomization (jitter as drawn, by the cell form; the unscrambled net under a digital
/// shift, by the Walsh form), and the measured slope lies in the interval of the predicted one
/// widened by the measurement's.
#[test]
fn a_study_as_used_predicts_and_measures_each_sampler_under_its_own_randomization() {
    use specvar::progress::Silent;
    use specvar::randomization::{Randomization, RandomizationChoice};
    let config = StudyConfig {
        samplers: vec![SamplerKind::Jitter, SamplerKind::SobolNet],
        integrands: vec!["disk:r=0.3".parse().unwrap()],
        ns: vec![16, 64, 256],
        trials: 2000,
        seed: 5,
        randomization: RandomizationChoice::Native,
        ..StudyConfig::in_dimension(2)
    };
    let study = run_study(&config, &Silent).unwrap();
    for series in &study.series {
        let native = series.sampler.native_randomization();
        assert!(native != Randomization::Shift);
        assert!(series.predicted.iter().all(|p| p.randomization == native));
        assert!(series.measured.iter().all(|m| m.randomization == native));
        assert!(series
            .predicted
            .iter()
            .all(|p| p.route.form != Form::Lattice));
    }
    for row in &study.rows {
        let (p, e) = (&row.predicted_rate, &row.empirical_rate);
        let half = (e.ci.1 - e.ci.0) / 2.0 + (p.ci.1 - p.ci.0) / 2.0;
        assert!(
            (p.slope - e.slope).abs() <= half,
            "{}: predicted {:.3}, measured {:.3} ± {:.3}",
            row.sampler,
            p.slope,
            e.slope,
            half
        );
    }
}

/// A fixed rule has no low-frequency power law: its row gives no theoretical rate (a rank-1
/// lattice's spectrum is peaks on its dual lattice, whose fitted "α" means nothing), while its
/// predicted and measured rates stand.
#[test]
fn a_fixed_rule_has_no_theoretical_rate() {
    use specvar::progress::Silent;
    let config = lattice_and_jitter(vec![16, 64, 256], 2);
    let study = run_study(&config, &Silent).unwrap();
    let (korobov, jitter) = (&study.rows[0], &study.rows[1]);
    assert_eq!(korobov.alpha_source, AlphaSource::NoPowerLaw);
    assert_eq!(korobov.theory_rate, None);
    assert!(korobov.predicted_rate.slope < -2.0);
    assert_eq!(jitter.theory_rate, Some(-2.0));
    assert_eq!(theory_text(korobov.theory_rate, 2), "no power law");
}

/// A rate study stops where the variance reaches the floor of double precision: Korobov's
/// lattice on the Gaussian falls by about N^-12, and its exact pair sum cancels to its rounding
/// bound by N = 361, so its fits use only the N below; jitter's exact values bend over the range
/// (not yet the asymptotic N^-2), and its predicted slope carries that bend as an interval.
#[test]
fn a_study_stops_at_the_floor_of_the_arithmetic_and_exact_slopes_carry_their_bend() {
    use specvar::progress::Silent;
    use specvar::rate::FLOOR_FRACTION;
    let config = lattice_and_jitter(vec![16, 49, 121, 361, 1024], 3);
    let study = run_study(&config, &Silent).unwrap();
    let (korobov, jitter) = (&study.rows[0], &study.rows[1]);
    let floor = korobov.floor_n.expect("the lattice reaches the floor");
    let at = config.ns.iter().position(|&n| n == floor).unwrap();
    let series = &study.series[0];
    let p = &series.predicted[at];
    assert!(p.budget.quadrature >= FLOOR_FRACTION * p.variance, "{p:?}");
    assert!(series.predicted[..at]
        .iter()
        .all(|p| p.budget.quadrature < FLOOR_FRACTION * p.variance));
    assert_eq!(korobov.predicted_rate.points, at);
    assert_eq!(korobov.empirical_rate.points, at);
    assert_eq!(jitter.floor_n, None);
    assert_eq!(jitter.predicted_rate.points, config.ns.len());
    // Exact values (closed form), yet an interval: their bend off a straight line.
    assert!(
        jitter.predicted_rate.stderr > 1e-3,
        "{:?}",
        jitter.predicted_rate
    );
    let (lo, hi) = jitter.predicted_rate.ci;
    let measured = jitter.empirical_rate.slope;
    assert!(lo < measured && measured < hi, "{lo} {measured} {hi}");
    // An N range that starts at the floor is refused with the N where it lies.
    let late = StudyConfig {
        samplers: vec![SamplerKind::Korobov],
        ns: vec![361, 1024],
        ..config
    };
    let refused = run_study(&late, &Silent).unwrap_err().to_string();
    assert!(refused.contains("floor of double precision"), "{refused}");
}

/// A short study of Korobov's lattice and jitter on the Gaussian at `ns`.
fn lattice_and_jitter(ns: Vec<usize>, seed: u64) -> StudyConfig {
    StudyConfig {
        samplers: vec![SamplerKind::Korobov, SamplerKind::Jitter],
        integrands: vec!["gaussian".parse().unwrap()],
        ns,
        trials: 400,
        seed,
        reference: ReferenceSpectrum {
            n: 256,
            kmax: 32,
            realizations: 8,
            costly_realizations: 2,
        },
        ..StudyConfig::in_dimension(2)
    }
}

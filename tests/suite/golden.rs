//! The route table frozen: for every sampler, every randomization and one integrand of each
//! kind, at a small and a larger N, the form and spectrum that answer (or the refusal) and the
//! variance to its stated digits, compared with `tests/golden/routes.tsv`.
//!
//! The file records what the library answers; a change to route choice shows here as a
//! changed line. After a deliberate change, write the file anew with
//! `SPECVAR_BLESS=1 cargo test --release golden -- --ignored` and read its diff.

use specvar::integrand::*;
use specvar::pointset::PointSet;
use specvar::predict::*;
use specvar::randomization::Randomization;
use specvar::sampler::*;
use std::fmt::Write as _;

/// The golden file, relative to the crate.
const GOLDEN: &str = "tests/golden/routes.tsv";

/// Significant digits of a variance the file keeps: estimates are the same bits on any
/// thread count, but a sum's last place may move with the order a refactoring gives its
/// terms; ten digits are far below any budget and far above rounding.
const DIGITS: usize = 10;

/// The parameters of every case: the defaults, with a coarser noise target so that estimated
/// routes draw their initial patterns alone (the golden file is about which route answers and
/// what it computes, not about how long an estimate runs).
fn params() -> PredictParams {
    PredictParams {
        target_noise: 0.5,
        ..PredictParams::default()
    }
}

/// One integrand of each kind in 2D, the Gaussian and polygon crossing a face.
fn integrands_2d() -> Vec<(&'static str, Box<dyn Integrand>)> {
    // A 4 × 4 grid of distinct values, so that no cell sum is trivial.
    let grid: Vec<f64> = (0..16).map(|i| ((i * 7) % 16) as f64 / 15.0).collect();
    vec![
        (
            "disk",
            Box::new(Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap()),
        ),
        (
            "gaussian-cut",
            Box::new(Gaussian::new(0.15, vec![0.2, 0.6], 1.0).unwrap()),
        ),
        (
            "triangle",
            Box::new(Polygon::new(vec![[0.12, 0.18], [0.83, 0.31], [0.41, 0.88]], 1.0).unwrap()),
        ),
        ("edge", Box::new(Polygon::edge(30.0, 0.4, 1.0).unwrap())),
        (
            "grid4",
            Box::new(
                GridIntegrand::new(4, 4, grid)
                    .unwrap()
                    .with_meaning(specvar::integrand::GridMeaning::Exact),
            ),
        ),
        (
            "agaussian",
            Box::new(AnisotropicGaussian::new(0.05, 0.15, 30.0, [0.5, 0.5], 1.0).unwrap()),
        ),
    ]
}

fn integrands_in(d: usize) -> Vec<(&'static str, Box<dyn Integrand>)> {
    match d {
        2 => integrands_2d(),
        _ => vec![
            (
                "ball",
                Box::new(Ball::new(0.25, vec![0.5; d], 1.0).unwrap()) as Box<dyn Integrand>,
            ),
            (
                "gaussian-cut",
                Box::new(Gaussian::new(0.15, vec![0.2; d], 1.0).unwrap()),
            ),
        ],
    }
}

/// The counts of a case: each sampler's nearest to 16 and to 256 (to 64 in 3D).
fn counts(kind: SamplerKind, d: usize) -> Vec<usize> {
    let targets: &[usize] = if d == 3 { &[16, 64] } else { &[16, 256] };
    let mut ns = kind.nearest_counts(targets, d);
    ns.dedup();
    ns
}

/// A variance to [`DIGITS`] significant digits.
fn digits(v: f64) -> String {
    format!("{v:.*e}", DIGITS - 1)
}

/// The line of one case: the answer's form, spectrum origin and variance, or the error.
fn outcome(problem: &Problem<'_>) -> String {
    outcome_with(problem, &params())
}

/// [`outcome`] with other parameters.
fn outcome_with(problem: &Problem<'_>, params: &PredictParams) -> String {
    match predict(problem, params) {
        Ok(p) => format!(
            "{}\t{}\t{}",
            p.route.form,
            origin_kind(&p.route.spectrum),
            digits(p.variance)
        ),
        Err(e) => format!("error\t{}", error_kind(&e)),
    }
}

/// The variant of a spectrum origin (its parameters are in the digits).
fn origin_kind(o: &SpectrumOrigin) -> String {
    let json = serde_json::to_value(o).unwrap();
    match json {
        serde_json::Value::String(s) => s,
        serde_json::Value::Object(map) => {
            let (key, value) = map.into_iter().next().unwrap();
            // A closed form and a cell origin say which: their variant is part of the route.
            match value {
                serde_json::Value::String(s) => format!("{key}:{s}"),
                serde_json::Value::Object(inner) if key == "closed" => {
                    format!("{key}:{}", inner.keys().next().cloned().unwrap_or_default())
                }
                serde_json::Value::Object(inner) if key == "cells" => {
                    let occupancy = match &inner["occupancy"] {
                        serde_json::Value::String(s) => s.clone(),
                        serde_json::Value::Object(o) => {
                            o.keys().next().cloned().unwrap_or_default()
                        }
                        other => other.to_string(),
                    };
                    format!("{key}:{occupancy}")
                }
                _ => key,
            }
        }
        other => other.to_string(),
    }
}

/// An error's variant, and its message up to the first colon or 80 characters (the message's
/// details may be reworded; its kind and subject may not change silently).
fn error_kind(e: &specvar::Error) -> String {
    let debug = format!("{e:?}");
    let variant: String = debug.chars().take_while(|c| c.is_alphanumeric()).collect();
    let message: String = e.to_string().chars().take(80).collect();
    format!("{variant}\t{}", message.replace(['\t', '\n'], " "))
}

/// Every case's line, in a fixed order.
fn table() -> String {
    let mut out = String::from("# dimension\tsampler\trandomization\tintegrand\tN\toutcome\n");
    for d in 1..=3 {
        let integrands = integrands_in(d);
        for kind in SamplerKind::ALL {
            if !kind.dimensions().contains(&d) {
                continue;
            }
            let sampler = kind.build(d).unwrap();
            for n in counts(kind, d) {
                for r in Randomization::ALL {
                    for (name, f) in &integrands {
                        let problem = Problem::new(sampler.as_ref(), f.as_ref(), n)
                            .unwrap()
                            .with_randomization(r);
                        let line = outcome(&problem);
                        writeln!(out, "{d}\t{kind}\t{r}\t{name}\t{n}\t{line}").unwrap();
                    }
                }
            }
        }
    }
    choices(&mut out);
    point_sets(&mut out);
    out
}

/// The choices a user may force (form, spectrum, lattice extent), on a sampler of each kind of
/// law, the disk and the cut Gaussian, at N = 64, under the shift and natively.
fn choices(out: &mut String) {
    let forced = [
        (
            "form=lattice",
            PredictParams {
                form: FormChoice::Lattice,
                ..params()
            },
        ),
        (
            "form=polar",
            PredictParams {
                form: FormChoice::Polar,
                ..params()
            },
        ),
        (
            "form=cells",
            PredictParams {
                form: FormChoice::Cells,
                ..params()
            },
        ),
        (
            "spectrum=closed",
            PredictParams {
                spectrum: SpectrumChoice::Closed,
                ..params()
            },
        ),
        (
            "spectrum=estimated",
            PredictParams {
                spectrum: SpectrumChoice::Estimated,
                ..params()
            },
        ),
        (
            "kmax=24",
            PredictParams {
                kmax: Some(24),
                ..params()
            },
        ),
    ];
    let integrands = integrands_2d();
    let kinds = [
        SamplerKind::Random,
        SamplerKind::Jitter,
        SamplerKind::PoissonDisk,
        SamplerKind::Sobol,
        SamplerKind::Cmj,
        SamplerKind::Halton,
        SamplerKind::Korobov,
    ];
    for kind in kinds {
        let sampler = kind.build(2).unwrap();
        let n = kind.nearest_count(64, 2);
        for r in [Randomization::Shift, kind.native_randomization()] {
            for (name, f) in integrands.iter().take(2) {
                for (what, p) in &forced {
                    let problem = Problem::new(sampler.as_ref(), f.as_ref(), n)
                        .unwrap()
                        .with_randomization(r);
                    let line = outcome_with(&problem, p);
                    writeln!(out, "choice {what}\t{kind}\t{r}\t{name}\t{n}\t{line}").unwrap();
                }
            }
        }
    }
}

/// Point sets of one's own: jittered sets under the shift, declared as strata, and as given
/// without a declaration; a fixed grid's one set under the shift.
fn point_sets(out: &mut String) {
    let jitter = Jitter::new(2).unwrap();
    let sets: Vec<PointSet> = (0..8).map(|r| jitter.sample(64, 3, r).unwrap()).collect();
    let grid = [Regular::new(2).unwrap().sample(64, 0, 0).unwrap()];
    for (name, f) in integrands_2d().iter().take(3) {
        let cases = [
            (
                "jitter sets, shift",
                Problem::from_point_sets(&sets, f.as_ref()).unwrap(),
            ),
            (
                "jitter sets, strata",
                Problem::from_point_sets(&sets, f.as_ref())
                    .unwrap()
                    .with_cells(CellRule::Strata)
                    .unwrap(),
            ),
            (
                "jitter sets, as given",
                Problem::from_point_sets(&sets, f.as_ref())
                    .unwrap()
                    .with_randomization(Randomization::None),
            ),
            (
                "grid set, shift",
                Problem::from_point_sets(&grid, f.as_ref()).unwrap(),
            ),
        ];
        for (what, problem) in cases {
            writeln!(out, "sets {what}\t\t\t{name}\t64\t{}", outcome(&problem)).unwrap();
        }
    }
}

/// Every case answers as the golden file says. The whole matrix takes minutes on two cores;
/// it is the reference for any change to how routes are chosen.
#[test]
#[ignore = "the full route matrix takes minutes; run before and after any change to route choice"]
fn every_route_answers_as_recorded() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(GOLDEN);
    let now = table();
    if std::env::var_os("SPECVAR_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &now).unwrap();
        return;
    }
    let recorded = std::fs::read_to_string(&path).unwrap();
    let changed: Vec<String> = recorded
        .lines()
        .zip(now.lines())
        .filter(|(a, b)| a != b)
        .map(|(a, b)| format!("recorded {a}\n     now {b}"))
        .collect();
    assert_eq!(recorded.lines().count(), now.lines().count(), "case count");
    assert!(
        changed.is_empty(),
        "{} cases changed:\n{}",
        changed.len(),
        changed.join("\n")
    );
}

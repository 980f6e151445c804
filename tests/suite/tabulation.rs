//! Grids that tabulate a finer function: the prediction extrapolated from the grid's coarser
//! levels covers the finer function's exact prediction within its budget, too coarse a grid is
//! refused with the resolution it needs, and a grid declared exact keeps its own answer.

use specvar::integrand::{Ball, GridIntegrand, GridMeaning, Integrand, Polygon};
use specvar::predict::{predict, PredictParams, Problem};
use specvar::sampler::SamplerKind;

/// The 99% interval's noise multiplier, as the budgets are read everywhere.
const Z: f64 = 2.576;

/// `f`'s cell averages on `m × m` cells (its exact masses over the cells), or its values at
/// the centres.
fn tabulate(f: &dyn Integrand, m: usize, meaning: GridMeaning) -> GridIntegrand {
    let values = match meaning {
        GridMeaning::PointSamples => (0..m * m)
            .map(|i| {
                let c = |j: usize| (j as f64 + 0.5) / m as f64;
                f.eval(&[c(i % m), c(i / m)])
            })
            .collect(),
        _ => {
            let masses = f.grid_masses(&[m, m], &[0.0, 0.0]).unwrap().masses;
            masses.iter().map(|v| v * (m * m) as f64).collect()
        }
    };
    GridIntegrand::new(m, m, values)
        .unwrap()
        .with_meaning(meaning)
}

fn triangle() -> Polygon {
    Polygon::new(vec![[0.12, 0.18], [0.83, 0.31], [0.41, 0.88]], 1.0).unwrap()
}

/// Each sampler's prediction for `f` itself, and for its tabulation on `m` cells per axis.
fn covered(f: &dyn Integrand, kind: SamplerKind, n: usize, m: usize, meaning: GridMeaning) {
    let sampler = kind.build(2).unwrap();
    let params = PredictParams::default();
    let truth = predict(&Problem::new(sampler.as_ref(), f, n).unwrap(), &params).unwrap();
    let grid = tabulate(f, m, meaning);
    let p = predict(&Problem::new(sampler.as_ref(), &grid, n).unwrap(), &params).unwrap();
    let half_width = p.budget.half_width(Z) + Z * truth.budget.spectrum_noise;
    assert!(
        (p.variance - truth.variance).abs() <= half_width,
        "{} {kind} N = {n} on {m}² ({meaning:?}): {:.4e} ± {:.1e} for {:.4e}",
        f.label(),
        p.variance,
        half_width,
        truth.variance
    );
    assert!(p.budget.tabulation > 0.0 && p.reason.contains("tabulates a finer function"));
}

#[test]
fn a_tabulated_triangle_is_predicted_as_the_triangle_within_its_budget() {
    let tri = triangle();
    for kind in [
        SamplerKind::Sobol,
        SamplerKind::SobolNet,
        SamplerKind::Jitter,
    ] {
        for m in [256, 512] {
            covered(&tri, kind, 1024, m, GridMeaning::CellAverages);
        }
    }
    covered(
        &tri,
        SamplerKind::Random,
        1024,
        32,
        GridMeaning::CellAverages,
    );
    covered(&tri, SamplerKind::Cmj, 1024, 512, GridMeaning::PointSamples);
    let disk = Ball::new(0.3, vec![0.5, 0.5], 1.0).unwrap();
    covered(
        &disk,
        SamplerKind::LatinHypercube,
        256,
        256,
        GridMeaning::CellAverages,
    );
}

/// At 256 cells per sample the budget informs: at most a fifth of the value.
#[test]
fn at_256_cells_per_sample_the_budget_is_at_most_a_fifth() {
    let grid = tabulate(&triangle(), 512, GridMeaning::CellAverages);
    for kind in [
        SamplerKind::Sobol,
        SamplerKind::SobolNet,
        SamplerKind::Jitter,
    ] {
        let sampler = kind.build(2).unwrap();
        let problem = Problem::new(sampler.as_ref(), &grid, 1024).unwrap();
        let p = predict(&problem, &PredictParams::default()).unwrap();
        assert!(p.budget.half_width(Z) <= 0.2 * p.variance, "{kind}: {p:?}");
    }
}

#[test]
fn too_coarse_a_tabulation_is_refused_with_the_resolution_it_needs() {
    let tri = triangle();
    let sobol = SamplerKind::Sobol.build(2).unwrap();
    for (m, needed) in [(32, "256"), (64, "256"), (128, "256")] {
        let grid = tabulate(&tri, m, GridMeaning::CellAverages);
        let e = predict(
            &Problem::new(sobol.as_ref(), &grid, 1024).unwrap(),
            &PredictParams::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains(&format!("at least {needed} cells per axis")),
            "{m}: {e}"
        );
    }
    // A smooth tabulation under a sampler whose projections are stratified into N intervals
    // needs 4 N cells per axis: correlated multi-jitter's variance of a Gaussian lies within
    // them.
    let bump = specvar::integrand::Gaussian::new(0.15, vec![0.45, 0.55], 1.0).unwrap();
    let grid = tabulate(&bump, 256, GridMeaning::CellAverages);
    let cmj = SamplerKind::Cmj.build(2).unwrap();
    let e = predict(
        &Problem::new(cmj.as_ref(), &grid, 1024).unwrap(),
        &PredictParams::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("at least 4096 cells per axis"), "{e}");
}

#[test]
fn a_grid_declared_exact_keeps_its_own_prediction() {
    let grid = tabulate(&triangle(), 64, GridMeaning::Exact);
    let jitter = SamplerKind::Jitter.build(2).unwrap();
    let p = predict(
        &Problem::new(jitter.as_ref(), &grid, 1024).unwrap(),
        &PredictParams::default(),
    )
    .unwrap();
    // The per-stratum form of the 64² grid: (1/N²) Σ_c Var_c over 32² strata of 2 × 2 cells.
    let v = grid.values();
    let mut sum = 0.0;
    for sy in 0..32 {
        for sx in 0..32 {
            let cell = |dx: usize, dy: usize| v[(2 * sy + dy) * 64 + 2 * sx + dx];
            let c = [cell(0, 0), cell(1, 0), cell(0, 1), cell(1, 1)];
            let mean = c.iter().sum::<f64>() / 4.0;
            sum += c.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 4.0;
        }
    }
    let exact = sum / (1024.0 * 1024.0);
    assert!(
        (p.variance - exact).abs() <= 1e-12 * exact,
        "{} vs {exact}",
        p.variance
    );
    assert_eq!(p.budget.tabulation, 0.0);
}

#[test]
fn coarser_levels_are_cell_averages_or_centre_values() {
    let tri = triangle();
    let fine = tabulate(&tri, 64, GridMeaning::CellAverages);
    let coarse = fine.averaged(32, 32).unwrap();
    let direct = tabulate(&tri, 32, GridMeaning::CellAverages);
    for (a, b) in coarse.values().iter().zip(direct.values()) {
        assert!((a - b).abs() < 1e-13, "{a} vs {b}");
    }
    // An uneven split keeps the integral.
    let uneven = fine.averaged(23, 17).unwrap();
    assert!((uneven.integral() - fine.integral()).abs() < 1e-14);
    // Centre values at half the resolution: the fine cell holding each coarse centre.
    let samples = tabulate(&tri, 64, GridMeaning::PointSamples);
    let half = samples.subsampled(32, 32).unwrap();
    for (i, v) in half.values().iter().enumerate() {
        let (x, y) = (i % 32, i / 32);
        assert_eq!(*v, samples.values()[(2 * y + 1) * 64 + 2 * x + 1]);
    }
}

/// A plan on a coarse tabulation stops at the largest N the grid serves, and says that the
/// grid's resolution is what stopped it: 64 cells per axis serve jitter up to N = 64.
#[test]
fn a_plan_asks_for_a_finer_tabulation_instead_of_planning_on_a_coarse_one() {
    use specvar::plan::{plan_many, PlanParams, Target};
    let grid = tabulate(&triangle(), 64, GridMeaning::CellAverages);
    let jitter = SamplerKind::Jitter.build(2).unwrap();
    let e = plan_many(
        &[jitter.as_ref()],
        &grid,
        &PlanParams::new(Target::RelativeRmse(1e-3)),
        &specvar::progress::Silent,
    )
    .unwrap_err();
    match e {
        specvar::Error::Unreachable {
            largest_n, limit, ..
        } => {
            assert_eq!(largest_n, 64);
            assert!(limit.contains("tabulated grid's resolution"), "{limit}");
        }
        other => panic!("{other}"),
    }
}

/// A disk crossing a face is cut there, as a Gaussian or a polygon is: white noise on it is
/// `A(1 − A)/N` with the cut area; `wrap` keeps the torus's disk; an interval is cut exactly;
/// a 3D ball crossing a face is refused, naming `wrap`.
#[test]
fn a_ball_crossing_a_face_is_cut_there_unless_it_wraps() {
    use specvar::integrand::IntegrandSpec;
    let build = |text: &str, d: usize| text.parse::<IntegrandSpec>().unwrap().build(d);
    let cut = build("disk:r=0.3,c=0.9;0.5", 2).unwrap();
    let r: f64 = 0.3;
    let area =
        std::f64::consts::PI * r * r - (r * r * (0.1 / r).acos() - 0.1 * (r * r - 0.01).sqrt());
    assert!((cut.integral() - area).abs() < 1e-12);
    let random = SamplerKind::Random.build(2).unwrap();
    let p = predict(
        &Problem::new(random.as_ref(), cut.as_ref(), 256).unwrap(),
        &PredictParams::default(),
    )
    .unwrap();
    let white = area * (1.0 - area) / 256.0;
    assert!(
        p.covers(white, Z) && p.budget.tabulation < 1e-3 * white,
        "{p:?} vs {white:e}"
    );
    let wrapped = build("disk:r=0.3,c=0.9;0.5,wrap", 2).unwrap();
    assert!((wrapped.integral() - std::f64::consts::PI * 0.09).abs() < 1e-15);
    assert_eq!(wrapped.eval(&[0.05, 0.5]), 1.0);
    assert_eq!(cut.eval(&[0.05, 0.5]), 0.0);
    let interval = build("ball:r=0.3,c=0.1", 1).unwrap();
    assert!((interval.integral() - 0.4).abs() < 1e-15);
    let e = build("ball:r=0.3,c=0.1;0.5;0.5", 3)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("wrapped around the torus (ball:…,wrap)"), "{e}");
    // The canonical text keeps the word.
    let spec: IntegrandSpec = "disk:r=0.3,c=0.9;0.5,wrap".parse().unwrap();
    assert_eq!(spec.to_string().parse::<IntegrandSpec>().unwrap(), spec);
}

/// A binary image with a small feature is not smooth, however its energies fall between two
/// levels: its largest step between neighbouring cells keeps the jump's height. (A speck a few
/// cells wide passes the energy test alone, and was refused as smooth.)
#[test]
fn a_small_binary_feature_is_not_taken_for_a_smooth_tabulation() {
    use specvar::predict::SMOOTH_RATIO;
    // `∫ (fine − coarse)²` for sides that halve.
    let energy = |fine: &GridIntegrand, coarse: &GridIntegrand| {
        let (m, c) = (fine.width(), coarse.width());
        let sum: f64 = (0..m * m)
            .map(|i| {
                let v = coarse.values()[(i / m) * c / m * c + (i % m) * c / m];
                (fine.values()[i] - v).powi(2)
            })
            .sum();
        sum / (m * m) as f64
    };
    let speck = Ball::new(0.02, vec![0.31, 0.47], 1.0).unwrap();
    let sobol = SamplerKind::Sobol.build(2).unwrap();
    let mut energy_alone_says_smooth = false;
    for m in [128, 256] {
        let grid = tabulate(&speck, m, GridMeaning::PointSamples);
        let (first, second) = (
            grid.coarser(m / 2, m / 2).unwrap(),
            grid.coarser(m / 4, m / 4).unwrap(),
        );
        energy_alone_says_smooth |= energy(&grid, &first) < SMOOTH_RATIO * energy(&first, &second);
        let p = predict(
            &Problem::new(sobol.as_ref(), &grid, 64).unwrap(),
            &PredictParams::default(),
        );
        assert!(p.is_ok(), "{m}: {}", p.unwrap_err());
    }
    assert!(
        energy_alone_says_smooth,
        "the case no longer tests the step criterion"
    );
}

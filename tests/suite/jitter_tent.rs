//! Jitter under a random shift summed in space over the strata's tent, against routes that
//! share none of its steps: cells of the shifted grid averaged over offsets (space, no
//! autocorrelation), the lattice form (Fourier), the polar form's radial integral, and, at the
//! largest N, the lattice form's failure it replaces.

use specvar::integrand::*;
use specvar::montecarlo::Z_99;
use specvar::predict::*;
use specvar::randomization::Randomization;
use specvar::sampler::*;
use specvar::spectrum::ClosedForm;

use crate::common;

fn shifted(f: &dyn Integrand, n: usize, params: &PredictParams) -> Prediction {
    let jitter = Jitter::new(f.dimension()).unwrap();
    predict(
        &Problem::new(&jitter, f, n)
            .unwrap()
            .with_randomization(Randomization::Shift),
        params,
    )
    .unwrap()
}

fn lattice_form() -> PredictParams {
    PredictParams {
        form: FormChoice::Lattice,
        ..Default::default()
    }
}

/// Two predictions agree within the sum of their 99% budgets.
fn assert_within_budgets(a: &Prediction, b: &Prediction, what: &str) {
    let allowed = a.budget.half_width(Z_99) + b.budget.half_width(Z_99);
    assert!(
        (a.variance - b.variance).abs() <= allowed,
        "{what}: {} against {} (allowed {allowed:e})",
        a.variance,
        b.variance
    );
}

/// The wide disk at 4 × 4 and 8 × 8 strata, whose autocorrelation wraps around the torus,
/// against the cells of the shifted grid averaged over q × q offsets by the midpoint rule,
/// whose error ten times its change from q/2 to q bounds (it converges like 1/q²).
#[test]
fn the_tent_matches_shifted_cells_of_a_wrapped_disk() {
    let disk = Ball::new(0.45, vec![0.5, 0.5], 1.0).unwrap();
    for (m, q) in [(4, 400), (8, 200)] {
        let (v, err, _) = jitter_shift_variance(&disk, &[m, m], &Default::default())
            .unwrap()
            .unwrap();
        let coarse = common::geometric_jitter_variance(0.45, [0.5, 0.5], m, q / 2);
        let truth = common::geometric_jitter_variance(0.45, [0.5, 0.5], m, q);
        let allowed = err + 10.0 * (truth - coarse).abs();
        assert!(
            (v - truth).abs() <= allowed,
            "m = {m}: {v} against {truth} ± {allowed:e}"
        );
    }
}

/// A product of truncated Gaussians in 1D and 2D against the per-axis mean over shifted cells
/// (error functions, no autocorrelation).
#[test]
fn the_tent_matches_shifted_cells_of_gaussian_products() {
    for (c, m) in [(vec![0.3], 64), (vec![0.1, 0.7], 16)] {
        let f = Gaussian::new(0.1, c.clone(), 1.0).unwrap();
        let strata = vec![m; c.len()];
        let (v, err, _) = jitter_shift_variance(&f, &strata, &Default::default())
            .unwrap()
            .unwrap();
        let truth = common::jitter_variance_of_product(&c, 0.1, m);
        assert!(
            (v - truth).abs() <= err + common::QUADRATURE * truth,
            "c = {c:?}, m = {m}: {v} against {truth} ± {err:e}"
        );
    }
}

/// Just beyond the widest lattice's reach (1049² strata) the default takes the tent, and the
/// lattice form asked for, whose tail bound is a few % there, agrees within its budget: a
/// disk, an edge at 30° (jumps at the square's faces too), a triangle and a binary grid; and
/// the edge on strata of two sizes.
#[test]
fn beyond_the_lattice_the_default_is_the_tent_and_the_lattice_agrees() {
    let n = 1049 * 1049;
    let shapes: Vec<Box<dyn Integrand>> = vec![
        Box::new(Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap()),
        Box::new(Polygon::edge(30.0, 0.5, 1.0).unwrap()),
        Box::new(Polygon::new(vec![[0.2, 0.2], [0.8, 0.3], [0.4, 0.9]], 1.0).unwrap()),
        Box::new(checkerboard()),
    ];
    for f in &shapes {
        let tent = shifted(f.as_ref(), n, &PredictParams::default());
        assert_eq!(
            tent.route.spectrum,
            SpectrumOrigin::Closed(ClosedForm::Jitter)
        );
        assert!(tent.reason.contains("tent"), "{}", tent.reason);
        assert_eq!(tent.budget.truncation, 0.0);
        assert!(
            tent.budget.half_width(Z_99) <= 1e-6 * tent.variance,
            "{}: {:?}",
            f.label(),
            tent.budget
        );
        let lattice = shifted(f.as_ref(), n, &lattice_form());
        assert_within_budgets(&tent, &lattice, &f.label());
    }
    // Strata of two sizes (1100 × 1050): the tent scales each axis by its own.
    let edge = Polygon::edge(30.0, 0.5, 1.0).unwrap();
    let n = 1100 * 1050;
    let tent = shifted(&edge, n, &PredictParams::default());
    assert!(tent.reason.contains("1100 × 1050"), "{}", tent.reason);
    assert_within_budgets(
        &tent,
        &shifted(&edge, n, &lattice_form()),
        "edge, 1100 × 1050",
    );
}

/// A 6 × 5 binary grid (a pixel-like integrand with jumps along its cells' sides).
fn checkerboard() -> GridIntegrand {
    let (w, h) = (6, 5);
    let values = (0..w * h).map(|i| ((i % w + i / w) % 2) as f64).collect();
    GridIntegrand::new(w, h, values)
        .unwrap()
        .with_meaning(specvar::integrand::GridMeaning::Exact)
}

/// At N = 10^12 the disk's tent agrees with the polar form's closed-form radial mean, and the
/// edge's, which has no polar form, is informative where the lattice form's tail bound is
/// the whole of its value (and that value hundreds of times too large).
#[test]
fn at_a_trillion_points_the_tent_is_exact_where_the_lattice_is_not() {
    let n = 1_000_000_000_000;
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let polar = PredictParams {
        form: FormChoice::Polar,
        ..Default::default()
    };
    assert_within_budgets(
        &shifted(&disk, n, &PredictParams::default()),
        &shifted(&disk, n, &polar),
        "disk",
    );
    let edge = Polygon::edge(30.0, 0.5, 1.0).unwrap();
    let tent = shifted(&edge, n, &PredictParams::default());
    let lattice = shifted(&edge, n, &lattice_form());
    assert!(tent.budget.half_width(Z_99) <= 1e-6 * tent.variance);
    assert!(lattice.budget.truncation > 0.5 * lattice.variance);
    // The lattice's interval holds the tent's value: the two routes do not contradict.
    assert!(tent.variance <= lattice.variance + lattice.budget.half_width(Z_99));
}

/// A triangle at 16 × 16 strata against Gauss–Legendre in polar coordinates with the angle
/// split at every kink of `a_f(0) − a_f` (the edges' directions, found from the vertices, and
/// the diagonal): on each piece the integrand is smooth in the angle and polynomial along the
/// rays, so 60 × 12 points are exact to rounding. Bisection from a single start once missed
/// this by 2e-7 of the value with an estimate of 2e-10.
#[test]
fn a_triangle_matches_gauss_legendre_split_at_its_kinks() {
    let vertices = [[0.2, 0.2], [0.8, 0.3], [0.4, 0.9]];
    let triangle = Polygon::new(vertices.to_vec(), 1.0).unwrap();
    let m = 16;
    let h = 1.0 / m as f64;
    let a0 = triangle.autocorrelation(&[0.0, 0.0]).unwrap();
    let drop = |u: f64, v: f64| a0 - triangle.autocorrelation(&[u * h, v * h]).unwrap();
    // Kinks of D(u, v) and D(u, −v) on the quarter θ ∈ [0, π/2]: each edge's direction, or
    // its mirror in the u axis, where it falls in the quarter.
    let quarter = std::f64::consts::FRAC_PI_2;
    let mut cuts = vec![0.0, quarter / 2.0, quarter];
    for k in 0..3 {
        let (p, q) = (vertices[k], vertices[(k + 1) % 3]);
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        for (x, y) in [(dx, dy), (-dx, -dy), (dx, -dy), (-dx, dy)] {
            let angle = y.atan2(x);
            if angle > 0.0 && angle < quarter {
                cuts.push(angle);
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    let (angles, radii) = (
        specvar::quadrature::GaussLegendre::new(60),
        specvar::quadrature::GaussLegendre::new(12),
    );
    let quarter_integral: f64 = cuts
        .windows(2)
        .map(|w| {
            angles.integrate(w[0], w[1], |theta| {
                let (s, c) = theta.sin_cos();
                radii.integrate(0.0, 1.0 / c.max(s), |rho| {
                    let (u, v) = (rho * c, rho * s);
                    rho * (drop(u, v) + drop(u, -v)) * (1.0 - u) * (1.0 - v)
                })
            })
        })
        .sum();
    let truth = 2.0 * quarter_integral / (m * m) as f64;
    let (v, err, _) = jitter_shift_variance(&triangle, &[m, m], &Default::default())
        .unwrap()
        .unwrap();
    assert!(
        (v - truth).abs() <= err + common::ROUNDING * truth,
        "{v} against {truth} ± {err:e}"
    );
}

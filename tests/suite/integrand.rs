//! Integrands: Parseval, transforms against direct integration, limits, parsing.

use rayon::prelude::*;
use specvar::integrand::*;
use specvar::predict::{predict_lattice, SpectrumSource};
use specvar::quadrature::{integrate_panels, panel_breakpoints, GaussLegendre};
use specvar::sampler::Jitter;
use specvar::spectrum::ClosedForm;
use std::f64::consts::PI;

use crate::common;

fn integrands(d: usize) -> Vec<Box<dyn Integrand>> {
    vec![
        Box::new(Ball::new(0.25, vec![0.5; d], 1.0).unwrap()),
        Box::new(Ball::new(0.2, vec![0.4; d], 4.0 / PI.sqrt()).unwrap()),
        Box::new(Gaussian::new(0.1, vec![0.5; d], 1.0).unwrap()),
        Box::new(Gaussian::new(0.0705, vec![0.45; d], 8.0).unwrap()),
    ]
}

/// `M ∫_0^L ρ^{d-1} P̆_f dρ` on half-period panels.
fn radial_energy(f: &dyn Integrand, end: f64) -> f64 {
    let d = f.dimension();
    let breaks = panel_breakpoints(end, f.panel_width(), []);
    let m = sphere_measure(d);
    integrate_panels(&breaks, 1e-16, |r| {
        m * r.powi(d as i32 - 1) * f.radial_power(r)
    })
    .value
}

#[test]
fn parseval_gaussian_to_1e_10() {
    for d in 1..=3 {
        for f in integrands(d)
            .iter()
            .filter(|f| f.decay_exponent().is_infinite())
        {
            let e = radial_energy(f.as_ref(), f.negligible_beyond());
            assert!(
                (e / f.spectral_energy() - 1.0).abs() < 1e-10,
                "{}",
                f.label()
            );
        }
    }
}

#[test]
fn parseval_disk_to_1e_10_with_the_exact_bessel_tail() {
    // 2D: ∫_L^∞ ρ P̆_f dρ = a² R² (J0(t)² + J1(t)²)/2 at t = 2πRL (from d/dt [J0² + J1²] = -2 J1²/t).
    for f in integrands(2)
        .iter()
        .filter(|f| f.decay_exponent().is_finite())
    {
        let ball = f.as_ref();
        let (r, a) = if ball.label().contains("r=0.25") {
            (0.25, 1.0)
        } else {
            (0.2, 4.0 / PI.sqrt())
        };
        let end = 200.0;
        let t = 2.0 * PI * r * end;
        let tail = 2.0 * PI * a * a * r * r * (libm::j0(t).powi(2) + libm::j1(t).powi(2)) / 2.0;
        let total = radial_energy(ball, end) + tail;
        assert!(
            (total / ball.spectral_energy() - 1.0).abs() < 1e-10,
            "{}",
            ball.label()
        );
    }
}

#[test]
fn parseval_ball_in_1d_and_3d_with_the_envelope_tail() {
    // Beyond L the power oscillates about its mean a² R^{d-1} / (2π² ρ^{d+1}) (half the peak
    // envelope); replacing it by the mean leaves an O(L^-2) error relative to the tail.
    for d in [1, 3] {
        let f = Ball::new(0.25, vec![0.5; d], 1.0).unwrap();
        let end = 2000.0;
        let m = sphere_measure(d);
        let tail = m * 0.25f64.powi(d as i32 - 1) / (2.0 * PI * PI) / end;
        let total = radial_energy(&f, end) + tail;
        assert!((total / f.spectral_energy() - 1.0).abs() < 1e-8, "d={d}");
    }
}

#[test]
fn transforms_match_direct_integration() {
    // 2D disk by Gauss–Legendre in polar coordinates around the centre (no Bessel function).
    let disk = Ball::new(0.25, vec![0.4, 0.6], 1.5).unwrap();
    let rule = GaussLegendre::new(60);
    for omega in [[0.0, 0.0], [1.0, 0.0], [2.0, 3.0], [-5.0, 1.5]] {
        let re = rule.integrate(0.0, 0.25, |r| {
            rule.integrate(0.0, 2.0 * PI, |t| {
                let x = [0.4 + r * t.cos(), 0.6 + r * t.sin()];
                1.5 * r * (-2.0 * PI * (omega[0] * x[0] + omega[1] * x[1])).cos()
            })
        });
        let im = rule.integrate(0.0, 0.25, |r| {
            rule.integrate(0.0, 2.0 * PI, |t| {
                let x = [0.4 + r * t.cos(), 0.6 + r * t.sin()];
                1.5 * r * (-2.0 * PI * (omega[0] * x[0] + omega[1] * x[1])).sin()
            })
        });
        let fh = disk.fourier(&omega);
        assert!(
            (fh.re - re).abs() < common::ROUNDING && (fh.im - im).abs() < common::ROUNDING,
            "{omega:?}"
        );
    }
    // 1D and 3D balls, and Gaussians, by Gauss–Legendre over the line / cube.
    let rule = GaussLegendre::new(40);
    let ball1 = Ball::new(0.3, vec![0.45], 2.0).unwrap();
    for w in [0.0, 0.7, 3.0] {
        let re = rule.integrate(0.15, 0.75, |x| 2.0 * (-2.0 * PI * w * x).cos());
        assert!((ball1.fourier(&[w]).re - re).abs() < 1e-13);
    }
    let ball3 = Ball::new(0.25, vec![0.5; 3], 1.0).unwrap();
    for rho in [0.0, 1.0, 2.5] {
        // Radial: f̂(ρ) = ∫_0^R 4π r² sinc(2πρr) dr for a centred ball.
        let direct = rule.integrate(0.0, 0.25, |r| {
            let t = 2.0 * PI * rho * r;
            4.0 * PI * r * r * if t == 0.0 { 1.0 } else { t.sin() / t }
        });
        assert!(
            (ball3.radial_power(rho) - direct * direct).abs() < 1e-13,
            "ρ={rho}"
        );
    }
    // A Gaussian this narrow has negligible mass outside the cube: its cube integral of
    // f e^{-2πiωx} matches the closed form up to that mass.
    let g = Gaussian::new(0.05, vec![0.5, 0.5], 1.0).unwrap();
    let panels = GaussLegendre::new(80);
    for omega in [[0.0, 0.0], [3.0, -2.0]] {
        let re = panels.integrate(0.0, 1.0, |x| {
            panels.integrate(0.0, 1.0, |y| {
                g.eval(&[x, y]) * (-2.0 * PI * (omega[0] * x + omega[1] * y)).cos()
            })
        });
        assert!(
            (g.fourier(&omega).re - re).abs() < common::ROUNDING,
            "{omega:?}"
        );
    }
}

#[test]
fn values_and_limits_at_zero_frequency() {
    for d in 1..=3 {
        for f in integrands(d) {
            let zero = vec![0.0; d];
            assert!(
                (f.fourier(&zero).re - f.spectral_integral()).abs() < 1e-14 * f.spectral_integral()
            );
            let small = f.radial_power(1e-7);
            assert!(
                (small / f.radial_power(0.0) - 1.0).abs() < 1e-9,
                "{}",
                f.label()
            );
        }
    }
    // The cube integral of a centred Gaussian falls short of the full-space one by its tail mass.
    let g = Gaussian::new(0.2, vec![0.5], 1.0).unwrap();
    let tail = 0.2 * (2.0 * PI).sqrt() * libm::erfc(0.5 / (0.2 * 2f64.sqrt()));
    assert!((g.spectral_integral() - g.integral() - tail).abs() < 1e-15);
}

#[test]
fn ball_power_decays_like_its_envelope() {
    // P̆_f ≤ a² R^{d-1} / (π² ρ^{d+1}) · (1 + O(1/ρ)), the envelope being half the peak mean.
    for d in 1..=3 {
        let f = Ball::new(0.25, vec![0.5; d], 1.0).unwrap();
        for rho in [50.0f64, 100.0, 400.0] {
            let envelope = 0.25f64.powi(d as i32 - 1) / (PI * PI * rho.powi(d as i32 + 1));
            assert!(f.radial_power(rho) <= envelope * 1.05, "d={d} ρ={rho}");
        }
    }
}

#[test]
fn invalid_parameters_are_errors() {
    assert!(Ball::new(-0.1, vec![0.5; 2], 1.0).is_err());
    assert!(Ball::new(0.6, vec![0.5; 2], 1.0).is_err());
    assert!(Ball::new(f64::NAN, vec![0.5; 2], 1.0).is_err());
    assert!(Ball::new(0.1, vec![0.5; 4], 1.0).is_err());
    assert!(Gaussian::new(0.0, vec![0.5; 2], 1.0).is_err());
    assert!(Gaussian::new(0.1, vec![1.5; 2], 1.0).is_err());
    assert!(Gaussian::new(0.1, vec![0.5; 2], f64::INFINITY).is_err());
}

#[test]
fn specs_parse_with_overrides_and_list_keys_on_error() {
    let s = parse_integrand("gaussian:sigma=0.0705,a=8").unwrap();
    let g = s.build(2).unwrap();
    assert!(g.label().contains("sigma=0.0705") && g.label().contains("a=8"));
    let c = parse_integrand("gaussian:c=0.3;0.5")
        .unwrap()
        .build(2)
        .unwrap();
    assert!(c.label().contains("[0.3, 0.5]"));
    assert!(parse_integrand("disk:c=0.3;0.5;0.2")
        .unwrap()
        .build(2)
        .is_err());
    let e = parse_integrand("disk:sigma=2").unwrap_err().to_string();
    assert!(e.contains("accepted keys"), "{e}");
    assert!(parse_integrand("cube").is_err());
    assert!(parse_integrand("disk:r=abc").is_err());
}

// ---- grid integrands ----

/// A small grid with irregular values (fixed).
fn small_grid() -> GridIntegrand {
    let values: Vec<f64> = (0..15)
        .map(|i| ((i * 7 + 3) % 11) as f64 / 10.0 - 0.2)
        .collect();
    GridIntegrand::new(5, 3, values).unwrap()
}

/// `f̂(ω)` of a piecewise-constant grid by summing each cell's exact transform, written
/// independently of the library (no FFT, no tables).
fn grid_transform_by_cells(g: &GridIntegrand, omega: [f64; 2]) -> num_complex::Complex64 {
    use num_complex::Complex64;
    use std::f64::consts::PI;
    // ∫_a^b e^{-2πi w x} dx
    let interval = |a: f64, b: f64, w: f64| -> Complex64 {
        if w == 0.0 {
            return Complex64::new(b - a, 0.0);
        }
        let e = |x: f64| Complex64::from_polar(1.0, -2.0 * PI * w * x);
        (e(b) - e(a)) / Complex64::new(0.0, -2.0 * PI * w)
    };
    let (w, h) = (g.width(), g.height());
    let mut total = Complex64::new(0.0, 0.0);
    for y in 0..h {
        for x in 0..w {
            let v = g.values()[y * w + x];
            total += interval(x as f64 / w as f64, (x + 1) as f64 / w as f64, omega[0])
                * interval(y as f64 / h as f64, (y + 1) as f64 / h as f64, omega[1])
                * v;
        }
    }
    total
}

#[test]
fn grid_transform_matches_the_cell_by_cell_integral() {
    let g = small_grid();
    for k in [
        [0.0, 0.0],
        [1.0, 0.0],
        [-3.0, 2.0],
        [7.0, -11.0],
        [40.0, 33.0],
    ] {
        let (a, b) = (g.fourier(&k), grid_transform_by_cells(&g, k));
        assert!((a - b).norm() < 1e-13, "{k:?}: {a} vs {b}");
    }
    for w in [[0.3, -1.7], [12.25, 4.5], [-0.01, 0.0]] {
        let (a, b) = (g.fourier(&w), grid_transform_by_cells(&g, w));
        assert!((a - b).norm() < common::ROUNDING, "{w:?}: {a} vs {b}");
    }
    assert!((g.fourier(&[0.0, 0.0]).re - g.integral()).abs() < 1e-15);
}

/// A grid's power on the lattice, computed axis by axis, is the squared modulus of its
/// coefficients, each from the cell-by-cell integral, at frequencies that alias past the grid.
#[test]
fn grid_power_on_the_lattice_is_its_coefficients_squared() {
    use specvar::spectrum::Lattice;
    let g = small_grid();
    let lattice = Lattice {
        dimension: 2,
        kmax: 13,
    };
    let mut power = vec![0.0; lattice.len()];
    g.power_on_lattice(lattice, &mut power);
    for (i, &p) in power.iter().enumerate() {
        let k = lattice.frequency(i);
        let exact = grid_transform_by_cells(&g, [k[0] as f64, k[1] as f64]).norm_sqr();
        assert!(
            (p - exact).abs() <= common::ROUNDING * g.integral_of_square(),
            "{k:?}: {p} vs {exact}"
        );
    }
}

#[test]
fn grid_radial_power_is_the_angular_mean() {
    let g = small_grid();
    for rho in [0.5, 3.0, 17.3] {
        // Brute force: midpoint rule with many more angles than the library uses.
        let m = 20000;
        let brute: f64 = (0..m)
            .map(|i| {
                let t = 2.0 * std::f64::consts::PI * (i as f64 + 0.5) / m as f64;
                grid_transform_by_cells(&g, [rho * t.cos(), rho * t.sin()]).norm_sqr()
            })
            .sum::<f64>()
            / m as f64;
        let r = g.radial_power(rho);
        assert!(
            (r - brute).abs() < 1e-10 * brute.max(1e-6),
            "ρ={rho}: {r} vs {brute}"
        );
    }
}

#[test]
fn grid_lattice_form_with_white_noise_is_the_exact_variance() {
    let g = small_grid();
    let exact = (g.integral_of_square() - g.integral().powi(2)) / 32.0;
    let p = predict_lattice(&g, &SpectrumSource::Closed(ClosedForm::WhiteNoise), 32, 16).unwrap();
    assert!(
        (p.variance - exact).abs() < 1e-14,
        "{} vs {exact}",
        p.variance
    );
}

/// The lattice form for a grid integrand against Monte Carlo: the jitter closed form (12 × 8
/// strata at N = 96) must fall inside the 99% interval of 20 000 homogenized trials.
#[test]
fn grid_lattice_form_agrees_with_monte_carlo() {
    // A 32 × 32 raster of a disk of radius 0.3 with an off-centre hole.
    let m = 32;
    let values: Vec<f64> = (0..m * m)
        .map(|i| {
            let (x, y) = (
                ((i % m) as f64 + 0.5) / m as f64,
                ((i / m) as f64 + 0.5) / m as f64,
            );
            let disk = (x - 0.5).powi(2) + (y - 0.5).powi(2) < 0.09;
            let hole = (x - 0.6).powi(2) + (y - 0.45).powi(2) < 0.01;
            if disk && !hole {
                1.0
            } else {
                0.0
            }
        })
        .collect();
    let g = GridIntegrand::new(m, m, values).unwrap();
    let predicted = predict_lattice(&g, &SpectrumSource::Closed(ClosedForm::Jitter), 96, 256)
        .unwrap()
        .variance;
    let params = specvar::montecarlo::McParams {
        patterns: 20000,
        ..Default::default()
    };
    let mc =
        specvar::montecarlo::empirical_variance(&Jitter::new(2).unwrap(), &g, 96, &params).unwrap();
    assert!(
        mc.ci_low <= predicted && predicted <= mc.ci_high,
        "predicted {predicted:e}, MC {:e} [{:e}, {:e}]",
        mc.variance,
        mc.ci_low,
        mc.ci_high
    );
}

#[test]
fn grid_files_parse_and_report_bad_lines() {
    let g = read_grid_text("# header\n0.5 1\n\n0, 0.25\n").unwrap();
    assert_eq!((g.width(), g.height()), (2, 2));
    // First line is the top row (largest y).
    assert_eq!(g.values(), &[0.0, 0.25, 0.5, 1.0]);
    let e = read_grid_text("1 2 3\n4 5\n").unwrap_err();
    assert!(e.to_string().starts_with("line 2:"), "{e}");
    let e = read_grid_text("1 2\n1 x\n").unwrap_err();
    assert!(
        e.to_string().contains("line 2") && e.to_string().contains("'x'"),
        "{e}"
    );
    assert!(read_grid_text("# nothing\n").is_err());
    assert!(read_grid_text("1 inf\n").is_err());
    assert!(GridIntegrand::new(2, 2, vec![1.0; 3]).is_err());
    assert!(GridIntegrand::new(0, 2, vec![]).is_err());
}

#[test]
fn png_grids_round_trip_with_the_top_row_at_the_largest_y() {
    // 3 × 2 grey image: top row 0, 255, 51; bottom row 102, 153, 204.
    let png = specvar::plot::gray_png(&[0, 255, 51, 102, 153, 204], 3, 2).unwrap();
    let g = read_grid_png(&png).unwrap();
    assert_eq!((g.width(), g.height()), (3, 2));
    let expected = [0.4, 0.6, 0.8, 0.0, 1.0, 0.2];
    for (v, e) in g.values().iter().zip(expected) {
        assert!((v - e).abs() < common::ROUNDING, "{v} vs {e}");
    }
    assert!(read_grid_png(b"not a png").is_err());
    let dir = std::env::temp_dir().join("specvar-grid-test");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("g.png");
    std::fs::write(&path, &png).unwrap();
    let spec = parse_integrand(&format!("grid:{}", path.display())).unwrap();
    let f = spec.build(2).unwrap();
    assert!(f.label().contains("g.png"));
    assert!(spec.build(3).is_err());
}

/// `∫_0^1 g(x) e^{-2πikx} dx` by 20-point Gauss–Legendre on panels of a quarter period: an
/// independent route to the truncated Gaussian's torus coefficients (no Faddeeva function).
fn coefficient_by_quadrature(k: i64, c: f64, s: f64) -> num_complex::Complex64 {
    let rule = GaussLegendre::new(20);
    let panels = (4 * k.unsigned_abs() as usize).max(16);
    let h = 1.0 / panels as f64;
    let (mut re, mut im) = (0.0, 0.0);
    for p in 0..panels {
        let a = p as f64 * h;
        let g = |x: f64| (-(x - c).powi(2) / (2.0 * s * s)).exp();
        re += rule.integrate(a, a + h, |x| g(x) * (2.0 * PI * k as f64 * x).cos());
        im -= rule.integrate(a, a + h, |x| g(x) * (2.0 * PI * k as f64 * x).sin());
    }
    num_complex::Complex64::new(re, im)
}

/// The truncated Gaussian's torus coefficients (closed form through the Faddeeva function)
/// against quadrature, for centred, off-centre, near-face, wide and narrow Gaussians, up to
/// k = 1024: agreement to 1e-14 of the mass (the quadrature's own rounding floor).
#[test]
fn truncated_gaussian_coefficients_match_quadrature() {
    for (c, s) in [
        (0.5, 0.1),
        (0.3, 0.1),
        (0.05, 0.02),
        (0.9, 0.5),
        (0.5, 3.0),
        (0.0, 0.05),
    ] {
        let g = Gaussian::new(s, vec![c], 1.0).unwrap();
        let mass = g.integral();
        for k in [0i64, 1, -2, 5, 17, 64, 255, 1024] {
            let closed = g.coefficient(&[k]);
            let quad = coefficient_by_quadrature(k, c, s);
            assert!(
                (closed - quad).norm() < 1e-14 * mass.max(1.0),
                "c={c} σ={s} k={k}: {closed} vs {quad}"
            );
        }
    }
    // In 2D the coefficient is the product over axes.
    let g = Gaussian::new(0.1, vec![0.3, 0.6], 2.0).unwrap();
    let product =
        2.0 * coefficient_by_quadrature(7, 0.3, 0.1) * coefficient_by_quadrature(-3, 0.6, 0.1);
    assert!((g.coefficient(&[7, -3]) - product).norm() < 1e-14);
}

/// Parseval on the torus: the squared coefficients of the truncated Gaussian add up to ∫ f² on
/// the cube (not to the full-space energy). An off-centre Gaussian jumps by A = g(0) - g(1) at
/// the faces, so the tail beyond K is about A²/(2π²K); it is allowed twice over.
#[test]
fn torus_parseval_holds_for_truncated_gaussians() {
    for (c, s) in [(0.5, 0.1), (0.2, 0.1), (0.5, 0.4)] {
        let g = Gaussian::new(s, vec![c], 1.0).unwrap();
        let kmax = 4096i64;
        let sum: f64 = (-kmax..=kmax).map(|k| g.coefficient(&[k]).norm_sqr()).sum();
        let jump = g.eval(&[0.0]) - g.eval(&[1.0 - 1e-15]);
        let tail = jump * jump / (2.0 * PI * PI * kmax as f64);
        let energy = g.integral_of_square();
        assert!(
            (energy - sum).abs() <= 2.0 * tail + common::ROUNDING * energy,
            "c={c} σ={s}: {energy} vs {sum}"
        );
    }
}

/// The projections' energies are the axis lines' Parseval sums: `∫F_a² = Σ_k |f̂(k e_a)|²`.
/// The sum stops at K; the projection of a Gaussian jumps at the faces by
/// `A = (g_a(0) - g_a(1)) Π_{b≠a} ∫g_b`, leaving a tail of about `A²/(2π²K)`, allowed twice.
/// The disk's projection (the chord measure, whose energy is `16R³/3`) is continuous with a
/// square-root edge: its tail falls like `K^-2`, 2e-4 of it at K = 20000 is ample.
#[test]
fn projection_energy_is_the_axis_line_sum() {
    let (c, s) = ([0.4, 0.7], 0.15);
    let g = Gaussian::new(s, c.to_vec(), 1.0).unwrap();
    let disk = Ball::new(0.2, vec![0.45, 0.5], 1.0).unwrap();
    let line = |f: &dyn Integrand, axis: usize, kmax: i64| -> f64 {
        (-kmax..=kmax)
            .map(|k| {
                let mut kk = [0i64; 2];
                kk[axis] = k;
                f.coefficient(&kk).norm_sqr()
            })
            .sum()
    };
    let kmax = 2048;
    for axis in 0..2 {
        let edge = |x: f64| (-(x - c[axis]).powi(2) / (2.0 * s * s)).exp();
        let jump = (edge(0.0) - edge(1.0)) * g.coefficient(&[0, 0]).re
            / Gaussian::new(s, vec![c[axis]], 1.0).unwrap().integral();
        let tail = jump * jump / (2.0 * PI * PI * kmax as f64);
        let (sum, exact) = (line(&g, axis, kmax), g.projection_energy(axis));
        assert!(
            (sum - exact).abs() <= 2.0 * tail + common::ROUNDING * exact,
            "Gaussian axis {axis}: {sum} vs {exact}"
        );
        let (sum, exact) = (line(&disk, axis, 20000), disk.projection_energy(axis));
        assert!(
            common::close(sum, exact, 2e-4),
            "disk axis {axis}: {sum} vs {exact}"
        );
    }
}

/// The torus autocorrelations against the midpoint rule on a 2000 × 2000 grid of `x`: the
/// Gaussian's (smooth but for the faces' jumps) to 1e-5, the wrapped disk's (a lens across the
/// torus's seam) to the grid's resolution along the disk's edge, about 4R/2000.
#[test]
fn autocorrelations_match_numerical_integration() {
    let g = Gaussian::new(0.1, vec![0.3, 0.6], 1.0).unwrap();
    let disk = Ball::new(0.3, vec![0.1, 0.5], 1.0).unwrap();
    // Polygons: the midpoint rule errs by about a cell along the boundary of the overlap,
    // its perimeter (at most twice the polygon's) over the grid step.
    let l_shape = Polygon::new(
        vec![
            [0.0, 0.0],
            [0.6, 0.0],
            [0.6, 0.2],
            [0.2, 0.2],
            [0.2, 0.8],
            [0.0, 0.8],
        ],
        1.5,
    )
    .unwrap();
    let edge = Polygon::edge(30.0, 0.4, 1.0).unwrap();
    let steps = 2000;
    for (f, tolerance) in [
        (&g as &dyn Integrand, 1e-5),
        (&disk, 4.0 * 0.3 / 2000.0),
        (&l_shape, 2.0 * 3.2 / 2000.0 / 0.2),
        (&edge, 2.0 * 4.0 / 2000.0 / 0.4),
    ] {
        for r in [[0.0, 0.0], [0.05, -0.1], [0.4, 0.3], [-0.45, 0.2]] {
            // The midpoint rule's rows in parallel, summed in order.
            let rows: Vec<f64> = (0..steps)
                .into_par_iter()
                .map(|i| {
                    (0..steps)
                        .map(|j| {
                            let x = [
                                (i as f64 + 0.5) / steps as f64,
                                (j as f64 + 0.5) / steps as f64,
                            ];
                            let y = [
                                specvar::pointset::wrap(x[0] + r[0]),
                                specvar::pointset::wrap(x[1] + r[1]),
                            ];
                            f.eval(&x) * f.eval(&y)
                        })
                        .sum::<f64>()
                })
                .collect();
            let numeric = rows.iter().sum::<f64>() / (steps * steps) as f64;
            let exact = f.autocorrelation(&r).unwrap();
            assert!(
                (numeric - exact).abs() <= tolerance * f.integral_of_square(),
                "{} r={r:?}: {numeric} vs {exact}",
                f.label()
            );
        }
    }
}

/// A grid's autocorrelation (the bilinear interpolation of its cells' FFT autocorrelation)
/// against the overlaps of every pair of cells summed directly, at offsets on and between the
/// cell lattice and across the torus's seam.
#[test]
fn grid_autocorrelation_is_the_sum_of_cell_overlaps() {
    let (w, h) = (6usize, 4usize);
    let values: Vec<f64> = (0..w * h).map(|i| ((i * 7) % 5) as f64 - 1.3).collect();
    let f = GridIntegrand::new(w, h, values.clone()).unwrap();
    // The overlap length of [a, a + c) with [b, b + c) moved by t on the circle of length 1.
    let overlap = |a: f64, b: f64, c: f64, t: f64| -> f64 {
        (-1..=1)
            .map(|m| {
                let start = a + t + m as f64;
                (start + c).min(b + c) - start.max(b)
            })
            .map(|o| o.max(0.0))
            .sum()
    };
    for r in [
        [0.0, 0.0],
        [0.25, 0.5],
        [0.1, 0.33],
        [0.97, 0.71],
        [-0.2, -0.6],
    ] {
        let mut direct = 0.0;
        for j in 0..h {
            for i in 0..w {
                for q in 0..h {
                    for p in 0..w {
                        let ox = overlap(
                            i as f64 / w as f64,
                            p as f64 / w as f64,
                            1.0 / w as f64,
                            r[0],
                        );
                        let oy = overlap(
                            j as f64 / h as f64,
                            q as f64 / h as f64,
                            1.0 / h as f64,
                            r[1],
                        );
                        direct += values[j * w + i] * values[q * w + p] * ox * oy;
                    }
                }
            }
        }
        let a = f.autocorrelation(&r).unwrap();
        assert!(
            (a - direct).abs() < common::ROUNDING * f.integral_of_square(),
            "r = {r:?}: {a} vs {direct}"
        );
    }
}

/// A ball across a face wraps around the torus: its value at a point and at the point's image,
/// its integral, and its coefficients equal to the full-space transform (as its images do not
/// overlap for R ≤ 1/2).
#[test]
fn a_ball_across_a_face_wraps_around_the_torus() {
    let f = Ball::new(0.3, vec![0.9, 0.5], 2.0).unwrap();
    assert_eq!(f.eval(&[0.1, 0.5]), 2.0);
    assert_eq!(f.eval(&[0.5, 0.5]), 0.0);
    assert!((f.integral() - 2.0 * PI * 0.09).abs() < common::ROUNDING);
    // Monte Carlo over the cube sees the wrapped disk: a midpoint rule on a fine grid agrees.
    let steps = 1000;
    let sum: f64 = (0..steps * steps)
        .map(|i| {
            f.eval(&[
                ((i % steps) as f64 + 0.5) / steps as f64,
                ((i / steps) as f64 + 0.5) / steps as f64,
            ])
        })
        .sum();
    assert!(
        (sum / (steps * steps) as f64 - f.integral()).abs() < 4.0 * 0.3 * 2.0 * 2.0 / steps as f64
    );
    assert!(Ball::new(0.51, vec![0.5, 0.5], 1.0).is_err());
}

/// The 2D lens (the disk's autocorrelation) near contact, `|r| = 2R − δ`, against its area by
/// quadrature of a positive integrand, `4R² ∫_0^θ sin²φ dφ` with `cos θ = |r|/(2R)` (two
/// circular segments; no cancellation). The textbook `2R² acos − (s/2)√(4R² − s²)` loses
/// `ε/δ` relative there. The offset is given by components, so `δ` carries a rounding of
/// `ε·2R`: the area's relative error from it is `1.5 ε 2R / δ`, allowed four times.
#[test]
fn disk_autocorrelation_is_accurate_near_contact() {
    let r = 0.3f64;
    let disk = Ball::new(r, vec![0.5, 0.5], 1.0).unwrap();
    let rule = specvar::quadrature::GaussLegendre::new(24);
    for delta in [1e-2f64, 1e-4, 1e-6, 1e-8] {
        let s = 2.0 * r - delta;
        let component = s / 2f64.sqrt();
        let theta = 2.0 * (delta / (4.0 * r)).sqrt().asin();
        let reference = 4.0 * r * r * rule.integrate(0.0, theta, |p| p.sin().powi(2));
        let value = disk.autocorrelation(&[component, component]).unwrap();
        let allowed = 6.0 * f64::EPSILON * 2.0 * r / delta + 1e-14;
        assert!(
            (value / reference - 1.0).abs() < allowed,
            "δ = {delta}: {value} vs {reference}"
        );
    }
}

/// A separable integrand's cells from its rows are its boxes' moments, to the bit, on grids of
/// unequal sides in 2D and 3D; integrands that are not products have no rows.
#[test]
fn separable_cells_are_the_boxes_moments() {
    for (grid, centre) in [
        (vec![8usize, 4], vec![0.2, 0.7]),
        (vec![5, 3, 2], vec![0.3, 0.6, 0.45]),
    ] {
        let g = Gaussian::new(0.17, centre, 1.3).unwrap();
        let rows = g.separable_cells(&grid).expect("a Gaussian is separable");
        let cells: usize = grid.iter().product();
        for index in 0..cells {
            let (mut lo, mut hi, mut rest) = (vec![], vec![], index);
            for &m in &grid {
                lo.push((rest % m) as f64 / m as f64);
                hi.push((rest % m + 1) as f64 / m as f64);
                rest /= m;
            }
            let boxed = g.box_moments(&lo, &hi).unwrap();
            let (a, b) = (rows.moments(index), boxed);
            assert_eq!(a.0.to_bits(), b.0.to_bits(), "{grid:?} cell {index}");
            assert_eq!(a.1.to_bits(), b.1.to_bits(), "{grid:?} cell {index}");
        }
    }
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    assert!(disk.separable_cells(&[4, 4]).is_none());
}

/// A ball's radial profile is refused where it would outgrow its memory (in 1D its `K²` values
/// outgrow the lattice's `2K + 1` long before), and the ball's power on such a lattice is then
/// read one coefficient at a time, the same values.
#[test]
fn a_radial_profile_beyond_its_memory_is_refused() {
    use specvar::spectrum::Lattice;
    assert!(RadialCoefficients::new(&[0.5], 3_000_000, |_| 1.0).is_none());
    assert!(RadialCoefficients::new(&[0.5, 0.5], 100, |_| 1.0).is_some());
    let ball = Ball::new(0.1, vec![0.3], 1.0).unwrap();
    let lattice = Lattice {
        dimension: 1,
        kmax: 3_000_000,
    };
    let mut power = vec![0.0; lattice.len()];
    ball.power_on_lattice(lattice, &mut power);
    for k in [0i64, 1, -7, 2_999_999] {
        let i = (k + lattice.kmax as i64) as usize;
        assert_eq!(power[i], ball.coefficient(&[k]).norm_sqr(), "k = {k}");
    }
}

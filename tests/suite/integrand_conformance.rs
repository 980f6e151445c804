//! One checker applied to every integrand form: its text round trip, its integral and energy
//! against quadrature of its values, its low Fourier coefficients against quadrature of
//! `f e^{-2πik·x}`, Parseval on the lattice, its lattice batches against its coefficients, and
//! its isotropy claim. Each quadrature comes with a bound derived from the cells' samples, so
//! no tolerance is tuned.

use num_complex::Complex64;
use rayon::prelude::*;
use specvar::integrand::{Integrand, IntegrandSpec};
use specvar::spectrum::Lattice;
use std::f64::consts::PI;

/// Cells per axis of the quadrature, by dimension.
fn cells(d: usize) -> usize {
    [0, 100_000, 512, 96][d]
}

/// Cells in which a polygon's corner can hide between the samples (a tip narrower than a
/// cell): at most one per vertex, and the polygons here have at most this many.
const HIDDEN_CORNER_CELLS: f64 = 16.0;

/// The relative error of one Fourier coefficient as the integrands compute it (Bessel and error
/// functions, polygon edges, the grids' and truncated lobes' longer sums): a few hundred units
/// of roundoff at most.
const COEFFICIENT_ERROR: f64 = 1e-13;

/// Every point of the cell grid, with the cell's samples (its corners and its midpoint).
fn for_each_cell(d: usize, mut visit: impl FnMut(&[f64], &[Vec<f64>])) {
    let m = cells(d);
    let h = 1.0 / m as f64;
    let below_one = |x: f64| x.min(1.0 - 1e-12);
    let mut index = vec![0usize; d];
    // One buffer for the midpoint and one per corner, refilled for each cell.
    let mut mid = vec![0.0; d];
    let mut corners = vec![vec![0.0; d]; 1 << d];
    loop {
        for a in 0..d {
            mid[a] = (index[a] as f64 + 0.5) * h;
        }
        for (mask, corner) in corners.iter_mut().enumerate() {
            for (a, x) in corner.iter_mut().enumerate() {
                *x = below_one((index[a] + (mask >> a & 1)) as f64 * h);
            }
        }
        visit(&mid, &corners);
        let mut a = 0;
        loop {
            if a == d {
                return;
            }
            index[a] += 1;
            if index[a] < m {
                break;
            }
            index[a] = 0;
            a += 1;
        }
    }
}

/// `∫ g(f(x), x) dx` by the midpoint rule, with a bound on its error: on each cell, `g` lies
/// between the smallest and largest of its samples at the corners and the midpoint (the
/// integrands here are piecewise constant, or smooth with their extremes at cell samples),
/// plus the phase's variation across the cell for a Fourier factor of frequency `k`.
fn quadrature(f: &dyn Integrand, k: &[i64], g: impl Fn(f64) -> f64) -> (Complex64, f64) {
    let d = f.dimension();
    let volume = (1.0 / cells(d) as f64).powi(d as i32);
    let phase_step = PI * k.iter().map(|c| c.abs() as f64).sum::<f64>() / cells(d) as f64;
    let (mut sum, mut bound, mut sup) = (Complex64::new(0.0, 0.0), 0.0, 0.0f64);
    for_each_cell(d, |mid, corners| {
        let value = g(f.eval(mid));
        let (lo, hi) = corners
            .iter()
            .map(|c| g(f.eval(c)))
            .fold((value, value), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let angle = -2.0 * PI * k.iter().zip(mid).map(|(&a, x)| a as f64 * x).sum::<f64>();
        sum += Complex64::from_polar(value, angle) * volume;
        bound += ((hi - lo) + value.abs().max(hi.abs()).max(lo.abs()) * phase_step) * volume;
        sup = sup.max(value.abs()).max(hi.abs()).max(lo.abs());
    });
    let hidden = if d == 2 {
        HIDDEN_CORNER_CELLS * sup * volume
    } else {
        0.0
    };
    (sum, bound + hidden)
}

/// Every form of the grammar, in each dimension it exists in.
fn specs(grid: &std::path::Path) -> Vec<(String, usize)> {
    let mut all: Vec<(String, usize)> = Vec::new();
    for d in 1..=3 {
        all.push(("disk:r=0.3,c=0.45".into(), d));
        all.push(("gaussian:sigma=0.12,a=2,c=0.45".into(), d));
    }
    all.push((format!("grid:{}", grid.display()), 2));
    all.push(("polygon:0.2,0.3;0.7,0.25;0.6,0.8".into(), 2));
    all.push(("edge:theta=30,offset=0.4,a=1.5".into(), 2));
    all.push(("agaussian:s1=0.1,s2=0.04,angle=25,c=0.45;0.55".into(), 2));
    all
}

#[test]
fn every_integrand_conforms() {
    let grid = std::env::temp_dir().join(format!("specvar-conformance-{}.txt", std::process::id()));
    std::fs::write(&grid, "0 1 0 2\n1 3 1 0\n0 1 0.5 0\n").unwrap();
    // The specifications are independent: checked side by side.
    specs(&grid).into_par_iter().for_each(|(text, d)| {
        let spec: IntegrandSpec = text.parse().unwrap();
        // The text round trip: the canonical text reads back as the same specification.
        assert_eq!(
            spec.to_string().parse::<IntegrandSpec>().unwrap(),
            spec,
            "{text}"
        );
        let f = spec.build(d).unwrap();
        let label = format!("{text} in {d}D");
        // The integral and the energy.
        let (integral, bound) = quadrature(f.as_ref(), &vec![0; d], |v| v);
        // The bound informs: its first-order cell ranges reach a fifth of the integral in 3D
        // at 96 cells per axis, far less in 1D and 2D.
        assert!(
            bound < 0.25 * f.integral().abs(),
            "{label}: bound {bound:.2e}"
        );
        assert!(
            (integral.re - f.integral()).abs() <= bound,
            "{label}: ∫f {} against quadrature {} ± {bound:.2e}",
            f.integral(),
            integral.re
        );
        let (energy, bound) = quadrature(f.as_ref(), &vec![0; d], |v| v * v);
        assert!(
            (energy.re - f.integral_of_square()).abs() <= bound,
            "{label}: ∫f² {} against quadrature {} ± {bound:.2e}",
            f.integral_of_square(),
            energy.re
        );
        // Low coefficients against quadrature of f e^{-2πik·x}.
        let ks: Vec<Vec<i64>> = match d {
            1 => vec![vec![1], vec![-3]],
            2 => vec![vec![1, 0], vec![2, -1], vec![-1, 3]],
            _ => vec![vec![1, 0, 0], vec![1, -1, 2]],
        };
        for k in ks {
            let (c, bound) = quadrature(f.as_ref(), &k, |v| v);
            let exact = f.coefficient(&k);
            assert!(
                (c - exact).norm() <= bound,
                "{label}: f̂{k:?} = {exact} against quadrature {c} ± {bound:.2e}"
            );
        }
        // Parseval on the lattice: the power below |k_i| ≤ K is part of the energy, and at
        // K = 32 most of it for these integrands, which reach over a tenth of the cube.
        let kmax = if d == 3 { 12 } else { 32 };
        let lattice = Lattice { dimension: d, kmax };
        let mut power = vec![0.0; lattice.len()];
        f.power_on_lattice(lattice, &mut power);
        let partial: f64 = power.iter().sum();
        let energy = f.integral_of_square();
        assert!(
            partial <= energy * (1.0 + 1e-9) && partial >= 0.8 * energy,
            "{label}: Σ|f̂|² on |k_i| ≤ {kmax} is {partial}, ∫f² is {energy}"
        );
        // The lattice batches (per-axis tables, one radial value per |k|²) against the
        // coefficient at each frequency: both carry the integrands' relative error of a
        // coefficient, and phases whose arguments reach 2πK per axis, rounded absolutely;
        // every coefficient is at most ∫|f| ≤ ‖f‖₂ in size.
        let mut coefficients = vec![Complex64::new(0.0, 0.0); lattice.len()];
        f.coefficients_on_lattice(lattice, &mut coefficients);
        let tables = f.coefficient_tables(kmax);
        let relative =
            COEFFICIENT_ERROR + 8.0 * f64::EPSILON * (1.0 + 2.0 * PI * (d * kmax) as f64);
        let delta = relative * energy.sqrt();
        for (i, (&p, &c)) in power.iter().zip(&coefficients).enumerate() {
            let k = lattice.frequency(i);
            let exact = f.coefficient(&k[..d]);
            assert!(
                (c - exact).norm() <= delta,
                "{label}: f̂{k:?} on the lattice {c} against {exact} (allowed {delta:e})"
            );
            if let Some(t) = &tables {
                let c = t.at(&k[..d]);
                assert!(
                    (c - exact).norm() <= delta,
                    "{label}: f̂{k:?} from its tables {c} against {exact} (allowed {delta:e})"
                );
            }
            let allowed = 2.0 * exact.norm() * delta + delta * delta;
            assert!(
                (p - exact.norm_sqr()).abs() <= allowed,
                "{label}: |f̂{k:?}|² on the lattice {p:e} against {:e} (allowed {allowed:e})",
                exact.norm_sqr()
            );
        }
        // Isotropy: |f̂(ω)| at equal lengths, and the radial power is |f̂|².
        if f.is_isotropic() {
            let length = 7.3;
            let mut a = vec![0.0; d];
            a[0] = length;
            let b: Vec<f64> = (0..d).map(|_| length / (d as f64).sqrt()).collect();
            let (fa, fb) = (f.fourier(&a).norm(), f.fourier(&b).norm());
            let scale = f.spectral_energy().sqrt();
            assert!((fa - fb).abs() <= 1e-12 * scale, "{label}: {fa} vs {fb}");
            let radial = f.radial_power(length);
            assert!(
                (radial - fa * fa).abs() <= 1e-9 * radial.max(1e-300),
                "{label}: radial power {radial} vs |f̂|² {}",
                fa * fa
            );
        }
    });
    let _ = std::fs::remove_file(&grid);
}

//! Each sampler's defining property, reproducibility, and its errors.

use rayon::prelude::*;
use specvar::sampler::*;
use specvar::{Error, PointSet};

mod common;

fn all_in_unit_cube(p: &PointSet) -> bool {
    p.coords().iter().all(|c| (0.0..1.0).contains(c))
}

/// A valid N near `target` for a sampler in dimension d.
fn valid_n(kind: SamplerKind, d: usize, target: usize) -> usize {
    match kind {
        SamplerKind::Regular | SamplerKind::Jitter => {
            let m = ((target as f64).powf(1.0 / d as f64).round() as usize).max(2);
            m.pow(d as u32)
        }
        _ => target,
    }
}

#[test]
fn every_sampler_every_dimension_gives_n_points_in_the_unit_cube() {
    for kind in SamplerKind::ALL {
        for d in kind.dimensions() {
            let s = kind.build(d).unwrap();
            let n = valid_n(kind, d, if d > 4 { 32 } else { 64 });
            let p = s.sample(n, 11, 3).unwrap();
            assert_eq!(p.len(), n, "{} d={d}", kind.name());
            assert_eq!(p.dimension(), d);
            assert!(all_in_unit_cube(&p), "{} d={d}", kind.name());
        }
    }
}

#[test]
fn same_seed_same_points_other_realization_other_points() {
    for kind in SamplerKind::ALL {
        let s = kind.build(2).unwrap();
        let n = valid_n(kind, 2, 49);
        assert_eq!(s.sample(n, 5, 2).unwrap(), s.sample(n, 5, 2).unwrap());
        if kind != SamplerKind::Regular {
            assert_ne!(s.sample(n, 5, 2).unwrap(), s.sample(n, 5, 3).unwrap());
            assert_ne!(s.sample(n, 5, 2).unwrap(), s.sample(n, 6, 2).unwrap());
        }
    }
}

#[test]
fn realizations_do_not_depend_on_thread_count() {
    let s = SamplerKind::PoissonDisk.build(2).unwrap();
    let serial: Vec<PointSet> = (0..8).map(|r| s.sample(100, 9, r).unwrap()).collect();
    let parallel = common::assert_thread_count_invariant(|| {
        (0..8)
            .into_par_iter()
            .map(|r| s.sample(100, 9, r).unwrap())
            .collect::<Vec<PointSet>>()
    });
    assert_eq!(serial, parallel);
}

#[test]
fn regular_points_sit_exactly_on_cell_centres() {
    for d in 1..=4 {
        let m = 5usize;
        let p = Regular::new(d)
            .unwrap()
            .sample(m.pow(d as u32), 0, 0)
            .unwrap();
        let mut seen = std::collections::HashSet::new();
        for x in p.points() {
            let cell: Vec<usize> = x.iter().map(|c| (c * m as f64).floor() as usize).collect();
            for (c, k) in x.iter().zip(&cell) {
                assert_eq!(*c, (*k as f64 + 0.5) / m as f64);
            }
            assert!(seen.insert(cell));
        }
    }
}

/// Counts points per cell of an `m^d` grid.
fn stratum_counts(p: &PointSet, m: usize) -> Vec<usize> {
    let mut counts = vec![0; m.pow(p.dimension() as u32)];
    for x in p.points() {
        let flat = x.iter().fold(0, |acc, c| acc * m + (c * m as f64) as usize);
        counts[flat] += 1;
    }
    counts
}

#[test]
fn jitter_puts_one_point_in_each_stratum() {
    for d in 1..=4 {
        let m: usize = 4;
        let p = Jitter::new(d)
            .unwrap()
            .sample(m.pow(d as u32), 3, 1)
            .unwrap();
        assert!(stratum_counts(&p, m).iter().all(|&c| c == 1), "d={d}");
    }
}

#[test]
fn jitter_stratifies_96_points_as_12_by_8() {
    let p = Jitter::new(2).unwrap().sample(96, 5, 2).unwrap();
    let mut counts = [[0; 8]; 12];
    for x in p.points() {
        counts[(x[0] * 12.0) as usize][(x[1] * 8.0) as usize] += 1;
    }
    assert!(counts.iter().flatten().all(|&c| c == 1));
    assert_eq!(specvar::sampler::strata(96, 2), Some(vec![12, 8]));
}

#[test]
fn jitter_rejects_non_powers_and_names_the_nearest() {
    let e = Jitter::new(2).unwrap().sample(17, 0, 0).unwrap_err();
    assert!(e.to_string().contains("16 or 18"), "{e}");
    let e = Jitter::new(2).unwrap().sample(22, 0, 0).unwrap_err();
    assert!(e.to_string().contains("20 or 24"), "{e}"); // 22 = 2 × 11 is too elongated
    let e = Jitter::new(3).unwrap().sample(30, 0, 0).unwrap_err();
    assert!(e.to_string().contains("27 or 64"), "{e}");
    assert!(matches!(e, Error::UnsupportedCount { .. }));
}

#[test]
fn unsupported_dimensions_and_counts_are_errors() {
    assert!(matches!(
        Ccvt::new(4),
        Err(Error::UnsupportedDimension { .. })
    ));
    assert!(matches!(
        CorrelatedMultiJitter::new(3),
        Err(Error::UnsupportedDimension { .. })
    ));
    assert!(Random::new(0).is_err());
    assert!(Random::new(9).is_err());
    assert!(Random::new(2).unwrap().sample(0, 0, 0).is_err());
    assert!(SamplerKind::from_name("nope")
        .unwrap_err()
        .to_string()
        .contains("jitter"));
}

#[test]
fn poisson_disk_keeps_the_minimum_distance() {
    for d in 1..=3 {
        for method in [PoissonMethod::DartThrowing, PoissonMethod::Bridson] {
            let s = PoissonDisk::new(d).unwrap().with_method(method);
            for n in [50, 400] {
                let p = s.sample(n, 4, 0).unwrap();
                assert_eq!(p.len(), n);
                let r = s.radius(n);
                assert!(p.min_toroidal_distance() >= r, "d={d} {method:?} n={n}");
            }
        }
    }
}

#[test]
fn poisson_disk_reports_saturation_instead_of_looping() {
    // Relative radius 1 is the densest packing: random placement cannot reach it.
    let s = PoissonDisk::new(2)
        .unwrap()
        .with_relative_radius(1.0)
        .unwrap();
    match s.sample(200, 1, 0) {
        Err(Error::Saturated {
            placed, requested, ..
        }) => {
            assert!(placed < requested);
            assert_eq!(requested, 200);
        }
        other => panic!("expected saturation, got {other:?}"),
    }
    assert!(PoissonDisk::new(2)
        .unwrap()
        .with_relative_radius(1.5)
        .is_err());
}

#[test]
fn ccvt_has_equal_capacities_and_converges_with_falling_energy() {
    for d in 1..=3 {
        let (p, stats) = Ccvt::new(d).unwrap().generate(64, 2, 0).unwrap();
        assert_eq!(p.len(), 64);
        let cap = CcvtParams::default().capacity;
        assert!(stats.capacities.iter().all(|&c| c == cap), "d={d}");
        assert!(stats.converged, "d={d}: {} iterations", stats.iterations);
        for w in stats.energy.windows(2) {
            assert!(
                w[1] <= w[0] * (1.0 + common::ROUNDING),
                "energy rose: {w:?}"
            );
        }
    }
}

#[test]
fn ccvt_points_are_well_spread() {
    // Converged CCVT points are far more regular than dart throwing allows to be random:
    // the minimum distance stays above half the densest-packing distance.
    let p = Ccvt::new(2).unwrap().sample(256, 1, 0).unwrap();
    assert!(p.min_toroidal_distance() > 0.5 * max_packing_radius(2, 256));
}

#[test]
fn latin_hypercube_has_one_point_per_row_on_every_axis() {
    for d in 1..=8 {
        let n = 37;
        let p = LatinHypercube::new(d).unwrap().sample(n, 8, 0).unwrap();
        for axis in 0..d {
            let mut rows: Vec<usize> = p.points().map(|x| (x[axis] * n as f64) as usize).collect();
            rows.sort_unstable();
            assert_eq!(rows, (0..n).collect::<Vec<_>>());
        }
    }
}

/// Whether the points of axes (a, b) form a (0, k, 2)-net: every elementary interval of
/// volume 2^-k (shape 2^-i × 2^-(k-i)) holds exactly one point.
fn is_0k2_net(p: &PointSet, a: usize, b: usize, k: u32) -> bool {
    (0..=k).all(|i| {
        let (nx, ny) = (1usize << i, 1usize << (k - i));
        let mut counts = vec![0; nx * ny];
        for x in p.points() {
            counts[(x[a] * nx as f64) as usize * ny + (x[b] * ny as f64) as usize] += 1;
        }
        counts.iter().all(|&c| c == 1)
    })
}

#[test]
fn sobol_first_2k_points_form_0k2_nets() {
    let s = Sobol::new(2).unwrap();
    for k in 1..=10 {
        for realization in 0..3 {
            let p = s.sample(1 << k, 7, realization).unwrap();
            assert!(is_0k2_net(&p, 0, 1, k), "k={k}");
        }
    }
}

#[test]
fn sobol_every_axis_is_stratified() {
    let p = Sobol::new(8).unwrap().sample(256, 1, 0).unwrap();
    for axis in 0..8 {
        let mut rows: Vec<usize> = p.points().map(|x| (x[axis] * 256.0) as usize).collect();
        rows.sort_unstable();
        assert_eq!(rows, (0..256).collect::<Vec<_>>(), "axis {axis}");
    }
}

#[test]
fn halton_axes_are_stratified_in_their_base() {
    let bases = [2usize, 3, 5, 7, 11, 13, 17, 19];
    let p = Halton::new(8).unwrap().sample(2 * 3 * 5 * 7, 3, 1).unwrap();
    for (axis, &b) in bases.iter().enumerate().take(4) {
        // The first b^j points fill the b^j intervals of their axis once each.
        let bj = b.pow((210f64.ln() / (b as f64).ln()).floor() as u32);
        let mut rows: Vec<usize> = p
            .points()
            .take(bj)
            .map(|x| (x[axis] * bj as f64) as usize)
            .collect();
        rows.sort_unstable();
        assert_eq!(rows, (0..bj).collect::<Vec<_>>(), "axis {axis}");
    }
}

#[test]
fn cmj_is_both_jittered_and_n_rooks() {
    for n in [96usize, 64, 35] {
        let p = CorrelatedMultiJitter::new(2)
            .unwrap()
            .sample(n, 5, 0)
            .unwrap();
        for axis in 0..2 {
            let mut rows: Vec<usize> = p.points().map(|x| (x[axis] * n as f64) as usize).collect();
            rows.sort_unstable();
            assert_eq!(rows, (0..n).collect::<Vec<_>>(), "n={n} axis {axis}");
        }
        let (m, r) = if n == 96 {
            (8, 12)
        } else if n == 64 {
            (8, 8)
        } else {
            (5, 7)
        };
        let mut cells: Vec<usize> = p
            .points()
            .map(|x| (x[1] * r as f64) as usize * m + (x[0] * m as f64) as usize)
            .collect();
        cells.sort_unstable();
        assert_eq!(cells, (0..n).collect::<Vec<_>>(), "n={n}");
    }
}

#[test]
fn homogenization_is_a_toroidal_translation() {
    let fixed = Jitter::new(2).unwrap();
    let shifted = Homogenized::new(fixed);
    let a = fixed.sample(16, 3, 4).unwrap();
    let b = shifted.sample(16, 3, 4).unwrap();
    assert_ne!(a, b);
    // The shift is one vector: every point moved by the same toroidal offset.
    let d0: Vec<f64> = (0..2).map(|k| b.point(0)[k] - a.point(0)[k]).collect();
    for i in 1..16 {
        for k in 0..2 {
            let di = b.point(i)[k] - a.point(i)[k];
            let diff = specvar::pointset::toroidal_delta(di.rem_euclid(1.0), d0[k].rem_euclid(1.0));
            assert!(diff.abs() < common::ROUNDING);
        }
    }
    assert_eq!(shifted.inner().sample(16, 3, 4).unwrap(), a);
}

#[test]
fn homogenized_points_are_uniform_in_each_coordinate() {
    // The first coordinate of point 0 of a homogenized regular grid is U(0,1): its mean over
    // R realizations lies within 4 standard errors (sd 1/√12) of 1/2.
    let s = Homogenized::new(Regular::new(2).unwrap());
    let r = 4000;
    let mean: f64 = (0..r)
        .map(|i| s.sample(4, 1, i).unwrap().point(0)[0])
        .sum::<f64>()
        / r as f64;
    let se = (1.0 / 12.0f64).sqrt() / (r as f64).sqrt();
    assert!((mean - 0.5).abs() < common::Z_LOOSE * se, "mean {mean}");
}

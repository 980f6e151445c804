//! Each sampler's defining property, reproducibility, and its errors.

use rayon::prelude::*;
use specvar::sampler::*;
use specvar::{Error, PointSet};

use crate::common;

fn all_in_unit_cube(p: &PointSet) -> bool {
    p.coords().iter().all(|c| (0.0..1.0).contains(c))
}

/// A valid N near `target` for a sampler in dimension d.
fn valid_n(kind: SamplerKind, d: usize, target: usize) -> usize {
    match kind {
        SamplerKind::Regular | SamplerKind::Jitter | SamplerKind::GaussianJitter => {
            let m = ((target as f64).powf(1.0 / d as f64).round() as usize).max(2);
            m.pow(d as u32)
        }
        _ => kind.nearest_count(target, d),
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
        if !kind.is_deterministic() {
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
fn cmj_and_mj_are_both_jittered_and_n_rooks() {
    let samplers: [Box<dyn Sampler>; 2] = [
        Box::new(CorrelatedMultiJitter::new(2).unwrap()),
        Box::new(MultiJitter::new(2).unwrap()),
    ];
    for (s, n) in samplers
        .iter()
        .flat_map(|s| [96usize, 64, 35].map(|n| (s, n)))
    {
        let p = s.sample(n, 5, 0).unwrap();
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

#[test]
fn fibonacci_lattice_uses_the_previous_fibonacci_number_and_refuses_other_counts() {
    let s = Rank1Lattice::new(2, LatticeRule::Fibonacci).unwrap();
    for (n, a) in [(2, 1), (3, 2), (5, 3), (89, 55), (6765, 4181)] {
        assert_eq!(s.generator(n).unwrap(), a);
    }
    match s.sample(90, 0, 0) {
        Err(Error::UnsupportedCount { nearest, .. }) => assert_eq!(nearest, "89 or 144"),
        other => panic!("{other:?}"),
    }
    assert!(Rank1Lattice::new(3, LatticeRule::Korobov).is_err());
}

/// The dual lattice's shortest vector by brute force over a box that must contain it (its
/// length is at most that of `(n, 0)`).
fn brute_shortest_dual_sq(n: u64, a: u64) -> u128 {
    let bound = (n as f64).sqrt().ceil() as i64 + 1;
    let mut best = (n as u128).pow(2);
    for k1 in -bound..=bound {
        for k0 in -(n as i64)..=(n as i64) {
            if (k0, k1) != (0, 0) && (k0 + a as i64 * k1).rem_euclid(n as i64) == 0 {
                best = best.min((k0 * k0 + k1 * k1) as u128);
            }
        }
    }
    best
}

#[test]
fn lattice_reduction_finds_the_shortest_dual_vector_and_korobov_maximizes_it() {
    for n in [7u64, 16, 55, 64, 89, 100] {
        for a in 1..n {
            assert_eq!(
                shortest_dual_vector_sq(n, a),
                brute_shortest_dual_sq(n, a),
                "{n} {a}"
            );
        }
        let korobov = Rank1Lattice::new(2, LatticeRule::Korobov).unwrap();
        let chosen = korobov.generator(n as usize).unwrap();
        let best = (1..n).map(|a| shortest_dual_vector_sq(n, a)).max().unwrap();
        assert_eq!(shortest_dual_vector_sq(n, chosen), best, "{n}");
    }
}

#[test]
fn rank1_lattices_are_groups_with_one_point_per_row_and_column() {
    for kind in [SamplerKind::Korobov, SamplerKind::Fibonacci] {
        let n = kind.nearest_count(144, 2);
        let p = kind.build(2).unwrap().sample(n, 3, 1).unwrap();
        let key = |x: &[f64]| {
            (
                (x[0] * n as f64).round() as usize,
                (x[1] * n as f64).round() as usize,
            )
        };
        let set: std::collections::HashSet<_> = (0..n).map(|i| key(p.point(i))).collect();
        for i in 0..n {
            for j in 0..n {
                let (a, b) = (key(p.point(i)), key(p.point(j)));
                assert!(set.contains(&((a.0 + b.0) % n, (a.1 + b.1) % n)), "{kind}");
            }
        }
        // x_i = i/N: one point per column; (1, a) with gcd(a, N) = 1 also one per row.
        let rows: std::collections::HashSet<_> = set.iter().map(|k| k.0).collect();
        assert_eq!(rows.len(), n);
    }
}

#[test]
fn kronecker_alpha_solves_the_generalized_golden_equation() {
    for d in 1..=4 {
        let alpha = Kronecker::new(d).unwrap().alpha();
        let phi = 1.0 / alpha[0];
        assert!((phi.powi(d as i32 + 1) - phi - 1.0).abs() < 1e-14, "{d}");
        for j in 1..d {
            assert!((alpha[j] - alpha[0].powi(j as i32 + 1)).abs() < 1e-15);
        }
    }
    // The golden ratio conjugate, to two ulps (the root and its 64-bit fraction both round).
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    assert!((Kronecker::new(1).unwrap().alpha()[0] - golden).abs() <= 2.0 * f64::EPSILON);
}

#[test]
fn gaussian_jitter_offsets_have_the_requested_width() {
    // 64 strata, 2000 realizations: 256000 offsets. Their mean square estimates w² with a
    // standard error w² √(2/n) (Gaussian offsets). An offset is recovered exactly by unwrapping
    // to the nearest copy of the cell: that fails only beyond m/2 = 4 strata, 16σ.
    let (m, realizations, w) = (8usize, 2000u64, 0.25);
    let s = GaussianJitter::new(2).unwrap().with_width(w).unwrap();
    let mut sum_sq = 0.0;
    let mut count = 0.0;
    for r in 0..realizations {
        let p = s.sample(m * m, 4, r).unwrap();
        for i in 0..m * m {
            let x = p.point(i);
            for axis in 0..2 {
                let cell = [i / m, i % m][axis] as f64;
                let mut offset = x[axis] * m as f64 - cell - 0.5;
                offset -= (offset / m as f64).round() * m as f64; // unwrap around the torus
                sum_sq += offset * offset;
                count += 1.0;
            }
        }
    }
    let variance = sum_sq / count;
    let standard_error = w * w * (2.0 / count).sqrt();
    assert!(
        (variance - w * w).abs() < 5.0 * standard_error,
        "{variance}"
    );
    assert!(GaussianJitter::new(2).unwrap().with_width(0.0).is_err());
    assert!(GaussianJitter::new(2)
        .unwrap()
        .with_width(f64::NAN)
        .is_err());
}

/// PMJ02's defining property: every prefix of `2^k` points (as one pattern of `2^k` points
/// or the first `2^k` of a longer one: the sequence is progressive) is a (0,k,2)-net, for
/// many seeds, and no seed gets stuck.
#[test]
fn pmj02_prefixes_of_powers_of_two_are_0k2_nets() {
    let s = Pmj02::new(2).unwrap();
    for realization in 0..40 {
        let long = s.sample(4096, 3, realization).unwrap();
        for k in 0..=12u32 {
            let prefix = PointSet::new(2, long.coords()[..2 << k].to_vec()).unwrap();
            assert!(
                is_0k2_net(&prefix, 0, 1, k),
                "realization {realization}, 2^{k}"
            );
        }
        // A shorter request is the prefix of the longer sequence.
        assert_eq!(
            s.sample(100, 3, realization).unwrap().coords(),
            &long.coords()[..200]
        );
    }
}

#[test]
fn gaussian_blue_noise_descends_its_energy() {
    for d in 1..=3 {
        let n = [64, 256, 512][d - 1];
        let energies: Vec<f64> = [1, 3, 10, 30, 100]
            .iter()
            .map(|&iterations| {
                let params = GbnParams {
                    iterations,
                    ..Default::default()
                };
                let s = GaussianBlueNoise::with_params(d, params).unwrap();
                s.energy(&s.sample(n, 4, 1).unwrap())
            })
            .collect();
        for w in energies.windows(2) {
            assert!(w[1] < w[0], "d={d}: energy rose: {energies:?}");
        }
        let s = GaussianBlueNoise::new(d).unwrap();
        let white = s.energy(&Random::new(d).unwrap().sample(n, 4, 1).unwrap());
        assert!(energies[4] < white, "d={d}: {energies:?} against {white}");
        if d == 1 {
            // In 1D the minimum is the regular lattice's, N Σ_{0<|m|<4c} exp(-m²/(2c²)) at width
            // c spacings (the energy counts pairs closer than 4σ); the descent from jitter
            // reaches it to within its last few steps' gain.
            let c = specvar::sampler::GbnParams::default().sigma;
            let lattice: f64 = (1..)
                .take_while(|&m| (m as f64) < 4.0 * c)
                .map(|m| 2.0 * n as f64 * (-(m * m) as f64 / (2.0 * c * c)).exp())
                .sum();
            let last_gain = energies[3] - energies[4];
            assert!(
                energies[4] >= lattice * (1.0 - 1e-12),
                "{energies:?} below {lattice}"
            );
            assert!(energies[4] - lattice < 10.0 * last_gain.max(1e-3 * lattice));
        }
    }
}

#[test]
fn gaussian_blue_noise_is_spread_and_the_same_on_any_thread_count() {
    let s = GaussianBlueNoise::new(2).unwrap();
    let p = s.sample(256, 1, 0).unwrap();
    assert!(p.min_toroidal_distance() > 0.5 * max_packing_radius(2, 256));
    let serial = s.sample(300, 2, 5).unwrap();
    let threaded = common::assert_thread_count_invariant(|| s.sample(300, 2, 5).unwrap());
    assert_eq!(serial, threaded);
}

/// Gaussian blue noise is blue noise without crystals: its spectrum stays suppressed beyond the
/// hexagonal lattice's Nyquist frequency, and its peak stays far below a lattice's Bragg
/// peaks (whose power grows with N).
#[test]
fn gaussian_blue_noise_has_a_wide_zero_region_and_no_crystal_peak() {
    use specvar::metrics::{effective_nyquist, hexagonal_nyquist};
    use specvar::spectrum::{estimate, SpectrumParams};
    let params = SpectrumParams {
        kmax: 32,
        realizations: 16,
        ..Default::default()
    };
    let e = estimate(&GaussianBlueNoise::new(2).unwrap(), 256, &params).unwrap();
    let nu = effective_nyquist(&e.radial).unwrap();
    assert!(nu > hexagonal_nyquist(), "ν_eff = {nu}");
    let peak = e.radial.bins.iter().map(|b| b.power).fold(0.0, f64::max);
    assert!(peak < 3.0, "peak {peak}");
}

/// Cached patterns are keyed by everything that shapes them: two radii of Poisson disk in the
/// same cache directory each get their own sampler's patterns.
#[test]
fn the_pattern_cache_keys_the_samplers_parameters() {
    let dir = std::env::temp_dir().join(format!("specvar-cache-params-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let narrow = PoissonDisk::new(2)
        .unwrap()
        .with_relative_radius(0.3)
        .unwrap();
    let wide = PoissonDisk::new(2)
        .unwrap()
        .with_relative_radius(0.7)
        .unwrap();
    let first = specvar::cache::DiskCached::new(Box::new(narrow), dir.clone()).unwrap();
    let second = specvar::cache::DiskCached::new(Box::new(wide), dir.clone()).unwrap();
    let a = first.sample(64, 3, 0).unwrap();
    let b = second.sample(64, 3, 0).unwrap();
    assert_eq!(a, narrow.sample(64, 3, 0).unwrap());
    assert_eq!(
        b,
        wide.sample(64, 3, 0).unwrap(),
        "the wider radius is not served the narrower's"
    );
    assert_ne!(a, b);
    // Read back from disk, each is still its own.
    let again = specvar::cache::DiskCached::new(Box::new(wide), dir.clone()).unwrap();
    assert_eq!(again.sample(64, 3, 0).unwrap(), b);
    let _ = std::fs::remove_dir_all(&dir);
}

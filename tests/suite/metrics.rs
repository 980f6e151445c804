//! Point-set measures: discrepancies against published values, the pair correlation function
//! against white noise and the regular grid, distances against the packings.

use specvar::metrics::*;
use specvar::PointSet;

/// scipy.stats.qmc.discrepancy's documented example: the six points (1,3), (2,6), (3,2),
/// (4,5), (5,1), (6,4) of a 6 × 6 Latin square scaled from [0.5, 6.5]² to the unit square,
/// i.e. `(v - 0.5)/6`. Its values (scipy 1.17): CD 0.008142039609053464, WD
/// 0.01684670781892894, L2-star 0.06833606212558091 (scipy's L2-star is the square root).
#[test]
fn discrepancies_match_scipys_published_values() {
    let raw = [
        [1.0, 3.0],
        [2.0, 6.0],
        [3.0, 2.0],
        [4.0, 5.0],
        [5.0, 1.0],
        [6.0, 4.0],
    ];
    let coords: Vec<f64> = raw.iter().flatten().map(|v| (v - 0.5) / 6.0).collect();
    let p = PointSet::new(2, coords).unwrap();
    // Six terms of a few operations each: a few ulps of the largest term (13/12)^2.
    let tolerance = 1e-15;
    let cd = squared_discrepancy(&p, DiscrepancyKind::Centred).unwrap();
    assert!((cd - 0.008142039609053464).abs() < tolerance, "{cd}");
    let wd = squared_discrepancy(&p, DiscrepancyKind::WrapAround).unwrap();
    assert!((wd - 0.01684670781892894).abs() < tolerance, "{wd}");
    let l2 = squared_discrepancy(&p, DiscrepancyKind::L2Star).unwrap();
    assert!(
        (l2.sqrt() - 0.06833606212558091).abs() < tolerance,
        "{}",
        l2.sqrt()
    );
}

/// White noise: the expected squared discrepancies have closed forms. For the wrap-around
/// one, `E[D²] = ((3/2)^d - (4/3)^d)/N`: the diagonal terms give `(3/2)^d / N`, and off the
/// diagonal `E[Π(3/2 - t(1-t))] = (4/3)^d` with `t` uniform. The mean over 400 sets is within
/// 4 standard errors (measured from the sets).
#[test]
fn white_noise_wrap_around_discrepancy_has_its_expected_value() {
    use specvar::sampler::{Random, Sampler};
    let (n, d, sets) = (64usize, 2usize, 400u64);
    let s = Random::new(d).unwrap();
    let values: Vec<f64> = (0..sets)
        .map(|r| {
            squared_discrepancy(&s.sample(n, 3, r).unwrap(), DiscrepancyKind::WrapAround).unwrap()
        })
        .collect();
    let mean = values.iter().sum::<f64>() / sets as f64;
    let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (sets as f64 - 1.0)).sqrt();
    let expected = (1.5f64.powi(d as i32) - (4.0f64 / 3.0).powi(d as i32)) / n as f64;
    assert!(
        (mean - expected).abs() < 4.0 * sd / (sets as f64).sqrt(),
        "{mean} vs {expected}"
    );
}

/// White noise: `g = 1` at every radius. The mean of 200 patterns' estimates against 1, radius
/// by radius, in the patterns' own standard errors; over 150 correlated radii a Bonferroni
/// bound at a total false-alarm rate of 1e-4 allows |z| ≤ 4.9.
#[test]
fn white_noise_pair_correlation_is_one() {
    use specvar::sampler::{Random, Sampler};
    for d in 1..=3 {
        let s = Random::new(d).unwrap();
        let patterns: Vec<_> = (0..100).map(|r| s.sample(512, 5, r).unwrap()).collect();
        let params = PcfParams {
            sigma: 0.1,
            ..PcfParams::default()
        };
        let pcf = pair_correlation(&patterns, &params).unwrap();
        for (i, (&g, &se)) in pcf.g.iter().zip(&pcf.stderr).enumerate() {
            let z = (g - 1.0) / se;
            assert!(
                z.abs() < 4.9,
                "d={d} r={}: g={g} ± {se}",
                pcf.radius_in_spacings[i]
            );
        }
    }
}

/// The square grid: no pair below the spacing, and the first shell holds exactly 4
/// neighbours: `(N - 1) ∫ g(r) 2πr dr` over the shell counts them, since `g (N - 1) 2πr dr` is
/// the mean number of other points at distance `[r, r + dr)` from a point. With σ = 0.02
/// spacings each neighbour's kernel lies within ±8σ = ±0.16 of it (the estimator ignores the
/// rest), inside its shell; the Riemann sum on radii one σ apart is exact to `exp(-2π²)`
/// ≈ 3e-9 of a Gaussian's mass, so 1e-6 is allowed.
#[test]
fn grid_pair_correlation_counts_its_neighbours() {
    use specvar::sampler::{Regular, Sampler};
    let (m, n) = (32usize, 1024usize);
    let grid = Regular::new(2).unwrap().sample(n, 0, 0).unwrap();
    let params = PcfParams {
        sigma: 0.02,
        ..PcfParams::default()
    };
    let pcf = pair_correlation(&[grid], &params).unwrap();
    let spacing = 1.0 / m as f64;
    let step = pcf.radius[1] - pcf.radius[0];
    let shell = |lo: f64, hi: f64| -> f64 {
        pcf.radius
            .iter()
            .zip(&pcf.g)
            .filter(|(r, _)| **r / spacing > lo && **r / spacing < hi)
            .map(|(r, g)| (n - 1) as f64 * g * 2.0 * std::f64::consts::PI * r * step)
            .sum()
    };
    assert!(shell(0.0, 0.8) < 1e-9, "nothing inside the spacing");
    assert!((shell(0.8, 1.2) - 4.0).abs() < 1e-6, "{}", shell(0.8, 1.2));
    assert!(
        (shell(1.2, 1.6) - 4.0).abs() < 1e-6,
        "diagonals: {}",
        shell(1.2, 1.6)
    );
}

#[test]
fn pair_correlation_refuses_what_it_cannot_measure() {
    use specvar::sampler::{Random, Sampler};
    let p = Random::new(2).unwrap().sample(16, 0, 0).unwrap();
    let wide = PcfParams {
        r_max: 3.0,
        ..PcfParams::default()
    };
    assert!(
        pair_correlation(std::slice::from_ref(&p), &wide).is_err(),
        "r_max beyond half the torus"
    );
    assert!(pair_correlation(&[], &PcfParams::default()).is_err());
    let q = Random::new(2).unwrap().sample(17, 0, 0).unwrap();
    let bad = PcfParams {
        sigma: 0.1,
        r_max: 1.0,
        radii: 10,
        ..PcfParams::default()
    };
    assert!(
        pair_correlation(&[p, q], &bad).is_err(),
        "patterns of different sizes"
    );
}

#[test]
fn hexagonal_packing_is_the_unit_of_distance() {
    use specvar::sampler::{PoissonDisk, Sampler};
    let p = PoissonDisk::new(2).unwrap().sample(1024, 1, 0).unwrap();
    let d = distances(&p).unwrap();
    // Dart throwing at relative radius 0.75 keeps every pair at least 0.75 packings apart.
    assert!(
        d.min_distance >= 0.75 - 1e-12 && d.min_distance < 0.8,
        "{d:?}"
    );
    assert!(d.mean_min_distance > d.min_distance && d.mean_min_distance < 1.0);
    assert!((hexagonal_nyquist() - 0.537284965911771).abs() < 1e-14);
}

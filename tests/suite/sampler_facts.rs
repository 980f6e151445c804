//! Every sampler's declared facts against what its patterns do: the symmetries it declares
//! (axis mirror, transpose, isotropy, scale invariance) against its estimated spectrum, with a
//! negative control for each check so that none of them passes whatever the spectrum.

use crate::common;

use specvar::prelude::*;
use specvar::sampler::{CountRule, Scaling, Symmetry};
use specvar::spectrum::LatticeSpectrum;

/// Realizations per estimate: enough that the mean periodogram at a frequency is close to
/// normal, so that a difference over its standard error is close to Student's t.
const REALIZATIONS: usize = 96;
/// Lattice extent of the estimates.
const KMAX: usize = 12;
/// How many standard deviations of the mean of z² a symmetric spectrum may reach.
const Z2_SIGMAS: f64 = 6.0;

/// The estimated spectrum of `kind` at `n` points in 2D.
fn spectrum(kind: SamplerKind, n: usize, seed: u64) -> LatticeSpectrum {
    let sampler = common::cached_sampler(kind, 2);
    let params = SpectrumParams {
        kmax: KMAX,
        realizations: REALIZATIONS,
        seed,
        ..SpectrumParams::default()
    };
    estimate(sampler.as_ref(), n, &params).unwrap().lattice
}

fn at(s: &LatticeSpectrum, k: [i64; 2]) -> (f64, f64) {
    let side = s.lattice.side() as i64;
    let kmax = s.lattice.kmax as i64;
    let flat = ((k[0] + kmax) * side + k[1] + kmax) as usize;
    (s.mean[flat], s.stderr[flat])
}

/// The mean of z² over `pairs` of frequencies, with z the difference of the two estimates over
/// its standard error, and the limit that mean may reach if the two are equal in expectation.
/// Under equality each z is close to Student's t with `M - 1` degrees of freedom:
/// `E[t²] = ν/(ν-2)`, `Var[t²] = 2ν²(ν-1)/((ν-2)²(ν-4))`; estimates of one spectrum are
/// positively correlated, which only lowers z².
fn mean_z2(a: &LatticeSpectrum, b: &LatticeSpectrum, pairs: &[([i64; 2], [i64; 2])]) -> (f64, f64) {
    let z2: Vec<f64> = pairs
        .iter()
        .map(|&(p, q)| {
            let ((x, sx), (y, sy)) = (at(a, p), at(b, q));
            (x - y).powi(2) / (sx * sx + sy * sy)
        })
        .collect();
    let nu = (REALIZATIONS - 1) as f64;
    let mean = nu / (nu - 2.0);
    let var = 2.0 * nu * nu * (nu - 1.0) / ((nu - 2.0).powi(2) * (nu - 4.0));
    let limit = mean + Z2_SIGMAS * (var / z2.len() as f64).sqrt();
    (z2.iter().sum::<f64>() / z2.len() as f64, limit)
}

/// Frequencies of the half lattice off the axes' origin, `0 < |k|`.
fn frequencies() -> Vec<[i64; 2]> {
    let k = KMAX as i64;
    (1..=k)
        .flat_map(|a| (-k..=k).map(move |b| [a, b]))
        .collect()
}

fn transposes() -> Vec<([i64; 2], [i64; 2])> {
    frequencies()
        .into_iter()
        .filter(|k| k[0] != k[1])
        .map(|k| (k, [k[1], k[0]]))
        .collect()
}

fn mirrors() -> Vec<([i64; 2], [i64; 2])> {
    frequencies()
        .into_iter()
        .filter(|k| k[1] > 0)
        .map(|k| (k, [k[0], -k[1]]))
        .collect()
}

/// Pairs of frequencies of equal length that no symmetry of the square maps onto each other.
fn equal_lengths() -> Vec<([i64; 2], [i64; 2])> {
    vec![
        ([5, 0], [3, 4]),
        ([7, 1], [5, 5]),
        ([8, 1], [7, 4]),
        ([9, 2], [7, 6]),
        ([10, 0], [8, 6]),
        ([11, 2], [10, 5]),
        ([0, 5], [4, -3]),
        ([1, 7], [5, -5]),
        ([10, 5], [11, -2]),
        ([12, 1], [9, 8]),
    ]
}

/// `k` at `n` and `2k` at `4n` have the same `ν`.
fn doubled() -> Vec<([i64; 2], [i64; 2])> {
    let h = KMAX as i64 / 2;
    (1..=h)
        .flat_map(|a| (-h..=h).map(move |b| ([a, b], [2 * a, 2 * b])))
        .collect()
}

/// A count at which every declared symmetry should show: square strata, a valid count.
fn square_count(kind: SamplerKind) -> usize {
    match kind.count_rule() {
        CountRule::PrimeSquare => 49,
        _ => kind.nearest_count(64, 2),
    }
}

fn check(name: &str, kind: SamplerKind, (z2, limit): (f64, f64)) {
    assert!(
        z2 <= limit,
        "{kind}: {name} declared, mean z² {z2:.2} > {limit:.2}"
    );
}

#[test]
fn declared_cube_symmetries_hold() {
    for kind in SamplerKind::in_dimension(2) {
        let symmetric = kind.facts().symmetry != Symmetry::Partial;
        if !symmetric || kind.is_deterministic() {
            continue;
        }
        let s = spectrum(kind, square_count(kind), 1);
        check("transpose", kind, mean_z2(&s, &s, &transposes()));
        check("axis mirror", kind, mean_z2(&s, &s, &mirrors()));
    }
}

#[test]
fn declared_isotropy_holds() {
    for kind in SamplerKind::in_dimension(2) {
        if kind.is_isotropic() {
            let s = spectrum(kind, 64, 2);
            check("isotropy", kind, mean_z2(&s, &s, &equal_lengths()));
        }
    }
}

#[test]
fn declared_scale_invariance_holds() {
    for kind in SamplerKind::in_dimension(2) {
        if kind.scaling() != Scaling::Never {
            let (a, b) = (spectrum(kind, 64, 3), spectrum(kind, 256, 4));
            check("scale invariance", kind, mean_z2(&a, &b, &doubled()));
        }
    }
}

#[test]
fn each_check_detects_a_sampler_without_the_symmetry() {
    // Rectangular strata (96 = 12 × 8) are not transposition symmetric.
    let strata = spectrum(SamplerKind::Jitter, 96, 5);
    let (z2, limit) = mean_z2(&strata, &strata, &transposes());
    assert!(z2 > limit, "transpose check blind: {z2:.2} ≤ {limit:.2}");
    // Latin hypercube: stratified along the axes, white off them.
    let lhs = spectrum(SamplerKind::LatinHypercube, 64, 6);
    let (z2, limit) = mean_z2(&lhs, &lhs, &equal_lengths());
    assert!(z2 > limit, "isotropy check blind: {z2:.2} ≤ {limit:.2}");
    // Its axes are N-strata, which change with N.
    let lhs_4n = spectrum(SamplerKind::LatinHypercube, 256, 7);
    let (z2, limit) = mean_z2(&lhs, &lhs_4n, &doubled());
    assert!(z2 > limit, "scale check blind: {z2:.2} ≤ {limit:.2}");
    // Halton's axes are different radical inverses (bases 2 and 3).
    let halton = spectrum(SamplerKind::Halton, 64, 8);
    let (z2, limit) = mean_z2(&halton, &halton, &transposes());
    assert!(z2 > limit, "Halton's axes look alike: {z2:.2} ≤ {limit:.2}");
}

#[test]
fn facts_are_consistent_with_the_samplers() {
    for kind in SamplerKind::ALL {
        let f = kind.facts();
        assert_eq!(f.name, kind.name());
        for d in f.dimensions.clone() {
            let sampler = kind.build(d).unwrap();
            assert_eq!(sampler.kind(), Some(kind));
            assert_eq!(sampler.name(), f.name);
            // The balanced counts are counts the sampler draws.
            for n in (1..=130).filter(|&n| f.balanced_counts.admits(n, d)) {
                assert!(f.count.admits(n, d), "{kind} in {d}D: balanced N = {n}");
            }
            // The count rule admits exactly what the sampler draws, on small counts.
            for n in 1..=130 {
                assert_eq!(
                    f.count.admits(n, d),
                    sampler.check_count(n).is_ok(),
                    "{kind} in {d}D at N = {n}: rule '{}'",
                    f.count
                );
            }
        }
        // A deterministic sampler draws the same pattern for every seed and realization.
        let d = *f.dimensions.start().max(&2).min(f.dimensions.end());
        let sampler = kind.build(d).unwrap();
        let n = kind.nearest_count(16, d);
        let same = sampler.sample(n, 1, 0).unwrap() == sampler.sample(n, 2, 3).unwrap();
        assert_eq!(same, kind.is_deterministic(), "{kind}");
    }
}

/// Every count rule's steps up and down agree with a walk over the counts it admits.
#[test]
fn count_rule_steps_match_a_walk() {
    let rules = [
        CountRule::Any,
        CountRule::Strata,
        CountRule::Fibonacci,
        CountRule::PrimeSquare,
        CountRule::PowerOfTwo,
    ];
    for rule in rules {
        for d in 1..=3 {
            for n in 1..=3000 {
                let up = (n..).find(|&c| rule.admits(c, d));
                let down = (1..n).rev().find(|&c| rule.admits(c, d));
                assert_eq!(rule.at_least(n, d), up, "{rule:?} d = {d}: at least {n}");
                assert_eq!(rule.below(n, d), down, "{rule:?} d = {d}: below {n}");
                let nearest = rule.nearest(n, d);
                assert!(rule.admits(nearest, d), "{rule:?} d = {d}: nearest {n}");
            }
        }
    }
    // Far up the ladders, without walking there.
    assert_eq!(
        CountRule::PowerOfTwo.at_least((1 << 40) + 1, 2),
        Some(1 << 41)
    );
    assert_eq!(
        CountRule::Strata.at_least(1_000_001, 3),
        Some(101 * 101 * 101)
    );
    assert_eq!(CountRule::PrimeSquare.below(1_000_000, 2), Some(997 * 997));
    assert_eq!(CountRule::PowerOfTwo.at_least(usize::MAX, 2), None);
}

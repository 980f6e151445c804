//! The fast engine's guarantee, `|S_fast(k) - S(k)| ≤ ε N` at every frequency for any point
//! set, checked against the direct sum across a tolerance sweep in 1, 2 and 3 dimensions, on
//! the sets that make it tight (all points at one place, where the one-point errors add
//! coherently) as well as on random ones; and the statistical tolerance's promise about `P`.

use num_complex::Complex64;
use specvar::sampler::{Random, Sampler};
use specvar::spectrum::lattice::direct_sums;
use specvar::spectrum::nufft::NufftPlan;
use specvar::spectrum::{
    engine_error, periodogram, statistical_tolerance, Engine, ENGINE_FLOOR, ENGINE_SHARE_OF_NOISE,
};
use specvar::PointSet;

use crate::common;

/// The direct sums' own rounding, relative to `N`: a few ulps per term, added over the
/// phase recurrence's length.
const DIRECT_ROUNDING: f64 = 1e-13;

const TOLERANCES: [f64; 11] = [
    1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13,
];

fn max_error_over_n(fast: &[Complex64], exact: &[Complex64], n: usize) -> f64 {
    fast.iter()
        .zip(exact)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max)
        / n as f64
}

/// `copies` points at one place: the one-point error times N, the worst case.
fn cluster(d: usize, at: &[f64], copies: usize) -> PointSet {
    PointSet::new(d, at.iter().copied().cycle().take(d * copies).collect()).unwrap()
}

fn random_offset(d: usize, seed: u64) -> Vec<f64> {
    let one = Random::new(d).unwrap().sample(1, seed, 0).unwrap();
    one.point(0).to_vec()
}

#[test]
fn the_guarantee_holds_across_a_tolerance_sweep() {
    for (d, kmax, n) in [(1, 200, 2000), (2, 24, 1500), (3, 8, 1000)] {
        let random = Random::new(d).unwrap().sample(n, 11, 0).unwrap();
        let exact_random = direct_sums(&random, kmax);
        for (i, &tolerance) in TOLERANCES.iter().enumerate() {
            let plan = NufftPlan::new(d, kmax, n, tolerance).unwrap();
            assert!(plan.error_bound() <= tolerance);
            let err = max_error_over_n(&plan.sums(&random).unwrap(), &exact_random, n);
            assert!(
                err <= tolerance + DIRECT_ROUNDING,
                "d={d} tol={tolerance:e} random: {err:e}"
            );
            // Coherent sets at several offsets: the bound holds, and is nearly reached.
            let mut worst: f64 = 0.0;
            for s in 0..8 {
                let set = cluster(d, &random_offset(d, 100 * i as u64 + s), 64);
                let err = max_error_over_n(&plan.sums(&set).unwrap(), &direct_sums(&set, kmax), 64);
                assert!(
                    err <= tolerance + DIRECT_ROUNDING,
                    "d={d} tol={tolerance:e} cluster {s}: {err:e}"
                );
                worst = worst.max(err);
            }
            // The bound is not vacuous where aliasing, not rounding, dominates.
            if plan.error_bound() > 1e-11 {
                assert!(
                    worst > plan.error_bound() / 30.0,
                    "d={d} tol={tolerance:e}: worst {worst:e} vs bound {:e}",
                    plan.error_bound()
                );
            }
        }
    }
}

#[test]
fn every_upsampling_meets_its_own_bound() {
    for (d, kmax) in [(1, 100), (2, 16), (3, 6)] {
        let set = Random::new(d).unwrap().sample(300, 5, 0).unwrap();
        let exact = direct_sums(&set, kmax);
        for sigma in specvar::spectrum::nufft::choice::UPSAMPLINGS {
            for width in [4, 8, 12, 16] {
                let plan = NufftPlan::with_kernel(d, kmax, sigma, width).unwrap();
                let err = max_error_over_n(&plan.sums(&set).unwrap(), &exact, 300);
                assert!(
                    err <= plan.error_bound() + DIRECT_ROUNDING,
                    "d={d} σ={sigma} w={width}: {err:e} > {:e}",
                    plan.error_bound()
                );
            }
        }
    }
}

#[test]
fn a_tolerance_below_reach_is_refused() {
    assert!(NufftPlan::new(2, 16, 100, 1e-15).is_err());
    assert!(NufftPlan::new(2, 16, 100, 0.5).is_err());
    assert!(NufftPlan::with_kernel(2, 16, 1.0, 8).is_err());
    assert!(NufftPlan::with_kernel(2, 16, 2.0, 40).is_err());
    assert!(NufftPlan::new(4, 16, 100, 1e-6).is_err());
    assert!(NufftPlan::new(2, 0, 100, 1e-6).is_err());
}

#[test]
fn the_statistical_tolerance_keeps_the_error_in_p_within_its_share() {
    for n in [16, 1024, 65536, 1 << 20] {
        for m in [1, 16, 256, 4096] {
            let eps = statistical_tolerance(n, m);
            let engine = Engine::Fast { tolerance: eps };
            // Every power from far below the floor to the largest possible, N.
            let mut p = 1e-14;
            while p <= n as f64 {
                let allowed = ENGINE_FLOOR.max(ENGINE_SHARE_OF_NOISE * p / (m as f64).sqrt());
                let bound = engine_error(engine, n, p);
                assert!(
                    bound <= allowed * (1.0 + 1e-12),
                    "N={n} M={m} P={p:e}: {bound:e} > {allowed:e}"
                );
                p *= 1.7;
            }
        }
    }
}

#[test]
fn the_automatic_engine_is_within_its_bound_of_the_direct_sum() {
    let set = Random::new(2).unwrap().sample(4096, 9, 0).unwrap();
    let kmax = 48;
    let engine = Engine::Auto.resolve(4096, 2, kmax, 1);
    assert!(matches!(engine, Engine::Fast { .. }), "{engine:?}");
    let fast = periodogram(&set, kmax, Engine::Auto).unwrap();
    let direct = periodogram(&set, kmax, Engine::Direct).unwrap();
    for (f, e) in fast.iter().zip(&direct) {
        let bound = engine_error(engine, 4096, *e) + common::ROUNDING;
        assert!((f - e).abs() <= bound, "{f} vs {e}: bound {bound:e}");
    }
}

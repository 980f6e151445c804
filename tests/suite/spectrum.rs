//! Spectra: engines against each other and against closed forms, with statistical bounds
//! derived from the number of realizations and lattice points.

use specvar::sampler::*;
use specvar::spectrum::lattice::{naive_periodogram, Lattice};
use specvar::spectrum::*;

use crate::common;

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn direct_engine_matches_the_naive_sum() {
    for (d, n, k) in [(1, 300, 40), (2, 256, 12), (3, 64, 5)] {
        let p = Random::new(d).unwrap().sample(n, 1, 0).unwrap();
        let direct = periodogram(&p, k, Engine::Direct).unwrap();
        let naive = naive_periodogram(&p, k);
        assert!(max_abs_diff(&direct, &naive) < 1e-9, "d={d}");
    }
}

#[test]
fn fast_engine_at_its_default_matches_direct_within_1e_8() {
    for (d, n, k) in [
        (1, 65536, 300),
        (2, 65536, 24),
        (2, 4096, 100),
        (3, 8192, 8),
    ] {
        let p = Random::new(d).unwrap().sample(n, 2, 0).unwrap();
        let direct = periodogram(&p, k, Engine::Direct).unwrap();
        let fast = periodogram(&p, k, Engine::fast()).unwrap();
        let err = max_abs_diff(&direct, &fast);
        assert!(err <= 1e-8, "d={d} n={n} K={k}: {err:e}");
    }
}

#[test]
fn fast_engine_error_follows_its_tolerance() {
    let p = Random::new(2).unwrap().sample(2000, 3, 0).unwrap();
    let direct = periodogram(&p, 30, Engine::Direct).unwrap();
    let engine = Engine::Fast { tolerance: 1e-4 };
    let loose = periodogram(&p, 30, engine).unwrap();
    // |δS| ≤ εN gives |δP| ≤ 2ε√(NP) + ε²N at every frequency; a loose tolerance shows.
    let mut largest: f64 = 0.0;
    for (f, e) in loose.iter().zip(&direct) {
        assert!((f - e).abs() <= engine_error(engine, 2000, *e) + common::ROUNDING);
        largest = largest.max((f - e).abs());
    }
    assert!(largest > 1e3 * common::ROUNDING, "{largest:e}");
}

#[test]
fn dc_is_n_and_the_spectrum_is_symmetric() {
    let p = Jitter::new(2).unwrap().sample(64, 4, 0).unwrap();
    for engine in [Engine::Direct, Engine::fast()] {
        let v = periodogram(&p, 10, engine).unwrap();
        let lattice = Lattice {
            dimension: 2,
            kmax: 10,
        };
        assert_eq!(v[lattice.dc_index()], 64.0);
        for i in 0..v.len() {
            assert!((v[i] - v[v.len() - 1 - i]).abs() < 1e-9);
        }
    }
}

#[test]
fn regular_grid_has_power_only_at_multiples_of_m() {
    let m = 6;
    let p = Regular::new(2).unwrap().sample(m * m, 0, 0).unwrap();
    let lattice = Lattice {
        dimension: 2,
        kmax: 20,
    };
    for engine in [Engine::Direct, Engine::fast()] {
        let v = periodogram(&p, 20, engine).unwrap();
        for (i, &value) in v.iter().enumerate() {
            let k = lattice.frequency(i);
            if k[0] % m as i64 == 0 && k[1] % m as i64 == 0 {
                assert!((value - 36.0).abs() < 1e-8, "{k:?}: {value}");
            } else {
                assert!(value.abs() < 1e-8, "{k:?}: {value}");
            }
        }
    }
}

/// White noise: `P(k)` has mean 1 and variance `1 - 1/N`; `P(k) = P(-k)`, so a ring of `c`
/// lattice points holds `c/2` distinct values, nearly uncorrelated (covariance O(1/N)). The
/// ring mean over M realizations then has standard deviation `√(2 / (M c))`.
#[test]
fn white_noise_rings_agree_with_one_within_the_derived_bound() {
    for d in 1..=3 {
        let m = 48;
        let params = SpectrumParams {
            kmax: if d == 3 { 8 } else { 24 },
            realizations: m,
            seed: 5,
            ..Default::default()
        };
        let est = estimate(&Random::new(d).unwrap(), 512, &params).unwrap();
        for b in &est.radial.bins {
            let sd = (2.0 / (m as f64 * b.count as f64)).sqrt();
            assert!(
                (b.power - 1.0).abs() < common::Z_STRICT * sd,
                "d={d} ring {}: {}",
                b.rho,
                b.power
            );
        }
        assert!((est.radial.dc_limit - 1.0).abs() < 0.5);
    }
}

#[test]
fn white_noise_anisotropy_is_minus_ten_log_m() {
    // The expected spectrum over M realizations varies over a ring with variance ≈ 1/M (the
    // per-value variance 1 over M), so the anisotropy is ≈ -10 log10 M dB. With c/2 ≥ 150
    // distinct values the relative error of the ring variance is ≤ √(2/150) ≈ 0.12, i.e.
    // ±0.5 dB at one sigma; we allow 5 sigma (2.5 dB).
    let m = 32;
    let params = SpectrumParams {
        kmax: 64,
        realizations: m,
        seed: 2,
        ..Default::default()
    };
    let est = estimate(&Random::new(2).unwrap(), 1024, &params).unwrap();
    let expected = -10.0 * (m as f64).log10();
    for b in est.radial.bins.iter().filter(|b| b.count >= 300) {
        assert!(
            (b.anisotropy_db - expected).abs() < 2.5,
            "{}: {}",
            b.rho,
            b.anisotropy_db
        );
    }
}

/// Jitter against its closed form `1 - Π sinc²(π k_i / m)`: each ring's mean of the closed
/// form lies within 5 standard errors (estimated across M = 64 realizations) of the estimate.
#[test]
fn jitter_rings_agree_with_the_closed_form() {
    // 96 = 12 × 8: rectangular strata, whose closed form uses k_x / 12 and k_y / 8.
    for (d, n, kmax) in [
        (1usize, 64usize, 100usize),
        (2, 256, 40),
        (2, 96, 40),
        (3, 512, 12),
    ] {
        let params = SpectrumParams {
            kmax,
            realizations: 64,
            seed: 8,
            ..Default::default()
        };
        let est = estimate(&Jitter::new(d).unwrap(), n, &params).unwrap();
        let lattice = est.lattice.lattice;
        // Ring means of the closed form over the same lattice points.
        let mut sums = vec![(0.0, 0usize); est.radial.bins.len() + kmax + 2];
        let closed_form = ClosedForm::Jitter.on_lattice(n, d, kmax);
        for i in 0..lattice.len() {
            if i == lattice.dc_index() || lattice.radius(i) >= kmax as f64 {
                continue;
            }
            let k = lattice.frequency(i);
            let ring = lattice.radius(i).floor() as usize;
            sums[ring].0 += closed_form.power(&k[..d]);
            sums[ring].1 += 1;
        }
        for b in &est.radial.bins {
            let ring = b.rho.floor() as usize;
            let closed = sums[ring].0 / sums[ring].1 as f64;
            assert!(
                (b.power - closed).abs() <= common::Z_STRICT * b.stderr + common::ROUNDING,
                "d={d} ring {ring}: {} vs {closed} ± {}",
                b.power,
                b.stderr
            );
        }
        assert!(est.radial.dc_limit < 0.05, "d={d}: {}", est.radial.dc_limit);
    }
}

#[test]
fn jitter_radial_closed_form_matches_a_brute_force_angular_mean() {
    // Independent route: the mean over many equally spaced angles (2D) or a fine
    // latitude-longitude grid (3D) of 1 - Π sinc².
    for nu in [0.1, 0.7, 1.3, 3.7] {
        let steps = 20000;
        let brute2: f64 = (0..steps)
            .map(|i| {
                let t = std::f64::consts::TAU * (i as f64 + 0.5) / steps as f64;
                ClosedForm::Jitter
                    .power(&[nu * t.cos(), nu * t.sin()])
                    .unwrap()
            })
            .sum::<f64>()
            / steps as f64;
        assert!(
            (ClosedForm::Jitter.radial(2, nu).unwrap() - brute2).abs() < 1e-9,
            "2D ν={nu}"
        );
        let (nt, np) = (600, 600);
        let mut brute3 = 0.0;
        for i in 0..nt {
            let u = -1.0 + 2.0 * (i as f64 + 0.5) / nt as f64;
            let s = (1.0 - u * u).sqrt();
            for j in 0..np {
                let phi = std::f64::consts::TAU * (j as f64 + 0.5) / np as f64;
                brute3 += ClosedForm::Jitter
                    .power(&[nu * s * phi.cos(), nu * s * phi.sin(), nu * u])
                    .unwrap();
            }
        }
        brute3 /= (nt * np) as f64;
        assert!(
            (ClosedForm::Jitter.radial(3, nu).unwrap() - brute3).abs() < 1e-5,
            "3D ν={nu}"
        );
    }
    assert_eq!(
        ClosedForm::Jitter.radial(1, 0.5),
        Some(1.0 - (2.0 / std::f64::consts::PI).powi(2))
    );
}

#[test]
fn rings_report_mean_radius_and_counts() {
    let params = SpectrumParams {
        kmax: 10,
        realizations: 2,
        ..Default::default()
    };
    let est = estimate(&Random::new(2).unwrap(), 100, &params).unwrap();
    let lattice = est.lattice.lattice;
    let ring3: Vec<f64> = (0..lattice.len())
        .map(|i| lattice.radius(i))
        .filter(|r| (3.0..4.0).contains(r))
        .collect();
    let bin = est
        .radial
        .bins
        .iter()
        .find(|b| b.rho >= 3.0 && b.rho < 4.0)
        .unwrap();
    assert_eq!(bin.count, ring3.len());
    let mean = ring3.iter().sum::<f64>() / ring3.len() as f64;
    assert!((bin.rho - mean).abs() < common::ROUNDING);
    assert!((bin.nu - mean / 10.0).abs() < common::ROUNDING);
    // Only complete rings: the outer radius stays within K.
    assert!(est.radial.bins.iter().all(|b| b.rho < 10.0));
}

#[test]
fn poisson_disk_has_a_low_plateau_and_a_peak() {
    let params = SpectrumParams {
        kmax: 80,
        realizations: 16,
        seed: 1,
        ..Default::default()
    };
    let est = estimate(&PoissonDisk::new(2).unwrap(), 1024, &params).unwrap();
    let low: Vec<f64> = est
        .radial
        .bins
        .iter()
        .filter(|b| b.nu < 0.3)
        .map(|b| b.power)
        .collect();
    let mean_low = low.iter().sum::<f64>() / low.len() as f64;
    // Blue noise: a positive plateau well below white noise at low frequency…
    assert!(mean_low > 0.02 && mean_low < 0.3, "plateau {mean_low}");
    // …and a peak above 1 near the packing frequency (ν ≈ 1).
    let peak = est
        .radial
        .bins
        .iter()
        .max_by(|a, b| a.power.total_cmp(&b.power))
        .unwrap();
    assert!(
        peak.power > 1.2 && (0.8..1.4).contains(&peak.nu),
        "{peak:?}"
    );
}

#[test]
fn ccvt_has_near_zero_power_below_its_cutoff() {
    let params = SpectrumParams {
        kmax: 48,
        realizations: 4,
        seed: 1,
        ..Default::default()
    };
    let est = estimate(&Ccvt::new(2).unwrap(), 1024, &params).unwrap();
    for b in est.radial.bins.iter().filter(|b| b.nu < 0.45) {
        assert!(b.power < 0.05, "{b:?}");
    }
    assert!(est.radial.bins.iter().any(|b| b.power > 1.2));
}

#[test]
fn estimates_do_not_depend_on_thread_count() {
    let params = SpectrumParams {
        kmax: 12,
        realizations: 10,
        seed: 3,
        ..Default::default()
    };
    let sampler = Jitter::new(2).unwrap();
    common::assert_thread_count_invariant(|| estimate(&sampler, 64, &params).unwrap());
}

#[test]
fn imported_point_sets_give_the_same_estimate() {
    let sampler = PoissonDisk::new(2).unwrap();
    let sets: Vec<_> = (0..6).map(|r| sampler.sample(200, 9, r).unwrap()).collect();
    let text = specvar::io::write_text(&sets);
    let read = specvar::io::read_text(&text).unwrap();
    let params = SpectrumParams {
        kmax: 16,
        realizations: 6,
        seed: 9,
        engine: Engine::Direct,
        ..Default::default()
    };
    let from_file = estimate_from_sets(&read, &params).unwrap();
    let direct = estimate(&sampler, 200, &params).unwrap();
    assert_eq!(from_file.lattice.mean, direct.lattice.mean);
}

#[test]
fn bad_spectrum_requests_are_errors() {
    let p = Random::new(4).unwrap().sample(10, 0, 0).unwrap();
    assert!(periodogram(&p, 4, Engine::Direct).is_err());
    let q = Random::new(2).unwrap().sample(10, 0, 0).unwrap();
    assert!(periodogram(&q, 0, Engine::Direct).is_err());
    assert!(periodogram(&q, 4, Engine::Fast { tolerance: 0.5 }).is_err());
    let params = SpectrumParams {
        realizations: 0,
        ..Default::default()
    };
    assert!(estimate(&Random::new(2).unwrap(), 10, &params).is_err());
    assert!(estimate_from_sets(&[], &SpectrumParams::default()).is_err());
}

/// CCVT's low band is `a ν² + b ν⁴` with the floor `a = π²/(3c²)` set by the discrete density's
/// capacity c (derived in `Ccvt::floor_coefficient`): fitted at N = 1024 (cN = 128² and 256²,
/// so no cell is dropped) for c = 16 and 64, each `a` within 4 of its standard errors of the
/// derivation, and the band `b` positive beyond 4 standard errors. So the estimator finds what
/// the sampler has, and the sampler's α is 2, not 4.
#[test]
fn ccvt_low_band_is_the_discrete_density_floor_under_a_nu4_band() {
    for capacity in [16usize, 64] {
        let ccvt = Ccvt::new(2)
            .unwrap()
            .with_params(CcvtParams {
                capacity,
                ..Default::default()
            })
            .unwrap();
        let params = SpectrumParams {
            kmax: 16,
            realizations: 32,
            seed: 4,
            ..Default::default()
        };
        let est = estimate(&common::kept_on_disk(Box::new(ccvt)), 1024, &params).unwrap();
        let fit = specvar::rate::fit_low_band(&est.radial, 0.3).unwrap();
        let a = ccvt.floor_coefficient();
        assert!(
            (fit.floor - a).abs() < common::Z_LOOSE * fit.floor_stderr,
            "c={capacity}: {fit:?}, derived {a:e}"
        );
        assert!(
            fit.band > common::Z_LOOSE * fit.band_stderr,
            "c={capacity}: {fit:?}"
        );
    }
}

/// A deterministic pattern's periodogram is its expected spectrum: the rank-1 lattices' must be
/// N on the dual lattice and 0 elsewhere, the Kronecker sequence's the Fejér kernel, to the
/// direct engine's rounding (N ulps of a sum of N unit terms).
#[test]
fn lattices_and_kronecker_spectra_are_their_closed_forms() {
    let kmax = 40;
    let lattice = Lattice { dimension: 2, kmax };
    for kind in [
        SamplerKind::Korobov,
        SamplerKind::Fibonacci,
        SamplerKind::Kronecker,
    ] {
        let n = kind.nearest_count(233, 2);
        let sampler = kind.build(2).unwrap();
        let closed = sampler.closed_form(n).unwrap().on_lattice(n, 2, kmax);
        let p = sampler.sample(n, 0, 0).unwrap();
        let direct = periodogram(&p, kmax, Engine::Direct).unwrap();
        let tolerance = 64.0 * n as f64 * f64::EPSILON * n as f64;
        let mut peaks = 0;
        for (i, &value) in direct.iter().enumerate() {
            let k = lattice.frequency(i);
            let expected = closed.power(&k);
            assert!(
                (value - expected).abs() < tolerance,
                "{kind} {k:?}: {value} vs {expected}"
            );
            peaks += usize::from(expected > 0.5 * n as f64);
        }
        assert!(peaks > 1, "{kind}: the lattice shows more peaks than DC");
    }
}

/// Gaussian jitter's closed form against the mean of 3000 periodograms, frequency by
/// frequency: each mean has a standard error s/√M from the realizations themselves, and over
/// the 312 independent frequencies (P(k) = P(-k)) a Bonferroni bound at a total false-alarm
/// rate of 1e-4 allows |z| ≤ 5.1.
#[test]
fn gaussian_jitter_mean_spectrum_is_its_closed_form() {
    let (n, kmax, realizations) = (64usize, 12usize, 3000u64);
    for width in [0.1, 0.25, 0.6] {
        let s = GaussianJitter::new(2).unwrap().with_width(width).unwrap();
        let closed = s.closed_form(n).unwrap().on_lattice(n, 2, kmax);
        let lattice = Lattice { dimension: 2, kmax };
        let runs: Vec<Vec<f64>> = (0..realizations)
            .map(|r| {
                let mut p = s.sample(n, 8, r).unwrap();
                homogenize(&mut p, 8, r);
                periodogram(&p, kmax, Engine::Direct).unwrap()
            })
            .collect();
        for i in 0..lattice.len() {
            let k = lattice.frequency(i);
            if k.iter().all(|&c| c == 0) {
                continue;
            }
            let m = realizations as f64;
            let mean = runs.iter().map(|r| r[i]).sum::<f64>() / m;
            let var = runs.iter().map(|r| (r[i] - mean).powi(2)).sum::<f64>() / (m - 1.0);
            let expected = closed.power(&k);
            let z = (mean - expected) / (var / m).sqrt().max(1e-12);
            assert!(
                z.abs() < 5.1,
                "w={width} {k:?}: {mean} vs {expected} (z={z:.2})"
            );
        }
    }
}

/// Sector spectra of an exactly known spectrum (Latin hypercube's closed form at N = 64): each
/// sector's mean is the brute-force mean of the closed form over the lattice points of the half
/// plane in that ring and direction, and the axis sectors hold 1D jitter's deep notch.
#[test]
fn sector_spectra_average_the_right_frequencies() {
    let (n, kmax, sectors, width) = (64usize, 24usize, 6usize, 3.0);
    let lattice = Lattice { dimension: 2, kmax };
    let closed = ClosedForm::LatinHypercube.on_lattice(n, 2, kmax);
    let mean: Vec<f64> = (0..lattice.len())
        .map(|i| closed.power(&lattice.frequency(i)[..2]))
        .collect();
    let spectrum = LatticeSpectrum {
        lattice,
        n,
        realizations: 1,
        engine: Engine::Direct,
        stderr: vec![0.0; mean.len()],
        mean,
    };
    let s = sector_spectrum(&spectrum, sectors, width).unwrap();
    for (b, ring) in s.rings.iter().enumerate() {
        for sector in 0..sectors {
            let (mut sum, mut count) = (0.0, 0usize);
            for k1 in 0..=kmax as i64 {
                for k0 in -(kmax as i64)..=kmax as i64 {
                    if k1 == 0 && k0 <= 0 {
                        continue;
                    }
                    let r = ((k0 * k0 + k1 * k1) as f64).sqrt();
                    let angle = (k1 as f64).atan2(k0 as f64).to_degrees();
                    let inside = (r / width).floor() as usize == b
                        && ((angle / 180.0 * sectors as f64) as usize).min(sectors - 1) == sector;
                    if inside {
                        sum += closed.power(&[k0, k1]);
                        count += 1;
                    }
                }
            }
            assert_eq!(ring.count[sector], count);
            if count > 0 {
                assert!((ring.power[sector] - sum / count as f64).abs() < 1e-12);
            }
        }
    }
    // The first ring's 0° sector holds only points near the k_0 axis, where N-rooks is
    // 1D jitter of 64 strata: far below white.
    assert!(s.rings[1].power[0] < s.rings[1].power[1]);
    assert!(sector_spectrum(&spectrum, 0, 1.0).is_err());
}

/// An estimate extended in uneven steps is the same bits as one reached in a single call, and
/// so are its weighted sums: each realization joins the sums after the ones before it.
#[test]
fn an_estimate_extended_in_steps_is_the_same_bits() {
    let sampler = Jitter::new(2).unwrap();
    let params = SpectrumParams {
        kmax: 12,
        realizations: 11,
        seed: 5,
        ..Default::default()
    };
    let source = PatternSource::Sampler {
        sampler: &sampler,
        n: 64,
        seed: 5,
    };
    let side = 2 * params.kmax + 1;
    let weights = vec![(0..side * side).map(|i| (i % 7) as f64).collect::<Vec<_>>()];
    let silent = specvar::progress::Silent;
    let mut once = SpectrumAccumulator::new(source, &params, weights.clone()).unwrap();
    once.extend_to(11, &silent).unwrap();
    let mut steps = SpectrumAccumulator::new(source, &params, weights).unwrap();
    for target in [1, 3, 3, 2, 7, 11] {
        steps.extend_to(target, &silent).unwrap();
    }
    assert_eq!(steps.realizations(), 11);
    let bits = |e: &SpectrumEstimate, w: &[WeightedMean]| {
        let lattice = e.lattice.mean.iter().chain(&e.lattice.stderr);
        let rings = e.radial.bins.iter().flat_map(|b| [b.power, b.stderr]);
        let weighted = w.iter().flat_map(|w| [w.mean, w.stderr]);
        lattice
            .copied()
            .chain(rings)
            .chain(weighted)
            .map(f64::to_bits)
            .collect::<Vec<_>>()
    };
    assert_eq!(
        bits(&once.estimate(), &once.weighted()),
        bits(&steps.estimate(), &steps.weighted())
    );
}

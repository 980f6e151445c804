//! Spectrum engines at N = 4096 in 2D, K = 320 (a 641 × 641 lattice), one realization each:
//! the fast engine (NUFFT) against the direct engine (phase recurrence), and the direct engine
//! against a per-term sin/cos DFT (at N = 256: both costs are linear in N, so the ratio holds).
//! Also one NUFFT transform with a reused plan at tolerance 1e-9 for the rows of the FINUFFT
//! comparison (`benches/compare/vs_finufft.py`). Run: `cargo bench --bench spectrum`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use num_complex::Complex64;
use specvar::sampler::{Random, Sampler};
use specvar::spectrum::lattice::naive_periodogram;
use specvar::spectrum::nufft::NufftPlan;
use specvar::spectrum::{periodogram, Engine};
use std::hint::black_box;
use std::time::Duration;

fn engines(c: &mut Criterion) {
    let points = Random::new(2).unwrap().sample(4096, 7, 0).unwrap();
    let small = Random::new(2).unwrap().sample(256, 7, 0).unwrap();
    let mut g = c.benchmark_group("spectrum_2d_k320");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    g.bench_function("fast_n4096", |b| {
        b.iter(|| black_box(periodogram(&points, 320, Engine::fast()).unwrap()))
    });
    g.bench_function("direct_n4096", |b| {
        b.iter(|| black_box(periodogram(&points, 320, Engine::Direct).unwrap()))
    });
    g.bench_function("direct_n256", |b| {
        b.iter(|| black_box(periodogram(&small, 320, Engine::Direct).unwrap()))
    });
    g.bench_function("naive_sincos_n256", |b| {
        b.iter(|| black_box(naive_periodogram(&small, 320)))
    });
    g.finish();

    // One transform with a reused plan and scratch, at the table's rows and tolerance 1e-9.
    let mut g = c.benchmark_group("nufft_1e-9");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    for (d, n, kmax) in [(2, 4096, 320), (2, 65536, 1280), (3, 32768, 40)] {
        let points = Random::new(d).unwrap().sample(n, 3, 0).unwrap();
        let plan = NufftPlan::new(d, kmax, n, 1e-9).unwrap();
        let mut scratch = plan.make_scratch();
        let mut sums = vec![Complex64::new(0.0, 0.0); plan.output_len()];
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(format!("{d}d_n{n}_k{kmax}"), |b| {
            b.iter(|| plan.sums_with_scratch(black_box(&points), &mut scratch, &mut sums))
        });
    }
    g.finish();
}

criterion_group!(benches, engines);
criterion_main!(benches);

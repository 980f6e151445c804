//! Spectrum engines at N = 4096 in 2D, K = 320 (a 641 × 641 lattice), one realization each:
//! the fast engine (NUFFT) against the direct engine (phase recurrence), and the direct engine
//! against a per-term sin/cos DFT (at N = 256: both costs are linear in N, so the ratio holds).
//! Also the NUFFT's spreading rate. Run: `cargo bench --bench spectrum`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use specvar::sampler::{Random, Sampler};
use specvar::spectrum::lattice::naive_periodogram;
use specvar::spectrum::nufft::{NufftPlan, DEFAULT_TOLERANCE};
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

    let plan = NufftPlan::new(2, 320, DEFAULT_TOLERANCE).unwrap();
    let mut grid = vec![0.0; plan.grid_size() * plan.grid_size()];
    let many = Random::new(2).unwrap().sample(65536, 3, 0).unwrap();
    let mut g = c.benchmark_group("nufft_spreading");
    g.throughput(Throughput::Elements(65536));
    g.sample_size(20);
    g.bench_function("spread_65536_points_w15", |b| {
        b.iter(|| plan.spread(black_box(&many), &mut grid))
    });
    g.finish();
}

criterion_group!(benches, engines);
criterion_main!(benches);

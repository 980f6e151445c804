//! Monte Carlo throughput: estimator evaluations per second, jitter on the disk at N = 4096
//! (pattern generation, homogenization and N integrand evaluations per estimate).
//! Run: `cargo bench --bench montecarlo`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use specvar::integrand::Ball;
use specvar::montecarlo::{empirical_variance, McParams};
use specvar::sampler::Jitter;
use std::hint::black_box;

fn throughput(c: &mut Criterion) {
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let jitter = Jitter::new(2).unwrap();
    let params = McParams {
        patterns: 1000,
        ..Default::default()
    };
    let mut g = c.benchmark_group("montecarlo");
    g.throughput(Throughput::Elements(1000));
    g.sample_size(10);
    g.bench_function("jitter_disk_n4096_1000_estimates", |b| {
        b.iter(|| black_box(empirical_variance(&jitter, &disk, 4096, &params).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, throughput);
criterion_main!(benches);

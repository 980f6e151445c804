//! Sampler speed: Poisson disk (target ≤ 20 ms for 4096 points in 2D), CCVT (≤ 1 s for
//! 1024, ≤ 10 s for 4096), PMJ02 (Pharr reports 5.19 ms for 4096 points on one 4 GHz core),
//! and the lattices. Run: `cargo bench --bench samplers`.

use criterion::{criterion_group, criterion_main, Criterion};
use specvar::sampler::{Ccvt, Jitter, PoissonDisk, PoissonMethod, Random, Sampler, SamplerKind};
use std::hint::black_box;
use std::time::Duration;

fn samplers(c: &mut Criterion) {
    let mut g = c.benchmark_group("samplers_2d");
    g.sample_size(20);
    let dart = PoissonDisk::new(2).unwrap();
    let bridson = PoissonDisk::new(2)
        .unwrap()
        .with_method(PoissonMethod::Bridson);
    let mut r = 0u64;
    g.bench_function("poisson_dart_4096", |b| {
        b.iter(|| {
            r += 1;
            black_box(dart.sample(4096, 1, r).unwrap())
        })
    });
    g.bench_function("poisson_bridson_4096", |b| {
        b.iter(|| {
            r += 1;
            black_box(bridson.sample(4096, 1, r).unwrap())
        })
    });
    g.bench_function("jitter_4096", |b| {
        b.iter(|| black_box(Jitter::new(2).unwrap().sample(4096, 1, 0).unwrap()))
    });
    g.bench_function("random_4096", |b| {
        b.iter(|| black_box(Random::new(2).unwrap().sample(4096, 1, 0).unwrap()))
    });
    for kind in [
        SamplerKind::Pmj02,
        SamplerKind::GaussianJitter,
        SamplerKind::Korobov,
        SamplerKind::Kronecker,
        SamplerKind::Sobol,
        SamplerKind::Halton,
    ] {
        let sampler = kind.build(2).unwrap();
        g.bench_function(format!("{kind}_4096"), |b| {
            b.iter(|| {
                r += 1;
                black_box(sampler.sample(4096, 1, r).unwrap())
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("ccvt_2d");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    let ccvt = Ccvt::new(2).unwrap();
    g.bench_function("ccvt_1024", |b| {
        b.iter(|| black_box(ccvt.sample(1024, 1, 0).unwrap()))
    });
    g.bench_function("ccvt_4096", |b| {
        b.iter(|| black_box(ccvt.sample(4096, 1, 0).unwrap()))
    });
    g.finish();
    let mut g = c.benchmark_group("gbn_2d");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    let gbn = SamplerKind::GaussianBlueNoise.build(2).unwrap();
    for n in [1024, 4096] {
        g.bench_function(format!("gbn_{n}"), |b| {
            b.iter(|| black_box(gbn.sample(n, 1, 0).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, samplers);
criterion_main!(benches);

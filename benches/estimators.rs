//! What a prediction of the unshifted estimator costs beside one of the shifted estimator, for
//! the same sampler, integrand and N: the cell form (exact for jitter, its occupancy estimated
//! for multi-jitter and Sobol') against the spectral route the shift takes. The ratios are in
//! `docs/performance.md`. Run: `cargo bench --bench estimators`.

use criterion::{criterion_group, criterion_main, Criterion};
use specvar::integrand::Polygon;
use specvar::predict::{predict, PredictParams, Problem};
use specvar::randomization::Randomization;
use specvar::sampler::SamplerKind;
use std::hint::black_box;

fn estimators(c: &mut Criterion) {
    let edge = Polygon::edge(30.0, 0.4, 1.0).unwrap();
    let params = PredictParams::default();
    let mut g = c.benchmark_group("estimators");
    g.sample_size(10);
    for kind in [
        SamplerKind::Jitter,
        SamplerKind::MultiJitter,
        SamplerKind::Sobol,
    ] {
        let sampler = kind.build(2).unwrap();
        for n in [256, 1024] {
            for r in [Randomization::Shift, Randomization::None] {
                let problem = Problem::new(sampler.as_ref(), &edge, n)
                    .unwrap()
                    .with_randomization(r);
                g.bench_function(format!("{kind}_edge_n{n}_{r}"), |b| {
                    b.iter(|| black_box(predict(&problem, &params).unwrap().variance))
                });
            }
        }
    }
    g.finish();
}

criterion_group!(benches, estimators);
criterion_main!(benches);

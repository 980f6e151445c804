//! What a prediction of the unshifted estimator costs beside one of the shifted estimator, for
//! the same sampler, integrand and N: the cell form (the per-stratum form for jitter, the pairs
//! of cells of Latin hypercube, multi-jitter and CMJ, Owen's gains for Sobol' and PMJ02, the
//! aliased pairs of Gaussian jitter) against the route the shift takes. The ratios are in
//! `docs/performance.md`. Run: `cargo bench --bench estimators`.

use criterion::{criterion_group, criterion_main, Criterion};
use specvar::integrand::{Ball, Integrand, Polygon};
use specvar::predict::{predict, PredictParams, Problem};
use specvar::randomization::Randomization;
use specvar::sampler::SamplerKind;
use std::hint::black_box;

fn estimators(c: &mut Criterion) {
    let integrands: [(&str, Box<dyn Integrand>); 2] = [
        ("edge", Box::new(Polygon::edge(30.0, 0.4, 1.0).unwrap())),
        (
            "disk",
            Box::new(Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap()),
        ),
    ];
    let params = PredictParams::default();
    let mut g = c.benchmark_group("estimators");
    g.sample_size(10);
    for kind in [
        SamplerKind::Jitter,
        SamplerKind::GaussianJitter,
        SamplerKind::LatinHypercube,
        SamplerKind::MultiJitter,
        SamplerKind::Cmj,
        SamplerKind::OrthogonalArray,
        SamplerKind::Sobol,
        SamplerKind::Pmj02,
    ] {
        let sampler = kind.build(2).unwrap();
        for n in kind.nearest_counts(&[1024, 4096], 2) {
            for (name, f) in &integrands {
                for r in [Randomization::Shift, Randomization::None] {
                    let problem = Problem::new(sampler.as_ref(), f.as_ref(), n)
                        .unwrap()
                        .with_randomization(r);
                    g.bench_function(format!("{kind}_{name}_n{n}_{r}"), |b| {
                        b.iter(|| black_box(predict(&problem, &params).unwrap().variance))
                    });
                }
            }
        }
    }
    g.finish();
}

criterion_group!(benches, estimators);
criterion_main!(benches);

//! Rendering: secondary rays per second (jitter, 96 rays per pixel), one pixel's visibility
//! grid (64² rays), and that grid's power on the prediction's lattice (FFT + |k_i| ≤ 64).
//! Run: `cargo bench --bench render`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use specvar::predict::LatticePower;
use specvar::render::geometry::Scene;
use specvar::render::{render_ao, Frame, RenderParams};
use specvar::sampler::Jitter;
use specvar::spectrum::Lattice;
use std::hint::black_box;

fn render(c: &mut Criterion) {
    let frame = Frame::new(Scene::cornell_box(), 32, 32).unwrap();
    let jitter = Jitter::new(2).unwrap();
    let params = RenderParams::default();
    let mut g = c.benchmark_group("render");
    g.sample_size(10);
    g.throughput(Throughput::Elements((32 * 32 * params.rays) as u64));
    g.bench_function("ao_32x32_jitter_96_rays", |b| {
        b.iter(|| {
            black_box(render_ao(&frame, &jitter, &params, &specvar::progress::Silent).unwrap())
        })
    });
    // A pixel on the floor near the blocks: a visibility with several occluders.
    let point = *frame.point(32 * 28 + 12).unwrap();
    g.throughput(Throughput::Elements(64 * 64));
    g.bench_function("visibility_grid_64", |b| {
        b.iter(|| black_box(point.visibility_grid(frame.scene(), 64, 0.5).unwrap()))
    });
    let grid = point.visibility_grid(frame.scene(), 64, 0.5).unwrap();
    let lattice = Lattice {
        dimension: 2,
        kmax: 64,
    };
    g.throughput(Throughput::Elements(lattice.len() as u64));
    g.bench_function("lattice_power_k64", |b| {
        b.iter(|| black_box(LatticePower::of(&grid, lattice).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, render);
criterion_main!(benches);

//! The polar integral's quadrature: accuracy against an exact reference, function evaluations
//! and time, for three rules on the same integral. Run: `cargo bench --bench quadrature`.
//!
//! The integral is `2π ∫_0^L ρ P̆_f(ρ) dρ` for the disk of radius 1/4 (height 1), L = 200: 100
//! oscillations of J1². Its exact value is `∫f² - π R² (J0(t)² + J1(t)²)` at `t = 2πRL` by the
//! Bessel identity `d/dt [J0² + J1²] = -2 J1²/t` (docs/theory.md), so the reference costs nothing.

use criterion::{criterion_group, criterion_main, Criterion};
use specvar::integrand::{Ball, Integrand};
use specvar::quadrature::{integrate_panels, panel_breakpoints, GaussLegendre};
use std::f64::consts::PI;
use std::hint::black_box;

const L: f64 = 200.0;

fn setup() -> (Ball, f64) {
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let t = 2.0 * PI * 0.25 * L;
    let exact =
        disk.integral_of_square() - PI * 0.0625 * (libm::j0(t).powi(2) + libm::j1(t).powi(2));
    (disk, exact)
}

fn integrand(disk: &Ball) -> impl Fn(f64) -> f64 + '_ {
    move |r: f64| 2.0 * PI * r * disk.radial_power(r)
}

/// (value, evaluations) of the three rules.
fn panel_de(disk: &Ball) -> (f64, u64) {
    let breaks = panel_breakpoints(L, disk.panel_width(), []);
    let r = integrate_panels(&breaks, 1e-15, integrand(disk));
    (r.value, r.evaluations)
}

fn single_de(disk: &Ball) -> (f64, u64) {
    let out = quadrature::double_exponential::integrate(integrand(disk), 0.0, L, 1e-15);
    (out.integral, out.num_function_evaluations as u64)
}

fn panel_gl(disk: &Ball, rule: &GaussLegendre, points: u64) -> (f64, u64) {
    let breaks = panel_breakpoints(L, disk.panel_width(), []);
    let f = integrand(disk);
    let value = breaks
        .windows(2)
        .map(|w| rule.integrate(w[0], w[1], &f))
        .sum();
    (value, points * (breaks.len() as u64 - 1))
}

fn quadrature_rules(c: &mut Criterion) {
    let (disk, exact) = setup();
    let gl = GaussLegendre::new(20);
    eprintln!("rule                       relative error   evaluations");
    for (name, (v, n)) in [
        ("DE on half-period panels", panel_de(&disk)),
        ("DE in one call over [0,L]", single_de(&disk)),
        ("GL-20 on half-period panels", panel_gl(&disk, &gl, 20)),
    ] {
        eprintln!("{name:<26} {:>14.2e}   {n:>11}", (v / exact - 1.0).abs());
    }
    let mut g = c.benchmark_group("polar_quadrature");
    g.bench_function("de_panels", |b| b.iter(|| black_box(panel_de(&disk))));
    g.bench_function("de_single_call", |b| b.iter(|| black_box(single_de(&disk))));
    g.bench_function("gl20_panels", |b| {
        b.iter(|| black_box(panel_gl(&disk, &gl, 20)))
    });
    g.finish();
}

criterion_group!(benches, quadrature_rules);
criterion_main!(benches);

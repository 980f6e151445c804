//! The generation cost each sampler declares ([`SamplerFacts::cost_per_point_ns`]) against a
//! measurement on this machine: the cost sizes work budgets, Monte Carlo pools and the costly
//! class, so a declared cost that has drifted beyond [`COST_TOLERANCE`] fails this benchmark.
//! Run on an idle machine: `cargo bench --bench sampler_costs`.

use specvar::sampler::{SamplerKind, COST_TOLERANCE};
use std::time::Instant;

/// Points per pattern: the N at which the costs were declared (1024 for the optimizers, whose
/// cost per point grows slowly with N).
fn points(kind: SamplerKind) -> usize {
    let n = if kind.cost_per_point_ns() > 10_000.0 {
        1024
    } else {
        4096
    };
    kind.nearest_count(n, 2)
}

/// The fastest of a few draws, per point, in nanoseconds: the least disturbed by other work.
fn measured_ns(kind: SamplerKind) -> f64 {
    let sampler = kind.build(2).expect("every sampler exists in 2D");
    let n = points(kind);
    let draws = if kind.is_costly() { 3 } else { 20 };
    (0..draws)
        .map(|r| {
            let start = Instant::now();
            let set = sampler.sample(n, 1, r).expect("a valid count");
            std::hint::black_box(set);
            start.elapsed().as_secs_f64() * 1e9 / n as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let mut drifted = Vec::new();
    println!(
        "{:<11} {:>12} {:>12} {:>7}",
        "sampler", "declared ns", "measured ns", "ratio"
    );
    for kind in SamplerKind::in_dimension(2) {
        let (declared, measured) = (kind.cost_per_point_ns(), measured_ns(kind));
        let ratio = measured / declared;
        println!(
            "{:<11} {declared:>12.1} {measured:>12.1} {ratio:>7.2}",
            kind.name()
        );
        if !(1.0 / COST_TOLERANCE..=COST_TOLERANCE).contains(&ratio) {
            drifted.push(format!("{kind} ({ratio:.2}×)"));
        }
    }
    assert!(
        drifted.is_empty(),
        "declared costs off by more than {COST_TOLERANCE}×: {}; update SamplerFacts::cost_per_point_ns",
        drifted.join(", ")
    );
}

//! An axis-aligned rectangle is a product of one interval per axis: its cell moments factor by
//! axis, so the unshifted strata, the multi-jittered samplers and Owen-scrambled nets take
//! their separable routes on it at any N. The same set drawn with a fifth vertex in the middle
//! of its lower edge is no longer recognised as a box and takes the general routes (every cell
//! clipped, inclusion–exclusion over dyadic levels): two independent computations of one
//! exact variance.

use specvar::integrand::{Integrand, Polygon};
use specvar::predict::{predict, PredictParams, Problem};
use specvar::sampler::SamplerKind;

fn rectangle() -> Polygon {
    Polygon::new(vec![[0.2, 0.3], [0.7, 0.3], [0.7, 0.8], [0.2, 0.8]], 1.0).unwrap()
}

/// The rectangle with a vertex added on its lower edge: the same function, not seen as a box.
fn rectangle_with_a_fifth_vertex() -> Polygon {
    Polygon::new(
        vec![[0.2, 0.3], [0.45, 0.3], [0.7, 0.3], [0.7, 0.8], [0.2, 0.8]],
        1.0,
    )
    .unwrap()
}

/// The default (unshifted) predictions of every exact route on the two descriptions agree
/// within the sum of their bounds, and the box's bound is informative (at most 1e-6 of the value).
#[test]
fn the_box_and_the_general_polygon_agree_on_every_exact_route() {
    let (boxed, general) = (rectangle(), rectangle_with_a_fifth_vertex());
    assert!(boxed.product_form().is_some());
    assert!(general.product_form().is_none());
    for (name, n) in [
        ("jitter", 1024),
        ("lhs", 1024),
        ("mj", 1024),
        ("cmj", 1024),
        ("orthogonal", 961),
        ("sobol", 1024),
        ("pmj02", 4096),
    ] {
        let kind: SamplerKind = name.parse().unwrap();
        let sampler = kind.build(2).unwrap();
        let run = |f: &dyn Integrand| {
            predict(
                &Problem::new(sampler.as_ref(), f, n).unwrap(),
                &PredictParams::default(),
            )
            .unwrap()
        };
        let (a, b) = (run(&boxed), run(&general));
        let allowed = a.budget.half_width(0.0) + b.budget.half_width(0.0);
        assert!(
            (a.variance - b.variance).abs() <= allowed,
            "{name}: box {:e} ({}) against polygon {:e} ({}), allowed {allowed:e}",
            a.variance,
            a.reason,
            b.variance,
            b.reason
        );
        assert!(
            a.budget.half_width(0.0) <= 1e-6 * a.variance,
            "{name}: bound {:e} on {:e}",
            a.budget.half_width(0.0),
            a.variance
        );
    }
}

/// Correlated multi-jitter at N = 262144 on the box is exact from its rows, where its
/// occupancy had to be estimated from patterns (5 s, ±4%).
#[test]
fn correlated_multi_jitter_on_a_box_is_exact_at_large_n() {
    let f = rectangle();
    let cmj = SamplerKind::Cmj.build(2).unwrap();
    let p = predict(
        &Problem::new(cmj.as_ref(), &f, 262_144).unwrap(),
        &PredictParams::default(),
    )
    .unwrap();
    assert_eq!(p.budget.spectrum_noise, 0.0, "{}", p.reason);
    assert!(
        p.budget.half_width(0.0) <= 1e-6 * p.variance,
        "{:?}",
        p.budget
    );
}

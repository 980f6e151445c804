//! Samplers with cells under a random shift (multi-jitter, CMJ, orthogonal arrays, PMJ02): the
//! default route averages each pattern's cell form on the shifted integrand over patterns and
//! shifts, checked against Monte Carlo of the shifted estimator and against the lattice form.

mod common;

use specvar::integrand::{Gaussian, Integrand, Polygon};
use specvar::montecarlo::{empirical_variance, McParams};
use specvar::predict::{predict, Form, PredictParams, Problem, SpectrumChoice, SpectrumOrigin};
use specvar::predict::{CellOrigin, Occupancy};
use specvar::randomization::Randomization;
use specvar::sampler::SamplerKind;

fn shifted(
    kind: SamplerKind,
    f: &dyn Integrand,
    n: usize,
    params: &PredictParams,
) -> specvar::predict::Prediction {
    let sampler = kind.build(2).unwrap();
    let problem = Problem::new(sampler.as_ref(), f, n)
        .unwrap()
        .with_randomization(Randomization::Shift);
    predict(&problem, params).unwrap()
}

#[test]
fn the_default_route_agrees_with_monte_carlo_across_the_faces() {
    let seam = Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap();
    let edge = Polygon::edge(30.0, 0.4, 1.0).unwrap();
    let kinds = [
        SamplerKind::MultiJitter,
        SamplerKind::Cmj,
        SamplerKind::OrthogonalArray,
        SamplerKind::Pmj02,
    ];
    for kind in kinds {
        for f in [&seam as &dyn Integrand, &edge] {
            let n = kind.nearest_count(256, 2);
            let p = shifted(kind, f, n, &PredictParams::default());
            assert_eq!(p.route.form, Form::Cells, "{kind}");
            assert!(
                matches!(
                    p.route.spectrum,
                    SpectrumOrigin::Cells(CellOrigin {
                        occupancy: Occupancy::EstimatedOverShifts { .. },
                        ..
                    })
                ),
                "{kind}: {}",
                p.route
            );
            assert_eq!(p.budget.truncation, 0.0);
            let sampler = kind.build(2).unwrap();
            let mc = empirical_variance(
                sampler.as_ref(),
                f,
                n,
                &McParams::pooled(kind, 30_000, 17, Randomization::Shift),
            )
            .unwrap();
            common::assert_agrees(
                &p,
                &mc,
                common::Z_LOOSE,
                &format!("{kind} on {}", f.label()),
            );
        }
    }
}

#[test]
fn the_lattice_form_stays_available_and_agrees_at_small_n() {
    let seam = Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap();
    let cells = shifted(SamplerKind::Cmj, &seam, 256, &PredictParams::default());
    let lattice = shifted(
        SamplerKind::Cmj,
        &seam,
        256,
        &PredictParams {
            spectrum: SpectrumChoice::Estimated,
            ..Default::default()
        },
    );
    assert_eq!(lattice.route.form, Form::Lattice);
    let allowed = common::Z_LOOSE
        * cells
            .budget
            .spectrum_noise
            .hypot(lattice.budget.spectrum_noise)
        + lattice.budget.truncation
        + lattice.budget.quadrature;
    assert!(
        (cells.variance - lattice.variance).abs() <= allowed,
        "cells {:.4e} ± {:.1e}, lattice {:.4e} ± {:.1e} (tail {:.1e})",
        cells.variance,
        cells.budget.spectrum_noise,
        lattice.variance,
        lattice.budget.spectrum_noise,
        lattice.budget.truncation
    );
}

#[test]
fn the_same_bits_on_any_thread_count() {
    let edge = Polygon::edge(30.0, 0.4, 1.0).unwrap();
    common::assert_thread_count_invariant(|| {
        shifted(SamplerKind::Cmj, &edge, 64, &PredictParams::default()).variance
    });
}

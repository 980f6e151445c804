//! Samplers with cells under a random shift (multi-jitter, CMJ, orthogonal arrays, PMJ02): the
//! default route, the lattice form with a measured tail, and the cell form (`--form cells`),
//! each pattern's cells on the shifted integrand averaged over patterns and shifts, checked
//! against Monte Carlo of the shifted estimator and against each other; CMJ on a Gaussian by
//! its exact variance at each shift.

use crate::common;

use specvar::integrand::{Gaussian, Integrand, Polygon};
use specvar::montecarlo::{empirical_variances, McParams};
use specvar::predict::{
    predict, Form, FormChoice, PredictParams, Problem, SpectrumChoice, SpectrumOrigin,
};
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

fn cell_form() -> PredictParams {
    PredictParams {
        form: FormChoice::Cells,
        ..Default::default()
    }
}

#[test]
fn both_routes_agree_with_monte_carlo_across_the_faces() {
    let seam = Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap();
    let edge = Polygon::edge(30.0, 0.4, 1.0).unwrap();
    let kinds = [
        SamplerKind::MultiJitter,
        SamplerKind::Cmj,
        SamplerKind::OrthogonalArray,
        SamplerKind::Pmj02,
    ];
    for kind in kinds {
        // PMJ02 between two powers of two: at one, Owen's gains over shifts answer it.
        let n = match kind {
            SamplerKind::Pmj02 => 200,
            _ => kind.nearest_count(256, 2),
        };
        // Both integrands on the same patterns and shifts.
        let runs = empirical_variances(
            kind.build(2).unwrap().as_ref(),
            &[&seam, &edge],
            n,
            &McParams::pooled(kind, 15_000, 17, Randomization::Shift),
            &specvar::progress::Silent,
        )
        .unwrap();
        for ((separable, f), mc) in [(true, &seam as &dyn Integrand), (false, &edge)]
            .into_iter()
            .zip(runs)
        {
            // CMJ (and an orthogonal array, CMJ on p × p cells in 2D) on a product of one-axis
            // factors: each shift's variance exact, whatever the form asked for.
            let per_shift =
                separable && matches!(kind, SamplerKind::Cmj | SamplerKind::OrthogonalArray);
            let default = shifted(kind, f, n, &PredictParams::default());
            let cells = shifted(kind, f, n, &cell_form());
            let occupancy = |p: &specvar::predict::Prediction| match p.route.spectrum {
                SpectrumOrigin::Cells(CellOrigin { occupancy, .. }) => Some(occupancy),
                _ => None,
            };
            if per_shift {
                for p in [&default, &cells] {
                    assert!(
                        matches!(occupancy(p), Some(Occupancy::PermutationsOverShifts { .. })),
                        "{kind}: {}",
                        p.route
                    );
                }
            } else {
                assert_eq!(default.route.form, Form::Lattice, "{kind}");
                assert!(
                    matches!(default.route.spectrum, SpectrumOrigin::MeasuredTail { .. }),
                    "{kind}: {}",
                    default.route
                );
                assert_eq!(cells.route.form, Form::Cells, "{kind}");
                assert!(
                    matches!(
                        occupancy(&cells),
                        Some(Occupancy::EstimatedOverShifts { .. })
                    ),
                    "{kind}: {}",
                    cells.route
                );
            }
            for p in [&default, &cells] {
                assert_eq!(p.budget.truncation, 0.0);
                common::assert_agrees(
                    p,
                    &mc,
                    common::Z_LOOSE,
                    &format!("{kind} on {} by the {}", f.label(), p.route),
                );
            }
        }
    }
}

#[test]
fn the_lattice_form_stays_available_and_agrees_at_small_n() {
    let seam = Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap();
    let cells = shifted(SamplerKind::Cmj, &seam, 256, &cell_form());
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
        let default = shifted(SamplerKind::Cmj, &edge, 64, &PredictParams::default());
        let cells = shifted(SamplerKind::Cmj, &edge, 64, &cell_form());
        (default.variance, cells.variance)
    });
}

/// The cell form is refused, with its reason, for an estimator that has none.
#[test]
fn the_cell_form_is_refused_where_there_is_none() {
    let seam = Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap();
    let halton = SamplerKind::Halton.build(2).unwrap();
    let problem = Problem::new(halton.as_ref(), &seam, 256)
        .unwrap()
        .with_randomization(Randomization::Shift);
    let e = predict(&problem, &cell_form()).unwrap_err();
    assert!(e.to_string().contains("has no cell form"), "{e}");
}

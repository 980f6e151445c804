//! The indicator of an interval `[lo, hi)` on the cells of one axis of a regular grid: the axis
//! factor of an axis-aligned rectangle, whose cell masses, squares and variances within cells
//! are lengths of overlaps, so that the rectangle's cell moments factor by axis as a
//! Gaussian's do ([`Integrand::separable_cells`](super::Integrand::separable_cells)).
//!
//! An overlap `min(b, hi) − max(a, lo)` is one subtraction of two of the given ends, so it is
//! the correctly rounded length of the overlap of the intervals as given: within `ε/2` of
//! itself. The cells' own ends `i/m` are exact when `m` is a power of two and nothing shifts
//! them; otherwise each end is rounded once, by at most `ε` (they lie in `[0, 2)`), which moves
//! an overlap by at most `2ε` in absolute terms.

use super::{over_wrapped_cell, AxisDetails};

/// The length of `[a, b) ∩ [lo, hi)`, 0 where they do not meet.
pub(crate) fn overlap(a: f64, b: f64, lo: f64, hi: f64) -> f64 {
    (b.min(hi) - a.max(lo)).max(0.0)
}

/// `∫` of the indicator of `[lo, hi)` over each of `m` equal cells of the unit interval
/// shifted by `t` on the torus (the indicator of `[lo, hi) − t mod 1`): a cell's pieces on
/// either side of the face summed. Unshifted, the second piece is empty and adds no bit, so a
/// cell's entry is the overlap [`overlap`] gives for its bounds.
pub(crate) fn masses(lo: f64, hi: f64, m: usize, t: f64) -> Vec<f64> {
    (0..m)
        .map(|i| over_wrapped_cell(i, m, t, |a, b| overlap(a, b, lo, hi)))
        .collect()
}

/// The rows of [`masses`] with what a scrambled net's fine levels read: the relative rounding
/// of each mass, and the variance within the cells, `Σ_c ∫_c (g − ḡ_c)² = Σ_c μ_c (w − μ_c)/w`
/// for an indicator (`∫_c g² = μ_c`), non-zero only on the cells an end of the interval cuts.
pub(crate) fn details(lo: f64, hi: f64, m: usize, t: f64) -> AxisDetails {
    let mass = masses(lo, hi, m, t);
    // Two pieces, each correctly rounded, and their sum: ε. Cells whose ends were rounded move
    // each piece by up to 2ε, relative to the smallest mass that is not 0.
    let moved = if t == 0.0 && m.is_power_of_two() {
        0.0
    } else {
        4.0 * f64::EPSILON
    };
    let smallest = mass
        .iter()
        .copied()
        .filter(|&x| x > 0.0)
        .fold(f64::INFINITY, f64::min);
    let mass_rounding = f64::EPSILON
        + if smallest.is_finite() {
            moved / smallest
        } else {
            0.0
        };
    let (mut within, mut within_error) = (0.0, 0.0);
    for (i, &mu) in mass.iter().enumerate() {
        let width = (i + 1) as f64 / m as f64 - i as f64 / m as f64;
        let part = (mu * (width - mu) / width).max(0.0);
        if part > 0.0 {
            within += part;
            // μ within `mass_rounding μ`, `w − μ` within that plus `ε w`, three roundings: the
            // product moves by at most `(3 mass_rounding + 4ε) μ`, as `μ ≤ w`.
            within_error += (3.0 * mass_rounding + 4.0 * f64::EPSILON) * mu;
        }
    }
    AxisDetails {
        mass,
        mass_rounding,
        // Counted in `mass_rounding`, relative to the smallest mass.
        end_rounding: 0.0,
        within,
        within_error: within_error + f64::EPSILON * within,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cases whose ends, cell counts and shifts are multiples of 1/3200, so that each cell's
    /// overlap is an exact rational: `(lo, hi, m, t)` in those units but `m`.
    const CASES: [(i64, i64, usize, i64); 5] = [
        (640, 2240, 16, 0),
        (800, 2400, 8, 0),
        (960, 2560, 10, 1184),
        (0, 1600, 32, 2880),
        (800, 2400, 64, 1600),
    ];
    const UNIT: f64 = 3200.0;

    /// The overlap of the cell `i` of `m`, shifted by `t`, with `[lo, hi)`, in units of
    /// 1/3200, from integers.
    fn exact_mass(lo: i64, hi: i64, m: usize, t: i64, i: usize) -> f64 {
        let w = 3200 / m as i64;
        let (a, b) = (i as i64 * w + t, (i as i64 + 1) * w + t);
        let piece = |a: i64, b: i64| (b.min(hi) - a.max(lo)).max(0);
        let total = piece(a.min(3200), b.min(3200)) + piece((a - 3200).max(0), (b - 3200).max(0));
        total as f64 / UNIT
    }

    /// Every mass is within its stated relative rounding of the exact overlap (the decimal
    /// inputs' own rounding, `2ε` on the ends, aside), and the variance within cells is the
    /// exact `Σ μ (w − μ)/w` within its stated error.
    #[test]
    fn masses_and_variance_within_cells_are_within_their_bounds() {
        for (lo, hi, m, t) in CASES {
            let d = details(lo as f64 / UNIT, hi as f64 / UNIT, m, t as f64 / UNIT);
            let w = 1.0 / m as f64;
            let mut within = 0.0;
            for (i, &mu) in d.mass.iter().enumerate() {
                let exact = exact_mass(lo, hi, m, t, i);
                within += exact * (w - exact) / w;
                let allowed = d.mass_rounding * exact + 4.0 * f64::EPSILON;
                assert!((mu - exact).abs() <= allowed, "{lo} {hi} {m} {t}: cell {i}");
            }
            let allowed = d.within_error + 8.0 * f64::EPSILON;
            assert!((d.within - within).abs() <= allowed, "{lo} {hi} {m} {t}");
            // Informative: the bound is far below the value wherever a cell is cut.
            assert!(d.within_error <= 1e-10 * d.within, "{lo} {hi} {m} {t}");
        }
    }

    /// Ends on the cells' faces leave no cell cut: no variance within cells, exactly, and each
    /// mass is exact.
    #[test]
    fn ends_on_faces_cut_no_cell() {
        let d = details(0.25, 0.75, 16, 0.0);
        assert_eq!(d.within, 0.0);
        assert_eq!(d.mass_rounding, f64::EPSILON);
        assert!(d.mass.iter().all(|&x| x == 0.0 || x == 1.0 / 16.0));
    }
}

//! The cell-centred regular grid.

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::ClosedForm;
use super::{check_supported, cmj::near_square_factors, perfect_root, Sampler, SamplerKind};
use crate::error::{Error, Result};
use crate::pointset::PointSet;
use crate::randomization::Randomization;

/// The regular grid: fixed, so used under a random shift.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "regular",
    description: "regular grid at cell centres (j + 1/2)/m; deterministic",
    dimensions: 1..=crate::pointset::MAX_DIMENSION,
    count: CountRule::Strata,
    balanced_counts: CountRule::Strata,
    randomness: Randomness::Deterministic,
    native_randomization: Randomization::Shift,
    cells: CellRule::None,
    cell_law: CellLaw::NoCells,
    closed_form: ClosedFormRule::WithStrata(ClosedForm::RegularGrid),
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::CubeWithSquareStrata,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Spacing,
    cost_per_point_ns: 4.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// Points at the cell centres of a grid of [`strata`]: `m^d` cells, or in 2D a near-square
/// `a × b` rectangle (`96 = 12 × 8`). Deterministic: the seed and the
/// realization are ignored, so use [`super::Homogenized`] for a randomized version.
#[derive(Debug, Clone, Copy)]
pub struct Regular {
    dimension: usize,
}

impl Regular {
    /// The regular grid in dimension `d` (1 to 8).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self { dimension: d })
    }
}

/// The cells per axis of a grid with `n` cells in dimension `d`: `[m; d]` when `n = m^d`; in 2D
/// otherwise the most nearly square rectangle `a × b = n` with `b < a ≤ 2b` (`a` cells along
/// x), so that `96 = 12 × 8`; `None` for any other `n`.
///
/// # Examples
/// ```
/// use specvar::sampler::strata;
/// assert_eq!(strata(100, 2), Some(vec![10, 10]));
/// assert_eq!(strata(96, 2), Some(vec![12, 8]));
/// assert_eq!(strata(97, 2), None); // prime: only a 97 × 1 strip
/// assert_eq!(strata(96, 3), None);
/// ```
pub fn strata(n: usize, d: usize) -> Option<Vec<usize>> {
    if let Some(m) = perfect_root(n, d) {
        return Some(vec![m; d]);
    }
    if d != 2 || n == 0 {
        return None;
    }
    let (b, a) = near_square_factors(n);
    (a <= 2 * b).then(|| vec![a, b])
}

/// The strata of `n` cells, or an error naming the rule and the nearest counts that have them.
pub(crate) fn check_strata(sampler: &'static str, d: usize, n: usize) -> Result<Vec<usize>> {
    if let Some(s) = strata(n, d) {
        return Ok(s);
    }
    let below = (1..n).rev().find(|&c| strata(c, d).is_some());
    let above = (n + 1..).find(|&c| strata(c, d).is_some());
    let nearest = match (below, above) {
        (Some(b), Some(a)) => format!("{b} or {a}"),
        (None, Some(a)) => format!("{a}"),
        _ => "1".to_string(),
    };
    let rule = if d == 2 {
        "N must be m^2, or a × b with b < a ≤ 2b (e.g. 96 = 12 × 8)".to_string()
    } else {
        format!("N must be m^{d} for an integer m")
    };
    Err(Error::UnsupportedCount {
        sampler,
        n,
        dimension: d,
        rule,
        nearest,
    })
}

/// Calls `f(point_index, axis, cell)` for the cells of a grid with `cells[axis]` cells per
/// axis, last axis fastest.
pub(crate) fn for_each_cell(cells: &[usize], mut f: impl FnMut(usize, usize, usize)) {
    let n: usize = cells.iter().product();
    // An odometer over the cells' indices: the same calls in the same order as dividing `i`
    // by each axis's count, without two integer divisions per axis and point (which cost more
    // than drawing the point).
    let mut index = vec![0usize; cells.len()];
    for i in 0..n {
        for axis in (0..cells.len()).rev() {
            f(i, axis, index[axis]);
        }
        for axis in (0..cells.len()).rev() {
            index[axis] += 1;
            if index[axis] < cells[axis] {
                break;
            }
            index[axis] = 0;
        }
    }
}

impl Sampler for Regular {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::Regular)
    }
    fn check_count(&self, n: usize) -> Result<()> {
        check_strata(self.name(), self.dimension, n).map(|_| ())
    }
    fn sample(&self, n: usize, _seed: u64, _realization: u64) -> Result<PointSet> {
        let d = self.dimension;
        let cells = check_strata(self.name(), d, n)?;
        let mut coords = vec![0.0; n * d];
        for_each_cell(&cells, |i, axis, cell| {
            coords[i * d + axis] = (cell as f64 + 0.5) / cells[axis] as f64;
        });
        Ok(PointSet::from_trusted(d, coords))
    }
}

#[cfg(test)]
mod tests {
    use super::for_each_cell;

    #[test]
    fn cells_are_visited_as_the_digits_of_their_index() {
        for cells in [vec![5], vec![2, 3], vec![4, 1, 3], vec![3, 2, 2, 2]] {
            let mut visits = Vec::new();
            for_each_cell(&cells, |i, axis, cell| visits.push((i, axis, cell)));
            let n: usize = cells.iter().product();
            let mut expected = Vec::new();
            for i in 0..n {
                let mut rest = i;
                for axis in (0..cells.len()).rev() {
                    expected.push((i, axis, rest % cells[axis]));
                    rest /= cells[axis];
                }
            }
            assert_eq!(visits, expected, "cells {cells:?}");
        }
    }
}

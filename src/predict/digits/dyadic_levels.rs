//! The variance of a separable integrand at each dyadic level, and beyond a set of levels,
//! without subtracting nearly equal sums.
//!
//! For `f = h Π_l g_l(x_l)`, the level-`k` component `⊗_l (P_{k_l} − P_{k_l−1}) f` has
//! `σ²_k = h² Π_l δ_l(k_l)` with `δ_l(a) = ‖(P_a − P_{a−1}) g_l‖²`: `δ_l(0) = (∫g_l)²`, and for
//! `a ≥ 1`, over the pairs of cells of level `a` that halve a cell of level `a − 1`,
//! `δ_l(a) = 2^{a−1} Σ_j (m_{2j} − m_{2j+1})²` with `m_i` the cells' masses of `g_l`. Each term
//! is a difference of two neighbouring masses, which keeps its digits where `g_l` varies by
//! little across a cell; the inclusion–exclusion of `‖P_a f‖²` over grids would subtract sums
//! that agree to within `4^{−|k|}` of each other.
//!
//! The levels beyond a set `D` closed downwards (every level below one of `D` in `D`) are
//! summed through the tails `T_l(b) = Σ_{a ≥ b} δ_l(a) = Σ_c ∫_c (g_l − ḡ_c)²` over the cells
//! of level `b − 1`, taken directly at the finest level `F_l` read and summed upwards from there:
//! `T_l(b) = T_l(F_l + 1) + Σ_{a=b}^{F_l} δ_l(a)`. With `D'` the levels of `D` on the axes before
//! the last and `b(k') = 1 + max{k_last : (k', k_last) ∈ D}`,
//! `Σ_{k ∉ D} Π_l δ_l(k_l) = Σ_{k' ∈ D'} Π_{l<last} δ_l(k'_l) T_last(b(k')) + T_last(0) Σ_{k' ∉ D'} …`,
//! the last sum the same over one axis fewer (and empty with none left). Every term is
//! positive, so the variance beyond a net's levels keeps its digits at any N.

use crate::integrand::Integrand;

/// The most axes a level has.
pub(crate) const MAX_AXES: usize = 3;

/// The levels of a dyadic grid: `2^{a_l}` cells on axis `l`.
pub(crate) type Levels = [u8; MAX_AXES];

/// A value and a bound on its error.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Bounded {
    pub(crate) value: f64,
    pub(crate) error: f64,
}

impl Bounded {
    fn exact(value: f64) -> Self {
        Self { value, error: 0.0 }
    }

    /// The sum, with its own rounding.
    pub(crate) fn plus(self, other: Self) -> Self {
        let value = self.value + other.value;
        Self {
            value,
            error: self.error + other.error + f64::EPSILON * value.abs(),
        }
    }

    /// The product, with its own rounding.
    pub(crate) fn times(self, other: Self) -> Self {
        let value = self.value * other.value;
        Self {
            value,
            error: self.value.abs() * other.error
                + other.value.abs() * self.error
                + self.error * other.error
                + f64::EPSILON * value.abs(),
        }
    }

    /// The product by an exact factor, with its own rounding.
    pub(crate) fn scaled(self, factor: f64) -> Self {
        self.times(Self::exact(factor))
    }
}

/// One axis: `δ(a)` for `a = 0..=F` and the tail `T(F + 1)`.
struct AxisLevels {
    detail: Vec<Bounded>,
    tail: Bounded,
}

impl AxisLevels {
    /// From the masses of `g` on the `2^F` cells of its finest level, their relative rounding,
    /// and its variance within those cells.
    fn new(axis: &crate::integrand::AxisDetails) -> Self {
        let mut row = axis.mass.clone();
        // A merged mass is a sum of positive finer ones: one more rounding a level.
        let mut relative = axis.mass_rounding;
        // A merged mass keeps its outer ends' error: its inner ends cancel.
        let ends = axis.end_rounding;
        let mut detail = Vec::new();
        while row.len() > 1 {
            let half = row.len() / 2;
            let scale = half as f64;
            let (mut value, mut error) = (
                crate::quadrature::CompensatedSum::default(),
                crate::quadrature::CompensatedSum::default(),
            );
            for pair in row.chunks_exact(2) {
                let difference = pair[0] - pair[1];
                // Three ends, the shared one twice.
                let e = relative * (pair[0].abs() + pair[1].abs())
                    + f64::EPSILON * difference.abs()
                    + 4.0 * ends;
                value.add(difference * difference);
                error.add(2.0 * difference.abs() * e + e * e);
            }
            let value = scale * value.value();
            detail.push(Bounded {
                value,
                error: scale * error.value() + 4.0 * f64::EPSILON * value,
            });
            row = row.chunks_exact(2).map(|p| p[0] + p[1]).collect();
            relative += f64::EPSILON;
        }
        let whole = row.first().copied().unwrap_or(0.0);
        let outer = 2.0 * ends;
        detail.push(Bounded {
            value: whole * whole,
            error: (2.0 * relative + f64::EPSILON) * whole * whole
                + 2.0 * whole.abs() * outer
                + outer * outer,
        });
        detail.reverse();
        Self {
            detail,
            tail: Bounded {
                value: axis.within,
                error: axis.within_error,
            },
        }
    }

    fn finest(&self) -> usize {
        self.detail.len() - 1
    }

    /// `T(b) = Σ_{a ≥ b} δ(a)`, for `b ≤ F + 1`.
    fn beyond(&self, b: usize) -> Bounded {
        self.detail[b.min(self.detail.len())..]
            .iter()
            .rev()
            .fold(self.tail, |sum, &d| sum.plus(d))
    }
}

/// `σ²_k` of a separable integrand at every level up to its finest levels, and beyond any set
/// of levels closed downwards.
pub(crate) struct SeparableLevels {
    height_squared: f64,
    axes: Vec<AxisLevels>,
}

impl SeparableLevels {
    /// The levels of `f` shifted by `t` on the torus (`f(x + t mod 1)`), read on the grid with
    /// `2^{finest_l}` cells on axis `l`; `None` where `f` is not separable.
    pub(crate) fn new(f: &dyn Integrand, finest: &[u8], t: &[f64]) -> Option<Self> {
        let grid: Vec<usize> = finest.iter().map(|&a| 1usize << a).collect();
        let details = f.separable_details(&grid, t)?;
        Some(Self {
            height_squared: details.height * details.height,
            axes: details.axes.iter().map(AxisLevels::new).collect(),
        })
    }

    /// `σ²_k = h² Π_l δ_l(k_l)`; `None` beyond the finest levels.
    pub(crate) fn level(&self, k: &Levels) -> Option<Bounded> {
        self.axes
            .iter()
            .zip(k)
            .try_fold(Bounded::exact(self.height_squared), |p, (axis, &a)| {
                axis.detail.get(a as usize).map(|&d| p.times(d))
            })
    }

    /// `Σ_{k ∉ D} σ²_k` for a set `D` of levels closed downwards and holding the coarsest;
    /// `None` if a level of `D` is beyond the finest levels.
    pub(crate) fn beyond(&self, downset: &[Levels]) -> Option<Bounded> {
        let exceeds = |k: &Levels| {
            self.axes
                .iter()
                .zip(k)
                .any(|(a, &l)| l as usize > a.finest())
        };
        if downset.iter().any(exceeds) {
            return None;
        }
        Some(
            self.beyond_on_axes(downset, self.axes.len())
                .scaled(self.height_squared),
        )
    }

    /// `Σ_{k ∉ D} Π_{l < axes} δ_l(k_l)` over the first `axes` axes (`D`'s other axes at 0).
    fn beyond_on_axes(&self, downset: &[Levels], axes: usize) -> Bounded {
        let Some(last) = axes.checked_sub(1) else {
            // With no axis left there is one level: beyond `D` unless `D` holds it.
            return Bounded::exact(if downset.is_empty() { 1.0 } else { 0.0 });
        };
        let mut columns: Vec<(Levels, u8)> = Vec::new();
        for k in downset {
            let mut prefix = *k;
            prefix[last] = 0;
            match columns.iter_mut().find(|(p, _)| *p == prefix) {
                Some((_, top)) => *top = (*top).max(k[last]),
                None => columns.push((prefix, k[last])),
            }
        }
        columns.sort_unstable();
        let axis = &self.axes[last];
        let within_columns = columns
            .iter()
            .fold(Bounded::default(), |sum, (prefix, top)| {
                let product = (0..last).fold(Bounded::exact(1.0), |p, l| {
                    p.times(self.axes[l].detail[prefix[l] as usize])
                });
                sum.plus(product.times(axis.beyond(*top as usize + 1)))
            });
        let prefixes: Vec<Levels> = columns.iter().map(|(p, _)| *p).collect();
        within_columns.plus(self.beyond_on_axes(&prefixes, last).times(axis.beyond(0)))
    }
}

/// Every level at or below one of `levels` (on each axis), and the coarsest.
pub(crate) fn closed_downwards(levels: &[Levels], d: usize) -> Vec<Levels> {
    let mut seen = std::collections::HashSet::new();
    let mut stack: Vec<Levels> = levels.to_vec();
    stack.push([0; MAX_AXES]);
    while let Some(k) = stack.pop() {
        if !seen.insert(k) {
            continue;
        }
        for l in 0..d {
            if k[l] > 0 {
                let mut below = k;
                below[l] -= 1;
                stack.push(below);
            }
        }
    }
    let mut all: Vec<Levels> = seen.into_iter().collect();
    all.sort_unstable();
    all
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::Gaussian;

    /// The levels of an axis and its tail at the finest level add up to `‖g‖²` (every level
    /// counted once), which the Gaussian has in closed form: within their bounds, at finest
    /// levels from 2 to 2^20 cells, narrow and wide, centred and cut by a face, shifted or not.
    #[test]
    fn the_levels_and_the_tail_are_the_whole_energy() {
        for (sigma, centre, shift) in [(0.2, 0.2, 0.0), (0.05, 0.9, 0.3), (1.5, 0.5, 0.71)] {
            let f = Gaussian::new(sigma, vec![centre], 1.0).unwrap();
            // ‖g‖² = ∫ exp(−(x − c)²/σ²), shifted or not.
            let (_, energy) = f.box_moments(&[0.0], &[1.0]).unwrap();
            for finest in [1u8, 5, 12, 20] {
                let levels = SeparableLevels::new(&f, &[finest], &[shift]).unwrap();
                let whole = levels.beyond(&[]).unwrap();
                let total = levels.axes[0].beyond(0);
                assert_eq!(whole.value, total.value);
                let allowed = total.error + 4.0 * f64::EPSILON * energy;
                assert!(
                    (total.value - energy).abs() <= allowed,
                    "σ = {sigma}, c = {centre}, t = {shift}, 2^{finest} cells: {} against {energy} \
                     (allowed {allowed:e})",
                    total.value
                );
                // Informative: the widest measured was 1e-10 of the energy (σ = 0.05, 32 cells).
                assert!(total.error <= 1e-9 * energy, "{:e}", total.error);
            }
        }
    }

    /// A level's variance against the inclusion–exclusion of `‖P_a f‖²` over the grids below it
    /// (each a sum of cell masses squared), at coarse levels, where that difference keeps most
    /// of its digits; and the levels beyond a set against `∫f² − I²` less the set's levels.
    #[test]
    fn levels_agree_with_squared_means_where_those_keep_their_digits() {
        let f = Gaussian::new(0.15, vec![0.3, 0.6], 2.0).unwrap();
        let levels = SeparableLevels::new(&f, &[6, 5], &[0.0, 0.0]).unwrap();
        let squared_mean = |a: [u8; 2]| {
            let grid = [1usize << a[0], 1usize << a[1]];
            let cells = f.separable_details(&grid, &[0.0, 0.0]).unwrap();
            let (x, y) = (&cells.axes[0].mass, &cells.axes[1].mass);
            let sum = |row: &[f64]| row.iter().map(|m| m * m).sum::<f64>();
            cells.height.powi(2) * sum(x) * sum(y) * (grid[0] * grid[1]) as f64
        };
        for k in [[1u8, 0], [0, 3], [2, 2], [4, 1], [6, 5]] {
            let mut by_grids = 0.0;
            for e in 0..4u32 {
                let a = [
                    k[0].checked_sub((e & 1) as u8),
                    k[1].checked_sub((e >> 1) as u8),
                ];
                if let [Some(a0), Some(a1)] = a {
                    let sign = if e.count_ones() % 2 == 0 { 1.0 } else { -1.0 };
                    by_grids += sign * squared_mean([a0, a1]);
                }
            }
            let level = levels.level(&[k[0], k[1], 0]).unwrap();
            let cancellation = 1e-13 * squared_mean(k);
            assert!(
                (level.value - by_grids).abs() <= level.error + cancellation,
                "{k:?}: {} against {by_grids}",
                level.value
            );
        }
        let set = closed_downwards(&[[3, 2, 0], [1, 4, 0]], 2);
        let (integral, energy) = f.box_moments(&[0.0, 0.0], &[1.0, 1.0]).unwrap();
        let inside: f64 = set.iter().map(|k| levels.level(k).unwrap().value).sum();
        let beyond = levels.beyond(&set).unwrap();
        let difference = energy - inside;
        assert!(integral > 0.0);
        assert!(
            (beyond.value - difference).abs() <= beyond.error + 1e-13 * energy,
            "{} against {difference}",
            beyond.value
        );
    }

    #[test]
    fn closed_downwards_holds_every_level_below() {
        let set = closed_downwards(&[[2, 1, 0]], 2);
        assert_eq!(set.len(), 6);
        assert!(set.contains(&[0, 0, 0]) && set.contains(&[2, 0, 0]) && set.contains(&[1, 1, 0]));
    }
}

//! Owen's gains: the variance of a base-2 net under nested uniform scrambling, exactly.
//!
//! Split `f` by dyadic levels: with `P_a` the mean of `f` over the cells of the grid with
//! `2^{a_l}` cells on axis `l`, the component at level `k` is `f_k = ⊗_l (P_{k_l} − P_{k_l−1})
//! f` (`P_{−1} = 0`), and `σ²_k = ‖f_k‖² = Σ_{e ≤ 1_u} (−1)^{|e|} S(k − e)` by inclusion–exclusion,
//! with `u` the axes where `k_l ≥ 1` and `S(a) = ‖P_a f‖² = Σ_c Φ_c² / |c|` read from the cells'
//! integrals `Φ_c` ([`Integrand::box_moments`]).
//!
//! Nested uniform scrambling in base 2 flips each digit by an independent bit of its node in
//! the tree of elementary intervals. Two scrambled coordinates that share exactly `γ` leading
//! digits still share them, differ in digit `γ + 1`, and have independent uniform digits below,
//! so a level-`k` component (antisymmetric in digit `k`, of mean zero given the digits above)
//! correlates by `1` if `γ ≥ k`, by `−1` if `γ = k − 1`, and not at all otherwise; components of
//! different levels never correlate. Summed over the pairs of points,
//!
//! `Var μ = (1/N) Σ_{k ≠ 0} Γ_k σ²_k`, `Γ_k = (1/N) Σ_{e ∈ {0,1}^u} Π_{l∈u} (e_l ? 2 : −1) C(k − 1_u + e)`,
//!
//! Owen's gain coefficients (Owen 1997, "Monte Carlo variance of scrambled net quadrature"),
//! with `C(a) = Σ_{i,j} [x_i, x_j share cell of grid a] = Σ_c n_c²`. Scrambling permutes the cells
//! of every dyadic grid, so `C` is read from any one scrambled pattern. `C(a) ≥ N`, with
//! equality once the grid separates the points, and then every gain it enters is 1: only the
//! levels just above the grids where two points share a cell differ from independent sampling,
//!
//! `N Var μ = (∫f² − I²) + Σ_{k ∈ K} (Γ_k − 1) σ²_k`, `K = {a + 1_u : C(a) > N, supp a ⊆ u}`,
//!
//! exact, nothing truncated. A separable integrand is summed without that formula's
//! cancellation, level by level and beyond ([`super::dyadic_levels`]). For a `(0, m, 2)`-net with `N = 2^m`, `Γ_k` is 0 for `k_1 + k_2 ≤ m`,
//! 2 for `k_1 + k_2 = m + 1` (both axes refined) and 1 beyond (`docs/theory.md`, "Scrambled
//! nets by levels").

use super::dyadic_levels::{closed_downwards, Levels, SeparableLevels, MAX_AXES};
use crate::budget::{Budget, Needs};
use crate::error::{Error, Result};
use crate::integrand::Integrand;
use crate::pointset::PointSet;
use crate::predict::strata::cell_moments::{
    cell_masses, chunked_sum, seconds_per_grid_cell, CellSum, CELL_ROUNDING,
};
use crate::predict::term_mean::{mean_of_exact_terms, OccupancyEstimate};
use crate::progress::Progress;
use crate::quadrature::CompensatedSum;
use rayon::prelude::*;
use std::collections::HashMap;

/// Binary digits of a pattern's coordinates (doubles in `[0, 1)` with 53-bit fractions).
const DIGITS: u8 = 53;

/// The pair counts `C(a)` of one scrambled pattern, and the grids where two points share a
/// cell.
struct PairCounts {
    n: usize,
    d: usize,
    /// The points' binary digits, one copy sorted by each axis' digits. Counted in the order
    /// of the axis that holds most of a grid's digits, consecutive points fall in nearby
    /// cells, and the counts being written fit the caches: in any order, the counts of a grid
    /// of `4N` cells are a scatter over tens of MB at large N.
    by_axis: Vec<Vec<[u64; MAX_AXES]>>,
    known: HashMap<Levels, u128>,
    /// The cell counts of one column, reused from column to column (tens of MB at large N,
    /// whose pages the system would otherwise map and clear for each).
    count: Vec<u32>,
}

impl PairCounts {
    /// The bytes the counts of `n` points in `d` dimensions hold: a copy of the points' digits
    /// per axis, and one column's cell counts (at most `2^{⌈log₂ n⌉ + 2}` cells of 4 bytes).
    fn bytes(n: usize, d: usize) -> f64 {
        let digits = d * n * std::mem::size_of::<[u64; MAX_AXES]>();
        let column = 4.0 * 2f64.powi((usize::BITS - n.leading_zeros()) as i32 + 2);
        digits as f64 + column
    }

    fn new(pattern: &PointSet) -> Self {
        let d = pattern.dimension();
        let scale = (1u64 << DIGITS) as f64;
        let digits: Vec<[u64; MAX_AXES]> = pattern
            .points()
            .map(|x| {
                let mut v = [0u64; MAX_AXES];
                for (a, &c) in x.iter().enumerate() {
                    v[a] = ((c * scale) as u64).min((1u64 << DIGITS) - 1);
                }
                v
            })
            .collect();
        let by_axis = (0..d)
            .map(|l| {
                let mut sorted = digits.clone();
                sorted.par_sort_unstable_by_key(|v| v[l]);
                sorted
            })
            .collect();
        Self {
            n: pattern.len(),
            d,
            by_axis,
            known: HashMap::new(),
            count: Vec::new(),
        }
    }

    /// `C(a) = Σ_c n_c²` over the cells of grid `a`.
    fn pairs(&mut self, a: Levels) -> u128 {
        if let Some(&c) = self.known.get(&a) {
            return c;
        }
        let bits: u32 = a.iter().map(|&l| l as u32).sum();
        // Grids of at most about 4N cells are counted in place, a column at a time; a column's
        // finest grid has at least about 2N cells (where a net's points are apart), or `a`'s.
        let in_place = 2 + usize::BITS - self.n.leading_zeros();
        if bits <= in_place {
            self.count_column(a, bits.max(in_place - 1));
            return self.known[&a];
        }
        let mut keys: Vec<u64> = self.by_axis[0]
            .iter()
            .map(|v| cell_key(v, &a, self.d))
            .collect();
        keys.sort_unstable();
        let c = keys
            .chunk_by(|x, y| x == y)
            .map(|run| (run.len() as u128).pow(2))
            .sum();
        self.known.insert(a, c);
        c
    }

    /// `C` of every grid of `a`'s column (its other axes fixed, the last one from 0 to the
    /// level whose grid has `2^cell_bits` cells, or `a`'s level if finer): the points are
    /// counted once into the column's finest cells, and each coarser grid's counts are its
    /// finer neighbour's summed in pairs, since a cell's key ends with its last axis' digits.
    /// One pass over the points answers a whole column, where each grid asked for its own.
    fn count_column(&mut self, a: Levels, cell_bits: u32) {
        let last = self.d - 1;
        let others: u32 = a[..last].iter().map(|&l| l as u32).sum();
        let mut g = a;
        g[last] = (cell_bits - others).clamp(a[last] as u32, DIGITS as u32) as u8;
        let count = &mut self.count;
        count.clear();
        count.resize(1usize << (others + g[last] as u32), 0);
        let most = (0..self.d).rev().max_by_key(|&l| g[l]).unwrap_or(0);
        for v in &self.by_axis[most] {
            count[cell_key(v, &g, self.d) as usize] += 1;
        }
        loop {
            let c = count.iter().map(|&c| u128::from(c) * u128::from(c)).sum();
            self.known.insert(g, c);
            if g[last] == 0 {
                break;
            }
            let half = count.len() / 2;
            for i in 0..half {
                count[i] = count[2 * i] + count[2 * i + 1];
            }
            count.truncate(half);
            g[last] -= 1;
        }
    }

    /// The grids in which two points share a cell (`C(a) > N`), a downward-closed set found
    /// from the coarsest grid by refining one axis at a time.
    fn shared_grids(&mut self) -> Result<Vec<Levels>> {
        let mut shared = Vec::new();
        let mut queue = vec![[0u8; MAX_AXES]];
        let mut seen = std::collections::HashSet::new();
        while let Some(a) = queue.pop() {
            if !seen.insert(a) || self.pairs(a) <= self.n as u128 {
                continue;
            }
            // 53 digits on every axis and still shared: two points coincide.
            let bits: u32 = a.iter().map(|&l| l as u32).sum();
            if a[..self.d].iter().all(|&l| l == DIGITS) || bits >= 60 {
                return Err(Error::OutsideValidity {
                    route: "Owen's gains".into(),
                    reason: "two points of the net share a cell of 2^60 cells".into(),
                });
            }
            shared.push(a);
            for l in 0..self.d {
                if a[l] < DIGITS {
                    let mut b = a;
                    b[l] += 1;
                    queue.push(b);
                }
            }
        }
        shared.sort_unstable();
        Ok(shared)
    }

    /// Owen's gain `Γ_k` of level `k` (refined on the axes where `k_l ≥ 1`).
    fn gain(&mut self, k: Levels) -> f64 {
        let axes: Vec<usize> = (0..self.d).filter(|&l| k[l] > 0).collect();
        let mut total: i128 = 0;
        for e in 0..1u32 << axes.len() {
            let mut a = k;
            let mut weight: i128 = 1;
            for (bit, &l) in axes.iter().enumerate() {
                if e >> bit & 1 == 1 {
                    weight *= 2;
                } else {
                    a[l] -= 1;
                    weight = -weight;
                }
            }
            total += weight * self.pairs(a) as i128;
        }
        total as f64 / self.n as f64
    }
}

/// The index of the cell of grid `a` holding a point of binary digits `v`: each axis' leading
/// `a_l` digits in turn, the last axis' least significant.
fn cell_key(v: &[u64; MAX_AXES], a: &Levels, d: usize) -> u64 {
    (0..d).fold(0u64, |k, l| {
        let take = a[l] as u32;
        if take == 0 {
            k
        } else {
            (k << take) | (v[l] >> (DIGITS as u32 - take))
        }
    })
}

/// The levels `k` whose gain may differ from 1: `a + 1_u` for every shared grid `a` and every
/// set of axes `u ⊇ supp a`, `u` not empty.
fn levels_off_one(shared: &[Levels], d: usize) -> Vec<Levels> {
    let mut levels = Vec::new();
    for a in shared {
        let support = (0..d).fold(0u32, |s, l| s | (u32::from(a[l] > 0) << l));
        for u in 1..1u32 << d {
            if u & support == support {
                let mut k = *a;
                (0..d).filter(|l| u >> l & 1 == 1).for_each(|l| k[l] += 1);
                levels.push(k);
            }
        }
    }
    levels.sort_unstable();
    levels.dedup();
    levels
}

/// The grids `k − e`, `e ≤ 1_u`, whose `S` the levels' variances read, and the whole cube
/// (`S = I²`).
fn grids_read(levels: &[Levels], d: usize) -> Vec<Levels> {
    let mut grids: Vec<Levels> = std::iter::once([0; MAX_AXES])
        .chain(levels.iter().flat_map(|k| {
            (0..1u32 << d).filter_map(move |e| {
                let mut g = *k;
                for l in 0..d {
                    if e >> l & 1 == 1 {
                        g[l] = g[l].checked_sub(1)?;
                    }
                }
                Some(g)
            })
        }))
        .collect();
    grids.sort_unstable();
    grids.dedup();
    grids
}

/// The finest grid of every column (all axes but the last fixed), from which the coarser grids
/// of the column follow by merging cells along the last axis.
fn columns(grids: &[Levels], d: usize) -> Vec<Levels> {
    let mut finest: HashMap<Levels, u8> = HashMap::new();
    for g in grids {
        let mut column = *g;
        column[d - 1] = 0;
        let top = finest.entry(column).or_insert(0);
        *top = (*top).max(g[d - 1]);
    }
    let mut tops: Vec<Levels> = finest
        .into_iter()
        .map(|(mut g, top)| {
            g[d - 1] = top;
            g
        })
        .collect();
    tops.sort_unstable();
    tops
}

fn cells_of(g: &Levels, d: usize) -> usize {
    1usize << g[..d].iter().map(|&l| l as u32).sum::<u32>()
}

/// `S(a) = Σ_c Φ_c² / |c|` for every grid of the columns, from the cells' integrals on the
/// finest grid of each column, for the integrand shifted by `t`: `S` and its rounding bound per
/// grid.
fn squared_means(
    f: &dyn Integrand,
    tops: &[Levels],
    d: usize,
    t: &[f64],
) -> HashMap<Levels, (f64, f64)> {
    let mut s = HashMap::new();
    for top in tops {
        let sizes: Vec<usize> = (0..d).map(|l| 1usize << top[l]).collect();
        let mut mass = cell_masses(f, &sizes, t);
        let mut g = *top;
        loop {
            let volume_inverse = cells_of(&g, d) as f64;
            let (squares, _) = chunked_sum(mass.len(), |i| (mass[i] * mass[i], 0.0));
            let value = squares * volume_inverse;
            s.insert(g, (value, CELL_ROUNDING * value));
            if g[d - 1] == 0 {
                break;
            }
            // Merge pairs of cells along the last axis (the slowest index).
            let block = mass.len() >> g[d - 1];
            mass = (0..mass.len() / 2)
                .map(|i| {
                    let (row, offset) = (i / block, i % block);
                    mass[2 * row * block + offset] + mass[(2 * row + 1) * block + offset]
                })
                .collect();
            g[d - 1] -= 1;
        }
    }
    s
}

/// A base-2 net under nested uniform scrambling, read once from one scrambled pattern: the
/// levels whose gain differs from 1, their excess gains `Γ_k − 1`, and the grids whose cells
/// their variances read. Its variance on any integrand (or any shift of one) follows from
/// those cells' integrals alone.
pub(crate) struct ScrambledNet {
    n: usize,
    d: usize,
    excess: Vec<(Levels, f64)>,
    /// Every level whose gain may differ from 1, its gain 1 or not.
    levels: Vec<Levels>,
    tops: Vec<Levels>,
    /// The cells whose integrals one variance reads.
    pub(crate) cells: usize,
}

impl ScrambledNet {
    /// The gains of the net `pattern` is a scrambling of, for an integrand of dimension `d`
    /// whose moments cost `cell_seconds` a cell.
    ///
    /// # Errors
    /// More than 3 axes, a pattern of another dimension, a pattern whose points coincide, or
    /// one variance's work beyond `budget`.
    pub(crate) fn new(
        pattern: &PointSet,
        d: usize,
        cell_seconds: f64,
        budget: &Budget,
    ) -> Result<Self> {
        if d > MAX_AXES || pattern.dimension() != d {
            return Err(Error::Mismatch(format!(
                "Owen's gains of a {}D pattern for a {d}D integrand (at most {MAX_AXES} axes)",
                pattern.dimension()
            )));
        }
        budget.check(
            "Owen's gains' pair counts",
            Needs::memory(PairCounts::bytes(pattern.len(), d)),
            "lower N",
        )?;
        let mut counts = PairCounts::new(pattern);
        let shared = counts.shared_grids()?;
        let levels = levels_off_one(&shared, d);
        let excess: Vec<(Levels, f64)> = levels
            .iter()
            .map(|&k| (k, counts.gain(k) - 1.0))
            .filter(|&(_, e)| e != 0.0)
            .collect();
        let kept: Vec<Levels> = excess.iter().map(|&(k, _)| k).collect();
        let tops = columns(&grids_read(&kept, d), d);
        let cells: usize = tops.iter().map(|g| cells_of(g, d)).sum();
        // One column's cell masses, or a separable integrand's rows of masses and squares on
        // each axis' finest level.
        let column_bytes = 8.0 * tops.iter().map(|g| cells_of(g, d)).max().unwrap_or(1) as f64;
        let row_bytes: f64 = (0..d)
            .map(|l| 16.0 * 2f64.powi(tops.iter().map(|g| g[l]).max().unwrap_or(0) as i32))
            .sum();
        budget.check(
            "Owen's gains",
            Needs {
                memory_bytes: column_bytes.max(row_bytes),
                work_seconds: cells as f64 * cell_seconds,
            },
            "lower N",
        )?;
        Ok(Self {
            n: pattern.len(),
            d,
            excess,
            levels,
            tops,
            cells,
        })
    }

    /// The variance of the scrambled net's estimator of `f` shifted by `t` on the torus
    /// (`f_t(x) = f(x + t mod 1)`; `t = 0`: of `f` itself), and its rounding bound.
    ///
    /// # Errors
    /// An integrand of another dimension than the net's, or without moments over boxes.
    pub(crate) fn variance(&self, f: &dyn Integrand, t: &[f64]) -> Result<CellSum> {
        if f.dimension() != self.d {
            return Err(Error::Mismatch(format!(
                "a {}D net's gains for a {}D integrand",
                self.d,
                f.dimension()
            )));
        }
        LevelVariances::new(f, &self.tops, t)?.variance(self)
    }
}

/// What a net's variance reads of an integrand: the variance at each level directly where
/// the integrand is separable ([`SeparableLevels`]), `S` on the grids otherwise.
enum LevelVariances {
    Separable(SeparableLevels),
    Squares(SquaredMeans),
}

impl LevelVariances {
    /// On the grids of the columns `tops` for `f` shifted by `t`.
    fn new(f: &dyn Integrand, tops: &[Levels], t: &[f64]) -> Result<Self> {
        let finest: Vec<u8> = (0..f.dimension())
            .map(|l| tops.iter().map(|g| g[l]).max().unwrap_or(0))
            .collect();
        Ok(match SeparableLevels::new(f, &finest, t) {
            Some(levels) => Self::Separable(levels),
            None => Self::Squares(SquaredMeans::new(f, tops, t)?),
        })
    }

    /// `(1/N) Σ_{k ≠ 0} Γ_k σ²_k` for `net`'s gains, and its rounding bound.
    ///
    /// # Errors
    /// A level of `net` that reads a grid or a level these variances lack.
    fn variance(&self, net: &ScrambledNet) -> Result<CellSum> {
        match self {
            Self::Squares(means) => means.variance(net),
            Self::Separable(levels) => separable_variance(levels, net),
        }
    }
}

/// `(1/N) [Σ_{k ∈ D, k ≠ 0} Γ_k σ²_k + Σ_{k ∉ D} σ²_k]` with `D` the levels at or below those
/// whose gain differs from 1 (the finest levels read are theirs): every term positive, so that the variance of a net far finer
/// than the integrand's features keeps its digits (through `∫f² − I²` less the levels of gain
/// 0, it would be the small difference of two large sums).
fn separable_variance(levels: &SeparableLevels, net: &ScrambledNet) -> Result<CellSum> {
    let missing = || Error::Mismatch("a net's levels beyond its integrand's finest cells".into());
    let kept: Vec<Levels> = net.excess.iter().map(|&(k, _)| k).collect();
    let downset = closed_downwards(&kept, net.d);
    let gains: HashMap<Levels, f64> = net.excess.iter().map(|&(k, e)| (k, 1.0 + e)).collect();
    let mut total = levels.beyond(&downset).ok_or_else(missing)?;
    for k in downset.iter().filter(|k| k.iter().any(|&l| l > 0)) {
        let gain = gains.get(k).copied().unwrap_or(1.0);
        total = total.plus(levels.level(k).ok_or_else(missing)?.scaled(gain));
    }
    let nf = net.n as f64;
    Ok(CellSum {
        variance: total.value.max(0.0) / nf,
        rounding: total.error / nf,
    })
}

/// An integrand's `S(a) = ‖P_a f‖²` on the grids a net's levels read, with `∫f²`: what the
/// variance of any net whose levels read no other grid follows from.
struct SquaredMeans {
    d: usize,
    s: HashMap<Levels, (f64, f64)>,
    whole: f64,
}

impl SquaredMeans {
    /// `S` on the grids of the columns `tops` for `f` shifted by `t`.
    fn new(f: &dyn Integrand, tops: &[Levels], t: &[f64]) -> Result<Self> {
        let d = f.dimension();
        let (_, whole) = f
            .box_moments(&vec![0.0; d], &vec![1.0; d])
            .ok_or_else(|| Error::Mismatch(format!("{} has no moments over boxes", f.label())))?;
        Ok(Self {
            d,
            s: squared_means(f, tops, d, t),
            whole,
        })
    }

    /// `(1/N) [(∫f² − I²) + Σ_k (Γ_k − 1) σ²_k]` for `net`'s gains, and its rounding bound.
    ///
    /// # Errors
    /// A level of `net` that reads a grid these means do not have.
    fn variance(&self, net: &ScrambledNet) -> Result<CellSum> {
        let d = self.d;
        let missing =
            || Error::Mismatch("a net's levels read a grid its integrand's means lack".into());
        let integral_sq = self.s.get(&[0; MAX_AXES]).ok_or_else(missing)?.0;
        let mut total = CompensatedSum::default();
        total.add(self.whole);
        total.add(-integral_sq);
        let mut rounding = CELL_ROUNDING * self.whole;
        for &(k, excess) in &net.excess {
            let axes: Vec<usize> = (0..d).filter(|&l| k[l] > 0).collect();
            let mut sigma = CompensatedSum::default();
            let mut sigma_rounding = 0.0;
            for e in 0..1u32 << axes.len() {
                let mut g = k;
                axes.iter()
                    .enumerate()
                    .filter(|(bit, _)| e >> bit & 1 == 1)
                    .for_each(|(_, &l)| g[l] -= 1);
                let (value, r) = *self.s.get(&g).ok_or_else(missing)?;
                sigma.add(if e.count_ones() % 2 == 0 {
                    value
                } else {
                    -value
                });
                sigma_rounding += r;
            }
            total.add(excess * sigma.value());
            rounding += excess.abs() * sigma_rounding;
        }
        let nf = net.n as f64;
        Ok(CellSum {
            variance: total.value().max(0.0) / nf,
            rounding: rounding / nf,
        })
    }
}

/// The variance of the estimator of a base-2 net under nested uniform scrambling, exactly by
/// Owen's gains read from one scrambled `pattern` of the net: the variance, its rounding bound,
/// and the cells whose moments it read.
///
/// # Errors
/// An integrand of more than 3 axes or without box moments, a pattern whose points coincide, or
/// work beyond `budget`.
pub(crate) fn scrambled_net_variance(
    f: &dyn Integrand,
    pattern: &PointSet,
    budget: &Budget,
) -> Result<(CellSum, usize)> {
    let d = f.dimension();
    let net = ScrambledNet::new(pattern, d, seconds_per_grid_cell(f), budget)?;
    Ok((net.variance(f, &[0.0; MAX_AXES][..d])?, net.cells))
}

/// What [`scrambled_law_variance`] finds: the mean of the patterns' scrambled variances and
/// its standard error, the largest rounding bound of a pattern's, and the cells one pattern's
/// variance reads.
pub(crate) struct ScrambledLawEstimate {
    pub(crate) estimate: OccupancyEstimate,
    pub(crate) cells: usize,
}

/// The variance of a base-2 net whose law nested uniform scrambling leaves unchanged, while its
/// pair counts differ between patterns (a progressive (0,2) sequence's prefix between two
/// powers of two): a scrambled pattern has the law of the patterns, so the variance is
/// `E_P Var[μ | P scrambled]`, the mean over patterns of each one's variance by Owen's gains,
/// exact given the pattern. The integrand's means are computed once, on the grids every level
/// of the first pattern may read; a later pattern whose levels read another grid is an error
/// (a (0,2) sequence's prefix of `N` points shares cells on the grids of at most
/// `2^⌊log2 N⌋` cells, whichever the pattern).
///
/// # Errors
/// An integrand of more than 3 axes or without box moments, a pattern that fails to draw or
/// whose points coincide, work beyond `budget`.
pub(crate) fn scrambled_law_variance(
    f: &dyn Integrand,
    pattern: impl Fn(usize) -> Result<PointSet> + Sync,
    counts: (usize, usize),
    target_noise: f64,
    budget: &Budget,
    progress: &dyn Progress,
) -> Result<ScrambledLawEstimate> {
    let d = f.dimension();
    let cell_seconds = seconds_per_grid_cell(f);
    let first = ScrambledNet::new(&pattern(0)?, d, cell_seconds, budget)?;
    let tops = columns(&grids_read(&first.levels, d), d);
    let means = LevelVariances::new(f, &tops, &vec![0.0; d])?;
    let estimate = mean_of_exact_terms(
        "scrambled variances of patterns",
        counts,
        target_noise,
        0.0,
        |i| match i {
            0 => means.variance(&first),
            _ => means.variance(&ScrambledNet::new(&pattern(i)?, d, cell_seconds, budget)?),
        },
        progress,
    )?;
    Ok(ScrambledLawEstimate {
        estimate,
        cells: tops.iter().map(|g| cells_of(g, d)).sum(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::costs::CELL_SECONDS;
    use crate::sampler::{Sampler, Sobol};

    /// A `(0, m, 2)`-net's gains: 0 up to `k_1 + k_2 = m`, 2 at `m + 1` with both axes refined,
    /// 1 beyond, and on one axis 0 up to `m`, 1 beyond.
    #[test]
    fn a_zero_m_two_net_has_the_known_gains() {
        for m in [0u8, 1, 4, 7] {
            let pattern = Sobol::new(2).unwrap().sample(1 << m, 3, 0).unwrap();
            let mut counts = PairCounts::new(&pattern);
            for k1 in 0..m + 4 {
                for k2 in 0..m + 4 {
                    if k1 + k2 == 0 {
                        continue;
                    }
                    let expected = match (k1, k2) {
                        (_, 0) | (0, _) if k1 + k2 <= m => 0.0,
                        (_, 0) | (0, _) => 1.0,
                        _ if k1 + k2 <= m => 0.0,
                        _ if k1 + k2 == m + 1 => 2.0,
                        _ => 1.0,
                    };
                    assert_eq!(counts.gain([k1, k2, 0]), expected, "m {m}, k ({k1}, {k2})");
                }
            }
        }
    }

    /// PMJ02 at a power of two and Sobol' share their pair counts, and so their gains: both
    /// are `(0, m, 2)`-nets, whose counts the net property fixes (the cell form reads PMJ02's
    /// gains from a Sobol' net).
    #[test]
    fn pmj02_and_sobol_have_the_same_gains_at_powers_of_two() {
        use crate::sampler::Pmj02;
        for m in 0..=12u32 {
            let n = 1usize << m;
            for seed in [1, 2] {
                let budget = Budget::default();
                let pmj = ScrambledNet::new(
                    &Pmj02::new(2).unwrap().sample(n, seed, 3).unwrap(),
                    2,
                    CELL_SECONDS,
                    &budget,
                )
                .unwrap();
                let sobol = ScrambledNet::new(
                    &Sobol::new(2).unwrap().sample(n, seed, 0).unwrap(),
                    2,
                    CELL_SECONDS,
                    &budget,
                )
                .unwrap();
                assert_eq!(pmj.excess, sobol.excess, "N = {n}, seed {seed}");
            }
        }
        // Between powers of two they differ from pattern to pattern.
        let counts = |realization| {
            let p = Pmj02::new(2).unwrap().sample(300, 1, realization).unwrap();
            ScrambledNet::new(&p, 2, CELL_SECONDS, &Budget::default())
                .unwrap()
                .excess
        };
        assert!((0..8).any(|r| counts(r) != counts(0)));
    }

    #[test]
    fn levels_off_one_are_those_of_shared_grids() {
        let pattern = Sobol::new(2).unwrap().sample(16, 1, 0).unwrap();
        let mut counts = PairCounts::new(&pattern);
        let shared = counts.shared_grids().unwrap();
        // Two points share a cell exactly where the 16 cells or fewer leave two per cell.
        assert!(shared.iter().all(|a| a[0] + a[1] <= 3));
        assert_eq!(shared.len(), 10);
        for k in levels_off_one(&shared, 2) {
            let in_k = |a: &Levels| k.iter().zip(a).all(|(x, y)| x >= y);
            assert!(shared.iter().any(in_k));
        }
    }
}

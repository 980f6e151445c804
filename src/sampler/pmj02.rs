//! Progressive multi-jittered (0,2) sequences (Christensen, Kensler and Kilpatrick 2018).

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::{check_supported, uniform, uniform_index, Sampler, SamplerKind};
use crate::error::{Error, Result};
use crate::pointset::PointSet;
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};

/// Progressive multi-jittered (0,2) sequences.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "pmj02",
    description:
        "progressive multi-jittered (0,2) (Christensen et al. 2018): every 2^m prefix a net",
    dimensions: 2..=2,
    count: CountRule::Any,
    balanced_counts: CountRule::PowerOfTwo,
    randomness: Randomness::ScrambledNet,
    native_randomization: Randomization::None,
    cells: CellRule::Dyadic,
    cell_law: CellLaw::ProgressiveNet,
    closed_form: ClosedFormRule::None,
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Partial,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Projections,
    cost_per_point_ns: 330.0,
    cost_growth: 0.5,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// The largest count: `2^26` points (the occupancy of every elementary-interval shape at the
/// last power of two takes `27 · 2^26` bits, 226 MB).
pub const MAX_PMJ02_POINTS: usize = 1 << 26;

/// Progressive multi-jittered (0,2) points in 2D: every prefix of `2^m` points is a (0,m,2)-net in
/// base 2, each of the `m + 1` elementary-interval shapes `2^i × 2^{m-i}` holding exactly one
/// point per cell; at `4^k` points they are also jittered (one per cell of the `2^k × 2^k`
/// grid) and N-rooks.
///
/// The sequence grows as Christensen et al. build it: from `N = 4^k` to `2N`, each point `i`
/// gets a partner in the diagonally opposite quarter of its cell of the `2^k × 2^k` grid; from
/// `2N` to `4N`, the two empty quarters of each cell get one point each, assigned at random.
/// Inside its quarter, a new point's finest strata `(x, y)` (of width `2^{-m}` at the phase's
/// `2^m` points) are drawn so that no elementary interval of any shape is occupied twice:
/// `x` uniformly among the free columns that leave some valid `y`, then `y` uniformly among
/// the valid rows, found by a depth-first walk over the bits of `y` that prunes every prefix
/// whose cell is taken (the idea of Pharr's 2019 construction, which tracks the valid strata
/// instead of throwing darts). The point is then uniform in its finest cell.
///
/// # Examples
/// ```
/// use specvar::sampler::{Pmj02, Sampler};
/// let p = Pmj02::new(2)?.sample(16, 1, 0)?;
/// // One point in each 4 × 4 cell, each of the 16 columns and each of the 16 rows.
/// let mut cells = [0; 16];
/// for i in 0..16 {
///     let x = p.point(i);
///     cells[(x[0] * 4.0) as usize * 4 + (x[1] * 4.0) as usize] += 1;
/// }
/// assert!(cells.iter().all(|&c| c == 1));
/// # Ok::<(), specvar::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Pmj02;

impl Pmj02 {
    /// PMJ02 sampling; only d = 2 exists.
    ///
    /// # Errors
    /// Any dimension other than 2.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self)
    }
}

/// Which cells of every elementary-interval shape `2^i × 2^{m-i}` (`i = 0 … m`) hold a point,
/// at `2^m` points: one bitset of `2^m` cells per shape, a cell indexed `x_cell · 2^{m-i} +
/// y_cell`.
struct Occupancy {
    bits: u32,
    shapes: Vec<Vec<u64>>,
}

impl Occupancy {
    fn new(bits: u32) -> Self {
        let words = (1usize << bits).div_ceil(64);
        Self {
            bits,
            shapes: vec![vec![0; words]; bits as usize + 1],
        }
    }

    /// The cell of shape `i` that finest strata `(x, y)` fall in, through its `y` prefix of
    /// `j = m - i` bits.
    #[inline]
    fn cell(&self, j: u32, x: u64, y_prefix: u64) -> usize {
        (((x >> j) << j) | y_prefix) as usize
    }

    #[inline]
    fn taken(&self, j: u32, x: u64, y_prefix: u64) -> bool {
        let c = self.cell(j, x, y_prefix);
        self.shapes[(self.bits - j) as usize][c / 64] >> (c % 64) & 1 == 1
    }

    /// The free columns (cells of the shape `2^m × 1`) in `[x0, x0 + 2^w)`, as `(word index,
    /// mask of its free bits in the range)`: a popcount per 64 columns instead of a test per
    /// column.
    fn free_column_words(&self, x0: u64, w: u32) -> impl Iterator<Item = (usize, u64)> + '_ {
        let columns = &self.shapes[self.bits as usize];
        let (start, end) = (x0 as usize, (x0 + (1 << w)) as usize);
        (start / 64..end.div_ceil(64)).map(move |word| {
            let (lo, hi) = ((word * 64).max(start), ((word + 1) * 64).min(end));
            let span = hi - lo;
            let range = if span == 64 {
                u64::MAX
            } else {
                ((1u64 << span) - 1) << (lo % 64)
            };
            (word, !columns[word] & range)
        })
    }

    /// How many columns in `[x0, x0 + 2^w)` are free.
    fn free_columns(&self, x0: u64, w: u32) -> usize {
        self.free_column_words(x0, w)
            .map(|(_, free)| free.count_ones() as usize)
            .sum()
    }

    /// The `rank`-th free column in `[x0, x0 + 2^w)`, in increasing order.
    fn nth_free_column(&self, x0: u64, w: u32, mut rank: usize) -> u64 {
        for (word, mut free) in self.free_column_words(x0, w) {
            let count = free.count_ones() as usize;
            if rank < count {
                for _ in 0..rank {
                    free &= free - 1;
                }
                return (word * 64) as u64 + free.trailing_zeros() as u64;
            }
            rank -= count;
        }
        unreachable!("a rank below the count of free columns")
    }

    fn mark(&mut self, x: u64, y: u64) {
        for j in 0..=self.bits {
            let c = self.cell(j, x, y >> (self.bits - j));
            self.shapes[(self.bits - j) as usize][c / 64] |= 1 << (c % 64);
        }
    }

    /// Every `y` in `[y0, y0 + 2^w)` that, with `x`, lands in free cells of every shape.
    fn valid_rows(&self, x: u64, y0: u64, w: u32, out: &mut Vec<u64>) {
        out.clear();
        let fixed = self.bits - w;
        let prefix = y0 >> w;
        if (0..=fixed).any(|j| self.taken(j, x, prefix >> (fixed - j))) {
            return;
        }
        self.extend(x, prefix, fixed, out);
    }

    fn extend(&self, x: u64, prefix: u64, j: u32, out: &mut Vec<u64>) {
        if j == self.bits {
            out.push(prefix);
            return;
        }
        for bit in 0..2 {
            let longer = (prefix << 1) | bit;
            if !self.taken(j + 1, x, longer) {
                self.extend(x, longer, j + 1, out);
            }
        }
    }
}

/// One phase: points added until `2^bits` (or `target`, if fewer), each in its quarter.
struct Phase<'a, R: rand::Rng> {
    occupancy: Occupancy,
    rng: &'a mut R,
    columns: Vec<u64>,
    rows: Vec<u64>,
}

impl<R: rand::Rng> Phase<'_, R> {
    /// Places one point in the quarter whose finest strata start at `(x0, y0)`, `2^w` wide:
    /// a column uniformly among the free ones, then a row among its valid ones; a column
    /// without valid rows is dropped and another drawn. The first draw reads the free columns'
    /// bits (a popcount per 64 columns); only after a column without rows is the list of free
    /// columns built, drawn from as before (the same draws, so the same points).
    fn place(&mut self, x0: u64, y0: u64, w: u32) -> Option<(f64, f64)> {
        let free = self.occupancy.free_columns(x0, w);
        if free == 0 {
            return None;
        }
        let pick = uniform_index(self.rng, free);
        let x = self.occupancy.nth_free_column(x0, w, pick);
        if let Some(point) = self.place_in_column(x, y0, w) {
            return Some(point);
        }
        self.columns.clear();
        for (word, mut free) in self.occupancy.free_column_words(x0, w) {
            while free != 0 {
                self.columns
                    .push((word * 64) as u64 + free.trailing_zeros() as u64);
                free &= free - 1;
            }
        }
        self.columns.swap_remove(pick);
        while !self.columns.is_empty() {
            let pick = uniform_index(self.rng, self.columns.len());
            let x = self.columns.swap_remove(pick);
            if let Some(point) = self.place_in_column(x, y0, w) {
                return Some(point);
            }
        }
        None
    }

    /// A point in column `x`, in a row drawn uniformly among its valid ones, if any.
    fn place_in_column(&mut self, x: u64, y0: u64, w: u32) -> Option<(f64, f64)> {
        let m = self.occupancy.bits;
        let mut rows = std::mem::take(&mut self.rows);
        self.occupancy.valid_rows(x, y0, w, &mut rows);
        let y = (!rows.is_empty()).then(|| rows[uniform_index(self.rng, rows.len())]);
        self.rows = rows;
        let y = y?;
        self.occupancy.mark(x, y);
        let scale = (-(m as i32) as f64).exp2();
        let fx = (x as f64 + uniform(self.rng)) * scale;
        let fy = (y as f64 + uniform(self.rng)) * scale;
        Some((fx.min(super::ONE_MINUS_EPS), fy.min(super::ONE_MINUS_EPS)))
    }
}

/// The quarter index (at `2^{k+1}` per axis) of a coordinate.
fn quarter(v: f64, k: u32) -> u64 {
    (v * (1u64 << (k + 1)) as f64) as u64
}

impl Sampler for Pmj02 {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        2
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::Pmj02)
    }
    fn check_count(&self, n: usize) -> Result<()> {
        super::check_positive(self.name(), 2, n)?;
        if n > MAX_PMJ02_POINTS {
            return Err(Error::UnsupportedCount {
                sampler: self.name(),
                n,
                dimension: 2,
                rule: format!("N at most {MAX_PMJ02_POINTS}"),
                nearest: MAX_PMJ02_POINTS.to_string(),
            });
        }
        Ok(())
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let mut pts: Vec<(f64, f64)> = Vec::with_capacity(n);
        pts.push((uniform(&mut rng), uniform(&mut rng)));
        let mut k = 0u32;
        while pts.len() < n {
            let base = pts.len(); // 4^k
                                  // 4^k → 2·4^k: the diagonally opposite quarter of each point's cell.
            let quarters: Vec<(u64, u64)> = pts
                .iter()
                .map(|&(x, y)| (quarter(x, k) ^ 1, quarter(y, k) ^ 1))
                .collect();
            extend(&mut pts, &quarters, 2 * k + 1, k, n, &mut rng)?;
            if pts.len() >= n {
                break;
            }
            // 2·4^k → 4·4^k: the two empty quarters of each cell, in random order.
            let mut first = Vec::with_capacity(base);
            let mut second = Vec::with_capacity(base);
            for i in 0..base {
                let (qx, qy) = (quarter(pts[i].0, k), quarter(pts[i].1, k));
                let (px, py) = (quarter(pts[base + i].0, k), quarter(pts[base + i].1, k));
                let (a, b) = ((qx, py), (px, qy));
                if uniform_index(&mut rng, 2) == 0 {
                    first.push(a);
                    second.push(b);
                } else {
                    first.push(b);
                    second.push(a);
                }
            }
            first.extend(second);
            extend(&mut pts, &first, 2 * k + 2, k, n, &mut rng)?;
            k += 1;
        }
        pts.truncate(n);
        Ok(PointSet::from_trusted(
            2,
            pts.iter().flat_map(|&(x, y)| [x, y]).collect(),
        ))
    }
}

/// Adds one point in each of `quarters` (at `2^{k+1}` per axis), in order, the phase ending at
/// `2^bits` points, stopping at `target` points.
fn extend<R: rand::Rng>(
    pts: &mut Vec<(f64, f64)>,
    quarters: &[(u64, u64)],
    bits: u32,
    k: u32,
    target: usize,
    rng: &mut R,
) -> Result<()> {
    let mut occupancy = Occupancy::new(bits);
    let total = (1u64 << bits) as f64;
    for &(x, y) in pts.iter() {
        occupancy.mark((x * total) as u64, (y * total) as u64);
    }
    let w = bits - (k + 1);
    let mut phase = Phase {
        occupancy,
        rng,
        columns: Vec::new(),
        rows: Vec::new(),
    };
    for &(qx, qy) in quarters {
        if pts.len() >= target {
            break;
        }
        let point = phase
            .place(qx << w, qy << w, w)
            .ok_or_else(|| Error::Stuck {
                generator: "pmj02",
                placed: pts.len(),
                requested: target,
                reason: "every elementary interval its quarter meets is taken".into(),
            })?;
        pts.push(point);
    }
    Ok(())
}

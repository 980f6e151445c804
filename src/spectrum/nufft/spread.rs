//! Spreading unit masses onto the oversampled grid.
//!
//! Each point adds the tensor product of its kernel values to a `w^d` block of cells. The grid
//! is padded by `w + 1` cells per axis, so every block is contiguous and no index wraps in the
//! inner loop; [`fold`] then adds the padding onto the periodic grid. The points are visited in
//! order of their cell block (a counting sort), so that consecutive blocks share cache lines.
//! The kernel width is a compile-time constant of the inner loops, which the compiler unrolls
//! and vectorizes.

use super::kernel::{KernelTable, MAX_WIDTH};
use crate::pointset::PointSet;

/// Side of the blocks of cells that order the points, in cells: 32 cells of 8 bytes fill four
/// cache lines per row of a block.
const SORT_BLOCK: usize = 32;

/// The padded grid: `side = g + w + 1` cells per axis, with the periodic cell `c` stored at
/// `c + offset` (and the padding folded back onto it by [`fold`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Padded {
    /// The periodic grid size `g`.
    pub grid: usize,
    /// Cells per padded axis.
    pub side: usize,
    /// Where periodic cell 0 sits, `⌊w/2⌋`.
    pub offset: usize,
    /// The dimension.
    pub dimension: usize,
}

impl Padded {
    /// The padded layout of a `d`-dimensional grid of `grid` cells per axis for a kernel of
    /// `width` cells.
    pub fn new(dimension: usize, grid: usize, width: usize) -> Self {
        Self {
            grid,
            side: grid + width + 1,
            offset: width / 2,
            dimension,
        }
    }

    /// The number of cells.
    pub fn len(&self) -> usize {
        self.side.pow(self.dimension as u32)
    }

    /// The flat index of the first cell of periodic row `row` (the row-major index over the
    /// first `d - 1` axes of the periodic grid).
    pub fn row_start(&self, row: usize) -> usize {
        let mut digits = [0usize; 2];
        let mut rest = row;
        for a in (0..self.dimension - 1).rev() {
            digits[a] = rest % self.grid;
            rest /= self.grid;
        }
        digits[..self.dimension - 1]
            .iter()
            .fold(0, |flat, &c| (flat + c + self.offset) * self.side)
            + self.offset
    }
}

/// Caller-owned buffers of the sort.
#[derive(Debug, Clone, Default)]
pub struct SortScratch {
    order: Vec<u32>,
    keys: Vec<u32>,
    counts: Vec<u32>,
}

/// Spreads unit masses at `points` onto the padded grid `cells`, which must be zero (as
/// [`fold`] and the row transforms leave it).
pub fn spread(
    kernel: &KernelTable,
    layout: &Padded,
    points: &PointSet,
    cells: &mut [f64],
    sort: &mut SortScratch,
) {
    block_order(layout, points, sort);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX, checked just above.
        unsafe { spread_avx(kernel, layout, points, &sort.order, cells) };
        return;
    }
    spread_any(kernel, layout, points, &sort.order, cells);
}

/// [`spread_any`] compiled for AVX: wider vectors for the same operations. Without FMA the
/// compiler keeps every multiply and add separately rounded, so the bits are those of the
/// portable build.
///
/// # Safety
/// The CPU must support AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn spread_avx(
    kernel: &KernelTable,
    layout: &Padded,
    points: &PointSet,
    order: &[u32],
    cells: &mut [f64],
) {
    spread_any(kernel, layout, points, order, cells);
}

/// Spreads in the order `order`, with the width as a compile-time constant.
#[inline(always)]
fn spread_any(
    kernel: &KernelTable,
    layout: &Padded,
    points: &PointSet,
    order: &[u32],
    cells: &mut [f64],
) {
    macro_rules! dispatch {
        ($($w:literal)*) => {
            match (layout.dimension, kernel.kernel().width) {
                $((1, $w) => spread_1d::<$w>(kernel, layout, points, order, cells),)*
                $((2, $w) => spread_2d::<$w>(kernel, layout, points, order, cells),)*
                $((3, $w) => spread_3d::<$w>(kernel, layout, points, order, cells),)*
                (d, w) => unreachable!("a plan has 1 to 3 dimensions and widths 2 to {MAX_WIDTH}, not {d}, {w}"),
            }
        };
    }
    dispatch!(2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20);
}

/// Orders the points by the block of [`SORT_BLOCK`] cells per axis that holds them.
fn block_order(layout: &Padded, points: &PointSet, sort: &mut SortScratch) {
    let d = layout.dimension;
    let blocks = layout.grid.div_ceil(SORT_BLOCK);
    let scale = layout.grid as f64 / SORT_BLOCK as f64;
    sort.keys.clear();
    sort.keys.extend(points.points().map(|p| {
        p.iter().fold(0usize, |key, &x| {
            key * blocks + ((x * scale) as usize).min(blocks - 1)
        }) as u32
    }));
    sort.counts.clear();
    sort.counts.resize(blocks.pow(d as u32) + 1, 0);
    for &k in &sort.keys {
        sort.counts[k as usize + 1] += 1;
    }
    for b in 1..sort.counts.len() {
        sort.counts[b] += sort.counts[b - 1];
    }
    sort.order.clear();
    sort.order.resize(points.len(), 0);
    for (i, &k) in sort.keys.iter().enumerate() {
        let slot = &mut sort.counts[k as usize];
        sort.order[*slot as usize] = i as u32;
        *slot += 1;
    }
}

/// The kernel values of a point along one axis and the padded index of its first cell.
#[inline(always)]
fn axis<const W: usize>(
    kernel: &KernelTable,
    layout: &Padded,
    x: f64,
    values: &mut [f64; W],
) -> usize {
    (kernel.values(x, values) + layout.offset as isize) as usize
}

#[inline(always)]
fn spread_1d<const W: usize>(
    kernel: &KernelTable,
    layout: &Padded,
    points: &PointSet,
    order: &[u32],
    cells: &mut [f64],
) {
    let mut kx = [0.0; W];
    for &i in order {
        let first = axis(kernel, layout, points.point(i as usize)[0], &mut kx);
        let block: &mut [f64; W] = (&mut cells[first..first + W]).try_into().expect("W cells");
        for (c, v) in block.iter_mut().zip(&kx) {
            *c += v;
        }
    }
}

#[inline(always)]
fn spread_2d<const W: usize>(
    kernel: &KernelTable,
    layout: &Padded,
    points: &PointSet,
    order: &[u32],
    cells: &mut [f64],
) {
    let side = layout.side;
    let (mut kx, mut ky) = ([0.0; W], [0.0; W]);
    for &i in order {
        let p = points.point(i as usize);
        let fx = axis(kernel, layout, p[0], &mut kx);
        let fy = axis(kernel, layout, p[1], &mut ky);
        for (a, &vx) in kx.iter().enumerate() {
            let start = (fx + a) * side + fy;
            let row: &mut [f64; W] = (&mut cells[start..start + W]).try_into().expect("W cells");
            for (c, vy) in row.iter_mut().zip(&ky) {
                *c += vx * vy;
            }
        }
    }
}

#[inline(always)]
fn spread_3d<const W: usize>(
    kernel: &KernelTable,
    layout: &Padded,
    points: &PointSet,
    order: &[u32],
    cells: &mut [f64],
) {
    let side = layout.side;
    let (mut kx, mut ky, mut kz) = ([0.0; W], [0.0; W], [0.0; W]);
    for &i in order {
        let p = points.point(i as usize);
        let fx = axis(kernel, layout, p[0], &mut kx);
        let fy = axis(kernel, layout, p[1], &mut ky);
        let fz = axis(kernel, layout, p[2], &mut kz);
        for (a, &vx) in kx.iter().enumerate() {
            for (b, &vy) in ky.iter().enumerate() {
                let start = ((fx + a) * side + fy + b) * side + fz;
                let row: &mut [f64; W] =
                    (&mut cells[start..start + W]).try_into().expect("W cells");
                let vxy = vx * vy;
                for (c, vz) in row.iter_mut().zip(&kz) {
                    *c += vxy * vz;
                }
            }
        }
    }
}

/// Adds the padding onto the periodic grid and clears it, axis by axis: padded cell
/// `p < offset` is periodic cell `p - offset + g`, stored at `p + g`; padded cell
/// `p ≥ offset + g` is stored at `p - g`. Axis `a` is folded only within the periodic part of
/// the axes before it, whose padding is already folded and cleared. Only the first `axes`
/// axes are folded: the last is folded row by row where the rows are transformed
/// ([`fold_row`]), while each row is in cache.
pub fn fold(layout: &Padded, cells: &mut [f64], axes: usize) {
    let (side, g, o, d) = (layout.side, layout.grid, layout.offset, layout.dimension);
    for axis in 0..axes {
        let stride = side.pow((d - 1 - axis) as u32);
        for outer in 0..g.pow(axis as u32) {
            // The padded index of the periodic position `outer` over axes 0..axis.
            let mut rest = outer;
            let mut base = 0;
            let mut scale = 1;
            for _ in 0..axis {
                base += (rest % g + o) * scale;
                rest /= g;
                scale *= side;
            }
            let block = &mut cells[base * side * stride..][..side * stride];
            for p in 0..o {
                let (low, high) = block.split_at_mut((p + g) * stride);
                add_and_clear(&mut low[p * stride..][..stride], &mut high[..stride]);
            }
            for p in o + g..side {
                let (low, high) = block.split_at_mut(p * stride);
                add_and_clear(&mut high[..stride], &mut low[(p - g) * stride..][..stride]);
            }
        }
    }
}

/// `to += from; from = 0`.
fn add_and_clear(from: &mut [f64], to: &mut [f64]) {
    for (t, f) in to.iter_mut().zip(from.iter_mut()) {
        *t += *f;
        *f = 0.0;
    }
}

/// Folds the padding of one padded row (`side` cells from `start - offset`) onto its periodic
/// cells, leaving the padding cleared.
pub fn fold_row(layout: &Padded, row: &mut [f64]) {
    let (g, o) = (layout.grid, layout.offset);
    for p in 0..o {
        row[p + g] += row[p];
        row[p] = 0.0;
    }
    for p in o + g..layout.side {
        row[p - g] += row[p];
        row[p] = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{Random, Sampler};
    use crate::spectrum::nufft::kernel::EsKernel;

    /// The AVX build of the spreading loop gives the portable build's bits: the results of a
    /// realization must not depend on the machine.
    #[test]
    fn avx_and_portable_spreading_agree_bit_for_bit() {
        for (d, kmax, width) in [(1, 50, 7), (2, 12, 13), (3, 5, 10)] {
            let grid = 2 * (2 * kmax + 1);
            let table = KernelTable::new(&EsKernel::for_band(width, grid, kmax));
            let layout = Padded::new(d, grid, width);
            let points = Random::new(d).unwrap().sample(500, 3, 0).unwrap();
            let mut sort = SortScratch::default();
            block_order(&layout, &points, &mut sort);
            let mut portable = vec![0.0; layout.len()];
            spread_any(&table, &layout, &points, &sort.order, &mut portable);
            let mut dispatched = vec![0.0; layout.len()];
            spread(&table, &layout, &points, &mut dispatched, &mut sort);
            assert!(portable
                .iter()
                .zip(&dispatched)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
            assert!(portable.iter().any(|&v| v != 0.0));
        }
    }
}

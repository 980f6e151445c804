//! Spreading unit masses onto the oversampled grid.
//!
//! Each point adds the tensor product of its kernel values to a `w^d` block of cells. The grid
//! is padded by `w + 1` cells per axis, so every block is contiguous and no index wraps in the
//! inner loop; [`fold`] then adds the padding onto the periodic grid. The points are visited in
//! order of their cell block (a counting sort), so that consecutive blocks share cache lines.
//! The kernel width is a compile-time constant of the inner loops, which the compiler unrolls
//! and vectorizes.

use super::kernel::{EsKernel, MAX_WIDTH};
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

/// Spreads unit masses at `points` onto the padded grid `cells` (zeroed first).
pub fn spread(
    kernel: &EsKernel,
    layout: &Padded,
    points: &PointSet,
    cells: &mut [f64],
    sort: &mut SortScratch,
) {
    cells.fill(0.0);
    block_order(layout, points, sort);
    macro_rules! dispatch {
        ($($w:literal)*) => {
            match (layout.dimension, kernel.width) {
                $((1, $w) => spread_1d::<$w>(kernel, layout, points, &sort.order, cells),)*
                $((2, $w) => spread_2d::<$w>(kernel, layout, points, &sort.order, cells),)*
                $((3, $w) => spread_3d::<$w>(kernel, layout, points, &sort.order, cells),)*
                (d, w) => unreachable!("a plan has 1 to 3 dimensions and widths 2 to {MAX_WIDTH}, not {d}, {w}"),
            }
        };
    }
    dispatch!(2 3 4 5 6 7 8 9 10 11 12 13 14 15 16);
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
fn axis<const W: usize>(kernel: &EsKernel, layout: &Padded, x: f64, values: &mut [f64; W]) -> usize {
    (kernel.values(x, values) + layout.offset as isize) as usize
}

fn spread_1d<const W: usize>(
    kernel: &EsKernel,
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

fn spread_2d<const W: usize>(
    kernel: &EsKernel,
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

fn spread_3d<const W: usize>(
    kernel: &EsKernel,
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

/// Adds the padding onto the periodic grid, axis by axis: padded cell `p < offset` is periodic
/// cell `p - offset + g`, stored at `p + g`; padded cell `p ≥ offset + g` is stored at `p - g`.
pub fn fold(layout: &Padded, cells: &mut [f64]) {
    let (side, g, o) = (layout.side, layout.grid, layout.offset);
    let d = layout.dimension;
    for axis in 0..d {
        let stride = side.pow((d - 1 - axis) as u32);
        let outer = side.pow(axis as u32);
        for a in 0..outer {
            let base = a * side * stride;
            for p in (0..o).chain(o + g..side) {
                let target = if p < o { p + g } else { p - g };
                let (src, dst) = (base + p * stride, base + target * stride);
                for s in 0..stride {
                    cells[dst + s] += cells[src + s];
                }
            }
        }
    }
}

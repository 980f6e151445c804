//! Spreading unit masses onto the oversampled grid.
//!
//! Each point adds the tensor product of its kernel values to a `w^d` block of cells. The grid
//! is padded by `w + 1` cells per axis, so every block is contiguous along the last axes and no
//! index wraps in the inner loop; the padding is folded back onto the periodic grid afterwards.
//! Along the first axis the grid may be held as a ring of slabs (see `stream`): a point's
//! slab `p` then sits in slot `p mod slots`. The points are visited in order of their cell block
//! (a counting sort), so that consecutive blocks share cache lines and the first axis' blocks
//! come in order. The kernel width is a compile-time constant of the inner loops, which the
//! compiler unrolls and vectorizes.

use super::kernel::{KernelTable, MAX_WIDTH};
use crate::pointset::PointSet;

/// Side of the blocks of cells that order the points, in cells: 32 cells of 8 bytes fill four
/// cache lines per row of a block.
const SORT_BLOCK: usize = 32;

/// The padded grid: `side = g + w + 1` cells per axis, with the periodic cell `c` stored at
/// `c + offset` (and the padding folded back onto it).
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
}

/// Caller-owned buffers of the sort.
#[derive(Debug, Clone, Default)]
pub struct SortScratch {
    /// The points' coordinates in block order, so that spreading reads them in sequence.
    coords: Vec<f64>,
    keys: Vec<u32>,
    counts: Vec<u32>,
    /// Where each block row (the blocks at one index of the first axis) ends, in points.
    row_ends: Vec<u32>,
    dimension: usize,
}

impl SortScratch {
    /// The coordinates of all the points, in block order.
    pub fn sorted(&self) -> &[f64] {
        &self.coords
    }

    /// The number of block rows (the blocks at one index of the first axis).
    pub fn block_row_count(&self) -> usize {
        self.row_ends.len()
    }

    /// The coordinates of the points of block row `b`, in block order. The first axis' blocks
    /// come in increasing order, and the points of block row `b` have their first cell at
    /// padded index `B b - 1` or beyond along the first axis, for blocks of `B` cells along it
    /// ([`first_axis_block`]): the cell of `x` is `⌊x g⌋`, less one for the rounding of
    /// `x g / B`, and the first cell is `offset` before it.
    pub fn block_row(&self, b: usize) -> &[f64] {
        let start = if b == 0 { 0 } else { self.row_ends[b - 1] };
        let d = self.dimension;
        &self.coords[start as usize * d..self.row_ends[b] as usize * d]
    }
}

/// Spreads unit masses at the points whose coordinates are `coords` (`d` per point, in
/// order) onto `cells`: the padded grid, or a ring of `slots` slabs along the first axis
/// (`slots = side` for the whole grid). The cells must be zero where the points land (as
/// folding and the row transforms leave them).
pub fn spread(
    kernel: &KernelTable,
    layout: &Padded,
    coords: &[f64],
    cells: &mut [f64],
    slots: usize,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX, checked just above.
        unsafe { spread_avx(kernel, layout, coords, cells, slots) };
        return;
    }
    spread_any(kernel, layout, coords, cells, slots);
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
    coords: &[f64],
    cells: &mut [f64],
    slots: usize,
) {
    spread_any(kernel, layout, coords, cells, slots);
}

/// Spreads the points in order, with the width as a compile-time constant.
#[inline(always)]
fn spread_any(
    kernel: &KernelTable,
    layout: &Padded,
    coords: &[f64],
    cells: &mut [f64],
    slots: usize,
) {
    macro_rules! dispatch {
        ($($w:literal)*) => {
            match (layout.dimension, kernel.kernel().width) {
                $((1, $w) => spread_1d::<$w>(kernel, layout, coords, cells),)*
                $((2, $w) => spread_2d::<$w>(kernel, layout, coords, cells, slots),)*
                $((3, $w) => spread_3d::<$w>(kernel, layout, coords, cells, slots),)*
                (d, w) => unreachable!("a plan has 1 to 3 dimensions and widths 2 to {MAX_WIDTH}, not {d}, {w}"),
            }
        };
    }
    dispatch!(2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20);
}

/// Orders the points by the block that holds them (the first axis slowest): [`SORT_BLOCK`]
/// cells along each axis but the first, [`first_axis_block`] along the first.
pub fn block_order(layout: &Padded, points: &PointSet, sort: &mut SortScratch) {
    match layout.dimension {
        1 => block_order_in::<1>(layout, points.coords(), sort),
        2 => block_order_in::<2>(layout, points.coords(), sort),
        3 => block_order_in::<3>(layout, points.coords(), sort),
        d => unreachable!("a plan has 1 to 3 dimensions, not {d}"),
    }
}

/// [`block_order`] with the dimension `D` a compile-time constant: each point's key and copy
/// are a few registers' work, where a slice of run-time length took a library copy per point
/// (a tenth of a periodogram's time at 2^20 points).
fn block_order_in<const D: usize>(layout: &Padded, coords: &[f64], sort: &mut SortScratch) {
    let first = first_axis_block(D);
    let side = |a: usize| if a == 0 { first } else { SORT_BLOCK };
    let blocks: [usize; D] = std::array::from_fn(|a| layout.grid.div_ceil(side(a)));
    let scales: [f64; D] = std::array::from_fn(|a| layout.grid as f64 / side(a) as f64);
    let rows = blocks[0];
    let per_row: usize = blocks[1..].iter().product();
    let points = || {
        coords
            .chunks_exact(D)
            .map(|p| -> [f64; D] { std::array::from_fn(|a| p[a]) })
    };
    sort.keys.clear();
    sort.keys.extend(points().map(|p| {
        (0..D).fold(0usize, |key, a| {
            key * blocks[a] + ((p[a] * scales[a]) as usize).min(blocks[a] - 1)
        }) as u32
    }));
    sort.counts.clear();
    sort.counts.resize(rows * per_row + 1, 0);
    for &k in &sort.keys {
        sort.counts[k as usize + 1] += 1;
    }
    for b in 1..sort.counts.len() {
        sort.counts[b] += sort.counts[b - 1];
    }
    sort.dimension = D;
    sort.coords.clear();
    sort.coords.resize(coords.len(), 0.0);
    let (sorted, _) = sort.coords.as_chunks_mut::<D>();
    for (p, &k) in points().zip(&sort.keys) {
        let slot = &mut sort.counts[k as usize];
        sorted[*slot as usize] = p;
        *slot += 1;
    }
    // Each count now holds the end of its block.
    sort.row_ends.clear();
    sort.row_ends
        .extend((1..=rows).map(|b| sort.counts[b * per_row - 1]));
}

/// Side of the blocks along the first axis, in cells: [`SORT_BLOCK`] in 1D and 2D, 4 in 3D.
/// Spreading streams through the first axis one block row at a time (see `stream`); in 3D a
/// block row of 4 planes keeps the slabs in flight near `w + 9` planes, and a block's cells,
/// `(4 + w) (32 + w)²` (a quarter of a megabyte at `w = 12`), within a core's cache, where
/// 32 planes let both spill: a quarter less time for the 3D transform at N = 32768, K = 40.
pub(super) fn first_axis_block(dimension: usize) -> usize {
    if dimension == 3 {
        4
    } else {
        SORT_BLOCK
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
    coords: &[f64],
    cells: &mut [f64],
) {
    let mut kx = [0.0; W];
    for &x in coords {
        let first = axis(kernel, layout, x, &mut kx);
        let block: &mut [f64; W] = (&mut cells[first..first + W]).try_into().expect("W cells");
        for (c, v) in block.iter_mut().zip(&kx) {
            *c += v;
        }
    }
}

/// The slot of the first-axis slab `first + a` in a ring of `slots`, given `start`, the slot of
/// `first`: a compare instead of a division per slab.
#[inline(always)]
fn slot(start: usize, a: usize, slots: usize) -> usize {
    let s = start + a;
    if s >= slots {
        s - slots
    } else {
        s
    }
}

#[inline(always)]
fn spread_2d<const W: usize>(
    kernel: &KernelTable,
    layout: &Padded,
    coords: &[f64],
    cells: &mut [f64],
    slots: usize,
) {
    let side = layout.side;
    let (mut kx, mut ky) = ([0.0; W], [0.0; W]);
    for p in coords.chunks_exact(2) {
        let fx = axis(kernel, layout, p[0], &mut kx) % slots;
        let fy = axis(kernel, layout, p[1], &mut ky);
        for (a, &vx) in kx.iter().enumerate() {
            let start = slot(fx, a, slots) * side + fy;
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
    coords: &[f64],
    cells: &mut [f64],
    slots: usize,
) {
    let side = layout.side;
    let (mut kx, mut ky, mut kz) = ([0.0; W], [0.0; W], [0.0; W]);
    for p in coords.chunks_exact(3) {
        let fx = axis(kernel, layout, p[0], &mut kx) % slots;
        let fy = axis(kernel, layout, p[1], &mut ky);
        let fz = axis(kernel, layout, p[2], &mut kz);
        for (a, &vx) in kx.iter().enumerate() {
            let plane = slot(fx, a, slots) * side;
            for (b, &vy) in ky.iter().enumerate() {
                let start = (plane + fy + b) * side + fz;
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

/// `to += from; from = 0`.
pub fn add_and_clear(from: &mut [f64], to: &mut [f64]) {
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
            let cells = layout.side.pow(d as u32);
            let mut portable = vec![0.0; cells];
            spread_any(&table, &layout, sort.sorted(), &mut portable, layout.side);
            let mut dispatched = vec![0.0; cells];
            spread(&table, &layout, sort.sorted(), &mut dispatched, layout.side);
            assert!(portable
                .iter()
                .zip(&dispatched)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
            assert!(portable.iter().any(|&v| v != 0.0));
        }
    }
}

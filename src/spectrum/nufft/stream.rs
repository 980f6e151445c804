//! Spreading interleaved with the row transforms: the padded grid as a ring of slabs.
//!
//! A slab is the padded grid at one index of the first axis: a row in 2D, a plane in 3D. The
//! points are spread in order of their cell block, block row by block row along the first axis,
//! so after each block row every slab below a known index is complete: no later point touches
//! it. A complete slab is folded along the first axis and, once a batch of rows is ready,
//! transformed along the last axis and cleared, all while it is in cache; the grid then holds
//! only the slabs in flight, a ring of [`Ring::slots`] slabs (slab `p` in slot `p mod slots`)
//! instead of the whole `(g + w + 1)^d` cells, which for a few thousand points would be read
//! from memory once per realization.
//!
//! The first axis is periodic, so each end's padding folds onto the other end. The padding
//! slabs before the periodic grid (`p < offset`) complete first: they are parked, and added
//! onto the last periodic slabs when those complete. The first periodic slabs receive the
//! padding after the grid, which completes only after the last point: they are parked until
//! then. Every cell receives the same additions in the same order as on the whole grid folded
//! afterwards, and the row pairs of the transform are the same, so the bits are those of the
//! whole grid.

use super::ring::{Ring, BATCH};
use super::spread::{self, add_and_clear, first_axis_block, Padded};
use super::{NufftPlan, NufftScratch};
use crate::pointset::PointSet;
use std::ops::Range;

/// How far the stream has come: slabs below `completed` are complete, and the periodic slabs
/// `ready` wait for their row transforms.
struct Front {
    completed: usize,
    ready: Range<usize>,
}

impl NufftPlan {
    /// Spreads `points` and transforms the grid's rows along the last axis into
    /// `scratch.rows` ([`transform_rows`](Self::transform_rows)), leaving the grid cleared.
    pub(super) fn spread_rows(&self, points: &PointSet, scratch: &mut NufftScratch) {
        let layout = &self.layout;
        spread::block_order(layout, points, &mut scratch.sort);
        let Some(ring) = scratch.ring else {
            // 1D: one row, the whole grid.
            let coords = scratch.sort.sorted();
            spread::spread(&self.table, layout, coords, &mut scratch.cells, layout.side);
            self.transform_rows(scratch, 0..1);
            return;
        };
        let mut front = Front {
            completed: 0,
            ready: ring.parked_start..ring.parked_start,
        };
        let block = first_axis_block(self.dimension);
        for b in 0..scratch.sort.block_row_count() {
            let coords = scratch.sort.block_row(b);
            spread::spread(&self.table, layout, coords, &mut scratch.cells, ring.slots);
            self.advance(scratch, &ring, &mut front, block * (b + 1) - 1);
        }
        self.advance(scratch, &ring, &mut front, layout.side);
        self.transform_ready(scratch, &ring, &mut front, true);
        self.unpark_start(scratch, &ring);
    }

    /// Completes the slabs below `until`, transforming the rows of the ready ones by batches.
    fn advance(&self, scratch: &mut NufftScratch, ring: &Ring, front: &mut Front, until: usize) {
        while front.completed < until.min(self.layout.side) {
            self.complete_slab(scratch, ring, front.completed, &mut front.ready);
            front.completed += 1;
            if front.ready.len() * ring.rows_per_slab >= 2 * BATCH {
                self.transform_ready(scratch, ring, front, false);
            }
        }
    }

    /// Folds the complete slab `p` along the first axis: parks it, adds it onto a parked slab,
    /// or (a periodic slab past the parked ones) folds it along the second axis in 3D and marks
    /// it ready.
    fn complete_slab(&self, s: &mut NufftScratch, ring: &Ring, p: usize, ready: &mut Range<usize>) {
        let (g, o, n) = (self.layout.grid, self.layout.offset, ring.slab);
        let slab = &mut s.cells[ring.start(p)..][..n];
        if p < o + ring.parked_start {
            // Padding before the grid, or a first periodic slab: parked at index p.
            s.parked[p * n..][..n].copy_from_slice(slab);
            slab.fill(0.0);
        } else if p < o + g {
            if p >= g {
                // A last periodic slab: the padding slab p - g before the grid folds onto it.
                add_and_clear(&mut s.parked[(p - g) * n..][..n], slab);
            }
            if self.dimension == 3 {
                fold_second_axis(&self.layout, slab);
            }
            ready.end = p - o + 1;
        } else {
            // Padding after the grid, onto the parked periodic slab p - g - o (at index p - g).
            add_and_clear(slab, &mut s.parked[(p - g) * n..][..n]);
        }
    }

    /// Transforms the rows of the ready slabs (in 2D an even number of them unless `last`, so
    /// that rows pair as on the whole grid).
    fn transform_ready(&self, s: &mut NufftScratch, ring: &Ring, front: &mut Front, last: bool) {
        let rps = ring.rows_per_slab;
        let mut slabs = front.ready.len();
        if rps % 2 == 1 && !last {
            slabs -= slabs % 2;
        }
        let first = front.ready.start;
        self.transform_slabs(s, ring, first..first + slabs);
        front.ready.start += slabs;
    }

    /// Transforms the rows of the periodic slabs `slabs`, and in 3D each plane's lines along
    /// the second axis after its rows.
    fn transform_slabs(&self, s: &mut NufftScratch, ring: &Ring, slabs: Range<usize>) {
        let rps = ring.rows_per_slab;
        if self.dimension == 3 {
            for q in slabs {
                self.transform_rows(s, q * rps..(q + 1) * rps);
                self.middle_plane(s, q);
            }
        } else {
            self.transform_rows(s, slabs.start * rps..slabs.end * rps);
        }
    }

    /// After the last point: the first periodic slabs, with the padding after the grid folded
    /// on, go back into the ring (empty by now) and are transformed.
    fn unpark_start(&self, s: &mut NufftScratch, ring: &Ring) {
        let (o, n) = (self.layout.offset, ring.slab);
        for p in o..o + ring.parked_start {
            let slab = &mut s.cells[ring.start(p)..][..n];
            slab.copy_from_slice(&s.parked[p * n..][..n]);
            if self.dimension == 3 {
                fold_second_axis(&self.layout, slab);
            }
        }
        self.transform_slabs(s, ring, 0..ring.parked_start);
    }
}

/// Folds the padding rows of a 3D slab (a padded plane of `side` rows) onto its periodic rows
/// and clears them.
fn fold_second_axis(layout: &Padded, slab: &mut [f64]) {
    let (side, g, o) = (layout.side, layout.grid, layout.offset);
    for r in 0..o {
        let (low, high) = slab.split_at_mut((r + g) * side);
        add_and_clear(&mut low[r * side..][..side], &mut high[..side]);
    }
    for r in o + g..side {
        let (low, high) = slab.split_at_mut(r * side);
        add_and_clear(&mut high[..side], &mut low[(r - g) * side..][..side]);
    }
}

/// Bytes of the grid's buffers for a plan: the ring and the parked slabs in 2D and 3D, the
/// padded row in 1D.
pub(super) fn grid_bytes(layout: &Padded, width: usize) -> f64 {
    let cells = Ring::for_layout(layout, width)
        .map_or(layout.side, |ring| ring.cells() + ring.parked_cells(layout));
    cells as f64 * 8.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{Random, Sampler};

    /// Point sets that stress the ring: random points, points on the edges of the sort's
    /// blocks along the first axis (where the rounding of the block index and of the first
    /// cell meet), points at both ends of the torus (the wrap), and a single point.
    fn stress_sets(d: usize, grid: usize) -> Vec<PointSet> {
        let random = Random::new(d).unwrap().sample(3000, 11, 0).unwrap();
        let edge = |i: usize| {
            let block = first_axis_block(d);
            let b = (i % (grid / block + 1)) * block;
            let nudge = [-1e-12, 0.0, 1e-12][i % 3];
            ((b as f64 / grid as f64) + nudge)
                .rem_euclid(1.0)
                .min(1.0 - f64::EPSILON)
        };
        let coordinates = |count: usize, first: &dyn Fn(usize) -> f64| -> PointSet {
            let rest = Random::new(d).unwrap().sample(count, 5, 1).unwrap();
            let data = (0..count)
                .flat_map(|i| {
                    let mut p = rest.point(i).to_vec();
                    p[0] = first(i);
                    p
                })
                .collect();
            PointSet::new(d, data).unwrap()
        };
        vec![
            random,
            coordinates(600, &edge),
            coordinates(400, &|i| [0.0, 1e-9, 1.0 - 1e-9, 0.999_999][i % 4]),
            coordinates(1, &|_| 0.5),
        ]
    }

    /// The ring gives the bits of the whole grid: the slabs are reused while the sets are
    /// spread, and every cell still receives the same additions in the same order.
    #[test]
    fn the_ring_gives_the_whole_grids_bits() {
        for (d, kmax, tolerance) in [(2, 60, 1e-9), (2, 45, 1e-4), (3, 20, 1e-9), (3, 14, 1e-3)] {
            let plan = NufftPlan::new(d, kmax, 3000, tolerance).unwrap();
            let ring = Ring::new(&plan.layout, plan.width());
            assert!(
                ring.slots < plan.layout.side,
                "the ring must wrap in this test"
            );
            let mut streamed = plan.scratch_with_ring(Some(ring));
            let mut whole = plan.scratch_with_ring(Some(Ring::whole(&plan.layout, plan.width())));
            let half = plan.output_len() / 2 + 1;
            let (mut a, mut b) = (vec![0.0; half], vec![0.0; half]);
            for points in stress_sets(d, plan.grid_size()) {
                plan.half_power_with_scratch(&points, &mut streamed, &mut a)
                    .unwrap();
                plan.half_power_with_scratch(&points, &mut whole, &mut b)
                    .unwrap();
                assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
                // The grid is left cleared for the next set.
                assert!(streamed.cells.iter().all(|&c| c == 0.0));
            }
        }
    }
}

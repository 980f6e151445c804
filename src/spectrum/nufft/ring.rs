//! The ring of slabs that the streamed spreading fills and the row transform empties, and the
//! batch of lines the transform takes at a time, which sizes the ring: the one place both
//! stages read them from.

use super::spread::{first_axis_block, Padded};

/// Lines transformed together.
pub(super) const BATCH: usize = 32;

/// The slabs held at once and the parked ones, for a plan in 2D or 3D.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Ring {
    /// Slabs in the ring.
    pub slots: usize,
    /// Cells per slab, `side^{d-1}`.
    pub slab: usize,
    /// Periodic rows of the last axis per slab, `g^{d-2}`.
    pub rows_per_slab: usize,
    /// Periodic slabs `0..parked_start` wait for the padding after the grid: at least the
    /// `w + 1 - offset` slabs it folds onto, rounded up to even so that the row pairs of the
    /// transform are those of the whole grid.
    pub parked_start: usize,
}

impl Ring {
    /// The ring a plan's scratch holds: none in 1D, whose grid is one padded row.
    pub fn for_layout(layout: &Padded, width: usize) -> Option<Self> {
        (layout.dimension > 1).then(|| Self::new(layout, width))
    }

    /// The ring for `layout` (2D or 3D) and a kernel of `width` cells: slabs from the oldest
    /// still waiting for its row transform to the last one the current block row can touch.
    pub fn new(layout: &Padded, width: usize) -> Self {
        let whole = Self::whole(layout, width);
        // Rows wait in batches: fewer than `2 BATCH` rows' slabs at a time.
        let waiting = (2 * BATCH).div_ceil(whole.rows_per_slab);
        // A block row spans B slabs and its kernels W more; one slab on each side
        // for the rounding of the block index and of the first cell, and two of margin.
        let in_flight = first_axis_block(layout.dimension) + width + 4 + waiting;
        Self {
            slots: in_flight.min(layout.side),
            ..whole
        }
    }

    /// A ring that holds the whole padded grid: no slot is reused.
    pub fn whole(layout: &Padded, width: usize) -> Self {
        let d = layout.dimension as u32;
        Self {
            slots: layout.side,
            slab: layout.side.pow(d - 1),
            rows_per_slab: layout.grid.pow(d - 2),
            parked_start: (width + 1 - layout.offset).next_multiple_of(2),
        }
    }

    /// Cells of the ring.
    pub fn cells(&self) -> usize {
        self.slots * self.slab
    }

    /// Cells of the parked slabs: the padding before the grid, then the first periodic slabs.
    pub fn parked_cells(&self, layout: &Padded) -> usize {
        (layout.offset + self.parked_start) * self.slab
    }

    /// Where slab `p` starts in the ring.
    pub fn start(&self, p: usize) -> usize {
        p % self.slots * self.slab
    }
}

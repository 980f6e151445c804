//! Strata in space: the cell form of the unshifted estimator of strata, N-rooks samplers and nets, and its averages over shifts.

pub(crate) mod cell_moments;
pub(crate) mod cell_pairs;
pub(crate) mod cells;
pub(crate) mod cmj_control;
pub(crate) mod shifted_cells;
pub(crate) mod shuffle_cells;

//! An integrand's moments over the cells of a grid (`Integrand::box_moments` per cell): the
//! cells' means and inner variances that every sum of the cell form reads, tabulated when a
//! route visits more cells than the grid has, and the checks and budget of such sums.

use crate::budget::{Budget, Needs};
use crate::error::{Error, Result};
use crate::integrand::{
    constant_on_cell, wrapped_interval, Integrand, IntegrandKind, SeparableCells,
};
use crate::quadrature::CompensatedSum;
use rayon::prelude::*;

/// The rows' size up to which [`crate::costs::SEPARABLE_CELL_SECONDS`] holds. Beyond, each lookup misses
/// the caches: 70–210 ns a point was measured with rows of 2–8 MB (N = 65536 to 262144,
/// drawing included), so [`crate::costs::CELL_SECONDS`] is kept there.
const SEPARABLE_ROWS_IN_CACHE: usize = 1 << 20;
/// The work of one cell of a whole grid's moments of a 3D ball (Owen's gains read every cell
/// of dyadic grids, coarse and slab-shaped ones among them, most of which the sphere crosses):
/// each crossed cell integrates its slices' disk–rectangle areas over height to 1e-14. The
/// gains of a 3D Sobol' net on `ball` measured 2.0 µs a cell at N = 4096 (1.74 million cells,
/// 3.6 s of CPU) and 1.6 µs at 32768 (20.8 million, 33 s), declared with a margin.
const BALL_GRID_CELL_SECONDS_3D: f64 = 2.5e-6;
/// The most cells an exact sum over all cells visits (Latin hypercube's pairs): `2^24`.
pub(crate) const EXACT_CELL_BUDGET: usize = 1 << 24;
/// Cells per parallel task of a table or a sum: sums over chunks in a fixed order give the same bits
/// on any number of threads.
const TABLE_CHUNK: usize = 4096;
pub(crate) use crate::integrand::CELL_ROUNDING;

/// A sum over cells, with a bound on its rounding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellSum {
    /// The variance.
    pub variance: f64,
    /// A bound on its rounding error.
    pub rounding: f64,
}

/// The box of cell `index` of `grid` (axis 0 varies fastest).
pub(crate) fn cell_box(index: usize, grid: &[usize], lo: &mut [f64], hi: &mut [f64]) {
    let mut rest = index;
    for (a, &m) in grid.iter().enumerate() {
        let i = rest % m;
        rest /= m;
        lo[a] = i as f64 / m as f64;
        hi[a] = (i + 1) as f64 / m as f64;
    }
}

/// `Φ_c = ∫_{c + t} f` for every cell `c` of `grid` (at most 3 axes), in parallel chunks: the
/// cells of the integrand shifted by `t` on the torus, `f_t(x) = f(x + t mod 1)` (`t = 0`: the
/// integrand's own cells).
pub(crate) fn cell_masses(f: &dyn Integrand, grid: &[usize], t: &[f64]) -> Vec<f64> {
    if let Some(cells) = f.grid_masses(grid, t) {
        return cells.masses;
    }
    let d = grid.len();
    let mut mass: Vec<f64> = vec![0.0; grid.iter().product()];
    mass.par_chunks_mut(TABLE_CHUNK)
        .enumerate()
        .for_each(|(c, chunk)| {
            let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
            for (i, slot) in chunk.iter_mut().enumerate() {
                cell_box(c * TABLE_CHUNK + i, grid, &mut lo[..d], &mut hi[..d]);
                *slot = wrapped_box_mass(f, &lo[..d], &hi[..d], t);
            }
        });
    mass
}

/// [`cell_masses`] of the unshifted integrand, and the cells on which `f` is constant up to
/// [`CELL_ROUNDING`] of its mean square (a shape's cells wholly inside or outside it) as a bit
/// set (cell `c` at bit `c % 64` of word `c / 64`): there `f` equals its cell mean almost
/// everywhere. Both from one box per cell, or from the integrand's own [`Integrand::grid_masses`]
/// (a polygon's clips only the cells its boundary touches; a Gaussian's cells all vary, and
/// its set is `None`).
pub(crate) fn masses_and_constant_cells(
    f: &dyn Integrand,
    grid: &[usize],
) -> (Vec<f64>, Option<Vec<u64>>) {
    let d = grid.len();
    if let Some(cells) = f.grid_masses(grid, &[0.0; 3][..d]) {
        return (cells.masses, cells.constant);
    }
    let cells: usize = grid.iter().product();
    let area = 1.0 / cells as f64;
    let mut mass = vec![0.0; cells];
    let mut words = vec![0u64; cells.div_ceil(64)];
    // A chunk of cells is a whole number of words.
    mass.par_chunks_mut(TABLE_CHUNK)
        .zip(words.par_chunks_mut(TABLE_CHUNK / 64))
        .enumerate()
        .for_each(|(c, (masses, bits))| {
            let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
            for (i, slot) in masses.iter_mut().enumerate() {
                cell_box(c * TABLE_CHUNK + i, grid, &mut lo[..d], &mut hi[..d]);
                let (m, square) = f.box_moments(&lo[..d], &hi[..d]).unwrap_or((0.0, 0.0));
                *slot = m;
                if constant_on_cell(m, square, area) {
                    bits[i / 64] |= 1 << (i % 64);
                }
            }
        });
    (mass, Some(words))
}

/// Whether cell `c` is marked in a bit set of constant cells
/// ([`masses_and_constant_cells`]'s layout: bit `c % 64` of word `c / 64`).
pub(crate) fn is_marked(bits: &[u64], c: usize) -> bool {
    bits[c / 64] >> (c % 64) & 1 == 1
}

/// `∫ f` over the box `[lo, hi) + t` taken modulo 1.
fn wrapped_box_mass(f: &dyn Integrand, lo: &[f64], hi: &[f64], t: &[f64]) -> f64 {
    wrapped_box_moments(f, lo, hi, t).0
}

/// `(∫ f, ∫ f²)` over the box `[lo, hi) + t` taken modulo 1: the pieces on either side of each
/// face it crosses, each a box of the unit cube.
fn wrapped_box_moments(f: &dyn Integrand, lo: &[f64], hi: &[f64], t: &[f64]) -> (f64, f64) {
    let d = lo.len();
    let moments = |a: &[f64], b: &[f64]| {
        if a.iter().zip(b).any(|(x, y)| x >= y) {
            (0.0, 0.0)
        } else {
            f.box_moments(a, b).unwrap_or((0.0, 0.0))
        }
    };
    if t.iter().all(|&s| s == 0.0) {
        return moments(lo, hi);
    }
    let (mut mass, mut square) = (0.0, 0.0);
    let (mut a, mut b) = ([0.0; 3], [0.0; 3]);
    // Piece `p`: on axis `l`, bit `l` of `p` picks the part past the face (moved back by 1).
    for p in 0..1u32 << d {
        for l in 0..d {
            (a[l], b[l]) = wrapped_interval(lo[l], hi[l], t[l])[(p >> l & 1) as usize];
        }
        let (m, q) = moments(&a[..d], &b[..d]);
        mass += m;
        square += q;
    }
    (mass, square)
}

/// `(F_c, V_c)` of the integrand shifted by `t` on the torus, `f(x + t mod 1)`: its mean over
/// cell `index` of `grid` and its variance inside the cell.
pub(crate) fn shifted_cell_mean_and_variance(
    f: &dyn Integrand,
    grid: &[usize],
    index: usize,
    t: &[f64],
) -> (f64, f64) {
    let d = grid.len();
    let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
    cell_box(index, grid, &mut lo[..d], &mut hi[..d]);
    let cells: f64 = grid.iter().map(|&m| m as f64).product();
    let (mass, square) = wrapped_box_moments(f, &lo[..d], &hi[..d], t);
    let mean = mass * cells;
    (mean, (square * cells - mean * mean).max(0.0))
}

/// The work of one cell's moments of `f` on `grid`, known before any row is computed: a few
/// products for a separable integrand whose rows fit in the caches, else its kind's cost
/// ([`crate::costs::DISK_CELL_SECONDS`] and the like; [`crate::costs::CELL_SECONDS`] for Gaussians and 3D balls).
pub(crate) fn seconds_per_cell(f: &dyn Integrand, grid: &[usize]) -> f64 {
    // One cell per axis asks whether f is separable at no cost.
    let separable = f.separable_cells(&vec![1; grid.len()]).is_some();
    if separable && separable_row_bytes(grid) <= SEPARABLE_ROWS_IN_CACHE as f64 {
        return crate::costs::SEPARABLE_CELL_SECONDS;
    }
    match (f.kind(), f.dimension()) {
        (IntegrandKind::Ball, 1 | 2) => crate::costs::DISK_CELL_SECONDS,
        (IntegrandKind::Polygon, _) => crate::costs::POLYGON_CELL_SECONDS,
        (IntegrandKind::Grid, _) => crate::costs::GRID_CELL_SECONDS,
        (IntegrandKind::AnisotropicGaussian, _) => crate::costs::ANISOTROPIC_CELL_SECONDS,
        _ => crate::costs::CELL_SECONDS,
    }
}

/// The work of one cell's moments of `f` when every cell of whole grids is read, coarse ones
/// included (Owen's gains): [`crate::costs::CELL_SECONDS`], or [`BALL_GRID_CELL_SECONDS_3D`] for a 3D ball,
/// whose crossed cells cost ten times as much and are most of a coarse grid's.
pub(crate) fn seconds_per_grid_cell(f: &dyn Integrand) -> f64 {
    match (f.kind(), f.dimension()) {
        (IntegrandKind::Ball, 3) => BALL_GRID_CELL_SECONDS_3D,
        _ => crate::costs::CELL_SECONDS,
    }
}

/// The memory of a separable integrand's rows on `grid` (two numbers a cell of each axis).
pub(crate) fn separable_row_bytes(grid: &[usize]) -> f64 {
    16.0 * grid.iter().map(|&m| m as f64).sum::<f64>()
}

/// An integrand's moments over the cells of one grid: from its rows of axis factors where it is
/// separable ([`Integrand::separable_cells`], a few products a cell), else one box at a time
/// ([`Integrand::box_moments`]); the two agree to the bit.
pub(crate) struct CellMoments<'a> {
    f: &'a dyn Integrand,
    grid: &'a [usize],
    cells: f64,
    separable: Option<SeparableCells>,
}

impl<'a> CellMoments<'a> {
    pub(crate) fn new(f: &'a dyn Integrand, grid: &'a [usize]) -> Self {
        Self {
            f,
            grid,
            cells: grid.iter().map(|&m| m as f64).product(),
            separable: f.separable_cells(grid),
        }
    }

    /// `∫ f` over the cube.
    pub(crate) fn integral(&self) -> f64 {
        self.f.integral()
    }

    /// `(F_c, V_c)`: the mean of `f` over cell `index` of the grid and its variance inside the
    /// cell.
    pub(crate) fn mean_and_variance(&self, index: usize) -> (f64, f64) {
        let (mass, square) = match &self.separable {
            Some(rows) => rows.moments(index),
            None => {
                let d = self.grid.len();
                let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
                cell_box(index, self.grid, &mut lo[..d], &mut hi[..d]);
                self.f.box_moments(&lo[..d], &hi[..d]).unwrap_or((0.0, 0.0))
            }
        };
        let mean = mass * self.cells;
        (mean, (square * self.cells - mean * mean).max(0.0))
    }
}

/// Errors unless `f` has closed-form moments over boxes ([`Integrand::box_moments`]).
pub(crate) fn check_box_moments(f: &dyn Integrand) -> Result<()> {
    let d = f.dimension();
    match f.box_moments(&vec![0.0; d], &vec![1.0; d]) {
        Some(_) => Ok(()),
        None => Err(Error::OutsideValidity {
            route: "the cell form of the unshifted estimator".into(),
            reason: format!(
                "{} has no closed form for its integral over a box, which the unshifted \
                 estimator's cells need; measure it with `specvar mc --randomization none`, or \
                 tabulate it on a grid",
                f.label()
            ),
        }),
    }
}

pub(crate) fn check_cells(what: &str, cells: usize, budget: &Budget) -> Result<()> {
    budget.check(
        what,
        Needs {
            memory_bytes: 0.0,
            work_seconds: cells as f64 * crate::costs::CELL_SECONDS,
        },
        "lower N",
    )
}

/// The cells' means, tabulated once when the patterns would visit more cells than the grid
/// has: `F_c − I` per cell, and the within-cell term `(1/N²) Σ_c E[Z_c] V_c` exactly.
pub(crate) struct CellTable {
    pub(crate) deviation: Vec<f64>,
    pub(crate) within: f64,
}

impl CellTable {
    /// The table of `moments`' cells, for patterns of `n` points.
    pub(crate) fn new(moments: &CellMoments, n: usize) -> Self {
        let cells: usize = moments.grid.iter().product();
        let integral = moments.integral();
        let mut deviation = vec![0.0; cells];
        let within: Vec<f64> = deviation
            .par_chunks_mut(TABLE_CHUNK)
            .enumerate()
            .map(|(c, chunk)| {
                let mut within = CompensatedSum::default();
                for (i, slot) in chunk.iter_mut().enumerate() {
                    let (mean, var) = moments.mean_and_variance(c * TABLE_CHUNK + i);
                    *slot = mean - integral;
                    within.add(var);
                }
                within.value()
            })
            .collect();
        let mut total = CompensatedSum::default();
        within.iter().for_each(|&w| total.add(w));
        Self {
            deviation,
            within: total.value() / (n as f64 * cells as f64),
        }
    }
}

/// `Σ_i term(i).0` over `0..count` and `Σ_i term(i).1`, in parallel chunks summed in a fixed
/// order (the same bits on any number of threads).
pub(crate) fn chunked_sum(count: usize, term: impl Fn(usize) -> (f64, f64) + Sync) -> (f64, f64) {
    let parts: Vec<(f64, f64)> = (0..count.div_ceil(TABLE_CHUNK))
        .into_par_iter()
        .map(|c| {
            let (mut a, mut b) = (CompensatedSum::default(), CompensatedSum::default());
            for i in c * TABLE_CHUNK..((c + 1) * TABLE_CHUNK).min(count) {
                let (x, y) = term(i);
                a.add(x);
                b.add(y);
            }
            (a.value(), b.value())
        })
        .collect();
    let (mut a, mut b) = (CompensatedSum::default(), CompensatedSum::default());
    for (x, y) in parts {
        a.add(x);
        b.add(y);
    }
    (a.value(), b.value())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::{Gaussian, Polygon};

    /// The constant cells of a triangle are those its edges miss (a segment clipped to the
    /// cell, Liang–Barsky, keeps a piece of positive length), and a marked cell's mean is the
    /// value at its centre. The masses are [`cell_masses`]'s to the bit (both the polygon's own
    /// grid masses, which `tests/suite/unshifted.rs` checks cell by cell against its box moments); a
    /// Gaussian marks none.
    #[test]
    fn constant_cells_are_those_the_boundary_misses() {
        let vertices = [[0.1, 0.2], [0.8, 0.35], [0.3, 0.9]];
        let triangle = Polygon::new(vertices.to_vec(), 2.0).unwrap();
        let grid = [16, 8];
        let (mass, constant) = masses_and_constant_cells(&triangle, &grid);
        assert_eq!(mass, cell_masses(&triangle, &grid, &[0.0, 0.0]));
        let constant = constant.unwrap();
        // Whether the segment a → b passes through the open box (lo, hi).
        let crosses = |a: [f64; 2], b: [f64; 2], lo: [f64; 2], hi: [f64; 2]| {
            let (mut t0, mut t1) = (0.0f64, 1.0f64);
            for axis in 0..2 {
                let delta = b[axis] - a[axis];
                for (p, q) in [(-delta, a[axis] - lo[axis]), (delta, hi[axis] - a[axis])] {
                    if p == 0.0 {
                        if q <= 0.0 {
                            return false;
                        }
                    } else if p < 0.0 {
                        t0 = t0.max(q / p);
                    } else {
                        t1 = t1.min(q / p);
                    }
                }
            }
            t1 > t0
        };
        let (mut lo, mut hi) = ([0.0; 2], [0.0; 2]);
        for c in 0..16 * 8 {
            cell_box(c, &grid, &mut lo, &mut hi);
            let crossed = (0..3).any(|e| crosses(vertices[e], vertices[(e + 1) % 3], lo, hi));
            let marked = is_marked(&constant, c);
            assert_eq!(
                marked, !crossed,
                "cell {c}: marked {marked}, crossed {crossed}"
            );
            if marked {
                let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
                let mean = mass[c] * 128.0;
                assert!(
                    (mean - triangle.eval(&centre)).abs() <= 1e-12,
                    "cell {c}: {mean}"
                );
            }
        }
        let g = Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap();
        assert!(masses_and_constant_cells(&g, &grid).1.is_none());
    }

    /// A shifted integrand's cells: the separable rows of a Gaussian against one wrapped box
    /// per cell, and for any integrand the cells' masses add up to the integral whatever the
    /// shift (the shift permutes the torus).
    #[test]
    fn shifted_cells_wrap_around_the_faces() {
        let g = Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap();
        let grid = [8, 4];
        let t = [0.93, 0.41];
        let rows = g.grid_masses(&grid, &t).unwrap().masses;
        let (mut lo, mut hi) = ([0.0; 2], [0.0; 2]);
        for (i, &m) in rows.iter().enumerate() {
            cell_box(i, &grid, &mut lo, &mut hi);
            let boxed = wrapped_box_mass(&g, &lo, &hi, &t);
            assert!(
                (m - boxed).abs() <= 1e-15 * g.integral(),
                "cell {i}: {m} vs {boxed}"
            );
        }
        let edge = Polygon::edge(30.0, 0.4, 1.0).unwrap();
        for f in [&g as &dyn Integrand, &edge] {
            for t in [[0.0, 0.0], [0.5, 0.25], [0.31, 0.87]] {
                let total: f64 = cell_masses(f, &[16, 8], &t).iter().sum();
                assert!(
                    (total - f.integral()).abs() <= 1e-14 * f.integral(),
                    "{}: {total} vs {}",
                    f.label(),
                    f.integral()
                );
            }
        }
        // A shift by one cell moves every mass to the neighbouring cell.
        let unshifted = cell_masses(&edge, &[16, 8], &[0.0, 0.0]);
        let moved = cell_masses(&edge, &[16, 8], &[1.0 / 16.0, 0.0]);
        for row in 0..8 {
            for col in 0..16 {
                let (a, b) = (moved[row * 16 + col], unshifted[row * 16 + (col + 1) % 16]);
                assert!((a - b).abs() <= 1e-15, "({col}, {row}): {a} vs {b}");
            }
        }
    }
}

//! Halton's finer digits on a realization, from the points in the varying cells alone.
//!
//! Halton's point `i` has on axis `a` (base `p_a`) its first `m_a` permuted digits from the
//! index's first `m_a` base-`p_a` digits, `i mod p_a^{m_a}`: every point whose index has that
//! residue lies in one cell of `p_a^{m_a}` along that axis, and distinct residues make distinct
//! cells. The level's moduli `p_a^{m_a}` are coprime, so by the Chinese remainder theorem the
//! indices that fall in a cell of the level are one residue modulo their product `M`, found
//! from the per-axis residues of the cell without drawing any other point. The finer digits'
//! part `g = f − (its cell's mean)` is zero on the cells where `f` is constant (most of a fine
//! level's cells for a shape), so a realization needs only the points of the others.
//!
//! A point is the floating-point sum of its digits' values, and its cell is found from that
//! sum, so rounding may move a point lying at a cell's side into the neighbouring cell: the
//! indices of every cell within one cell of a varying one are drawn, and each point is kept
//! where its own cell varies. The points kept are exactly those the direct sum evaluates, and
//! they are summed in the same order.

use crate::predict::strata::cell_moments::is_marked;
use crate::predict::strata::cells::{cell_coordinates, cell_of};
use crate::predict::walsh::forms::Remainder;
use crate::sampler::{Halton, HaltonRealization, Sampler};

/// The most axes (the level's).
const AXES: usize = 3;

/// The candidate cells of a level and the remainder theorem's coefficients.
pub(crate) struct VaryingIndices {
    halton: Halton,
    /// Per axis, the digits of the level.
    digits: Vec<u32>,
    /// Cells within one cell on every axis of a cell where the integrand varies, by their
    /// coordinates.
    candidates: Vec<[u32; AXES]>,
    /// `e_a` with `e_a ≡ 1 (mod M_a)` and `e_a ≡ 0` modulo the other axes' moduli.
    coefficients: Vec<u64>,
    /// `M = Π_a M_a`, `M_a = p_a^{m_a}` the axes' cells.
    modulus: u64,
}

impl VaryingIndices {
    /// The candidates of the level `grid` (`bases[a]^digits[a]` cells on axis `a`, coprime
    /// bases) whose constant cells are marked in `constant`.
    pub(crate) fn new(halton: Halton, grid: &[usize], digits: &[u32], constant: &[u64]) -> Self {
        let d = grid.len();
        let cells: usize = grid.iter().product();
        let mut marked = vec![0u64; cells.div_ceil(64)];
        for c in (0..cells).filter(|&c| !is_marked(constant, c)) {
            let at = cell_coordinates(c, grid);
            for_each_neighbour(&at[..d], grid, |n| marked[n / 64] |= 1 << (n % 64));
        }
        let candidates = (0..cells)
            .filter(|&c| is_marked(&marked, c))
            .map(|c| cell_coordinates(c, grid).map(|x| x as u32))
            .collect();
        let modulus: u64 = grid.iter().map(|&m| m as u64).product();
        let coefficients = grid
            .iter()
            .map(|&m| {
                let (m, rest) = (m as u64, modulus / m as u64);
                rest * inverse_modulo(rest % m, m) % modulus
            })
            .collect();
        Self {
            halton,
            digits: digits.to_vec(),
            candidates,
            coefficients,
            modulus,
        }
    }

    /// The points drawn a realization for `n` indices: the candidates' indices below `n`.
    pub(crate) fn draws(&self, n: usize) -> f64 {
        self.candidates.len() as f64 * (n as f64 / self.modulus as f64).ceil()
    }

    /// `((1/N) Σ_j g(x_j))²` on realization `unit` of `seed` of `n` points, the same bits as
    /// [`Remainder::as_drawn`] on that realization's pattern.
    pub(crate) fn as_drawn(
        &self,
        remainder: &Remainder<'_>,
        n: usize,
        seed: u64,
        unit: u64,
    ) -> f64 {
        let d = self.digits.len();
        let realization = self.halton.realization(seed, unit);
        let residues = self.residues_of_cells(&realization);
        let constant = remainder.constant;
        let mut kept: Vec<(u64, [f64; AXES])> = Vec::new();
        let mut y = [0.0; AXES];
        for cell in &self.candidates {
            let first = (0..d).fold(0u64, |i, a| {
                (i + residues[a][cell[a] as usize] * self.coefficients[a]) % self.modulus
            });
            for index in (first..n as u64).step_by(self.modulus as usize) {
                realization.point(index, &mut y[..d]);
                let c = cell_of(&y[..d], remainder.grid);
                if !constant.is_some_and(|bits| is_marked(bits, c)) {
                    kept.push((index, y));
                }
            }
        }
        kept.sort_unstable_by_key(|&(index, _)| index);
        remainder.squared_mean(n, kept.into_iter().map(|(_, y)| y), d)
    }

    /// Per axis, the index's residue whose points lie in each cell of the axis.
    fn residues_of_cells(&self, realization: &HaltonRealization) -> Vec<Vec<u64>> {
        self.digits
            .iter()
            .enumerate()
            .map(|(a, &m)| {
                let cells = realization.leading_cells(a, m);
                let mut residues = vec![0u64; cells.len()];
                for (r, &c) in cells.iter().enumerate() {
                    residues[c] = r as u64;
                }
                residues
            })
            .collect()
    }
}

/// Whether `sampler` draws `halton`'s realizations (a sampler that says it is Halton but moves
/// its points would not): the first points of realization 0 of `seed`, to the bit.
pub(crate) fn draws_as(halton: &Halton, sampler: &dyn Sampler, n: usize, seed: u64) -> bool {
    let k = n.min(8);
    let realization = halton.realization(seed, 0);
    let mut y = [0.0; AXES];
    sampler.sample(k, seed, 0).is_ok_and(|drawn| {
        drawn.dimension() <= AXES
            && drawn.points().enumerate().all(|(i, x)| {
                realization.point(i as u64, &mut y[..x.len()]);
                x.iter().zip(&y).all(|(a, b)| a.to_bits() == b.to_bits())
            })
    })
}

/// `x⁻¹ mod m` for `x` coprime to `m`, by the extended Euclidean algorithm.
fn inverse_modulo(x: u64, m: u64) -> u64 {
    let (mut a, mut b) = (x as i128, m as i128);
    let (mut u, mut v) = (1i128, 0i128);
    while b != 0 {
        let q = a / b;
        (a, b) = (b, a - q * b);
        (u, v) = (v, u - q * v);
    }
    u.rem_euclid(m as i128) as u64
}

/// Calls `visit` with the index of every cell of `grid` within one cell of `cell` on every
/// axis (the cell itself included; no wrapping at the faces).
fn for_each_neighbour(cell: &[usize], grid: &[usize], mut visit: impl FnMut(usize)) {
    let d = cell.len();
    for code in 0..3usize.pow(d as u32) {
        let (mut index, mut stride, mut rest) = (0usize, 1usize, code);
        let mut inside = true;
        for a in 0..d {
            let c = cell[a] as i64 + (rest % 3) as i64 - 1;
            rest /= 3;
            if c < 0 || c >= grid[a] as i64 {
                inside = false;
                break;
            }
            index += c as usize * stride;
            stride *= grid[a];
        }
        if inside {
            visit(index);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::{Ball, Integrand, Polygon};
    use crate::predict::strata::cell_moments::masses_and_constant_cells;
    use crate::sampler::Sampler;

    /// The points found from the varying cells' indices are summed as the whole realization's
    /// are: the same bits, with fewer and more points than the level's cells, in 1 to 3 axes.
    #[test]
    fn the_varying_cells_indices_give_the_drawn_realizations_remainder() {
        // An integrand, the level's digits per axis, the counts drawn.
        type Case = (Box<dyn Integrand>, Vec<u32>, Vec<usize>);
        let cases: Vec<Case> = vec![
            (
                Box::new(Ball::new(0.2, vec![0.3], 1.0).unwrap()),
                vec![6],
                vec![50, 200],
            ),
            (
                Box::new(Polygon::edge(30.0, 0.4, 1.0).unwrap()),
                vec![5, 3],
                vec![300, 2000],
            ),
            (
                Box::new(Ball::new(0.25, vec![0.15, 0.6], 2.0).unwrap()),
                vec![4, 3],
                vec![1000],
            ),
            (
                Box::new(Ball::new(0.3, vec![0.4, 0.55, 0.9], 1.0).unwrap()),
                vec![3, 2, 1],
                vec![250, 900],
            ),
        ];
        for (f, digits, counts) in cases {
            let d = f.dimension();
            let grid: Vec<usize> = digits
                .iter()
                .zip(crate::sampler::HALTON_BASES)
                .map(|(&m, b)| (b as usize).pow(m))
                .collect();
            let cells: usize = grid.iter().product();
            let (masses, constant) = masses_and_constant_cells(f.as_ref(), &grid);
            let means: Vec<f64> = masses.iter().map(|m| m * cells as f64).collect();
            let constant = constant.expect("a shape's constant cells");
            let remainder = Remainder {
                f: f.as_ref(),
                means: &means,
                grid: &grid,
                constant: Some(&constant),
                axis_means: None,
            };
            let halton = Halton::new(d).unwrap();
            let indices = VaryingIndices::new(halton, &grid, &digits, &constant);
            assert!(indices.candidates.len() < cells, "{}", f.label());
            for n in counts {
                let mut evaluated = 0;
                for unit in 0..8 {
                    let direct = remainder.as_drawn(&halton.sample(n, 3, unit).unwrap());
                    let indexed = indices.as_drawn(&remainder, n, 3, unit);
                    assert_eq!(
                        direct.to_bits(),
                        indexed.to_bits(),
                        "{}, N = {n}, realization {unit}",
                        f.label()
                    );
                    evaluated += usize::from(direct > 0.0);
                }
                assert!(evaluated > 0, "{}, N = {n}: no varying point", f.label());
            }
        }
    }

    #[test]
    fn only_halton_draws_as_halton() {
        let halton = Halton::new(2).unwrap();
        assert!(draws_as(&halton, &halton, 1000, 7));
        let jitter = crate::sampler::Jitter::new(2).unwrap();
        assert!(!draws_as(&halton, &jitter, 1024, 7));
    }

    #[test]
    fn inverses_modulo() {
        for m in [2u64, 9, 27, 125, 4096] {
            for x in (1..m).filter(|x| gcd(*x, m) == 1) {
                assert_eq!(x * inverse_modulo(x, m) % m, 1, "{x} mod {m}");
            }
        }
    }

    fn gcd(a: u64, b: u64) -> u64 {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
}

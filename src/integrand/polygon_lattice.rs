//! A polygon's coefficients and power on a whole lattice, without a sine or cosine per
//! frequency.
//!
//! Each edge from `a` to `b` (`Δ = b − a`, midpoint `m`) contributes
//! `(ω_x Δ_y − ω_y Δ_x) e^{−iω·m} sinc(ω·Δ/2)` at `ω = 2πk` (the edge sum of
//! [`Polygon`](super::Polygon)'s transform). On the lattice `k = (k_x, k_y)` both oscillating
//! factors separate by axis: `e^{−2πi k·m} = e^{−2πi k_x m_x} e^{−2πi k_y m_y}`, and
//! `sin(π k·Δ) = sin(π k_x Δ_x) cos(π k_y Δ_y) + cos(π k_x Δ_x) sin(π k_y Δ_y)`. Tables of
//! these per edge and axis (`2K + 1` entries each) leave a few products per edge and frequency.
//! Near the line `k·Δ = 0` the quotient `sin(π k·Δ)/(π k·Δ)` would divide the sum formula's
//! rounding by a small number, so there (`|π k·Δ| < 1`, `O(K)` frequencies per edge) the sine
//! is taken directly.

use super::COEFFICIENT_TABLES_BYTES;
use crate::spectrum::Lattice;
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Below this `|π k·Δ|` an edge's sinc is evaluated directly: the sum formula's absolute
/// rounding (a few ulps of 1) is then at most a few ulps of the sinc itself.
const DIRECT_SINC_BELOW: f64 = 1.0;

/// One edge's factors along one axis at `k = −K … K`.
struct AxisTable {
    /// `sin(π k Δ_axis)`.
    sin: Vec<f64>,
    /// `cos(π k Δ_axis)`.
    cos: Vec<f64>,
    /// `e^{−2πi k m_axis}`.
    phase: Vec<Complex64>,
}

impl AxisTable {
    fn new(delta: f64, mid: f64, kmax: i64) -> Self {
        let (mut sin, mut cos, mut phase) = (Vec::new(), Vec::new(), Vec::new());
        for k in -kmax..=kmax {
            let (s, c) = (PI * k as f64 * delta).sin_cos();
            sin.push(s);
            cos.push(c);
            phase.push(Complex64::from_polar(1.0, -2.0 * PI * k as f64 * mid));
        }
        Self { sin, cos, phase }
    }
}

/// An edge's vector and its two axis tables.
struct EdgeTable {
    delta: [f64; 2],
    axes: [AxisTable; 2],
}

/// Whether the tables of `edges` edges on `lattice` fit in [`COEFFICIENT_TABLES_BYTES`] (two
/// axes of `2K + 1` sines, cosines and phases each): beyond (thousands of edges on a wide
/// lattice) each frequency takes the edge sum with its sines instead.
pub(super) fn tables_fit(edges: usize, lattice: Lattice) -> bool {
    let per_edge = 2 * lattice.side() * (2 * size_of::<f64>() + size_of::<Complex64>());
    edges.saturating_mul(per_edge) <= COEFFICIENT_TABLES_BYTES
}

/// The tables of `edges` on a lattice of extent `kmax`.
fn edge_tables(edges: &[([f64; 2], [f64; 2])], kmax: i64) -> Vec<EdgeTable> {
    edges
        .iter()
        .map(|&(a, b)| {
            let delta = [b[0] - a[0], b[1] - a[1]];
            let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            EdgeTable {
                delta,
                axes: [
                    AxisTable::new(delta[0], mid[0], kmax),
                    AxisTable::new(delta[1], mid[1], kmax),
                ],
            }
        })
        .collect()
}

/// A polygon's coefficients on `|k_a| ≤ K` from its edges' tables.
pub(super) struct PolygonTables {
    tables: Vec<EdgeTable>,
    kmax: i64,
    area: f64,
    height: f64,
}

impl PolygonTables {
    /// The tables of `edges` (vertex pairs, counter-clockwise or clockwise alike) of the
    /// polygon of `area` and `height` on `|k_a| ≤ kmax` (whose tables fit: [`tables_fit`]).
    pub(super) fn new(edges: &[([f64; 2], [f64; 2])], area: f64, height: f64, kmax: usize) -> Self {
        let kmax = kmax as i64;
        Self {
            tables: edge_tables(edges, kmax),
            kmax,
            area,
            height,
        }
    }

    /// `|f̂(k)|²` at every frequency of the 2D `lattice` (of extent `K`), in lattice order.
    pub(super) fn power_on_lattice(&self, lattice: Lattice, out: &mut [f64]) {
        self.on_lattice(lattice, out, |k, sum| {
            let w2 = squared_frequency(k);
            if w2 == 0.0 {
                (self.height * self.area).powi(2)
            } else {
                (self.height / w2).powi(2) * sum.norm_sqr()
            }
        });
    }

    /// `f̂(k)` at every frequency of the 2D `lattice` (of extent `K`), in lattice order.
    pub(super) fn coefficients_on_lattice(&self, lattice: Lattice, out: &mut [Complex64]) {
        self.on_lattice(lattice, out, |k, sum| self.coefficient(k, sum));
    }

    /// `f̂(k)` from its edge sum: `i (height / |ω|²)` times it, as
    /// [`Polygon`](super::Polygon)'s transform takes it.
    fn coefficient(&self, k: [i64; 2], sum: Complex64) -> Complex64 {
        let w2 = squared_frequency(k);
        if w2 == 0.0 {
            Complex64::new(self.height * self.area, 0.0)
        } else {
            Complex64::new(0.0, self.height / w2) * sum
        }
    }

    /// `value(k, Σ_e flux_e sinc_e e^{−2πi k·m_e})` at every frequency of `lattice`, in lattice
    /// order, rows in parallel.
    fn on_lattice<T: Send>(
        &self,
        lattice: Lattice,
        out: &mut [T],
        value: impl Fn([i64; 2], Complex64) -> T + Sync,
    ) {
        let (kmax, side) = (lattice.kmax as i64, lattice.side());
        out.par_chunks_mut(side)
            .enumerate()
            .for_each(|(row, slots)| {
                let kx = row as i64 - kmax;
                for (col, slot) in slots.iter_mut().enumerate() {
                    let k = [kx, col as i64 - kmax];
                    *slot = value(k, edge_sum(&self.tables, k, [row, col]));
                }
            });
    }
}

impl super::CoefficientTables for PolygonTables {
    fn at(&self, k: &[i64]) -> Complex64 {
        let k = [k[0], k[1]];
        let at = k.map(|c| (c + self.kmax) as usize);
        self.coefficient(k, edge_sum(&self.tables, k, at))
    }
}

/// `|ω|² = 4π² |k|²`.
fn squared_frequency(k: [i64; 2]) -> f64 {
    4.0 * PI * PI * (k[0] * k[0] + k[1] * k[1]) as f64
}

/// `Σ_e flux_e sinc_e e^{−2πi k·m_e}` at `k ≠ 0`, whose table indices are `at`.
fn edge_sum(tables: &[EdgeTable], k: [i64; 2], at: [usize; 2]) -> Complex64 {
    let (kx, ky) = (k[0] as f64, k[1] as f64);
    let mut sum = Complex64::new(0.0, 0.0);
    for e in tables {
        let flux = 2.0 * PI * (kx * e.delta[1] - ky * e.delta[0]);
        let half = PI * (kx * e.delta[0] + ky * e.delta[1]);
        let [x, y] = &e.axes;
        let sinc = if half.abs() < DIRECT_SINC_BELOW {
            crate::spectrum::sinc(half)
        } else {
            (x.sin[at[0]] * y.cos[at[1]] + x.cos[at[0]] * y.sin[at[1]]) / half
        };
        sum += x.phase[at[0]] * y.phase[at[1]] * (flux * sinc);
    }
    sum
}

#[cfg(test)]
mod tests {
    use crate::integrand::{Integrand, Polygon};
    use crate::spectrum::Lattice;
    use num_complex::Complex64;
    use std::f64::consts::PI;

    /// The tables against the edge sum at each frequency (`Integrand::coefficient`, one sine
    /// per edge and frequency). Both take each edge's sine to a few ulps of its argument, at
    /// most `π K (|Δ_x| + |Δ_y|) ≤ 2πK` (argument reduction: the error is absolute, not
    /// relative to the sine, which vanishes where `k·Δ` is a whole number), and divide it by
    /// `max(1, |π k·Δ|)` at most. So each term `flux sinc` is within `8 ε (1 + 2πK)` of
    /// `m_e = |flux| / max(1, |π k·Δ|)`, the two sums within `δ = 8 ε (1 + 2πK) Σ_e m_e`, and
    /// the powers within `2|f̂| δ + δ²` (in the height's units).
    #[test]
    fn the_tables_are_the_edge_sum() {
        let polygons = [
            (vec![[0.1, 0.2], [0.8, 0.1], [0.4, 0.9]], 2.0),
            (vec![[0.2, 0.3], [0.7, 0.3], [0.7, 0.8], [0.2, 0.8]], -1.5),
        ]
        .into_iter()
        .map(|(v, height)| (Polygon::new(v, height).unwrap(), height))
        .chain(
            [(30.0, 0.4), (90.0, 0.25), (45.0, 0.5)]
                .map(|(theta, offset)| (Polygon::edge(theta, offset, 1.0).unwrap(), 1.0)),
        );
        for (f, height) in polygons {
            for kmax in [3, 40, 300] {
                let lattice = Lattice { dimension: 2, kmax };
                let mut fast = vec![0.0; lattice.len()];
                f.power_on_lattice(lattice, &mut fast);
                let mut coefficients = vec![Complex64::new(0.0, 0.0); lattice.len()];
                f.coefficients_on_lattice(lattice, &mut coefficients);
                for (i, &value) in fast.iter().enumerate() {
                    let k = lattice.frequency(i);
                    let exact = f.coefficient(&k[..2]);
                    let w2 = 4.0 * PI * PI * ((k[0] * k[0] + k[1] * k[1]) as f64);
                    let terms = if w2 == 0.0 {
                        0.0
                    } else {
                        edge_term_magnitudes(&f, [k[0] as f64, k[1] as f64]) * height.abs() / w2
                    };
                    let delta = 8.0 * f64::EPSILON * (1.0 + 2.0 * PI * kmax as f64) * terms;
                    let allowed = 2.0 * exact.norm() * delta + delta * delta;
                    assert!(
                        (value - exact.norm_sqr()).abs() <= allowed.max(f64::MIN_POSITIVE),
                        "{} at {k:?}: {value:e} against {:e} (allowed {allowed:e})",
                        f.label(),
                        exact.norm_sqr()
                    );
                    let off = (coefficients[i] - exact).norm();
                    assert!(
                        off <= delta.max(f64::MIN_POSITIVE),
                        "{} at {k:?}: coefficient {} against {exact} (allowed {delta:e})",
                        f.label(),
                        coefficients[i]
                    );
                }
            }
        }
    }

    /// The tables are kept to [`super::COEFFICIENT_TABLES_BYTES`]: a clipped edge's few edges
    /// on the widest lattice the routes use fit; the most vertices a polygon may have, on it,
    /// do not (and take the edge sum frequency by frequency).
    #[test]
    fn the_tables_fit_their_memory() {
        let widest = Lattice {
            dimension: 2,
            kmax: 1024,
        };
        assert!(super::tables_fit(6, widest));
        assert!(!super::tables_fit(crate::integrand::MAX_VERTICES, widest));
        assert!(!super::tables_fit(usize::MAX, widest));
    }

    /// `Σ_e m_e`, `m_e = |flux_e| / max(1, |π k·Δ_e|)`: each edge's term's largest magnitude.
    fn edge_term_magnitudes(f: &Polygon, k: [f64; 2]) -> f64 {
        let v = f.vertices();
        (0..v.len())
            .map(|i| {
                let (a, b) = (v[i], v[(i + 1) % v.len()]);
                let d = [b[0] - a[0], b[1] - a[1]];
                let flux = 2.0 * PI * (k[0] * d[1] - k[1] * d[0]);
                let half = PI * (k[0] * d[0] + k[1] * d[1]);
                flux.abs() / half.abs().max(1.0)
            })
            .sum()
    }
}

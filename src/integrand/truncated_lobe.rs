//! A 2D Gaussian of any covariance truncated to the unit square: its torus Fourier
//! coefficients, integral and projections, one axis in closed form and the other by
//! Gauss–Legendre.
//!
//! With `Σ` the covariance, the lobe `a exp(−½ (x − c)ᵀ Σ⁻¹ (x − c))` factors, at each `y`, into
//! the marginal `a exp(−(y − c_y)²/(2Σ_yy))` and a 1D Gaussian in `x` of mean
//! `m(y) = c_x + (Σ_xy/Σ_yy)(y − c_y)` and width `s = √(Σ_xx − Σ_xy²/Σ_yy)`. The coefficient
//! `∫_0^1 ∫_0^1 f e^{−2πi(k_x x + k_y y)}` is therefore
//! `∫_0^1 a exp(−(y − c_y)²/(2Σ_yy)) e^{−2πi k_y y} T(k_x, m(y), s) dy`, with `T` the truncated
//! 1D Gaussian's coefficient (Faddeeva, exact). The remaining integrand is smooth; composite
//! Gauss–Legendre panels resolve its envelope, the drift of `m(y)` on the scale `s` and every
//! oscillation (at most [`PANEL_PHASE`] radians a panel), which makes the rule exact to
//! rounding.

use super::gaussian::axis_coefficient;
use crate::quadrature::GaussLegendre;
use num_complex::Complex64;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Nodes per panel.
const PANEL_NODES: usize = 20;
/// The largest phase a panel spans: a 20-point rule integrates `e^{iθ}` over 10 radians with an
/// error near `5^{40}/40! ≈ 1e−20`.
const PANEL_PHASE: f64 = 10.0;
/// The marginal is integrated over `c_y ± 9 √Σ_yy` (beyond, `exp(−40.5) ≈ 3e−18` of the peak).
const REACH_SIGMAS: f64 = 9.0;

fn rule() -> &'static GaussLegendre {
    static RULE: OnceLock<GaussLegendre> = OnceLock::new();
    RULE.get_or_init(|| GaussLegendre::new(PANEL_NODES))
}

/// A quadrature node in `y` (see [`TruncatedLobe::nodes`]).
struct Node {
    y: f64,
    weight: f64,
    marginal: f64,
    mean: f64,
}

/// A lobe `height · exp(−½ (x − centre)ᵀ Σ⁻¹ (x − centre))` on the unit square, zero outside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TruncatedLobe {
    /// Σ as (xx, xy, yy).
    pub cov: [f64; 3],
    pub centre: [f64; 2],
    pub height: f64,
}

impl TruncatedLobe {
    /// The same lobe with the axes exchanged.
    fn transposed(&self) -> Self {
        Self {
            cov: [self.cov[2], self.cov[1], self.cov[0]],
            centre: [self.centre[1], self.centre[0]],
            height: self.height,
        }
    }

    /// The lobe squared: covariance halved, height squared.
    pub fn squared(&self) -> Self {
        Self {
            cov: [self.cov[0] / 2.0, self.cov[1] / 2.0, self.cov[2] / 2.0],
            centre: self.centre,
            height: self.height * self.height,
        }
    }

    /// `x`'s conditional mean slope `Σ_xy/Σ_yy` and width `s`.
    fn conditional(&self) -> (f64, f64) {
        let slope = self.cov[1] / self.cov[2];
        let s = (self.cov[0] - self.cov[1] * slope).max(0.0).sqrt();
        (slope, s)
    }

    /// The panels the quadrature in `y` needs before any oscillation: the envelope's and the
    /// drift of `m(y)`'s.
    pub fn base_panels(&self) -> f64 {
        let (lo, hi) = self.reach();
        ((hi - lo) / self.panel_width(0.0)).ceil()
    }

    /// The widest panel for the envelope (`√Σ_yy`), for `m(y)` to move by at most `s`, and for
    /// an oscillation of `frequency` cycles per unit to turn by at most [`PANEL_PHASE`].
    fn panel_width(&self, frequency: f64) -> f64 {
        let (slope, s) = self.conditional();
        let width = self.cov[2]
            .sqrt()
            .min(PANEL_PHASE / (2.0 * PI * frequency.max(1.0)));
        if slope != 0.0 {
            width.min(s / slope.abs())
        } else {
            width
        }
    }

    /// The range of `y` the marginal reaches within the square.
    fn reach(&self) -> (f64, f64) {
        let sd = self.cov[2].sqrt();
        (
            (self.centre[1] - REACH_SIGMAS * sd).max(0.0),
            (self.centre[1] + REACH_SIGMAS * sd).min(1.0),
        )
    }

    /// Quadrature nodes in `y`: the node, its weight, the marginal `a exp(−(y − c_y)²/(2Σ_yy))`
    /// there and the conditional mean `m(y)`, on panels of [`Self::panel_width`].
    fn nodes(&self, frequency: f64) -> Vec<Node> {
        let (lo, hi) = self.reach();
        if hi <= lo {
            return Vec::new();
        }
        let (slope, _) = self.conditional();
        let panels = ((hi - lo) / self.panel_width(frequency))
            .ceil()
            .clamp(1.0, 1e6) as usize;
        let h = (hi - lo) / panels as f64;
        let mut out = Vec::with_capacity(panels * PANEL_NODES);
        for p in 0..panels {
            let a = lo + p as f64 * h;
            for (y, w) in rule().on(a, a + h) {
                let dy = y - self.centre[1];
                out.push(Node {
                    y,
                    weight: w,
                    marginal: self.height * (-dy * dy / (2.0 * self.cov[2])).exp(),
                    mean: self.centre[0] + slope * dy,
                });
            }
        }
        out
    }

    /// The torus coefficient at `k`.
    pub fn coefficient(&self, k: [i64; 2]) -> Complex64 {
        let (slope, s) = self.conditional();
        let frequency = k[1].abs() as f64 + k[0].abs() as f64 * slope.abs();
        self.nodes(frequency)
            .into_iter()
            .map(|n| {
                let phase = Complex64::from_polar(1.0, -2.0 * PI * k[1] as f64 * n.y);
                axis_coefficient(k[0], n.mean, s) * phase * (n.weight * n.marginal)
            })
            .sum()
    }

    /// `|coefficient|²` on the lattice `|k_i| ≤ kmax`, first component major: one pass over the
    /// nodes, each node's `x` coefficients computed once and its phases by recurrence.
    pub fn power_on_lattice(&self, kmax: usize, out: &mut [f64]) {
        let side = 2 * kmax + 1;
        let (slope, s) = self.conditional();
        let nodes = self.nodes(kmax as f64 * (1.0 + slope.abs()));
        let mut sums = vec![Complex64::new(0.0, 0.0); side * side];
        let mut row = vec![Complex64::new(0.0, 0.0); side];
        let mut phases = vec![Complex64::new(0.0, 0.0); side];
        for n in nodes {
            for (i, t) in row.iter_mut().enumerate() {
                *t = axis_coefficient(i as i64 - kmax as i64, n.mean, s) * (n.weight * n.marginal);
            }
            let step = Complex64::from_polar(1.0, -2.0 * PI * n.y);
            phases[0] = Complex64::from_polar(1.0, 2.0 * PI * kmax as f64 * n.y);
            for j in 1..side {
                phases[j] = phases[j - 1] * step;
            }
            for (i, t) in row.iter().enumerate() {
                let line = &mut sums[i * side..(i + 1) * side];
                for (c, p) in line.iter_mut().zip(&phases) {
                    *c += t * p;
                }
            }
        }
        for (o, c) in out.iter_mut().zip(&sums) {
            *o = c.norm_sqr();
        }
    }

    /// `∫_{[0,1)²} f`.
    pub fn integral(&self) -> f64 {
        let (_, s) = self.conditional();
        self.nodes(0.0)
            .into_iter()
            .map(|n| n.weight * n.marginal * axis_coefficient(0, n.mean, s).re)
            .sum()
    }

    /// `∫` of the lobe over the box `[lo, hi]`: at each node in `y` the integral over
    /// `[lo_x, hi_x]` of the conditional 1D Gaussian in closed form (error functions), on
    /// panels no wider than the envelope's and the conditional mean's scales.
    pub fn box_mass(&self, lo: [f64; 2], hi: [f64; 2]) -> f64 {
        let (reach_lo, reach_hi) = self.reach();
        let (a, b) = (lo[1].max(reach_lo), hi[1].min(reach_hi));
        if b <= a {
            return 0.0;
        }
        let (slope, s) = self.conditional();
        let panels = ((b - a) / self.panel_width(0.0)).ceil().clamp(1.0, 1e6) as usize;
        let h = (b - a) / panels as f64;
        (0..panels)
            .map(|p| {
                rule().integrate(a + p as f64 * h, a + (p + 1) as f64 * h, |y| {
                    let dy = y - self.centre[1];
                    let marginal = self.height * (-dy * dy / (2.0 * self.cov[2])).exp();
                    let mean = self.centre[0] + slope * dy;
                    marginal * super::gaussian::axis_mass(lo[0], hi[0], mean, s)
                })
            })
            .sum()
    }

    /// `∫_0^1 F_a(x)² dx` for the projection `F_a = ∫ f dx_other` onto axis `a`.
    pub fn projection_energy(&self, axis: usize) -> f64 {
        // Projecting onto x integrates y out: with the axes exchanged, y is integrated in
        // closed form at each node x.
        let lobe = if axis == 0 { self.transposed() } else { *self };
        let (_, s) = lobe.conditional();
        lobe.nodes(0.0)
            .into_iter()
            .map(|n| {
                let projection = n.marginal * axis_coefficient(0, n.mean, s).re;
                n.weight * projection * projection
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lobe well inside the square: the quadrature gives the full-space transform
    /// `a 2π √det Σ exp(−2π² kᵀΣk) e^{−2πik·c}`, an independent closed form.
    #[test]
    fn a_contained_lobe_gives_the_full_space_transform() {
        let (v1, v2, t) = (0.04f64.powi(2), 0.01f64.powi(2), 0.6f64);
        let (c, s) = (t.cos(), t.sin());
        let cov = [
            v1 * c * c + v2 * s * s,
            (v1 - v2) * c * s,
            v1 * s * s + v2 * c * c,
        ];
        let lobe = TruncatedLobe {
            cov,
            centre: [0.48, 0.53],
            height: 2.0,
        };
        let det = v1 * v2;
        for k in [[0i64, 0], [3, -1], [-7, 9], [20, 15]] {
            let (kx, ky) = (k[0] as f64, k[1] as f64);
            let quad = cov[0] * kx * kx + 2.0 * cov[1] * kx * ky + cov[2] * ky * ky;
            let exact = Complex64::from_polar(
                2.0 * 2.0 * PI * det.sqrt() * (-2.0 * PI * PI * quad).exp(),
                -2.0 * PI * (kx * 0.48 + ky * 0.53),
            );
            let got = lobe.coefficient(k);
            assert!((got - exact).norm() < 1e-14, "{k:?}: {got} against {exact}");
        }
    }
}

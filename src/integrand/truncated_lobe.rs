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

/// The node counts a panel narrower than the widest may take instead of [`PANEL_NODES`].
const SHORT_PANEL_NODES: [usize; 6] = [3, 4, 6, 8, 10, 14];
/// The largest box, as a fraction of the lobe's scale on each axis, whose moments a tensor rule
/// of the lobe's values takes ([`TruncatedLobe::small_box_moments`]): where [`rule_for`] asks
/// for at most 4 nodes on either axis, for `f²` too (its scales are `1/√2` of `f`'s).
const SMALL_BOX_FRACTION: f64 = 0.0025 / std::f64::consts::SQRT_2;
/// The error the node count of a panel is chosen for, as [`PANEL_PHASE`]'s is.
const PANEL_ERROR: f64 = 1.2e-20;

/// The rule for a panel of `fraction` of the widest panel's width: the widest spans at most
/// [`PANEL_PHASE`] radians of the integrand's scale, and an `n`-point rule over `θ` radians
/// errs by about `(θ/2)^{2n}/(2n)!` (`5^{40}/40! ≈ 1.1e−20` for the widest with 20 nodes), so
/// the fewest nodes whose error at `θ = 10 · fraction` is as small. A cell of a fine grid is a
/// small fraction of a panel: a hundredth takes 4 nodes.
fn rule_for(fraction: f64) -> &'static GaussLegendre {
    static RULES: OnceLock<Vec<GaussLegendre>> = OnceLock::new();
    let rules = RULES.get_or_init(|| {
        SHORT_PANEL_NODES
            .iter()
            .map(|&n| GaussLegendre::new(n))
            .collect()
    });
    let half_phase = PANEL_PHASE / 2.0 * fraction;
    SHORT_PANEL_NODES
        .iter()
        .zip(rules)
        .find(|&(&n, _)| {
            let error = (1..=2 * n).fold(1.0, |e, j| e * half_phase / j as f64);
            error <= PANEL_ERROR
        })
        .map_or_else(rule, |(_, r)| r)
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
    /// The quadrature runs along the box's shorter side (the axes exchanged where that is `x`):
    /// a cell of a fine grid is short on one side at least, where a few nodes suffice
    /// ([`rule_for`]), while along a long side the panels would span the lobe's whole reach.
    pub fn box_mass(&self, lo: [f64; 2], hi: [f64; 2]) -> f64 {
        if hi[0] - lo[0] < hi[1] - lo[1] {
            self.transposed()
                .box_mass_along_y([lo[1], lo[0]], [hi[1], hi[0]])
        } else {
            self.box_mass_along_y(lo, hi)
        }
    }

    /// `(∫ f, ∫ f²)` over a box small on the lobe's scales (at most [`SMALL_BOX_FRACTION`] of
    /// `√Σ_yy` and of `s/|slope|` in `y`, of `s` in `x`), else `None`: a tensor Gauss–Legendre
    /// rule of the lobe's values, whose squares are `f²`'s, with the node counts [`rule_for`]
    /// gives each axis at `f²`'s scales (the panels' error model; a cell of a fine grid takes
    /// 3 × 3 nodes), where [`box_mass`](Self::box_mass) of `f` and of `f²` take two quadratures
    /// of a 1D Gaussian's mass at each node. The marginal's reach cuts `y` as there.
    pub fn small_box_moments(&self, lo: [f64; 2], hi: [f64; 2]) -> Option<(f64, f64)> {
        let (slope, s) = self.conditional();
        let fraction_x = (hi[0] - lo[0]) / s;
        let fraction_y = (hi[1] - lo[1]) / self.panel_width(0.0);
        if !(fraction_x <= SMALL_BOX_FRACTION && fraction_y <= SMALL_BOX_FRACTION) {
            return None;
        }
        let (reach_lo, reach_hi) = self.reach();
        let (a, b) = (lo[1].max(reach_lo), hi[1].min(reach_hi));
        if b <= a {
            return Some((0.0, 0.0));
        }
        let square_scale = std::f64::consts::SQRT_2;
        let (rule_x, rule_y) = (
            rule_for(fraction_x * square_scale),
            rule_for(fraction_y * square_scale),
        );
        let (mut mass, mut square) = (0.0, 0.0);
        for (y, wy) in rule_y.on(a, b) {
            let dy = y - self.centre[1];
            let marginal = self.height * (-dy * dy / (2.0 * self.cov[2])).exp();
            let mean = self.centre[0] + slope * dy;
            let (mut row, mut row_square) = (0.0, 0.0);
            for (x, wx) in rule_x.on(lo[0], hi[0]) {
                let t = (x - mean) / s;
                let v = (-0.5 * t * t).exp();
                row += wx * v;
                row_square += wx * v * v;
            }
            mass += wy * marginal * row;
            square += wy * marginal * marginal * row_square;
        }
        Some((mass, square))
    }

    /// [`box_mass`](Self::box_mass) with the quadrature in `y`.
    fn box_mass_along_y(&self, lo: [f64; 2], hi: [f64; 2]) -> f64 {
        let (reach_lo, reach_hi) = self.reach();
        let (a, b) = (lo[1].max(reach_lo), hi[1].min(reach_hi));
        if b <= a {
            return 0.0;
        }
        let (slope, s) = self.conditional();
        let width = self.panel_width(0.0);
        let panels = ((b - a) / width).ceil().clamp(1.0, 1e6) as usize;
        let h = (b - a) / panels as f64;
        let rule = rule_for(h / width);
        (0..panels)
            .map(|p| {
                rule.integrate(a + p as f64 * h, a + (p + 1) as f64 * h, |y| {
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

    /// Boxes from a millionth to half the square on either side, near the lobe and in its
    /// flank: the mass against a tensor Gauss–Legendre rule of the lobe's values on the box
    /// (40 × 40 nodes, exact to rounding on a box no wider than the lobe's scales, and split
    /// into 8 × 8 such boxes where wider), which shares no step with the conditional form.
    #[test]
    fn box_masses_match_a_tensor_rule_on_boxes_of_every_shape() {
        let lobe = TruncatedLobe {
            cov: [0.001975, 0.000909, 0.000925],
            centre: [0.45, 0.6],
            height: 1.5,
        };
        let inverse = {
            let [a, b, c] = lobe.cov;
            let det = a * c - b * b;
            [c / det, -b / det, a / det]
        };
        let value = |x: f64, y: f64| {
            let (dx, dy) = (x - lobe.centre[0], y - lobe.centre[1]);
            let q = inverse[0] * dx * dx + 2.0 * inverse[1] * dx * dy + inverse[2] * dy * dy;
            lobe.height * (-0.5 * q).exp()
        };
        let rule = GaussLegendre::new(40);
        let tensor = |lo: [f64; 2], hi: [f64; 2]| {
            let split = if (hi[0] - lo[0]).max(hi[1] - lo[1]) > 0.01 {
                8
            } else {
                1
            };
            // Shared breakpoints, the last one the box's own: the pieces tile the box exactly
            // (a piece's own width, rounded near 0.44, would be 4e-10 off on a side of 1e-7).
            let point = |a: usize, i: usize| {
                if i == split {
                    hi[a]
                } else {
                    lo[a] + (hi[a] - lo[a]) * i as f64 / split as f64
                }
            };
            let mut total = 0.0;
            for i in 0..split {
                for j in 0..split {
                    total += rule.integrate(point(1, j), point(1, j + 1), |y| {
                        rule.integrate(point(0, i), point(0, i + 1), |x| value(x, y))
                    });
                }
            }
            total
        };
        for (corner, sides) in [
            ([0.44, 0.58], [1e-6, 1e-6]),
            ([0.44, 0.58], [1e-6, 0.3]),
            ([0.3, 0.58], [0.3, 1e-6]),
            ([0.5, 0.62], [2e-3, 5e-4]),
            ([0.52, 0.5], [0.01, 0.2]),
            ([0.0, 0.0], [0.5, 0.5]),
        ] {
            let (lo, hi) = (corner, [corner[0] + sides[0], corner[1] + sides[1]]);
            let (got, want) = (lobe.box_mass(lo, hi), tensor(lo, hi));
            assert!(
                (got - want).abs() <= 1e-12 * want.abs() + 1e-300,
                "{lo:?} to {hi:?}: {got:e} against {want:e}"
            );
        }
    }

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

    /// Boxes small on the lobe's scales, near its peak, in its flank and beyond its reach, for
    /// a tilted and an axis-aligned lobe, for `f` and for `f²`: the tensor rule of the lobe's
    /// values against a 12 × 12 tensor rule of its quadratic form (not factored by the
    /// conditional; exact to rounding on such a box), within rounding; and against the
    /// conditional form, whose 1D masses by differences of `erf` lose about `ε s / h` of
    /// themselves on a box of side `h`.
    #[test]
    fn small_boxes_take_the_tensor_rule_within_rounding() {
        let lobes = [
            TruncatedLobe {
                cov: [0.001975, 0.000909, 0.000925],
                centre: [0.45, 0.6],
                height: 1.5,
            },
            TruncatedLobe {
                cov: [0.0025, 0.0, 0.0004],
                centre: [0.5, 0.5],
                height: 1.0,
            },
        ];
        let reference = GaussLegendre::new(12);
        let mut small = 0;
        for lobe in &lobes {
            let [a, b, c] = lobe.cov;
            let det = a * c - b * b;
            let inverse = [c / det, -b / det, a / det];
            let value = |x: f64, y: f64| {
                let (dx, dy) = (x - lobe.centre[0], y - lobe.centre[1]);
                let q = inverse[0] * dx * dx + 2.0 * inverse[1] * dx * dy + inverse[2] * dy * dy;
                lobe.height * (-0.5 * q).exp()
            };
            let (_, s) = lobe.conditional();
            for &side in &[1e-6, 2.0f64.powi(-20), 1e-5, 3e-5] {
                for &(x, y) in &[
                    (0.45, 0.6),
                    (0.52, 0.63),
                    (0.3, 0.45),
                    (0.1, 0.95),
                    (0.61, 0.57),
                ] {
                    let (lo, hi) = ([x, y], [x + side, y + 0.7 * side]);
                    let Some((mass, square)) = lobe.small_box_moments(lo, hi) else {
                        continue;
                    };
                    small += 1;
                    let (mut m, mut q) = (0.0, 0.0);
                    for (y, wy) in reference.on(lo[1], hi[1]) {
                        for (x, wx) in reference.on(lo[0], hi[0]) {
                            let v = value(x, y);
                            m += wx * wy * v;
                            q += wx * wy * v * v;
                        }
                    }
                    // Beyond the marginal's reach both routes drop what is left: under
                    // `exp(−REACH_SIGMAS²/2)` of the peak.
                    let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
                    let cut = (-0.5 * REACH_SIGMAS * REACH_SIGMAS).exp() * area;
                    let tight = 64.0 * f64::EPSILON;
                    assert!(
                        (mass - m).abs() <= tight * m + cut * lobe.height,
                        "{lobe:?} {lo:?}: {mass} against {m}"
                    );
                    assert!(
                        (square - q).abs() <= tight * q + cut * lobe.height * lobe.height,
                        "{lobe:?} {lo:?}: {square} against {q}"
                    );
                    let loose = 64.0 * f64::EPSILON * s / side;
                    let conditional = lobe.box_mass(lo, hi);
                    assert!(
                        (mass - conditional).abs() <= loose * m + cut * lobe.height,
                        "{lobe:?} {lo:?}: {mass} against {conditional}"
                    );
                }
            }
            // A box wider than the lobe's small scale takes the panels.
            assert!(lobe.small_box_moments([0.4, 0.4], [0.41, 0.41]).is_none());
        }
        assert!(small >= 30, "{small} small boxes");
    }
}

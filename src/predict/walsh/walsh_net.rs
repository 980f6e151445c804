//! A linear digital net under a digital shift, for a product integrand: the Walsh sum at every
//! level, exactly, by one table per axis.
//!
//! Under a uniform digital shift the estimator's variance is `Σ_{κ≠0} |f̌(κ)|² |S_κ|²`
//! ([`super::walsh`]). When the pattern is a linear net of `p` digits per axis
//! ([`LinearNet`]), `|S_κ|²` reads only the first `p` digits `r_l` of each `κ_l`, and is 1 on
//! the net's dual `D` and 0 elsewhere. When the integrand is a product
//! `a Π_l g_l(x_l)` ([`ProductForm`]), `|f̌(κ)|² = a² Π_l |ǧ_l(κ_l)|²`. The sum then folds
//! every finer digit into one table per axis,
//!
//! `G_l(r) = Σ_{κ_l ≡ r} |ǧ_l(κ_l)|² = E_u[(w Σ_c wal_r(c) g_l(c w + u))²]`, `w = 2^{−p}`,
//!
//! (Parseval on one cell of width `w`, `u` uniform in it: the Walsh functions of the digits
//! past `p` are a basis of its functions), and
//!
//! `Var = a² [Σ_{r ∈ D, r ≠ 0} Π_l G_l(r_l) + Π_l G_l(0) − Π_l I_l²]`,
//!
//! with `I_l = ∫ g_l` and `G_l(0) = I_l² + E_u[(w Σ_c g_l(c w + u) − I_l)²]` written so that the
//! last difference is a sum of positive terms. The expectation over `u` is a Gauss–Legendre rule
//! on panels between the factor's breakpoints (where it is analytic, so the rule converges
//! geometrically), doubled until two successive answers agree; the fast Walsh–Hadamard
//! transform gives every `r` at once. Every term is positive, so rounding stays relative
//! (`docs/theory.md`, "Digital shifts of a linear net").

use super::linear_net::LinearNet;
use super::walsh_transform::walsh_hadamard;
use crate::integrand::{AxisFactor, ProductForm};
use crate::pointset::PointSet;
use crate::quadrature::GaussLegendre;
use rayon::prelude::*;

/// Gauss–Legendre nodes on each panel of a cell.
const NODES_PER_PANEL: usize = 6;
/// The most panels a cell's piece is cut into before the route gives way to the measured one.
const MAX_PANELS: usize = 64;
/// Two successive quadratures agreeing to this relative difference end the doubling: the
/// finer one's error is then far below it (Gauss–Legendre on analytic pieces converges
/// geometrically), and the difference is what the budget reports.
const QUADRATURE_TOLERANCE: f64 = 1e-7;
/// The most work the route spends: beyond it (a 3D net's dual of `2^{2p}` elements past
/// `p = 13`) the measured remainder of [`super::walsh`] answers within a few per cent sooner.
const MAX_ROUTE_SECONDS: f64 = 4.0;

/// The variance of a linear net under a digital shift, and its error bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct NetVariance {
    /// The variance, averaged over the patterns.
    pub(crate) variance: f64,
    /// The difference from the quadrature with half as many panels: a bound on this one's
    /// quadrature error.
    pub(crate) quadrature: f64,
    /// A bound on the rounding of the tables and the sum.
    pub(crate) rounding: f64,
    /// Gauss–Legendre nodes per cell (the most of any axis).
    pub(crate) nodes: usize,
    /// Binary digits per axis of the nets.
    pub(crate) digits: u32,
    /// Elements of each net's dual (the largest).
    pub(crate) dual_size: u64,
}

/// One axis's folded energies `G(r)` at `p` digits, and an upper bound on each.
struct FoldedAxis {
    /// `G(r)`; entry 0 is `I² + ε`.
    energy: Vec<f64>,
    /// `G(r)` plus a bound on its rounding.
    upper: Vec<f64>,
    /// `I²`.
    integral_sq: f64,
    /// `ε = G(0) − I²`, computed as a mean of squares.
    excess: f64,
    /// A bound on the rounding of `ε`.
    excess_rounding: f64,
}

/// The nodes and weights (summing to 1) of the rule on `[0, w)`: `panels` equal panels of
/// each piece between the offsets of the factor's breakpoints within a cell.
pub(crate) fn cell_rule(g: &AxisFactor, w: f64, panels: usize) -> Vec<(f64, f64)> {
    let mut ends = vec![0.0, w];
    for b in g.breakpoints() {
        let offset = b - (b / w).floor() * w;
        if 0.0 < offset && offset < w {
            ends.push(offset);
        }
    }
    ends.sort_by(f64::total_cmp);
    ends.dedup();
    let rule = GaussLegendre::new(NODES_PER_PANEL);
    let mut nodes = Vec::new();
    for piece in ends.windows(2) {
        let h = (piece[1] - piece[0]) / panels as f64;
        for k in 0..panels {
            let a = piece[0] + k as f64 * h;
            nodes.extend(rule.on(a, a + h).map(|(u, v)| (u, v / w)));
        }
    }
    nodes
}

/// `G(r)` for every `r < 2^p` of the factor `g`, by the rule of [`cell_rule`].
fn fold_axis(g: &AxisFactor, p: u32, panels: usize) -> FoldedAxis {
    let cells = 1usize << p;
    let w = 1.0 / cells as f64;
    let integral = g.integral();
    let mut energy = vec![0.0; cells];
    let (mut excess, mut rounding_sq, mut worst) = (0.0, 0.0, 0.0f64);
    let mut values = vec![0.0; cells];
    for (u, weight) in cell_rule(g, w, panels) {
        values
            .par_iter_mut()
            .enumerate()
            .for_each(|(c, v)| *v = g.eval(c as f64 * w + u));
        let magnitude: f64 = values.iter().map(|v| v.abs()).sum();
        walsh_hadamard(&mut values);
        // Each transformed value is off by at most one rounding per butterfly and one per
        // factor value, of the sum of magnitudes.
        let delta = (f64::from(p) + 2.0) * f64::EPSILON * w * magnitude;
        worst = worst.max(delta);
        let e = w * values[0] - integral;
        excess += weight * e * e;
        rounding_sq += weight * (2.0 * e.abs() * delta + delta * delta);
        energy
            .par_iter_mut()
            .zip(&values)
            .skip(1)
            .for_each(|(s, &v)| *s += weight * (w * v) * (w * v));
    }
    let integral_sq = integral * integral;
    energy[0] = integral_sq + excess;
    // Σ ω (2|a|δ + δ²) ≤ 2δ √(Σ ω a²) + δ² for weights summing to 1 (Cauchy–Schwarz).
    let upper = energy
        .iter()
        .map(|&s| s + 2.0 * worst * s.sqrt() + worst * worst + 4.0 * f64::EPSILON * s)
        .collect();
    FoldedAxis {
        energy,
        upper,
        integral_sq,
        excess,
        excess_rounding: rounding_sq + 4.0 * f64::EPSILON * excess,
    }
}

/// `Π_l (I_l² + ε_l) − Π_l I_l²` as a sum over the non-empty subsets of axes (of positive
/// terms), and a bound on its rounding (the same sum with each `ε_l` at its upper bound, less
/// the sum).
fn excess_of_product(axes: &[FoldedAxis]) -> (f64, f64) {
    let subsets_sum = |excess: &dyn Fn(&FoldedAxis) -> f64| -> f64 {
        (1..1usize << axes.len())
            .map(|subset| {
                axes.iter()
                    .enumerate()
                    .map(|(l, a)| {
                        if subset >> l & 1 == 1 {
                            excess(a)
                        } else {
                            a.integral_sq
                        }
                    })
                    .product::<f64>()
            })
            .sum()
    };
    let sum = subsets_sum(&|a| a.excess);
    let upper = subsets_sum(&|a| a.excess + a.excess_rounding);
    let terms = (1usize << axes.len()) as f64;
    (
        sum,
        (upper - sum).max(0.0) + 2.0 * terms * f64::EPSILON * sum,
    )
}

/// One pattern's variance (without the height) and its rounding bound, from the tables.
fn net_variance(net: &LinearNet, axes: &[FoldedAxis]) -> (f64, f64) {
    let [sum, upper] = net.sum_over_dual(|kappa| {
        axes.iter().enumerate().fold([1.0, 1.0], |[s, u], (l, a)| {
            let r = net.axis_digits(kappa, l);
            [s * a.energy[r], u * a.upper[r]]
        })
    });
    let (excess, excess_rounding) = excess_of_product(axes);
    let rounding = (upper - sum).max(0.0)
        + excess_rounding
        + 2.0 * net.dual_size() as f64 * f64::EPSILON * sum;
    (sum + excess, rounding)
}

/// The variance of every pattern's estimator under a digital shift (each pattern equally
/// likely) with `panels` panels per piece of a cell.
fn variance_at(form: &ProductForm, nets: &[LinearNet], p: u32, panels: usize) -> (f64, f64) {
    let axes: Vec<FoldedAxis> = form.axes.iter().map(|g| fold_axis(g, p, panels)).collect();
    let (mut variance, mut rounding) = (0.0, 0.0);
    for net in nets {
        let (v, r) = net_variance(net, &axes);
        variance += v;
        rounding += r;
    }
    let scale = form.height * form.height / nets.len() as f64;
    (scale * variance, scale * rounding)
}

/// The estimated work of the route's tables with `panels` panels per piece, and of the sums
/// over every net's dual, in seconds of one core.
fn work_seconds(form: &ProductForm, nets: &[LinearNet], p: u32, panels: usize) -> f64 {
    let d = form.axes.len() as f64;
    let nodes: usize = form
        .axes
        .iter()
        .map(|g| (g.breakpoints().len() + 1) * panels * NODES_PER_PANEL)
        .sum();
    let tables = nodes as f64 * (1u64 << p) as f64 * crate::costs::CELL_NODE_SECONDS;
    let duals: f64 = nets.iter().map(|n| n.dual_size() as f64).sum();
    tables + duals * d * crate::costs::DUAL_SECONDS
}

/// The exact variance of `patterns` (each equally likely) under a uniform digital shift, when
/// every pattern is a linear net up to a digital shift, all with the same digits, the
/// integrand `form` is a product, and the route's work fits `work_seconds` and its tables
/// `memory_bytes`; `None` otherwise (the measured route then answers).
pub(crate) fn linear_net_variance(
    form: &ProductForm,
    patterns: &[PointSet],
    work_seconds_allowed: f64,
    memory_bytes: f64,
) -> Option<NetVariance> {
    let work_seconds_allowed = work_seconds_allowed.min(MAX_ROUTE_SECONDS);
    let nets: Vec<LinearNet> = patterns.iter().map(LinearNet::of).collect::<Option<_>>()?;
    let p = nets.first()?.digits();
    let d = form.axes.len();
    if nets.iter().any(|n| n.digits() != p || n.dimension() != d) {
        return None;
    }
    let table_bytes = 3.0 * d as f64 * 8.0 * (1u64 << p) as f64;
    let mut spent = work_seconds(form, &nets, p, 1);
    if table_bytes > memory_bytes || spent > work_seconds_allowed {
        return None;
    }
    let mut panels = 1;
    let mut coarse = variance_at(form, &nets, p, panels);
    while panels < MAX_PANELS {
        panels *= 2;
        spent += work_seconds(form, &nets, p, panels);
        if spent > work_seconds_allowed {
            return None;
        }
        let fine = variance_at(form, &nets, p, panels);
        let difference = (fine.0 - coarse.0).abs();
        if difference <= QUADRATURE_TOLERANCE * fine.0.abs() {
            let w = 1.0 / (1u64 << p) as f64;
            return Some(NetVariance {
                variance: fine.0,
                quadrature: difference,
                rounding: fine.1,
                nodes: form
                    .axes
                    .iter()
                    .map(|g| cell_rule(g, w, panels).len())
                    .max()?,
                digits: p,
                dual_size: nets.iter().map(LinearNet::dual_size).max()?,
            });
        }
        coarse = fine;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::{parse_integrand, Integrand};
    use crate::quadrature::GaussLegendre;
    use crate::sampler::{Sampler, SobolNet};

    fn integrand(text: &str, d: usize) -> Box<dyn Integrand> {
        parse_integrand(text).and_then(|s| s.build(d)).unwrap()
    }

    /// The variance by its definition, `E_Δ[(μ(Δ) − I)²]` over a uniform digital shift `Δ`,
    /// in space: `Δ`'s first `p` digits `a` take every value (the points move to the cells
    /// `u_j ⊕ a`), and its finer part `δ`, common to every point, is integrated by a tensor
    /// Gauss–Legendre rule of `q` nodes on each piece of the cell between the integrand's
    /// breakpoints. No Walsh function appears.
    fn by_definition(f: &dyn Integrand, pattern: &PointSet, p: u32, q: usize) -> f64 {
        let d = pattern.dimension();
        let w = 1.0 / f64::from(1u32 << p);
        let form = f.product_form().unwrap();
        let rule = GaussLegendre::new(q);
        let axis_rules: Vec<Vec<(f64, f64)>> = form
            .axes
            .iter()
            .map(|g| {
                let mut ends = vec![0.0, w];
                ends.extend(g.breakpoints().iter().map(|b| b % w).filter(|&o| o > 0.0));
                ends.sort_by(f64::total_cmp);
                ends.windows(2)
                    .flat_map(|e| {
                        rule.on(e[0], e[1])
                            .map(|(x, v)| (x, v / w))
                            .collect::<Vec<_>>()
                    })
                    .collect()
            })
            .collect();
        let cells: Vec<Vec<usize>> = pattern
            .points()
            .map(|x| x.iter().map(|&t| (t / w) as usize).collect())
            .collect();
        let integral = f.integral();
        let mut total = 0.0;
        let mut y = vec![0.0; d];
        for a in 0..1usize << (d as u32 * p) {
            let digits: Vec<usize> = (0..d)
                .map(|l| (a >> (l as u32 * p)) & ((1 << p) - 1))
                .collect();
            let mut node = vec![0usize; d];
            'nodes: loop {
                let weight: f64 = (0..d).map(|l| axis_rules[l][node[l]].1).product();
                let mut sum = 0.0;
                for c in &cells {
                    for l in 0..d {
                        y[l] = (c[l] ^ digits[l]) as f64 * w + axis_rules[l][node[l]].0;
                    }
                    sum += f.eval(&y);
                }
                let e = sum / pattern.len() as f64 - integral;
                total += weight * e * e;
                for l in 0..d {
                    node[l] += 1;
                    if node[l] < axis_rules[l].len() {
                        continue 'nodes;
                    }
                    node[l] = 0;
                }
                break;
            }
        }
        total / (1usize << (d as u32 * p)) as f64
    }

    /// The route against the definition, on Sobol' nets in one, two and three axes, for
    /// Gaussians (analytic) and a rectangle (jumps inside cells). Both are exact to
    /// quadrature: they must agree within the route's bound, the definition's own quadrature
    /// change (`q` = 6 against 9) and its summation's rounding.
    #[test]
    fn the_route_is_the_variance_by_definition() {
        for (text, d, n) in [
            ("gaussian:sigma=0.2,c=0.2;0.7", 2, 32),
            ("gaussian:sigma=0.05,c=0.3;0.6", 2, 32),
            ("polygon:0.2,0.3;0.7,0.3;0.7,0.8;0.2,0.8", 2, 32),
            ("gaussian:sigma=0.15,c=0.3", 1, 16),
            ("gaussian:sigma=0.15,c=0.3", 3, 8),
        ] {
            let f = integrand(text, d);
            let pattern = SobolNet::new(d).unwrap().sample(n, 0, 0).unwrap();
            let form = f.product_form().unwrap();
            let route = linear_net_variance(&form, std::slice::from_ref(&pattern), 60.0, 1e9)
                .expect("a Sobol' net and a product");
            let p = route.digits;
            let (coarse, fine) = (
                by_definition(f.as_ref(), &pattern, p, 6),
                by_definition(f.as_ref(), &pattern, p, 9),
            );
            let allowed = route.quadrature
                + route.rounding
                + (fine - coarse).abs()
                + 1e3 * f64::EPSILON * f.integral_of_square();
            assert!(
                (route.variance - fine).abs() <= allowed,
                "{text} d {d} N {n}: route {:e}, definition {fine:e} (allowed {allowed:e})",
                route.variance
            );
        }
    }
}

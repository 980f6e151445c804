//! Quadrature rules: Gauss–Legendre nodes, panel rules and compensated sums.

use std::f64::consts::PI;

/// Gauss–Legendre nodes and weights on `[-1, 1]` with `n` points (Newton's method on the
/// Legendre recurrence; exact for polynomials of degree `2n - 1`).
///
/// # Examples
/// ```
/// let (x, w) = specvar::quadrature::gauss_legendre(5);
/// let integral: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(8)).sum();
/// assert!((integral - 2.0 / 9.0).abs() < 1e-15);
/// ```
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        // Tricomi's initial guess, then Newton.
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 0.0;
        for _ in 0..100 {
            let (p, dp) = legendre_with_derivative(n, x);
            derivative = dp;
            let step = p / dp;
            x -= step;
            if step.abs() < 1e-16 {
                break;
            }
        }
        let (_, dp) = legendre_with_derivative(n, x);
        derivative = if dp != 0.0 { dp } else { derivative };
        let w = 2.0 / ((1.0 - x * x) * derivative * derivative);
        nodes[i] = -x;
        nodes[n - 1 - i] = x;
        weights[i] = w;
        weights[n - 1 - i] = w;
    }
    (nodes, weights)
}

/// `P_n(x)` and `P_n'(x)` by the three-term recurrence.
fn legendre_with_derivative(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
        p0 = p1;
        p1 = p2;
    }
    let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, dp)
}

/// A Gauss–Legendre rule mapped onto intervals.
#[derive(Debug, Clone)]
pub struct GaussLegendre {
    nodes: Vec<f64>,
    weights: Vec<f64>,
}

impl GaussLegendre {
    /// An `n`-point rule.
    pub fn new(n: usize) -> Self {
        let (nodes, weights) = gauss_legendre(n);
        Self { nodes, weights }
    }

    /// The rule's nodes and weights mapped onto `[a, b]`: `∫_a^b f ≈ Σ w f(x)`.
    pub fn on(&self, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let (mid, half) = ((a + b) / 2.0, (b - a) / 2.0);
        self.nodes
            .iter()
            .zip(&self.weights)
            .map(move |(x, w)| (mid + half * x, w * half))
    }

    /// `∫_a^b f`.
    pub fn integrate(&self, a: f64, b: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
        let (mid, half) = ((a + b) / 2.0, (b - a) / 2.0);
        let mut sum = 0.0;
        for (x, w) in self.nodes.iter().zip(&self.weights) {
            sum += w * f(mid + half * x);
        }
        sum * half
    }
}

/// Kahan–Babuška (Neumaier) compensated sum.
#[derive(Debug, Clone, Copy, Default)]
pub struct CompensatedSum {
    sum: f64,
    compensation: f64,
}

impl CompensatedSum {
    /// Adds a term.
    pub fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.compensation += (self.sum - t) + x;
        } else {
            self.compensation += (x - t) + self.sum;
        }
        self.sum = t;
    }
    /// The sum so far.
    pub fn value(&self) -> f64 {
        self.sum + self.compensation
    }
}

/// The result of a panel quadrature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PanelResult {
    /// The integral.
    pub value: f64,
    /// The sum of the panels' error estimates.
    pub error: f64,
    /// Function evaluations.
    pub evaluations: u64,
}

/// `∫ f` over consecutive panels `[b_i, b_{i+1}]` (sorted breakpoints), with the
/// double-exponential rule of the `quadrature` crate on each panel and a compensated sum.
/// Panels should hold at most half an oscillation and no kink of `f`: there the rule converges
/// fast; on a long oscillatory range in one call it does not. The panels are integrated in
/// parallel and summed in their order, so the result has the same bits on any thread count.
pub fn integrate_panels(
    breakpoints: &[f64],
    tolerance: f64,
    f: impl Fn(f64) -> f64 + Sync,
) -> PanelResult {
    use rayon::prelude::*;
    let panels: Vec<(f64, f64, u64)> = breakpoints
        .par_windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| {
            let out = quadrature::double_exponential::integrate(&f, w[0], w[1], tolerance);
            (
                out.integral,
                out.error_estimate,
                out.num_function_evaluations as u64,
            )
        })
        .collect();
    let mut sum = CompensatedSum::default();
    let (mut error, mut evaluations) = (0.0, 0u64);
    for (integral, panel_error, panel_evaluations) in panels {
        sum.add(integral);
        error += panel_error;
        evaluations += panel_evaluations;
    }
    PanelResult {
        value: sum.value(),
        error,
        evaluations,
    }
}

/// Breakpoints `0, w, 2w, … , end` merged with extra points inside `(0, end)`.
pub fn panel_breakpoints(end: f64, width: f64, extra: impl IntoIterator<Item = f64>) -> Vec<f64> {
    let count = (end / width).ceil().max(1.0) as usize;
    let mut points: Vec<f64> = (0..count).map(|i| i as f64 * width).collect();
    points.push(end);
    points.extend(extra.into_iter().filter(|&x| x > 0.0 && x < end));
    points.sort_by(f64::total_cmp);
    // Drop near-duplicates: a sliver panel only costs evaluations.
    points.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * end.max(1.0));
    points
}

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

/// One panel's estimate by an adaptive rule: the value, a bound on its error, and the work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PanelEstimate {
    /// The panel's integral.
    pub value: f64,
    /// An estimate of its error (an upper estimate for smooth integrands).
    pub error: f64,
    /// Function evaluations.
    pub evaluations: u64,
}

/// The pair of Gauss–Legendre rules of an adaptive quadrature: the 10-point rule's value, and
/// its difference from the 5-point rule's as the error estimate (other counts by
/// [`EmbeddedRules::new`]). For an integrand smooth on the
/// panel the 10-point rule's true error is far below that difference (it is exact to degree 19,
/// the 5-point rule to degree 9), so the estimate is an upper one; at a kink both rules err by
/// about the same, and bisection shrinks the kink's panel until its share is small.
#[derive(Debug, Clone)]
pub struct EmbeddedRules {
    low: GaussLegendre,
    high: GaussLegendre,
}

/// Points of the lower rule of [`EmbeddedRules`].
const LOW_RULE_POINTS: usize = 5;
/// Points of the higher rule of [`EmbeddedRules`].
const HIGH_RULE_POINTS: usize = 10;

impl Default for EmbeddedRules {
    fn default() -> Self {
        Self::new(LOW_RULE_POINTS, HIGH_RULE_POINTS)
    }
}

impl EmbeddedRules {
    /// A lower rule of `low` points and a higher one of `high` points (`low < high`): the
    /// higher one's value, their difference its error estimate.
    pub fn new(low: usize, high: usize) -> Self {
        Self {
            low: GaussLegendre::new(low),
            high: GaussLegendre::new(high),
        }
    }

    /// The nodes of both rules on `[a, b]`, the lower rule's first: 15 abscissae and their
    /// weights.
    pub fn nodes(&self, a: f64, b: f64) -> Vec<(f64, f64)> {
        self.nodes_on(a, b).collect()
    }

    /// The points of the lower rule and of the higher one.
    pub fn point_counts(&self) -> (usize, usize) {
        (self.low.nodes.len(), self.high.nodes.len())
    }

    /// [`EmbeddedRules::nodes`] without collecting them, for hot loops.
    pub fn nodes_on(&self, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.low.on(a, b).chain(self.high.on(a, b))
    }

    /// The panel's estimate of `f`, whose value at each node comes with a bound on its own
    /// error: [`EmbeddedRules::estimate`] of its values at [`EmbeddedRules::nodes`], without
    /// collecting either (the same sums in the same order, for hot loops).
    ///
    /// # Examples
    /// ```
    /// use specvar::quadrature::EmbeddedRules;
    /// let p = EmbeddedRules::default().integrate(0.0, 1.0, |x| (x.powi(12), 0.0));
    /// assert!((p.value - 1.0 / 13.0).abs() < 1e-15 && p.error > 0.0);
    /// ```
    pub fn integrate(&self, a: f64, b: f64, mut f: impl FnMut(f64) -> (f64, f64)) -> PanelEstimate {
        let mut low = 0.0;
        for (x, w) in self.low.on(a, b) {
            low += w * f(x).0;
        }
        let (mut high, mut inner) = (0.0, 0.0);
        for (x, w) in self.high.on(a, b) {
            let (v, e) = f(x);
            high += w * v;
            inner += w.abs() * e;
        }
        PanelEstimate {
            value: high,
            error: (high - low).abs() + inner,
            evaluations: (self.low.nodes.len() + self.high.nodes.len()) as u64,
        }
    }

    /// The panel's estimate from `f`'s values at [`EmbeddedRules::nodes`]: each value comes
    /// with a bound on its own error (0 for an exact evaluation; an inner quadrature's estimate
    /// for a nested one), which the higher rule's weights carry into the panel's error.
    pub fn estimate(
        &self,
        a: f64,
        b: f64,
        values: &[(f64, f64)],
        evaluations: u64,
    ) -> PanelEstimate {
        // The weights in the order of [`EmbeddedRules::nodes`], without collecting them again.
        let weights = self.low.on(a, b).chain(self.high.on(a, b)).map(|(_, w)| w);
        let (mut low, mut high, mut inner) = (0.0, 0.0, 0.0);
        for (k, (w, &(v, e))) in weights.zip(values).enumerate() {
            if k < self.low.nodes.len() {
                low += w * v;
            } else {
                high += w * v;
                inner += w.abs() * e;
            }
        }
        PanelEstimate {
            value: high,
            error: (high - low).abs() + inner,
            evaluations,
        }
    }
}

/// `∫_a^b` of an integrand by adaptive bisection: `panel(a, b)` estimates one panel (with
/// [`EmbeddedRules`]); the panel of largest error is halved until the errors sum to at most
/// `max(relative · |value|, absolute)` or `max_panels` panels are reached.
///
/// A panel's two rules can agree by accident where the integrand has kinks inside it (their
/// errors cancel), so a converged partition is checked once more with every panel halved: if
/// the halves' sum moves by more than the target, the halves are refined in turn; the error
/// returned is at least that move. Returns the compensated sum of the panels in their order
/// along `[a, b]`, the error estimate reached (whether or not the target was) and the
/// evaluations.
///
/// # Examples
/// ```
/// use specvar::quadrature::{adaptive, EmbeddedRules};
/// // A kink at 1/3, which no panel boundary meets: ∫_0^1 |x − 1/3| dx = 5/18.
/// let rules = EmbeddedRules::default();
/// let f = |x: f64| (x - 1.0 / 3.0).abs();
/// let result = adaptive((0.0, 1.0), (1e-12, 0.0), 200, |a, b| {
///     let values: Vec<(f64, f64)> = rules.nodes(a, b).iter().map(|&(x, _)| (f(x), 0.0)).collect();
///     rules.estimate(a, b, &values, values.len() as u64)
/// });
/// assert!((result.value - 5.0 / 18.0).abs() <= result.error);
/// assert!(result.error <= 1e-12 * 5.0 / 18.0);
/// ```
pub fn adaptive(
    (a, b): (f64, f64),
    (relative, absolute): (f64, f64),
    max_panels: usize,
    mut panel: impl FnMut(f64, f64) -> PanelEstimate,
) -> PanelResult {
    let first = panel(a, b);
    let mut evaluations = first.evaluations;
    let mut panels = vec![(a, b, first)];
    let sum = |panels: &[(f64, f64, PanelEstimate)]| {
        let (mut value, mut error) = (CompensatedSum::default(), 0.0);
        for (_, _, p) in panels {
            value.add(p.value);
            error += p.error;
        }
        (value.value(), error)
    };
    loop {
        let (value, error) = sum(&panels);
        let target = (relative * value.abs()).max(absolute);
        if error <= target || panels.len() >= max_panels {
            // Every panel halved: the check of the partition.
            let mut halves = Vec::with_capacity(2 * panels.len());
            for &(lo, hi, _) in &panels {
                let mid = 0.5 * (lo + hi);
                let (left, right) = (panel(lo, mid), panel(mid, hi));
                evaluations += left.evaluations + right.evaluations;
                halves.push((lo, mid, left));
                halves.push((mid, hi, right));
            }
            let (finer, finer_error) = sum(&halves);
            let moved = (finer - value).abs();
            if moved <= target || 2 * panels.len() >= max_panels {
                return PanelResult {
                    value: finer,
                    error: finer_error.max(moved),
                    evaluations,
                };
            }
            panels = halves;
            continue;
        }
        let worst = (0..panels.len())
            .max_by(|&i, &j| panels[i].2.error.total_cmp(&panels[j].2.error))
            .unwrap_or(0);
        let (lo, hi, _) = panels[worst];
        let mid = 0.5 * (lo + hi);
        let (left, right) = (panel(lo, mid), panel(mid, hi));
        evaluations += left.evaluations + right.evaluations;
        panels[worst] = (lo, mid, left);
        panels.insert(worst + 1, (mid, hi, right));
    }
}

/// [`adaptive`] from two starting partitions, `[a, b]` whole and in thirds: the second's value,
/// with the two values' difference added to its error. Bisection from one start can be fooled
/// where the two rules' errors at a kink happen to agree panel after panel (a triangle's
/// autocorrelation integrated over angles from one start was 2e-9 off with an estimate of
/// 1e-12; from thirds, 8e-14 off); two starts place every kink differently within its panels.
///
/// # Examples
/// ```
/// use specvar::quadrature::{adaptive_from_two_starts, EmbeddedRules};
/// // Two kinks: ∫_0^1 |x − c| dx = (c² + (1 − c)²)/2 for each.
/// let exact = (0.3f64 * 0.3 + 0.7 * 0.7) / 2.0 + (0.71f64 * 0.71 + 0.29 * 0.29) / 2.0;
/// let rules = EmbeddedRules::default();
/// let f = |x: f64| (x - 0.3).abs() + (x - 0.71).abs();
/// let result = adaptive_from_two_starts((0.0, 1.0), (1e-12, 0.0), 300, |a, b| {
///     let values: Vec<(f64, f64)> = rules.nodes(a, b).iter().map(|&(x, _)| (f(x), 0.0)).collect();
///     rules.estimate(a, b, &values, values.len() as u64)
/// });
/// assert!((result.value - exact).abs() <= result.error);
/// ```
pub fn adaptive_from_two_starts(
    (a, b): (f64, f64),
    tolerance: (f64, f64),
    max_panels: usize,
    mut panel: impl FnMut(f64, f64) -> PanelEstimate,
) -> PanelResult {
    let whole = adaptive((a, b), tolerance, max_panels, &mut panel);
    let third = (b - a) / 3.0;
    let mut thirds = PanelResult {
        value: 0.0,
        error: 0.0,
        evaluations: 0,
    };
    for j in 0..3 {
        let lo = a + j as f64 * third;
        let hi = if j == 2 { b } else { lo + third };
        let part = adaptive((lo, hi), tolerance, max_panels / 3, &mut panel);
        thirds.value += part.value;
        thirds.error += part.error;
        thirds.evaluations += part.evaluations;
    }
    PanelResult {
        value: thirds.value,
        error: thirds.error.max(whole.error) + (thirds.value - whole.value).abs(),
        evaluations: whole.evaluations + thirds.evaluations,
    }
}

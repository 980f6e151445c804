//! Jitter under a random shift, summed in space: the strata's tent.
//!
//! Jittered sampling with strata of sides `h_i = 1/m_i` has the closed-form spectrum
//! `1 − Π_i sinc²(π k_i h_i)`, and `Π_i sinc²(π k_i h_i)` is the Fourier coefficient of the
//! tent `Λ(r) = Π_i max(0, 1 − |r_i|/h_i) / h_i` (a stratum's box convolved with itself, of
//! unit mass). By Parseval the shifted estimator's variance is therefore
//!
//! `(1/N) Σ_{k≠0} |f̂(k)|² (1 − Λ̂(k)) = (1/N) ∫ (a_f(0) − a_f(r)) Λ(r) dr`,
//!
//! with `a_f` the integrand's torus autocorrelation: an integral over one stratum's width,
//! whatever N. The lattice form of the same spectrum needs frequencies up to `|k_i| ≈ m_i` to
//! see a jump's energy, which no lattice holds at large N: its tail bound then is most of the
//! variance. Here nothing is truncated; the error is the quadrature's, which is estimated.
//!
//! The integral is taken over `r_1 ≥ 0` (`a_f` is even) in the stratum's scaled coordinates
//! `r_i = h_i u_i`, in polar coordinates `(ρ, θ)` of `u`: `a_f(0) − a_f` has a cone at the
//! origin (it grows like `|r|`) and kinks along lines through it (a polygon's edge
//! directions), which are smooth along every ray and bisected across them.

use super::gaussian_jitter::{replica_energy, ReplicaAxis};
use crate::budget::{Budget, Needs};
use crate::error::{invalid, Error, Result};
use crate::integrand::Integrand;
use crate::predict::{ErrorBudget, Form, Prediction, Route, SpectrumOrigin};
use crate::quadrature::{adaptive, adaptive_from_two_starts, EmbeddedRules, PanelResult};
use crate::randomization::Randomization;
use crate::sampler::ClosedForm;
use rayon::prelude::*;
use std::f64::consts::FRAC_PI_4;

/// The quadrature's relative target: the outer (angular) integral's estimated error at most
/// this share of the variance. Far below any other term of a prediction's budget.
const RELATIVE_TARGET: f64 = 1e-9;
/// The inner (radial) integrals' target, a tenth of the outer one, so that their errors, which
/// the outer estimate carries, take a small share of it.
const INNER_RELATIVE_TARGET: f64 = RELATIVE_TARGET / 10.0;
/// Panels of the angular integral at most: a kink direction costs about 2 panels per halving
/// of its panel, and 20 halvings bring a kink's share below the target.
const MAX_OUTER_PANELS: usize = 600;
/// Panels of each radial integral at most: along a ray the integrand is smooth except where
/// the offset reaches another feature of the integrand (large strata only).
const MAX_INNER_PANELS: usize = 40;
/// The rounding of one autocorrelation value, in units of `a_f(0) = ∫f²`: the few ulps of a
/// sum of areas, products or error functions of size at most `∫f²`. `a_f(0) − a_f(r)` carries
/// two of them, and the tent has unit mass.
const AUTOCORRELATION_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// The Gaussian weight is cut at this many of its standard deviations: the mass beyond,
/// `erfc(10/√2) ≈ 1.5e-23` per axis, is bounded in the truncation term.
const GAUSSIAN_REACH: f64 = 10.0;

/// The density of the difference of two points' offsets within their strata, per axis, in
/// units of the strata's sides: what weighs `a_f(0) − a_f(r)`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Weight {
    /// Two uniform offsets: the tent `1 − |u|` on `[−1, 1]`.
    Tent,
    /// Two Gaussian offsets of `width` strata: a Gaussian of standard deviation `√2 width`.
    Gaussian {
        /// The difference's standard deviation, in strata.
        deviation: f64,
    },
}

impl Weight {
    /// How far the weight reaches (its support, or its cut).
    fn reach(self) -> f64 {
        match self {
            Weight::Tent => 1.0,
            Weight::Gaussian { deviation } => GAUSSIAN_REACH * deviation,
        }
    }

    /// The density at `u ≥ 0`.
    fn at(self, u: f64) -> f64 {
        match self {
            Weight::Tent => 1.0 - u,
            Weight::Gaussian { deviation } => {
                let z = u / deviation;
                (-0.5 * z * z).exp() / (deviation * (2.0 * std::f64::consts::PI).sqrt())
            }
        }
    }

    /// The mass beyond the reach on either side of one axis.
    fn mass_beyond(self) -> f64 {
        match self {
            Weight::Tent => 0.0,
            Weight::Gaussian { .. } => libm::erfc(GAUSSIAN_REACH / std::f64::consts::SQRT_2),
        }
    }
}

/// The variance of jittered sampling on the strata `strata` (one uniform point in each, 1D or
/// 2D) under a uniform random shift, by the strata's tent in space: the value, the
/// quadrature's error estimate (rounding included) and the autocorrelation evaluations. `None`
/// if `f` has no closed-form autocorrelation.
///
/// # Errors
/// Strata of another dimension than the integrand's, a dimension other than 1 or 2, or work
/// beyond the budget.
///
/// One stratum on every axis is one uniform point: its tent folds onto the torus as the
/// uniform density, and the variance is `a_f(0) − I²`, taken at once (the quadrature over a
/// tent as wide as the torus meets every image of the integrand's features).
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Integrand};
/// use specvar::predict::{jitter_shift_variance, predict, PredictParams, Problem};
/// use specvar::randomization::Randomization;
/// use specvar::sampler::SamplerKind;
/// // 2 × 2 strata on a disk, against the lattice form of jitter's closed-form spectrum.
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
/// let (v, err, _) = jitter_shift_variance(&disk, &[2, 2], &Default::default())?.unwrap();
/// let jitter = SamplerKind::Jitter.build(2)?;
/// let problem = Problem::new(jitter.as_ref(), &disk, 4)?.with_randomization(Randomization::Shift);
/// let lattice = predict(&problem, &PredictParams::default())?;
/// assert!((v - lattice.variance).abs() <= err + lattice.budget.half_width(0.0));
/// // One stratum: jitter is white noise, ∫f² − I².
/// let (v, err, _) = jitter_shift_variance(&disk, &[1, 1], &Default::default())?.unwrap();
/// let white = disk.integral_of_square() - disk.integral().powi(2);
/// assert!((v - white).abs() <= err);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn jitter_shift_variance(
    f: &dyn Integrand,
    strata: &[usize],
    budget: &Budget,
) -> Result<Option<(f64, f64, u64)>> {
    if strata.len() == f.dimension() && strata.iter().all(|&m| m == 1) {
        return Ok(f.autocorrelation(&vec![0.0; strata.len()]).map(|a0| {
            let mean = f.integral();
            // Both terms within the autocorrelation's rounding of `a_f(0)`.
            let error = 2.0 * AUTOCORRELATION_ROUNDING * a0;
            ((a0 - mean * mean).max(0.0), error, 1)
        }));
    }
    Ok(weighted_drop(f, strata, Weight::Tent, budget)?.map(|w| (w.value, w.error, w.evaluations)))
}

/// `(1/N) ∫ (a_f(0) − a_f(r)) W(r) dr` for the product weight `W` on the strata's sides: the
/// value, its error (quadrature, rounding and the weight's cut mass) and the evaluations.
/// `None` if `f` has no closed-form autocorrelation.
fn weighted_drop(
    f: &dyn Integrand,
    strata: &[usize],
    weight: Weight,
    budget: &Budget,
) -> Result<Option<PanelResult>> {
    let d = f.dimension();
    if strata.len() != d || !(1..=2).contains(&d) || strata.contains(&0) {
        return Err(invalid(
            "strata",
            format!("{strata:?}"),
            format!("one positive count per axis of the integrand ({d}), in 1 or 2 dimensions"),
        ));
    }
    let Some(a0) = f.autocorrelation(&vec![0.0; d]) else {
        return Ok(None);
    };
    let rules = EmbeddedRules::default();
    budget.check(
        "the strata's weight in space",
        Needs {
            memory_bytes: 0.0,
            work_seconds: most_evaluations(&rules, d) * super::space::autocorrelation_seconds(f),
        },
        "finer strata (a larger N), or the lattice form (--form lattice)",
    )?;
    let h: Vec<f64> = strata.iter().map(|&m| 1.0 / m as f64).collect();
    let n: f64 = strata.iter().map(|&m| m as f64).product();
    // `a_f(0) − a_f(r)`, with `r` in units of the strata's sides.
    let drop = |u: &[f64]| -> f64 {
        let r = [u[0] * h[0], u.get(1).map_or(0.0, |v| v * h[1])];
        a0 - f.autocorrelation(&r[..d]).unwrap_or(a0)
    };
    let floor = AUTOCORRELATION_ROUNDING * a0;
    let result = if d == 1 {
        // (2/N) ∫_0^R (a(0) − a(hu)) w(u) du.
        let line = |u: f64| drop(&[u]) * weight.at(u);
        adaptive_from_two_starts(
            (0.0, weight.reach()),
            (RELATIVE_TARGET, floor),
            MAX_OUTER_PANELS,
            |lo, hi| rules.integrate(lo, hi, |u| (line(u), 0.0)),
        )
    } else {
        plane(&rules, &drop, weight, floor)
    };
    let scale = 2.0 / n;
    // Rounding: two values of `a_f` per point, the weight of unit mass. Cut: `|D| ≤ 2 a_f(0)`
    // on the mass beyond the reach, on each axis.
    let rounding = 2.0 * floor / n;
    let cut = 2.0 * a0 * 2.0 * d as f64 * weight.mass_beyond() / n;
    Ok(Some(PanelResult {
        value: (scale * result.value).max(0.0),
        error: scale * result.error + rounding + cut,
        evaluations: result.evaluations,
    }))
}

/// `∫_{[0,R]²} (D(u, v) + D(u, −v)) w(u) w(v) du dv` in polar coordinates, the angle split at
/// the diagonal where the square's far side changes, each ray's radius scaled to `[0, 1]`; the
/// rays of one angular panel are integrated in parallel.
fn plane(
    rules: &EmbeddedRules,
    drop: &(dyn Fn(&[f64]) -> f64 + Sync),
    weight: Weight,
    floor: f64,
) -> PanelResult {
    let mut total = PanelResult {
        value: 0.0,
        error: 0.0,
        evaluations: 0,
    };
    for half in [(0.0, FRAC_PI_4), (FRAC_PI_4, 2.0 * FRAC_PI_4)] {
        let part = adaptive_from_two_starts(
            half,
            (RELATIVE_TARGET, floor),
            MAX_OUTER_PANELS,
            |lo, hi| {
                let rays: Vec<PanelResult> = rules
                    .nodes(lo, hi)
                    .par_iter()
                    .map(|&(theta, _)| ray(rules, drop, weight, floor, theta))
                    .collect();
                let values: Vec<(f64, f64)> = rays.iter().map(|r| (r.value, r.error)).collect();
                rules.estimate(lo, hi, &values, rays.iter().map(|r| r.evaluations).sum())
            },
        );
        total.value += part.value;
        total.error += part.error;
        total.evaluations += part.evaluations;
    }
    total
}

/// The radial integral `∫_0^{R(θ)} ρ E(ρ cos θ, ρ sin θ) w(u) w(v) dρ` along the ray at angle
/// `θ`, to the square's far side `R(θ) = R / max(cos θ, sin θ)`, with
/// `E(u, v) = D(u, v) + D(u, −v)`; each autocorrelation value is one evaluation (two a node).
fn ray(
    rules: &EmbeddedRules,
    drop: &(dyn Fn(&[f64]) -> f64 + Sync),
    weight: Weight,
    floor: f64,
    theta: f64,
) -> PanelResult {
    let (s, c) = theta.sin_cos();
    let reach = weight.reach() / c.max(s);
    let (cu, cv) = (reach * c, reach * s);
    let radial = |t: f64| {
        let (u, v) = (t * cu, t * cv);
        t * (drop(&[u, v]) + drop(&[u, -v])) * weight.at(u) * weight.at(v)
    };
    let inner = adaptive(
        (0.0, 1.0),
        (INNER_RELATIVE_TARGET, floor / 10.0),
        MAX_INNER_PANELS,
        |lo, hi| rules.integrate(lo, hi, |t| (radial(t), 0.0)),
    );
    let jacobian = reach * reach;
    PanelResult {
        value: jacobian * inner.value,
        error: jacobian * inner.error,
        evaluations: 2 * inner.evaluations,
    }
}

/// Autocorrelation values the Gaussian weight's quadrature takes on strata finer than the
/// integrand's features: measured 1.4 million for an edge (each ray's Gaussian needs several
/// radial panels where the tent's polynomial needs one), fewer for a disk; what the route
/// weighs against the frequency sum's work.
const TYPICAL_WEIGHT_EVALUATIONS: f64 = 1.5e6;

/// The typical work of [`predict_gaussian_jitter_in_space`] on `f`.
pub(crate) fn typical_weight_seconds(f: &dyn Integrand) -> f64 {
    TYPICAL_WEIGHT_EVALUATIONS * super::space::autocorrelation_seconds(f)
}

/// The most autocorrelation values the quadrature may take: an adaptive integral ends with at
/// most its cap of panels, halved once more by its check, after at most as many again before
/// a failed check (3 × the cap, 15 nodes each), and the angular integral (the line's in 1D) is
/// taken from two starts; the plane has two angular halves, and its rays take two values a
/// node. Coarse strata, whose tent meets many of the integrand's features,
/// come near it (a single stratum of a polygon: minutes); strata finer than the features take
/// a few thousand.
fn most_evaluations(rules: &EmbeddedRules, d: usize) -> f64 {
    let per_panel = rules.nodes(0.0, 1.0).len() as f64;
    let outer = 2.0 * 3.0 * MAX_OUTER_PANELS as f64 * per_panel;
    let inner = 3.0 * MAX_INNER_PANELS as f64 * per_panel;
    if d == 1 {
        outer
    } else {
        4.0 * outer * inner
    }
}

/// Jitter on `strata` under a random shift, by the strata's tent in space.
///
/// # Errors
/// An integrand without a closed-form autocorrelation, a dimension other than 1 or 2, or work
/// beyond the budget.
pub(crate) fn predict_jitter_tent(
    f: &dyn Integrand,
    strata: &[usize],
    budget: &Budget,
) -> Result<Prediction> {
    let (variance, quadrature, evaluations) = jitter_shift_variance(f, strata, budget)?
        .ok_or_else(|| Error::OutsideValidity {
            route: "the strata's tent in space".into(),
            reason: format!("{} has no closed-form autocorrelation", f.label()),
        })?;
    let grid = crate::predict::grid_label(strata);
    let reason = format!(
        "jitter under a random shift ({grid} strata): its closed-form spectrum 1 − Π sinc² \
         summed exactly in space, (1/N) ∫ (a_f(0) − a_f(r)) Λ(r) dr over the strata's tent Λ \
         (one stratum's width), with the integrand's closed-form autocorrelation, by adaptive \
         Gauss–Legendre quadrature; nothing truncated"
    );
    Ok(Prediction {
        randomization: Randomization::Shift,
        variance,
        route: Route {
            form: Form::Lattice,
            spectrum: SpectrumOrigin::Closed(ClosedForm::Jitter),
        },
        reason,
        budget: ErrorBudget {
            tabulation: 0.0,
            quadrature,
            ..Default::default()
        },
        n: strata.iter().product(),
        dimension: f.dimension(),
        dc_term: 0.0,
        evaluations,
        alternatives: Vec::new(),
        analysis: None,
    })
}

/// The replicas `ℓ` whose damping `e^{−4π²w²ℓ_a²}` on an axis is above `e^{−140}` are summed;
/// the rest are bounded with `|f̂|² ≤ ∫f²` by the damping's tail past them. The frequency
/// route's floor, `1e-20`, would leave a bound of `1e-20 ∫f²`, most of the variance at
/// N = 10^12.
const REPLICA_EXPONENT: f64 = 140.0;

/// Gaussian jitter of `width` strata (`form`) on `strata` under a random shift, in space: its
/// spectrum `1 − φ² + N φ² [k ∈ m Z^d]` is, apart from the grid's replicas, the white part
/// `(1/N) ∫ (a_f(0) − a_f(r)) G(r) dr` with `G` the density of two offsets' difference (a
/// Gaussian of `√2 w` strata a side), and the replicas `Σ_{ℓ≠0} |f̂(m ℓ)|² e^{−4π²w²|ℓ|²}`
/// ([`replica_energy`], to [`REPLICA_EXPONENT`]). At any N:
/// the Parseval route's frequencies grow like N.
///
/// # Errors
/// A closed form other than Gaussian jitter's, an integrand without a closed-form
/// autocorrelation, a dimension other than 1 or 2, or work beyond the budget.
pub(crate) fn predict_gaussian_jitter_in_space(
    f: &dyn Integrand,
    form: ClosedForm,
    strata: &[usize],
    budget: &Budget,
) -> Result<Prediction> {
    let ClosedForm::GaussianJitter { width } = form else {
        return Err(invalid("closed form", form.name(), "Gaussian jitter's"));
    };
    let deviation = std::f64::consts::SQRT_2 * width;
    let white =
        weighted_drop(f, strata, Weight::Gaussian { deviation }, budget)?.ok_or_else(|| {
            Error::OutsideValidity {
                route: "Gaussian jitter in space".into(),
                reason: format!("{} has no closed-form autocorrelation", f.label()),
            }
        })?;
    // The replicas' damping e^{−4π²w²|ℓ|²} is φ² of the offsets: φ of offsets √2 times wider.
    let axes: Vec<ReplicaAxis> = strata
        .iter()
        .map(|&m| ReplicaAxis::new(m, deviation, (-REPLICA_EXPONENT).exp()))
        .collect();
    let replicas = replica_energy(f, &axes)?;
    let count = replicas.terms - 1;
    let grid = crate::predict::grid_label(strata);
    let reason = format!(
        "gjitter under a random shift ({grid} strata, offsets of {width} strata): its \
         closed-form spectrum 1 − φ² + N φ² [k ∈ m Z^d] summed exactly in space, the white part \
         (1/N) ∫ (a_f(0) − a_f(r)) G(r) dr over the offsets' difference G by adaptive \
         Gauss–Legendre quadrature with the integrand's closed-form autocorrelation, and the \
         grid's {count} replicas damped above e^-140 on each axis one by one, the rest bounded"
    );
    Ok(Prediction {
        randomization: Randomization::Shift,
        variance: white.value + replicas.value,
        route: Route {
            form: Form::Lattice,
            spectrum: SpectrumOrigin::Closed(form),
        },
        reason,
        budget: ErrorBudget {
            tabulation: 0.0,
            quadrature: white.error,
            truncation: f.integral_of_square() * replicas.beyond,
            ..Default::default()
        },
        n: strata.iter().product(),
        dimension: f.dimension(),
        dc_term: 0.0,
        evaluations: white.evaluations + count,
        alternatives: Vec::new(),
        analysis: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::Polygon;

    /// Gaussian jitter in space against its closed-form spectrum summed by Parseval (the
    /// smoothed energy and the replicas in frequency, no autocorrelation), where both are
    /// affordable: a disk, an edge at 30° (whose jumps at the faces the grid's replicas see)
    /// and a triangle, offsets of 0.25 and 0.1 strata, 64² and 128² strata.
    #[test]
    fn gaussian_jitter_in_space_matches_its_parseval_sum() {
        use crate::integrand::Ball;
        let shapes: Vec<Box<dyn Integrand>> = vec![
            Box::new(Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap()),
            Box::new(Polygon::edge(30.0, 0.5, 1.0).unwrap()),
            Box::new(Polygon::new(vec![[0.2, 0.2], [0.8, 0.3], [0.4, 0.9]], 1.0).unwrap()),
        ];
        let budget = Budget::default();
        for f in &shapes {
            for (width, m) in [(0.25, 64), (0.1, 128)] {
                let form = ClosedForm::GaussianJitter { width };
                let strata = [m, m];
                let space =
                    predict_gaussian_jitter_in_space(f.as_ref(), form, &strata, &budget).unwrap();
                let parseval =
                    crate::predict::fourier::gaussian_jitter::predict_gaussian_jitter_shifted(
                        f.as_ref(),
                        form,
                        &strata,
                        &budget,
                    )
                    .unwrap();
                let allowed = space.budget.half_width(crate::montecarlo::Z_99)
                    + parseval.budget.half_width(crate::montecarlo::Z_99);
                assert!(
                    (space.variance - parseval.variance).abs() <= allowed,
                    "{} w = {width} m = {m}: {} against {} (allowed {allowed:e})",
                    f.label(),
                    space.variance,
                    parseval.variance
                );
            }
        }
    }

    /// One stratum is white noise, `(∫f² − I²)/N` exactly: for a square, the tent covers the
    /// whole torus and the autocorrelation's kinks cross every ray away from the origin (where
    /// the quadrature's two rules once agreed by accident). The quadrature is checked through
    /// the weight's integral itself; the public function answers this case without it.
    #[test]
    fn one_stratum_is_white_noise() {
        let square =
            Polygon::new(vec![[0.2, 0.3], [0.7, 0.3], [0.7, 0.8], [0.2, 0.8]], 1.0).unwrap();
        let white = square.integral_of_square() - square.integral().powi(2);
        let (exact, exact_err, _) = jitter_shift_variance(&square, &[1, 1], &Budget::default())
            .unwrap()
            .unwrap();
        assert!((exact - white).abs() <= exact_err);
        let quadrature = weighted_drop(&square, &[1, 1], Weight::Tent, &Budget::default())
            .unwrap()
            .unwrap();
        let (v, err) = (quadrature.value, quadrature.error);
        assert!((v - white).abs() <= err, "{v} against {white} ± {err}");
    }
}

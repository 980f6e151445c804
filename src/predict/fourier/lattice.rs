//! The lattice form, exact on the torus:
//! `Var[μ_N] = (1/N) Σ_{k≠0} |f̂(k)|² E[P_S(k)]`, with `f̂` the torus coefficients of the function
//! Monte Carlo integrates. It is summed over the lattice `|k_i| ≤ K`; beyond, the energy is
//! known exactly by Parseval (and on each axis line by Parseval in 1D, through the projection
//! of the integrand onto the axis), is counted as white (`P_S = 1`), and the deviation from
//! white is bounded: `|truncation| ≤ (δ_axis E_axis + δ_off E_rest) / N`.

use super::low_band::{DiscFit, LowBand, FIT_DEGREE};
use crate::budget::{try_filled, Budget, Needs};
use crate::costs::COEFFICIENT_SECONDS;
use crate::error::{finite, invalid, Error, Result};
use crate::integrand::Integrand;
use crate::predict::SpectrumSource;
use crate::predict::{
    check_dimension, check_n, ErrorBudget, Form, Prediction, Route, SpectrumOrigin,
};
use crate::progress::Progress;
use crate::quadrature::CompensatedSum;
use crate::spectrum::{
    engine_error, ClosedForm, ClosedLattice, Lattice, LatticeSpectrum, PatternSource,
    SpectrumAccumulator, SpectrumParams, TailDeviation, WeightedMean,
};
use rayon::prelude::*;

/// An integrand's power `|f̂(k)|²` on a lattice of integer frequencies, with the energy beyond
/// it: everything the lattice form needs from the integrand. The mean of these over many
/// integrands (the pixels of an image) predicts their mean variance, since the variance is
/// linear in the power.
#[derive(Debug, Clone, PartialEq)]
pub struct LatticePower {
    /// The frequencies.
    pub lattice: Lattice,
    /// `|f̂(k)|²` in lattice order (0 at DC, which the variance excludes).
    pub power: Vec<f64>,
    /// `∫ f² - I² - Σ_{k≠0 in the lattice} |f̂(k)|²` by Parseval: the energy beyond the lattice.
    pub beyond: f64,
    /// The part of `beyond` on the axis lines `k = k_a e_a` (`|k_a| > K`), by Parseval on the
    /// projections onto the axes.
    pub axis_beyond: f64,
    /// What it is the power of.
    pub label: String,
}

impl LatticePower {
    /// The power of `f` on `lattice` (its torus coefficients, computed in parallel over rows).
    ///
    /// # Errors
    /// A lattice of another dimension than `f`, or a dimension outside 1 to 3.
    pub fn of(f: &dyn Integrand, lattice: Lattice) -> Result<Self> {
        Self::of_within(f, lattice, &Budget::default())
    }

    /// [`of`](Self::of), refused before any work when the lattice's memory (8 bytes a
    /// frequency) or its coefficients' work exceeds `budget`, and allocated fallibly.
    ///
    /// # Errors
    /// As [`of`](Self::of), [`Error::TooLarge`] above the budget, [`Error::OutOfMemory`] when
    /// the system refuses the memory.
    ///
    /// # Examples
    /// ```
    /// use specvar::budget::Budget;
    /// use specvar::integrand::Ball;
    /// use specvar::predict::LatticePower;
    /// use specvar::spectrum::Lattice;
    /// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
    /// let huge = Lattice { dimension: 2, kmax: 1_000_000_000 };
    /// assert!(LatticePower::of_within(&disk, huge, &Budget::default()).is_err());
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn of_within(f: &dyn Integrand, lattice: Lattice, budget: &Budget) -> Result<Self> {
        budget.check(
            &format!(
                "the integrand's power on |k_i| ≤ {} in {}D",
                lattice.kmax, lattice.dimension
            ),
            lattice_needs(lattice),
            "lower kmax",
        )?;
        let d = f.dimension();
        check_dimension(d)?;
        if lattice.dimension != d {
            return Err(Error::Mismatch(format!(
                "lattice of dimension {} for an integrand of dimension {d}",
                lattice.dimension
            )));
        }
        let mut power = try_filled(lattice.len(), 0.0, "the integrand's power on the lattice")?;
        f.power_on_lattice(lattice, &mut power);
        power[lattice.dc_index()] = 0.0;
        let i0 = f.integral();
        let energy = f.integral_of_square() - i0 * i0;
        let mut inside = CompensatedSum::default();
        power.iter().for_each(|&p| inside.add(p));
        let beyond = (energy - inside.value()).max(0.0);
        // Each axis line's energy beyond K: ∫ F_a² - I² less the line's part inside.
        let side = lattice.side();
        let axis_beyond: f64 = (0..d)
            .map(|a| {
                let stride = side.pow((d - 1 - a) as u32);
                let line: f64 = (1..=lattice.kmax)
                    .map(|t| {
                        power[lattice.dc_index() + t * stride]
                            + power[lattice.dc_index() - t * stride]
                    })
                    .sum();
                (f.projection_energy(a) - i0 * i0 - line).max(0.0)
            })
            .sum::<f64>()
            .min(beyond);
        Ok(Self {
            lattice,
            power,
            beyond,
            axis_beyond,
            label: f.label(),
        })
    }

    /// The mean of several powers on one lattice.
    ///
    /// # Errors
    /// No parts, or parts on different lattices.
    pub fn mean(parts: &[LatticePower], label: impl Into<String>) -> Result<Self> {
        let first = parts
            .first()
            .ok_or_else(|| invalid("lattice powers", 0, "at least one"))?;
        if parts.iter().any(|p| p.lattice != first.lattice) {
            return Err(Error::Mismatch(
                "lattice powers on different lattices".into(),
            ));
        }
        let scale = 1.0 / parts.len() as f64;
        let mut power = vec![0.0; first.power.len()];
        for part in parts {
            for (acc, p) in power.iter_mut().zip(&part.power) {
                *acc += p * scale;
            }
        }
        Ok(Self {
            lattice: first.lattice,
            power,
            beyond: parts.iter().map(|p| p.beyond).sum::<f64>() * scale,
            axis_beyond: parts.iter().map(|p| p.axis_beyond).sum::<f64>() * scale,
            label: label.into(),
        })
    }

    /// The power averaged over the symmetries of the cube (axis permutations and reflections):
    /// for a sampler whose distribution has them, `E[P_S]` has them too, so the lattice form is
    /// unchanged and a per-pattern estimate of it gets less noisy.
    pub fn symmetrized(&self) -> Self {
        let lattice = self.lattice;
        let d = lattice.dimension;
        let perms = permutations(d);
        let images = (perms.len() << d) as f64;
        let side = lattice.side() as i64;
        let kmax = lattice.kmax as i64;
        let power = (0..lattice.len())
            .into_par_iter()
            .map(|i| {
                let k = lattice.frequency(i);
                let mut sum = 0.0;
                for perm in &perms {
                    for signs in 0..1usize << d {
                        let flat = (0..d).fold(0i64, |acc, a| {
                            let c = k[perm[a]] * if signs >> a & 1 == 1 { -1 } else { 1 };
                            acc * side + c + kmax
                        });
                        sum += self.power[flat as usize];
                    }
                }
                sum / images
            })
            .collect();
        Self {
            power,
            ..self.clone()
        }
    }

    /// The bound on `(1/N) Σ_{beyond} |f̂|² (P - 1)` given bounds on `|P - 1|` beyond.
    fn tail_bound(&self, deviation: TailDeviation) -> f64 {
        deviation.axis * self.axis_beyond + deviation.off_axis * (self.beyond - self.axis_beyond)
    }
}

/// What an integrand's power on `lattice` costs: 8 bytes and one coefficient's work
/// ([`COEFFICIENT_SECONDS`]) a frequency, counted in floating point so that no size overflows.
fn lattice_needs(lattice: Lattice) -> Needs {
    let len = (2.0 * lattice.kmax as f64 + 1.0).powi(lattice.dimension as i32);
    Needs {
        memory_bytes: 8.0 * len,
        work_seconds: len * COEFFICIENT_SECONDS,
    }
}

/// The permutations of `0..d`.
fn permutations(d: usize) -> Vec<Vec<usize>> {
    if d == 1 {
        return vec![vec![0]];
    }
    let mut out = Vec::new();
    for rest in permutations(d - 1) {
        for at in 0..d {
            let mut p = rest.clone();
            p.insert(at, d - 1);
            out.push(p);
        }
    }
    out
}

/// The lattice-form variance of the homogenized estimator with `n` points, summed over
/// `|k_i| ≤ kmax` (for an estimated spectrum, its own K), the energy beyond counted as white
/// with its deviation bounded.
///
/// # Errors
/// `n = 0`, a dimension mismatch, or an estimated spectrum at another N.
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Integrand};
/// use specvar::predict::{predict_lattice, SpectrumSource};
/// use specvar::spectrum::ClosedForm;
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
/// let p = predict_lattice(&disk, &SpectrumSource::Closed(ClosedForm::WhiteNoise), 64, 32).unwrap();
/// let exact = (disk.integral_of_square() - disk.integral().powi(2)) / 64.0;
/// assert!((p.variance - exact).abs() < 1e-12 * exact);
/// ```
pub fn predict_lattice(
    f: &dyn Integrand,
    source: &SpectrumSource<'_>,
    n: usize,
    kmax: usize,
) -> Result<Prediction> {
    let lattice = match source {
        SpectrumSource::Closed(_) => Lattice {
            dimension: f.dimension(),
            kmax,
        },
        SpectrumSource::Estimated(e) => e.lattice.lattice,
    };
    // A lattice of another dimension is refused by `LatticePower::of`.
    predict_from_power(&LatticePower::of(f, lattice)?, source, n)
}

/// The lattice-form variance from an integrand's power on the lattice (see [`LatticePower`]):
/// `(Σ_{k≠0} |f̂(k)|² P_S(k) + beyond) / N`. With a closed form the tail bound is exact (none
/// exists for the regular grid's replicas, so it is refused: use [`crate::predict::predict`]); with an
/// estimated mean spectrum the noise is propagated per frequency and the tail deviation is
/// measured at the lattice's edge.
///
/// # Errors
/// `n = 0`, the regular grid's closed form, or an estimated spectrum at another N or on
/// another lattice.
pub fn predict_from_power(
    power: &LatticePower,
    source: &SpectrumSource<'_>,
    n: usize,
) -> Result<Prediction> {
    check_n(n)?;
    let lattice = power.lattice;
    check_dimension(lattice.dimension)?;
    let (spectrum, deviation) = match source {
        SpectrumSource::Closed(c) => {
            let closed = c.on_lattice(n, lattice.dimension, lattice.kmax);
            let deviation = closed
                .tail_deviation()
                .ok_or_else(|| Error::OutsideValidity {
                    route: format!(
                        "the lattice form with the {}'s spectrum on a finite lattice",
                        c.name()
                    ),
                    reason: "its peaks (power up to N) continue beyond any lattice; predict() \
                             sums them exactly in space"
                        .into(),
                })?;
            (SpectrumAt::Closed(closed), deviation)
        }
        SpectrumSource::Estimated(e) => {
            let s = &e.lattice;
            if s.n != n || s.lattice != lattice {
                return Err(Error::Mismatch(format!(
                    "lattice spectrum of N = {} in {}D with K = {} for N = {n} in {}D with K = {}",
                    s.n, s.lattice.dimension, s.lattice.kmax, lattice.dimension, lattice.kmax
                )));
            }
            (SpectrumAt::Estimated(s), measured_tail_deviation(s))
        }
    };
    let sums = weighted_sums(power, &spectrum);
    let truncation = power.tail_bound(deviation) / n as f64;
    Ok(Prediction {
        randomization: crate::randomization::Randomization::Shift,
        variance: (sums.value + power.beyond) / n as f64,
        route: Route {
            form: Form::Lattice,
            spectrum: source.origin(),
        },
        reason: String::new(),
        budget: ErrorBudget {
            tabulation: 0.0,
            // P(k) = P(-k) exactly, so the two halves add coherently: 2 Σ (w se)².
            spectrum_noise: (2.0 * sums.noise).sqrt() / n as f64,
            quadrature: 0.0,
            truncation,
            model: 0.0,
        },
        n,
        dimension: lattice.dimension,
        dc_term: 0.0,
        evaluations: lattice.len() as u64,
        alternatives: Vec::new(),
        analysis: None,
    })
}

/// The white-noise variance, exact: `(∫f² - I²) / N` by Parseval, no lattice.
pub(crate) fn white_noise(f: &dyn Integrand, n: usize) -> Result<Prediction> {
    check_n(n)?;
    let i0 = f.integral();
    let variance = (f.integral_of_square() - i0 * i0) / n as f64;
    Ok(Prediction {
        randomization: crate::randomization::Randomization::Shift,
        variance: variance.max(0.0),
        route: Route {
            form: Form::Lattice,
            spectrum: SpectrumOrigin::Closed(ClosedForm::WhiteNoise),
        },
        reason: String::new(),
        budget: ErrorBudget {
            tabulation: 0.0,
            // The subtraction's rounding, the only error left.
            quadrature: 4.0 * f64::EPSILON * f.integral_of_square() / n as f64,
            ..Default::default()
        },
        n,
        dimension: f.dimension(),
        dc_term: 0.0,
        evaluations: 1,
        alternatives: Vec::new(),
        analysis: None,
    })
}

/// A spectrum read on one lattice for one N: a tabulated closed form, or an estimate there.
enum SpectrumAt<'a> {
    Closed(ClosedLattice),
    Estimated(&'a LatticeSpectrum),
}

impl SpectrumAt<'_> {
    /// The mean power and its standard error at flat index `i`, frequency `k`.
    #[inline]
    fn at(&self, i: usize, k: &[i64]) -> (f64, f64) {
        match self {
            Self::Closed(c) => (c.power(k), 0.0),
            Self::Estimated(s) => (s.mean[i], s.stderr[i]),
        }
    }
}

struct Sums {
    value: f64,
    noise: f64,
}

/// `Σ_{k≠0} |f̂|² P` and `Σ (|f̂|² se(P))²`, parallel over rows, reduced in order.
fn weighted_sums(power: &LatticePower, spectrum: &SpectrumAt<'_>) -> Sums {
    let lattice = power.lattice;
    let (side, d) = (lattice.side(), lattice.dimension);
    let per_row: Vec<[f64; 2]> = power
        .power
        .par_chunks(side)
        .enumerate()
        .map(|(r, row)| {
            let mut acc = [0.0; 2];
            for (j, &power_f) in row.iter().enumerate() {
                let i = r * side + j;
                if i == lattice.dc_index() {
                    continue;
                }
                let k = lattice.frequency(i);
                let (power_s, se) = spectrum.at(i, &k[..d]);
                acc[0] += power_f * power_s;
                if se.is_finite() {
                    acc[1] += (power_f * se).powi(2);
                }
            }
            acc
        })
        .collect();
    let mut value = CompensatedSum::default();
    let mut noise = 0.0;
    for [w, q] in per_row {
        value.add(w);
        noise += q;
    }
    Sums {
        value: value.value(),
        noise,
    }
}

/// Standard errors a measured deviation from white adds to itself, so that the bound holds
/// beyond the edge where the spectrum is no farther from white than in the lattice's outer half.
const EDGE_MARGIN_Z: f64 = 3.0;

/// Bounds on `|P - 1|` beyond the lattice, measured in its outer half (`K/2 < |k|_∞ ≤ K`): the
/// largest deviation of a ring mean (off the axes) or of a stretch of an axis line, plus three
/// of its standard errors. It assumes the spectrum gets no farther from white beyond the edge
/// than it is there, which holds for spectra that settle to 1 (every sampler but lattices).
pub(crate) fn measured_tail_deviation(s: &LatticeSpectrum) -> TailDeviation {
    let lattice = s.lattice;
    let (d, kmax) = (lattice.dimension, lattice.kmax as i64);
    let half = kmax / 2;
    // Off the axes: rings of unit width in |k|; on the axes: stretches of K/8 frequencies.
    let stretch = (kmax / 8).max(1);
    let mut rings: std::collections::BTreeMap<i64, (f64, f64, f64)> = Default::default();
    let mut lines: std::collections::BTreeMap<(usize, i64), (f64, f64, f64)> = Default::default();
    for i in 0..lattice.len() {
        let k = lattice.frequency(i);
        let k = &k[..d];
        if k.iter().map(|c| c.abs()).max().unwrap_or(0) <= half {
            continue;
        }
        let nonzero: Vec<usize> = (0..d).filter(|&a| k[a] != 0).collect();
        let slot = if nonzero.len() == 1 {
            let a = nonzero[0];
            lines.entry((a, k[a].abs() / stretch)).or_default()
        } else {
            let r = (k.iter().map(|c| c * c).sum::<i64>() as f64).sqrt().floor() as i64;
            rings.entry(r).or_default()
        };
        slot.0 += s.mean[i];
        slot.1 += if s.stderr[i].is_finite() {
            s.stderr[i].powi(2)
        } else {
            0.0
        };
        slot.2 += 1.0;
    }
    let worst = |groups: &mut dyn Iterator<Item = (f64, f64, f64)>| {
        groups
            .map(|(sum, var, count)| {
                // P(k) = P(-k): the count holds each value twice.
                let se = (2.0 * var).sqrt() / count;
                (sum / count - 1.0).abs() + EDGE_MARGIN_Z * se
            })
            .fold(0.0f64, f64::max)
    };
    let off_axis = worst(&mut rings.values().copied());
    let axis = worst(&mut lines.values().copied()).max(if d == 1 { off_axis } else { 0.0 });
    TailDeviation {
        axis: if d == 1 { axis.max(off_axis) } else { axis },
        off_axis,
    }
}

/// How the per-pattern lattice form spends its realizations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatternPlan {
    /// Realizations to start with (rounded up to a multiple of 4).
    pub initial: usize,
    /// Keep adding realizations while the relative standard error is above this…
    pub target_noise: f64,
    /// …and the total stays within this many.
    pub max_realizations: usize,
    /// Spectrum parameters (lattice extent, engine, seed).
    pub spectrum: SpectrumParams,
    /// Average the weights over the cube's symmetries (for samplers whose distribution has
    /// them).
    pub symmetric: bool,
    /// Read the low band from a fit over this disc (for stationary, isotropic samplers; the
    /// raw estimate is kept beside it, and the narrower is reported).
    pub low_band: Option<LowBand>,
}

/// The lattice form pattern by pattern: each pattern's `V_r = (1/N) Σ_{k≠0} |f̂(k)|² P_r(k)` (its
/// exact variance under random shifts, up to the lattice's truncation), their mean over the
/// patterns, its standard error from their spread, and a tail bound from the spectrum's measured
/// deviation from white at the lattice's edge. Realizations are added (in the same order, so
/// the result depends only on the final count) while the relative error exceeds
/// `plan.target_noise` and the count stays within `plan.max_realizations`.
///
/// Returns the prediction and the number of realizations used.
///
/// # Errors
/// As [`SpectrumAccumulator`], or a lattice that differs from the plan's.
pub fn predict_on_patterns(
    power: &LatticePower,
    source: PatternSource<'_>,
    plan: &PatternPlan,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let mut all = predict_on_patterns_many(std::slice::from_ref(power), source, plan, progress)?;
    all.pop()
        .ok_or_else(|| Error::Mismatch("no prediction for one power".into()))
}

/// [`predict_on_patterns`] for several integrands' powers on the same lattice, on the same
/// patterns: their per-pattern sums are accumulated together, and realizations are added until
/// every one meets `plan.target_noise` (or the cap).
///
/// # Errors
/// As [`predict_on_patterns`].
pub fn predict_on_patterns_many(
    powers: &[LatticePower],
    source: PatternSource<'_>,
    plan: &PatternPlan,
    progress: &dyn Progress,
) -> Result<Vec<Prediction>> {
    if powers.is_empty() {
        return Ok(Vec::new());
    }
    let mut estimate = PatternEstimate::new(powers, source, plan)?;
    let all: Vec<usize> = (0..powers.len()).collect();
    estimate.extend(&all, progress)?;
    estimate.predictions(&all)
}

/// The per-pattern lattice form of several powers on the same patterns, resumable: a first
/// look stopped at a few realizations ([`limit_to`](Self::limit_to)) can be continued for some
/// of the powers ([`lift_limit`](Self::lift_limit)) without drawing or transforming the first
/// patterns again. The engine is the plan's throughout (its tolerance follows the plan's cap)
/// and the realizations are added in the same order whatever the stops on the way, so the
/// result depends only on the final count.
pub(crate) struct PatternEstimate<'a, 'p> {
    powers: &'p [LatticePower],
    weights: Vec<PowerWeights>,
    fits: Option<LowBandFits>,
    acc: SpectrumAccumulator<'a>,
    /// The most realizations the plan may use.
    cap: usize,
    /// Where a first look stops (`usize::MAX` for none).
    limit: usize,
    plan: PatternPlan,
}

impl<'a, 'p> PatternEstimate<'a, 'p> {
    /// An estimate of `powers` (all on the plan's lattice) from `source`'s patterns, with no
    /// realization yet. The spectrum engine's tolerance follows the most realizations the
    /// plan may reach.
    ///
    /// # Errors
    /// As [`SpectrumAccumulator::new`], or a power on another lattice than the plan's.
    pub(crate) fn new(
        powers: &'p [LatticePower],
        source: PatternSource<'a>,
        plan: &PatternPlan,
    ) -> Result<Self> {
        let Some(first) = powers.first() else {
            return Err(Error::Mismatch("an estimate of no power".into()));
        };
        let lattice = first.lattice;
        if let Some(p) = powers
            .iter()
            .find(|p| p.lattice != lattice || plan.spectrum.kmax != p.lattice.kmax)
        {
            return Err(Error::Mismatch(format!(
                "spectrum on |k_i| ≤ {} for a power on |k_i| ≤ {}",
                plan.spectrum.kmax, p.lattice.kmax
            )));
        }
        let fits = plan.low_band.and_then(|band| {
            Some(LowBandFits {
                radius: band.radius,
                reported: band.fit(lattice, FIT_DEGREE)?,
                check: band.fit(lattice, FIT_DEGREE + 1)?,
            })
        });
        let weights: Vec<PowerWeights> = powers
            .iter()
            .map(|p| {
                let raw = if plan.symmetric {
                    p.symmetrized().power
                } else {
                    p.power.clone()
                };
                PowerWeights::new(raw, fits.as_ref())
            })
            .collect();
        let cap = source
            .available()
            .unwrap_or(usize::MAX)
            .min(plan.max_realizations);
        let spectrum = SpectrumParams {
            realizations: cap.min(plan.max_realizations.max(plan.initial)),
            ..plan.spectrum
        };
        let flat: Vec<Vec<f64>> = weights.iter().flat_map(PowerWeights::vectors).collect();
        Ok(Self {
            powers,
            weights,
            fits,
            acc: SpectrumAccumulator::new(source, &spectrum, flat)?,
            cap,
            limit: usize::MAX,
            plan: *plan,
        })
    }

    /// Stops this estimate's extensions at `count` realizations (a first look); the engine
    /// stays the plan's, so the look can be continued ([`lift_limit`](Self::lift_limit)).
    pub(crate) fn limit_to(&mut self, count: usize) {
        self.limit = count;
    }

    /// Lets the extensions run to the plan's cap again, from the realizations so far.
    pub(crate) fn lift_limit(&mut self) {
        self.limit = usize::MAX;
    }

    /// Adds realizations from the plan's initial count on, while the relative error of any of
    /// the powers `active` (indices into the powers) exceeds the plan's target, up to the
    /// plan's cap (and the limit of a first look).
    ///
    /// # Errors
    /// As [`SpectrumAccumulator::extend_to`].
    pub(crate) fn extend(&mut self, active: &[usize], progress: &dyn Progress) -> Result<()> {
        let cap = self.cap.min(self.limit);
        let mut target = round_up(self.plan.initial, cap);
        loop {
            if target > self.acc.realizations() {
                progress.begin(
                    "spectrum realizations",
                    (target - self.acc.realizations()) as u64,
                );
                self.acc.extend_to(target, progress)?;
                progress.end();
            }
            // A relative error that is not a number (one realization, a zero mean) cannot
            // improve.
            let sums = self.acc.weighted();
            let split = PowerWeights::split(&self.weights, &sums);
            let worst = active
                .iter()
                .map(|&i| self.weights[i].relative_noise(split[i].clone()))
                .filter(|rel| rel.is_finite())
                .fold(0.0, f64::max);
            if worst <= self.plan.target_noise || target >= cap {
                return Ok(());
            }
            let wanted = (target as f64 * (worst / self.plan.target_noise).powi(2)).ceil() as usize;
            target = round_up(wanted.max(target + 4), cap);
        }
    }

    /// The predictions of the powers `which` (indices into the powers) from the realizations so
    /// far.
    ///
    /// # Errors
    /// A power whose prediction cannot be formed (as [`predict_on_patterns`]).
    pub(crate) fn predictions(&self, which: &[usize]) -> Result<Vec<Prediction>> {
        let estimate = self.acc.estimate();
        let deviation = measured_tail_deviation(&estimate.lattice);
        let sums = self.acc.weighted();
        let split = PowerWeights::split(&self.weights, &sums);
        which
            .iter()
            .map(|&i| {
                let (power, w, s) = (&self.powers[i], &self.weights[i], &split[i]);
                let on = |weights: &[f64], sums: &WeightedMean, low_band: Option<f64>| {
                    pattern_prediction(
                        power,
                        (weights, sums),
                        &estimate.lattice,
                        deviation,
                        low_band,
                    )
                };
                let raw = on(&w.raw, s[0], None)?;
                let (Some(band), Some(fits), Some(fitted)) = (&w.band, &self.fits, s.get(1)) else {
                    return Ok(raw);
                };
                if !fit_agrees(s[3]) {
                    return Ok(raw);
                }
                let mut smooth = on(&band.fitted, fitted, Some(fits.radius))?;
                smooth.budget.model = low_band_model(s[2]) / estimate.lattice.n as f64;
                // The fit is reported where its 99% budget, model term included, is the
                // narrower, with the raw sums beside it; where it is not, the fit is no answer
                // (a spectrum that vanishes at the origin, as CCVT's, leaves a line fit far
                // off) and is not shown.
                let width = |p: &Prediction| p.budget.half_width(crate::montecarlo::Z_99);
                if width(&smooth) >= width(&raw) {
                    return Ok(raw);
                }
                smooth.alternatives.push(raw.as_alternative());
                Ok(smooth)
            })
            .collect()
    }
}

/// The weights one power's per-pattern sums are taken with: the raw power, and for a sampler
/// with a low band ([`LowBand`]) the weights of its fit and the difference the fit one degree
/// higher makes (whose mean and paired standard error bound the fit's model error).
struct PowerWeights {
    raw: Vec<f64>,
    band: Option<FittedWeights>,
}

/// The low band's two fits over one lattice, shared by every power: the reported one and the
/// check one degree higher.
struct LowBandFits {
    radius: f64,
    reported: DiscFit,
    check: DiscFit,
}

/// A low band's weights: the reported fit, the check's difference from it, and the fit's
/// difference from the raw weights (its departure from the raw sums, tested per pattern).
struct FittedWeights {
    fitted: Vec<f64>,
    check: Vec<f64>,
    departure: Vec<f64>,
}

impl PowerWeights {
    fn new(raw: Vec<f64>, fits: Option<&LowBandFits>) -> Self {
        let band = fits.and_then(|f| {
            let fitted = f.reported.smoothed(&raw)?;
            let higher = f.check.smoothed(&raw)?;
            let check = higher.iter().zip(&fitted).map(|(h, f)| h - f).collect();
            let departure = fitted.iter().zip(&raw).map(|(f, r)| f - r).collect();
            Some(FittedWeights {
                fitted,
                check,
                departure,
            })
        });
        Self { raw, band }
    }

    /// The vectors accumulated, in the order [`split`](Self::split) reads them back.
    fn vectors(&self) -> Vec<Vec<f64>> {
        let mut out = vec![self.raw.clone()];
        if let Some(b) = &self.band {
            out.push(b.fitted.clone());
            out.push(b.check.clone());
            out.push(b.departure.clone());
        }
        out
    }

    /// The accumulated sums, one slice per power (raw, then fitted, check and departure if
    /// any).
    fn split<'a>(all: &[Self], sums: &'a [WeightedMean]) -> Vec<Vec<&'a WeightedMean>> {
        let mut rest = sums.iter();
        all.iter()
            .map(|w| {
                let count = if w.band.is_some() { 4 } else { 1 };
                rest.by_ref().take(count).collect()
            })
            .collect()
    }

    /// The relative noise of the narrower of the raw and fitted estimates (the fit's model
    /// bound counted as noise at 99%; a fit the raw sums reject is no candidate): realizations
    /// are added until the one reported meets the target.
    fn relative_noise(&self, sums: Vec<&WeightedMean>) -> f64 {
        let raw = sums[0].stderr / sums[0].mean;
        match (sums.get(1), sums.get(2), sums.get(3)) {
            (Some(fitted), Some(check), Some(departure)) if fit_agrees(departure) => {
                let fit =
                    (fitted.stderr + low_band_model(check) / crate::montecarlo::Z_99) / fitted.mean;
                if fit.is_finite() {
                    fit.min(raw)
                } else {
                    raw
                }
            }
            _ => raw,
        }
    }
}

/// Whether the fit's mean departure from the raw sums is within its paired noise at 99%. The
/// raw sums are unbiased whatever the spectrum's shape, so a significant departure shows a low
/// band the fit's polynomial does not describe (a spectrum that changes faster than the disc's
/// scale, as Gaussian blue noise's, which climbs back to white noise's at the lowest
/// frequencies); the degree check cannot see a change both fits smooth over.
fn fit_agrees(departure: &WeightedMean) -> bool {
    departure.stderr.is_finite()
        && departure.mean.abs() <= crate::montecarlo::Z_99 * departure.stderr
}

/// The fit's model term (unnormalized): the mean difference the next degree makes and its
/// paired standard error at 99%.
fn low_band_model(check: &WeightedMean) -> f64 {
    let stderr = if check.stderr.is_finite() {
        check.stderr
    } else {
        0.0
    };
    check.mean.abs() + crate::montecarlo::Z_99 * stderr
}

/// The lattice form of one power from its per-pattern sums with `weights`.
fn pattern_prediction(
    power: &LatticePower,
    (weights, sums): (&[f64], &WeightedMean),
    spectrum: &LatticeSpectrum,
    deviation: TailDeviation,
    low_band: Option<f64>,
) -> Result<Prediction> {
    let n = spectrum.n;
    let WeightedMean {
        mean,
        stderr,
        realizations,
    } = *sums;
    let variance = finite((mean + power.beyond) / n as f64, || {
        format!("the lattice form of {} is not finite", power.label)
    })?;
    Ok(Prediction {
        randomization: crate::randomization::Randomization::Shift,
        variance,
        route: Route {
            form: Form::Lattice,
            spectrum: SpectrumOrigin::Estimated {
                n,
                realizations,
                kmax: power.lattice.kmax,
                low_band,
            },
        },
        reason: String::new(),
        budget: ErrorBudget {
            tabulation: 0.0,
            spectrum_noise: if stderr.is_finite() {
                stderr / n as f64
            } else {
                0.0
            },
            quadrature: engine_bound(weights, spectrum),
            truncation: power.tail_bound(deviation) / n as f64,
            model: 0.0,
        },
        n,
        dimension: power.lattice.dimension,
        dc_term: 0.0,
        evaluations: (power.lattice.len() * realizations) as u64,
        alternatives: Vec::new(),
        analysis: None,
    })
}

/// What the spectrum engine's error can add to `(1/N) Σ_k w(k) P(k)`: `(1/N) Σ |w(k)| δP(k)`
/// with `δP` the engine's bound at the mean power (the bound is concave in `P`, so its mean
/// over the patterns is at most its value at the mean); zero for the direct engine.
fn engine_bound(weights: &[f64], spectrum: &LatticeSpectrum) -> f64 {
    let n = spectrum.n;
    let sum: f64 = weights
        .iter()
        .zip(&spectrum.mean)
        .enumerate()
        .filter(|(i, _)| !spectrum.is_dc(*i))
        .map(|(_, (w, p))| w.abs() * engine_error(spectrum.engine, n, *p))
        .sum();
    sum / n as f64
}

/// `wanted` rounded up to a multiple of 4, at most `cap` (which need not be one).
fn round_up(wanted: usize, cap: usize) -> usize {
    (wanted.div_ceil(4) * 4).min(cap).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::Gaussian;
    use crate::progress::Silent;
    use crate::sampler::{Jitter, Sampler};

    /// A first look continued is the full plan's estimate from the start, to the bit.
    #[test]
    fn a_continued_first_look_is_the_full_estimate() {
        let jitter = Jitter::new(2).unwrap();
        let source = PatternSource::Sampler {
            sampler: &jitter as &dyn Sampler,
            n: 64,
            seed: 9,
        };
        let f = Gaussian::new(0.1, vec![0.3, 0.6], 1.0).unwrap();
        let lattice = Lattice {
            dimension: 2,
            kmax: 8,
        };
        let powers = [LatticePower::of_within(&f, lattice, &Budget::default()).unwrap()];
        // A target no count meets: the full estimate runs to its cap.
        let full = PatternPlan {
            initial: 8,
            target_noise: 1e-6,
            max_realizations: 40,
            spectrum: SpectrumParams {
                kmax: 8,
                ..Default::default()
            },
            symmetric: false,
            low_band: None,
        };
        let mut estimate = PatternEstimate::new(&powers, source, &full).unwrap();
        estimate.limit_to(full.initial);
        estimate.extend(&[0], &Silent).unwrap();
        let first = estimate.predictions(&[0]).unwrap().remove(0);
        estimate.lift_limit();
        estimate.extend(&[0], &Silent).unwrap();
        let continued = estimate.predictions(&[0]).unwrap().remove(0);
        let fresh = predict_on_patterns_many(&powers, source, &full, &Silent)
            .unwrap()
            .remove(0);
        assert_ne!(first.variance, fresh.variance, "the look stopped early");
        assert_eq!(continued.variance.to_bits(), fresh.variance.to_bits());
        assert_eq!(continued.budget, fresh.budget);
    }
}

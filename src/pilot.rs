//! Planning from a pilot: a few renders of an image at a small sample count, instead of the
//! pixels' integrands.
//!
//! Tabulating every pixel's integrand can cost more than rendering the image. A pilot asks
//! less: `k ≥ 2` renders of the image with the sampler to be planned, at a small count `n₀`.
//! Their spread gives the image's variance at `n₀`, `V̂ = (1/P) Σ_p s²_p` (the mean over the
//! `P` pixels of each pixel's sample variance across the renders, unbiased for the image's
//! mean-square error at `n₀`). How that variance falls from `n₀` to N is not in the pilot; it
//! comes from the sampler's own predictions on an [`EdgeFamily`], discontinuous integrands in
//! general position (a disk and edges at oblique angles), the class of a pixel whose integrand
//! is cut by visibility:
//!
//! `Var(N) = V̂ · ρ(N)`, `ρ(N) = exp(mean_i ln(Var_i(N) / Var_i(n₀)))`,
//!
//! with `Var_i` the prediction for the family's member `i` under the estimator planned for.
//! This captures what a power law would miss: the sampler's pre-asymptotic regime, its rate on
//! discontinuities (`N^{-1}` for random points, near `N^{-3/2}` for strata and nets in 2D) and
//! its count ladder.
//!
//! The budget has three parts: the pilot's noise (the standard error of `V̂`: the larger of
//! the spread of the pixels' sample variances over `√P`, which counts the pixels' differences as
//! noise and so errs wide, and the normal-theory `V̂ √(2 / ((k−1) P))`); the members'
//! prediction noise; and a model term, the largest relative distance of one member's ratio from
//! `ρ` plus the members' own bounds. An image whose pixels' ratios lie within the family's is
//! covered by the model term, since the image's ratio is a mean of its pixels' ratios weighted
//! by their variances at `n₀`. A pixel whose discontinuities run along the axes falls faster
//! under nets than the family does, and a smooth image faster than any discontinuous one: the
//! plan then errs towards more samples than needed.
//!
//! A render's pixel is rarely one 2D integral: the film position, the light sample, the lens
//! are pairs of dimensions that the renderer pads together, and the interaction between pairs
//! is integrated almost as by independent points (`crate::padded`): that part of the variance
//! falls like `1/N` whatever the sampler. A pilot cannot tell the two parts apart, so the
//! default [`PilotModel::Padded`] carries the variance by `ρ = (ρ_edges + n₀/N) / 2` and widens
//! the model term to hold any split between the two (all interaction: `n₀/N`; none: the
//! family's ratio). [`PilotModel::Single`] is for a pixel integrated by one 2D pattern (a light
//! sample at a fixed shading point): `ρ = ρ_edges`. On a Cornell-box crop rendered by Mitsuba
//! 3 (film × light), four renders at 16 samples planned 462 samples for a 1% image RMSE with
//! the padded model (renders measured 0.93%) and 221 with the single one (1.35%).
//!
//! A pilot of one pixel cannot plan to a useful precision: four renders give its variance with
//! the spread of a `χ²₃`, a factor of ten across its 90% range. The pixels of an image average
//! that out; the plan's interval says how far.

use crate::error::{invalid, Error, Result};
use crate::integrand::{Ball, Integrand, Polygon};
use crate::npy::{read_npy, NpyArray};
use crate::plan::{plan_by, reached, resolve, Plan, PlanParams};
use crate::predict::{predict_with, ErrorBudget, PredictParams, Prediction, Problem};
use crate::progress::Progress;
use crate::randomization::Randomization;
use crate::sampler::Sampler;
use serde::Serialize;
use std::path::Path;

/// The dimension of the light or lens samples a pilot plans for.
pub const PILOT_DIMENSION: usize = 2;

/// What the pixels of a pilot integrate, which decides how their variance falls with N.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PilotModel {
    /// Pairs of dimensions padded together (film × light, …): part of the variance falls like
    /// the sampler's on discontinuities, part (the pairs' interaction) like `1/N`, in a split
    /// the pilot does not know. A render's pixels, by default.
    #[default]
    Padded,
    /// One 2D pattern per pixel (e.g. the light sample at a fixed shading point): the variance
    /// falls like the sampler's on discontinuities.
    Single,
}

impl std::str::FromStr for PilotModel {
    type Err = Error;
    /// `padded` or `single`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "padded" => Ok(PilotModel::Padded),
            "single" => Ok(PilotModel::Single),
            other => Err(invalid("pilot model", other, "padded or single")),
        }
    }
}

impl std::fmt::Display for PilotModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            PilotModel::Padded => "padded",
            PilotModel::Single => "single",
        })
    }
}

/// Renders of an image at one sample count, with the sampler to be planned.
#[derive(Debug, Clone, PartialEq)]
pub struct Pilot {
    n: usize,
    renders: usize,
    values: Vec<f64>,
    model: PilotModel,
}

/// What a pilot says of the image at its sample count.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PilotVariance {
    /// The sample count of the renders.
    pub n: usize,
    /// Renders.
    pub renders: usize,
    /// Pixels per render.
    pub pixels: usize,
    /// The image's mean value (over pixels and renders).
    pub mean: f64,
    /// The image's variance at `n`: the mean over pixels of their sample variances.
    pub variance: f64,
    /// Its standard error.
    pub standard_error: f64,
}

impl Pilot {
    /// A pilot of `renders` renders at `n` samples per pixel, `values` render by render (all
    /// pixels of render 0 first).
    ///
    /// # Errors
    /// `n` of 0, fewer than two renders, values not a whole number of renders, a value that is
    /// not finite, or renders that are all the same (no variance to scale).
    pub fn new(n: usize, renders: usize, values: Vec<f64>) -> Result<Self> {
        if n == 0 {
            return Err(invalid("pilot sample count", n, "at least 1"));
        }
        if renders < 2 {
            return Err(invalid(
                "pilot renders",
                renders,
                "at least 2 renders (their spread is the pilot's variance)",
            ));
        }
        if values.is_empty() || !values.len().is_multiple_of(renders) {
            return Err(invalid(
                "pilot values",
                values.len(),
                format!("a positive multiple of the {renders} renders (renders × pixels)"),
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(invalid(
                "pilot value",
                values[i],
                format!(
                    "a finite number (render {}, pixel {})",
                    i / (values.len() / renders),
                    i % (values.len() / renders)
                ),
            ));
        }
        let pilot = Self {
            n,
            renders,
            values,
            model: PilotModel::default(),
        };
        if pilot.variance().variance <= 0.0 {
            return Err(invalid(
                "pilot",
                "identical renders",
                "renders with independent randomizations (their spread is the variance planned from)",
            ));
        }
        Ok(pilot)
    }

    /// A pilot from an array whose first axis is the render: `(renders, pixels)`,
    /// `(renders, height, width)` or any shape with renders first.
    ///
    /// # Errors
    /// An array of rank below 2, and as [`new`](Self::new).
    pub fn from_array(n: usize, array: NpyArray) -> Result<Self> {
        match array.shape.as_slice() {
            [renders, _, ..] => Self::new(n, *renders, array.values),
            _ => Err(Error::format(
                "pilot",
                format!(
                    "shape {:?}: (renders, pixels) or (renders, height, width)",
                    array.shape
                ),
            )),
        }
    }

    /// Reads a pilot from a `.npy` file ([`from_array`](Self::from_array)).
    ///
    /// # Errors
    /// An unreadable or malformed file, and as [`from_array`](Self::from_array).
    pub fn read(path: &Path, n: usize) -> Result<Self> {
        Self::from_array(n, read_npy(&crate::io::read_bounded(path)?)?)
    }

    /// The sample count of the renders.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The same pilot, its pixels integrating as `model` says ([`PilotModel::Padded`] by
    /// default).
    pub fn with_model(self, model: PilotModel) -> Self {
        Self { model, ..self }
    }

    /// What its pixels integrate.
    pub fn model(&self) -> PilotModel {
        self.model
    }

    /// The image's variance at the pilot's count, and its standard error.
    pub fn variance(&self) -> PilotVariance {
        let pixels = self.values.len() / self.renders;
        let k = self.renders as f64;
        let sample_variances: Vec<f64> = (0..pixels)
            .map(|p| {
                let of = |r: usize| self.values[r * pixels + p];
                let mean = (0..self.renders).map(of).sum::<f64>() / k;
                (0..self.renders)
                    .map(|r| (of(r) - mean).powi(2))
                    .sum::<f64>()
                    / (k - 1.0)
            })
            .collect();
        let count = pixels as f64;
        let variance = sample_variances.iter().sum::<f64>() / count;
        let spread = if pixels > 1 {
            let ss = sample_variances
                .iter()
                .map(|s| (s - variance).powi(2))
                .sum::<f64>();
            (ss / (count - 1.0) / count).sqrt()
        } else {
            0.0
        };
        let normal = variance * (2.0 / ((k - 1.0) * count)).sqrt();
        PilotVariance {
            n: self.n,
            renders: self.renders,
            pixels,
            mean: self.values.iter().sum::<f64>() / self.values.len() as f64,
            variance,
            standard_error: spread.max(normal),
        }
    }
}

/// Discontinuous integrands in general position whose predicted variances carry a pilot's
/// variance from its count to others: a disk off the square's centre and three edges at
/// oblique angles, none along an axis (where nets do better than on a pixel's typical edge).
pub struct EdgeFamily {
    members: Vec<Box<dyn Integrand>>,
}

/// The relative noise each family member's prediction aims at: the geometric mean of four
/// carries about half of it, well under a pilot's own noise (a 64-pixel image of four renders
/// knows its variance to about 10%), so a tighter one only costs time (estimated routes need
/// `1/ε²` patterns).
pub const FAMILY_TARGET_NOISE: f64 = 0.05;

/// The edges of [`EdgeFamily`]: angle in degrees and offset.
const FAMILY_EDGES: [(f64, f64); 3] = [(17.0, 0.43), (38.0, 0.61), (62.0, 0.37)];
/// The disk of [`EdgeFamily`]: radius and centre.
const FAMILY_DISK: (f64, [f64; 2]) = (0.3, [0.43, 0.52]);

impl EdgeFamily {
    /// The family in 2D.
    ///
    /// # Errors
    /// None in practice (the members' parameters are valid); the constructors' errors.
    pub fn new() -> Result<Self> {
        let mut members: Vec<Box<dyn Integrand>> = vec![Box::new(Ball::new(
            FAMILY_DISK.0,
            FAMILY_DISK.1.to_vec(),
            1.0,
        )?)];
        for (theta, offset) in FAMILY_EDGES {
            members.push(Box::new(Polygon::edge(theta, offset, 1.0)?));
        }
        Ok(Self { members })
    }

    /// The members' predictions at `n` for `sampler` under `randomization`.
    fn predict(
        &self,
        sampler: &dyn Sampler,
        randomization: Randomization,
        n: usize,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Vec<Prediction>> {
        self.members
            .iter()
            .map(|f| {
                let problem =
                    Problem::new(sampler, f.as_ref(), n)?.with_randomization(randomization);
                predict_with(&problem, params, progress)
            })
            .collect()
    }
}

/// The family's ratio `ρ = Var(n) / Var(n₀)` and its uncertainty, relative to `ρ`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct FamilyRatio {
    ratio: f64,
    /// One standard error from the members' prediction noise.
    noise: f64,
    /// The members' spread about `ρ` and their predictions' bounds.
    model: f64,
}

/// The ratio under `model` from `n₀` to `n`: the family's, or for padded pixels the mean of the
/// family's and the white `n₀/n`, with a model term that holds every split between them.
fn model_ratio(model: PilotModel, family: FamilyRatio, n0: usize, n: usize) -> FamilyRatio {
    match model {
        PilotModel::Single => family,
        PilotModel::Padded => {
            let white = n0 as f64 / n as f64;
            let ratio = 0.5 * (family.ratio + white);
            let high = white.max(family.ratio * (1.0 + family.model));
            let low = white.min(family.ratio * (1.0 - family.model).max(0.0));
            FamilyRatio {
                ratio,
                noise: family.noise * 0.5 * family.ratio / ratio,
                model: (high - ratio).max(ratio - low) / ratio,
            }
        }
    }
}

fn family_ratio(at_pilot: &[Prediction], at_n: &[Prediction]) -> FamilyRatio {
    let count = at_pilot.len() as f64;
    let ratios: Vec<f64> = at_pilot
        .iter()
        .zip(at_n)
        .map(|(a, b)| b.variance / a.variance)
        .collect();
    let ratio = (ratios.iter().map(|r| r.ln()).sum::<f64>() / count).exp();
    let relative = |p: &Prediction, part: fn(&ErrorBudget) -> f64| part(&p.budget) / p.variance;
    let noise_of = |b: &ErrorBudget| b.spectrum_noise;
    let bounds_of = ErrorBudget::bounds;
    let noise = at_pilot
        .iter()
        .chain(at_n)
        .map(|p| relative(p, noise_of).powi(2))
        .sum::<f64>()
        .sqrt()
        / count;
    let spread = ratios
        .iter()
        .map(|r| (r / ratio - 1.0).abs())
        .fold(0.0, f64::max);
    let bounds = at_pilot
        .iter()
        .zip(at_n)
        .map(|(a, b)| relative(a, bounds_of) + relative(b, bounds_of))
        .fold(0.0, f64::max);
    FamilyRatio {
        ratio,
        noise,
        model: spread + bounds,
    }
}

/// Plans the samples per pixel for `sampler` from `pilot`, renders of the image made with that
/// sampler under the estimator planned for: the smallest balanced count whose image RMSE,
/// `√(V̂ ρ(N))`, reaches the target (a relative target is relative to the pilot's mean value).
/// The plan's route says it is a pilot's; its interval carries the pilot's noise and the
/// family's spread (see the module's notes).
///
/// # Errors
/// A sampler other than 2D, a pilot count the sampler cannot produce, and as
/// [`crate::plan::plan`].
///
/// # Examples
/// ```
/// use specvar::pilot::{plan_pilot, Pilot};
/// use specvar::plan::{PlanParams, Target};
/// use specvar::progress::Silent;
/// use specvar::sampler::Jitter;
/// // Two renders of a three-pixel image at 16 samples per pixel.
/// let pilot = Pilot::new(16, 2, vec![0.50, 0.31, 0.72, 0.46, 0.35, 0.70])?;
/// let p = plan_pilot(&Jitter::new(2)?, &pilot, &PlanParams::new(Target::Rmse(0.005)), &Silent)?;
/// assert!(p.n > 16 && p.rmse <= 0.005);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn plan_pilot(
    sampler: &dyn Sampler,
    pilot: &Pilot,
    params: &PlanParams,
    progress: &dyn Progress,
) -> Result<Plan> {
    if sampler.dimension() != PILOT_DIMENSION {
        return Err(invalid(
            "pilot sampler dimension",
            sampler.dimension(),
            "2 (a pilot plans a pixel's 2D light or lens samples)",
        ));
    }
    sampler.check_count(pilot.n)?;
    let (kind, randomization) = resolve(sampler, params)?;
    let measured = pilot.variance();
    let family = EdgeFamily::new()?;
    let member = PredictParams {
        target_noise: params.predict.target_noise.max(FAMILY_TARGET_NOISE),
        ..params.predict
    };
    let at_pilot = family.predict(sampler, randomization, pilot.n, &member, progress)?;
    let pilot_noise = measured.standard_error / measured.variance;
    let mut plan = reached(plan_by(
        (kind, PILOT_DIMENSION),
        measured.mean,
        params,
        |n| {
            let at_n = family.predict(sampler, randomization, n, &member, progress)?;
            let r = model_ratio(pilot.model, family_ratio(&at_pilot, &at_n), pilot.n, n);
            let variance = measured.variance * r.ratio;
            Ok(Prediction {
                variance,
                budget: ErrorBudget {
                    tabulation: 0.0,
                    spectrum_noise: variance * pilot_noise.hypot(r.noise),
                    model: variance * r.model,
                    ..ErrorBudget::default()
                },
                evaluations: at_n.iter().map(|p| p.evaluations).sum(),
                alternatives: Vec::new(),
                analysis: None,
                ..at_n[0].clone()
            })
        },
    )?)?;
    let carried = match pilot.model {
        PilotModel::Single => format!(
            "the {} on {} discontinuities",
            plan.route,
            family.members.len()
        ),
        PilotModel::Padded => format!(
            "the mean of 1/N (padded pairs' interaction) and the {} on {} discontinuities",
            plan.route,
            family.members.len()
        ),
    };
    plan.route = format!(
        "pilot ({} renders of {} pixels at N = {}, {} model), carried to N by {carried}",
        measured.renders, measured.pixels, measured.n, pilot.model
    );
    plan.reason = format!(
        "the pilot's variance {:.4e} ± {:.2e} at N = {} times the ratio of the sampler's \
         predictions on discontinuities in general position",
        measured.variance, measured.standard_error, measured.n
    );
    Ok(plan)
}

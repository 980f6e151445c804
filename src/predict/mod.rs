//! Variance and bias predicted from spectra.
//!
//! [`predict`] is the one call: given a [`Problem`] (a sampler or your own point sets, an
//! integrand, N) it chooses a route that is valid for that problem, computes the spectrum the
//! route needs, and returns a [`Prediction`] that says which route it took, why, and its error
//! budget (spectrum noise, quadrature, truncation, model). The routes and their validity
//! (`docs/theory.md` has the derivations):
//!
//! - **a closed form at N** (white noise, jitter with its strata, Latin hypercube, the
//!   homogenized regular grid): the lattice form with it, exact on the torus; white noise by
//!   Parseval, the regular grid summed in space through the integrand's autocorrelation, the
//!   others with a tail bound from the closed form;
//! - **otherwise, the spectrum estimated at N**: the lattice form pattern by pattern
//!   ([`predict_on_patterns`]), with the noise of the patterns and a tail bound from the
//!   spectrum's measured deviation from white; your own point sets take this route;
//! - **the polar form** ([`predict_polar`]) on request or as an alternative: only for an
//!   isotropic integrand contained in the cube whose autocorrelation, with the pattern's
//!   correlations, fits in the torus; with an estimated spectrum only for a sampler that is
//!   scale invariant at N and at the reference N, and never below the estimate's first ring
//!   (N at most the reference N).
//!
//! The bias of a fixed pattern is [`bias_of_pattern`] and [`regular_grid_bias`].

mod analysis;
mod digits;
mod fourier;
mod route;
mod strata;
mod table;
mod tabulation;
mod term_mean;
mod walsh;

pub use analysis::{
    analyses_markdown, analysis_markdown_table, AnalysisKind, AnalysisPlan, PlanNeeds,
};
pub use digits::permuted_digits::PermutedDigitsOrigin;
pub use digits::permuted_level::PermutedLevelOrigin;
pub use fourier::bias::{
    bias_of_pattern, regular_grid_bias, sampler_bias, BiasMethod, SpectralBias,
};
pub use fourier::gaussian_jitter::gaussian_jitter_bias;
pub use fourier::jitter_tent::jitter_shift_variance;
pub use fourier::lattice::{
    predict_from_power, predict_lattice, predict_on_patterns, LatticePower, PatternPlan,
};
pub use fourier::low_band::{DiscFit, LowBand};
pub use fourier::pair::{pair_correlation_variance, PcfVariance};
pub use fourier::polar::{predict_polar, PolarParams};
pub use fourier::space::{
    kronecker_variance, pattern_shift_variance, rank1_lattice_variance, regular_grid_variance,
};
pub use route::{default_kmax, default_reference_n, polar_validity};
pub use strata::cell_moments::CellSum;
pub use strata::cell_pairs::{
    correlated_multi_jitter_variance, latin_hypercube_variance, multi_jitter_variance,
};
pub use strata::cells::{fixed_strata_variance, occupancy_variance, CellOrigin, Occupancy};
pub use tabulation::{
    min_tabulation_cells, MIN_COARSE_CELLS_PER_SPACING, SMOOTH_RATIO, SMOOTH_STEP_RATIO,
};
pub use term_mean::OccupancyEstimate;
pub use walsh::forms::{WalshNetOrigin, WalshOrigin};

use crate::error::{finite, invalid, Error, Result};
use crate::integrand::Integrand;
use crate::pointset::PointSet;
use crate::progress::{Progress, Silent};
use crate::randomization::Randomization;
use crate::sampler::{CellRule, Sampler, SamplerKind};
use crate::spectrum::{ClosedForm, SpectrumEstimate};
use serde::Serialize;
use std::fmt;

/// Where a sampler's expected spectrum comes from, for either form.
#[derive(Debug, Clone, Copy)]
pub enum SpectrumSource<'a> {
    /// A closed form, exact at every N (the lattice form reads it at integer frequencies, the
    /// polar form its radial mean, where it has one).
    Closed(ClosedForm),
    /// An estimate at some N: the polar form reads its radial spectrum at `ν = ρ/N^{1/d}` (any
    /// N, for a scale-invariant sampler); the lattice form needs it at the target N.
    Estimated(&'a SpectrumEstimate),
}

impl SpectrumSource<'_> {
    /// What the source is, as an owned typed value.
    pub fn origin(&self) -> SpectrumOrigin {
        match self {
            SpectrumSource::Closed(c) => SpectrumOrigin::Closed(*c),
            SpectrumSource::Estimated(e) => SpectrumOrigin::Estimated {
                n: e.lattice.n,
                realizations: e.lattice.realizations,
                kmax: e.lattice.lattice.kmax,
                low_band: None,
            },
        }
    }
}

/// Where the spectrum of a prediction came from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SpectrumOrigin {
    /// A closed form.
    Closed(ClosedForm),
    /// No spectrum: the unshifted estimator summed over cells in space.
    Cells(CellOrigin),
    /// Walsh coefficients of the integrand and of a fixed pattern (a digital shift).
    Walsh(WalshOrigin),
    /// Walsh energies of a product integrand's factors at every level, summed over a linear
    /// net's dual (a digital shift): exact to quadrature.
    WalshNet(WalshNetOrigin),
    /// Each axis's factor by its energy on every support of digits, summed over the pairs of
    /// Halton's points drawn with permuted digits: exact to quadrature.
    PermutedDigits(PermutedDigitsOrigin),
    /// The integrand's and the points' energies on every support of digits through a level
    /// of cells, exact, the finer digits measured on Halton's realizations as drawn.
    PermutedLevel(PermutedLevelOrigin),
    /// Each given set's own periodogram, summed in space over its pairs of points through the
    /// integrand's autocorrelation: exact.
    Pairs {
        /// Sets averaged.
        sets: usize,
    },
    /// Each of `patterns` patterns of `n` points by its own periodogram, summed in space over
    /// its pairs of points through the integrand's autocorrelation: exact for each pattern,
    /// their mean estimated.
    PatternPairs {
        /// The N of the patterns.
        n: usize,
        /// Patterns averaged.
        patterns: usize,
    },
    /// Estimated from `realizations` patterns of `n` points on the lattice `|k_i| ≤ kmax`.
    Estimated {
        /// The N of the patterns.
        n: usize,
        /// Patterns averaged.
        realizations: usize,
        /// The lattice extent.
        kmax: usize,
        /// The radius of the disc over which a stationary, isotropic sampler's low band was
        /// fitted (`None`: every frequency read as measured).
        low_band: Option<f64>,
    },
    /// Each pattern's own transform on the lattice `|k_i| ≤ kmax`, and beyond it the residual
    /// of its error at `shifts` shifts each, over `patterns` patterns of `n` points.
    MeasuredTail {
        /// The N of the patterns.
        n: usize,
        /// Patterns averaged.
        patterns: usize,
        /// The lattice extent.
        kmax: usize,
        /// Shifts per pattern at which the residual beyond the lattice was measured.
        shifts: usize,
    },
}

impl fmt::Display for SpectrumOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SpectrumOrigin::Closed(c) => write!(f, "closed form ({})", c.name()),
            SpectrumOrigin::Cells(c) => c.fmt(f),
            SpectrumOrigin::Walsh(w) => w.fmt(f),
            SpectrumOrigin::WalshNet(w) => w.fmt(f),
            SpectrumOrigin::PermutedDigits(h) => h.fmt(f),
            SpectrumOrigin::PermutedLevel(h) => h.fmt(f),
            SpectrumOrigin::Pairs { sets } => write!(
                f,
                "each set's own periodogram, summed in space over its pairs ({sets} sets)"
            ),
            SpectrumOrigin::PatternPairs { n, patterns } => write!(
                f,
                "each of {patterns} patterns at N = {n} by its own periodogram, summed in space \
                 over its pairs"
            ),
            SpectrumOrigin::Estimated {
                n,
                realizations,
                kmax,
                low_band,
            } => {
                write!(
                    f,
                    "estimated at N = {n} ({realizations} realizations, |k_i| ≤ {kmax}"
                )?;
                if let Some(radius) = low_band {
                    write!(f, ", the low band fitted over |k| ≤ {radius:.1}")?;
                }
                f.write_str(")")
            }
            SpectrumOrigin::MeasuredTail {
                n,
                patterns,
                kmax,
                shifts,
            } => write!(
                f,
                "{patterns} patterns at N = {n} on |k_i| ≤ {kmax}, the tail measured at \
                 {shifts} shifts each"
            ),
        }
    }
}

/// The two forms of the variance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Form {
    /// The radial integral (isotropic integrands).
    Polar,
    /// The sum over the integer lattice (exact on the torus).
    Lattice,
    /// The sum over a sampler's cells in space (the unshifted estimator of strata and nets).
    Cells,
    /// The sum over Walsh frequencies (fixed patterns under a digital shift).
    Walsh,
    /// The sum over the pairs of frequencies a sampler's strata alias together (Gaussian
    /// jitter as drawn).
    #[serde(rename = "aliased_pairs")]
    AliasedPairs,
}

impl fmt::Display for Form {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Form::Polar => "polar form",
            Form::Lattice => "lattice form",
            Form::Cells => "cell form",
            Form::Walsh => "Walsh form",
            Form::AliasedPairs => "aliased-pair form",
        })
    }
}

/// A route of prediction: a form and a spectrum.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Route {
    /// The form.
    pub form: Form,
    /// The spectrum.
    pub spectrum: SpectrumOrigin,
}

impl fmt::Display for Route {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.spectrum {
            SpectrumOrigin::Cells(cells) => write!(f, "{}, {cells}", self.form),
            SpectrumOrigin::Walsh(walsh) => write!(f, "{}, {walsh}", self.form),
            SpectrumOrigin::WalshNet(net) => write!(f, "{}, {net}", self.form),
            SpectrumOrigin::PermutedDigits(h) => write!(f, "{}, {h}", self.form),
            SpectrumOrigin::PermutedLevel(h) => write!(f, "{}, {h}", self.form),
            _ => write!(f, "{}, spectrum {}", self.form, self.spectrum),
        }
    }
}

/// The uncertainty of a predicted variance, by source, each in units of the variance.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ErrorBudget {
    /// One standard error from the noise of an estimated spectrum (0 for closed forms).
    pub spectrum_noise: f64,
    /// The quadrature's error estimate (polar form), the rounding of an exact sum, or the
    /// spectrum engine's bound on what it adds to a lattice sum (fast engine).
    pub quadrature: f64,
    /// A bound on what the truncation of the sum or integral leaves out.
    pub truncation: f64,
    /// A systematic term from the route's model (e.g. the gap to another valid route).
    pub model: f64,
    /// For a grid that tabulates a finer function: a bound on the gap between the function's
    /// variance and the extrapolation from the grid and its coarser averages (0 for a grid
    /// declared exact and for every other integrand; see `docs/theory.md`, "Tabulated integrands").
    pub tabulation: f64,
}

impl ErrorBudget {
    /// The systematic bounds, added linearly: `quadrature + truncation + model + tabulation`.
    pub fn bounds(&self) -> f64 {
        self.quadrature + self.truncation + self.model + self.tabulation
    }

    /// The half-width of an interval around the prediction at `z` standard errors of the noise:
    /// `z · noise + quadrature + truncation + model + tabulation` (the bounds add linearly).
    pub fn half_width(&self, z: f64) -> f64 {
        z * self.spectrum_noise + self.bounds()
    }
}

/// Another route's value for the same problem, reported beside the chosen one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Alternative {
    /// The route.
    pub route: Route,
    /// Its variance.
    pub variance: f64,
    /// Its budget.
    pub budget: ErrorBudget,
}

/// A predicted variance of an estimator.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Prediction {
    /// `Var[μ_N]`.
    pub variance: f64,
    /// The estimator it is for: how the patterns are randomized.
    pub randomization: Randomization,
    /// The route that produced it.
    pub route: Route,
    /// Why this route (empty for a route called directly).
    pub reason: String,
    /// Its uncertainty.
    pub budget: ErrorBudget,
    /// Points per pattern.
    pub n: usize,
    /// Dimension.
    pub dimension: usize,
    /// The DC term `P̆_S(0⁺) I² / N` already subtracted (polar form; 0 for the lattice form).
    pub dc_term: f64,
    /// Integrand or spectrum evaluations spent.
    pub evaluations: u64,
    /// Other valid routes computed for comparison.
    pub alternatives: Vec<Alternative>,
    /// The analysis of the plan that produced it (`None` for a route called directly, and for
    /// predictions composed from others, such as padded pairs).
    pub analysis: Option<AnalysisKind>,
}

impl Prediction {
    /// Whether `value` lies within the budget's interval at `z` standard errors of the noise.
    pub fn covers(&self, value: f64, z: f64) -> bool {
        (value - self.variance).abs() <= self.budget.half_width(z)
    }

    /// This prediction as another route's value, to stand beside a chosen one.
    pub(crate) fn as_alternative(&self) -> Alternative {
        Alternative {
            route: self.route,
            variance: self.variance,
            budget: self.budget,
        }
    }

    /// The gap between this prediction and a Monte Carlo measurement beyond the prediction's
    /// bounds (quadrature, truncation, model), in units of their combined standard errors
    /// (the spectrum noise and the measurement's, read from its 99% interval): 0 when the
    /// bounds cover the gap, signed like `predicted - measured`.
    pub fn z_beyond_bounds(&self, measured: &crate::montecarlo::McResult) -> f64 {
        let mc_se = (measured.ci_high - measured.ci_low) / (2.0 * crate::montecarlo::Z_99);
        let b = &self.budget;
        let bounds = b.bounds();
        let diff = self.variance - measured.variance;
        let sigma = b.spectrum_noise.hypot(mc_se);
        (diff.abs() - bounds).max(0.0) / sigma * diff.signum()
    }
}

pub(crate) fn check_n(n: usize) -> Result<()> {
    if n == 0 {
        return Err(invalid("N", 0, "at least 1"));
    }
    Ok(())
}

/// The dimensions in which spectra, and so predictions, are computed.
pub const PREDICTION_DIMENSIONS: std::ops::RangeInclusive<usize> = 1..=3;

pub(crate) fn check_dimension(d: usize) -> Result<()> {
    if PREDICTION_DIMENSIONS.contains(&d) {
        Ok(())
    } else {
        Err(invalid(
            "dimension",
            d,
            "1 to 3 for spectra and predictions",
        ))
    }
}

/// The patterns of a problem: a sampler, or point sets of one's own.
#[derive(Clone, Copy)]
pub enum Patterns<'a> {
    /// Realizations of a sampler.
    Sampler(&'a dyn Sampler),
    /// Given point sets (e.g. read from a file), all of one N and dimension: the sampler is
    /// whatever produced them.
    PointSets(&'a [PointSet]),
}

/// What to predict: the variance of `integrand`'s estimator with `n` points from `patterns`,
/// randomized by `randomization`.
#[derive(Clone, Copy)]
pub struct Problem<'a> {
    /// The patterns.
    pub patterns: Patterns<'a>,
    /// The integrand.
    pub integrand: &'a dyn Integrand,
    /// Points per pattern.
    pub n: usize,
    /// How each pattern is randomized: by default a sampler's native randomization (how it is
    /// used in practice: strata and nets as drawn, fixed rules under a random shift), and the
    /// random toroidal shift for point sets and samplers of unknown law.
    pub randomization: Randomization,
    /// For given point sets: the cells in which their producer guarantees the points are
    /// independent and uniform once their cells are known ([`with_cells`](Self::with_cells));
    /// `None` otherwise (a sampler's own come from its facts).
    pub cells: Option<CellRule>,
}

impl<'a> Problem<'a> {
    /// A sampler's problem, under its native randomization
    /// ([`crate::sampler::native_randomization`]: the estimator it is used with in practice);
    /// [`with_randomization`](Self::with_randomization) chooses another.
    ///
    /// # Errors
    /// Mismatched dimensions, or an N the sampler cannot produce.
    pub fn new(sampler: &'a dyn Sampler, integrand: &'a dyn Integrand, n: usize) -> Result<Self> {
        check_dimensions(sampler.dimension(), integrand)?;
        sampler.check_count(n)?;
        Ok(Self {
            patterns: Patterns::Sampler(sampler),
            integrand,
            n,
            randomization: crate::sampler::sampler_native_randomization(sampler),
            cells: None,
        })
    }

    /// The problem of given point sets (all of one N and dimension), under a random toroidal
    /// shift: the one estimator the spectral routes predict for patterns of unknown law.
    ///
    /// # Errors
    /// No sets, sets of different sizes, or a dimension other than the integrand's.
    ///
    /// # Examples
    /// ```
    /// use specvar::prelude::*;
    /// // Point sets from anywhere (here a file's text), 8 realizations of 64 points.
    /// let text = specvar::io::write_text(
    ///     &(0..8).map(|r| Jitter::new(2)?.sample(64, 5, r)).collect::<Result<Vec<_>>>()?,
    /// );
    /// let sets = specvar::io::read_text(&text)?;
    /// let f = Gaussian::new(0.1, vec![0.5, 0.5], 1.0)?;
    /// let p = predict(&Problem::from_point_sets(&sets, &f)?, &PredictParams::default())?;
    /// assert_eq!(p.n, 64);
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn from_point_sets(sets: &'a [PointSet], integrand: &'a dyn Integrand) -> Result<Self> {
        let first = sets
            .first()
            .ok_or_else(|| invalid("point sets", 0, "at least one"))?;
        if sets
            .iter()
            .any(|s| s.len() != first.len() || s.dimension() != first.dimension())
        {
            return Err(Error::Mismatch(
                "all point sets must have the same dimension and number of points".into(),
            ));
        }
        check_dimensions(first.dimension(), integrand)?;
        Ok(Self {
            patterns: Patterns::PointSets(sets),
            integrand,
            n: first.len(),
            randomization: Randomization::Shift,
            cells: None,
        })
    }

    /// The same problem for the estimator randomized by `randomization`.
    ///
    /// # Examples
    /// ```
    /// use specvar::prelude::*;
    /// use specvar::randomization::Randomization;
    /// let f = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
    /// let poisson = PoissonDisk::new(2)?;
    /// // Toroidal dart throwing treats every position alike: unshifted, its estimator is the
    /// // shifted one.
    /// let problem = Problem::new(&poisson, &f, 64)?.with_randomization(Randomization::None);
    /// let params = PredictParams { target_noise: 0.1, ..PredictParams::default() };
    /// assert_eq!(predict(&problem, &params)?.randomization, Randomization::None);
    /// // Jitter's strata are not: as drawn (its native use) the cell form predicts it, and the
    /// // centred disk, symmetric about the strata, is luckier than under a shift.
    /// let jitter = Jitter::new(2)?;
    /// let drawn = predict(&Problem::new(&jitter, &f, 64)?, &params)?;
    /// assert_eq!(drawn.randomization, Randomization::None);
    /// assert_eq!(drawn.route.form, Form::Cells);
    /// let shifted = Problem::new(&jitter, &f, 64)?.with_randomization(Randomization::Shift);
    /// assert!(predict(&shifted, &params)?.variance > drawn.variance);
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn with_randomization(self, randomization: Randomization) -> Self {
        Self {
            randomization,
            ..self
        }
    }

    /// The same given point sets used as given, with the cells `rule` names: their producer
    /// guarantees that, once each point's cell is known, the points are independent and uniform
    /// in their cells (a renderer's jittered strata: `CellRule::Strata`; its multi-jittered or
    /// orthogonal-array points: `CellRule::Rows`; an Owen-scrambled base-2 net:
    /// `CellRule::Dyadic`). The cell form then predicts them as given, exactly for strata and
    /// from the sets' own occupancy otherwise. The occupancy is checked here; the uniformity
    /// inside the cells is the producer's word.
    ///
    /// # Errors
    /// A sampler's problem (its cells are its own), a rule without cells, or a set whose points
    /// do not occupy the cells as the rule says.
    ///
    /// # Examples
    /// ```
    /// use specvar::prelude::*;
    /// use specvar::sampler::CellRule;
    /// // A renderer's jittered 8 × 8 strata, 16 pixels' worth.
    /// let sets: Vec<PointSet> = (0..16).map(|r| Jitter::new(2)?.sample(64, 9, r)).collect::<Result<_>>()?;
    /// let f = Gaussian::new(0.2, vec![0.8, 0.3], 1.0)?;
    /// let p = predict(&Problem::from_point_sets(&sets, &f)?.with_cells(CellRule::Strata)?, &Default::default())?;
    /// let jitter = Jitter::new(2)?;
    /// let q = predict(&Problem::new(&jitter, &f, 64)?, &Default::default())?;
    /// assert_eq!((p.randomization, p.variance), (Randomization::None, q.variance));
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn with_cells(self, rule: CellRule) -> Result<Self> {
        let Patterns::PointSets(sets) = self.patterns else {
            return Err(invalid(
                "cells",
                rule,
                "given point sets only: a sampler's cells come from its facts",
            ));
        };
        let grid = rule.grid(self.n, self.dimension()).ok_or_else(|| {
            invalid(
                "cells",
                rule,
                format!(
                    "a rule with a grid of cells at N = {} in {}D",
                    self.n,
                    self.dimension()
                ),
            )
        })?;
        strata::cells::check_sets_occupy(sets, rule, &grid)?;
        Ok(Self {
            cells: Some(rule),
            randomization: Randomization::None,
            ..self
        })
    }

    /// The dimension.
    pub fn dimension(&self) -> usize {
        self.integrand.dimension()
    }

    /// Which of this crate's samplers draws the patterns, if one does (`None` for point sets
    /// and samplers of one's own).
    pub fn kind(&self) -> Option<crate::sampler::SamplerKind> {
        match self.patterns {
            Patterns::Sampler(s) => s.kind(),
            Patterns::PointSets(_) => None,
        }
    }
}

fn check_dimensions(d: usize, f: &dyn Integrand) -> Result<()> {
    check_dimension(f.dimension())?;
    if d != f.dimension() {
        return Err(Error::Mismatch(format!(
            "patterns of dimension {d} for an integrand of dimension {}",
            f.dimension()
        )));
    }
    Ok(())
}

/// Which form [`predict`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FormChoice {
    /// The lattice form (exact on the torus), with the polar form as an alternative where it is
    /// valid and cheap.
    #[default]
    Auto,
    /// The lattice form.
    Lattice,
    /// The polar form, where it is valid (an error otherwise).
    Polar,
    /// The cell form, where the estimator has one (an error otherwise): strata and nets as
    /// drawn, and under a shift the samplers with cells (multi-jitter, CMJ, orthogonal
    /// arrays and PMJ02 by each pattern's cells on the shifted integrand; Sobol' by Owen's
    /// gains), averaged over patterns and shifts.
    Cells,
}

/// Which spectrum [`predict`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SpectrumChoice {
    /// A closed form where the sampler has one at N, an estimate otherwise.
    #[default]
    Auto,
    /// A closed form (an error if there is none).
    Closed,
    /// Estimated from realizations.
    Estimated,
}

impl fmt::Display for FormChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FormChoice::Auto => "auto",
            FormChoice::Lattice => "lattice",
            FormChoice::Polar => "polar",
            FormChoice::Cells => "cells",
        })
    }
}

impl fmt::Display for SpectrumChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SpectrumChoice::Auto => "auto",
            SpectrumChoice::Closed => "closed",
            SpectrumChoice::Estimated => "estimated",
        })
    }
}

impl std::str::FromStr for FormChoice {
    type Err = Error;
    /// `auto`, `lattice`, `polar` or `cells`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "auto" => Ok(FormChoice::Auto),
            "lattice" => Ok(FormChoice::Lattice),
            "polar" => Ok(FormChoice::Polar),
            "cells" => Ok(FormChoice::Cells),
            other => Err(invalid("form", other, "auto, lattice, polar or cells")),
        }
    }
}

impl std::str::FromStr for SpectrumChoice {
    type Err = Error;
    /// `auto`, `closed` or `estimated`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "auto" => Ok(SpectrumChoice::Auto),
            "closed" => Ok(SpectrumChoice::Closed),
            "estimated" => Ok(SpectrumChoice::Estimated),
            other => Err(invalid("spectrum", other, "auto, closed or estimated")),
        }
    }
}

/// Parameters of [`predict`]. Every default is the library's choice; override what you need.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictParams {
    /// The form.
    pub form: FormChoice,
    /// The spectrum.
    pub spectrum: SpectrumChoice,
    /// The polar form's reference N for an estimated spectrum (`None`: N itself, at least
    /// [`default_reference_n`]).
    pub reference_n: Option<usize>,
    /// Realizations of an estimated spectrum (`None`: start at 32 and add while the relative
    /// noise exceeds `target_noise` and the work budget allows).
    pub realizations: Option<usize>,
    /// The relative standard error an estimated prediction aims at.
    pub target_noise: f64,
    /// The work an estimated prediction may spend, in seconds of one core (from the samplers'
    /// measured generation costs): it bounds the realizations. The default,
    /// [`DEFAULT_ESTIMATE_SECONDS`], answers within 10 s on two cores.
    pub work_budget_seconds: f64,
    /// Seed of the realizations.
    pub seed: u64,
    /// The lattice extent (`None`: chosen from N and the integrand, then widened while the tail
    /// bound exceeds 0.1% of the variance for closed forms, 1% for estimates).
    pub kmax: Option<usize>,
    /// The polar form's quadrature.
    pub polar: PolarParams,
    /// The hard limit on memory and work (checked before the work starts).
    pub budget: crate::budget::Budget,
}

/// The default work of an estimated prediction, in seconds of one core: 16, so that on two
/// cores it answers within 10 s with room for what the estimate does not count (the exact
/// parts of a route, tables of cells, the estimate's own error of up to a fifth).
pub const DEFAULT_ESTIMATE_SECONDS: f64 = 16.0;

impl Default for PredictParams {
    fn default() -> Self {
        Self {
            form: FormChoice::Auto,
            spectrum: SpectrumChoice::Auto,
            reference_n: None,
            realizations: None,
            target_noise: 0.02,
            work_budget_seconds: DEFAULT_ESTIMATE_SECONDS,
            seed: 0,
            kmax: None,
            polar: PolarParams::default(),
            budget: crate::budget::Budget::default(),
        }
    }
}

/// Predicts the variance of the homogenized estimator, choosing a valid route (see the module
/// notes, and [`predict_with`], which also reports progress).
///
/// # Errors
/// As [`predict_with`].
///
/// # Examples
/// ```
/// use specvar::integrand::Ball;
/// use specvar::predict::{predict, PredictParams, Problem};
/// use specvar::sampler::Jitter;
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
/// let jitter = Jitter::new(2)?;
/// let p = predict(&Problem::new(&jitter, &disk, 256)?, &PredictParams::default())?;
/// println!("{:.4e} by the {} ({})", p.variance, p.route, p.reason);
/// // Jitter is used as drawn: the per-stratum form, exact, with no noise and no tail.
/// assert!(p.variance > 0.0 && p.budget.spectrum_noise == 0.0);
/// assert!(p.budget.truncation == 0.0);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn predict(problem: &Problem<'_>, params: &PredictParams) -> Result<Prediction> {
    predict_with(problem, params, &Silent)
}

/// Whether `problem`'s estimator has a prediction route at all (before any work): `Ok` where
/// one applies, else the error [`predict`] would return, which says why and what to do instead
/// (Halton's permuted digits used as drawn, for one, have no route; Monte Carlo measures them).
///
/// # Errors
/// The estimator's [`Error::OutsideValidity`].
pub fn check_route(problem: &Problem<'_>) -> Result<()> {
    route::check_estimator(problem)
}

/// The plan of `problem`'s prediction, made before any work: the analysis that answers it, why,
/// and what it needs, checked against `params.budget` ([`predict_with`] runs the same plan).
///
/// # Errors
/// The error [`predict`] would return before any work: no analysis for this estimator, a choice
/// outside every applicable analysis's validity, or needs above the budget.
///
/// # Examples
/// ```
/// use specvar::prelude::*;
/// use specvar::predict::{plan_analysis, AnalysisKind};
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
/// let jitter = Jitter::new(2)?;
/// let problem = Problem::new(&jitter, &disk, 256)?;
/// let plan = plan_analysis(&problem, &PredictParams::default())?;
/// assert_eq!(plan.analysis, AnalysisKind::FixedStrata);
/// let p = predict(&problem, &PredictParams::default())?;
/// assert_eq!(p.analysis, Some(plan.analysis));
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn plan_analysis(problem: &Problem<'_>, params: &PredictParams) -> Result<AnalysisPlan> {
    check_params(params)?;
    plan_levels(problem, params).map(|(_, plan, _)| plan)
}

/// The analysis of `problem` and its plan, and for a tabulated grid its coarser levels with
/// the analysis of each, whose needs the plan's include and whose sum is checked against the
/// budget.
fn plan_levels(
    problem: &Problem<'_>,
    params: &PredictParams,
) -> Result<(
    &'static dyn analysis::Analysis,
    AnalysisPlan,
    Option<PlannedLevels>,
)> {
    let (row, mut plan) = table::choose(problem, params)?;
    let Some(levels) = tabulation::levels(problem)? else {
        return Ok((row, plan, None));
    };
    let mut rows = Vec::with_capacity(2);
    for grid in &levels.coarser {
        let (row, coarse) = table::choose(&tabulation::on(problem, grid), params)?;
        // The levels run one after another: their work adds, their memory does not.
        plan.needs.seconds += coarse.needs.seconds;
        plan.needs.bytes = plan.needs.bytes.max(coarse.needs.bytes);
        rows.push(row);
    }
    params.budget.check(
        &format!(
            "the {} analysis at N = {} on the grid and its two coarser averages",
            plan.analysis, problem.n
        ),
        crate::budget::Needs {
            memory_bytes: plan.needs.bytes,
            work_seconds: plan.needs.seconds,
        },
        "lower N",
    )?;
    Ok((row, plan, Some(PlannedLevels { levels, rows })))
}

/// A tabulated grid's coarser levels and the analysis that answers each.
struct PlannedLevels {
    levels: tabulation::Levels,
    rows: Vec<&'static dyn analysis::Analysis>,
}

/// Refuses an estimator whose mean squared error is not its variance: Gaussian jitter used as
/// drawn is biased (its points' density ripples at the grid's period;
/// [`gaussian_jitter_bias`]), so a plan or an image's MSE, which read the variance as the
/// squared error, would leave the bias out. Other estimators with a route are unbiased.
///
/// # Errors
/// [`Error::OutsideValidity`] for Gaussian jitter used as drawn.
///
/// # Examples
/// ```
/// use specvar::predict::check_unbiased;
/// use specvar::randomization::Randomization;
/// use specvar::sampler::SamplerKind;
/// assert!(check_unbiased(SamplerKind::GaussianJitter, Randomization::None).is_err());
/// assert!(check_unbiased(SamplerKind::GaussianJitter, Randomization::Shift).is_ok());
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn check_unbiased(kind: SamplerKind, randomization: Randomization) -> Result<()> {
    // The one sampler whose points' density is not uniform as drawn: no other fact sets it
    // apart (its randomness is stratified, as jitter's, and its closed form is of its width).
    if kind == SamplerKind::GaussianJitter && randomization == Randomization::None {
        return Err(Error::OutsideValidity {
            route: "a squared error from the variance".into(),
            reason: "gjitter used as drawn is biased (`specvar predict` states its bias), so its \
                     mean squared error is the variance plus the bias squared; plan or render it \
                     with --randomization shift"
                .into(),
        });
    }
    Ok(())
}

/// Predicts the variance of the homogenized estimator, reporting the spectrum estimate's
/// progress to `progress`.
///
/// # Errors
/// A closed form asked for a sampler without one; a route asked for outside its validity
/// domain ([`Error::OutsideValidity`]); bad parameters; a sampler error; a result that is not
/// finite.
pub fn predict_with(
    problem: &Problem<'_>,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    check_params(params)?;
    predict_planned(problem, params, progress)
        .and_then(finite_prediction)
        .map(|p| for_estimator(p, problem))
}

/// The planned analysis's prediction for `problem`, labelled with the analysis.
fn predict_planned(
    problem: &Problem<'_>,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let (row, plan, levels) = plan_levels(problem, params)?;
    let fine = row.predict(problem, params, progress)?;
    let Some(PlannedLevels { levels, rows }) = levels else {
        return Ok(planned(fine, &plan));
    };
    let mut coarser = Vec::with_capacity(2);
    for (grid, row) in levels.coarser.iter().zip(rows) {
        coarser.push(row.predict(&tabulation::on(problem, grid), params, progress)?);
    }
    let coarser: [Prediction; 2] = coarser
        .try_into()
        .map_err(|_| Error::Mismatch("a tabulated grid's levels left unpredicted".into()))?;
    tabulation::extrapolate(fine, coarser, &levels).map(|p| planned(p, &plan))
}

/// `p` labelled with the analysis of `plan`.
fn planned(p: Prediction, plan: &AnalysisPlan) -> Prediction {
    Prediction {
        analysis: Some(plan.analysis),
        ..p
    }
}

/// `p`, which a route computed for the shifted estimator or for the law as drawn, labelled with
/// the estimator of `problem` it predicts ([`route::check_estimator`] admitted only
/// randomizations with the same variance), its reason saying why the two agree.
fn for_estimator(p: Prediction, problem: &Problem<'_>) -> Prediction {
    let randomization = problem.randomization;
    let agreement = match randomization {
        Randomization::Shift => None,
        _ if route::scrambling_absorbs_shift(problem) => Some((
            "the law as drawn",
            "a digital shift of an Owen-scrambled net is again nested uniform scrambling, and \
             leaves PMJ02's law, which no fixed flip of digits changes, as it is",
        )),
        _ => problem
            .kind()
            .and_then(|k| k.facts().randomness.why_shifted_variance(randomization))
            .map(|why| ("the variance is the shifted one's", why)),
    };
    let reason = match agreement {
        Some((what, why)) => format!(
            "{}; under randomization {randomization} {what}: {why}",
            p.reason
        ),
        None => p.reason,
    };
    Prediction {
        randomization,
        reason,
        ..p
    }
}

/// Predicts several integrands on the same patterns (one sampler and N, or the same point
/// sets): each prediction is what [`predict_with`] gives by the same route, but integrands on
/// the per-pattern lattice form share one spectrum estimate per lattice size, their weighted
/// sums accumulated on the same patterns, until every one reaches the target noise. The cost
/// is about that of the most demanding integrand instead of the sum over all.
///
/// # Errors
/// As [`predict_with`], or problems that do not share their patterns.
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Gaussian, Integrand};
/// use specvar::predict::{predict_many, PredictParams, Problem};
/// use specvar::progress::Silent;
/// use specvar::sampler::PoissonDisk;
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
/// let bump = Gaussian::new(0.1, vec![0.5, 0.5], 1.0)?;
/// let poisson = PoissonDisk::new(2)?;
/// let problems = [Problem::new(&poisson, &disk, 64)?, Problem::new(&poisson, &bump, 64)?];
/// let params = PredictParams { target_noise: 0.1, ..PredictParams::default() };
/// let both = predict_many(&problems, &params, &Silent)?;
/// assert_eq!(both.len(), 2);
/// assert!(both.iter().all(|p| p.variance > 0.0));
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn predict_many(
    problems: &[Problem<'_>],
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Vec<Prediction>> {
    check_params(params)?;
    // Tabulated grids' coarser levels are predicted on the same patterns as the grids.
    let levels = problems
        .iter()
        .map(tabulation::levels)
        .collect::<Result<Vec<_>>>()?;
    let mut all = problems.to_vec();
    for (problem, levels) in problems.iter().zip(&levels) {
        for grid in levels.iter().flat_map(|l| &l.coarser) {
            all.push(tabulation::on(problem, grid));
        }
    }
    let mut predictions = table::predict_planned_many(&all, params, progress)?.into_iter();
    let fine: Vec<Prediction> = predictions.by_ref().take(problems.len()).collect();
    let mut combined = Vec::with_capacity(problems.len());
    for (p, levels) in fine.into_iter().zip(&levels) {
        combined.push(match levels {
            None => p,
            Some(levels) => {
                let mut coarser = predictions.by_ref().take(2);
                let (Some(a), Some(b)) = (coarser.next(), coarser.next()) else {
                    return Err(Error::Mismatch(
                        "a tabulated grid's levels left unpredicted".into(),
                    ));
                };
                tabulation::extrapolate(p, [a, b], levels)?
            }
        });
    }
    combined
        .into_iter()
        .zip(problems)
        .map(|(p, problem)| finite_prediction(p).map(|p| for_estimator(p, problem)))
        .collect()
}

fn check_params(params: &PredictParams) -> Result<()> {
    if !(params.target_noise > 0.0 && params.target_noise.is_finite()) {
        return Err(invalid(
            "target noise",
            params.target_noise,
            "a positive number",
        ));
    }
    if !(params.work_budget_seconds > 0.0 && params.work_budget_seconds.is_finite()) {
        return Err(invalid(
            "work budget",
            params.work_budget_seconds,
            "a positive number of seconds",
        ));
    }
    if params.realizations.is_some_and(|m| m < 2) {
        return Err(invalid(
            "realizations",
            params.realizations.unwrap_or(0),
            "at least 2, so that the spectrum's noise can be estimated",
        ));
    }
    if let Some(kmax) = params.kmax {
        crate::spectrum::check_kmax(kmax)?;
    }
    Ok(())
}

/// `p` if its variance and budget are finite numbers; otherwise an error that says so.
fn finite_prediction(p: Prediction) -> Result<Prediction> {
    let b = &p.budget;
    for (what, v) in [
        ("variance", p.variance),
        ("spectrum noise", b.spectrum_noise),
        ("quadrature error", b.quadrature),
        ("truncation bound", b.truncation),
        ("model term", b.model),
        ("tabulation term", b.tabulation),
    ] {
        finite(v, || format!("the {what} of the {} is {v}", p.route))?;
    }
    Ok(p)
}

/// A grid of strata in words: `16 × 8`.
pub(crate) fn grid_label(strata: &[usize]) -> String {
    strata
        .iter()
        .map(|s| s.to_string())
        .collect::<Vec<_>>()
        .join(" × ")
}

//! Padded dimensions: a 4D integrand under two 2D patterns paired by a random permutation.
//!
//! A renderer's pixel integrand is 4D or more (film × light × …), and renderers sample it with
//! 2D patterns *padded* together: sample `j` takes point `a_j` of one pattern for the first two
//! dimensions and `b_{π(j)}` of an independent one for the last two, `π` a uniformly random
//! permutation. Write `f(u, v) = I + g_A(u) + g_B(v) + h(u, v)` (the ANOVA decomposition:
//! `g_A(u) = ∫ f(u, v) dv − I`, `g_B` likewise, `h` the interaction, whose integral over `u` or
//! over `v` alone is zero). For unbiased patterns the cross terms vanish and
//!
//! `Var = V_A[g_A] + V_B[g_B] + E[((1/N) Σ_j h(a_j, b_{π(j)}))²]`,
//!
//! the first two the 2D estimators' own variances (each on its default route, with its
//! budget). The permutation makes the interaction almost white: averaging over `π` (the
//! variance of a random permutation's diagonal mean) gives exactly
//!
//! `E[H²] = (‖h‖² − E_u V_B[h(u, ·)] − E_v V_A[h(·, v)]) / (N − 1) + N / (N − 1) · V_{A×B}[h]`,
//!
//! with `V_B[h(u, ·)]` the second pattern's variance on the slice at `u` and `V_{A×B}[h]` the
//! product pattern's (all `N²` pairs) on `h`. For independent random points each `V` is the
//! function's energy over N and `E[H²] = ‖h‖²/N`; for strata and nets the slices' variances
//! fall faster than `1/N` and `E[H²] → ‖h‖²/(N − 1)`, a touch above white. Under random shifts
//! the same term reads `‖h‖²/N + Σ_{k,q≠0} |ĥ(k, q)|² (1 − P_A(k)) (1 − P_B(q)) / (N (N − 1))`
//! with `P` the patterns' power spectra (`docs/theory.md`, "Padded dimensions"). So the padded
//! variance converges like `‖h‖²/N` once the 2D parts have fallen below it: padding keeps each
//! pair's stratification, not the joint one.
//!
//! `‖h‖²` is exact for a tabulated integrand; the three small corrections (order `1/N` of the
//! interaction term) are averaged over pairs of patterns drawn as the estimator draws them,
//! each pair costing one pass over the 4D grid, and their standard error enters the budget.

use crate::budget::{Budget, Needs};
use crate::error::{invalid, Error, Result};
use crate::integrand::{GridIntegrand, GridMeaning};
use crate::montecarlo::{result_from_estimates, trial_pattern, McParams, McResult, MIN_UNITS};
use crate::npy::{read_npy, NpyArray};
use crate::pixels::mean_of;
use crate::plan::{plan_by, reached, resolve, Plan, PlanParams};
use crate::pointset::PointSet;
use crate::predict::{
    plan_analysis, predict_with, ErrorBudget, PredictParams, Prediction, Problem,
};
use crate::progress::Progress;
use crate::randomization::{Randomization, RandomizationChoice};
use crate::rng::{realization_rng, splitmix64, Stream};
use crate::sampler::{sampler_native_randomization, CountRule, Sampler, SamplerKind};
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

/// Pattern pairs over which the interaction's corrections are averaged.
pub const CORRECTION_PAIRS: usize = 64;
/// The largest number of cells of a padded grid (8 bytes each): 2^24, 128 MiB.
pub const MAX_PADDED_CELLS: usize = 1 << 24;
/// Mixed into the seed of the second pattern, so that the two patterns of one trial are
/// independent even when they come from the same sampler.
const SECOND_PATTERN_SEED: u64 = 0x5EC0_4D2A_11A5_B0B5;

/// A piecewise-constant function on `[0,1)⁴`: `values[ay, ax, by, bx]` in C order, the first
/// pair of coordinates `u = (ux, uy)` on an `ah × aw` grid (the first pattern's), the second
/// `v = (vx, vy)` on a `bh × bw` grid (the second's), each pair's cell `(x, y)` covering
/// `[x/w, (x+1)/w) × [y/h, (y+1)/h)` as for a 2D grid.
#[derive(Debug, Clone, PartialEq)]
pub struct PaddedGrid {
    /// `[ah, aw, bh, bw]`.
    shape: [usize; 4],
    values: Vec<f64>,
    /// What the cells are.
    meaning: GridMeaning,
}

impl PaddedGrid {
    /// The function with cell values `values[ay, ax, by, bx]` on a grid of `shape`
    /// `[ah, aw, bh, bw]`.
    ///
    /// # Errors
    /// A zero side, more than [`MAX_PADDED_CELLS`] cells, a value count other than the
    /// shape's, or a value that is not finite.
    ///
    /// # Examples
    /// ```
    /// use specvar::padded::PaddedGrid;
    /// // f(u, v) = [u_x < 1/2] · [v_x < 1/2] on 2 × 2 × 2 × 2 cells.
    /// let values = (0..16).map(|i| ((i & 1 == 0) && (i & 4 == 0)) as u8 as f64).collect();
    /// let f = PaddedGrid::new([2, 2, 2, 2], values)?;
    /// assert_eq!(f.integral(), 0.25);
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn new(shape: [usize; 4], values: Vec<f64>) -> Result<Self> {
        let cells = shape
            .iter()
            .try_fold(1usize, |c, &s| c.checked_mul(s))
            .filter(|&c| c <= MAX_PADDED_CELLS);
        let Some(cells) = cells.filter(|_| shape.iter().all(|&s| s > 0)) else {
            return Err(invalid(
                "padded grid shape",
                format!("{shape:?}"),
                format!("four positive sides with at most {MAX_PADDED_CELLS} cells"),
            ));
        };
        if values.len() != cells {
            return Err(invalid(
                "padded grid values",
                values.len(),
                format!("{cells}, the cells of shape {shape:?}"),
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(invalid(
                "padded grid value",
                format!("{} (cell {i})", values[i]),
                "a finite number",
            ));
        }
        Ok(Self {
            shape,
            values,
            meaning: GridMeaning::CellAverages,
        })
    }

    /// The same grid with another meaning: what its cells are
    /// ([`GridMeaning`]: a finer function's cell averages by default). Its marginals, which the
    /// two patterns integrate, are grids of the same meaning.
    pub fn with_meaning(self, meaning: GridMeaning) -> Self {
        Self { meaning, ..self }
    }

    /// A grid from a rank-4 array `(ah, aw, bh, bw)` (as `numpy.save` writes it).
    ///
    /// # Errors
    /// Another rank, and as [`new`](Self::new).
    pub fn from_array(array: NpyArray) -> Result<Self> {
        match *array.shape.as_slice() {
            [ah, aw, bh, bw] => Self::new([ah, aw, bh, bw], array.values),
            _ => Err(Error::format(
                "padded grid",
                format!(
                    "shape {:?}: rank 4, (first height, first width, second height, second width)",
                    array.shape
                ),
            )),
        }
    }

    /// Reads a grid from a `.npy` file ([`from_array`](Self::from_array)).
    ///
    /// # Errors
    /// An unreadable or malformed file, and as [`from_array`](Self::from_array).
    pub fn read(path: &Path) -> Result<Self> {
        Self::from_array(read_npy(&crate::io::read_bounded(path)?)?)
    }

    /// `[ah, aw, bh, bw]`.
    pub fn shape(&self) -> [usize; 4] {
        self.shape
    }

    fn first_cells(&self) -> usize {
        self.shape[0] * self.shape[1]
    }

    fn second_cells(&self) -> usize {
        self.shape[2] * self.shape[3]
    }

    /// `∫ f`.
    pub fn integral(&self) -> f64 {
        self.values.iter().sum::<f64>() / self.values.len() as f64
    }

    /// `∫ f(u, v) dv`, a function of the first pair: the part the first pattern integrates.
    ///
    /// # Errors
    /// None in practice (the grid's values are finite).
    pub fn first_marginal(&self) -> Result<GridIntegrand> {
        let nb = self.second_cells();
        let values = self
            .values
            .chunks_exact(nb)
            .map(|row| row.iter().sum::<f64>() / nb as f64)
            .collect();
        Ok(GridIntegrand::new(self.shape[1], self.shape[0], values)?.with_meaning(self.meaning))
    }

    /// `∫ f(u, v) du`, a function of the second pair.
    ///
    /// # Errors
    /// None in practice (the grid's values are finite).
    pub fn second_marginal(&self) -> Result<GridIntegrand> {
        let (na, nb) = (self.first_cells(), self.second_cells());
        let mut values = vec![0.0; nb];
        for row in self.values.chunks_exact(nb) {
            for (s, v) in values.iter_mut().zip(row) {
                *s += v;
            }
        }
        values.iter_mut().for_each(|s| *s /= na as f64);
        Ok(GridIntegrand::new(self.shape[3], self.shape[2], values)?.with_meaning(self.meaning))
    }

    /// The interaction `h = f − I − g_A − g_B` on the cells, in the grid's order.
    fn interaction(&self, first: &GridIntegrand, second: &GridIntegrand) -> Vec<f64> {
        let nb = self.second_cells();
        let mean = self.integral();
        self.values
            .chunks_exact(nb)
            .zip(first.values())
            .flat_map(|(row, ga)| {
                row.iter()
                    .zip(second.values())
                    .map(move |(f, gb)| f - ga - gb + mean)
            })
            .collect()
    }

    /// The value at `(u, v)`.
    pub fn eval(&self, u: &[f64], v: &[f64]) -> f64 {
        let (a, b) = (self.first_cell(u), self.second_cell(v));
        self.values[a * self.second_cells() + b]
    }

    fn first_cell(&self, u: &[f64]) -> usize {
        cell(u, self.shape[1], self.shape[0])
    }

    fn second_cell(&self, v: &[f64]) -> usize {
        cell(v, self.shape[3], self.shape[2])
    }
}

/// The cell of `p` on a `w × h` grid of the unit square, row by row from `y = 0`.
fn cell(p: &[f64], w: usize, h: usize) -> usize {
    let x = ((p[0] * w as f64) as usize).min(w - 1);
    let y = ((p[1] * h as f64) as usize).min(h - 1);
    y * w + x
}

/// The two 2D samplers of a padded estimator and how each randomizes its patterns.
#[derive(Clone, Copy)]
pub struct PaddedSamplers<'a> {
    /// The first pair's sampler (e.g. the film's).
    pub first: &'a dyn Sampler,
    /// The second pair's sampler (e.g. the light's).
    pub second: &'a dyn Sampler,
    /// Their randomizations.
    pub randomizations: (Randomization, Randomization),
}

impl<'a> PaddedSamplers<'a> {
    /// Two samplers, each randomized as `choice` says (by default its native randomization).
    ///
    /// # Errors
    /// A sampler that is not 2D, or a fixed pattern used without a randomization.
    pub fn new(
        first: &'a dyn Sampler,
        second: &'a dyn Sampler,
        choice: RandomizationChoice,
    ) -> Result<Self> {
        let resolve = |s: &dyn Sampler| choice.resolve(sampler_native_randomization(s));
        let samplers = Self {
            first,
            second,
            randomizations: (resolve(first), resolve(second)),
        };
        samplers.check()?;
        Ok(samplers)
    }

    /// Two samplers, each under its native randomization.
    ///
    /// # Errors
    /// As [`new`](Self::new).
    pub fn native(first: &'a dyn Sampler, second: &'a dyn Sampler) -> Result<Self> {
        Self::new(first, second, RandomizationChoice::Native)
    }

    /// Checks that both are 2D and unbiased under their randomizations (the padded identity
    /// needs every point of each pattern to integrate without bias once permuted).
    ///
    /// # Errors
    /// A sampler that is not 2D, or a fixed pattern used without a randomization.
    pub fn check(&self) -> Result<()> {
        for (s, r) in [
            (self.first, self.randomizations.0),
            (self.second, self.randomizations.1),
        ] {
            if s.dimension() != 2 {
                return Err(invalid(
                    "padded sampler dimension",
                    s.dimension(),
                    "2 (each pattern samples one pair of dimensions)",
                ));
            }
            let fixed = s.kind().is_some_and(|k| k.is_deterministic());
            if fixed && r == Randomization::None {
                return Err(invalid(
                    "padded randomization",
                    format!("none for {}", s.name()),
                    "shift or digital-shift: a fixed pattern as given is biased, and the padded \
                     variance is that of unbiased patterns",
                ));
            }
        }
        Ok(())
    }

    /// What `trials` pattern pairs of `n` points need on `f`: both patterns drawn (a sampler of
    /// one's own at a microsecond a point), one pass over the pair's cells or points each, the
    /// memory of one pair per thread.
    fn needs(&self, f: &PaddedGrid, n: usize, trials: usize) -> Needs {
        let pattern = |s: &dyn Sampler| {
            s.kind().map_or(
                Needs {
                    memory_bytes: 16.0 * n as f64,
                    work_seconds: 1e-6 * n as f64,
                },
                |k| k.pattern_needs(n, 2),
            )
        };
        let pair = pattern(self.first).and(pattern(self.second));
        // One pass over the 4D grid, or over the points with their permutation.
        let pass = (f.first_cells() as f64 * f.second_cells() as f64).max(n as f64);
        let one = Needs {
            memory_bytes: 2.0 * pair.memory_bytes + 8.0 * n as f64,
            work_seconds: pair.work_seconds + pass * crate::costs::PASS_SECONDS,
        };
        Needs {
            memory_bytes: one.memory_bytes * rayon::current_num_threads() as f64,
            work_seconds: one.work_seconds * trials as f64,
        }
    }

    /// The two patterns of trial `t` of `seed`, randomized.
    fn patterns(&self, n: usize, seed: u64, t: usize) -> Result<(PointSet, PointSet)> {
        let params = |seed, randomization| McParams {
            patterns: 1,
            shifts: 1,
            seed,
            randomization,
            budget: Default::default(),
        };
        let second_seed = splitmix64(seed ^ SECOND_PATTERN_SEED);
        Ok((
            trial_pattern(self.first, n, &params(seed, self.randomizations.0), t)?,
            trial_pattern(
                self.second,
                n,
                &params(second_seed, self.randomizations.1),
                t,
            )?,
        ))
    }
}

/// The predicted variance of a padded estimator, term by term.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PaddedPrediction {
    /// `Var[μ_N]`: the sum of the three terms below.
    pub variance: f64,
    /// Samples (points of each pattern).
    pub n: usize,
    /// `V_A[g_A]`: the first pattern on the first pair's marginal.
    pub first: Prediction,
    /// `V_B[g_B]`: the second pattern on the second pair's marginal.
    pub second: Prediction,
    /// `‖h‖²`, the interaction's energy (exact).
    pub interaction_energy: f64,
    /// `E[H²]`, the interaction's term.
    pub interaction: f64,
    /// `‖h‖² / N`: the interaction's term if it were integrated by independent points.
    pub interaction_white: f64,
    /// The corrections' standard error (pattern pairs averaged: [`CORRECTION_PAIRS`]).
    pub interaction_noise: f64,
    /// The whole prediction's budget: the 2D terms' and the corrections' noise, the 2D
    /// terms' bounds.
    pub budget: ErrorBudget,
}

impl PaddedPrediction {
    /// The prediction as one [`Prediction`]: the whole variance and budget, the first pair's
    /// route and randomization (the reason names both pairs' routes).
    pub fn as_prediction(&self) -> Prediction {
        Prediction {
            variance: self.variance,
            reason: format!(
                "padded pairs: the first by the {}, the second by the {}, the interaction by \
                 the permutation identity",
                self.first.route, self.second.route
            ),
            budget: self.budget,
            alternatives: Vec::new(),
            analysis: None,
            evaluations: self.first.evaluations + self.second.evaluations,
            ..self.first.clone()
        }
    }
}

/// Plans the samples per pixel of a padded estimator: the smallest count, among the balanced
/// counts of the sparser of the two samplers' ladders (powers of two where either is a net),
/// whose predicted RMSE on `f` reaches the target (a relative target is relative to `∫ f`).
/// The samplers keep their own randomizations (`params.randomization` is not used).
///
/// # Errors
/// As [`predict_padded`] and [`crate::plan::plan`]; a count of the ladder that the other
/// sampler cannot produce.
pub fn plan_padded(
    f: &PaddedGrid,
    samplers: PaddedSamplers,
    params: &PlanParams,
    progress: &dyn Progress,
) -> Result<Plan> {
    samplers.check()?;
    let kind = ladder_kind(samplers, params)?;
    reached(plan_by((kind, 2), f.integral(), params, |n| {
        samplers.first.check_count(n)?;
        samplers.second.check_count(n)?;
        predict_padded(f, samplers, n, &params.predict, progress).map(|p| p.as_prediction())
    })?)
}

/// Plans the samples per pixel of an image of padded pixels: the smallest balanced count (as
/// [`plan_padded`] chooses them) whose image RMSE, the root of the mean of the pixels'
/// predicted variances, reaches the target (a relative target is relative to the image's mean
/// value).
///
/// # Errors
/// No pixels, and as [`plan_padded`].
pub fn plan_padded_pixels(
    pixels: &[PaddedGrid],
    samplers: PaddedSamplers,
    params: &PlanParams,
    progress: &dyn Progress,
) -> Result<Plan> {
    samplers.check()?;
    if pixels.is_empty() {
        return Err(invalid("padded pixels", 0, "at least one pixel"));
    }
    let mean = pixels.iter().map(|f| f.integral()).sum::<f64>() / pixels.len() as f64;
    let kind = ladder_kind(samplers, params)?;
    reached(plan_by((kind, 2), mean, params, |n| {
        samplers.first.check_count(n)?;
        samplers.second.check_count(n)?;
        let predictions = pixels
            .iter()
            .map(|f| predict_padded(f, samplers, n, &params.predict, progress))
            .collect::<Result<Vec<_>>>()?;
        let each: Vec<Prediction> = predictions.iter().map(|p| p.as_prediction()).collect();
        let (variance, budget) = mean_of(&each.iter().collect::<Vec<_>>());
        let image = Prediction {
            variance,
            budget,
            ..each[0].clone()
        };
        Ok(image)
    })?)
}

/// The sampler whose balanced counts a padded plan steps along: the sparser ladder (powers of
/// two where either sampler is a net).
fn ladder_kind(samplers: PaddedSamplers, params: &PlanParams) -> Result<SamplerKind> {
    let (first, _) = resolve(samplers.first, params)?;
    let (second, _) = resolve(samplers.second, params)?;
    let sparse = |k: SamplerKind| k.facts().balanced_counts == CountRule::PowerOfTwo;
    Ok(if sparse(second) && !sparse(first) {
        second
    } else {
        first
    })
}

/// Predicts the variance of `f` integrated by `n` padded samples of `samplers` (see the module
/// notes): the two 2D terms on their default routes, the interaction exactly up to corrections
/// of order `1/N` averaged over [`CORRECTION_PAIRS`] pattern pairs of `params.seed`.
///
/// # Errors
/// A sampler that is not 2D, a fixed pattern without a randomization, an N a sampler cannot
/// produce or below 2, and the 2D predictions' own errors.
///
/// # Examples
/// ```
/// use specvar::integrand::GridMeaning;
/// use specvar::padded::{predict_padded, PaddedGrid, PaddedSamplers};
/// use specvar::predict::PredictParams;
/// use specvar::progress::Silent;
/// use specvar::sampler::Jitter;
/// // A film coordinate that moves a shadow edge across the light: f = [v_x < u_x].
/// let m = 8;
/// let values = (0..m * m * m * m)
///     .map(|i| (((i % m) as f64) < ((i / (m * m)) % m) as f64) as u8 as f64)
///     .collect();
/// // The grid is the function here (a tabulation's marginals would need finer cells at N = 64).
/// let f = PaddedGrid::new([m, m, m, m], values)?.with_meaning(GridMeaning::Exact);
/// let jitter = Jitter::new(2)?;
/// let p = predict_padded(&f, PaddedSamplers::native(&jitter, &jitter)?, 64, &PredictParams::default(), &Silent)?;
/// // The interaction dominates: near white, not stratified.
/// assert!(p.interaction > 0.5 * p.variance);
/// assert!((p.interaction / p.interaction_white - 1.0).abs() < 0.1);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn predict_padded(
    f: &PaddedGrid,
    samplers: PaddedSamplers,
    n: usize,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<PaddedPrediction> {
    samplers.check()?;
    if n < 2 {
        return Err(invalid("N", n, "at least 2 for a padded estimator"));
    }
    let (ga, gb) = (f.first_marginal()?, f.second_marginal()?);
    // The two 2D predictions' plans and the corrections' pattern pairs, against the budget
    // before any of them is computed.
    let plan = |s: &dyn Sampler, g: &GridIntegrand, r: Randomization| {
        plan_analysis(&Problem::new(s, g, n)?.with_randomization(r), params)
    };
    let plans = [
        plan(samplers.first, &ga, samplers.randomizations.0)?,
        plan(samplers.second, &gb, samplers.randomizations.1)?,
    ];
    let two_d = plans.iter().fold(Needs::default(), |all, p| {
        all.and(Needs {
            memory_bytes: p.needs.bytes,
            work_seconds: p.needs.seconds,
        })
    });
    params.budget.check(
        &format!("the padded prediction at N = {n}"),
        two_d.and(samplers.needs(f, n, CORRECTION_PAIRS)),
        "lower N",
    )?;
    let predict_2d = |s: &dyn Sampler, g: &GridIntegrand, r: Randomization| {
        predict_with(
            &Problem::new(s, g, n)?.with_randomization(r),
            params,
            progress,
        )
    };
    let first = predict_2d(samplers.first, &ga, samplers.randomizations.0)?;
    let second = predict_2d(samplers.second, &gb, samplers.randomizations.1)?;
    let h = f.interaction(&ga, &gb);
    let energy = h.iter().map(|x| x * x).sum::<f64>() / h.len() as f64;
    let corrections = (0..CORRECTION_PAIRS)
        .into_par_iter()
        .map(|t| {
            let (a, b) = samplers.patterns(n, params.seed, t)?;
            Ok(correction_terms(f, &h, &a, &b))
        })
        .collect::<Result<Vec<[f64; 3]>>>()?;
    let nf = n as f64;
    let per_pair: Vec<f64> = corrections
        .iter()
        .map(|[slices_b, slices_a, product]| {
            (-slices_b - slices_a) / (nf - 1.0) + nf / (nf - 1.0) * product
        })
        .collect();
    // 64 pairs' terms may be skewed: their standard error is widened for their kurtosis, as
    // every mean of estimated terms is.
    let (mean, se) = crate::spread::mean_and_standard_error(&per_pair);
    let interaction = (energy / (nf - 1.0) + mean).max(0.0);
    let variance = first.variance + second.variance + interaction;
    let budget = ErrorBudget {
        spectrum_noise: (first.budget.spectrum_noise.powi(2)
            + second.budget.spectrum_noise.powi(2)
            + se * se)
            .sqrt(),
        quadrature: first.budget.quadrature + second.budget.quadrature,
        truncation: first.budget.truncation + second.budget.truncation,
        model: first.budget.model + second.budget.model,
        tabulation: first.budget.tabulation + second.budget.tabulation,
    };
    Ok(PaddedPrediction {
        variance,
        n,
        first,
        second,
        interaction_energy: energy,
        interaction,
        interaction_white: energy / nf,
        interaction_noise: se,
        budget,
    })
}

/// For one pair of patterns: the mean over the first pair's cells `u` of
/// `((1/N) Σ_m h(u, b_m))²`, the mean over the second's `v` of `((1/N) Σ_j h(a_j, v))²`, and
/// `((1/N²) Σ_{j,m} h(a_j, b_m))²`: one draw each of `E_u V_B[h(u,·)]`, `E_v V_A[h(·,v)]`
/// and `V_{A×B}[h]`.
fn correction_terms(f: &PaddedGrid, h: &[f64], a: &PointSet, b: &PointSet) -> [f64; 3] {
    let (na, nb) = (f.first_cells(), f.second_cells());
    let n = a.len() as f64;
    let mut count_a = vec![0.0; na];
    let mut count_b = vec![0.0; nb];
    a.points().for_each(|p| count_a[f.first_cell(p)] += 1.0 / n);
    b.points()
        .for_each(|p| count_b[f.second_cell(p)] += 1.0 / n);
    // (1/N) Σ_j h(a_j, v) for every v, and (1/N) Σ_m h(u, b_m) for every u.
    let mut over_a = vec![0.0; nb];
    let mut slices_b = 0.0;
    for (row, &wa) in h.chunks_exact(nb).zip(&count_a) {
        let mut over_b = 0.0;
        for ((x, &wb), s) in row.iter().zip(&count_b).zip(over_a.iter_mut()) {
            over_b += x * wb;
            *s += x * wa;
        }
        slices_b += over_b * over_b;
    }
    let slices_a = over_a.iter().map(|s| s * s).sum::<f64>() / nb as f64;
    let product: f64 = over_a.iter().zip(&count_b).map(|(s, w)| s * w).sum();
    [slices_b / na as f64, slices_a, product * product]
}

/// Monte Carlo of the padded estimator: `trials` estimates `(1/N) Σ_j f(a_j, b_{π(j)})`, each
/// with fresh patterns (randomized as `samplers` say) and a fresh permutation, all keyed by
/// (`seed`, trial); the variance about the exact integral with its 99% interval.
///
/// # Errors
/// As [`predict_padded`]'s checks, fewer than [`MIN_UNITS`] trials (too few for an interval),
/// or trials whose needs exceed `budget`.
pub fn padded_monte_carlo(
    f: &PaddedGrid,
    samplers: PaddedSamplers,
    n: usize,
    trials: usize,
    seed: u64,
    budget: &Budget,
) -> Result<McResult> {
    samplers.check()?;
    if trials < MIN_UNITS {
        return Err(invalid(
            "trials",
            trials,
            format!("at least {MIN_UNITS}, for a 99% interval from the trials"),
        ));
    }
    budget.check(
        &format!("{trials} padded trials at N = {n}"),
        samplers.needs(f, n, trials),
        "fewer trials or a lower N",
    )?;
    let estimates = (0..trials)
        .into_par_iter()
        .map(|t| {
            let (a, b) = samplers.patterns(n, seed, t)?;
            let order = permutation(n, seed, t);
            let sum: f64 = a
                .points()
                .zip(&order)
                .map(|(u, &m)| f.eval(u, b.point(m)))
                .sum();
            Ok(sum / n as f64)
        })
        .collect::<Result<Vec<f64>>>()?;
    let params = McParams {
        patterns: trials,
        shifts: 1,
        seed,
        randomization: samplers.randomizations.0,
        budget: Default::default(),
    };
    result_from_estimates(n, &params, &estimates, Some(f.integral()))
}

/// A uniformly random permutation of `0..n` for trial `t` of `seed` (Fisher–Yates; reducing a
/// 64-bit draw modulo `i + 1` biases it by less than `n / 2^64`).
fn permutation(n: usize, seed: u64, t: usize) -> Vec<usize> {
    use rand::Rng;
    let mut rng = realization_rng(seed, t as u64, Stream::Trial);
    let mut order: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    order
}

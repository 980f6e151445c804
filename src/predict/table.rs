//! The ordered table of analyses: the first row that applies answers. Each row states its
//! conditions (what the sampler's facts, the randomization, the integrand and the parameters
//! must be), its needs, and calls its computation.

use super::analysis::{Analysis, AnalysisKind, Applies};
use super::analysis::{AnalysisPlan, PlanNeeds};
use super::route;
use super::strata::cells::{cell_method, cell_method_needs, CellMethod, CellSource};
use super::{FormChoice, Patterns, PredictParams, Prediction, Problem, SpectrumChoice};
use crate::budget::Needs;
use crate::error::{invalid, Error, Result};
use crate::progress::Progress;
use crate::randomization::Randomization;
use crate::spectrum::ClosedForm;

/// Every row, in the order they are asked.
pub(super) static TABLE: &[&dyn Analysis] = &[
    &JitterAliasing,
    &StrataInSpace(AnalysisKind::FixedStrata),
    &StrataInSpace(AnalysisKind::RooksPairs),
    &StrataInSpace(AnalysisKind::OwenGains),
    &StrataInSpace(AnalysisKind::OwenGainsOverPatterns),
    &StrataInSpace(AnalysisKind::EstimatedOccupancy),
    &WalshFixed,
    &WalshDrawn,
    &PermutedDigits,
    &PermutedLevel,
    &AliasedPairs,
    &OwenGainsOverShifts,
    &RooksOverShifts,
    &MeasuredTail,
    &StrataOverShifts,
    &GaussianJitterShifted,
    &FixedPairs,
    &ClosedPolar,
    &ClosedLattice,
    &RescaledPolar,
    &EstimatedLattice,
];

/// The row of the table that answers `problem`, with its reason and needs; the needs are
/// checked against `params.budget` here, before any work.
pub(super) fn choose(
    problem: &Problem<'_>,
    params: &PredictParams,
) -> Result<(&'static dyn Analysis, AnalysisPlan)> {
    route::check_estimator(problem)?;
    for row in TABLE {
        let reason = match row.applies(problem, params) {
            Applies::Yes(reason) => reason,
            Applies::No => continue,
            Applies::Refuse(e) => return Err(e),
        };
        let needs = row.needs(problem, params);
        params.budget.check(
            &format!(
                "the {} analysis at N = {} ({})",
                row.kind(),
                problem.n,
                row.kind().description()
            ),
            needs,
            "lower N",
        )?;
        let plan = AnalysisPlan {
            analysis: row.kind(),
            reason,
            needs: PlanNeeds::of(row.kind(), needs),
        };
        return Ok((*row, plan));
    }
    Err(Error::OutsideValidity {
        route: "every analysis".into(),
        reason: format!(
            "no analysis answers the {} estimator of {} at N = {}",
            problem.randomization.estimator(),
            problem.integrand.label(),
            problem.n
        ),
    })
}

/// Predictions for problems that share their patterns (one sampler and N, or the same point
/// sets), each by its planned analysis, except that those whose plan is the per-pattern
/// lattice form share their spectrum estimates ([`estimated_lattice_many`]).
pub(super) fn predict_planned_many(
    problems: &[Problem<'_>],
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Vec<Prediction>> {
    let Some(first) = problems.first() else {
        return Ok(Vec::new());
    };
    let same = |p: &Problem<'_>| {
        p.n == first.n
            && p.randomization == first.randomization
            && match (p.patterns, first.patterns) {
                (Patterns::Sampler(a), Patterns::Sampler(b)) => std::ptr::addr_eq(a, b),
                (Patterns::PointSets(a), Patterns::PointSets(b)) => std::ptr::eq(a, b),
                _ => false,
            }
    };
    if !problems.iter().all(same) {
        return Err(Error::Mismatch(
            "problems predicted together must share their sampler, N and randomization, or their \
             point sets"
                .into(),
        ));
    }
    let plans = problems
        .iter()
        .map(|p| choose(p, params))
        .collect::<Result<Vec<_>>>()?;
    let shared: Vec<usize> = (0..problems.len())
        .filter(|&i| plans[i].1.analysis == AnalysisKind::EstimatedLattice)
        .collect();
    let refs: Vec<&Problem<'_>> = shared.iter().map(|&i| &problems[i]).collect();
    let mut estimated =
        route::estimated_lattice_many(&refs, first.kind(), params, progress)?.into_iter();
    let mut out = Vec::with_capacity(problems.len());
    for (problem, (row, plan)) in problems.iter().zip(plans) {
        let p = if plan.analysis == AnalysisKind::EstimatedLattice {
            estimated
                .next()
                .ok_or_else(|| Error::Mismatch("a problem left unpredicted".into()))?
        } else {
            row.predict(problem, params, progress)?
        };
        out.push(super::planned(p, &plan));
    }
    Ok(out)
}

/// `Yes(reason)` where `condition` holds.
fn when(condition: bool, reason: impl FnOnce() -> String) -> Applies {
    if condition {
        Applies::Yes(reason())
    } else {
        Applies::No
    }
}

/// The patterns' one draw: a sampler's pattern at N, or nothing for given sets.
fn one_pattern(problem: &Problem<'_>) -> Needs {
    problem.kind().map_or(Needs::default(), |k| {
        k.pattern_needs(problem.n, problem.dimension())
    })
}

/// `count` patterns drawn one after another: one held at a time, the work of all.
fn patterns(problem: &Problem<'_>, count: usize) -> Needs {
    let one = one_pattern(problem);
    Needs {
        memory_bytes: one.memory_bytes,
        work_seconds: one.work_seconds * count as f64,
    }
}

/// The cells of a problem that uses them: a sampler's, or the declared cells of given sets.
fn cell_source<'a>(problem: &Problem<'a>) -> Option<CellSource<'a>> {
    match (problem.patterns, problem.kind(), problem.cells) {
        (Patterns::Sampler(sampler), Some(k), _) => Some(CellSource::Sampler(sampler, k)),
        (Patterns::PointSets(sets), _, Some(rule)) => Some(CellSource::Sets(sets, rule)),
        _ => None,
    }
}

/// Jitter as drawn beyond its table of strata on a smooth integrand.
struct JitterAliasing;

impl Analysis for JitterAliasing {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::JitterAliasing
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        when(
            route::uses_cells(problem) && route::jitter_aliasing_applies(problem, params),
            || {
                "jitter as drawn beyond its table of strata, on a smooth integrand: the shifted \
                 closed form, its gap to the unshifted estimator bounded through the strata's \
                 aliases"
                    .into()
            },
        )
    }

    fn needs(&self, _: &Problem<'_>, _: &PredictParams) -> Needs {
        // The shifted closed form on a lattice within its own bounded budget.
        route::closed_lattice_needs()
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        if let Some(p) = route::jitter_by_aliasing(problem, params, progress)? {
            return Ok(p);
        }
        // The aliasing bound above its share of the value: the strata's own cell form.
        let source = cell_source(problem)
            .ok_or_else(|| Error::Mismatch("a cell form without cells".into()))?;
        let method = cell_method(problem.integrand, source, problem.n, params)?;
        super::strata::cells::predict_cells(
            problem.integrand,
            source,
            method,
            problem.n,
            params,
            progress,
        )
    }
}

/// The cell form of the unshifted estimator, one row per way of knowing the occupancy.
struct StrataInSpace(AnalysisKind);

fn method_kind(method: CellMethod) -> AnalysisKind {
    match method {
        CellMethod::Fixed => AnalysisKind::FixedStrata,
        CellMethod::Rooks(_) => AnalysisKind::RooksPairs,
        CellMethod::Gains(_) => AnalysisKind::OwenGains,
        CellMethod::GainsOverPatterns(_) => AnalysisKind::OwenGainsOverPatterns,
        CellMethod::Estimated => AnalysisKind::EstimatedOccupancy,
    }
}

impl Analysis for StrataInSpace {
    fn kind(&self) -> AnalysisKind {
        self.0
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        if !route::uses_cells(problem) {
            return Applies::No;
        }
        let Some(source) = cell_source(problem) else {
            return Applies::Refuse(Error::Mismatch("a cell form without cells".into()));
        };
        match cell_method(problem.integrand, source, problem.n, params) {
            Err(e) => Applies::Refuse(e),
            Ok((method, grid)) => when(method_kind(method) == self.0, || {
                let how = match method {
                    CellMethod::Fixed => "a fixed occupancy: the per-stratum form, exact",
                    CellMethod::Rooks(_) => {
                        "N-rooks permutations: their pairs of occupied cells in closed form"
                    }
                    CellMethod::Gains(_) => "a scrambled net: Owen's gains from one net, exact",
                    CellMethod::GainsOverPatterns(_) => {
                        "a net whose pair counts differ between patterns: Owen's gains averaged \
                         over patterns"
                    }
                    CellMethod::Estimated => {
                        "an occupancy without a closed form: estimated from patterns, each \
                         pattern's terms exact"
                    }
                };
                format!(
                    "{} used {} is uniform in the cells of its {} grid once they are known, \
                     with {how}",
                    source_name(problem),
                    problem.randomization.estimator(),
                    super::grid_label(&grid)
                )
            }),
        }
    }

    fn needs(&self, problem: &Problem<'_>, params: &PredictParams) -> Needs {
        let Some(source) = cell_source(problem) else {
            return Needs::default();
        };
        cell_method(problem.integrand, source, problem.n, params)
            .map_or(Needs::default(), |(method, _)| {
                cell_method_needs(method, source, problem.n, problem.dimension())
            })
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        let source = cell_source(problem)
            .ok_or_else(|| Error::Mismatch("a cell form without cells".into()))?;
        let method = cell_method(problem.integrand, source, problem.n, params)?;
        super::strata::cells::predict_cells(
            problem.integrand,
            source,
            method,
            problem.n,
            params,
            progress,
        )
    }
}

/// The sampler's name, or the given sets'.
fn source_name(problem: &Problem<'_>) -> String {
    match problem.patterns {
        Patterns::Sampler(s) => s.name().to_string(),
        Patterns::PointSets(sets) => format!("{} given point sets", sets.len()),
    }
}

/// Fixed patterns under a digital shift.
struct WalshFixed;

impl Analysis for WalshFixed {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::WalshFixed
    }

    fn applies(&self, problem: &Problem<'_>, _: &PredictParams) -> Applies {
        when(route::uses_walsh(problem), || {
            format!(
                "{} are fixed patterns under a random digital shift: the Walsh form, the \
                 characters of the shift's group",
                source_name(problem)
            )
        })
    }

    fn needs(&self, problem: &Problem<'_>, _: &PredictParams) -> Needs {
        one_pattern(problem)
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        super::walsh::forms::predict_walsh(problem, params, progress)
    }
}

/// Patterns drawn anew under a digital shift that changes their law.
struct WalshDrawn;

impl Analysis for WalshDrawn {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::WalshDrawn
    }

    fn applies(&self, problem: &Problem<'_>, _: &PredictParams) -> Applies {
        when(route::drawn_under_digital_shift(problem), || {
            format!(
                "{} under a random digital shift, which changes its law: each pattern's Walsh \
                 sum, averaged over patterns",
                source_name(problem)
            )
        })
    }

    fn needs(&self, problem: &Problem<'_>, _: &PredictParams) -> Needs {
        patterns(problem, route::INITIAL_REALIZATIONS)
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        let Patterns::Sampler(sampler) = problem.patterns else {
            return Err(Error::Mismatch(
                "patterns drawn anew without a sampler".into(),
            ));
        };
        super::walsh::forms::predict_walsh_drawn(problem, sampler, params, progress)
    }
}

/// Halton as drawn on a product integrand, by its pairs of points.
struct PermutedDigits;

impl Analysis for PermutedDigits {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::PermutedDigits
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        match route::halton_analysis(problem, params) {
            Err(e) => Applies::Refuse(e),
            Ok(kind) => when(kind == Some(route::HaltonMethod::Pairs), || {
                "halton as drawn on a product of one factor per axis: each axis's energy on \
                 every support of digits, summed over the pairs of its points, exact"
                    .into()
            }),
        }
    }

    fn needs(&self, problem: &Problem<'_>, _: &PredictParams) -> Needs {
        let (n, d) = (problem.n, problem.dimension());
        Needs::work(super::digits::permuted_digits::pair_work_seconds(n, d))
            .and(one_pattern(problem))
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        _: &dyn Progress,
    ) -> Result<Prediction> {
        let form = problem
            .integrand
            .product_form()
            .ok_or_else(|| Error::Mismatch("permuted digits without a product form".into()))?;
        super::digits::permuted_digits::predict_halton_as_drawn(
            &form,
            problem.n,
            params.work_budget_seconds,
            &params.budget,
        )
    }
}

/// Halton as drawn through a level of digit cells.
struct PermutedLevel;

impl Analysis for PermutedLevel {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::PermutedLevel
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        match route::halton_analysis(problem, params) {
            Err(e) => Applies::Refuse(e),
            Ok(kind) => when(kind == Some(route::HaltonMethod::Level), || {
                "halton as drawn: the integrand's and the points' energies on every support of \
                 digits through a level of cells, exact, the finer digits measured on its \
                 realizations"
                    .into()
            }),
        }
    }

    fn needs(&self, problem: &Problem<'_>, _: &PredictParams) -> Needs {
        patterns(problem, route::INITIAL_REALIZATIONS)
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        let Patterns::Sampler(sampler) = problem.patterns else {
            return Err(Error::Mismatch("halton's level without its sampler".into()));
        };
        super::digits::permuted_level::predict_halton_level(
            problem.integrand,
            sampler,
            problem.n,
            params,
            progress,
        )
    }
}

/// Gaussian jitter as drawn.
struct AliasedPairs;

impl Analysis for AliasedPairs {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::AliasedPairs
    }

    fn applies(&self, problem: &Problem<'_>, _: &PredictParams) -> Applies {
        when(route::gaussian_jitter_as_drawn(problem).is_some(), || {
            "gjitter as drawn: independent points with known densities, whose variance the \
             pairs of frequencies its strata alias together give exactly"
                .into()
        })
    }

    fn needs(&self, _: &Problem<'_>, _: &PredictParams) -> Needs {
        // Sums over the strata's aliases, bounded by their own check as they are built.
        Needs::default()
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        _: &dyn Progress,
    ) -> Result<Prediction> {
        let (form, strata) = route::gaussian_jitter_as_drawn(problem)
            .ok_or_else(|| Error::Mismatch("aliased pairs without Gaussian jitter".into()))?;
        super::fourier::gaussian_jitter::predict_gaussian_jitter_as_drawn(
            problem.integrand,
            form,
            &strata,
            &params.budget,
        )
    }
}

/// An Owen-scrambled net under a random shift.
struct OwenGainsOverShifts;

impl Analysis for OwenGainsOverShifts {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::OwenGainsOverShifts
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        when(
            route::shifted_scrambled_net(problem, params).is_some(),
            || {
                format!(
                "{} under a random shift on an integrand with moments over boxes: Owen's gains \
                 averaged over shifts, nothing truncated",
                source_name(problem)
            )
            },
        )
    }

    fn needs(&self, problem: &Problem<'_>, _: &PredictParams) -> Needs {
        one_pattern(problem)
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        let sampler = route::shifted_scrambled_net(problem, params)
            .ok_or_else(|| Error::Mismatch("a shifted net without its sampler".into()))?;
        super::digits::shifted_gains::predict_shifted_net(
            problem.integrand,
            sampler,
            problem.n,
            params,
            progress,
        )
    }
}

/// N-rooks permutations under a random shift, on a separable integrand.
struct RooksOverShifts;

impl Analysis for RooksOverShifts {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::RooksOverShifts
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        let rooks = route::shifted_strata(problem, params).is_some_and(|(_, kind, _)| {
            super::strata::shifted_cells::shuffles_over_shifts(problem.integrand, kind)
        });
        when(rooks, || {
            format!(
                "{} under a random shift on a separable integrand: the N-rooks permutations' \
                 pairs in closed form on each shifted integrand, averaged over shifts",
                source_name(problem)
            )
        })
    }

    fn needs(&self, _: &Problem<'_>, _: &PredictParams) -> Needs {
        // Two rows of cells per axis, checked by the computation as it builds them.
        Needs::default()
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        let (_, kind, _) = route::shifted_strata(problem, params)
            .ok_or_else(|| Error::Mismatch("shifted rooks without a sampler".into()))?;
        super::strata::shifted_cells::predict_shifted_shuffles(
            problem.integrand,
            kind,
            problem.n,
            params,
            progress,
        )
    }
}

/// Strata under a random shift by default: the lattice form with a measured tail.
struct MeasuredTail;

impl Analysis for MeasuredTail {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::MeasuredTail
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        when(
            params.form == FormChoice::Auto && route::shifted_strata(problem, params).is_some(),
            || {
                format!(
                    "{} under a random shift has no closed form: the lattice form with each \
                     pattern's transform, the tail measured at shifts",
                    source_name(problem)
                )
            },
        )
    }

    fn needs(&self, problem: &Problem<'_>, _: &PredictParams) -> Needs {
        route::estimated_lattice_needs(problem)
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        let (sampler, kind, _) = route::shifted_strata(problem, params)
            .ok_or_else(|| Error::Mismatch("shifted strata without a sampler".into()))?;
        route::shifted_strata_measured(problem, (sampler, kind), params, progress)
    }
}

/// Strata under a random shift, the cell form asked for.
struct StrataOverShifts;

impl Analysis for StrataOverShifts {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::StrataOverShifts
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        if params.form != FormChoice::Cells {
            return Applies::No;
        }
        if route::shifted_strata(problem, params).is_some() {
            return Applies::Yes(format!(
                "{} under a random shift, the cell form asked for: each pattern's cells on the \
                 shifted integrand, averaged over patterns and shifts",
                source_name(problem)
            ));
        }
        Applies::Refuse(Error::OutsideValidity {
            route: "the cell form".into(),
            reason: format!(
                "{} used {} has no cell form: it is the form of strata and nets used as drawn, \
                 and under a shift of multi-jitter, CMJ, orthogonal arrays, PMJ02 and Sobol' on \
                 integrands with moments over boxes (no spectrum or lattice asked for)",
                problem
                    .kind()
                    .map_or("given point sets".to_string(), |k| k.to_string()),
                problem.randomization.estimator()
            ),
        })
    }

    fn needs(&self, problem: &Problem<'_>, _: &PredictParams) -> Needs {
        patterns(problem, route::INITIAL_REALIZATIONS)
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        let (sampler, kind, grid) = route::shifted_strata(problem, params)
            .ok_or_else(|| Error::Mismatch("shifted strata without a sampler".into()))?;
        super::strata::shifted_cells::predict_shifted_cells(
            problem.integrand,
            (sampler, kind),
            &grid,
            problem.n,
            params,
            progress,
        )
    }
}

/// The closed form of a sampler's problem, unless an estimate was asked for.
fn closed(problem: &Problem<'_>, params: &PredictParams) -> Option<ClosedForm> {
    match (params.spectrum, problem.patterns) {
        (SpectrumChoice::Estimated, _) | (_, Patterns::PointSets(_)) => None,
        (_, Patterns::Sampler(s)) => s.closed_form(problem.n),
    }
}

/// Gaussian jitter under a shift, its closed form summed exactly.
struct GaussianJitterShifted;

impl GaussianJitterShifted {
    fn strata(problem: &Problem<'_>, params: &PredictParams) -> Option<(ClosedForm, Vec<usize>)> {
        let form @ ClosedForm::GaussianJitter { .. } = closed(problem, params)? else {
            return None;
        };
        let defaults = params.form == FormChoice::Auto && params.kmax.is_none();
        (problem.randomization == Randomization::Shift && defaults)
            .then(|| crate::sampler::strata(problem.n, problem.dimension()))
            .flatten()
            .map(|strata| (form, strata))
    }
}

impl Analysis for GaussianJitterShifted {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::GaussianJitterShifted
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        when(Self::strata(problem, params).is_some(), || {
            "gjitter under a random shift: its closed form summed exactly, by Parseval in \
             frequency or over the offsets' difference in space, whichever is cheaper"
                .into()
        })
    }

    fn needs(&self, _: &Problem<'_>, _: &PredictParams) -> Needs {
        // Either sum checks its own size and gives way to the other when too large.
        Needs::default()
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        _: &dyn Progress,
    ) -> Result<Prediction> {
        let (form, strata) = Self::strata(problem, params)
            .ok_or_else(|| Error::Mismatch("gjitter's sum without its strata".into()))?;
        route::gaussian_jitter_shifted(problem.integrand, form, &strata, params)
    }
}

/// Fixed patterns under a shift, summed exactly over their pairs.
struct FixedPairs;

impl Analysis for FixedPairs {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::FixedPairs
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        let asked = params.spectrum == SpectrumChoice::Auto
            && params.form != FormChoice::Polar
            && params.kmax.is_none()
            && closed(problem, params).is_none();
        when(asked && route::fixed_pairs_fit(problem), || {
            format!(
                "{} are fixed under a random shift: each set's periodogram summed in space over \
                 its pairs through the integrand's autocorrelation, exact",
                source_name(problem)
            )
        })
    }

    fn needs(&self, problem: &Problem<'_>, _: &PredictParams) -> Needs {
        route::fixed_pairs_needs(problem).and(one_pattern(problem))
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        _: &dyn Progress,
    ) -> Result<Prediction> {
        route::fixed_pairs(problem, params)
    }
}

/// The polar form with a closed form.
struct ClosedPolar;

impl Analysis for ClosedPolar {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::ClosedPolar
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        if params.spectrum == SpectrumChoice::Closed && closed(problem, params).is_none() {
            return Applies::Refuse(invalid(
                "spectrum",
                "closed",
                "a sampler with a closed form at N (random; jitter, Gaussian jitter and the \
                 regular grid with strata at N; Latin hypercube; rank-1 lattices; Kronecker); \
                 use the estimated spectrum",
            ));
        }
        when(
            params.form == FormChoice::Polar && closed(problem, params).is_some(),
            || "the polar form asked for, with the closed form's radial mean".into(),
        )
    }

    fn needs(&self, _: &Problem<'_>, _: &PredictParams) -> Needs {
        Needs::default()
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        _: &dyn Progress,
    ) -> Result<Prediction> {
        let c = closed(problem, params)
            .ok_or_else(|| Error::Mismatch("a closed polar form without one".into()))?;
        route::closed_polar(problem, c, problem.kind(), params)
    }
}

/// The lattice form with a closed form.
struct ClosedLattice;

impl Analysis for ClosedLattice {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::ClosedLattice
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        match closed(problem, params) {
            Some(c) => Applies::Yes(format!(
                "{} has a closed form at N = {} ({}): the lattice form, exact on the torus, or \
                 its sum in space",
                source_name(problem),
                problem.n,
                c.name()
            )),
            None => Applies::No,
        }
    }

    fn needs(&self, problem: &Problem<'_>, params: &PredictParams) -> Needs {
        closed(problem, params).map_or(Needs::default(), |c| route::closed_form_needs(problem, c))
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        _: &dyn Progress,
    ) -> Result<Prediction> {
        let c = closed(problem, params)
            .ok_or_else(|| Error::Mismatch("a closed lattice form without one".into()))?;
        route::closed_lattice(problem, c, problem.kind(), params)
    }
}

/// The polar form with a rescaled estimate.
struct RescaledPolar;

impl Analysis for RescaledPolar {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::RescaledPolar
    }

    fn applies(&self, _: &Problem<'_>, params: &PredictParams) -> Applies {
        when(params.form == FormChoice::Polar, || {
            "the polar form asked for: the radial spectrum estimated at a reference N, read at \
             ν = ρ/N^(1/d)"
                .into()
        })
    }

    fn needs(&self, problem: &Problem<'_>, params: &PredictParams) -> Needs {
        route::rescaled_polar_needs(problem, params)
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        route::rescaled_polar(problem, problem.kind(), params, progress)
    }
}

/// The lattice form with the spectrum estimated at N.
struct EstimatedLattice;

impl Analysis for EstimatedLattice {
    fn kind(&self) -> AnalysisKind {
        AnalysisKind::EstimatedLattice
    }

    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies {
        Applies::Yes(match (problem.kind(), params.spectrum) {
            (None, _) => format!(
                "{}: no closed form is known; the lattice form with each pattern's own \
                 transform at N",
                source_name(problem)
            ),
            (Some(k), SpectrumChoice::Estimated) => format!(
                "the estimated spectrum of {k} was asked for: the lattice form with each \
                 pattern's transform at N"
            ),
            (Some(k), _) => format!(
                "{k} has no closed form at N = {}: the lattice form with each pattern's \
                 transform at N, the tail bounded or measured",
                problem.n
            ),
        })
    }

    fn needs(&self, problem: &Problem<'_>, _: &PredictParams) -> Needs {
        route::estimated_lattice_needs(problem)
    }

    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction> {
        route::estimated_lattice(problem, problem.kind(), params, progress)
    }
}

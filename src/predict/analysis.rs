//! A prediction is planned before it is computed. Each analysis (a Fourier form, strata in
//! space, Owen's gains, a Walsh sum, …) states whether it applies to a problem and why, what it
//! needs (seconds of one core and bytes) as a function of the problem, and computes its
//! prediction with every budget term. [`plan_analysis`] walks one ordered table of analyses,
//! takes the first that applies, and checks its needs against the budget before any work; the
//! plan is a value that can be shown ([`AnalysisPlan`], `specvar predict --explain`) and then
//! run. Every prediction of the crate (one problem, many problems, pixels, plans, padded pairs,
//! the report) goes through it.

use super::{PredictParams, Prediction, Problem};
use crate::budget::Needs;
use crate::error::{Error, Result};
use crate::progress::Progress;
use serde::Serialize;
use std::fmt;

/// The analyses of the table, in the order they are tried.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum AnalysisKind {
    /// Jitter as drawn beyond its table of strata on a smooth integrand: the shifted
    /// estimator's closed form, the gap between the two bounded through the strata's aliases.
    JitterAliasing,
    /// Strata (or independent points) as drawn with a fixed occupancy: the per-stratum form.
    FixedStrata,
    /// N-rooks samplers as drawn (Latin hypercube, multi-jitter, CMJ, orthogonal arrays): their
    /// pairs of occupied cells in closed form.
    RooksPairs,
    /// An Owen-scrambled base-2 net as drawn: Owen's gains from one net's pair counts.
    OwenGains,
    /// PMJ02 as drawn between powers of two: Owen's gains averaged over patterns.
    OwenGainsOverPatterns,
    /// Strata as drawn whose occupancy has no closed form: estimated from patterns, each
    /// pattern's terms exact.
    EstimatedOccupancy,
    /// Fixed patterns (a deterministic sampler's, or given sets) under a digital shift: the
    /// Walsh form.
    WalshFixed,
    /// A random sampler under a digital shift that changes its law: each pattern's Walsh sum,
    /// averaged over patterns.
    WalshDrawn,
    /// Halton with permuted digits as drawn on a product integrand: its pairs of points.
    PermutedDigits,
    /// Halton with permuted digits as drawn: a level of digit cells exact, the finer digits
    /// measured.
    PermutedLevel,
    /// Gaussian jitter as drawn: the pairs of frequencies its strata alias together.
    AliasedPairs,
    /// An Owen-scrambled net under a random shift: Owen's gains averaged over shifts.
    OwenGainsOverShifts,
    /// N-rooks permutations under a random shift: their pairs in closed form averaged over
    /// shifts.
    RooksOverShifts,
    /// Strata under a random shift: the lattice form with each pattern's transform and the
    /// tail measured at shifts.
    MeasuredTail,
    /// Strata under a random shift, the cell form asked for: each pattern's cells on the
    /// shifted integrand.
    StrataOverShifts,
    /// Gaussian jitter under a shift: its closed form summed exactly, in frequency or in space.
    GaussianJitterShifted,
    /// Fixed patterns under a shift: each set's periodogram summed in space over its pairs.
    FixedPairs,
    /// The polar form with a closed form's radial mean.
    ClosedPolar,
    /// The lattice form with a closed form (exact on the torus), or its sums in space.
    ClosedLattice,
    /// The polar form with a spectrum estimated at a reference N and rescaled.
    RescaledPolar,
    /// The lattice form with the spectrum estimated at N, pattern by pattern.
    EstimatedLattice,
}

impl AnalysisKind {
    /// Every analysis, in the table's order.
    pub const ALL: [AnalysisKind; 21] = [
        AnalysisKind::JitterAliasing,
        AnalysisKind::FixedStrata,
        AnalysisKind::RooksPairs,
        AnalysisKind::OwenGains,
        AnalysisKind::OwenGainsOverPatterns,
        AnalysisKind::EstimatedOccupancy,
        AnalysisKind::WalshFixed,
        AnalysisKind::WalshDrawn,
        AnalysisKind::PermutedDigits,
        AnalysisKind::PermutedLevel,
        AnalysisKind::AliasedPairs,
        AnalysisKind::OwenGainsOverShifts,
        AnalysisKind::RooksOverShifts,
        AnalysisKind::MeasuredTail,
        AnalysisKind::StrataOverShifts,
        AnalysisKind::GaussianJitterShifted,
        AnalysisKind::FixedPairs,
        AnalysisKind::ClosedPolar,
        AnalysisKind::ClosedLattice,
        AnalysisKind::RescaledPolar,
        AnalysisKind::EstimatedLattice,
    ];

    /// The name in output and on the command line (`fixed-strata`).
    pub fn name(self) -> &'static str {
        match self {
            AnalysisKind::JitterAliasing => "jitter-aliasing",
            AnalysisKind::FixedStrata => "fixed-strata",
            AnalysisKind::RooksPairs => "rooks-pairs",
            AnalysisKind::OwenGains => "owen-gains",
            AnalysisKind::OwenGainsOverPatterns => "owen-gains-over-patterns",
            AnalysisKind::EstimatedOccupancy => "estimated-occupancy",
            AnalysisKind::WalshFixed => "walsh-fixed",
            AnalysisKind::WalshDrawn => "walsh-drawn",
            AnalysisKind::PermutedDigits => "permuted-digits",
            AnalysisKind::PermutedLevel => "permuted-level",
            AnalysisKind::AliasedPairs => "aliased-pairs",
            AnalysisKind::OwenGainsOverShifts => "owen-gains-over-shifts",
            AnalysisKind::RooksOverShifts => "rooks-over-shifts",
            AnalysisKind::MeasuredTail => "measured-tail",
            AnalysisKind::StrataOverShifts => "strata-over-shifts",
            AnalysisKind::GaussianJitterShifted => "gaussian-jitter-shifted",
            AnalysisKind::FixedPairs => "fixed-pairs",
            AnalysisKind::ClosedPolar => "closed-polar",
            AnalysisKind::ClosedLattice => "closed-lattice",
            AnalysisKind::RescaledPolar => "rescaled-polar",
            AnalysisKind::EstimatedLattice => "estimated-lattice",
        }
    }
}

impl AnalysisKind {
    /// Whether the analysis sizes some of its tables as it builds them (a table of cells whose
    /// size depends on which cells the integrand's boundary crosses, a lattice that gives way
    /// to another form when too large), each checked against the budget before it is
    /// allocated: its plan's needs are then what it spends before those tables.
    pub fn sizes_tables_as_built(self) -> bool {
        match self {
            AnalysisKind::JitterAliasing
            | AnalysisKind::FixedStrata
            | AnalysisKind::RooksPairs
            | AnalysisKind::OwenGains
            | AnalysisKind::OwenGainsOverPatterns
            | AnalysisKind::EstimatedOccupancy
            | AnalysisKind::WalshFixed
            | AnalysisKind::WalshDrawn
            | AnalysisKind::PermutedDigits
            | AnalysisKind::PermutedLevel
            | AnalysisKind::AliasedPairs
            | AnalysisKind::OwenGainsOverShifts
            | AnalysisKind::RooksOverShifts
            | AnalysisKind::StrataOverShifts
            | AnalysisKind::GaussianJitterShifted
            | AnalysisKind::ClosedLattice => true,
            AnalysisKind::MeasuredTail
            | AnalysisKind::FixedPairs
            | AnalysisKind::ClosedPolar
            | AnalysisKind::RescaledPolar
            | AnalysisKind::EstimatedLattice => false,
        }
    }

    /// What it computes, in a phrase.
    pub fn description(self) -> &'static str {
        match self {
            AnalysisKind::JitterAliasing => {
                "jitter's shifted closed form, the gap to the strata as drawn bounded by aliasing"
            }
            AnalysisKind::FixedStrata => "the per-stratum form, (1/N²) Σ_c Var_c f, exact",
            AnalysisKind::RooksPairs => {
                "the cell form with the N-rooks permutations' pairs of cells in closed form"
            }
            AnalysisKind::OwenGains => "Owen's gains read from one net's pair counts, exact",
            AnalysisKind::OwenGainsOverPatterns => "Owen's gains averaged over patterns",
            AnalysisKind::EstimatedOccupancy => {
                "the cell form with the occupancy estimated from patterns"
            }
            AnalysisKind::WalshFixed => "the Walsh form of fixed patterns under a digital shift",
            AnalysisKind::WalshDrawn => "each drawn pattern's Walsh sum, averaged over patterns",
            AnalysisKind::PermutedDigits => "the pairs of Halton's points on every digit support",
            AnalysisKind::PermutedLevel => {
                "a level of digit cells exact, Halton's finer digits measured"
            }
            AnalysisKind::AliasedPairs => "the aliased-pair form of Gaussian jitter as drawn",
            AnalysisKind::OwenGainsOverShifts => "Owen's gains averaged over random shifts",
            AnalysisKind::RooksOverShifts => {
                "the N-rooks pairs in closed form averaged over random shifts"
            }
            AnalysisKind::MeasuredTail => {
                "the lattice form on each pattern's transform, its tail measured at shifts"
            }
            AnalysisKind::StrataOverShifts => "each pattern's cells on the shifted integrand",
            AnalysisKind::GaussianJitterShifted => {
                "Gaussian jitter's closed form by Parseval or summed in space"
            }
            AnalysisKind::FixedPairs => "each fixed set's pairs summed in space",
            AnalysisKind::ClosedPolar => "the polar form with a closed form's radial mean",
            AnalysisKind::ClosedLattice => {
                "the lattice form with a closed form, or summed in space over its peaks"
            }
            AnalysisKind::RescaledPolar => "the polar form with a spectrum rescaled from N_ref",
            AnalysisKind::EstimatedLattice => "the lattice form with each pattern's transform at N",
        }
    }
}

impl fmt::Display for AnalysisKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Whether an analysis answers a problem.
pub(crate) enum Applies {
    /// It does, for this reason.
    Yes(String),
    /// It does not (the next row is asked).
    No,
    /// The problem asks for something this analysis's family refuses (a lattice extent for the
    /// cell form, say): the plan stops with this error.
    Refuse(Error),
}

/// One analysis: a row of the table.
pub(crate) trait Analysis: Sync {
    /// Which analysis it is.
    fn kind(&self) -> AnalysisKind;

    /// Whether it answers `problem` with `params`, decided before any work.
    fn applies(&self, problem: &Problem<'_>, params: &PredictParams) -> Applies;

    /// What its first pass needs (the patterns, tables and transforms it must hold or compute
    /// before it can say anything), from the problem's sizes alone. Adaptive analyses spend
    /// more within `params.work_budget_seconds`, each further step checked as it goes.
    fn needs(&self, problem: &Problem<'_>, params: &PredictParams) -> Needs;

    /// Its prediction, with every budget term.
    ///
    /// # Errors
    /// What the computation refuses (a budget, a validity check only the work reveals).
    fn predict(
        &self,
        problem: &Problem<'_>,
        params: &PredictParams,
        progress: &dyn Progress,
    ) -> Result<Prediction>;
}

/// The plan of a prediction: the analysis chosen, why, and what it needs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AnalysisPlan {
    /// The analysis.
    pub analysis: AnalysisKind,
    /// Why it answers this problem.
    pub reason: String,
    /// What it needs before it can answer.
    pub needs: PlanNeeds,
}

/// [`Needs`] as a plan reports them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlanNeeds {
    /// Seconds of one core's work.
    pub seconds: f64,
    /// Bytes held at once.
    pub bytes: f64,
    /// Whether tables sized as they are built come on top, each checked against the budget
    /// before it is allocated ([`AnalysisKind::sizes_tables_as_built`]).
    pub tables_checked_as_built: bool,
}

impl PlanNeeds {
    /// `needs` of `analysis`.
    pub(crate) fn of(analysis: AnalysisKind, needs: Needs) -> Self {
        Self {
            seconds: needs.work_seconds,
            bytes: needs.memory_bytes,
            tables_checked_as_built: analysis.sizes_tables_as_built(),
        }
    }
}

/// The table from (sampler, randomization, integrand kind) to the analysis that answers it in
/// 2D at the count nearest `n`, with default parameters, as markdown: the plan alone, no work.
/// A cell names the analysis, or `refused` where no analysis answers that estimator.
///
/// # Examples
/// ```
/// let table = specvar::predict::analysis_markdown_table(256);
/// assert!(table.contains("| jitter | none (native) | fixed-strata |"));
/// ```
pub fn analysis_markdown_table(n: usize) -> String {
    use crate::integrand::Polygon;
    use crate::integrand::{AnisotropicGaussian, Ball, Gaussian, GridIntegrand, Integrand};
    use crate::randomization::Randomization;
    use crate::sampler::SamplerKind;
    // One integrand of each kind, the Gaussian and the grid crossing no face, the polygon a
    // triangle inside the square.
    let built: Result<Vec<(&str, Box<dyn Integrand>)>> = (|| {
        Ok(vec![
            (
                "disk",
                Box::new(Ball::new(0.25, vec![0.5, 0.5], 1.0)?) as Box<dyn Integrand>,
            ),
            (
                "gaussian",
                Box::new(Gaussian::new(0.1, vec![0.5, 0.5], 1.0)?),
            ),
            (
                "polygon",
                Box::new(Polygon::new(
                    vec![[0.12, 0.18], [0.83, 0.31], [0.41, 0.88]],
                    1.0,
                )?),
            ),
            (
                "grid",
                Box::new(
                    GridIntegrand::new(4, 4, (0..16).map(f64::from).collect())?
                        .with_meaning(crate::integrand::GridMeaning::Exact),
                ),
            ),
            (
                "agaussian",
                Box::new(AnisotropicGaussian::new(0.05, 0.15, 30.0, [0.5, 0.5], 1.0)?),
            ),
        ])
    })();
    let Ok(integrands) = built else {
        return String::new();
    };
    let mut md = String::from("| sampler | randomization |");
    for (name, _) in &integrands {
        md.push_str(&format!(" {name} |"));
    }
    md.push_str("\n|---|---|");
    md.push_str(&"---|".repeat(integrands.len()));
    md.push('\n');
    // Every sampler of the crate in 2D, in the order `specvar samplers` lists them.
    for kind in SamplerKind::in_dimension(2) {
        let Ok(sampler) = kind.build(2) else { continue };
        let count = kind.nearest_count(n, 2);
        for r in Randomization::ALL {
            let native = if r == kind.native_randomization() {
                " (native)"
            } else {
                ""
            };
            md.push_str(&format!("| {kind} | {r}{native} |"));
            for (_, f) in &integrands {
                let plan = Problem::new(sampler.as_ref(), f.as_ref(), count).and_then(|p| {
                    super::plan_analysis(&p.with_randomization(r), &Default::default())
                });
                let cell = plan.map_or("refused".to_string(), |p| p.analysis.to_string());
                md.push_str(&format!(" {cell} |"));
            }
            md.push('\n');
        }
    }
    md
}

/// Every analysis with what it computes, then [`analysis_markdown_table`] at `n`, as markdown:
/// the theory notes' reference (`specvar samplers --analyses`).
pub fn analyses_markdown(n: usize) -> String {
    let mut md = String::from("| analysis | what it computes |\n|---|---|\n");
    for kind in AnalysisKind::ALL {
        md.push_str(&format!("| `{kind}` | {} |\n", kind.description()));
    }
    md.push('\n');
    md.push_str(&analysis_markdown_table(n));
    md
}

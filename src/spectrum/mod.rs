//! Spectral analysis of point sets.
//!
//! The power spectrum of an N-point set is `P_S(k) = |Σ_j e^{-2πi k·x_j}|² / N`, evaluated
//! only at integer `k` (elsewhere the finite window leaks in). White noise has `E[P_S] = 1`
//! away from DC and `P_S(0) = N` always. Two engines compute it:
//!
//! - [`Engine::Direct`]: the exact sum by a phase recurrence (complex multiplication along an
//!   axis, no `sin`/`cos` per term), parallel over frequencies. The accuracy reference.
//! - [`Engine::Fast`]: a type-1 non-uniform FFT ([`nufft`]) with a tolerance.
//!
//! [`estimate`] averages the periodograms of many realizations into an expected lattice
//! spectrum with per-frequency standard errors, and a [`RadialSpectrum`].

mod accumulate;
pub mod export;
mod in_order;
pub mod lattice;
pub mod nufft;
mod radial;
mod sector;

pub use accumulate::{PatternSource, SpectrumAccumulator, WeightedMean};
// Closed forms are facts about samplers; the spectra read them.
pub use crate::sampler::{fejer, sinc, ClosedForm, ClosedLattice, TailDeviation};
pub use lattice::Lattice;
pub use radial::{RadialBin, RadialSpectrum};
pub use sector::{sector_spectrum, SectorRing, SectorSpectrum, MAX_SECTORS};

use crate::error::{invalid, Result};
use crate::pointset::PointSet;
use crate::sampler::Sampler;
use num_complex::Complex64;
use serde::Serialize;

/// How to compute a periodogram.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Engine {
    /// Exact sum by phase recurrence.
    Direct,
    /// Non-uniform FFT at the given tolerance.
    Fast {
        /// Relative tolerance (see [`nufft::NufftPlan::new`]).
        tolerance: f64,
    },
    /// Whichever of the two is cheaper for the problem size.
    Auto,
}

/// An engine as a caller names it, before a fast engine's tolerance is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EngineChoice {
    /// The cheaper of the two, the fast one at the tolerance the statistics need.
    #[default]
    Auto,
    /// Exact sums by phase recurrence.
    Direct,
    /// The non-uniform FFT.
    Fast,
}

impl EngineChoice {
    /// The engine: the fast one at `tolerance`, or at the [`statistical_tolerance`] of
    /// `realizations` sets of `n` points when none is given; a tolerance with `Auto` asks for
    /// the fast engine at it.
    ///
    /// # Errors
    /// A tolerance with the direct engine, which is exact.
    ///
    /// # Examples
    /// ```
    /// use specvar::spectrum::{Engine, EngineChoice};
    /// assert_eq!(EngineChoice::Auto.engine(None, 64, 8)?, Engine::Auto);
    /// assert_eq!(
    ///     EngineChoice::Auto.engine(Some(1e-9), 64, 8)?,
    ///     Engine::Fast { tolerance: 1e-9 }
    /// );
    /// assert!(EngineChoice::Direct.engine(Some(1e-9), 64, 8).is_err());
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn engine(self, tolerance: Option<f64>, n: usize, realizations: usize) -> Result<Engine> {
        match (self, tolerance) {
            (EngineChoice::Direct, Some(t)) => Err(invalid(
                "tolerance",
                t,
                "only with the fast or automatic engine: the direct sum is exact",
            )),
            (EngineChoice::Direct, None) => Ok(Engine::Direct),
            (EngineChoice::Fast, t) | (EngineChoice::Auto, t @ Some(_)) => {
                Ok(Engine::fast_at(t, n, realizations))
            }
            (EngineChoice::Auto, None) => Ok(Engine::Auto),
        }
    }
}

impl std::fmt::Display for EngineChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            EngineChoice::Auto => "auto",
            EngineChoice::Direct => "direct",
            EngineChoice::Fast => "fast",
        })
    }
}

impl std::str::FromStr for EngineChoice {
    type Err = crate::Error;
    /// `auto`, `direct` or `fast`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "auto" => Ok(EngineChoice::Auto),
            "direct" => Ok(EngineChoice::Direct),
            "fast" => Ok(EngineChoice::Fast),
            other => Err(invalid("engine", other, "auto, direct or fast")),
        }
    }
}

impl std::fmt::Display for Engine {
    /// `direct`, `auto`, or `fast:tolerance=T`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Engine::Direct => f.write_str("direct"),
            Engine::Auto => f.write_str("auto"),
            Engine::Fast { tolerance } => write!(f, "fast:tolerance={tolerance:e}"),
        }
    }
}

impl std::str::FromStr for Engine {
    type Err = crate::Error;
    /// `direct`, `auto`, `fast` (at the default tolerance) or `fast:tolerance=T`.
    fn from_str(s: &str) -> Result<Self> {
        let s = s.trim();
        let allowed = "direct, auto, fast or fast:tolerance=T with T in (0, 1)";
        match s.split_once(':') {
            None => match s
                .parse::<EngineChoice>()
                .map_err(|_| invalid("engine", s, allowed))?
            {
                EngineChoice::Auto => Ok(Engine::Auto),
                EngineChoice::Direct => Ok(Engine::Direct),
                EngineChoice::Fast => Ok(Engine::fast()),
            },
            Some(("fast", rest)) => rest
                .strip_prefix("tolerance=")
                .and_then(|t| t.trim().parse::<f64>().ok())
                .filter(|t| *t > 0.0 && *t < 1.0)
                .map(|tolerance| Engine::Fast { tolerance })
                .ok_or_else(|| invalid("engine", s, allowed)),
            Some(_) => Err(invalid("engine", s, allowed)),
        }
    }
}

impl Engine {
    /// The fast engine at its default tolerance.
    pub fn fast() -> Self {
        Engine::Fast {
            tolerance: nufft::DEFAULT_TOLERANCE,
        }
    }

    /// The fast engine at `tolerance`, or, when none is given, at the [`statistical_tolerance`]
    /// of `realizations` sets of `n` points.
    pub fn fast_at(tolerance: Option<f64>, n: usize, realizations: usize) -> Self {
        Engine::Fast {
            tolerance: tolerance.unwrap_or_else(|| statistical_tolerance(n, realizations)),
        }
    }

    /// Resolves `Auto` for `realizations` patterns of `n` points on `|k_i| ≤ kmax`: the fast
    /// engine at the [`statistical_tolerance`] if the cost model of
    /// [`nufft::choice`] predicts it cheaper than the direct sum (`N (2K+1)^d / 2` complex
    /// multiply-adds at 0.25 ns), else the direct engine. Other engines are returned as they
    /// are.
    pub fn resolve(self, n: usize, d: usize, kmax: usize, realizations: usize) -> Engine {
        if self != Engine::Auto {
            return self;
        }
        let tolerance = statistical_tolerance(n, realizations);
        let direct = n as f64 * ((2 * kmax + 1) as f64).powi(d as i32) / 2.0
            * crate::costs::DIRECT_MAC_SECONDS;
        match nufft::choice::Choice::cheapest(d, kmax, n, tolerance) {
            Ok(c) if c.seconds(d, kmax, n) < direct => Engine::Fast { tolerance },
            _ => Engine::Direct,
        }
    }

    /// A short name: `direct` or `fast`.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Direct => "direct",
            Engine::Fast { .. } => "fast",
            Engine::Auto => "auto",
        }
    }
}

/// The error in `P` the fast engine may add, as a fraction of one standard error of an
/// `M`-realization mean (whose standard error is about `P / √M`, the periodogram being
/// roughly exponential), with a floor of [`ENGINE_FLOOR`] absolute.
pub const ENGINE_SHARE_OF_NOISE: f64 = 0.01;

/// The absolute error in `P` below which the fast engine's error is never a concern.
pub const ENGINE_FLOOR: f64 = 1e-8;

/// The fast engine's tolerance for an estimate from `realizations` patterns of `n` points: the
/// largest `ε` with `|δP| ≤ max(ENGINE_FLOOR, ENGINE_SHARE_OF_NOISE · P / √M)` at every `P`.
///
/// A guarantee `|δS| ≤ εN` gives `|δP| ≤ 2ε√(NP) + ε²N`. Against the floor this needs
/// `ε ≤ floor / (2√(NP))`, against the noise share `ε ≤ share √P / (2√(NM))`; the two meet at
/// `P* = floor √M / share`, where both give `ε = floor / (2 √(N P*))
/// = √(share · floor) / (2 √N M^{1/4})` (`5·10⁻⁶ / (√N M^{1/4})`); any other `P` is looser.
/// The `ε²N` term is below `floor / 100` for every `N, M ≥ 1`.
///
/// # Examples
/// ```
/// use specvar::spectrum::statistical_tolerance;
/// let eps = statistical_tolerance(4096, 64);
/// assert!((eps - 5e-6 / (64.0 * 64f64.powf(0.25))).abs() < 1e-15);
/// ```
pub fn statistical_tolerance(n: usize, realizations: usize) -> f64 {
    let scale = (ENGINE_SHARE_OF_NOISE * ENGINE_FLOOR).sqrt() / 2.0;
    let m = realizations.max(1) as f64;
    (scale / ((n.max(1) as f64).sqrt() * m.powf(0.25))).max(nufft::MIN_TOLERANCE)
}

/// The bound on `|δP|` at power `p` for sets of `n` points from the fast engine at `tolerance`
/// (`2ε√(NP) + ε²N`; zero for the direct engine).
pub fn engine_error(engine: Engine, n: usize, p: f64) -> f64 {
    match engine {
        Engine::Fast { tolerance } => {
            let n = n as f64;
            2.0 * tolerance * (n * p.max(0.0)).sqrt() + tolerance * tolerance * n
        }
        _ => 0.0,
    }
}

/// Parameters of a spectrum estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpectrumParams {
    /// Largest frequency per axis `K`.
    pub kmax: usize,
    /// Realizations to average.
    pub realizations: usize,
    /// Seed of the realizations.
    pub seed: u64,
    /// Engine.
    pub engine: Engine,
    /// Ring width in `|k|` for the radial spectrum.
    pub bin_width: f64,
    /// What the estimate may spend (checked before it starts).
    pub budget: crate::budget::Budget,
}

impl Default for SpectrumParams {
    fn default() -> Self {
        Self {
            kmax: 64,
            realizations: 16,
            seed: 0,
            engine: Engine::Auto,
            bin_width: 1.0,
            budget: crate::budget::Budget::default(),
        }
    }
}

/// An expected power spectrum on the lattice `|k_i| ≤ K`.
#[derive(Debug, Clone, PartialEq)]
pub struct LatticeSpectrum {
    /// The lattice geometry.
    pub lattice: Lattice,
    /// Points per pattern.
    pub n: usize,
    /// Realizations averaged.
    pub realizations: usize,
    /// The engine that computed it (resolved, never `Auto`).
    pub engine: Engine,
    /// Mean power per frequency, in lattice order. `mean[dc_index] = N` (flagged, not data).
    pub mean: Vec<f64>,
    /// Standard error of the mean per frequency (`NaN` with one realization).
    pub stderr: Vec<f64>,
}

impl LatticeSpectrum {
    /// The mean power at integer frequency `k` (length `d`), if inside the lattice.
    pub fn at(&self, k: &[i64]) -> Option<f64> {
        self.lattice.index(k).map(|i| self.mean[i])
    }

    /// Whether flat index `i` is the DC frequency.
    pub fn is_dc(&self, i: usize) -> bool {
        i == self.lattice.dc_index()
    }
}

/// An expected lattice spectrum with its radial spectrum.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectrumEstimate {
    /// The lattice spectrum.
    pub lattice: LatticeSpectrum,
    /// Its radial spectrum, with per-ring standard errors across realizations.
    pub radial: RadialSpectrum,
}

/// The lattice extent that reaches the scaled frequency `ν = K / N^{1/d}` at `n` points in
/// dimension `d`: `⌈ν N^{1/d}⌉`.
///
/// # Examples
/// ```
/// assert_eq!(specvar::spectrum::kmax_at_nu(256, 2, 3.0), 48);
/// assert_eq!(specvar::spectrum::kmax_at_nu(1000, 3, 1.5), 15);
/// ```
pub fn kmax_at_nu(n: usize, d: usize, nu: f64) -> usize {
    (nu * (n as f64).powf(1.0 / d as f64)).ceil() as usize
}

/// The periodogram `P_S(k)` of one point set on the lattice `|k_i| ≤ kmax`.
///
/// # Errors
/// A dimension above 3 or a bad tolerance.
///
/// # Examples
/// ```
/// use specvar::spectrum::{periodogram, Engine, Lattice};
/// let grid = specvar::sampler::Regular::new(1).unwrap();
/// use specvar::Sampler;
/// let p = periodogram(&grid.sample(8, 0, 0).unwrap(), 16, Engine::Direct).unwrap();
/// // A regular grid of 8 points has power N at multiples of 8 and none elsewhere.
/// assert!((p[16 + 8] - 8.0).abs() < 1e-9 && p[16 + 3] < 1e-20);
/// ```
pub fn periodogram(points: &PointSet, kmax: usize, engine: Engine) -> Result<Vec<f64>> {
    check_kmax(kmax)?;
    let (d, n) = (points.dimension(), points.len());
    let engine = engine.resolve(n, d, kmax, 1);
    let needs = transform_needs(d, n, kmax, engine, 1);
    crate::budget::Budget::default().check("a periodogram", needs, "lower kmax")?;
    let planned = Planned::new(d, n, kmax, engine)?;
    let mut work = planned.workspace();
    planned.half_periodogram(points, &mut work)?;
    let mut power = std::mem::take(&mut work.half_power);
    mirror_in_place(&mut power, planned.lattice().len());
    Ok(power)
}

/// Extends `values`, the half lattice `0..=dc`, to the whole lattice of `len` frequencies with
/// `v(-k) = v(k)` (flat index `i` ↔ `len - 1 - i`).
pub(crate) fn mirror_in_place(values: &mut Vec<f64>, len: usize) {
    let half = values.len();
    debug_assert_eq!(half, len / 2 + 1);
    values.extend_from_within(..len - half);
    values[half..].reverse();
}

/// An engine with its plan, reusable across realizations.
pub(crate) enum Planned {
    Direct(Lattice),
    Fast(Box<nufft::NufftPlan>),
}

/// One thread's buffers for [`Planned::half_periodogram`]: power, and the engine's scratch.
pub(crate) struct Workspace {
    /// The last periodogram computed, on the half lattice: flat indices `0..=dc`, which with
    /// `P(-k) = P(k)` (index `i` ↔ `len - 1 - i`) give the whole.
    pub half_power: Vec<f64>,
    /// The direct engine's sums and phase tables (empty for the fast engine).
    sums: Vec<Complex64>,
    tables: lattice::PhaseTables,
    nufft: Option<nufft::NufftScratch>,
}

/// The largest lattice extent accepted anywhere: `2^24` (a larger one would be refused by the
/// memory budget in any dimension; refusing it first keeps every size computation in range).
pub const MAX_KMAX: usize = 1 << 24;

/// Checks a lattice extent: 1 to [`MAX_KMAX`].
///
/// # Errors
/// [`crate::Error::InvalidParameter`] outside that range.
pub fn check_kmax(kmax: usize) -> Result<()> {
    if (1..=MAX_KMAX).contains(&kmax) {
        Ok(())
    } else {
        Err(invalid(
            "kmax",
            kmax,
            format!("1 to {MAX_KMAX} (2^24; the memory budget refuses far less)"),
        ))
    }
}

impl Planned {
    pub(crate) fn new(d: usize, n: usize, kmax: usize, engine: Engine) -> Result<Self> {
        if !(1..=3).contains(&d) {
            return Err(invalid("dimension", d, "1 to 3 for spectra"));
        }
        check_kmax(kmax)?;
        Ok(match engine.resolve(n, d, kmax, 1) {
            Engine::Fast { tolerance } => {
                Planned::Fast(Box::new(nufft::NufftPlan::new(d, kmax, n, tolerance)?))
            }
            _ => Planned::Direct(Lattice { dimension: d, kmax }),
        })
    }

    fn lattice(&self) -> Lattice {
        match self {
            Planned::Direct(lattice) => *lattice,
            Planned::Fast(plan) => Lattice {
                dimension: plan.dimension(),
                kmax: plan.kmax(),
            },
        }
    }

    pub(crate) fn workspace(&self) -> Workspace {
        let len = self.lattice().len();
        let (sums, nufft) = match self {
            Planned::Fast(plan) => (Vec::new(), Some(plan.make_scratch())),
            Planned::Direct(_) => (vec![Complex64::new(0.0, 0.0); len], None),
        };
        Workspace {
            half_power: vec![0.0; len / 2 + 1],
            sums,
            tables: lattice::PhaseTables::default(),
            nufft,
        }
    }

    /// The periodogram of `points` on the half lattice into `work.half_power`, with DC pinned
    /// to exactly `N` so that rounding in either engine cannot disturb it.
    pub(crate) fn half_periodogram(&self, points: &PointSet, work: &mut Workspace) -> Result<()> {
        match (self, &mut work.nufft) {
            (Planned::Fast(plan), Some(scratch)) => {
                plan.half_power_with_scratch(points, scratch, &mut work.half_power)?
            }
            (Planned::Direct(lattice), _) => {
                lattice::direct_sums_into(points, lattice.kmax, &mut work.tables, &mut work.sums);
                let scale = 1.0 / points.len() as f64;
                for (p, s) in work.half_power.iter_mut().zip(&work.sums) {
                    *p = s.norm_sqr() * scale;
                }
            }
            (Planned::Fast(_), None) => unreachable!("a fast plan's workspace has NUFFT scratch"),
        }
        let dc = work.half_power.len() - 1;
        work.half_power[dc] = points.len() as f64;
        Ok(())
    }

    pub(crate) fn engine(&self) -> Engine {
        match self {
            Planned::Direct(_) => Engine::Direct,
            Planned::Fast(plan) => Engine::Fast {
                tolerance: plan.tolerance(),
            },
        }
    }
}

/// Estimates the expected spectrum of `sampler` at `n` points over `params.realizations`
/// realizations `0..M` of `params.seed`. The patterns are used as the sampler gives them; wrap
/// it in [`crate::sampler::Homogenized`] for shifted patterns (the spectrum is shift-invariant,
/// so it makes no difference here). Parallel over realizations, and identical for any thread
/// count (each realization joins the sums after every realization before it).
///
/// # Errors
/// A sampler error, a dimension above 3, or bad parameters.
///
/// # Examples
/// ```
/// use specvar::sampler::Random;
/// use specvar::spectrum::{estimate, SpectrumParams};
/// let params = SpectrumParams { kmax: 8, realizations: 64, ..Default::default() };
/// let est = estimate(&Random::new(2).unwrap(), 64, &params).unwrap();
/// // White noise: every ring near 1.
/// assert!(est.radial.bins.iter().all(|b| (b.power - 1.0).abs() < 6.0 * b.stderr));
/// ```
pub fn estimate(
    sampler: &dyn Sampler,
    n: usize,
    params: &SpectrumParams,
) -> Result<SpectrumEstimate> {
    let source = PatternSource::Sampler {
        sampler,
        n,
        seed: params.seed,
    };
    estimate_with_progress(source, params, &crate::progress::Silent)
}

/// Estimates the expected spectrum of given point sets (e.g. read from a file): all must have
/// the same dimension and size; every set is used (`params.realizations` is ignored).
///
/// # Errors
/// Empty input, mixed dimensions or sizes, a dimension above 3, or bad parameters.
pub fn estimate_from_sets(sets: &[PointSet], params: &SpectrumParams) -> Result<SpectrumEstimate> {
    estimate_with_progress(PatternSource::Sets(sets), params, &crate::progress::Silent)
}

/// As [`estimate`] or [`estimate_from_sets`], for either source, advancing `progress` by one
/// per realization: `params.realizations` of a sampler, or every given set.
///
/// # Errors
/// As [`estimate`] and [`estimate_from_sets`].
pub fn estimate_with_progress(
    source: PatternSource<'_>,
    params: &SpectrumParams,
    progress: &dyn crate::progress::Progress,
) -> Result<SpectrumEstimate> {
    let target = source.available().unwrap_or(params.realizations);
    if target == 0 {
        return Err(invalid("realizations", 0, "at least 1"));
    }
    let params = SpectrumParams {
        realizations: target,
        ..*params
    };
    let mut acc = SpectrumAccumulator::new(source, &params, Vec::new())?;
    acc.extend_to(target, progress)?;
    Ok(acc.estimate())
}

/// The memory and time of transforming `realizations` patterns of `n` points on the lattice
/// `|k_i| ≤ kmax` with `engine` (resolved), one workspace per thread: the lattice's sums,
/// powers and moments (40 bytes a frequency), the NUFFT's scratch, and per pattern
/// `N (2K+1)^d / 2` complex multiply-adds (direct) or the fast engine's cost model
/// ([`nufft::choice::Choice::seconds`]).
pub fn transform_needs(
    d: usize,
    n: usize,
    kmax: usize,
    engine: Engine,
    realizations: usize,
) -> crate::budget::Needs {
    let len = ((2 * kmax + 1) as f64).powi(d as i32);
    let threads = rayon::current_num_threads().max(1) as f64;
    let (scratch, per_pattern) = match engine {
        Engine::Fast { tolerance } => {
            let choice =
                nufft::choice::Choice::cheapest(d, kmax, n, tolerance).unwrap_or_else(|_| {
                    nufft::choice::Choice::with_width(d, kmax, 2.0, nufft::kernel::MAX_WIDTH)
                });
            (choice.scratch_bytes(d, kmax), choice.seconds(d, kmax, n))
        }
        _ => (0.0, n as f64 * len / 2.0 * crate::costs::DIRECT_MAC_SECONDS),
    };
    crate::budget::Needs {
        memory_bytes: threads * (len * 40.0 + scratch) + 2.0 * threads * len * 16.0,
        work_seconds: realizations as f64 * per_pattern,
    }
}

/// `len` zeros, written rather than allocated zeroed, for buffers that are added into before
/// they are written (the spreading's cells, the sums over realizations): on zeroed pages fresh
/// from the system each first addition is a read fault onto the shared zero page and then a
/// copy-on-write fault, whose TLB flush interrupts every other thread of the process (on a
/// virtual machine, an exit to the hypervisor each). Written pages fault once, on the write.
pub(crate) fn written_zeros(len: usize) -> Vec<f64> {
    let mut zeros = Vec::with_capacity(len);
    zeros.resize(len, 0.0);
    zeros
}

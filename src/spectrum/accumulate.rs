//! Accumulating periodograms over realizations: the expected lattice spectrum, its radial
//! spectrum, and per realization the lattice form of given weights.
//!
//! The lattice form of one pattern, `V_r = (1/N) Σ_{k≠0} w(k) P_r(k)` with `w = |f̂|²`, is that
//! pattern's variance under random shifts; its mean over realizations is the homogenized
//! estimator's variance, and the spread of the `V_r` gives that mean's standard error with every
//! correlation between frequencies included (a per-frequency error propagation would treat them
//! as independent).

use super::in_order::{lock, InOrder};
use super::{radial, Lattice, LatticeSpectrum, Planned, RadialSpectrum, SpectrumEstimate};
use super::{SpectrumParams, Workspace};
use crate::error::{invalid, Error, Result};
use crate::pointset::PointSet;
use crate::progress::Progress;
use crate::sampler::Sampler;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Where the patterns of an estimate come from.
#[derive(Clone, Copy)]
pub enum PatternSource<'a> {
    /// Realizations `0, 1, …` of `seed` of a sampler at `n` points.
    Sampler {
        /// The sampler.
        sampler: &'a dyn Sampler,
        /// Points per pattern.
        n: usize,
        /// The seed.
        seed: u64,
    },
    /// Given point sets, in order.
    Sets(&'a [PointSet]),
}

impl PatternSource<'_> {
    pub(crate) fn dimension(&self) -> usize {
        match self {
            PatternSource::Sampler { sampler, .. } => sampler.dimension(),
            PatternSource::Sets(sets) => sets[0].dimension(),
        }
    }

    pub(crate) fn points(&self) -> usize {
        match self {
            PatternSource::Sampler { n, .. } => *n,
            PatternSource::Sets(sets) => sets[0].len(),
        }
    }

    /// How many realizations exist (`None`: unbounded).
    pub fn available(&self) -> Option<usize> {
        match self {
            PatternSource::Sampler { .. } => None,
            PatternSource::Sets(sets) => Some(sets.len()),
        }
    }

    /// The memory and time of one pattern (none for given sets).
    pub(crate) fn pattern_needs(&self) -> crate::budget::Needs {
        match self {
            PatternSource::Sampler { sampler, n, .. } => match sampler.kind() {
                Some(kind) => kind.pattern_needs(*n, sampler.dimension()),
                None => crate::budget::Needs {
                    memory_bytes: (*n * sampler.dimension() * 32) as f64,
                    work_seconds: *n as f64 * 1e-6,
                },
            },
            PatternSource::Sets(_) => crate::budget::Needs::default(),
        }
    }

    pub(crate) fn realization(&self, r: usize) -> Result<PointSet> {
        match self {
            PatternSource::Sampler { sampler, n, seed } => sampler.sample(*n, *seed, r as u64),
            PatternSource::Sets(sets) => Ok(sets[r].clone()),
        }
    }

    pub(crate) fn check(&self) -> Result<()> {
        match self {
            PatternSource::Sampler { sampler, n, .. } => sampler.check_count(*n),
            PatternSource::Sets(sets) => {
                let first = sets
                    .first()
                    .ok_or_else(|| Error::Mismatch("no point sets".into()))?;
                let (d, n) = (first.dimension(), first.len());
                if sets.iter().any(|s| s.dimension() != d || s.len() != n) {
                    return Err(Error::Mismatch(
                        "all point sets must have the same dimension and number of points".into(),
                    ));
                }
                Ok(())
            }
        }
    }
}

/// The mean over realizations of a per-realization value, with its standard error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WeightedMean {
    /// The mean.
    pub mean: f64,
    /// Its standard error (`NaN` with one realization).
    pub stderr: f64,
    /// Realizations.
    pub realizations: usize,
}

/// One realization's contribution, summarized by the thread that transformed it: its
/// periodogram on the half lattice, its mean power per ring, and its weighted sums.
struct Realization {
    power: Vec<f64>,
    ring_means: Vec<f64>,
    weighted: Vec<f64>,
}

impl Realization {
    /// Summarizes `power`, a periodogram on the half lattice (`0..=dc`, DC last), by the
    /// rings and by the weights folded onto the same half; `ring_sum` is scratch of one slot
    /// per ring and a spare one.
    fn new(
        power: Vec<f64>,
        geometry: &Geometry,
        weights: &[Vec<f64>],
        ring_sum: &mut [f64],
    ) -> Self {
        ring_sum.fill(0.0);
        // Neighbouring frequencies fall in the same ring in runs: a run is summed in a
        // register, in the same order as one by one, instead of through memory, where each
        // addition waited for the store of the one before. Frequencies in no ring go to the
        // spare slot.
        let mut ring = geometry.ring_of.first().map_or(0, |&b| b as usize);
        let mut run = 0.0;
        for (&b, &v) in geometry.ring_of.iter().zip(&power) {
            let b = b as usize;
            if b != ring {
                ring_sum[ring] = run;
                (ring, run) = (b, ring_sum[b]);
            }
            run += v;
        }
        ring_sum[ring] = run;
        let ring_means = ring_sum[..geometry.rings]
            .iter()
            .zip(&geometry.ring_count)
            .map(|(s, &count)| if count > 0.0 { s / count } else { 0.0 })
            .collect();
        // The folded weights are zero at DC.
        let weighted = weighted_sums(weights, &power);
        Self {
            power,
            ring_means,
            weighted,
        }
    }
}

/// Lanes of a weighted sum: independent partial sums, so that the additions of neighbouring
/// frequencies do not wait for each other and vectorize.
const LANES: usize = 8;
/// Frequencies per block of [`weighted_sums`]: a block of the power stays in the first-level
/// cache while every weight vector reads it.
const BLOCK: usize = 512;

/// `Σ_k w(k) P(k)` for each weight vector `w` (each as long as `power`), block by block and
/// lane by lane, in an order that depends on the lengths alone (so the same bits on any
/// machine and thread count).
fn weighted_sums(weights: &[Vec<f64>], power: &[f64]) -> Vec<f64> {
    let mut lanes = vec![[0.0; LANES]; weights.len()];
    let mut tails = vec![0.0; weights.len()];
    for (start, p) in (0..power.len()).step_by(BLOCK).zip(power.chunks(BLOCK)) {
        for ((w, lane), tail) in weights.iter().zip(&mut lanes).zip(&mut tails) {
            let w = &w[start..start + p.len()];
            let (w_body, w_tail) = w.split_at(p.len() - p.len() % LANES);
            let (p_body, p_tail) = p.split_at(w_body.len());
            // The lanes in registers for the block (through `lane` they would be stored back
            // on every step).
            let mut acc = *lane;
            for (wc, pc) in w_body.chunks_exact(LANES).zip(p_body.chunks_exact(LANES)) {
                for l in 0..LANES {
                    acc[l] += wc[l] * pc[l];
                }
            }
            *lane = acc;
            *tail += w_tail.iter().zip(p_tail).map(|(w, p)| w * p).sum::<f64>();
        }
    }
    lanes
        .iter()
        .zip(tails)
        .map(|(lane, tail)| {
            let [a, b, c, d, e, f, g, h] = *lane;
            ((a + b) + (c + d)) + ((e + f) + (g + h)) + tail
        })
        .collect()
}

/// Running sums over realizations: per frequency, per ring, and per weight vector.
struct Moments {
    sum: Vec<f64>,
    sum_sq: Vec<f64>,
    ring: Vec<(f64, f64)>,
    /// Each weight vector's sum per realization, in order: their mean, and from their spread
    /// and tails its standard error.
    weighted_terms: Vec<Vec<f64>>,
}

impl Moments {
    fn new(len: usize, rings: usize, weights: usize) -> Self {
        Self {
            sum: super::written_zeros(len),
            sum_sq: super::written_zeros(len),
            ring: vec![(0.0, 0.0); rings],
            weighted_terms: vec![Vec::new(); weights],
        }
    }

    /// Adds one realization (rings holding no frequency are left out).
    fn add(&mut self, r: &Realization, ring_count: &[f64]) {
        for ((s, s2), &v) in self
            .sum
            .iter_mut()
            .zip(self.sum_sq.iter_mut())
            .zip(&r.power)
        {
            *s += v;
            *s2 += v * v;
        }
        for ((acc, &mean), &count) in self.ring.iter_mut().zip(&r.ring_means).zip(ring_count) {
            if count > 0.0 {
                acc.0 += mean;
                acc.1 += mean * mean;
            }
        }
        for (terms, &value) in self.weighted_terms.iter_mut().zip(&r.weighted) {
            terms.push(value);
        }
    }
}

/// Buffers kept between realizations and between extensions: fresh buffers of megabytes
/// cost more in page faults than a transform.
#[derive(Default)]
struct Pools {
    workspaces: Mutex<Vec<Workspace>>,
    power: Mutex<Vec<Vec<f64>>>,
}

impl Pools {
    fn take_workspace(&self, planned: &Planned) -> Workspace {
        let spare = lock(&self.workspaces).pop();
        spare.unwrap_or_else(|| planned.workspace())
    }

    fn give_back(&self, work: Workspace) {
        lock(&self.workspaces).push(work);
    }

    /// A buffer of `len` values for a periodogram (which overwrites all of them).
    fn take_power(&self, len: usize) -> Vec<f64> {
        let spare = lock(&self.power).pop();
        spare.unwrap_or_else(|| vec![0.0; len])
    }

    fn recycle_power(&self, power: Vec<f64>) {
        lock(&self.power).push(power);
    }
}

/// One extension of an estimate, shared by the threads that transform its realizations.
struct Extension<'r, 'a> {
    source: &'r PatternSource<'a>,
    planned: &'r Planned,
    geometry: &'r Geometry,
    weights: &'r [Vec<f64>],
    pools: &'r Pools,
    progress: &'r dyn Progress,
    /// The next realization to hand out.
    next: AtomicUsize,
    target: usize,
    /// The earliest realization that failed, with its error.
    failure: Mutex<Option<(usize, Error)>>,
    total: InOrder<Realization, &'r mut Moments>,
}

impl Extension<'_, '_> {
    /// Transforms realizations, handed out in order, until none is left, one fails, or more
    /// than `backlog` finished ones wait for an earlier one (which bounds the memory they
    /// hold; the threads still working finish the rest).
    fn work(&self, backlog: usize) {
        let mut work = self.pools.take_workspace(self.planned);
        let mut ring_sum = vec![0.0; self.geometry.rings + 1];
        while self.total.parked() <= backlog && lock(&self.failure).is_none() {
            let r = self.next.fetch_add(1, Ordering::Relaxed);
            if r >= self.target {
                break;
            }
            match self.realize(r, &mut work, &mut ring_sum) {
                Ok(done) => {
                    self.total.offer(r, done, |total, done| {
                        total.add(&done, &self.geometry.ring_count);
                        self.pools.recycle_power(done.power);
                    });
                    self.progress.advance(1);
                }
                Err(e) => {
                    let mut failure = lock(&self.failure);
                    if failure.as_ref().is_none_or(|(first, _)| r < *first) {
                        *failure = Some((r, e));
                    }
                    break;
                }
            }
        }
        self.pools.give_back(work);
    }

    fn realize(&self, r: usize, work: &mut Workspace, ring_sum: &mut [f64]) -> Result<Realization> {
        if work.half_power.is_empty() {
            // The last realization's buffer went to the sums. Taken only now, the buffer is
            // likely the one this thread just added, still in its cache.
            work.half_power = self.pools.take_power(self.geometry.lattice.dc_index() + 1);
        }
        self.planned
            .half_periodogram(&self.source.realization(r)?, work)?;
        let power = std::mem::take(&mut work.half_power);
        Ok(Realization::new(
            power,
            self.geometry,
            self.weights,
            ring_sum,
        ))
    }
}

/// The lattice and its rings.
struct Geometry {
    lattice: Lattice,
    /// The ring of each frequency of the half lattice, or `rings` (a spare slot) for none.
    ring_of: Vec<u32>,
    ring_count: Vec<f64>,
    rings: usize,
}

/// A spectrum estimate that can be extended with more realizations. The result for `M`
/// realizations is the same bits however it was reached (one call or several, any thread
/// count): each realization is added to the sums after every realization before it.
pub struct SpectrumAccumulator<'a> {
    source: PatternSource<'a>,
    params: SpectrumParams,
    planned: Planned,
    geometry: Geometry,
    weights: Vec<Vec<f64>>,
    total: Moments,
    realizations: usize,
    pools: Pools,
}

impl<'a> SpectrumAccumulator<'a> {
    /// An empty estimate of `source`'s spectrum on the lattice `|k_i| ≤ params.kmax` with
    /// `params.engine` and rings of `params.bin_width`. Each of `weights` (one value per lattice
    /// frequency, in lattice order; DC is ignored) gets its per-realization sum
    /// `Σ_k w(k) P_r(k)` accumulated (see [`weighted`](Self::weighted)).
    /// `params.realizations` and, for sets, `params.seed` are not used here.
    ///
    /// # Errors
    /// Bad parameters, a dimension outside 1 to 3, a pattern source that cannot give N points,
    /// or weights of another length than the lattice.
    pub fn new(
        source: PatternSource<'a>,
        params: &SpectrumParams,
        weights: Vec<Vec<f64>>,
    ) -> Result<Self> {
        source.check()?;
        super::check_kmax(params.kmax)?;
        if !(params.bin_width.is_finite() && params.bin_width > 0.0) {
            return Err(invalid("bin width", params.bin_width, "a positive number"));
        }
        let (d, n) = (source.dimension(), source.points());
        let engine = params
            .engine
            .resolve(n, d, params.kmax, params.realizations);
        let what = format!("a spectrum on |k_i| ≤ {} in {d}D", params.kmax);
        let one = super::transform_needs(d, n, params.kmax, engine, 0).and(source.pattern_needs());
        params.budget.check(&what, one, "lower kmax or N")?;
        let planned = Planned::new(d, n, params.kmax, engine)?;
        let lattice = Lattice {
            dimension: d,
            kmax: params.kmax,
        };
        if let Some(w) = weights.iter().find(|w| w.len() != lattice.len()) {
            return Err(Error::Mismatch(format!(
                "weights of length {} for a lattice of {} frequencies",
                w.len(),
                lattice.len()
            )));
        }
        // Everything is kept on the half lattice `0..=dc`: P(-k) = P(k).
        let half = lattice.dc_index() + 1;
        // Rings narrower than K / half would outnumber the frequencies, most of them empty.
        let finest = params.kmax as f64 / half as f64;
        if params.bin_width < finest {
            return Err(invalid(
                "bin width",
                params.bin_width,
                format!(
                    "at least {finest:.3e} on |k_i| ≤ {}, so that rings do not outnumber the \
                     frequencies",
                    params.kmax
                ),
            ));
        }
        let (ring_of, rings) = radial::ring_assignment(&lattice, params.bin_width, half);
        if rings == 0 {
            return Err(invalid(
                "bin width",
                params.bin_width,
                format!("at most K = {} so that at least one ring fits", params.kmax),
            ));
        }
        let mut ring_count = vec![0.0; rings];
        for &b in ring_of.iter().filter(|&&b| (b as usize) < rings) {
            ring_count[b as usize] += 1.0;
        }
        let weight_count = weights.len();
        let weights = weights.iter().map(|w| fold_weights(w)).collect();
        Ok(Self {
            source,
            params: *params,
            planned,
            geometry: Geometry {
                lattice,
                ring_of,
                ring_count,
                rings,
            },
            weights,
            total: Moments::new(half, rings, weight_count),
            realizations: 0,
            pools: Pools::default(),
        })
    }

    /// Realizations accumulated so far.
    pub fn realizations(&self) -> usize {
        self.realizations
    }

    /// Adds realizations until there are `target`, advancing `progress` by one per
    /// realization. A target at or below the realizations so far adds none.
    ///
    /// # Errors
    /// A sampler or engine error, or more realizations than the given sets hold. The
    /// realizations before the first that failed stay accumulated.
    pub fn extend_to(&mut self, target: usize, progress: &dyn Progress) -> Result<()> {
        if let Some(available) = self.source.available()
            && target > available
        {
            return Err(invalid(
                "realizations",
                target,
                format!("at most the {available} point sets given"),
            ));
        }
        if target == 0 && self.realizations == 0 {
            return Err(invalid("realizations", 0, "at least 1"));
        }
        let more = target.saturating_sub(self.realizations);
        if more == 0 {
            return Ok(());
        }
        let per_pattern = self.source.pattern_needs().work_seconds;
        let (d, n) = (self.geometry.lattice.dimension, self.source.points());
        let engine = self.planned.engine();
        let work = super::transform_needs(d, n, self.params.kmax, engine, more).work_seconds
            + more as f64 * per_pattern;
        self.params.budget.check(
            &format!("{more} more realizations"),
            crate::budget::Needs::work(work),
            "lower the realizations, kmax or N",
        )?;
        let workers = rayon::current_num_threads().clamp(1, more);
        let extension = Extension {
            source: &self.source,
            planned: &self.planned,
            geometry: &self.geometry,
            weights: &self.weights,
            pools: &self.pools,
            progress,
            next: AtomicUsize::new(self.realizations),
            target,
            failure: Mutex::new(None),
            total: InOrder::new(self.realizations, &mut self.total),
        };
        // Each worker holds a workspace; a few finished realizations at most wait per worker.
        (0..workers)
            .into_par_iter()
            .for_each(|_| extension.work(2 * workers));
        // Whatever workers stopping at their backlog left, here.
        extension.work(usize::MAX);
        let failure = lock(&extension.failure).take();
        let (added, _) = extension.total.into_inner();
        self.realizations = added;
        match failure {
            Some((_, e)) => Err(e),
            None => Ok(()),
        }
    }

    /// The per-realization sums `Σ_k w(k) P_r(k)` of each weight vector: their mean over the
    /// realizations so far, and its standard error.
    pub fn weighted(&self) -> Vec<WeightedMean> {
        let m = self.realizations as f64;
        self.total
            .weighted_terms
            .iter()
            .map(|terms| {
                // Summed in realization order, as the terms arrived.
                let mean = terms.iter().sum::<f64>() / m;
                WeightedMean {
                    mean,
                    stderr: crate::spread::standard_error_about(terms, mean),
                    realizations: self.realizations,
                }
            })
            .collect()
    }

    /// The estimate from the realizations so far.
    pub fn estimate(&self) -> SpectrumEstimate {
        let m = self.realizations;
        let mf = m as f64;
        let lattice = self.geometry.lattice;
        let n = self.source.points();
        // The lattice's mean and standard error, written on the half lattice and mirrored, in
        // place (no half-lattice copies, whose fresh pages would cost more than the arithmetic).
        let len = lattice.len();
        let half = self.total.sum.len();
        let mut mean = Vec::with_capacity(len);
        mean.extend(self.total.sum.iter().map(|s| s / mf));
        let (stderr, radial) = rayon::join(
            || {
                let mut stderr = Vec::with_capacity(len);
                stderr.extend(self.total.sum_sq.iter().zip(&mean).map(|(s2, mu)| {
                    if m > 1 {
                        ((s2 / mf - mu * mu).max(0.0) / (mf - 1.0)).sqrt()
                    } else {
                        f64::NAN
                    }
                }));
                super::mirror_in_place(&mut stderr, len);
                stderr
            },
            || {
                RadialSpectrum::from_parts(
                    &lattice,
                    &mean[..half],
                    n,
                    m,
                    (&self.geometry.ring_of, self.geometry.rings),
                    self.params.bin_width,
                    &self.total.ring,
                )
            },
        );
        super::mirror_in_place(&mut mean, len);
        SpectrumEstimate {
            lattice: LatticeSpectrum {
                lattice,
                n,
                realizations: m,
                engine: self.planned.engine(),
                mean,
                stderr,
            },
            radial,
        }
    }
}

/// Weights folded onto the half lattice `0..=dc`: `w(k) + w(-k)`, and zero at DC, so that
/// `Σ_half w_folded P = Σ_{k≠0} w P` for a spectrum with `P(-k) = P(k)`.
fn fold_weights(w: &[f64]) -> Vec<f64> {
    let len = w.len();
    let dc = (len - 1) / 2;
    (0..=dc)
        .map(|i| if i == dc { 0.0 } else { w[i] + w[len - 1 - i] })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocked, laned sums are the plain sums up to rounding: each differs by at most
    /// `len · ε · Σ|w p|` (the bound of any order of summation).
    #[test]
    fn weighted_sums_are_the_plain_sums() {
        for len in [0, 1, 7, 8, BLOCK - 1, BLOCK + 3, 3 * BLOCK + 17] {
            let power: Vec<f64> = (0..len).map(|k| 1.0 + (k as f64 * 0.37).sin()).collect();
            let weights: Vec<Vec<f64>> = (1..4)
                .map(|j| {
                    (0..len)
                        .map(|k| (k as f64 * 0.11 * j as f64).cos())
                        .collect()
                })
                .collect();
            let sums = weighted_sums(&weights, &power);
            assert_eq!(sums.len(), weights.len());
            for (w, sum) in weights.iter().zip(sums) {
                let plain: f64 = w.iter().zip(&power).map(|(w, p)| w * p).sum();
                let scale: f64 = w.iter().zip(&power).map(|(w, p)| (w * p).abs()).sum();
                let bound = len as f64 * f64::EPSILON * scale;
                assert!((sum - plain).abs() <= bound, "{len}: {sum} against {plain}");
            }
        }
    }
}

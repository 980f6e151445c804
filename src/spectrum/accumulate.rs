//! Accumulating periodograms over realizations: the expected lattice spectrum, its radial
//! spectrum, and per realization the lattice form of given weights.
//!
//! The lattice form of one pattern, `V_r = (1/N) Σ_{k≠0} w(k) P_r(k)` with `w = |f̂|²`, is that
//! pattern's variance under random shifts; its mean over realizations is the homogenized
//! estimator's variance, and the spread of the `V_r` gives that mean's standard error with every
//! correlation between frequencies included (a per-frequency error propagation would treat them
//! as independent).

use super::{radial, Lattice, LatticeSpectrum, Planned, RadialSpectrum, SpectrumEstimate};
use super::{SpectrumParams, Workspace};
use crate::error::{invalid, Error, Result};
use crate::pointset::PointSet;
use crate::progress::Progress;
use crate::sampler::Sampler;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::Mutex;

/// Realizations per chunk of the deterministic reduction.
const REDUCE_CHUNK: usize = 4;

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
    fn dimension(&self) -> usize {
        match self {
            PatternSource::Sampler { sampler, .. } => sampler.dimension(),
            PatternSource::Sets(sets) => sets[0].dimension(),
        }
    }

    fn points(&self) -> usize {
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
    fn pattern_needs(&self) -> crate::budget::Needs {
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

    fn realization(&self, r: usize) -> Result<PointSet> {
        match self {
            PatternSource::Sampler { sampler, n, seed } => sampler.sample(*n, *seed, r as u64),
            PatternSource::Sets(sets) => Ok(sets[r].clone()),
        }
    }

    fn check(&self) -> Result<()> {
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

/// Running sums over realizations: per frequency, per ring, and per weight vector.
struct Moments {
    sum: Vec<f64>,
    sum_sq: Vec<f64>,
    ring: Vec<(f64, f64)>,
    weighted: Vec<(f64, f64)>,
    /// Scratch: one realization's ring sums.
    ring_sum: Vec<f64>,
}

impl Moments {
    fn new(len: usize, rings: usize, weights: usize) -> Self {
        Self {
            sum: vec![0.0; len],
            sum_sq: vec![0.0; len],
            ring: vec![(0.0, 0.0); rings],
            weighted: vec![(0.0, 0.0); weights],
            ring_sum: vec![0.0; rings + 1],
        }
    }

    fn clear(&mut self) {
        self.sum.fill(0.0);
        self.sum_sq.fill(0.0);
        self.ring.fill((0.0, 0.0));
        self.weighted.fill((0.0, 0.0));
    }

    /// Adds one realization's periodogram on the half lattice (`0..=dc`, DC last), with the
    /// rings' assignment and the weights folded onto the same half.
    fn add(&mut self, p: &[f64], geometry: &Geometry, weights: &[Vec<f64>]) {
        self.ring_sum.fill(0.0);
        // Two passes: the first vectorizes, the second scatters into the rings (frequencies in
        // no ring go to the spare last slot).
        for ((s, s2), &v) in self.sum.iter_mut().zip(self.sum_sq.iter_mut()).zip(p) {
            *s += v;
            *s2 += v * v;
        }
        // Neighbouring frequencies fall in the same ring in runs: a run is summed in a
        // register, in the same order as one by one (the same bits), instead of through memory,
        // where each addition waited for the store of the one before.
        let mut ring = geometry.ring_of.first().map_or(0, |&b| b as usize);
        let mut run = 0.0;
        for (&b, &v) in geometry.ring_of.iter().zip(p) {
            let b = b as usize;
            if b != ring {
                self.ring_sum[ring] = run;
                (ring, run) = (b, self.ring_sum[b]);
            }
            run += v;
        }
        self.ring_sum[ring] = run;
        for (b, s) in self.ring_sum[..geometry.rings].iter().enumerate() {
            if geometry.ring_count[b] > 0.0 {
                let mean = s / geometry.ring_count[b];
                self.ring[b].0 += mean;
                self.ring[b].1 += mean * mean;
            }
        }
        for (w, acc) in weights.iter().zip(self.weighted.iter_mut()) {
            // The folded weights are zero at DC.
            let value: f64 = w.iter().zip(p).map(|(w, p)| w * p).sum();
            acc.0 += value;
            acc.1 += value * value;
        }
    }

    fn merge(&mut self, other: &Moments) {
        // The merges run between batches of realizations, with the other threads idle: the two
        // large sums are added side by side (element by element, so the same bits).
        let add = |to: &mut [f64], from: &[f64]| {
            for (a, b) in to.iter_mut().zip(from) {
                *a += b;
            }
        };
        rayon::join(
            || add(&mut self.sum, &other.sum),
            || add(&mut self.sum_sq, &other.sum_sq),
        );
        for (a, b) in self.ring.iter_mut().zip(&other.ring) {
            a.0 += b.0;
            a.1 += b.1;
        }
        for (a, b) in self.weighted.iter_mut().zip(&other.weighted) {
            a.0 += b.0;
            a.1 += b.1;
        }
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
/// count): realizations are reduced in fixed chunks, in order.
pub struct SpectrumAccumulator<'a> {
    source: PatternSource<'a>,
    params: SpectrumParams,
    planned: Planned,
    geometry: Geometry,
    weights: Vec<Vec<f64>>,
    total: Moments,
    realizations: usize,
    workspaces: Mutex<Vec<Workspace>>,
    spare_moments: Mutex<Vec<Moments>>,
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
            workspaces: Mutex::new(Vec::new()),
            spare_moments: Mutex::new(Vec::new()),
        })
    }

    /// Realizations accumulated so far.
    pub fn realizations(&self) -> usize {
        self.realizations
    }

    /// Adds realizations until there are `target` (a multiple of the reduction chunk of 4
    /// unless it is the last), advancing `progress` by one per realization.
    ///
    /// # Errors
    /// A sampler error, more realizations than the given sets hold, or a target below the
    /// realizations already accumulated that is not a continuation.
    pub fn extend_to(&mut self, target: usize, progress: &dyn Progress) -> Result<()> {
        if let Some(available) = self.source.available() {
            if target > available {
                return Err(invalid(
                    "realizations",
                    target,
                    format!("at most the {available} point sets given"),
                ));
            }
        }
        if target == 0 && self.realizations == 0 {
            return Err(invalid("realizations", 0, "at least 1"));
        }
        if !self.realizations.is_multiple_of(REDUCE_CHUNK) && target > self.realizations {
            return Err(invalid(
                "realizations",
                self.realizations,
                "a multiple of 4 before an estimate is extended",
            ));
        }
        let more = target.saturating_sub(self.realizations);
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
        let first_chunk = self.realizations / REDUCE_CHUNK;
        let chunk_count = target.div_ceil(REDUCE_CHUNK);
        let g = &self.geometry;
        // Chunks are merged in their own order, so the sums do not depend on the thread count; a
        // batch of chunks at a time bounds the memory to a few sets of moments per thread. The
        // workspaces are pooled: fresh buffers of tens of MB cost more in page faults than a
        // transform.
        let batch = 2 * rayon::current_num_threads().max(1);
        for first in (first_chunk..chunk_count).step_by(batch) {
            let chunks: Vec<Result<Moments>> = (first..(first + batch).min(chunk_count))
                .into_par_iter()
                .map(|c| {
                    let mut work = self.take_workspace();
                    let mut moments = self.take_moments();
                    for r in c * REDUCE_CHUNK..((c + 1) * REDUCE_CHUNK).min(target) {
                        self.planned
                            .half_periodogram(&self.source.realization(r)?, &mut work)?;
                        moments.add(&work.half_power, g, &self.weights);
                        progress.advance(1);
                    }
                    self.give_back(work);
                    Ok(moments)
                })
                .collect();
            for c in chunks {
                let c = c?;
                self.total.merge(&c);
                if let Ok(mut spare) = self.spare_moments.lock() {
                    spare.push(c);
                }
            }
        }
        self.realizations = target.max(self.realizations);
        Ok(())
    }

    fn take_workspace(&self) -> Workspace {
        let spare = self.workspaces.lock().ok().and_then(|mut s| s.pop());
        spare.unwrap_or_else(|| self.planned.workspace())
    }

    fn take_moments(&self) -> Moments {
        let spare = self.spare_moments.lock().ok().and_then(|mut s| s.pop());
        let mut moments = spare.unwrap_or_else(|| {
            let g = &self.geometry;
            Moments::new(g.lattice.dc_index() + 1, g.rings, self.weights.len())
        });
        moments.clear();
        moments
    }

    fn give_back(&self, work: Workspace) {
        if let Ok(mut s) = self.workspaces.lock() {
            s.push(work);
        }
    }

    /// The per-realization sums `Σ_k w(k) P_r(k)` of each weight vector: their mean over the
    /// realizations so far, and its standard error.
    pub fn weighted(&self) -> Vec<WeightedMean> {
        let m = self.realizations as f64;
        self.total
            .weighted
            .iter()
            .map(|&(s, s2)| {
                let mean = s / m;
                WeightedMean {
                    mean,
                    stderr: if self.realizations > 1 {
                        ((s2 / m - mean * mean).max(0.0) / (m - 1.0)).sqrt()
                    } else {
                        f64::NAN
                    },
                    realizations: self.realizations,
                }
            })
            .collect()
    }

    /// The estimate from the realizations so far.
    pub fn estimate(&self) -> SpectrumEstimate {
        let m = self.realizations;
        let mf = m as f64;
        let half_mean: Vec<f64> = self.total.sum.iter().map(|s| s / mf).collect();
        let lattice = self.geometry.lattice;
        let n = self.source.points();
        // The lattice's mean and standard error, and the rings: independent, side by side.
        let ((mean, stderr), radial) = rayon::join(
            || {
                let half_stderr: Vec<f64> = self
                    .total
                    .sum_sq
                    .iter()
                    .zip(&half_mean)
                    .map(|(s2, mu)| {
                        if m > 1 {
                            ((s2 / mf - mu * mu).max(0.0) / (mf - 1.0)).sqrt()
                        } else {
                            f64::NAN
                        }
                    })
                    .collect();
                (
                    super::mirror(&half_mean, lattice.len()),
                    super::mirror(&half_stderr, lattice.len()),
                )
            },
            || {
                RadialSpectrum::from_parts(
                    &lattice,
                    &half_mean,
                    n,
                    m,
                    (&self.geometry.ring_of, self.geometry.rings),
                    self.params.bin_width,
                    &self.total.ring,
                )
            },
        );
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

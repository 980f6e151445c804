//! Gaussian blue noise: points that descend a Gaussian-kernel energy on the torus (after Ahmed,
//! Ren and Wonka 2022, "Gaussian Blue Noise").
//!
//! The energy of a pattern is `E = Σ_{i≠j} exp(-|x_i - x_j|² / (2σ²))` with toroidal
//! distances and `σ = c · N^{-1/d}` a fixed fraction of the mean spacing. Its gradient pushes
//! every point away from its neighbours, most strongly from the nearest; gradient descent from
//! white noise (jitter in 1D) spreads the points evenly while the kernel's short reach and the
//! few steps leave the pattern without long-range order.
//!
//! The descent relaxes a density wave of scaled frequency `ν` like diffusion, its power falling
//! as `exp(-ν²/ν_r²)` over the steps: with the default 100 steps the spectrum is about 1e-6
//! from `ν ≈ 0.03` to its rise near `ν ≈ 0.5`, but climbs back to white noise's below
//! `ν_r ≈ 0.0085` (0.29 in the lowest ring at N = 16384). The spectrum is a function of `ν` alone
//! (every length is in spacings), its `α` is 0, and integration converges like `N^{-1}` once N
//! is so large that an integrand's power reaches below `ν_r` (`docs/theory.md`). Each step moves every point from the same old positions (a Jacobi
//! step), so a pattern is the same bits for any thread count.

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::{check_positive, check_supported, uniform, Sampler, SamplerKind};
use crate::error::{invalid, Result};
use crate::pointset::{near_delta, toroidal_delta, wrap, PointSet, MAX_DIMENSION};
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};
use crate::vector_exp::exp_in_place;
use rayon::prelude::*;

/// Gaussian blue noise.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "gbn",
    description:
        "Gaussian blue noise (after Ahmed et al. 2022): descent of a Gaussian-kernel energy",
    dimensions: 1..=3,
    count: CountRule::Any,
    balanced_counts: CountRule::Any,
    randomness: Randomness::Relaxed,
    native_randomization: Randomization::None,
    cells: CellRule::None,
    cell_law: CellLaw::NoCells,
    closed_form: ClosedFormRule::None,
    known_alpha: Some(0.0),
    scaling: Scaling::Invariant,
    isotropic: true,
    symmetry: Symmetry::Cube,
    correlation_reach: RELAXED_REACH,
    axis_strata: super::AxisStrata::Spacing,
    cost_per_point_ns: 45_000.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerDimension(8.5),
    working_bytes: super::facts::one_word_per_point,
};

/// The scaled frequency `ν_r` below which the descent leaves density waves unrelaxed: the power
/// left at `ν` falls like `exp(-ν²/ν_r²)` (measured in 2D at N = 16384, `docs/theory.md`).
const RELAXATION_FREQUENCY: f64 = 0.0085;

/// How far the pair correlations reach, in spacings: the spectrum's drop from white to blue over
/// `ν ≈ ν_r` is a Gaussian component of `g − 1` with standard deviation `1/(√2 π ν_r)` (26.5
/// spacings), counted to three of them. Far beyond the nearest neighbours: routes that assume
/// short correlations (the polar form's images, the low band's smoothness) see it.
const RELAXED_REACH: f64 =
    3.0 / (std::f64::consts::SQRT_2 * std::f64::consts::PI * RELAXATION_FREQUENCY);

/// The kernel is cut where it falls below `exp(-CUTOFF_SIGMAS² / 2)` (3e-4 of its peak).
const CUTOFF_SIGMAS: f64 = 4.0;

/// Parameters of the descent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GbnParams {
    /// The kernel's standard deviation in mean spacings `N^{-1/d}`.
    pub sigma: f64,
    /// Gradient steps.
    pub iterations: usize,
    /// The step, relative to the kernel's mass: a point moves by
    /// `(step / S) Σ_j (x_i - x_j) exp(-|x_i - x_j|²/(2σ²))`, with `S = (2π)^{d/2} c^d` the
    /// continuum value of `Σ_j exp(…)` at width `c` spacings, so that the same step is as
    /// stable in every dimension and at every width (the descent oscillates above about 2.5).
    pub step: f64,
}

impl Default for GbnParams {
    fn default() -> Self {
        Self {
            sigma: DEFAULT_SIGMA,
            iterations: DEFAULT_ITERATIONS,
            step: DEFAULT_STEP,
        }
    }
}

/// The default kernel width, in spacings (see `docs/theory.md` for the measured choice).
pub const DEFAULT_SIGMA: f64 = 0.9;
/// The default number of gradient steps.
pub const DEFAULT_ITERATIONS: usize = 100;
/// The default step.
pub const DEFAULT_STEP: f64 = 2.0;

/// Gaussian blue noise in 1 to 3 dimensions, any N.
#[derive(Debug, Clone, Copy)]
pub struct GaussianBlueNoise {
    dimension: usize,
    params: GbnParams,
}

impl GaussianBlueNoise {
    /// Gaussian blue noise in dimension `d` (1 to 3) with the default parameters.
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        Self::with_params(d, GbnParams::default())
    }

    /// Gaussian blue noise with the given parameters.
    ///
    /// # Errors
    /// An unsupported dimension, a width outside 0.1–2 spacings, no iterations, or a step
    /// outside (0, 2.5].
    pub fn with_params(d: usize, params: GbnParams) -> Result<Self> {
        check_supported(&FACTS, d)?;
        if !(0.1..=2.0).contains(&params.sigma) {
            return Err(invalid("GBN sigma", params.sigma, "0.1 to 2 spacings"));
        }
        if params.iterations == 0 || params.iterations > 100_000 {
            return Err(invalid("GBN iterations", params.iterations, "1 to 100000"));
        }
        if !(params.step > 0.0 && params.step <= 2.5) {
            return Err(invalid("GBN step", params.step, "in (0, 2.5]"));
        }
        Ok(Self {
            dimension: d,
            params,
        })
    }
}

impl GaussianBlueNoise {
    /// The energy `Σ_{i≠j} exp(-|x_i - x_j|²/(2σ²))` over the pairs closer than `4σ` (the
    /// kernel's cut-off) that the descent lowers, at this sampler's width for `points.len()` points.
    pub fn energy(&self, points: &PointSet) -> f64 {
        let (n, d) = (points.len(), points.dimension());
        let sigma = self.params.sigma * (n as f64).powf(-1.0 / d as f64);
        let mut cells = Cells::new(d, CUTOFF_SIGMAS * sigma, n);
        let x = points.coords();
        cells.sort(x);
        let inv = -1.0 / (2.0 * sigma * sigma);
        let cut2 = cells.reach * cells.reach;
        (0..n)
            .map(|i| {
                let xi = &x[i * d..(i + 1) * d];
                let mut e = 0.0;
                cells.for_each_near(xi, |j| {
                    let r2: f64 = (0..d)
                        .map(|a| toroidal_delta(xi[a], x[j * d + a]).powi(2))
                        .sum();
                    if j != i && r2 < cut2 {
                        e += (r2 * inv).exp();
                    }
                });
                e
            })
            .sum()
    }
}

impl Sampler for GaussianBlueNoise {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::GaussianBlueNoise)
    }
    fn check_count(&self, n: usize) -> Result<()> {
        check_positive(self.name(), self.dimension, n)?;
        if n > u32::MAX as usize {
            return Err(invalid("N", n, "at most 2^32 - 1 for gbn"));
        }
        Ok(())
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let d = self.dimension;
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let mut x: Vec<f64> = (0..n * d).map(|_| uniform(&mut rng)).collect();
        if d == 1 {
            // The descent relaxes a mode of wavelength 1/k in about (N/k)² steps: in 1D, where
            // the lowest modes would keep white noise's power, start from jitter instead.
            for (i, xi) in x.iter_mut().enumerate() {
                *xi = (i as f64 + *xi) / n as f64;
            }
        }
        let sigma = self.params.sigma * (n as f64).powf(-1.0 / d as f64);
        let mass =
            (2.0 * std::f64::consts::PI).powf(d as f64 / 2.0) * self.params.sigma.powi(d as i32);
        let step = self.params.step / mass;
        let mut cells = Cells::new(d, CUTOFF_SIGMAS * sigma, n);
        let mut next = vec![0.0; n * d];
        let mut by_cell = vec![0.0; n * d];
        for _ in 0..self.params.iterations {
            cells.sort(&x);
            descend(&x, &cells, sigma, step, &mut by_cell, &mut next);
            std::mem::swap(&mut x, &mut next);
        }
        PointSet::new(d, x)
    }
}

/// One Jacobi step: every point's new position from the old ones.
///
/// The points of one cell share their neighbourhood, so it is gathered once per cell into
/// contiguous coordinates, in the order in which [`Cells::for_each_near`] visits it; each
/// point's force then sums its neighbours in that order, the same sum term by term. The new
/// positions go to `by_cell` in the points' cell order, then to `out` in theirs.
fn descend(x: &[f64], cells: &Cells, sigma: f64, step: f64, by_cell: &mut [f64], out: &mut [f64]) {
    let d = cells.d;
    // The slices of `by_cell` that each cell's points fill.
    let mut rest = &mut by_cell[..];
    let mut slices = Vec::with_capacity(cells.homes());
    for h in 0..cells.homes() {
        let (range_start, range_end) = cells.home_range(h);
        let (head, tail) = rest.split_at_mut((range_end - range_start) * d);
        slices.push((h, head));
        rest = tail;
    }
    let force = Force::new(sigma, cells.reach);
    slices.into_par_iter().for_each_init(
        || Neighbourhood::new(d),
        |block, (h, new)| {
            block.gather(x, cells, h);
            let (lo, _) = cells.home_range(h);
            for (k, new) in new.chunks_exact_mut(d).enumerate() {
                let i = cells.order[lo + k] as usize;
                let xi = &x[i * d..(i + 1) * d];
                let f = force.on(i, xi, block);
                for a in 0..d {
                    new[a] = wrap(xi[a] + step * f[a]);
                }
            }
        },
    );
    for (k, &i) in cells.order.iter().enumerate() {
        let i = i as usize;
        out[i * d..(i + 1) * d].copy_from_slice(&by_cell[k * d..(k + 1) * d]);
    }
}

/// The kernel's force on a point from a gathered neighbourhood.
struct Force {
    inv: f64,
    cut2: f64,
}

impl Force {
    fn new(sigma: f64, reach: f64) -> Self {
        Self {
            inv: -1.0 / (2.0 * sigma * sigma),
            cut2: reach * reach,
        }
    }

    /// `Σ_j (x_i - x_j) exp(-|x_i - x_j|²/(2σ²))` over the neighbours within the cut-off, in
    /// the neighbourhood's order; first the squared distances of all of them (a loop without
    /// branches), then the exponents of those within the cut-off, gathered and raised together
    /// by [`exp_in_place`] (the descent's cost was one library `exp` per pair), then the sum.
    fn on(&self, i: usize, xi: &[f64], block: &mut Neighbourhood) -> [f64; MAX_DIMENSION] {
        let d = block.d;
        let len = block.ids.len();
        block.r2.clear();
        block.r2.resize(len, 0.0);
        for a in 0..d {
            let (column, r2) = (&block.coords[a * len..(a + 1) * len], &mut block.r2);
            for (r, &xj) in r2.iter_mut().zip(column) {
                let t = near_delta(xi[a], xj);
                *r += t * t;
            }
        }
        // Kept without branches (each slot is written, and the count moves on only for a
        // neighbour within the cut-off): about a third of the block is, in no predictable order.
        block.near.resize(len, 0);
        block.weights.resize(len, 0.0);
        let mut kept = 0;
        for (k, (&r2, &id)) in block.r2.iter().zip(&block.ids).enumerate() {
            block.near[kept] = k as u32;
            block.weights[kept] = r2 * self.inv;
            kept += usize::from(r2 < self.cut2 && id as usize != i);
        }
        let weights = &mut block.weights[..kept];
        exp_in_place(weights);
        let mut force = [0.0; MAX_DIMENSION];
        for (&k, &w) in block.near[..kept].iter().zip(weights.iter()) {
            for a in 0..d {
                // `near_delta` is `toroidal_delta` by selects (coordinates differ by less than
                // 1), up to the sign of a zero, which adds nothing to the sum.
                force[a] += near_delta(xi[a], block.coords[a * len + k as usize]) * w;
            }
        }
        force
    }
}

/// The points around one cell, in visiting order: their indices and their coordinates, axis
/// by axis; and one point's scratch: squared distances to them all, and the positions and
/// kernel values of those within the cut-off.
struct Neighbourhood {
    d: usize,
    ids: Vec<u32>,
    coords: Vec<f64>,
    r2: Vec<f64>,
    near: Vec<u32>,
    weights: Vec<f64>,
}

impl Neighbourhood {
    fn new(d: usize) -> Self {
        Self {
            d,
            ids: Vec::new(),
            coords: Vec::new(),
            r2: Vec::new(),
            near: Vec::new(),
            weights: Vec::new(),
        }
    }

    fn gather(&mut self, x: &[f64], cells: &Cells, home: usize) {
        let d = self.d;
        self.ids.clear();
        cells.for_each_near_home(home, |j| self.ids.push(j as u32));
        let len = self.ids.len();
        self.coords.clear();
        self.coords.resize(len * d, 0.0);
        for (k, &j) in self.ids.iter().enumerate() {
            for a in 0..d {
                self.coords[a * len + k] = x[j as usize * d + a];
            }
        }
    }
}

/// Points sorted into `g^d` cells of side at least `reach` (a counting sort, stable in the
/// point index), so that the points within `reach` of any point lie in its `3^d` neighbouring
/// cells; with fewer than 3 cells per axis every point is a neighbour of every other.
struct Cells {
    d: usize,
    g: usize,
    reach: f64,
    start: Vec<u32>,
    order: Vec<u32>,
}

impl Cells {
    fn new(d: usize, reach: f64, n: usize) -> Self {
        let g = ((1.0 / reach).floor() as usize).clamp(1, 1 << (30 / d));
        Self {
            d,
            g,
            reach,
            start: vec![0; g.pow(d as u32) + 1],
            order: vec![0; n],
        }
    }

    fn cell(&self, p: &[f64]) -> usize {
        (0..self.d).fold(0, |acc, a| {
            acc * self.g + ((p[a] * self.g as f64) as usize).min(self.g - 1)
        })
    }

    fn sort(&mut self, x: &[f64]) {
        self.start.fill(0);
        for p in x.chunks_exact(self.d) {
            let c = self.cell(p);
            self.start[c + 1] += 1;
        }
        for c in 1..self.start.len() {
            self.start[c] += self.start[c - 1];
        }
        let mut fill = self.start.clone();
        for (i, p) in x.chunks_exact(self.d).enumerate() {
            let c = self.cell(p);
            self.order[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
    }

    /// The groups of points that share a neighbourhood: the cells, or, when the grid has
    /// fewer than 3 cells per axis, all the points as one.
    fn homes(&self) -> usize {
        if self.g < 3 {
            1
        } else {
            self.start.len() - 1
        }
    }

    /// The positions in `order` of the points of group `h` (see [`Cells::homes`]).
    fn home_range(&self, h: usize) -> (usize, usize) {
        if self.g < 3 {
            (0, self.order.len())
        } else {
            (self.start[h] as usize, self.start[h + 1] as usize)
        }
    }

    /// Calls `visit` with every point in the cells around `p` (every point, when the grid has
    /// fewer than 3 cells per axis), each once.
    fn for_each_near(&self, p: &[f64], visit: impl FnMut(usize)) {
        let home = if self.g < 3 { 0 } else { self.cell(p) };
        self.for_each_near_home(home, visit);
    }

    /// [`Cells::for_each_near`] for the points of group `h`.
    fn for_each_near_home(&self, h: usize, mut visit: impl FnMut(usize)) {
        if self.g < 3 {
            self.order.iter().for_each(|&j| visit(j as usize));
            return;
        }
        let g = self.g as isize;
        let mut home = [0isize; 3];
        let mut rest = h;
        for a in (0..self.d).rev() {
            home[a] = (rest % self.g) as isize;
            rest /= self.g;
        }
        let offsets = 3usize.pow(self.d as u32);
        for o in 0..offsets {
            let mut flat = 0usize;
            let mut rest = o;
            for a in 0..self.d {
                let step = (rest % 3) as isize - 1;
                rest /= 3;
                flat = flat * self.g + (home[a] + step).rem_euclid(g) as usize;
            }
            let (lo, hi) = (self.start[flat] as usize, self.start[flat + 1] as usize);
            self.order[lo..hi].iter().for_each(|&j| visit(j as usize));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbouring_cells_hold_every_point_within_reach_once() {
        let d = 2;
        let mut rng = realization_rng(3, 0, Stream::Points);
        let x: Vec<f64> = (0..400 * d).map(|_| uniform(&mut rng)).collect();
        let mut cells = Cells::new(d, 0.13, 400);
        cells.sort(&x);
        for i in 0..400 {
            let mut seen = vec![0; 400];
            cells.for_each_near(&x[i * d..(i + 1) * d], |j| seen[j] += 1);
            for j in 0..400 {
                let r2: f64 = (0..d)
                    .map(|a| toroidal_delta(x[i * d + a], x[j * d + a]).powi(2))
                    .sum();
                assert!(seen[j] <= 1);
                if r2 < 0.13 * 0.13 {
                    assert_eq!(seen[j], 1, "{i} {j}");
                }
            }
        }
    }
}

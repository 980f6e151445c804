//! Poisson disk sampling on the torus: dart throwing and Bridson's algorithm.
//!
//! The minimum distance is `r = relative_radius · r_max(N, d)`, where `r_max` is the distance
//! between neighbours in the densest packing of N equal balls on the unit torus:
//!
//! `r_max = 2 (η_d / (N V_d))^{1/d}` with `V_d` the unit-ball volume and `η_d` the packing
//! density (1 in 1D, `π/(2√3)` for the hexagonal packing in 2D, `π/(3√2)` for FCC in 3D).
//! In 2D this is `r_max = √(2 / (√3 N))` (Lagae and Dutré 2008).

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::{check_supported, uniform, uniform_index, Sampler, SamplerKind};
use crate::error::{invalid, Error, Result};
use crate::pointset::{toroidal_distance_sq, toroidal_square, wrap, PointSet};
use crate::randomization::Randomization;
use crate::rng::{realization_rng, splitmix64, Stream};
use rand_pcg::Pcg64;
use std::f64::consts::PI;

/// Poisson disk by dart throwing (its grid of candidates: 64 bytes a point).
pub(crate) const DART_FACTS: SamplerFacts = SamplerFacts {
    name: "poisson",
    description: "Poisson disk: toroidal dart throwing, relative radius 0.75 (0.65 in 1D)",
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
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Spacing,
    cost_per_point_ns: 4_500.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerDimension(5.3),
    working_bytes: |n, _| n * 64.0,
};

/// Poisson disk by Bridson's algorithm.
pub(crate) const BRIDSON_FACTS: SamplerFacts = SamplerFacts {
    name: "bridson",
    description: "Poisson disk: Bridson's algorithm on the torus, thinned to N",
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
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Spacing,
    cost_per_point_ns: 8_400.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerDimension(4.1),
    working_bytes: |n, _| n * 64.0,
};

/// The neighbour distance of the densest packing of `n` balls on the unit `d`-torus.
///
/// # Examples
/// ```
/// let r = specvar::sampler::max_packing_radius(2, 100);
/// assert!((r - (2.0 / (3f64.sqrt() * 100.0)).sqrt()).abs() < 1e-15);
/// ```
pub fn max_packing_radius(d: usize, n: usize) -> f64 {
    let (density, ball_volume) = match d {
        1 => (1.0, 2.0),
        2 => (PI / (2.0 * 3f64.sqrt()), PI),
        _ => (PI / (3.0 * 2f64.sqrt()), 4.0 * PI / 3.0),
    };
    2.0 * (density / (n as f64 * ball_volume)).powf(1.0 / d as f64)
}

/// Which generator a [`PoissonDisk`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PoissonMethod {
    /// Uniform dart throwing: each accepted point is uniform over the still-uncovered region
    /// (random sequential adsorption). Darts are thrown only into cells that may still hold
    /// uncovered space (Ebeida et al. 2011), which gives the same distribution faster.
    DartThrowing,
    /// Bridson's algorithm (2007): candidates in the annulus `[r, 2r]` around active points,
    /// 30 tries each, run until no point is active. The gaps this leaves are then filled by
    /// dart throwing (as above) until N points are placed, and a set larger than N is thinned
    /// by removing uniformly chosen points (which keeps the minimum distance).
    Bridson,
}

/// Poisson disk sampling in 1 to 3 dimensions with a relative radius
/// (default [`default_relative_radius`]).
#[derive(Debug, Clone, Copy)]
pub struct PoissonDisk {
    dimension: usize,
    relative_radius: f64,
    method: PoissonMethod,
}

/// The default relative radius: 0.75 in 2D and 3D, 0.65 in 1D.
///
/// Dart throwing jams at a packing fraction of 0.7476 in 1D (Rényi's parking constant), about
/// 0.547 in 2D and 0.38 in 3D. Relative radius `ρ` fills a fraction `η_d ρ^d` of the torus:
/// 0.75 gives 0.51 in 2D and 0.31 in 3D, below jamming, but 0.75 in 1D, above it; 0.65 in 1D
/// stays below.
pub fn default_relative_radius(d: usize) -> f64 {
    if d == 1 {
        0.65
    } else {
        0.75
    }
}

/// Deepest subdivision of the active cells; below it, a round of darts that places nothing
/// ends the run (uncovered gaps then measure under `h · 2^-12`).
const MAX_LEVEL: u32 = 12;
/// Attempts before a saturated run is reported as an error.
pub const MAX_ATTEMPTS: u64 = 64;
/// Bridson's candidate count per active point.
const BRIDSON_TRIES: usize = 30;

impl PoissonDisk {
    /// Dart throwing at the default relative radius in dimension `d` (1 to 3).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&DART_FACTS, d)?;
        Ok(Self {
            dimension: d,
            relative_radius: default_relative_radius(d),
            method: PoissonMethod::DartThrowing,
        })
    }

    /// Sets the relative radius `r / r_max`.
    ///
    /// # Errors
    /// Outside `(0, 1]`.
    pub fn with_relative_radius(mut self, relative_radius: f64) -> Result<Self> {
        if !(relative_radius > 0.0 && relative_radius <= 1.0) {
            return Err(invalid("relative radius", relative_radius, "in (0, 1]"));
        }
        self.relative_radius = relative_radius;
        Ok(self)
    }

    /// Chooses the generator.
    pub fn with_method(mut self, method: PoissonMethod) -> Self {
        self.method = method;
        self
    }

    /// The minimum distance used for `n` points.
    pub fn radius(&self, n: usize) -> f64 {
        self.relative_radius * max_packing_radius(self.dimension, n)
    }
}

impl Sampler for PoissonDisk {
    fn name(&self) -> &'static str {
        match self.method {
            PoissonMethod::DartThrowing => DART_FACTS.name,
            PoissonMethod::Bridson => BRIDSON_FACTS.name,
        }
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(match self.method {
            PoissonMethod::DartThrowing => SamplerKind::PoissonDisk,
            PoissonMethod::Bridson => SamplerKind::Bridson,
        })
    }
    /// A run that fills the torus before placing N points (jamming fluctuates most at small
    /// N) restarts from the next attempt's stream, up to [`MAX_ATTEMPTS`] times: the pattern is
    /// dart throwing conditioned on reaching N. Attempts are keyed by (seed, realization,
    /// attempt), so the result is still reproducible.
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let r = self.radius(n);
        let mut last = None;
        for attempt in 0..MAX_ATTEMPTS {
            let key = if attempt == 0 {
                seed
            } else {
                splitmix64(seed ^ splitmix64(attempt))
            };
            let mut rng = realization_rng(key, realization, Stream::Points);
            let mut grid = Grid::new(self.dimension, r, n);
            let outcome = match self.method {
                PoissonMethod::DartThrowing => dart_throwing(&mut grid, n, &mut rng),
                PoissonMethod::Bridson => bridson(&mut grid, n, &mut rng),
            };
            match outcome {
                Ok(()) => return Ok(PointSet::from_trusted(self.dimension, grid.points)),
                Err(e @ Error::Saturated { .. }) => last = Some(e),
                Err(e) => return Err(e),
            }
        }
        Err(last.unwrap_or(Error::Saturated {
            method: "dart throwing",
            placed: 0,
            requested: n,
            radius: r,
        }))
    }
}

/// A background grid of `g^d` cells of side `1/g ≤ r/√d`: a cell holds at most one point.
struct Grid {
    d: usize,
    g: usize,
    r2: f64,
    cells: Vec<u32>,
    points: Vec<f64>,
    /// How many cells away a point within `r` can lie.
    reach: isize,
}

/// Largest `2 reach + 1`: `reach = ⌈r g⌉ ≤ ⌈√d⌉ + 1 ≤ 3`.
const MAX_SPAN: usize = 7;

const EMPTY: u32 = u32::MAX;

impl Grid {
    fn new(d: usize, r: f64, n: usize) -> Self {
        let g = ((d as f64).sqrt() / r).ceil().max(1.0) as usize;
        let reach = (r * g as f64).ceil() as isize;
        debug_assert!((2 * reach + 1) as usize <= MAX_SPAN);
        Self {
            d,
            g,
            r2: r * r,
            cells: vec![EMPTY; g.pow(d as u32)],
            points: Vec::with_capacity(n * d),
            reach,
        }
    }

    fn len(&self) -> usize {
        self.points.len() / self.d
    }

    fn cell_of(&self, p: &[f64]) -> [usize; 3] {
        let mut c = [0; 3];
        for a in 0..self.d {
            c[a] = ((p[a] * self.g as f64) as usize).min(self.g - 1);
        }
        c
    }

    fn flat(&self, c: [usize; 3]) -> usize {
        (0..self.d).fold(0, |acc, a| acc * self.g + c[a])
    }

    /// Calls `visit` with each point index in the cells around cell `c` until it returns true.
    fn any_neighbour(&self, c: [usize; 3], mut visit: impl FnMut(usize) -> bool) -> bool {
        let g = self.g as isize;
        let span = (2 * self.reach + 1) as usize;
        // Wrapped cell coordinates along each axis, computed once per call.
        let mut axis = [[0usize; MAX_SPAN]; 3];
        for a in 0..3 {
            for (k, slot) in axis[a].iter_mut().enumerate().take(span) {
                *slot = if a < self.d {
                    (c[a] as isize + k as isize - self.reach).rem_euclid(g) as usize
                } else {
                    0
                };
            }
        }
        let extent = |a: usize| if a < self.d { span } else { 1 };
        for &x in &axis[0][..extent(0)] {
            for &y in &axis[1][..extent(1)] {
                let row = if self.d >= 2 { x * self.g + y } else { x };
                for &z in &axis[2][..extent(2)] {
                    let flat = if self.d == 3 { row * self.g + z } else { row };
                    let idx = self.cells[flat];
                    if idx != EMPTY && visit(idx as usize) {
                        return true;
                    }
                }
            }
        }
        false
    }

    fn point(&self, i: usize) -> &[f64] {
        &self.points[i * self.d..(i + 1) * self.d]
    }

    fn conflicts(&self, p: &[f64]) -> bool {
        let c = self.cell_of(p);
        if self.cells[self.flat(c)] != EMPTY {
            return true;
        }
        self.any_neighbour(c, |i| toroidal_distance_sq(self.point(i), p) < self.r2)
    }

    fn insert(&mut self, p: &[f64]) {
        let c = self.flat(self.cell_of(p));
        self.cells[c] = self.len() as u32;
        self.points.extend_from_slice(p);
    }

    /// The coordinates of the points in the cells around base cell `c` (those that can cover a
    /// part of it), in `out`.
    fn points_near(&self, c: [usize; 3], out: &mut Vec<f64>) {
        out.clear();
        self.any_neighbour(c, |i| {
            out.extend_from_slice(self.point(i));
            false
        });
    }

    /// Whether one of the points `near` (those around the sub-cell's base cell) covers the
    /// whole sub-cell `c` of side `1/(g 2^level)`: a ball is convex, so covering the 2^d
    /// corners suffices.
    ///
    /// A corner's squared distance is a sum over the axes of the squared distance to the
    /// cell's lower or upper side on that axis; the corner taking the larger on every axis is
    /// the farthest, and rounding, which never decreases a sum when a term grows, keeps it the
    /// largest computed sum too. So one sum of the axes' larger terms decides for all the
    /// corners, with the same bits as that corner's own distance.
    fn covers_subcell(&self, near: &[f64], c: &[u32; 3], level: u32) -> bool {
        let d = self.d;
        let side = 1.0 / (self.g as f64 * (1u64 << level) as f64);
        let mut sides = [[0.0f64; 2]; 3];
        for a in 0..d {
            sides[a] = [c[a] as f64 * side, (c[a] as f64 + 1.0) * side];
        }
        near.chunks_exact(d).any(|q| {
            let farthest: f64 = (0..d)
                .map(|a| {
                    let [lo, hi] = sides[a];
                    toroidal_square(q[a] - lo).max(toroidal_square(q[a] - hi))
                })
                .sum();
            farthest < self.r2
        })
    }

    fn base_cell(&self, c: &[u32; 3], level: u32) -> [usize; 3] {
        let mut b = [0usize; 3];
        for a in 0..self.d {
            b[a] = (c[a] >> level) as usize;
        }
        b
    }

    fn base_occupied(&self, c: &[u32; 3], level: u32) -> bool {
        self.cells[self.flat(self.base_cell(c, level))] != EMPTY
    }
}

/// Dart throwing restricted to active cells, refined level by level, until the grid holds `n`
/// points. Points already in the grid are kept.
fn dart_throwing(grid: &mut Grid, n: usize, rng: &mut Pcg64) -> Result<()> {
    if grid.len() >= n {
        return Ok(());
    }
    let d = grid.d;
    let g = grid.g as u32;
    let mut active: Vec<[u32; 3]> = (0..grid.cells.len())
        .map(|flat| {
            let mut c = [0u32; 3];
            let mut rest = flat as u32;
            for a in (0..d).rev() {
                c[a] = rest % g;
                rest /= g;
            }
            c
        })
        .filter(|c| !grid.base_occupied(c, 0))
        .collect();
    let mut level = 0u32;
    let mut p = [0.0f64; 3];
    loop {
        if active.is_empty() {
            break;
        }
        let side = 1.0 / (g as f64 * (1u64 << level) as f64);
        let placed_before = grid.len();
        for _ in 0..active.len() {
            let c = active[uniform_index(rng, active.len())];
            if grid.base_occupied(&c, level) {
                continue;
            }
            for a in 0..d {
                p[a] = ((c[a] as f64 + uniform(rng)) * side).min(super::ONE_MINUS_EPS);
            }
            if !grid.conflicts(&p[..d]) {
                grid.insert(&p[..d]);
                if grid.len() == n {
                    return Ok(());
                }
            }
        }
        if level < MAX_LEVEL {
            active = refine(grid, &active, level);
            level += 1;
        } else if grid.len() == placed_before {
            break;
        } else {
            active.retain(|c| !grid.base_occupied(c, level));
        }
    }
    Err(Error::Saturated {
        method: "dart throwing",
        placed: grid.len(),
        requested: n,
        radius: grid.r2.sqrt(),
    })
}

/// Splits every active cell into its 2^d children, keeping those not provably covered. A cell
/// and its children share their base cell, so the points around it are gathered once for all.
fn refine(grid: &Grid, active: &[[u32; 3]], level: u32) -> Vec<[u32; 3]> {
    let d = grid.d;
    let mut next = Vec::with_capacity(active.len() * 2);
    let mut near = Vec::new();
    for c in active {
        if grid.base_occupied(c, level) {
            continue;
        }
        grid.points_near(grid.base_cell(c, level), &mut near);
        if grid.covers_subcell(&near, c, level) {
            continue;
        }
        for bits in 0..1usize << d {
            let mut child = [0u32; 3];
            for a in 0..d {
                child[a] = 2 * c[a] + ((bits >> a) & 1) as u32;
            }
            if !grid.covers_subcell(&near, &child, level + 1) {
                next.push(child);
            }
        }
    }
    next
}

/// A uniform random direction in `d` dimensions (1 to 3).
fn random_direction(d: usize, rng: &mut Pcg64) -> [f64; 3] {
    match d {
        1 => [if uniform(rng) < 0.5 { -1.0 } else { 1.0 }, 0.0, 0.0],
        2 => {
            let t = 2.0 * PI * uniform(rng);
            [t.cos(), t.sin(), 0.0]
        }
        _ => {
            // Archimedes: z uniform on [-1, 1] gives a uniform point on the sphere.
            let z = 2.0 * uniform(rng) - 1.0;
            let t = 2.0 * PI * uniform(rng);
            let s = (1.0 - z * z).sqrt();
            [s * t.cos(), s * t.sin(), z]
        }
    }
}

/// Bridson's algorithm on the torus, then uniform thinning to exactly `n` points.
fn bridson(grid: &mut Grid, n: usize, rng: &mut Pcg64) -> Result<()> {
    let d = grid.d;
    let r = grid.r2.sqrt();
    let mut p = [0.0f64; 3];
    for v in p.iter_mut().take(d) {
        *v = uniform(rng);
    }
    grid.insert(&p[..d]);
    let mut active = vec![0usize];
    let (rd, r2d) = (r.powi(d as i32), (2.0 * r).powi(d as i32));
    while !active.is_empty() {
        let slot = uniform_index(rng, active.len());
        let centre: [f64; 3] = {
            let q = grid.point(active[slot]);
            let mut c = [0.0; 3];
            c[..d].copy_from_slice(q);
            c
        };
        let mut found = false;
        for _ in 0..BRIDSON_TRIES {
            // Uniform in the annulus volume between r and 2r.
            let rho = (rd + uniform(rng) * (r2d - rd)).powf(1.0 / d as f64);
            let dir = random_direction(d, rng);
            for a in 0..d {
                p[a] = wrap(centre[a] + rho * dir[a]);
            }
            if !grid.conflicts(&p[..d]) {
                grid.insert(&p[..d]);
                active.push(grid.len() - 1);
                found = true;
                break;
            }
        }
        if !found {
            active.swap_remove(slot);
        }
    }
    // Thirty tries per point leave gaps; fill them by exact dart throwing before thinning.
    dart_throwing(grid, n, rng).map_err(|e| match e {
        Error::Saturated {
            placed,
            requested,
            radius,
            ..
        } => Error::Saturated {
            method: "Bridson",
            placed,
            requested,
            radius,
        },
        other => other,
    })?;
    let placed = grid.len();
    let keep = super::random_permutation(rng, placed);
    let mut points = Vec::with_capacity(n * d);
    for &i in &keep[..n] {
        points.extend_from_slice(grid.point(i));
    }
    grid.points = points;
    Ok(())
}

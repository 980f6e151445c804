//! Capacity-constrained Voronoi tessellation (Balzer, Schlömer and Deussen 2009) on the torus.
//!
//! The density (uniform) is represented by `M = N · capacity` stratified random points. Each of the N
//! sites owns exactly `capacity` of them. One iteration visits every pair of neighbouring
//! sites `(i, j)` and swaps points between them while that lowers the energy: with
//! `h_i(x) = |x - s_i|² - |x - s_j|²` for points of `i` and `h_j` likewise, the largest `h_i`
//! and `h_j` are exchanged while their sum is positive. Then every site moves to the centroid
//! of its points. Capacities never change, and the energy `Σ |x - s(x)|²` never increases.
//!
//! **Convergence criterion:** an iteration in which no pair swaps any point (the assignment
//! is stable), or `max_iterations`. Neighbouring pairs are the sites closer than
//! `2 N^{-1/d}` (the Voronoi neighbours lie within about `1.5 N^{-1/d}`).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::{check_supported, uniform, PoissonDisk, Sampler, SamplerKind};
use crate::error::{invalid, Result};
use crate::pointset::{near_delta, toroidal_delta, toroidal_distance_sq, wrap, PointSet};
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};

/// CCVT's working memory: its `64 n` discrete points and, while assigning them, about `5^d`
/// candidate pairs of 24 bytes per discrete point.
fn working_bytes(n: f64, d: usize) -> f64 {
    n * 64.0 * (8.0 * d as f64 + 4.0 + 24.0 * 5f64.powi(d as i32))
}

/// CCVT (its low-frequency exponent is explained at [`SamplerKind::known_alpha`](super::SamplerKind::known_alpha)).
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "ccvt",
    description: "capacity-constrained Voronoi tessellation (Balzer et al. 2009)",
    dimensions: 1..=3,
    count: CountRule::Any,
    balanced_counts: CountRule::Any,
    randomness: Randomness::Relaxed,
    native_randomization: Randomization::None,
    cells: CellRule::None,
    cell_law: CellLaw::NoCells,
    closed_form: ClosedFormRule::None,
    known_alpha: Some(2.0),
    scaling: Scaling::Invariant,
    isotropic: true,
    symmetry: Symmetry::Cube,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Spacing,
    cost_per_point_ns: 85_000.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerDimension(4.5),
    working_bytes,
};

/// CCVT parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CcvtParams {
    /// Discrete points per site (Balzer et al. use up to 1024; more is smoother and slower).
    pub capacity: usize,
    /// Iteration cap, for patterns that keep swapping a few points for long.
    pub max_iterations: usize,
}

impl Default for CcvtParams {
    fn default() -> Self {
        Self {
            capacity: 64,
            max_iterations: 200,
        }
    }
}

/// What a CCVT run did.
#[derive(Debug, Clone, PartialEq)]
pub struct CcvtStats {
    /// Iterations run.
    pub iterations: usize,
    /// Whether the last iteration swapped nothing.
    pub converged: bool,
    /// Mean squared toroidal distance from each discrete point to its site, after each
    /// iteration (recorded by [`Ccvt::generate`]; a plain `sample` skips it).
    pub energy: Vec<f64>,
    /// The number of discrete points each site owns at the end.
    pub capacities: Vec<usize>,
}

/// The CCVT sampler in 1 to 3 dimensions.
#[derive(Debug, Clone, Copy)]
pub struct Ccvt {
    dimension: usize,
    params: CcvtParams,
}

impl Ccvt {
    /// CCVT in dimension `d` (1 to 3) with default parameters.
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self {
            dimension: d,
            params: CcvtParams::default(),
        })
    }

    /// Sets the parameters.
    ///
    /// # Errors
    /// A capacity below 2 or zero iterations.
    pub fn with_params(mut self, params: CcvtParams) -> Result<Self> {
        if params.capacity < 2 {
            return Err(invalid("capacity", params.capacity, "at least 2"));
        }
        if params.max_iterations == 0 {
            return Err(invalid("max_iterations", 0, "at least 1"));
        }
        self.params = params;
        Ok(self)
    }

    /// The floor `a` of the sites' spectrum at low frequencies, `P̆ ≈ a ν²` with
    /// `a = π²/(3c²)` for capacity `c`: each site is the centroid of exactly `c` points of a
    /// jittered discrete density of `cN` points (whose spectrum is `π²|k|²/(3cN)` near DC),
    /// and to second order in `k` a site's phase is the mean of its points' phases, so the
    /// sites' spectrum is the discrete density's divided by `c`. (Exact for `cN = g^d`; with
    /// cells dropped at random the floor gains a white term.)
    pub fn floor_coefficient(&self) -> f64 {
        std::f64::consts::PI.powi(2) / (3.0 * (self.params.capacity as f64).powi(2))
    }

    /// Generates one realization and reports how the optimization went.
    ///
    /// # Errors
    /// `n = 0`.
    pub fn generate(&self, n: usize, seed: u64, realization: u64) -> Result<(PointSet, CcvtStats)> {
        self.run(n, seed, realization, true)
    }

    /// The optimization; the energy after each iteration is recorded only when asked for
    /// (it is a pass over every discrete point, which the pattern does not need).
    fn run(
        &self,
        n: usize,
        seed: u64,
        realization: u64,
        record_energy: bool,
    ) -> Result<(PointSet, CcvtStats)> {
        self.check_count(n)?;
        let mut state = State::new(self.dimension, n, self.params.capacity, seed, realization);
        let mut energy = Vec::new();
        let mut converged = false;
        let mut iterations = 0;
        while iterations < self.params.max_iterations {
            iterations += 1;
            let swaps = state.swap_pass();
            state.move_sites();
            if record_energy {
                energy.push(state.energy());
            }
            if swaps == 0 {
                converged = true;
                break;
            }
        }
        let capacities = state.owned.iter().map(Owned::len).collect();
        let stats = CcvtStats {
            iterations,
            converged,
            energy,
            capacities,
        };
        Ok((PointSet::from_trusted(self.dimension, state.sites), stats))
    }
}

impl Sampler for Ccvt {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::Ccvt)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.run(n, seed, realization, false).map(|(p, _)| p)
    }
}

/// `m` points representing the uniform density: one jittered point in each cell of the
/// smallest `g^d ≥ m` grid, less `g^d - m` cells chosen at random.
///
/// Sites inherit the low-frequency density fluctuations of these points. Independent uniform
/// points would give the sites a white floor `P ≈ 1/capacity` at low frequency (0.016 at
/// capacity 64); stratified points have almost none, so the sites keep CCVT's deep low band.
fn stratified_density(d: usize, m: usize, seed: u64, realization: u64) -> Vec<f64> {
    let mut rng = realization_rng(seed, realization, Stream::Points);
    let g = (m as f64).powf(1.0 / d as f64).ceil() as usize;
    let g = if g.pow(d as u32) < m { g + 1 } else { g };
    let cells = g.pow(d as u32);
    let mut dropped = vec![false; cells];
    for &c in &super::random_permutation(&mut rng, cells)[..cells - m] {
        dropped[c] = true;
    }
    let mut points = Vec::with_capacity(m * d);
    for (c, _) in dropped.iter().enumerate().filter(|&(_, &drop)| !drop) {
        let mut rest = c;
        let mut cell = [0usize; 3];
        for a in (0..d).rev() {
            cell[a] = rest % g;
            rest /= g;
        }
        for a in 0..d {
            points.push(super::in_cell(cell[a], uniform(&mut rng), g));
        }
    }
    points
}

/// Initial sites: a Poisson disk pattern at the sampler's default relative radius.
fn initial_sites(d: usize, n: usize, seed: u64, realization: u64) -> Vec<f64> {
    match PoissonDisk::new(d).and_then(|p| p.sample(n, seed ^ 0xCC07, realization)) {
        Ok(p) => p.coords().to_vec(),
        // Dart throwing below jamming practically never saturates; if it does, start from
        // uniform sites rather than fail.
        Err(_) => {
            let mut rng = realization_rng(seed ^ 0xCC07, realization, Stream::Points);
            (0..n * d).map(|_| uniform(&mut rng)).collect()
        }
    }
}

/// The sites in a toroidal grid of `g^d` cells over the unit cube.
struct SiteGrid {
    d: usize,
    g: usize,
    cells: Vec<Vec<u32>>,
}

impl SiteGrid {
    fn new(d: usize, g: usize, sites: &[f64]) -> Self {
        let mut grid = Self {
            d,
            g,
            cells: vec![Vec::new(); g.pow(d as u32)],
        };
        for (s, site) in sites.chunks_exact(d).enumerate() {
            let c = grid.cell_of(site);
            let flat = c[..d].iter().fold(0, |acc, &x| acc * g + x);
            grid.cells[flat].push(s as u32);
        }
        grid
    }

    fn cell_of(&self, p: &[f64]) -> [usize; 3] {
        let mut c = [0; 3];
        for (c, x) in c.iter_mut().zip(p) {
            *c = ((x * self.g as f64) as usize).min(self.g - 1);
        }
        c
    }

    /// Calls `visit` with each site in the `(2 reach + 1)^d` cells around the cell of `p`,
    /// the first axis's offset varying fastest, cell by cell in the order of their sites. The
    /// cells are distinct when `2 reach < g`.
    fn for_each_near(&self, p: &[f64], reach: usize, mut visit: impl FnMut(u32)) {
        let (d, g) = (self.d, self.g);
        let c = self.cell_of(p);
        let side = 2 * reach + 1;
        let mut offset = [0usize; 3];
        for _ in 0..side.pow(d as u32) {
            let mut flat = 0;
            for a in 0..d {
                // c + offset - reach lies in [-reach, g + reach): one wrap either way.
                let x = c[a] + offset[a] + g - reach;
                let x = if x >= 2 * g {
                    x - 2 * g
                } else if x >= g {
                    x - g
                } else {
                    x
                };
                flat = flat * g + x;
            }
            self.cells[flat].iter().for_each(|&s| visit(s));
            for o in offset[..d].iter_mut() {
                *o += 1;
                if *o < side {
                    break;
                }
                *o = 0;
            }
        }
    }
}

/// Capacity-constrained greedy assignment of points to sites (see [`State::new`]): the
/// candidate pairs are taken by increasing key, a point by its first pair whose site still has
/// room.
///
/// A key is one integer, (distance, point, site) from the most significant bits down: the bits
/// of a non-negative f64 order as its value (`+ 0.0` makes a -0 a +0), so keys order by
/// distance, then point, then site, a total order. Rather than sorting every pair, a heap holds
/// each free point's smallest untried pair; when its site is full, the point's next pair goes
/// in. This visits the pairs that matter in the same order as a sort of all of them, so the
/// assignment is the same: every key popped is the smallest left (a point's next pair is
/// larger than the pair just popped), and a full site stays full.
fn greedy_assignment(
    d: usize,
    n: usize,
    capacity: usize,
    points: &[f64],
    sites: &[f64],
) -> Vec<Vec<u32>> {
    let m = points.len() / d;
    let g = ((n as f64).powf(1.0 / d as f64).floor() as usize).max(1);
    let grid = SiteGrid::new(d, g, sites);
    let choices = Choices {
        d,
        n,
        points,
        sites,
        grid: &grid,
    };
    let mut firsts: Vec<u128> = (0..m).filter_map(|x| choices.next(x, None)).collect();
    firsts.sort_unstable();
    let mut keys = KeysInOrder {
        firsts: &firsts,
        taken: 0,
        later: BinaryHeap::new(),
    };
    let mut owned: Vec<Vec<u32>> = vec![Vec::with_capacity(capacity); n];
    let mut assigned = vec![false; m];
    while let Some(key) = keys.pop() {
        let (x, s) = ((key >> 32) as u32 as usize, key as u32 as usize);
        if owned[s].len() < capacity {
            assigned[x] = true;
            owned[s].push(x as u32);
        } else if let Some(next) = choices.next(x, Some(key)) {
            keys.later.push(Reverse(next));
        }
    }
    for x in (0..m).filter(|&x| !assigned[x]) {
        let p = &points[x * d..(x + 1) * d];
        let site = |s: usize| &sites[s * d..(s + 1) * d];
        let nearest_with_room = (0..n)
            .filter(|&s| owned[s].len() < capacity)
            .min_by(|&a, &b| {
                toroidal_distance_sq(p, site(a)).total_cmp(&toroidal_distance_sq(p, site(b)))
            });
        // n·capacity points for n sites of `capacity` each: some site always has room.
        if let Some(s) = nearest_with_room {
            owned[s].push(x as u32);
        }
    }
    owned
}

/// The keys of [`greedy_assignment`] in increasing order: every point's first key, sorted
/// once, merged with the later keys pushed while it runs. The same order as one heap of all of
/// them (keys are distinct), without a heap of `64 N` keys, whose every pop misses the caches.
struct KeysInOrder<'a> {
    firsts: &'a [u128],
    taken: usize,
    later: BinaryHeap<Reverse<u128>>,
}

impl KeysInOrder<'_> {
    fn pop(&mut self) -> Option<u128> {
        let first = self.firsts.get(self.taken).copied();
        match (first, self.later.peek()) {
            (Some(a), Some(&Reverse(b))) if b < a => self.later.pop().map(|r| r.0),
            (Some(a), _) => {
                self.taken += 1;
                Some(a)
            }
            (None, _) => self.later.pop().map(|r| r.0),
        }
    }
}

/// The candidate pairs of each point in [`greedy_assignment`]: the sites in the 5^d grid cells
/// around it (all sites on a grid too small to have 5 distinct cells a side), as
/// (distance, point, site) keys.
struct Choices<'a> {
    d: usize,
    n: usize,
    points: &'a [f64],
    sites: &'a [f64],
    grid: &'a SiteGrid,
}

/// A squared distance below which a key found in the `3^d` cells around a point is smaller
/// than any key in the ring of cells beyond them: a site there lies at least one cell side
/// `1/g` away along some axis. The margin covers the rounding of the point's cell index and of
/// the computed distances (a few units in the last place), with room to spare.
fn inner_reach_sq(g: usize) -> f64 {
    (1.0 - 1e-9) / (g * g) as f64
}

impl Choices<'_> {
    /// Point `x`'s smallest key above `after` (or its smallest of all), if any is left.
    ///
    /// The nearest cells are searched first, and the outer ring only when what they hold is
    /// not closer than [`inner_reach_sq`]: the same key as a search of every candidate.
    fn next(&self, x: usize, after: Option<u128>) -> Option<u128> {
        let p = &self.points[x * self.d..(x + 1) * self.d];
        let mut best = None;
        if self.grid.g < 5 {
            (0..self.n as u32).for_each(|s| self.consider(x, s, after, &mut best));
            return best;
        }
        self.grid
            .for_each_near(p, 1, |s| self.consider(x, s, after, &mut best));
        let distance = |key: u128| f64::from_bits((key >> 64) as u64);
        if best.is_some_and(|b| distance(b) < inner_reach_sq(self.grid.g)) {
            return best;
        }
        self.grid
            .for_each_near(p, 2, |s| self.consider(x, s, after, &mut best));
        best
    }

    /// Keeps the key of point `x` and site `s` in `best` if it is above `after` and smaller.
    fn consider(&self, x: usize, s: u32, after: Option<u128>, best: &mut Option<u128>) {
        let d = self.d;
        let p = &self.points[x * d..(x + 1) * d];
        let site = &self.sites[s as usize * d..(s as usize + 1) * d];
        let distance = toroidal_distance_sq(p, site) + 0.0;
        let key = (u128::from(distance.to_bits()) << 64) | ((x as u128) << 32) | u128::from(s);
        if after.is_none_or(|a| key > a) && best.is_none_or(|b| key < b) {
            *best = Some(key);
        }
    }
}

/// The discrete points one site owns: their indices (which order equal gains) and their
/// coordinates beside them, in the same order, so that the pair pass reads each site's points
/// from one contiguous block instead of gathering them from the whole density.
struct Owned {
    ids: Vec<u32>,
    coords: Vec<f64>,
}

impl Owned {
    fn with_points(d: usize, ids: Vec<u32>, points: &[f64]) -> Self {
        let coords = ids
            .iter()
            .flat_map(|&x| &points[x as usize * d..(x as usize + 1) * d])
            .copied()
            .collect();
        Self { ids, coords }
    }

    fn len(&self) -> usize {
        self.ids.len()
    }

    /// Removes the points whose positions `gone` lists, keeping the others in order.
    fn remove(&mut self, d: usize, gone: &[Gain]) {
        let mut kept = 0;
        for k in 0..self.ids.len() {
            if gone.iter().all(|g| g.position as usize != k) {
                self.ids[kept] = self.ids[k];
                self.coords.copy_within(k * d..(k + 1) * d, kept * d);
                kept += 1;
            }
        }
        self.ids.truncate(kept);
        self.coords.truncate(kept * d);
    }
}

/// A point's gain from moving to the other site of a pair, with its index and its position
/// in its site's list.
#[derive(Clone, Copy)]
struct Gain {
    gain: f64,
    id: u32,
    position: u32,
}

/// A pair of sites seen from the first, at `a`: the step `e = b − a` to the second and its
/// squared length. The gain `|x − a|² − |x − b|²` of moving a point `x` from the first site to
/// the second is, with `δ = x − a` (toroidal, both short: the point is near its site and the
/// sites are neighbours), `2 δ·e − |e|²`: one difference per axis.
struct PairFrame {
    a: [f64; 3],
    e: [f64; 3],
    ee: f64,
    d: usize,
}

impl PairFrame {
    fn new(a: &[f64], b: &[f64]) -> Self {
        let d = a.len();
        let mut frame = Self {
            a: [0.0; 3],
            e: [0.0; 3],
            ee: 0.0,
            d,
        };
        for k in 0..d {
            frame.a[k] = a[k];
            frame.e[k] = toroidal_delta(b[k], a[k]);
        }
        frame.ee = frame.e[..d].iter().map(|v| v * v).sum();
        frame
    }

    /// `2 δ·e − |e|²` for the point `p`.
    fn gain(&self, p: &[f64]) -> f64 {
        self.gain_over(p, self.d)
    }

    /// `2 δ·e − |e|²` over the first `d` axes of `p` (inlined, so that a constant `d` unrolls).
    #[inline(always)]
    fn gain_over(&self, p: &[f64], d: usize) -> f64 {
        let mut dot = 0.0;
        for k in 0..d {
            dot += near_delta(p[k], self.a[k]) * self.e[k];
        }
        2.0 * dot - self.ee
    }

    /// The largest [`gain`](Self::gain) over points of `D` coordinates: the same gains in
    /// four independent running maxima (a maximum is exact in any order), which the compiler
    /// can keep in one vector register instead of a chain of dependent compares.
    fn best_gain<const D: usize>(&self, coords: &[f64]) -> f64 {
        let gain = |p: &[f64]| self.gain_over(p, D);
        let larger = |best: f64, g: f64| if g > best { g } else { best };
        let mut lanes = [f64::NEG_INFINITY; 4];
        let mut blocks = coords.chunks_exact(4 * D);
        for block in &mut blocks {
            for (lane, p) in lanes.iter_mut().zip(block.chunks_exact(D)) {
                *lane = larger(*lane, gain(p));
            }
        }
        for p in blocks.remainder().chunks_exact(D) {
            lanes[0] = larger(lanes[0], gain(p));
        }
        lanes.into_iter().fold(f64::NEG_INFINITY, larger)
    }
}

struct State {
    d: usize,
    n: usize,
    /// The number of discrete points.
    m: usize,
    sites: Vec<f64>,
    owned: Vec<Owned>,
    // Scratch buffers for the pair pass, reused so the inner loop does not allocate.
    hi: Vec<Gain>,
    hj: Vec<Gain>,
    moving: Vec<f64>,
    /// Sites whose points changed during the current pass, and during the previous one.
    changed: Vec<bool>,
    previous: Vec<bool>,
}

impl State {
    /// Initial state: sites from Poisson disk dart throwing (isotropic, so no grid can imprint
    /// itself on the result), and a capacity-constrained greedy assignment: candidate
    /// (point, site) pairs between each point and the sites of its neighbouring grid cells,
    /// taken by increasing distance while the point is free and the site has room. Points left
    /// over go to the nearest site with room; the swap passes then settle them.
    fn new(d: usize, n: usize, capacity: usize, seed: u64, realization: u64) -> Self {
        let points = stratified_density(d, n * capacity, seed, realization);
        let sites = initial_sites(d, n, seed, realization);
        let owned = greedy_assignment(d, n, capacity, &points, &sites)
            .into_iter()
            .map(|ids| Owned::with_points(d, ids, &points))
            .collect();
        let mut state = Self {
            d,
            n,
            m: points.len() / d,
            sites,
            owned,
            hi: Vec::with_capacity(capacity),
            hj: Vec::with_capacity(capacity),
            moving: Vec::with_capacity(capacity * d),
            changed: vec![true; n],
            previous: vec![true; n],
        };
        state.move_sites();
        state.previous = vec![true; n];
        state
    }

    fn site(&self, s: usize) -> &[f64] {
        &self.sites[s * self.d..(s + 1) * self.d]
    }

    /// Pairs of sites closer than `2 N^{-1/d}`, found through a grid of sites.
    fn neighbour_pairs(&self) -> Vec<(usize, usize)> {
        let d = self.d;
        let reach = 2.0 * (self.n as f64).powf(-1.0 / d as f64);
        let g = (1.0 / reach).floor() as usize;
        let reach2 = reach * reach;
        let mut pairs = Vec::new();
        if g < 3 {
            for i in 0..self.n {
                for j in i + 1..self.n {
                    if toroidal_distance_sq(self.site(i), self.site(j)) < reach2 {
                        pairs.push((i, j));
                    }
                }
            }
            return pairs;
        }
        let grid = SiteGrid::new(d, g, &self.sites);
        for i in 0..self.n {
            grid.for_each_near(self.site(i), 1, |j| {
                let j = j as usize;
                if j > i && toroidal_distance_sq(self.site(i), self.site(j)) < reach2 {
                    pairs.push((i, j));
                }
            });
        }
        pairs
    }

    /// One pass over all neighbouring pairs; returns the number of points swapped.
    ///
    /// A pair whose two sites kept their points since the previous pass (and so did not move)
    /// is skipped: it was examined then with the same points and sites and swapped nothing,
    /// so it would swap nothing now. Exact, and most pairs after the first few passes.
    fn swap_pass(&mut self) -> usize {
        let pairs = self.neighbour_pairs();
        let mut swaps = 0;
        for (i, j) in pairs {
            let stale =
                !(self.previous[i] || self.previous[j] || self.changed[i] || self.changed[j]);
            if stale {
                continue;
            }
            let moved = self.swap_pair(i, j);
            if moved > 0 {
                self.changed[i] = true;
                self.changed[j] = true;
            }
            swaps += moved;
        }
        swaps
    }

    /// The largest gain of moving a point of `from` to `to` ([`PairFrame`]).
    fn best_gain(&self, from: usize, to: usize) -> f64 {
        let frame = PairFrame::new(self.site(from), self.site(to));
        let coords = &self.owned[from].coords;
        match self.d {
            1 => frame.best_gain::<1>(coords),
            2 => frame.best_gain::<2>(coords),
            _ => frame.best_gain::<3>(coords),
        }
    }

    /// The points of `from` whose gain to `to` exceeds `floor`, in their order, in `out`.
    fn gains_above(&self, from: usize, to: usize, floor: f64, out: &mut Vec<Gain>) {
        out.clear();
        let frame = PairFrame::new(self.site(from), self.site(to));
        let owned = &self.owned[from];
        for (position, (&id, p)) in owned
            .ids
            .iter()
            .zip(owned.coords.chunks_exact(self.d))
            .enumerate()
        {
            let gain = frame.gain(p);
            if gain > floor {
                out.push(Gain {
                    gain,
                    id,
                    position: position as u32,
                });
            }
        }
    }

    /// Swaps points between sites `i` and `j` while the sum of their gains is positive;
    /// returns how many went each way. Most pairs swap nothing, and their best gains alone
    /// say so: the lists are built only for the others.
    fn swap_pair(&mut self, i: usize, j: usize) -> usize {
        let (best_i, best_j) = (self.best_gain(i, j), self.best_gain(j, i));
        if best_i + best_j <= 0.0 {
            return 0;
        }
        let mut hi = std::mem::take(&mut self.hi);
        let mut hj = std::mem::take(&mut self.hj);
        // Only a point whose gain beats minus the other side's best can be in a swapped pair:
        // sort those alone (usually a handful of the capacity).
        self.gains_above(i, j, -best_j, &mut hi);
        self.gains_above(j, i, -best_i, &mut hj);
        let by_gain = |a: &Gain, b: &Gain| b.gain.total_cmp(&a.gain).then(a.id.cmp(&b.id));
        hi.sort_unstable_by(by_gain);
        hj.sort_unstable_by(by_gain);
        let mut swaps = 0;
        while swaps < hi.len() && swaps < hj.len() && hi[swaps].gain + hj[swaps].gain > 0.0 {
            swaps += 1;
        }
        if swaps > 0 {
            self.exchange(i, &hi[..swaps], j, &hj[..swaps]);
        }
        self.hi = hi;
        self.hj = hj;
        swaps
    }

    /// Moves the points `out_i` of site `i` to site `j` and `out_j` of `j` to `i`: each
    /// site keeps its other points in order and takes the newcomers at its end, in the order
    /// given.
    fn exchange(&mut self, i: usize, out_i: &[Gain], j: usize, out_j: &[Gain]) {
        let d = self.d;
        let mut moving = std::mem::take(&mut self.moving);
        moving.clear();
        for (site, out) in [(i, out_i), (j, out_j)] {
            let coords = &self.owned[site].coords;
            for g in out {
                let at = g.position as usize * d;
                moving.extend_from_slice(&coords[at..at + d]);
            }
        }
        let (from_i, from_j) = moving.split_at(out_i.len() * d);
        self.owned[i].remove(d, out_i);
        self.owned[j].remove(d, out_j);
        for (site, out, coords) in [(i, out_j, from_j), (j, out_i, from_i)] {
            let owned = &mut self.owned[site];
            owned.ids.extend(out.iter().map(|g| g.id));
            owned.coords.extend_from_slice(coords);
        }
        self.moving = moving;
    }

    /// Moves every site whose points changed in this pass to the toroidal centroid of its
    /// points (the others are at theirs already, and keep their bits), then starts a new pass.
    fn move_sites(&mut self) {
        let d = self.d;
        for s in (0..self.n).filter(|&s| self.changed[s]) {
            let mut mean = [0.0f64; 3];
            for p in self.owned[s].coords.chunks_exact(d) {
                for a in 0..d {
                    mean[a] += toroidal_delta(p[a], self.sites[s * d + a]);
                }
            }
            let count = self.owned[s].len() as f64;
            for a in 0..d {
                self.sites[s * d + a] = wrap(self.sites[s * d + a] + mean[a] / count);
            }
        }
        std::mem::swap(&mut self.previous, &mut self.changed);
        self.changed.iter_mut().for_each(|c| *c = false);
    }

    fn energy(&self) -> f64 {
        let d = self.d;
        let total: f64 = (0..self.n)
            .map(|s| {
                self.owned[s]
                    .coords
                    .chunks_exact(d)
                    .map(|p| toroidal_distance_sq(p, self.site(s)))
                    .sum::<f64>()
            })
            .sum();
        total / self.m as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point's first keys, in order, are the same whether the search stops at the nearest
    /// cells or always scans the whole `5^d` block (the greedy assignment seldom goes further
    /// down a point's list).
    #[test]
    fn pruned_search_gives_the_keys_of_the_whole_block() {
        for (d, n) in [(2, 200), (3, 250)] {
            let sites = initial_sites(d, n, 7, 0);
            let points = stratified_density(d, 16 * n, 7, 0);
            let g = ((n as f64).powf(1.0 / d as f64).floor() as usize).max(1);
            assert!(g >= 5);
            let grid = SiteGrid::new(d, g, &sites);
            let choices = Choices {
                d,
                n,
                points: &points,
                sites: &sites,
                grid: &grid,
            };
            for x in 0..points.len() / d {
                let p = &points[x * d..(x + 1) * d];
                let mut after = None;
                for _ in 0..6 {
                    let mut whole = None;
                    grid.for_each_near(p, 2, |s| choices.consider(x, s, after, &mut whole));
                    let pruned = choices.next(x, after);
                    assert_eq!(pruned, whole, "d = {d}, point {x}");
                    match pruned {
                        Some(key) => after = Some(key),
                        None => break,
                    }
                }
            }
        }
    }
}

//! Capacity-constrained Voronoi tessellation (Balzer, Schlömer and Deussen 2009) on the torus.
//!
//! The density (uniform) is represented by `M = N · capacity` random points. Each of the N
//! sites owns exactly `capacity` of them. One iteration visits every pair of neighbouring
//! sites `(i, j)` and swaps points between them while that lowers the energy: with
//! `h_i(x) = |x - s_i|² - |x - s_j|²` for points of `i` and `h_j` likewise, the largest `h_i`
//! and `h_j` are exchanged while their sum is positive. Then every site moves to the centroid
//! of its points. Capacities never change, and the energy `Σ |x - s(x)|²` never increases.
//!
//! **Convergence criterion:** an iteration in which no pair swaps any point (the assignment
//! is stable), or `max_iterations`. Neighbouring pairs are the sites closer than
//! `2 N^{-1/d}` (the Voronoi neighbours lie within about `1.5 N^{-1/d}`).

use super::{check_supported, uniform, Sampler};
use crate::error::{invalid, Result};
use crate::pointset::{toroidal_delta, toroidal_distance_sq, wrap, PointSet};
use crate::rng::{realization_rng, Stream};

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
    /// iteration.
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
        check_supported("ccvt", d, 1..=3)?;
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

    /// Generates one realization and reports how the optimization went.
    ///
    /// # Errors
    /// `n = 0`.
    pub fn generate(&self, n: usize, seed: u64, realization: u64) -> Result<(PointSet, CcvtStats)> {
        self.check_count(n)?;
        let mut state = State::new(self.dimension, n, self.params.capacity, seed, realization);
        let mut energy = Vec::new();
        let mut converged = false;
        let mut iterations = 0;
        while iterations < self.params.max_iterations {
            iterations += 1;
            let swaps = state.swap_pass();
            state.move_sites();
            energy.push(state.energy());
            if swaps == 0 {
                converged = true;
                break;
            }
        }
        let capacities = state.owned.iter().map(Vec::len).collect();
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
        "ccvt"
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.generate(n, seed, realization).map(|(p, _)| p)
    }
}

struct State {
    d: usize,
    n: usize,
    points: Vec<f64>,
    sites: Vec<f64>,
    owned: Vec<Vec<u32>>,
    // Scratch buffers for the pair pass, reused so the inner loop does not allocate.
    hi: Vec<(f64, u32)>,
    hj: Vec<(f64, u32)>,
}

/// Interleaves the top 10 bits of each coordinate (Morton order), for spatially compact
/// initial clusters.
fn morton_key(p: &[f64]) -> u64 {
    let mut key = 0u64;
    for bit in (0..10).rev() {
        for &c in p {
            let q = (c * 1024.0) as u64;
            key = (key << 1) | ((q >> bit) & 1);
        }
    }
    key
}

impl State {
    fn new(d: usize, n: usize, capacity: usize, seed: u64, realization: u64) -> Self {
        let m = n * capacity;
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let points: Vec<f64> = (0..m * d).map(|_| uniform(&mut rng)).collect();
        let mut order: Vec<(u64, u32)> = (0..m)
            .map(|i| (morton_key(&points[i * d..(i + 1) * d]), i as u32))
            .collect();
        order.sort_unstable();
        let owned: Vec<Vec<u32>> = order
            .chunks(capacity)
            .map(|chunk| chunk.iter().map(|&(_, i)| i).collect())
            .collect();
        // Seed each site at one of its points so the toroidal centroid is well defined.
        let mut sites = vec![0.0; n * d];
        for (s, list) in owned.iter().enumerate() {
            let i = list[0] as usize;
            sites[s * d..(s + 1) * d].copy_from_slice(&points[i * d..(i + 1) * d]);
        }
        let mut state = Self {
            d,
            n,
            points,
            sites,
            owned,
            hi: Vec::with_capacity(capacity),
            hj: Vec::with_capacity(capacity),
        };
        state.move_sites();
        state
    }

    fn point(&self, i: u32) -> &[f64] {
        let i = i as usize;
        &self.points[i * self.d..(i + 1) * self.d]
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
        let cell_of = |p: &[f64]| -> Vec<usize> {
            p.iter()
                .map(|c| ((c * g as f64) as usize).min(g - 1))
                .collect()
        };
        let flat = |c: &[usize]| c.iter().fold(0, |acc, &x| acc * g + x);
        let mut buckets: Vec<Vec<usize>> = vec![Vec::new(); g.pow(d as u32)];
        for s in 0..self.n {
            buckets[flat(&cell_of(self.site(s)))].push(s);
        }
        let offsets = 3usize.pow(d as u32);
        for i in 0..self.n {
            let c = cell_of(self.site(i));
            for o in 0..offsets {
                let mut nc = c.clone();
                let mut rest = o;
                for x in nc.iter_mut() {
                    *x = (*x + g + rest % 3 - 1) % g;
                    rest /= 3;
                }
                for &j in &buckets[flat(&nc)] {
                    if j > i && toroidal_distance_sq(self.site(i), self.site(j)) < reach2 {
                        pairs.push((i, j));
                    }
                }
            }
        }
        pairs
    }

    /// One pass over all neighbouring pairs; returns the number of points swapped.
    fn swap_pass(&mut self) -> usize {
        let pairs = self.neighbour_pairs();
        pairs.into_iter().map(|(i, j)| self.swap_pair(i, j)).sum()
    }

    fn gains(&self, from: usize, to: usize, out: &mut Vec<(f64, u32)>) -> f64 {
        out.clear();
        let (a, b) = (self.site(from), self.site(to));
        let mut best = f64::NEG_INFINITY;
        for &x in &self.owned[from] {
            let p = self.point(x);
            let h = toroidal_distance_sq(p, a) - toroidal_distance_sq(p, b);
            best = best.max(h);
            out.push((h, x));
        }
        best
    }

    fn swap_pair(&mut self, i: usize, j: usize) -> usize {
        let mut hi = std::mem::take(&mut self.hi);
        let mut hj = std::mem::take(&mut self.hj);
        let best_i = self.gains(i, j, &mut hi);
        let best_j = self.gains(j, i, &mut hj);
        let mut swaps = 0;
        if best_i + best_j > 0.0 {
            let by_gain = |a: &(f64, u32), b: &(f64, u32)| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1));
            hi.sort_unstable_by(by_gain);
            hj.sort_unstable_by(by_gain);
            while swaps < hi.len() && swaps < hj.len() && hi[swaps].0 + hj[swaps].0 > 0.0 {
                swaps += 1;
            }
            if swaps > 0 {
                // Keep the points that stay, then take the other site's best movers.
                let keep_i = hi[swaps..].iter().map(|&(_, x)| x);
                let keep_j = hj[swaps..].iter().map(|&(_, x)| x);
                let new_i: Vec<u32> = keep_i.chain(hj[..swaps].iter().map(|&(_, x)| x)).collect();
                let new_j: Vec<u32> = keep_j.chain(hi[..swaps].iter().map(|&(_, x)| x)).collect();
                self.owned[i] = new_i;
                self.owned[j] = new_j;
            }
        }
        self.hi = hi;
        self.hj = hj;
        swaps
    }

    /// Moves every site to the toroidal centroid of its points.
    fn move_sites(&mut self) {
        let d = self.d;
        for s in 0..self.n {
            let mut mean = [0.0f64; 3];
            for &x in &self.owned[s] {
                let p = self.point(x);
                for a in 0..d {
                    mean[a] += toroidal_delta(p[a], self.sites[s * d + a]);
                }
            }
            let count = self.owned[s].len() as f64;
            for a in 0..d {
                self.sites[s * d + a] = wrap(self.sites[s * d + a] + mean[a] / count);
            }
        }
    }

    fn energy(&self) -> f64 {
        let total: f64 = (0..self.n)
            .map(|s| {
                self.owned[s]
                    .iter()
                    .map(|&x| toroidal_distance_sq(self.point(x), self.site(s)))
                    .sum::<f64>()
            })
            .sum();
        total / (self.points.len() / self.d) as f64
    }
}

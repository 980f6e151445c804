//! Choosing the upsampling and kernel width: the cheapest pair that meets a tolerance.
//!
//! A finer grid (upsampling 2) needs a narrower kernel for the same error; a coarser one
//! (1.25) a wider kernel on a smaller FFT. Which is cheaper depends on the number of points
//! against the grid: spreading costs `N w^d` cell updates, the FFTs `g^d log g` per axis. The
//! choice uses a fixed cost model (operation counts weighted by per-operation times measured
//! once on an x86-64 core with AVX), never timings at run time, so the same inputs give the same
//! plan, and the same bits, on every machine.

use super::kernel::{tensor_error, EsKernel, MAX_WIDTH};
use super::spread::Padded;
use super::stream::grid_bytes;
use crate::error::{Error, Result};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock, PoisonError};

/// The upsampling factors tried, from the cheapest FFT to the cheapest spreading. 1.2 and 1.25
/// often need the same width, and the grid sizes the FFT handles fastest fall differently
/// above each (800 and 810 cells for `K = 320`, 3200 and 3240 for `K = 1280`).
pub const UPSAMPLINGS: [f64; 4] = [1.2, 1.25, 1.5, 2.0];

// Per-operation times, fitted to single-thread transforms of the FINUFFT comparison's rows
// (2D N = 4096, K = 320; 2D N = 65536, K = 1280; 3D N = 32768, K = 40; 1D N = 10^5, K = 5000)
// at every upsampling: the model picks the measured fastest in each.

/// A kernel and grid for one transform, with the error it guarantees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choice {
    /// The kernel, including its grid size.
    pub kernel: EsKernel,
    /// Upsampling factor asked for (the grid is the next FFT-friendly size above it).
    pub upsampling: f64,
    /// `|S_fast(k) - S(k)| ≤ error · N` at every frequency of the band, for any points.
    pub error: f64,
}

impl Choice {
    /// The kernel of `width` cells at upsampling `sigma` for the band `|k| ≤ kmax` in
    /// `dimension` dimensions, with its measured error.
    pub fn with_width(dimension: usize, kmax: usize, sigma: f64, width: usize) -> Self {
        let side = 2 * kmax + 1;
        let grid = nice_size(((sigma * side as f64).ceil() as usize).max(2 * width));
        let kernel = EsKernel::for_band(width, grid, kmax);
        Self {
            kernel,
            upsampling: sigma,
            error: tensor_error(kernel.point_error(kmax), dimension),
        }
    }

    /// The narrowest kernel at upsampling `sigma` whose error is at most `tolerance`, if any:
    /// a bisection over the widths, the error falling with the width.
    pub fn narrowest(dimension: usize, kmax: usize, sigma: f64, tolerance: f64) -> Option<Self> {
        let at = |w| Self::with_width(dimension, kmax, sigma, w);
        let widest = at(MAX_WIDTH);
        if widest.error > tolerance {
            return None;
        }
        // Invariant: width `hi` meets the tolerance, width `lo` does not (or is below 2).
        let (mut lo, mut hi, mut best) = (1, MAX_WIDTH, widest);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            let c = at(mid);
            if c.error <= tolerance {
                (hi, best) = (mid, c);
            } else {
                lo = mid;
            }
        }
        Some(best)
    }

    /// The cheapest choice for `points` points meeting `tolerance`, by the cost model.
    ///
    /// # Errors
    /// [`Error::OutsideValidity`] when no kernel reaches the tolerance.
    pub fn cheapest(dimension: usize, kmax: usize, points: usize, tolerance: f64) -> Result<Self> {
        let candidates = narrowest_per_upsampling(dimension, kmax, tolerance);
        candidates
            .into_iter()
            .flatten()
            .min_by(|a, b| {
                let (ca, cb) = (
                    a.seconds(dimension, kmax, points),
                    b.seconds(dimension, kmax, points),
                );
                ca.total_cmp(&cb)
            })
            .ok_or_else(|| {
                let finest = Self::with_width(dimension, kmax, 2.0, MAX_WIDTH);
                Error::OutsideValidity {
                    route: format!("the fast engine at a tolerance of {tolerance:e}"),
                    reason: format!(
                        "the widest kernel guarantees {:.1e} on |k_i| ≤ {kmax}; use a looser \
                         tolerance or the direct engine",
                        finest.error
                    ),
                }
            })
    }

    /// Predicted seconds of one transform of `points` points (see the module notes).
    pub fn seconds(&self, dimension: usize, kmax: usize, points: usize) -> f64 {
        let (d, w, g) = (
            dimension as i32,
            self.kernel.width as f64,
            self.kernel.grid as f64,
        );
        let spread = points as f64
            * (dimension as f64 * w * crate::costs::NUFFT_KERNEL_VALUE_NS
                + w.powi(d) * crate::costs::NUFFT_CELL_UPDATE_NS);
        let padded = (g + w + 1.0).powi(d) * crate::costs::NUFFT_GRID_CELL_NS;
        let fft = fft_lines(dimension, self.kernel.grid, kmax)
            * crate::costs::NUFFT_FFT_NS
            * g
            * g.log2();
        (spread + padded + fft) * 1e-9
    }

    /// Bytes of one transform's scratch: the grid's slabs in flight and the half-spectrum
    /// buffers.
    pub fn scratch_bytes(&self, dimension: usize, kmax: usize) -> f64 {
        let g = self.kernel.grid as f64;
        let half = (kmax + 1) as f64;
        // The rows' half spectra (one plane's in 3D), the second axis' output in 3D, the FFT
        // batch and scratch.
        let rows = if dimension == 1 { half } else { g * half };
        let spare = if dimension == 3 {
            (2 * kmax + 1) as f64 * half * g
        } else {
            0.0
        };
        let layout = Padded::new(dimension, self.kernel.grid, self.kernel.width);
        grid_bytes(&layout, self.kernel.width) + (rows + spare + 4.0 * g) * 16.0
    }
}

/// The narrowest kernel at each upsampling of [`UPSAMPLINGS`] for a band and tolerance,
/// remembered: finding them measures dozens of kernels (milliseconds), and one estimate asks
/// for the same choice several times (to pick its engine, to size its budget, to plan).
fn narrowest_per_upsampling(dimension: usize, kmax: usize, tolerance: f64) -> Vec<Option<Choice>> {
    type Key = (usize, usize, u64);
    /// Bands and tolerances remembered at most; beyond, the memory starts afresh.
    const REMEMBERED: usize = 256;
    static MADE: OnceLock<Mutex<HashMap<Key, Vec<Option<Choice>>>>> = OnceLock::new();
    let made = MADE.get_or_init(Default::default);
    let key = (dimension, kmax, tolerance.to_bits());
    let lock = || made.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(found) = lock().get(&key) {
        return found.clone();
    }
    // Each upsampling's kernels are measured on their own: in parallel.
    let candidates: Vec<Option<Choice>> = UPSAMPLINGS
        .par_iter()
        .map(|&s| Choice::narrowest(dimension, kmax, s, tolerance))
        .collect();
    let mut made = lock();
    if made.len() >= REMEMBERED {
        made.clear();
    }
    made.insert(key, candidates.clone());
    candidates
}

/// Full complex FFTs of length `g` per transform: the real FFT of each of the `g^{d-1}` rows
/// counts half, then each remaining axis transforms only the lines the crop keeps.
fn fft_lines(dimension: usize, grid: usize, kmax: usize) -> f64 {
    let (g, half, side) = (grid as f64, (kmax + 1) as f64, (2 * kmax + 1) as f64);
    match dimension {
        1 => 0.5,
        2 => 0.5 * g + half,
        _ => 0.5 * g * g + g * half + side * half,
    }
}

/// The smallest even `2^a 3^b 5^c` at least `n`: sizes the FFT handles fastest (odd ones such
/// as 125 or 729 take 1.5 to 2.5 times as long per `n log n` in rustfft).
pub fn nice_size(n: usize) -> usize {
    (n..)
        .find(|&m| {
            if m % 2 == 1 {
                return false;
            }
            let mut r = m;
            for p in [2, 3, 5] {
                while r % p == 0 {
                    r /= p;
                }
            }
            r == 1
        })
        .unwrap_or(n)
}

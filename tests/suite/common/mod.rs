//! Checks and tolerances shared by the tests. Each tolerance is named once here, with the
//! reasoning that gives its value.
#![allow(dead_code)]

use std::fmt::Debug;

/// Relative rounding error of a sum of up to ~10⁴ double-precision terms of one sign, or of a
/// closed form with a few dozen operations: about `10⁴ · ε = 10⁴ · 1.1e-16 ≈ 1e-12`.
pub const ROUNDING: f64 = 1e-12;

/// Relative error of the double-exponential rule on half-period panels at the library's
/// default tolerance (1e-14 of `∫ f²` per panel): over up to 10⁴ panels the errors add to
/// 1e-10, plus the rounding of the compensated sum; measured 4e-15 on the disk's Parseval
/// integral (`docs/performance.md`).
pub const QUADRATURE: f64 = 1e-9;

/// Standard errors a statistical check allows, so that a correct implementation fails it with
/// probability `P(|Z| > 5) = 5.7e-7` per check: across the few hundred such checks of the
/// suite, about one failure in ten thousand runs.
pub const Z_STRICT: f64 = 5.0;

/// The same for one-sided checks or checks of a single statistic where a looser bound is
/// enough: `P(|Z| > 4) = 6.3e-5`.
pub const Z_LOOSE: f64 = 4.0;

/// Runs `f` on thread pools of 1, 2 and 3 threads and on the global pool, asserts that every
/// result is the same, and returns it: realization `i` of seed `s` must be the same bits on
/// any thread count.
pub fn assert_thread_count_invariant<T: PartialEq + Debug + Send>(f: impl Fn() -> T + Sync) -> T {
    let reference = f();
    for threads in 1..=3 {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        let other = pool.install(&f);
        assert_eq!(reference, other, "result differs on {threads} thread(s)");
    }
    reference
}

/// `|a/b - 1| ≤ tolerance`.
pub fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a / b - 1.0).abs() <= tolerance
}

/// Area of the disk (centre c, radius r) below-left of the corner (x, y):
/// `∫_{-r}^{min(x-cx, r)} (clamp(y - cy, -h, h) + h) dt`, `h = √(r² - t²)`, in closed form.
pub fn corner_area(x: f64, y: f64, c: [f64; 2], r: f64) -> f64 {
    let (xr, yr) = (x - c[0], y - c[1]);
    let h_int = |t: f64| {
        let t = t.clamp(-r, r);
        (t * (r * r - t * t).max(0.0).sqrt() + r * r * (t / r).asin()) / 2.0
    };
    let upper = xr.min(r);
    if upper <= -r || yr <= -r {
        return 0.0;
    }
    // ∫ 2h over [a, b]
    let full = |a: f64, b: f64| {
        if b > a {
            2.0 * (h_int(b) - h_int(a))
        } else {
            0.0
        }
    };
    // ∫ (y + h) over [a, b]
    let partial = |a: f64, b: f64| {
        if b > a {
            yr * (b - a) + h_int(b) - h_int(a)
        } else {
            0.0
        }
    };
    if yr >= r {
        return full(-r, upper);
    }
    let s = (r * r - yr * yr).sqrt();
    // |t| > s: h < |y|: the whole chord (y > 0) or nothing (y < 0); |t| < s: from -h to y.
    let outer = |a: f64, b: f64| if yr > 0.0 { full(a, b) } else { 0.0 };
    outer(-r, upper.min(-s)) + partial(-s, upper.min(s)) + outer(s, upper)
}

pub fn rect_area(x0: f64, x1: f64, y0: f64, y1: f64, c: [f64; 2], r: f64) -> f64 {
    corner_area(x1, y1, c, r) - corner_area(x0, y1, c, r) - corner_area(x1, y0, c, r)
        + corner_area(x0, y0, c, r)
}

/// Homogenized jitter's variance for the disk without Fourier analysis: with grid offset u,
/// `Var = ∫f²/N - E_u[Σ_j (∫_{cell_j(u)} f)²]`, the mean over u by the midpoint rule on a
/// `q × q` grid of offsets (the function is periodic in u).
/// The area of the disk inside the torus rectangle `[x0, x0 + w) × [y0, y0 + h)`, whose parts
/// below 0 wrap to the top of the square.
pub fn torus_rect_area(x0: f64, w: f64, y0: f64, h: f64, c: [f64; 2], r: f64) -> f64 {
    let pieces = |a: f64, len: f64| -> Vec<(f64, f64)> {
        if a < 0.0 {
            vec![(a + 1.0, 1.0), (0.0, a + len)]
        } else {
            vec![(a, a + len)]
        }
    };
    let mut area = 0.0;
    for (xa, xb) in pieces(x0, w) {
        for &(ya, yb) in &pieces(y0, h) {
            area += rect_area(xa, xb, ya, yb, c, r);
        }
    }
    area
}

/// Homogenized jitter's variance for the disk of height 1 (`m × m` strata) without Fourier
/// analysis: with grid offset u, `Var = ∫f²/N - E_u[Σ_j (∫_{cell_j(u)} f)²]`, the mean over u by
/// the midpoint rule on a `q × q` grid of offsets (the function is periodic in u), cells
/// wrapping around the torus.
pub fn geometric_jitter_variance(r: f64, c: [f64; 2], m: usize, q: usize) -> f64 {
    let n = (m * m) as f64;
    let energy = std::f64::consts::PI * r * r;
    let w = 1.0 / m as f64;
    let mut mean = 0.0;
    for a in 0..q {
        for b in 0..q {
            let (ux, uy) = ((a as f64 + 0.5) / q as f64, (b as f64 + 0.5) / q as f64);
            let mut sum = 0.0;
            for i in 0..m {
                for j in 0..m {
                    let x0 = (i as f64 + ux) * w - w;
                    let y0 = (j as f64 + uy) * w - w;
                    let area = torus_rect_area(x0, w, y0, w, c, r);
                    sum += area * area;
                }
            }
            mean += sum;
        }
    }
    energy / n - mean / (q * q) as f64
}

/// `z` with `P(Z > z) = p`, by bisection on the complementary error function.
pub fn inverse_normal_tail(p: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 10.0);
    for _ in 0..100 {
        let mid = (lo + hi) / 2.0;
        if libm::erfc(mid / std::f64::consts::SQRT_2) / 2.0 > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo + hi) / 2.0
}

/// Asserts that prediction `p` and Monte Carlo run `mc` of the same estimator agree: their gap
/// beyond the prediction's bounds is below `z_limit` combined standard errors.
pub fn assert_agrees(
    p: &specvar::predict::Prediction,
    mc: &specvar::montecarlo::McResult,
    z_limit: f64,
    what: &str,
) {
    let z = p.z_beyond_bounds(mc);
    assert!(
        z.abs() < z_limit,
        "{what}: predicted {:.4e} ± {:.1e}, measured {:.4e} [{:.4e}, {:.4e}], z = {z:.2}",
        p.variance,
        p.budget.spectrum_noise,
        mc.variance,
        mc.ci_low,
        mc.ci_high
    );
}

/// Asserts that prediction `p`'s budget, widened to `z` standard errors, meets Monte Carlo run
/// `mc`'s 99% interval: the two intervals overlap.
pub fn assert_intervals_meet(
    p: &specvar::predict::Prediction,
    mc: &specvar::montecarlo::McResult,
    z: f64,
    what: &str,
) {
    let band = p.budget.half_width(z);
    assert!(
        p.variance - band <= mc.ci_high && mc.ci_low <= p.variance + band,
        "{what}: {} ± {band:.2e} against Monte Carlo [{}, {}]",
        p.variance,
        mc.ci_low,
        mc.ci_high
    );
}

/// A pixel's soft shadow on `m × m` cells: a penumbra of `width` across a line at `angle`
/// degrees through `offset` (along the line's normal), over a gradient in x that makes the
/// values at opposite faces differ (the seam an unshifted estimator never sees).
pub fn soft_shadow(
    m: usize,
    angle: f64,
    offset: f64,
    width: f64,
) -> specvar::integrand::GridIntegrand {
    let (c, s) = (angle.to_radians().cos(), angle.to_radians().sin());
    let values = (0..m * m)
        .map(|i| {
            let (x, y) = (
                ((i % m) as f64 + 0.5) / m as f64,
                ((i / m) as f64 + 0.5) / m as f64,
            );
            let t = ((x * c + y * s - offset) / width + 0.5).clamp(0.0, 1.0);
            0.1 + 0.6 * t * t * (3.0 - 2.0 * t) + 0.3 * x
        })
        .collect();
    specvar::integrand::GridIntegrand::new(m, m, values)
        .unwrap()
        .with_meaning(specvar::integrand::GridMeaning::Exact)
}

/// `kind` in dimension `d` with its costly patterns (CCVT, Gaussian blue noise, Poisson disk)
/// kept under the build's directory between runs of the suite, as a user's cache keeps them
/// between commands: the first run draws them, later runs read the same bits.
pub fn cached_sampler(
    kind: specvar::sampler::SamplerKind,
    d: usize,
) -> Box<dyn specvar::sampler::Sampler> {
    specvar::cache::cached_sampler(
        kind,
        d,
        Some(&pattern_dir()),
        specvar::cache::PATTERN_MEMORY,
    )
    .unwrap()
}

/// `sampler` (one of specvar's, with any parameters) with its patterns kept on disk like
/// [`cached_sampler`]'s.
pub fn kept_on_disk(sampler: Box<dyn specvar::sampler::Sampler>) -> specvar::cache::DiskCached {
    specvar::cache::DiskCached::new(sampler, pattern_dir()).unwrap()
}

/// Where the suite keeps costly patterns between runs.
fn pattern_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("test-patterns")
}

/// Waits for `child` to end, killing it and panicking (with `what`) past `limit`. The pause
/// between polls starts at a millisecond and doubles to 50 ms: most commands end in a few
/// milliseconds, and a fixed 20–50 ms pause made the waiting longer than the commands.
pub fn wait_bounded(
    child: &mut std::process::Child,
    limit: std::time::Duration,
    what: &dyn Fn() -> String,
) -> std::process::ExitStatus {
    let start = std::time::Instant::now();
    let mut pause = std::time::Duration::from_millis(1);
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            return status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{} ran past {limit:?}", what());
        }
        std::thread::sleep(pause);
        pause = (pause * 2).min(std::time::Duration::from_millis(50));
    }
}

/// `∫_a^b exp(-(x - c)²/(2s²)) dx` by libm's real erf (no Faddeeva function).
pub fn segment(a: f64, b: f64, c: f64, s: f64) -> f64 {
    let k = s * std::f64::consts::SQRT_2;
    s * (std::f64::consts::PI / 2.0).sqrt() * (libm::erf((b - c) / k) - libm::erf((a - c) / k))
}

/// The 1D truncated Gaussian integrated over the torus interval `[a, a + w)` (wrapping at 1).
pub fn wrapped_segment(a: f64, w: f64, c: f64, s: f64) -> f64 {
    let a = a - a.floor();
    if a + w <= 1.0 {
        segment(a, a + w, c, s)
    } else {
        segment(a, 1.0, c, s) + segment(0.0, a + w - 1.0, c, s)
    }
}

/// Homogenized jitter's variance for a product of truncated 1D Gaussians (centre `c`, width
/// `s`, strata `m` per axis), without Fourier analysis: with the strata shifted by `u`,
/// `Var = (1/N) ∫f² - E_u Σ_cells (∫_cell f)²`, and both factor over the axes; the mean over
/// each axis's shift by 64-point Gauss–Legendre on each of 32 panels of `[0, 1/m)`.
pub fn jitter_variance_of_product(c: &[f64], s: f64, m: usize) -> f64 {
    let (nodes, weights) = specvar::quadrature::gauss_legendre(64);
    let w = 1.0 / m as f64;
    let mut mean_square_cells = 1.0;
    let mut square_integral = 1.0;
    for &ci in c {
        let panels = 32;
        let mut acc = 0.0;
        for p in 0..panels {
            let (lo, hi) = (
                p as f64 * w / panels as f64,
                (p + 1) as f64 * w / panels as f64,
            );
            for (x, wt) in nodes.iter().zip(&weights) {
                let u = (lo + hi) / 2.0 + (hi - lo) / 2.0 * x;
                let cells: f64 = (0..m)
                    .map(|i| wrapped_segment(u + i as f64 * w, w, ci, s).powi(2))
                    .sum();
                acc += wt * (hi - lo) / 2.0 * cells;
            }
        }
        mean_square_cells *= acc / w;
        square_integral *= segment(0.0, 1.0, ci, s / std::f64::consts::SQRT_2);
    }
    let n = m.pow(c.len() as u32) as f64;
    square_integral / n - mean_square_cells
}

//! L2 discrepancies with closed forms (Hickernell 1998): the L2-star, centred and wrap-around
//! discrepancies, each a double sum over the points.

use crate::error::{invalid, Result};
use crate::pointset::PointSet;
use crate::quadrature::CompensatedSum;
use rayon::prelude::*;
use serde::Serialize;

/// Which L2 discrepancy.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DiscrepancyKind {
    /// The L2-star discrepancy: the L2 norm over anchored boxes `[0, y)` of the local
    /// discrepancy (Warnock's formula).
    L2Star,
    /// The centred L2 discrepancy: boxes anchored at the cube's nearest corner to `y`; invariant
    /// under reflections `x_a → 1 - x_a`.
    Centred,
    /// The wrap-around L2 discrepancy: boxes that wrap around the torus; invariant under
    /// toroidal shifts, so it measures a homogenized pattern.
    WrapAround,
}

impl DiscrepancyKind {
    /// All kinds, in display order.
    pub const ALL: [DiscrepancyKind; 3] = [
        DiscrepancyKind::L2Star,
        DiscrepancyKind::Centred,
        DiscrepancyKind::WrapAround,
    ];

    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            DiscrepancyKind::L2Star => "L2-star",
            DiscrepancyKind::Centred => "centred L2",
            DiscrepancyKind::WrapAround => "wrap-around L2",
        }
    }
}

/// The largest point count a discrepancy is computed for: the double sum costs `N² d`
/// operations, 10^11 at this size (about a minute on two cores).
pub const MAX_DISCREPANCY_POINTS: usize = 1 << 17;

/// The squared discrepancy `D²` of `points` (the quantity scipy.stats.qmc.discrepancy returns
/// for "CD" and "WD"; its "L2-star" returns `D`). Closed forms, with `x` and `y` two points:
///
/// - L2-star: `3^{-d} - (2^{1-d}/N) Σ_i Π_a (1 - x_a²) + (1/N²) Σ_{i,j} Π_a (1 - max(x_a, y_a))`
/// - centred: `(13/12)^d - (2/N) Σ_i Π_a (1 + |x_a - ½|/2 - |x_a - ½|²/2)
///   + (1/N²) Σ_{i,j} Π_a (1 + |x_a - ½|/2 + |y_a - ½|/2 - |x_a - y_a|/2)`
/// - wrap-around: `-(4/3)^d + (1/N²) Σ_{i,j} Π_a (3/2 - |x_a - y_a| (1 - |x_a - y_a|))`
///
/// # Errors
/// An empty set, or more than [`MAX_DISCREPANCY_POINTS`] points.
///
/// # Examples
/// ```
/// use specvar::metrics::{squared_discrepancy, DiscrepancyKind};
/// use specvar::PointSet;
/// // One point at the centre of the unit interval.
/// let p = PointSet::new(1, vec![0.5])?;
/// let cd = squared_discrepancy(&p, DiscrepancyKind::Centred)?;
/// assert!((cd - 1.0 / 12.0).abs() < 1e-15);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn squared_discrepancy(points: &PointSet, kind: DiscrepancyKind) -> Result<f64> {
    let n = points.len();
    if n == 0 || n > MAX_DISCREPANCY_POINTS {
        return Err(invalid(
            "point count",
            n,
            format!("1 to {MAX_DISCREPANCY_POINTS} (the double sum costs N² d)"),
        ));
    }
    let d = points.dimension() as i32;
    let single = |x: &[f64]| -> f64 {
        match kind {
            DiscrepancyKind::L2Star => x.iter().map(|&v| 1.0 - v * v).product(),
            DiscrepancyKind::Centred => x
                .iter()
                .map(|&v| {
                    let c = (v - 0.5).abs();
                    1.0 + 0.5 * c - 0.5 * c * c
                })
                .product(),
            DiscrepancyKind::WrapAround => 0.0,
        }
    };
    let pair = |x: &[f64], y: &[f64]| -> f64 {
        x.iter()
            .zip(y)
            .map(|(&a, &b)| match kind {
                DiscrepancyKind::L2Star => 1.0 - a.max(b),
                DiscrepancyKind::Centred => {
                    1.0 + 0.5 * (a - 0.5).abs() + 0.5 * (b - 0.5).abs() - 0.5 * (a - b).abs()
                }
                DiscrepancyKind::WrapAround => {
                    let t = (a - b).abs();
                    1.5 - t * (1.0 - t)
                }
            })
            .product()
    };
    let rows: Vec<(f64, f64)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let x = points.point(i);
            let mut row = CompensatedSum::default();
            for j in 0..n {
                row.add(pair(x, points.point(j)));
            }
            (single(x), row.value())
        })
        .collect();
    let (mut singles, mut pairs) = (CompensatedSum::default(), CompensatedSum::default());
    for &(s, p) in &rows {
        singles.add(s);
        pairs.add(p);
    }
    let nf = n as f64;
    let (constant, single_weight) = match kind {
        DiscrepancyKind::L2Star => (3f64.powi(-d), 2f64.powi(1 - d)),
        DiscrepancyKind::Centred => ((13.0f64 / 12.0).powi(d), 2.0),
        DiscrepancyKind::WrapAround => (-(4.0f64 / 3.0).powi(d), 0.0),
    };
    Ok(constant - single_weight * singles.value() / nf + pairs.value() / (nf * nf))
}

//! Polygons in the unit square: indicators with exact Fourier transforms, and the edge (a
//! half-plane clipped to the square) at any angle.

use super::interval_cells;
use super::polygon_overlap::{bounds, clip, clip_into, cross, signed_area};
use super::{Integrand, IntegrandKind, MAX_HEIGHT};
use crate::error::{invalid, Result};
use crate::quadrature::{CompensatedSum, GaussLegendre};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;

thread_local! {
    /// [`Polygon::area_in_box`]'s clipped parts, one buffer for the part and one for the next.
    static CLIP_BUFFERS: std::cell::RefCell<[Vec<[f64; 2]>; 2]> = const {
        std::cell::RefCell::new([Vec::new(), Vec::new()])
    };
}

/// The most vertices a polygon may have: its transform costs one term per edge.
pub const MAX_VERTICES: usize = 10_000;

/// `height` on a simple polygon (vertices in either orientation, inside the closed unit
/// square), 0 elsewhere.
///
/// Its transform is exact, by the divergence theorem: with `ω = 2πk`, each edge `e` from `a` to
/// `b` (counter-clockwise), `Δ = b − a` and midpoint `m`,
/// `f̂(k) = (i a / |ω|²) Σ_e (ω_x Δ_y − ω_y Δ_x) e^{−iω·m} sinc(ω·Δ/2)`
/// (`∇·(iω e^{−iω·x}/|ω|²) = e^{−iω·x}`, and an edge's integral of `e^{−iω·x}` is
/// `|Δ| e^{−iω·m} sinc(ω·Δ/2)`). The polygon lies in the square, so these are also its torus
/// coefficients. Its edges make the spectrum anisotropic: `|f̂|²` falls like `|k|^{-2}` across
/// an edge's direction and like `|k|^{-4}` elsewhere, `|k|^{-3}` on average over angles.
///
/// # Examples
/// ```
/// use specvar::integrand::{Integrand, Polygon};
/// // The left half of the square: ∫f = 1/2, and f̂(1, 0) = ∫_0^½ e^{-2πix} dx = −i/π.
/// let half = Polygon::new(vec![[0.0, 0.0], [0.5, 0.0], [0.5, 1.0], [0.0, 1.0]], 1.0)?;
/// assert!((half.integral() - 0.5).abs() < 1e-15);
/// let c = half.coefficient(&[1, 0]);
/// assert!(c.re.abs() < 1e-15 && (c.im + 1.0 / std::f64::consts::PI).abs() < 1e-15);
/// # Ok::<(), specvar::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Polygon {
    /// Counter-clockwise vertices.
    vertices: Vec<[f64; 2]>,
    height: f64,
    area: f64,
    /// The corners `(min, max)` of the box around it, which every clip to a cell reads first.
    bounds: ([f64; 2], [f64; 2]),
    label: String,
    /// Its triangles, cut when the autocorrelation is first asked for (`None`: not cut).
    triangles: std::sync::OnceLock<Option<Vec<[[f64; 2]; 3]>>>,
    /// Its overlaps with its translates in closed form, made when first asked for (`None`:
    /// not convex).
    convex: std::sync::OnceLock<Option<super::polygon_overlap::ConvexOverlap>>,
    /// Its edges that are not horizontal, as [`eval`](Integrand::eval) reads them.
    spans: Vec<Span>,
    /// Whether it is its bounding box: then a product of one interval per axis.
    is_box: bool,
}

/// An edge `a → b` that is not horizontal, for the even–odd rule: it spans the heights
/// `[lo, hi)`, and the ray towards `+x` from a point at height `y` in that span crosses it at
/// `a_x + (y − a_y) · slope`. The slope is divided out once, not per point.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Span {
    lo: f64,
    hi: f64,
    a: [f64; 2],
    slope: f64,
}

impl Span {
    /// The edge `a → b`, or `None` for a horizontal one (which no ray crosses).
    fn of(a: [f64; 2], b: [f64; 2]) -> Option<Self> {
        (a[1] != b[1]).then(|| Self {
            lo: a[1].min(b[1]),
            hi: a[1].max(b[1]),
            a,
            slope: (b[0] - a[0]) / (b[1] - a[1]),
        })
    }
}

impl Polygon {
    /// A polygon of `height` on `vertices`.
    ///
    /// # Errors
    /// Fewer than 3 or more than [`MAX_VERTICES`] vertices, a vertex outside the closed unit
    /// square or not finite, a non-finite height, zero area, or edges that cross.
    pub fn new(vertices: Vec<[f64; 2]>, height: f64) -> Result<Self> {
        Self::labelled(vertices, height, None)
    }

    fn labelled(mut vertices: Vec<[f64; 2]>, height: f64, label: Option<String>) -> Result<Self> {
        if !(3..=MAX_VERTICES).contains(&vertices.len()) {
            return Err(invalid(
                "polygon vertices",
                vertices.len(),
                format!("3 to {MAX_VERTICES}"),
            ));
        }
        if let Some(v) = vertices
            .iter()
            .find(|v| !v.iter().all(|c| (0.0..=1.0).contains(c)))
        {
            return Err(invalid(
                "polygon vertex",
                format!("({}, {})", v[0], v[1]),
                "coordinates in [0, 1] (the polygon lies in the unit square)",
            ));
        }
        if !(height.is_finite() && height.abs() <= MAX_HEIGHT) {
            return Err(invalid(
                "height",
                height,
                format!("finite, at most {MAX_HEIGHT:e}"),
            ));
        }
        let signed = signed_area(&vertices);
        if signed.abs() < 1e-14 {
            return Err(invalid(
                "polygon",
                "zero area",
                "vertices that enclose an area",
            ));
        }
        if signed < 0.0 {
            vertices.reverse();
        }
        if let Some((i, j)) = crossing_edges(&vertices) {
            return Err(invalid(
                "polygon",
                format!("edges {i} and {j} cross"),
                "a simple polygon (no edge crosses another)",
            ));
        }
        let label = label.unwrap_or_else(|| {
            format!(
                "polygon({} vertices, area {:.4}, a={height})",
                vertices.len(),
                signed.abs()
            )
        });
        let mut polygon = Self {
            area: signed.abs(),
            bounds: bounds(&vertices),
            vertices,
            height,
            label,
            triangles: std::sync::OnceLock::new(),
            convex: std::sync::OnceLock::new(),
            spans: Vec::new(),
            is_box: false,
        };
        polygon.spans = polygon
            .edges()
            .filter_map(|(a, b)| Span::of(a, b))
            .collect();
        polygon.is_box = polygon.fills_its_box();
        Ok(polygon)
    }

    /// Whether every vertex is a corner of the bounding box and the area is the box's: the
    /// polygon is then that box, the product of one interval per axis.
    fn fills_its_box(&self) -> bool {
        let (lo, hi) = self.bounds;
        let at_corner = |v: &[f64; 2]| (0..2).all(|a| v[a] == lo[a] || v[a] == hi[a]);
        let box_area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
        self.vertices.iter().all(at_corner)
            && (self.area - box_area).abs() <= 4.0 * f64::EPSILON * box_area
    }

    /// A box's interval masses on each axis of `grid`, shifted by `t` on the torus; `None` for
    /// a polygon that is not its box, or a grid or shift not in 2D.
    fn interval_rows(&self, grid: &[usize], t: &[f64]) -> Option<Vec<Vec<f64>>> {
        if !(self.is_box && grid.len() == 2 && t.len() == 2) {
            return None;
        }
        let (min, max) = self.bounds;
        Some(
            (0..2)
                .map(|a| interval_cells::masses(min[a], max[a], grid[a], t[a]))
                .collect(),
        )
    }

    /// The half-plane `{x : n·x ≤ t}` clipped to the unit square, `n = (cos θ, sin θ)` with `θ`
    /// in degrees and the line at the fraction `offset` of the square's extent along `n`
    /// (0.5: through the centre), of `height`.
    ///
    /// # Errors
    /// A non-finite angle, an offset outside `(0, 1)`, or a non-finite height.
    ///
    /// # Examples
    /// ```
    /// use specvar::integrand::{Integrand, Polygon};
    /// let edge = Polygon::edge(30.0, 0.5, 1.0)?;
    /// assert!((edge.integral() - 0.5).abs() < 1e-14); // through the centre: half the square
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn edge(theta_degrees: f64, offset: f64, height: f64) -> Result<Self> {
        if !theta_degrees.is_finite() {
            return Err(invalid("theta", theta_degrees, "an angle in degrees"));
        }
        if !(offset > 0.0 && offset < 1.0) {
            return Err(invalid(
                "offset",
                offset,
                "a fraction in (0, 1) of the square's extent",
            ));
        }
        // A multiple of 90° is an axis exactly (the cosine of π/2 in floating point is not
        // 0), so that an axis-aligned edge is the rectangle it names.
        let n = if theta_degrees % 90.0 == 0.0 {
            [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]]
                [(theta_degrees / 90.0).rem_euclid(4.0) as usize]
        } else {
            let t = theta_degrees.to_radians();
            [libm::cos(t), libm::sin(t)]
        };
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let along: Vec<f64> = square.iter().map(|v| n[0] * v[0] + n[1] * v[1]).collect();
        let (lo, hi) = along
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let level = lo + offset * (hi - lo);
        let clipped = clip(&square, n, level);
        let label = format!("edge(theta={theta_degrees}, offset={offset}, a={height})");
        Self::labelled(clipped, height, Some(label))
    }

    /// The counter-clockwise vertices.
    pub fn vertices(&self) -> &[[f64; 2]] {
        &self.vertices
    }

    fn edges(&self) -> impl Iterator<Item = ([f64; 2], [f64; 2])> + '_ {
        let next = self.vertices.iter().skip(1).chain(self.vertices.first());
        self.vertices.iter().copied().zip(next.copied())
    }

    /// The indicator's transform at frequency `nu` (cycles per unit), by the edge sum.
    fn transform(&self, nu: [f64; 2]) -> Complex64 {
        let omega = [2.0 * PI * nu[0], 2.0 * PI * nu[1]];
        let w2 = omega[0] * omega[0] + omega[1] * omega[1];
        if w2 == 0.0 {
            return Complex64::new(self.height * self.area, 0.0);
        }
        let mut sum = Complex64::new(0.0, 0.0);
        for (a, b) in self.edges() {
            let delta = [b[0] - a[0], b[1] - a[1]];
            let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            let flux = omega[0] * delta[1] - omega[1] * delta[0];
            let half = 0.5 * (omega[0] * delta[0] + omega[1] * delta[1]);
            let phase = -(omega[0] * mid[0] + omega[1] * mid[1]);
            sum += Complex64::from_polar(flux * crate::spectrum::sinc(half), phase);
        }
        Complex64::new(0.0, self.height / w2) * sum
    }

    /// Its edges' sine and phase tables on `|k_a| ≤ kmax`, where they fit their memory
    /// ([`polygon_lattice::tables_fit`](super::polygon_lattice::tables_fit)).
    fn lattice_tables(&self, kmax: usize) -> Option<super::polygon_lattice::PolygonTables> {
        use super::polygon_lattice::{tables_fit, PolygonTables};
        let edges: Vec<_> = self.edges().collect();
        let lattice = crate::spectrum::Lattice { dimension: 2, kmax };
        tables_fit(edges.len(), lattice)
            .then(|| PolygonTables::new(&edges, self.area, self.height, kmax))
    }

    /// The length of the polygon's section by the line `x_axis = value` (even–odd rule).
    fn chord(&self, axis: usize, value: f64) -> f64 {
        let other = 1 - axis;
        let mut crossings: Vec<f64> = self
            .edges()
            .filter(|(a, b)| (a[axis] <= value) != (b[axis] <= value))
            .map(|(a, b)| {
                let t = (value - a[axis]) / (b[axis] - a[axis]);
                a[other] + t * (b[other] - a[other])
            })
            .collect();
        crossings.sort_by(f64::total_cmp);
        crossings.chunks_exact(2).map(|p| p[1] - p[0]).sum()
    }
}

/// The first pair of non-adjacent edges that cross, if any (`O(n²)`).
fn crossing_edges(v: &[[f64; 2]]) -> Option<(usize, usize)> {
    let n = v.len();
    for i in 0..n {
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue; // adjacent through the closing edge
            }
            let (p, q) = (v[i], v[(i + 1) % n]);
            let (r, s) = (v[j], v[(j + 1) % n]);
            let (d1, d2) = (cross(p, q, r), cross(p, q, s));
            let (d3, d4) = (cross(r, s, p), cross(r, s, q));
            if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
                return Some((i, j));
            }
        }
    }
    None
}

impl Polygon {
    /// The area of the polygon inside the box `[lo, hi]`: the polygon clipped by the box's four
    /// half-planes ([`clipped_area`]).
    fn area_in_box(&self, lo: &[f64], hi: &[f64]) -> f64 {
        let [x0, y0, x1, y1] = [lo[0], lo[1], hi[0], hi[1]];
        let (min, max) = self.bounds;
        if max[0] <= x0 || min[0] >= x1 || max[1] <= y0 || min[1] >= y1 {
            return 0.0;
        }
        // Called for every cell of every grid the cell forms read: the clipped parts live in
        // two buffers of the thread's, reused from call to call.
        CLIP_BUFFERS.with_borrow_mut(|[part, next]| {
            let planes = [
                ([-1.0, 0.0], -x0),
                ([1.0, 0.0], x1),
                ([0.0, -1.0], -y0),
                ([0.0, 1.0], y1),
            ];
            clipped_area(&self.vertices, &planes, [x0, y0], [part, next])
        })
    }
}

/// The area of the part of the simple polygon `polygon` where `n·x ≤ level` for each of
/// `planes` (Sutherland–Hodgman keeps the area of any simple polygon clipped by a convex
/// window; the edges it adds along the window enclose nothing), in the buffers `part` and
/// `next`, whose allocations the caller reuses. The shoelace is summed about `corner`: its
/// products are then of the window's size, not the square's, so a small cell's area rounds
/// relative to itself (a cell of 1e-6 about the origin would carry 1e-10 of rounding).
fn clipped_area(
    polygon: &[[f64; 2]],
    planes: &[([f64; 2], f64)],
    corner: [f64; 2],
    [part, next]: [&mut Vec<[f64; 2]>; 2],
) -> f64 {
    part.clear();
    part.extend_from_slice(polygon);
    for &(n, level) in planes {
        if part.len() < 3 {
            return 0.0;
        }
        clip_into(part, n, level, next);
        std::mem::swap(part, next);
    }
    if part.len() < 3 {
        return 0.0;
    }
    for p in part.iter_mut() {
        *p = [p[0] - corner[0], p[1] - corner[1]];
    }
    signed_area(part).max(0.0)
}

/// How far an edge's computed height at a strip's side, and the cell it falls in, may be from
/// the line's, in the square's units: the height `a + (x − a₀)/(b₀ − a₀) · (b − a)` (every
/// term at most 1 in the square) rounds five times, within `7ε`, and the cell's index
/// `⌊y m⌋` once more, within `ε` of `y`; `32ε` leaves room.
const STRIP_ROUNDING: f64 = 32.0 * f64::EPSILON;

/// Whether `x` is, to the bit, one of the lines `j / m` (`j = 0..=m`) that bound `m` cells.
fn on_grid_line(x: f64, m: f64) -> bool {
    let j = (x * m).round();
    (0.0..=m).contains(&j) && j / m == x
}

/// Where the boundary meets the strips of a grid across one axis (strip `i`: the cells whose
/// index on that axis is `i`; across axis 0 the strips are columns, across axis 1 rows), in
/// flat arrays: per strip, the ranges of cells the boundary touches, widened by
/// [`STRIP_ROUNDING`] so that rounding never calls a touched cell whole, and where the boundary
/// crosses the strip's centre line. Every cell no range holds lies wholly inside or wholly
/// outside the polygon, as the parity of the crossings below its centre says (the polygon lies
/// in the square, so below it is outside).
struct Strips {
    /// Strip `i`'s ranges are `ranges[range_at[i]..range_at[i + 1]]`, sorted.
    range_at: Vec<usize>,
    ranges: Vec<Touch>,
    /// Strip `i`'s crossings are `crossings[crossing_at[i]..crossing_at[i + 1]]`, sorted.
    crossing_at: Vec<usize>,
    crossings: Vec<f64>,
    /// Cells per strip.
    cells: usize,
}

/// The cells `lo..=hi` of a strip that one edge touches, and that edge's index when it crosses
/// the whole strip ([`NO_EDGE`] otherwise): in the cells no other edge touches, the polygon is
/// then the half-plane on its side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Touch {
    lo: usize,
    hi: usize,
    spanning: u32,
}

/// [`Touch::spanning`] of an edge that ends inside the strip.
const NO_EDGE: u32 = u32::MAX;

/// One strip of [`Strips`].
struct Strip<'a> {
    ranges: &'a [Touch],
    crossings: &'a [f64],
    cells: usize,
}

impl Strips {
    fn len(&self) -> usize {
        self.range_at.len() - 1
    }

    fn strip(&self, i: usize) -> Strip<'_> {
        Strip {
            ranges: &self.ranges[self.range_at[i]..self.range_at[i + 1]],
            crossings: &self.crossings[self.crossing_at[i]..self.crossing_at[i + 1]],
            cells: self.cells,
        }
    }
}

impl Strip<'_> {
    /// The touched cells as disjoint increasing runs `start..end`.
    fn touched_runs(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.ranges
            .iter()
            .scan(0, |next, t| {
                let start = t.lo.max(*next);
                *next = (*next).max(t.hi + 1);
                Some((start, t.hi + 1))
            })
            .filter(|&(start, end)| start < end)
    }

    /// Calls `visit(start, end, edge)` for the touched cells as disjoint increasing runs,
    /// [`touched_runs`](Self::touched_runs) split where a second range begins: `edge` is the one
    /// edge that alone touches every cell of the run and crosses the whole strip, if there is
    /// one.
    fn for_each_touched(&self, mut visit: impl FnMut(usize, usize, Option<usize>)) {
        let mut next = 0;
        for (k, t) in self.ranges.iter().enumerate() {
            let (start, end) = (t.lo.max(next), t.hi + 1);
            next = next.max(end);
            if start >= end {
                continue;
            }
            // The earlier ranges end before `start`, and the later ones begin no lower than the
            // next: the cells below it are this range's alone.
            let alone = self
                .ranges
                .get(k + 1)
                .map_or(end, |u| u.lo.clamp(start, end));
            if start < alone {
                visit(
                    start,
                    alone,
                    (t.spanning != NO_EDGE).then_some(t.spanning as usize),
                );
            }
            if alone < end {
                visit(alone, end, None);
            }
        }
    }

    /// How many crossings lie below the centre of cell `c`.
    fn crossings_below(&self, c: usize) -> usize {
        let centre = cell_centre(c, self.cells as f64);
        self.crossings.partition_point(|&y| y < centre)
    }

    /// Calls `visit(start, end)` for each run of untouched cells `start..end` that lies inside.
    ///
    /// A cell's side is inside when an odd number of crossings lie below its centre. Within a
    /// run of untouched cells that count changes only at an edge on a grid line (every other
    /// edge's crossing lies in the cells it touches), so each run is split where such a
    /// crossing passes from below one cell's centre to below the next's.
    fn for_each_inside_run(&self, mut visit: impl FnMut(usize, usize)) {
        let cells = self.cells as f64;
        let ends = self
            .touched_runs()
            .map(|(start, _)| start)
            .chain(std::iter::once(self.cells));
        let starts = std::iter::once(0).chain(self.touched_runs().map(|(_, end)| end));
        for (start, end) in starts.zip(ends).filter(|&(start, end)| start < end) {
            let (mut from, mut count) = (start, self.crossings_below(start));
            loop {
                // The first cell of the run with more crossings below its centre.
                let next = match self.crossings.get(count) {
                    Some(&y) if y < cell_centre(end - 1, cells) => {
                        first_centre_above(y, cells).max(from + 1)
                    }
                    _ => end,
                };
                if count % 2 == 1 {
                    visit(from, next);
                }
                if next == end {
                    break;
                }
                (from, count) = (next, self.crossings_below(next));
            }
        }
    }
}

/// The centre `(c + 1/2)/m` of cell `c` of `m` along a strip (or of strip `c` of `m`), as every
/// parity test computes it.
fn cell_centre(c: usize, m: f64) -> f64 {
    (c as f64 + 0.5) / m
}

/// The first cell of `m` whose centre ([`cell_centre`]) lies above `y`.
fn first_centre_above(y: f64, m: f64) -> usize {
    let mut c = (y * m - 0.5).floor().max(0.0) as usize;
    while c > 0 && cell_centre(c - 1, m) > y {
        c -= 1;
    }
    while cell_centre(c, m) <= y {
        c += 1;
    }
    c
}

impl Polygon {
    /// Calls `visit(strip, touched, crossing)` for each strip of `grid` across axis `across`
    /// that each edge meets: the cells it touches (widened by [`STRIP_ROUNDING`]), if any, and
    /// where it crosses the strip's centre line, if it does.
    ///
    /// An edge that lies on a line of the grid (the square's faces, and any axis-aligned edge at
    /// a multiple of the cell side) passes through no cell's interior: it touches none. The
    /// cells beside it are whole or empty unless another edge passes through them, and that
    /// edge touches them; the parity of the crossings still classifies them, so such an edge
    /// keeps its crossings. The line must be the grid's to the bit (`j / m` as the cells'
    /// sides are computed), so that the clips it spares would have cut nothing.
    fn visit_strips(
        &self,
        grid: &[usize],
        across: usize,
        mut visit: impl FnMut(usize, Option<Touch>, Option<f64>),
    ) {
        let along = 1 - across;
        let (fx, fy) = (grid[across] as f64, grid[along] as f64);
        let to_cell = |y: f64| (y * fy).floor().clamp(0.0, fy - 1.0) as usize;
        for (e, (a, b)) in self.edges().enumerate() {
            let (a, b) = ([a[across], a[along]], [b[across], b[along]]);
            if a[0] == b[0] && on_grid_line(a[0], fx) {
                // Along a strips' boundary: no cell touched, and no strip's centre crossed.
                continue;
            }
            let touches = !(a[1] == b[1] && on_grid_line(a[1], fy));
            let (xmin, xmax) = (a[0].min(b[0]), a[0].max(b[0]));
            let y_at = |x: f64| a[1] + (x - a[0]) / (b[0] - a[0]) * (b[1] - a[1]);
            let first = ((xmin * fx).floor() - 1.0).clamp(0.0, fx - 1.0) as usize;
            let last = ((xmax * fx).floor() + 1.0).clamp(0.0, fx - 1.0) as usize;
            for i in first..=last {
                let (x0, x1) = (i as f64 / fx, (i + 1) as f64 / fx);
                if xmax < x0 || xmin > x1 {
                    continue;
                }
                let (ya, yb) = if a[0] == b[0] {
                    (a[1], b[1])
                } else {
                    (y_at(x0.max(xmin)), y_at(x1.min(xmax)))
                };
                let touched = touches.then(|| Touch {
                    lo: to_cell(ya.min(yb) - STRIP_ROUNDING),
                    hi: to_cell(ya.max(yb) + STRIP_ROUNDING),
                    spanning: if xmin <= x0 && xmax >= x1 {
                        e as u32
                    } else {
                        NO_EDGE
                    },
                });
                // Half-open across the strip, so a vertex on the line counts once.
                let centre = cell_centre(i, fx);
                let crossing = ((a[0] > centre) != (b[0] > centre)).then(|| y_at(centre));
                visit(i, touched, crossing);
            }
        }
    }

    /// The [`Strips`] of `grid` across axis `across`: the edges are visited twice, once to
    /// count each strip's entries and once to place them.
    fn strips(&self, grid: &[usize], across: usize) -> Strips {
        let count = grid[across];
        let (mut range_at, mut crossing_at) = (vec![0; count + 1], vec![0; count + 1]);
        self.visit_strips(grid, across, |i, touched, crossing| {
            range_at[i + 1] += usize::from(touched.is_some());
            crossing_at[i + 1] += usize::from(crossing.is_some());
        });
        for i in 0..count {
            range_at[i + 1] += range_at[i];
            crossing_at[i + 1] += crossing_at[i];
        }
        let mut ranges = vec![
            Touch {
                lo: 0,
                hi: 0,
                spanning: NO_EDGE
            };
            range_at[count]
        ];
        let mut crossings = vec![0.0; crossing_at[count]];
        // Each strip's start serves as its cursor, which then ends at the next strip's start:
        // shifted back by one, the starts are restored.
        self.visit_strips(grid, across, |i, touched, crossing| {
            if let Some(range) = touched {
                ranges[range_at[i]] = range;
                range_at[i] += 1;
            }
            if let Some(y) = crossing {
                crossings[crossing_at[i]] = y;
                crossing_at[i] += 1;
            }
        });
        for at in [&mut range_at, &mut crossing_at] {
            at.copy_within(0..count, 1);
            at[0] = 0;
        }
        for i in 0..count {
            ranges[range_at[i]..range_at[i + 1]].sort_unstable();
            crossings[crossing_at[i]..crossing_at[i + 1]].sort_by(f64::total_cmp);
        }
        Strips {
            range_at,
            ranges,
            crossing_at,
            crossings,
            cells: grid[1 - across],
        }
    }

    /// Calls `visit(j, area)` with the polygon's area in each cell `j` of strip `i` (of `grid`
    /// across axis `across`) that the boundary touches. Where one edge alone touches the cell
    /// and crosses the whole strip, the polygon there is that edge's half-plane where its line
    /// passes through the cell ([`Polygon::area_beside_edge`]), and the cell is whole or empty
    /// where it does not; elsewhere the polygon is clipped to the strip (once, when first
    /// needed) and that part to the cell, in `buffers`.
    fn for_each_touched_area(
        &self,
        (strips, i): (&Strips, usize),
        (grid, across): (&[usize], usize),
        buffers: &mut [Vec<[f64; 2]>; 3],
        mut visit: impl FnMut(usize, f64),
    ) {
        let along = 1 - across;
        let (fx, fy) = (grid[across] as f64, grid[along] as f64);
        let (x0, x1) = (i as f64 / fx, (i + 1) as f64 / fx);
        let toward = |axis: usize, sign: f64| {
            let mut n = [0.0; 2];
            n[axis] = sign;
            n
        };
        let [strip_part, part, next] = buffers;
        let mut clipped = false;
        let strip = strips.strip(i);
        strip.for_each_touched(|start, end, edge| {
            for j in start..end {
                let (y0, y1) = (j as f64 / fy, (j + 1) as f64 / fy);
                let area = match edge {
                    Some(e) => self
                        .area_beside_edge(e, across, [x0, x1], [y0, y1])
                        .unwrap_or_else(|| {
                            // Whole or empty, as the parity at its centre says.
                            let odd = strip.crossings_below(j) % 2 == 1;
                            if odd {
                                (x1 - x0) * (y1 - y0)
                            } else {
                                0.0
                            }
                        }),
                    None => {
                        if !clipped {
                            clip_into(&self.vertices, toward(across, -1.0), -x0, next);
                            strip_part.clear();
                            if next.len() >= 3 {
                                clip_into(next, toward(across, 1.0), x1, strip_part);
                            }
                            clipped = true;
                        }
                        let planes = [(toward(along, -1.0), -y0), (toward(along, 1.0), y1)];
                        let mut corner = [0.0; 2];
                        (corner[across], corner[along]) = (x0, y0);
                        clipped_area(strip_part, &planes, corner, [part, next])
                    }
                };
                visit(j, area);
            }
        });
    }

    /// The area of the cell `[x0, x1] × [y0, y1]` (in the strips' frame, `x` across them) on the
    /// polygon's side of edge `e`, which crosses the whole strip while no other edge touches the
    /// cell, when the edge's line passes through the cell's interior; `None` when it may not.
    ///
    /// Inside the cell the boundary is then that line alone (the edge's ends lie outside the
    /// open strip, and an edge on a grid line lies on the cell's sides), so the polygon there is
    /// the half-plane left of the edge (its vertices turn counter-clockwise), right of it in the
    /// frame across axis 1, whose axes are swapped. A line that misses the interior, or may by
    /// its rounding, leaves a cell that is whole or empty, but not always on this line's side:
    /// an end of the edge at a corner of the cell turns there, and an edge on a grid line may
    /// lie between. The caller then reads the cell's side from the parity of the crossings
    /// below its centre, which counts every edge; the cell is whole or empty but for a sliver
    /// of the depth the line may enter by, within [`STRIP_ROUNDING`].
    ///
    /// The line's height over the cell's width is linear between the cell's sides, so the mean
    /// of its clamp to the cell is exact from the two ends ([`mean_clamped`]). The height is
    /// taken along the axis on which the line is less steep, where its rounding is a few ε (as
    /// a clip's crossing is), not amplified by the slope; [`STRIP_ROUNDING`] bounds it.
    fn area_beside_edge(
        &self,
        e: usize,
        across: usize,
        [x0, x1]: [f64; 2],
        [y0, y1]: [f64; 2],
    ) -> Option<f64> {
        let (p, q) = (
            self.vertices[e],
            self.vertices[(e + 1) % self.vertices.len()],
        );
        let (a, b) = ([p[across], p[1 - across]], [q[across], q[1 - across]]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let (w, h) = (x1 - x0, y1 - y0);
        // The part of the cell below (before) a line whose height (width) runs from `c0` to `c1`
        // over the cell, if the line clearly passes through it.
        let crossing = |c0: f64, c1: f64, side: f64, length: f64| {
            let (lo, hi) = (c0.min(c1), c0.max(c1));
            (hi > STRIP_ROUNDING && lo < side - STRIP_ROUNDING)
                .then(|| length * mean_clamped(c0, c1, side))
        };
        let left = if dy.abs() <= dx.abs() {
            let slope = dy / dx;
            let height = |x: f64| (a[1] - y0) + (x - a[0]) * slope;
            let below = crossing(height(x0), height(x1), h, w)?;
            // Left of a line running towards +x is above it.
            if dx > 0.0 {
                w * h - below
            } else {
                below
            }
        } else {
            let slope = dx / dy;
            let width = |y: f64| (a[0] - x0) + (y - a[1]) * slope;
            let before = crossing(width(y0), width(y1), w, h)?;
            // Left of a line running towards +y is before it in x.
            if dy > 0.0 {
                before
            } else {
                w * h - before
            }
        };
        let inside = if across == 0 { left } else { w * h - left };
        Some(inside.clamp(0.0, w * h))
    }

    /// [`CellSums`](super::CellSums) over the `mx × my` cells of `grid`, visiting only the cells
    /// the boundary touches: every other cell lies wholly inside (mean `height`, no inner
    /// variance) or wholly outside.
    fn polygon_cell_sums(&self, grid: &[usize]) -> super::CellSums {
        let (a, cells_f) = (self.height, (grid[0] * grid[1]) as f64);
        let strips = self.strips(grid, 0);
        let column = |buffers: &mut [Vec<[f64; 2]>; 3], i: usize| {
            let (mut squares, mut within) = (CompensatedSum::default(), CompensatedSum::default());
            let mut inside = 0;
            strips
                .strip(i)
                .for_each_inside_run(|start, end| inside += end - start);
            squares.add(a * a * inside as f64);
            let mut touched = 0;
            self.for_each_touched_area((&strips, i), (grid, 0), buffers, |_, area| {
                let mean = a * area * cells_f;
                squares.add(mean * mean);
                within.add((a * a * area * cells_f - mean * mean).max(0.0));
                touched += 1;
            });
            (squares.value(), within.value(), touched)
        };
        let columns: Vec<(f64, f64, u64)> = (0..strips.len())
            .into_par_iter()
            .map_init(|| [Vec::new(), Vec::new(), Vec::new()], column)
            .collect();
        super::CellSums::of_columns(columns)
    }

    /// `∫_c f` over the `mx × my` cells of `grid`, row by row, with the cells on which `f` is
    /// constant: only the cells the boundary touches are computed
    /// ([`Polygon::for_each_touched_area`]); the other cells are the height times the cell's
    /// area, or 0.
    fn polygon_grid_masses(&self, grid: &[usize]) -> super::GridMasses {
        let mx = grid[0];
        let area = 1.0 / (grid[0] * grid[1]) as f64;
        let whole = self.height * area;
        let strips = self.strips(grid, 1);
        // Every cell constant until its area says otherwise.
        let constant = super::ConstantCells::all(mx * grid[1]);
        let mut masses = vec![0.0; mx * grid[1]];
        masses.par_chunks_mut(mx).enumerate().for_each_init(
            || [Vec::new(), Vec::new(), Vec::new()],
            |buffers, (j, row)| {
                strips
                    .strip(j)
                    .for_each_inside_run(|start, end| row[start..end].fill(whole));
                self.for_each_touched_area((&strips, j), (grid, 1), buffers, |i, clipped| {
                    row[i] = self.height * clipped;
                    if !super::constant_on_cell(row[i], self.height * row[i], area) {
                        constant.clear(j * mx + i);
                    }
                });
            },
        );
        super::GridMasses {
            masses,
            constant: Some(constant.into_words()),
        }
    }
}

/// The mean over `t ∈ [0, 1]` of `clamp(c0 + (c1 − c0) t, 0, h)`: the share of `t` on which the
/// linear height lies within `[0, h]`, at the mean of its ends there, and the share above, at
/// `h`, each from the height's run (exact pieces of a linear function).
fn mean_clamped(c0: f64, c1: f64, h: f64) -> f64 {
    let (lo, hi) = (c0.min(c1), c0.max(c1));
    if hi <= 0.0 {
        return 0.0;
    }
    if lo >= h {
        return h;
    }
    let run = hi - lo;
    if run == 0.0 {
        // A level line, inside the cell's height.
        return lo;
    }
    let (bottom, top) = (lo.max(0.0), hi.min(h));
    (top - bottom) / run * (0.5 * (bottom + top)) + (hi - top) / run * h
}

impl Integrand for Polygon {
    fn cell_sums(&self, grid: &[usize]) -> Option<super::CellSums> {
        (grid.len() == 2 && grid.iter().all(|&m| m > 0)).then(|| self.polygon_cell_sums(grid))
    }
    fn grid_masses(&self, grid: &[usize], t: &[f64]) -> Option<super::GridMasses> {
        // Shifted, the polygon wraps across the faces into up to four pieces: one box a cell.
        let unshifted = t.iter().all(|&x| x == 0.0);
        (unshifted && grid.len() == 2 && grid.iter().all(|&m| m > 0))
            .then(|| self.polygon_grid_masses(grid))
    }
    fn box_moments(&self, lo: &[f64], hi: &[f64]) -> Option<(f64, f64)> {
        if self.is_box {
            // The products the rows of `separable_cells` give, in the same order, so that the
            // two agree to the bit.
            let (min, max) = self.bounds;
            let (mut mass, mut square) = (self.height, self.height * self.height);
            for a in 0..2 {
                let length = interval_cells::overlap(lo[a], hi[a], min[a], max[a]);
                mass *= length;
                square *= length;
            }
            return Some((mass, square));
        }
        let area = self.area_in_box(lo, hi);
        Some((self.height * area, self.height * self.height * area))
    }
    fn separable_cells(&self, grid: &[usize]) -> Option<super::SeparableCells> {
        self.shifted_separable_cells(grid, &[0.0, 0.0])
    }
    fn shifted_separable_cells(&self, grid: &[usize], t: &[f64]) -> Option<super::SeparableCells> {
        // The indicator is its own square: one row per axis serves both moments.
        let mass = self.interval_rows(grid, t)?;
        Some(super::SeparableCells {
            height: self.height,
            square: mass.clone(),
            mass,
        })
    }
    fn separable_details(&self, grid: &[usize], t: &[f64]) -> Option<super::SeparableDetails> {
        if !(self.is_box && grid.len() == 2 && t.len() == 2 && !grid.contains(&0)) {
            return None;
        }
        let (min, max) = self.bounds;
        Some(super::SeparableDetails {
            height: self.height,
            axes: (0..2)
                .map(|a| interval_cells::details(min[a], max[a], grid[a], t[a]))
                .collect(),
        })
    }
    fn product_form(&self) -> Option<super::ProductForm> {
        let (lo, hi) = self.bounds;
        self.is_box.then(|| super::ProductForm {
            height: self.height,
            axes: (0..2)
                .map(|a| super::AxisFactor::Interval {
                    lo: lo[a],
                    hi: hi[a],
                })
                .collect(),
        })
    }
    fn kind(&self) -> IntegrandKind {
        IntegrandKind::Polygon
    }
    fn label(&self) -> String {
        self.label.clone()
    }
    fn is_isotropic(&self) -> bool {
        false
    }
    fn dimension(&self) -> usize {
        2
    }
    fn eval(&self, x: &[f64]) -> f64 {
        // Even–odd rule: a ray towards +x crosses the boundary an odd number of times. No edge
        // spans a height outside the box's, so there (and at its top) the ray crosses none.
        let (px, py) = (x[0], x[1]);
        let (low, high) = (self.bounds.0[1], self.bounds.1[1]);
        if !(py >= low && py < high) {
            return 0.0;
        }
        let mut inside = false;
        for s in &self.spans {
            // The edge's span is half-open, so a ray through a vertex counts it once.
            inside ^= py >= s.lo && py < s.hi && px < s.a[0] + (py - s.a[1]) * s.slope;
        }
        if inside {
            self.height
        } else {
            0.0
        }
    }
    fn integral(&self) -> f64 {
        self.height * self.area
    }
    fn integral_of_square(&self) -> f64 {
        self.height * self.height * self.area
    }
    fn coefficient(&self, k: &[i64]) -> Complex64 {
        self.transform([k[0] as f64, k[1] as f64])
    }
    fn power_on_lattice(&self, lattice: crate::spectrum::Lattice, out: &mut [f64]) {
        match self.lattice_tables(lattice.kmax) {
            Some(tables) => tables.power_on_lattice(lattice, out),
            None => super::on_lattice(lattice, out, |k| self.coefficient(k).norm_sqr()),
        }
    }
    fn coefficients_on_lattice(&self, lattice: crate::spectrum::Lattice, out: &mut [Complex64]) {
        match self.lattice_tables(lattice.kmax) {
            Some(tables) => tables.coefficients_on_lattice(lattice, out),
            None => super::on_lattice(lattice, out, |k| self.coefficient(k)),
        }
    }
    fn coefficient_tables(&self, kmax: usize) -> Option<Box<dyn super::CoefficientTables>> {
        self.lattice_tables(kmax)
            .map(|t| Box::new(t) as Box<dyn super::CoefficientTables>)
    }
    fn square_coefficient(&self, k: &[i64]) -> Option<Complex64> {
        // An indicator times its height: f² = a f.
        Some(self.coefficient(k) * self.height)
    }
    fn projection_energy(&self, axis: usize) -> f64 {
        // The section length is linear between the vertices' coordinates along the axis, so
        // its square is quadratic there: two Gauss points per piece are exact.
        let mut cuts: Vec<f64> = self.vertices.iter().map(|v| v[axis]).collect();
        cuts.push(0.0);
        cuts.push(1.0);
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let rule = GaussLegendre::new(2);
        let h2 = self.height * self.height;
        cuts.windows(2)
            .map(|w| rule.integrate(w[0], w[1], |x| self.chord(axis, x).powi(2)))
            .sum::<f64>()
            * h2
    }
    fn fourier(&self, omega: &[f64]) -> Complex64 {
        self.transform([omega[0], omega[1]])
    }
    /// `a² Σ_m area(P ∩ (P + r + m))` over the images `m ∈ {0, −1}²` of `r` reduced to
    /// `[0, 1)²` (the others miss the square), each overlap by clipping the polygon with the
    /// triangles of its moved copy; `None` for a polygon of more than 512 vertices.
    fn autocorrelation(&self, r: &[f64]) -> Option<f64> {
        let triangles = self
            .triangles
            .get_or_init(|| super::polygon_overlap::triangulate(&self.vertices))
            .as_ref()?;
        let s = [r[0] - r[0].floor(), r[1] - r[1].floor()];
        let convex = self
            .convex
            .get_or_init(|| super::polygon_overlap::ConvexOverlap::new(&self.vertices, self.area));
        // The quadratures in space take millions of values: each thread keeps its buffers.
        thread_local! {
            static SCRATCH: std::cell::RefCell<super::polygon_overlap::ClipScratch> =
                Default::default();
        }
        let area: f64 = SCRATCH.with_borrow_mut(|scratch| {
            [[0.0, 0.0], [-1.0, 0.0], [0.0, -1.0], [-1.0, -1.0]]
                .iter()
                .map(|m| {
                    let shift = [s[0] + m[0], s[1] + m[1]];
                    let (lo, hi) = self.bounds;
                    if (0..2).any(|a| shift[a].abs() >= hi[a] - lo[a]) {
                        // Moved past its own extent: no overlap.
                        return 0.0;
                    }
                    // The image nearest the origin, for a convex polygon: its closed form
                    // while no edge vanishes.
                    let nearest = shift.iter().all(|t| t.abs() <= 0.5);
                    convex
                        .as_ref()
                        .filter(|_| nearest)
                        .and_then(|c| c.shared_area(shift))
                        .unwrap_or_else(|| {
                            super::polygon_overlap::shared_area(
                                &self.vertices,
                                self.bounds,
                                triangles,
                                shift,
                                scratch,
                            )
                        })
                })
                .sum()
        });
        Some(self.height * self.height * area)
    }
    fn autocorrelation_beyond(&self, distance: f64) -> Option<f64> {
        // a(r) vanishes once r exceeds the polygon's extent along an axis; below, it is at
        // most ∫f² (Cauchy–Schwarz).
        let (lo, hi) = self.bounds;
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        Some(if distance > extent {
            0.0
        } else {
            self.integral_of_square()
        })
    }
    fn spectral_integral(&self) -> f64 {
        self.integral()
    }
    fn spectral_energy(&self) -> f64 {
        self.integral_of_square()
    }
    fn radial_power(&self, rho: f64) -> f64 {
        super::circular_mean_power(rho, |nu| self.transform(nu))
    }
    fn decay_exponent(&self) -> f64 {
        3.0
    }
    fn panel_width(&self) -> f64 {
        0.25
    }
    fn negligible_beyond(&self) -> f64 {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The clamped linear height's mean against the midpoint rule on 2^16 panels (exact on each
    /// panel but the few where the clamp bends, each off by at most `h / panels`), the level
    /// and the degenerate cases included.
    #[test]
    fn the_clamped_height_is_its_mean() {
        const PANELS: usize = 1 << 16;
        let h = 0.7;
        let ends = [-0.4, -0.0, 0.0, 0.1, 0.35, 0.7, 0.9, 1.6];
        for &c0 in &ends {
            for &c1 in &ends {
                let midpoint = (0..PANELS)
                    .map(|k| {
                        let t = (k as f64 + 0.5) / PANELS as f64;
                        (c0 + (c1 - c0) * t).clamp(0.0, h)
                    })
                    .sum::<f64>()
                    / PANELS as f64;
                let mean = mean_clamped(c0, c1, h);
                assert!(
                    (mean - midpoint).abs() <= 2.0 * h / PANELS as f64,
                    "{c0} → {c1}: {mean} against {midpoint}"
                );
            }
        }
    }

    /// A box's rows give the moments `box_moments` gives, to the bit, and both are the clipped
    /// area of the general polygon to rounding, on cells inside, outside and across its edges.
    #[test]
    fn a_box_factors_by_axis() {
        let boxed =
            Polygon::new(vec![[0.2, 0.3], [0.7, 0.3], [0.7, 0.8], [0.2, 0.8]], 2.5).unwrap();
        assert!(boxed.is_box);
        let grid = [7, 12];
        let rows = boxed.separable_cells(&grid).unwrap();
        for index in 0..grid[0] * grid[1] {
            let (i, j) = (index % grid[0], index / grid[0]);
            let lo = [i as f64 / 7.0, j as f64 / 12.0];
            let hi = [(i + 1) as f64 / 7.0, (j + 1) as f64 / 12.0];
            let from_rows = rows.moments(index);
            assert_eq!(Some(from_rows), boxed.box_moments(&lo, &hi), "cell {index}");
            let clipped = boxed.area_in_box(&lo, &hi);
            assert!((from_rows.0 - 2.5 * clipped).abs() <= 1e-15, "cell {index}");
            assert!(
                (from_rows.1 - 6.25 * clipped).abs() <= 1e-14,
                "cell {index}"
            );
        }
        let rotated = Polygon::new(vec![[0.5, 0.1], [0.9, 0.5], [0.5, 0.9], [0.1, 0.5]], 1.0);
        assert!(rotated.unwrap().separable_cells(&grid).is_none());
    }
}

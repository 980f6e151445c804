//! The volume a ball shares with an axis-aligned box, in 1 to 3 dimensions: exact in 1D and 2D
//! (the disk's area below and left of a corner has a closed form, and a rectangle is four
//! corners by inclusion–exclusion), and in 3D the integral of the 2D areas across the box's
//! shortest side, split where a slice's radius crosses a face or an edge of the box, so that
//! every piece is smooth inside and at most algebraically singular at its ends: a short piece
//! by a pair of Gauss–Legendre rules (after a substitution that flattens its ends where one is
//! singular), any other by the double-exponential rule, which converges exponentially there.

use crate::quadrature::{EmbeddedRules, PanelEstimate};

/// The relative accuracy asked of each 3D piece.
const SLICE_TOLERANCE: f64 = 1e-14;

/// `√(r² − x²)`, from `(r − x)(r + x)`: exact differences near `|x| = r`, where `r² − x²`
/// would cancel.
pub(super) fn half_chord(x: f64, r: f64) -> f64 {
    ((r - x) * (r + x)).max(0.0).sqrt()
}

/// `∫_0^x √(r² − t²) dt` for `|x| ≤ r`. The angle is `atan2(x, √(r² − x²))`, not
/// `asin(x/r)`: near `|x| = r` the arcsine turns a rounding of `x/r` by `ε` into an error of
/// `√ε` (a cell touching the circle where it is tangent to the cell's side lost 8 digits).
fn half_chord_integral(x: f64, r: f64) -> f64 {
    let s = half_chord(x, r);
    0.5 * (x * s + r * r * libm::atan2(x, s))
}

/// The area of the disk (centre `c`, radius `r`) inside `[lo, hi]`.
pub(crate) fn disk_in_rectangle(c: [f64; 2], r: f64, lo: [f64; 2], hi: [f64; 2]) -> f64 {
    let (x0, x1, y0, y1) = (lo[0] - c[0], hi[0] - c[0], lo[1] - c[1], hi[1] - c[1]);
    if x1 <= -r || x0 >= r || y1 <= -r || y0 >= r || r <= 0.0 {
        return 0.0;
    }
    if let Some(whole_or_none) = whole_or_none(&[x0, y0], &[x1, y1], r) {
        return whole_or_none;
    }
    if let Some(area) = small_box_area(r, [x0, x1], [y0, y1]) {
        return area;
    }
    band_area(r, [x0.max(-r), x1.min(r)], [y0, y1]).max(0.0)
}

/// Boxes whose diagonal is at most this share of the radius take [`small_box_area`]: the arcs
/// inside them subtend less than about a quarter of a radian.
const SMALL_BOX_SHARE: f64 = 0.25;

/// Whether boxes of `w × h` are small beside a circle of radius `r`: a diagonal of at most
/// [`SMALL_BOX_SHARE`] `r`, where a circular segment's series holds.
pub(super) fn cells_are_small(w: f64, h: f64, r: f64) -> bool {
    w * w + h * h <= (SMALL_BOX_SHARE * r).powi(2)
}

/// Where a box's side meets the circle, walking the box counterclockwise: entering the disk or
/// leaving it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Boundary {
    /// A corner of the box inside the disk.
    Corner,
    /// The side enters the disk here.
    Entry,
    /// The side leaves the disk here; the region's boundary follows the circle to the next
    /// entry.
    Exit,
}

/// The area of the disk of radius `r` at the origin inside a box `[x0, x1] × [y0, y1]` that the
/// circle crosses, the box small beside the disk (diagonal at most [`SMALL_BOX_SHARE`] `r`):
/// the convex region's vertices (the corners inside and the sides' crossings of the circle,
/// counterclockwise) by the shoelace about the box's corner, plus the circular segment over
/// each chord from an exit to the next entry, `r²(θ − sin θ)/2`, by its series (a corner on
/// the circle is an exit, an entry or a plain corner as its sides leave or enter the disk).
/// Every term is of the box's size, so the area rounds relative to the box (`ε r / side`),
/// where the chord integrals' arctangents, of the disk's size, round by `ε r²` (a relative
/// `3e-6` for cells of side `1e-6`). `None` for larger boxes, and where a side's crossing
/// rounds onto a corner that is not on the circle, or a side touches it (one point where two
/// would be counted).
fn small_box_area(r: f64, [x0, x1]: [f64; 2], [y0, y1]: [f64; 2]) -> Option<f64> {
    if !cells_are_small(x1 - x0, y1 - y0, r) {
        return None;
    }
    let corners = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]];
    let on_circle = corners.map(|p| p[0] * p[0] + p[1] * p[1] == r * r);
    let mut points = [([0.0; 2], Boundary::Corner); 12];
    let mut count = 0;
    for k in 0..4 {
        let (p, q) = (corners[k], corners[(k + 1) % 4]);
        let inside = p[0] * p[0] + p[1] * p[1];
        if on_circle[k] {
            // A corner on the circle is where the region's boundary turns from the box's
            // side to the arc, or back, as its sides point into the disk or out of it.
            let o = corners[(k + 3) % 4];
            let arrives_inside = (p[0] - o[0]) * p[0] + (p[1] - o[1]) * p[1] > 0.0;
            let leaves_inside = (q[0] - p[0]) * p[0] + (q[1] - p[1]) * p[1] < 0.0;
            let kind = match (arrives_inside, leaves_inside) {
                (true, true) => Boundary::Corner,
                (true, false) => Boundary::Exit,
                (false, true) => Boundary::Entry,
                // Both sides leave the disk: the box meets it at this corner alone.
                (false, false) => return Some(0.0),
            };
            points[count] = ([p[0] - x0, p[1] - y0], kind);
            count += 1;
        } else if inside < r * r {
            points[count] = ([p[0] - x0, p[1] - y0], Boundary::Corner);
            count += 1;
        }
        // The side's axis `a` varies from p to q; the other is fixed at `level`.
        let a = if p[1] == q[1] { 0 } else { 1 };
        let level = p[1 - a];
        if level.abs() >= r {
            continue;
        }
        let w = half_chord(level, r);
        let (from, to) = (p[a], q[a]);
        let forward = to > from;
        let (lo, hi) = if forward { (from, to) } else { (to, from) };
        // Walking forward along the axis the side enters at −w and leaves at +w.
        let crossings = if forward {
            [(-w, true), (w, false)]
        } else {
            [(w, true), (-w, false)]
        };
        for (t, entering) in crossings {
            // A crossing at a corner on the circle is that corner, listed as it.
            let at_start = t == from && on_circle[k];
            let at_end = t == to && on_circle[(k + 1) % 4];
            if at_start || at_end {
                continue;
            }
            if t == lo || t == hi {
                return None;
            }
            if t > lo && t < hi {
                let mut point = [0.0; 2];
                point[a] = t;
                point[1 - a] = level;
                let kind = if entering {
                    Boundary::Entry
                } else {
                    Boundary::Exit
                };
                points[count] = ([point[0] - x0, point[1] - y0], kind);
                count += 1;
            }
        }
    }
    let points = &points[..count];
    if count < 2 {
        return None;
    }
    let mut twice_area = 0.0;
    let mut segments = 0.0;
    for k in 0..count {
        let (p, kind) = points[k];
        let (q, next) = points[(k + 1) % count];
        twice_area += p[0] * q[1] - q[0] * p[1];
        if kind == Boundary::Exit {
            if next != Boundary::Entry {
                return None;
            }
            let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
            // Lengths below the radius: no overflow that `hypot` would guard against.
            segments += circular_segment(r, (dx * dx + dy * dy).sqrt());
        }
    }
    Some((0.5 * twice_area + segments).max(0.0))
}

/// The area between a chord of length `c` and its arc on a circle of radius `r`,
/// `r²(θ − sin θ)/2` with `θ = 2 asin(c / 2r)`, for chords up to a quarter of the radius
/// (`θ ≤ 0.2507`): `θ − sin θ` by its series `θ³ Σ_j (−θ²)^j / (2j + 3)!` to `j = 5` (the next
/// term is below `3e-19` of the first), where the difference would cancel.
pub(super) fn circular_segment(r: f64, c: f64) -> f64 {
    let theta = 2.0 * (c / (2.0 * r)).asin();
    let t2 = theta * theta;
    // 1/(2j + 3)! for j = 5 down to 0, in Horner's form.
    const INVERSE_ODD_FACTORIALS: [f64; 6] = [
        1.0 / 6_227_020_800.0,
        1.0 / 39_916_800.0,
        1.0 / 362_880.0,
        1.0 / 5_040.0,
        1.0 / 120.0,
        1.0 / 6.0,
    ];
    let series = INVERSE_ODD_FACTORIALS[1..]
        .iter()
        .fold(INVERSE_ODD_FACTORIALS[0], |acc, &inv| inv - t2 * acc);
    0.5 * r * r * theta * t2 * series
}

/// The volume the ball of radius `r` at the origin shares with the box `[lo, hi]` when the box
/// lies wholly inside it (its farthest corner does) or wholly outside (its nearest point
/// does); `None` when the sphere crosses it.
pub(super) fn whole_or_none(lo: &[f64], hi: &[f64], r: f64) -> Option<f64> {
    let (mut far, mut near) = (0.0, 0.0);
    for (&l, &h) in lo.iter().zip(hi) {
        let f = l.abs().max(h.abs());
        far += f * f;
        let n = if l > 0.0 {
            l
        } else if h < 0.0 {
            -h
        } else {
            0.0
        };
        near += n * n;
    }
    if far <= r * r {
        Some(lo.iter().zip(hi).map(|(l, h)| h - l).product())
    } else if near >= r * r {
        Some(0.0)
    } else {
        None
    }
}

/// `∫_a^b |[−s(x), s(x)] ∩ [y0, y1]| dx` for the disk of radius `r` at the origin,
/// `s(x) = √(r² − x²)`, `−r ≤ a < b ≤ r`. Between the abscissae where the chord's ends cross
/// `y0` or `y1` (`|x| = √(r² − y²)`), each end is either the chord's (`±s`, whose integral is
/// [`half_chord_integral`]) or the band's (a constant): one arctangent per such abscissa and
/// per end of `[a, b]`, rather than per corner and piece.
fn band_area(r: f64, [a, b]: [f64; 2], [y0, y1]: [f64; 2]) -> f64 {
    if b <= a {
        return 0.0;
    }
    let mut cuts = [a, b, 0.0, 0.0, 0.0, 0.0];
    let mut count = 2;
    for y in [y0, y1] {
        if y.abs() < r {
            let w = half_chord(y, r);
            for x in [-w, w] {
                if x > a && x < b {
                    cuts[count] = x;
                    count += 1;
                }
            }
        }
    }
    let cuts = &mut cuts[..count];
    cuts.sort_by(f64::total_cmp);
    let mut total = 0.0;
    let mut left = (cuts[0], half_chord_integral(cuts[0], r));
    for &x in &cuts[1..] {
        let right = (x, half_chord_integral(x, r));
        let (p, q) = (left.0, right.0);
        if q > p {
            // Which end bounds the overlap is the same across the piece: read at its middle,
            // except where the band's side is at or beyond the circle's top or bottom, which
            // the chord reaches at one point at most (the middle may be that point).
            let s = half_chord(0.5 * (p + q), r);
            if s.min(y1) > (-s).max(y0) {
                let chord = right.1 - left.1;
                let top = if y1 >= r || s < y1 {
                    chord
                } else {
                    y1 * (q - p)
                };
                let bottom = if y0 <= -r || -s > y0 {
                    -chord
                } else {
                    y0 * (q - p)
                };
                total += top - bottom;
            }
        }
        left = right;
    }
    total
}

/// The volume of the ball (centre `c`, radius `r`, dimension `c.len()`, 1 to 3) inside the box
/// `[lo, hi]`, the ball not wrapped.
pub(crate) fn ball_in_box(c: &[f64], r: f64, lo: &[f64], hi: &[f64]) -> f64 {
    match c.len() {
        1 => (hi[0].min(c[0] + r) - lo[0].max(c[0] - r)).max(0.0),
        2 => disk_in_rectangle([c[0], c[1]], r, [lo[0], lo[1]], [hi[0], hi[1]]),
        _ => ball_in_cuboid(c, r, lo, hi),
    }
}

fn ball_in_cuboid(c: &[f64], r: f64, lo: &[f64], hi: &[f64]) -> f64 {
    // Each axis's extent within the ball's reach; an empty one leaves nothing.
    let reach: [(f64, f64); 3] =
        std::array::from_fn(|a| (lo[a].max(c[a] - r), hi[a].min(c[a] + r)));
    if reach.iter().any(|(a, b)| b <= a) {
        return 0.0;
    }
    // Wholly inside or outside: no slice to integrate.
    let centred = |v: &[f64]| [v[0] - c[0], v[1] - c[1], v[2] - c[2]];
    if let Some(whole_or_none) = whole_or_none(&centred(lo), &centred(hi), r) {
        return whole_or_none;
    }
    // Slices across the axis where the box is shortest: a slab's pieces are short beside the
    // radius, where a few Gauss–Legendre nodes reach the tolerance.
    let k = (0..3)
        .min_by(|&a, &b| (reach[a].1 - reach[a].0).total_cmp(&(reach[b].1 - reach[b].0)))
        .unwrap_or(2);
    let (i, j) = match k {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let slice = |t: f64| {
        let s = half_chord(t - c[k], r);
        disk_in_rectangle([c[i], c[j]], s, [lo[i], lo[j]], [hi[i], hi[j]])
    };
    // The slice's area changes form where its radius reaches a face line or a corner of the
    // rectangle (and at the equator, where the radius turns).
    let (dx, dy) = ([lo[i] - c[i], hi[i] - c[i]], [lo[j] - c[j], hi[j] - c[j]]);
    let (a, b) = reach[k];
    // Each cut with whether the slice's area is singular there (a kink), rather than
    // analytic through it (a face of the box, a pole of the ball, the equator).
    let mut cuts = [(0.0, false); 3 + 2 * 8];
    cuts[..3].copy_from_slice(&[(a, false), (b, false), (c[k].clamp(a, b), false)]);
    let mut count = 3;
    let distances = dx
        .iter()
        .chain(&dy)
        .map(|v| v.abs())
        .chain(dx.iter().flat_map(|&x| dy.iter().map(move |&y| x.hypot(y))));
    for d in distances.filter(|&d| d < r) {
        let t = half_chord(d, r);
        for z in [c[k] - t, c[k] + t] {
            if z >= a && z <= b {
                cuts[count] = (z, true);
                count += 1;
            }
        }
    }
    let cuts = &mut cuts[..count];
    cuts.sort_by(|p, q| p.0.total_cmp(&q.0));
    let mut total = 0.0;
    let mut start = cuts[0];
    for &next in &cuts[1..] {
        if next.0 > start.0 {
            total += piece_integral(&slice, start, next, r);
            start = next;
        } else {
            // The same place twice: a kink if either is.
            start.1 |= next.1;
        }
    }
    total.max(0.0)
}

/// Pieces at most this share of the radius long first try Gauss–Legendre pairs.
const SHORT_PIECE_SHARE: f64 = 0.125;

/// `∫_a^b slice` to [`SLICE_TOLERANCE`] of the piece's scale (its length times the disk's
/// area), each end given with whether the slice's area is singular there. A short piece
/// whose ends are both analytic tries the plain pair of [`piece_rules`], then any short piece
/// the flat-ended pair after its substitution; a pair's value is kept where its two rules agree
/// to the tolerance, and every other piece takes the double-exponential rule.
fn piece_integral(
    slice: &impl Fn(f64) -> f64,
    (a, kink_at_a): (f64, bool),
    (b, kink_at_b): (f64, bool),
    r: f64,
) -> f64 {
    let tolerance = SLICE_TOLERANCE * (b - a) * std::f64::consts::PI * r * r;
    if b - a <= SHORT_PIECE_SHARE * r {
        let [plain, flat_ended] = piece_rules();
        let agreed = |p: PanelEstimate| (p.error <= tolerance).then_some(p.value);
        let smooth = !(kink_at_a || kink_at_b);
        let plain_value = || agreed(plain.integrate(a, b, |t| (slice(t), 0.0)));
        // `t = a + L φ(s)`, `φ(s) = s²(3 − 2s)`: a piece's ends are where a slice's radius
        // crosses a face line or a corner, where the area goes like a half-integer power of
        // the distance, and `φ`'s flat ends (`φ ∝ s²` at 0, `1 − φ ∝ (1 − s)²` at 1) turn
        // those powers into odd powers of `s` times powers of `3 − 2s` and `1 + 2s`, so the
        // rules converge geometrically.
        let length = b - a;
        let flat_ended_value = || {
            agreed(flat_ended.integrate(0.0, 1.0, |s| {
                let place = a + length * s * s * (3.0 - 2.0 * s);
                (slice(place) * length * 6.0 * s * (1.0 - s), 0.0)
            }))
        };
        if let Some(value) = smooth.then(plain_value).flatten().or_else(flat_ended_value) {
            return value;
        }
    }
    quadrature::double_exponential::integrate(slice, a, b, tolerance).integral
}

/// Points of the plain pair of Gauss–Legendre rules, for a piece whose slice areas are
/// analytic through both ends.
const PLAIN_RULES: (usize, usize) = (4, 6);

/// Points of the flat-ended pair: after its substitution a piece's integrand is analytic
/// within the ellipse through `s = 3/2` and `s = −1/2` (parameter `2 + √3` on `[0, 1]`), where
/// an `n`-point rule errs by about `(2 + √3)^{-2n}` of the integrand's size: `2e-14` at 12
/// points, `6e-19` at 16.
const FLAT_ENDED_RULES: (usize, usize) = (12, 16);

/// The plain and the flat-ended pairs, built once; each keeps the higher rule's value where the
/// two agree to the tolerance (their difference bounds the higher one's error for an integrand
/// analytic on the piece).
fn piece_rules() -> &'static [EmbeddedRules; 2] {
    static RULES: std::sync::OnceLock<[EmbeddedRules; 2]> = std::sync::OnceLock::new();
    RULES.get_or_init(|| {
        [PLAIN_RULES, FLAT_ENDED_RULES].map(|(low, high)| EmbeddedRules::new(low, high))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Rectangles whose sides touch the circle where it turns (the dyadic cells of a centred
    /// disk: `y = 0.25` is its bottom): halves and quarters to rounding, however the band's
    /// sides meet the chords.
    #[test]
    fn sides_at_the_circles_extremes_cut_halves_and_quarters() {
        let (c, r) = ([0.5, 0.5], 0.25);
        let half = PI * r * r / 2.0;
        for (lo, hi, exact) in [
            ([0.0, 0.25], [1.0, 0.5], half),
            ([0.0, 0.5], [1.0, 0.75], half),
            ([0.25, 0.0], [0.5, 1.0], half),
            ([0.5, 0.0], [0.75, 1.0], half),
            ([0.25, 0.25], [0.5, 0.5], half / 2.0),
            ([0.0, 0.25], [0.5, 0.5], half / 2.0),
            ([0.5, 0.5], [1.0, 0.75], half / 2.0),
            ([0.25, 0.25], [0.75, 0.75], 2.0 * half),
        ] {
            let area = disk_in_rectangle(c, r, lo, hi);
            assert!(
                (area - exact).abs() < 4.0 * f64::EPSILON * exact,
                "{lo:?} {hi:?}: {area}"
            );
        }
    }

    #[test]
    fn the_whole_disk_and_its_quarters() {
        let whole = disk_in_rectangle([0.5, 0.5], 0.25, [0.0, 0.0], [1.0, 1.0]);
        assert!((whole - PI / 16.0).abs() < 1e-15);
        let quarter = disk_in_rectangle([0.5, 0.5], 0.25, [0.5, 0.5], [1.0, 1.0]);
        assert!((quarter - PI / 64.0).abs() < 1e-15);
        // A band through the centre of height 2h: 2 (h √(r²−h²) + r² asin(h/r)).
        let (r, h): (f64, f64) = (0.25, 0.1);
        let band = disk_in_rectangle([0.5, 0.5], r, [0.0, 0.5 - h], [1.0, 0.5 + h]);
        let exact = 2.0 * (h * (r * r - h * h).sqrt() + r * r * (h / r).asin());
        assert!((band - exact).abs() < 1e-15);
    }

    #[test]
    fn cells_tile_the_disk() {
        // The areas over an 37 × 37 grid of cells sum to the disk's.
        let m = 37;
        let mut total = 0.0;
        for i in 0..m {
            for j in 0..m {
                let lo = [i as f64 / m as f64, j as f64 / m as f64];
                let hi = [(i + 1) as f64 / m as f64, (j + 1) as f64 / m as f64];
                total += disk_in_rectangle([0.43, 0.58], 0.3, lo, hi);
            }
        }
        assert!((total - PI * 0.09).abs() < 1e-13);
    }

    #[test]
    fn cells_where_the_circle_touches_their_sides_tile_their_band() {
        // The circle's leftmost and rightmost points fall on the cells' sides (x = 0.45 and
        // 0.95 at m = 100, the centre's row at y = 0.5): the band's cells must sum to the band
        // to the rounding of 100 areas, where an arcsine of the clamped ratio lost 8 digits.
        let (c, r, m) = ([0.7, 0.5], 0.25, 100);
        for (y0, y1) in [(0.49, 0.5), (0.5, 0.51)] {
            let band = disk_in_rectangle(c, r, [0.0, y0], [1.0, y1]);
            let cells: f64 = (0..m)
                .map(|i| {
                    let (x0, x1) = (i as f64 / m as f64, (i + 1) as f64 / m as f64);
                    disk_in_rectangle(c, r, [x0, y0], [x1, y1])
                })
                .sum();
            assert!((band - cells).abs() < 1e-14 * band, "{band:e} vs {cells:e}");
        }
    }

    /// Boxes small beside the disk, near its circle at every angle: the shoelace with segments
    /// against the chord integrals, which are accurate to `ε r²` and so, for boxes of a tenth
    /// of the radius, to about `1e-13` of the box.
    /// A box with a corner on the circle (15² + 20² = 25²) and the box's other corners
    /// inside but one: the region's boundary leaves the box's top side there for the arc. Its
    /// area in closed form, `∫_15^16 √(625 − x²) dx − 19`, at radius 25 and scaled by `2^-10`
    /// (exactly: the corner stays on the circle).
    #[test]
    fn a_corner_on_the_circle_turns_onto_the_arc() {
        for scale in [1.0, 1.0 / 1024.0] {
            let r = 25.0 * scale;
            let primitive = |x: f64| 0.5 * (x * (r * r - x * x).sqrt() + r * r * (x / r).asin());
            let truth = primitive(16.0 * scale) - primitive(15.0 * scale) - 19.0 * scale * scale;
            let x = [15.0 * scale, 16.0 * scale];
            let y = [19.0 * scale, 20.0 * scale];
            let area = small_box_area(r, x, y).expect("a small box");
            assert!(
                (area - truth).abs() <= 1e-12 * scale * scale,
                "scale {scale}: {area:e} vs {truth:e}"
            );
            // Its mirror images across the axes: the corner on the circle entered instead.
            let mirrored = small_box_area(r, [-x[1], -x[0]], y).expect("a small box");
            assert!((mirrored - truth).abs() <= 1e-12 * scale * scale);
            // The box beyond the corner meets the disk there alone.
            let beyond = small_box_area(
                r,
                [15.0 * scale, 16.0 * scale],
                [20.0 * scale, 21.0 * scale],
            );
            assert_eq!(beyond, Some(0.0));
        }
    }

    #[test]
    fn small_boxes_agree_with_the_chord_integrals() {
        let r = 0.25;
        let mut compared = 0;
        for k in 0..400 {
            let angle = k as f64 * 0.0157 + 0.003;
            let side = r * (0.02 + 0.15 * ((k * 37) % 100) as f64 / 100.0);
            let (x, y) = (r * angle.cos(), r * angle.sin());
            let (x0, y0) = (x - side * 0.37, y - side * 0.61);
            let (x1, y1) = (x0 + side, y0 + 0.9 * side);
            let Some(small) = small_box_area(r, [x0, x1], [y0, y1]) else {
                continue;
            };
            let band = band_area(r, [x0.max(-r), x1.min(r)], [y0, y1]);
            let area = side * 0.9 * side;
            assert!(
                (small - band).abs() < 1e-12 * area,
                "{k}: {small:e} against {band:e} (box {area:e})"
            );
            compared += 1;
        }
        assert!(compared > 390, "{compared}");
    }

    /// Cells of side `1e-6` on the circle of radius 0.25: each area against Gauss–Legendre on
    /// the cell's column between the abscissae where the chord's ends cross its sides (the
    /// overlap's height is smooth between them), which rounds like `ε r / side` (`3e-11`). The
    /// chord integrals' arctangents of size `r²` rounded by a relative `3e-6` here.
    #[test]
    fn fine_cells_round_relative_to_themselves() {
        let (r, side) = (0.25, 1e-6);
        let rule = crate::quadrature::GaussLegendre::new(20);
        let mut worst: f64 = 0.0;
        for k in 0..200 {
            let angle = 0.011 + k as f64 * 0.0311;
            let (x0, y0) = (
                (r * angle.cos() / side).floor() * side,
                (r * angle.sin() / side).floor() * side,
            );
            let (x1, y1) = (x0 + side, y0 + side);
            let area = disk_in_rectangle([0.0, 0.0], r, [x0, y0], [x1, y1]);
            let height = |x: f64| {
                let s = half_chord(x, r);
                (s.min(y1) - (-s).max(y0)).max(0.0)
            };
            let mut cuts = vec![x0, x1];
            for y in [y0, y1] {
                let w = half_chord(y, r);
                cuts.extend([-w, w].into_iter().filter(|&c| c > x0 && c < x1));
            }
            cuts.sort_by(f64::total_cmp);
            let reference: f64 = cuts
                .windows(2)
                .map(|w| rule.integrate(w[0], w[1], height))
                .sum();
            if reference > 0.0 && reference < side * side {
                worst = worst.max((area - reference).abs() / (side * side));
            }
        }
        assert!(worst < 1e-9, "worst relative error {worst:e}");
    }

    #[test]
    fn cuboids_tile_the_ball() {
        let (c, r) = ([0.47, 0.52, 0.55], 0.31);
        let m = 5;
        let mut total = 0.0;
        for i in 0..m {
            for j in 0..m {
                for k in 0..m {
                    let lo = [i, j, k].map(|v| v as f64 / m as f64);
                    let hi = [i, j, k].map(|v| (v + 1) as f64 / m as f64);
                    total += ball_in_box(&c, r, &lo, &hi);
                }
            }
        }
        let exact = 4.0 / 3.0 * PI * r * r * r;
        assert!((total - exact).abs() < 1e-12 * exact, "{total} {exact}");
    }

    /// Slabs and boxes of every aspect the dyadic grids of a 3D net make (one side `2^-a`,
    /// `2^-b`, `2^-c` with `a + b + c = 12`), at every offset where the sphere crosses them:
    /// the volume, sliced across the shortest side (short pieces by Gauss–Legendre pairs,
    /// plain or substituted), meets the same volume sliced along the last axis by the
    /// double-exponential rule alone, within both rules' tolerance of each piece's scale.
    #[test]
    fn slabs_sliced_across_their_thin_side_meet_slices_along_the_last_axis() {
        let (c, r) = ([0.47, 0.52, 0.55], 0.31);
        let along_last_axis = |lo: &[f64; 3], hi: &[f64; 3]| {
            let slice = |z: f64| {
                let s = half_chord(z - c[2], r);
                disk_in_rectangle([c[0], c[1]], s, [lo[0], lo[1]], [hi[0], hi[1]])
            };
            let (a, b) = (lo[2].max(c[2] - r), hi[2].min(c[2] + r));
            let mut cuts = vec![a, b, c[2].clamp(a, b)];
            for x in [lo[0] - c[0], hi[0] - c[0]] {
                for y in [lo[1] - c[1], hi[1] - c[1]] {
                    for d in [x.abs(), y.abs(), x.hypot(y)] {
                        if d < r {
                            let t = half_chord(d, r);
                            cuts.extend(
                                [c[2] - t, c[2] + t]
                                    .into_iter()
                                    .filter(|z| *z > a && *z < b),
                            );
                        }
                    }
                }
            }
            cuts.sort_by(f64::total_cmp);
            cuts.windows(2)
                .filter(|w| w[1] > w[0])
                .map(|w| {
                    let tolerance = 1e-3 * SLICE_TOLERANCE * (w[1] - w[0]) * PI * r * r;
                    quadrature::double_exponential::integrate(slice, w[0], w[1], tolerance).integral
                })
                .sum::<f64>()
        };
        let (mut checked, mut short) = (0, 0);
        for (a, b) in [(12, 0), (0, 12), (6, 6), (9, 2), (4, 4)] {
            let digits = [a, b, 12 - a - b];
            let side = digits.map(|d| 0.5f64.powi(d));
            // A sample of each grid's cells: a prime stride through them.
            let cells: [usize; 3] = digits.map(|d| 1usize << d);
            for index in (0..cells.iter().product::<usize>()).step_by(7) {
                let at = [
                    index % cells[0],
                    index / cells[0] % cells[1],
                    index / cells[0] / cells[1],
                ];
                let lo: [f64; 3] = std::array::from_fn(|l| at[l] as f64 * side[l]);
                let hi: [f64; 3] = std::array::from_fn(|l| lo[l] + side[l]);
                let centred = |v: &[f64; 3]| [v[0] - c[0], v[1] - c[1], v[2] - c[2]];
                if whole_or_none(&centred(&lo), &centred(&hi), r).is_some() {
                    continue;
                }
                let volume = ball_in_box(&c, r, &lo, &hi);
                let reference = along_last_axis(&lo, &hi);
                let thickest = side.iter().fold(0.0f64, |m, &s| m.max(s.min(2.0 * r)));
                let allowed = 3.0 * SLICE_TOLERANCE * thickest * PI * r * r;
                assert!(
                    (volume - reference).abs() <= allowed,
                    "{lo:?}–{hi:?}: {volume:e} against {reference:e} (allowed {allowed:e})"
                );
                checked += 1;
                short += usize::from(side.iter().any(|&s| s <= SHORT_PIECE_SHARE * r));
            }
        }
        assert!(
            checked > 1000 && short > checked / 2,
            "{checked} boxes, {short} short"
        );
    }
}

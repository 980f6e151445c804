//! The volume a ball shares with an axis-aligned box, in 1 to 3 dimensions: exact in 1D and 2D
//! (the disk's area below and left of a corner has a closed form, and a rectangle is four
//! corners by inclusion–exclusion), and in 3D the integral over height of the 2D areas, split
//! where a slice's radius crosses a face or an edge of the box, so that every piece is smooth
//! inside and at most algebraically singular at its ends, where the double-exponential rule
//! converges exponentially.

/// The relative accuracy asked of each 3D piece.
const SLICE_TOLERANCE: f64 = 1e-14;

/// `√(r² − x²)`, from `(r − x)(r + x)`: exact differences near `|x| = r`, where `r² − x²`
/// would cancel.
fn half_chord(x: f64, r: f64) -> f64 {
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
    band_area(r, [x0.max(-r), x1.min(r)], [y0, y1]).max(0.0)
}

/// The volume the ball of radius `r` at the origin shares with the box `[lo, hi]` when the box
/// lies wholly inside it (its farthest corner does) or wholly outside (its nearest point
/// does); `None` when the sphere crosses it.
fn whole_or_none(lo: &[f64], hi: &[f64], r: f64) -> Option<f64> {
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
    let (a, b) = (lo[2].max(c[2] - r), hi[2].min(c[2] + r));
    if b <= a {
        return 0.0;
    }
    // Wholly inside or outside: no slice to integrate.
    let centred = |v: &[f64]| [v[0] - c[0], v[1] - c[1], v[2] - c[2]];
    if let Some(whole_or_none) = whole_or_none(&centred(lo), &centred(hi), r) {
        return whole_or_none;
    }
    let slice = |z: f64| {
        let s = (r * r - (z - c[2]) * (z - c[2])).max(0.0).sqrt();
        disk_in_rectangle([c[0], c[1]], s, [lo[0], lo[1]], [hi[0], hi[1]])
    };
    // The slice's area changes form where its radius reaches a face line or a corner of the
    // rectangle (and at the equator, where the radius turns).
    let (dx, dy) = ([lo[0] - c[0], hi[0] - c[0]], [lo[1] - c[1], hi[1] - c[1]]);
    let mut distances: Vec<f64> = dx.iter().chain(&dy).map(|v| v.abs()).collect();
    for x in dx {
        for y in dy {
            distances.push(x.hypot(y));
        }
    }
    let mut cuts = vec![a, b, c[2].clamp(a, b)];
    for d in distances.into_iter().filter(|&d| d < r) {
        let t = (r * r - d * d).sqrt();
        cuts.extend(
            [c[2] - t, c[2] + t]
                .into_iter()
                .filter(|z| *z > a && *z < b),
        );
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    cuts.windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| {
            let scale = (w[1] - w[0]) * std::f64::consts::PI * r * r;
            quadrature::double_exponential::integrate(slice, w[0], w[1], SLICE_TOLERANCE * scale)
                .integral
        })
        .sum::<f64>()
        .max(0.0)
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
}

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

/// The area of the disk of radius `r` at the origin with `X ≤ u` and `Y ≤ v`: the integral over
/// `X` of the length of the chord below `v`.
fn quadrant_area(u: f64, v: f64, r: f64) -> f64 {
    let u = u.clamp(-r, r);
    let h = |x: f64| half_chord_integral(x, r);
    if v >= r {
        return 2.0 * (h(u) - h(-r));
    }
    if v <= -r {
        return 0.0;
    }
    // The chord at X runs over |Y| ≤ √(r² − X²); below v it is whole where |X| ≥ w.
    let w = half_chord(v, r);
    let piece = |a: f64, b: f64| {
        let b = b.min(u);
        if b <= a {
            (0.0, 0.0)
        } else {
            (b - a, h(b) - h(a))
        }
    };
    let (middle_length, middle) = piece(-w, w);
    let middle_area = v * middle_length + middle;
    if v >= 0.0 {
        2.0 * (piece(-r, -w).1 + piece(w, r).1) + middle_area
    } else {
        middle_area
    }
}

/// The area of the disk (centre `c`, radius `r`) inside `[lo, hi]`.
pub(crate) fn disk_in_rectangle(c: [f64; 2], r: f64, lo: [f64; 2], hi: [f64; 2]) -> f64 {
    let (x0, x1, y0, y1) = (lo[0] - c[0], hi[0] - c[0], lo[1] - c[1], hi[1] - c[1]);
    if x1 <= -r || x0 >= r || y1 <= -r || y0 >= r || r <= 0.0 {
        return 0.0;
    }
    // Wholly inside the disk: every corner is.
    let far_x = x0.abs().max(x1.abs());
    let far_y = y0.abs().max(y1.abs());
    if far_x * far_x + far_y * far_y <= r * r {
        return (x1 - x0) * (y1 - y0);
    }
    let near = |a: f64, b: f64| {
        if a > 0.0 {
            a
        } else if b < 0.0 {
            -b
        } else {
            0.0
        }
    };
    let (nx, ny) = (near(x0, x1), near(y0, y1));
    if nx * nx + ny * ny >= r * r {
        return 0.0;
    }
    let q = |u, v| quadrant_area(u, v, r);
    (q(x1, y1) - q(x0, y1) - q(x1, y0) + q(x0, y0)).max(0.0)
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

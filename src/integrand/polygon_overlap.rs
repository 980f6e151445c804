//! Areas of clipped polygons: Sutherland–Hodgman clipping by half-planes, the shoelace area,
//! and the area two placements of a simple polygon share: the torus autocorrelation of a polygon's
//! indicator. One placement is cut into triangles (ear clipping); the other is clipped by each
//! triangle's three half-planes (Sutherland–Hodgman keeps the area of any simple polygon clipped
//! by a convex window), and the areas add, since the triangles partition the polygon.

/// Twice the shoelace sum, halved: positive for counter-clockwise vertices.
pub(super) fn signed_area(v: &[[f64; 2]]) -> f64 {
    let n = v.len();
    0.5 * (0..n)
        .map(|i| {
            let (a, b) = (v[i], v[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
}

/// Sutherland–Hodgman: the part of a convex polygon with `n·x ≤ level`.
pub(super) fn clip(polygon: &[[f64; 2]], n: [f64; 2], level: f64) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    clip_into(polygon, n, level, &mut out);
    out
}

/// [`clip`] into `out` (cleared first), whose allocation a caller reuses from call to call.
pub(super) fn clip_into(polygon: &[[f64; 2]], n: [f64; 2], level: f64, out: &mut Vec<[f64; 2]>) {
    let side = |p: [f64; 2]| n[0] * p[0] + n[1] * p[1] - level;
    out.clear();
    let Some(&first) = polygon.first() else {
        return;
    };
    // Each vertex's side is computed once and carried to the next edge (the same values as
    // computing both ends of every edge), and the wrap to the first vertex is a comparison,
    // not a division: this runs once per cell a boundary touches.
    let (mut a, mut sa) = (first, side(first));
    for i in 0..polygon.len() {
        let b = polygon.get(i + 1).copied().unwrap_or(first);
        let sb = side(b);
        if sa <= 0.0 {
            out.push(a);
        }
        if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
            let t = sa / (sa - sb);
            let mut p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            // On a line of one axis (a cell's side) the crossing lies on it exactly: the
            // interpolated coordinate would carry the rounding of the vertices' size, which
            // on a cell a millionth wide is a part in 10^10 of its width.
            if n[1] == 0.0 {
                p[0] = level / n[0];
            } else if n[0] == 0.0 {
                p[1] = level / n[1];
            }
            out.push(p);
        }
        (a, sa) = (b, sb);
    }
}

/// The most vertices a polygon is triangulated with (ear clipping is `O(n²)` per ear found).
pub(super) const MAX_TRIANGULATED: usize = 512;

type Triangle = [[f64; 2]; 3];

/// `(a − o) × (b − o)`: positive when `o, a, b` turn counter-clockwise.
pub(super) fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// The triangles of a simple polygon with counter-clockwise `vertices`, by ear clipping: a
/// convex vertex whose triangle holds no other vertex (on its boundary included) is cut off;
/// a vertex on the line of its neighbours is dropped (its triangle has no area). `None` when
/// no ear is found (a polygon that rounding has made not quite simple) or beyond
/// [`MAX_TRIANGULATED`] vertices.
pub(super) fn triangulate(vertices: &[[f64; 2]]) -> Option<Vec<Triangle>> {
    if vertices.len() > MAX_TRIANGULATED {
        return None;
    }
    let mut ring: Vec<usize> = (0..vertices.len()).collect();
    let mut triangles = Vec::with_capacity(vertices.len());
    while ring.len() > 3 {
        let m = ring.len();
        let ear = (0..m).find_map(|i| {
            let (p, c, n) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
            let (a, b, e) = (vertices[p], vertices[c], vertices[n]);
            let turn = cross(a, b, e);
            if turn == 0.0 {
                return Some((i, None));
            }
            if turn < 0.0 {
                return None;
            }
            let blocked = ring
                .iter()
                .filter(|&&j| j != p && j != c && j != n)
                .any(|&j| {
                    let x = vertices[j];
                    cross(a, b, x) >= 0.0 && cross(b, e, x) >= 0.0 && cross(e, a, x) >= 0.0
                });
            (!blocked).then_some((i, Some([a, b, e])))
        })?;
        if let (_, Some(t)) = ear {
            triangles.push(t);
        }
        ring.remove(ear.0);
    }
    let last = [vertices[ring[0]], vertices[ring[1]], vertices[ring[2]]];
    if cross(last[0], last[1], last[2]) > 0.0 {
        triangles.push(last);
    }
    Some(triangles)
}

/// The corners `(min, max)` of the box around `vertices`.
pub(super) fn bounds(vertices: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    vertices
        .iter()
        .fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(l, h), v| {
            (
                [l[0].min(v[0]), l[1].min(v[1])],
                [h[0].max(v[0]), h[1].max(v[1])],
            )
        })
}

/// Two buffers for [`shared_area`]'s clipped parts, which a caller reuses from call to call:
/// the autocorrelation's quadratures take millions of overlaps.
pub(super) type ClipScratch = (Vec<[f64; 2]>, Vec<[f64; 2]>);

/// The area `polygon` (counter-clockwise, within `bounds`, its [`bounds`]) shares with the
/// triangles moved by `shift`. Each triangle's first side clips the polygon itself, the next
/// ones the part left: the same clips as of a copy.
pub(super) fn shared_area(
    polygon: &[[f64; 2]],
    (lo, hi): ([f64; 2], [f64; 2]),
    triangles: &[Triangle],
    shift: [f64; 2],
    (part, clipped): &mut ClipScratch,
) -> f64 {
    let mut area = 0.0;
    for t in triangles {
        let moved = t.map(|v| [v[0] + shift[0], v[1] + shift[1]]);
        let outside = (0..2)
            .any(|a| moved.iter().all(|v| v[a] >= hi[a]) || moved.iter().all(|v| v[a] <= lo[a]));
        if outside {
            continue;
        }
        for i in 0..3 {
            let (a, b) = (moved[i], moved[(i + 1) % 3]);
            // Left of a → b: (b_y − a_y) x − (b_x − a_x) y ≤ the same at a.
            let n = [b[1] - a[1], a[0] - b[0]];
            let level = n[0] * a[0] + n[1] * a[1];
            if i == 0 {
                clip_into(polygon, n, level, part);
            } else {
                clip_into(part, n, level, clipped);
                std::mem::swap(part, clipped);
            }
            if part.len() < 3 {
                break;
            }
        }
        if part.len() >= 3 {
            area += signed_area(part).max(0.0);
        }
    }
    area
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An L-shaped (non-convex) hexagon: its triangles cover its area, and its overlap with
    /// itself moved along an axis is the area of the two rectangles' overlaps, by hand.
    #[test]
    fn an_l_shape_overlaps_itself_as_drawn() {
        let l = [
            [0.0, 0.0],
            [0.6, 0.0],
            [0.6, 0.2],
            [0.2, 0.2],
            [0.2, 0.8],
            [0.0, 0.8],
        ];
        let triangles = triangulate(&l).unwrap();
        let covered: f64 = triangles.iter().map(|t| signed_area(t)).sum();
        assert!((covered - signed_area(&l)).abs() < 1e-15);
        let shared =
            |shift| shared_area(&l, bounds(&l), &triangles, shift, &mut Default::default());
        assert!((shared([0.0, 0.0]) - signed_area(&l)).abs() < 1e-15);
        // Moved right by 0.1: the foot (0.6 × 0.2) keeps 0.5 × 0.2, the leg (0.2 × 0.6 above
        // the foot) keeps 0.1 × 0.6.
        let moved = shared([0.1, 0.0]);
        assert!((moved - (0.1 + 0.06)).abs() < 1e-15, "{moved}");
        // Moved up by 0.3: the leg keeps 0.2 × 0.5 of its 0.8; the foot meets only the leg.
        let up = shared([0.0, 0.3]);
        assert!((up - 0.2 * 0.5).abs() < 1e-15, "{up}");
    }
}

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

/// The least sine of a convex polygon's turn at a vertex for [`ConvexOverlap`]: its corners'
/// terms divide by it.
const MIN_TURN_SINE: f64 = 1e-3;

/// A convex polygon's overlap with its own translates, in closed form while the shift is
/// small. `P ∩ (P + r)` is `P` with each edge `i` moved inward by `d_i = max(0, −n_i·r)` (`n_i`
/// its outward unit normal): the half-planes of both, the tighter of each pair. While no edge
/// vanishes, the moved polygon's area is quadratic in the `d_i`, and its gradient is minus the
/// moved edges' lengths `L_i − s_i − e_i`, where edge `i`'s start moves along it by
/// `s_i = (d_{i−1} − d_i cos θ_i) / sin θ_i` and its end by
/// `e_i = (d_{i+1} − d_i cos θ_{i+1}) / sin θ_{i+1}` (`θ_i` the turn of the normals at vertex
/// `i`), so the area lost is `D = Σ_i d_i (L_i − (s_i + e_i)/2)`.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct ConvexOverlap {
    area: f64,
    /// Per edge `i` (from vertex `i` to `i + 1`): its outward unit normal and length.
    normals: Vec<[f64; 2]>,
    lengths: Vec<f64>,
    /// Per vertex `i`: `cos θ_i` and `1 / sin θ_i`, `θ_i` the turn from `n_{i−1}` to `n_i`.
    cosines: Vec<f64>,
    inverse_sines: Vec<f64>,
}

impl ConvexOverlap {
    /// The overlaps of `vertices` (counter-clockwise, of area `area`); `None` unless every
    /// turn is a left one with a sine of at least [`MIN_TURN_SINE`].
    pub(super) fn new(vertices: &[[f64; 2]], area: f64) -> Option<Self> {
        let n = vertices.len();
        let (mut normals, mut lengths) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for i in 0..n {
            let (a, b) = (vertices[i], vertices[(i + 1) % n]);
            let length = (b[0] - a[0]).hypot(b[1] - a[1]);
            if length == 0.0 {
                return None;
            }
            normals.push([(b[1] - a[1]) / length, (a[0] - b[0]) / length]);
            lengths.push(length);
        }
        let (mut cosines, mut inverse_sines) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for i in 0..n {
            let (p, q) = (normals[(i + n - 1) % n], normals[i]);
            let sine = p[0] * q[1] - p[1] * q[0];
            if sine < MIN_TURN_SINE {
                return None;
            }
            cosines.push(p[0] * q[0] + p[1] * q[1]);
            inverse_sines.push(1.0 / sine);
        }
        Some(Self {
            area,
            normals,
            lengths,
            cosines,
            inverse_sines,
        })
    }

    /// The area the polygon shares with itself moved by `r`; `None` where the shift makes an
    /// edge vanish (the moved polygon then has fewer sides, and clipping gives its area).
    pub(super) fn shared_area(&self, r: [f64; 2]) -> Option<f64> {
        let n = self.normals.len();
        let inward = |i: usize| {
            let m = self.normals[i % n];
            (-(m[0] * r[0] + m[1] * r[1])).max(0.0)
        };
        let (mut before, mut here) = (inward(n - 1), inward(0));
        let mut lost = 0.0;
        for i in 0..n {
            let after = inward(i + 1);
            let next = (i + 1) % n;
            let start = (before - here * self.cosines[i]) * self.inverse_sines[i];
            let end = (after - here * self.cosines[next]) * self.inverse_sines[next];
            if self.lengths[i] - start - end < 0.0 {
                return None;
            }
            lost += here * (self.lengths[i] - 0.5 * (start + end));
            (before, here) = (here, after);
        }
        Some((self.area - lost).max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An L-shaped hexagon, not convex.
    const L_SHAPE: [[f64; 2]; 6] = [
        [0.0, 0.0],
        [0.6, 0.0],
        [0.6, 0.2],
        [0.2, 0.2],
        [0.2, 0.8],
        [0.0, 0.8],
    ];

    /// The L-shaped hexagon: its triangles cover its area, and its overlap with
    /// itself moved along an axis is the area of the two rectangles' overlaps, by hand.
    #[test]
    fn an_l_shape_overlaps_itself_as_drawn() {
        let l = L_SHAPE;
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

    /// The closed form against clipping for convex polygons (a triangle, a skewed quadrangle,
    /// a hexagon) at shifts in every direction from 1e-7 to past where an edge vanishes: equal
    /// within the areas' rounding wherever it answers, and answering at every small shift.
    #[test]
    fn convex_overlaps_in_closed_form_are_the_clipped_ones() {
        let polygons: [&[[f64; 2]]; 3] = [
            &[[0.3, 0.2], [0.8, 0.4], [0.5, 0.85]],
            &[[0.1, 0.1], [0.9, 0.2], [0.7, 0.7], [0.2, 0.6]],
            &[
                [0.4, 0.1],
                [0.7, 0.2],
                [0.8, 0.5],
                [0.6, 0.8],
                [0.3, 0.7],
                [0.2, 0.4],
            ],
        ];
        for v in polygons {
            let area = signed_area(v);
            let overlap = ConvexOverlap::new(v, area).unwrap();
            let triangles = triangulate(v).unwrap();
            let (mut answered, mut refused) = (0, 0);
            for k in 0..48 {
                let angle = k as f64 * std::f64::consts::TAU / 48.0 + 0.1;
                for length in [1e-7, 1e-4, 0.01, 0.1, 0.3, 0.7] {
                    let r = [length * angle.cos(), length * angle.sin()];
                    let clipped = shared_area(v, bounds(v), &triangles, r, &mut Default::default());
                    match overlap.shared_area(r) {
                        Some(closed) => {
                            answered += 1;
                            assert!(
                                (closed - clipped).abs() <= 16.0 * f64::EPSILON * area,
                                "{v:?} moved by {r:?}: {closed:e} vs {clipped:e}"
                            );
                        }
                        None => {
                            refused += 1;
                            assert!(length > 0.01, "{v:?} refused at {r:?}");
                        }
                    }
                }
            }
            assert!(
                answered > 0 && refused > 0,
                "{v:?}: {answered} answered, {refused} refused"
            );
        }
        // Not convex, or a turn too slight: no closed form.
        assert!(ConvexOverlap::new(&L_SHAPE, signed_area(&L_SHAPE)).is_none());
        let flat = [[0.0, 0.0], [0.5, 1e-6], [1.0, 0.0], [0.5, 0.5]];
        assert!(ConvexOverlap::new(&flat, signed_area(&flat)).is_none());
    }
}

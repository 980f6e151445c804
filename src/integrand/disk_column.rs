//! A disk's area in the cells of one column of a fine grid, row by row along its circle.
//!
//! In a column `[x0, x1]` the disk of radius `r` at `(c_x, c_y)` is the region between its
//! bottom and top arcs, `c_y ∓ s(u)` with `u = x − c_x` and `s(u) = √(r² − u²)`. For a row
//! `[y_j, y_j + h]`, the length of `[c_y − s, c_y + s] ∩ [y_j, y_j + h]` is
//! `clamp(c_y + s − y_j, 0, h) − clamp(c_y − s − y_j, 0, h)`, so the cell's area is the
//! difference of two integrals, one per arc, each `U = ∫ clamp(a(u) − L, 0, h) du` with
//! `a = ±s` and `L = y_j − c_y`. On a piece of the column where `a` is monotone (either side of
//! the centre) the arc crosses the row's bottom and top once each, at `u = ±√(r² − v²)`: beyond
//! the top crossing the arc is above the row (a full `h`), between the two it is inside, and
//! its integral there is the trapezoid under its chord plus the circular segment between chord
//! and arc (added for the top arc, which is concave, and taken away for the bottom one). A
//! crossed cell takes its two crossings per arc, a chord and an arcsine, with no walk round its
//! corners and no branch on which of them lie inside.
//!
//! Every term is of the cell's size (lengths and heights measured from the cell's sides), so
//! the area rounds relative to the cell, as [`super::ball_in_box`]'s small boxes do; the
//! segment's series holds for chords up to a quarter of the radius, so a cell's diagonal must
//! be at most a quarter of `r` ([`cells_are_small`]).

#[cfg(doc)]
use super::ball_in_box::cells_are_small;
use super::ball_in_box::{circular_segment, half_chord, whole_or_none};

/// A piece of the column where the arc `a(u) = σ s(u)` is monotone: its ends, ordered by the
/// arc's value (`low` where `a` is least), the arc's values there, and the side of the centre
/// it lies on (the sign of `u`, which the crossings take).
/// Where an arc reaches a height: the abscissa and the arc's height there.
type Crossing = (f64, f64);

#[derive(Debug, Clone, Copy)]
struct ArcPiece {
    sigma: f64,
    side: f64,
    low: f64,
    high: f64,
    a_low: f64,
    a_high: f64,
    r: f64,
}

impl ArcPiece {
    /// The arc `σ s` on `[p0, p1]`, one side of the centre (`side` the sign of `u` there).
    fn new(sigma: f64, [p0, p1]: [f64; 2], side: f64, r: f64) -> Self {
        let (s0, s1) = (half_chord(p0, r), half_chord(p1, r));
        // s increases towards the centre: on the left side (u ≤ 0) with u, on the right against.
        let increasing = sigma * side < 0.0;
        let ((low, s_low), (high, s_high)) = if increasing {
            ((p0, s0), (p1, s1))
        } else {
            ((p1, s1), (p0, s0))
        };
        Self {
            sigma,
            side,
            low,
            high,
            a_low: sigma * s_low,
            a_high: sigma * s_high,
            r,
        }
    }

    /// Where the arc reaches height `v` (an end where it stays beyond `v`), and its height
    /// there.
    fn crossing(&self, v: f64) -> Crossing {
        if v <= self.a_low {
            (self.low, self.a_low)
        } else if v >= self.a_high {
            (self.high, self.a_high)
        } else {
            let u = self.side * half_chord(v, self.r);
            let (lo, hi) = (self.low.min(self.high), self.low.max(self.high));
            (u.clamp(lo, hi), v)
        }
    }

    /// `∫ clamp(a(u) − l, 0, h_top − l) du` over the piece, for the row `[l, h_top]` (relative
    /// to the centre). A row boundary's crossing is found again for the row above: sharing
    /// it measured no faster.
    fn under(&self, (l, h_top): (f64, f64)) -> f64 {
        let ((c_l, a_l), (c_h, a_h)) = (self.crossing(l), self.crossing(h_top));
        let full = (h_top - l) * (self.high - c_h).abs();
        let len = (c_h - c_l).abs();
        if len == 0.0 {
            // The arc is beyond the row on the whole piece, or below it.
            return full;
        }
        let (t_l, t_h) = (a_l - l, a_h - l);
        let dt = t_h - t_l;
        let chord = (len * len + dt * dt).sqrt();
        let partial = len * 0.5 * (t_l + t_h) + self.sigma * circular_segment(self.r, chord);
        full + partial
    }
}

/// The disk of radius `r` at `c` in the cells of column `[x0, x1]` of a grid of `rows` rows
/// (row `j` spans `[j/rows, (j+1)/rows]`), whose cells are small beside it
/// ([`cells_are_small`]): appends `(row, area)` for every row the circle may cross (the rows
/// within one of its crossings; their areas may be 0 or the whole cell), and returns the rows
/// between them, `first..=last`, which lie wholly inside the disk (`None` if there are none).
pub(super) fn disk_column(
    c: [f64; 2],
    r: f64,
    [x0, x1]: [f64; 2],
    rows: usize,
    cells: &mut Vec<(usize, f64)>,
) -> Option<(usize, usize)> {
    let (u0, u1) = (x0 - c[0], x1 - c[0]);
    if u1 <= -r || u0 >= r || rows == 0 {
        return None;
    }
    let (a, b) = (u0.max(-r), u1.min(r));
    let pieces: ([f64; 2], Option<[f64; 2]>) = if a < 0.0 && b > 0.0 {
        ([a, 0.0], Some([0.0, b]))
    } else {
        ([a, b], None)
    };
    let side = |p: [f64; 2]| if p[1] <= 0.0 { -1.0 } else { 1.0 };
    let (s_a, s_b) = (half_chord(a, r), half_chord(b, r));
    let s_min = s_a.min(s_b);
    let s_max = if pieces.1.is_some() { r } else { s_a.max(s_b) };
    let my = rows as f64;
    let last = rows as i64 - 1;
    let row_of = |y: f64| ((y * my).floor() as i64).clamp(-1, rows as i64);
    // The rows either arc may cross, one more on each side for the rounding of `floor`.
    let bottom = (row_of(c[1] - s_max) - 1, row_of(c[1] - s_min) + 1);
    let top = (row_of(c[1] + s_min) - 1, row_of(c[1] + s_max) + 1);
    // The rows between the two ranges are inside; where the ranges meet there are none.
    let (merged, apart) = ([(bottom.0, top.1)], [bottom, top]);
    let (ranges, inside): (&[(i64, i64)], _) = if bottom.1 + 1 >= top.0 {
        (&merged, None)
    } else {
        let (first, end) = ((bottom.1 + 1).max(0), (top.0 - 1).min(last));
        (
            &apart,
            (first <= end).then_some((first as usize, end as usize)),
        )
    };
    // Both arcs on each piece, on the stack: a column's work is a few cells.
    let arc = |sigma: f64, p: [f64; 2]| ArcPiece::new(sigma, p, side(p), r);
    let mut arcs = [
        arc(1.0, pieces.0),
        arc(-1.0, pieces.0),
        arc(1.0, pieces.0),
        arc(1.0, pieces.0),
    ];
    let count = match pieces.1 {
        Some(p) => {
            arcs[2] = arc(1.0, p);
            arcs[3] = arc(-1.0, p);
            4
        }
        None => 2,
    };
    let arcs = &arcs[..count];
    for &(first, end) in ranges {
        for j in first.max(0)..=end.min(last) {
            let (y0, y1) = (j as f64 / my, (j + 1) as f64 / my);
            let row = (y0 - c[1], y1 - c[1]);
            let area = whole_or_none(&[u0, row.0], &[u1, row.1], r).unwrap_or_else(|| {
                let area: f64 = arcs.iter().map(|arc| arc.sigma * arc.under(row)).sum();
                area.max(0.0)
            });
            cells.push((j as usize, area));
        }
    }
    inside
}

/// Sorts `cells` by row and sums the areas of a row listed more than once (a cell several
/// images of a wrapped disk cross: they do not overlap, so their areas add).
pub(super) fn merge_by_row(cells: &mut Vec<(usize, f64)>) {
    cells.sort_unstable_by_key(|&(j, _)| j);
    let mut kept = 0;
    for k in 0..cells.len() {
        if kept > 0 && cells[kept - 1].0 == cells[k].0 {
            cells[kept - 1].1 += cells[k].1;
        } else {
            cells[kept] = cells[k];
            kept += 1;
        }
    }
    cells.truncate(kept);
}

#[cfg(test)]
mod tests {
    use super::super::ball_in_box::{cells_are_small, disk_in_rectangle};
    use super::*;

    /// Each row's area against the cell's own, and the rows counted inside against whole
    /// cells, for columns across the whole disk, at its extremes, and cut by the faces.
    #[test]
    fn columns_agree_with_their_cells() {
        let cases = [
            ([0.5, 0.5], 0.25, [64usize, 64]),
            ([0.5, 0.5], 0.25, [300, 200]),
            ([0.3, 0.61], 0.2, [1000, 999]),
            ([0.02, 0.5], 0.05, [1000, 999]),
            ([0.9, 0.1], 0.45, [250, 4096]),
        ];
        for (c, r, [mx, my]) in cases {
            let (w, h) = (1.0 / mx as f64, 1.0 / my as f64);
            assert!(cells_are_small(w, h, r));
            let mut cells = Vec::new();
            for i in 0..mx {
                let (x0, x1) = (i as f64 / mx as f64, (i + 1) as f64 / mx as f64);
                cells.clear();
                let inside = disk_column(c, r, [x0, x1], my, &mut cells)
                    .map_or(0, |(first, last)| last + 1 - first);
                let mut listed = vec![false; my];
                for &(j, area) in &cells {
                    let (y0, y1) = (j as f64 / my as f64, (j + 1) as f64 / my as f64);
                    let truth = disk_in_rectangle(c, r, [x0, y0], [x1, y1]);
                    // Both round relative to the cell: `ε r / side` of its area, a few times.
                    let tolerance = 64.0 * f64::EPSILON * (r / w.min(h)) * w * h;
                    assert!(
                        (area - truth).abs() <= tolerance,
                        "disk {c:?} r = {r}, column {i}, row {j}: {area:e} vs {truth:e}"
                    );
                    listed[j] = true;
                }
                let whole = (0..my)
                    .filter(|&j| !listed[j])
                    .filter(|&j| {
                        let (y0, y1) = (j as f64 / my as f64, (j + 1) as f64 / my as f64);
                        let area = disk_in_rectangle(c, r, [x0, y0], [x1, y1]);
                        // Whole cells' areas are their sides' product, measured from the centre.
                        let cell = (x1 - x0) * (y1 - y0);
                        assert!(
                            area == 0.0 || (area - cell).abs() <= 1e-6 * cell,
                            "disk {c:?} r = {r}, column {i}, row {j} unlisted but crossed"
                        );
                        area > 0.0
                    })
                    .count();
                assert_eq!(inside, whole, "disk {c:?} r = {r}, column {i}");
            }
        }
    }
}

//! Point sets on the unit torus `[0,1)^d`.

use crate::error::{invalid, Error, Result};

/// Largest supported dimension.
pub const MAX_DIMENSION: usize = 8;

/// `N` points in `[0,1)^d`, stored row-major as one contiguous `Vec<f64>` of length `N·d`.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSet {
    dimension: usize,
    coords: Vec<f64>,
}

impl PointSet {
    /// Builds a point set from row-major coordinates.
    ///
    /// # Errors
    /// The dimension must be 1 to 8, the length a non-zero multiple of it, and every coordinate
    /// finite and in `[0, 1)`.
    ///
    /// # Examples
    /// ```
    /// let p = specvar::PointSet::new(2, vec![0.1, 0.2, 0.5, 0.75]).unwrap();
    /// assert_eq!(p.len(), 2);
    /// assert_eq!(p.point(1), &[0.5, 0.75]);
    /// ```
    pub fn new(dimension: usize, coords: Vec<f64>) -> Result<Self> {
        check_dimension(dimension)?;
        if coords.is_empty() || !coords.len().is_multiple_of(dimension) {
            return Err(invalid(
                "coordinate count",
                coords.len(),
                format!("a non-zero multiple of the dimension {dimension}"),
            ));
        }
        if let Some(i) = coords.iter().position(|c| !(0.0..1.0).contains(c)) {
            return Err(invalid(
                "coordinate",
                coords[i],
                format!("point {} has a coordinate outside [0, 1)", i / dimension),
            ));
        }
        Ok(Self { dimension, coords })
    }

    /// Builds a point set from coordinates that the caller guarantees are in `[0,1)`.
    pub(crate) fn from_trusted(dimension: usize, coords: Vec<f64>) -> Self {
        debug_assert!(coords.iter().all(|c| (0.0..1.0).contains(c)));
        debug_assert!(!coords.is_empty() && coords.len().is_multiple_of(dimension));
        Self { dimension, coords }
    }

    /// The dimension `d`.
    pub fn dimension(&self) -> usize {
        self.dimension
    }

    /// The number of points `N`.
    pub fn len(&self) -> usize {
        self.coords.len() / self.dimension
    }

    /// Always false: a point set holds at least one point.
    pub fn is_empty(&self) -> bool {
        self.coords.is_empty()
    }

    /// Point `i` as a slice of `d` coordinates.
    ///
    /// # Panics
    /// If `i >= len()`, like slice indexing.
    pub fn point(&self, i: usize) -> &[f64] {
        &self.coords[i * self.dimension..(i + 1) * self.dimension]
    }

    /// Iterates over the points.
    pub fn points(&self) -> std::slice::ChunksExact<'_, f64> {
        self.coords.chunks_exact(self.dimension)
    }

    /// All coordinates, row-major.
    pub fn coords(&self) -> &[f64] {
        &self.coords
    }

    /// Adds `shift` to every point, modulo 1 (a toroidal translation).
    ///
    /// # Errors
    /// `shift` must have `d` finite components.
    pub fn translate(&mut self, shift: &[f64]) -> Result<()> {
        if shift.len() != self.dimension || shift.iter().any(|s| !s.is_finite()) {
            return Err(invalid(
                "shift",
                format!("{shift:?}"),
                format!("{} finite components", self.dimension),
            ));
        }
        for p in self.coords.chunks_exact_mut(self.dimension) {
            for (c, s) in p.iter_mut().zip(shift) {
                *c = wrap(*c + s);
            }
        }
        Ok(())
    }

    /// Smallest toroidal distance between two distinct points (O(N²); for tests and checks).
    pub fn min_toroidal_distance(&self) -> f64 {
        let mut best = f64::INFINITY;
        for i in 0..self.len() {
            for j in i + 1..self.len() {
                best = best.min(toroidal_distance_sq(self.point(i), self.point(j)).sqrt());
            }
        }
        best
    }
}

/// Checks that `d` is a supported dimension (1 to 8).
pub(crate) fn check_dimension(d: usize) -> Result<()> {
    if (1..=MAX_DIMENSION).contains(&d) {
        Ok(())
    } else {
        Err(invalid("dimension", d, format!("1 to {MAX_DIMENSION}")))
    }
}

/// Reduces `x` into `[0, 1)`.
#[inline]
pub fn wrap(x: f64) -> f64 {
    // A point plus a shift falls in [0, 2): a compare and a select instead of a call to
    // `floor` (the baseline x86-64 target has no rounding instruction), with its bits
    // (`+ 0.0` turns -0 into 0, as `x - floor(x)` does).
    if (0.0..2.0).contains(&x) {
        let whole = if x >= 1.0 { 1.0 } else { 0.0 };
        return x - whole + 0.0;
    }
    let y = x - x.floor();
    // x - floor(x) can round up to exactly 1.0 for tiny negative x.
    if y >= 1.0 {
        0.0
    } else {
        y
    }
}

/// [`toroidal_delta`] for coordinates in `[0, 1)`: the same value, computed without branches
/// (so that a loop of them vectorizes). The difference lies in `(-1, 1)`, and subtracting or
/// adding `0.0` leaves it as it is.
#[inline]
pub(crate) fn near_delta(a: f64, b: f64) -> f64 {
    fold_near(a - b)
}

/// A difference `t` in `(-3/2, 3/2)` reduced into `[-1/2, 1/2)` by selects: subtracting or
/// adding `0.0` leaves it as it is.
#[inline]
fn fold_near(t: f64) -> f64 {
    let down = if t >= 0.5 { 1.0 } else { 0.0 };
    let up = if t < -0.5 { 1.0 } else { 0.0 };
    t - down + up
}

/// `toroidal_delta(a, b)²` from `t = a - b`, with selects where that has branches: the same
/// value (up to the sign of a zero difference, which squaring removes), without the branch
/// mispredictions that random points cause in a loop over many of them.
#[inline]
pub fn toroidal_square(t: f64) -> f64 {
    let u = if t.abs() < 1.5 {
        fold_near(t)
    } else {
        t - (t + 0.5).floor()
    };
    u * u
}

/// The toroidal difference `a - b` reduced into `[-1/2, 1/2)`.
#[inline]
pub fn toroidal_delta(a: f64, b: f64) -> f64 {
    let t = a - b;
    // Coordinates on the torus differ by less than 1: two compares instead of a floor.
    if t.abs() < 1.5 {
        if t >= 0.5 {
            t - 1.0
        } else if t < -0.5 {
            t + 1.0
        } else {
            t
        }
    } else {
        t - (t + 0.5).floor()
    }
}

/// Squared toroidal distance between two points.
#[inline]
pub fn toroidal_distance_sq(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| toroidal_square(x - y)).sum()
}

impl TryFrom<(usize, Vec<f64>)> for PointSet {
    type Error = Error;
    fn try_from((d, c): (usize, Vec<f64>)) -> Result<Self> {
        Self::new(d, c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The branchless difference is the toroidal one to the bit, at the edges of its cases
    /// (differences of exactly ±1/2, and as close to ±1 as coordinates in `[0, 1)` allow) and on
    /// a grid of coordinate pairs.
    #[test]
    fn near_delta_is_toroidal_delta_on_the_unit_interval() {
        let below_one = 1.0 - f64::EPSILON / 2.0;
        let mut values = vec![0.0, 0.5, 0.25, 0.75, below_one, f64::EPSILON, 0.5 - 1e-17];
        values.extend((0..200).map(|i| i as f64 / 199.0 * below_one));
        for &a in &values {
            for &b in &values {
                assert_eq!(
                    near_delta(a, b).to_bits(),
                    toroidal_delta(a, b).to_bits(),
                    "{a} {b}"
                );
            }
        }
    }

    #[test]
    fn toroidal_square_is_the_square_of_the_toroidal_delta_bit_for_bit() {
        let edges = [
            0.0, -0.0, 0.5, -0.5, 0.25, -0.75, 1.0, -1.0, 1.4999, -1.5, 2.3, -3.7,
        ];
        let grid = (0..2000).map(|i| -2.5 + i as f64 * 0.0025);
        for t in edges.into_iter().chain(grid) {
            let delta = toroidal_delta(t, 0.0);
            assert_eq!(
                toroidal_square(t).to_bits(),
                (delta * delta).to_bits(),
                "t = {t}"
            );
        }
    }
}

//! The ball (the disk in 2D, an interval in 1D) of constant height, on the torus.

use super::ball_in_box::cells_are_small;
use super::disk_column::{disk_column, merge_by_row};
use super::{
    check_parameters, shift_phase, unit_ball_volume, Integrand, IntegrandKind, RadialOscillation,
};
use super::{
    constant_on_cell, on_lattice, CellSums, CoefficientTables, ConstantCells, GridMasses,
    RadialCoefficients,
};
use crate::error::{invalid, Result};
use crate::pointset::{toroidal_distance_sq, toroidal_square};
use crate::quadrature::CompensatedSum;
use crate::spectrum::Lattice;
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The cells per axis of a disk cut at the square's faces ([`Ball::cut_at_the_faces`]): 2048,
/// which serves the tabulation's extrapolation up to `N = 65536` for structured samplers
/// ([`crate::predict::min_tabulation_cells`]) in 32 MiB of values.
pub const CUT_DISK_CELLS: usize = 2048;

/// `f(x) = a` inside the ball `|x - x0| < R` on the torus (distances taken toroidally, so a ball
/// that crosses a face of the cube wraps around to the opposite one), 0 outside.
///
/// `f̂(ρ) = a (R/ρ)^{d/2} J_{d/2}(2π R ρ)`: `a sin(2πRρ)/(πρ)` in 1D, `a R J_1(2πRρ)/ρ` in 2D,
/// and in 3D `a (R/ρ)^{3/2} J_{3/2}(2πRρ)` with `J_{3/2}(t) = √(2/(πt)) (sin t / t - cos t)`.
/// With `R ≤ 1/2` the wrapped ball never overlaps itself, so these are its torus coefficients at
/// integer frequencies exactly, wherever it is centred.
#[derive(Debug, Clone, PartialEq)]
pub struct Ball {
    radius: f64,
    centre: Vec<f64>,
    height: f64,
}

impl Ball {
    /// A ball of radius `radius` (at most 1/2), centre `centre` (its length is the dimension,
    /// 1 to 3) and height `height`.
    ///
    /// # Errors
    /// A radius that is not in `(0, 1/2]`, a height that is not finite, or a centre outside the
    /// cube.
    ///
    /// # Examples
    /// ```
    /// use specvar::integrand::{Ball, Integrand};
    /// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    /// assert!((disk.integral() - std::f64::consts::PI / 16.0).abs() < 1e-15);
    /// // Across a face, the disk wraps around the torus: the same integral, the same value at
    /// // a point and at its image across the face.
    /// let wrapped = Ball::new(0.3, vec![0.1, 0.5], 1.0).unwrap();
    /// assert!((wrapped.integral() - std::f64::consts::PI * 0.09).abs() < 1e-15);
    /// assert_eq!(wrapped.eval(&[0.95, 0.5]), 1.0);
    /// assert!(Ball::new(0.6, vec![0.5, 0.5], 1.0).is_err()); // would overlap itself
    /// ```
    pub fn new(radius: f64, centre: Vec<f64>, height: f64) -> Result<Self> {
        check_parameters("ball", "radius", radius, &centre, height)?;
        if radius > 0.5 {
            return Err(invalid(
                "radius",
                radius,
                "at most 1/2: a wider ball overlaps itself on the torus",
            ));
        }
        Ok(Self {
            radius,
            centre,
            height,
        })
    }

    /// The radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }
    /// The centre.
    pub fn centre(&self) -> &[f64] {
        &self.centre
    }
    /// The height.
    pub fn height(&self) -> f64 {
        self.height
    }

    /// Whether the ball crosses a face of the cube (where it wraps around the torus).
    pub fn crosses_a_face(&self) -> bool {
        self.centre
            .iter()
            .any(|&c| c - self.radius < 0.0 || c + self.radius > 1.0)
    }

    /// The ball cut at the faces of the cube, as every other integrand is: zero outside the
    /// cube, where this ball wraps around the torus. In 1D the cut is an interval, a ball
    /// again; in 2D the disk's cell averages on [`CUT_DISK_CELLS`]² cells, each exact (the
    /// disk's area in a rectangle has a closed form), a tabulation whose predictions carry
    /// their tabulation term ([`GridMeaning::CellAverages`](super::GridMeaning)). A ball inside
    /// the cube is itself.
    ///
    /// # Errors
    /// A 3D ball that crosses a face (no route reads its cut yet; `wrap` keeps the torus's).
    ///
    /// # Examples
    /// ```
    /// use specvar::integrand::{Ball, Integrand};
    /// // Cut at x = 1, 0.1 from the centre: the disk less the segment beyond the face,
    /// // πr² − (r² acos(0.1/r) − 0.1 √(r² − 0.01)) = 0.2002413 (each cell's area is exact).
    /// let cut = Ball::new(0.3, vec![0.9, 0.5], 1.0)?.cut_at_the_faces()?;
    /// let r: f64 = 0.3;
    /// let area = std::f64::consts::PI * r * r - (r * r * (0.1 / r).acos() - 0.1 * (r * r - 0.01).sqrt());
    /// assert!((cut.integral() - area).abs() < 1e-12);
    /// assert_eq!(cut.eval(&[0.05, 0.5]), 0.0); // no lobe across the face
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn cut_at_the_faces(&self) -> Result<Box<dyn Integrand>> {
        if !self.crosses_a_face() {
            return Ok(Box::new(self.clone()));
        }
        match *self.centre.as_slice() {
            [c] => {
                let (lo, hi) = ((c - self.radius).max(0.0), (c + self.radius).min(1.0));
                Ok(Box::new(Ball::new(
                    0.5 * (hi - lo),
                    vec![0.5 * (lo + hi)],
                    self.height,
                )?))
            }
            [x, y] => Ok(Box::new(self.cut_disk([x, y])?)),
            _ => Err(invalid(
                "ball",
                self.label(),
                "inside the cube, or wrapped around the torus (ball:…,wrap): a 3D ball cut at \
                 the faces has no route yet",
            )),
        }
    }

    /// The disk centred at `c` cut at the square's faces, as its exact cell averages.
    fn cut_disk(&self, c: [f64; 2]) -> Result<super::GridIntegrand> {
        let m = CUT_DISK_CELLS;
        let side = 1.0 / m as f64;
        let values: Vec<f64> = (0..m * m)
            .into_par_iter()
            .map(|i| {
                let (x, y) = ((i % m) as f64 * side, (i / m) as f64 * side);
                let area = super::ball_in_box::disk_in_rectangle(
                    c,
                    self.radius,
                    [x, y],
                    [x + side, y + side],
                );
                self.height * area / (side * side)
            })
            .collect();
        Ok(super::GridIntegrand::new(m, m, values)?.with_name(format!(
            "{} cut at the faces (exact cell averages on {m}×{m} cells)",
            self.label()
        )))
    }

    fn d(&self) -> usize {
        self.centre.len()
    }

    fn volume(&self) -> f64 {
        unit_ball_volume(self.d()) * self.radius.powi(self.d() as i32)
    }

    /// The real transform of the centred ball at `|ω| = rho`.
    fn centred_transform(&self, rho: f64) -> f64 {
        let (r, a) = (self.radius, self.height);
        if rho == 0.0 {
            return a * self.volume();
        }
        let t = 2.0 * PI * r * rho;
        match self.d() {
            1 => a * t.sin() / (PI * rho),
            2 => a * r * libm::j1(t) / rho,
            _ => {
                // Small t: the closed form cancels; use the series of 3 (sin t - t cos t)/t³.
                let ratio = if t < 1e-3 {
                    1.0 - t * t / 10.0 + t.powi(4) / 280.0
                } else {
                    3.0 * (t.sin() - t * t.cos()) / t.powi(3)
                };
                a * self.volume() * ratio
            }
        }
    }

    /// The volume of the intersection of two balls of radius R at distance `s`.
    fn lens(&self, s: f64) -> f64 {
        let r = self.radius;
        if s >= 2.0 * r {
            return 0.0;
        }
        match self.d() {
            1 => 2.0 * r - s,
            2 => r * r * lens_2d_shape(s / (2.0 * r), (2.0 * r - s) / (2.0 * r)),
            _ => PI / 12.0 * (4.0 * r + s) * (2.0 * r - s).powi(2),
        }
    }
}

/// `2θ − sin 2θ` with `θ = acos(x)`, given `x` and `1 − x` (the lens of two unit disks whose
/// centres are `2x` apart has area `2θ − sin 2θ`). The textbook form
/// `2 acos(x) − 2x√(1 − x²)` cancels catastrophically as `x → 1` (both terms `O(√(1−x))`, their
/// difference `O((1−x)^{3/2})`): `θ = 2 asin(√((1−x)/2))` is exact to rounding there, and below
/// `2θ = 1` the series `Σ_{k≥1} (−1)^{k+1} (2θ)^{2k+1}/(2k+1)!` replaces `2θ − sin 2θ`.
fn lens_2d_shape(x: f64, one_minus_x: f64) -> f64 {
    let theta = if x > 0.5 {
        2.0 * libm::asin((0.5 * one_minus_x).sqrt())
    } else {
        libm::acos(x)
    };
    let t = 2.0 * theta;
    if t >= 1.0 {
        return t - libm::sin(t);
    }
    // Terms fall by t²/((2k+2)(2k+3)) ≤ 1/20 each: 12 terms reach 1e-17 of the first.
    let mut term = t * t * t / 6.0;
    let mut sum = 0.0;
    for k in 1..=12 {
        sum += term;
        term *= -t * t / ((2 * k + 2) as f64 * (2 * k + 3) as f64);
    }
    sum
}

impl Ball {
    /// The ball's coefficients on `|k_a| ≤ kmax` as its radial profile about its centre: each
    /// distinct `|k|²` takes one Bessel value; `None` where the profile would not fit its
    /// memory ([`RadialCoefficients::new`]).
    fn radial_coefficients(&self, kmax: usize) -> Option<RadialCoefficients> {
        RadialCoefficients::new(&self.centre, kmax, |rho| self.centred_transform(rho))
    }

    /// A disk's centre and its images across the faces that meet the square, as
    /// [`box_moments`](Integrand::box_moments) wraps them.
    fn disk_images(&self) -> Vec<[f64; 2]> {
        let r = self.radius;
        let offsets = |c: f64| -> Vec<f64> {
            let mut o = vec![0.0];
            if c + r > 1.0 {
                o.push(-1.0);
            }
            if c < r {
                o.push(1.0);
            }
            o
        };
        offsets(self.centre[0])
            .iter()
            .flat_map(|&ox| offsets(self.centre[1]).into_iter().map(move |oy| [ox, oy]))
            .map(|[ox, oy]| [self.centre[0] + ox, self.centre[1] + oy])
            .collect()
    }

    /// Strip `i` of `grid` across axis `across` (across 0: column `i`; across 1: row `i`): into
    /// `interior`, the runs `lo..=hi` of its cells wholly inside the disk or an image (the disk
    /// is at most half the square wide, so its images never overlap), with one cell of margin
    /// on either side so that rounding never calls a crossed cell whole; into `crossed`, the
    /// other cells the circles may cross, sorted, each once. Both are cleared first.
    fn disk_strip(
        &self,
        images: &[[f64; 2]],
        (grid, across, i): (&[usize], usize, usize),
        interior: &mut Vec<(usize, usize)>,
        crossed: &mut Vec<usize>,
    ) {
        let (along, r) = (1 - across, self.radius);
        let (mx, my) = (grid[across] as f64, grid[along] as f64);
        let (x0, x1) = (i as f64 / mx, (i + 1) as f64 / mx);
        interior.clear();
        crossed.clear();
        for image in images {
            let c = [image[across], image[along]];
            let half = |x: f64| (r * r - (x - c[0]).powi(2)).max(0.0).sqrt();
            let nearest = c[0].clamp(x0, x1);
            if (nearest - c[0]).abs() >= r {
                continue;
            }
            let (outer, inner) = (half(nearest), half(x0).min(half(x1)));
            let to_cell = |y: f64| (y * my).floor();
            let first = to_cell(c[1] - outer).max(0.0) as usize;
            let last = (to_cell(c[1] + outer).min(my - 1.0)).max(0.0) as usize;
            let (lo, hi) = (to_cell(c[1] - inner) + 2.0, to_cell(c[1] + inner) - 2.0);
            if inner > 0.0 && lo <= hi && lo <= last as f64 && hi >= first as f64 {
                let (lo, hi) = ((lo as usize).max(first), (hi as usize).min(last));
                interior.push((lo, hi));
                crossed.extend(first..lo);
                crossed.extend(hi + 1..=last);
            } else {
                crossed.extend(first..=last);
            }
        }
        crossed.sort_unstable();
        crossed.dedup();
    }

    /// [`Integrand::cell_sums`] of a disk: a cell the circle (or one of its images across the
    /// faces) does not cross has `F_c` equal to the height or 0 and no inner variance, so only
    /// the crossed cells' moments are computed, column by column (`O(m)` of the `m²` cells).
    fn disk_cell_sums(&self, grid: &[usize]) -> CellSums {
        let (mx, my) = (grid[0], grid[1]);
        let a = self.height;
        let cells = (mx * my) as f64;
        let images = self.disk_images();
        if cells_are_small(1.0 / mx as f64, 1.0 / my as f64, self.radius) {
            return self.disk_cell_sums_by_rows(grid, &images);
        }
        let column = |(interior, crossed): &mut (Vec<(usize, usize)>, Vec<usize>),
                      i: usize|
         -> (f64, f64, u64) {
            let (x0, x1) = (i as f64 / mx as f64, (i + 1) as f64 / mx as f64);
            self.disk_strip(&images, (grid, 0, i), interior, crossed);
            let inside: usize = interior.iter().map(|&(lo, hi)| hi + 1 - lo).sum();
            let (mut squares, mut within) = (CompensatedSum::default(), CompensatedSum::default());
            squares.add(a * a * inside as f64);
            for &j in crossed.iter() {
                let (y0, y1) = (j as f64 / my as f64, (j + 1) as f64 / my as f64);
                let moments = self.box_moments(&[x0, y0], &[x1, y1]).unwrap_or((0.0, 0.0));
                add_crossed_cell(moments, cells, (&mut squares, &mut within));
            }
            (squares.value(), within.value(), crossed.len() as u64)
        };
        // Each thread's strips reuse two buffers: a million columns would otherwise allocate
        // two million times.
        let columns: Vec<(f64, f64, u64)> = (0..mx)
            .into_par_iter()
            .map_init(|| (Vec::new(), Vec::new()), column)
            .collect();
        CellSums::of_columns(columns)
    }

    /// [`disk_cell_sums`](Self::disk_cell_sums) on cells small beside the disk: each column's
    /// crossed cells' areas from each circle's crossings of the rows ([`disk_column`]), the
    /// images' areas in a cell summed (they do not overlap).
    fn disk_cell_sums_by_rows(&self, grid: &[usize], images: &[[f64; 2]]) -> CellSums {
        let (mx, my) = (grid[0], grid[1]);
        let a = self.height;
        let cells = (mx * my) as f64;
        let column = |crossed: &mut Vec<(usize, f64)>, i: usize| -> (f64, f64, u64) {
            let (x0, x1) = (i as f64 / mx as f64, (i + 1) as f64 / mx as f64);
            crossed.clear();
            let inside: usize = images
                .iter()
                .filter_map(|&c| disk_column(c, self.radius, [x0, x1], my, crossed))
                .map(|(first, last)| last + 1 - first)
                .sum();
            merge_by_row(crossed);
            let (mut squares, mut within) = (CompensatedSum::default(), CompensatedSum::default());
            squares.add(a * a * inside as f64);
            for &(_, area) in crossed.iter() {
                // As `box_moments` gives them: the height times the area, and its square.
                add_crossed_cell((a * area, a * a * area), cells, (&mut squares, &mut within));
            }
            (squares.value(), within.value(), crossed.len() as u64)
        };
        let columns: Vec<(f64, f64, u64)> =
            (0..mx).into_par_iter().map_init(Vec::new, column).collect();
        CellSums::of_columns(columns)
    }

    /// [`Integrand::grid_masses`] of an unshifted disk, row by row: the cells inside are the
    /// height times their area, the crossed ones their box moments, the rest 0; the cells no
    /// circle crosses are constant.
    fn disk_grid_masses(&self, grid: &[usize]) -> GridMasses {
        let (mx, my) = (grid[0], grid[1]);
        let area = 1.0 / (mx * my) as f64;
        let whole = self.height * area;
        let images = self.disk_images();
        let constant = ConstantCells::all(mx * my);
        let mut masses = vec![0.0; mx * my];
        if cells_are_small(1.0 / mx as f64, 1.0 / my as f64, self.radius) {
            // Row by row along each circle: the rows of the transposed grid are the columns.
            masses
                .par_chunks_mut(mx)
                .enumerate()
                .for_each_init(Vec::new, |crossed, (j, row)| {
                    let (y0, y1) = (j as f64 / my as f64, (j + 1) as f64 / my as f64);
                    crossed.clear();
                    for c in &images {
                        let inside = disk_column([c[1], c[0]], self.radius, [y0, y1], mx, crossed);
                        if let Some((first, last)) = inside {
                            row[first..=last].fill(whole);
                        }
                    }
                    merge_by_row(crossed);
                    for &(i, a) in crossed.iter() {
                        let (mass, square) = (self.height * a, self.height * self.height * a);
                        row[i] = mass;
                        if !constant_on_cell(mass, square, area) {
                            constant.clear(j * mx + i);
                        }
                    }
                });
            return GridMasses {
                masses,
                constant: Some(constant.into_words()),
            };
        }
        masses.par_chunks_mut(mx).enumerate().for_each_init(
            || (Vec::new(), Vec::new()),
            |(interior, crossed), (j, row)| {
                self.disk_strip(&images, (grid, 1, j), interior, crossed);
                for &(lo, hi) in interior.iter() {
                    row[lo..=hi].fill(whole);
                }
                let (y0, y1) = (j as f64 / my as f64, (j + 1) as f64 / my as f64);
                for &i in crossed.iter() {
                    let (x0, x1) = (i as f64 / mx as f64, (i + 1) as f64 / mx as f64);
                    let (mass, square) =
                        self.box_moments(&[x0, y0], &[x1, y1]).unwrap_or((0.0, 0.0));
                    row[i] = mass;
                    if !constant_on_cell(mass, square, area) {
                        constant.clear(j * mx + i);
                    }
                }
            },
        );
        GridMasses {
            masses,
            constant: Some(constant.into_words()),
        }
    }
}

/// A crossed cell's terms of [`CellSums`] from its moments `(∫ f, ∫ f²)` over the cell, on a
/// grid of `cells` cells: its mean's square into `squares`, the variance within it into
/// `within`.
fn add_crossed_cell(
    (mass, square): (f64, f64),
    cells: f64,
    (squares, within): (&mut CompensatedSum, &mut CompensatedSum),
) {
    let mean = mass * cells;
    squares.add(mean * mean);
    within.add((square * cells - mean * mean).max(0.0));
}

impl Integrand for Ball {
    fn cell_sums(&self, grid: &[usize]) -> Option<CellSums> {
        (self.d() == 2 && grid.len() == 2).then(|| self.disk_cell_sums(grid))
    }
    fn grid_masses(&self, grid: &[usize], t: &[f64]) -> Option<GridMasses> {
        // Shifted, a cell's box wraps across the faces: one box a cell.
        let unshifted = t.iter().all(|&x| x == 0.0);
        (unshifted && self.d() == 2 && grid.len() == 2 && grid.iter().all(|&m| m > 0))
            .then(|| self.disk_grid_masses(grid))
    }
    fn box_moments(&self, lo: &[f64], hi: &[f64]) -> Option<(f64, f64)> {
        // The ball is wrapped around the torus: its images at the 3^d integer offsets of
        // {-1, 0, 1}^d (radius at most 1/2, so no farther image meets the cube) each meet the
        // box in a plain ball–box volume, and they do not overlap one another.
        let (d, r) = (self.d(), self.radius);
        // The image at c − 1 meets the cube only if c + r > 1, the one at c + 1 only if c < r.
        let mut offsets = [[0.0; 3]; 3];
        let mut counts = [1usize; 3];
        for (a, &c) in self.centre.iter().enumerate() {
            for (wraps, o) in [(c + r > 1.0, -1.0), (c < r, 1.0)] {
                if wraps {
                    offsets[a][counts[a]] = o;
                    counts[a] += 1;
                }
            }
        }
        let mut volume = 0.0;
        let mut image = [0.0; 3];
        for code in 0..counts[..d].iter().product::<usize>() {
            let mut rest = code;
            for a in 0..d {
                image[a] = self.centre[a] + offsets[a][rest % counts[a]];
                rest /= counts[a];
            }
            volume += super::ball_in_box::ball_in_box(&image[..d], r, lo, hi);
        }
        Some((self.height * volume, self.height * self.height * volume))
    }
    fn kind(&self) -> IntegrandKind {
        IntegrandKind::Ball
    }
    fn is_isotropic(&self) -> bool {
        true
    }
    fn label(&self) -> String {
        let name = if self.d() == 2 { "disk" } else { "ball" };
        format!(
            "{name}(r={}, c={:?}, a={}, d={})",
            self.radius,
            self.centre,
            self.height,
            self.d()
        )
    }
    fn dimension(&self) -> usize {
        self.d()
    }
    fn sum_at(&self, coords: &[f64]) -> f64 {
        let (h, r2) = (self.height, self.radius * self.radius);
        if let [cx, cy] = self.centre[..] {
            // The plane's loop, free of the general distance's iterators and branches: the
            // same terms summed in the same order.
            return coords
                .chunks_exact(2)
                .map(|p| {
                    let d2 = toroidal_square(p[0] - cx) + toroidal_square(p[1] - cy);
                    if d2 < r2 {
                        h
                    } else {
                        0.0
                    }
                })
                .sum();
        }
        coords.chunks_exact(self.d()).map(|x| self.eval(x)).sum()
    }
    fn eval(&self, x: &[f64]) -> f64 {
        if toroidal_distance_sq(x, &self.centre) < self.radius * self.radius {
            self.height
        } else {
            0.0
        }
    }
    fn integral(&self) -> f64 {
        self.height * self.volume()
    }
    fn integral_of_square(&self) -> f64 {
        self.height * self.height * self.volume()
    }
    fn coefficient(&self, k: &[i64]) -> Complex64 {
        // On the stack: a lattice sum calls this once per frequency.
        let mut omega = [0.0; crate::pointset::MAX_DIMENSION];
        for (w, &c) in omega.iter_mut().zip(k) {
            *w = c as f64;
        }
        self.fourier(&omega[..k.len()])
    }
    fn coefficient_tables(&self, kmax: usize) -> Option<Box<dyn CoefficientTables>> {
        self.radial_coefficients(kmax)
            .map(|r| Box::new(r) as Box<dyn CoefficientTables>)
    }
    fn power_on_lattice(&self, lattice: Lattice, out: &mut [f64]) {
        match self.radial_coefficients(lattice.kmax) {
            Some(radial) => on_lattice(lattice, out, |k| radial.power(k)),
            None => on_lattice(lattice, out, |k| self.coefficient(k).norm_sqr()),
        }
    }
    fn coefficients_on_lattice(&self, lattice: Lattice, out: &mut [Complex64]) {
        match self.radial_coefficients(lattice.kmax) {
            Some(radial) => on_lattice(lattice, out, |k| radial.at(k)),
            None => on_lattice(lattice, out, |k| self.coefficient(k)),
        }
    }
    fn square_coefficient(&self, k: &[i64]) -> Option<Complex64> {
        // An indicator times its height: f² = a f.
        Some(self.coefficient(k) * self.height)
    }
    fn projection_energy(&self, _axis: usize) -> f64 {
        // The projection is the chord measure: 2h√(R² - x²) in 2D, πh(R² - x²) in 3D.
        let (r, h2) = (self.radius, self.height * self.height);
        match self.d() {
            1 => 2.0 * r * h2,
            2 => 16.0 / 3.0 * h2 * r.powi(3),
            _ => PI * PI * h2 * 16.0 / 15.0 * r.powi(5),
        }
    }
    fn autocorrelation(&self, r: &[f64]) -> Option<f64> {
        // The wrapped ball's autocorrelation sums the lens volumes over the images of the
        // offset; with R ≤ 1/2 only the images in the neighbouring cells can be within 2R.
        let d = self.d();
        let mut total = 0.0;
        for image in 0..3usize.pow(d as u32) {
            let mut rest = image;
            let mut s2 = 0.0;
            for &c in r {
                let shift = (rest % 3) as f64 - 1.0;
                rest /= 3;
                let t = crate::pointset::toroidal_delta(c, 0.0) + shift;
                s2 += t * t;
            }
            total += self.lens(s2.sqrt());
        }
        Some(self.height * self.height * total)
    }
    fn fourier(&self, omega: &[f64]) -> Complex64 {
        let rho = omega.iter().map(|w| w * w).sum::<f64>().sqrt();
        shift_phase(omega, &self.centre) * self.centred_transform(rho)
    }
    fn spectral_integral(&self) -> f64 {
        self.integral()
    }
    fn spectral_energy(&self) -> f64 {
        self.integral_of_square()
    }
    fn autocorrelation_beyond(&self, distance: f64) -> Option<f64> {
        // Two balls of radius R do not meet beyond 2R; closer, the images overlap and no small
        // bound exists.
        (distance >= 2.0 * self.radius).then_some(0.0)
    }
    fn radial_power(&self, rho: f64) -> f64 {
        self.centred_transform(rho).powi(2)
    }
    fn decay_exponent(&self) -> f64 {
        self.d() as f64 + 1.0
    }
    fn panel_width(&self) -> f64 {
        // J(2πRρ) has zeros about π apart in t = 2πRρ: half a period is 1/(2R) in ρ.
        1.0 / (2.0 * self.radius)
    }
    fn negligible_beyond(&self) -> f64 {
        f64::INFINITY
    }
    fn radial_oscillation(&self, rho: f64) -> Option<RadialOscillation> {
        // With t = 2πRρ and μ = d/2, J_μ(t) = M cos θ and Y_μ(t) = M sin θ (modulus and phase):
        // J² = M² (1 + cos 2θ) / 2, and θ' = 2 / (π t M²) (the Wronskian). M² is 2/(πt) in 1D,
        // (2/(πt)) (1 + 1/t²) in 3D (half-integer orders), J_1² + Y_1² in 2D.
        if rho.is_nan() || rho <= 0.0 {
            return None;
        }
        let (r, a, d) = (self.radius, self.height, self.d());
        let t = 2.0 * PI * r * rho;
        let modulus_sq = match d {
            1 => 2.0 / (PI * t),
            2 => libm::j1(t).powi(2) + libm::y1(t).powi(2),
            _ => 2.0 / (PI * t) * (1.0 + 1.0 / (t * t)),
        };
        Some(RadialOscillation {
            mean: a * a * (r / rho).powi(d as i32) * modulus_sq / 2.0,
            phase_rate: 8.0 * r / (t * modulus_sq),
        })
    }
}

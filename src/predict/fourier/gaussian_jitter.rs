//! Gaussian jitter as drawn: independent points with Gaussian densities about the grid's
//! centres, summed over the aliased pairs of frequencies.
//!
//! Point `j` is the centre `c_j = (j + 1/2)/m` of its stratum moved by a Gaussian of standard
//! deviation `s_a = w/m_a` on axis `a`, wrapped onto the torus: independent points with
//! densities `p_j = ρ(· − c_j)`, whose characteristic function at integer `k` is
//! `φ(k) = Π_a exp(−2π² s_a² k_a²)`. Used as drawn (no shift), `E f(x_j) = h(c_j)` and
//! `E f(x_j)² = h₂(c_j)`, with `h = f ⊛ ρ` and `h₂ = f² ⊛ ρ` the torus smoothings, so
//!
//! `E μ = (1/N) Σ_j h(c_j)`,  `Var μ = (1/N²) Σ_j [h₂(c_j) − h(c_j)²]`.
//!
//! On the centres every frequency folds onto its class modulo `m`:
//! `h(c_j) = Σ_p G(p) e^{2πi p·j/m}` with `G(p) = Σ_{k ≡ p} f̂(k) φ(k) e^{iπ Σ_a k_a/m_a}`, so by
//! Parseval on the grid `(1/N) Σ_j h(c_j)² = Σ_p |G(p)|²`, and `E μ = G(0)`; and
//! `(1/N) Σ_j h₂(c_j) = Σ_ℓ \hat{f²}(mℓ) φ(mℓ) (−1)^{Σ ℓ_a}`. Hence
//!
//! `Var μ = (1/N) [Σ_ℓ \hat{f²}(mℓ) φ(mℓ) (−1)^{Σ ℓ_a} − Σ_p |G(p)|²]`,
//!
//! the variance as a sum over the pairs of frequencies `(k, k − mℓ)` that the strata alias
//! together, in closed form. `φ` falls as a Gaussian, so the sums stop where it is below
//! [`TRUNCATION`], and what they leave out is bounded by `|f̂| ≤ ‖f‖₂` (`docs/theory.md`,
//! "Gaussian jitter as drawn"). The estimator is biased (`Σ_j ρ(x − c_j)` ripples at the
//! grid's period): its bias `G(0) − I` is exact too and is stated with the variance.

use crate::budget::{Budget, Needs};
use crate::costs::COEFFICIENT_SECONDS;
use crate::error::{invalid, Error, Result};
use crate::integrand::{
    CoefficientTables, Integrand, SeparableCoefficients, COEFFICIENT_TABLES_BYTES,
};
use crate::predict::{ErrorBudget, Form, Prediction, Route, SpectrumOrigin};
use crate::quadrature::CompensatedSum;
use crate::randomization::Randomization;
use crate::sampler::ClosedForm;
use crate::spectrum::Lattice;
use num_complex::Complex64;
use std::f64::consts::{PI, SQRT_2};

/// The relative weight `φ` below which frequencies are left out (their part is bounded).
const TRUNCATION: f64 = 1e-20;

/// Relative error of one coefficient as the integrands compute it (Bessel functions, error
/// functions, polygon edges: a few units of roundoff each, and a few hundred for the grids' and
/// the truncated lobes' longer sums), carried into the two sums whose difference is the
/// variance.
const COEFFICIENT_ROUNDING: f64 = 1e-13;

/// The exact variance and bias of one pattern family as drawn.
struct Moments {
    variance: f64,
    bias: f64,
    rounding: f64,
    truncation: f64,
    frequencies: u64,
}

/// One axis: the offset's characteristic function and the centres' phase on `|k| ≤ kmax`.
struct Axis {
    strata: usize,
    /// `c` in `φ_a(k) = exp(−c k²)`.
    decay: f64,
    kmax: i64,
    weight: Vec<f64>,
    phase: Vec<Complex64>,
    /// `Σ_{|k| ≤ kmax} φ_a(k)` and a bound on the rest of `Σ_k φ_a(k)`.
    inside: f64,
    beyond: f64,
}

impl Axis {
    /// `c` of `φ(k) = exp(−c k²)`, `c = 2π² (w/m)²`, and the frequency where `φ` falls below
    /// `floor`.
    fn decay_and_reach(strata: usize, width: f64, floor: f64) -> (f64, i64) {
        let c = 2.0 * PI * PI * (width / strata as f64).powi(2);
        (c, (-floor.ln() / c).sqrt().ceil() as i64)
    }

    /// What a sum over the grid's replicas reads of the axis.
    fn replicas(&self) -> ReplicaAxis {
        ReplicaAxis {
            strata: self.strata,
            decay: self.decay,
            kmax: self.kmax,
        }
    }

    /// The length `2 kmax + 1` of each axis's tables, known before they are built: a budget
    /// reads it first (at 10^6 strata an axis, 1.1e7 entries each, whose building took longer
    /// than the answer the budget then refused).
    fn lengths(strata: &[usize], width: f64) -> Vec<usize> {
        strata
            .iter()
            .map(|&m| (2 * Self::decay_and_reach(m, width, TRUNCATION).1 + 1) as usize)
            .collect()
    }

    fn new(strata: usize, width: f64) -> Self {
        let (c, kmax) = Self::decay_and_reach(strata, width, TRUNCATION);
        let weight: Vec<f64> = (-kmax..=kmax)
            .map(|k| (-c * (k * k) as f64).exp())
            .collect();
        let phase = (-kmax..=kmax)
            .map(|k| Complex64::from_polar(1.0, PI * k as f64 / strata as f64))
            .collect();
        Self {
            strata,
            decay: c,
            kmax,
            inside: weight.iter().sum(),
            beyond: gaussian_tail(c, kmax),
            weight,
            phase,
        }
    }

    fn index(&self, k: i64) -> usize {
        (k + self.kmax) as usize
    }

    /// The frequencies `k ≡ p (mod m)` with `|k| ≤ kmax`.
    fn class(&self, p: usize) -> impl Iterator<Item = i64> + '_ {
        let m = self.strata as i64;
        let first = p as i64 - (self.kmax + p as i64) / m * m;
        (0..)
            .map(move |j| first + j * m)
            .take_while(move |&k| k <= self.kmax)
    }
}

/// `2 Σ_{k > K} exp(−c k²)`, bounded by a geometric series from `K + 1`.
fn gaussian_tail(c: f64, kmax: i64) -> f64 {
    let first = (kmax + 1) as f64;
    2.0 * (-c * first * first).exp() / (1.0 - (-c * (2.0 * first + 1.0)).exp())
}

/// The variance of Gaussian jitter of width `width` (in strata) on the grid `strata`, as
/// drawn, with its bias, exactly up to the bounded truncation and rounding.
fn moments(f: &dyn Integrand, strata: &[usize], width: f64, budget: &Budget) -> Result<Moments> {
    let lengths = Axis::lengths(strata, width);
    let frequencies: f64 = lengths.iter().map(|&l| l as f64).product();
    budget.check(
        "Gaussian jitter's aliased frequencies",
        Needs {
            memory_bytes: 24.0 * lengths.iter().sum::<usize>() as f64
                + (16.0 * frequencies).min(COEFFICIENT_TABLES_BYTES as f64),
            work_seconds: frequencies * COEFFICIENT_SECONDS,
        },
        "lower N or widen the offsets",
    )?;
    let axes: Vec<Axis> = strata.iter().map(|&m| Axis::new(m, width)).collect();
    let classes: usize = strata.iter().product();
    let (aliased, mean) =
        match f.separable_coefficients(&axes.iter().map(|a| a.kmax as usize).collect::<Vec<_>>()) {
            Some(rows) => separable_folds(&rows, &axes),
            None => {
                let coefficients = Coefficients::new(f, &axes);
                // f is real, so G(−p) = G(p)*: each pair of opposite classes is summed once.
                let term = |p: usize| {
                    let opposite = opposite_class(&axes, p);
                    let fold = || folded_class(&coefficients, &axes, p).norm_sqr();
                    match p.cmp(&opposite) {
                        std::cmp::Ordering::Less => 2.0 * fold(),
                        std::cmp::Ordering::Equal => fold(),
                        std::cmp::Ordering::Greater => 0.0,
                    }
                };
                let (aliased, _) =
                    crate::predict::strata::cell_moments::chunked_sum(classes, |p| (term(p), 0.0));
                (aliased, folded_class(&coefficients, &axes, 0).re)
            }
        };
    let squares = square_sum(f, &axes)?;
    let i0 = f.integral();
    let n = classes as f64;
    let energy = f.integral_of_square();
    // |f̂(k)| ≤ ∫|f| ≤ ‖f‖₂ on the unit cube, and the same for f² with ∫f².
    let norm = energy.sqrt();
    let total: f64 = axes.iter().map(|a| a.inside + a.beyond).product();
    let inside: f64 = axes.iter().map(|a| a.inside).product();
    let left = norm * (total - inside);
    let truncation = (2.0 * norm * total * left + left * left + energy * squares.beyond) / n;
    let rounding = COEFFICIENT_ROUNDING * (squares.value.abs() + aliased) / n;
    Ok(Moments {
        variance: ((squares.value - aliased) / n).max(0.0),
        bias: mean - i0,
        rounding,
        truncation,
        frequencies: frequencies as u64 + squares.terms,
    })
}

/// The frequencies of [`predict_gaussian_jitter_shifted`]'s smoothed sum on `strata` with
/// offsets of `width` strata: those where `φ²` (the characteristic function of offsets √2 times
/// wider) is above [`TRUNCATION`].
fn shifted_frequencies(strata: &[usize], width: f64) -> f64 {
    strata
        .iter()
        .map(|&m| (2 * Axis::decay_and_reach(m, width * SQRT_2, TRUNCATION).1 + 1) as f64)
        .product()
}

/// The work of [`predict_gaussian_jitter_shifted`] on `strata` with `form`'s offsets: one
/// coefficient per frequency ([`shifted_frequencies`]), or next to none for a separable
/// integrand, whose sum factors by axis. Zero for a form other than Gaussian jitter's.
pub(crate) fn shifted_frequency_seconds(
    f: &dyn Integrand,
    form: ClosedForm,
    strata: &[usize],
) -> f64 {
    let ClosedForm::GaussianJitter { width } = form else {
        return 0.0;
    };
    if f.separable_coefficients(&vec![0; strata.len()]).is_some() {
        return 0.0;
    }
    shifted_frequencies(strata, width) * COEFFICIENT_SECONDS
}

/// The variance of Gaussian jitter of width `width` (in strata) on the grid `strata` under a
/// uniform random shift, exactly up to the bounded truncation and rounding: with
/// `E P(k) = 1 − φ(k)² + N φ(k)² [k ∈ mZ^d]`,
/// `Var = (1/N) [∫f² − Σ_k |f̂(k)|² φ(k)²] + Σ_{ℓ≠0} |f̂(mℓ)|² φ(mℓ)²` (the first sum by
/// Parseval, so no energy is counted as white beyond a lattice).
fn shifted_moments(
    f: &dyn Integrand,
    strata: &[usize],
    width: f64,
    budget: &Budget,
) -> Result<Moments> {
    // φ² is the characteristic function of offsets √2 times wider.
    let sides = Axis::lengths(strata, width * SQRT_2);
    let frequencies = shifted_frequencies(strata, width);
    budget.check(
        "Gaussian jitter's smoothed energy",
        Needs {
            memory_bytes: 24.0 * sides.iter().sum::<usize>() as f64
                + (16.0 * frequencies).min(COEFFICIENT_TABLES_BYTES as f64),
            work_seconds: frequencies * COEFFICIENT_SECONDS,
        },
        "lower N or widen the offsets",
    )?;
    let axes: Vec<Axis> = strata
        .iter()
        .map(|&m| Axis::new(m, width * SQRT_2))
        .collect();
    let kmax: Vec<usize> = axes.iter().map(|a| a.kmax as usize).collect();
    let smoothed = match f.separable_coefficients(&kmax) {
        Some(rows) => {
            rows.axes
                .iter()
                .zip(&axes)
                .map(|(row, axis)| {
                    let mut sum = CompensatedSum::default();
                    for (c, w) in row.iter().zip(&axis.weight) {
                        sum.add(c.norm_sqr() * w);
                    }
                    sum.value()
                })
                .product::<f64>()
                * rows.height
                * rows.height
        }
        None => {
            let count: usize = sides.iter().product();
            let coefficients = Coefficients::new(f, &axes);
            // The box is symmetric and |f̂(−k)| = |f̂(k)|: frequency `count − 1 − i` is `−k`,
            // so each opposite pair is evaluated once.
            let term = |i: usize| {
                let multiplicity = match i.cmp(&(count - 1 - i)) {
                    std::cmp::Ordering::Less => 2.0,
                    std::cmp::Ordering::Equal => 1.0,
                    std::cmp::Ordering::Greater => return (0.0, 0.0),
                };
                let (mut k, mut rest, mut weight) = ([0i64; 3], i, multiplicity);
                for (a, axis) in axes.iter().enumerate() {
                    k[a] = (rest % sides[a]) as i64 - axis.kmax;
                    rest /= sides[a];
                    weight *= axis.weight[axis.index(k[a])];
                }
                (coefficients.at(&k[..axes.len()]).norm_sqr() * weight, 0.0)
            };
            crate::predict::strata::cell_moments::chunked_sum(count, term).0
        }
    };
    let replicas = replica_energy(f, &axes.iter().map(Axis::replicas).collect::<Vec<_>>())?;
    let n: f64 = strata.iter().map(|&m| m as f64).product();
    let energy = f.integral_of_square();
    let total: f64 = axes.iter().map(|a| a.inside + a.beyond).product();
    let inside: f64 = axes.iter().map(|a| a.inside).product();
    // |f̂(k)|² ≤ ‖f‖₂² on the unit cube.
    let truncation = energy * (total - inside) / n + energy * replicas.beyond;
    let rounding = COEFFICIENT_ROUNDING * ((energy + smoothed) / n + replicas.value);
    Ok(Moments {
        variance: ((energy - smoothed) / n + replicas.value).max(0.0),
        bias: 0.0,
        rounding,
        truncation,
        frequencies: frequencies as u64 + replicas.terms,
    })
}

/// The integrand's coefficients on the axes' box `|k_a| ≤ kmax_a`: every class reads every
/// frequency once, so they are tabulated on the lattice that holds the box (at once, as a
/// polygon does from per-edge tables) where it fits [`COEFFICIENT_TABLES_BYTES`]; beyond, read
/// from the integrand's own tables where it has them (a polygon's edges, a ball's radial
/// profile: [`Integrand::coefficient_tables`]), and one at a time otherwise.
enum Coefficients<'a> {
    Table(&'a dyn Integrand, Lattice, Vec<Complex64>),
    Tables(Box<dyn CoefficientTables>),
    Direct(&'a dyn Integrand),
}

impl<'a> Coefficients<'a> {
    fn new(f: &'a dyn Integrand, axes: &[Axis]) -> Self {
        let kmax = axes.iter().map(|a| a.kmax as usize).max().unwrap_or(0);
        let lattice = Lattice {
            dimension: axes.len(),
            kmax,
        };
        let fits = lattice
            .side()
            .checked_pow(axes.len() as u32)
            .and_then(|count| count.checked_mul(size_of::<Complex64>()))
            .is_some_and(|bytes| bytes <= COEFFICIENT_TABLES_BYTES);
        if !fits {
            return f
                .coefficient_tables(kmax)
                .map_or(Self::Direct(f), Self::Tables);
        }
        let mut values = vec![Complex64::new(0.0, 0.0); lattice.len()];
        f.coefficients_on_lattice(lattice, &mut values);
        Self::Table(f, lattice, values)
    }

    fn at(&self, k: &[i64]) -> Complex64 {
        match self {
            Self::Direct(f) => f.coefficient(k),
            Self::Tables(tables) => tables.at(k),
            // The classes stay inside the box the table holds.
            Self::Table(f, lattice, values) => lattice
                .index(k)
                .map_or_else(|| f.coefficient(k), |i| values[i]),
        }
    }
}

/// `G(p) = Σ_{k ≡ p} f̂(k) φ(k) e^{iπ Σ_a k_a/m_a}` for the class `p` of residues (axis 0
/// fastest), summed over its frequencies in order.
fn folded_class(coefficients: &Coefficients, axes: &[Axis], p: usize) -> Complex64 {
    let d = axes.len();
    let mut residue = [0usize; 3];
    let mut rest = p;
    for (a, axis) in axes.iter().enumerate() {
        residue[a] = rest % axis.strata;
        rest /= axis.strata;
    }
    let mut sum = Complex64::new(0.0, 0.0);
    let mut k = [0i64; 3];
    fold_class(axes, &residue[..d], 0, &mut k[..d], &mut |k| {
        let mut weight = Complex64::new(1.0, 0.0);
        for (axis, &ka) in axes.iter().zip(k.iter()) {
            weight *= axis.phase[axis.index(ka)] * axis.weight[axis.index(ka)];
        }
        sum += coefficients.at(k) * weight;
    });
    sum
}

/// `(Σ_p |G(p)|², G(0))` for a separable integrand, whose folds factor by axis:
/// `G(p) = height · Π_a G_a(p_a)`, so the sum over the `N` classes is a product of sums over
/// each axis's `m_a` classes.
fn separable_folds(rows: &SeparableCoefficients, axes: &[Axis]) -> (f64, f64) {
    let (mut aliased, mut mean) = (rows.height * rows.height, rows.height);
    for (row, axis) in rows.axes.iter().zip(axes) {
        let fold = |p: usize| -> Complex64 {
            axis.class(p)
                .map(|k| {
                    row[axis.index(k)] * axis.phase[axis.index(k)] * axis.weight[axis.index(k)]
                })
                .sum()
        };
        let mut squares = CompensatedSum::default();
        for p in 0..axis.strata {
            squares.add(fold(p).norm_sqr());
        }
        aliased *= squares.value();
        mean *= fold(0).re;
    }
    (aliased, mean)
}

/// The index of the class `−p` (modulo each axis's strata; axis 0 fastest).
fn opposite_class(axes: &[Axis], p: usize) -> usize {
    let (mut rest, mut index, mut stride) = (p, 0, 1);
    for axis in axes {
        let residue = rest % axis.strata;
        rest /= axis.strata;
        index += ((axis.strata - residue) % axis.strata) * stride;
        stride *= axis.strata;
    }
    index
}

/// The bias `E μ − I` of `f`'s estimator with Gaussian jitter of width `width` (in strata) at
/// `n` points, used as drawn: `G(0) − I`, exactly (the frequencies left out weigh below
/// 10⁻²⁰ of `‖f‖₂`). The points' density `Σ_j ρ(x − c_j)/N` ripples at the grid's period, so
/// the estimator integrates `f` against it rather than against 1.
///
/// # Errors
/// An `n` that is not a count of strata in `f`'s dimension, a width outside Gaussian
/// jitter's range, or a dimension above 3.
///
/// # Examples
/// ```
/// use specvar::integrand::Gaussian;
/// use specvar::predict::gaussian_jitter_bias;
/// let f = Gaussian::new(0.2, vec![0.2, 0.7], 1.0)?;
/// let bias = gaussian_jitter_bias(&f, 256, 0.25)?;
/// assert!(bias.abs() > 1e-4 && bias.abs() < 1e-2);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn gaussian_jitter_bias(f: &dyn Integrand, n: usize, width: f64) -> Result<f64> {
    crate::sampler::GaussianJitter::new(1)?.with_width(width)?;
    let d = f.dimension();
    if d > 3 {
        return Err(invalid("dimension", d, "1 to 3"));
    }
    let strata = crate::sampler::strata(n, d).ok_or_else(|| {
        invalid(
            "N",
            n,
            format!("a count of strata in {d}D (m^d, or a × b with b < a ≤ 2b in 2D)"),
        )
    })?;
    let axes: Vec<Axis> = strata.iter().map(|&m| Axis::new(m, width)).collect();
    Ok(folded_class(&Coefficients::Direct(f), &axes, 0).re - f.integral())
}

/// Visits every frequency of the class `residue` with `|k_a| ≤ kmax_a`, axis by axis.
fn fold_class(
    axes: &[Axis],
    residue: &[usize],
    a: usize,
    k: &mut [i64],
    visit: &mut dyn FnMut(&[i64]),
) {
    if a == k.len() {
        visit(k);
        return;
    }
    for ka in axes[a].class(residue[a]) {
        k[a] = ka;
        fold_class(axes, residue, a + 1, k, visit);
    }
}

/// A sum over the replicas `k = mℓ` with `|k_a| ≤ kmax_a`, with a bound on the rest relative
/// to the largest term's size.
pub(crate) struct ReplicaSum {
    pub(crate) value: f64,
    pub(crate) beyond: f64,
    pub(crate) terms: u64,
}

/// What a sum over the grid's replicas reads of an axis: its strata `m`, the decay `c` of
/// `φ(k) = exp(−c k²)`, and the extent `|k| ≤ kmax` of the sum.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ReplicaAxis {
    strata: usize,
    decay: f64,
    kmax: i64,
}

impl ReplicaAxis {
    /// The axis of `strata` strata whose `φ` is that of offsets of `width` strata, summed while
    /// `φ` is at least `floor`.
    pub(crate) fn new(strata: usize, width: f64, floor: f64) -> Self {
        let (decay, kmax) = Axis::decay_and_reach(strata, width, floor);
        Self {
            strata,
            decay,
            kmax,
        }
    }

    /// `φ(k)`, the same operations as [`Axis`]' table.
    fn weight(&self, k: i64) -> f64 {
        (-self.decay * (k * k) as f64).exp()
    }
}

/// `Σ_ℓ term(mℓ, ℓ) φ(mℓ)` over the replicas inside the axes' extents, in order, and
/// `Σ φ(mℓ)` over those outside, bounded: per axis `φ_a(m ℓ) = exp(−c m² ℓ²)`, whose tail past
/// the extent is bounded like the full lattice's.
fn replica_sum(
    axes: &[ReplicaAxis],
    mut term: impl FnMut(&[i64], &[i64]) -> Result<f64>,
) -> Result<ReplicaSum> {
    let d = axes.len();
    let extents: Vec<i64> = axes.iter().map(|a| a.kmax / a.strata as i64).collect();
    let count: usize = extents.iter().map(|&l| (2 * l + 1) as usize).product();
    let mut sum = CompensatedSum::default();
    let (mut k, mut l) = ([0i64; 3], [0i64; 3]);
    for code in 0..count {
        let mut rest = code;
        let mut weight = 1.0;
        for (a, axis) in axes.iter().enumerate() {
            let side = (2 * extents[a] + 1) as usize;
            l[a] = (rest % side) as i64 - extents[a];
            rest /= side;
            k[a] = l[a] * axis.strata as i64;
            weight *= axis.weight(k[a]);
        }
        sum.add(term(&k[..d], &l[..d])? * weight);
    }
    // `Π (inside_a + tail_a) − Π inside_a`, axis by axis in positive terms: the tails are far
    // below the rounding of the products, whose difference would be 0.
    let (beyond, _) = axes
        .iter()
        .zip(&extents)
        .map(|(axis, &l)| {
            let c = axis.decay * (axis.strata * axis.strata) as f64;
            let inside: f64 = (-l..=l).map(|j| axis.weight(j * axis.strata as i64)).sum();
            (inside, gaussian_tail(c, l))
        })
        .fold((0.0, 1.0), |(beyond, inside), (ia, ta)| {
            (beyond * (ia + ta) + inside * ta, inside * ia)
        });
    Ok(ReplicaSum {
        value: sum.value(),
        beyond,
        terms: count as u64,
    })
}

/// `Σ_{ℓ≠0} |f̂(mℓ)|² φ(mℓ)` over the replicas inside the axes' extents (`φ` the damping of
/// the grid's replicas in the spectrum under a shift, `φ²` of the offsets), with the bound of
/// [`replica_sum`] on the rest.
pub(crate) fn replica_energy(f: &dyn Integrand, axes: &[ReplicaAxis]) -> Result<ReplicaSum> {
    replica_sum(axes, |k, l| {
        Ok(if l.iter().all(|&x| x == 0) {
            0.0
        } else {
            f.coefficient(k).norm_sqr()
        })
    })
}

/// `Σ_ℓ \hat{f²}(mℓ) φ(mℓ) (−1)^{Σ ℓ_a}`: the points' mean second moment.
fn square_sum(f: &dyn Integrand, axes: &[Axis]) -> Result<ReplicaSum> {
    let axes: Vec<ReplicaAxis> = axes.iter().map(Axis::replicas).collect();
    replica_sum(&axes, |k, l| {
        let c = f
            .square_coefficient(k)
            .ok_or_else(|| Error::OutsideValidity {
                route: "the aliased-pair form of Gaussian jitter".into(),
                reason: format!(
                    "{} has no closed-form Fourier coefficients of its square, which the points' \
                 second moments need; measure it with `specvar mc --randomization none`, or \
                 predict with --randomization shift",
                    f.label()
                ),
            })?;
        let sign = if l.iter().sum::<i64>() % 2 == 0 {
            1.0
        } else {
            -1.0
        };
        Ok(c.re * sign)
    })
}

/// The variance of `f`'s estimator with Gaussian jitter (`form`, at `n` on the grid `strata`)
/// under a uniform random shift, exactly: the closed-form spectrum summed by Parseval rather
/// than on a capped lattice.
///
/// # Errors
/// A closed form other than Gaussian jitter's, or work beyond the budget.
pub(crate) fn predict_gaussian_jitter_shifted(
    f: &dyn Integrand,
    form: ClosedForm,
    strata: &[usize],
    budget: &Budget,
) -> Result<Prediction> {
    let (width, d) = check_form(f, form, strata)?;
    let m = shifted_moments(f, strata, width, budget)?;
    let reason = format!(
        "gjitter, randomly shifted: its closed-form spectrum 1 − φ² + N φ² [k ∈ m Z^d] summed \
         exactly, the white part by Parseval ((∫f² − Σ_k |f̂|² φ²)/N) and the grid's replicas \
         one by one, so no energy beyond a lattice is counted as white ({} grid)",
        crate::predict::grid_label(strata)
    );
    Ok(exact_prediction(
        m,
        (Randomization::Shift, Form::Lattice, form),
        reason,
        strata,
        d,
    ))
}

/// The variance of `f`'s estimator with Gaussian jitter (`form`, at `n` on the grid
/// `strata`) used as drawn, with its bias in the reason.
///
/// # Errors
/// A closed form other than Gaussian jitter's, an integrand without the coefficients of its
/// square, or work beyond the budget.
pub(crate) fn predict_gaussian_jitter_as_drawn(
    f: &dyn Integrand,
    form: ClosedForm,
    strata: &[usize],
    budget: &Budget,
) -> Result<Prediction> {
    let (width, d) = check_form(f, form, strata)?;
    let m = moments(f, strata, width, budget)?;
    let reason = format!(
        "gjitter used as drawn: independent points, each a Gaussian of {width} strata about its \
         centre in the {} grid, so the variance is exact as a sum over the frequency pairs \
         the strata alias together (bias E μ − I = {:.6e}, exact; it is not part of the \
         variance)",
        crate::predict::grid_label(strata),
        m.bias
    );
    Ok(exact_prediction(
        m,
        (Randomization::None, Form::AliasedPairs, form),
        reason,
        strata,
        d,
    ))
}

/// Gaussian jitter's width, and the dimension, checked against the strata.
fn check_form(f: &dyn Integrand, form: ClosedForm, strata: &[usize]) -> Result<(f64, usize)> {
    let ClosedForm::GaussianJitter { width } = form else {
        return Err(invalid("closed form", form.name(), "Gaussian jitter's"));
    };
    let d = f.dimension();
    if strata.len() != d || d > 3 {
        return Err(Error::Mismatch(format!(
            "strata of dimension {} for an integrand of dimension {d}",
            strata.len()
        )));
    }
    Ok((width, d))
}

/// An exact route's prediction: rounding and truncation its only budget.
fn exact_prediction(
    m: Moments,
    (randomization, shape, form): (Randomization, Form, ClosedForm),
    reason: String,
    strata: &[usize],
    dimension: usize,
) -> Prediction {
    Prediction {
        variance: m.variance,
        randomization,
        route: Route {
            form: shape,
            spectrum: SpectrumOrigin::Closed(form),
        },
        reason,
        budget: ErrorBudget {
            tabulation: 0.0,
            quadrature: m.rounding,
            truncation: m.truncation,
            ..Default::default()
        },
        n: strata.iter().product(),
        dimension,
        dc_term: 0.0,
        evaluations: m.frequencies,
        alternatives: Vec::new(),
        analysis: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::{Ball, Polygon};

    /// The three sources of coefficients fold every class alike: the table of the box (a
    /// polygon's from per-edge tables, a ball's from radial values), the integrand's own tables
    /// read one coefficient at a time (a polygon's edges, a ball's radial profile and phases),
    /// and the coefficients one at a time. Each coefficient carries the integrands' relative error
    /// and its phases' absolute rounding (arguments up to `2πK` per axis), and a class sums at
    /// most `Σ φ` of them, each at most `‖f‖₂`.
    #[test]
    fn every_source_folds_the_classes_alike() {
        let shapes: [(Box<dyn Integrand>, usize); 3] = [
            (Box::new(Ball::new(0.3, vec![0.3, 0.6], 1.0).unwrap()), 8),
            (
                Box::new(Ball::new(0.25, vec![0.4, 0.5, 0.7], 2.0).unwrap()),
                4,
            ),
            (Box::new(Polygon::edge(30.0, 0.4, 1.0).unwrap()), 8),
        ];
        for (f, m) in shapes {
            let d = f.dimension();
            let axes: Vec<Axis> = (0..d).map(|_| Axis::new(m, 0.25)).collect();
            let kmax = axes[0].kmax as usize;
            let table = Coefficients::new(f.as_ref(), &axes);
            assert!(matches!(table, Coefficients::Table(..)));
            let direct = Coefficients::Direct(f.as_ref());
            let tables = f.coefficient_tables(kmax).map(Coefficients::Tables);
            let weights: f64 = axes.iter().map(|a| a.inside).product();
            let relative =
                COEFFICIENT_ROUNDING + 8.0 * f64::EPSILON * (1.0 + 2.0 * PI * (d * kmax) as f64);
            let allowed = relative * weights * f.integral_of_square().sqrt();
            for p in 0..m.pow(d as u32) {
                let exact = folded_class(&direct, &axes, p);
                for source in std::iter::once(&table).chain(tables.as_ref()) {
                    let folded = folded_class(source, &axes, p);
                    assert!(
                        (folded - exact).norm() <= allowed,
                        "{}, class {p}: {folded} against {exact} (allowed {allowed:e})",
                        f.label()
                    );
                }
            }
        }
    }
}

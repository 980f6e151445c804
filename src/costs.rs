//! Every cost the crate's plans read, once: the seconds (or nanoseconds) of one core that one
//! unit of each computation takes, each with what it counts and how it was measured. Plans
//! multiply them by the sizes a problem implies and check the product against the budget
//! before any work ([`crate::budget`]); the estimates are rough on purpose (they tell an
//! afternoon from a minute), and err on the side of refusing. The benchmarks that check them
//! are `benches/estimators.rs`, `benches/spectrum.rs` and `benches/montecarlo.rs`.
//!
//! A sampler's cost per point is one of its facts ([`crate::sampler::SamplerFacts`]), beside
//! the rest of what is known about it.

// Integrands.

/// The work of one integrand coefficient or autocorrelation value (a Bessel function, a few
/// exponentials or error functions): 200 ns, above the 50–150 ns the integrands' benchmarks
/// measure, so that estimates err on the side of refusing.
pub const COEFFICIENT_SECONDS: f64 = 2e-7;

// The non-uniform FFT (its choice of engine and upsampling).

/// Nanoseconds per kernel value (an `exp` and a `sqrt`).
pub const NUFFT_KERNEL_VALUE_NS: f64 = 7.0;
/// Nanoseconds per cell update in the spreading loop.
pub const NUFFT_CELL_UPDATE_NS: f64 = 0.25;
/// Nanoseconds per `n log2 n` of a complex FFT of length `n`.
pub const NUFFT_FFT_NS: f64 = 0.55;
/// Nanoseconds per padded cell to fold the grid and clear it.
pub const NUFFT_GRID_CELL_NS: f64 = 0.5;

// The direct transform.

/// Seconds per complex multiply-add of the direct engine.
pub const DIRECT_MAC_SECONDS: f64 = 0.25e-9;

// Sums over cells.

/// The work of one cell's moments (a clip, a disk–rectangle area, four error functions) and of
/// finding the cell: 250–280 ns a point measured on a truncated Gaussian at N = 262144, whose
/// cells' table no longer fits the caches (the integrands' coefficient cost, 200 ns, held at
/// smaller N).
pub const CELL_SECONDS: f64 = 2.7e-7;
/// The work of one cell's moments of a disk (or an interval), of a polygon or an edge, and of
/// a tabulated grid, and of finding the cell. Most of a fine grid's cells lie inside or outside
/// the shape (a comparison) or within one pixel (a lookup): measured in multi-jitter's and
/// CMJ's occupancy estimates at N = 65536 and 262144 (user time a point, less the drawing),
/// disks 43 ns, polygons and edges 53–86 ns, a 512 × 512 image 64 ns, declared with a margin.
/// [`CELL_SECONDS`], a Gaussian's four error functions, held these estimates to a fifth of the
/// patterns their work budget affords.
pub const DISK_CELL_SECONDS: f64 = 6e-8;
/// See [`DISK_CELL_SECONDS`].
pub const POLYGON_CELL_SECONDS: f64 = 1e-7;
/// See [`DISK_CELL_SECONDS`].
pub const GRID_CELL_SECONDS: f64 = 9e-8;
/// An anisotropic Gaussian's cell (its box mass by quadrature along the shorter side, twice):
/// CMJ's occupancy estimates spent 336 and 374 ns a point at N = 65536 and 262144 (user time
/// over points, the drawing included), where [`CELL_SECONDS`] let them run 20–34% past their
/// work budget.
pub const ANISOTROPIC_CELL_SECONDS: f64 = 3.8e-7;
/// The work of one cell's moments from a separable integrand's rows held in the caches (a
/// product per axis and a lookup per row), and of finding the cell: 20 ns, a bound on what was
/// measured at N = 4096 (Latin hypercube's 200 patterns in 0.6 s, with their drawing).
pub const SEPARABLE_CELL_SECONDS: f64 = 2e-8;

// Correlated multi-jitter's control variate.

/// Seconds to draw one permutation entry (a bounded random index and a swap).
pub const SHUFFLE_SECONDS: f64 = 1e-8;

// Halton's varying points.

/// The work of drawing one candidate point (its index by the remainder theorem, its digits on
/// every axis, its cell).
pub const CANDIDATE_SECONDS: f64 = 8e-8;

// Walsh sums over a linear net's dual.

/// The work of one factor value and its share of a transform, per cell and node (an
/// exponential and `p` butterflies), measured at about 25 ns at `p = 18`, with a margin.
pub const CELL_NODE_SECONDS: f64 = 4e-8;
/// The work of one element of the dual in the sum (two products of `d` table reads), per
/// axis: about 2 ns measured in 3D at `p = 14` (tables beyond the caches), with a margin.
pub const DUAL_SECONDS: f64 = 3e-9;

// Halton's pairs of points.

/// The work of one pair of points per axis in one pair sum (its digits compared, a table
/// read, the products of the axes' subsets): 15 ns measured in 2D at N = 16384.
pub const PAIR_AXIS_SECONDS: f64 = 1.5e-8;

// Owen's gains.

/// Seconds a point of a pattern takes to be counted on one dyadic grid.
pub const PAIR_COUNT_SECONDS: f64 = 2e-9;

// Walsh forms.

/// The work of one evaluation of the remainder `g` at a shifted point: the integrand (a
/// truncated Gaussian's exponentials are the costliest built-in) and its cell's mean, measured
/// at 230 ns at N = 262144 (the cell table beyond the caches).
pub const REMAINDER_EVALUATION_SECONDS: f64 = 2.5e-7;
/// The work of visiting a shifted point whose cell the integrand is constant on (its digits
/// XORed, its cell found, one bit read): such points need no evaluation.
pub const SKIP_SECONDS: f64 = 2e-8;
/// The work of visiting one varying cell of a shifted pattern's index (its start in a table
/// beyond the caches, about one memory access).
pub const VISIT_SECONDS: f64 = 1e-7;
/// The work of one cell of the level per binary digit of its transform.
pub const WALSH_BUTTERFLY_SECONDS: f64 = 1e-9;

// Halton's level of digit cells.

/// The work of one point of a realization: its digits scrambled on every axis and its cell
/// found (a constant cell needs no evaluation).
pub const VARYING_POINT_SECONDS: f64 = 1e-7;
/// The work of one cell of the level per digit: its Helmert butterfly, in two tables.
pub const HELMERT_BUTTERFLY_SECONDS: f64 = 4e-9;

// Spectrum estimates.

/// Seconds a transform takes per cell of its oversampled grid.
pub const TRANSFORM_CELL_SECONDS: f64 = 3e-8;

// Measured tails and Monte Carlo.

/// Seconds per lattice frequency and shift of the lattice part's sum (a complex product).
pub const LATTICE_TERM_SECONDS: f64 = 2e-9;
/// Seconds per point and shift of the integrand's value at a shifted point.
pub const SHIFTED_EVALUATION_SECONDS: f64 = 5e-8;

// Pools of patterns.

/// The pool rule ([`SamplerKind::pool`]): a pattern is used under one shift per this many
/// nanoseconds of its declared generation cost per point. A fixed rule, not a measured time, so
/// that pools, and with them every Monte Carlo result, do not move with the machine: it was
/// the cost of one evaluation with its shift when the rule was set. Evaluations have since
/// become about 10 ns (`benches/sampler_costs.rs` prints the current cost beside it), so the
/// rule reuses patterns less than the costs alone would.
pub const POOL_NS_PER_SHIFT: f64 = 140.0;

// Padded pairs.

/// One pass over a cell of a padded pair's grid, or over a point with its permutation: a
/// multiply-add and a load (the corrections' loops).
pub const PASS_SECONDS: f64 = 2e-9;

// Autocorrelations (the pair sums in space).

/// One autocorrelation value of a ball: a pair sum over 1024 points measures 0.19 µs a pair on
/// a disk, rounded up.
pub const BALL_AUTOCORRELATION_SECONDS: f64 = 2e-7;
/// One autocorrelation value of an isotropic Gaussian: 0.39 µs measured, rounded up.
pub const GAUSSIAN_AUTOCORRELATION_SECONDS: f64 = 4e-7;
/// One autocorrelation value of a clipped shape (a polygon, a grid, an anisotropic Gaussian):
/// 0.32 µs for a triangle, 0.51 µs for an axis-aligned square, 1.5 µs for an edge, whose copies
/// wrap across the faces; the dearest, rounded up.
pub const CLIPPED_AUTOCORRELATION_SECONDS: f64 = 2e-6;

// Point-set metrics.

/// One ordered pair of points' toroidal distance, compared or binned (the nearest-neighbour
/// and pair-correlation loops).
pub const PAIR_DISTANCE_SECONDS: f64 = 3e-9;

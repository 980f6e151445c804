"""specvar: Fourier analysis of Monte Carlo sampling, from Python.

Predict the variance of Monte Carlo integration from power spectra, and check it against Monte
Carlo runs. Samplers give numpy arrays of shape ``(M, N, d)``; realization ``i`` of seed ``s``
is the same bits as in the Rust library and the ``specvar`` command line. Every error of the
library is raised as ``ValueError`` with the command line's one-line message.

>>> import specvar
>>> p = specvar.predict("disk", sampler="jitter", n=256)
>>> m = specvar.monte_carlo("disk", sampler="jitter", n=256, trials=4000)
>>> p.interval(3.0)[0] < m.ci_high and m.ci_low < p.interval(3.0)[1]
True

The theory (the lattice and polar forms, the routes and their error budgets) is in the
repository's ``docs/theory.md``.
"""

from __future__ import annotations

import functools
import inspect
import json
import math
import warnings
from dataclasses import dataclass, field, fields
from typing import Any, Callable, Literal, Optional, Sequence, Union

import numpy as np

from . import _specvar

__version__ = _specvar.__version__

__all__ = [
    "Alternative",
    "ErrorBudget",
    "Integrand",
    "McResult",
    "ImagePrediction",
    "Plan",
    "Prediction",
    "RadialSpectrum",
    "Route",
    "SamplerInfo",
    "SlopeFit",
    "Spectrum",
    "Study",
    "StudyRow",
    "StudySeries",
    "integrand",
    "monte_carlo",
    "periodogram",
    "plan",
    "plan_padded",
    "plan_pilot",
    "PilotPlan",
    "predict",
    "predict_image",
    "predict_padded",
    "read_points",
    "sample",
    "samplers",
    "set_budget",
    "spectrum",
    "study",
    "tabulate",
    "tabulate_adaptive",
    "Tabulation",
    "write_points",
]

# A function of one's own: points of shape (N, d) in, one value per point out.
PythonIntegrand = Callable[[np.ndarray], Any]

# How each pattern is randomized before it integrates: the estimator. ``native`` is the
# sampler's own (none for random samplers and your own points, shift for fixed rules).
RandomizationName = Literal["native", "shift", "digital-shift", "none"]
CellsName = Literal["strata", "rows", "dyadic", "whole"]
TabulationName = Literal["averages", "samples", "exact"]
SpectrumName = Literal["auto", "closed", "estimated"]
FormName = Literal["auto", "lattice", "polar", "cells"]
EngineName = Literal["auto", "direct", "fast"]


def _build(cls: type, raw: dict, **converted: Any) -> Any:
    """``cls`` from the fields of ``raw`` it declares (with ``converted`` ones replaced), so
    that a field the library adds does not break an older dataclass."""
    values = {**raw, **converted}
    return cls(**{f.name: values[f.name] for f in fields(cls) if f.name in values})


def _counts_checked(function):
    """Refuses integer arguments that the Rust core cannot hold (negative, or 2^64 and above)
    with a ``ValueError`` naming the argument, as the core's own errors do."""
    signature = inspect.signature(function)

    @functools.wraps(function)
    def checked(*args, **kwargs):
        bound = signature.bind(*args, **kwargs)
        for name, value in bound.arguments.items():
            if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
                if not 0 <= int(value) < 2**64:
                    raise ValueError(f"invalid {name}: {value} (a non-negative integer below 2^64)")
        return function(*args, **kwargs)

    return checked


def _integrand(integrand: Any) -> Any:
    """A specification string or a function as given; a pair ``(values, meaning)`` with its
    values as a float64 array; anything else as a float64 array of cell values."""
    if isinstance(integrand, str) or callable(integrand):
        return integrand
    if isinstance(integrand, tuple) and len(integrand) == 2 and isinstance(integrand[1], str):
        return (np.asarray(integrand[0], dtype=np.float64), integrand[1])
    return np.asarray(integrand, dtype=np.float64)


def _check_tabulation_memory(resolution: int, arrays: int) -> None:
    """Raises ``ValueError`` when ``arrays`` float64 arrays of ``resolution²`` entries would
    need more memory than the budget (:func:`set_budget`) allows."""
    memory_gib, _ = _specvar.set_budget(None, None)
    needed = arrays * 8 * float(resolution) ** 2 / 2**30
    if needed > memory_gib:
        raise ValueError(
            f"tabulating at resolution {resolution} would need {needed:.3g} GiB, above the budget "
            f"of {memory_gib:.3g} GiB; lower the resolution, or raise the budget (set_budget)"
        )


def tabulate(f: PythonIntegrand, resolution: int = 256) -> np.ndarray:
    """A function of one's own on the unit square as cell values ``values[y, x]`` at the
    centres of a ``resolution × resolution`` grid: the piecewise-constant integrand that
    :func:`predict` reads exactly (its coefficients come from one FFT). Its gap to ``f`` is the
    tabulation's: refine ``resolution`` until the prediction stops moving.

    Raises ``ValueError`` for a resolution that is not a positive integer, or one whose points
    and values would need more memory than the budget (:func:`set_budget`) allows."""
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) or resolution < 1:
        raise ValueError(f"invalid resolution: {resolution!r} (a positive integer of cells per side)")
    # Three float64 arrays of resolution² entries: the two coordinates and the values.
    _check_tabulation_memory(resolution, 3)
    c = (np.arange(resolution) + 0.5) / resolution
    x, y = np.meshgrid(c, c, indexing="xy")
    values = np.asarray(f(np.column_stack([x.ravel(), y.ravel()])), dtype=np.float64)
    return values.reshape(resolution, resolution)


@dataclass(frozen=True)
class Tabulation:
    """An adaptive tabulation: cell values ``values[y, x]`` on a ``resolution × resolution``
    grid, the evaluations of ``f`` it spent, and its error estimate: ``l2_error``, the
    root-mean-square gap between ``f`` and the cell values where cells were filled from a coarser
    cell instead of evaluated (each such cell's gap taken as the largest difference between its
    coarse cell and that cell's neighbours), and ``flat_share``, the share of the square so
    filled. An estimator whose variance is at most ``c σ²/N`` (random points: ``c = 1``;
    jitter: ``c ≤ 1``) has an RMSE that moves by at most ``√c · l2_error / √N``."""

    values: np.ndarray
    resolution: int
    evaluations: int
    l2_error: float
    flat_share: float


def tabulate_adaptive(
    f: PythonIntegrand,
    resolution: int = 256,
    start: int = 16,
    tolerance: float = 1e-3,
    max_evaluations: Optional[int] = None,
) -> Tabulation:
    """Tabulate ``f`` as :func:`tabulate` does, evaluating it only where it varies: at the
    centres of a ``start × start`` grid first, then, level by level up to ``resolution`` (which
    must be ``start · 2^L``), only in the cells whose value differs from a neighbour's by more
    than ``tolerance`` times the range of the first level's values; the other cells pass their
    value to their four children. A pixel's integrand, flat but for a shadow's edge, costs a
    small share of the full grid's evaluations. ``max_evaluations`` stops the refinement when
    the next level would exceed it (its cells then keep their coarser values, and the error
    estimate counts them). Raises ``ValueError`` for sizes that do not nest."""
    for name, v in (("resolution", resolution), ("start", start)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise ValueError(f"invalid {name}: {v!r} (a positive integer of cells per side)")
    levels = 0
    while start << levels < resolution:
        levels += 1
    if start << levels != resolution:
        raise ValueError(f"invalid resolution: {resolution} (start · 2^L with start = {start})")
    if not (tolerance > 0 and math.isfinite(tolerance)):
        raise ValueError(f"invalid tolerance: {tolerance!r} (a positive number)")
    # The values, the gaps, the next level's children and its mask.
    _check_tabulation_memory(resolution, 4)

    def evaluate(m: int, cells_y: np.ndarray, cells_x: np.ndarray) -> np.ndarray:
        points = np.column_stack([(cells_x + 0.5) / m, (cells_y + 0.5) / m])
        return np.asarray(f(points), dtype=np.float64).reshape(len(cells_x))

    m = start
    ys, xs = np.mgrid[0:m, 0:m]
    values = evaluate(m, ys.ravel(), xs.ravel()).reshape(m, m)
    evaluations = m * m
    scale = tolerance * max(float(values.max() - values.min()), np.finfo(float).tiny)
    # The gap each cell may carry (0 where evaluated), and whether it was filled from a coarser
    # cell.
    gap = np.zeros((m, m))
    filled = np.zeros((m, m), dtype=bool)
    for _ in range(levels):
        # A cell varies when it differs from a neighbour (on the torus's grid, not across it)
        # by more than the tolerance.
        spread = np.zeros_like(values)
        for axis in (0, 1):
            d = np.abs(np.diff(values, axis=axis))
            lo = [slice(None), slice(None)]
            hi = [slice(None), slice(None)]
            lo[axis], hi[axis] = slice(0, -1), slice(1, None)
            spread[tuple(lo)] = np.maximum(spread[tuple(lo)], d)
            spread[tuple(hi)] = np.maximum(spread[tuple(hi)], d)
        varies = spread > scale
        block = np.ones((2, 2))
        children = np.kron(values, block)
        m *= 2
        cy, cx = np.nonzero(np.kron(varies, block) > 0)
        if max_evaluations is not None and evaluations + len(cx) > max_evaluations:
            # Over the budget: every cell keeps its value and carries its spread.
            gap = np.kron(np.maximum(gap, spread), block)
            filled = np.ones((m, m), dtype=bool)
            values = children
            continue
        gap = np.kron(np.where(varies, 0.0, np.maximum(gap, spread)), block)
        filled = np.kron(~varies, block) > 0
        if len(cx):
            children[cy, cx] = evaluate(m, cy, cx)
            evaluations += len(cx)
        values = children
    return Tabulation(
        values=values,
        resolution=resolution,
        evaluations=int(evaluations),
        l2_error=float(np.sqrt(np.mean(gap**2))),
        flat_share=float(np.mean(filled)),
    )


def _points(points: Optional[Any]) -> Optional[np.ndarray]:
    """A float64 array, read in place by the Rust core when it already is one."""
    if points is None:
        return None
    return np.asarray(points, dtype=np.float64)


@dataclass(frozen=True)
class SamplerInfo:
    """A sampler's facts: name, dimensions, the N it can draw (``count_rule``) and those at
    which its patterns are complete (``balanced_counts``: ``any``, ``strata``,
    ``power_of_two``, ``prime_square``, ``fibonacci``), its known exponent α."""

    name: str
    description: str
    dimensions: tuple
    count_rule: str
    balanced_counts: str
    deterministic: bool
    isotropic: bool
    known_alpha: Optional[float]
    randomness: str
    native_randomization: str
    symmetry: str
    scaling: str
    cost_per_point_ns: float


@_counts_checked
def set_budget(memory_gib: Optional[float] = None, seconds: Optional[float] = None) -> tuple:
    """What one call may spend, checked before it starts (default 8 GiB and one hour of one
    core's work, as on the command line): a call above it raises ``ValueError`` saying what it
    would need. Returns the budget in force as ``(GiB, seconds)``."""
    return _specvar.set_budget(memory_gib, seconds)


def samplers() -> list[SamplerInfo]:
    """Every sampler, with its facts (as ``specvar samplers`` lists them)."""
    return [_build(SamplerInfo, row, dimensions=tuple(row["dimensions"])) for row in _specvar.samplers()]


@_counts_checked
def sample(
    sampler: str,
    n: int,
    realizations: int = 1,
    dimension: int = 2,
    seed: int = 0,
    start: int = 0,
    randomization: RandomizationName = "none",
    cache: bool = True,
) -> np.ndarray:
    """Realizations ``start … start + realizations - 1`` of ``seed``: an array ``(M, N, d)``.

    The same bits as ``specvar sample`` and the Rust library's ``Sampler::sample``.
    ``randomization`` applies each realization's random toroidal shift (``shift``) or
    digital shift (``digital-shift``); ``none`` leaves the patterns as drawn. Costly patterns
    (CCVT, Poisson disk) are read from and kept in the cache directory unless ``cache`` is
    false.
    """
    return _specvar.sample(sampler, n, realizations, dimension, seed, start, randomization, cache)


@_counts_checked
def periodogram(
    points: Any, kmax: int, engine: EngineName = "auto", tolerance: Optional[float] = None
) -> np.ndarray:
    """``P(k) = |Σ_j exp(-2πi k·x_j)|² / N`` of one point set ``(N, d)`` on ``|k_i| ≤ kmax``.

    The result has side ``2 kmax + 1`` on each axis, zero frequency at index ``kmax``.
    ``engine`` is ``auto``, ``direct`` (exact sums) or ``fast`` (NUFFT at ``tolerance``).
    """
    return _specvar.periodogram(_points(points), kmax, engine, tolerance)


@dataclass(frozen=True)
class RadialSpectrum:
    """Rings of the lattice spectrum in scaled frequency ``ν = |k| / N^{1/d}``."""

    nu: np.ndarray
    rho: np.ndarray
    power: np.ndarray
    stderr: np.ndarray
    count: np.ndarray
    anisotropy_db: np.ndarray
    dc_limit: float
    bin_width: float


@dataclass(frozen=True)
class Spectrum:
    """An expected power spectrum: the lattice mean (shape ``(2K+1,)*d``, zero frequency at
    the centre, where the value N is a flag, not data), its standard error, and its rings."""

    n: int
    dimension: int
    kmax: int
    realizations: int
    engine: str
    mean: np.ndarray
    stderr: np.ndarray
    radial: RadialSpectrum

    def frequencies(self) -> np.ndarray:
        """The integer frequencies of one axis, ``-kmax … kmax``."""
        return np.arange(-self.kmax, self.kmax + 1)


@_counts_checked
def spectrum(
    sampler: Optional[str] = None,
    points: Optional[Any] = None,
    n: Optional[int] = None,
    dimension: int = 2,
    realizations: int = 16,
    kmax: int = 64,
    seed: int = 0,
    engine: EngineName = "auto",
    tolerance: Optional[float] = None,
    bin_width: float = 1.0,
    cache: bool = True,
) -> Spectrum:
    """The expected spectrum of a sampler (``sampler=``, ``n=``) or of your own point sets
    (``points=``, shape ``(M, N, d)``, every set used)."""
    raw = _specvar.spectrum(
        sampler, _points(points), n, dimension, realizations, kmax, seed, engine, tolerance, bin_width, cache
    )
    return _build(Spectrum, raw, radial=_build(RadialSpectrum, raw["radial"]))


@dataclass(frozen=True)
class ErrorBudget:
    """A prediction's uncertainty by source, in units of the variance: one standard error of
    spectrum noise, and bounds on quadrature, truncation, the route's model and, for a grid that
    tabulates a finer function, the tabulation."""

    spectrum_noise: float
    quadrature: float
    truncation: float
    model: float
    tabulation: float = 0.0

    def half_width(self, z: float) -> float:
        """``z · spectrum_noise + quadrature + truncation + model + tabulation``."""
        return z * self.spectrum_noise + self.quadrature + self.truncation + self.model + self.tabulation


@dataclass(frozen=True)
class Route:
    """A form (``lattice``, ``polar``, or ``cells`` for the unshifted estimator of strata and
    nets, summed over cells in space) and what it read: a closed-form spectrum, an estimate with
    its N, realizations and lattice extent, or the cells and how their occupancy is known."""

    form: str
    spectrum: Any

    def __str__(self) -> str:
        return f"{self.form} form, spectrum {self.spectrum}"


@dataclass(frozen=True)
class Alternative:
    """Another valid route's value for the same problem."""

    route: Route
    variance: float
    budget: ErrorBudget


@dataclass(frozen=True)
class Prediction:
    """A predicted variance of an estimator (``randomization``: how its patterns are
    randomized), with its route, the reason for the route, and its error budget."""

    variance: float
    randomization: str
    route: Route
    reason: str
    budget: ErrorBudget
    n: int
    dimension: int
    dc_term: float
    evaluations: int
    alternatives: list = field(default_factory=list)

    def interval(self, z: float = 3.0) -> tuple:
        """``variance ± budget.half_width(z)``."""
        h = self.budget.half_width(z)
        return (self.variance - h, self.variance + h)

    def covers(self, value: float, z: float = 3.0) -> bool:
        """Whether ``value`` lies within :meth:`interval`."""
        low, high = self.interval(z)
        return low <= value <= high

    @staticmethod
    def _from(raw: dict) -> "Prediction":
        alternatives = [
            Alternative(_build(Route, a["route"]), a["variance"], _build(ErrorBudget, a["budget"]))
            for a in raw["alternatives"]
        ]
        return _build(
            Prediction,
            raw,
            route=_build(Route, raw["route"]),
            budget=_build(ErrorBudget, raw["budget"]),
            alternatives=alternatives,
        )


@_counts_checked
def predict(
    integrand: Union[str, np.ndarray],
    sampler: Optional[str] = None,
    points: Optional[Any] = None,
    n: Optional[int] = None,
    dimension: int = 2,
    spectrum: SpectrumName = "auto",
    form: FormName = "auto",
    realizations: Optional[int] = None,
    reference_n: Optional[int] = None,
    kmax: Optional[int] = None,
    seed: int = 0,
    randomization: RandomizationName = "native",
    cells: Optional[CellsName] = None,
    cache: bool = True,
) -> Prediction:
    """Predict the variance of integrating ``integrand`` (``disk``, ``gaussian:sigma=0.1``,
    ``edge:theta=30``, … as on the command line, or cell values ``values[y, x]`` on the unit
    square: by default a finer function's averages over the cells, predicted for that function
    with the budget's ``tabulation`` term and refused where too coarse for ``n``; a pair
    ``(values, "samples")`` for values at the cells' centres, as :func:`tabulate` gives, or
    ``(values, "exact")`` for a grid that is the function) with ``n`` points of ``sampler``, or with the
    patterns ``points`` of your own. The library chooses a valid route unless ``spectrum``
    (``auto``, ``closed``, ``estimated``) or ``form`` (``auto``, ``lattice``, ``polar``,
    ``cells``) say otherwise. ``randomization`` names the estimator: ``native`` (the default: the sampler's
    own use, so strata, N-rooks samplers and scrambled nets as drawn, predicted by the cell
    form in space; fixed rules under a shift; given ``points`` as given, which no route
    predicts), ``shift`` (the randomly shifted, homogenized one of the spectral routes),
    ``none`` (as drawn) or ``digital-shift`` (for independent points); other pairs raise
    ``ValueError`` saying how to measure them with :func:`monte_carlo`. With ``points``,
    ``cells`` (``strata``, ``rows``, ``dyadic``, ``whole``) declares the cells in which their
    sampler guarantees the points are uniform (a renderer's jittered strata, its multi-jittered
    or orthogonal-array points, an Owen-scrambled base-2 net): the sets are then predicted as
    given, by the cell form."""
    raw = _specvar.predict(
        _integrand(integrand),
        sampler,
        _points(points),
        n,
        dimension,
        spectrum,
        form,
        realizations,
        reference_n,
        kmax,
        seed,
        randomization,
        cells,
        cache,
    )
    return Prediction._from(raw)


@dataclass(frozen=True)
class McResult:
    """A Monte Carlo variance with its 99% interval. ``bias`` is ``None`` for a Python
    integrand run without its exact ``integral``, whose errors are taken about their mean."""

    n: int
    trials: int
    patterns: int
    shifts: int
    variance: float
    ci_low: float
    ci_high: float
    bias: Optional[float]
    bias_stderr: Optional[float]
    randomization: str
    interval: str
    effective_units: float


@_counts_checked
def monte_carlo(
    integrand: Union[str, np.ndarray, PythonIntegrand],
    sampler: Optional[str] = None,
    points: Optional[Any] = None,
    n: Optional[int] = None,
    dimension: int = 2,
    trials: int = 10000,
    shifts: Optional[int] = None,
    seed: int = 0,
    randomization: RandomizationName = "native",
    integral: Optional[float] = None,
    cache: bool = True,
) -> McResult:
    """Monte Carlo of the estimator ``(1/N) Σ f(x_j)``, with a 99% interval.

    ``integrand`` is a built-in specification, cell values (as :func:`predict` takes them), or
    a Python function ``f(points) -> values`` vectorized over an ``(N, d)`` array. A function is integrated on the same shifted patterns
    the built-in integrands see, one shift per pattern; give its exact ``integral`` if you know
    it (the errors are then ``μ_N − integral``), else the variance is the sample variance.
    With ``points=`` every set of your own is one pattern. ``randomization`` names the
    estimator: ``native`` (the default, as for :func:`predict`, so that the two compare the
    same estimator), ``shift`` (a random toroidal shift of each pattern), ``digital-shift`` (a
    random XOR of its binary digits), or ``none`` (the patterns as drawn, or as given).
    """
    call = _integrand(integrand)
    if callable(integrand):

        def call(x: np.ndarray) -> np.ndarray:
            return np.asarray(integrand(x), dtype=np.float64)

    raw = _specvar.monte_carlo(
        call, sampler, _points(points), n, dimension, trials, shifts, seed, randomization, integral, cache
    )
    if callable(integrand) and integral is None:
        raw = {**raw, "bias": None, "bias_stderr": None}
    return _build(McResult, raw)


@dataclass(frozen=True)
class ImagePrediction:
    """Every pixel's predicted variance (``variance[row, column]``, with the half-widths of
    their 99% budgets) and the image's MSE, their mean, with its budget."""

    n: int
    randomization: str
    mse: float
    budget: ErrorBudget
    variance: np.ndarray
    half_width: np.ndarray
    route: Route


@_counts_checked
def predict_image(
    pixels: Any,
    sampler: str,
    n: int,
    randomization: RandomizationName = "native",
    seed: int = 0,
    cache: bool = True,
    tabulation: TabulationName = "averages",
) -> ImagePrediction:
    """Predict every pixel of an image integrated with ``n`` points of ``sampler`` per pixel:
    ``pixels`` holds each pixel's cell values ``values[y, x]`` (as :func:`predict` takes one),
    shaped ``(pixels, h, w)`` or ``(rows, columns, h, w)``; ``tabulation`` says what their cells
    are (``averages`` of a finer function, the default; ``samples``; ``exact``), as for
    :func:`predict`. Each pixel takes its own default
    route and seed; the image's MSE is their mean."""
    stack = np.ascontiguousarray(pixels, dtype=np.float64)
    raw = _specvar.predict_image(stack, sampler, n, randomization, seed, cache, tabulation)
    shape = (raw["rows"], raw["columns"])
    return ImagePrediction(
        n=raw["n"],
        randomization=raw["randomization"],
        mse=raw["mse"],
        budget=_build(ErrorBudget, raw["budget"]),
        variance=np.array([p["variance"] for p in raw["pixels"]]).reshape(shape),
        half_width=np.array([p["half_width"] for p in raw["pixels"]]).reshape(shape),
        route=_build(Route, raw["route"]),
    )


@dataclass(frozen=True)
class Plan:
    """One sampler's plan: the smallest N among its balanced counts (``counts``: powers of two
    for nets, strata for jitter, …) whose predicted RMSE reaches the target, the prediction
    there (its RMSE, the interval of its 99% error budget, its route), and the largest count
    below N that was predicted (``below``: ``{"n", "rmse"}``), which misses the target."""

    sampler: str
    n: int
    rmse: float
    rmse_interval: tuple
    budget: float
    target: float
    form: str
    route: str
    reason: str
    randomization: str
    counts: str
    below: Optional[dict]
    rate: Optional[float]
    predictions: int
    reached: bool = True
    limit: Optional[str] = None


@_counts_checked
def plan(
    integrand: Union[str, np.ndarray, PythonIntegrand],
    rmse: float,
    relative: bool = False,
    samplers: Optional[Sequence[str]] = None,
    dimension: int = 2,
    randomization: RandomizationName = "native",
    max_n: Optional[int] = None,
    seed: int = 0,
    cache: bool = True,
) -> list[Plan]:
    """How many samples: for each of ``samplers`` (default: random, jitter, cmj and sobol in
    2D), the smallest N whose predicted RMSE on ``integrand`` (a specification or cell values,
    as :func:`predict` takes them, or a function ``f(points) -> values``, tabulated first by
    :func:`tabulate_adaptive` at resolution 256; or a stack of pixels' cell values shaped
    ``(pixels, h, w)`` or ``(rows, columns, h, w)``, whose image RMSE, the root of the mean of
    the pixels' variances, is planned) is at most ``rmse`` (relative to ``|∫f|`` with
    ``relative=True``), for the estimator each sampler is used with (``randomization``). The
    search follows the predictions' own rate, a handful of predictions per sampler. A sampler
    that no N up to ``max_n`` (default 2^20 in 2D) brings to the target is a row with
    ``reached=False``, its largest N and the RMSE there, and ``limit`` saying what stopped it.
    A sampler whose estimator has no valid route (Halton used as drawn on an integrand that is
    not a product of one factor per axis) is left out with a
    ``UserWarning`` that gives the reason. Raises ``ValueError`` for a target that is not
    positive and finite, one that no sampler reaches (naming that N and its RMSE), or when
    every sampler is refused."""
    if callable(integrand):
        integrand = (tabulate_adaptive(integrand, resolution=256).values, "samples")
    spec, pixels, tabulation = _integrand(integrand), None, "averages"
    if isinstance(spec, tuple) and spec[0].ndim in (3, 4):
        spec, tabulation = spec[0], spec[1]
    if isinstance(spec, np.ndarray) and spec.ndim in (3, 4):
        spec, pixels = None, np.ascontiguousarray(spec)
    raw = _specvar.plan(
        spec,
        float(rmse),
        relative,
        None if samplers is None else list(samplers),
        dimension,
        randomization,
        max_n,
        seed,
        cache,
        pixels,
        tabulation,
    )
    for refusal in raw["refused"]:
        warnings.warn(f"{refusal['sampler']} is not planned: {refusal['reason']}", stacklevel=2)
    return [_build(Plan, r, rmse_interval=tuple(r["rmse_interval"])) for r in raw["rows"]]


@dataclass(frozen=True)
class PilotPlan(Plan):
    """A plan from a pilot: a :class:`Plan`, and what the pilot measured (``pilot``: its
    ``n``, ``renders``, ``pixels``, the image's ``mean``, its ``variance`` at ``n`` and that
    variance's ``standard_error``)."""

    pilot: Optional[dict] = None


@_counts_checked
def plan_pilot(
    renders: Any,
    n: int,
    sampler: str,
    rmse: float,
    relative: bool = False,
    model: Literal["padded", "single"] = "padded",
    randomization: RandomizationName = "native",
    max_n: Optional[int] = None,
    seed: int = 0,
    cache: bool = True,
) -> PilotPlan:
    """How many samples per pixel, from a pilot instead of the pixels' integrands: ``renders``
    (an array whose first axis is the render, ``(renders, h, w)`` or ``(renders, pixels)``; at
    least two) of an image made with ``sampler`` at ``n`` samples per pixel. The image's
    variance at ``n`` (the mean over pixels of each pixel's sample variance across the renders)
    is carried to other counts by the sampler's own predictions on discontinuities in general
    position (a disk and oblique edges), and the plan is the smallest balanced count whose
    image RMSE reaches ``rmse`` (relative to the image's mean with ``relative=True``). With
    ``model="padded"`` (the default, a render's pixels: film, light and other pairs of
    dimensions padded together) half the variance is taken to fall like ``1/N`` instead, the
    pairs' interaction, with an interval that holds any split; ``model="single"`` is for pixels
    integrated by one 2D pattern (a light sample at a fixed shading point). Its
    interval carries the pilot's noise and the spread of those discontinuities' rates; on an
    image smoother than a discontinuity (or with edges along the axes, for nets) the plan is
    conservative. Four renders of one pixel are too few to plan from (their variance spreads
    like a χ² with 3 degrees of freedom); an image's pixels average that out.
    Raises ``ValueError`` for fewer than two renders, renders that are all equal, a count
    the sampler cannot produce, a sampler other than 2D, or a target out of reach."""
    raw = _specvar.plan_pilot(
        np.ascontiguousarray(renders, dtype=np.float64),
        int(n),
        sampler,
        float(rmse),
        relative,
        model,
        randomization,
        max_n,
        seed,
        cache,
    )
    return _build(PilotPlan, raw, rmse_interval=tuple(raw["rmse_interval"]))


@_counts_checked
def predict_padded(
    values: Any,
    sampler: str,
    n: int,
    second: Optional[str] = None,
    randomization: RandomizationName = "native",
    mc: Optional[int] = None,
    seed: int = 0,
    cache: bool = True,
    tabulation: TabulationName = "averages",
) -> dict:
    """The variance of a 4D integrand under two 2D patterns padded together, as renderers pad
    them: ``values[ay, ax, by, bx]`` are its cell values (the first pair of dimensions, e.g. the
    film, on the first two axes; the second, e.g. the light, on the last two); ``sampler``
    draws the first pair and ``second`` (default: the same) the second, paired by a random
    permutation. Returns a dict: ``variance``, ``budget``, the two marginals' predictions
    (``first``, ``second``), the interaction's term (``interaction``) beside its white value
    ``interaction_white`` (``‖h‖²/N``), and with ``mc`` trials the Monte Carlo measurement of
    the padded estimator (``measured``: ``variance``, ``ci_low``, ``ci_high``, …).
    ``tabulation`` says what the cells are: ``averages`` of a finer function (the default; the
    marginals carry the tabulation term, and too coarse a grid for ``n`` raises
    ``ValueError``), ``samples`` (values at the centres) or ``exact`` (the grid is the
    function)."""
    return _specvar.predict_padded(
        np.ascontiguousarray(values, dtype=np.float64),
        sampler,
        n,
        second,
        randomization,
        mc,
        seed,
        cache,
        tabulation,
    )


@_counts_checked
def plan_padded(
    values: Any,
    sampler: str,
    rmse: float,
    relative: bool = False,
    second: Optional[str] = None,
    randomization: RandomizationName = "native",
    max_n: Optional[int] = None,
    seed: int = 0,
    cache: bool = True,
    tabulation: TabulationName = "averages",
) -> Plan:
    """How many samples for a 4D integrand ``values[ay, ax, by, bx]`` integrated by two 2D
    patterns padded together (as :func:`predict_padded`): the smallest balanced count (of the
    sparser ladder of the two samplers) whose predicted RMSE reaches ``rmse`` (relative to
    ``|∫f|`` with ``relative=True``). A stack of such pixels, ``values[pixel, ay, ax, by, bx]``,
    is planned for the image's RMSE (the root of the mean of the pixels' variances; relative to
    the image's mean). ``tabulation`` as for :func:`predict_padded`. Raises ``ValueError`` as
    :func:`plan` does."""
    raw = _specvar.plan_padded(
        np.ascontiguousarray(values, dtype=np.float64),
        sampler,
        float(rmse),
        relative,
        second,
        randomization,
        max_n,
        seed,
        cache,
        tabulation,
    )
    return _build(Plan, raw, rmse_interval=tuple(raw["rmse_interval"]))


@dataclass(frozen=True)
class Integrand:
    """A built-in integrand (a specification or cell values): its label, exact integral and
    energy, and its values."""

    spec: Any
    dimension: int
    label: str
    integral: float
    integral_of_square: float
    isotropic: bool

    def __call__(self, points: Any) -> np.ndarray:
        """``f`` at points ``(N, d)`` (or ``(M, N, d)``, flattened)."""
        return _specvar.evaluate(self.spec, _points(points))


@_counts_checked
def integrand(spec: Union[str, np.ndarray], dimension: int = 2) -> Integrand:
    """The built-in integrand ``spec`` in ``dimension``, e.g. ``integrand("disk:r=0.2")``, or
    the piecewise-constant one of cell values ``values[y, x]``."""
    spec = _integrand(spec)
    facts = _specvar.integrand_facts(spec, dimension)
    return _build(Integrand, facts, spec=spec, dimension=dimension)


def read_points(path: str) -> Union[np.ndarray, list]:
    """Point sets from a UTK text, UTK binary or JSON file: ``(M, N, d)``, or a list of
    ``(N, d)`` arrays when the sets differ in size."""
    return _specvar.read_points(str(path))


def write_points(path: str, points: Any, format: str = "text") -> None:
    """Write point sets ``(M, N, d)`` or ``(N, d)`` atomically as ``text`` (UTK), ``binary``
    (UTK's "UTK!" format) or ``json``."""
    _specvar.write_points(str(path), _points(points), format)


@dataclass(frozen=True)
class SlopeFit:
    """A fitted log-log slope with its standard error and 99% interval."""

    slope: float
    stderr: float
    ci: tuple
    intercept: float
    points: int


@dataclass(frozen=True)
class StudyRow:
    """One sampler on one integrand: the theoretical, predicted and measured rates."""

    sampler: str
    integrand: str
    dimension: int
    alpha: float
    alpha_source: str
    theory_rate: Optional[float]
    log_factor: bool
    predicted_rate: SlopeFit
    empirical_rate: SlopeFit
    #: The first N at which the variance reaches the floor of double precision (both fits stop
    #: below it), or ``None``.
    floor_n: Optional[int] = None


@dataclass(frozen=True)
class StudySeries:
    """One sampler on one integrand over the N values: predictions beside Monte Carlo."""

    sampler: str
    integrand: str
    label: str
    ns: np.ndarray
    predicted: list
    measured: list

    @property
    def predicted_variance(self) -> np.ndarray:
        """The predicted variances, one per N."""
        return np.array([p.variance for p in self.predicted])

    @property
    def measured_variance(self) -> np.ndarray:
        """The Monte Carlo variances, one per N."""
        return np.array([m.variance for m in self.measured])

    @property
    def measured_interval(self) -> np.ndarray:
        """``(len(ns), 2)``: the 99% intervals."""
        return np.array([(m.ci_low, m.ci_high) for m in self.measured])


@dataclass(frozen=True)
class Study:
    """A rate study: every series and the rate table; ``raw`` holds the library's whole
    result (spectra, fitted exponents) as plain Python values."""

    rows: list
    series: list
    raw: dict

    @staticmethod
    def _from(raw: dict) -> "Study":
        rows = [
            _build(
                StudyRow,
                r,
                predicted_rate=_build(SlopeFit, r["predicted_rate"], ci=tuple(r["predicted_rate"]["ci"])),
                empirical_rate=_build(SlopeFit, r["empirical_rate"], ci=tuple(r["empirical_rate"]["ci"])),
            )
            for r in raw["rows"]
        ]
        series = [
            StudySeries(
                sampler=s["sampler"],
                integrand=s["integrand"],
                label=s["label"],
                ns=np.array(s["ns"]),
                predicted=[Prediction._from(p) for p in s["predicted"]],
                measured=[_build(McResult, m) for m in s["measured"]],
            )
            for s in raw["series"]
        ]
        return Study(rows=rows, series=series, raw=raw)


def _describe(
    samplers: Sequence[str],
    integrands: Sequence[str],
    ns: Sequence[int],
    trials: int,
    dimension: int,
    seed: int,
    reference: Optional[dict],
    cache: bool,
    randomization: str = "shift",
) -> str:
    return json.dumps(
        {
            "randomization": randomization,
            "dimension": int(dimension),
            "samplers": list(samplers),
            "integrands": list(integrands),
            "ns": [int(n) for n in ns],
            "trials": int(trials),
            "seed": int(seed),
            "reference": reference,
            "cache": bool(cache),
        }
    )


@_counts_checked
def study(
    samplers: Sequence[str],
    integrands: Sequence[str],
    ns: Sequence[int],
    trials: int = 4000,
    dimension: int = 2,
    seed: int = 0,
    reference: Optional[dict] = None,
    client: Any = None,
    patterns_per_block: int = 256,
    cache: bool = False,
    randomization: Literal["shift", "native", "digital-shift", "none"] = "shift",
) -> Study:
    """A rate study: every sampler on every integrand at every N, predicted and measured.

    ``reference`` overrides the reference spectrum (``{"n", "kmax", "realizations",
    "costly_realizations"}``). ``randomization`` names the estimator predicted and measured
    (the random shift by default, the talk's setting; ``native``: each sampler as it is used). Without ``client`` the study runs in this process; with a
    ``dask.distributed`` client its Monte Carlo runs on the cluster in blocks of
    ``patterns_per_block`` patterns (see :func:`specvar.cluster.study`), with the same bits.
    """
    described = _describe(samplers, integrands, ns, trials, dimension, seed, reference, cache, randomization)
    if client is None:
        return Study._from(_specvar.run_study(described))
    from . import cluster

    return cluster.run(described, client, patterns_per_block)

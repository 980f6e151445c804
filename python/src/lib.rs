//! `specvar._specvar`: the Rust core of the Python package. Each function converts its
//! arguments, makes one library call with the interpreter released, and converts the result;
//! the Python layer (`specvar/__init__.py`) wraps the results in dataclasses. Every library
//! error becomes a `ValueError` carrying the command line's one-line message.

mod convert;
mod study;

use convert::{array_of_sets, point_sets, to_py, OrValueError};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use specvar::budget::{Budget, DEFAULT_MEMORY_BYTES, DEFAULT_WORK_SECONDS};
use specvar::integrand::{GridIntegrand, GridMeaning, Integrand, IntegrandSpec};
use specvar::montecarlo::{
    blocked_run_needs, empirical_variances, empirical_variances_of_sets, result_from_estimates,
    shifted_pattern, trial_pattern, McParams, McResult, TRIAL_BLOCK,
};
use specvar::pointset::PointSet;
use specvar::predict::{predict as predict_variance, PredictParams, Problem};
use specvar::randomization::{Randomization, RandomizationChoice};
use specvar::sampler::{draw_realizations, native_randomization, CellRule, Sampler, SamplerKind};
use specvar::spectrum::{
    estimate_with_progress, Engine, EngineChoice, PatternSource, SpectrumParams,
};

/// What one call may spend, checked before it starts (the command line's `--budget-memory`
/// and `--budget-seconds`); [`set_budget`] changes it for the process.
static BUDGET: std::sync::RwLock<Budget> = std::sync::RwLock::new(Budget {
    memory_bytes: DEFAULT_MEMORY_BYTES,
    work_seconds: DEFAULT_WORK_SECONDS,
});

/// The budget now in force.
pub(crate) fn budget() -> Budget {
    *BUDGET
        .read()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Sets what one call may spend: memory in GiB and work in seconds of one core (each left as
/// it is when `None`); returns the budget in force afterwards as `(GiB, seconds)`.
#[pyfunction]
#[pyo3(signature = (memory_gib=None, seconds=None))]
fn set_budget(memory_gib: Option<f64>, seconds: Option<f64>) -> PyResult<(f64, f64)> {
    let positive = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(PyValueError::new_err(format!(
                "invalid {name}: {v} (a positive number)"
            )))
        }
    };
    let mut b = budget();
    if let Some(gib) = memory_gib {
        b.memory_bytes = positive("budget memory", gib)? * GIB;
    }
    if let Some(s) = seconds {
        b.work_seconds = positive("budget seconds", s)?;
    }
    *BUDGET
        .write()
        .unwrap_or_else(|poisoned| poisoned.into_inner()) = b;
    Ok((b.memory_bytes / GIB, b.work_seconds))
}

const GIB: f64 = (1u64 << 30) as f64;

/// A sampler by name in dimension `d`, its costly patterns read from and written to the cache
/// directory when `cache` is set (the same bits either way).
fn build_sampler(name: &str, d: usize, cache: bool) -> specvar::Result<Box<dyn Sampler>> {
    let kind: SamplerKind = name.parse()?;
    let dir = cache.then(specvar::cache::default_dir);
    specvar::cache::cached_sampler(kind, d, dir.as_deref(), specvar::cache::PATTERN_MEMORY)
}

/// The patterns of a call: a sampler's realizations or the caller's point sets.
enum Source {
    Sampler(SamplerKind, Box<dyn Sampler>, usize),
    Sets(Vec<PointSet>),
}

impl Source {
    /// Exactly one of `sampler` (with `n`) and `points`.
    fn from_args(
        sampler: Option<&str>,
        points: Option<PyReadonlyArrayDyn<'_, f64>>,
        n: Option<usize>,
        d: usize,
        cache: bool,
    ) -> PyResult<Self> {
        match (sampler, points) {
            (Some(name), None) => {
                let n = n.ok_or_else(|| PyValueError::new_err("n is required with a sampler"))?;
                let kind: SamplerKind = name.parse().or_value_error()?;
                let s = build_sampler(name, d, cache).or_value_error()?;
                s.check_count(n).or_value_error()?;
                Ok(Source::Sampler(kind, s, n))
            }
            (None, Some(array)) => Ok(Source::Sets(point_sets(&array)?)),
            _ => Err(PyValueError::new_err(
                "give exactly one of sampler= (a name, with n=) and points= (an array of shape \
                 (M, N, d) or (N, d))",
            )),
        }
    }

    /// The randomization named `choice` (`native`, `shift`, `digital-shift`, `none`) for these
    /// patterns.
    fn randomization(&self, choice: &str) -> PyResult<Randomization> {
        let kind = match self {
            Source::Sampler(kind, ..) => Some(*kind),
            Source::Sets(_) => None,
        };
        let choice: RandomizationChoice = choice.parse().or_value_error()?;
        Ok(choice.resolve(native_randomization(kind)))
    }

    fn dimension(&self) -> usize {
        match self {
            Source::Sampler(_, s, _) => s.dimension(),
            Source::Sets(sets) => sets[0].dimension(),
        }
    }

    fn n(&self) -> usize {
        match self {
            Source::Sampler(_, _, n) => *n,
            Source::Sets(sets) => sets[0].len(),
        }
    }
}

/// A built-in integrand from a specification string (`disk:r=0.2`, as on the command line),
/// a 2D array of cell values `values[y, x]` on the unit square (a finer function's cell
/// averages, [`specvar::integrand::GridIntegrand`]), or a pair `(values, meaning)` whose
/// meaning (`"averages"`, `"samples"` for values at the cells' centres, `"exact"` for a grid
/// that is the function) says what the cells are; `None` for anything else.
fn builtin_integrand(
    integrand: &Bound<'_, PyAny>,
    d: usize,
) -> PyResult<Option<Box<dyn Integrand>>> {
    if let Ok(text) = integrand.extract::<String>() {
        let spec: IntegrandSpec = text.parse().or_value_error()?;
        return spec.build(d).map(Some).or_value_error();
    }
    if let Ok((values, meaning)) = integrand.extract::<(Bound<'_, PyAny>, String)>() {
        let meaning: GridMeaning = meaning.parse().or_value_error()?;
        return Ok(
            grid_of(&values)?.map(|g| Box::new(g.with_meaning(meaning)) as Box<dyn Integrand>)
        );
    }
    Ok(grid_of(integrand)?.map(|g| Box::new(g) as Box<dyn Integrand>))
}

/// The grid of a 2D float64 array `values[y, x]`, if `values` is an array.
fn grid_of(values: &Bound<'_, PyAny>) -> PyResult<Option<GridIntegrand>> {
    let Ok(values) = values.extract::<PyReadonlyArrayDyn<'_, f64>>() else {
        return Ok(None);
    };
    let shape = values.shape().to_vec();
    let [height, width] = shape[..] else {
        return Err(PyValueError::new_err(format!(
            "a tabulated integrand is a 2D array values[y, x], not shape {shape:?}"
        )));
    };
    let flat: Vec<f64> = values.as_array().iter().copied().collect();
    GridIntegrand::new(width, height, flat)
        .map(Some)
        .or_value_error()
}

/// [`builtin_integrand`], which must succeed.
fn required_integrand(integrand: &Bound<'_, PyAny>, d: usize) -> PyResult<Box<dyn Integrand>> {
    builtin_integrand(integrand, d)?.ok_or_else(|| {
        PyValueError::new_err(
            "the integrand must be a specification string (disk, gaussian:sigma=0.1, …), a 2D \
             float64 array of cell values, or a pair (values, \"averages\" | \"samples\" | \
             \"exact\")",
        )
    })
}

/// Every sampler with its facts.
#[pyfunction]
fn samplers(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let rows = SamplerKind::ALL.iter().map(|k| {
        let s = k.summary();
        let row = PyDict::new(py);
        row.set_item("name", s.name.name())?;
        row.set_item("description", s.description)?;
        row.set_item("dimensions", (s.min_dimension, s.max_dimension))?;
        row.set_item("count_rule", s.count_rule)?;
        row.set_item("balanced_counts", to_py(py, &s.balanced_counts)?)?;
        row.set_item("deterministic", s.deterministic)?;
        row.set_item("isotropic", s.isotropic)?;
        row.set_item("known_alpha", s.known_alpha)?;
        row.set_item("randomness", s.randomness.to_string())?;
        row.set_item("native_randomization", s.native_randomization.name())?;
        row.set_item("symmetry", s.symmetry.to_string())?;
        row.set_item("scaling", s.scaling.to_string())?;
        row.set_item("cost_per_point_ns", s.cost_per_point_ns)?;
        Ok(row)
    });
    PyList::new(py, rows.collect::<PyResult<Vec<_>>>()?)
}

/// Realizations `start … start + realizations - 1` of `seed`: an array `(M, N, d)`.
#[pyfunction]
#[pyo3(signature = (sampler, n, realizations=1, dimension=2, seed=0, start=0, randomization="none", cache=true))]
#[allow(clippy::too_many_arguments)]
fn sample<'py>(
    py: Python<'py>,
    sampler: &str,
    n: usize,
    realizations: usize,
    dimension: usize,
    seed: u64,
    start: u64,
    randomization: &str,
    cache: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let s = build_sampler(sampler, dimension, cache).or_value_error()?;
    let randomization = randomization
        .parse::<RandomizationChoice>()
        .or_value_error()?
        .resolve(specvar::sampler::sampler_native_randomization(s.as_ref()));
    let end = start.checked_add(realizations as u64).ok_or_else(|| {
        PyValueError::new_err("start + realizations overflows a 64-bit realization index")
    })?;
    let b = budget();
    let sets = py
        .detach(|| draw_realizations(s.as_ref(), n, seed, start..end, randomization, &b))
        .or_value_error()?;
    array_of_sets(py, &sets, n, dimension)
}

/// The engine named by `method` (`auto`, `direct`, `fast`), the fast one at `tolerance` or the
/// tolerance the statistics of `realizations` sets of `n` points need.
fn engine(method: &str, tolerance: Option<f64>, n: usize, realizations: usize) -> PyResult<Engine> {
    let choice: EngineChoice = method.parse().or_value_error()?;
    choice.engine(tolerance, n, realizations).or_value_error()
}

/// The periodogram `P(k) = |Σ e^{-2πi k·x}|² / N` of one point set `(N, d)` on the lattice
/// `|k_i| ≤ kmax`: an array of side `2 kmax + 1` in each of the `d` axes.
#[pyfunction]
#[pyo3(signature = (points, kmax, engine="auto", tolerance=None))]
fn periodogram<'py>(
    py: Python<'py>,
    points: PyReadonlyArrayDyn<'py, f64>,
    kmax: usize,
    engine: &str,
    tolerance: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    if points.ndim() != 2 {
        return Err(PyValueError::new_err(format!(
            "points must have shape (N, d), not {:?}",
            points.shape()
        )));
    }
    let set = point_sets(&points)?.remove(0);
    let eng = self::engine(engine, tolerance, set.len(), 1)?;
    let d = set.dimension();
    let power = py
        .detach(|| specvar::spectrum::periodogram(&set, kmax, eng))
        .or_value_error()?;
    let side = 2 * kmax + 1;
    Ok(PyArray1::from_vec(py, power)
        .reshape(vec![side; d])?
        .into_any())
}

/// The expected spectrum of a sampler's realizations or of given point sets: lattice and
/// radial.
#[pyfunction]
#[pyo3(signature = (sampler=None, points=None, n=None, dimension=2, realizations=16, kmax=64, seed=0, engine="auto", tolerance=None, bin_width=1.0, cache=true))]
#[allow(clippy::too_many_arguments)]
fn spectrum<'py>(
    py: Python<'py>,
    sampler: Option<&str>,
    points: Option<PyReadonlyArrayDyn<'py, f64>>,
    n: Option<usize>,
    dimension: usize,
    realizations: usize,
    kmax: usize,
    seed: u64,
    engine: &str,
    tolerance: Option<f64>,
    bin_width: f64,
    cache: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let source = Source::from_args(sampler, points, n, dimension, cache)?;
    let m = match &source {
        Source::Sets(sets) => sets.len(),
        Source::Sampler(..) => realizations,
    };
    let params = SpectrumParams {
        kmax,
        realizations,
        seed,
        engine: self::engine(engine, tolerance, source.n(), m)?,
        bin_width,
        budget: budget(),
    };
    let estimate = py
        .detach(|| {
            let patterns = match &source {
                Source::Sampler(_, s, n) => PatternSource::Sampler {
                    sampler: s.as_ref(),
                    n: *n,
                    seed,
                },
                Source::Sets(sets) => PatternSource::Sets(sets),
            };
            estimate_with_progress(patterns, &params, &specvar::progress::Silent)
        })
        .or_value_error()?;
    convert::spectrum_dict(py, &estimate)
}

/// The predicted variance of an estimator (randomized by `randomization`) on a built-in
/// integrand (a specification string or a 2D array of cell values): the library's route, its
/// reason and its error budget.
#[pyfunction]
#[pyo3(signature = (integrand, sampler=None, points=None, n=None, dimension=2, spectrum="auto", form="auto", realizations=None, reference_n=None, kmax=None, seed=0, randomization="native", cells=None, cache=true))]
#[allow(clippy::too_many_arguments)]
fn predict<'py>(
    py: Python<'py>,
    integrand: Bound<'py, PyAny>,
    sampler: Option<&str>,
    points: Option<PyReadonlyArrayDyn<'py, f64>>,
    n: Option<usize>,
    dimension: usize,
    spectrum: &str,
    form: &str,
    realizations: Option<usize>,
    reference_n: Option<usize>,
    kmax: Option<usize>,
    seed: u64,
    randomization: &str,
    cells: Option<&str>,
    cache: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let source = Source::from_args(sampler, points, n, dimension, cache)?;
    let randomization = source.randomization(randomization)?;
    let cells: Option<CellRule> = cells.map(str::parse).transpose().or_value_error()?;
    let f = required_integrand(&integrand, source.dimension())?;
    let params = PredictParams {
        spectrum: spectrum.parse().or_value_error()?,
        form: form.parse().or_value_error()?,
        realizations,
        reference_n,
        kmax,
        seed,
        budget: budget(),
        ..Default::default()
    };
    let prediction = py
        .detach(|| {
            let problem = match &source {
                Source::Sampler(_, s, n) => Problem::new(s.as_ref(), f.as_ref(), *n)?,
                Source::Sets(sets) => Problem::from_point_sets(sets, f.as_ref())?,
            };
            // A sampler's problem refuses declared cells: its own come from its facts.
            let problem = match cells {
                Some(rule) => problem.with_cells(rule)?,
                None => problem,
            };
            predict_variance(&problem.with_randomization(randomization), &params)
        })
        .or_value_error()?;
    to_py(py, &prediction)
}

/// A plan's parameters from Python's arguments: the library's defaults with the session's
/// budget.
fn plan_params(
    target: specvar::plan::Target,
    randomization: RandomizationChoice,
    max_n: Option<usize>,
    seed: u64,
) -> specvar::plan::PlanParams {
    let base = specvar::plan::PlanParams::new(target);
    specvar::plan::PlanParams {
        randomization,
        max_n,
        predict: PredictParams {
            seed,
            budget: budget(),
            ..base.predict
        },
        ..base
    }
}

/// For each sampler, the smallest balanced N whose predicted RMSE on `integrand` reaches
/// `rmse` (relative to the integral's magnitude with `relative`), with the prediction there; or,
/// for a stack of per-pixel cell values `(pixels, h, w)` or `(rows, columns, h, w)` in
/// `pixels`, the image's RMSE.
#[pyfunction]
#[pyo3(signature = (integrand, rmse, relative=false, samplers=None, dimension=2, randomization="native", max_n=None, seed=0, cache=true, pixels=None, tabulation="averages"))]
#[allow(clippy::too_many_arguments)]
fn plan<'py>(
    py: Python<'py>,
    integrand: Option<Bound<'py, PyAny>>,
    rmse: f64,
    relative: bool,
    samplers: Option<Vec<String>>,
    dimension: usize,
    randomization: &str,
    max_n: Option<usize>,
    seed: u64,
    cache: bool,
    pixels: Option<PyReadonlyArrayDyn<'py, f64>>,
    tabulation: &str,
) -> PyResult<Bound<'py, PyAny>> {
    use specvar::pixels::PixelStack;
    let meaning: GridMeaning = tabulation.parse().or_value_error()?;
    use specvar::plan::{default_samplers, plan_many, plan_pixels_many, Target};
    let target = Target::new(rmse, relative);
    let kinds: Vec<SamplerKind> = match samplers {
        Some(names) => names
            .iter()
            .map(|n| n.parse())
            .collect::<specvar::Result<_>>()
            .or_value_error()?,
        None => default_samplers(dimension),
    };
    let built = kinds
        .iter()
        .map(|k| build_sampler(k.name(), dimension, cache))
        .collect::<specvar::Result<Vec<_>>>()
        .or_value_error()?;
    let params = plan_params(target, randomization.parse().or_value_error()?, max_n, seed);
    let refs: Vec<&dyn Sampler> = built.iter().map(|s| s.as_ref()).collect();
    let silent = specvar::progress::Silent;
    let plans = match (integrand, pixels) {
        (None, Some(stack)) => {
            let stack = PixelStack::from_array(specvar::npy::NpyArray {
                shape: stack.shape().to_vec(),
                values: stack.as_array().iter().copied().collect(),
            })
            .or_value_error()?
            .with_meaning(meaning);
            py.detach(|| plan_pixels_many(&refs, &stack, &params, &silent))
        }
        (Some(integrand), None) => {
            let f = required_integrand(&integrand, dimension)?;
            py.detach(|| plan_many(&refs, f.as_ref(), &params, &silent))
        }
        _ => {
            return Err(PyValueError::new_err(
                "give one of an integrand and a stack of pixels",
            ))
        }
    }
    .or_value_error()?;
    to_py(py, &plans)
}

/// The samples per pixel for `sampler` from a pilot: `renders`, an array whose first axis is
/// the render (`(renders, h, w)` or `(renders, pixels)`), made with that sampler at `n`
/// samples per pixel; planned for the image's RMSE.
#[pyfunction]
#[pyo3(signature = (renders, n, sampler, rmse, relative=false, model="padded", randomization="native", max_n=None, seed=0, cache=true))]
#[allow(clippy::too_many_arguments)]
fn plan_pilot<'py>(
    py: Python<'py>,
    renders: PyReadonlyArrayDyn<'py, f64>,
    n: usize,
    sampler: &str,
    rmse: f64,
    relative: bool,
    model: &str,
    randomization: &str,
    max_n: Option<usize>,
    seed: u64,
    cache: bool,
) -> PyResult<Bound<'py, PyAny>> {
    use specvar::pilot::{plan_pilot, Pilot, PilotModel};
    use specvar::plan::Target;
    let target = Target::new(rmse, relative);
    let pilot = Pilot::from_array(
        n,
        specvar::npy::NpyArray {
            shape: renders.shape().to_vec(),
            values: renders.as_array().iter().copied().collect(),
        },
    )
    .or_value_error()?
    .with_model(model.parse::<PilotModel>().or_value_error()?);
    let built = build_sampler(sampler, 2, cache).or_value_error()?;
    let params = plan_params(target, randomization.parse().or_value_error()?, max_n, seed);
    let silent = specvar::progress::Silent;
    let plan = py
        .detach(|| plan_pilot(built.as_ref(), &pilot, &params, &silent))
        .or_value_error()?;
    let variance = pilot.variance();
    let out = to_py(py, &plan)?;
    out.set_item("pilot", to_py(py, &variance)?)?;
    Ok(out)
}

/// A padded problem from Python's arguments: the 4D grids (one, or a stack of pixels) and the
/// two samplers.
struct PaddedInput {
    pixels: Vec<specvar::padded::PaddedGrid>,
    first: Box<dyn Sampler>,
    second: Box<dyn Sampler>,
}

impl PaddedInput {
    /// `values` of rank 4 (one grid) or 5 (pixels first).
    fn new(
        values: &PyReadonlyArrayDyn<'_, f64>,
        sampler: &str,
        second: Option<&str>,
        tabulation: &str,
        cache: bool,
    ) -> PyResult<Self> {
        let meaning: GridMeaning = tabulation.parse().or_value_error()?;
        let shape = values.shape().to_vec();
        let all: Vec<f64> = values.as_array().iter().copied().collect();
        let (count, grid) = match shape.as_slice() {
            [p, rest @ ..] if rest.len() == 4 => (*p, rest.to_vec()),
            _ => (1, shape.clone()),
        };
        let cells = grid.iter().product::<usize>().max(1);
        let pixels = (0..count)
            .map(|p| {
                specvar::padded::PaddedGrid::from_array(specvar::npy::NpyArray {
                    shape: grid.clone(),
                    values: all[p * cells..(p + 1) * cells].to_vec(),
                })
                .map(|g| g.with_meaning(meaning))
            })
            .collect::<specvar::Result<Vec<_>>>()
            .or_value_error()?;
        Ok(Self {
            pixels,
            first: build_sampler(sampler, 2, cache).or_value_error()?,
            second: build_sampler(second.unwrap_or(sampler), 2, cache).or_value_error()?,
        })
    }

    /// The one grid of a rank-4 input.
    fn grid(&self) -> PyResult<&specvar::padded::PaddedGrid> {
        match self.pixels.as_slice() {
            [f] => Ok(f),
            _ => Err(PyValueError::new_err(
                "one 4D grid (ay, ax, by, bx): a stack of pixels is planned, not predicted here",
            )),
        }
    }

    /// The two samplers randomized as `randomization` names.
    fn samplers(&self, randomization: &str) -> PyResult<specvar::padded::PaddedSamplers<'_>> {
        let choice: RandomizationChoice = randomization.parse().or_value_error()?;
        specvar::padded::PaddedSamplers::new(self.first.as_ref(), self.second.as_ref(), choice)
            .or_value_error()
    }
}

/// The variance of a 4D integrand `values[ay, ax, by, bx]` under two 2D patterns padded
/// together (`sampler` on the first pair, `second` on the other), and with `mc` trials its
/// Monte Carlo measurement.
#[pyfunction]
#[pyo3(signature = (values, sampler, n, second=None, randomization="native", mc=None, seed=0, cache=true, tabulation="averages"))]
#[allow(clippy::too_many_arguments)]
fn predict_padded<'py>(
    py: Python<'py>,
    values: PyReadonlyArrayDyn<'py, f64>,
    sampler: &str,
    n: usize,
    second: Option<&str>,
    randomization: &str,
    mc: Option<usize>,
    seed: u64,
    cache: bool,
    tabulation: &str,
) -> PyResult<Bound<'py, PyAny>> {
    use specvar::padded::{padded_monte_carlo, predict_padded};
    let input = PaddedInput::new(&values, sampler, second, tabulation, cache)?;
    let (f, samplers) = (input.grid()?, input.samplers(randomization)?);
    let params = PredictParams {
        seed,
        budget: budget(),
        ..Default::default()
    };
    let silent = specvar::progress::Silent;
    let (prediction, measured) = py
        .detach(|| {
            let p = predict_padded(f, samplers, n, &params, &silent)?;
            let m = mc
                .map(|trials| padded_monte_carlo(f, samplers, n, trials, seed, &budget()))
                .transpose()?;
            Ok::<_, specvar::Error>((p, m))
        })
        .or_value_error()?;
    let out = to_py(py, &prediction)?;
    out.set_item("measured", to_py(py, &measured)?)?;
    Ok(out)
}

/// The samples for a target RMSE of a padded estimator on a 4D integrand, or on an image of
/// them (`values` of rank 5, pixels first: the image's RMSE).
#[pyfunction]
#[pyo3(signature = (values, sampler, rmse, relative=false, second=None, randomization="native", max_n=None, seed=0, cache=true, tabulation="averages"))]
#[allow(clippy::too_many_arguments)]
fn plan_padded<'py>(
    py: Python<'py>,
    values: PyReadonlyArrayDyn<'py, f64>,
    sampler: &str,
    rmse: f64,
    relative: bool,
    second: Option<&str>,
    randomization: &str,
    max_n: Option<usize>,
    seed: u64,
    cache: bool,
    tabulation: &str,
) -> PyResult<Bound<'py, PyAny>> {
    use specvar::padded::{plan_padded, plan_padded_pixels};
    use specvar::plan::Target;
    let input = PaddedInput::new(&values, sampler, second, tabulation, cache)?;
    let samplers = input.samplers(randomization)?;
    let target = Target::new(rmse, relative);
    // The samplers carry their randomizations: the plan's own is not read.
    let params = plan_params(target, RandomizationChoice::Native, max_n, seed);
    let silent = specvar::progress::Silent;
    let plan = py
        .detach(|| match input.pixels.as_slice() {
            [f] => plan_padded(f, samplers, &params, &silent),
            pixels => plan_padded_pixels(pixels, samplers, &params, &silent),
        })
        .or_value_error()?;
    to_py(py, &plan)
}

/// Every pixel's predicted variance, and the image's MSE, for a stack of per-pixel cell values
/// `(pixels, h, w)` or `(rows, columns, h, w)`, each `values[y, x]`.
#[pyfunction]
#[pyo3(signature = (pixels, sampler, n, randomization="native", seed=0, cache=true, tabulation="averages"))]
#[allow(clippy::too_many_arguments)]
fn predict_image<'py>(
    py: Python<'py>,
    pixels: PyReadonlyArrayDyn<'py, f64>,
    sampler: &str,
    n: usize,
    randomization: &str,
    seed: u64,
    cache: bool,
    tabulation: &str,
) -> PyResult<Bound<'py, PyAny>> {
    use specvar::pixels::{pixel_params, predict_pixels, PixelStack};
    let array = specvar::npy::NpyArray {
        shape: pixels.shape().to_vec(),
        values: pixels.as_array().iter().copied().collect(),
    };
    let meaning: GridMeaning = tabulation.parse().or_value_error()?;
    let stack = PixelStack::from_array(array)
        .or_value_error()?
        .with_meaning(meaning);
    let s = build_sampler(sampler, 2, cache).or_value_error()?;
    s.check_count(n).or_value_error()?;
    let choice: RandomizationChoice = randomization.parse().or_value_error()?;
    let params = pixel_params(&PredictParams {
        seed,
        budget: budget(),
        ..Default::default()
    });
    let image = py
        .detach(|| {
            predict_pixels(
                &stack,
                s.as_ref(),
                n,
                choice,
                &params,
                &specvar::progress::Silent,
            )
        })
        .or_value_error()?;
    to_py(py, &image)
}

/// Monte Carlo of the estimator with a 99% interval, on a built-in integrand (a specification
/// string or a 2D array of cell values) or a Python function `f(points (N, d)) -> values (N,)`.
#[pyfunction]
#[pyo3(signature = (integrand, sampler=None, points=None, n=None, dimension=2, trials=10000, shifts=None, seed=0, randomization="native", integral=None, cache=true))]
#[allow(clippy::too_many_arguments)]
fn monte_carlo<'py>(
    py: Python<'py>,
    integrand: Bound<'py, PyAny>,
    sampler: Option<&str>,
    points: Option<PyReadonlyArrayDyn<'py, f64>>,
    n: Option<usize>,
    dimension: usize,
    trials: usize,
    shifts: Option<usize>,
    seed: u64,
    randomization: &str,
    integral: Option<f64>,
    cache: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let source = Source::from_args(sampler, points, n, dimension, cache)?;
    let randomization = source.randomization(randomization)?;
    let result =
        match builtin_integrand(&integrand, source.dimension())? {
            Some(f) => {
                if integral.is_some() {
                    return Err(PyValueError::new_err(
                        "integral= is for Python integrands: a built-in integrand knows its own",
                    ));
                }
                builtin_monte_carlo(py, f.as_ref(), &source, trials, shifts, seed, randomization)?
            }
            None if integrand.is_callable() => {
                if shifts.is_some_and(|s| s != 1) {
                    return Err(PyValueError::new_err(
                    "a Python integrand is integrated with one shift per pattern: leave shifts \
                     unset",
                ));
                }
                callable_monte_carlo(
                    py,
                    &integrand,
                    &source,
                    trials,
                    seed,
                    randomization,
                    integral,
                )?
            }
            None => return Err(PyValueError::new_err(
                "the integrand must be a specification string, a 2D array of cell values, or a \
                 function f(points) -> values",
            )),
        };
    to_py(py, &result)
}

fn builtin_monte_carlo(
    py: Python<'_>,
    f: &dyn Integrand,
    source: &Source,
    trials: usize,
    shifts: Option<usize>,
    seed: u64,
    randomization: Randomization,
) -> PyResult<McResult> {
    let silent = &specvar::progress::Silent;
    py.detach(|| match source {
        Source::Sampler(kind, s, n) => {
            let params = McParams {
                budget: budget(),
                ..McParams::for_sampler(*kind, trials, shifts, seed, randomization)
            };
            empirical_variances(s.as_ref(), &[f], *n, &params, silent)
        }
        Source::Sets(sets) => {
            let params = McParams {
                budget: budget(),
                ..McParams::for_sets(sets.len(), trials, shifts, seed, randomization)
            };
            empirical_variances_of_sets(sets, &[f], &params, silent)
        }
    })
    .map(|mut r| r.remove(0))
    .or_value_error()
}

/// Monte Carlo of a Python function: the patterns are drawn (and shifted) in parallel with the
/// interpreter released, block by block; the function sees each pattern as an `(N, d)` array.
fn callable_monte_carlo(
    py: Python<'_>,
    f: &Bound<'_, PyAny>,
    source: &Source,
    trials: usize,
    seed: u64,
    randomization: Randomization,
    integral: Option<f64>,
) -> PyResult<McResult> {
    let patterns = match source {
        Source::Sampler(..) => trials,
        Source::Sets(sets) => sets.len(),
    };
    let params = McParams {
        patterns,
        shifts: 1,
        seed,
        randomization,
        budget: budget(),
    };
    let (n, d) = (source.n(), source.dimension());
    if let Source::Sampler(_, s, _) = source {
        let needs = blocked_run_needs(s.as_ref(), n, patterns);
        params
            .budget
            .check("the Monte Carlo run", needs, "lower the trials or N")
            .or_value_error()?;
    }
    let mut estimates = Vec::with_capacity(patterns);
    for first in (0..patterns).step_by(TRIAL_BLOCK) {
        let last = (first + TRIAL_BLOCK).min(patterns);
        let sets = py
            .detach(|| {
                (first..last)
                    .into_par_iter()
                    .map(|t| match source {
                        Source::Sampler(_, s, n) => trial_pattern(s.as_ref(), *n, &params, t),
                        Source::Sets(sets) => shifted_pattern(&sets[t], &params, t),
                    })
                    .collect::<specvar::Result<Vec<_>>>()
            })
            .or_value_error()?;
        for set in sets {
            let x = PyArray1::from_vec(py, set.coords().to_vec()).reshape([n, d])?;
            let values = f.call1((x,))?;
            let values: PyReadonlyArrayDyn<'_, f64> = values.extract().map_err(|_| {
                PyValueError::new_err(
                    "the integrand must return a float64 array of shape (N,) for points of \
                     shape (N, d)",
                )
            })?;
            let values = values.as_array();
            if values.len() != n {
                return Err(PyValueError::new_err(format!(
                    "the integrand returned {} values for {n} points; it must return one per \
                     point",
                    values.len()
                )));
            }
            estimates.push(values.iter().sum::<f64>() / n as f64);
        }
    }
    result_from_estimates(n, &params, &estimates, integral).or_value_error()
}

/// The exact integral, energy and label of a built-in integrand (string or cell values).
#[pyfunction]
#[pyo3(signature = (integrand, dimension=2))]
fn integrand_facts<'py>(
    py: Python<'py>,
    integrand: Bound<'py, PyAny>,
    dimension: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let f = required_integrand(&integrand, dimension)?;
    let facts = PyDict::new(py);
    facts.set_item("label", f.label())?;
    facts.set_item("integral", f.integral())?;
    facts.set_item("integral_of_square", f.integral_of_square())?;
    facts.set_item("isotropic", f.is_isotropic())?;
    Ok(facts)
}

/// A built-in integrand (string or cell values) evaluated at points `(N, d)`: an array `(N,)`.
#[pyfunction]
#[pyo3(signature = (integrand, points))]
fn evaluate<'py>(
    py: Python<'py>,
    integrand: Bound<'py, PyAny>,
    points: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let sets = point_sets(&points)?;
    let f = required_integrand(&integrand, sets[0].dimension())?;
    let values: Vec<f64> = sets
        .iter()
        .flat_map(|s| s.points().map(|x| f.eval(x)))
        .collect();
    Ok(PyArray1::from_vec(py, values))
}

/// Point sets from a file (UTK text or binary, JSON): an array `(M, N, d)` when every set has
/// the same N, else a list of `(N, d)` arrays.
#[pyfunction]
fn read_points<'py>(py: Python<'py>, path: std::path::PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let sets = specvar::io::read_file(&path).or_value_error()?;
    let (n, d) = (sets[0].len(), sets[0].dimension());
    if sets.iter().all(|s| s.len() == n) {
        return array_of_sets(py, &sets, n, d);
    }
    let arrays = sets
        .iter()
        .map(|s| PyArray1::from_slice(py, s.coords()).reshape([s.len(), d]))
        .collect::<PyResult<Vec<_>>>()?;
    Ok(PyList::new(py, arrays)?.into_any())
}

/// Writes point sets `(M, N, d)` or `(N, d)` atomically as UTK text (`text`), UTK binary
/// (`binary`) or JSON (`json`).
#[pyfunction]
#[pyo3(signature = (path, points, format="text"))]
fn write_points(
    path: std::path::PathBuf,
    points: PyReadonlyArrayDyn<'_, f64>,
    format: &str,
) -> PyResult<()> {
    let sets = point_sets(&points)?;
    let bytes = match format {
        "text" => specvar::io::write_text(&sets).into_bytes(),
        "binary" => specvar::io::write_utk_binary(&sets).or_value_error()?,
        "json" => specvar::io::write_json(&sets)
            .or_value_error()?
            .into_bytes(),
        other => {
            return Err(PyValueError::new_err(format!(
                "invalid format: {other} (allowed: text, binary or json)"
            )))
        }
    };
    specvar::output::write_atomic(&path, &bytes).or_value_error()
}

/// The module.
#[pymodule]
fn _specvar(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(set_budget, m)?)?;
    m.add_function(wrap_pyfunction!(samplers, m)?)?;
    m.add_function(wrap_pyfunction!(sample, m)?)?;
    m.add_function(wrap_pyfunction!(periodogram, m)?)?;
    m.add_function(wrap_pyfunction!(spectrum, m)?)?;
    m.add_function(wrap_pyfunction!(predict, m)?)?;
    m.add_function(wrap_pyfunction!(monte_carlo, m)?)?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(plan_pilot, m)?)?;
    m.add_function(wrap_pyfunction!(predict_padded, m)?)?;
    m.add_function(wrap_pyfunction!(plan_padded, m)?)?;
    m.add_function(wrap_pyfunction!(predict_image, m)?)?;
    m.add_function(wrap_pyfunction!(integrand_facts, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(read_points, m)?)?;
    m.add_function(wrap_pyfunction!(write_points, m)?)?;
    study::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

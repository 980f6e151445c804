//! Conversions between the library's types and Python's: errors, point sets, results.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use pyo3::IntoPyObjectExt;
use specvar::pointset::PointSet;
use specvar::spectrum::SpectrumEstimate;

/// A library result as a Python one: errors become `ValueError` with the library's message,
/// the line the command line prints after `error: `.
pub trait OrValueError<T> {
    /// The value, or the error as a `ValueError`.
    fn or_value_error(self) -> PyResult<T>;
}

impl<T> OrValueError<T> for specvar::Result<T> {
    fn or_value_error(self) -> PyResult<T> {
        self.map_err(|e| PyValueError::new_err(e.to_string()))
    }
}

/// Point sets from an array `(M, N, d)` or `(N, d)`, read in place (one copy into each set's
/// coordinates, which the library owns). Coordinates must lie in `[0, 1)`.
pub fn point_sets(array: &PyReadonlyArrayDyn<'_, f64>) -> PyResult<Vec<PointSet>> {
    let shape = array.shape().to_vec();
    let (m, n, d) = match shape[..] {
        [n, d] => (1, n, d),
        [m, n, d] => (m, n, d),
        _ => {
            return Err(PyValueError::new_err(format!(
                "points must have shape (M, N, d) or (N, d), not {shape:?}"
            )))
        }
    };
    if m == 0 || n == 0 || d == 0 {
        return Err(PyValueError::new_err(format!(
            "points must hold at least one set of one point in at least one dimension, not \
             shape {shape:?}"
        )));
    }
    let view = array.as_array();
    let flat: Vec<f64> = match array.as_slice() {
        Ok(slice) => slice.to_vec(),
        // A strided view (a slice of a larger array): read in logical order.
        Err(_) => view.iter().copied().collect(),
    };
    flat.chunks_exact(n * d)
        .map(|coords| PointSet::new(d, coords.to_vec()).or_value_error())
        .collect()
}

/// Sets of `n` points in dimension `d` as one array `(M, N, d)`, built from one buffer that
/// numpy takes over without a copy.
pub fn array_of_sets<'py>(
    py: Python<'py>,
    sets: &[PointSet],
    n: usize,
    d: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let mut flat = Vec::with_capacity(sets.len() * n * d);
    for s in sets {
        flat.extend_from_slice(s.coords());
    }
    Ok(PyArray1::from_vec(py, flat)
        .reshape([sets.len(), n, d])?
        .into_any())
}

/// Any serializable result as Python objects (dicts, lists, floats, ints, strings), through
/// its serde form; non-finite floats, which serde writes as null, become `None`.
pub fn to_py<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let tree = serde_json::to_value(value)
        .map_err(|e| PyValueError::new_err(format!("cannot convert a result: {e}")))?;
    json_to_py(py, &tree)
}

fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    match v {
        Value::Null => Ok(py.None().into_bound(py)),
        Value::Bool(b) => b.into_bound_py_any(py),
        Value::Number(x) => match (x.as_u64(), x.as_i64()) {
            (Some(u), _) => u.into_bound_py_any(py),
            (None, Some(i)) => i.into_bound_py_any(py),
            _ => x.as_f64().unwrap_or(f64::NAN).into_bound_py_any(py),
        },
        Value::String(s) => s.into_bound_py_any(py),
        Value::Array(items) => {
            let items = items
                .iter()
                .map(|i| json_to_py(py, i))
                .collect::<PyResult<Vec<_>>>()?;
            Ok(PyList::new(py, items)?.into_any())
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, v) in map {
                dict.set_item(k, json_to_py(py, v)?)?;
            }
            Ok(dict.into_any())
        }
    }
}

/// A spectrum estimate as a dict of arrays: the lattice mean and standard error shaped
/// `(2K+1,)*d` (NaN standard errors kept as NaN), and the radial rings column by column.
pub fn spectrum_dict<'py>(
    py: Python<'py>,
    estimate: &SpectrumEstimate,
) -> PyResult<Bound<'py, PyAny>> {
    let lattice = &estimate.lattice;
    let shape = vec![lattice.lattice.side(); lattice.lattice.dimension];
    let out = PyDict::new(py);
    out.set_item("n", lattice.n)?;
    out.set_item("dimension", lattice.lattice.dimension)?;
    out.set_item("kmax", lattice.lattice.kmax)?;
    out.set_item("realizations", lattice.realizations)?;
    out.set_item("engine", lattice.engine.name())?;
    let array = |v: &[f64]| PyArray1::from_slice(py, v).reshape(shape.clone());
    out.set_item("mean", array(&lattice.mean)?)?;
    out.set_item("stderr", array(&lattice.stderr)?)?;
    let radial = &estimate.radial;
    let column = |f: fn(&specvar::spectrum::RadialBin) -> f64| {
        PyArray1::from_vec(py, radial.bins.iter().map(f).collect())
    };
    let rings = PyDict::new(py);
    rings.set_item("nu", column(|b| b.nu))?;
    rings.set_item("rho", column(|b| b.rho))?;
    rings.set_item("power", column(|b| b.power))?;
    rings.set_item("stderr", column(|b| b.stderr))?;
    rings.set_item("count", column(|b| b.count as f64))?;
    rings.set_item("anisotropy_db", column(|b| b.anisotropy_db))?;
    rings.set_item("dc_limit", radial.dc_limit)?;
    rings.set_item("bin_width", radial.bin_width)?;
    out.set_item("radial", rings)?;
    Ok(out.into_any())
}

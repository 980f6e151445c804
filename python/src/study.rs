//! Rate studies, whole or as blocks of Monte Carlo patterns that run anywhere (the workers of
//! a Dask cluster) and are finished in one place, with the same bits as the whole study.

use crate::convert::{to_py, OrValueError};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use specvar::montecarlo::PatternErrors;
use specvar::progress::Silent;
use specvar::rate::{BlockErrors, McBlock, StudyConfig, StudyDescription};

/// The library's configuration from its description ([`StudyDescription`], the one schema of
/// a study outside Rust), under the module's budget.
fn config(described: &str) -> PyResult<StudyConfig> {
    let description = StudyDescription::from_json(described).or_value_error()?;
    Ok(description.into_config(crate::budget()))
}

/// A block as Python holds it: `(sampler, n, start, count)`.
type BlockTuple = (String, usize, usize, usize);

fn block(t: &BlockTuple) -> PyResult<McBlock> {
    Ok(McBlock {
        sampler: t.0.parse().or_value_error()?,
        n: t.1,
        start: t.2,
        count: t.3,
    })
}

/// The whole study in this process.
#[pyfunction]
fn run_study<'py>(py: Python<'py>, described: &str) -> PyResult<Bound<'py, PyAny>> {
    let config = config(described)?;
    let study = py
        .detach(|| specvar::rate::run_study(&config, &Silent))
        .or_value_error()?;
    to_py(py, &study)
}

/// The study's Monte Carlo as blocks of at most `patterns_per_block` patterns, after checking
/// the whole study.
#[pyfunction]
fn study_blocks(described: &str, patterns_per_block: usize) -> PyResult<Vec<BlockTuple>> {
    let config = config(described)?;
    config.check().or_value_error()?;
    Ok(config
        .mc_blocks(patterns_per_block)
        .into_iter()
        .map(|b| (b.sampler.name().to_string(), b.n, b.start, b.count))
        .collect())
}

/// One block's errors: an array `(count, integrands, 2)` of each pattern's mean error and mean
/// squared error over its shifts.
#[pyfunction]
fn study_block<'py>(
    py: Python<'py>,
    described: &str,
    block: BlockTuple,
) -> PyResult<Bound<'py, PyAny>> {
    let config = config(described)?;
    let b = self::block(&block)?;
    let errors = py
        .detach(|| config.run_mc_block(&b, &Silent))
        .or_value_error()?;
    let k = config.integrands.len();
    let flat: Vec<f64> = errors
        .iter()
        .flat_map(|row| row.iter().flat_map(|e| [e.mean, e.mean_square]))
        .collect();
    Ok(PyArray1::from_vec(py, flat)
        .reshape([errors.len(), k, 2])?
        .into_any())
}

/// The study from its blocks and their errors (in the same order).
#[pyfunction]
fn finish_study<'py>(
    py: Python<'py>,
    described: &str,
    blocks: Vec<BlockTuple>,
    errors: Vec<PyReadonlyArrayDyn<'py, f64>>,
) -> PyResult<Bound<'py, PyAny>> {
    let config = config(described)?;
    if blocks.len() != errors.len() {
        return Err(PyValueError::new_err(format!(
            "{} blocks but {} arrays of errors",
            blocks.len(),
            errors.len()
        )));
    }
    let k = config.integrands.len();
    let mut done = Vec::with_capacity(blocks.len());
    for (t, e) in blocks.iter().zip(&errors) {
        let b = block(t)?;
        if e.shape() != [b.count, k, 2] {
            return Err(PyValueError::new_err(format!(
                "the errors of block {t:?} have shape {:?}; expected ({}, {k}, 2)",
                e.shape(),
                b.count
            )));
        }
        let values: Vec<f64> = e.as_array().iter().copied().collect();
        let rows: BlockErrors = values
            .chunks_exact(2 * k)
            .map(|row| {
                row.chunks_exact(2)
                    .map(|p| PatternErrors {
                        mean: p[0],
                        mean_square: p[1],
                    })
                    .collect()
            })
            .collect();
        done.push((b, rows));
    }
    let study = py
        .detach(|| specvar::rate::finish_study(&config, &done, &Silent))
        .or_value_error()?;
    to_py(py, &study)
}

/// Adds the study functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run_study, m)?)?;
    m.add_function(wrap_pyfunction!(study_blocks, m)?)?;
    m.add_function(wrap_pyfunction!(study_block, m)?)?;
    m.add_function(wrap_pyfunction!(finish_study, m)?)?;
    Ok(())
}

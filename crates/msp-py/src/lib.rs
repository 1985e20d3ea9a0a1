//! Python bindings: thin conversions around the `msp` library and its registry.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A `ValueError` with the library's message.
pub(crate) fn value_err(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

mod columns;
mod controller;
mod convert;
mod estimator;
mod plant;
mod study;

use controller::{Controller, PyPid};
use plant::{parse_plant, Plant};
use study::{
    autotune, compare, controllers, identify, margins, run, run_matrix, simulate, step, step_info,
    sweep, tradeoff, tune, tune_matrix, tune_rules,
};

/// The compiled part of the ``msp`` package.
#[pymodule]
fn _msp(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Plant>()?;
    m.add_class::<estimator::Estimator>()?;
    m.add_class::<Controller>()?;
    m.add_class::<PyPid>()?;
    m.add_class::<convert::PendingAnalysis>()?;
    m.add_function(wrap_pyfunction!(parse_plant, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(tune, m)?)?;
    m.add_function(wrap_pyfunction!(tune_rules, m)?)?;
    m.add_function(wrap_pyfunction!(tune_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(run_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(step_info, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(tradeoff, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(margins, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(autotune, m)?)?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(step, m)?)?;
    m.add_function(wrap_pyfunction!(controllers, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // the scenario's fields as the library defines them (tests check the keyword arguments)
    m.add("SCENARIO_FIELDS", msp::study::Scenario::FIELDS.to_vec())?;
    // their keywords in Python (`set` is `params`, `lambda` is `lambda_`): all of
    // them (`run`, `compare`), a design's (`margins`, `sweep`) and a tuning's (`tune`)
    m.add("SCENARIO_KEYWORDS", convert::Takes::All.keywords())?;
    m.add("DESIGN_KEYWORDS", convert::Takes::Design(&[]).keywords())?;
    m.add(
        "TUNE_KEYWORDS",
        convert::Takes::Only(convert::TUNE).keywords(),
    )?;
    Ok(())
}

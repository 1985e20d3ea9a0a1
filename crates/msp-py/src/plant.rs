//! Plants: the `Plant` class and the conversion of a plant argument (a `Plant` or an expression).

use crate::value_err;
use msp::poly::TransferFunction;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyString;

/// A transfer function with dead time ``num(s)/den(s)·e^(−delay·s)``.
///
/// Parameters
/// ----------
/// num, den : list of float
///     The coefficients in descending powers of ``s``.
/// delay : float, optional
///     The dead time (s).
///
/// Examples
/// --------
/// >>> from msp import Plant
/// >>> p = Plant([2.0], [10.0, 1.0], 5.0)
/// >>> str(p), p.kind
/// ('2*e^(-5s)/(10s + 1)', 'stable')
#[pyclass(frozen, module = "msp._msp")]
#[derive(Clone)]
pub struct Plant {
    inner: TransferFunction,
}

#[pymethods]
impl Plant {
    /// From coefficients in descending powers of `s` and a dead time.
    #[new]
    #[pyo3(signature = (num, den, delay = 0.0))]
    fn new(num: Vec<f64>, den: Vec<f64>, delay: f64) -> PyResult<Self> {
        Ok(Plant {
            inner: TransferFunction::new(&num, &den, delay).map_err(value_err)?,
        })
    }
    /// Numerator coefficients (descending powers of s).
    #[getter]
    fn num(&self) -> Vec<f64> {
        self.inner.num.clone()
    }
    /// Denominator coefficients (descending powers of s).
    #[getter]
    fn den(&self) -> Vec<f64> {
        self.inner.den.clone()
    }
    /// Dead time (s).
    #[getter]
    fn delay(&self) -> f64 {
        self.inner.delay
    }
    /// "stable", "integrating" or "unstable".
    #[getter]
    fn kind(&self) -> String {
        self.inner.kind().to_string()
    }
    /// Denominator degree.
    #[getter]
    fn order(&self) -> usize {
        self.inner.order()
    }
    fn __str__(&self) -> String {
        self.inner.to_string()
    }
    fn __repr__(&self) -> String {
        format!("msp.parse_plant({:?})", self.inner.to_string())
    }
    fn __eq__(&self, other: &Plant) -> bool {
        self.inner == other.inner
    }
}

/// Parses a plant expression such as ``"0.2/s*e^-7.4s"``.
///
/// Parameters
/// ----------
/// expr : str
///     Polynomials in ``s`` with sums, products and integer powers, and delay factors
///     ``e^-θs`` or ``exp(-θ*s)``.
///
/// Returns
/// -------
/// Plant
///
/// Raises
/// ------
/// ValueError
///     The problem and its column, with a caret under it.
///
/// Examples
/// --------
/// >>> from msp import parse_plant
/// >>> str(parse_plant("2*e^-5s/(10s+1)^4"))
/// '2*e^(-5s)/(10s + 1)^4'
#[pyfunction]
pub(crate) fn parse_plant(expr: &str) -> PyResult<Plant> {
    Ok(Plant {
        inner: msp::syntax::parse_plant(expr).map_err(value_err)?,
    })
}

pub(crate) fn plant_of(obj: &Bound<'_, PyAny>) -> PyResult<TransferFunction> {
    if let Ok(p) = obj.downcast::<Plant>() {
        return Ok(p.get().inner.clone());
    }
    if obj.downcast::<PyString>().is_ok() {
        let s: String = obj.extract()?;
        return msp::syntax::parse_plant(&s).map_err(value_err);
    }
    Err(PyValueError::new_err(
        "a plant is an expression string or an msp.Plant",
    ))
}

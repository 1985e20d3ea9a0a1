//! Python arguments to the library's typed values, and its results to dicts.

use std::collections::BTreeMap;

use crate::plant::plant_of;
use crate::value_err;
use msp::registry::Params;
use msp::sim::{Disturbance, SetpointStep};
use msp::study::{Perturbation, RunOutput, Scenario};
use numpy::IntoPyArray;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The set point from a number, ``"V@T"``, or a list or tuple of
/// ``(value, time)`` pairs, ``"V@T"`` strings and numbers.
pub(crate) fn setpoints(obj: &Bound<'_, PyAny>) -> PyResult<Vec<SetpointStep>> {
    if let Ok(v) = obj.extract::<f64>() {
        return Ok(vec![SetpointStep { value: v, at: 0.0 }]);
    }
    if let Ok(s) = obj.extract::<String>() {
        return Ok(vec![s.parse().map_err(value_err)?]);
    }
    // a list or a tuple (a string is neither here: it was read above)
    let list: Vec<Bound<'_, PyAny>> = obj.extract().map_err(|_| {
        PyValueError::new_err(
            "setpoint: a number, 'V@T', or a list of (value, time) pairs or 'V@T' strings",
        )
    })?;
    let mut out = Vec::new();
    for item in list {
        if let Ok((value, at)) = item.extract::<(f64, f64)>() {
            out.push(SetpointStep { value, at });
        } else if let Ok(s) = item.extract::<String>() {
            out.push(s.parse().map_err(value_err)?);
        } else if let Ok(v) = item.extract::<f64>() {
            out.push(SetpointStep { value: v, at: 0.0 });
        } else {
            return Err(PyValueError::new_err(
                "setpoint: each step is (value, time) or 'V@T'",
            ));
        }
    }
    Ok(out)
}

/// The disturbances from one ``"input:V@T"`` or dict, or a list or tuple of them.
pub(crate) fn disturbances(obj: &Bound<'_, PyAny>) -> PyResult<Vec<Disturbance>> {
    let items: Vec<Bound<'_, PyAny>> = match obj.extract::<String>() {
        Ok(_) => vec![obj.clone()],
        Err(_) => obj.extract().unwrap_or_else(|_| vec![obj.clone()]),
    };
    let mut out = Vec::new();
    for item in items {
        if let Ok(s) = item.extract::<String>() {
            out.push(s.parse().map_err(value_err)?);
            continue;
        }
        if !item.is_instance_of::<PyDict>() {
            return Err(PyValueError::new_err(
                "disturbance: 'input:V@T' or a dict with location, value, at, shape, freq",
            ));
        }
        // the structured form of a scenario file, read by the library's serde
        let d: Disturbance = pythonize::depythonize(&item)
            .map_err(|e| PyValueError::new_err(format!("disturbance: {e}")))?;
        out.push(d);
    }
    Ok(out)
}

/// A scheme's parameters as a dict (the serde form the JSON report prints).
pub(crate) fn params_dict<'py>(py: Python<'py>, p: &Params) -> PyResult<Bound<'py, PyDict>> {
    Ok(pythonize::pythonize(py, p)?.downcast_into::<PyDict>()?)
}

pub(crate) fn output_dict<'py>(py: Python<'py>, out: RunOutput) -> PyResult<Bound<'py, PyDict>> {
    // the library's report (the keys of `msp run --report`), then the signals
    let d = pythonize::pythonize(py, &out.report())?.downcast_into::<PyDict>()?;
    let r = out.result;
    let signals = PyDict::new(py);
    for (name, v) in r.signals {
        signals.set_item(name, v.into_pyarray(py))?;
    }
    d.set_item("t", r.t.into_pyarray(py))?;
    d.set_item("r", r.r.into_pyarray(py))?;
    d.set_item("y", r.y.into_pyarray(py))?;
    d.set_item("u", r.u.into_pyarray(py))?;
    if !r.u_applied.is_empty() {
        d.set_item("u_applied", r.u_applied.into_pyarray(py))?;
    }
    d.set_item("d", r.d.into_pyarray(py))?;
    d.set_item("d_out", r.d_out.into_pyarray(py))?;
    if !r.y2.is_empty() {
        let rows = r.y2.len();
        d.set_item("y2", r.y2.into_pyarray(py))?;
        let d0 = if r.d_inner.is_empty() {
            vec![0.0; rows]
        } else {
            r.d_inner
        };
        d.set_item("d_inner", d0.into_pyarray(py))?;
    }
    d.set_item("signals", signals)?;
    Ok(d)
}

/// The Python keyword of a scenario field: ``set`` is ``params``, ``lambda``
/// (a Python keyword) is ``lambda_``; the others keep their names.
pub(crate) fn keyword(field: &str) -> &str {
    match field {
        "set" => "params",
        "lambda" => "lambda_",
        f => f,
    }
}

/// The scenario fields of a design (the processes, the controller and its
/// tuning, the period, the precision and the memory) that ``margins`` and
/// ``sweep`` take.
const DESIGN: &[&str] = &[
    "controller",
    "float32",
    "inner_model",
    "inner_plant",
    "lambda",
    "max_memory",
    "model",
    "rule",
    "set",
    "target",
    "ts",
];

/// The scenario's fields a study function takes as keywords (with the plant
/// apart).
#[derive(Clone, Copy)]
pub(crate) enum Takes {
    /// Every field of [`Scenario::FIELDS`].
    All,
    /// The fields of a design, and these (library names).
    Design(&'static [&'static str]),
    /// These fields only (library names).
    Only(&'static [&'static str]),
}

/// The scenario fields ``tune`` takes.
pub(crate) const TUNE: &[&str] = &[
    "inner_plant",
    "controller",
    "lambda",
    "rule",
    "target",
    "set",
    "ts",
];

impl Takes {
    /// The Python keywords of the fields taken (the plant apart), in the
    /// order of [`Scenario::FIELDS`].
    pub(crate) fn keywords(self) -> Vec<&'static str> {
        Scenario::FIELDS
            .iter()
            .filter(|f| **f != "plant" && self.takes(f))
            .map(|f| keyword(f))
            .collect()
    }

    fn takes(self, field: &str) -> bool {
        match self {
            Takes::All => true,
            Takes::Design(also) => DESIGN.contains(&field) || also.contains(&field),
            Takes::Only(list) => list.contains(&field),
        }
    }
}

/// A scenario from ``plant`` and the keyword arguments of a study function:
/// each key a field of [`Scenario::FIELDS`] under its Python name
/// ([`keyword`]), converted as the CLI's flag would be; ``None`` leaves the
/// default. This is the one place the keywords are read: ``run``,
/// ``compare``, ``margins``, ``sweep`` and ``tune`` take their subsets of it.
pub(crate) fn scenario_from(
    plant: &Bound<'_, PyAny>,
    kwargs: Option<&Bound<'_, PyDict>>,
    takes: Takes,
) -> PyResult<Scenario> {
    let mut sc = Scenario {
        plant: Some(plant_of(plant)?),
        ..Default::default()
    };
    for (k, v) in kwargs.into_iter().flat_map(|d| d.iter()) {
        let key: String = k.extract()?;
        let field = Scenario::FIELDS
            .iter()
            .copied()
            .find(|f| *f != "plant" && keyword(f) == key)
            .filter(|f| takes.takes(f))
            .ok_or_else(|| PyTypeError::new_err(format!("unexpected keyword argument '{key}'")))?;
        if v.is_none() {
            continue;
        }
        set_field(&mut sc, field, &v)?;
    }
    if sc.inner_model.is_some() && sc.inner_plant.is_none() {
        return Err(PyValueError::new_err(
            "inner_model needs inner_plant (the secondary process)",
        ));
    }
    Ok(sc)
}

/// Sets the field ``field`` of ``sc`` from the Python value ``v``.
fn set_field(sc: &mut Scenario, field: &str, v: &Bound<'_, PyAny>) -> PyResult<()> {
    match field {
        "model" => sc.model = Some(plant_of(v)?),
        "inner_plant" => sc.inner_plant = Some(plant_of(v)?),
        "inner_model" => sc.inner_model = Some(plant_of(v)?),
        "controller" => sc.controller = Some(v.extract()?),
        "lambda" => sc.lambda = Some(v.extract()?),
        "rule" => sc.rule = Some(v.extract()?),
        "target" => {
            let t: String = v.extract()?;
            sc.target = Some(t.parse().map_err(pyo3::exceptions::PyValueError::new_err)?);
        }
        "set" => sc.set = v.extract()?,
        "ts" => sc.ts = Some(v.extract()?),
        "duration" => sc.duration = Some(v.extract()?),
        "setpoint" => sc.setpoint = setpoints(v)?,
        "disturbance" => sc.disturbance = disturbances(v)?,
        "noise" => sc.noise = Some(v.extract()?),
        "seed" => sc.seed = Some(v.extract()?),
        "umin" => sc.umin = Some(v.extract()?),
        "umax" => sc.umax = Some(v.extract()?),
        "substeps" => sc.substeps = Some(v.extract()?),
        "float32" => sc.float32 = v.extract()?,
        "max_memory" => sc.max_memory = Some(v.extract()?),
        // the operator's events as the flag writes them (["60:manual=0.3", "120:auto"])
        "events" => {
            let list: Vec<String> = match v.extract::<String>() {
                Ok(one) => vec![one],
                Err(_) => v.extract()?,
            };
            sc.events = list
                .iter()
                .map(|s| s.parse().map_err(value_err))
                .collect::<PyResult<_>>()?;
        }
        "actuator" => {
            let (lo, hi): (f64, f64) = v.extract()?;
            if lo.is_nan() || hi.is_nan() || lo >= hi {
                return Err(PyValueError::new_err(
                    "actuator: (min, max) with min below max",
                ));
            }
            sc.actuator = Some((lo, hi));
        }
        "reset_feedback" => sc.reset_feedback = v.extract()?,
        "setpoint_ramp" => sc.setpoint_ramp = Some(v.extract()?),
        other => {
            return Err(PyTypeError::new_err(format!(
                "the scenario field '{other}' is not taken from Python"
            )))
        }
    }
    Ok(())
}

/// A perturbation from ``"delay=20%,tau=-20%"`` or ``{"delay": 0.2, "tau": -0.2}``.
pub(crate) fn perturbation_of(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Perturbation>> {
    let Some(obj) = obj else {
        return Ok(None);
    };
    if let Ok(s) = obj.extract::<String>() {
        return s.parse().map(Some).map_err(value_err);
    }
    let d: BTreeMap<String, f64> = obj.extract()?;
    let mut p = Perturbation::default();
    for (k, v) in d {
        match k.as_str() {
            "gain" => p.gain = v,
            "delay" => p.delay = v,
            "tau" => p.tau = v,
            "inner_gain" => p.inner_gain = v,
            "inner_delay" => p.inner_delay = v,
            "inner_tau" => p.inner_tau = v,
            o => {
                return Err(PyValueError::new_err(format!(
                    "unknown perturbation '{o}': use gain, delay, tau, inner_gain, inner_delay or inner_tau"
                )))
            }
        }
    }
    Ok(Some(p))
}

pub(crate) fn fit_dict<'py>(
    py: Python<'py>,
    fit: &msp::ident::Fit,
) -> PyResult<Bound<'py, PyDict>> {
    // the library's report: the keys of `msp identify --json`
    Ok(pythonize::pythonize(py, fit)?.downcast_into::<PyDict>()?)
}

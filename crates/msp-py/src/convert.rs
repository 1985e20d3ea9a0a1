//! Python arguments to the library's typed values, and its results to dicts.

use std::collections::BTreeMap;

use crate::plant::plant_of;
use crate::value_err;
use msp::registry::Params;
use msp::sim::{Disturbance, Location, SetpointStep, Shape};
use msp::study::{Perturbation, RunOutput, Scenario};
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

pub(crate) fn setpoints(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<SetpointStep>> {
    let Some(obj) = obj else {
        return Ok(Vec::new());
    };
    if let Ok(v) = obj.extract::<f64>() {
        return Ok(vec![SetpointStep { value: v, at: 0.0 }]);
    }
    if let Ok(s) = obj.extract::<String>() {
        return Ok(vec![s.parse().map_err(value_err)?]);
    }
    let list = obj.downcast::<PyList>().map_err(|_| {
        PyValueError::new_err(
            "setpoint: a number, 'V@T', or a list of (value, time) pairs or 'V@T' strings",
        )
    })?;
    let mut out = Vec::new();
    for item in list.iter() {
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

pub(crate) fn disturbances(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Disturbance>> {
    let Some(obj) = obj else {
        return Ok(Vec::new());
    };
    let items: Vec<Bound<'_, PyAny>> = if obj.downcast::<PyList>().is_ok() {
        obj.downcast::<PyList>()?.iter().collect()
    } else {
        vec![obj.clone()]
    };
    let mut out = Vec::new();
    for item in items {
        if let Ok(s) = item.extract::<String>() {
            out.push(s.parse().map_err(value_err)?);
            continue;
        }
        let d = item.downcast::<PyDict>().map_err(|_| {
            PyValueError::new_err(
                "disturbance: 'input:V@T' or a dict with location, value, at, shape, freq",
            )
        })?;
        let get = |k: &str| -> PyResult<Option<Bound<'_, PyAny>>> { d.get_item(k) };
        for key in d.keys() {
            let k: String = key.extract()?;
            if !["location", "value", "at", "shape", "freq"].contains(&k.as_str()) {
                return Err(PyValueError::new_err(format!(
                    "disturbance: unknown field '{k}'"
                )));
            }
        }
        let location = match get("location")?
            .map(|v| v.extract::<String>())
            .transpose()?
            .as_deref()
        {
            Some("input") | Some("load") | Some("d2") | None => Location::Input,
            Some("output") | Some("d1") => Location::Output,
            Some("inner") | Some("d0") => Location::Inner,
            Some(o) => {
                return Err(PyValueError::new_err(format!(
                    "disturbance location '{o}': use 'input' (d2), 'output' (d1) or 'inner' (d0)"
                )))
            }
        };
        let shape = match get("shape")?
            .map(|v| v.extract::<String>())
            .transpose()?
            .as_deref()
        {
            Some("step") | None => Shape::Step,
            Some("ramp") => Shape::Ramp,
            Some("sine") => Shape::Sine,
            Some(o) => {
                return Err(PyValueError::new_err(format!(
                    "disturbance shape '{o}': use step, ramp or sine"
                )))
            }
        };
        let num = |k: &str, default: Option<f64>| -> PyResult<f64> {
            match get(k)? {
                Some(v) => v.extract::<f64>(),
                None => default.ok_or_else(|| {
                    PyValueError::new_err(format!("disturbance: '{k}' is required"))
                }),
            }
        };
        out.push(Disturbance {
            location,
            shape,
            value: num("value", None)?,
            at: num("at", Some(0.0))?,
            freq: num("freq", Some(0.0))?,
        });
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

/// The processes of a scenario: the plant, the controller's model, and the
/// secondary process and its model of a cascade (each a ``Plant`` or an expression).
pub(crate) struct Processes<'a, 'py> {
    pub(crate) plant: &'a Bound<'py, PyAny>,
    pub(crate) model: Option<&'a Bound<'py, PyAny>>,
    pub(crate) inner_plant: Option<&'a Bound<'py, PyAny>>,
    pub(crate) inner_model: Option<&'a Bound<'py, PyAny>>,
}

impl<'a, 'py> Processes<'a, 'py> {
    /// The keyword arguments of the same names.
    pub(crate) fn of(
        plant: &'a Bound<'py, PyAny>,
        model: Option<&'a Bound<'py, PyAny>>,
        inner_plant: Option<&'a Bound<'py, PyAny>>,
        inner_model: Option<&'a Bound<'py, PyAny>>,
    ) -> Self {
        Processes {
            plant,
            model,
            inner_plant,
            inner_model,
        }
    }
}

/// The scenario keywords shared by ``run``, ``compare``, ``margins`` and ``sweep``.
#[allow(clippy::too_many_arguments)]
pub(crate) fn scenario(
    processes: &Processes<'_, '_>,
    controller: Option<String>,
    params: Option<BTreeMap<String, f64>>,
    ts: Option<f64>,
    duration: Option<f64>,
    setpoint: Option<&Bound<'_, PyAny>>,
    disturbance: Option<&Bound<'_, PyAny>>,
    noise: Option<f64>,
    seed: Option<u64>,
    umin: Option<f64>,
    umax: Option<f64>,
    lambda_: Option<f64>,
    rule: Option<String>,
    substeps: Option<usize>,
    float32: bool,
    max_memory: Option<u64>,
) -> PyResult<Scenario> {
    if processes.inner_model.is_some() && processes.inner_plant.is_none() {
        return Err(PyValueError::new_err(
            "inner_model needs inner_plant (the secondary process)",
        ));
    }
    Ok(Scenario {
        plant: Some(plant_of(processes.plant)?),
        model: processes.model.map(plant_of).transpose()?,
        inner_plant: processes.inner_plant.map(plant_of).transpose()?,
        inner_model: processes.inner_model.map(plant_of).transpose()?,
        controller,
        lambda: lambda_,
        rule,
        set: params.unwrap_or_default(),
        ts,
        duration,
        setpoint: setpoints(setpoint)?,
        disturbance: disturbances(disturbance)?,
        noise,
        seed,
        umin,
        umax,
        substeps,
        float32,
        max_memory,
        events: Vec::new(),
        actuator: None,
        reset_feedback: false,
        setpoint_ramp: None,
    })
}

/// The operator's events, the outside actuator and the set-point ramp of
/// ``run`` and ``compare``: ``events`` as the flag writes them
/// (``["60:manual=0.3", "120:auto"]``), ``actuator`` as ``(min, max)``.
pub(crate) fn with_operation(
    mut sc: Scenario,
    events: Option<&Bound<'_, PyAny>>,
    actuator: Option<(f64, f64)>,
    reset_feedback: bool,
    setpoint_ramp: Option<f64>,
) -> PyResult<Scenario> {
    sc.setpoint_ramp = setpoint_ramp;
    if let Some(e) = events {
        let list: Vec<String> = match e.extract::<String>() {
            Ok(one) => vec![one],
            Err(_) => e.extract()?,
        };
        sc.events = list
            .iter()
            .map(|s| s.parse().map_err(value_err))
            .collect::<PyResult<_>>()?;
    }
    if let Some((lo, hi)) = actuator {
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return Err(PyValueError::new_err(
                "actuator: (min, max) with min below max",
            ));
        }
    }
    sc.actuator = actuator;
    sc.reset_feedback = reset_feedback;
    Ok(sc)
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
    let d = PyDict::new(py);
    d.set_item("model", fit.model.kind())?;
    let (ps, n) = fit.model.params();
    for (k, v) in ps.iter().take(n) {
        d.set_item(*k, *v)?;
    }
    d.set_item("rmse", fit.rmse)?;
    d.set_item("r2", fit.r2)?;
    Ok(d)
}

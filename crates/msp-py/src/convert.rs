//! Python arguments to the library's typed values, and its results to dicts.

use std::collections::BTreeMap;

use crate::plant::plant_of;
use crate::value_err;
use msp::registry::Params;
use msp::sim::{Disturbance, SetpointStep};
use msp::study::{Perturbation, RunOutput, Scenario};
use numpy::{PyArray1, PyArrayMethods};
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
    signals_into(py, &d, out.result)?;
    Ok(d)
}

/// The figures of a run computed when first asked for: its metrics and event
/// figures (``Result.metrics``, ``.metrics_delayed_reference``, ``.events``)
/// and its analysis (``.stable``, ``.stability``, ``.robustness``,
/// ``.warnings``; ``.report()`` wants both). Holds the run without its
/// signals and the read-only arrays that have them.
#[pyclass(module = "msp._msp")]
pub(crate) struct PendingAnalysis {
    out: RunOutput,
    t: Py<PyArray1<f64>>,
    r: Py<PyArray1<f64>>,
    y: Py<PyArray1<f64>>,
    u: Py<PyArray1<f64>>,
    measured: bool,
    analysed: bool,
}

impl PendingAnalysis {
    /// The report's `keys`, as ``msp run --report`` writes them.
    fn keys<'py>(&self, py: Python<'py>, keys: &[&str]) -> PyResult<Bound<'py, PyDict>> {
        let report = pythonize::pythonize(py, &self.out.report())?.downcast_into::<PyDict>()?;
        let d = PyDict::new(py);
        for key in keys {
            if let Some(v) = report.get_item(key)? {
                d.set_item(key, v)?;
            }
        }
        Ok(d)
    }

    /// Measures the run once; whether the loop as built came to rest (`RunOutput::settled_as_built`).
    fn ensure_measured(&mut self, py: Python<'_>) -> PyResult<Option<bool>> {
        let (t, r, y, u) = (
            self.t.bind(py).readonly(),
            self.r.bind(py).readonly(),
            self.y.bind(py).readonly(),
            self.u.bind(py).readonly(),
        );
        let cols = msp::study::Columns {
            t: t.as_slice()?,
            r: r.as_slice()?,
            y: y.as_slice()?,
            u: u.as_slice()?,
            substeps: self.out.result.substeps,
            diverged_at: self.out.result.diverged_at,
        };
        if !self.measured {
            let out = &mut self.out;
            py.allow_threads(|| out.measure_from(&cols))
                .map_err(value_err)?;
            self.measured = true;
        }
        Ok(self.out.settled_as_built(cols.t, cols.y))
    }
}

#[pymethods]
impl PendingAnalysis {
    /// ``metrics``, ``metrics_delayed_reference`` and ``events``.
    fn measure<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.ensure_measured(py)?;
        self.keys(py, &["metrics", "metrics_delayed_reference", "events"])
    }

    /// ``stable``, ``stability``, ``robustness`` and ``warnings``.
    fn compute<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let settled = self.ensure_measured(py)?;
        if !self.analysed {
            let out = &mut self.out;
            py.allow_threads(|| out.analyse_settled(settled));
            self.analysed = true;
        }
        self.keys(py, &["stable", "stability", "robustness", "warnings"])
    }
}

/// A run of [`msp::study::Scenario::run_unmeasured`] as a dict: the report
/// and the signals (read-only arrays that take over the run's buffers) now,
/// the figures under ``_analysis``, computed when read.
pub(crate) fn output_dict_deferred<'py>(
    py: Python<'py>,
    mut out: RunOutput,
) -> PyResult<Bound<'py, PyDict>> {
    let d = pythonize::pythonize(py, &out.report())?.downcast_into::<PyDict>()?;
    let mut result = std::mem::take(&mut out.result);
    out.result.substeps = result.substeps;
    out.result.diverged_at = result.diverged_at;
    let column = |v: &mut Vec<f64>| -> PyResult<Bound<'py, PyArray1<f64>>> {
        let a = crate::columns::array(py, std::mem::take(v))?;
        a.call_method1("setflags", (false,))?;
        Ok(a)
    };
    let (t, r, y, u) = (
        column(&mut result.t)?,
        column(&mut result.r)?,
        column(&mut result.y)?,
        column(&mut result.u)?,
    );
    for (k, a) in [("t", &t), ("r", &r), ("y", &y), ("u", &u)] {
        d.set_item(k, a)?;
    }
    signals_into(py, &d, result)?;
    let pending = PendingAnalysis {
        out,
        t: t.unbind(),
        r: r.unbind(),
        y: y.unbind(),
        u: u.unbind(),
        measured: false,
        analysed: false,
    };
    d.set_item("_analysis", Py::new(py, pending)?)?;
    Ok(d)
}

/// The signals of a run into `d`: numpy arrays that take over the run's
/// own buffers (no copy).
fn signals_into<'py>(
    py: Python<'py>,
    d: &Bound<'py, PyDict>,
    r: msp::sim::SimResult,
) -> PyResult<()> {
    let column = |v: Vec<f64>| crate::columns::array(py, v);
    let signals = PyDict::new(py);
    for (name, v) in r.signals {
        signals.set_item(name, column(v)?)?;
    }
    // (a deferred run has set these already, read-only)
    for (k, v) in [("t", r.t), ("r", r.r), ("y", r.y), ("u", r.u)] {
        if !d.contains(k)? {
            d.set_item(k, column(v)?)?;
        }
    }
    if r.u_applied.is_empty() {
        crate::columns::give(r.u_applied);
    } else {
        d.set_item("u_applied", column(r.u_applied)?)?;
    }
    d.set_item("d", column(r.d)?)?;
    d.set_item("d_out", column(r.d_out)?)?;
    if r.y2.is_empty() {
        crate::columns::give(r.y2);
        crate::columns::give(r.d_inner);
    } else {
        let rows = r.y2.len();
        d.set_item("y2", column(r.y2)?)?;
        let d0 = if r.d_inner.is_empty() {
            crate::columns::give(r.d_inner);
            vec![0.0; rows]
        } else {
            r.d_inner
        };
        d.set_item("d_inner", column(d0)?)?;
    }
    d.set_item("signals", signals)?;
    Ok(())
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
pub(crate) const TUNE: &[&str] = Scenario::TUNE_FIELDS;

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
        "quantization" => sc.quantization = Some(v.extract()?),
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
        "adapt" => sc.adapt = adapt_options(v)?,
        "monitor" => sc.monitor = v.extract()?,
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

/// A Python ``adapt`` argument: ``True``/``False`` or a dict of the
/// options (``delay=(min, max)``, ``forgetting``, ``excitation``,
/// ``min_change``, ``prefilter``, ``dead_zone``, ``bound``, ``apply``, ``alarm``,
/// ``background_design``).
pub(crate) fn adapt_options(v: &Bound<'_, PyAny>) -> PyResult<Option<msp::study::AdaptOptions>> {
    if let Ok(on) = v.extract::<bool>() {
        return Ok(on.then(msp::study::AdaptOptions::default));
    }
    let d = v.downcast::<pyo3::types::PyDict>().map_err(|_| {
        PyTypeError::new_err(
            "adapt: True, False or a dict of delay=(min, max), forgetting, excitation, min_change, prefilter, dead_zone, bound, apply, alarm, background_design",
        )
    })?;
    let mut o = msp::study::AdaptOptions::default();
    for (k, x) in d.iter() {
        let k: String = k.extract()?;
        match k.as_str() {
            "delay" => o.delay = Some(x.extract()?),
            "forgetting" => o.forgetting = Some(x.extract()?),
            "excitation" => o.excitation = Some(x.extract()?),
            "min_change" => o.min_change = Some(x.extract()?),
            "prefilter" => o.prefilter = Some(x.extract()?),
            "apply" => o.apply = Some(x.extract()?),
            "dead_zone" => o.dead_zone = Some(x.extract()?),
            "bound" => o.bound = Some(x.extract()?),
            "alarm" => o.alarm = Some(x.extract()?),
            "background_design" => o.background_design = Some(x.extract()?),
            other => {
                return Err(PyValueError::new_err(format!(
                    "adapt: unknown option '{other}' (delay, forgetting, excitation, min_change, prefilter, dead_zone, bound, apply, alarm, background_design)"
                )))
            }
        }
    }
    Ok(Some(o))
}

//! Python bindings: thin conversions around the `msp` library and its registry.

use std::collections::BTreeMap;

use msp::poly::TransferFunction;
use msp::registry::{self, Build, DynController, Params};
use msp::sim::{Disturbance, Location, SetpointStep, Shape};
use msp::study::{Metrics, Perturbation, RunOutput, Scenario};
use msp::{AntiWindup, Pid, PidConfig};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

fn value_err(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A transfer function with dead time `num(s)/den(s)·e^(−delay·s)`.
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
#[pyfunction]
fn parse_plant(expr: &str) -> PyResult<Plant> {
    Ok(Plant {
        inner: msp::syntax::parse_plant(expr).map_err(value_err)?,
    })
}

fn plant_of(obj: &Bound<'_, PyAny>) -> PyResult<TransferFunction> {
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

fn setpoints(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<SetpointStep>> {
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

fn disturbances(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Disturbance>> {
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

fn metrics_dict<'py>(py: Python<'py>, m: &Metrics) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in m.fields() {
        d.set_item(k, v)?;
    }
    Ok(d)
}

fn params_dict<'py>(py: Python<'py>, p: &Params) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in p.iter() {
        d.set_item(k, v)?;
    }
    Ok(d)
}

fn output_dict<'py>(py: Python<'py>, out: RunOutput) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("plant", out.plant.to_string())?;
    d.set_item("model", out.model.to_string())?;
    d.set_item(
        "inner_plant",
        out.inner.as_ref().map(|(p, _)| p.to_string()),
    )?;
    d.set_item(
        "inner_model",
        out.inner.as_ref().map(|(_, m)| m.to_string()),
    )?;
    d.set_item("ts", out.ts)?;
    d.set_item("duration", out.duration)?;
    let c = PyDict::new(py);
    c.set_item("name", out.controller)?;
    c.set_item("params", params_dict(py, &out.params)?)?;
    d.set_item("controller", c)?;
    d.set_item("float32", out.float32)?;
    d.set_item("metrics", metrics_dict(py, &out.metrics)?)?;
    d.set_item(
        "metrics_delayed_reference",
        metrics_dict(py, &out.metrics_delayed_reference)?,
    )?;
    d.set_item("stable", out.result.diverged_at.is_none())?;
    d.set_item("diverged_at", out.result.diverged_at)?;
    let r = out.result;
    let signals = PyDict::new(py);
    for (name, v) in r.signals {
        signals.set_item(name, v.into_pyarray(py))?;
    }
    d.set_item("t", r.t.into_pyarray(py))?;
    d.set_item("r", r.r.into_pyarray(py))?;
    d.set_item("y", r.y.into_pyarray(py))?;
    d.set_item("u", r.u.into_pyarray(py))?;
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

/// The scenario keywords shared by ``run`` and ``compare``.
#[allow(clippy::too_many_arguments)]
fn scenario(
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
    Ok(Scenario {
        plant: String::new(),
        model: None,
        inner_plant: None,
        inner_model: None,
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
    })
}

/// The secondary process and its model of a cascade scenario.
fn inner_of(
    plant: Option<&Bound<'_, PyAny>>,
    model: Option<&Bound<'_, PyAny>>,
) -> PyResult<Option<(TransferFunction, TransferFunction)>> {
    match (plant, model) {
        (None, None) => Ok(None),
        (None, Some(_)) => Err(PyValueError::new_err(
            "inner_model needs inner_plant (the secondary process)",
        )),
        (Some(p), m) => {
            let p2 = plant_of(p)?;
            let m2 = match m {
                Some(m) => plant_of(m)?,
                None => p2.clone(),
            };
            Ok(Some((p2, m2)))
        }
    }
}

/// Simulates the closed loop (see ``msp.run``); returns a dict of arrays and figures.
#[pyfunction]
#[pyo3(signature = (plant, controller=None, params=None, *, model=None, inner_plant=None, inner_model=None,
                    ts=None, duration=None, setpoint=None, disturbance=None, noise=None, seed=None, umin=None,
                    umax=None, lambda_=None, rule=None, substeps=None, float32=false, max_memory=None))]
#[allow(clippy::too_many_arguments)]
fn run<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    controller: Option<String>,
    params: Option<BTreeMap<String, f64>>,
    model: Option<&Bound<'py, PyAny>>,
    inner_plant: Option<&Bound<'py, PyAny>>,
    inner_model: Option<&Bound<'py, PyAny>>,
    ts: Option<f64>,
    duration: Option<f64>,
    setpoint: Option<&Bound<'py, PyAny>>,
    disturbance: Option<&Bound<'py, PyAny>>,
    noise: Option<f64>,
    seed: Option<u64>,
    umin: Option<f64>,
    umax: Option<f64>,
    lambda_: Option<f64>,
    rule: Option<String>,
    substeps: Option<usize>,
    float32: bool,
    max_memory: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let plant_tf = plant_of(plant)?;
    let model_tf = match model {
        Some(m) => plant_of(m)?,
        None => plant_tf.clone(),
    };
    let sc = scenario(
        controller,
        params,
        ts,
        duration,
        setpoint,
        disturbance,
        noise,
        seed,
        umin,
        umax,
        lambda_,
        rule,
        substeps,
        float32,
        max_memory,
    )?;
    let inner = inner_of(inner_plant, inner_model)?;
    let out = py
        .allow_threads(|| sc.run_process(plant_tf, model_tf, inner))
        .map_err(value_err)?;
    output_dict(py, out)
}

/// Runs each controller on the same (perturbed) plant; a list of ``run`` dicts.
#[pyfunction]
#[pyo3(signature = (plant, controllers, *, perturb=None, params=None, model=None, inner_plant=None,
                    inner_model=None, ts=None, duration=None, setpoint=None, disturbance=None, noise=None,
                    seed=None, umin=None, umax=None, lambda_=None, rule=None, substeps=None,
                    float32=false, max_memory=None))]
#[allow(clippy::too_many_arguments)]
fn compare<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    controllers: Vec<String>,
    perturb: Option<&Bound<'py, PyAny>>,
    params: Option<BTreeMap<String, f64>>,
    model: Option<&Bound<'py, PyAny>>,
    inner_plant: Option<&Bound<'py, PyAny>>,
    inner_model: Option<&Bound<'py, PyAny>>,
    ts: Option<f64>,
    duration: Option<f64>,
    setpoint: Option<&Bound<'py, PyAny>>,
    disturbance: Option<&Bound<'py, PyAny>>,
    noise: Option<f64>,
    seed: Option<u64>,
    umin: Option<f64>,
    umax: Option<f64>,
    lambda_: Option<f64>,
    rule: Option<String>,
    substeps: Option<usize>,
    float32: bool,
    max_memory: Option<u64>,
) -> PyResult<Bound<'py, PyList>> {
    let mut sc = scenario(
        None,
        params,
        ts,
        duration,
        setpoint,
        disturbance,
        noise,
        seed,
        umin,
        umax,
        lambda_,
        rule,
        substeps,
        float32,
        max_memory,
    )?;
    sc.plant = plant_of(plant)?.to_string();
    sc.model = model.map(plant_of).transpose()?.map(|m| m.to_string());
    if let Some((p2, m2)) = inner_of(inner_plant, inner_model)? {
        sc.inner_plant = Some(p2.to_string());
        sc.inner_model = Some(m2.to_string());
    }
    let p = perturbation_of(perturb)?.unwrap_or_default();
    let runs = py
        .allow_threads(|| msp::study::compare(&sc, &controllers, p))
        .map_err(value_err)?;
    let out = PyList::empty(py);
    for r in runs {
        out.append(output_dict(py, r)?)?;
    }
    Ok(out)
}

/// A perturbation from ``"delay=20%,tau=-20%"`` or ``{"delay": 0.2, "tau": -0.2}``.
fn perturbation_of(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Perturbation>> {
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

fn margins_dict<'py>(py: Python<'py>, m: &msp::analysis::Margins) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in m.fields() {
        d.set_item(k, v)?;
    }
    Ok(d)
}

/// Margins, stability region and robust-stability test (see ``msp.margins``).
#[pyfunction]
#[pyo3(signature = (plant, controller=None, params=None, *, model=None, inner_plant=None, inner_model=None,
                    ts=None, lambda_=None, rule=None, discrete=false, uncertainty=None, float32=false, max_memory=None))]
#[allow(clippy::too_many_arguments)]
fn margins<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    controller: Option<String>,
    params: Option<BTreeMap<String, f64>>,
    model: Option<&Bound<'py, PyAny>>,
    inner_plant: Option<&Bound<'py, PyAny>>,
    inner_model: Option<&Bound<'py, PyAny>>,
    ts: Option<f64>,
    lambda_: Option<f64>,
    rule: Option<String>,
    discrete: bool,
    uncertainty: Option<&Bound<'py, PyAny>>,
    float32: bool,
    max_memory: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut sc = scenario(
        controller, params, ts, None, None, None, None, None, None, None, lambda_, rule, None,
        float32, max_memory,
    )?;
    sc.plant = plant_of(plant)?.to_string();
    sc.model = model.map(plant_of).transpose()?.map(|m| m.to_string());
    if let Some((p2, m2)) = inner_of(inner_plant, inner_model)? {
        sc.inner_plant = Some(p2.to_string());
        sc.inner_model = Some(m2.to_string());
    }
    let uncertainty = perturbation_of(uncertainty)?;
    let view = if discrete {
        msp::analysis::View::Discrete
    } else {
        msp::analysis::View::Sampled
    };
    let an = py
        .allow_threads(|| msp::analysis::analyze(&sc, view, uncertainty))
        .map_err(value_err)?;
    let d = margins_dict(py, &an.margins)?;
    d.set_item("plant", an.plant.to_string())?;
    d.set_item("model", an.model.to_string())?;
    d.set_item("ts", an.ts)?;
    let c = PyDict::new(py);
    c.set_item("name", an.controller)?;
    c.set_item("params", params_dict(py, &an.params)?)?;
    d.set_item("controller", c)?;
    d.set_item("stable", an.stable)?;
    if let Some(i) = &an.inner {
        d.set_item("inner", margins_dict(py, i)?)?;
    }
    d.set_item("region", an.region.clone())?;
    d.set_item("robust_peak", an.robust_peak)?;
    d.set_item("w", an.response.w.clone().into_pyarray(py))?;
    let l: Vec<f64> = an.response.l.iter().flat_map(|c| [c.re, c.im]).collect();
    let arr = l.into_pyarray(py).reshape([an.response.w.len(), 2])?;
    d.set_item("l", arr)?;
    Ok(d)
}

/// A sweep of plant perturbations (see ``msp.sweep``): a dict of numpy columns.
#[pyfunction]
#[pyo3(signature = (plant, controller=None, params=None, *, gain=(0.0, 0.0), delay=(0.0, 0.0), tau=(0.0, 0.0),
                    grid=11, samples=0, seed=1, shard=(0, 1), model=None, inner_plant=None, inner_model=None,
                    ts=None, duration=None, lambda_=None, rule=None, float32=false, max_memory=None))]
#[allow(clippy::too_many_arguments)]
fn sweep<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    controller: Option<String>,
    params: Option<BTreeMap<String, f64>>,
    gain: (f64, f64),
    delay: (f64, f64),
    tau: (f64, f64),
    grid: usize,
    samples: usize,
    seed: u64,
    shard: (usize, usize),
    model: Option<&Bound<'py, PyAny>>,
    inner_plant: Option<&Bound<'py, PyAny>>,
    inner_model: Option<&Bound<'py, PyAny>>,
    ts: Option<f64>,
    duration: Option<f64>,
    lambda_: Option<f64>,
    rule: Option<String>,
    float32: bool,
    max_memory: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    use msp::sweep::{Range, SweepSpec};
    let range = |(lo, hi): (f64, f64), name: &str| -> PyResult<Range> {
        if lo.is_nan() || hi.is_nan() || lo > hi || lo <= -1.0 {
            return Err(PyValueError::new_err(format!("{name}: need -1 < lo <= hi")));
        }
        Ok(Range { lo, hi })
    };
    let spec = SweepSpec {
        gain: range(gain, "gain")?,
        delay: range(delay, "delay")?,
        tau: range(tau, "tau")?,
        grid,
        samples,
        seed,
        shard,
    };
    let mut sc = scenario(
        controller, params, ts, duration, None, None, None, None, None, None, lambda_, rule, None,
        float32, max_memory,
    )?;
    sc.plant = plant_of(plant)?.to_string();
    sc.model = model.map(plant_of).transpose()?.map(|m| m.to_string());
    if let Some((p2, m2)) = inner_of(inner_plant, inner_model)? {
        sc.inner_plant = Some(p2.to_string());
        sc.inner_model = Some(m2.to_string());
    }
    let rows = py
        .allow_threads(|| msp::sweep::sweep(&sc, &spec, &|_| {}))
        .map_err(value_err)?;
    let col = |f: &dyn Fn(&msp::sweep::SweepRow) -> f64| {
        rows.iter().map(f).collect::<Vec<_>>().into_pyarray(py)
    };
    let d = PyDict::new(py);
    d.set_item(
        "index",
        rows.iter()
            .map(|r| r.index)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item("gain", col(&|r| r.gain))?;
    d.set_item("delay", col(&|r| r.delay))?;
    d.set_item("tau", col(&|r| r.tau))?;
    d.set_item(
        "stable",
        rows.iter()
            .map(|r| r.stable)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    if let Some(first) = rows.first() {
        for (i, (k, _)) in first.metrics.fields().iter().enumerate() {
            let metric = col(&|r| r.metrics.fields().get(i).map_or(f64::NAN, |f| f.1));
            d.set_item(*k, metric)?;
        }
    }
    d.set_item("max_abs_u", col(&|r| r.max_abs_u))?;
    Ok(d)
}

fn fit_dict<'py>(py: Python<'py>, fit: &msp::ident::Fit) -> PyResult<Bound<'py, PyDict>> {
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

/// Relay test, identification, tuning and closed loop (see ``msp.autotune``).
#[pyfunction]
#[pyo3(signature = (plant, *, relay_amplitude=1.0, hysteresis=None, bias=None, noise=0.0, seed=0, model=None,
                    controller=None, ts=None, band=f64::INFINITY, duration=None))]
#[allow(clippy::too_many_arguments)]
fn autotune<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    relay_amplitude: f64,
    hysteresis: Option<f64>,
    bias: Option<f64>,
    noise: f64,
    seed: u64,
    model: Option<String>,
    controller: Option<String>,
    ts: Option<f64>,
    band: f64,
    duration: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let tf = plant_of(plant)?;
    let model = model
        .map(|m| m.parse::<msp::ident::ModelKind>())
        .transpose()
        .map_err(PyValueError::new_err)?;
    let o = msp::ident::AutotuneOptions {
        amplitude: relay_amplitude,
        hysteresis,
        bias,
        noise,
        seed,
        model,
        controller,
        ts,
        band,
    };
    let base = Scenario {
        duration,
        ..Default::default()
    };
    let out = py
        .allow_threads(|| msp::ident::autotune(&tf, &o, &base))
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item("identified", fit_dict(py, &out.fit)?)?;
    let r = &out.result;
    let (ku, tu) = r.ultimate();
    let relay = PyDict::new(py);
    for (k, v) in [
        ("amplitude", r.amplitude),
        ("hysteresis", r.hysteresis),
        ("bias", r.bias),
        ("t_up", r.t_up),
        ("t_down", r.t_down),
        ("period", r.period),
        ("a_max", r.a_max),
        ("a_min", r.a_min),
        ("ku", ku),
        ("tu", tu),
    ] {
        relay.set_item(k, v)?;
    }
    relay.set_item("gain", r.gain())?;
    relay.set_item("cycles", r.cycles)?;
    d.set_item("relay", relay)?;
    d.set_item("run", output_dict(py, out.run)?)?;
    Ok(d)
}

/// Step-test identification from samples (see ``msp.identify``).
#[pyfunction]
#[pyo3(signature = (t, u, y, model="fopdt"))]
fn identify<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    model: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let kind: msp::ident::ModelKind = model.parse().map_err(PyValueError::new_err)?;
    let (t, u, y) = (
        t.as_slice()?.to_vec(),
        u.as_slice()?.to_vec(),
        y.as_slice()?.to_vec(),
    );
    let fit = py
        .allow_threads(|| msp::ident::identify_step(kind, &t, &u, &y))
        .map_err(value_err)?;
    fit_dict(py, &fit)
}

/// Tuned parameters of a controller for a plant: ``{"name": ..., "params": {...}}``,
/// with ``robust_peak`` (Eq. 17) when an ``uncertainty`` is given, as ``msp tune``.
#[pyfunction]
#[pyo3(signature = (plant, controller=None, params=None, *, inner_plant=None, ts=None, lambda_=None,
                    rule=None, uncertainty=None))]
#[allow(clippy::too_many_arguments)]
fn tune<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    controller: Option<String>,
    params: Option<BTreeMap<String, f64>>,
    inner_plant: Option<&Bound<'py, PyAny>>,
    ts: Option<f64>,
    lambda_: Option<f64>,
    rule: Option<String>,
    uncertainty: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let tf = plant_of(plant)?;
    let inner = inner_plant.map(plant_of).transpose()?;
    let mut sc = scenario(
        controller, params, ts, None, None, None, None, None, None, None, lambda_, rule, None,
        false, None,
    )?;
    let (scheme, p) = sc.tune_for(&tf, inner.as_ref()).map_err(value_err)?;
    let d = PyDict::new(py);
    d.set_item("name", scheme.name)?;
    d.set_item("params", params_dict(py, &p)?)?;
    if let Some(u) = perturbation_of(uncertainty)? {
        sc.plant = tf.to_string();
        sc.inner_plant = inner.map(|i| i.to_string());
        sc.controller = Some(scheme.name.to_string());
        let an = py
            .allow_threads(|| msp::analysis::analyze(&sc, msp::analysis::View::Discrete, Some(u)))
            .map_err(value_err)?;
        d.set_item("robust_peak", an.robust_peak)?;
    }
    Ok(d)
}

/// Every controller of the registry: name, aliases, summary, source, params, plants.
#[pyfunction]
fn controllers(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for s in registry::SCHEMES {
        let d = PyDict::new(py);
        d.set_item("name", s.name)?;
        d.set_item("aliases", s.aliases.to_vec())?;
        d.set_item("summary", s.summary)?;
        d.set_item("source", s.source)?;
        d.set_item("params", s.params.to_vec())?;
        d.set_item("cascade", s.is_cascade())?;
        d.set_item(
            "plants",
            s.plants.iter().map(|k| k.to_string()).collect::<Vec<_>>(),
        )?;
        out.append(d)?;
    }
    Ok(out)
}

fn loop_many<'py>(
    py: Python<'py>,
    r: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    mut f: impl FnMut(f64, f64) -> f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (r, y) = (r.as_slice()?, y.as_slice()?);
    if r.len() != y.len() {
        return Err(PyValueError::new_err(format!(
            "r has {} samples but y has {}",
            r.len(),
            y.len()
        )));
    }
    let u: Vec<f64> = r.iter().zip(y).map(|(r, y)| f(*r, *y)).collect();
    Ok(u.into_pyarray(py))
}

/// A per-sample controller of any registered scheme, tuned for a plant.
#[pyclass(subclass, module = "msp._msp")]
pub struct Controller {
    inner: DynController,
    name: &'static str,
    params: Params,
}

#[pymethods]
impl Controller {
    /// Tunes scheme ``name`` for ``plant`` (model), builds it at period ``ts``.
    #[new]
    #[pyo3(signature = (name, plant, ts, params=None, *, inner_plant=None, umin=f64::NEG_INFINITY, umax=f64::INFINITY, lambda_=None, rule=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        name: &str,
        plant: &Bound<'_, PyAny>,
        ts: f64,
        params: Option<BTreeMap<String, f64>>,
        inner_plant: Option<&Bound<'_, PyAny>>,
        umin: f64,
        umax: f64,
        lambda_: Option<f64>,
        rule: Option<String>,
    ) -> PyResult<Self> {
        let tf = plant_of(plant)?;
        let p2 = inner_plant.map(plant_of).transpose()?;
        let scheme = registry::find(name).map_err(value_err)?;
        let overrides: Vec<(String, f64)> = params.unwrap_or_default().into_iter().collect();
        let p = scheme
            .tune_process(&tf, p2.as_ref(), lambda_, rule.as_deref(), &overrides)
            .map_err(value_err)?;
        let inner = scheme
            .build_process(
                &p,
                &tf,
                p2.as_ref(),
                &Build {
                    ts,
                    u_min: umin,
                    u_max: umax,
                },
            )
            .map_err(value_err)?;
        Ok(Controller {
            inner,
            name: scheme.name,
            params: p,
        })
    }
    /// One sample: set point and measurement in, actuator value out; ``y2`` is
    /// the secondary measurement of a cascade (ignored by single-loop schemes).
    #[pyo3(signature = (r, y, y2=None))]
    fn update(&mut self, r: f64, y: f64, y2: Option<f64>) -> f64 {
        match y2 {
            Some(y2) => self.inner.update_cascade(r, y, y2),
            None => self.inner.update(r, y),
        }
    }
    /// ``update`` over arrays of set points and measurements (and secondary
    /// measurements), looped in Rust.
    #[pyo3(signature = (r, y, y2=None))]
    fn update_many<'py>(
        &mut self,
        py: Python<'py>,
        r: PyReadonlyArray1<'py, f64>,
        y: PyReadonlyArray1<'py, f64>,
        y2: Option<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let c = &mut self.inner;
        match y2 {
            None => loop_many(py, r, y, |r, y| c.update(r, y)),
            Some(y2) => {
                let y2 = y2.as_slice()?;
                if y2.len() != y.len()? {
                    return Err(PyValueError::new_err(format!(
                        "y has {} samples but y2 has {}",
                        y.len()?,
                        y2.len()
                    )));
                }
                let mut k = 0usize;
                loop_many(py, r, y, |r, y| {
                    let u = c.update_cascade(r, y, y2.get(k).copied().unwrap_or(f64::NAN));
                    k += 1;
                    u
                })
            }
        }
    }
    /// True for a cascade scheme (pass ``y2`` to ``update``).
    #[getter]
    fn is_cascade(&self) -> bool {
        self.inner.is_cascade()
    }
    /// Zeroes every state.
    fn reset(&mut self) {
        self.inner.reset();
    }
    /// The scheme's name.
    #[getter]
    fn name(&self) -> &'static str {
        self.name
    }
    /// Tuned parameters.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        params_dict(py, &self.params)
    }
    /// Names of the internal signals.
    #[getter]
    fn signal_names(&self) -> Vec<&'static str> {
        self.inner.signal_names().to_vec()
    }
    /// Internal signals after the last update.
    #[getter]
    fn signals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (i, n) in self.inner.signal_names().iter().enumerate() {
            d.set_item(*n, self.inner.signal(i))?;
        }
        Ok(d)
    }
    /// One internal signal by name.
    fn signal(&self, name: &str) -> PyResult<f64> {
        self.inner.signal_by_name(name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "no signal '{name}'; signals: {}",
                self.inner.signal_names().join(", ")
            ))
        })
    }
    /// True when the last update got a non-finite input and held its output.
    #[getter]
    fn fault(&self) -> bool {
        self.inner.fault()
    }
}

/// The industrial PID controller (ISA form ``Kp(1 + 1/(Ti s) + Td s)``).
#[pyclass(module = "msp._msp", name = "Pid")]
pub struct PyPid {
    inner: Pid<f64>,
}

#[pymethods]
impl PyPid {
    #[new]
    #[pyo3(signature = (kp, ti=f64::INFINITY, td=0.0, ts=1.0, *, n=10.0, b=1.0, c=1.0, umin=f64::NEG_INFINITY,
                        umax=f64::INFINITY, anti_windup="back-calculation", tt=None, rate_limit=f64::INFINITY))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        kp: f64,
        ti: f64,
        td: f64,
        ts: f64,
        n: f64,
        b: f64,
        c: f64,
        umin: f64,
        umax: f64,
        anti_windup: &str,
        tt: Option<f64>,
        rate_limit: f64,
    ) -> PyResult<Self> {
        let mut cfg = PidConfig::try_isa(kp, ti, td, ts)
            .map_err(value_err)?
            .with_filter(n)
            .with_weights(b, c)
            .with_limits(umin, umax)
            .with_rate_limit(rate_limit);
        cfg.anti_windup = match (anti_windup, cfg.anti_windup) {
            (_, AntiWindup::None) if ti.is_infinite() => AntiWindup::None,
            ("back-calculation", AntiWindup::BackCalculation { tt: d }) => {
                AntiWindup::BackCalculation {
                    tt: tt.unwrap_or(d),
                }
            }
            ("back-calculation", _) => AntiWindup::BackCalculation {
                tt: tt.unwrap_or(ti),
            },
            ("conditional", _) => AntiWindup::Conditional,
            ("none", _) => AntiWindup::None,
            (o, _) => {
                return Err(PyValueError::new_err(format!(
                    "anti_windup '{o}': use back-calculation, conditional or none"
                )))
            }
        };
        Ok(PyPid {
            inner: Pid::new(cfg).map_err(value_err)?,
        })
    }
    /// One sample.
    fn update(&mut self, r: f64, y: f64) -> f64 {
        self.inner.update(r, y)
    }
    /// One sample with the actuator's real value for the integrator to track.
    fn update_tracking(&mut self, r: f64, y: f64, u_actual: f64) -> f64 {
        self.inner.update_tracking(r, y, u_actual)
    }
    /// ``update`` over arrays, looped in Rust.
    fn update_many<'py>(
        &mut self,
        py: Python<'py>,
        r: PyReadonlyArray1<'py, f64>,
        y: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let c = &mut self.inner;
        loop_many(py, r, y, |r, y| c.update(r, y))
    }
    /// Zeroes the state, back to auto mode.
    fn reset(&mut self) {
        self.inner.reset();
    }
    /// Manual mode holding the last output.
    fn set_manual(&mut self) {
        self.inner.set_manual();
    }
    /// Manual output value.
    fn set_manual_output(&mut self, u: f64) -> PyResult<()> {
        self.inner.set_manual_output(u).map_err(value_err)
    }
    /// Back to auto mode (bumpless).
    fn set_auto(&mut self) {
        self.inner.set_auto();
    }
    /// Proportional term of the last update.
    #[getter]
    fn p(&self) -> f64 {
        self.inner.terms().p
    }
    /// Integral term of the last update.
    #[getter]
    fn i(&self) -> f64 {
        self.inner.terms().i
    }
    /// Derivative term of the last update.
    #[getter]
    fn d(&self) -> f64 {
        self.inner.terms().d
    }
    /// Last output.
    #[getter]
    fn output(&self) -> f64 {
        self.inner.output()
    }
    /// True when the last update got a non-finite input.
    #[getter]
    fn fault(&self) -> bool {
        self.inner.fault()
    }
    /// Parameters ``kp``, ``ti``, ``td``.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.inner.config();
        let d = PyDict::new(py);
        d.set_item("kp", c.kp)?;
        d.set_item("ti", c.ti())?;
        d.set_item("td", c.td())?;
        Ok(d)
    }
}

/// The compiled part of the ``msp`` package.
#[pymodule]
fn _msp(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Plant>()?;
    m.add_class::<Controller>()?;
    m.add_class::<PyPid>()?;
    m.add_function(wrap_pyfunction!(parse_plant, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(tune, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(margins, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(autotune, m)?)?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(controllers, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // the scenario's fields as the library defines them (tests check the keyword arguments)
    m.add("SCENARIO_FIELDS", msp::study::Scenario::FIELDS.to_vec())?;
    Ok(())
}

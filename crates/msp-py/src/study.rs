//! The study functions: run, compare, margins, sweep, autotune, identify, tune, controllers.

use crate::convert::{
    fit_dict, output_dict, output_dict_deferred, perturbation_of, scenario_from, Takes, TUNE,
};
use crate::plant::plant_of;
use crate::value_err;
use msp::registry;
use msp::study::Scenario;
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// Simulates the closed loop (see ``msp.run``); returns a dict of arrays and
/// figures. The keywords are the scenario's fields ([`scenario_from`]).
#[pyfunction]
#[pyo3(signature = (plant, **scenario))]
pub(crate) fn run<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    scenario: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = scenario_from(plant, scenario, Takes::All)?;
    run_scenario(py, &sc)
}

/// The scenario run (its measures deferred until read), in a dict.
fn run_scenario<'py>(py: Python<'py>, sc: &msp::study::Scenario) -> PyResult<Bound<'py, PyDict>> {
    crate::columns::lend();
    let out = py
        .allow_threads(|| sc.run_unmeasured())
        .map_err(value_err)?;
    output_dict_deferred(py, out)
}

/// The forced response (see ``msp.simulate``): ``run`` with the set point
/// and loads given as sampled arrays.
#[pyfunction]
#[pyo3(signature = (plant, t, r, d, d_out, **scenario))]
pub(crate) fn simulate<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    r: PyReadonlyArray1<'py, f64>,
    d: Option<PyReadonlyArray1<'py, f64>>,
    d_out: Option<PyReadonlyArray1<'py, f64>>,
    scenario: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = scenario_from(plant, scenario, Takes::All)?;
    let input = msp::study::SampledInput {
        t: t.as_slice()?,
        r: r.as_slice()?,
        d: match &d {
            Some(a) => a.as_slice()?,
            None => &[],
        },
        d_out: match &d_out {
            Some(a) => a.as_slice()?,
            None => &[],
        },
    };
    let sc = sc.with_input(input).map_err(value_err)?;
    run_scenario(py, &sc)
}

/// Runs each controller on the same (perturbed) plant; a list of ``run`` dicts.
#[pyfunction]
#[pyo3(signature = (plant, controllers, *, perturb=None, **scenario))]
pub(crate) fn compare<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    controllers: Vec<String>,
    perturb: Option<&Bound<'py, PyAny>>,
    scenario: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyList>> {
    let sc = scenario_from(plant, scenario, Takes::All)?;
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

/// Margins, stability region and robust-stability test (see ``msp.margins``).
#[pyfunction]
#[pyo3(signature = (plant, *, discrete=false, continuous=false, uncertainty=None, **scenario))]
pub(crate) fn margins<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    discrete: bool,
    continuous: bool,
    uncertainty: Option<&Bound<'py, PyAny>>,
    scenario: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = scenario_from(plant, scenario, Takes::Design(&[]))?;
    let uncertainty = perturbation_of(uncertainty)?;
    let view = match (discrete, continuous) {
        (true, true) => {
            return Err(PyValueError::new_err(
                "discrete and continuous are two views of the plant: give one",
            ))
        }
        (true, false) => msp::analysis::View::Discrete,
        (false, true) => msp::analysis::View::Continuous,
        (false, false) => msp::analysis::View::Sampled,
    };
    let an = py
        .allow_threads(|| msp::study::analyze(&sc, view, uncertainty))
        .map_err(value_err)?;
    // the library's report (the keys of `msp margins --json`), its loop
    // response as numpy arrays
    let mut report = an.report();
    let (w, l, phase) = (
        std::mem::take(&mut report.w),
        std::mem::take(&mut report.l),
        std::mem::take(&mut report.phase_unwrapped),
    );
    let d = pythonize::pythonize(py, &report)?.downcast_into::<PyDict>()?;
    let n = w.len();
    d.set_item("w", w.into_pyarray(py))?;
    let flat: Vec<f64> = l.into_iter().flatten().collect();
    d.set_item("l", flat.into_pyarray(py).reshape([n, 2])?)?;
    d.set_item("phase_unwrapped", phase.into_pyarray(py))?;
    Ok(d)
}

/// A sweep of plant perturbations (see ``msp.sweep``): a dict of numpy
/// columns. ``seed`` is the sampling's (a sweep adds no noise).
#[pyfunction]
#[pyo3(signature = (plant, *, gain=(0.0, 0.0), delay=(0.0, 0.0), tau=(0.0, 0.0), grid=11, samples=0, seed=1,
                    shard=(0, 1), **scenario))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn sweep<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    gain: (f64, f64),
    delay: (f64, f64),
    tau: (f64, f64),
    grid: usize,
    samples: usize,
    seed: u64,
    shard: (usize, usize),
    scenario: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    use msp::sweep::{Range, SweepSpec};
    let range = |(lo, hi): (f64, f64), name: &str| -> PyResult<Range> {
        Range::new(lo, hi).map_err(|why| PyValueError::new_err(format!("{name}: {why}")))
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
    let sc = scenario_from(plant, scenario, Takes::Design(&["duration"]))?;
    let rows = py
        .allow_threads(|| msp::sweep::sweep(&sc, &spec, &|_| {}))
        .map_err(value_err)?;
    let col = |f: &dyn Fn(&msp::sweep::SweepRow) -> f64| {
        rows.iter().map(f).collect::<Vec<_>>().into_pyarray(py)
    };
    let d = PyDict::new(py);
    let index: Vec<usize> = rows.iter().map(|r| r.index).collect();
    let stable: Vec<bool> = rows.iter().map(|r| r.stable).collect();
    d.set_item("index", index.into_pyarray(py))?;
    d.set_item("gain", col(&|r| r.gain))?;
    d.set_item("delay", col(&|r| r.delay))?;
    d.set_item("tau", col(&|r| r.tau))?;
    d.set_item("stable", stable.into_pyarray(py))?;
    if let Some(first) = rows.first() {
        for (i, (k, _)) in first.metrics.fields().enumerate() {
            let metric = col(&|r| r.metrics.fields().nth(i).map_or(f64::NAN, |f| f.1));
            d.set_item(k, metric)?;
        }
    }
    d.set_item("max_abs_u", col(&|r| r.max_abs_u))?;
    Ok(d)
}

/// Relay test, identification, tuning and closed loop (see ``msp.autotune``).
#[pyfunction]
#[pyo3(signature = (plant, *, relay_amplitude=1.0, hysteresis=None, bias=None, noise=0.0, seed=0, model=None,
                    controller=None, ts=None, band=f64::INFINITY, duration=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn autotune<'py>(
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
        .map_err(|e| match e {
            // the experiment itself stopped: a run-time failure, not a bad argument
            msp::ident::AutotuneError::Aborted(_) => PyRuntimeError::new_err(e.to_string()),
            _ => PyValueError::new_err(e.to_string()),
        })?;
    let d = PyDict::new(py);
    d.set_item("identified", fit_dict(py, &out.fit)?)?;
    // the library's report: the keys of `msp autotune --report`
    d.set_item("relay", pythonize::pythonize(py, &out.relay_report())?)?;
    d.set_item("run", output_dict(py, out.run)?)?;
    Ok(d)
}

/// The plant's own unit step response and step information (see ``msp.step``).
#[pyfunction]
#[pyo3(signature = (plant, *, ts=None, duration=None))]
pub(crate) fn step<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    ts: Option<f64>,
    duration: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let plant = plant_of(plant)?;
    let s = py
        .allow_threads(|| msp::analysis::step_response(&plant, ts, duration))
        .map_err(value_err)?;
    let d = pythonize::pythonize(py, &s)?.downcast_into::<PyDict>()?;
    d.set_item("t", s.t.into_pyarray(py))?;
    d.set_item("y", s.y.into_pyarray(py))?;
    Ok(d)
}

/// Step-test identification from samples (see ``msp.identify``).
#[pyfunction]
#[pyo3(signature = (t, u, y, model="fopdt"))]
pub(crate) fn identify<'py>(
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

/// Every scheme's λ swept: robustness against performance (see ``msp.tradeoff``).
#[pyfunction]
#[pyo3(signature = (plant, controllers, **scenario))]
pub(crate) fn tradeoff<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    controllers: Vec<String>,
    scenario: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = scenario_from(plant, scenario, Takes::Only(&["model", "ts"]))?;
    let t = py
        .allow_threads(|| msp::study::tradeoff(&sc, &controllers, &|_, _| {}))
        .map_err(value_err)?;
    Ok(pythonize::pythonize(py, &t)?.downcast_into::<PyDict>()?)
}

/// MATLAB's ``stepinfo`` of recorded data (see ``msp.step_info``).
#[pyfunction]
#[pyo3(signature = (t, y, yinit, yfinal, settling_threshold, rise_limits))]
pub(crate) fn step_info<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    yinit: Option<f64>,
    yfinal: Option<f64>,
    settling_threshold: f64,
    rise_limits: (f64, f64),
) -> PyResult<Bound<'py, PyDict>> {
    let opts = msp::metrics::StepInfoOptions {
        settling_threshold,
        rise_limits,
    };
    let s = msp::metrics::step_info_of_data(t.as_slice()?, y.as_slice()?, yinit, yfinal, opts)
        .map_err(value_err)?;
    Ok(pythonize::pythonize(py, &s)?.downcast_into::<PyDict>()?)
}

/// Tuned parameters of a controller for a plant: ``{"name": ..., "params": {...}}``,
/// with ``robust_peak`` (Eq. 17) when an ``uncertainty`` is given, as ``msp tune``.
#[pyfunction]
#[pyo3(signature = (plant, *, uncertainty=None, **scenario))]
pub(crate) fn tune<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    uncertainty: Option<&Bound<'py, PyAny>>,
    scenario: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = scenario_from(plant, scenario, Takes::Only(TUNE))?;
    let unc = perturbation_of(uncertainty)?;
    let r = py
        .allow_threads(|| sc.tune_report(unc))
        .map_err(value_err)?;
    // the library's report: the keys of `msp tune --json`
    Ok(pythonize::pythonize(py, &r)?.downcast_into::<PyDict>()?)
}

/// The multivariable report of ``msp tune --plant "[…]" --json``: the RGA,
/// the pairing, the Niederlinski index, the design of ``controller``
/// (``pi``, ``smith``, ``decoupled``), the sampled loop's verdict and Lcm.
#[pyfunction]
#[pyo3(signature = (plant, controller=None, rule=None, ts=None))]
pub(crate) fn tune_matrix<'py>(
    py: Python<'py>,
    plant: &str,
    controller: Option<String>,
    rule: Option<String>,
    ts: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let m: msp::poly::TransferMatrix = plant.parse().map_err(value_err)?;
    let scheme = controller.as_deref().unwrap_or("pi");
    let r = py
        .allow_threads(|| msp::study::mimo::report(&m, scheme, rule.as_deref(), ts))
        .map_err(value_err)?;
    Ok(pythonize::pythonize(py, &r)?.downcast_into::<PyDict>()?)
}

/// A matrix plant's run (``msp run --plant "[…]"``): the report (the JSON
/// of ``--report``) and the columns ``t`` and per loop ``r``, ``y``, ``u``.
#[pyfunction]
#[pyo3(signature = (plant, controller=None, rule=None, ts=None, duration=None, loop_setpoint=Vec::new(), loop_disturbance=Vec::new(), disturbance_plant=None, disturbance_step=Vec::new(), channel_dead_time=Vec::new(), loop_event=Vec::new(), noise=0.0, seed=0, actuator=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub(crate) fn run_matrix<'py>(
    py: Python<'py>,
    plant: &str,
    controller: Option<String>,
    rule: Option<String>,
    ts: Option<f64>,
    duration: Option<f64>,
    loop_setpoint: Vec<String>,
    loop_disturbance: Vec<String>,
    disturbance_plant: Option<String>,
    disturbance_step: Vec<String>,
    channel_dead_time: Vec<String>,
    loop_event: Vec<String>,
    noise: f64,
    seed: u64,
    actuator: Option<(f64, f64)>,
) -> PyResult<(
    Bound<'py, PyDict>,
    Bound<'py, numpy::PyArray1<f64>>,
    Vec<[Bound<'py, numpy::PyArray1<f64>>; 3]>,
)> {
    let m: msp::poly::TransferMatrix = plant.parse().map_err(value_err)?;
    let n = m.size();
    let mut setpoints = vec![Vec::new(); n];
    for s in &loop_setpoint {
        let (l, step) = msp::syntax::parse_loop_setpoint(s).map_err(value_err)?;
        setpoints
            .get_mut(l)
            .ok_or_else(|| value_err(format!("loop_setpoint {s}: the plant has {n} loops")))?
            .push(step);
    }
    let parse_all = |v: &[String]| -> PyResult<Vec<msp::sim::SetpointStep>> {
        v.iter().map(|s| s.parse().map_err(value_err)).collect()
    };
    let disturbance = match disturbance_plant {
        Some(d) => Some(msp::sim::DisturbanceVector {
            channels: msp::syntax::parse_column(&d).map_err(value_err)?,
            steps: parse_all(&disturbance_step)?,
        }),
        None if disturbance_step.is_empty() => None,
        None => return Err(value_err(
            "disturbance_step needs disturbance_plant (the disturbance's channel to each output)",
        )),
    };
    let sc = msp::study::MimoScenario {
        plant: m,
        controller,
        rule,
        ts,
        duration,
        setpoints,
        events: msp::sim::MimoEvents {
            loads: loop_disturbance
                .iter()
                .map(|s| s.parse().map_err(value_err))
                .collect::<PyResult<_>>()?,
            disturbance,
            dead_times: channel_dead_time
                .iter()
                .map(|s| s.parse().map_err(value_err))
                .collect::<PyResult<_>>()?,
            modes: loop_event
                .iter()
                .map(|s| s.parse().map_err(value_err))
                .collect::<PyResult<_>>()?,
            noise,
            seed,
            actuator,
        },
    };
    let mut out = py.allow_threads(|| sc.run()).map_err(value_err)?;
    let report = pythonize::pythonize(py, &out)?.downcast_into::<PyDict>()?;
    let run = std::mem::take(&mut out.run);
    let mut loops = Vec::with_capacity(n);
    for ((r, y), u) in run.r.into_iter().zip(run.y).zip(run.u) {
        loops.push([
            crate::columns::array(py, r)?,
            crate::columns::array(py, y)?,
            crate::columns::array(py, u)?,
        ]);
    }
    Ok((report, crate::columns::array(py, run.t)?, loops))
}

/// Every PI/PID tuning rule applied to the plant with the loop each gives, as
/// ``msp tune --rules --json`` prints its ``rules``.
#[pyfunction]
#[pyo3(signature = (plant, **scenario))]
pub(crate) fn tune_rules<'py>(
    py: Python<'py>,
    plant: &Bound<'py, PyAny>,
    scenario: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let sc = scenario_from(plant, scenario, Takes::Only(TUNE))?;
    let rows = py.allow_threads(|| sc.rules_report()).map_err(value_err)?;
    Ok(pythonize::pythonize(py, &rows)?)
}

/// Every controller of the registry, as ``msp list`` prints them.
///
/// Returns
/// -------
/// list of dict
///     ``{"name", "aliases", "summary", "source", "params", "design", "cascade", "plants"}``
///     per scheme: its tuned parameters, the design keys read before tuning, and the plant
///     kinds it controls.
///
/// Examples
/// --------
/// >>> from msp import controllers
/// >>> smith = next(c for c in controllers() if c["name"] == "smith")
/// >>> smith["params"][:3], "stable" in smith["plants"]
/// (['kp', 'ti', 'td'], True)
#[pyfunction]
pub(crate) fn controllers(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for s in registry::SCHEMES {
        let d = PyDict::new(py);
        d.set_item("name", s.name)?;
        d.set_item("aliases", s.aliases.to_vec())?;
        d.set_item("summary", s.summary)?;
        d.set_item("source", s.source)?;
        d.set_item("params", s.params.to_vec())?;
        d.set_item("design", s.design.to_vec())?;
        d.set_item("cascade", s.is_cascade())?;
        d.set_item(
            "plants",
            s.plants.iter().map(|k| k.to_string()).collect::<Vec<_>>(),
        )?;
        out.append(d)?;
    }
    Ok(out)
}

//! Per-sample controller objects: any registry scheme, and the PID.

use std::collections::BTreeMap;

use crate::convert::params_dict;
use crate::plant::plant_of;
use crate::value_err;
use msp::registry::{self, Build, DynController, Params};
use msp::{AntiWindup, CascadeControl, Controller as _, Introspect, Operated, Pid, PidConfig};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

mod pid;
pub use pid::PyPid;

pub(crate) fn loop_many<'py>(
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
///
/// Parameters
/// ----------
/// name : str
///     The scheme (``msp.controllers()``).
/// plant : str or Plant
///     The model the scheme is tuned for and holds.
/// ts : float
///     The sample period (s).
/// params : dict, optional
///     Overrides of tuned parameters or design values by name.
/// inner_plant : str or Plant, optional
///     A cascade's secondary process.
/// umin, umax : float, optional
///     The actuator's limits.
/// lambda_ : float, optional
///     The tuning rule's closed-loop time constant (s).
/// rule : str, optional
///     A named tuning rule for ``pid``/``pi``.
/// max_dead_time : float, optional
///     The longest dead time (s) ``set_dead_time`` may give the model later
///     (the delay line's room; default the model's own).
/// adapt : bool or dict, optional
///     Adaptive dead-time compensation (``msp run --adapt``; a FOPDT or IPDT
///     model, the ``smith`` scheme): ``estimate`` gives the estimate and the
///     model in use, ``freeze()``/``resume()`` stop and restart adapting; a
///     dict of options as ``msp.run``'s ``adapt`` (``{"apply": False}``: the
///     model-error monitor alone, its alarm in ``estimate["alarm"]``).
///
/// The controller is operated as in a plant: ``manual(u)``, ``track(u)`` and
/// ``auto()`` (bumpless), ``update(r, y, u_applied=...)`` (external reset),
/// ``set_dead_time``/``ramp_dead_time``, ``retune(kp=...)`` and
/// ``set_setpoint_ramp``.
///
/// Examples
/// --------
/// >>> from msp import Controller
/// >>> c = Controller("smith", "5.6*e^-93.9s/(40.2s+1)", 1.0)
/// >>> c.name, round(c.update(1.0, 0.0), 4)
/// ('smith', 0.0764)
#[pyclass(subclass, module = "msp._msp")]
pub struct Controller {
    inner: Operated<f64, DynController>,
    name: &'static str,
    params: Params,
    ts: f64,
    /// The plant tuned for (the loop of `to_control`), for a single loop.
    plant: Option<msp::poly::TransferFunction>,
}

#[pymethods]
impl Controller {
    /// Tunes scheme ``name`` for ``plant`` (model), builds it at period ``ts``.
    #[new]
    #[pyo3(signature = (name, plant, ts, params=None, *, inner_plant=None, umin=f64::NEG_INFINITY, umax=f64::INFINITY, lambda_=None, rule=None, max_dead_time=0.0, adapt=None))]
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
        max_dead_time: f64,
        adapt: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let tf = plant_of(plant)?;
        if let Some(opts) = adapt
            .map(crate::convert::adapt_options)
            .transpose()?
            .flatten()
        {
            // the scenario's construction: tuned, built, wrapped for adaptation
            let sc = msp::study::Scenario {
                plant: Some(tf.clone()),
                controller: Some(name.to_string()),
                ts: Some(ts),
                lambda: lambda_,
                rule,
                set: params.unwrap_or_default(),
                umin: umin.is_finite().then_some(umin),
                umax: umax.is_finite().then_some(umax),
                adapt: Some(opts),
                ..Default::default()
            };
            if inner_plant.is_some() {
                return Err(PyValueError::new_err(
                    "adaptation is for a single loop (not a cascade process)",
                ));
            }
            let built = sc
                .build_controller(&tf)
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            // what the build could not do as asked, as Python warns
            let py = plant.py();
            for note in &built.notes {
                let text = std::ffi::CString::new(note.as_str()).unwrap_or_default();
                let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
                PyErr::warn(py, &category, &text, 1)?;
            }
            return Ok(Controller {
                inner: Operated::new(built.controller),
                name: built.scheme,
                params: built.params,
                ts,
                plant: Some(tf),
            });
        }
        let p2 = inner_plant.map(plant_of).transpose()?;
        // the delay lines, checked against the budget before anything is taken
        let delay = tf.delay + p2.as_ref().map_or(0.0, |p| p.delay);
        msp::study::check_controller_memory(delay, max_dead_time, ts, None)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
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
                    max_dead_time,
                },
            )
            .map_err(value_err)?;
        Ok(Controller {
            inner: Operated::new(inner),
            name: scheme.name,
            params: p,
            ts,
            plant: if p2.is_none() { Some(tf) } else { None },
        })
    }
    /// The controller's linear parts and its loop as python-control systems.
    ///
    /// Parameters
    /// ----------
    /// plant : str or Plant, optional
    ///     The process of the loop (default: the plant the controller was
    ///     tuned for; a cascade's loop runs through its inner loop and is not
    ///     given).
    ///
    /// Returns
    /// -------
    /// dict
    ///     ``control.TransferFunction`` objects, discrete at ``ts``: ``"cr"`` and
    ///     ``"cy"`` (``u = Cr·r − Cy·y``, limits inactive) and, for a single loop,
    ///     ``"plant"`` (sampled exactly: ZOH, the dead time as powers of ``z⁻¹``),
    ///     ``"L"`` (``Cy·P``), ``"S"`` and ``"T"``. The same coefficients as
    ///     ``msp tune --json``'s ``transfer``.
    ///
    /// Examples
    /// --------
    /// >>> import control, msp
    /// >>> c = msp.Controller("smith", "e^-0.5s/(s+1)", 0.1)
    /// >>> sys = c.to_control()
    /// >>> gm, pm, wcg, wcp = control.margin(sys["L"])
    /// >>> m = msp.margins("e^-0.5s/(s+1)", "smith", ts=0.1, discrete=True)
    /// >>> abs(float(pm) - m["pm"]) < 1e-6
    /// True
    #[pyo3(signature = (plant=None))]
    fn to_control<'py>(
        &self,
        py: Python<'py>,
        plant: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let plant = match plant {
            Some(p) => Some(plant_of(p)?),
            None => self.plant.clone(),
        };
        let t = msp::analysis::transfer(&**self.inner.inner(), plant.as_ref(), self.ts)
            .map_err(value_err)?
            .ok_or_else(|| {
                PyValueError::new_err(format!("{} gives no transfer function", self.name))
            })?;
        let control = py.import("control")?;
        let tf = control.getattr("TransferFunction")?;
        let out = PyDict::new(py);
        let put = |k: &str, c: &msp::analysis::Coefficients| -> PyResult<()> {
            out.set_item(k, tf.call1((c.num.clone(), c.den.clone(), self.ts))?)
        };
        put("cr", &t.cr)?;
        put("cy", &t.cy)?;
        for (k, c) in [("plant", &t.plant), ("L", &t.l), ("S", &t.s), ("T", &t.t)] {
            if let Some(c) = c {
                put(k, c)?;
            }
        }
        Ok(out)
    }
    /// What an adaptive controller (``adapt=``) knows now, a dict under the
    /// names of its recorded signals (the library's ``AdaptiveState``, as C's
    /// ``msp_adaptive_read`` gives it): the estimate ``k_hat``, ``tau_hat``,
    /// ``theta_hat`` (NaN before it means anything) and the ``evidence`` for
    /// its dead time over the candidates that cannot be the same (small:
    /// ambiguous; as :class:`Estimator`'s), the model in use ``k_model``,
    /// ``tau_model``, ``theta_model``, the changes logged ``adapt_changes``
    /// and the last one's kind ``adapt_kind`` (0: none), the model's error
    /// against the process ``mismatch`` (0.3: 30 %; NaN before it means
    /// anything), the alarm ``model_alarm`` (bool), the estimator's counts
    /// ``onsets``, ``restarts`` and ``learnt`` (``learnt`` 0: nothing has
    /// moved the loop enough to identify the process), the responses (a load's, a set-point change's)
    /// the level test compared ``responses``, took as evidence
    /// ``responses_used`` and found a ramp load's ``responses_ramps`` (while
    /// they outnumber the ones taken since the model in use was set, it
    /// holds back), and ``frozen``;
    /// ``None`` for one that does not adapt.
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        use msp::Operate;
        let Some(state) = self.inner.inner().adaptive_state() else {
            return Ok(None);
        };
        Ok(Some(
            pythonize::pythonize(py, &state)?.downcast_into::<PyDict>()?,
        ))
    }
    /// The changes an adaptive controller logged (the last 16), oldest
    /// first: dicts of ``sample`` (from the first update), ``at`` (s),
    /// ``kind`` (``"applied"``, ``"restored"``, ``"refused"``, ``"alarm"``,
    /// ``"cleared"``, as the report's ``adaptation``) and the model ``k``,
    /// ``tau``, ``theta``; empty for one that does not adapt.
    #[getter]
    fn log<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        use msp::Operate;
        let mut changes = Vec::new();
        self.inner.inner().visit_log(&mut |c| changes.push(c));
        changes
            .into_iter()
            .map(|c| {
                // the library's serde type: the names the report writes
                let d = pythonize::pythonize(py, &c)?.downcast_into::<PyDict>()?;
                d.set_item("at", c.sample as f64 * self.ts)?;
                Ok(d)
            })
            .collect()
    }
    /// Freezes an adaptive controller's adaptation: it learns and applies
    /// nothing until ``resume()``.
    fn freeze(&mut self) -> PyResult<()> {
        self.inner
            .inner_mut()
            .set_adapting(false)
            .map_err(value_err)
    }
    /// Resumes an adaptive controller's adaptation.
    fn resume(&mut self) -> PyResult<()> {
        self.inner.inner_mut().set_adapting(true).map_err(value_err)
    }
    /// Designs the scheme a new model waits for, as a device's background
    /// task does between samples (``adapt={"background_design": True}``:
    /// a Karan–Dey or filtered Smith predictor, rebuilt for each model,
    /// is then not designed in the ``update`` that applies the model);
    /// whether one was. False for a controller with nothing waiting.
    fn design(&mut self) -> bool {
        use msp::Operate;
        self.inner.inner_mut().design()
    }
    /// One sample: set point and measurement in, actuator value out; ``y2`` is
    /// the secondary measurement of a cascade (ignored by single-loop schemes);
    /// ``u_applied`` is what the actuator really applied for the last output
    /// (external reset: the controller follows it, no windup against a limit
    /// it does not own).
    #[pyo3(signature = (r, y, y2=None, u_applied=None))]
    fn update(&mut self, r: f64, y: f64, y2: Option<f64>, u_applied: Option<f64>) -> f64 {
        self.inner.feed_back(u_applied);
        match y2 {
            Some(y2) => self.inner.update_cascade(r, y, y2),
            None => self.inner.update(r, y),
        }
    }
    /// Manual mode: the output is ``u``; the controller's model and
    /// integrators follow it, so that ``auto()`` is bumpless.
    fn manual(&mut self, u: f64) -> PyResult<()> {
        self.inner.manual(u).map_err(value_err)
    }
    /// Tracking mode: the output follows ``u`` (call again as it changes).
    fn track(&mut self, u: f64) -> PyResult<()> {
        self.inner.track(u).map_err(value_err)
    }
    /// Automatic mode (bumpless from manual or tracking).
    fn auto(&mut self) {
        self.inner.auto();
    }
    /// The mode: ``"auto"``, ``"manual"`` or ``"track"``.
    #[getter]
    fn mode(&self) -> &'static str {
        match self.inner.mode() {
            msp::operate::Mode::Auto => "auto",
            msp::operate::Mode::Manual(_) => "manual",
            msp::operate::Mode::Track(_) => "track",
        }
    }
    /// Gives the controller's model the dead time ``theta`` (s), within the
    /// ``max_dead_time`` it was built with (for a cascade scheme the dead time
    /// from the plant input to ``y``). The predictor schemes (``fsp``,
    /// ``fspcc``, ``gpcc``) are redesigned for it and take whole samples;
    /// ``pid`` and ``pi`` have no model dead time and raise ``ValueError``.
    fn set_dead_time(&mut self, theta: f64) -> PyResult<()> {
        if !(theta.is_finite() && theta >= 0.0) {
            return Err(PyValueError::new_err(
                "`theta` must be a finite time of at least 0",
            ));
        }
        self.inner.set_dead_time(theta / self.ts).map_err(value_err)
    }
    /// Changes gains of the primary PID while running, bumpless (``kp``,
    /// ``ti``, ``td`` by name): the output does not jump at the change.
    #[pyo3(signature = (**params))]
    fn retune(&mut self, params: Option<BTreeMap<String, f64>>) -> PyResult<()> {
        use msp::operate::Gain;
        for (name, v) in params.unwrap_or_default() {
            let gain = match name.as_str() {
                "kp" => Gain::Kp,
                "ti" => Gain::Ti,
                "td" => Gain::Td,
                other => {
                    return Err(PyValueError::new_err(format!(
                        "retune: '{other}' is not a gain that changes online (kp, ti, td)"
                    )))
                }
            };
            msp::Operate::retune(&mut self.inner, gain, v).map_err(value_err)?;
            self.params.set(&name, v);
        }
        Ok(())
    }
    /// Moves the model's dead time to ``theta`` (s) at ``rate`` seconds per
    /// second (a delay that drifts: no jump of the prediction). The
    /// predictor schemes (``fsp``, ``fspcc``, ``gpcc``) are redesigned for
    /// whole samples: their dead time moves one sample at a time, at that
    /// mean rate.
    fn ramp_dead_time(&mut self, theta: f64, rate: f64) -> PyResult<()> {
        if !(theta.is_finite() && theta >= 0.0) {
            return Err(PyValueError::new_err(
                "`theta` must be a finite time of at least 0",
            ));
        }
        msp::Operate::ramp_dead_time(&mut self.inner, theta / self.ts, rate).map_err(value_err)
    }
    /// Limits the set point's change to ``rate`` per second (``inf``: off).
    fn set_setpoint_ramp(&mut self, rate: f64) -> PyResult<()> {
        self.inner
            .set_setpoint_ramp(rate, self.ts)
            .map_err(value_err)
    }
    /// The model's dead time (s), or None for a scheme without one.
    #[getter]
    fn dead_time(&self) -> Option<f64> {
        msp::Operate::dead_time(&self.inner).map(|d| d * self.ts)
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
            None => loop_many(py, r, y, |r, y| msp::Controller::update(c, r, y)),
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
        self.inner.inner().is_cascade()
    }
    /// Zeroes every state; the next update takes its sample as a PID's
    /// derivative reference (no kick: started on a running process).
    fn reset(&mut self) {
        self.inner.reset();
    }
    /// Zeroes every state with the loop at rest before the next update
    /// (every signal zero): the controller is then the transfer functions
    /// of :meth:`to_control` from rest, sample for sample, a PID's
    /// derivative kick on a first-sample step included — as
    /// :func:`simulate` starts every loop.
    fn reset_to_rest(&mut self) {
        self.inner.reset_to_rest();
    }
    /// The scheme's name.
    #[getter]
    fn name(&self) -> &'static str {
        self.name
    }
    /// The sample period (s).
    #[getter]
    fn ts(&self) -> f64 {
        self.ts
    }
    /// `<msp.SmithPredictor smith: kp=0.0764 ti=40.2 td=0 lambda=93.9, ts=1 s>`.
    fn __repr__(slf: &Bound<'_, Self>) -> PyResult<String> {
        let class = slf.get_type().name()?.to_string();
        let c = slf.borrow();
        let params: Vec<String> = c
            .params
            .iter()
            .map(|(k, v)| format!("{k}={}", msp::poly::fmt_num(msp::poly::round_sig(v, 4))))
            .collect();
        Ok(format!(
            "<msp.{class} {}: {}, ts={} s>",
            c.name,
            params.join(" "),
            msp::poly::fmt_num(c.ts)
        ))
    }
    /// Tuned parameters.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        params_dict(py, &self.params)
    }
    /// Names of the internal signals.
    #[getter]
    fn signal_names(&self) -> Vec<&'static str> {
        self.inner.inner().signal_names().to_vec()
    }
    /// Internal signals after the last update.
    #[getter]
    fn signals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let c = self.inner.inner();
        for (i, n) in c.signal_names().iter().enumerate() {
            d.set_item(*n, c.signal(i))?;
        }
        Ok(d)
    }
    /// One internal signal by name.
    fn signal(&self, name: &str) -> PyResult<f64> {
        self.inner.inner().signal_by_name(name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "no signal '{name}'; signals: {}",
                self.inner.inner().signal_names().join(", ")
            ))
        })
    }
    /// True when the last update got a non-finite input and held its output.
    #[getter]
    fn fault(&self) -> bool {
        self.inner.fault()
    }
}

//! `msp.Pid`: the library's PID one sample at a time, in either form, with
//! its weights, limits, rate limit and anti-windup.

use super::*;
use pyo3::exceptions::PyTypeError;

/// The industrial PID controller (ISA form ``Kp(1 + 1/(Ti s) + Td s)``).
///
/// Parameters
/// ----------
/// kp : float
///     The proportional gain (its sign is the loop's direction).
/// ti : float, optional
///     The integral time (s); ``inf`` switches the integral off.
/// td : float, optional
///     The derivative time (s).
/// ts : float, optional
///     The sample period (s).
/// n : float, optional
///     The derivative filter ratio (``Td/N`` is the filter's time constant).
/// b, c : float, optional
///     The set-point weights of the proportional and derivative terms.
/// umin, umax : float, optional
///     The output limits.
/// anti_windup : str, optional
///     ``"back-calculation"`` (default), ``"clamping"`` or ``"none"``.
/// tt : float, optional
///     The tracking time of back-calculation (default ``sqrt(Ti·Td)``, or ``Ti``).
/// rate_limit : float, optional
///     The largest output change per second.
///
/// Examples
/// --------
/// >>> from msp import Pid
/// >>> pid = Pid(2.0, ti=10.0, ts=1.0)
/// >>> [round(pid.update(1.0, 0.0), 6) for _ in range(3)]   # kp·e, then the integral adds kp·e·ts/ti
/// [2.0, 2.2, 2.4]
#[pyclass(module = "msp._msp", name = "Pid")]
pub struct PyPid {
    inner: Pid<f64>,
}

/// The keywords both forms take (`PidOptions` in the stubs): the set-point
/// weights, the limits, the rate limit and the anti-windup, read in one
/// place; an unknown keyword is refused by name, as Python's own are.
struct PidOptions {
    b: f64,
    c: f64,
    umin: f64,
    umax: f64,
    anti_windup: String,
    tt: Option<f64>,
    rate_limit: f64,
}

impl PidOptions {
    fn read(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut o = PidOptions {
            b: 1.0,
            c: 1.0,
            umin: f64::NEG_INFINITY,
            umax: f64::INFINITY,
            anti_windup: "back-calculation".to_string(),
            tt: None,
            rate_limit: f64::INFINITY,
        };
        for (k, v) in kwargs.into_iter().flat_map(|d| d.iter()) {
            let key: String = k.extract()?;
            let number = || {
                v.extract::<f64>().map_err(|_| {
                    PyTypeError::new_err(format!("argument '{key}': a number, not {v}"))
                })
            };
            match key.as_str() {
                "b" => o.b = number()?,
                "c" => o.c = number()?,
                "umin" => o.umin = number()?,
                "umax" => o.umax = number()?,
                "rate_limit" => o.rate_limit = number()?,
                "tt" => o.tt = if v.is_none() { None } else { Some(number()?) },
                "anti_windup" => {
                    o.anti_windup = v.extract().map_err(|_| {
                        PyTypeError::new_err(format!("argument 'anti_windup': a name, not {v}"))
                    })?
                }
                _ => {
                    return Err(PyTypeError::new_err(format!(
                        "unexpected keyword argument '{key}'"
                    )))
                }
            }
        }
        Ok(o)
    }

    /// The controller of `cfg` with these options, checked.
    fn build(self, cfg: PidConfig<f64>) -> PyResult<PyPid> {
        let mut cfg = cfg
            .with_weights(self.b, self.c)
            .with_limits(self.umin, self.umax)
            .with_rate_limit(self.rate_limit);
        // the name is checked whatever the form needs
        let integral = cfg.ki != 0.0;
        let tt = self.tt;
        cfg.anti_windup = match (self.anti_windup.as_str(), cfg.anti_windup) {
            ("back-calculation" | "clamping" | "conditional" | "none", _) if !integral => {
                AntiWindup::None
            }
            ("back-calculation", AntiWindup::BackCalculation { tt: d }) => {
                AntiWindup::BackCalculation {
                    tt: tt.unwrap_or(d),
                }
            }
            ("back-calculation", _) => AntiWindup::BackCalculation {
                tt: tt.unwrap_or(cfg.ts),
            },
            ("clamping" | "conditional", _) => AntiWindup::Conditional,
            ("none", _) => AntiWindup::None,
            (o, _) => {
                return Err(PyValueError::new_err(format!(
                    "anti_windup '{o}': use back-calculation, clamping (conditional) or none"
                )))
            }
        };
        Ok(PyPid {
            inner: Pid::new(cfg).map_err(value_err)?,
        })
    }
}

#[pymethods]
impl PyPid {
    #[new]
    #[pyo3(signature = (kp, ti=f64::INFINITY, td=0.0, ts=1.0, *, n=10.0, **options))]
    fn new(
        kp: f64,
        ti: f64,
        td: f64,
        ts: f64,
        n: f64,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let options = PidOptions::read(options)?;
        // in the ISA form kp scales every term: with kp = 0 a given ti or td
        // would do nothing, and is not dropped without a word
        if kp == 0.0 && (ti.is_finite() || td > 0.0) {
            return Err(PyValueError::new_err(
                "kp = 0 with ti or td: in the ISA form kp scales every term, so ti and td would do nothing; use Pid.parallel(kp, ki, kd) for a pure I or D controller",
            ));
        }
        let cfg = PidConfig::try_isa(kp, ti, td, ts)
            .map_err(value_err)?
            .with_filter(n);
        options.build(cfg)
    }

    /// The parallel form ``u = kp·(b·r − y) + ki·∫(r − y) + kd·d(c·r − y)/dt``
    /// (pid-rs's and simple-pid's gains): ``kp = 0`` is allowed (a pure I or
    /// D controller). ``tf`` is the derivative filter's time constant (default
    /// ``kd/(10·kp)``, ``0`` — unfiltered — when ``kp = 0``); the other
    /// keywords are :class:`PidOptions`, as the constructor's.
    #[staticmethod]
    #[pyo3(signature = (kp, ki=0.0, kd=0.0, ts=1.0, *, tf=None, **options))]
    fn parallel(
        kp: f64,
        ki: f64,
        kd: f64,
        ts: f64,
        tf: Option<f64>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let options = PidOptions::read(options)?;
        let mut cfg = PidConfig::parallel(kp, ki, kd, ts);
        if let Some(tf) = tf {
            cfg = cfg.with_filter_time(tf);
        }
        options.build(cfg)
    }

    /// Sets the integral so that the next output is ``u`` for zero error (a
    /// bumpless start from a steady state with the actuator at ``u``).
    fn preset(&mut self, u: f64) -> PyResult<()> {
        self.inner.preset(u).map_err(value_err)
    }

    /// The constructor call that builds this controller (``eval`` gives
    /// one that computes the same outputs from the same state): the ISA
    /// form, or the parallel form for ``kp = 0`` (a pure I or D controller,
    /// which the ISA form cannot hold). Its state (``mode``, ``output``) is
    /// in its properties.
    fn __repr__(&self) -> String {
        let c = self.inner.config();
        let num = |v: f64| {
            if v.is_nan() {
                "float('nan')".to_string()
            } else if v.is_infinite() {
                format!("float('{}inf')", if v < 0.0 { "-" } else { "" })
            } else {
                format!("{v:?}")
            }
        };
        let (aw, tt) = match c.anti_windup {
            AntiWindup::None => ("none", None),
            AntiWindup::BackCalculation { tt } => ("back-calculation", Some(tt)),
            AntiWindup::Conditional => ("clamping", None),
        };
        let tail = format!(
            "b={}, c={}, umin={}, umax={}, anti_windup='{aw}', tt={}, rate_limit={})",
            num(c.b),
            num(c.c),
            num(c.u_min),
            num(c.u_max),
            tt.map_or("None".to_string(), num),
            num(c.rate_limit)
        );
        if c.kp == 0.0 {
            format!(
                "msp.Pid.parallel(kp={}, ki={}, kd={}, ts={}, tf={}, {tail}",
                num(c.kp),
                num(c.ki),
                num(c.kd),
                num(c.ts),
                num(c.tf)
            )
        } else {
            // N = Td/Tf (any value without a derivative: 10, the default)
            let n = if c.td() > 0.0 {
                if c.tf > 0.0 {
                    c.td() / c.tf
                } else {
                    f64::INFINITY
                }
            } else {
                10.0
            };
            format!(
                "msp.Pid(kp={}, ti={}, td={}, ts={}, n={}, {tail}",
                num(c.kp),
                num(c.ti()),
                num(c.td()),
                num(c.ts),
                num(n)
            )
        }
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
    /// Zeroes the state, back to auto mode: the next update takes its
    /// sample as the derivative's reference (no kick).
    fn reset(&mut self) {
        self.inner.reset();
    }
    /// Zeroes the state, back to auto mode, with the loop at rest before
    /// the next update (every signal zero, as the transfer function from
    /// rest has it): its derivative differences ``c·r − y`` against zero,
    /// a step kicks it as it does later.
    ///
    /// Examples
    /// --------
    /// >>> import msp
    /// >>> c = msp.Pid(kp=0.5, ti=4, td=2, ts=0.1)
    /// >>> c.update(1, 0)  # new: the first sample is the derivative's reference
    /// 0.5
    /// >>> c.reset_to_rest()
    /// >>> round(c.update(1, 0), 12)  # 0.5 + 0.5·2/(0.2 + 0.1)
    /// 3.833333333333
    fn reset_to_rest(&mut self) {
        self.inner.reset_to_rest();
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
    /// Parameters: the ISA ``kp``, ``ti``, ``td`` and the parallel ``ki``,
    /// ``kd`` (``ti`` and ``td`` are ``None`` for ``kp = 0``, a pure I or D
    /// controller, which has no ISA form).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.inner.config();
        let d = PyDict::new(py);
        let isa = c.kp != 0.0;
        d.set_item("kp", c.kp)?;
        d.set_item("ti", isa.then(|| c.ti()))?;
        d.set_item("td", isa.then(|| c.td()))?;
        d.set_item("ki", c.ki)?;
        d.set_item("kd", c.kd)?;
        Ok(d)
    }
}

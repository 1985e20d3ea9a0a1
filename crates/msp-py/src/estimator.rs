//! `msp.Estimator`: the on-line identifier of a dead-time process, one
//! sample at a time.

use crate::value_err;
use msp::adapt::{Estimator as Bank, EstimatorConfig};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Candidate dead times of a Python estimator.
const N: usize = 32;
/// Its history of input differences (the longest dead time + 2).
const H: usize = 4096;

/// The on-line identifier of ``K e^(−θs)/(τs + 1)`` (or ``K e^(−θs)/s``) from
/// closed-loop data: a bank of recursive least-squares estimators over 32
/// candidate dead times from ``d_min`` samples (the library's
/// ``msp::adapt::Estimator``).
///
/// Parameters
/// ----------
/// ts : float
///     The sample period (s).
/// d_min : int
///     The smallest candidate dead time (samples); the candidates are
///     ``d_min … d_min + 31`` (``d_min + 33 ≤ 4096``).
/// d_max : int, optional
///     The longest candidate dead time (samples, at least ``d_min``;
///     default ``d_min + 31``): the candidates end there.
/// decimation : int, optional
///     Controller samples per estimator sample (default 1): it learns from
///     their block means, and ``d_min``, ``d_max`` count its samples, a
///     candidate ``d`` then standing for ``d + 1`` of them (a block's input,
///     as its means see it, is a block older).
/// integrating : bool, optional
///     The process integrates (``a = 1``).
/// forgetting : float, optional
///     The forgetting factor (default 0.999).
/// prefilter : float, optional
///     The prefilter's time constant (s; default 0: plain differences).
/// excitation : float, optional
///     No learning unless the input moved this much (default 1e-6).
///
/// Examples
/// --------
/// >>> import math, msp
/// >>> est = msp.Estimator(ts=0.1, d_min=5)
/// >>> a = math.exp(-0.1 / 4.0)
/// >>> y, us = 0.0, []
/// >>> for k in range(16000):
/// ...     u = 1.0 if (k // 200) % 2 else -1.0
/// ...     _ = est.update(y, u)
/// ...     us.append(u)
/// ...     y = a * y + 2.0 * (1 - a) * (us[k - 12] if k >= 12 else 0.0)
/// >>> e = est.estimate
/// >>> round(e["k"], 3), round(e["tau"], 3), round(e["theta"], 3)
/// (2.0, 4.0, 1.2)
#[pyclass(module = "msp._msp")]
pub struct Estimator {
    inner: Box<Bank<f64, N, H>>,
}

#[pymethods]
impl Estimator {
    #[new]
    #[pyo3(signature = (ts, d_min, *, d_max = None, decimation = 1, integrating = false, forgetting = 0.999, prefilter = 0.0, excitation = 1e-6))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        ts: f64,
        d_min: usize,
        d_max: Option<usize>,
        decimation: usize,
        integrating: bool,
        forgetting: f64,
        prefilter: f64,
        excitation: f64,
    ) -> PyResult<Self> {
        let mut cfg = EstimatorConfig::new(ts, d_min);
        cfg.d_max = d_max;
        cfg.decimation = decimation;
        cfg.integrating = integrating;
        cfg.forgetting = forgetting;
        cfg.set_prefilter_time(prefilter).map_err(value_err)?;
        cfg.min_excitation = excitation;
        Ok(Estimator {
            inner: Box::new(Bank::new(cfg).map_err(value_err)?),
        })
    }

    /// One sample: ``y`` measured now and ``u_applied`` the input the plant
    /// receives from now on; ``ok=False`` for a sample that is not the
    /// process's own response (saturated, manual, a fault). With
    /// ``decimation`` N the estimator learns from the means of each N
    /// samples (``d_min``, ``d_max`` and ``estimate["d"]`` count its own
    /// samples, N·ts s each); returns whether a block's learning ended
    /// here (from N = 4 it is spread over the block's last sample and the
    /// three after it).
    #[pyo3(signature = (y, u_applied, ok = true))]
    fn update(&mut self, y: f64, u_applied: f64, ok: bool) -> bool {
        self.inner.update(y, u_applied, ok)
    }

    /// Load onsets found so far: at rest, an error no input move can
    /// explain (it teaches nothing; every model takes the measurement as
    /// its state there).
    #[getter]
    fn onsets(&self) -> u32 {
        self.inner.onsets()
    }

    /// The responses (a load's, a set-point change's) the level test compared so far and, of them,
    /// the ones it took as evidence, ``(responses, responses_used)`` (the
    /// others held back: within the noise or the rounding, a measurement
    /// that hardly moved, a drift, another dead time's).
    #[getter]
    fn level_responses(&self) -> (u32, u32) {
        self.inner.level_responses()
    }

    /// Of the responses the level test compared, those it found a ramp
    /// load's (a drift, a misfit no model removes): while, since the model
    /// in use was set, they outnumber the ones taken as evidence, the level
    /// test proposes nothing.
    #[getter]
    fn level_ramps(&self) -> u32 {
        self.inner.level_ramps()
    }

    /// The samples the chosen candidate has learnt from so far (its RLS
    /// steps; the adaptive controller applies no estimate of a block with
    /// fewer than a response's).
    #[getter]
    fn learnt(&self) -> u32 {
        self.inner.learnt()
    }

    /// The model now, a dict with ``k``, ``tau`` (``inf``: integrating),
    /// ``theta`` (s), ``d`` (whole samples) and ``evidence`` (the next
    /// candidate's cost less the chosen one's in units of the chosen one's
    /// error per sample: small is ambiguous), or
    /// ``None`` before it means anything.
    #[getter]
    fn estimate<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(e) = self.inner.estimate() else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("k", e.k)?;
        d.set_item("tau", e.tau)?;
        d.set_item("theta", e.theta)?;
        d.set_item("d", e.d)?;
        d.set_item("evidence", e.evidence)?;
        Ok(Some(d))
    }

    /// Starts from the model ``k e^(−theta s)/(tau s + 1)`` (``tau=inf``:
    /// integrating), e.g. the one the controller was designed for: its dead
    /// time is the choice until the data say otherwise, and every
    /// candidate's coefficients start at the model's.
    fn start_from(&mut self, k: f64, tau: f64, theta: f64) -> PyResult<()> {
        self.inner.start_from(k, tau, theta).map_err(value_err)
    }

    /// Each candidate's discounted squared prediction error, from ``d_min``
    /// on (the curve the choice of dead time minimises).
    #[getter]
    fn costs(&self) -> Vec<f64> {
        self.inner.costs().collect()
    }

    /// The chosen candidate's covariance trace (bounded: no bursting).
    #[getter]
    fn trace(&self) -> f64 {
        self.inner.trace()
    }

    /// The model in use, ``k e^(−theta s)/(tau s + 1)`` (``tau=inf``:
    /// integrating), which the estimator weighs against its own
    /// (:attr:`mismatch`, :attr:`recent_mismatch`).
    fn set_reference(&mut self, k: f64, tau: f64, theta: f64) -> PyResult<()> {
        self.inner.set_reference(k, tau, theta).map_err(value_err)
    }

    /// How far the model in use (:meth:`set_reference`) is from the
    /// process over the costs' long memory, a dict with ``error`` (the
    /// model's error relative to the movement it predicts: 0.3, about a
    /// gain 30 % off) and ``evidence`` (that it is not the noise's), or
    /// ``None`` before a whole response was compared.
    #[getter]
    fn mismatch<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        mismatch_dict(py, self.inner.mismatch())
    }

    /// :attr:`mismatch` over the last response only, the change
    /// detector's simulations at every dead time, and at the chosen one
    /// with other gains and lags, beside the chosen candidate (the
    /// monitor's quick view: a new dead time, gain or lag shows there
    /// before the estimate has learnt it).
    #[getter]
    fn recent_mismatch<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        mismatch_dict(py, self.inner.recent_mismatch())
    }

    /// The estimator samples of a response: the longest candidate dead
    /// time and, with a prior model, four of its time constants (the
    /// excitation gate's and the recent view's memory).
    #[getter]
    fn window(&self) -> usize {
        self.inner.window()
    }

    /// The measurement noise's standard deviation as the estimator sees it
    /// (0 before any data).
    #[getter]
    fn noise_level(&self) -> f64 {
        self.inner.noise_level()
    }

    /// How many times the change detector found a step of the dead time
    /// and restarted the candidates from the model before it.
    #[getter]
    fn restarts(&self) -> u32 {
        self.inner.restarts()
    }
}

/// A model error as a dict (``None``: not yet compared).
fn mismatch_dict<'py>(
    py: Python<'py>,
    m: Option<msp::adapt::Mismatch<f64>>,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let Some(m) = m else {
        return Ok(None);
    };
    let d = PyDict::new(py);
    d.set_item("error", m.error)?;
    d.set_item("evidence", m.evidence)?;
    Ok(Some(d))
}

//! The study layer: a typed [`Scenario`] is parsed at its edge, tuned, built,
//! simulated by the engine ([`crate::sim`]) and measured; [`compare`] runs
//! several schemes on one plant. Text is read only by [`crate::syntax`].
//!
//! Its rooms: `build` (tuning and construction, the memory budget), `run`
//! (one closed loop), `metrics` and `output` (what a run measured), `report`
//! (the serde types every front end prints), `margins` (a scenario's loop
//! analysed: `msp margins`), `robustness` (margins and their advice),
//! `target` (λ solved for a robustness or bandwidth target), `compare`,
//! `tradeoff`, `forced` (a run driven by sampled set points and loads),
//! `adapt` (a scenario's adaptive dead-time compensation) and `bank` (the
//! adaptation's benchmark bank). The period and duration a run chooses are
//! the engine's ([`crate::sim::choose_ts`]), re-exported here.

mod adapt;
pub mod bank;
mod build;
mod compare;
mod forced;
mod margins;
mod metrics;
pub mod mimo;
mod output;
mod report;
mod robustness;
mod run;
mod target;
mod tradeoff;

pub use adapt::{AdaptOptions, CANDIDATES as ADAPT_CANDIDATES};

pub(crate) use build::PLANT_BYTES_PER_SAMPLE;
pub use build::{check_budget, check_controller_memory, BuiltController, Tuned};
use build::{BYTES_PER_SCHEDULED, CONTROLLER_BYTES_PER_SAMPLE, RECORDED_COLUMNS};
pub use compare::{compare, Perturbation};
// the sample period and duration a run chooses: the engine's, seen from here
pub use crate::sim::{
    choose_duration, choose_ts, choose_ts_as, describe_ts, kind_of, F32_POLE_DISTANCE,
    MAX_CHOSEN_SAMPLES,
};
pub use forced::SampledInput;
pub use margins::{analyze, analyze_tuned, tuned_stability, MarginsReport};
pub use metrics::{
    measure, metrics, next_event, settled, settles, stable, swing, Columns, DisturbanceEvent,
    Event, Metrics, SetpointEvent,
};
pub use mimo::{
    Interaction, MimoDesign, MimoOutput, MimoReport, MimoScenario, MimoScenarioFile, MimoScheme,
    MIMO_SCHEMES,
};
pub use output::RunOutput;
pub use report::{
    AdaptationReport, ControllerReport, ProcessReport, Report, RuleRow, TuneReport, TuningReport,
};
pub(crate) use robustness::Advice;
pub use robustness::Robustness;
pub(crate) use run::Plants;
pub use target::{Figure, Target, TargetReport};
pub use tradeoff::{tradeoff, tradeoff_factors, Tradeoff, TradeoffPoint};

use std::string::String;
use std::vec::Vec;

use crate::error::Error;
use crate::poly::{PlantKind, TransferFunction};
use crate::registry::{self, Params, RegistryError};
use crate::sim::{simulate_cascade, Disturbance, SetpointStep, SimConfig, SimResult};

/// A complete run description: what `msp run` takes from its flags or from a
/// TOML/JSON file (`msp run --scenario file.toml`), and Python's `run` from
/// its keyword arguments. The plants are typed: expressions are parsed at the
/// edge (a flag, a file's field) and never again. Unknown fields are rejected
/// by name.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct Scenario {
    /// The plant (required to run); a scenario file writes it as an
    /// expression, e.g. `plant = "0.2/s*e^-7.4s"`.
    #[cfg_attr(feature = "serde", serde(with = "crate::syntax::expr::as_expression"))]
    pub plant: Option<TransferFunction>,
    /// The controller's model (defaults to the plant: a perfect model).
    #[cfg_attr(feature = "serde", serde(with = "crate::syntax::expr::as_expression"))]
    pub model: Option<TransferFunction>,
    /// Cascade processes: the secondary process `P2 e^{−L2 s}` whose output is
    /// measured and drives `plant` (then the primary `P1 e^{−L1 s}`).
    #[cfg_attr(feature = "serde", serde(with = "crate::syntax::expr::as_expression"))]
    pub inner_plant: Option<TransferFunction>,
    /// The controller's model of the secondary process (defaults to `inner_plant`).
    #[cfg_attr(feature = "serde", serde(with = "crate::syntax::expr::as_expression"))]
    pub inner_model: Option<TransferFunction>,
    /// Controller name from the registry (default: chosen by plant kind).
    pub controller: Option<String>,
    /// Closed-loop time constant for tuning (s).
    pub lambda: Option<f64>,
    /// A named tuning rule (for `pid`: `imc`, `simc`, or a rule of Tables 3.2/3.3).
    pub rule: Option<String>,
    /// A design target the tuning's `λ` is solved for (`ms=1.4`, `pm=60`,
    /// `gm=3`, `dm=0.3θ`, `wc=0.2`), when `lambda` is not given.
    pub target: Option<Target>,
    /// Parameter overrides, by the names in the report (`kp = 0.05`).
    pub set: std::collections::BTreeMap<String, f64>,
    /// Sample period (s); chosen from the plant when absent.
    pub ts: Option<f64>,
    /// Duration (s); chosen from the plant when absent.
    pub duration: Option<f64>,
    /// Set-point steps (default: a unit step at t = 0). A file may write
    /// them as the flag does (`"1@0"`) or structured (`{value, at}`).
    #[cfg_attr(feature = "serde", serde(with = "crate::syntax::text_or_struct"))]
    pub setpoint: Vec<SetpointStep>,
    /// Disturbances, as the flag writes them (`"input:-0.1@1000"`) or
    /// structured.
    #[cfg_attr(feature = "serde", serde(with = "crate::syntax::text_or_struct"))]
    pub disturbance: Vec<Disturbance>,
    /// Measurement-noise standard deviation.
    pub noise: Option<f64>,
    /// Noise seed.
    pub seed: Option<u64>,
    /// The measurement's resolution (an ADC's step, e.g. the span over
    /// 4096 for 12 bits): the controller sees the output rounded to it.
    pub quantization: Option<f64>,
    /// Actuator lower limit.
    pub umin: Option<f64>,
    /// Actuator upper limit.
    pub umax: Option<f64>,
    /// Plant outputs per controller period in the signals (smooth plots).
    pub substeps: Option<usize>,
    /// The controller computes in `f32`, as firmware does (designed in `f64`,
    /// run through [`crate::Widened`]); the plant stays exact in `f64`.
    pub float32: bool,
    /// The memory a run may take (bytes; default [`DEFAULT_MAX_MEMORY`]):
    /// the delay lines and the recorded signals are estimated before anything
    /// is allocated, and a run that needs more is refused.
    pub max_memory: Option<u64>,
    /// What an operator does during the run, as the flag writes it
    /// (`"60:manual=0.3"`, `"120:auto"`, `"60:plant-dead-time=9"`) or
    /// structured.
    #[cfg_attr(feature = "serde", serde(with = "crate::syntax::text_or_struct"))]
    pub events: Vec<crate::sim::Operation>,
    /// An actuator limit outside the controller, `(min, max)`: the plant
    /// receives the controller's output clamped to it.
    #[cfg_attr(feature = "serde", serde(with = "crate::syntax::exact_pair"))]
    pub actuator: Option<(f64, f64)>,
    /// The value the plant received is fed back to the controller each
    /// sample (external reset: no windup against the outside actuator).
    pub reset_feedback: bool,
    /// The controller's set point moves by at most this much per second
    /// (off when absent).
    pub setpoint_ramp: Option<f64>,
    /// Adaptive dead-time compensation: the scheme's model kept right by
    /// on-line identification ([`crate::adapt`]; off when absent).
    pub adapt: Option<AdaptOptions>,
    /// The model-error monitor: the estimator watches the model in use and
    /// raises an alarm when the process no longer matches it (with `adapt`:
    /// beside the adaptation; without: nothing is applied).
    pub monitor: bool,
}

/// The memory a run may take unless the scenario says otherwise: 1 GiB.
pub const DEFAULT_MAX_MEMORY: u64 = 1 << 30;

/// The step load of the default scenario at the plant input: a fifth of a
/// unit set-point step at the output in steady state, `−0.2/K` for a plant
/// of gain `K`, `−0.02/Kv` for an integrator `Kv/s` (the thesis's −0.1 on
/// `0.2/s`); the gain's sign as the actuator acts (the high-frequency sign
/// for an unstable plant: `K/(Ts − 1)` has `G(0) = −K` but rises with `u`).
/// `None` for a plant without a usable gain.
pub(crate) fn default_load(whole: &TransferFunction) -> Option<f64> {
    let gain = match whole.kind() {
        PlantKind::Unstable => {
            let hf = whole.num.first().copied().unwrap_or(1.0)
                / whole.den.first().copied().unwrap_or(1.0);
            whole.gain().abs() * hf.signum()
        }
        _ => whole.gain(),
    };
    if !(gain.abs() > 0.0 && gain.is_finite()) {
        return None;
    }
    Some(match whole.kind() {
        PlantKind::Integrating => -0.1 * (0.2 / gain),
        _ => -0.2 / gain,
    })
}

/// The smallest round number (1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 times a
/// power of ten) at or above `x > 0`.
pub(crate) fn nice_ceil(x: f64) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return x;
    }
    let mut decade = 10f64.powf(x.log10().floor());
    loop {
        for m in [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0] {
            let v = crate::poly::round_sig(m * decade, 7);
            if v >= x * (1.0 - 1e-12) {
                return v;
            }
        }
        decade *= 10.0;
    }
}

/// What a run keeps ([`Scenario::run_tuned_measured`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Keep {
    /// Every signal, with the metrics and event figures.
    Measured,
    /// Every signal; the figures left for [`RunOutput::measure`].
    Signals,
    /// `t`, `y` and `u` only, no figures (a sweep's row computes its own).
    Output,
}

std::thread_local! {
    /// The buffers of a run whose signals were read and are no longer
    /// needed, for the next run on this thread ([`recycle`]).
    static SPARE: core::cell::RefCell<Option<SimResult>> = const { core::cell::RefCell::new(None) };
}

/// `f` of each item, in order: on every core with the `parallel` feature
/// (rayon's pool; each thread reuses its own buffers, [`recycle`]), one
/// after another without it. Sweeps, trade-offs and comparisons run their
/// loops through it.
pub(crate) fn each<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync + Send) -> Vec<R> {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        // the runs side by side share the memory budget: each may take
        // its part ([`check_budget`] divides by it), so that together they
        // stay within what one run may take
        let side_by_side = rayon::current_num_threads().min(items.len()).max(1);
        let share = u64::try_from(side_by_side).unwrap_or(u64::MAX);
        items
            .par_iter()
            .map(|item| {
                let outer = SHARE.with(|s| s.replace(s.get().max(share)));
                let r = f(item);
                SHARE.with(|s| s.set(outer));
                r
            })
            .collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        items.iter().map(f).collect()
    }
}

std::thread_local! {
    /// How many runs share the memory budget on this thread's behalf (1:
    /// it is this run's alone; see [`each`]).
    pub(crate) static SHARE: core::cell::Cell<u64> = const { core::cell::Cell::new(1) };
}

/// Gives the buffers of a finished run back for the next run on this
/// thread to write into: a sweep of many runs then writes to memory that
/// is already mapped (on a virtual machine the first touch of a fresh page
/// costs more than the simulation of the samples it holds).
pub fn recycle(result: SimResult) {
    SPARE.with(|s| *s.borrow_mut() = Some(result));
}

/// The buffers [`recycle`] gave back, or none.
fn spare() -> SimResult {
    SPARE.with(|s| s.borrow_mut().take()).unwrap_or_default()
}

/// Why a scenario could not run.
#[derive(Debug)]
pub enum RunError {
    /// A required field of the scenario is absent (`plant`).
    Missing(&'static str),
    /// A controller or its parameters are wrong.
    Registry(RegistryError),
    /// A scenario value is wrong.
    Invalid(Error),
    /// A requested size is beyond a limit (the message names both).
    Limit(String),
    /// Something scheduled falls outside the run (the message names it).
    Schedule(String),
}

impl core::fmt::Display for RunError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            RunError::Missing(field) => write!(f, "the scenario has no {field}"),
            RunError::Registry(e) => write!(f, "{e}"),
            RunError::Invalid(e) => write!(f, "{e}"),
            RunError::Limit(m) | RunError::Schedule(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for RunError {}

impl From<Error> for RunError {
    fn from(e: Error) -> Self {
        RunError::Invalid(e)
    }
}
impl From<RegistryError> for RunError {
    fn from(e: RegistryError) -> Self {
        RunError::Registry(e)
    }
}

impl Scenario {
    /// The longest dead time (s) the events give the plant (`plant`) or the
    /// controller's model (0 without such events).
    fn event_dead_time(&self, plant: bool) -> f64 {
        self.events
            .iter()
            .filter_map(|e| match (e.action, plant) {
                (crate::sim::Action::PlantDeadTime(d), true)
                | (
                    crate::sim::Action::PlantDrift(crate::sim::PlantParameter::DeadTime, d, _),
                    true,
                )
                | (crate::sim::Action::DeadTime(d), false)
                | (crate::sim::Action::DeadTimeRamp(d, _), false) => Some(d),
                _ => None,
            })
            .fold(0.0, f64::max)
    }

    /// The latest thing the scenario schedules — a set-point step, a
    /// disturbance or an operator event — as `(time, what)`.
    pub fn last_scheduled(&self) -> Option<(f64, String)> {
        let fmt = crate::poly::fmt_num;
        self.setpoint
            .iter()
            .map(|s| {
                (
                    s.at,
                    std::format!("the set-point step to {} at {} s", fmt(s.value), fmt(s.at)),
                )
            })
            .chain(self.disturbance.iter().map(|d| {
                (
                    d.at,
                    std::format!("the {} disturbance at {} s", d.location.name(), fmt(d.at)),
                )
            }))
            .chain(
                self.events
                    .iter()
                    .map(|e| (e.at, std::format!("the operator event at {} s", fmt(e.at)))),
            )
            .filter(|(at, _)| at.is_finite())
            .max_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// A duration that ends before something the scenario schedules is an
    /// error naming it: the run would drop it without a word.
    fn check_duration_covers(&self, duration: f64) -> Result<(), RunError> {
        match self.last_scheduled() {
            Some((at, what)) if at > duration => Err(RunError::Schedule(std::format!(
                "{what} is after the end of the run ({} s): give a longer duration, or leave it out to have msp cover every scheduled step and its settling",
                crate::poly::fmt_num(duration)
            ))),
            _ => Ok(()),
        }
    }

    /// The events' values and the actuator's range, checked (a scenario file
    /// may give them structured, past the flags' parser).
    fn check_operation(&self) -> Result<(), RunError> {
        use crate::sim::{Action, PlantParameter};
        for e in &self.events {
            crate::real::non_negative(e.at, "event time")?;
            if let Action::PlantDrift(_, _, rate) = e.action {
                crate::real::positive(rate, "event drift rate")?;
            }
            match e.action {
                Action::Manual(v) | Action::Track(v) => {
                    crate::real::finite(v, "event value")?;
                }
                Action::DeadTime(d)
                | Action::PlantDeadTime(d)
                | Action::PlantDrift(PlantParameter::DeadTime, d, _) => {
                    crate::real::non_negative(d, "event dead time")?;
                }
                Action::PlantGain(k) | Action::PlantDrift(PlantParameter::Gain, k, _) => {
                    crate::real::finite(k, "event plant gain")?;
                    if k == 0.0 {
                        return Err(RunError::Invalid(Error::OutOfRange(
                            "event plant gain: not zero",
                        )));
                    }
                }
                Action::PlantLag(tau) | Action::PlantDrift(PlantParameter::Lag, tau, _) => {
                    crate::real::positive(tau, "event plant lag")?;
                }
                Action::DeadTimeRamp(d, rate) => {
                    crate::real::non_negative(d, "event dead time")?;
                    crate::real::positive(rate, "event dead-time rate")?;
                }
                Action::Retune(_, v) => {
                    if v.is_nan() {
                        return Err(RunError::Invalid(Error::NonFinite("event value")));
                    }
                }
                Action::Auto | Action::Adapt(_) => {}
            }
        }
        if let Some((lo, hi)) = self.actuator {
            if lo.is_nan() || hi.is_nan() || lo >= hi {
                return Err(RunError::Invalid(Error::InvalidLimits("actuator")));
            }
        }
        Ok(())
    }

    /// The scenario's fields, by the names of the scenario file and the report.
    /// The CLI's flags and Python's keyword arguments are checked against this
    /// list by the test suites (`--inner-plant` for `inner_plant`; Python writes
    /// `params` for `set` and `lambda_` for `lambda`).
    pub const FIELDS: &'static [&'static str] = &[
        "plant",
        "model",
        "inner_model",
        "inner_plant",
        "controller",
        "lambda",
        "rule",
        "target",
        "set",
        "ts",
        "duration",
        "setpoint",
        "disturbance",
        "noise",
        "seed",
        "quantization",
        "umin",
        "umax",
        "substeps",
        "float32",
        "max_memory",
        "events",
        "actuator",
        "reset_feedback",
        "setpoint_ramp",
        "adapt",
        "monitor",
    ];

    /// The fields a tuning takes besides the plant (`msp tune`, Python's
    /// `tune`): `inner_plant` to `ts` of [`Scenario::FIELDS`].
    pub const TUNE_FIELDS: &'static [&'static str] = Self::FIELDS.split_at(3).1.split_at(7).0;

    /// The plant and the controller's model (the plant when no model is given).
    pub fn plant_and_model(&self) -> Result<(TransferFunction, TransferFunction), RunError> {
        let plant = self.plant.clone().ok_or(RunError::Missing("plant"))?;
        let model = self.model.clone().unwrap_or_else(|| plant.clone());
        Ok((plant, model))
    }

    /// The secondary process and its model (cascade scenarios).
    pub fn inner_process(&self) -> Result<Option<(TransferFunction, TransferFunction)>, RunError> {
        match (&self.inner_plant, &self.inner_model) {
            (None, None) => Ok(None),
            (None, Some(_)) => Err(RunError::Invalid(Error::Unsupported(
                "an inner model without an inner plant",
            ))),
            (Some(p2), m2) => Ok(Some((p2.clone(), m2.clone().unwrap_or_else(|| p2.clone())))),
        }
    }
}

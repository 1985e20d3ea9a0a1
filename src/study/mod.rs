//! The study layer: a typed [`Scenario`] is parsed at its edge, tuned, built,
//! simulated by the engine ([`crate::sim`]) and measured; [`compare`] runs
//! several schemes on one plant. Text is read only by [`crate::syntax`].

mod adapt;
mod build;
mod compare;
mod defaults;
mod forced;
mod metrics;
mod report;
mod robustness;
mod target;
mod tradeoff;

pub use adapt::{AdaptOptions, CANDIDATES as ADAPT_CANDIDATES};

pub(crate) use build::PLANT_BYTES_PER_SAMPLE;
pub use build::{check_budget, check_controller_memory, BuiltController, Tuned};
use build::{BYTES_PER_ROW, BYTES_PER_SCHEDULED, CONTROLLER_BYTES_PER_SAMPLE};
pub use compare::{compare, Perturbation};
pub use defaults::{choose_duration, choose_ts, describe_ts, kind_of};
pub use forced::SampledInput;
pub use metrics::{
    measure, metrics, next_event, settled, Columns, DisturbanceEvent, Event, Metrics, SetpointEvent,
};
pub use report::{
    AdaptationReport, ControllerReport, ProcessReport, Report, RuleRow, TuneReport, TuningReport,
};
pub use robustness::Robustness;
pub use target::{Figure, Target, TargetReport};
pub use tradeoff::{tradeoff, tradeoff_factors, Tradeoff, TradeoffPoint};

use std::string::String;
use std::vec::Vec;

use crate::poly::{PlantKind, TransferFunction};
use crate::registry::{self, Params, RegistryError};
use crate::sim::{simulate_cascade, Disturbance, SetpointStep, SimConfig, SimResult};
use crate::Error;

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

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunOutput {
    /// The plant.
    pub plant: TransferFunction,
    /// The controller's model.
    pub model: TransferFunction,
    /// Cascade processes: the secondary process and its model.
    pub inner: Option<(TransferFunction, TransferFunction)>,
    /// Sample period used.
    pub ts: f64,
    /// Whether `ts` was chosen automatically.
    pub ts_chosen: bool,
    /// Duration used.
    pub duration: f64,
    /// Whether the duration was chosen automatically.
    pub duration_chosen: bool,
    /// The figures of each set-point step and disturbance over its segment.
    pub events: Vec<metrics::Event>,
    /// The run is the default scenario ([`Scenario::run`]: a set-point step,
    /// then a load once it has settled), not one the user named.
    pub default_scenario: bool,
    /// The scenario as it was given (what msp chose is `None` or empty in
    /// it, and the run's own fields say what was chosen): run again, it gives
    /// this run again.
    pub scenario: Scenario,
    /// What the run found that the user should know, beside an instability
    /// (part of [`RunOutput::warnings`]).
    pub notes: Vec<String>,
    /// The designed quantities a paper prints beside the parameters
    /// ([`registry::Scheme::design_report`]), for a run by [`Scenario::run`].
    pub design: registry::DesignReport,
    /// The tuned loop's margins (sampled view), for a single loop run by
    /// [`Scenario::run`].
    pub robustness: Option<crate::analysis::Margins>,
    /// The loop's stability verdict ([`crate::analysis::stability`]),
    /// cross-checked by this run, for a run by [`Scenario::run`].
    pub stability: crate::analysis::Stability,
    /// Whether the tuning's `lambda` was chosen automatically.
    pub lambda_chosen: bool,
    /// The design target the tuning's `lambda` was solved for, and what the
    /// loop reaches.
    pub target: Option<TargetReport>,
    /// Controller name.
    pub controller: &'static str,
    /// Its parameters.
    pub params: Params,
    /// The signals.
    pub result: SimResult,
    /// Metrics on `e = r − y`.
    pub metrics: Metrics,
    /// Metrics on `e = r(t − θm) − y`, time from `θm`.
    pub metrics_delayed_reference: Metrics,
    /// The set-point profile used.
    pub setpoint: Vec<SetpointStep>,
    /// The disturbances used.
    pub disturbance: Vec<crate::sim::Disturbance>,
    /// The controller computed in `f32` ([`Scenario::float32`]).
    pub float32: bool,
    /// When the loop first stopped being the one built and analysed (s),
    /// and what changed it: a process drift, the controller's dead time or
    /// gains, the first model the adaptation applied (`None`: the loop ran
    /// as built to the end).
    pub loop_change: Option<(f64, &'static str)>,
}

impl RunOutput {
    /// Computes the metrics and the event figures of the run from its
    /// signals (a run of [`Scenario::run_unmeasured`]; for any other run
    /// they are computed already and come out the same).
    pub fn measure(&mut self) -> Result<(), RunError> {
        let figures = self.figures(&self.result.columns())?;
        self.set_figures(figures);
        Ok(())
    }

    /// [`RunOutput::measure`] from columns held elsewhere (the arrays a
    /// run's signals were handed to).
    pub fn measure_from(&mut self, cols: &Columns<'_>) -> Result<(), RunError> {
        let figures = self.figures(cols)?;
        self.set_figures(figures);
        Ok(())
    }

    fn figures(&self, cols: &Columns<'_>) -> Result<(Metrics, Metrics, Vec<Event>), RunError> {
        Ok(measure(
            cols,
            &self.setpoint,
            &self.disturbance,
            self.ts,
            self.model_delay(),
        )?)
    }

    fn set_figures(&mut self, (m0, m1, events): (Metrics, Metrics, Vec<Event>)) {
        self.metrics = m0;
        self.metrics_delayed_reference = m1;
        self.events = events;
    }

    /// Whether the run came to rest and did not diverge, its output `y`
    /// (its own column, or the array it was handed to): what the stability
    /// verdict is cross-checked with. Reads the measured figures.
    pub fn settled_with(&self, y: &[f64]) -> bool {
        self.result.diverged_at.is_none() && settled(y, &self.metrics, self.duration)
    }

    /// Adds the loop's analysis to a run of [`Scenario::run_unanalysed`]
    /// (or of [`Scenario::run_unmeasured`], measured first here): the
    /// stability verdict cross-checked by this run, and the robustness
    /// figures with what they warn of. Reads the signals (has the run come
    /// to rest?); [`RunOutput::analyse_settled`] takes that answer instead.
    pub fn analyse(&mut self) -> Result<(), RunError> {
        if self.metrics.indices.iae.is_nan() && self.result.diverged_at.is_none() {
            self.measure()?;
        }
        self.analyse_settled(self.settled_as_built(&self.result.t, &self.result.y));
        Ok(())
    }

    /// Whether the loop as built came to rest in the output `y` at the
    /// times `t` (the run's signals): over the run, or when the loop
    /// changes ([`RunOutput::loop_change`]) up to the change (`None`: too
    /// short a stretch before it to have come to rest in).
    pub fn settled_as_built(&self, t: &[f64], y: &[f64]) -> Option<bool> {
        match self.loop_change {
            Some((at, _)) => {
                let rows = t.iter().take_while(|t| **t < at).count();
                (rows >= 10).then(|| {
                    self.result.diverged_at.map_or(true, |d| d >= at)
                        && settled(y.get(..rows).unwrap_or(y), &self.metrics, at)
                })
            }
            None => Some(self.settled_with(y)),
        }
    }

    /// The verdict of the loop as built cross-checked by this run (`settled`:
    /// [`RunOutput::settled_as_built`]).
    pub(crate) fn cross_checked(
        &self,
        stability: crate::analysis::Stability,
        settled: Option<bool>,
    ) -> crate::analysis::Stability {
        match (self.loop_change, settled) {
            (Some((at, what)), _) => stability.as_built(settled, at, what),
            (None, Some(settled)) => stability.with_simulation(settled, self.duration),
            (None, None) => stability,
        }
    }

    /// When the loop first stops being the one built (and analysed): a
    /// process drift (`plant-gain`, `plant-lag`, `plant-dead-time`), the
    /// controller's dead time or gains changed by an event, or the first
    /// model the adaptation applied. Modes (manual, tracking) do not change
    /// the loop that returns.
    fn find_loop_change(
        events: &[crate::sim::Operation],
        result: &SimResult,
    ) -> Option<(f64, &'static str)> {
        use crate::sim::Action;
        let event = events
            .iter()
            .filter_map(|e| {
                let what = match e.action {
                    Action::PlantGain(_) | Action::PlantLag(_) | Action::PlantDeadTime(_) => {
                        "the process drifts"
                    }
                    Action::DeadTime(_) | Action::DeadTimeRamp(..) => {
                        "the controller's dead time changes"
                    }
                    Action::Retune(..) => "the controller is retuned",
                    Action::Manual(_) | Action::Track(_) | Action::Auto | Action::Adapt(_) => {
                        return None
                    }
                };
                Some((e.at, what))
            })
            .fold(None, |first: Option<(f64, &str)>, e| match first {
                Some(f) if f.0 <= e.0 => Some(f),
                _ => Some(e),
            });
        // the adaptation's log: the first model it put in (an alarm or a
        // refusal leaves the loop as it is)
        let adapted = report::adaptation_log(result)
            .into_iter()
            .find(|c| {
                matches!(
                    c.kind,
                    crate::adapt::ChangeKind::Applied | crate::adapt::ChangeKind::Restored
                )
            })
            .map(|c| (c.at, "the adaptation applies a model"));
        match (event, adapted) {
            (Some(e), Some(a)) => Some(if a.0 < e.0 { a } else { e }),
            (e, a) => e.or(a),
        }
    }

    /// [`RunOutput::analyse`] with `settled` (the loop as built came to
    /// rest and did not diverge: [`RunOutput::settled_as_built`]; `None`: no
    /// simulation to compare) given: the signals are not read.
    pub fn analyse_settled(&mut self, settled: Option<bool>) {
        let tuned = match registry::find(self.controller) {
            Ok(scheme) => Tuned {
                scheme,
                params: self.params.clone(),
                lambda_chosen: self.lambda_chosen,
                target: self.target.clone(),
            },
            Err(e) => {
                self.stability = crate::analysis::Stability::unknown(e.to_string());
                return;
            }
        };
        let (stability, robust) =
            self.scenario
                .loop_analysis(&tuned, &self.plant, &self.model, self.inner.as_ref());
        self.apply_analysis(stability, robust, settled);
    }

    /// The loop's verdict and robustness into the run, the verdict
    /// cross-checked by it (`settled`), and what they warn of into its notes.
    fn apply_analysis(
        &mut self,
        stability: crate::analysis::Stability,
        robust: Option<Robustness>,
        settled: Option<bool>,
    ) {
        if let Some(r) = robust {
            self.notes.extend(r.warnings);
            if let (Some((at, what)), true) = (
                self.loop_change,
                r.margins.gm.is_finite() || r.margins.pm.is_finite(),
            ) {
                self.notes.push(std::format!(
                    "the robustness margins are the loop's as built: at {} s {what}, and they do not cover the loop after that",
                    crate::poly::fmt_num(crate::poly::round_sig(at, 3))
                ));
            }
            self.robustness = Some(r.margins);
        }
        self.stability = self.cross_checked(stability, settled);
        if self.stability.stable == Some(false) && self.result.diverged_at.is_none() {
            self.notes.push(std::format!(
                "the closed loop with {} is unstable: {}",
                self.controller,
                self.stability.reason
            ));
        }
    }

    /// The controller's dead time: the model's, plus the secondary model's for
    /// a cascade process (the delay of the delayed-reference metrics).
    pub fn model_delay(&self) -> f64 {
        self.model.delay + self.inner.as_ref().map_or(0.0, |(_, m)| m.delay)
    }
    /// The whole model from the plant input: `model`, or `model·inner model`.
    pub fn whole_model(&self) -> TransferFunction {
        match &self.inner {
            Some((_, m2)) => self.model.series(m2).unwrap_or_else(|_| self.model.clone()),
            None => self.model.clone(),
        }
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
        items.par_iter().map(f).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        items.iter().map(f).collect()
    }
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
        use crate::sim::Action;
        for e in &self.events {
            crate::real::non_negative(e.at, "event time")?;
            match e.action {
                Action::Manual(v) | Action::Track(v) => {
                    crate::real::finite(v, "event value")?;
                }
                Action::DeadTime(d) | Action::PlantDeadTime(d) => {
                    crate::real::non_negative(d, "event dead time")?;
                }
                Action::PlantGain(k) => {
                    crate::real::finite(k, "event plant gain")?;
                    if k == 0.0 {
                        return Err(RunError::Invalid(Error::OutOfRange(
                            "event plant gain: not zero",
                        )));
                    }
                }
                Action::PlantLag(tau) => {
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

    /// Tunes, builds and simulates; the output carries the tuned loop's
    /// robustness ([`Scenario::robustness`]).
    pub fn run(&self) -> Result<RunOutput, RunError> {
        self.run_deferring(true, true)
    }

    /// [`Scenario::run`] without the loop's analysis: the simulation, its
    /// metrics and the design, but no stability verdict and no robustness
    /// figures (`stability` says they were not computed, `robustness` is
    /// `None`) — for a caller that reads them later, or never
    /// ([`RunOutput::analyse`] adds them, as `run` would have).
    pub fn run_unanalysed(&self) -> Result<RunOutput, RunError> {
        self.run_deferring(true, false)
    }

    /// [`Scenario::run_unanalysed`] that also leaves the metrics and the
    /// event figures of a run of a given duration for later
    /// ([`RunOutput::measure`]): the simulation and the design only, the
    /// figures NaN and `events` empty until measured. What Python's
    /// `msp.run` computes before it returns.
    pub fn run_unmeasured(&self) -> Result<RunOutput, RunError> {
        self.run_deferring(false, false)
    }

    fn run_deferring(&self, measure: bool, analyse: bool) -> Result<RunOutput, RunError> {
        let (plant, model) = self.plant_and_model()?;
        let inner = self.inner_process()?;
        let tuned = self.tune_for(&model, inner.as_ref().map(|(_, m)| m))?;
        // the analysis before the simulation: its own runs (the advice's
        // priced alternatives) do not need memory beside the recorded columns
        let analysis = analyse.then(|| self.loop_analysis(&tuned, &plant, &model, inner.as_ref()));
        let mut out =
            if self.setpoint.is_empty() && self.disturbance.is_empty() && self.duration.is_none() {
                self.run_default_protocol(&tuned, &plant, &model, &inner)?
            } else {
                self.run_tuned_measured(
                    &tuned,
                    plant,
                    model,
                    inner,
                    if measure {
                        Keep::Measured
                    } else {
                        Keep::Signals
                    },
                )?
            };
        out.scenario = self.clone();
        out.design = tuned.scheme.design_report(
            &out.params,
            &out.model,
            out.inner.as_ref().map(|(_, m)| m),
            out.ts,
        )?;
        out.stability = crate::analysis::Stability::unknown("not analysed");
        if let Some((stability, robust)) = analysis {
            let settled = out.settled_as_built(&out.result.t, &out.result.y);
            out.apply_analysis(stability, robust, settled);
        }
        Ok(out)
    }

    /// The tuned loop's stability verdict and, for a single loop, its
    /// robustness (margins and what they warn of).
    pub(crate) fn loop_analysis(
        &self,
        tuned: &Tuned,
        plant: &TransferFunction,
        model: &TransferFunction,
        inner: Option<&(TransferFunction, TransferFunction)>,
    ) -> (crate::analysis::Stability, Option<Robustness>) {
        let stability = crate::analysis::tuned_stability(self, tuned, plant, model, inner);
        let robust = match (inner, stability.stable) {
            // an unstable loop has no margins: the verdict says why
            (None, Some(false)) => Some(Robustness {
                margins: crate::analysis::Margins::unstable(),
                warnings: Vec::new(),
            }),
            (None, _) => self.robustness(tuned, plant, model),
            (Some(_), _) => None,
        };
        (stability, robust)
    }

    /// The processes, the tuned controller and, for a single loop, its
    /// robustness: what [`Scenario::run`] and [`Scenario::tune_report`] start from.
    #[allow(clippy::type_complexity)]
    pub(crate) fn tuned_loop(
        &self,
    ) -> Result<
        (
            TransferFunction,
            TransferFunction,
            Option<(TransferFunction, TransferFunction)>,
            Tuned,
            Option<Robustness>,
            crate::analysis::Stability,
        ),
        RunError,
    > {
        let (plant, model) = self.plant_and_model()?;
        let inner = self.inner_process()?;
        let tuned = self.tune_for(&model, inner.as_ref().map(|(_, m)| m))?;
        let (stability, robust) = self.loop_analysis(&tuned, &plant, &model, inner.as_ref());
        Ok((plant, model, inner, tuned, robust, stability))
    }

    /// The default scenario of a run that names no set point, disturbance or
    /// duration, the protocol of Bag (2022) ch. 5: a unit set-point step at
    /// 0 s, then, once its response has settled, a step load at the plant
    /// input (`−0.2/K` for a plant of gain `K`, a fifth of the step at the
    /// output in steady state; `−0.02/Kv` for an integrator `Kv/s`, the
    /// thesis's −0.1 on `0.2/s`), and a duration that ends soon after the
    /// load is rejected.
    /// The load comes at a round time after 1.25 settling times, the run ends
    /// at a round time after 1.25 recovery times (each found from a probe
    /// run); a loop that does not settle runs as the plain set-point step.
    fn run_default_protocol(
        &self,
        tuned: &Tuned,
        plant: &TransferFunction,
        model: &TransferFunction,
        inner: &Option<(TransferFunction, TransferFunction)>,
    ) -> Result<RunOutput, RunError> {
        let mut sc = self.clone();
        sc.setpoint = std::vec![SetpointStep {
            value: 1.0,
            at: 0.0
        }];
        let run = |sc: &Scenario| sc.run_tuned(tuned, plant.clone(), model.clone(), inner.clone());
        let first = run(&sc)?;
        let settle = first.metrics.step.settling_time;
        let whole = match inner {
            Some((p2, _)) => plant.series(p2)?,
            None => plant.clone(),
        };
        let Some(load) = default_load(&whole) else {
            return Ok(first);
        };
        if first.result.diverged_at.is_some() || !settle.is_finite() {
            return Ok(first);
        }
        let at = nice_ceil(1.25 * settle.max(first.ts));
        // operator events of the scenario stay inside every run of the
        // protocol: the first run's chosen duration covers the last of them
        let cover = |d: f64| {
            if self.events.is_empty() {
                d
            } else {
                d.max(first.duration)
            }
        };
        sc.disturbance = std::vec![crate::sim::Disturbance::input_step(load, at)];
        // probes: the load's segment as long as the set point needed, doubled
        // until the load is rejected
        let mut span = first.duration.max(2.0 * settle);
        let mut recovery = f64::NAN;
        for _ in 0..4 {
            sc.duration = Some(cover(at + span));
            let Ok(probe) = run(&sc) else {
                return Ok(first);
            };
            recovery = probe
                .events
                .iter()
                .find_map(|e| match e {
                    metrics::Event::Disturbance(d) => Some(d.recovery_time),
                    metrics::Event::Setpoint(_) => None,
                })
                .unwrap_or(f64::NAN);
            if probe.result.diverged_at.is_some() {
                return Ok(first);
            }
            if recovery.is_finite() && recovery < 0.8 * span {
                break;
            }
            span *= 2.0;
        }
        if !recovery.is_finite() {
            return Ok(first);
        }
        sc.duration = Some(cover(nice_ceil(at + 1.25 * recovery.max(settle))));
        let Ok(mut out) = run(&sc) else {
            return Ok(first);
        };
        out.duration_chosen = true;
        out.default_scenario = true;
        Ok(out)
    }

    /// [`Scenario::run`] with a controller already tuned (`tuned`) and the
    /// processes given: the scenario's plants, `controller`, `lambda`, `rule`
    /// and `set` are not read.
    ///
    /// A duration the scenario does not give is chosen from the plant
    /// ([`choose_duration`]) and, when the output has not come to rest by
    /// then, doubled up to four times (within the memory budget); a run
    /// that still has not settled says so in its warnings.
    pub fn run_tuned(
        &self,
        tuned: &Tuned,
        plant: TransferFunction,
        model: TransferFunction,
        inner: Option<(TransferFunction, TransferFunction)>,
    ) -> Result<RunOutput, RunError> {
        self.run_tuned_measured(tuned, plant, model, inner, Keep::Measured)
    }

    /// [`Scenario::run_tuned`] keeping `keep` (with a duration given: a
    /// chosen one needs the figures to know the run has settled).
    pub(crate) fn run_tuned_measured(
        &self,
        tuned: &Tuned,
        plant: TransferFunction,
        model: TransferFunction,
        inner: Option<(TransferFunction, TransferFunction)>,
        keep: Keep,
    ) -> Result<RunOutput, RunError> {
        // a chosen duration is extended until the run settles: measured
        let keep = if self.duration.is_none() {
            Keep::Measured
        } else {
            keep
        };
        let mut out = self.run_once(tuned, plant.clone(), model.clone(), inner.clone(), keep)?;
        if self.duration.is_some() {
            return Ok(out);
        }
        let mut longer = self.clone();
        for _ in 0..4 {
            if out.result.diverged_at.is_some() || out.has_settled() {
                return Ok(out);
            }
            longer.duration = Some(out.duration * 2.0);
            match longer.run_once(tuned, plant.clone(), model.clone(), inner.clone(), keep) {
                Ok(mut o) => {
                    o.duration_chosen = true;
                    out = o;
                }
                // beyond the memory budget: keep the run there is
                Err(_) => break,
            }
        }
        if out.result.diverged_at.is_none() && !out.has_settled() {
            out.notes.push(std::format!(
                "the output had not settled after {} s (the chosen duration, extended); give --duration (Python: duration=) to run longer",
                crate::poly::fmt_num(out.duration)
            ));
        }
        Ok(out)
    }

    /// One run of [`Scenario::run_tuned`] at the scenario's duration (or the
    /// one chosen from the plant).
    fn run_once(
        &self,
        tuned: &Tuned,
        plant: TransferFunction,
        model: TransferFunction,
        inner: Option<(TransferFunction, TransferFunction)>,
        keep: Keep,
    ) -> Result<RunOutput, RunError> {
        let measure = keep == Keep::Measured;
        let built = self.build_tuned(tuned, &model, inner.as_ref().map(|(_, m)| m))?;
        let (scheme, params, mut ctrl, ts, ts_chosen) = (
            built.scheme,
            built.params,
            built.controller,
            built.ts,
            built.ts_chosen,
        );
        let (u_min, u_max) = (built.u_min, built.u_max);
        let (duration, duration_chosen) = match self.duration {
            Some(d) => {
                let d = crate::real::positive(d, "duration")?;
                self.check_duration_covers(d)?;
                (d, false)
            }
            // the plant's settling, or twenty closed-loop time constants λ
            // where the loop is slower (a delay-free integrator has no time
            // constant of its own)
            None => (
                choose_duration(
                    &match &inner {
                        Some((p2, _)) => plant.series(p2)?,
                        None => plant.clone(),
                    },
                    ts,
                )
                .max(
                    20.0 * tuned
                        .params
                        .lambda()
                        .filter(|l| l.is_finite())
                        .unwrap_or(0.0),
                ),
                true,
            ),
        };
        // the chosen duration covers settling from a step at 0: from the last
        // thing scheduled as well
        let duration = match (duration_chosen, self.last_scheduled()) {
            (true, Some((at, _))) if at > 0.0 => at + duration,
            _ => duration,
        };
        let substeps = self.substeps.unwrap_or(1);
        if substeps == 0 || substeps > 1000 {
            return Err(RunError::Invalid(Error::OutOfRange("substeps")));
        }
        // the plant's delay lines and the recorded signals, before they are allocated
        let model_samples = (model.delay + inner.as_ref().map_or(0.0, |(_, m)| m.delay))
            .max(self.event_dead_time(false))
            / ts;
        let plant_samples = (plant.delay + inner.as_ref().map_or(0.0, |(p, _)| p.delay))
            .max(self.event_dead_time(true))
            / ts;
        self.check_operation()?;
        #[allow(clippy::cast_precision_loss)] // at most 1000
        let rows = (duration / ts + 1.0) * substeps as f64;
        // each scheduled item is held several times over (the schedule, the
        // scenario and the report's copies, the event figures)
        #[allow(clippy::cast_precision_loss)]
        let items = (self.setpoint.len() + self.disturbance.len() + self.events.len()) as f64;
        self.within_budget(
            model_samples * CONTROLLER_BYTES_PER_SAMPLE
                + plant_samples * PLANT_BYTES_PER_SAMPLE
                + rows * BYTES_PER_ROW
                + items * BYTES_PER_SCHEDULED,
            &std::format!(
                "{} scheduled steps and events, {} recorded rows ({} s at ts = {} s{}) and {} samples of dead time",
                items,
                crate::poly::fmt_num(rows.ceil()),
                crate::poly::fmt_num(duration),
                crate::poly::fmt_num(ts),
                if substeps > 1 {
                    std::format!(", {substeps} substeps")
                } else {
                    String::new()
                },
                crate::poly::fmt_num(plant_samples.ceil())
            ),
        )?;
        let setpoint = if self.setpoint.is_empty() {
            std::vec![SetpointStep {
                value: 1.0,
                at: 0.0
            }]
        } else {
            self.setpoint.clone()
        };
        for s in &setpoint {
            crate::real::finite(s.value, "setpoint")?;
            crate::real::non_negative(s.at, "setpoint")?;
        }
        for d in &self.disturbance {
            crate::real::finite(d.value, "disturbance")?;
            crate::real::non_negative(d.at, "disturbance")?;
            crate::real::non_negative(d.freq, "disturbance")?;
        }
        let cfg = SimConfig {
            ts,
            duration,
            setpoint: setpoint.clone(),
            disturbances: self.disturbance.clone(),
            noise: crate::real::non_negative(self.noise.unwrap_or(0.0), "noise")?,
            seed: self.seed.unwrap_or(0),
            quantization: crate::real::non_negative(
                self.quantization.unwrap_or(0.0),
                "quantization",
            )?,
            u_min,
            u_max,
            substeps,
            record: if keep == Keep::Output {
                crate::sim::Record::OutputAndInput
            } else {
                crate::sim::Record::All
            },
            operations: self.events.clone(),
            actuator: self.actuator,
            reset_feedback: self.reset_feedback,
            setpoint_ramp: self.setpoint_ramp.unwrap_or(f64::INFINITY),
        };
        let result = match &inner {
            Some((p2, _)) => simulate_cascade(&plant, p2, &mut ctrl, &cfg)?,
            None => {
                // into the buffers a finished run on this thread gave back
                // (a sweep's rows): memory already mapped
                let mut res = spare();
                crate::sim::simulate_into(&plant, &mut ctrl, &cfg, &mut res)?;
                res
            }
        };
        let model_delay = model.delay + inner.as_ref().map_or(0.0, |(_, m)| m.delay);
        let nan = metrics::Metrics {
            indices: crate::metrics::Indices {
                iae: f64::NAN,
                ise: f64::NAN,
                itae: f64::NAN,
                itse: f64::NAN,
                tv: f64::NAN,
            },
            step: crate::metrics::step_info(&[], &[], 0.0, f64::NAN, 0.0),
        };
        let (m0, m1, events) = if measure {
            metrics::measure(
                &result.columns(),
                &setpoint,
                &self.disturbance,
                ts,
                model_delay,
            )?
        } else {
            (nan, nan, Vec::new())
        };
        let loop_change = RunOutput::find_loop_change(&self.events, &result);
        Ok(RunOutput {
            loop_change,
            plant,
            model,
            inner,
            ts,
            ts_chosen,
            duration,
            duration_chosen,
            lambda_chosen: tuned.lambda_chosen,
            target: tuned.target.clone(),
            controller: scheme,
            params,
            result,
            metrics: m0,
            metrics_delayed_reference: m1,
            setpoint,
            disturbance: self.disturbance.clone(),
            float32: self.float32,
            events,
            default_scenario: false,
            scenario: self.clone(),
            notes: Vec::new(),
            robustness: None,
            stability: crate::analysis::Stability::unknown(
                "the run was not analysed (a run by Scenario::run is)",
            ),
            design: Vec::new(),
        })
    }
}

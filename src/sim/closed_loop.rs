//! The closed loop: a controller against the exact sampled process.

use std::vec::Vec;

use super::cascade::JointSim;
use super::drift::PlantParameter;
use super::engine::{self, Flags, Run};
use super::plant::PlantSim;
use super::result::Columns;
use super::schedule::{first_sample_at, Track};
use super::{Disturbance, Location, SetpointStep, SimResult};
use crate::poly::TransferFunction;
use crate::Error;
use crate::{CascadeControl, Introspect, Operate};

/// Settings of one closed-loop simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// Sample period (s).
    pub ts: f64,
    /// Length of the run (s).
    pub duration: f64,
    /// Set-point profile.
    pub setpoint: Vec<SetpointStep>,
    /// Disturbances.
    pub disturbances: Vec<Disturbance>,
    /// Standard deviation of Gaussian measurement noise.
    pub noise: f64,
    /// Seed of the noise generator.
    pub seed: u64,
    /// The measurement's resolution (an ADC's least significant bit): the
    /// controller sees the noisy output rounded to a multiple of it; 0: none.
    pub quantization: f64,
    /// Actuator lower limit.
    pub u_min: f64,
    /// Actuator upper limit.
    pub u_max: f64,
    /// Plant outputs per controller period (1: at the samples only; more for
    /// smooth intersample plots).
    pub substeps: usize,
    /// Which signals are recorded.
    pub record: Record,
    /// What an operator does during the run (modes, dead-time changes).
    pub operations: Vec<Operation>,
    /// An actuator limit outside the controller (the controller does not
    /// know it): the plant receives the controller's output clamped to it.
    pub actuator: Option<(f64, f64)>,
    /// The value the plant received is fed back to the controller each
    /// sample (external reset, [`crate::Operate::apply`]).
    pub reset_feedback: bool,
    /// The controller's set point moves to the scheduled one by at most this
    /// much per second (industrial blocks' set-point ramp); ∞: steps.
    pub setpoint_ramp: f64,
}

/// An operator's action at a time of the run.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Operation {
    /// When (s).
    pub at: f64,
    /// What.
    pub action: Action,
}

/// What an operator does ([`Operation`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum Action {
    /// Manual mode with this output.
    Manual(f64),
    /// The output follows this value.
    Track(f64),
    /// Back to automatic.
    Auto,
    /// The controller's model is given this dead time (s).
    DeadTime(f64),
    /// The controller's model's dead time moves to the first value (s) at
    /// the second rate (seconds of dead time per second).
    DeadTimeRamp(f64, f64),
    /// The process's dead time becomes this (s): for a cascade process the
    /// one from the plant input to `y` (`L1 + L2`), the primary's changing.
    PlantDeadTime(f64),
    /// The process's static gain becomes this (the velocity gain of an
    /// integrating process): its input gain changes, its output does not
    /// jump.
    PlantGain(f64),
    /// The process's time constant becomes this (s), for a plant with one
    /// lag (`K/(τs + 1)`, behind its dead time); its output does not jump.
    PlantLag(f64),
    /// The process drifts: the parameter moves to the value (its units; a
    /// dead time in s) at the rate (those units per second), from the next
    /// sample on (see [`PlantParameter`]).
    PlantDrift(PlantParameter, f64, f64),
    /// An adaptive controller's adaptation resumes (`true`) or freezes.
    Adapt(bool),
    /// A gain of the controller's primary PID changes (bumpless).
    Retune(crate::operate::Gain, f64),
}

/// Which signals a run records. Time, the output `y` and the actuator `u`
/// (and `y2` of a cascade) are always recorded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Record {
    /// Every signal: also the set point, the disturbances and the
    /// controller's internal signals.
    #[default]
    All,
    /// `t`, `y`, `u` (and `y2`) only: the other columns of the result stay
    /// empty. The fastest form, for sweeps and Monte Carlo runs.
    OutputAndInput,
}

impl SimConfig {
    /// A run of `duration` seconds sampled every `ts`: no set point (add steps
    /// to `setpoint`), no disturbance, no noise, no limits, no sub-steps.
    pub fn new(ts: f64, duration: f64) -> Self {
        SimConfig {
            ts,
            duration,
            setpoint: Vec::new(),
            disturbances: Vec::new(),
            noise: 0.0,
            seed: 0,
            quantization: 0.0,
            u_min: f64::NEG_INFINITY,
            u_max: f64::INFINITY,
            substeps: 1,
            record: Record::All,
            operations: Vec::new(),
            actuator: None,
            reset_feedback: false,
            setpoint_ramp: f64::INFINITY,
        }
    }
}

/// A seeded Gaussian generator (SplitMix64 + Box–Muller), reproducible everywhere.
#[derive(Debug, Clone)]
pub struct Noise {
    state: u64,
    spare: Option<f64>,
}

impl Noise {
    /// A generator with this seed.
    pub fn new(seed: u64) -> Self {
        Noise {
            state: seed,
            spare: None,
        }
    }
    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// A uniform sample in (0, 1).
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    /// A standard normal sample.
    pub fn gaussian(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = core::f64::consts::TAU * u2;
        self.spare = Some(r * a.sin());
        r * a.cos()
    }
}

/// The process as simulated: one plant, or a cascade (García et al. (2010)
/// Fig. 1). With `v = u + d2` held over each period and `d0` held too,
/// `y2 = P2 e^{−L2 s}·v + d0` (its own block) and
/// `y = P1 e^{−L1 s}(P2 e^{−L2 s}·v + d0) + d1` ([`JointSim`]), both sampled exactly.
pub(super) enum Process {
    Single(PlantSim),
    Cascade {
        p2: PlantSim,
        joint: Box<JointSim>,
        sub2: Vec<f64>,
    },
}

impl Process {
    pub(super) fn set_dead_time(&mut self, samples: f64) -> Result<(), Error> {
        match self {
            Process::Single(p) => p.set_dead_time(samples),
            Process::Cascade { joint, .. } => joint.set_dead_time(samples),
        }
    }

    /// The process's gain becomes `k` (a single plant's).
    pub(super) fn set_gain(&mut self, k: f64) -> Result<(), Error> {
        match self {
            Process::Single(p) => p.set_gain(k),
            Process::Cascade { .. } => Err(Error::Unsupported(CASCADE_DRIFT)),
        }
    }

    /// The process's time constant becomes `tau` (a single plant's).
    pub(super) fn set_lag(&mut self, tau: f64) -> Result<(), Error> {
        match self {
            Process::Single(p) => p.set_lag(tau),
            Process::Cascade { .. } => Err(Error::Unsupported(CASCADE_DRIFT)),
        }
    }
}

const CASCADE_DRIFT: &str =
    "plant-gain and plant-lag events change a single plant, not a cascade process";

impl Process {
    /// The process's dead time (samples), gain or lag now.
    pub(super) fn parameter(&self, what: PlantParameter) -> Result<f64, Error> {
        match (self, what) {
            (Process::Single(p), PlantParameter::DeadTime) => Ok(p.dead_time()),
            (Process::Cascade { joint, .. }, PlantParameter::DeadTime) => Ok(joint.dead_time()),
            (Process::Single(p), PlantParameter::Gain) => Ok(p.gain()),
            (Process::Single(p), PlantParameter::Lag) => p.lag(),
            (Process::Cascade { .. }, _) => Err(Error::Unsupported(CASCADE_DRIFT)),
        }
    }
}

/// A schedule `(time, item)` as `(first sample, item)` in time order (ties
/// keep their order).
fn by_sample<T>(items: impl Iterator<Item = (f64, T)>, ts: f64) -> Vec<(usize, T)> {
    let mut v: Vec<(usize, T)> = items.map(|(at, x)| (first_sample_at(at, ts), x)).collect();
    v.sort_by_key(|e| e.0);
    v
}

/// Runs the closed loop of `controller` on `plant`.
///
/// The plant is simulated exactly at the sample instants (its ZOH
/// equivalent, the dead time as whole samples of delay): a PI with
/// `Kp·K = 1`, `Ti = T` on `K/(Ts + 1)` makes the loop `1/(T s + 1)`, whose
/// samples `1 − e^{−kTs/T}` the run reproduces to rounding.
///
/// ```
/// use msp::sim::{simulate, SetpointStep, SimConfig};
/// let plant: msp::poly::TransferFunction = "2/(4s+1)".parse()?;
/// let mut pi = msp::Pid::new(msp::PidConfig::isa(0.5, 4.0, 0.0, 0.1))?;
/// let cfg = SimConfig {
///     setpoint: vec![SetpointStep { value: 1.0, at: 0.0 }],
///     ..SimConfig::new(0.1, 20.0)
/// };
/// let res = simulate(&plant, &mut pi, &cfg)?;
/// let (t, y) = (res.t[100], res.y[100]); // 10 s
/// assert!((y - (1.0 - (-t / 4.0f64).exp())).abs() < 0.02, "{y}");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn simulate<C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized>(
    plant: &TransferFunction,
    controller: &mut C,
    cfg: &SimConfig,
) -> Result<SimResult, Error> {
    let mut res = SimResult::default();
    simulate_process(plant, None, controller, cfg, &mut res)?;
    Ok(res)
}

/// [`simulate`] into the buffers of an earlier result: its columns are
/// overwritten and keep their allocations, so repeated runs (sweeps, Monte
/// Carlo, benchmarks) write to memory that is already mapped. On an error
/// `out` is left empty.
pub fn simulate_into<C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized>(
    plant: &TransferFunction,
    controller: &mut C,
    cfg: &SimConfig,
    out: &mut SimResult,
) -> Result<(), Error> {
    let done = simulate_process(plant, None, controller, cfg, out);
    if done.is_err() {
        out.clear();
    }
    done
}

/// Runs the closed loop of `controller` on the cascade process: primary
/// `p1` (with its dead time `L1`) fed by the secondary `p2` (dead time `L2`),
/// whose output `y2` the controller also receives
/// ([`CascadeControl::update_cascade`]). Disturbances at [`Location::Input`] act
/// at the input of `p2` (`d2`), at [`Location::Inner`] on `y2` (`d0`), at
/// [`Location::Output`] on `y` (`d1`).
pub fn simulate_cascade<C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized>(
    p1: &TransferFunction,
    p2: &TransferFunction,
    controller: &mut C,
    cfg: &SimConfig,
) -> Result<SimResult, Error> {
    let mut res = SimResult::default();
    simulate_process(p1, Some(p2), controller, cfg, &mut res)?;
    Ok(res)
}

/// Prepares the run (checks, the process, the schedules as sample indices)
/// and runs the loop compiled for it ([`super::engine`]). The columns of an
/// earlier result are sized in place: memory a reused result already holds
/// is written once, by the run.
fn simulate_process<C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized>(
    plant: &TransferFunction,
    inner: Option<&TransferFunction>,
    controller: &mut C,
    cfg: &SimConfig,
    res: &mut SimResult,
) -> Result<(), Error> {
    let ts = crate::real::positive(cfg.ts, "ts")?;
    let duration = crate::real::non_negative(cfg.duration, "duration")?;
    crate::real::non_negative(cfg.noise, "noise")?;
    crate::real::non_negative(cfg.quantization, "quantization")?;
    if cfg.u_min > cfg.u_max {
        return Err(Error::InvalidLimits("u_min"));
    }
    if cfg.setpoint_ramp.is_nan() || cfg.setpoint_ramp <= 0.0 {
        return Err(Error::NotPositive("setpoint_ramp"));
    }
    let steps = num_traits::ToPrimitive::to_usize(&(duration / ts).round())
        .ok_or(Error::OutOfRange("duration"))?;
    let n = steps.saturating_add(1);
    let m = cfg.substeps.max(1);
    let n_rows = n.saturating_mul(m);
    // room in the plant's line for the longest dead time an event sets
    let plant_room = cfg
        .operations
        .iter()
        .filter_map(|o| match o.action {
            Action::PlantDeadTime(d) | Action::PlantDrift(PlantParameter::DeadTime, d, _) => {
                Some(d)
            }
            _ => None,
        })
        .fold(0.0, f64::max);
    let process = match inner {
        None => Process::Single(PlantSim::with_room(plant, ts, m, plant_room)?),
        Some(p2) => Process::Cascade {
            p2: PlantSim::new(p2, ts, m)?,
            joint: Box::new(JointSim::with_room(plant, p2, ts, m, plant_room)?),
            sub2: Vec::with_capacity(m),
        },
    };
    let cascade = inner.is_some();
    let all = cfg.record == Record::All;
    res.substeps = m;
    // each location's disturbances as events at their first sample: a
    // schedule of 10⁶ steps costs one comparison per segment, not 10⁶
    let track =
        |loc: Location| Track::new(cfg.disturbances.iter().filter(|d| d.location == loc), ts);
    let (inputs, outputs, middles) = (
        track(Location::Input),
        track(Location::Output),
        track(Location::Inner),
    );
    if !cascade && !middles.is_empty() {
        return Err(Error::Unsupported(
            "an 'inner' (d0) disturbance needs a cascade process (an inner plant)",
        ));
    }
    let scale = cfg
        .setpoint
        .iter()
        .map(|s| s.value.abs())
        .chain(cfg.disturbances.iter().map(|d| d.value.abs()))
        .fold(1.0, f64::max);
    let ops = by_sample(cfg.operations.iter().map(|o| (o.at, o.action)), ts);
    // a run without an operator pays nothing for one, a plain run nothing
    // for sub-steps, noise or a cascade: the loop is compiled for each
    let operated = !cfg.operations.is_empty()
        || cfg.actuator.is_some()
        || cfg.reset_feedback
        || cfg.setpoint_ramp != f64::INFINITY;
    let applies = !ops.is_empty() || cfg.actuator.is_some();
    let columns = Columns {
        cascade,
        all,
        applied: operated && applies,
        d_inner: !middles.is_empty(),
    };
    let zeroed = res.size(controller.signal_names(), n_rows, columns)?;
    let mut run = Run {
        n,
        m,
        process,
        sub: Vec::with_capacity(m),
        noise: Noise::new(cfg.seed),
        inputs,
        outputs,
        middles,
        steps: by_sample(cfg.setpoint.iter().map(|s| (s.at, s.value)), ts),
        ops,
        flags: Flags {
            ts,
            bound: 1e6 * scale,
            columns,
            ramp: cfg.setpoint_ramp * ts,
            applies,
            limited: cfg.u_min > f64::NEG_INFINITY || cfg.u_max < f64::INFINITY,
        },
        zeroed,
    };
    let plain = run.is_plain(cfg);
    let rows = match (operated, plain) {
        (true, true) => engine::samples::<C, true, true>(&mut run, controller, cfg, res),
        (true, false) => engine::samples::<C, true, false>(&mut run, controller, cfg, res),
        (false, true) => engine::samples::<C, false, true>(&mut run, controller, cfg, res),
        (false, false) => engine::samples::<C, false, false>(&mut run, controller, cfg, res),
    };
    res.truncate(rows?);
    Ok(())
}

//! What a closed-loop simulation is given: its settings ([`SimConfig`]),
//! the operator's actions and the process parameters they move, the
//! measurement noise, and the process itself (one plant, or a cascade's
//! two): the types the engine, the drifts and the front door share, below
//! them all.

use std::boxed::Box;
use std::vec::Vec;

use super::cascade::JointSim;
use super::plant::PlantSim;
use super::{Disturbance, SetpointStep};
use crate::error::Error;

/// The process parameter a drift moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum PlantParameter {
    /// The dead time (s; the rate in seconds of dead time per second).
    DeadTime,
    /// The static gain (the velocity gain of an integrating process).
    Gain,
    /// The time constant of a plant with one lag (s; the rate in s/s).
    Lag,
}

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
    /// The controller's background work runs between samples, as a
    /// device's background task would: [`crate::Operate::design`] after
    /// each update (an adaptive controller with
    /// [`crate::adapt::AdaptiveConfig::background_design`]).
    pub background: bool,
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
            background: false,
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

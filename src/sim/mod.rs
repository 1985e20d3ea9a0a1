//! The exact sampled-data closed-loop simulator and the scenario that drives it.
//!
//! The controller runs every `Ts`. The plant's rational part is discretized
//! by zero-order hold at `Ts` — exact at the sample instants for the held
//! actuator value — and its dead time `θ = (k + f)·Ts` is handled exactly: the
//! plant input is the held value delayed by `θ`, so over each period it takes
//! the value `v[n−k−1]` for the first `f·Ts` and `v[n−k]` for the rest; the
//! simulator integrates the two pieces with ZOH discretizations at `f·Ts` and
//! `(1−f)·Ts` (the modified z-transform). Figures from `msp` are therefore the
//! sampled loop's own, not an integrator's error.
//!
//! Disturbances are sampled and held like the actuator (exact for steps at
//! sample instants; ramps and sines are held over each period). Output
//! disturbances and measurement noise are added at the sample instants.
//!
//! The engine takes typed values only: a plant as a [`TransferFunction`], any
//! [`Controller`], and the schedules of [`SimConfig`]. It never parses text and
//! never tunes; the study layer ([`crate::study`]) does that and calls it.
//!
//! [`TransferFunction`]: crate::poly::TransferFunction
//! [`Controller`]: crate::Controller

mod cascade;
mod closed_loop;
mod config;
mod defaults;
mod drift;
mod engine;
mod mimo;
mod plant;
mod result;
mod schedule;

pub use cascade::CascadeStepper;
pub use closed_loop::{simulate, simulate_cascade, simulate_into};
pub use config::{Action, Noise, Operation, PlantParameter, Record, SimConfig};
pub(crate) use defaults::f32_note;
pub use defaults::{
    choose_duration, choose_ts, choose_ts_as, describe_ts, kind_of, F32_POLE_DISTANCE,
    MAX_CHOSEN_SAMPLES,
};
pub use mimo::{
    simulate_mimo, ChannelDeadTime, DisturbanceVector, LoopLoad, LoopMode, MimoEvents, MimoRun,
};
pub use plant::{open_loop, PlantStepper};
pub use result::SimResult;
pub(crate) use schedule::first_sample_at;
pub use schedule::{setpoint_at, Disturbance, Location, SetpointStep, Shape};

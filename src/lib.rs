//! # msp — dead-time compensation for process control
//!
//! Smith predictors and their modern modifications for stable, integrating and
//! unstable plants, the PID controllers inside them, their tuning, and the tools
//! to simulate and compare them.
//!
//! The core (`delay`, `lti`, `pid`, `model`, `dtc`, `tuning`, `metrics`) is
//! `no_std`, never allocates and never panics: firmware constructs a controller
//! once (every parameter is validated and a typed [`Error`] names the field that
//! is wrong) and then calls [`Controller::update`] once per sample.
//!
//! ```
//! use msp::{Controller, Fopdt, SmithPredictor, tuning};
//!
//! // Plant model 5.6 e^{-93.9 s} / (40.2 s + 1), sampled every 1 s.
//! let model = Fopdt::new(5.6, 40.2, 93.9)?;
//! let pi = tuning::kaya_fopdt(&model, 1.0)?; // Kaya 2003, lambda = L
//! // model order 1, dead time in a 128-sample line stored inline
//! let mut sp: SmithPredictor<f64, 1, [f64; 128]> =
//!     SmithPredictor::from_model(pi.config(1.0), &model.into(), 1.0)?;
//! let u = sp.update(1.0, 0.0); // set point, measurement -> actuator
//! assert!(u > 0.0);
//! # Ok::<(), msp::Error>(())
//! ```
//!
//! The relay experiment of [`autotune`] runs on the device too. Behind
//! features: `alloc` adds the text grammars ([`syntax`]), transfer
//! functions ([`poly`]) and the scheme registry ([`registry`]); `std` (default)
//! adds the exact sampled-data simulator ([`sim`]), the study layer that
//! tunes, builds, runs and compares scenarios ([`study`]), step information
//! ([`metrics::step_info`]), frequency-domain analysis ([`analysis`]), sweeps
//! ([`sweep`], parallel with `parallel`) and identification ([`ident`]).
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![forbid(unsafe_code)]
// Unit tests may unwrap; the library code may not.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing,
        clippy::todo,
        clippy::unimplemented,
        clippy::unreachable,
        clippy::cast_possible_truncation
    )
)]
// Integer arithmetic in `src/` is written with explicit `wrapping_*`/`saturating_*`
// operations where an overflow is conceivable; `clippy::arithmetic_side_effects`
// is not used because it cannot tell the generic float arithmetic (`T: Real`)
// from integer arithmetic.
// `!(x > 0)` is how a check rejects NaN along with the non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

#[cfg(feature = "alloc")]
extern crate alloc;

pub mod adapt;
pub mod autotune;
pub mod complex;
mod controller;
pub mod delay;
pub mod dtc;
mod error;
mod loop_controller;
pub mod lti;
pub mod metrics;
pub mod mimo;
pub mod model;
pub mod operate;
pub mod params;
pub mod pid;
mod real;
#[cfg(test)]
mod test_util;
pub mod tuning;

#[cfg(feature = "std")]
pub mod analysis;
#[cfg(feature = "std")]
pub mod ident;
#[cfg(feature = "alloc")]
pub mod poly;
#[cfg(feature = "alloc")]
pub mod registry;
#[cfg(feature = "std")]
pub mod sim;
#[cfg(feature = "std")]
pub mod study;
#[cfg(feature = "std")]
pub mod sweep;
#[cfg(feature = "alloc")]
pub mod syntax;

pub use complex::Complex;
pub use controller::{CascadeControl, Controller, FrequencyResponse, Introspect};
pub use delay::{Delay, DelayLine, DelayLineRef};
pub use dtc::{KaranDey, SmithPredictor};
pub use error::Error;
pub use loop_controller::{LoopController, Widened};
pub use lti::{Discretization, Lti};
pub use metrics::IntegralIndices;
pub use model::{Foipdt, Fopdt, Ipdt, ProcessModel, Sopdt, Ufopdt};
pub use operate::{Operate, Operated, Tracking};
pub use params::{DesignSet, ParamList, ParamSet};
pub use pid::{AntiWindup, Pid, PidConfig, PidTerms};
pub use real::Real;

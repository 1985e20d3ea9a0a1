//! Dead-time compensators, one module per scheme.
//!
//! Each scheme lives in its own module and is built from the shared blocks:
//! [`crate::Pid`], [`crate::Lti`] and [`DelayedModel`] (the delay-free model
//! and its dead time in a [`crate::Delay`]).

pub mod astrom_hang_lim;
pub mod cascade;
pub mod compensator;
mod delayed_model;
pub mod disturbance_estimator;
pub mod filtered_smith;
pub mod fsp;
pub mod gpcc;
pub mod huang;
pub mod karan_dey;
pub mod kaya_atherton;
pub mod matausek_micic;
mod smith;
pub mod watanabe_ito;

pub use compensator::Compensator;
pub use delayed_model::DelayedModel;
pub use karan_dey::{KaranDey, KaranDeyParams};
pub use smith::SmithPredictor;

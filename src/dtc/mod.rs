//! Dead-time compensators, one module per scheme.
//!
//! Each scheme lives in its own module and is built from the shared blocks:
//! [`crate::Pid`], [`crate::Lti`] (the delay-free model) and [`crate::Delay`]
//! (the model's dead time).

pub mod astrom_hang_lim;
pub mod cascade;
pub mod compensator;
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
pub use karan_dey::{KaranDey, KaranDeyParams};
pub use smith::SmithPredictor;

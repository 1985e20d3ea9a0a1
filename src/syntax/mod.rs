//! Every text grammar of `msp`, in one place, used only at the edges (the
//! command line, scenario files, Python): plant expressions ([`expr`]) and,
//! with `std`, the schedules and perturbations of a run (`1@0`,
//! `input:-0.1@300`, `gain=+10%`) as `FromStr` implementations of the typed
//! values in [`crate::sim`] and [`crate::study`].

pub mod expr;
mod matrix;
#[cfg(feature = "std")]
mod schedule;

pub use expr::{parse_plant, ParseError};
pub use matrix::{parse_column, parse_matrix};
#[cfg(all(feature = "std", feature = "serde"))]
pub use schedule::{exact_pair, text_or_struct};
#[cfg(feature = "std")]
pub use schedule::{
    parse_actuator, parse_assignment, parse_bytes, parse_dead_times, parse_loop_setpoint,
    parse_number, parse_setting,
};

//! The msp controllers for C: `include/msp.h` (generated from this file by
//! cbindgen, see `tests/header.rs`) and a static library `libmsp.a`.
//!
//! The conventions of the C API:
//!
//! - every name starts with `msp_`; `float` entry points are the device's,
//!   the same calls ending in `_f64` take `double`;
//! - memory is the caller's: `msp_<scheme>_size(config, max_dead_time_samples,
//!   &status)` gives the bytes a controller needs (its delay lines included),
//!   `msp_<scheme>_init(buf, len, config, &ctrl)` builds it in `buf` (any
//!   alignment: the controller starts at the first suitably aligned byte).
//!   Nothing is allocated, and `buf` must stay where it is while `ctrl` is
//!   used (the controller points into it);
//! - every failure is an [`msp_status`] with a message from
//!   [`msp_status_str`]: null pointers, a buffer too small, parameters that are
//!   not finite or out of range, a dead time beyond the buffer;
//! - no call can panic or abort: the library is `no_std` with a panic handler
//!   no code path reaches (the release library for `thumbv7em-none-eabihf`
//!   has no panic symbol, checked by `scripts/c`).
#![no_std]
#![allow(non_camel_case_types)]

// a host test links std (and its panic handler); the library itself does not
#[cfg(test)]
extern crate std;

/// Writes each C entry point twice from one body: for `float` as given,
/// and `_f64` for `double`, where every type written `float_type | double_type`
/// takes its second form (the body calls generic functions, which read the
/// precision from the arguments). The twin's documentation points to the
/// `float` entry point. cbindgen reads the expanded crate (`tests/header.rs`).
macro_rules! twins {
    ($(
        $(#[doc = $doc:literal])*
        fn $name:ident, $name64:ident($($arg:ident: $t:ty $(| $t64:ty)?),* $(,)?)
            -> $ret:ty $body:block
    )*) => {$(
        $(#[doc = $doc])*
        #[no_mangle]
        pub unsafe extern "C" fn $name($($arg: $t),*) -> $ret $body

        #[doc = concat!(" [`", stringify!($name), "`] in double precision.")]
        #[doc = ""]
        #[doc = " # Safety"]
        #[doc = concat!(" As [`", stringify!($name), "`].")]
        #[no_mangle]
        pub unsafe extern "C" fn $name64($($arg: twins!(@double $t $(| $t64)?)),*) -> $ret $body
    )*};
    (@double $t:ty) => { $t };
    (@double $t:ty | $t64:ty) => { $t64 };
}

/// Declares a C enumeration: `#[repr(C)]`, each value numbered as
/// written (the numbers are the ABI: a new value takes a new number).
macro_rules! c_enum {
    ($(#[$meta:meta])* $name:ident { $($(#[$vmeta:meta])* $v:ident = $n:literal,)+ }) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum $name { $($(#[$vmeta])* $v = $n,)+ }
    };
}

/// Declares a C configuration struct `name_of<T>` (`#[repr(C)]`, every
/// field public) and its two precisions: `name` in `float` (the device's
/// type) and `name_f64` in `double` (a host's).
macro_rules! c_config {
    (
        $(#[$meta:meta])*
        $generic:ident: $float:ident, $double:ident { $($field:ident: $t:ty,)+ }
    ) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct $generic<T> { $(pub $field: $t,)+ }

        /// In `float`, the device's type.
        pub type $float = $generic<f32>;
        /// In `double`, a host's type.
        pub type $double = $generic<f64>;
    };
}

mod adapt;
mod api;
mod handle;
mod mimo;
mod relay;

use core::ffi::c_char;

pub use adapt::*;
pub use api::*;
pub use handle::*;
pub use mimo::*;
pub use relay::*;

c_enum! {
    /// The result of every call that can fail.
    msp_status {
        /// Success.
        MSP_OK = 0,
        /// A pointer argument is null.
        MSP_NULL_POINTER = 1,
        /// The buffer is smaller than `msp_<scheme>_size` said.
        MSP_BUFFER_TOO_SMALL = 2,
        /// A parameter is NaN or infinite where a finite value is needed.
        MSP_NOT_FINITE = 3,
        /// A parameter must be greater than zero.
        MSP_NOT_POSITIVE = 4,
        /// A parameter must not be negative.
        MSP_NEGATIVE = 5,
        /// A parameter is outside its range (e.g. a model kind the scheme does
        /// not take, or a bias at least the relay amplitude).
        MSP_OUT_OF_RANGE = 6,
        /// The lower actuator limit is above the upper one.
        MSP_INVALID_LIMITS = 7,
        /// The dead time, in samples, is longer than the buffer holds (or than
        /// `max_dead_time_samples`).
        MSP_DEAD_TIME_TOO_LONG = 8,
        /// The scheme cannot be built for this model (e.g. an unstable model for
        /// the classic Smith predictor).
        MSP_UNSUPPORTED = 9,
        /// A numerical step of the design failed (a singular system).
        MSP_NUMERICAL = 10,
        /// The handle was not made by an `msp_*_init` of this precision.
        MSP_BAD_HANDLE = 11,
    }
}

impl From<msp_core::Error> for msp_status {
    fn from(e: msp_core::Error) -> Self {
        use msp_core::Error as E;
        match e {
            E::NonFinite(_) | E::NonFiniteAt(..) => msp_status::MSP_NOT_FINITE,
            E::NotPositive(_) | E::NotIncreasing(..) => msp_status::MSP_NOT_POSITIVE,
            E::Negative(_) => msp_status::MSP_NEGATIVE,
            E::InvalidLimits(_) => msp_status::MSP_INVALID_LIMITS,
            E::DelayTooLong(_) | E::OutOfMemory(_) => msp_status::MSP_DEAD_TIME_TOO_LONG,
            E::Unsupported(_) | E::Improper(_) | E::OrderTooHigh(_) => msp_status::MSP_UNSUPPORTED,
            E::Numerical(_) => msp_status::MSP_NUMERICAL,
            _ => msp_status::MSP_OUT_OF_RANGE,
        }
    }
}

/// What a status means, as a constant NUL-terminated string (an integer
/// that is no `msp_status` gives "unknown status").
#[no_mangle]
pub extern "C" fn msp_status_str(status: core::ffi::c_int) -> *const c_char {
    const ALL: [msp_status; 12] = [
        msp_status::MSP_OK,
        msp_status::MSP_NULL_POINTER,
        msp_status::MSP_BUFFER_TOO_SMALL,
        msp_status::MSP_NOT_FINITE,
        msp_status::MSP_NOT_POSITIVE,
        msp_status::MSP_NEGATIVE,
        msp_status::MSP_OUT_OF_RANGE,
        msp_status::MSP_INVALID_LIMITS,
        msp_status::MSP_DEAD_TIME_TOO_LONG,
        msp_status::MSP_UNSUPPORTED,
        msp_status::MSP_NUMERICAL,
        msp_status::MSP_BAD_HANDLE,
    ];
    let Some(status) = ALL.into_iter().find(|s| *s as core::ffi::c_int == status) else {
        return c"unknown status".as_ptr();
    };
    let s: &'static core::ffi::CStr = match status {
        msp_status::MSP_OK => c"ok",
        msp_status::MSP_NULL_POINTER => c"a pointer argument is null",
        msp_status::MSP_BUFFER_TOO_SMALL => c"the buffer is smaller than msp_*_size says",
        msp_status::MSP_NOT_FINITE => c"a parameter is NaN or infinite",
        msp_status::MSP_NOT_POSITIVE => c"a parameter must be greater than zero",
        msp_status::MSP_NEGATIVE => c"a parameter must not be negative",
        msp_status::MSP_OUT_OF_RANGE => c"a parameter is out of its range",
        msp_status::MSP_INVALID_LIMITS => c"the lower limit is above the upper limit",
        msp_status::MSP_DEAD_TIME_TOO_LONG => c"the dead time is longer than the buffer holds",
        msp_status::MSP_UNSUPPORTED => c"the scheme cannot be built for this model",
        msp_status::MSP_NUMERICAL => c"a numerical step of the design failed",
        msp_status::MSP_BAD_HANDLE => c"not a controller made by msp_*_init of this precision",
    };
    s.as_ptr()
}

/// Writes `status` through `out` when it is not null, and passes it on.
fn report(out: *mut msp_status, status: msp_status) -> msp_status {
    if !out.is_null() {
        // SAFETY: a non-null `out` points to an `msp_status` the caller owns
        unsafe { out.write(status) };
    }
    status
}

/// An `msp_*_size` answer: the bytes `size` gives for the configuration
/// read (`None`: a null pointer), or 0 with the reason through `status`.
fn reported_size<C>(
    config: Option<C>,
    status: *mut msp_status,
    size: impl FnOnce(&C) -> Result<usize, msp_core::Error>,
) -> usize {
    let Some(c) = config else {
        report(status, msp_status::MSP_NULL_POINTER);
        return 0;
    };
    match size(&c) {
        Ok(n) => {
            report(status, msp_status::MSP_OK);
            n
        }
        Err(e) => {
            report(status, e.into());
            0
        }
    }
}

/// A panic cannot happen: every operation of the library is checked (the
/// lints deny `unwrap`, `expect`, `panic!` and unchecked indexing), and the
/// release build for a device is checked to contain no panic symbol. Should
/// one be reached all the same, the call does not return.
#[cfg(not(test))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        core::hint::spin_loop();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use msp_core::{Controller, Fopdt, PidConfig, ProcessModel, SmithPredictor};

    /// A controller built through the C API in a caller buffer computes what
    /// the library's own type computes with its storage (the same samples,
    /// bit for bit), through a whole set-point and load response.
    #[test]
    fn the_c_smith_predictor_is_the_library_one() -> Result<(), msp_core::Error> {
        let mut cfg = core::mem::MaybeUninit::<msp_smith_config_f64>::uninit();
        // SAFETY: a writable config
        let s = unsafe { msp_tune_smith_fopdt_f64(5.6, 40.2, 93.9, 0.939, 0.0, cfg.as_mut_ptr()) };
        assert_eq!(s, msp_status::MSP_OK);
        // SAFETY: written by the tuning above
        let cfg = unsafe { cfg.assume_init() };
        let mut buf = std::vec![0u8; 4096];
        let mut c: *mut msp_controller_f64 = core::ptr::null_mut();
        // SAFETY: the buffer outlives the controller
        let s = unsafe { msp_smith_init_f64(buf.as_mut_ptr().cast(), buf.len(), &cfg, &mut c) };
        assert_eq!(s, msp_status::MSP_OK);
        let model: ProcessModel<f64> = Fopdt::new(5.6, 40.2, 93.9)?.into();
        let pi = PidConfig::isa(cfg.pid.kp, cfg.pid.ti, 0.0, 0.939);
        let mut sp: SmithPredictor<f64, 1, [f64; 128]> =
            SmithPredictor::from_model(pi, &model, 0.939)?;
        let (a, b) = (
            (-0.939f64 / 40.2).exp(),
            5.6 * (1.0 - (-0.939f64 / 40.2).exp()),
        );
        let mut line = std::collections::VecDeque::from(std::vec![0.0; 100]);
        let (mut y, mut settled) = (0.0, f64::NAN);
        for k in 0..2000 {
            if k == 1000 {
                settled = y;
            }
            let r = if k < 1000 { 1.0 } else { 0.5 };
            // SAFETY: the handle from init, its buffer in place
            let u = unsafe { msp_update_f64(c, r, y) };
            assert_eq!(u.to_bits(), sp.update(r, y).to_bits(), "sample {k}");
            line.push_back(u - if k > 1500 { 0.05 } else { 0.0 });
            let v = line.pop_front().unwrap_or(0.0);
            y = a * y + b * v;
        }
        // the run is a real response: the output had come to the set point
        assert!((settled - 1.0).abs() < 1e-3, "{settled}");
        Ok(())
    }
}

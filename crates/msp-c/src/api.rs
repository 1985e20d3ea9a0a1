//! The C entry points: sizes, initialization, the per-sample calls and the
//! operation of a controller.
//!
//! Each entry point is a one-line call of a generic function of
//! [`crate::handle`], written once in `twins!` (`lib.rs`) for `float` and its `_f64`
//! twin for `double` (the precision is read from the argument types).

use crate::handle::*;
use crate::msp_status;

/// Each scheme's two construction calls in both precisions (through
/// `twins!`): `size` (the bytes its buffer needs; 0 on an error, with the
/// reason in `*status`) and `init` (builds it in the buffer, `*ctrl` its
/// handle), from its configuration type, its buffer's kind and dead-time
/// count, and its constructor.
macro_rules! scheme_entries {
    ($(
        $(#[doc = $size_doc:literal])*
        fn $size:ident, $size64:ident = ($kind:expr, $samples:expr);
        $(#[doc = $init_doc:literal])*
        fn $init:ident, $init64:ident = $make:expr;
        config: $cfg:ident, $cfg64:ident;
    )*) => { twins! { $(
        $(#[doc = $size_doc])*
        ///
        /// # Safety
        /// `config` and `status` are null or valid pointers.
        fn $size, $size64(
            config: *const $cfg | *const $cfg64,
            max_dead_time_samples: u32,
            status: *mut msp_status,
        ) -> usize {
            // SAFETY: forwarded
            unsafe { config_size(config, max_dead_time_samples, status, $kind, $samples) }
        }

        $(#[doc = $init_doc])*
        ///
        /// # Safety
        /// `buf` is null or points to `len` writable bytes that stay in place
        /// while the controller is used; `config` and `ctrl` are null or valid.
        fn $init, $init64(
            buf: *mut core::ffi::c_void,
            len: usize,
            config: *const $cfg | *const $cfg64,
            ctrl: *mut *mut msp_controller | *mut *mut msp_controller_f64,
        ) -> msp_status {
            // SAFETY: forwarded
            unsafe { config_init(buf, len, config, ctrl, $make) }
        }
    )* } };
}

scheme_entries! {
    /// The bytes a PID controller needs; 0 on an error, with the reason in
    /// `*status` (`status` may be null). `max_dead_time_samples` is not read.
    fn msp_pid_size, msp_pid_size_f64 = (Kind::Pid, pid_samples);
    /// Builds a PID controller in `buf` (`len` bytes, any alignment); `*ctrl`
    /// is its handle.
    fn msp_pid_init, msp_pid_init_f64 = |c, _| make_pid(c);
    config: msp_pid_config, msp_pid_config_f64;

    /// The bytes a Smith predictor needs for its model's dead time, or for
    /// `max_dead_time_samples` when that is longer (room to lengthen the dead
    /// time at run time); 0 on an error, with the reason in `*status`.
    fn msp_smith_size, msp_smith_size_f64 = (Kind::Line, smith_samples);
    /// Builds a Smith predictor in `buf`: its delay line takes the rest of the
    /// buffer (the longest dead time it can be given later).
    fn msp_smith_init, msp_smith_init_f64 = make_smith;
    config: msp_smith_config, msp_smith_config_f64;

    /// [`msp_smith_size`] for the Karan–Dey predictor.
    fn msp_karan_dey_size, msp_karan_dey_size_f64 = (Kind::Line, karan_dey_samples);
    /// Builds a Karan–Dey predictor in `buf`.
    fn msp_karan_dey_init, msp_karan_dey_init_f64 = make_karan_dey;
    config: msp_karan_dey_config, msp_karan_dey_config_f64;

    /// [`msp_smith_size`] for the filtered Smith predictor (its design's scratch
    /// included).
    fn msp_fsp_size, msp_fsp_size_f64 = (Kind::Fsp, fsp_samples);
    /// Designs and builds a filtered Smith predictor in `buf`.
    fn msp_fsp_init, msp_fsp_init_f64 = make_fsp;
    config: msp_fsp_config, msp_fsp_config_f64;
}

/// One sample: the set point `r` and the measurement `y` in, the actuator
/// value out. The handle's tag is checked first, as every call does: a null
/// pointer, or memory that holds no handle of this precision (never
/// initialized, cleared, overwritten), gives NaN and touches nothing else.
/// Then one indirect call into the scheme.
///
/// # Safety
/// `ctrl` is null or points to readable memory of at least four bytes; it
/// controls only when it is a handle from an `msp_*_init` call whose buffer
/// is in place.
#[cfg(not(all(target_arch = "arm", target_os = "none")))]
#[no_mangle]
pub unsafe extern "C" fn msp_update(ctrl: *mut msp_controller, r: f32, y: f32) -> f32 {
    // SAFETY: forwarded
    unsafe { update_unchecked(ctrl, r, y) }
}

/// [`msp_update`] in double precision.
///
/// # Safety
/// As [`msp_update`].
#[cfg(not(all(target_arch = "arm", target_os = "none")))]
#[no_mangle]
pub unsafe extern "C" fn msp_update_f64(ctrl: *mut msp_controller_f64, r: f64, y: f64) -> f64 {
    // SAFETY: forwarded
    unsafe { update_unchecked(ctrl, r, y) }
}

/// The per-sample call through a handle's bound update: null gives NaN.
///
/// # Safety
/// `ctrl` is null or points to at least four readable bytes.
#[cfg(not(all(target_arch = "arm", target_os = "none")))]
#[inline(always)]
unsafe fn update_unchecked<T: Precision, H: Opaque<T = T>>(ctrl: *mut H, r: T, y: T) -> T {
    // SAFETY: the caller's handle (or null, or memory that holds no handle:
    // its tag is read first, and nothing else unless it is ours)
    match unsafe { crate::handle::handle(ctrl) } {
        // SAFETY: `bind` pointed both at this handle's controller
        Some(h) => unsafe { (h.update)(h.ctrl, r, y) },
        None => T::nan(),
    }
}

/// `msp_update` and `msp_update_f64` on a Cortex-M: the same call written as
/// a frameless trampoline (the target keeps a frame pointer in every Rust
/// function, three instructions of the dispatch's cost): NULL, or memory
/// whose first word is not the precision's tag (a buffer that holds no
/// handle, or a handle cleared by `memset`), gives NaN; otherwise the bound
/// update is tail-called with the controller's address in `r0` and the
/// arguments untouched in `s0`/`s1` (`d0`/`d1`). The tag is one byte
/// repeated, a Thumb-2 immediate: the check is a load, a compare and a branch.
///
/// cbindgen:ignore
#[cfg(all(target_arch = "arm", target_os = "none"))]
mod trampoline {
    use super::{msp_controller, msp_controller_f64, Handle};
    use crate::handle::Precision;
    use core::mem::offset_of;

    const MAGIC: u32 = <f32 as Precision>::MAGIC;
    const MAGIC_F64: u32 = <f64 as Precision>::MAGIC;
    // the tag is the handle's first word
    const _: () = assert!(offset_of!(Handle<f32>, magic) == 0);
    const _: () = assert!(offset_of!(Handle<f64>, magic) == 0);

    /// The trampoline: the tag checked, the bound update tail-called; else
    /// the NaN the given instructions put in the return register.
    macro_rules! dispatch {
        ($update:ident, $magic:ident, $($nan:literal),+) => {
            core::arch::naked_asm!(
                "cbz r0, 2f",
                "ldr r1, [r0]",
                "cmp r1, #{magic}",
                "bne 2f",
                "ldrd r1, r0, [r0, #{update}]",
                "bx r1",
                "2:",
                $($nan,)+
                "bx lr",
                update = const $update,
                magic = const $magic,
            )
        };
    }

    const UPDATE: usize = offset_of!(Handle<f32>, update);
    const UPDATE_F64: usize = offset_of!(Handle<f64>, update);
    // `ldrd` takes the update and the controller's address as a pair
    const _: () = assert!(offset_of!(Handle<f32>, ctrl) == UPDATE + 4 && UPDATE % 4 == 0);
    const _: () = assert!(offset_of!(Handle<f64>, ctrl) == UPDATE_F64 + 4 && UPDATE_F64 % 4 == 0);

    /// See `msp_update` in the header.
    ///
    /// # Safety
    /// As the host version.
    #[unsafe(naked)]
    #[no_mangle]
    pub unsafe extern "C" fn msp_update(_ctrl: *mut msp_controller, _r: f32, _y: f32) -> f32 {
        dispatch!(
            UPDATE,
            MAGIC,
            "movw r1, #0",
            "movt r1, #0x7fc0",
            "vmov s0, r1"
        )
    }

    /// See `msp_update_f64` in the header.
    ///
    /// # Safety
    /// As the host version.
    #[unsafe(naked)]
    #[no_mangle]
    pub unsafe extern "C" fn msp_update_f64(
        _ctrl: *mut msp_controller_f64,
        _r: f64,
        _y: f64,
    ) -> f64 {
        dispatch!(
            UPDATE_F64,
            MAGIC_F64,
            "movs r1, #0",
            "movw r2, #0",
            "movt r2, #0x7ff8",
            "vmov d0, r1, r2"
        )
    }
}

twins! {
    /// Clears the controller's state (integrators, model, delay lines) and
    /// returns it to automatic mode.
    ///
    /// # Safety
    /// As [`msp_update`].
    fn msp_reset, msp_reset_f64(
        ctrl: *mut msp_controller | *mut msp_controller_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        match unsafe { handle(ctrl) } {
            Some(h) => {
                reset(h);
                msp_status::MSP_OK
            }
            None => bad(ctrl),
        }
    }

    /// Clears the controller's state as [`msp_reset`] does, with the loop at
    /// rest before the next update (every signal zero, the initial condition
    /// of the controller's transfer function): a PID's first update then
    /// differences its derivative input against zero (a step kicks it),
    /// where after [`msp_reset`] or `init` it takes its first sample as the
    /// reference (no kick: a controller started on a running process).
    ///
    /// # Safety
    /// As [`msp_update`].
    fn msp_reset_to_rest, msp_reset_to_rest_f64(
        ctrl: *mut msp_controller | *mut msp_controller_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        match unsafe { handle(ctrl) } {
            Some(h) => {
                reset_to_rest(h);
                msp_status::MSP_OK
            }
            None => bad(ctrl),
        }
    }

    /// Whether the last update met a NaN or infinite input (the output was held
    /// and the model kept following the actuator). A bad handle is a fault.
    ///
    /// # Safety
    /// As [`msp_update`].
    fn msp_fault, msp_fault_f64(
        ctrl: *const msp_controller | *const msp_controller_f64,
    ) -> bool {
        // SAFETY: forwarded
        unsafe { handle(ctrl.cast_mut()) }.is_none_or(fault)
    }

    /// Manual mode: the output is `u` from the next update on; the controller's
    /// model and integrators follow it, so that [`msp_auto`] is bumpless.
    /// Tracking (the output follows an external value) is the same call, made
    /// each sample with the value to follow.
    ///
    /// # Safety
    /// `ctrl` is null or a handle from an `msp_*_init` call whose buffer is in place.
    fn msp_manual, msp_manual_f64(
        ctrl: *mut msp_controller | *mut msp_controller_f64,
        u: f32 | f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { operate(ctrl, |h| manual(h, u)) }
    }

    /// Automatic mode: the next output continues from the last applied one.
    ///
    /// # Safety
    /// As [`msp_manual`].
    fn msp_auto, msp_auto_f64(ctrl: *mut msp_controller | *mut msp_controller_f64) -> msp_status {
        // SAFETY: forwarded
        unsafe { operate(ctrl, auto) }
    }

    /// External reset: the value the actuator really applied for the last
    /// output (after a limit or an override downstream), given before the next
    /// [`msp_update`]; the integrators (back-calculation) and the model follow it.
    ///
    /// # Safety
    /// As [`msp_manual`].
    fn msp_applied, msp_applied_f64(
        ctrl: *mut msp_controller | *mut msp_controller_f64,
        u_applied: f32 | f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { operate(ctrl, |h| applied(h, u_applied)) }
    }

    /// Gives the controller's model the dead time `samples` (fractional allowed),
    /// within the buffer's capacity (`max_dead_time_samples` of the size call);
    /// `MSP_UNSUPPORTED` for a scheme whose design contains the dead time (FSP)
    /// or that has none (PID).
    ///
    /// # Safety
    /// As [`msp_manual`].
    fn msp_set_dead_time, msp_set_dead_time_f64(
        ctrl: *mut msp_controller | *mut msp_controller_f64,
        samples: f32 | f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { operate(ctrl, |h| set_dead_time(h, samples)) }
    }

    /// Changes a gain of the primary PID while running (`gain`: an
    /// `msp_gain`), bumpless: the output does not jump at the change.
    /// `MSP_UNSUPPORTED` where the scheme's controllers share the gain
    /// (Karan–Dey's `kp`) or the primary is not a PID.
    ///
    /// # Safety
    /// As [`msp_manual`].
    fn msp_retune, msp_retune_f64(
        ctrl: *mut msp_controller | *mut msp_controller_f64,
        gain: u32,
        value: f32 | f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { operate(ctrl, |h| retune(h, gain, value)) }
    }
}

c_enum! {
    /// A gain of the primary PID ([`msp_retune`]).
    msp_gain {
        /// The proportional gain `kp`.
        MSP_KP = 0,
        /// The integral time `ti` (s; `INFINITY` turns the integral off).
        MSP_TI = 1,
        /// The derivative time `td` (s).
        MSP_TD = 2,
    }
}

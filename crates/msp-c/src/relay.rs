//! Tuning on the device: the rules that turn a process model into a
//! controller's configuration, and the relay experiment that finds the model.

use msp_core::autotune::{
    identify_fopdt, identify_ipdt, identify_ufopdt, RelayConfig, RelayResult, RelayState, RelayTest,
};
use msp_core::{tuning, Error, Fopdt, Ipdt, ProcessModel, Real};

use crate::handle::{
    model, msp_karan_dey_config_of, msp_model_kind, msp_model_of, msp_pid_config_of,
    msp_pid_params_of, msp_smith_config_of, Arena, Precision,
};
use crate::msp_status;

/// `lambda`, or `default` when it is zero (NaN and negative values are errors).
fn lambda_or<T: Real>(lambda: T, default: T) -> Result<T, Error> {
    if lambda == T::zero() {
        Ok(default)
    } else if lambda.is_nan() {
        Err(Error::NonFinite("lambda"))
    } else {
        Ok(lambda)
    }
}

/// Writes the result of a tuning through `out`.
///
/// # Safety
/// `out` is null or writable.
pub(crate) unsafe fn tuned<C>(out: *mut C, c: Result<C, Error>) -> msp_status {
    if out.is_null() {
        return msp_status::MSP_NULL_POINTER;
    }
    match c {
        Ok(c) => {
            // SAFETY: non-null and the caller's
            unsafe { out.write(c) };
            msp_status::MSP_OK
        }
        Err(e) => e.into(),
    }
}

/// The PID parameters of gains `g`, without actuator limits.
fn unlimited<T: Real>(g: &tuning::PidGains<T>) -> msp_pid_params_of<T> {
    msp_pid_params_of {
        kp: g.kp,
        ti: g.ti,
        td: g.td,
        u_min: T::neg_infinity(),
        u_max: T::infinity(),
    }
}

fn smith_fopdt<T: Real>(
    k: T,
    tau: T,
    theta: T,
    ts: T,
    lambda: T,
) -> Result<msp_smith_config_of<T>, Error> {
    let f = Fopdt::new(k, tau, theta)?;
    // Kaya (2003) Eq. 26: λ = θ is ISE-optimal
    let lambda = lambda_or(lambda, theta)?;
    let g = tuning::kaya(&ProcessModel::from(f), lambda)?;
    g.config(ts).validate()?;
    Ok(msp_smith_config_of {
        ts,
        model: msp_model_of {
            kind: msp_model_kind::MSP_FOPDT as u32,
            k,
            tau,
            theta,
        },
        pid: unlimited(&g),
    })
}

pub(crate) fn karan_dey_ipdt<T: Real>(
    k: T,
    theta: T,
    ts: T,
    lambda: T,
) -> Result<msp_karan_dey_config_of<T>, Error> {
    let m = Ipdt::new(k, theta)?;
    let lambda = lambda_or(lambda, tuning::karan_dey_default_lambda(&m))?;
    let p = tuning::karan_dey(&m, lambda)?;
    if !(ts.is_finite() && ts > T::zero()) {
        return Err(Error::NotPositive("ts"));
    }
    Ok(msp_karan_dey_config_of {
        ts,
        model: msp_model_of {
            kind: msp_model_kind::MSP_IPDT as u32,
            k,
            tau: T::zero(),
            theta,
        },
        kp: p.kp,
        ti: p.ti,
        beta: p.beta,
        gamma: p.gamma,
        td: p.td,
        n: p.n,
        u_min: T::neg_infinity(),
        u_max: T::infinity(),
    })
}

twins! {
    /// Tunes a Smith predictor for the FOPDT model `k e^{−θs}/(τs + 1)`: Kaya's
    /// IMC PI `kp = τ/(kλ)`, `ti = τ` (Kaya (2003) Eqs. 20–21), with the
    /// closed-loop time constant `lambda` (0: `λ = θ`, Eq. 26), at the period `ts`.
    ///
    /// # Safety
    /// `config` is null or writable.
    fn msp_tune_smith_fopdt, msp_tune_smith_fopdt_f64(
        k: f32 | f64,
        tau: f32 | f64,
        theta: f32 | f64,
        ts: f32 | f64,
        lambda: f32 | f64,
        config: *mut crate::msp_smith_config | *mut crate::msp_smith_config_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { tuned(config, smith_fopdt(k, tau, theta, ts, lambda)) }
    }

    /// Tunes the Karan–Dey predictor for the IPDT model `k e^{−θs}/s` (Bag
    /// (2022) Eqs. 4.30–4.44), with the closed-loop time constant `lambda`
    /// (0: the thesis's default `λ = θ/4`, Eq. 4.32), at the period `ts`.
    ///
    /// # Safety
    /// `config` is null or writable.
    fn msp_tune_karan_dey_ipdt, msp_tune_karan_dey_ipdt_f64(
        k: f32 | f64,
        theta: f32 | f64,
        ts: f32 | f64,
        lambda: f32 | f64,
        config: *mut crate::msp_karan_dey_config | *mut crate::msp_karan_dey_config_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { tuned(config, karan_dey_ipdt(k, theta, ts, lambda)) }
    }
}

fn pid_crossover<T: Real>(
    m: &msp_model_of<T>,
    wc: T,
    pm: T,
    derivative: bool,
    ts: T,
) -> Result<msp_pid_config_of<T>, Error> {
    let g = tuning::at_crossover(&model(m)?, wc, pm, derivative)?;
    g.config(ts).validate()?;
    Ok(msp_pid_config_of {
        ts,
        pid: unlimited(&g),
    })
}

twins! {
    /// Designs a PI (or, `derivative` nonzero, a PID with `td = ti/4`) for
    /// the process model `model` whose loop crosses 0 dB at `wc` rad/s with
    /// the phase margin `pm` degrees (MATLAB `pidtune(G, 'PI', wc)` with its
    /// `PhaseMargin`; the closed form of `msp::tuning::pi_at`), sampled every
    /// `ts`. A loop that would need the controller to lead (or a PI to lag
    /// by 90° or more) is `MSP_UNSUPPORTED`.
    ///
    /// # Safety
    /// `model` is null or readable; `config` is null or writable.
    fn msp_tune_pid_crossover, msp_tune_pid_crossover_f64(
        model: *const crate::msp_model | *const crate::msp_model_f64,
        wc: f32 | f64,
        pm: f32 | f64,
        derivative: u8,
        ts: f32 | f64,
        config: *mut crate::msp_pid_config | *mut crate::msp_pid_config_f64,
    ) -> msp_status {
        // SAFETY: the caller's pointer, null or readable
        let Some(model) = (unsafe { model.as_ref() }) else {
            return msp_status::MSP_NULL_POINTER;
        };
        // SAFETY: forwarded
        unsafe { tuned(config, pid_crossover(model, wc, pm, derivative != 0, ts)) }
    }
}

/// Settings of a relay experiment (Kaya (2003) Fig. 4, Sec. 3.1):
/// amplitude `h` (negative for a reverse-acting process: the identified
/// gains come out negative), hysteresis `ε` on the error, a bias on both levels (for
/// the static gain), the steady state `(u0, y0)` it starts from, actuator
/// limits, a safety band on `|y − y0|`, a sample budget, the agreeing
/// periods needed and their relative tolerance, the period `ts` (s).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct msp_relay_config {
    pub amplitude: f32,
    pub hysteresis: f32,
    pub bias: f32,
    pub u0: f32,
    pub y0: f32,
    pub u_min: f32,
    pub u_max: f32,
    pub band: f32,
    pub max_samples: u32,
    pub cycles: u8,
    pub tolerance: f32,
    pub ts: f32,
}

/// What a settled limit cycle measured (deviations from `(u0, y0)`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct msp_relay_result {
    pub amplitude: f32,
    pub hysteresis: f32,
    pub bias: f32,
    pub t_up: f32,
    pub t_down: f32,
    pub period: f32,
    pub a_max: f32,
    pub a_min: f32,
    pub mean_u: f32,
    pub mean_y: f32,
    pub cycles: u32,
}

/// The C structure and the library's type of the same fields, converted
/// both ways field by field.
macro_rules! same_fields {
    ($c:ident, $lib:ty { $($f:ident),* $(,)? }) => {
        impl From<&$lib> for $c {
            fn from(v: &$lib) -> Self {
                $c { $($f: v.$f),* }
            }
        }
        impl From<&$c> for $lib {
            fn from(v: &$c) -> Self {
                Self { $($f: v.$f),* }
            }
        }
    };
}

same_fields!(msp_relay_config, RelayConfig<f32> {
    amplitude, hysteresis, bias, u0, y0, u_min, u_max, band, max_samples, cycles, tolerance, ts,
});
same_fields!(msp_relay_result, RelayResult<f32> {
    amplitude, hysteresis, bias, t_up, t_down, period, a_max, a_min, mean_u, mean_y, cycles,
});

c_enum! {
    /// Where a relay experiment is.
    msp_relay_state {
        /// Still oscillating.
        MSP_RELAY_RUNNING = 0,
        /// A settled limit cycle: the result is there, the actuator back at `u0`.
        MSP_RELAY_DONE = 1,
        /// No settled limit cycle within the sample budget (actuator at `u0`).
        MSP_RELAY_TIMEOUT = 2,
        /// The output left its safety band (actuator at `u0`).
        MSP_RELAY_OUT_OF_BAND = 3,
        /// A measurement was NaN or infinite (actuator at `u0`).
        MSP_RELAY_BAD_MEASUREMENT = 4,
    }
}

/// A relay experiment built by [`msp_relay_init`] (opaque).
pub struct msp_relay {
    _opaque: [u8; 0],
}

#[repr(C)]
struct RelayHandle {
    magic: u32,
    test: RelayTest<f32>,
}

const RELAY_MAGIC: u32 = 0x5252_5252;

/// The defaults for an amplitude and a period: no hysteresis, no bias,
/// steady state at zero, no limits, no band, 3 periods agreeing within 1 %,
/// at most 10⁶ samples.
///
/// # Safety
/// `config` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn msp_relay_default_config(
    amplitude: f32,
    ts: f32,
    config: *mut msp_relay_config,
) -> msp_status {
    let c = RelayConfig::new(amplitude, ts);
    let out = msp_relay_config::from(&c);
    // SAFETY: forwarded
    unsafe { tuned(config, c.validate().map(|()| out)) }
}

/// The bytes [`msp_relay_init`] needs.
#[no_mangle]
pub extern "C" fn msp_relay_size() -> usize {
    core::mem::size_of::<RelayHandle>() + core::mem::align_of::<RelayHandle>()
}

/// Starts a relay experiment in `buf` (`len` bytes); `*relay` is its handle.
/// Call [`msp_relay_update`] once per sample and apply what it returns.
///
/// # Safety
/// `buf` is null or points to `len` writable bytes that stay in place while
/// the experiment runs; `config` and `relay` are null or valid.
#[no_mangle]
pub unsafe extern "C" fn msp_relay_init(
    buf: *mut core::ffi::c_void,
    len: usize,
    config: *const msp_relay_config,
    relay: *mut *mut msp_relay,
) -> msp_status {
    if buf.is_null() || relay.is_null() {
        return msp_status::MSP_NULL_POINTER;
    }
    // SAFETY: null-checked by `as_ref`
    let Some(c) = (unsafe { config.as_ref() }) else {
        return msp_status::MSP_NULL_POINTER;
    };
    let cfg = RelayConfig::from(c);
    let test = match RelayTest::new(cfg) {
        Ok(t) => t,
        Err(e) => return e.into(),
    };
    let Some(slot) = Arena::new(buf.cast(), len).place::<RelayHandle>() else {
        return msp_status::MSP_BUFFER_TOO_SMALL;
    };
    // SAFETY: aligned and inside the buffer (checked by the arena)
    unsafe {
        slot.write(RelayHandle {
            magic: RELAY_MAGIC,
            test,
        });
        relay.write(slot.cast());
    }
    msp_status::MSP_OK
}

/// # Safety
/// `relay` is null or from [`msp_relay_init`].
unsafe fn relay_handle<'a>(relay: *mut msp_relay) -> Option<&'a mut RelayHandle> {
    let p = relay.cast::<RelayHandle>();
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null; the tag is read (at any alignment) before the rest is trusted
    let magic = unsafe { core::ptr::addr_of!((*p).magic).read_unaligned() };
    if magic != RELAY_MAGIC {
        return None;
    }
    // SAFETY: a tagged handle was written by `msp_relay_init`
    unsafe { p.as_mut() }
}

/// One sample of the experiment: the measurement in, the actuator value out
/// (`u0` once it has ended; NaN for a null or foreign handle).
///
/// # Safety
/// `relay` is null or a handle from [`msp_relay_init`] whose buffer is in place.
#[no_mangle]
pub unsafe extern "C" fn msp_relay_update(relay: *mut msp_relay, y: f32) -> f32 {
    // SAFETY: forwarded
    match unsafe { relay_handle(relay) } {
        Some(h) => h.test.update(y),
        None => f32::NAN,
    }
}

/// Where the experiment is (`*state`), and its result once done (`*result`,
/// which may be null).
///
/// # Safety
/// `relay` is null or from [`msp_relay_init`]; `state` and `result` are null
/// or writable.
#[no_mangle]
pub unsafe extern "C" fn msp_relay_poll(
    relay: *const msp_relay,
    state: *mut msp_relay_state,
    result: *mut msp_relay_result,
) -> msp_status {
    if state.is_null() {
        return msp_status::MSP_NULL_POINTER;
    }
    // SAFETY: forwarded
    let Some(h) = (unsafe { relay_handle(relay.cast_mut()) }) else {
        return if relay.is_null() {
            msp_status::MSP_NULL_POINTER
        } else {
            msp_status::MSP_BAD_HANDLE
        };
    };
    let (s, r) = match h.test.state() {
        RelayState::Running => (msp_relay_state::MSP_RELAY_RUNNING, None),
        RelayState::Done(r) => (msp_relay_state::MSP_RELAY_DONE, Some(r)),
        RelayState::Aborted(a) => (
            match a {
                msp_core::autotune::RelayAbort::Timeout => msp_relay_state::MSP_RELAY_TIMEOUT,
                msp_core::autotune::RelayAbort::OutOfBand => msp_relay_state::MSP_RELAY_OUT_OF_BAND,
                msp_core::autotune::RelayAbort::BadMeasurement => {
                    msp_relay_state::MSP_RELAY_BAD_MEASUREMENT
                }
            },
            None,
        ),
    };
    // SAFETY: non-null, the caller's
    unsafe { state.write(s) };
    if let (Some(r), false) = (r, result.is_null()) {
        // SAFETY: non-null, the caller's
        unsafe { result.write(msp_relay_result::from(&r)) };
    }
    msp_status::MSP_OK
}

/// The IPDT model `k e^{−θs}/s` of a symmetric limit cycle: `k = 4a/(hP)`,
/// `θ = (a − ε)P/(4a)` with `a` the half peak-to-peak amplitude.
///
/// # Safety
/// `result` is null or readable, `model` null or writable.
#[no_mangle]
pub unsafe extern "C" fn msp_relay_ipdt(
    result: *const msp_relay_result,
    model: *mut crate::msp_model,
) -> msp_status {
    // SAFETY: null-checked by `as_ref`
    let Some(r) = (unsafe { result.as_ref() }) else {
        return msp_status::MSP_NULL_POINTER;
    };
    let m = identify_ipdt(&RelayResult::from(r)).map(|m| msp_model_of {
        kind: msp_model_kind::MSP_IPDT as u32,
        k: m.k,
        tau: 0.0,
        theta: m.l,
    });
    // SAFETY: forwarded
    unsafe { tuned(model, m) }
}

/// The FOPDT model `k e^{−θs}/(τs + 1)` of a limit cycle, given the static
/// gain `k` (from a biased relay: `mean_y/mean_u`, or known otherwise).
///
/// # Safety
/// `result` is null or readable, `model` null or writable.
#[no_mangle]
pub unsafe extern "C" fn msp_relay_fopdt(
    result: *const msp_relay_result,
    k: f32,
    model: *mut crate::msp_model,
) -> msp_status {
    // SAFETY: null-checked by `as_ref`
    let Some(r) = (unsafe { result.as_ref() }) else {
        return msp_status::MSP_NULL_POINTER;
    };
    let m = identify_fopdt(&RelayResult::from(r), k).map(|m| msp_model_of {
        kind: msp_model_kind::MSP_FOPDT as u32,
        k: m.k,
        tau: m.t,
        theta: m.l,
    });
    // SAFETY: forwarded
    unsafe { tuned(model, m) }
}

/// The unstable FOPDT model `k e^{−θs}/(τs − 1)` of a limit cycle from a
/// biased relay (the cycle's asymmetry determines it; a symmetric relay's
/// does not: `MSP_UNSUPPORTED`). Exact for plants of that form, to the
/// relay's sampling.
///
/// # Safety
/// `result` is null or readable, `model` null or writable.
#[no_mangle]
pub unsafe extern "C" fn msp_relay_ufopdt(
    result: *const msp_relay_result,
    model: *mut crate::msp_model,
) -> msp_status {
    // SAFETY: null-checked by `as_ref`
    let Some(r) = (unsafe { result.as_ref() }) else {
        return msp_status::MSP_NULL_POINTER;
    };
    let m = identify_ufopdt(&RelayResult::from(r)).map(|m| msp_model_of {
        kind: msp_model_kind::MSP_UFOPDT as u32,
        k: m.k,
        tau: m.t,
        theta: m.l,
    });
    // SAFETY: forwarded
    unsafe { tuned(model, m) }
}

// the handle types of both precisions are tagged differently
const _: () = assert!(<f32 as Precision>::MAGIC != RELAY_MAGIC);

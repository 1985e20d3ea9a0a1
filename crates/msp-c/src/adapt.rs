//! Adaptive dead-time compensation on the device: the on-line identifier
//! (`msp_estimator_*`) and the adaptive Smith predictor with its model-error
//! alarm (`msp_adaptive_*`), each in the caller's memory.
//!
//! Both hold a bank of [`MSP_ADAPT_CANDIDATES`] candidate dead times
//! `d_min … d_min + 15` over a history of [`MSP_ADAPT_HISTORY`] inputs (a
//! dead time of at most `MSP_ADAPT_HISTORY − 18` samples).

use msp_core::adapt::{Adaptive, AdaptiveConfig, Estimator, EstimatorConfig, Redesign};
use msp_core::{tuning, Error, Fopdt, Ipdt, ProcessModel, Real, SmithPredictor};

use crate::handle::{
    bad, model_in, msp_model_kind, msp_model_of, msp_smith_config_of, pid_config, read,
    smith_samples, Arena, Precision,
};
use crate::relay::tuned;
use crate::{msp_status, report};

/// Candidate dead times of the device's estimator.
pub const MSP_ADAPT_CANDIDATES: usize = 16;
/// Inputs the device's estimator remembers (the longest candidate dead time
/// plus two).
pub const MSP_ADAPT_HISTORY: usize = 512;

const N: usize = MSP_ADAPT_CANDIDATES;
const H: usize = MSP_ADAPT_HISTORY;

c_config! {
    /// Settings of an on-line identifier (`msp::adapt::EstimatorConfig`):
    /// the period `ts` (s), the shortest candidate dead time `d_min`
    /// (samples), `integrating` (nonzero: `k e^{−θs}/s`), the forgetting
    /// factor (0.999: a memory of 1000 samples), the prefilter's time
    /// constant (s; 0: plain differences, which amplify noise) and the
    /// excitation gate (the input's move needed to learn).
    msp_estimator_config_of: msp_estimator_config, msp_estimator_config_f64 {
        ts: T,
        d_min: u32,
        integrating: u32,
        forgetting: T,
        prefilter: T,
        excitation: T,
    }
}

c_config! {
    /// An estimate: gain `k`, time constant `tau` (s; `INFINITY`:
    /// integrating), dead time `theta` (s), its whole samples `d` and the
    /// evidence for it over the candidates that are not its neighbours
    /// (small: ambiguous). All NaN (and `d` 0) before it means anything.
    msp_estimate_of: msp_estimate, msp_estimate_f64 {
        k: T,
        tau: T,
        theta: T,
        d: u32,
        evidence: T,
    }
}

c_config! {
    /// An adaptive Smith predictor (`msp::adapt::Adaptive`): the predictor
    /// `smith` (FOPDT or IPDT model), the candidates from `d_min` samples,
    /// the estimator's `forgetting`, `prefilter` (s) and `excitation`, the
    /// relative change `min_change` that is applied, the model error
    /// `alarm` that raises the alarm (`INFINITY`: none), `apply` (0: a
    /// model-error monitor only), and the primary retuned at each change by
    /// Kaya's IMC rule with the closed-loop time constant `lambda` (0:
    /// `λ = θ`; NaN: the gains stay).
    msp_adaptive_config_of: msp_adaptive_config, msp_adaptive_config_f64 {
        smith: msp_smith_config_of<T>,
        d_min: u32,
        forgetting: T,
        prefilter: T,
        excitation: T,
        min_change: T,
        alarm: T,
        apply: u32,
        lambda: T,
    }
}

c_config! {
    /// What an adaptive controller knows: the estimate, the model in use
    /// (`k`, `tau`, `theta`), its error against the process `mismatch`
    /// (0.3: 30 %; NaN before it means anything), the alarm, whether
    /// adaptation is frozen, and how many changes were logged.
    msp_adaptive_state_of: msp_adaptive_state, msp_adaptive_state_f64 {
        estimate: msp_estimate_of<T>,
        k: T,
        tau: T,
        theta: T,
        mismatch: T,
        alarm: u32,
        frozen: u32,
        changes: u32,
    }
}

/// An identifier built by `msp_estimator_init` (opaque).
pub struct msp_estimator {
    _opaque: [u8; 0],
}

/// An identifier built by `msp_estimator_init_f64` (opaque).
pub struct msp_estimator_f64 {
    _opaque: [u8; 0],
}

/// An adaptive controller built by `msp_adaptive_init` (opaque).
pub struct msp_adaptive {
    _opaque: [u8; 0],
}

/// An adaptive controller built by `msp_adaptive_init_f64` (opaque).
pub struct msp_adaptive_f64 {
    _opaque: [u8; 0],
}

/// The handles of this module and their precisions and tags.
trait Tagged {
    type T: Precision;
    const MAGIC: u32;
}

impl Tagged for msp_estimator {
    type T = f32;
    const MAGIC: u32 = 0x4545_4545;
}
impl Tagged for msp_estimator_f64 {
    type T = f64;
    const MAGIC: u32 = 0x6565_6565;
}
impl Tagged for msp_adaptive {
    type T = f32;
    const MAGIC: u32 = 0x4141_4141;
}
impl Tagged for msp_adaptive_f64 {
    type T = f64;
    const MAGIC: u32 = 0x6161_6161;
}

/// The primary retuned by Kaya's IMC rule (Kaya (2003) Eqs. 20–21; the
/// tuning of `msp_tune_smith_fopdt`) at `lambda` (0: `λ = θ`, Eq. 26; NaN:
/// never).
#[derive(Debug, Clone, Copy)]
struct Kaya<T> {
    lambda: T,
}

impl<T: Real, C> Redesign<T, C> for Kaya<T> {
    fn gains(&mut self, k: T, tau: T, theta: T) -> Option<[T; 3]> {
        if self.lambda.is_nan() {
            return None;
        }
        let m: ProcessModel<T> = if tau.is_infinite() {
            Ipdt::new(k, theta).ok()?.into()
        } else {
            Fopdt::new(k, tau, theta).ok()?.into()
        };
        let lambda = if self.lambda == T::zero() {
            theta
        } else {
            self.lambda
        };
        let g = tuning::kaya(&m, lambda).ok()?;
        Some([g.kp, g.ti, g.td])
    }
}

type Bank<T> = Estimator<T, N, H>;
type Smith<T> = SmithPredictor<T, 1, &'static mut [T]>;
type AdaptiveSmith<T> = Adaptive<T, Smith<T>, Kaya<T>, N, H>;

/// What sits at the start of the caller's buffer: the tag, then the value.
#[repr(C)]
struct Tag<V> {
    magic: u32,
    value: V,
}

/// The value behind a handle of ours (`None`: null or another's).
///
/// # Safety
/// `p` is null or a handle from this module's `init` of the same type whose
/// buffer is in place.
unsafe fn value<'a, H: Tagged, V>(p: *mut H) -> Option<&'a mut V> {
    let p = p.cast::<Tag<V>>();
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null; the tag is read (at any alignment) before the rest is trusted
    let magic = unsafe { core::ptr::addr_of!((*p).magic).read_unaligned() };
    if magic != H::MAGIC {
        return None;
    }
    // SAFETY: a tagged value was written by `place`
    unsafe { p.as_mut() }.map(|t| &mut t.value)
}

/// Writes `v` tagged at the start of the arena and `*out` its handle.
///
/// # Safety
/// `out` is writable.
unsafe fn place<H: Tagged, V>(a: &mut Arena, v: V, out: *mut *mut H) -> msp_status {
    let Some(slot) = a.place::<Tag<V>>() else {
        return msp_status::MSP_BUFFER_TOO_SMALL;
    };
    // SAFETY: the slot from the arena; `out` forwarded
    unsafe { tag(slot, v, out) }
}

/// Writes `v` tagged into `slot` and `*out` its handle.
///
/// # Safety
/// `slot` is aligned, inside its buffer (an arena's) and writable; `out`
/// is writable.
unsafe fn tag<H: Tagged, V>(slot: *mut Tag<V>, v: V, out: *mut *mut H) -> msp_status {
    // SAFETY: the caller's
    unsafe {
        slot.write(Tag {
            magic: H::MAGIC,
            value: v,
        });
        out.write(slot.cast());
    }
    msp_status::MSP_OK
}

fn estimator_config<T: Real>(c: &msp_estimator_config_of<T>) -> Result<EstimatorConfig<T>, Error> {
    let d_min = usize::try_from(c.d_min).map_err(|_| Error::DelayTooLong("d_min"))?;
    let mut e = EstimatorConfig::new(c.ts, d_min);
    e.integrating = c.integrating != 0;
    e.forgetting = c.forgetting;
    e.set_prefilter_time(c.prefilter)?;
    e.min_excitation = c.excitation;
    e.validate()?;
    Ok(e)
}

fn estimate_of<T: Real>(e: Option<msp_core::adapt::Estimate<T>>) -> msp_estimate_of<T> {
    match e {
        Some(e) => msp_estimate_of {
            k: e.k,
            tau: e.tau,
            theta: e.theta,
            d: u32::try_from(e.d).unwrap_or(u32::MAX),
            evidence: e.evidence,
        },
        None => msp_estimate_of {
            k: T::nan(),
            tau: T::nan(),
            theta: T::nan(),
            d: 0,
            evidence: T::nan(),
        },
    }
}

fn estimator_default<T: Real>(ts: T, d_min: u32) -> Result<msp_estimator_config_of<T>, Error> {
    let e = EstimatorConfig::new(ts, 0);
    let c = msp_estimator_config_of {
        ts,
        d_min,
        integrating: 0,
        forgetting: e.forgetting,
        prefilter: T::zero(),
        excitation: e.min_excitation,
    };
    Bank::<T>::new(estimator_config(&c)?)?;
    Ok(c)
}

/// The model `(k, tau, theta)` of a C model (FOPDT or IPDT: `tau` infinite).
fn fopdt_or_ipdt<T: Real>(m: &msp_model_of<T>) -> Result<(T, T, T), Error> {
    if m.kind == msp_model_kind::MSP_IPDT as u32 {
        Ok((m.k, T::infinity(), m.theta))
    } else if m.kind == msp_model_kind::MSP_FOPDT as u32 {
        Ok((m.k, m.tau, m.theta))
    } else {
        Err(Error::Unsupported("adaptation: a FOPDT or IPDT model"))
    }
}

/// The settings of `msp::adapt::Adaptive` for a C configuration.
fn adaptive_config<T: Real>(c: &msp_adaptive_config_of<T>) -> Result<AdaptiveConfig<T>, Error> {
    let (_, tau, _) = fopdt_or_ipdt(&c.smith.model)?;
    let est = estimator_config(&msp_estimator_config_of {
        ts: c.smith.ts,
        d_min: c.d_min,
        integrating: u32::from(tau.is_infinite()),
        forgetting: c.forgetting,
        prefilter: c.prefilter,
        excitation: c.excitation,
    })?;
    let mut a = AdaptiveConfig::new(est);
    a.min_change = c.min_change;
    a.alarm = c.alarm;
    a.apply = c.apply != 0;
    a.validate()?;
    Ok(a)
}

/// The values of a controller's dead-time line: room for the longest
/// candidate and its fraction.
fn line_values(c: &msp_adaptive_config_of<impl Real>) -> usize {
    (c.d_min as usize).saturating_add(N).saturating_add(2)
}

fn adaptive_default<T: Real>(
    s: &msp_smith_config_of<T>,
) -> Result<msp_adaptive_config_of<T>, Error> {
    let d = smith_samples(s)?;
    // the candidates around the model's dead time: 6 below, 9 above
    let below = (d.floor() - T::of(6.0))
        .max(T::zero())
        .to_f64()
        .unwrap_or(f64::NAN);
    if below.is_nan() || below >= f64::from(u32::MAX) {
        return Err(Error::DelayTooLong("dead time"));
    }
    // in range: checked just above
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let d_min = below as u32;
    let e = EstimatorConfig::new(s.ts, 0);
    let (_, tau, theta) = fopdt_or_ipdt(&s.model)?;
    // the prefilter's time constant 2.5 of the model's (an integrating
    // model's: 2.5 dead times), as `msp run --adapt`
    let t = if tau.is_finite() {
        tau * T::of(2.5)
    } else {
        theta.max(s.ts) * T::of(2.5)
    };
    let a = AdaptiveConfig::new(e);
    let c = msp_adaptive_config_of {
        smith: *s,
        d_min,
        forgetting: e.forgetting,
        prefilter: t,
        excitation: e.min_excitation,
        min_change: a.min_change,
        alarm: a.alarm,
        apply: 1,
        lambda: T::zero(),
    };
    adaptive_config(&c)?;
    Ok(c)
}

/// Builds the adaptive Smith predictor in the arena: the handle, then the
/// dead-time line over the rest.
fn make_adaptive<T: Precision>(
    c: &msp_adaptive_config_of<T>,
    a: &mut Arena,
) -> Result<AdaptiveSmith<T>, Error> {
    let cfg = adaptive_config(c)?;
    let (k, tau, theta) = fopdt_or_ipdt(&c.smith.model)?;
    smith_samples(&c.smith)?;
    let pid = pid_config(&c.smith.pid, c.smith.ts)?;
    let (block, line) = model_in(&c.smith.model, c.smith.ts, a)?;
    let sp = SmithPredictor::new(pid, block, line)?;
    Adaptive::new(sp, (k, tau, theta), cfg, Kaya { lambda: c.lambda })
}

fn adaptive_size<T: Precision>(c: &msp_adaptive_config_of<T>) -> Result<usize, Error> {
    adaptive_config(c)?;
    let values = line_values(c);
    core::mem::size_of::<Tag<AdaptiveSmith<T>>>()
        .checked_add(core::mem::align_of::<Tag<AdaptiveSmith<T>>>())
        .and_then(|b| b.checked_add(values.checked_mul(core::mem::size_of::<T>())?))
        .and_then(|b| b.checked_add(core::mem::align_of::<T>()))
        .ok_or(Error::DelayTooLong("buffer"))
}

/// # Safety
/// `buf` is null or `len` writable bytes that stay in place; `config` and
/// `out` null or valid.
unsafe fn adaptive_init<H: Tagged>(
    buf: *mut core::ffi::c_void,
    len: usize,
    config: *const msp_adaptive_config_of<H::T>,
    out: *mut *mut H,
) -> msp_status {
    if buf.is_null() || out.is_null() {
        return msp_status::MSP_NULL_POINTER;
    }
    // SAFETY: forwarded
    let Some(c) = (unsafe { read(config) }) else {
        return msp_status::MSP_NULL_POINTER;
    };
    let mut a = Arena::new(buf.cast(), len);
    // the handle first (its size is known), the line after it
    let Some(slot) = a.place::<Tag<AdaptiveSmith<H::T>>>() else {
        return msp_status::MSP_BUFFER_TOO_SMALL;
    };
    let values = line_values(&c);
    let line = match a.slice::<H::T>(values) {
        Ok(l) => l,
        Err(_) => return msp_status::MSP_BUFFER_TOO_SMALL,
    };
    let mut rest = Arena::new(line.as_mut_ptr().cast(), core::mem::size_of_val(line));
    let v = match make_adaptive(&c, &mut rest) {
        Ok(v) => v,
        Err(e) => return e.into(),
    };
    // SAFETY: the slot from the arena; `out` non-null
    unsafe { tag(slot, v, out) }
}

/// # Safety
/// As [`value`].
unsafe fn adaptive_update<H: Tagged>(h: *mut H, r: H::T, y: H::T, u: Option<H::T>) -> H::T {
    // SAFETY: forwarded
    match unsafe { value::<H, AdaptiveSmith<H::T>>(h) } {
        Some(c) => c.update_applied(r, y, u),
        None => <H::T as Real>::of(f64::NAN),
    }
}

/// # Safety
/// As [`value`]; `out` null or writable.
unsafe fn adaptive_state<H: Tagged>(
    h: *mut H,
    out: *mut msp_adaptive_state_of<H::T>,
) -> msp_status {
    if out.is_null() {
        return msp_status::MSP_NULL_POINTER;
    }
    // SAFETY: forwarded
    let Some(c) = (unsafe { value::<H, AdaptiveSmith<H::T>>(h) }) else {
        return bad(h);
    };
    let (k, tau, theta) = c.model();
    let s = msp_adaptive_state_of {
        estimate: estimate_of(c.estimate()),
        k,
        tau,
        theta,
        mismatch: c
            .mismatch()
            .map_or(<H::T as Real>::of(f64::NAN), |m| m.error),
        alarm: u32::from(c.alarm()),
        frozen: u32::from(c.is_frozen()),
        changes: u32::try_from(c.changes()).unwrap_or(u32::MAX),
    };
    // SAFETY: non-null, the caller's
    unsafe { out.write(s) };
    msp_status::MSP_OK
}

/// # Safety
/// As [`value`].
unsafe fn adaptive_freeze<H: Tagged>(h: *mut H, frozen: bool) -> msp_status {
    // SAFETY: forwarded
    let Some(c) = (unsafe { value::<H, AdaptiveSmith<H::T>>(h) }) else {
        return bad(h);
    };
    if frozen {
        c.freeze();
    } else {
        c.resume();
    }
    msp_status::MSP_OK
}

/// # Safety
/// `buf` is null or `len` writable bytes that stay in place; `config` and
/// `out` null or valid.
unsafe fn estimator_init<H: Tagged>(
    buf: *mut core::ffi::c_void,
    len: usize,
    config: *const msp_estimator_config_of<H::T>,
    out: *mut *mut H,
) -> msp_status {
    if buf.is_null() || out.is_null() {
        return msp_status::MSP_NULL_POINTER;
    }
    // SAFETY: forwarded
    let Some(c) = (unsafe { read(config) }) else {
        return msp_status::MSP_NULL_POINTER;
    };
    let bank = match estimator_config(&c).and_then(Bank::<H::T>::new) {
        Ok(b) => b,
        Err(e) => return e.into(),
    };
    // SAFETY: `out` non-null
    unsafe { place(&mut Arena::new(buf.cast(), len), bank, out) }
}

fn estimator_size<T: Precision>() -> usize {
    core::mem::size_of::<Tag<Bank<T>>>() + core::mem::align_of::<Tag<Bank<T>>>()
}

twins! {
    /// The defaults of an identifier for the period `ts` with candidates
    /// from `d_min` samples: forgetting 0.999, plain differences (set
    /// `prefilter` under noise), excitation 1e-6.
    ///
    /// # Safety
    /// `config` is null or writable.
    fn msp_estimator_default_config, msp_estimator_default_config_f64(
        ts: f32 | f64,
        d_min: u32,
        config: *mut msp_estimator_config | *mut msp_estimator_config_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { tuned(config, estimator_default(ts, d_min)) }
    }

    /// Builds an identifier in `buf` (`len` bytes, at least
    /// `msp_estimator_size()`); `*est` is its handle.
    ///
    /// # Safety
    /// `buf` is null or `len` writable bytes that stay in place while the
    /// identifier is used; `config` and `est` are null or valid.
    fn msp_estimator_init, msp_estimator_init_f64(
        buf: *mut core::ffi::c_void,
        len: usize,
        config: *const msp_estimator_config | *const msp_estimator_config_f64,
        est: *mut *mut msp_estimator | *mut *mut msp_estimator_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { estimator_init(buf, len, config, est) }
    }

    /// Starts the identifier from a model (FOPDT or IPDT, the latter for an
    /// integrating identifier): its dead time is the choice until the data
    /// say otherwise, every candidate starts at its coefficients, and the
    /// estimates stay plausible (the gain's sign, the time constant within a
    /// factor 20).
    ///
    /// # Safety
    /// `est` is null or from `msp_estimator_init`; `model` null or valid.
    fn msp_estimator_start_from, msp_estimator_start_from_f64(
        est: *mut msp_estimator | *mut msp_estimator_f64,
        model: *const crate::msp_model | *const crate::msp_model_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        let Some(m) = (unsafe { read(model) }) else {
            return msp_status::MSP_NULL_POINTER;
        };
        // SAFETY: forwarded
        let Some(b) = (unsafe { value::<_, Bank<_>>(est) }) else {
            return bad(est);
        };
        match fopdt_or_ipdt(&m).and_then(|(k, tau, theta)| b.start_from(k, tau, theta)) {
            Ok(()) => msp_status::MSP_OK,
            Err(e) => e.into(),
        }
    }

    /// One sample: `y` measured now, `u_applied` the input the plant
    /// receives from now on; `ok` zero for a sample that is not the
    /// process's own response (saturated, manual, a fault): nothing is
    /// learnt from it.
    ///
    /// # Safety
    /// `est` is null or from `msp_estimator_init`.
    fn msp_estimator_update, msp_estimator_update_f64(
        est: *mut msp_estimator | *mut msp_estimator_f64,
        y: f32 | f64,
        u_applied: f32 | f64,
        ok: core::ffi::c_int,
    ) -> msp_status {
        // SAFETY: forwarded
        let Some(b) = (unsafe { value::<_, Bank<_>>(est) }) else {
            return bad(est);
        };
        b.update(y, u_applied, ok != 0);
        msp_status::MSP_OK
    }

    /// The estimate now (`*out`; NaN before it means anything).
    ///
    /// # Safety
    /// `est` is null or from `msp_estimator_init`; `out` null or writable.
    fn msp_estimator_estimate, msp_estimator_estimate_f64(
        est: *mut msp_estimator | *mut msp_estimator_f64,
        out: *mut msp_estimate | *mut msp_estimate_f64,
    ) -> msp_status {
        if out.is_null() {
            return msp_status::MSP_NULL_POINTER;
        }
        // SAFETY: forwarded
        let Some(b) = (unsafe { value::<_, Bank<_>>(est) }) else {
            return bad(est);
        };
        // SAFETY: non-null, the caller's
        unsafe { out.write(estimate_of(b.estimate())) };
        msp_status::MSP_OK
    }

    /// The defaults of an adaptive Smith predictor around `smith`: the 16
    /// candidates from 6 samples below its dead time, forgetting 0.999, the
    /// prefilter 2.5 time constants, a 5 % change applied, the alarm at a
    /// 10 % model error, applying, retuned by Kaya's rule at `λ = θ`.
    ///
    /// # Safety
    /// `smith` and `config` are null or valid.
    fn msp_adaptive_default_config, msp_adaptive_default_config_f64(
        smith: *const crate::msp_smith_config | *const crate::msp_smith_config_f64,
        config: *mut msp_adaptive_config | *mut msp_adaptive_config_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        let Some(s) = (unsafe { read(smith) }) else {
            return msp_status::MSP_NULL_POINTER;
        };
        // SAFETY: forwarded
        unsafe { tuned(config, adaptive_default(&s)) }
    }

    /// The bytes `msp_adaptive_init` needs for `config` (0 and `*status`
    /// set when it is not valid; `status` may be null).
    ///
    /// # Safety
    /// `config` and `status` are null or valid.
    fn msp_adaptive_size, msp_adaptive_size_f64(
        config: *const msp_adaptive_config | *const msp_adaptive_config_f64,
        status: *mut msp_status,
    ) -> usize {
        // SAFETY: forwarded
        let Some(c) = (unsafe { read(config) }) else {
            report(status, msp_status::MSP_NULL_POINTER);
            return 0;
        };
        match adaptive_size(&c) {
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

    /// Builds an adaptive Smith predictor in `buf` (`len` bytes, at least
    /// `msp_adaptive_size(config)`); `*ctrl` is its handle.
    ///
    /// # Safety
    /// `buf` is null or `len` writable bytes that stay in place while the
    /// controller is used; `config` and `ctrl` are null or valid.
    fn msp_adaptive_init, msp_adaptive_init_f64(
        buf: *mut core::ffi::c_void,
        len: usize,
        config: *const msp_adaptive_config | *const msp_adaptive_config_f64,
        ctrl: *mut *mut msp_adaptive | *mut *mut msp_adaptive_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { adaptive_init(buf, len, config, ctrl) }
    }

    /// The estimate, the model in use, its error, the alarm (`*state`).
    ///
    /// # Safety
    /// `ctrl` is null or from `msp_adaptive_init`; `state` null or writable.
    fn msp_adaptive_read, msp_adaptive_read_f64(
        ctrl: *mut msp_adaptive | *mut msp_adaptive_f64,
        state: *mut msp_adaptive_state | *mut msp_adaptive_state_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { adaptive_state(ctrl, state) }
    }

    /// Freezes adaptation (`frozen` nonzero: nothing learnt or applied) or
    /// resumes it.
    ///
    /// # Safety
    /// `ctrl` is null or from `msp_adaptive_init`.
    fn msp_adaptive_freeze, msp_adaptive_freeze_f64(
        ctrl: *mut msp_adaptive | *mut msp_adaptive_f64,
        frozen: core::ffi::c_int,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { adaptive_freeze(ctrl, frozen != 0) }
    }
}

/// One sample: set point and measurement in, actuator value out (NaN for a
/// null or foreign handle); the plant is taken to have received the last
/// output.
///
/// # Safety
/// `ctrl` is null or from `msp_adaptive_init` with its buffer in place.
#[no_mangle]
pub unsafe extern "C" fn msp_adaptive_update(ctrl: *mut msp_adaptive, r: f32, y: f32) -> f32 {
    // SAFETY: forwarded
    unsafe { adaptive_update(ctrl, r, y, None) }
}

/// [`msp_adaptive_update`] in double precision.
///
/// # Safety
/// As [`msp_adaptive_update`].
#[no_mangle]
pub unsafe extern "C" fn msp_adaptive_update_f64(
    ctrl: *mut msp_adaptive_f64,
    r: f64,
    y: f64,
) -> f64 {
    // SAFETY: forwarded
    unsafe { adaptive_update(ctrl, r, y, None) }
}

/// One sample with the value the plant really received over the last
/// period (`u_applied`: a limit, an operator): the identifier learns from
/// what the plant got.
///
/// # Safety
/// As [`msp_adaptive_update`].
#[no_mangle]
pub unsafe extern "C" fn msp_adaptive_update_applied(
    ctrl: *mut msp_adaptive,
    r: f32,
    y: f32,
    u_applied: f32,
) -> f32 {
    // SAFETY: forwarded
    unsafe { adaptive_update(ctrl, r, y, Some(u_applied)) }
}

/// [`msp_adaptive_update_applied`] in double precision.
///
/// # Safety
/// As [`msp_adaptive_update`].
#[no_mangle]
pub unsafe extern "C" fn msp_adaptive_update_applied_f64(
    ctrl: *mut msp_adaptive_f64,
    r: f64,
    y: f64,
    u_applied: f64,
) -> f64 {
    // SAFETY: forwarded
    unsafe { adaptive_update(ctrl, r, y, Some(u_applied)) }
}

/// The bytes `msp_estimator_init` needs.
#[no_mangle]
pub extern "C" fn msp_estimator_size() -> usize {
    estimator_size::<f32>()
}

/// The bytes `msp_estimator_init_f64` needs.
#[no_mangle]
pub extern "C" fn msp_estimator_size_f64() -> usize {
    estimator_size::<f64>()
}

//! Controllers in caller-owned memory: the configurations, the handle at the
//! start of the caller's buffer, the arena that places a scheme after it, and
//! the generic functions the C entry points ([`crate::api`]) wrap.

use core::mem::{align_of, size_of};

use msp_core::dtc::compensator;
use msp_core::dtc::fsp::{design_in, FilteredSmith, FrSpec, FspDesign, FspPredictor};
use msp_core::dtc::karan_dey::{KaranDey, KaranDeyParams};
use msp_core::{
    Controller, Delay, Error, Fopdt, Ipdt, Operate, ParamList, Pid, PidConfig, ProcessModel, Real,
    SmithPredictor, Tracking, Ufopdt,
};

use crate::{msp_status, report};

mod build;
pub(crate) use build::*;

c_enum! {
    /// The kind of process model a controller is built around.
    msp_model_kind {
        /// First order plus dead time `k e^{−θs}/(τs + 1)`.
        MSP_FOPDT = 0,
        /// Integrator plus dead time `k e^{−θs}/s` (`tau` is not read).
        MSP_IPDT = 1,
        /// Unstable first order plus dead time `k e^{−θs}/(τs − 1)`.
        MSP_UFOPDT = 2,
    }
}

c_config! {
    /// A process model: its kind (an `msp_model_kind`, held as an integer so
    /// that any value a caller writes is read safely: an unknown one is
    /// `MSP_OUT_OF_RANGE`), gain `k`, time constant `tau` (s) and dead time
    /// `theta` (s).
    msp_model_of: msp_model, msp_model_f64 {
        kind: u32,
        k: T,
        tau: T,
        theta: T,
    }
}

c_config! {
    /// A PID in ISA form `kp(1 + 1/(ti s) + td s)` with actuator limits:
    /// `ti = INFINITY` removes the integral, `td = 0` the derivative (filter
    /// `td/10`), `u_min = -INFINITY`, `u_max = INFINITY` for no limits.
    msp_pid_params_of: msp_pid_params, msp_pid_params_f64 {
        kp: T,
        ti: T,
        td: T,
        u_min: T,
        u_max: T,
    }
}

c_config! {
    /// A PID controller sampled every `ts` seconds.
    msp_pid_config_of: msp_pid_config, msp_pid_config_f64 {
        ts: T,
        pid: msp_pid_params_of<T>,
    }
}

c_config! {
    /// The classic Smith predictor (Kaya (2003) Fig. 1, Bag (2022) Eq. 4.5): the PID `pid` around the
    /// model `model` (FOPDT or IPDT) and its dead time, sampled every `ts` seconds.
    msp_smith_config_of: msp_smith_config, msp_smith_config_f64 {
        ts: T,
        model: msp_model_of<T>,
        pid: msp_pid_params_of<T>,
    }
}

c_config! {
    /// The Karan–Dey modified Smith predictor for integrating plants (Bag
    /// (2022) Fig. 4.11, Eqs. 4.22–4.24): `Gc1 = kp(1 + 1/(ti s))`,
    /// `Gc2 = beta·kp`, `Gc3 = gamma·kp(1 + td s/(1 + (td/n) s))`, around an
    /// IPDT model.
    msp_karan_dey_config_of: msp_karan_dey_config, msp_karan_dey_config_f64 {
        ts: T,
        model: msp_model_of<T>,
        kp: T,
        ti: T,
        beta: T,
        gamma: T,
        td: T,
        n: T,
        u_min: T,
        u_max: T,
    }
}

c_config! {
    /// The filtered Smith predictor for unstable, integrating and stable plants
    /// (García, Santos, Normey-Rico & Albertos (2010)): the PID `pid` around the
    /// predictor `ŷ = S(z)u + Fr(z)y` with the filter time constant `tf` (s),
    /// `Fr` and `S` designed at initialization (in double precision).
    msp_fsp_config_of: msp_fsp_config, msp_fsp_config_f64 {
        ts: T,
        model: msp_model_of<T>,
        pid: msp_pid_params_of<T>,
        tf: T,
    }
}

/// A `float` controller built by an `msp_*_init` call (opaque).
pub struct msp_controller {
    _opaque: [u8; 0],
}

/// A `double` controller built by an `msp_*_init_f64` call (opaque).
pub struct msp_controller_f64 {
    _opaque: [u8; 0],
}

/// The opaque handle types of C, each with its precision: the entry points
/// of both precisions are one body ([`crate::api`]), the precision read
/// from the handle's type.
pub(crate) trait Opaque {
    /// The handle's precision.
    type T: Precision;
}

impl Opaque for msp_controller {
    type T = f32;
}

impl Opaque for msp_controller_f64 {
    type T = f64;
}

/// Storage that lives in the caller's buffer.
pub(crate) type Buf<T> = &'static mut [T];

/// The schemes one handle can hold.
pub(crate) enum Scheme<T: Real> {
    Pid(Pid<T>),
    Smith(SmithPredictor<T, 1, Buf<T>>),
    KaranDey(KaranDey<T, 1, Buf<T>>),
    Fsp(Fsp<T>),
}

/// What sits at the start of the caller's buffer: a tag saying the handle is
/// one of ours and of which precision, then the scheme (`repr(C)`: the tag
/// is the first word, read before anything else is trusted).
///
/// `update` and `ctrl` are the per-sample path: the scheme's own update
/// function and the controller inside `scheme`, so that `msp_update` is a
/// tag check and one indirect call, without a dispatch on the scheme.
#[repr(C)]
pub(crate) struct Handle<T: Real> {
    pub(crate) magic: u32,
    pub(crate) update: UpdateFn<T>,
    pub(crate) ctrl: *mut u8,
    /// The output in manual or tracking mode (then `update` is
    /// [`held_update`] and `ctrl` the handle itself).
    held: T,
    /// The scheme's own update and controller (what `update` and `ctrl` are
    /// in automatic mode).
    auto_update: UpdateFn<T>,
    auto_ctrl: *mut u8,
    scheme: Scheme<T>,
}

/// The per-sample call in manual or tracking mode: the scheme computes (its
/// model and filters see every measurement) and is amended to the held
/// output, which it returns.
///
/// # Safety
/// `h` is a handle of precision `T` (`bind_held` points `ctrl` at it).
unsafe fn held_update<T: Precision>(h: *mut u8, r: T, y: T) -> T {
    // SAFETY: `bind_held` made `ctrl` this handle's own address
    let h = unsafe { &mut *h.cast::<Handle<T>>() };
    let v = h.held;
    // SAFETY: `bind` pointed both at this handle's controller
    unsafe { (h.auto_update)(h.auto_ctrl, r, y) };
    h.operate(Apply(v, Tracking::Full));
    v
}

/// A scheme's per-sample call on its controller's address.
type UpdateFn<T> = unsafe fn(*mut u8, T, T) -> T;

/// The per-sample call of a controller of type `C` at `c`.
///
/// # Safety
/// `c` points to a live `C` (the one inside a handle).
unsafe fn update_of<T: Real, C: Controller<T>>(c: *mut u8, r: T, y: T) -> T {
    // SAFETY: the handle's `ctrl` points to its scheme's controller
    unsafe { (*c.cast::<C>()).update(r, y) }
}

impl<T: Precision> Handle<T> {
    /// Points `update` and `ctrl` at the controller in `scheme` (the handle
    /// is in its final place: the caller's buffer).
    /// `f` on the scheme as its operation trait (a match, not a trait
    /// object: a vtable would take the schemes' `update` out of line, where
    /// the per-sample call inlines it).
    fn operate<R>(&mut self, f: impl OperateFn<T, R>) -> R {
        match &mut self.scheme {
            Scheme::Smith(c) => f.call(c),
            Scheme::KaranDey(c) => f.call(c),
            Scheme::Fsp(c) => f.call(c),
            Scheme::Pid(c) => f.call(c),
        }
    }

    /// Manual or tracking mode with the output `v`.
    fn bind_held(&mut self, v: T) {
        self.held = v;
        self.update = held_update::<T>;
        self.ctrl = (self as *mut Self).cast();
    }

    fn bind(&mut self) {
        fn of<T: Real, C: Controller<T>>(c: &mut C) -> (UpdateFn<T>, *mut u8) {
            (update_of::<T, C>, (c as *mut C).cast())
        }
        (self.auto_update, self.auto_ctrl) = match &mut self.scheme {
            Scheme::Smith(c) => of(c),
            Scheme::KaranDey(c) => of(c),
            Scheme::Fsp(c) => of(c),
            Scheme::Pid(c) => of(c),
        };
        (self.update, self.ctrl) = (self.auto_update, self.auto_ctrl);
    }
}

/// A call on any scheme through [`Operate`] (generic over the scheme, which
/// a closure cannot be).
trait OperateFn<T: Real, R> {
    fn call<C: Operate<T>>(self, c: &mut C) -> R;
}

/// [`Operate::apply`].
struct Apply<T>(T, Tracking);
impl<T: Real> OperateFn<T, ()> for Apply<T> {
    fn call<C: Operate<T>>(self, c: &mut C) {
        c.apply(self.0, self.1);
    }
}

/// [`Controller::reset`].
struct Reset;
impl<T: Real> OperateFn<T, ()> for Reset {
    fn call<C: Operate<T>>(self, c: &mut C) {
        c.reset();
    }
}

/// [`msp_core::Controller::reset_to_rest`].
struct ResetToRest;
impl<T: Real> OperateFn<T, ()> for ResetToRest {
    fn call<C: Operate<T>>(self, c: &mut C) {
        c.reset_to_rest();
    }
}

/// [`Operate::retune`].
struct Retune<T>(msp_core::operate::Gain, T);
impl<T: Real> OperateFn<T, Result<(), Error>> for Retune<T> {
    fn call<C: Operate<T>>(self, c: &mut C) -> Result<(), Error> {
        c.retune(self.0, self.1)
    }
}

/// [`Operate::set_dead_time`].
struct SetDeadTime<T>(T);
impl<T: Real> OperateFn<T, Result<(), Error>> for SetDeadTime<T> {
    fn call<C: Operate<T>>(self, c: &mut C) -> Result<(), Error> {
        c.set_dead_time(self.0)
    }
}

/// The handle of a precision: its tag.
pub(crate) trait Precision: Real {
    const MAGIC: u32;
}
impl Precision for f32 {
    const MAGIC: u32 = 0x6d6d_6d6d; // one byte repeated: a Thumb-2 immediate
}
impl Precision for f64 {
    const MAGIC: u32 = 0x3636_3636;
}

/// A bump allocator over the caller's buffer.
pub(crate) struct Arena {
    at: usize,
    end: usize,
    /// Set when a request did not fit.
    pub(crate) exhausted: bool,
}

impl Arena {
    /// The arena of `len` bytes at `buf`.
    pub(crate) fn new(buf: *mut u8, len: usize) -> Self {
        let at = buf as usize;
        Arena {
            at,
            end: at.saturating_add(len),
            exhausted: false,
        }
    }

    /// Room for one `U`, aligned.
    pub(crate) fn place<U>(&mut self) -> Option<*mut U> {
        let p = self.take_bytes(size_of::<U>(), align_of::<U>())?;
        Some(p.cast())
    }

    /// `n` values of `U`, zeroed, living as long as the caller's buffer.
    pub(crate) fn slice<U: Real>(&mut self, n: usize) -> Result<&'static mut [U], Error> {
        let bytes = n.checked_mul(size_of::<U>());
        let Some(p) = bytes.and_then(|b| self.take_bytes(b, align_of::<U>())) else {
            self.exhausted = true;
            return Err(Error::DelayTooLong("buffer"));
        };
        let p = p.cast::<U>();
        for i in 0..n {
            // SAFETY: `p..p+n` is inside the caller's buffer, aligned for `U`,
            // and given out once
            unsafe { p.add(i).write(U::zero()) };
        }
        // SAFETY: as above; the caller keeps the buffer while the handle lives
        Ok(unsafe { core::slice::from_raw_parts_mut(p, n) })
    }

    /// What is left, in values of `U`.
    pub(crate) fn rest<U: Real>(&mut self) -> Result<&'static mut [U], Error> {
        let start = align_up(self.at, align_of::<U>());
        let n = start.map_or(0, |s| self.end.saturating_sub(s) / size_of::<U>());
        self.slice(n)
    }

    fn take_bytes(&mut self, bytes: usize, align: usize) -> Option<*mut u8> {
        let start = align_up(self.at, align)?;
        let stop = start.checked_add(bytes)?;
        if stop > self.end {
            self.exhausted = true;
            return None;
        }
        self.at = stop;
        Some(start as *mut u8)
    }
}

fn align_up(x: usize, align: usize) -> Option<usize> {
    let a = align.max(1);
    x.checked_add(a - 1).map(|v| v / a * a)
}

/// Bytes for a handle and `values` values of `T` (and `scratch` doubles of
/// design scratch), with the alignment slack of any buffer.
fn bytes_for<T: Precision>(values: usize, scratch: usize) -> Option<usize> {
    let slack = align_of::<Handle<T>>() + align_of::<T>() + align_of::<f64>();
    size_of::<Handle<T>>()
        .checked_add(values.checked_mul(size_of::<T>())?)?
        .checked_add(scratch.checked_mul(size_of::<f64>())?)?
        .checked_add(slack)
}

/// The handle behind a pointer, when it is one of ours of its type's precision.
///
/// # Safety
/// `ctrl` is null or was given by an `msp_*_init` call of this precision.
#[inline(always)]
pub(crate) unsafe fn handle<'a, H: Opaque>(ctrl: *mut H) -> Option<&'a mut Handle<H::T>> {
    let p = ctrl.cast::<Handle<H::T>>();
    if p.is_null() {
        return None;
    }
    // the tag alone first (a word at any alignment): the rest is a valid
    // handle only when it matches, and a handle is aligned
    // SAFETY: non-null; the caller's memory holds at least the tag
    let magic = unsafe { core::ptr::addr_of!((*p).magic).read_unaligned() };
    if magic != H::T::MAGIC {
        return None;
    }
    // SAFETY: a tagged handle was written by `init`
    unsafe { p.as_mut() }
}

pub(crate) fn reset<T: Precision>(h: &mut Handle<T>) {
    h.operate(Reset);
    h.bind();
}

pub(crate) fn reset_to_rest<T: Precision>(h: &mut Handle<T>) {
    h.operate(ResetToRest);
    h.bind();
}

pub(crate) fn fault<T: Precision>(h: &mut Handle<T>) -> bool {
    match &h.scheme {
        Scheme::Smith(c) => c.fault(),
        Scheme::KaranDey(c) => c.fault(),
        Scheme::Fsp(c) => c.fault(),
        Scheme::Pid(c) => Controller::fault(c),
    }
}

/// Reads a configuration.
///
/// # Safety
/// `p` is null or points to a readable `C`.
pub(crate) unsafe fn read<C: Copy>(p: *const C) -> Option<C> {
    // SAFETY: the caller's pointer, null-checked by `as_ref`
    unsafe { p.as_ref().copied() }
}

/// `msp_<scheme>_size` for a configuration read through `config`: `samples`
/// checks it and gives its dead time in samples.
///
/// # Safety
/// `config` and `status` are null or valid pointers.
pub(crate) unsafe fn config_size<T: Precision, C: Copy>(
    config: *const C,
    max_samples: u32,
    status: *mut msp_status,
    kind: Kind,
    samples: impl FnOnce(&C) -> Result<T, Error>,
) -> usize {
    // SAFETY: forwarded
    match unsafe { read(config) } {
        Some(c) => size_for::<T>(kind, samples(&c), max_samples, status),
        None => {
            report(status, msp_status::MSP_NULL_POINTER);
            0
        }
    }
}

/// `msp_<scheme>_init` for a configuration read through `config`.
///
/// # Safety
/// As [`init`]; `config` is null or valid.
pub(crate) unsafe fn config_init<T: Precision, C: Copy, H>(
    buf: *mut core::ffi::c_void,
    len: usize,
    config: *const C,
    ctrl: *mut *mut H,
    make: impl FnOnce(&C, &mut Arena) -> Result<Scheme<T>, Error>,
) -> msp_status {
    // SAFETY: forwarded
    let Some(c) = (unsafe { read(config) }) else {
        return msp_status::MSP_NULL_POINTER;
    };
    // SAFETY: forwarded
    unsafe { init::<T, H>(buf.cast(), len, ctrl, |a| make(&c, a)) }
}

pub(crate) fn pid_samples<T: Real>(c: &msp_pid_config_of<T>) -> Result<T, Error> {
    pid_config(&c.pid, c.ts)?;
    Ok(T::zero())
}

pub(crate) fn smith_samples<T: Real>(c: &msp_smith_config_of<T>) -> Result<T, Error> {
    takes(
        &c.model,
        &[msp_model_kind::MSP_FOPDT, msp_model_kind::MSP_IPDT],
    )?;
    pid_config(&c.pid, c.ts)?;
    Ok(dead_time(&c.model, c.ts)?.1)
}

pub(crate) fn karan_dey_samples<T: Real>(c: &msp_karan_dey_config_of<T>) -> Result<T, Error> {
    takes(&c.model, &[msp_model_kind::MSP_IPDT])?;
    Ok(dead_time(&c.model, c.ts)?.1)
}

pub(crate) fn fsp_samples<T: Real>(c: &msp_fsp_config_of<T>) -> Result<T, Error> {
    pid_config(&c.pid, c.ts)?;
    positive(c.tf, "tf")?;
    Ok(dead_time(&c.model, c.ts)?.1)
}

/// The status of a handle that is not one of ours.
pub(crate) fn bad<H>(ctrl: *mut H) -> msp_status {
    if ctrl.is_null() {
        msp_status::MSP_NULL_POINTER
    } else {
        msp_status::MSP_BAD_HANDLE
    }
}

/// The mode calls of both precisions: `f` on the handle, or the status of a
/// pointer that is not one.
///
/// # Safety
/// `ctrl` is null or from an `msp_*_init` call of precision `T`.
pub(crate) unsafe fn operate<H: Opaque>(
    ctrl: *mut H,
    f: impl FnOnce(&mut Handle<H::T>) -> Result<(), Error>,
) -> msp_status {
    // SAFETY: forwarded
    match unsafe { handle(ctrl) } {
        Some(h) => match f(h) {
            Ok(()) => msp_status::MSP_OK,
            Err(e) => e.into(),
        },
        None => bad(ctrl),
    }
}

pub(crate) fn manual<T: Precision>(h: &mut Handle<T>, u: T) -> Result<(), Error> {
    if !u.is_finite() {
        return Err(Error::NonFinite("u"));
    }
    h.bind_held(u);
    Ok(())
}

pub(crate) fn auto<T: Precision>(h: &mut Handle<T>) -> Result<(), Error> {
    h.bind();
    Ok(())
}

pub(crate) fn applied<T: Precision>(h: &mut Handle<T>, u: T) -> Result<(), Error> {
    if !u.is_finite() {
        return Err(Error::NonFinite("u_applied"));
    }
    // in manual or tracking the held value is what was applied already
    if h.ctrl != (h as *mut Handle<T>).cast() {
        h.operate(Apply(u, Tracking::Reset));
    }
    Ok(())
}

pub(crate) fn set_dead_time<T: Precision>(h: &mut Handle<T>, samples: T) -> Result<(), Error> {
    h.operate(SetDeadTime(samples))
}

pub(crate) fn retune<T: Precision>(h: &mut Handle<T>, gain: u32, value: T) -> Result<(), Error> {
    use msp_core::operate::Gain;
    let g = match gain {
        0 => Gain::Kp,
        1 => Gain::Ti,
        2 => Gain::Td,
        _ => return Err(Error::OutOfRange("gain")),
    };
    h.operate(Retune(g, value))
}

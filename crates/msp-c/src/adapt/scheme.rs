//! The adaptive schemes one handle holds, and the generic bodies of the
//! `msp_adaptive_*` and `msp_estimator_*` entry points.

use super::*;

/// The adaptive schemes one handle can hold (sized for the largest: the
/// buffer is the caller's, and a box is what the device has not).
#[allow(clippy::large_enum_variant)]
pub(super) enum Adapting<T: Real> {
    Smith(AdaptiveSmith<T>),
    KaranDey(AdaptiveKd<T>),
    Fsp(AdaptiveFsp<T>),
}

/// What the C calls ask of an adaptive scheme, whichever it is.
pub(super) trait View<T> {
    fn update_applied(&mut self, r: T, y: T, u: Option<T>) -> T;
    fn state(&self) -> msp_adaptive_state_of<T>;
    fn freeze(&mut self, frozen: bool);
    fn design(&mut self) -> bool;
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>> View<T> for Adaptive<T, C, R, N, H> {
    fn update_applied(&mut self, r: T, y: T, u: Option<T>) -> T {
        Adaptive::update_applied(self, r, y, u)
    }

    fn state(&self) -> msp_adaptive_state_of<T> {
        // the library's state, field by field under its names
        let s = Adaptive::state(self);
        msp_adaptive_state_of {
            k_hat: s.k_hat,
            tau_hat: s.tau_hat,
            theta_hat: s.theta_hat,
            evidence: s.evidence,
            k_model: s.k_model,
            tau_model: s.tau_model,
            theta_model: s.theta_model,
            adapt_changes: u32::try_from(s.adapt_changes).unwrap_or(u32::MAX),
            adapt_kind: u32::from(s.adapt_kind),
            mismatch: s.mismatch,
            model_alarm: u32::from(s.model_alarm),
            onsets: s.onsets,
            restarts: s.restarts,
            learnt: s.learnt,
            responses: s.responses,
            responses_used: s.responses_used,
            responses_ramps: s.responses_ramps,
            frozen: u32::from(s.frozen),
        }
    }

    fn freeze(&mut self, frozen: bool) {
        if frozen {
            Adaptive::freeze(self);
        } else {
            self.resume();
        }
    }

    fn design(&mut self) -> bool {
        Adaptive::design(self)
    }
}

impl<T: Real> Adapting<T> {
    fn view(&mut self) -> &mut dyn View<T> {
        match self {
            Adapting::Smith(a) => a,
            Adapting::KaranDey(a) => a,
            Adapting::Fsp(a) => a,
        }
    }
}

/// What sits at the start of the caller's buffer: the tag, then the value.
#[repr(C)]
pub(super) struct Tag<V> {
    magic: u32,
    value: V,
}

/// The value behind a handle of ours (`None`: null or another's).
///
/// # Safety
/// `p` is null or a handle from this module's `init` of the same type whose
/// buffer is in place.
pub(super) unsafe fn value<'a, H: Tagged, V>(p: *mut H) -> Option<&'a mut V> {
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
pub(super) unsafe fn place<H: Tagged, V>(a: &mut Arena, v: V, out: *mut *mut H) -> msp_status {
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
pub(super) unsafe fn tag<H: Tagged, V>(slot: *mut Tag<V>, v: V, out: *mut *mut H) -> msp_status {
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

/// A scheme's own configuration, as its adaptive one reads it.
pub(super) trait SchemeConfig<T>: Copy {
    /// Why an adaptive scheme of it needs its λ (it is redesigned at every
    /// change), `None` where it is not.
    const REDESIGNED: Option<&'static str>;
    fn model(&self) -> &msp_model_of<T>;
    fn ts(&self) -> T;
    /// Checks the settings; the dead time in samples.
    fn samples(&self) -> Result<T, Error>;
}

/// `SchemeConfig` of the configuration types: the model, the period and
/// the dead-time count, and the redesign's reason.
macro_rules! scheme_config {
    ($($config:ident, $samples:ident, $redesigned:expr;)*) => {$(
        impl<T: Real> SchemeConfig<T> for $config<T> {
            const REDESIGNED: Option<&'static str> = $redesigned;
            fn model(&self) -> &msp_model_of<T> {
                &self.model
            }
            fn ts(&self) -> T {
                self.ts
            }
            fn samples(&self) -> Result<T, Error> {
                $samples(self)
            }
        }
    )*};
}

scheme_config! {
    msp_smith_config_of, smith_samples, None;
    msp_karan_dey_config_of, karan_dey_samples, Some(
        "lambda: the Karan-Dey predictor is redesigned at every change (0: its default)",
    );
    msp_fsp_config_of, fsp_samples, Some(
        "lambda: the filtered Smith predictor is redesigned at every change (0: λ = θ)",
    );
}

/// An adaptive configuration's two parts: the scheme's own and the
/// adaptation's.
pub(super) trait Parts<T>: Sized + Copy {
    /// The dead-time lines it needs (two: a redesigned scheme warms up
    /// beside the one in use).
    const LOTS: usize;
    /// The scheme's own configuration.
    type Inner: SchemeConfig<T>;
    /// The adaptive configuration of `inner` with `adapt`.
    fn of(inner: Self::Inner, adapt: msp_adapt_config_of<T>) -> Self;
    /// The scheme's own configuration and the adaptation's.
    fn parts(&self) -> (&Self::Inner, &msp_adapt_config_of<T>);
}

/// `Parts` of the adaptive configuration types: the field that holds the
/// scheme's own configuration, its type, the lines it needs.
macro_rules! parts {
    ($($config:ident { $field:ident: $inner:ident }, $lots:literal;)*) => {$(
        impl<T: Real> Parts<T> for $config<T> {
            const LOTS: usize = $lots;
            type Inner = $inner<T>;
            fn of($field: Self::Inner, adapt: msp_adapt_config_of<T>) -> Self {
                Self { $field, adapt }
            }
            fn parts(&self) -> (&Self::Inner, &msp_adapt_config_of<T>) {
                (&self.$field, &self.adapt)
            }
        }
    )*};
}

parts! {
    msp_adaptive_config_of { smith: msp_smith_config_of }, 1;
    msp_adaptive_karan_dey_config_of { karan_dey: msp_karan_dey_config_of }, 2;
    msp_adaptive_fsp_config_of { fsp: msp_fsp_config_of }, 2;
}

/// A scheme's configuration that adapts in the caller's memory.
pub(super) trait Scheme<T: Precision>: Parts<T> {
    /// The defaults around the scheme's configuration.
    fn around(inner: Self::Inner) -> Result<Self, Error> {
        let adapt = scheme_default(inner.model(), inner.ts(), inner.samples())?;
        Ok(Self::of(inner, adapt))
    }
    fn model(&self) -> &msp_model_of<T> {
        self.parts().0.model()
    }
    fn ts(&self) -> T {
        self.parts().0.ts()
    }
    fn adapt(&self) -> &msp_adapt_config_of<T> {
        self.parts().1
    }
    /// Checks the scheme's own settings; its dead time in samples.
    fn samples(&self) -> Result<T, Error> {
        if let Some(why) = Self::Inner::REDESIGNED {
            if self.adapt().lambda.is_nan() {
                return Err(Error::NonFinite(why));
            }
        }
        self.parts().0.samples()
    }
    /// The scheme with its lines in `lots`, designed in `scratch`.
    fn make(
        &self,
        cfg: AdaptiveConfig<T>,
        lots: (Lot, Lot),
        scratch: Lot,
    ) -> Result<Adapting<T>, Error>;

    fn config(&self) -> Result<AdaptiveConfig<T>, Error> {
        self.samples()?;
        adaptive_config(self.adapt(), self.model(), self.ts())
    }

    /// Every lot's values: a dead-time line with room for the longest
    /// candidate and its fraction.
    fn values(&self) -> usize {
        (self.adapt().d_max as usize).saturating_add(3)
    }

    /// The f64 scratch of a design (none).
    fn scratch(&self) -> usize {
        0
    }
}

impl<T: Precision> Scheme<T> for msp_adaptive_config_of<T> {
    fn make(&self, cfg: AdaptiveConfig<T>, lots: (Lot, Lot), _: Lot) -> Result<Adapting<T>, Error> {
        let c = &self.smith;
        let m = fopdt_or_ipdt(&c.model)?;
        let pid = pid_config(&c.pid, c.ts)?;
        let (block, line) = model_in(&c.model, c.ts, &mut Arena::new(lots.0.at, lots.0.bytes))?;
        let sp = SmithPredictor::new(pid, block, line)?;
        let lambda = self.adapt.lambda;
        Ok(Adapting::Smith(Adaptive::new(sp, m, cfg, Kaya { lambda })?))
    }
}

impl<T: Precision> Scheme<T> for msp_adaptive_karan_dey_config_of<T> {
    fn make(&self, cfg: AdaptiveConfig<T>, lots: (Lot, Lot), _: Lot) -> Result<Adapting<T>, Error> {
        let c = &self.karan_dey;
        let m = fopdt_or_ipdt(&c.model)?;
        let kd = karan_dey_in(c, &mut Arena::new(lots.0.at, lots.0.bytes))?;
        let redesign = KaranDeyRedesign {
            ts: c.ts,
            lambda: self.adapt.lambda,
            limits: (c.u_min, c.u_max),
            lots: Lots {
                lots,
                second: false,
            },
        };
        Ok(Adapting::KaranDey(Adaptive::new(kd, m, cfg, redesign)?))
    }
}

impl<T: Precision> Scheme<T> for msp_adaptive_fsp_config_of<T> {
    /// The predictor for the longest candidate's dead time rounded up.
    fn values(&self) -> usize {
        self.lot().0
    }
    fn scratch(&self) -> usize {
        self.lot().1
    }
    fn make(
        &self,
        cfg: AdaptiveConfig<T>,
        lots: (Lot, Lot),
        scratch: Lot,
    ) -> Result<Adapting<T>, Error> {
        let c = &self.fsp;
        let m = fopdt_or_ipdt(&c.model)?;
        let mut s = Arena::new(scratch.at, scratch.bytes);
        let (design, pid) = fsp_design(c, |n| s.slice::<f64>(n))?;
        let mut a = Arena::new(lots.0.at, lots.0.bytes);
        let fsp = fsp_with(&design, pid, |n| a.slice::<T>(n))?;
        let redesign = FspRedesign {
            ts: c.ts,
            lambda: self.adapt.lambda,
            tf: c.tf,
            limits: (c.pid.u_min, c.pid.u_max),
            lots: Lots {
                lots,
                second: false,
            },
            scratch,
            built: None,
        };
        Ok(Adapting::Fsp(Adaptive::new(fsp, m, cfg, redesign)?))
    }
}

impl<T> msp_adaptive_fsp_config_of<T> {
    /// The values and the scratch of a predictor for `d_max + 1` samples.
    fn lot(&self) -> (usize, usize) {
        fsp_storage((self.adapt.d_max as usize).saturating_add(1)).unwrap_or((usize::MAX, 0))
    }
}

/// The configuration behind `config` of an `init` call whose buffer `buf`
/// and handle `out` are given (`Err`: one of the three is null).
///
/// # Safety
/// `config` is null or valid.
unsafe fn given<C: Copy, H>(
    buf: *mut core::ffi::c_void,
    config: *const C,
    out: *mut *mut H,
) -> Result<C, msp_status> {
    if buf.is_null() || out.is_null() {
        return Err(msp_status::MSP_NULL_POINTER);
    }
    // SAFETY: the caller's pointer
    unsafe { read(config) }.ok_or(msp_status::MSP_NULL_POINTER)
}

/// The defaults of adaptation for a scheme of the model `m` at `ts`.
pub(super) fn scheme_default<T: Real>(
    m: &msp_model_of<T>,
    ts: T,
    d: Result<T, Error>,
) -> Result<msp_adapt_config_of<T>, Error> {
    adapt_default(m, d?, ts)
}

/// `msp_adaptive*_default_config`.
///
/// # Safety
/// `inner` and `config` are null or valid.
pub(super) unsafe fn default_config<T: Precision, S: Scheme<T>>(
    inner: *const S::Inner,
    config: *mut S,
) -> msp_status {
    // SAFETY: forwarded
    let Some(i) = (unsafe { read(inner) }) else {
        return msp_status::MSP_NULL_POINTER;
    };
    // SAFETY: forwarded
    unsafe { tuned(config, S::around(i)) }
}

/// `msp_adaptive*_size`.
///
/// # Safety
/// `config` and `status` are null or valid.
pub(super) unsafe fn size_of_config<T: Precision, S: Scheme<T>>(
    config: *const S,
    status: *mut msp_status,
) -> usize {
    // SAFETY: forwarded
    crate::reported_size(unsafe { read(config) }, status, adaptive_size)
}

pub(super) fn adaptive_size<T: Precision, S: Scheme<T>>(c: &S) -> Result<usize, Error> {
    c.config()?;
    let line = c
        .values()
        .checked_mul(core::mem::size_of::<T>())
        .and_then(|b| b.checked_add(core::mem::align_of::<T>()))
        .and_then(|b| b.checked_mul(S::LOTS));
    let scratch = c
        .scratch()
        .checked_mul(core::mem::size_of::<f64>())
        .and_then(|b| b.checked_add(core::mem::align_of::<f64>()));
    line.zip(scratch)
        .and_then(|(l, s)| {
            core::mem::size_of::<Tag<Adapting<T>>>()
                .checked_add(core::mem::align_of::<Tag<Adapting<T>>>())?
                .checked_add(l)?
                .checked_add(s)
        })
        .ok_or(Error::DelayTooLong("buffer"))
}

/// # Safety
/// `buf` is null or `len` writable bytes that stay in place; `config` and
/// `out` null or valid.
pub(super) unsafe fn adaptive_init<H: Tagged, S: Scheme<H::T>>(
    buf: *mut core::ffi::c_void,
    len: usize,
    config: *const S,
    out: *mut *mut H,
) -> msp_status {
    // SAFETY: forwarded
    let c = match unsafe { given(buf, config, out) } {
        Ok(c) => c,
        Err(status) => return status,
    };
    let cfg = match c.config() {
        Ok(cfg) => cfg,
        Err(e) => return e.into(),
    };
    let mut a = Arena::new(buf.cast(), len);
    // the handle first (its size is known), the lines after it
    let Some(slot) = a.place::<Tag<Adapting<H::T>>>() else {
        return msp_status::MSP_BUFFER_TOO_SMALL;
    };
    fn lot<U: Real>(l: &'static mut [U]) -> Lot {
        Lot {
            at: l.as_mut_ptr().cast(),
            bytes: core::mem::size_of_val(l),
        }
    }
    let first = a.slice::<H::T>(c.values()).map(lot);
    let second = if S::LOTS > 1 {
        a.slice::<H::T>(c.values()).map(lot)
    } else {
        first
    };
    let scratch = a.slice::<f64>(c.scratch()).map(lot);
    let (Ok(first), Ok(second), Ok(scratch)) = (first, second, scratch) else {
        return msp_status::MSP_BUFFER_TOO_SMALL;
    };
    let v = match c.make(cfg, (first, second), scratch) {
        Ok(v) => v,
        Err(e) => return e.into(),
    };
    // SAFETY: the slot from the arena; `out` non-null
    unsafe { tag(slot, v, out) }
}

/// # Safety
/// As [`value`].
pub(super) unsafe fn adaptive_update<H: Tagged>(
    h: *mut H,
    r: H::T,
    y: H::T,
    u: Option<H::T>,
) -> H::T {
    // SAFETY: forwarded
    match unsafe { value::<H, Adapting<H::T>>(h) } {
        Some(c) => c.view().update_applied(r, y, u),
        None => <H::T as Real>::of(f64::NAN),
    }
}

/// # Safety
/// As [`value`]; `out` null or writable.
pub(super) unsafe fn adaptive_state<H: Tagged>(
    h: *mut H,
    out: *mut msp_adaptive_state_of<H::T>,
) -> msp_status {
    if out.is_null() {
        return msp_status::MSP_NULL_POINTER;
    }
    // SAFETY: forwarded
    let Some(c) = (unsafe { value::<H, Adapting<H::T>>(h) }) else {
        return bad(h);
    };
    // SAFETY: non-null, the caller's
    unsafe { out.write(c.view().state()) };
    msp_status::MSP_OK
}

/// # Safety
/// As [`value`].
pub(super) unsafe fn adaptive_freeze<H: Tagged>(h: *mut H, frozen: bool) -> msp_status {
    // SAFETY: forwarded
    let Some(c) = (unsafe { value::<H, Adapting<H::T>>(h) }) else {
        return bad(h);
    };
    c.view().freeze(frozen);
    msp_status::MSP_OK
}

/// # Safety
/// As [`value`]; `built` null or valid.
pub(super) unsafe fn adaptive_design<H: Tagged>(
    h: *mut H,
    built: *mut core::ffi::c_int,
) -> msp_status {
    // SAFETY: forwarded
    let Some(c) = (unsafe { value::<H, Adapting<H::T>>(h) }) else {
        return bad(h);
    };
    let done = c.view().design();
    if !built.is_null() {
        // SAFETY: non-null, the caller's
        unsafe { built.write(core::ffi::c_int::from(done)) };
    }
    msp_status::MSP_OK
}

/// # Safety
/// `buf` is null or `len` writable bytes that stay in place; `config` and
/// `out` null or valid.
pub(super) unsafe fn estimator_init<H: Tagged>(
    buf: *mut core::ffi::c_void,
    len: usize,
    config: *const msp_estimator_config_of<H::T>,
    out: *mut *mut H,
) -> msp_status {
    // SAFETY: forwarded
    let c = match unsafe { given(buf, config, out) } {
        Ok(c) => c,
        Err(status) => return status,
    };
    let bank = match estimator_config(&c).and_then(Bank::<H::T>::new) {
        Ok(b) => b,
        Err(e) => return e.into(),
    };
    // SAFETY: `out` non-null
    unsafe { place(&mut Arena::new(buf.cast(), len), bank, out) }
}

pub(super) fn estimator_size<T: Precision>() -> usize {
    core::mem::size_of::<Tag<Bank<T>>>() + core::mem::align_of::<Tag<Bank<T>>>()
}

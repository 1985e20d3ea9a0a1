//! Adaptive dead-time compensation on the device: the on-line identifier
//! (`msp_estimator_*`) and the adaptive Smith, Karan–Dey and filtered Smith
//! predictors with their model-error alarm (`msp_adaptive_*`), each in the
//! caller's memory.
//!
//! Both hold a bank of [`MSP_ADAPT_CANDIDATES`] candidate dead times
//! `d_min … d_max` (`d_max ≤ d_min + 15`) over a history of
//! [`MSP_ADAPT_HISTORY`] inputs (a dead time of at most
//! `MSP_ADAPT_HISTORY − 18` samples).

use msp_core::adapt::{Adaptive, AdaptiveConfig, Estimate, Estimator, EstimatorConfig, Redesign};
use msp_core::dtc::karan_dey::KaranDey;
use msp_core::operate::Operate;
use msp_core::{tuning, Error, Fopdt, Ipdt, ProcessModel, Real, SmithPredictor};

use crate::handle::{
    bad, fsp_design, fsp_samples, fsp_storage, fsp_with, karan_dey_in, karan_dey_samples, model_in,
    msp_fsp_config_of, msp_karan_dey_config_of, msp_model_kind, msp_model_of, msp_pid_params_of,
    msp_smith_config_of, pid_config, read, smith_samples, Arena, Buf, Fsp, Precision,
};
use crate::relay::{karan_dey_ipdt, tuned};
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
    /// the period `ts` (s), `decimation` (controller samples per estimator
    /// sample, at least 1: it learns from their means), the candidate dead
    /// times `d_min … d_max` (estimator samples; at most 16 of them),
    /// `integrating` (nonzero: `k e^{−θs}/s`), the forgetting factor
    /// (0.999: a memory of 1000 estimator samples), the prefilter's time
    /// constant (s; 0: plain differences, which a load's onset needs) and
    /// the excitation gate (the input's move needed to learn).
    msp_estimator_config_of: msp_estimator_config, msp_estimator_config_f64 {
        ts: T,
        decimation: u32,
        d_min: u32,
        d_max: u32,
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
    /// How a scheme adapts (`msp::adapt::AdaptiveConfig`): `decimation`
    /// (controller samples per estimator sample: by default a tenth of the
    /// model's dead time), the candidate dead times `d_min … d_max`
    /// (estimator samples; at most 16 of them), the estimator's
    /// `forgetting`, `prefilter` (s; 0 by default) and `excitation`, the
    /// relative change `min_change` that is applied, the factor `bound` of
    /// the commissioned gain and lag no applied estimate passes (4), the
    /// model error `alarm` that raises the alarm (`INFINITY`: none), the oscillation
    /// detector's `band` on the control error (0: four times the noise the
    /// estimator measures, the least it takes), `apply` (0: a model-error
    /// monitor only), and the closed-loop time constant
    /// `lambda` of the scheme's own tuning rule at each change (0: the
    /// rule's default; NaN: a Smith predictor's gains stay, and a
    /// Karan–Dey predictor, whose every block is designed from the model,
    /// cannot take it).
    msp_adapt_config_of: msp_adapt_config, msp_adapt_config_f64 {
        decimation: u32,
        d_min: u32,
        d_max: u32,
        forgetting: T,
        prefilter: T,
        excitation: T,
        min_change: T,
        bound: T,
        alarm: T,
        band: T,
        apply: u32,
        lambda: T,
    }
}

c_config! {
    /// An adaptive Smith predictor (`msp::adapt::Adaptive`): the predictor
    /// `smith` (FOPDT or IPDT model), its primary retuned at each change by
    /// Kaya's IMC rule (`λ = θ` by default), and how it adapts.
    msp_adaptive_config_of: msp_adaptive_config, msp_adaptive_config_f64 {
        smith: msp_smith_config_of<T>,
        adapt: msp_adapt_config_of<T>,
    }
}

c_config! {
    /// An adaptive Karan–Dey predictor (`msp::adapt::Adaptive`): the
    /// predictor `karan_dey` (IPDT model), redesigned at each change by the
    /// thesis's rule (Bag (2022) Eqs. 4.30–4.44; its default `λ` by
    /// default) and warmed up beside the one in use before it takes over,
    /// and how it adapts.
    msp_adaptive_karan_dey_config_of: msp_adaptive_karan_dey_config, msp_adaptive_karan_dey_config_f64 {
        karan_dey: msp_karan_dey_config_of<T>,
        adapt: msp_adapt_config_of<T>,
    }
}

c_config! {
    /// An adaptive filtered Smith predictor (`msp::adapt::Adaptive`): the
    /// predictor `fsp` (FOPDT or IPDT model, a dead time of whole samples),
    /// redesigned at each change for the model's dead time rounded to a
    /// sample (García et al. (2010) Sec. 3; the primary by
    /// `msp::tuning::fsp_pi`, `λ = θ` by default, the filter's `tf` kept)
    /// and warmed up beside the one in use before it takes over, and how
    /// it adapts. The model read back is the one the predictor runs: the
    /// estimate applied, its dead time rounded.
    msp_adaptive_fsp_config_of: msp_adaptive_fsp_config, msp_adaptive_fsp_config_f64 {
        fsp: msp_fsp_config_of<T>,
        adapt: msp_adapt_config_of<T>,
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

/// An adaptive controller built by `msp_adaptive_init`,
/// `msp_adaptive_karan_dey_init` or `msp_adaptive_fsp_init` (opaque).
pub struct msp_adaptive {
    _opaque: [u8; 0],
}

/// An adaptive controller built by `msp_adaptive_init_f64`,
/// `msp_adaptive_karan_dey_init_f64` or `msp_adaptive_fsp_init_f64`
/// (opaque).
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

/// A lot of the caller's memory a dead-time line is built in.
#[derive(Debug, Clone, Copy)]
struct Lot {
    at: *mut u8,
    bytes: usize,
}

/// The two lots a redesigned scheme's lines alternate between: the one in
/// use holds one, its successor is built in the other.
#[derive(Debug, Clone, Copy)]
struct Lots {
    lots: (Lot, Lot),
    /// Whether the scheme in use holds the second lot.
    second: bool,
}

impl Lots {
    /// An arena over the lot no scheme alive holds: the supervisor builds
    /// only while none it built before is warming up
    /// (`Redesign::rebuild`), so the one in use, on the other lot, is the
    /// only one.
    fn free(&self) -> Arena {
        let lot = if self.second {
            self.lots.0
        } else {
            self.lots.1
        };
        Arena::new(lot.at, lot.bytes)
    }

    /// The scheme built last took over (`Redesign::took_over`).
    fn swap(&mut self) {
        self.second = !self.second;
    }
}

/// The Karan–Dey predictor designed anew for a model: the thesis's tuning
/// (Bag (2022) Eqs. 4.30–4.44, `msp_tune_karan_dey_ipdt`) at `lambda` (0:
/// its default), the actuator's limits kept, its line in whichever of the
/// two lots the predictor in use does not hold.
struct KaranDeyRedesign<T> {
    ts: T,
    lambda: T,
    limits: (T, T),
    lots: Lots,
}

impl<T: Real> Redesign<T, Kd<T>> for KaranDeyRedesign<T> {
    fn rebuild(&mut self, k: T, tau: T, theta: T) -> Option<Kd<T>> {
        if !tau.is_infinite() {
            return None;
        }
        let mut c = karan_dey_ipdt(k, theta, self.ts, self.lambda).ok()?;
        (c.u_min, c.u_max) = self.limits;
        karan_dey_in(&c, &mut self.lots.free()).ok()
    }

    fn took_over(&mut self) {
        self.lots.swap();
    }
}

/// The filtered Smith predictor designed anew for a model: its dead time
/// rounded to whole samples (the predictor realizes `z^{−h}`; the estimate
/// is not finer under noise), the primary by [`tuning::fsp_pi`] at
/// `lambda` (0: `λ = θ`), the filter's `tf` and the actuator's limits
/// kept; designed in `scratch`, its predictor in whichever of the two lots
/// the one in use does not hold.
struct FspRedesign<T> {
    ts: T,
    lambda: T,
    tf: T,
    limits: (T, T),
    lots: Lots,
    scratch: Lot,
    /// The rounded dead time of the predictor built last (s).
    built: Option<T>,
}

impl<T: Real> Redesign<T, Fsp<T>> for FspRedesign<T> {
    fn rebuild(&mut self, k: T, tau: T, theta: T) -> Option<Fsp<T>> {
        let ts = self.ts;
        let theta = (theta / ts).round().max(T::one()) * ts;
        self.built = Some(theta);
        let (m, model): (ProcessModel<T>, _) = if tau.is_infinite() {
            let m = (k, T::zero(), msp_model_kind::MSP_IPDT);
            (Ipdt::new(k, theta).ok()?.into(), m)
        } else {
            let m = (k, tau, msp_model_kind::MSP_FOPDT);
            (Fopdt::new(k, tau, theta).ok()?.into(), m)
        };
        let lambda = if self.lambda == T::zero() {
            theta
        } else {
            self.lambda
        };
        let g = tuning::fsp_pi(&m, lambda).ok()?;
        let c = msp_fsp_config_of {
            ts,
            model: msp_model_of {
                kind: model.2 as u32,
                k: model.0,
                tau: model.1,
                theta,
            },
            pid: msp_pid_params_of {
                kp: g.kp,
                ti: g.ti,
                td: T::zero(),
                u_min: self.limits.0,
                u_max: self.limits.1,
            },
            tf: self.tf,
        };
        // the scratch holds no scheme's state (the design is copied into
        // the predictor)
        let mut scratch = Arena::new(self.scratch.at, self.scratch.bytes);
        let (design, pid) = fsp_design(&c, |n| scratch.slice::<f64>(n)).ok()?;
        let mut a = self.lots.free();
        fsp_with(&design, pid, |n| a.slice::<T>(n)).ok()
    }

    fn took_over(&mut self) {
        self.lots.swap();
    }

    fn built_dead_time(&self) -> Option<T> {
        self.built
    }
}

type Bank<T> = Estimator<T, N, H>;
type Smith<T> = SmithPredictor<T, 1, Buf<T>>;
type Kd<T> = KaranDey<T, 1, Buf<T>>;
type AdaptiveSmith<T> = Adaptive<T, Smith<T>, Kaya<T>, N, H>;
type AdaptiveKd<T> = Adaptive<T, Kd<T>, KaranDeyRedesign<T>, N, H>;
type AdaptiveFsp<T> = Adaptive<T, Fsp<T>, FspRedesign<T>, N, H>;

/// The adaptive schemes one handle can hold (sized for the largest: the
/// buffer is the caller's, and a box is what the device has not).
#[allow(clippy::large_enum_variant)]
enum Adapting<T: Real> {
    Smith(AdaptiveSmith<T>),
    KaranDey(AdaptiveKd<T>),
    Fsp(AdaptiveFsp<T>),
}

/// What the C calls ask of an adaptive scheme, whichever it is.
trait View<T> {
    fn update_applied(&mut self, r: T, y: T, u: Option<T>) -> T;
    fn state(&self) -> msp_adaptive_state_of<T>;
    fn freeze(&mut self, frozen: bool);
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>> View<T> for Adaptive<T, C, R, N, H> {
    fn update_applied(&mut self, r: T, y: T, u: Option<T>) -> T {
        Adaptive::update_applied(self, r, y, u)
    }

    fn state(&self) -> msp_adaptive_state_of<T> {
        let (k, tau, theta) = self.model();
        msp_adaptive_state_of {
            estimate: estimate_of(self.estimate()),
            k,
            tau,
            theta,
            mismatch: self.mismatch().map_or(T::nan(), |m| m.error),
            alarm: u32::from(self.alarm()),
            frozen: u32::from(self.is_frozen()),
            changes: u32::try_from(self.changes()).unwrap_or(u32::MAX),
        }
    }

    fn freeze(&mut self, frozen: bool) {
        if frozen {
            Adaptive::freeze(self);
        } else {
            self.resume();
        }
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

/// A sample count of C as an index.
fn index(v: u32, name: &'static str) -> Result<usize, Error> {
    usize::try_from(v).map_err(|_| Error::DelayTooLong(name))
}

fn estimator_config<T: Real>(c: &msp_estimator_config_of<T>) -> Result<EstimatorConfig<T>, Error> {
    let d_min = index(c.d_min, "d_min")?;
    let d_max = index(c.d_max, "d_max")?;
    if d_max < d_min || d_max - d_min >= N {
        return Err(Error::OutOfRange(
            "d_max: from d_min to d_min + 15 (16 candidates)",
        ));
    }
    let mut e = EstimatorConfig::new(c.ts, d_min);
    e.decimation = index(c.decimation, "decimation")?;
    e.d_max = Some(d_max);
    e.integrating = c.integrating != 0;
    e.forgetting = c.forgetting;
    e.set_prefilter_time(c.prefilter)?;
    e.min_excitation = c.excitation;
    e.validate()?;
    Ok(e)
}

fn estimate_of<T: Real>(e: Option<Estimate<T>>) -> msp_estimate_of<T> {
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

/// The last of the 16 candidates from `d_min`.
fn bank_end(d_min: u32) -> u32 {
    d_min.saturating_add(N as u32 - 1)
}

fn estimator_default<T: Real>(ts: T, d_min: u32) -> Result<msp_estimator_config_of<T>, Error> {
    let e = EstimatorConfig::new(ts, 0);
    let c = msp_estimator_config_of {
        ts,
        decimation: 1,
        d_min,
        d_max: bank_end(d_min),
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

/// The settings of `msp::adapt::Adaptive` for a scheme of the model `m`
/// sampled every `ts`.
fn adaptive_config<T: Real>(
    c: &msp_adapt_config_of<T>,
    m: &msp_model_of<T>,
    ts: T,
) -> Result<AdaptiveConfig<T>, Error> {
    let (_, tau, _) = fopdt_or_ipdt(m)?;
    let est = estimator_config(&msp_estimator_config_of {
        ts,
        decimation: c.decimation,
        d_min: c.d_min,
        d_max: c.d_max,
        integrating: u32::from(tau.is_infinite()),
        forgetting: c.forgetting,
        prefilter: c.prefilter,
        excitation: c.excitation,
    })?;
    let mut a = AdaptiveConfig::new(est);
    a.min_change = c.min_change;
    a.bound = c.bound;
    a.alarm = c.alarm;
    a.band = c.band;
    a.apply = c.apply != 0;
    a.validate()?;
    Ok(a)
}

/// The adaptation's defaults for a scheme of the model `m` whose dead time
/// is `d` samples at `ts`, as `msp run --adapt`'s: the estimator at a tenth
/// of the dead time per sample (`decimation`), its 16 candidates from 6
/// of its samples below the model's dead time, plain differences (no
/// prefilter: a load's onset needs them).
fn adapt_default<T: Real>(
    m: &msp_model_of<T>,
    d: T,
    ts: T,
) -> Result<msp_adapt_config_of<T>, Error> {
    let per = (d / T::of(10.0)).ceil().max(T::one());
    let whole = |x: T| {
        x.to_f64()
            .filter(|x| x.is_finite() && *x >= 0.0 && *x < f64::from(u32::MAX))
            .ok_or(Error::DelayTooLong("dead time"))
    };
    // in range: checked by whole()
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let (decimation, d_min) = (
        whole(per)? as u32,
        whole(((d / per).floor() - T::of(6.0)).max(T::zero()))? as u32,
    );
    let e = EstimatorConfig::new(ts, 0);
    let a = AdaptiveConfig::new(e);
    let c = msp_adapt_config_of {
        decimation,
        d_min,
        d_max: bank_end(d_min),
        forgetting: e.forgetting,
        prefilter: T::zero(),
        excitation: e.min_excitation,
        min_change: a.min_change,
        bound: a.bound,
        alarm: a.alarm,
        band: a.band,
        apply: 1,
        lambda: T::zero(),
    };
    adaptive_config(&c, m, ts)?;
    Ok(c)
}

/// A scheme's configuration that adapts in the caller's memory.
trait Scheme<T: Precision>: Sized + Copy {
    /// The dead-time lines it needs (two: a redesigned scheme warms up
    /// beside the one in use).
    const LOTS: usize;
    /// The scheme's own configuration.
    type Inner: Copy;
    /// The defaults around the scheme's configuration.
    fn around(inner: Self::Inner) -> Result<Self, Error>;
    fn model(&self) -> &msp_model_of<T>;
    fn ts(&self) -> T;
    fn adapt(&self) -> &msp_adapt_config_of<T>;
    /// Checks the scheme's own settings; its dead time in samples.
    fn samples(&self) -> Result<T, Error>;
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
    const LOTS: usize = 1;
    type Inner = msp_smith_config_of<T>;
    fn around(smith: Self::Inner) -> Result<Self, Error> {
        let adapt = scheme_default(&smith.model, smith.ts, smith_samples(&smith))?;
        Ok(Self { smith, adapt })
    }
    fn model(&self) -> &msp_model_of<T> {
        &self.smith.model
    }
    fn ts(&self) -> T {
        self.smith.ts
    }
    fn adapt(&self) -> &msp_adapt_config_of<T> {
        &self.adapt
    }
    fn samples(&self) -> Result<T, Error> {
        smith_samples(&self.smith)
    }
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
    const LOTS: usize = 2;
    type Inner = msp_karan_dey_config_of<T>;
    fn around(karan_dey: Self::Inner) -> Result<Self, Error> {
        let m = &karan_dey.model;
        let adapt = scheme_default(m, karan_dey.ts, karan_dey_samples(&karan_dey))?;
        Ok(Self { karan_dey, adapt })
    }
    fn model(&self) -> &msp_model_of<T> {
        &self.karan_dey.model
    }
    fn ts(&self) -> T {
        self.karan_dey.ts
    }
    fn adapt(&self) -> &msp_adapt_config_of<T> {
        &self.adapt
    }
    fn samples(&self) -> Result<T, Error> {
        if self.adapt.lambda.is_nan() {
            return Err(Error::NonFinite(
                "lambda: the Karan-Dey predictor is redesigned at every change (0: its default)",
            ));
        }
        karan_dey_samples(&self.karan_dey)
    }
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
    const LOTS: usize = 2;
    type Inner = msp_fsp_config_of<T>;
    fn around(fsp: Self::Inner) -> Result<Self, Error> {
        let adapt = scheme_default(&fsp.model, fsp.ts, fsp_samples(&fsp))?;
        Ok(Self { fsp, adapt })
    }
    fn model(&self) -> &msp_model_of<T> {
        &self.fsp.model
    }
    fn ts(&self) -> T {
        self.fsp.ts
    }
    fn adapt(&self) -> &msp_adapt_config_of<T> {
        &self.adapt
    }
    fn samples(&self) -> Result<T, Error> {
        if self.adapt.lambda.is_nan() {
            return Err(Error::NonFinite(
                "lambda: the filtered Smith predictor is redesigned at every change (0: λ = θ)",
            ));
        }
        fsp_samples(&self.fsp)
    }
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

/// The defaults of adaptation for a scheme of the model `m` at `ts`.
fn scheme_default<T: Real>(
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
unsafe fn default_config<T: Precision, S: Scheme<T>>(
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
unsafe fn size_of_config<T: Precision, S: Scheme<T>>(
    config: *const S,
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

fn adaptive_size<T: Precision, S: Scheme<T>>(c: &S) -> Result<usize, Error> {
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
unsafe fn adaptive_init<H: Tagged, S: Scheme<H::T>>(
    buf: *mut core::ffi::c_void,
    len: usize,
    config: *const S,
    out: *mut *mut H,
) -> msp_status {
    if buf.is_null() || out.is_null() {
        return msp_status::MSP_NULL_POINTER;
    }
    // SAFETY: forwarded
    let Some(c) = (unsafe { read(config) }) else {
        return msp_status::MSP_NULL_POINTER;
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
unsafe fn adaptive_update<H: Tagged>(h: *mut H, r: H::T, y: H::T, u: Option<H::T>) -> H::T {
    // SAFETY: forwarded
    match unsafe { value::<H, Adapting<H::T>>(h) } {
        Some(c) => c.view().update_applied(r, y, u),
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
    let Some(c) = (unsafe { value::<H, Adapting<H::T>>(h) }) else {
        return bad(h);
    };
    // SAFETY: non-null, the caller's
    unsafe { out.write(c.view().state()) };
    msp_status::MSP_OK
}

/// # Safety
/// As [`value`].
unsafe fn adaptive_freeze<H: Tagged>(h: *mut H, frozen: bool) -> msp_status {
    // SAFETY: forwarded
    let Some(c) = (unsafe { value::<H, Adapting<H::T>>(h) }) else {
        return bad(h);
    };
    c.view().freeze(frozen);
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
        unsafe { default_config(smith, config) }
    }

    /// The defaults of an adaptive Karan–Dey predictor around `karan_dey`
    /// (IPDT model): as `msp_adaptive_default_config`'s, the prefilter 2.5
    /// dead times, redesigned by the thesis's rule at its default `λ`.
    ///
    /// # Safety
    /// `karan_dey` and `config` are null or valid.
    fn msp_adaptive_karan_dey_default_config, msp_adaptive_karan_dey_default_config_f64(
        karan_dey: *const crate::msp_karan_dey_config | *const crate::msp_karan_dey_config_f64,
        config: *mut msp_adaptive_karan_dey_config | *mut msp_adaptive_karan_dey_config_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { default_config(karan_dey, config) }
    }

    /// The defaults of an adaptive filtered Smith predictor around `fsp`
    /// (FOPDT or IPDT model): as `msp_adaptive_default_config`'s,
    /// redesigned at `λ = θ` with its `tf` kept.
    ///
    /// # Safety
    /// `fsp` and `config` are null or valid.
    fn msp_adaptive_fsp_default_config, msp_adaptive_fsp_default_config_f64(
        fsp: *const crate::msp_fsp_config | *const crate::msp_fsp_config_f64,
        config: *mut msp_adaptive_fsp_config | *mut msp_adaptive_fsp_config_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { default_config(fsp, config) }
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
        unsafe { size_of_config(config, status) }
    }

    /// The bytes `msp_adaptive_karan_dey_init` needs for `config` (two
    /// dead-time lines: the redesigned predictor warms up beside the one in
    /// use; 0 and `*status` set when it is not valid; `status` may be null).
    ///
    /// # Safety
    /// `config` and `status` are null or valid.
    fn msp_adaptive_karan_dey_size, msp_adaptive_karan_dey_size_f64(
        config: *const msp_adaptive_karan_dey_config | *const msp_adaptive_karan_dey_config_f64,
        status: *mut msp_status,
    ) -> usize {
        // SAFETY: forwarded
        unsafe { size_of_config(config, status) }
    }

    /// The bytes `msp_adaptive_fsp_init` needs for `config` (two
    /// predictors and a design's scratch; 0 and `*status` set when it is
    /// not valid; `status` may be null).
    ///
    /// # Safety
    /// `config` and `status` are null or valid.
    fn msp_adaptive_fsp_size, msp_adaptive_fsp_size_f64(
        config: *const msp_adaptive_fsp_config | *const msp_adaptive_fsp_config_f64,
        status: *mut msp_status,
    ) -> usize {
        // SAFETY: forwarded
        unsafe { size_of_config(config, status) }
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

    /// Builds an adaptive Karan–Dey predictor in `buf` (`len` bytes, at
    /// least `msp_adaptive_karan_dey_size(config)`); `*ctrl` is its handle,
    /// for the `msp_adaptive_*` calls.
    ///
    /// # Safety
    /// `buf` is null or `len` writable bytes that stay in place while the
    /// controller is used; `config` and `ctrl` are null or valid.
    fn msp_adaptive_karan_dey_init, msp_adaptive_karan_dey_init_f64(
        buf: *mut core::ffi::c_void,
        len: usize,
        config: *const msp_adaptive_karan_dey_config | *const msp_adaptive_karan_dey_config_f64,
        ctrl: *mut *mut msp_adaptive | *mut *mut msp_adaptive_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { adaptive_init(buf, len, config, ctrl) }
    }

    /// Builds an adaptive filtered Smith predictor in `buf` (`len` bytes, at
    /// least `msp_adaptive_fsp_size(config)`); `*ctrl` is its handle, for
    /// the `msp_adaptive_*` calls.
    ///
    /// # Safety
    /// `buf` is null or `len` writable bytes that stay in place while the
    /// controller is used; `config` and `ctrl` are null or valid.
    fn msp_adaptive_fsp_init, msp_adaptive_fsp_init_f64(
        buf: *mut core::ffi::c_void,
        len: usize,
        config: *const msp_adaptive_fsp_config | *const msp_adaptive_fsp_config_f64,
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

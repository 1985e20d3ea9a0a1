//! Adaptive dead-time compensation on the device: the on-line identifier
//! (`msp_estimator_*`) and the adaptive Smith, Karan–Dey and filtered Smith
//! predictors with their model-error alarm (`msp_adaptive_*`), each in the
//! caller's memory.
//!
//! Both hold a bank of [`MSP_ADAPT_CANDIDATES`] candidate dead times
//! `d_min … d_max` (`d_max ≤ d_min + 15`) over a history of
//! [`MSP_ADAPT_HISTORY`] inputs (a dead time of at most
//! `MSP_ADAPT_HISTORY − 18` samples).

use msp_core::adapt::{
    Adaptive, AdaptiveConfig, Estimate, Estimator, EstimatorConfig, Mismatch, Redesign,
};
use msp_core::dtc::karan_dey::KaranDey;
use msp_core::operate::Operate;
use msp_core::{tuning, Error, Fopdt, Ipdt, ProcessModel, Real, SmithPredictor};

use crate::handle::{
    bad, fsp_design, fsp_samples, fsp_storage, fsp_with, karan_dey_in, karan_dey_samples, model_in,
    msp_fsp_config_of, msp_karan_dey_config_of, msp_model_kind, msp_model_of, msp_pid_params_of,
    msp_smith_config_of, pid_config, read, smith_samples, Arena, Buf, Fsp, Precision,
};
use crate::msp_status;
use crate::relay::{karan_dey_ipdt, tuned};

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
    /// times `d_min … d_max` (estimator samples; at most 16 of them; with
    /// decimation, candidate `d` is `d + 1` of them, the block's input as its
    /// means see it a block older),
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
    /// How far the model in use (`msp_estimator_set_reference`) is from
    /// the process (`msp::adapt::Mismatch`): `error`, the model's error
    /// relative to the movement it predicts (0.3: about a gain 30 % off),
    /// and the `evidence` that it is not the noise's. NaN before a whole
    /// response was compared.
    msp_mismatch_of: msp_mismatch, msp_mismatch_f64 {
        error: T,
        evidence: T,
    }
}

c_config! {
    /// How a scheme adapts (`msp::adapt::AdaptiveConfig`): `decimation`
    /// (controller samples per estimator sample: by default a tenth of the
    /// model's dead time), the candidate dead times `d_min … d_max`
    /// (estimator samples; at most 16 of them; with decimation, candidate `d`
    /// is `d + 1` of them), the estimator's
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
    /// cannot take it); `background_design` (nonzero: a Karan–Dey or a
    /// filtered Smith predictor is designed for a new model by
    /// `msp_adaptive_design`, called outside the sample, e.g. by a
    /// background task, rather than in the update that applies it: the
    /// update stays within its budget; 0 by default; a Smith predictor's
    /// model changes in place within the update's budget, and there it has
    /// no effect).
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
        background_design: u32,
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
    /// What an adaptive controller knows (the library's `AdaptiveState`,
    /// under the names of the recorded signals, as Python's
    /// `Controller.state` and a run's CSV give them): the estimate
    /// `k_hat`, `tau_hat`, `theta_hat` (NaN before it means anything) and
    /// the `evidence` for its dead time, the model in use `k_model`,
    /// `tau_model`, `theta_model` (`tau` `INFINITY`: integrating), the
    /// changes logged `adapt_changes` and the last one's kind `adapt_kind`
    /// (1 applied, 2 restored, 3 refused, 4 alarm, 5 cleared, 6 emergency,
    /// 7 detuned, 8 edge; 0 none), its error against the process
    /// `mismatch` (0.3: 30 %; NaN before it means anything), the alarm
    /// `model_alarm`, the estimator's counts `onsets`, `restarts`,
    /// `learnt` (0: nothing has moved the loop enough to identify the
    /// process), `responses` (the responses, a load's or a set-point change's, the level test compared)
    /// `responses_used` (those it took as evidence) and `responses_ramps`
    /// (those it found a ramp load's: while they outnumber the ones taken
    /// since the model in use was set, it holds back), and whether
    /// adaptation is `frozen`.
    msp_adaptive_state_of: msp_adaptive_state, msp_adaptive_state_f64 {
        k_hat: T,
        tau_hat: T,
        theta_hat: T,
        evidence: T,
        k_model: T,
        tau_model: T,
        theta_model: T,
        adapt_changes: u32,
        adapt_kind: u32,
        mismatch: T,
        model_alarm: u32,
        onsets: u32,
        restarts: u32,
        learnt: u32,
        responses: u32,
        responses_used: u32,
        responses_ramps: u32,
        frozen: u32,
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

type Bank<T> = Estimator<T, N, H>;
type Smith<T> = SmithPredictor<T, 1, Buf<T>>;
type Kd<T> = KaranDey<T, 1, Buf<T>>;
type AdaptiveSmith<T> = Adaptive<T, Smith<T>, Kaya<T>, N, H>;
type AdaptiveKd<T> = Adaptive<T, Kd<T>, KaranDeyRedesign<T>, N, H>;
type AdaptiveFsp<T> = Adaptive<T, Fsp<T>, FspRedesign<T>, N, H>;

mod redesign;
mod scheme;
mod settings;

use redesign::*;
use scheme::*;
use settings::*;

twins! {
    /// The defaults of an identifier for the period `ts` with candidates
    /// from `d_min` samples: no decimation, forgetting 0.999, plain
    /// differences (a load's onset needs them), excitation 1e-6.
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
        unsafe { with_model(est, model, Bank::start_from) }
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

    /// The model in use, which the estimator weighs against its own
    /// (`msp_estimator_mismatch`): a FOPDT or IPDT `model`.
    ///
    /// # Safety
    /// `est` is null or from `msp_estimator_init`; `model` null or valid.
    fn msp_estimator_set_reference, msp_estimator_set_reference_f64(
        est: *mut msp_estimator | *mut msp_estimator_f64,
        model: *const crate::msp_model | *const crate::msp_model_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { with_model(est, model, Bank::set_reference) }
    }

    /// The model in use against the process (`*out`): over the costs'
    /// long memory (`recent` zero: what gates an applied model), or over
    /// the last response only (`recent` nonzero: the monitor's quick view,
    /// beside the change detector's simulations at every dead time, and at
    /// the chosen one with other gains and lags).
    ///
    /// # Safety
    /// `est` is null or from `msp_estimator_init`; `out` null or writable.
    fn msp_estimator_mismatch, msp_estimator_mismatch_f64(
        est: *mut msp_estimator | *mut msp_estimator_f64,
        recent: core::ffi::c_int,
        out: *mut msp_mismatch | *mut msp_mismatch_f64,
    ) -> msp_status {
        if out.is_null() {
            return msp_status::MSP_NULL_POINTER;
        }
        // SAFETY: forwarded
        let Some(b) = (unsafe { value::<_, Bank<_>>(est) }) else {
            return bad(est);
        };
        let m = if recent != 0 {
            b.recent_mismatch()
        } else {
            b.mismatch()
        };
        // SAFETY: non-null, the caller's
        unsafe { out.write(mismatch_of(m)) };
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

    /// Designs the Karan–Dey or filtered Smith predictor a new model waits
    /// for (`background_design`): call it outside the sample, e.g. from a
    /// background task, with the controller not updated meanwhile. `*built`
    /// (when not null) is 1 where one was designed (it warms up beside the
    /// one in use and takes over, as the change logged), 0 where none was
    /// waiting or the design failed (adaptation frozen, logged as refused).
    ///
    /// # Safety
    /// `ctrl` is null or from `msp_adaptive_init`; `built` null or valid.
    fn msp_adaptive_design, msp_adaptive_design_f64(
        ctrl: *mut msp_adaptive | *mut msp_adaptive_f64,
        built: *mut core::ffi::c_int,
    ) -> msp_status {
        // SAFETY: forwarded
        unsafe { adaptive_design(ctrl, built) }
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

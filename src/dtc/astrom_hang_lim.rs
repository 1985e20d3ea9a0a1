//! Åström, Hang and Lim's Smith predictor for an integrator plus dead time
//! (Bag (2022) Sec. 4.4.2, Eqs. 4.13–4.17; IEEE TAC 39(2), 1994).
//!
//! The set point acts through a gain on the delay-free model only,
//! `u1 = kp·(r − ym)` with `kp = k/Kv`, so `y/r = k/(s + k)·e^{−Ls}` (Eq. 4.14);
//! the model error reaches the plant input only through the disturbance
//! compensator `M(s)` ([`AhlFilter`]), so `y/d = G e^{−Ls}/(1 + M G e^{−Ls})`
//! (Eq. 4.15): the two responses are decoupled, and `M` does not change the
//! set-point response (tested).

use crate::delay::Delay;
use crate::dtc::compensator::{AhlFilter, Compensator, DisturbancePath, ErrorPath};
use crate::params::{param_struct, ParamList};
use crate::{error::Error, lti::Lti, pid::Pid, pid::PidConfig, real::Real};

pub use crate::dtc::compensator::AhlFilter as DisturbanceCompensator;

param_struct! {
    /// Parameters of the Åström–Hang–Lim predictor (Bag (2022) Eqs. 4.14–4.17).
    pub struct AstromHangLimParams {
        /// Set-point pole `k` (1/s): `y/r = k/(s + k)·e^{−Ls}`.
        k: Positive,
        /// `M(s)`'s `k1`.
        k1: Finite,
        /// `M(s)`'s `k2`.
        k2: Finite,
        /// `M(s)`'s `k3`.
        k3: Finite,
    }
}

crate::params::design_struct! {
    /// Design inputs of the Åström–Hang–Lim predictor.
    pub struct AstromHangLimTuning {
        /// The load loop's double pole `−a` (1/s); default `1/L`.
        a,
    }
}

/// The compensator for the model `kv·e^{−Ls}/s`; `line` holds `L` again for `M(s)`.
pub fn build<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>>(
    p: &AstromHangLimParams<T>,
    kv: T,
    ts: T,
    model: Lti<T, N>,
    delay: Delay<T, S>,
    line: Delay<T, S>,
) -> Result<Compensator<T, N, S>, Error> {
    let k = crate::real::positive(p.k, "k")?;
    let gc1 = Pid::new(PidConfig::parallel(k / kv, T::zero(), T::zero(), ts))?;
    let m = AhlFilter::new(p.k1, p.k2, p.k3, kv, ts, line)?;
    Ok(Compensator::new(gc1, model, delay, ParamList::of(p))?
        .with_error_path(ErrorPath::Blocked)?
        .with_disturbance(DisturbancePath::AstromHangLim(m)))
}

//! The Smith predictor with a filter on the model error
//! (the MathWorks Smith predictor example, "Smith Predictor" and "Improving Robustness").
//!
//! `e = r − yp − F·(y − y1)`: the model error `dy = y − y1` passes through
//! `F` before it corrects the prediction. With a perfect model `dy = 0`, so the
//! set-point response is the classic Smith predictor's whatever `F`; `F` shapes
//! the load response and the robustness of the outer loop. The example uses
//! `F = 1/(20s + 1)` and, for more robustness, the lead-lag `(1 + 10s)/(1 + 100s)`;
//! any proper rational `F` is accepted. The PI is designed on the delay-free
//! model for a closed-loop time constant `λ` ([`crate::tuning::kaya`]: for
//! `5.6/(40.2s + 1)` and `λ = 12.5 s` it gives the example's `Kp = 0.574`, `Ti = 40.2`).

use crate::delay::Delay;
use crate::dtc::compensator::{Compensator, ErrorPath, AUX};
use crate::params::ParamList;
use crate::{error::Error, lti::Lti, pid::Pid, pid::PidConfig, real::Real};

crate::pid::pid_params! {
    /// Parameters of the filtered Smith predictor: the PID and the lead-lag
    /// filter `F = (1 + a·s)/(1 + b·s)` on the model error (Normey-Rico &
    /// Camacho's filter). The PID's design does not read `F`: the tuning
    /// gives the MathWorks example's defaults, and `--set a=…` replaces them.
    pub struct FilteredSmithParams {
        /// Lead time constant `a` of `F` (s); tuned: 0.
        a: NonNegative,
        /// Lag time constant `b` of `F` (s), tuned: half the model's dominant
        /// lag; `a = b = 0`: no filter.
        b: NonNegative,
    }
}

/// The filter `F = (1 + a·s)/(1 + b·s)` ZOH-discretized (`a = 0`: first order `1/(b s + 1)`;
/// `b = 0`: no filter).
pub fn lead_lag_filter<T: Real>(a: T, b: T, ts: T) -> Result<Lti<T, AUX>, Error> {
    Lti::lead_lag(T::one(), a, b, ts)
}

/// The filtered Smith predictor with primary `pid` (its gains `p.kp`, `p.ti`,
/// `p.td`; it carries the period and limits) and the filter `F` of `p`.
pub fn build<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>>(
    pid: PidConfig<T>,
    p: &FilteredSmithParams<T>,
    model: Lti<T, N>,
    delay: Delay<T, S>,
) -> Result<Compensator<T, N, S>, Error> {
    let f = lead_lag_filter(p.a, p.b, pid.ts)?;
    Compensator::new(Pid::new(pid)?, model, delay, ParamList::of(p))?
        .with_error_path(ErrorPath::Filter(f))
}

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
use crate::dtc::compensator::{Compensator, ErrorPath, ParamList, AUX};
use crate::{Discretization, Error, Lti, Pid, PidConfig, Real};

/// Parameter names: the PID and the lead-lag filter `F = (1 + a·s)/(1 + b·s)`.
pub const PARAMS: &[&str] = &["kp", "ti", "td", "a", "b"];

/// The filter `F = (1 + a·s)/(1 + b·s)` ZOH-discretized (`a = 0`: first order `1/(b s + 1)`;
/// `b = 0`: no filter).
pub fn lead_lag_filter<T: Real>(a: T, b: T, ts: T) -> Result<Lti<T, AUX>, Error> {
    if b == T::zero() && a == T::zero() {
        return Lti::gain(T::one());
    }
    Lti::from_tf(
        &[a, T::one()],
        &[crate::real::positive(b, "b")?, T::one()],
        ts,
        Discretization::Zoh,
    )
}

/// The filtered Smith predictor with primary `pid` and filter `f` (any block).
pub fn build<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>>(
    pid: PidConfig<T>,
    f: Lti<T, AUX>,
    model: Lti<T, N>,
    delay: Delay<T, S>,
    params: ParamList<T>,
) -> Result<Compensator<T, N, S>, Error> {
    Compensator::new(Pid::new(pid)?, model, delay, params)?.with_error_path(ErrorPath::Filter(f))
}

//! The Smith predictor with Huang's approximate inverse of dead time
//! (the MathWorks Smith predictor example, "Improving Disturbance Rejection", after
//! Huang et al., AIChE J. 36, 1990).
//!
//! The ideal filter on the model error would be `e^{+τs}` (a perfect load
//! rejection, not causal). Huang's phase-lead approximation is
//!
//! `F(s) = (1 + B(s))/(1 + B(s)·e^{−τs})`,
//!
//! with `B` a low-pass filter with the model's time constant (the example:
//! `B = 0.05/(40s + 1)`, `τ` the model dead time); realized as
//! `f = x + B·(x − e^{−τs}·f)`. The set-point response stays the Smith
//! predictor's; the PI is re-designed slower (the example: `Kp = 0.144`,
//! `Ti = 40.1`).

use crate::delay::Delay;
use crate::dtc::compensator::{Compensator, ErrorPath};
use crate::params::ParamList;
use crate::{error::Error, lti::Discretization, lti::Lti, pid::Pid, pid::PidConfig, real::Real};

crate::pid::pid_params! {
    /// Parameters of Huang's predictor: the PID and `B = kb/(tb·s + 1)`.
    /// The PID's design does not read `B`: the tuning gives the MathWorks
    /// example's (`B = 0.05/(40 s + 1)` for the 40.2 s lag), and `--set kb=…`
    /// replaces it.
    pub struct HuangParams {
        /// Gain of `B`; tuned: 0.05.
        kb: Finite,
        /// Time constant of `B` (s); tuned: the model's dominant lag.
        tb: Positive,
    }
}

/// The predictor with `B = kb/(tb s + 1)`; `line` holds the model dead time
/// again (it delays `f`), at least one sample.
pub fn build<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>>(
    pid: PidConfig<T>,
    p: &HuangParams<T>,
    model: Lti<T, N>,
    delay: Delay<T, S>,
    line: Delay<T, S>,
) -> Result<Compensator<T, N, S>, Error> {
    let b = Lti::from_tf(
        &[crate::real::finite(p.kb, "kb")?],
        &[crate::real::positive(p.tb, "tb")?, T::one()],
        pid.ts,
        Discretization::Zoh,
    )?;
    Compensator::new(Pid::new(pid)?, model, delay, ParamList::of(p))?
        .with_error_path(ErrorPath::Huang { b, line })
}

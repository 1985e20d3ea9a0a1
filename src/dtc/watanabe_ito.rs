//! Watanabe and Ito's process-model control for integrating plants
//! (Bag (2022) Sec. 4.4.1, Fig. 4.8, Eq. 4.12; Watanabe & Ito,
//! IEEE TAC 26(6), 1981 — ref. \[3\] of Draganović et al. (2001)).
//!
//! The thesis names the scheme and its filter `G1(s) = 1/(1 + sL)` but its
//! figure is missing. Built here from the published idea: the classic
//! predictor `Gm(s)(1 − e^{−Ls})` of an integrating model has the static gain
//! `Kv·L`, which under a constant load leaves the offset `Kv·L·d` of the
//! classic Smith predictor; Watanabe and Ito subtract `m(s) = Kv·L·G1(s)`, a
//! stable block with the same static gain, from the prediction:
//!
//! `e = r − y − [Gm(s)(1 − e^{−Ls}) − Kv·L/(1 + sL)]·u`.
//!
//! The predictor then has zero static gain and a PI primary controller
//! removes constant loads (the defining property, tested). The price is a
//! set-point response no longer exactly the delay-free one.

use crate::delay::Delay;
use crate::dtc::compensator::Compensator;
use crate::params::ParamList;
use crate::pid::PidGains;
use crate::{error::Error, lti::Lti, pid::Pid, pid::PidConfig, real::Real};

/// The compensator for an integrating model with velocity gain `kv` and dead
/// time `l` (s); `pid` (gains `p`) carries the period and limits.
pub fn build<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>>(
    pid: PidConfig<T>,
    p: &PidGains<T>,
    kv: T,
    l: T,
    model: Lti<T, N>,
    delay: Delay<T, S>,
) -> Result<Compensator<T, N, S>, Error> {
    Compensator::new(Pid::new(pid)?, model, delay, ParamList::of(p))?
        .with_integrating_correction(kv, l, pid.ts)
}

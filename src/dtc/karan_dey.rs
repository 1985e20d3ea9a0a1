//! The Karan–Dey three-controller modified Smith predictor (MSP) for
//! integrating processes with long dead time (Bag (2022) Sec. 4.5).
//!
//! Controllers (Eqs. 4.22–4.24):
//! `Gc1 = Kp(1 + 1/(Ti s))` (set-point, IMC-PI), `Gc2 = β·Kp` (stabilizing, P),
//! `Gc3 = γ·Kp(1 + Td s/(1 + (Td/N) s))` (disturbance rejection, PD with a
//! derivative filter; the thesis leaves `Gc3` unfiltered, which is not
//! realizable — `N = 10` by default, the same ratio as Kaya–Atherton's
//! `Gc3 = kb(Td s + 1)/(0.1 Td s + 1)` in Sec. 4.4.3).
//!
//! The thesis's block diagram (Fig. 4.11) is missing from the source. This
//! realization reproduces its set-point response (Eq. 4.20) and its
//! disturbance response (Eq. 4.21 with the term `Gc1·Gc3·e^{−θs}` read as
//! `Gm·Gc1·e^{−θs}`, see the seeds' README):
//!
//! ```text
//! u1 = Gc1·(r − ym − ε) − Gc2·ym      ym = Gm·u1  (delay-free model)
//! ε  = y − e^{−θm s}·ym               u  = u1 − Gc3·ε
//! ```
//!
//! Derivation: with `y = e^{−θs}G(u + d)` and a perfect model,
//! `ε = e^{−θs}G(d − Gc3 ε)`, so `ε = e^{−θs}G d/(1 + Gc3 G e^{−θs})` (the
//! characteristic equation 4.41) and `ε = 0` without a load: then
//! `y = e^{−θs}·ym = e^{−θs}·Gm Gc1/(1 + Gm(Gc1 + Gc2))·r`, Eq. 4.20. With the
//! tuning of [`crate::tuning::karan_dey`] this is exactly `e^{−θs}/(1 + θs/8)`.
//! Under a constant input load `d`, `ε → d/(γKp)`, the integral of `Gc1`
//! drives `ym → r − ε`, so `y → r` (zero steady-state error) and `u → −d`.

use crate::delay::{Delay, DelayStorage};
use crate::dtc::compensator::{self, Compensator, CompensatorParams, Controllers};
use crate::params::{param_struct, ParamSet};
use crate::real::finite;
use crate::{error::Error, lti::Lti, model::ProcessModel, pid::Pid, pid::PidConfig, real::Real};

param_struct! {
    /// Tuned parameters of the Karan–Dey MSP (names as in reports and `--set`).
    pub struct KaranDeyParams {
        /// Proportional gain `Kp` shared by the three controllers (negative
        /// for a plant of negative gain).
        kp: Finite,
        /// Integral time `Ti` of `Gc1` (s).
        ti: Positive,
        /// Weight `β` of `Gc2 = β·Kp`.
        beta: NonNegative,
        /// Weight `γ` of `Gc3 = γ·Kp(1 + Td s)`.
        gamma: NonNegative,
        /// Derivative time `Td` of `Gc3` (s).
        td: NonNegative,
        /// Derivative filter ratio `N` of `Gc3` (`Tf = Td/N`).
        n: Positive,
    }
}

/// The Karan–Dey MSP: the general [`Compensator`] configured with `Gc1` (PI),
/// `Gc2 = β·Kp` on the model output and `Gc3` on the model error.
pub type KaranDey<T, const N: usize, S> = Compensator<T, N, S>;

/// The MSP's controllers, sampled every `ts` (built around the delay-free
/// model by [`compensator::build`]): `Gc1` PI, `Gc2 = β·Kp`, and
/// `Gc3 = γKp(1 + Td s/(1 + (Td/N)s))` as the lead-lag
/// `γKp(1 + (Td + Td/N)s)/(1 + (Td/N)s)`, ZOH-discretized.
impl<T: Real> CompensatorParams<T> for KaranDeyParams<T> {
    fn controllers(&self, ts: T) -> Result<Controllers<T>, Error> {
        self.validate()?;
        let p = self;
        let tf = p.td / p.n;
        Ok(Controllers {
            gc1: Pid::new(PidConfig::isa(p.kp, p.ti, T::zero(), ts))?,
            gc2: Some(Pid::new(PidConfig::parallel(
                p.beta * p.kp,
                T::zero(),
                T::zero(),
                ts,
            ))?),
            gc3: Some(Lti::lead_lag(p.gamma * p.kp, p.td + tf, tf, ts)?),
        })
    }
}

/// [`compensator::build`] with the model ZOH-discretized from a process model.
pub fn from_model<T: Real, const N: usize, S: DelayStorage<T>>(
    p: &KaranDeyParams<T>,
    model: &ProcessModel<T>,
    ts: T,
) -> Result<KaranDey<T, N, S>, Error> {
    let (block, d) = model.discretize::<N>(finite(ts, "ts")?)?;
    compensator::build(p, ts, block, Delay::new_in(d)?)
}

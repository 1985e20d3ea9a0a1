//! The Smith predictor with a disturbance estimator for integrating plants
//! (Draganović et al. (2001), Draganović, Stojić & Matijević; Fig. 1, Eqs. 1–17).
//!
//! The figure is missing from the source; the realization follows from Eq. 1:
//! the classic Smith predictor with the P main controller `Kr` produces `u`
//! (its models driven by `u`), the disturbance estimator
//! `d̂ = A(s)/C(s)·(y − Gm·u)` acts on the model error, and the plant receives
//! `u − d̂`. Substituting gives exactly Eq. 1; in the nominal case
//! `y/r = Kr Kν/(s + Kr Kν)·e^{−Ls}` (Eq. 15, time constant `Td = 1/(Kr Kν)`)
//! and the load response is governed by `1 + A/C·Kν e^{−Ls}/s = 0` (Eq. 19).
//! The six designs of `A/C` are in [`crate::tuning::disturbance_estimator`].

use crate::dtc::compensator::{CompensatorParams, Controllers};
use crate::params::param_struct;
use crate::{error::Error, lti::Discretization, lti::Lti, pid::Pid, pid::PidConfig, real::Real};

param_struct! {
    /// Parameters of the predictor with a disturbance estimator
    /// (Draganović et al. (2001)): the main gain, the case and its design.
    pub struct DisturbanceEstimatorParams {
        /// Main gain `Kr` (`Kr = 1/(Kν·Td)`, Eq. 15).
        kr: Finite,
        /// Set-point time constant `Td` (s) `Kr` was tuned for.
        td: Any,
        /// Estimator design, case 1–6.
        case: Finite,
        /// Estimator gain `K_A`.
        ka: Finite,
        /// Estimator time constant `T_A` (s).
        ta: NonNegative,
        /// Estimator filter time constant `T_C` (s).
        tc: NonNegative,
        /// Design: the estimator's dominant time constant `T_de` (s).
        tde: Any,
        /// Design: the damping or pole ratio `α` of the case.
        alpha: Any,
        /// Resonance `ω0` of case 6 (rad/s).
        w0: Finite,
    }
}

crate::params::design_struct! {
    /// Design inputs of the disturbance estimator (Draganović et al. (2001)).
    /// `alpha` is the case's damping or pole ratio here (default 0.5; 0.95
    /// for Case 6), and also sets `td = alpha·L` when `td` and `lambda` are absent.
    pub struct DisturbanceEstimatorTuning {
        /// Set-point time constant `Td` (s); default `λ` (`L/4`).
        td,
        /// The case, 1–6; default 1.
        case,
        /// The estimator's dominant time constant `T_de` (s); default `0.55·L`.
        tde,
        /// Frequency of the sine disturbance of Case 6 (rad/s); default 0.05.
        w0,
    }
}

/// The case number 1–6 of a real value; the error names `case`.
pub fn case_number<T: Real>(case: T) -> Result<u8, Error> {
    (1u8..=6)
        .find(|c| T::of(f64::from(*c)) == case)
        .ok_or(Error::OutOfRange("case"))
}

/// The estimator `A(s)/C(s)` in descending powers of `s` (degree ≤ 2).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Estimator<T> {
    /// Numerator `A(s)`.
    pub a: [T; 3],
    /// Denominator `C(s)`.
    pub c: [T; 3],
}

impl<T: Real> Estimator<T> {
    /// `A(s)/C(s)` of case 1–6 from its gains (Draganović et al. (2001) Eqs. 20, 23, 31, 41, 58 —
    /// case 2's PD with a derivative filter `C = T_A/10·s + 1` to make it proper,
    /// case 6 with `C = (s² + ω0²)/ω0`, see [`crate::tuning::disturbance_estimator`]).
    pub fn from_case(case: u8, ka: T, ta: T, tc: T, w0: T) -> Result<Self, Error> {
        let (z, o) = (T::zero(), T::one());
        let ka = crate::real::finite(ka, "ka")?;
        let ta = crate::real::non_negative(ta, "ta")?;
        let tc = crate::real::non_negative(tc, "tc")?;
        Ok(match case {
            1 => Estimator {
                a: [z, z, ka],
                c: [z, z, o],
            },
            // the PD of Eq. 23 is improper; its derivative is filtered with T_A/10
            2 => Estimator {
                a: [z, ka * ta, ka],
                c: [z, ta / T::of(10.0), o],
            },
            3 => Estimator {
                a: [z, ka * ta, ka],
                c: [z, crate::real::positive(tc, "tc")?, o],
            },
            4 | 5 => Estimator {
                a: [z, ka * ta, ka],
                c: [z, crate::real::positive(ta, "ta")?, z],
            },
            6 => {
                let w0 = crate::real::positive(w0, "w0")?;
                Estimator {
                    a: [ka * ta, ka, z],
                    c: [o / w0, z, w0],
                }
            }
            _ => return Err(Error::OutOfRange("case")),
        })
    }
}

/// The predictor's main gain `p.kr` and the estimator `A(s)/C(s)` of case
/// `p.case` on the model error, sampled every `ts`.
impl<T: Real> CompensatorParams<T> for DisturbanceEstimatorParams<T> {
    fn controllers(&self, ts: T) -> Result<Controllers<T>, Error> {
        let p = self;
        let est = Estimator::from_case(case_number(p.case)?, p.ka, p.ta, p.tc, p.w0)?;
        Ok(Controllers {
            gc1: Pid::new(PidConfig::parallel(p.kr, T::zero(), T::zero(), ts))?,
            gc2: None,
            gc3: Some(Lti::from_tf(&est.a, &est.c, ts, Discretization::Zoh)?),
        })
    }
}

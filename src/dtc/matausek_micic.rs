//! Matausek and Micic's modified Smith predictor for an integrator and long
//! dead time (Bag (2022) Sec. 4.4.3, refs. \[8\], \[52\]; IEEE TAC
//! 41(8), 1996).
//!
//! The thesis only names it. Built from the published structure: a classic
//! Smith predictor with the P set-point controller `Kr = 1/(Kv·Tr)` on the
//! model `Kv e^{−Ls}/s` (first-order set-point response with time constant
//! `Tr`), plus a proportional feedback `K0` of the model error to the plant
//! input that rejects constant loads. Its three tuning parameters are those of
//! the paper's abstract: `L`, `Kv` and `Tr`; `K0 = 1/(2·Kv·L)` makes the load
//! loop `1 + K0 Kv e^{−Ls}/s` aperiodic (the M-circle condition,
//! Draganović et al. (2001) Eq. 22). Defining properties (tested): the
//! set-point response `e^{−Ls}/(Tr s + 1)` and zero steady-state error under
//! a constant load.

use crate::dtc::compensator::{CompensatorParams, Controllers};
use crate::params::param_struct;
use crate::{error::Error, lti::Lti, pid::Pid, pid::PidConfig, real::Real};

param_struct! {
    /// Parameters of the Matausek–Micić predictor.
    pub struct MatausekMicicParams {
        /// Set-point gain `kr` (`kr = 1/(Kv·tr)`).
        kr: Finite,
        /// Load feedback gain `k0`.
        k0: Finite,
        /// Set-point time constant `tr` (s) the gain `kr` was tuned for.
        tr: Any,
    }
}

crate::params::design_struct! {
    /// Design inputs of the Matausek–Micić predictor.
    pub struct MatausekMicicTuning {
        /// Set-point time constant `Tr` (s); default `λ`.
        tr,
    }
}

/// The predictor's set-point gain `p.kr` and load feedback `p.k0`.
impl<T: Real> CompensatorParams<T> for MatausekMicicParams<T> {
    fn controllers(&self, ts: T) -> Result<Controllers<T>, Error> {
        Ok(Controllers {
            gc1: Pid::new(PidConfig::parallel(self.kr, T::zero(), T::zero(), ts))?,
            gc2: None,
            gc3: Some(Lti::gain(self.k0)?),
        })
    }
}

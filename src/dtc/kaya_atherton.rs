//! Kaya and Atherton's PI-PD Smith predictor (Bag (2022)
//! Sec. 4.4.3, Fig. 4.10, Eq. 4.18; a modification of Matausek & Micic 1996).
//!
//! Three controllers around the model: `Gc1` PI on the predicted error, `Gc2`
//! P or PD in the inner feedback of the model output (it moves the poles of
//! the model loop, which matters for integrating and unstable models), and the
//! disturbance controller `Gc3 = kb(Td s + 1)/(0.1·Td s + 1)` on the model
//! error at the plant input (Eq. 4.18). The figure is missing from the
//! thesis; the realization is the same skeleton as the Karan–Dey MSP
//! ([`crate::dtc::compensator`]), which the thesis derives from it.

use crate::dtc::compensator::{CompensatorParams, Controllers};
use crate::{error::Error, lti::Lti, pid::Pid, pid::PidConfig, real::Real};

crate::params::base_struct! { $ kaya_atherton_params;
    /// Parameters of the PI-PD Smith predictor: `Gc1 = kp(1 + 1/(ti s))`,
    /// `Gc2 = kf(1 + tf s)`, `Gc3 = kb(td s + 1)/(0.1 td s + 1)`;
    /// `kaya_atherton_params!` declares a scheme's built around this
    /// predictor (these first).
    pub struct KayaAthertonParams {
        /// Proportional gain of `Gc1`.
        kp: Finite,
        /// Integral time of `Gc1` (s).
        ti: Positive,
        /// Gain of `Gc2`.
        kf: Finite,
        /// Derivative time of `Gc2` (s).
        tf: NonNegative,
        /// Gain of `Gc3`.
        kb: Finite,
        /// Lead time of `Gc3` (s).
        td: NonNegative,
    }
}

/// The PI-PD Smith predictor's controllers.
impl<T: Real> CompensatorParams<T> for KayaAthertonParams<T> {
    fn controllers(&self, ts: T) -> Result<Controllers<T>, Error> {
        let Self {
            kp,
            ti,
            kf,
            tf,
            kb,
            td,
        } = *self;
        let td = crate::real::non_negative(td, "td")?;
        Ok(Controllers {
            gc1: Pid::new(PidConfig::isa(kp, ti, T::zero(), ts))?,
            gc2: Some(Pid::new(PidConfig::parallel(kf, T::zero(), kf * tf, ts))?),
            gc3: Some(Lti::lead_lag(kb, td, T::of(0.1) * td, ts)?),
        })
    }
}

//! The parameters of an ISA PID as a scheme's parameter type ([`PidGains`]),
//! and `pid_params!`, which declares a predictor's parameters around them.

use crate::real::Real;

crate::params::base_struct! { $ pid_params;
    /// PID settings in ISA form `Kp(1 + 1/(Ti s) + Td s)`; `td = 0` for PI.
    /// The parameters of the `pid`, `smith` and `watanabe-ito` schemes;
    /// `pid_params!` declares a predictor's around an ISA PID (these first).
    pub struct PidGains {
        /// Proportional gain `Kp`.
        kp: Finite,
        /// Integral time `Ti` (s).
        ti: Positive,
        /// Derivative time `Td` (s).
        td: NonNegative,
    }
}

impl<T: Real> PidGains<T> {
    /// The PID configuration for sample period `ts` (defaults of [`crate::PidConfig::isa`]).
    pub fn config(&self, ts: T) -> crate::pid::PidConfig<T> {
        crate::pid::PidConfig::isa(self.kp, self.ti, self.td, ts)
    }
}

//! Tuning rules: pure functions from a process model to controller parameters.

use crate::dtc::KaranDeyParams;
use crate::real::positive;
use crate::{Error, Ipdt, ProcessModel, Real};

/// PID settings in ISA form `Kp(1 + 1/(Ti s) + Td s)`; `td = 0` for PI.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PidGains<T> {
    /// Proportional gain `Kp`.
    pub kp: T,
    /// Integral time `Ti` (s).
    pub ti: T,
    /// Derivative time `Td` (s).
    pub td: T,
}

impl<T: Real> PidGains<T> {
    /// The PID configuration for sample period `ts` (defaults of [`crate::PidConfig::isa`]).
    pub fn config(&self, ts: T) -> crate::PidConfig<T> {
        crate::PidConfig::isa(self.kp, self.ti, self.td, ts)
    }
}

/// Kaya's IMC tuning of the primary controller of a Smith predictor
/// (`001_8c052250023526e6.txt` Eqs. 18–33), for a closed-loop (filter) time
/// constant `lambda`:
///
/// - FOPDT `K e^{−Ls}/(T s + 1)`: PI, `Kp = T/(K λ)`, `Ti = T` (Eqs. 20–21);
/// - SOPDT `K e^{−Ls}/((T1 s + 1)(T2 s + 1))`: PID, `Kp = (T1 + T2)/(K λ)`,
///   `Ti = T1 + T2`, `Td = T1 T2/(T1 + T2)` (Eqs. 29–31).
///
/// The ISE-optimal choice is `λ = L` (Eq. 26); Kaya's speed factor `α` of
/// Eqs. 32–33 is `λ = α·L`. With a perfect model the delay-free loop is
/// `1/(λ s + 1)`, so the set-point response is `1 − e^{−(t − L)/λ}` after the delay.
pub fn kaya<T: Real>(model: &ProcessModel<T>, lambda: T) -> Result<PidGains<T>, Error> {
    let lambda = positive(lambda, "lambda")?;
    match *model {
        ProcessModel::Fopdt(m) => Ok(PidGains {
            kp: m.t / (m.k * lambda),
            ti: m.t,
            td: T::zero(),
        }),
        ProcessModel::Sopdt(m) => {
            let s = m.t1 + m.t2;
            Ok(PidGains {
                kp: s / (m.k * lambda),
                ti: s,
                td: m.t1 * m.t2 / s,
            })
        }
        _ => Err(Error::Unsupported(
            "Kaya's rule needs an FOPDT or SOPDT model",
        )),
    }
}

/// Kaya's rule with the speed factor `α` (`λ = α·L`, Eqs. 32–33; `α = 1` is the
/// ISE optimum).
pub fn kaya_alpha<T: Real>(model: &ProcessModel<T>, alpha: T) -> Result<PidGains<T>, Error> {
    let alpha = positive(alpha, "alpha")?;
    let l = positive(model.delay(), "l")?;
    kaya(model, alpha * l)
}

/// [`kaya`] for an FOPDT model with `λ = α·L`.
pub fn kaya_fopdt<T: Real>(model: &crate::Fopdt<T>, alpha: T) -> Result<PidGains<T>, Error> {
    kaya_alpha(&ProcessModel::Fopdt(*model), alpha)
}

/// IMC-PI for an integrating model `K/s` with the filter `(2λs + 1)/(λs + 1)²`
/// (`000_3f0725a46e29ef08.txt` Eqs. 4.25–4.31): `Kp = 2/(K λ)`, `Ti = 2λ`.
/// The delay-free loop is then `(2λs + 1)/(λs + 1)²` (13.5 % overshoot).
pub fn imc_pi_integrating<T: Real>(model: &Ipdt<T>, lambda: T) -> Result<PidGains<T>, Error> {
    let lambda = positive(lambda, "lambda")?;
    Ok(PidGains {
        kp: T::two() / (model.k * lambda),
        ti: T::two() * lambda,
        td: T::zero(),
    })
}

/// The Karan–Dey MSP tuning with the single parameter `λ`
/// (`000_3f0725a46e29ef08.txt` Sec. 4.5.2): `Kp = 2/(K λ)`, `Ti = 2λ`
/// (Eqs. 4.30–4.31), `β = 1/(K Kp Ti)` (Eq. 4.37, `= 0.25`), `Td = λ` (Eq. 4.44),
/// `γ = 0.5/(θm K Kp)` (Eq. 4.50, the middle of the Routh range 4.49). The thesis
/// recommends `λ = θm/4` (Eq. 4.32); then `γ = 1/16` (printed rounded as 0.06 in
/// Eq. 4.51) and the set-point response is `e^{−θs}/(1 + θs/8)`. The derivative
/// filter ratio is `N = 10`.
pub fn karan_dey<T: Real>(model: &Ipdt<T>, lambda: T) -> Result<KaranDeyParams<T>, Error> {
    let lambda = positive(lambda, "lambda")?;
    let theta = positive(model.l, "l")?;
    let k = model.k;
    let kp = T::two() / (k * lambda);
    let ti = T::two() * lambda;
    Ok(KaranDeyParams {
        kp,
        ti,
        beta: T::one() / (k * kp * ti),
        gamma: T::half() / (theta * k * kp),
        td: lambda,
        n: T::of(10.0),
    })
}

/// The thesis's default `λ = θm/4` (Eq. 4.32).
pub fn karan_dey_default_lambda<T: Real>(model: &Ipdt<T>) -> T {
    model.l / T::of(4.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Fopdt, Sopdt};

    #[test]
    fn kaya_examples_2_and_3() {
        // 001_… Example 2: FOPDT e^{-10.87s}/(1.27s+1), α = 0.5 → Kc = 0.234, Ti = 1.27
        let m = ProcessModel::Fopdt(Fopdt::<f64>::new(1.0, 1.27, 10.87).unwrap());
        let g = kaya_alpha(&m, 0.5).unwrap();
        assert!((g.kp - 0.234).abs() < 5e-4, "{}", g.kp);
        assert_eq!(g.ti, 1.27);
        // SOPDT e^{-10s}/(s+1)^2, α = 0.5 → Kc = 0.400, Ti = 2, Td = 0.5
        let m = ProcessModel::Sopdt(Sopdt::<f64>::new(1.0, 1.0, 1.0, 10.0).unwrap());
        let g = kaya_alpha(&m, 0.5).unwrap();
        assert!((g.kp - 0.4).abs() < 1e-12);
        assert_eq!((g.ti, g.td), (2.0, 0.5));
    }

    #[test]
    fn karan_dey_thesis_settings() {
        // 000_… Sec. 4.5.3: 0.2/s e^{-7.4s} → Kp = 5.4, Ti = 3.70, β = 0.25, Td = 1.85, γ ≈ 0.06
        let m = Ipdt::<f64>::new(0.2, 7.4).unwrap();
        let p = karan_dey(&m, karan_dey_default_lambda(&m)).unwrap();
        assert!((p.kp - 5.4).abs() < 0.01, "{}", p.kp);
        assert!((p.ti - 3.70).abs() < 1e-12);
        assert!((p.beta - 0.25).abs() < 1e-12);
        assert!((p.td - 1.85).abs() < 1e-12);
        assert!((p.gamma - 0.0625).abs() < 1e-12);
        // 0.05/s e^{-6s} → Kp = 26.67, Ti = 3.00, Td = 1.50
        let m = Ipdt::<f64>::new(0.05, 6.0).unwrap();
        let p = karan_dey(&m, karan_dey_default_lambda(&m)).unwrap();
        assert!((p.kp - 26.67).abs() < 0.005);
        assert!((p.ti - 3.0).abs() < 1e-12 && (p.td - 1.5).abs() < 1e-12);
    }
}

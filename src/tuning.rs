//! Tuning rules: pure functions from a process model to controller parameters.

use crate::dtc::KaranDeyParams;
use crate::real::positive;
use crate::{error::Error, model::Ipdt, model::ProcessModel, real::Real};

// the gains the rules give: the PID's own parameter type
pub use crate::pid::PidGains;

mod shaping;
pub use shaping::{at_crossover, pi_at, pid_at, TD_RATIO};

/// Kaya's IMC tuning of the primary controller of a Smith predictor
/// (Kaya (2003) Eqs. 18–33), for a closed-loop (filter) time
/// constant `lambda`:
///
/// - FOPDT `K e^{−Ls}/(T s + 1)`: PI, `Kp = T/(K λ)`, `Ti = T` (Eqs. 20–21);
/// - SOPDT `K e^{−Ls}/((T1 s + 1)(T2 s + 1))`: PID, `Kp = (T1 + T2)/(K λ)`,
///   `Ti = T1 + T2`, `Td = T1 T2/(T1 + T2)` (Eqs. 29–31).
///
/// The ISE-optimal choice is `λ = L` (Eq. 26); Kaya's speed factor `α` of
/// Eqs. 32–33 is `λ = α·L`. With a perfect model the delay-free loop is
/// `1/(λ s + 1)`, so the set-point response is `1 − e^{−(t − L)/λ}` after the delay.
///
/// ```
/// use msp::{tuning, Fopdt, ProcessModel};
/// let m = ProcessModel::from(Fopdt::new(5.6f64, 40.2, 93.9)?);
/// let g = tuning::kaya(&m, 93.9)?; // λ = L
/// assert!((g.kp - 40.2 / (5.6 * 93.9)).abs() < 1e-12 && g.ti == 40.2 && g.td == 0.0);
/// let pid = msp::Pid::new(g.config(1.0))?; // the PI, sampled every second
/// # let _ = pid;
/// # Ok::<(), msp::Error>(())
/// ```
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

/// The filtered Smith predictor's primary PI (García et al. (2010): the
/// delay-free loop of the model designed as usual, Sec. 3), at the
/// closed-loop time constant `λ`:
///
/// - `K/(Ts − 1)`: the double pole at `−1/λ`, `K·Kp = 1 + 2T/λ`,
///   `Ti = K·Kp·λ²/T` (from `T s² + (K Kp − 1) s + K Kp/Ti` against
///   `T (s + 1/λ)²`);
/// - `K/s`: the same placement, `Kp = 2/(K λ)`, `Ti = 2λ` (the IMC-PI of an
///   integrator);
/// - FOPDT and SOPDT: Kaya's rule ([`kaya`], its PI part).
///
/// ```
/// use msp::{tuning, Ipdt, ProcessModel};
/// let m = ProcessModel::from(Ipdt::new(0.5f64, 1.0)?);
/// let g = tuning::fsp_pi(&m, 2.0)?;
/// assert!((g.kp - 2.0).abs() < 1e-12 && g.ti == 4.0 && g.td == 0.0);
/// # Ok::<(), msp::Error>(())
/// ```
pub fn fsp_pi<T: Real>(model: &ProcessModel<T>, lambda: T) -> Result<PidGains<T>, Error> {
    let lambda = positive(lambda, "lambda")?;
    let two = T::of(2.0);
    let (kp, ti) = match *model {
        ProcessModel::Ufopdt(u) => {
            let kkc = T::one() + two * u.t / lambda;
            (kkc / u.k, kkc * lambda * lambda / u.t)
        }
        ProcessModel::Ipdt(i) => (two / (i.k * lambda), two * lambda),
        _ => {
            let g = kaya(model, lambda)?;
            (g.kp, g.ti)
        }
    };
    Ok(PidGains {
        kp,
        ti,
        td: T::zero(),
    })
}

/// Kaya's rule with the speed factor `α` (`λ = α·L`, Eqs. 32–33; `α = 1` is the
/// ISE optimum).
///
/// ```
/// use msp::{tuning, Fopdt, ProcessModel};
/// let m = ProcessModel::from(Fopdt::new(5.6f64, 40.2, 93.9)?);
/// // α = 0.5: λ = 46.95 s, twice the gain of λ = L
/// let g = tuning::kaya_alpha(&m, 0.5)?;
/// assert!((g.kp - 40.2 / (5.6 * 0.5 * 93.9)).abs() < 1e-12 && g.ti == 40.2);
/// # Ok::<(), msp::Error>(())
/// ```
pub fn kaya_alpha<T: Real>(model: &ProcessModel<T>, alpha: T) -> Result<PidGains<T>, Error> {
    let alpha = positive(alpha, "alpha")?;
    let l = positive(model.delay(), "l")?;
    kaya(model, alpha * l)
}

/// [`kaya`] for an FOPDT model with `λ = α·L`.
pub fn kaya_fopdt<T: Real>(model: &crate::model::Fopdt<T>, alpha: T) -> Result<PidGains<T>, Error> {
    kaya_alpha(&ProcessModel::Fopdt(*model), alpha)
}

/// IMC-PI for an integrating model `K/s` with the filter `(2λs + 1)/(λs + 1)²`
/// (Bag (2022) Eqs. 4.25–4.31): `Kp = 2/(K λ)`, `Ti = 2λ`.
/// The delay-free loop is then `(2λs + 1)/(λs + 1)²` (13.5 % overshoot).
///
/// ```
/// use msp::{tuning, Ipdt};
/// // the thesis's benchmark 0.2 e^{-7.4s}/s with λ = θ/4 = 1.85 s
/// let g = tuning::imc_pi_integrating(&Ipdt::new(0.2f64, 7.4)?, 1.85)?;
/// assert!((g.kp - 5.4054).abs() < 1e-4 && (g.ti - 3.7).abs() < 1e-12);
/// # Ok::<(), msp::Error>(())
/// ```
pub fn imc_pi_integrating<T: Real>(model: &Ipdt<T>, lambda: T) -> Result<PidGains<T>, Error> {
    let lambda = positive(lambda, "lambda")?;
    Ok(PidGains {
        kp: T::two() / (model.k * lambda),
        ti: T::two() * lambda,
        td: T::zero(),
    })
}

/// IMC-PID for an integrating model with a lag `K/(s(Ts + 1))`: the IMC-PI of
/// `K/s` ([`imc_pi_integrating`], Bag (2022) Eqs. 4.25–4.31) in series with
/// the lead `Ts + 1` that cancels the lag, so the delay-free loop of a Smith
/// predictor is the IMC-PI's. The series PID `Kc(1 + 1/(Ti s))(1 + T s)` is
/// written in ISA form: `Kp = Kc(Ti + T)/Ti`, `Ti' = Ti + T`,
/// `Td = Ti·T/(Ti + T)` (the interacting-to-ISA conversion of Åström &
/// Hägglund (2006), Sec. 3.4).
///
/// ```
/// use msp::{tuning, Foipdt};
/// let (k, t, lambda) = (0.5f64, 3.0, 2.0);
/// let g = tuning::imc_pid_integrating_lag(&Foipdt::new(k, t, 4.0)?, lambda)?;
/// // the series form Kc(1 + 1/(Ti s))(1 + T s) with Kc = 2/(Kλ), Ti = 2λ
/// let (kc, ti) = (2.0 / (k * lambda), 2.0 * lambda);
/// assert!((g.kp - kc * (ti + t) / ti).abs() < 1e-12);
/// assert!((g.ti - (ti + t)).abs() < 1e-12 && (g.td - ti * t / (ti + t)).abs() < 1e-12);
/// # Ok::<(), msp::Error>(())
/// ```
pub fn imc_pid_integrating_lag<T: Real>(
    model: &crate::model::Foipdt<T>,
    lambda: T,
) -> Result<PidGains<T>, Error> {
    // the integrator and dead time of the model: the PI of K/s reads only K
    let pi = imc_pi_integrating(&Ipdt::new(model.k, model.l)?, lambda)?;
    let ti = pi.ti + model.t;
    Ok(PidGains {
        kp: pi.kp * ti / pi.ti,
        ti,
        td: pi.ti * model.t / ti,
    })
}

/// The Karan–Dey MSP tuning with the single parameter `λ`
/// (Bag (2022) Sec. 4.5.2): `Kp = 2/(K λ)`, `Ti = 2λ`
/// (Eqs. 4.30–4.31), `β = 1/(K Kp Ti)` (Eq. 4.37, `= 0.25`), `Td = λ` (Eq. 4.44),
/// `γ = 0.5/(θm K Kp)` (Eq. 4.50, the middle of the Routh range 4.49). The thesis
/// recommends `λ = θm/4` (Eq. 4.32); then `γ = 1/16` (printed rounded as 0.06 in
/// Eq. 4.51) and the set-point response is `e^{−θs}/(1 + θs/8)`. The derivative
/// filter ratio is `N = 10`.
///
/// ```
/// use msp::{tuning, Ipdt};
/// // the thesis's benchmark 0.2 e^{-7.4s}/s (Bag (2022) Eqs. 4.32-4.51)
/// let m = Ipdt::new(0.2f64, 7.4)?;
/// let p = tuning::karan_dey(&m, tuning::karan_dey_default_lambda(&m))?;
/// assert!((p.kp - 5.4054).abs() < 1e-4 && (p.ti - 3.7).abs() < 1e-12);
/// assert!((p.beta - 0.25).abs() < 1e-12 && (p.gamma - 1.0 / 16.0).abs() < 1e-12);
/// assert_eq!(p.td, 1.85);
/// # Ok::<(), msp::Error>(())
/// ```
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

/// IMC-PID for an FOPDT model with a first-order Padé approximation of the
/// dead time (Bag (2022) Eqs. 3.19–3.27):
/// `Kc = (τp + θ/2)/(kp(λ + θ/2))`, `τI = τp + θ/2`, `τD = τp θ/(2τp + θ)`.
///
/// ```
/// use msp::{tuning, Fopdt};
/// let (k, tau, theta, lambda) = (2.0f64, 10.0, 4.0, 3.0);
/// let g = tuning::imc_pid(&Fopdt::new(k, tau, theta)?, lambda)?;
/// assert!((g.kp - 12.0 / (2.0 * 5.0)).abs() < 1e-12); // (τ + θ/2)/(k(λ + θ/2))
/// assert!((g.ti - 12.0).abs() < 1e-12 && (g.td - 40.0 / 24.0).abs() < 1e-12);
/// # Ok::<(), msp::Error>(())
/// ```
pub fn imc_pid<T: Real>(model: &crate::model::Fopdt<T>, lambda: T) -> Result<PidGains<T>, Error> {
    let lambda = positive(lambda, "lambda")?;
    let h = T::half() * model.l;
    Ok(PidGains {
        kp: (model.t + h) / (model.k * (lambda + h)),
        ti: model.t + h,
        td: model.t * model.l / (T::two() * model.t + model.l),
    })
}

/// Skogestad's SIMC rules (2003) for a closed-loop time constant `tc`:
/// FOPDT `Kc = T/(K(τc + θ))`, `τI = min(T, 4(τc + θ))`; SOPDT the same with
/// `τD = T2`; IPDT `Kc = 1/(K(τc + θ))`, `τI = 4(τc + θ)`; FOIPDT with `τD = T`.
///
/// ```
/// use msp::{tuning, Fopdt, Ipdt, ProcessModel};
/// // Skogestad's τc = θ: Kc = T/(2Kθ), τI = min(T, 8θ)
/// let g = tuning::simc(&ProcessModel::from(Fopdt::new(1.0f64, 8.0, 1.0)?), 1.0)?;
/// assert!((g.kp - 4.0).abs() < 1e-12 && (g.ti - 8.0).abs() < 1e-12);
/// let g = tuning::simc(&ProcessModel::from(Ipdt::new(0.2f64, 7.4)?), 7.4)?;
/// assert!((g.kp - 1.0 / (0.2 * 14.8)).abs() < 1e-12 && (g.ti - 4.0 * 14.8).abs() < 1e-12);
/// # Ok::<(), msp::Error>(())
/// ```
pub fn simc<T: Real>(model: &ProcessModel<T>, tc: T) -> Result<PidGains<T>, Error> {
    let tc = positive(tc, "lambda")?;
    let four = T::of(4.0);
    match *model {
        ProcessModel::Fopdt(m) => {
            let s = tc + m.l;
            Ok(PidGains {
                kp: m.t / (m.k * s),
                ti: m.t.min(four * s),
                td: T::zero(),
            })
        }
        ProcessModel::Sopdt(m) => {
            let s = tc + m.l;
            Ok(PidGains {
                kp: m.t1 / (m.k * s),
                ti: m.t1.min(four * s),
                td: m.t2,
            })
        }
        ProcessModel::Ipdt(m) => {
            let s = tc + m.l;
            Ok(PidGains {
                kp: T::one() / (m.k * s),
                ti: four * s,
                td: T::zero(),
            })
        }
        ProcessModel::Foipdt(m) => {
            let s = tc + m.l;
            Ok(PidGains {
                kp: T::one() / (m.k * s),
                ti: four * s,
                td: m.t,
            })
        }
        ProcessModel::Ufopdt(_) => Err(Error::Unsupported("SIMC tuning of an unstable plant")),
    }
}

/// The AMIGO rules (Åström & Hägglund (2004), *J. Process Control* 14,
/// Sec. 6; Åström & Hägglund (2006), *Advanced PID Control*, Secs. 7.6–7.7):
/// PI (`pi_only`) or PID settings with the set-point weight `b` of the
/// proportional term, from a FOPDT `K e^{−Ls}/(Ts + 1)` or an IPDT
/// `Kv e^{−Ls}/s` model. With `τ = L/(L + T)`:
///
/// - PI, FOPDT: `Kp = 0.15/K + (0.35 − LT/(L + T)²)·T/(K L)`,
///   `Ti = 0.35 L + 13 L T²/(T² + 12 L T + 7 L²)`;
/// - PI, IPDT: `Kp = 0.35/(Kv L)`, `Ti = 13.4 L`;
/// - PID, FOPDT: `Kp = (0.2 + 0.45 T/L)/K`, `Ti = (0.4 L + 0.8 T)/(L + 0.1 T)·L`,
///   `Td = 0.5 L T/(0.3 L + T)`;
/// - PID, IPDT: `Kp = 0.45/(Kv L)`, `Ti = 8 L`, `Td = 0.5 L`;
/// - `b = 0` for `τ ≤ 0.5`, `b = 1` above (an IPDT has `τ = 0`); the
///   derivative acts on the measurement only (`c = 0`; the registry's
///   `amigo` rule sets both weights).
///
/// The IPDT settings are the FOPDT ones as `T → ∞` with `K/T = Kv`. The
/// rules aim at `Ms ≈ 1.4`; the PID rule is meant for `τ ≥ 0.3` or so
/// (below it the derivative gains less than a better-tuned PI would).
/// A model without dead time has no AMIGO setting ([`Error::NotPositive`]).
///
/// ```
/// use msp::{tuning, Fopdt, ProcessModel};
/// let (g, b) = tuning::amigo(&ProcessModel::from(Fopdt::new(2.0f64, 4.0, 3.0)?), false)?;
/// assert!((g.kp - (0.2 + 0.45 * 4.0 / 3.0) / 2.0).abs() < 1e-12);
/// assert_eq!(b, 0.0); // τ = 3/7 ≤ 0.5: no proportional kick on set-point steps
/// let cfg = g.config(0.1).with_weights(b, 0.0);
/// # let _ = cfg;
/// # Ok::<(), msp::Error>(())
/// ```
pub fn amigo<T: Real>(model: &ProcessModel<T>, pi_only: bool) -> Result<(PidGains<T>, T), Error> {
    let c = T::of;
    match *model {
        ProcessModel::Fopdt(m) => {
            let (k, t, l) = (m.k, m.t, positive(m.l, "dead time")?);
            let tau = l / (l + t);
            let b = if tau <= c(0.5) { T::zero() } else { T::one() };
            let g = if pi_only {
                PidGains {
                    kp: c(0.15) / k + (c(0.35) - l * t / ((l + t) * (l + t))) * t / (k * l),
                    ti: c(0.35) * l
                        + c(13.0) * l * t * t / (t * t + c(12.0) * l * t + c(7.0) * l * l),
                    td: T::zero(),
                }
            } else {
                PidGains {
                    kp: (c(0.2) + c(0.45) * t / l) / k,
                    ti: (c(0.4) * l + c(0.8) * t) / (l + c(0.1) * t) * l,
                    td: c(0.5) * l * t / (c(0.3) * l + t),
                }
            };
            Ok((g, b))
        }
        ProcessModel::Ipdt(m) => {
            let (kv, l) = (m.k, positive(m.l, "dead time")?);
            let g = if pi_only {
                PidGains {
                    kp: c(0.35) / (kv * l),
                    ti: c(13.4) * l,
                    td: T::zero(),
                }
            } else {
                PidGains {
                    kp: c(0.45) / (kv * l),
                    ti: c(8.0) * l,
                    td: c(0.5) * l,
                }
            };
            Ok((g, T::zero()))
        }
        _ => Err(Error::Unsupported(
            "the AMIGO rules take a FOPDT or an IPDT model",
        )),
    }
}

/// An ultimate-cycle rule: `Kc = a·Ku`, `Ti = b·Tu`, `Td = c·Tu`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UltimateRule {
    /// The rule's name (`--rule`).
    pub name: &'static str,
    /// Who published it and what it aims at, as Tables 3.2/3.3 print it.
    pub note: &'static str,
    /// `Kc/Ku`.
    pub a: f64,
    /// `Ti/Tu`.
    pub b: f64,
    /// `Td/Tu` (0 for PI).
    pub c: f64,
}

macro_rules! rules {
    ($($name:literal, $note:literal, $a:literal, $b:literal, $c:literal;)*) => {
        &[$(UltimateRule { name: $name, note: $note, a: $a, b: $b, c: $c },)*]
    };
}

/// Every rule of Bag (2022) Tables 3.2 (PI, the first [`PI_COUNT`]) and
/// 3.3 (PID): one table, the two views below.
const ULTIMATE_RULES: &[UltimateRule] = rules![
    // Table 3.2: rows without an author in the extracted table carry the
    // previous author's name and a number
    "zn-pi", "Ziegler-Nichols, quarter decay ratio", 0.45, 0.83, 0.0;
    "hang-pi", "Hang et al., dominant time delay", 0.25, 0.2546, 0.0;
    "mcmillan-pi", "McMillan", 0.3571, 1.0, 0.0;
    "astrom-hagglund-pi", "Astrom-Hagglund, Am = 2, phase margin 20 deg", 0.4698, 0.4373, 0.0;
    "parr-pi", "Parr, Am = 2.44, phase margin 61 deg", 0.1988, 0.0882, 0.0;
    "yu-pi", "Yu, Am = 3.45", 0.2015, 0.1537, 0.0;
    "yu-pi-2", "phase margin 46 deg", 0.5, 0.43, 0.0;
    "yu-pi-3", "quarter decay ratio", 0.33, 2.0, 0.0;
    // Table 3.3
    "zn", "Ziegler-Nichols, quarter decay ratio (Kc from [0.6, 1] Ku)", 0.6, 0.5, 0.125;
    "blickley", "Blickley, quarter decay ratio", 0.5, 1.0, 0.125;
    "parr", "Parr, about 20 % servo overshoot", 0.5, 1.0, 0.2;
    "de-paor", "De Paor, quarter decay ratio", 0.5, 0.34, 0.08;
    "de-paor-2", "phase margin 30 deg", 0.866, 0.5, 0.125;
    "corripio", "Corripio, quarter decay ratio", 0.75, 0.63, 0.1;
    "mantz-tacconi", "Mantz and Tacconi, phase margin 25 deg", 0.906, 0.5, 0.125;
    "astrom-hagglund", "Astrom-Hagglund, Am = 2, phase margin 20 deg", 0.4698, 0.4546, 0.1136;
    "astrom-hagglund-2", "Astrom-Hagglund, phase margin 61 deg", 0.1988, 1.2308, 0.3077;
    "atkinson-davey", "Atkinson and Davey, phase margin 46 deg", 0.2015, 0.7878, 0.1970;
    "perry-chilton", "Perry and Chilton, Am >= 2, phase margin >= 45 deg", 0.35, 0.77, 0.19;
    "overshoot-20", "20 % overshoot servo response", 0.25, 0.75, 0.25;
    "some-overshoot", "'some' overshoot", 0.33, 0.5, 0.33;
    "yu", "Yu, 'no' overshoot", 0.2, 0.5, 0.33;
    "luo", "Luo et al., 'some' overshoot", 0.33, 0.5, 0.125;
    "luo-2", "Luo et al.", 0.48, 0.5, 0.125;
    "mcmillan", "McMillan, 'no' overshoot", 0.2, 0.5, 0.125;
    "mcavoy-johnson", "McAvoy and Johnson", 0.5, 0.5, 0.125;
    "mcavoy-johnson-2", "McAvoy and Johnson", 0.54, 1.0, 0.2;
    "st-clair", "St. Clair, 'aggressive'", 0.5, 1.2, 0.125;
    "st-clair-2", "St. Clair, 'conservative'", 0.25, 1.2, 0.125;
];

/// The number of PI rules (Table 3.2) at the head of the table.
const PI_COUNT: usize = 8;

/// The PI rules of Bag (2022) Table 3.2 that need only `Ku`
/// and `Tu` (Hwang–Chang also needs a decay measurement and is left out).
/// Rows without an author in the extracted table carry the previous author's
/// name and a number.
pub static PI_RULES: &[UltimateRule] = ULTIMATE_RULES.split_at(PI_COUNT).0;

/// The PID rules of Bag (2022) Table 3.3 with single values
/// (for a range, its lower end; Karaboga–Kalinli's ranges are left out).
pub static PID_RULES: &[UltimateRule] = ULTIMATE_RULES.split_at(PI_COUNT).1;

/// The rule called `name` in Tables 3.2 and 3.3.
pub fn ultimate_rule(name: &str) -> Option<&'static UltimateRule> {
    ULTIMATE_RULES.iter().find(|r| r.name == name)
}

/// Settings from the ultimate gain `ku` and period `tu` by `rule`.
///
/// ```
/// use msp::tuning;
/// // Ziegler–Nichols PID: Kp = 0.6 Ku, Ti = Tu/2, Td = Tu/8
/// let zn = tuning::ultimate_rule("zn").ok_or(msp::Error::Unsupported("zn"))?;
/// let g = tuning::ultimate_cycle(zn, 2.5f64, 40.0)?;
/// assert!((g.kp - 1.5).abs() < 1e-12 && g.ti == 20.0 && g.td == 5.0);
/// # Ok::<(), msp::Error>(())
/// ```
pub fn ultimate_cycle<T: Real>(rule: &UltimateRule, ku: T, tu: T) -> Result<PidGains<T>, Error> {
    let ku = positive(ku, "ku")?;
    let tu = positive(tu, "tu")?;
    Ok(PidGains {
        kp: T::of(rule.a) * ku,
        ti: T::of(rule.b) * tu,
        td: T::of(rule.c) * tu,
    })
}

crate::params::design_struct! {
    /// Design inputs of a scheme tuned by `λ` alone (PID, PI, the Smith
    /// predictor, Karan–Dey, Watanabe–Ito, Kaya–Atherton).
    pub struct LambdaTuning {}
}

/// Design values of the disturbance estimator (Draganović et al. (2001) Sec. 3).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EstimatorDesign<T> {
    /// The case, 1 to 6.
    pub case: u8,
    /// Case 3: dominant time constant `T_DE` of the load response (s).
    pub tde: T,
    /// Cases 5 and 6: the Padé split `α` (`β = 1 − α`).
    pub alpha: T,
    /// Case 6: the disturbance frequency `ω0` (rad/s).
    pub w0: T,
}

/// The estimator's gains as the paper names them, with the estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorTuning<T> {
    /// `K_A`.
    pub ka: T,
    /// `T_A` (s), 0 where the case has none.
    pub ta: T,
    /// `T_C` (s), 0 where the case has none.
    pub tc: T,
    /// `A(s)/C(s)`.
    pub estimator: crate::dtc::disturbance_estimator::Estimator<T>,
}

/// The six designs of the disturbance estimator `A(s)/C(s)` for the model
/// `Kv e^{−Ls}/s` (Draganović et al. (2001) Eqs. 19–66):
///
/// 1. P by the M circle: `K_A = 0.5/(Kv L)` (Eq. 22);
/// 2. PD by the M circle with `T_A = L/2`: `K_A` from Eq. 28 (`≈ 0.927/(Kv L)`, Eq. 30);
/// 3. lead `K_A(T_A s+1)/(T_C s+1)` by triple-pole placement for `T_DE` (Eqs. 37–40);
/// 4. PI `K_A(T_A s+1)/(T_A s)` for ramps, triple pole (Eqs. 46–48: `K_A = 0.44/(Kv L)`, `T_A = 6.27 L`);
/// 5. the same with the Padé split `e^{−Ls} ≈ (1 − αLs)/(1 + βLs)` (Eqs. 55–57);
/// 6. resonant `K_A s(T_A s+1)/((s² + ω0²)/ω0)` for a sinusoid at `ω0` (Eqs. 64–66).
///
/// Case 6: the paper prints `C(s) = (s² + ω0²)/ω0²` (Eq. 58), but its
/// characteristic equation and its solution (Eqs. 60–66) follow from
/// `C(s) = (s² + ω0²)/ω0`: with `C` normalized by `ω0^c` the constant term of the
/// load loop is `ω0² + ω0^c·K_A Kv`, and Eq. 65 (`K_A = (βσ³L − ω0²)/(ω0 Kv)`) is
/// the `c = 1` solution. The triple pole is then really placed, which this
/// implementation checks; `/ω0²` would leave a much slower estimator. The
/// numbers printed beside Fig. 7 (`K_A = 0.049`, `T_A = 31.178` for
/// `α = 0.95`, `ω0 = 0.05`) follow from neither normalization (Eqs. 64–66 give
/// `K_A = 0.098`, `T_A = 22.5`); the equations are used.
pub fn disturbance_estimator<T: Real>(
    kv: T,
    l: T,
    d: &EstimatorDesign<T>,
) -> Result<EstimatorTuning<T>, Error> {
    use crate::dtc::disturbance_estimator::Estimator;
    let kv = crate::real::finite(kv, "k")?;
    let l = positive(l, "l")?;
    let (z, o) = (T::zero(), T::one());
    let kvl = kv * l;
    let cbrt = |x: T| x.cbrt();
    let est = |case: u8, ka: T, ta: T, tc: T| Estimator::from_case(case, ka, ta, tc, d.w0);
    match d.case {
        1 => {
            let ka = T::half() / kvl;
            Ok(EstimatorTuning {
                ka,
                ta: z,
                tc: z,
                estimator: est(1, ka, z, z)?,
            })
        }
        2 => {
            let ta = T::half() * l;
            let pi6 = T::PI() / T::of(6.0);
            let r = ta / l;
            let ka = pi6
                / kvl
                / (o - T::two() * r + r * r + T::PI() * T::PI() * r * r / T::of(36.0)).sqrt();
            Ok(EstimatorTuning {
                ka,
                ta,
                tc: z,
                estimator: est(2, ka, ta, z)?,
            })
        }
        3 => {
            let tde = positive(d.tde, "tde")?;
            if !(o / tde > T::two() / l * (cbrt(T::two()) - o)) {
                return Err(Error::OutOfRange("tde"));
            }
            let tc =
                T::of(8.0) / (l * l) / ((o / tde + T::two() / l).powi(3) - T::of(16.0) / l.powi(3));
            let ka = tc * l / (T::two() * tde.powi(3) * kv);
            let ta = T::of(4.0) * tde.powi(3) / (l * l) + T::two() * tde.powi(3) / (l * tc)
                - T::of(6.0) * tde * tde / l;
            if !(ta > tc && tc > z) {
                return Err(Error::OutOfRange("tde"));
            }
            Ok(EstimatorTuning {
                ka,
                ta,
                tc,
                estimator: est(3, ka, ta, tc)?,
            })
        }
        4 | 5 => {
            let alpha = if d.case == 4 { T::half() } else { d.alpha };
            if !(alpha > z && alpha < o) {
                return Err(Error::OutOfRange("alpha"));
            }
            let beta = o - alpha;
            let sigma = (cbrt(o + alpha / beta) - o) / (alpha * l);
            let ka = (o - T::of(3.0) * beta * sigma * l) / (alpha * kvl);
            let ta = T::of(3.0) / sigma + alpha * l;
            Ok(EstimatorTuning {
                ka,
                ta,
                tc: z,
                estimator: est(d.case, ka, ta, z)?,
            })
        }
        6 => {
            let alpha = d.alpha;
            if !(alpha > z && alpha < o) {
                return Err(Error::OutOfRange("alpha"));
            }
            let w0 = positive(d.w0, "w0")?;
            let beta = o - alpha;
            let sigma = (cbrt(o + alpha / beta * (o + w0 * w0 * alpha * l * l)) - o) / (alpha * l);
            let g = beta * sigma.powi(3) * l - w0 * w0;
            if !(g > z) || !(T::of(3.0) * beta * sigma * l < o) {
                return Err(Error::OutOfRange("w0"));
            }
            let ka = g / (w0 * kv);
            let ta = (o - T::of(3.0) * beta * sigma * l) / (alpha * l * g);
            Ok(EstimatorTuning {
                ka,
                ta,
                tc: z,
                estimator: est(6, ka, ta, z)?,
            })
        }
        _ => Err(Error::OutOfRange("case")),
    }
}

#[cfg(test)]
mod tests;

//! The predictors for integrating plants of Bag (2022), Sec. 4.4–4.5:
//! Karan–Dey, Watanabe–Ito, Åström–Hang–Lim, Matausek–Micić, Kaya–Atherton.

use alloc::vec::Vec;

use super::common::*;
use super::{Build, Design, Params};
use crate::dtc::astrom_hang_lim::{AstromHangLimParams, AstromHangLimTuning};
use crate::dtc::kaya_atherton::KayaAthertonParams;
use crate::dtc::matausek_micic::{MatausekMicicParams, MatausekMicicTuning};
use crate::dtc::{self, Compensator, KaranDeyParams};
use crate::poly::TransferFunction;
use crate::tuning::{LambdaTuning, PidGains};
use crate::{model::ProcessModel, params::DesignSet, real::Real, tuning};
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

pub fn tune_karan_dey(plant: &Tf, d: &Design) -> Tuned {
    // the MSP's three controllers are designed for K·e^{−θs}/s; its set-point
    // PI ignores a lag, which the predictor then keeps in the loop
    let m = match plant.exact_model() {
        Some(ProcessModel::Ipdt(m)) if m.l <= 0.0 => {
            return Err(crate::error::Error::Unsupported(
                "the Karan-Dey MSP compensates a dead time, and this integrator has none; use pid (the default for it)",
            ))
        }
        Some(ProcessModel::Ipdt(m)) => m,
        _ if plant.kind() == crate::poly::PlantKind::Integrating => {
            return Err(crate::error::Error::Unsupported(
                "the Karan-Dey MSP is designed for an IPDT model K*e^(-θs)/s; for an integrating plant with lags or zeros use matausek-micic or pid (msp picks one by default), or give --model as an IPDT",
            ))
        }
        _ => return Err(crate::error::Error::Unsupported("the Karan-Dey MSP needs an integrating plant")),
    };
    let lambda = lambda_for(&m.into(), &d.typed::<LambdaTuning>(), 0.25);
    Ok(Params::of(&tuning::karan_dey(&m, lambda)?).with_lambda(lambda))
}

/// The MSP's three controllers as Bag (2022) Eqs. 4.22–4.24 write them:
/// `Gc1 = Kp(1 + 1/(Ti s))`, `Gc2 = β·Kp`, `Gc3 = γ·Kp(1 + Td s/(1 + (Td/N)s))`,
/// and the Routh range `0 < γ < 1/(θm·K·Kp)` of Eq. 4.49 that keeps the
/// disturbance loop stable (the tuning takes its middle, Eq. 4.50).
pub fn describe_karan_dey(p: &Params, model: &Tf, _inner: Option<&Tf>, _ts: f64) -> Described {
    use super::DesignValue::{Scalar, StableRange};
    let k: KaranDeyParams<f64> = p.typed()?;
    let mut out = alloc::vec![
        ("gc1_kp", Scalar(k.kp)),
        ("gc1_ti", Scalar(k.ti)),
        ("gc2_gain", Scalar(k.beta * k.kp)),
        ("gc3_gain", Scalar(k.gamma * k.kp)),
        ("gc3_td", Scalar(k.td)),
        ("gc3_tf", Scalar(k.td / k.n)),
    ];
    if let Some(ProcessModel::Ipdt(m)) = model.exact_model() {
        out.push((
            "gamma_range",
            StableRange {
                param: "gamma",
                low: 0.0,
                high: 1.0 / (m.l * m.k * k.kp),
            },
        ));
    }
    Ok(out)
}

pub fn tune_watanabe_ito(plant: &Tf, d: &Design) -> Tuned {
    // The W-I loop is 1 + C·Kv/(s(1 + Ls)) (see dtc::watanabe_ito): SIMC PI for
    // an integrator with the lag L folded into the delay, τc = λ (default L/2).
    let m = integrating_model(plant, WI_PLANT)?;
    let lambda = lambda_for(&m.into(), &d.typed::<LambdaTuning>(), 0.5);
    let s = lambda + m.l;
    let g = PidGains {
        kp: 1.0 / (m.k * s),
        ti: 4.0 * s,
        td: 0.0,
    };
    Ok(Params::of(&g).with_lambda(lambda))
}

const WI_PLANT: &str = "the Watanabe-Ito predictor needs an integrating plant";

pub fn build_watanabe_ito<T: Real, const N: usize>(p: &Params, model: &Tf, b: &Build) -> Built<T> {
    let m = integrating_model(model, WI_PLANT)?;
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let c = dtc::watanabe_ito::build(
        pid_cfg(p, b)?,
        &p.typed()?,
        T::of(m.k),
        T::of(m.l),
        lti,
        delay,
    )?;
    limited(c, b)
}

const AHL_PLANT: &str = "the Astrom-Hang-Lim predictor needs an integrating plant";

pub fn tune_astrom_hang_lim(plant: &Tf, d: &Design) -> Tuned {
    // set point k/(s + k) with k = 1/λ (λ = L/4 by default); load loop
    // (1 + k1)s² + k2 s + k3 = (s + a)² with a = 1/L.
    let m = integrating_model(plant, AHL_PLANT)?;
    let t: AstromHangLimTuning = d.typed();
    let lambda = lambda_for(&m.into(), &t, 0.25);
    let a = t.a.unwrap_or(1.0 / m.l);
    let p = AstromHangLimParams {
        k: 1.0 / lambda,
        k1: 0.0,
        k2: 2.0 * a,
        k3: a * a,
    };
    Ok(Params::of(&p).with_lambda(lambda))
}

pub fn build_astrom_hang_lim<T: Real, const N: usize>(
    p: &Params,
    model: &Tf,
    b: &Build,
) -> Built<T> {
    let m = integrating_model(model, AHL_PLANT)?;
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    // M's window: the dead time in whole samples, with the model's room
    let mut line = delay_again::<T>(model, b)?;
    line.set_delay(line.delay().floor())?;
    let c = dtc::astrom_hang_lim::build(&p.typed()?, T::of(m.k), T::of(b.ts), lti, delay, line)?;
    limited(c, b)
}

pub fn tune_matausek_micic(plant: &Tf, d: &Design) -> Tuned {
    let m = integrating_model(
        plant,
        "the Matausek-Micic predictor needs an integrating plant",
    )?;
    if m.l <= 0.0 {
        return Err(crate::error::Error::Unsupported(
            "the Matausek-Micic predictor designs its load gain k0 = 0.5/(K*θ) from a dead time or a lag, and this plant has neither; use pid (the default for it)",
        ));
    }
    let t: MatausekMicicTuning = d.typed();
    let tr = t.tr.unwrap_or_else(|| lambda_for(&m.into(), &t, 0.25));
    Ok(Params::of(&MatausekMicicParams {
        kr: 1.0 / (m.k * tr),
        k0: 0.5 / (m.k * m.l),
        tr,
    }))
}

const KA_PLANT: &str = "the Kaya-Atherton predictor needs a stable or integrating plant";

/// Kaya–Atherton's settings for `plant` and the `λ` they were tuned for.
pub(super) fn kaya_atherton_settings<D: DesignSet>(
    plant: &TransferFunction,
    d: &D,
) -> Result<(KayaAthertonParams, f64), crate::error::Error> {
    let m = match plant.kind() {
        crate::poly::PlantKind::Integrating => {
            ProcessModel::Ipdt(integrating_model(plant, KA_PLANT)?)
        }
        _ => plant.reduce(false)?,
    };
    Ok(match m {
        ProcessModel::Ipdt(i) => {
            // the Karan-Dey settings: Gc2 = beta·Kp (P), Gc3 from gamma·Kp with Td = λ
            let lambda = lambda_for(&m, d, 0.25);
            let k = tuning::karan_dey(&i, lambda)?;
            let p = KayaAthertonParams {
                kp: k.kp,
                ti: k.ti,
                kf: k.beta * k.kp,
                tf: 0.0,
                kb: k.gamma * k.kp,
                td: k.td,
            };
            (p, lambda)
        }
        ProcessModel::Fopdt(_) | ProcessModel::Sopdt(_) => {
            // Kaya's PI on the model loop; a proportional Gc3 with loop gain 1/2,
            // stable for any dead time by the small-gain theorem
            let lambda = lambda_for(&m, d, 1.0);
            let g = tuning::kaya(&m, lambda)?;
            let p = KayaAthertonParams {
                kp: g.kp,
                ti: g.ti,
                kf: 0.0,
                tf: 0.0,
                kb: 0.5 / plant.gain(),
                td: 0.0,
            };
            (p, lambda)
        }
        _ => return Err(crate::error::Error::Unsupported(KA_PLANT)),
    })
}

pub fn tune_kaya_atherton(plant: &Tf, d: &Design) -> Tuned {
    let (p, lambda) = kaya_atherton_settings(plant, &d.typed::<LambdaTuning>())?;
    Ok(Params::of(&p).with_lambda(lambda))
}

/// Kaya–Atherton's predictor on `model` (without limits).
pub(super) fn kaya_atherton_on<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<Compensator<T, N, Vec<T>>, crate::error::Error> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    dtc::compensator::build(
        &p.typed::<T, KayaAthertonParams<T>>()?,
        T::of(b.ts),
        lti,
        delay,
    )
}

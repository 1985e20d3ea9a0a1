//! `smith`, `filtered-smith`, `huang`: the Smith predictor and its filters on
//! the model error (Kaya (2003); the MathWorks Smith predictor example).

use alloc::boxed::Box;

use super::common::*;
use super::{Build, Design, Params};
use crate::dtc::filtered_smith::FilteredSmithParams;
use crate::dtc::huang::HuangParams;
use crate::dtc::{self, SmithPredictor};
use crate::poly::TransferFunction;
use crate::tuning::LambdaTuning;
use crate::{model::ProcessModel, params::DesignSet, params::ParamSet, real::Real, tuning};

/// Kaya's PI/PID for a stable model, the thesis's IMC-PI for an integrating one.
fn primary_gains<D: DesignSet>(
    plant: &TransferFunction,
    d: &D,
    stable_factor: f64,
) -> Result<(tuning::PidGains<f64>, f64, ProcessModel<f64>), crate::error::Error> {
    let m = plant.reduce(plant.order() >= 2)?;
    Ok(match m {
        ProcessModel::Foipdt(f) => {
            let lambda = lambda_for(&m, d, 0.25);
            (tuning::imc_pid_integrating_lag(&f, lambda)?, lambda, m)
        }
        ProcessModel::Ipdt(i) => {
            let lambda = lambda_for(&m, d, 0.25);
            (tuning::imc_pi_integrating(&i, lambda)?, lambda, m)
        }
        _ => {
            let lambda = lambda_for(&m, d, stable_factor);
            (tuning::kaya(&m, lambda)?, lambda, m)
        }
    })
}

pub fn tune_smith(plant: &Tf, d: &Design) -> Tuned {
    let (g, lambda, _) = primary_gains(plant, &d.typed::<LambdaTuning>(), 1.0)?;
    Ok(Params::of(&g).with_lambda(lambda))
}

pub fn build_smith<T: Real, const N: usize>(p: &Params, model: &Tf, b: &Build) -> Built<T> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    Ok(Box::new(SmithPredictor::new(pid_cfg(p, b)?, lti, delay)?))
}

/// The dominant time constant of a stable model (for filter defaults).
fn dominant_lag(m: &ProcessModel<f64>) -> f64 {
    match *m {
        ProcessModel::Fopdt(f) => f.t,
        ProcessModel::Sopdt(s) => s.t1.max(s.t2),
        _ => m.delay(),
    }
}

pub fn tune_filtered_smith(plant: &Tf, d: &Design) -> Tuned {
    // the MathWorks Smith predictor example: λ = 12.5 s for L = 93.9 s (bandwidth 0.08 rad/s) → λ = L/7.5
    let (g, lambda, m) = primary_gains(plant, &d.typed::<LambdaTuning>(), 1.0 / 7.5)?;
    let p = FilteredSmithParams {
        a: 0.0,
        b: 0.5 * dominant_lag(&m),
        ..Default::default()
    }
    .with_fields_of(&g);
    Ok(Params::of(&p).with_lambda(lambda))
}

pub fn build_filtered_smith<T: Real, const N: usize>(
    p: &Params,
    model: &Tf,
    b: &Build,
) -> Built<T> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let c = dtc::filtered_smith::build(pid_cfg(p, b)?, &p.typed()?, lti, delay)?;
    limited(c, b)
}

pub fn tune_huang(plant: &Tf, d: &Design) -> Tuned {
    // the MathWorks Smith predictor example: Kp = 0.144 (λ ≈ 50 s ≈ L/2), B = 0.05/(40 s + 1)
    let (g, lambda, m) = primary_gains(plant, &d.typed::<LambdaTuning>(), 0.5)?;
    let p = HuangParams {
        kb: 0.05,
        tb: dominant_lag(&m),
        ..Default::default()
    }
    .with_fields_of(&g);
    Ok(Params::of(&p).with_lambda(lambda))
}

pub fn build_huang<T: Real, const N: usize>(p: &Params, model: &Tf, b: &Build) -> Built<T> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let line = delay_again(model, b)?;
    let c = dtc::huang::build(pid_cfg(p, b)?, &p.typed()?, lti, delay, line)?;
    limited(c, b)
}

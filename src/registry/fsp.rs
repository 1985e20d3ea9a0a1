//! `fsp`: the filtered Smith predictor for unstable, integrating and stable
//! plants (García et al. (2010), Sec. 3, Eq. 10).

use alloc::boxed::Box;
use alloc::vec::Vec;

use super::common::*;
use super::{Build, Builders, Design, DynControllerOf, Params, Scheme, SchemeFns, MAX_ORDER};
use crate::dtc;
use crate::dtc::fsp::{FspParams, FspTuning};
use crate::poly::TransferFunction;
use crate::{tuning, DesignSet, ParamList, ParamSet, PidConfig, ProcessModel, Real};
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

fn tune_fsp(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let t: FspTuning = d.typed();
    let m = plant.reduce(false)?;
    let lambda = lambda_for(&m, &t, 1.0);
    let (kp, ti) = match m {
        // K/(T s − 1): the delay-free loop with a PI gets the double pole −1/λ
        ProcessModel::Ufopdt(u) => {
            let kkc = 1.0 + 2.0 * u.t / lambda;
            (kkc / u.k, kkc * lambda * lambda / u.t)
        }
        // K/s: the same placement gives the thesis's IMC-PI
        ProcessModel::Ipdt(i) => (2.0 / (i.k * lambda), 2.0 * lambda),
        _ => {
            let g = tuning::kaya(&plant.reduce(true)?, lambda)?;
            (g.kp, g.ti)
        }
    };
    let tf = t.tf.unwrap_or(0.5 * m.delay().max(1e-9));
    Ok(Params::of(&FspParams { kp, ti, tf }).with_lambda(lambda))
}

/// The dead time of `model` in whole samples: the predictors of García et al. (2010)
/// realize `z^{−h}` inside `S` and `F1`, so `h` must be an integer.
pub(super) fn whole_samples(model: &TransferFunction, ts: f64) -> Result<usize, crate::Error> {
    let d = model.delay_samples(ts)?;
    let h = d.round();
    if (d - h).abs() > 1e-6 {
        return Err(crate::Error::Unsupported(
            "the predictor needs a dead time of a whole number of samples: choose ts = L/n",
        ));
    }
    num_traits::ToPrimitive::to_usize(&h).ok_or(crate::Error::DelayTooLong("delay"))
}

fn build_fsp<T: Real>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let fp: FspParams<T> = p.typed()?;
    let h = whole_samples(model, b.ts)?;
    let gm = model.to_model_lti::<MAX_ORDER>(b.ts)?;
    let design = dtc::fsp::design::<Vec<f64>, MAX_ORDER>(&gm, h, b.ts, fp.tf.f64())?;
    let k = PidConfig::isa(fp.kp, fp.ti, T::zero(), T::of(b.ts))
        .with_limits(T::of(b.u_min), T::of(b.u_max));
    Ok(Box::new(dtc::fsp::FilteredSmith::<T, Vec<T>>::new(
        k,
        &design,
        ParamList::of(&fp),
    )?))
}

pub(super) const FSP: Scheme = Scheme {
    name: "fsp",
    aliases: &["filtered-smith-unstable"],
    summary: "filtered Smith predictor for unstable, integrating and stable plants: Fr(z) from the Diophantine condition",
    source: "García et al. (2010) Sec. 3, Eq. 10",
    plants: ALL,
    params: FspParams::<f64>::NAMES,
    design: FspTuning::NAMES,
    fns: SchemeFns::Single {
        tune: tune_fsp,
        build: both!(build_fsp),
    },
};

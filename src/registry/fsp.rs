//! `fsp`: the filtered Smith predictor for unstable, integrating and stable
//! plants (García et al. (2010), Sec. 3, Eq. 10).

use alloc::boxed::Box;
use alloc::vec;
use alloc::vec::Vec;

use super::common::*;
use super::{Build, Design, Params, MAX_ORDER};
use crate::dtc;
use crate::dtc::fsp::{FspParams, FspTuning};
use crate::{model::ProcessModel, params::ParamList, pid::PidConfig, real::Real, tuning};
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

pub fn tune_fsp(plant: &Tf, d: &Design) -> Tuned {
    let t: FspTuning = d.typed();
    let m = plant.reduce(false)?;
    let lambda = lambda_for(&m, &t, 1.0);
    // a stable plant reduced for Kaya's rule (FOPDT or SOPDT)
    let rule = match m {
        ProcessModel::Ufopdt(_) | ProcessModel::Ipdt(_) => m,
        _ => plant.reduce(true)?,
    };
    let tuning::PidGains { kp, ti, .. } = tuning::fsp_pi(&rule, lambda)?;
    let tf = t.tf.unwrap_or(0.5 * m.delay().max(1e-9));
    Ok(Params::of(&FspParams { kp, ti, tf }).with_lambda(lambda))
}

/// The dead time of `model` in whole samples: the predictors of García et al. (2010)
/// realize `z^{−h}` inside `S` and `F1`, so `h` must be an integer.
pub(super) fn whole_samples(model: &Tf, ts: f64) -> Result<usize, crate::error::Error> {
    crate::delay::whole_samples(
        model.delay_samples(ts)?,
        usize::MAX,
        "the predictor needs a dead time of a whole number of samples: choose ts = L/n",
    )
}

pub fn build_fsp<T: Real>(p: &Params, model: &Tf, b: &Build) -> Built<T> {
    let fp: FspParams<T> = p.typed()?;
    let h = whole_samples(model, b.ts)?;
    let gm = model.to_model_lti::<MAX_ORDER>(b.ts)?;
    let spec = dtc::fsp::FrSpec {
        tf: fp.tf.f64(),
        lead: None,
        biproper: false,
    };
    let k = PidConfig::isa(fp.kp, fp.ti, T::zero(), T::of(b.ts))
        .with_limits(T::of(b.u_min), T::of(b.u_max));
    Ok(Box::new(dtc::fsp::FilteredSmith::with_predictor(
        k,
        fsp_predictor(&gm, h, b, spec)?,
        ParamList::of(&fp),
    )?))
}

/// The longest dead time a build may be given at run time
/// ([`Build::max_dead_time`]), in whole samples (0: none).
pub(super) fn room_samples(b: &Build) -> usize {
    num_traits::ToPrimitive::to_usize(&(b.max_dead_time / b.ts + 1e-6).floor()).unwrap_or(0)
}

/// The filtered Smith predictor's `Fr` and `S` for the model `gm` with `h`
/// samples of dead time, keeping the model and the filter's shape so that a
/// run-time dead time (up to [`Build::max_dead_time`]) redesigns them.
pub(super) fn fsp_predictor<T: Real>(
    gm: &crate::lti::Lti<f64, MAX_ORDER>,
    h: usize,
    b: &Build,
    spec: dtc::fsp::FrSpec,
) -> Result<dtc::fsp::FspPredictor<T, Vec<T>>, crate::error::Error> {
    let design = dtc::fsp::design_with::<Vec<f64>, MAX_ORDER>(gm, h, b.ts, &spec)?;
    let (nm, dm) = dtc::fsp::model_tf(gm);
    Ok(dtc::fsp::FspPredictor::new(&design)?.with_redesign(
        nm,
        dm,
        b.ts,
        spec,
        (h, room_samples(b)),
    ))
}

/// What García et al. (2010) print of a designed robustness filter
/// `Fr = kf·Π(z − ρi)/Π(z − γi)` (Examples 1–3): `Fr` itself, its gain `kf`,
/// its real zeros `ρi` and poles `γi`, and the poles it cancels from the
/// predictor — the model's poles on or outside the unit circle, and `z = 1`
/// for the integral action (Eq. 10's conditions).
pub(super) fn fr_report<const N: usize>(
    design: &dtc::fsp::FspDesign<Vec<f64>>,
    gm: &crate::lti::Lti<f64, N>,
) -> Described {
    use super::DesignValue::{Filter, List, Scalar};
    const RHO: [&str; 4] = ["rho1", "rho2", "rho3", "rho4"];
    const GAMMA: [&str; 4] = ["gamma1", "gamma2", "gamma3", "gamma4"];
    let (nr, dr) = (design.nr.as_slice(), design.dr.as_slice());
    let lead = |p: &[f64]| p.iter().copied().find(|c| *c != 0.0).unwrap_or(1.0);
    let real = |p: &[f64]| -> Result<Vec<f64>, crate::error::Error> {
        let mut r: Vec<f64> = crate::poly::poly_roots(p)?
            .into_iter()
            .filter(|(re, im)| im.abs() <= 1e-9 * re.abs().max(1.0))
            .map(|(re, _)| re)
            .collect();
        r.sort_by(f64::total_cmp);
        Ok(r)
    };
    let mut out: super::DesignReport = vec![
        (
            "fr",
            Filter {
                num: nr.to_vec(),
                den: dr.to_vec(),
            },
        ),
        ("kf", Scalar(lead(nr) / lead(dr))),
    ];
    out.extend(RHO.iter().zip(real(nr)?).map(|(n, v)| (*n, Scalar(v))));
    out.extend(GAMMA.iter().zip(real(dr)?).map(|(n, v)| (*n, Scalar(v))));
    let (_, dm) = dtc::fsp::model_tf(gm);
    let mut cancels: Vec<f64> = crate::poly::poly_roots(dm.as_slice())?
        .into_iter()
        .filter(|(re, im)| re.hypot(*im) >= 1.0 - 1e-9 && im.abs() <= 1e-9)
        .map(|(re, _)| re)
        .collect();
    if !cancels.iter().any(|z| (z - 1.0).abs() < 1e-6) {
        cancels.push(1.0);
    }
    cancels.sort_by(f64::total_cmp);
    out.push(("cancels", List(cancels)));
    Ok(out)
}

pub fn describe_fsp(p: &Params, model: &Tf, _inner: Option<&Tf>, ts: f64) -> Described {
    let fp: FspParams<f64> = p.typed()?;
    let h = whole_samples(model, ts)?;
    let gm = model.to_model_lti::<MAX_ORDER>(ts)?;
    let design = dtc::fsp::design::<Vec<f64>, MAX_ORDER>(&gm, h, ts, fp.tf)?;
    fr_report(&design, &gm)
}

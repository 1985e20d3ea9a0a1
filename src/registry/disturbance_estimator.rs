//! `disturbance-estimator`: Draganović et al. (2001), Cases 1–6.

use super::common::*;
use super::{Design, Params};
use crate::dtc::disturbance_estimator::{
    case_number, DisturbanceEstimatorParams, DisturbanceEstimatorTuning,
};
use crate::tuning;

pub fn tune_disturbance_estimator(plant: &Tf, d: &Design) -> Tuned {
    let m = integrating_model(
        plant,
        "the disturbance estimator needs an integrating plant",
    )?;
    let t: DisturbanceEstimatorTuning = d.typed();
    let td = t.td.unwrap_or_else(|| lambda_for(&m.into(), &t, 0.25));
    let case = t.case.unwrap_or(1.0);
    let design = tuning::EstimatorDesign {
        case: case_number(case)?,
        tde: t.tde.unwrap_or(0.55 * m.l),
        alpha: t.alpha.unwrap_or(if case == 6.0 { 0.95 } else { 0.5 }),
        w0: t.w0.unwrap_or(0.05),
    };
    let t = tuning::disturbance_estimator(m.k, m.l, &design)?;
    Ok(Params::of(&DisturbanceEstimatorParams {
        kr: 1.0 / (m.k * td),
        td,
        case,
        ka: t.ka,
        ta: t.ta,
        tc: t.tc,
        tde: design.tde,
        alpha: design.alpha,
        w0: design.w0,
    }))
}

//! Several controllers on one (perturbed) plant.

use std::string::String;
use std::vec::Vec;

use super::{choose_duration, choose_ts, RunError, RunOutput, Scenario};
use crate::Error;

/// Relative perturbations of the plant for `msp compare` (each controller keeps
/// the nominal model): `0.1` is +10 %.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct Perturbation {
    /// Gain change.
    pub gain: f64,
    /// Dead-time change.
    pub delay: f64,
    /// Time-constant change.
    pub tau: f64,
    /// Cascade processes: gain change of the secondary process (the three
    /// fields above act on the primary).
    pub inner_gain: f64,
    /// Dead-time change of the secondary process.
    pub inner_delay: f64,
    /// Time-constant change of the secondary process.
    pub inner_tau: f64,
}

/// Runs `base` once per controller on the same (optionally perturbed) plant,
/// each controller tuned on and holding the nominal model, at one common sample period.
pub fn compare(
    base: &Scenario,
    controllers: &[String],
    perturb: Perturbation,
) -> Result<Vec<RunOutput>, RunError> {
    let (nominal, model) = base.plant_and_model()?;
    let plant = nominal.perturbed(perturb.gain, perturb.delay, perturb.tau)?;
    let inner = match base.inner_process()? {
        Some((p2, m2)) => Some((
            p2.perturbed(perturb.inner_gain, perturb.inner_delay, perturb.inner_tau)?,
            m2,
        )),
        None => {
            if perturb.inner_gain != 0.0 || perturb.inner_delay != 0.0 || perturb.inner_tau != 0.0 {
                return Err(RunError::Invalid(Error::Unsupported(
                    "inner perturbations need a cascade process (an inner plant)",
                )));
            }
            None
        }
    };
    let (whole_model, whole_plant) = match &inner {
        Some((p2, m2)) => (model.series(m2)?, plant.series(p2)?),
        None => (model.clone(), plant.clone()),
    };
    let mut sc = base.clone();
    sc.ts = Some(match base.ts {
        Some(ts) => ts,
        None => choose_ts(&whole_model),
    });
    if sc.duration.is_none() {
        sc.duration = Some(choose_duration(&whole_plant, sc.ts.unwrap_or(1.0)));
    }
    if controllers.is_empty() {
        return Err(RunError::Invalid(Error::OutOfRange("controllers")));
    }
    controllers
        .iter()
        .map(|c| {
            let mut one = sc.clone();
            one.controller = Some(c.clone());
            let tuned = one.tune_for(&model, inner.as_ref().map(|(_, m)| m))?;
            let mut out = one.run_tuned(&tuned, plant.clone(), model.clone(), inner.clone())?;
            let settled = out.result.diverged_at.is_none() && out.has_settled();
            out.stability =
                crate::analysis::tuned_stability(&one, &tuned, &plant, &model, inner.as_ref())
                    .with_simulation(settled, out.duration);
            Ok(out)
        })
        .collect()
}

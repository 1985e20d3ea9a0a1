//! Several controllers on one (perturbed) plant.

use std::string::String;
use std::vec::Vec;

use super::{choose_duration, choose_ts_as, RunError, RunOutput, Scenario};
use crate::error::Error;

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
        None => choose_ts_as(&whole_model, base.float32),
    });
    if sc.duration.is_none() {
        sc.duration = Some(choose_duration(&whole_plant, sc.ts.unwrap_or(1.0)));
    }
    if controllers.is_empty() {
        return Err(RunError::Invalid(Error::OutOfRange("controllers")));
    }
    // every scheme tuned for the nominal model, at equal robustness where
    // the user left its tuning to msp
    let mut tuned = Vec::with_capacity(controllers.len());
    for c in controllers {
        let mut one = sc.clone();
        one.controller = Some(c.clone());
        let t = one.tune_for(&model, inner.as_ref().map(|(_, m)| m))?;
        tuned.push((one, t));
    }
    // a design target given: each scheme solved for it (by `tune_for`);
    // else equal robustness
    let target = if inner.is_none() && base.target.is_none() {
        equal_robustness(&mut tuned, &nominal, &model)
    } else {
        None
    };
    // the default scenario of `run`: a set-point step, then a load at a
    // common time after the slowest response settled
    let default =
        base.setpoint.is_empty() && base.disturbance.is_empty() && base.duration.is_none();
    if default {
        let mut settle = 0.0f64;
        let probes = super::each(&tuned, |(one, t)| {
            one.run_tuned(t, plant.clone(), model.clone(), inner.clone())
                .map(|probe| probe.metrics.step.settling_time)
        });
        for probe in probes {
            settle = settle.max(probe?);
        }
        if let Some(load) = super::default_load(&whole_plant).filter(|_| settle.is_finite()) {
            let at = super::nice_ceil(1.25 * settle.max(sc.ts.unwrap_or(1.0)));
            for (one, _) in &mut tuned {
                one.setpoint = std::vec![crate::sim::SetpointStep {
                    value: 1.0,
                    at: 0.0
                }];
                one.disturbance = std::vec![crate::sim::Disturbance::input_step(load, at)];
                one.duration = Some(super::nice_ceil(at + 2.0 * at.max(settle)));
            }
        }
    }
    // each scheme's run and verdict on its own core
    super::each(&tuned, |(one, t)| {
        let mut out = one.run_tuned(t, plant.clone(), model.clone(), inner.clone())?;
        let settled = out.settled_as_built(&out.result.t, &out.result.y);
        let verdict = super::tuned_stability(one, t, &plant, &model, inner.as_ref());
        out.stability = out.cross_checked(verdict, settled);
        out.default_scenario = default;
        // the margins the comparison's table prints, in the report too: an
        // unstable loop has none; a cascade's loop is broken at the inner
        // set point, a single loop at the plant input (the plant behind
        // the hold), as the run's controller was tuned
        out.robustness = if out.stability.stable == Some(false) {
            Some(crate::analysis::Margins::unstable())
        } else if inner.is_some() {
            super::analyze(one, crate::analysis::View::Discrete, None)
                .ok()
                .map(|an| an.margins)
        } else {
            one.margins_of_tuned(t, &plant, &model, 6000)
        };
        if let Some(t) = &out.target {
            out.notes.push(std::format!(
                "{}: tuned for the target {}: {}",
                out.controller,
                t.target,
                t.outcome()
            ));
        }
        if let (Some(ms), Some(l)) = (target, one.lambda.filter(|_| base.lambda.is_none())) {
            let got = one
                .margins_of_tuned(t, &nominal, &model, 300)
                .map_or(f64::NAN, |m| m.ms);
            out.notes.push(std::format!(
                "{}: tuned for the common Ms = {}: lambda = {} gives Ms = {}",
                out.controller,
                crate::poly::fmt_num(crate::poly::round_sig(ms, 3)),
                crate::poly::fmt_num(crate::poly::round_sig(l, 4)),
                crate::poly::fmt_num(crate::poly::round_sig(got, 3))
            ));
        }
        Ok(out)
    })
    .into_iter()
    .collect()
}

/// The sensitivity peak a comparison tunes every scheme to by default.
pub const COMPARE_MS: f64 = 1.6;

/// Retunes, at equal robustness, each scheme whose tuning the user left to
/// msp (no `--lambda`, no `--set` for it) and whose rule has a `λ`: the
/// largest `Ms ≤ 1.6` ([`COMPARE_MS`]) every such scheme reaches, each
/// scheme's `λ` found by bisection on `ln λ` where its `Ms` crosses the
/// target (the branch of the larger `λ` where `Ms(λ)` is not monotone).
/// Returns the common target.
fn equal_robustness(
    tuned: &mut [(Scenario, super::Tuned)],
    plant: &crate::poly::TransferFunction,
    model: &crate::poly::TransferFunction,
) -> Option<f64> {
    const FACTORS: [f64; 9] = [0.125, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0];
    let free = |one: &Scenario, t: &super::Tuned| {
        one.lambda.is_none()
            && !one.set.keys().any(|k| match k.split_once('.') {
                Some((scheme, _)) => {
                    crate::registry::find(scheme).is_ok_and(|s| s.name == t.scheme.name)
                }
                None => true,
            })
            && t.params.lambda().is_some_and(|l| l.is_finite() && l > 0.0)
    };
    let ms_at = |one: &Scenario, l: f64| -> Option<f64> {
        let mut sc = one.clone();
        sc.lambda = Some(l);
        let t = sc.tune_for(model, None).ok()?;
        sc.margins_of_tuned(&t, plant, model, 300)
            .map(|m| m.ms)
            .filter(|m| m.is_finite())
    };
    // each free scheme's Ms over a range of λ around its own, the schemes
    // on their own cores
    let shared: &[(Scenario, super::Tuned)] = tuned;
    let indices: std::vec::Vec<usize> = (0..shared.len()).collect();
    let mut curves: std::vec::Vec<(usize, std::vec::Vec<(f64, f64)>)> =
        super::each(&indices, |&i| {
            let (one, t) = shared.get(i)?;
            if !free(one, t) {
                return None;
            }
            let l0 = t.params.lambda()?;
            let pts: std::vec::Vec<(f64, f64)> = FACTORS
                .iter()
                .filter_map(|f| ms_at(one, l0 * f).map(|m| (l0 * f, m)))
                .collect();
            (pts.len() >= 2).then_some((i, pts))
        })
        .into_iter()
        .flatten()
        .collect();
    if curves.is_empty() {
        return None;
    }
    // a scheme whose Ms does not move with λ keeps its own tuning
    let span = |p: &[(f64, f64)]| {
        let (lo, hi) = p
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x.1), b.max(x.1))
            });
        (lo, hi)
    };
    curves.retain(|(_, p)| {
        let (lo, hi) = span(p);
        hi - lo > 0.01 * lo
    });
    if curves.is_empty() {
        return None;
    }
    // the largest Ms up to 1.6 that every scheme reaches from its less robust side
    let highest = curves
        .iter()
        .map(|(_, p)| span(p).1)
        .fold(f64::INFINITY, f64::min);
    let target = COMPARE_MS.min(highest);
    // each scheme's λ for the target, on its own core
    let chosen = super::each(&curves, |(i, pts)| {
        let Some((one, _)) = shared.get(*i) else {
            return (*i, f64::NAN);
        };
        // the bracket of the largest λ where Ms crosses the target
        let bracket = pts
            .windows(2)
            .rev()
            .find(|w| match (w.first(), w.get(1)) {
                (Some(a), Some(b)) => (a.1 - target) * (b.1 - target) <= 0.0,
                _ => false,
            })
            .and_then(|w| Some((*w.first()?, *w.get(1)?)));
        let l = match bracket {
            Some(((mut lo, mut mlo), (mut hi, _))) => {
                for _ in 0..30 {
                    let mid = (lo * hi).sqrt();
                    let Some(m) = ms_at(one, mid) else { break };
                    if (m - target) * (mlo - target) <= 0.0 {
                        hi = mid;
                    } else {
                        (lo, mlo) = (mid, m);
                    }
                    if hi / lo < 1.0 + 1e-4 {
                        break;
                    }
                }
                (lo * hi).sqrt()
            }
            // not reached: the λ whose Ms is nearest
            None => pts
                .iter()
                .min_by(|a, b| (a.1 - target).abs().total_cmp(&(b.1 - target).abs()))
                .map_or(f64::NAN, |p| p.0),
        };
        (*i, l)
    });
    for (i, l) in chosen {
        let Some((one, t)) = tuned.get_mut(i) else {
            continue;
        };
        if !l.is_finite() {
            continue;
        }
        one.lambda = Some(crate::poly::round_sig(l, 4));
        if let Ok(t2) = one.tune_for(model, None) {
            *t = t2;
        }
    }
    Some(target)
}

//! `pid`: the PI/PID baseline (Bag (2022), Ch. 3).

use alloc::boxed::Box;

use super::common::*;
use super::{Build, Design, Params};
use crate::pid::Pid;
use crate::tuning::LambdaTuning;
use crate::{model::Fopdt, model::Ipdt, model::ProcessModel, real::Real, tuning};

pub fn tune_pid(plant: &Tf, d: &Design) -> Tuned {
    tune(plant, d, false)
}

pub fn tune_pi(plant: &Tf, d: &Design) -> Tuned {
    tune(plant, d, true)
}

/// The PID (or, `pi_only`, the PI: `td = 0` by the rule, never by dropping a
/// tuned derivative) of the named or default rule.
fn tune(plant: &Tf, d: &Design, pi_only: bool) -> Tuned {
    // a PI is tuned on the first-order model (SIMC's half rule: the smaller
    // lag's half to the larger one and half to the dead time, Skogestad
    // (2003)), a PID on the second-order one
    let m = match plant.reduce(!pi_only)? {
        ProcessModel::Sopdt(s) if pi_only => {
            let (big, small) = (s.t1.max(s.t2), s.t1.min(s.t2));
            ProcessModel::Fopdt(Fopdt::new(s.k, big + small / 2.0, s.l + small / 2.0)?)
        }
        // an integrator with a lag: SIMC's PI is tuned on the IPDT with the
        // lag in the delay (its PID would cancel the lag with td = T)
        ProcessModel::Foipdt(f) if pi_only => ProcessModel::Ipdt(Ipdt::new(f.k, f.l + f.t)?),
        other => other,
    };
    let default_rule = if !pi_only && matches!(plant.reduce(false)?, ProcessModel::Fopdt(_)) {
        "imc"
    } else {
        "simc"
    };
    let rule = d.rule.as_deref().unwrap_or(default_rule);
    let t: LambdaTuning = d.typed();
    let named = |name: &'static str| super::Rule {
        name,
        ku: None,
        tu: None,
        weights: None,
    };
    let (g, lambda, named) = match rule {
        "imc" | "imc-pid" if pi_only => {
            return Err(crate::error::Error::Unsupported(
                "IMC-PID is a PID: use --controller pid, or --rule simc for a PI",
            ))
        }
        "imc" | "imc-pid" => {
            let f = match plant.reduce(false)? {
                ProcessModel::Fopdt(f) => f,
                _ => {
                    return Err(crate::error::Error::Unsupported(
                        "IMC-PID needs a stable FOPDT model (use --rule simc)",
                    ))
                }
            };
            let lambda = lambda_for(&f.into(), &t, 1.0);
            (tuning::imc_pid(&f, lambda)?, lambda, named("imc"))
        }
        "simc" => {
            let lambda = lambda_for(&m, &t, 1.0);
            (tuning::simc(&m, lambda)?, lambda, named("simc"))
        }
        "amigo" => {
            // on the first-order model (the rules are for FOPDT and IPDT);
            // an integrator with a lag: its lag in the dead time, as SIMC's PI
            let f = match plant.reduce(false)? {
                ProcessModel::Foipdt(f) => ProcessModel::Ipdt(Ipdt::new(f.k, f.l + f.t)?),
                other => other,
            };
            let (g, b) = tuning::amigo(&f, pi_only)?;
            let rule = super::Rule {
                weights: Some((b, 0.0)),
                ..named("amigo")
            };
            (g, f64::NAN, rule)
        }
        name => {
            let r = tuning::ultimate_rule(name).ok_or(crate::error::Error::Unsupported(
                "unknown tuning rule (see `msp list`)",
            ))?;
            if pi_only && r.c != 0.0 {
                return Err(crate::error::Error::Unsupported(
                    "this ultimate-cycle rule gives a PID: use --controller pid, or a PI rule (see `msp list`)",
                ));
            }
            let (ku, tu) = plant.ultimate().ok_or(crate::error::Error::Unsupported(
                "the plant has no ultimate point",
            ))?;
            let rule = super::Rule {
                name: r.name,
                ku: Some(ku),
                tu: Some(tu),
                weights: None,
            };
            (tuning::ultimate_cycle(r, ku, tu)?, f64::NAN, rule)
        }
    };
    let p = Params::of(&g).with_rule(named);
    Ok(if lambda.is_nan() {
        p
    } else {
        p.with_lambda(lambda)
    })
}

pub fn build_pid<T: Real>(p: &Params, _m: &Tf, b: &Build) -> Built<T> {
    Ok(Box::new(Pid::new(pid_cfg(p, b)?)?))
}

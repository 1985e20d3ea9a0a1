//! `pid`: the PI/PID baseline (Bag (2022), Ch. 3).

use alloc::boxed::Box;

use super::common::*;
use super::{Build, Builders, Design, DynControllerOf, Params, Scheme, SchemeFns};
use crate::poly::TransferFunction;
use crate::tuning::PidGains;
use crate::Pid;
use crate::{tuning, ParamSet, ProcessModel, Real};

fn tune_pid(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let m = plant.reduce(true)?;
    let default_rule = if matches!(plant.reduce(false)?, ProcessModel::Fopdt(_)) {
        "imc"
    } else {
        "simc"
    };
    let rule = d.rule.as_deref().unwrap_or(default_rule);
    let (g, lambda) = match rule {
        "imc" | "imc-pid" => {
            let f = match plant.reduce(false)? {
                ProcessModel::Fopdt(f) => f,
                _ => {
                    return Err(crate::Error::Unsupported(
                        "IMC-PID needs a stable FOPDT model (use --rule simc)",
                    ))
                }
            };
            let lambda = lambda_for(&f.into(), d, 1.0);
            (tuning::imc_pid(&f, lambda)?, lambda)
        }
        "simc" => {
            let lambda = lambda_for(&m, d, 1.0);
            (tuning::simc(&m, lambda)?, lambda)
        }
        name => {
            let r = tuning::ultimate_rule(name).ok_or(crate::Error::Unsupported(
                "unknown tuning rule (see `msp list`)",
            ))?;
            let (ku, tu) = plant
                .ultimate()
                .ok_or(crate::Error::Unsupported("the plant has no ultimate point"))?;
            (tuning::ultimate_cycle(r, ku, tu)?, f64::NAN)
        }
    };
    let p = Params::of(&g);
    Ok(if lambda.is_nan() {
        p
    } else {
        p.with_lambda(lambda)
    })
}

fn build_pid<T: Real>(
    p: &Params,
    _m: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    Ok(Box::new(Pid::new(pid_cfg(p, b)?)?))
}

pub(super) const PID: Scheme = Scheme {
    name: "pid",
    aliases: &["pi"],
    summary: "plain PI/PID feedback, the baseline: IMC-PID (default), SIMC, or an ultimate-cycle rule (--rule)",
    source: "Bag (2022) Eqs. 3.19-3.27, Tables 3.2-3.3",
    plants: STABLE_INT,
    params: PidGains::<f64>::NAMES,
    design: &["lambda", "alpha"],
    fns: SchemeFns::Single {
        tune: tune_pid,
        build: both!(build_pid),
    },
};

//! What the schemes' tuning and construction share: parameter access, λ,
//! the model's parts, and the build dispatch on the model order.

use alloc::boxed::Box;
use alloc::vec::Vec;

use super::{Build, DynControllerOf, Params};
use crate::delay::Delay;
use crate::dtc::{self, compensator::CompensatorParams, Compensator};
use crate::poly::{PlantKind, TransferFunction};
use crate::tuning::PidGains;
use crate::{
    lti::Lti, model::Ipdt, model::ProcessModel, params::DesignSet, pid::PidConfig, real::Real,
};

/// A plant or model, as the registry's functions take it.
pub(super) type Tf = TransferFunction;
/// What a scheme's tuning returns.
pub(super) type Tuned = Result<Params, crate::error::Error>;
/// What a scheme's construction returns.
pub(super) type Built<T> = Result<DynControllerOf<T>, crate::error::Error>;
/// What a scheme's `describe` returns.
pub(super) type Described = Result<super::DesignReport, crate::error::Error>;

/// The PID of a scheme's parameters (its `kp`, `ti`, `td`) with the build's
/// period and actuator limits.
pub(super) fn pid_cfg<T: Real>(p: &Params, b: &Build) -> Result<PidConfig<T>, crate::error::Error> {
    let g: PidGains<T> = p.typed()?;
    let cfg = PidConfig::try_isa(g.kp, g.ti, g.td, T::of(b.ts))?
        .with_limits(T::of(b.u_min), T::of(b.u_max));
    // a rule's own set-point weights (AMIGO)
    Ok(match p.rule().and_then(|r| r.weights) {
        Some((wb, wc)) => cfg.with_weights(T::of(wb), T::of(wc)),
        None => cfg,
    })
}

/// `λ`: given, or `alpha·L`, or `default_factor·L`; for a model without dead
/// time, [`delay_free_lambda`].
pub(super) fn lambda_for<D: DesignSet>(
    model: &ProcessModel<f64>,
    d: &D,
    default_factor: f64,
) -> f64 {
    let l = model.delay();
    match (d.lambda(), d.alpha()) {
        (Some(lambda), _) => lambda,
        (None, Some(a)) if l > 0.0 => a * l,
        (None, None) if l > 0.0 => default_factor * l,
        _ => delay_free_lambda(model),
    }
}

/// `λ` for a model without dead time, where the rules' `λ = α·L` is zero:
/// half the largest time constant (the closed loop twice as fast as the
/// open loop, as SIMC's `τc` may be chosen freely when `θ = 0`, Skogestad
/// (2003)), or 1 s for a pure integrator, which has no time scale of its own.
pub(crate) fn delay_free_lambda(model: &ProcessModel<f64>) -> f64 {
    let lag = model.largest_lag();
    if lag > 0.0 {
        0.5 * lag
    } else {
        1.0
    }
}

/// A model's delay-free block and its dead-time line.
pub(super) type ModelParts<T, const N: usize> = (Lti<T, N>, Delay<T, Vec<T>>);

/// The model's delay-free part at the controller period and its dead time.
pub(super) fn model_parts<T: Real, const N: usize>(
    model: &TransferFunction,
    b: &Build,
) -> Result<ModelParts<T, N>, crate::error::Error> {
    Ok((
        Lti::of(&model.to_model_lti::<N>(b.ts)?),
        delay_again(model, b)?,
    ))
}

/// The model's dead time in a line of its own (Huang's filter, Åström–Hang–Lim's M, Uma et al.'s model),
/// with room for the longest dead time the run will give the model
/// ([`Build::max_dead_time`]).
pub(super) fn delay_again<T: Real>(
    model: &TransferFunction,
    b: &Build,
) -> Result<Delay<T, Vec<T>>, crate::error::Error> {
    let d = model.delay_samples(b.ts)?;
    let room = if b.max_dead_time > 0.0 {
        (b.max_dead_time / b.ts).max(d)
    } else {
        d
    };
    let line: Delay<T, Vec<T>> = Delay::new_in(T::of(room))?;
    Delay::with_storage(line.into_storage(), T::of(d))
}

/// The compensator of the scheme whose parameters are `P`, around the
/// model's parts, with the build's actuator limits, boxed.
pub(super) fn compensator<T: Real, P: CompensatorParams<T>, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::error::Error> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    limited(
        dtc::compensator::build(&p.typed::<T, P>()?, T::of(b.ts), lti, delay)?,
        b,
    )
}

/// A compensator with the build's actuator limits, boxed.
pub(super) fn limited<T: Real, const N: usize>(
    c: Compensator<T, N, Vec<T>>,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::error::Error> {
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

/// The integrating model `K e^{−Ls}/s` of `plant`; `scheme` names the scheme
/// in the error for any other plant.
pub(super) fn integrating_model(
    plant: &TransferFunction,
    scheme: &'static str,
) -> Result<Ipdt<f64>, crate::error::Error> {
    match plant.reduce(false)? {
        ProcessModel::Ipdt(m) => Ok(m),
        // an integrator with a lag T acts at low frequency as K/s with T more
        // dead time (Skogestad's half rule puts every lag of an integrating
        // plant into the delay); the predictor still holds the whole model
        ProcessModel::Foipdt(f) => Ipdt::new(f.k, f.l + f.t),
        _ => Err(crate::error::Error::Unsupported(scheme)),
    }
}

/// A build function dispatched on the model order, so that the model block
/// holds no more states than it needs (the update cost grows with them);
/// `by_order!(common::compensator<KaranDeyParams>)` builds the compensator
/// of a parameter type.
macro_rules! by_order {
    ($($f:ident)::+ $(<$p:ident>)?) => {{
        pub(super) fn dispatch<T: Real>(
            p: &Params,
            m: &TransferFunction,
            b: &Build,
        ) -> Result<DynControllerOf<T>, crate::error::Error> {
            match m.model_order() {
                0 | 1 => $($f)::+::<T, $($p<T>,)? 1>(p, m, b),
                2 => $($f)::+::<T, $($p<T>,)? 2>(p, m, b),
                3 | 4 => $($f)::+::<T, $($p<T>,)? 4>(p, m, b),
                _ => $($f)::+::<T, $($p<T>,)? MAX_ORDER>(p, m, b),
            }
        }
        both!(dispatch)
    }};
}

/// A generic build function in both precisions.
macro_rules! both {
    ($($f:ident)::+) => {
        Builders {
            f64: $($f)::+::<f64>,
            f32: $($f)::+::<f32>,
        }
    };
}

pub(super) const STABLE: &[PlantKind] = &[PlantKind::Stable];
pub(super) const ALL: &[PlantKind] = &[
    PlantKind::Stable,
    PlantKind::Integrating,
    PlantKind::Unstable,
];
pub(super) const STABLE_INT: &[PlantKind] = &[PlantKind::Stable, PlantKind::Integrating];
pub(super) const INT: &[PlantKind] = &[PlantKind::Integrating];

pub(super) use {both, by_order};

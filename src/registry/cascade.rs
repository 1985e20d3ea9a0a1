//! The cascade schemes of García et al. (2010): FSPCC, GPCC, and the
//! competitors of Uma et al. (2009) and Kaya et al. (2008).

use alloc::boxed::Box;
use alloc::vec::Vec;

use super::common::*;
use super::fsp::{fsp_predictor, room_samples, whole_samples};
use super::integrating::{kaya_atherton_on, kaya_atherton_settings};
use super::{Build, Design, Params, MAX_ORDER};
use crate::dtc;
use crate::poly::TransferFunction;
use crate::{lti::Lti, params::ParamList, params::ParamSet, pid::Pid, pid::PidConfig, real::Real};

use crate::dtc::cascade::{
    self, Cascade, CascadePrimary, CascadePrimaryTuning, FspccParams, FspccTuning, GpccParams,
    GpccTuning, Imc, KayaCascadeParams, KayaCascadeTuning, UmaParams, UmaTuning,
};
use crate::dtc::compensator::{Compensator, DisturbancePath, ErrorPath, AUX};
use crate::dtc::fsp::{FrSpec, Predicted};
use crate::dtc::gpcc::GpccPredictor;
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

/// The inner IMC filter time constant: given, or the secondary dead time
/// (the paper's examples: λ2 = L2 = 2 s in Example 1), or a tenth of the
/// secondary's slowest time scale when it has no dead time.
fn lambda2_for(p2: &Tf, lambda2: Option<f64>) -> Result<f64, crate::error::Error> {
    if let Some(l) = lambda2 {
        return Ok(l);
    }
    if p2.delay > 0.0 {
        return Ok(p2.delay);
    }
    let slow = p2.time_scales()?.into_iter().fold(0.0, f64::max);
    Ok(if slow > 0.0 { 0.1 * slow } else { 1.0 })
}

/// The primary model `Gm e^{−Ls}` (with the inner loop closed), `λ` and the
/// pole-placed series PID `(kp, ki, kd, τ)` for it. Default `λ = 0.8·L`: Uma
/// et al.'s Example 1 design places the poles at `−1/5` for `L = 6 s`.
fn cascade_primary(
    p1: &TransferFunction,
    p2: &TransferFunction,
    d: &CascadePrimaryTuning,
) -> Result<(f64, f64, [f64; 4], TransferFunction), crate::error::Error> {
    let lambda2 = lambda2_for(p2, d.lambda2)?;
    let gm = cascade::primary_model(p1, p2, lambda2)?;
    let lambda = match (d.lambda, d.alpha) {
        (Some(l), _) => l,
        (None, Some(a)) => a * gm.delay,
        (None, None) if gm.delay > 0.0 => 0.8 * gm.delay,
        (None, None) => lambda2,
    };
    let k = cascade::pole_placement(&gm, lambda)?;
    Ok((lambda2, lambda, k, gm))
}

/// The primary PID of a cascade scheme (`kp, ki, kd, tau`), the set-point
/// weight (0.3, the paper's examples) and `lambda2`, with the primary model
/// `Gm` and `λ`.
fn cascade_primary_params(
    p1: &TransferFunction,
    p2: &TransferFunction,
    d: &Design,
) -> Result<(CascadePrimary, TransferFunction, f64), crate::error::Error> {
    let d: CascadePrimaryTuning = d.typed();
    let (lambda2, lambda, [kp, ki, kd, tau], gm) = cascade_primary(p1, p2, &d)?;
    let primary = CascadePrimary {
        kp,
        ki,
        kd,
        tau,
        epsilon: d.epsilon.unwrap_or(0.3),
        lambda2,
    };
    Ok((primary, gm, lambda))
}

/// A cascade scheme's parameters: its own fields `own`, the primary's from
/// `c`, tuned for `lambda`.
fn tuned<P: ParamSet<f64>>(own: P, c: &CascadePrimary, lambda: f64) -> Params {
    Params::of(&own.with_fields_of(c)).with_lambda(lambda)
}

/// The parts every cascade scheme builds: the primary model `Gm e^{−(L1+L2)s}`,
/// its ZOH block, its dead time in whole samples, the inner loop and the
/// primary controller (as Uma et al.'s PID and as FSPCC's matched `K(z)`).
struct CascadeParts<T> {
    model: TransferFunction,
    /// The primary model's delay-free part, designed in `f64`.
    gm: Lti<f64, MAX_ORDER>,
    h: usize,
    imc: Imc<T, Vec<T>>,
    /// Uma et al.'s `Gcs` as a PID (their continuous design, sampled).
    k: PidConfig<T>,
    /// The same, pole-zero matched (FSPCC's and GPCC's `K(z)`).
    km: dtc::fsp::Matched2Dof<T>,
}

/// The primary model `Gm e^{−(L1+L2)s}` and the inner IMC loop of a cascade
/// scheme (actuator limits on the inner loop's output, the plant input).
fn cascade_inner<T: Real>(
    lambda2: f64,
    p1: &TransferFunction,
    p2: &TransferFunction,
    b: &Build,
) -> Result<(TransferFunction, Imc<T, Vec<T>>), crate::error::Error> {
    let imc =
        Imc::<T, Vec<T>>::design(p2, lambda2, b.ts)?.with_limits(T::of(b.u_min), T::of(b.u_max))?;
    Ok((cascade::primary_model(p1, p2, lambda2)?, imc))
}

fn cascade_parts<T: Real>(
    p: &Params,
    p1: &TransferFunction,
    p2: &TransferFunction,
    b: &Build,
) -> Result<CascadeParts<T>, crate::error::Error> {
    let c: CascadePrimary = p.typed()?;
    let (model, imc) = cascade_inner(c.lambda2, p1, p2, b)?;
    Ok(CascadeParts {
        gm: model.to_model_lti::<MAX_ORDER>(b.ts)?,
        h: whole_samples(&model, b.ts)?,
        model,
        imc,
        k: cascade::series_pid(
            T::of(c.kp),
            T::of(c.ki),
            T::of(c.kd),
            T::of(c.tau),
            T::of(c.epsilon),
            T::of(b.ts),
        )?,
        km: cascade::matched_primary(c.kp, c.ki, c.kd, c.tau, c.epsilon, b.ts)?,
    })
}

const PREDICTED_SIGNALS: &[&str] = &["r2", "inner_error", "prediction"];
const COMPENSATOR_SIGNALS: &[&str] = &[
    "r2",
    "inner_error",
    "ym",
    "ym_delayed",
    "model_error",
    "u1",
    "u3",
];

pub fn tune_fspcc(p1: &Tf, p2: &Tf, d: &Design) -> Tuned {
    let (c, gm, lambda) = cascade_primary_params(p1, p2, d)?;
    let t: FspccTuning = d.typed();
    let p = FspccParams {
        tf: t.tf.unwrap_or(0.5 * gm.delay.max(1e-9)),
        lead: t.lead.unwrap_or(0.0),
        lag: t.lag.unwrap_or(0.0),
        ..Default::default()
    };
    Ok(tuned(p, &c, lambda))
}

/// FSPCC's `Fr` shape: biproper, with the lead-lag of `Gcd` when both
/// time constants are given (García et al. (2010) Sec. 4).
fn fr_spec(f: &FspccParams) -> FrSpec {
    FrSpec {
        tf: f.tf,
        lead: if f.lead > 0.0 && f.lag > 0.0 {
            Some((f.lead, f.lag))
        } else {
            None
        },
        biproper: true,
    }
}

pub fn build_fspcc<T: Real>(p: &Params, p1: &Tf, p2: &Tf, b: &Build) -> Built<T> {
    let c = cascade_parts(p, p1, p2, b)?;
    let f: FspccParams = p.typed()?;
    let pred = fsp_predictor(&c.gm, c.h, b, fr_spec(&f))?;
    let outer = Predicted::<T, _, _>::with_primary(c.km, pred, ParamList::of(&f.cast::<T>()));
    Ok(Box::new(Cascade::new(outer, c.imc, PREDICTED_SIGNALS)))
}

/// The cascade's outer model at `ts`, as the predictors see it (the primary
/// with the closed inner IMC loop), and its dead time in samples.
fn outer_model(
    p: &Params,
    p1: &TransferFunction,
    inner: Option<&Tf>,
    ts: f64,
) -> Result<CascadeParts<f64>, crate::error::Error> {
    let p2 = inner.ok_or(crate::error::Error::Unsupported(
        "a cascade scheme needs the secondary process",
    ))?;
    let b = Build::unlimited(ts);
    cascade_parts(p, p1, p2, &b)
}

/// FSPCC's `Fr` as García et al. (2010) print it (Example 1 at `Ts = 0.2`:
/// `kf = 14.95`, `ρ2 = 0.9957`).
pub fn describe_fspcc(p: &Params, p1: &Tf, inner: Option<&Tf>, ts: f64) -> Described {
    let c = outer_model(p, p1, inner, ts)?;
    let f: FspccParams = p.typed()?;
    let spec = fr_spec(&f);
    let design = dtc::fsp::design_with::<Vec<f64>, MAX_ORDER>(&c.gm, c.h, ts, &spec)?;
    super::fsp::fr_report(&design, &c.gm)
}

/// GPCC's filters (García et al. (2010) Sec. 3.2): `Γ`, `F2`, and `F1` by its
/// number of taps and its static gain.
pub fn describe_gpcc(p: &Params, p1: &Tf, inner: Option<&Tf>, ts: f64) -> Described {
    use super::DesignValue::{Filter, Scalar};
    let c = outer_model(p, p1, inner, ts)?;
    let f = dtc::gpcc::GpccFilters::design(&c.gm, c.h)?;
    #[allow(clippy::cast_precision_loss)] // a delay line's length
    let taps = c.h as f64;
    Ok(alloc::vec![
        (
            "gamma",
            Filter {
                num: f.gamma_num.as_slice().to_vec(),
                den: f.gamma_den.as_slice().to_vec(),
            },
        ),
        (
            "f2",
            Filter {
                num: f.f2_num.as_slice().to_vec(),
                den: f.f2_den.as_slice().to_vec(),
            },
        ),
        ("f1_taps", Scalar(taps)),
        ("f1_gain", Scalar(f.f1_taps(c.h).sum())),
    ])
}

pub fn tune_gpcc(p1: &Tf, p2: &Tf, d: &Design) -> Tuned {
    let (c, _, lambda) = cascade_primary_params(p1, p2, d)?;
    let p = GpccParams {
        tk: d.typed::<GpccTuning>().tk.unwrap_or(0.0),
        ..Default::default()
    };
    Ok(tuned(p, &c, lambda))
}

pub fn build_gpcc<T: Real>(p: &Params, p1: &Tf, p2: &Tf, b: &Build) -> Built<T> {
    let c = cascade_parts(p, p1, p2, b)?;
    let g: GpccParams = p.typed()?;
    let room = room_samples(b);
    let pred = GpccPredictor::<T, Vec<T>>::design_with_room(&c.gm, (c.h, room), b.ts, g.tk)?;
    let outer = Predicted::<T, _, _>::with_primary(c.km, pred, ParamList::of(&g.cast::<T>()));
    Ok(Box::new(Cascade::new(outer, c.imc, PREDICTED_SIGNALS)))
}

pub fn tune_uma(p1: &Tf, p2: &Tf, d: &Design) -> Tuned {
    // Gcd: Uma et al. tune it on a Padé approximation of the dead time, a rule
    // the sources do not give: its gains are left to --set (NaN until then)
    let (c, _, lambda) = cascade_primary_params(p1, p2, d)?;
    let t: UmaTuning = d.typed();
    let p = UmaParams {
        kpd: f64::NAN,
        kid: f64::NAN,
        kdd: f64::NAN,
        lead: t.lead.unwrap_or(0.0),
        lag: t.lag.unwrap_or(0.0),
        tf: t.tf.unwrap_or(0.0),
        ..Default::default()
    };
    Ok(tuned(p, &c, lambda))
}

pub fn build_uma<T: Real>(p: &Params, p1: &Tf, p2: &Tf, b: &Build) -> Built<T> {
    let c = cascade_parts(p, p1, p2, b)?;
    let u: UmaParams = p.typed()?;
    if [u.kpd, u.kid, u.kdd].iter().any(|v| v.is_nan()) {
        return Err(crate::error::Error::Unsupported(
            "uma: the disturbance controller Gcd has no tuning rule in the sources; set kpd, kid and kdd (and lead, lag) with --set",
        ));
    }
    // Gcd = (kpd + kid/s + kdd s)(lead s + 1)/(lag s + 1), pole-zero matched
    let (mut num, mut den) = if u.kid != 0.0 {
        (alloc::vec![u.kdd, u.kpd, u.kid], alloc::vec![1.0, 0.0])
    } else {
        (alloc::vec![u.kdd, u.kpd], alloc::vec![1.0])
    };
    num = crate::poly::mul(&num, &[u.lead, 1.0]);
    den = crate::poly::mul(&den, &[u.lag, 1.0]);
    let gcd = Lti::of(&Lti::<f64, AUX>::from_tf(
        &num,
        &den,
        b.ts,
        crate::lti::Discretization::Matched,
    )?);
    let err = if u.tf > 0.0 {
        ErrorPath::Filter(Lti::of(&Lti::<f64, AUX>::from_tf(
            &[1.0],
            &[u.tf, 1.0],
            b.ts,
            crate::lti::Discretization::Matched,
        )?))
    } else {
        ErrorPath::Direct
    };
    let delay = delay_again(&c.model, b)?;
    let outer = Compensator::new(
        Pid::new(c.k)?,
        Lti::of(&c.gm),
        delay,
        ParamList::of(&u.cast::<T>()),
    )?
    .with_error_path(err)?
    .with_disturbance(DisturbancePath::Block(gcd));
    Ok(Box::new(Cascade::new(outer, c.imc, COMPENSATOR_SIGNALS)))
}

pub fn tune_kaya_cascade(p1: &Tf, p2: &Tf, d: &Design) -> Tuned {
    let t: KayaCascadeTuning = d.typed();
    let lambda2 = lambda2_for(p2, t.lambda2)?;
    let gm = cascade::primary_model(p1, p2, lambda2)?;
    let (k, lambda) = kaya_atherton_settings(&gm, &t)?;
    let p = KayaCascadeParams {
        lambda2,
        ..Default::default()
    }
    .with_fields_of(&k);
    Ok(Params::of(&p).with_lambda(lambda))
}

pub fn build_kaya_cascade<T: Real>(p: &Params, p1: &Tf, p2: &Tf, b: &Build) -> Built<T> {
    let k: KayaCascadeParams<T> = p.typed()?;
    let (gm, imc) = cascade_inner(k.lambda2.f64(), p1, p2, b)?;
    let outer = kaya_atherton_on::<T, MAX_ORDER>(p, &gm, b)?.with_params(ParamList::of(&k));
    Ok(Box::new(Cascade::new(outer, imc, COMPENSATOR_SIGNALS)))
}

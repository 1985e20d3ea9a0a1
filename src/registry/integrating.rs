//! The predictors for integrating plants of Bag (2022), Sec. 4.4–4.5:
//! Karan–Dey, Watanabe–Ito, Åström–Hang–Lim, Matausek–Micić, Kaya–Atherton.

use alloc::boxed::Box;
use alloc::vec::Vec;

use super::common::*;
use super::{Build, Builders, Design, DynControllerOf, Params, Scheme, SchemeFns, MAX_ORDER};
use crate::delay::Delay;
use crate::dtc::{self, Compensator, KaranDeyParams};
use crate::poly::TransferFunction;
use crate::{tuning, Ipdt, ProcessModel, Real};
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

fn tune_karan_dey(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let m = integrating_model(plant, "the Karan-Dey MSP needs an integrating plant")?;
    let lambda = lambda_for(&m.into(), d, 0.25);
    let k = tuning::karan_dey(&m, lambda)?;
    Ok(params_of(
        KD_PARAMS,
        &[k.kp, k.ti, k.beta, k.gamma, k.td, k.n, lambda],
    ))
}

const KD_PARAMS: &[&str] = &["kp", "ti", "beta", "gamma", "td", "n", "lambda"];

fn build_karan_dey<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let params = KaranDeyParams {
        kp: req(p, "kp")?,
        ti: req(p, "ti")?,
        beta: req(p, "beta")?,
        gamma: req(p, "gamma")?,
        td: req(p, "td")?,
        n: req(p, "n")?,
    };
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    Ok(Box::new(
        dtc::karan_dey::build(&params, lti, delay, T::of(b.ts))?
            .with_limits(T::of(b.u_min), T::of(b.u_max))?,
    ))
}

fn tune_watanabe_ito(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    // The W-I loop is 1 + C·Kv/(s(1 + Ls)) (see dtc::watanabe_ito): SIMC PI for
    // an integrator with the lag L folded into the delay, τc = λ (default L/2).
    let m = integrating_model(
        plant,
        "the Watanabe-Ito predictor needs an integrating plant",
    )?;
    let lambda = lambda_for(&m.into(), d, 0.5);
    let s = lambda + m.l;
    Ok(params_of(
        WI_PARAMS,
        &[1.0 / (m.k * s), 4.0 * s, 0.0, lambda],
    ))
}

const WI_PARAMS: &[&str] = &["kp", "ti", "td", "lambda"];

fn build_watanabe_ito<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let m = integrating_model(
        model,
        "the Watanabe-Ito predictor needs an integrating plant",
    )?;
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let c = dtc::watanabe_ito::build(
        pid_cfg(p, b)?,
        T::of(m.k),
        T::of(m.l),
        lti,
        delay,
        list(WI_PARAMS, p),
    )?;
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

fn tune_astrom_hang_lim(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    // set point k/(s + k) with k = 1/λ (λ = L/4 by default); load loop
    // (1 + k1)s² + k2 s + k3 = (s + a)² with a = 1/L.
    let m = integrating_model(
        plant,
        "the Astrom-Hang-Lim predictor needs an integrating plant",
    )?;
    let lambda = lambda_for(&m.into(), d, 0.25);
    let a = d.get("a").unwrap_or(1.0 / m.l);
    Ok(params_of(
        AHL_PARAMS,
        &[1.0 / lambda, 0.0, 2.0 * a, a * a, lambda],
    ))
}

const AHL_PARAMS: &[&str] = &["k", "k1", "k2", "k3", "lambda"];

fn build_astrom_hang_lim<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let m = integrating_model(
        model,
        "the Astrom-Hang-Lim predictor needs an integrating plant",
    )?;
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let line = Delay::new_in(T::of(model.delay_samples(b.ts)?.floor()))?;
    let c = dtc::astrom_hang_lim::build(
        req(p, "k")?,
        req(p, "k1")?,
        req(p, "k2")?,
        req(p, "k3")?,
        T::of(m.k),
        T::of(b.ts),
        lti,
        delay,
        line,
        list(AHL_PARAMS, p),
    )?;
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

fn tune_matausek_micic(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let m = integrating_model(
        plant,
        "the Matausek-Micic predictor needs an integrating plant",
    )?;
    let tr = d
        .get("tr")
        .unwrap_or_else(|| lambda_for(&m.into(), d, 0.25));
    Ok(params_of(
        MM_PARAMS,
        &[1.0 / (m.k * tr), 0.5 / (m.k * m.l), tr],
    ))
}

const MM_PARAMS: &[&str] = &["kr", "k0", "tr"];

fn build_matausek_micic<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let c = dtc::matausek_micic::build(
        req(p, "kr")?,
        req(p, "k0")?,
        T::of(b.ts),
        lti,
        delay,
        list(MM_PARAMS, p),
    )?;
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

pub(super) fn tune_kaya_atherton(
    plant: &TransferFunction,
    d: &Design,
) -> Result<Params, crate::Error> {
    let m = match plant.reduce(false)? {
        // an integrator with a lag T acts at low frequency as K/s with T more dead time
        ProcessModel::Foipdt(f) => ProcessModel::Ipdt(Ipdt::new(f.k, f.l + f.t)?),
        other => other,
    };
    let values = match m {
        ProcessModel::Ipdt(i) => {
            // the Karan-Dey settings: Gc2 = beta·Kp (P), Gc3 from gamma·Kp with Td = λ
            let lambda = lambda_for(&m, d, 0.25);
            let k = tuning::karan_dey(&i, lambda)?;
            [k.kp, k.ti, k.beta * k.kp, 0.0, k.gamma * k.kp, k.td, lambda]
        }
        ProcessModel::Fopdt(_) | ProcessModel::Sopdt(_) => {
            // Kaya's PI on the model loop; a proportional Gc3 with loop gain 1/2,
            // stable for any dead time by the small-gain theorem
            let lambda = lambda_for(&m, d, 1.0);
            let g = tuning::kaya(&m, lambda)?;
            let k = plant.gain();
            [g.kp, g.ti, 0.0, 0.0, 0.5 / k, 0.0, lambda]
        }
        _ => {
            return Err(crate::Error::Unsupported(
                "the Kaya-Atherton predictor needs a stable or integrating plant",
            ))
        }
    };
    Ok(params_of(KA_PARAMS, &values))
}

pub(super) const KA_PARAMS: &[&str] = &["kp", "ti", "kf", "tf", "kb", "td", "lambda"];

/// Kaya–Atherton's predictor on `model`, reporting `names` (without limits).
pub(super) fn kaya_atherton_on<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
    names: &'static [&'static str],
) -> Result<Compensator<T, N, Vec<T>>, crate::Error> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    dtc::kaya_atherton::build(
        req(p, "kp")?,
        req(p, "ti")?,
        req(p, "kf")?,
        req(p, "tf")?,
        req(p, "kb")?,
        req(p, "td")?,
        T::of(b.ts),
        lti,
        delay,
        list(names, p),
    )
}

fn build_kaya_atherton<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let c = kaya_atherton_on::<T, N>(p, model, b, KA_PARAMS)?;
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

pub(super) const WATANABE_ITO: Scheme = Scheme {
    name: "watanabe-ito",
    aliases: &["wi"],
    summary: "Watanabe-Ito predictor for integrating plants: the predictor's static gain removed",
    source: "Bag (2022) Sec. 4.4.1",
    plants: INT,
    params: WI_PARAMS,
    design: &["lambda", "alpha"],
    fns: SchemeFns::Single {
        tune: tune_watanabe_ito,
        build: by_order!(build_watanabe_ito),
    },
};
pub(super) const ASTROM_HANG_LIM: Scheme = Scheme {
    name: "astrom-hang-lim",
    aliases: &["ahl"],
    summary:
        "Astrom-Hang-Lim predictor for integrating plants: set-point and load responses decoupled",
    source: "Bag (2022) Sec. 4.4.2, Eqs. 4.13-4.17",
    plants: INT,
    params: AHL_PARAMS,
    design: &["lambda", "alpha", "a"],
    fns: SchemeFns::Single {
        tune: tune_astrom_hang_lim,
        build: by_order!(build_astrom_hang_lim),
    },
};
pub(super) const MATAUSEK_MICIC: Scheme = Scheme {
    name: "matausek-micic",
    aliases: &["mm"],
    summary: "Matausek-Micic predictor for integrating plants: P set point, P load feedback",
    source: "Bag (2022) Sec. 4.4.3, refs [8], [52]",
    plants: INT,
    params: MM_PARAMS,
    design: &["lambda", "alpha", "tr"],
    fns: SchemeFns::Single {
        tune: tune_matausek_micic,
        build: by_order!(build_matausek_micic),
    },
};
pub(super) const KAYA_ATHERTON: Scheme = Scheme {
    name: "kaya-atherton",
    aliases: &["ka", "pi-pd"],
    summary: "Kaya-Atherton PI-PD Smith predictor: Gc1 PI, Gc2 P/PD, Gc3 = kb(Td s+1)/(0.1 Td s+1)",
    source: "Bag (2022) Sec. 4.4.3, Eq. 4.18",
    plants: STABLE_INT,
    params: KA_PARAMS,
    design: &["lambda", "alpha"],
    fns: SchemeFns::Single {
        tune: tune_kaya_atherton,
        build: by_order!(build_kaya_atherton),
    },
};
pub(super) const KARAN_DEY: Scheme = Scheme {
    name: "karan-dey",
    aliases: &["msp"],
    summary:
        "Karan-Dey three-controller modified Smith predictor for integrating plants (lambda = L/4)",
    source: "Bag (2022) Sec. 4.5",
    plants: INT,
    params: KD_PARAMS,
    design: &["lambda", "alpha"],
    fns: SchemeFns::Single {
        tune: tune_karan_dey,
        build: by_order!(build_karan_dey),
    },
};

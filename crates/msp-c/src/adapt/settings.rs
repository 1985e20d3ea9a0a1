//! The C settings of the identifier and of an adaptation, read into the
//! library's, and their defaults.

use super::*;

/// A sample count of C as an index.
pub(super) fn index(v: u32, name: &'static str) -> Result<usize, Error> {
    usize::try_from(v).map_err(|_| Error::DelayTooLong(name))
}

pub(super) fn estimator_config<T: Real>(
    c: &msp_estimator_config_of<T>,
) -> Result<EstimatorConfig<T>, Error> {
    let d_min = index(c.d_min, "d_min")?;
    let d_max = index(c.d_max, "d_max")?;
    if d_max < d_min || d_max - d_min >= N {
        return Err(Error::OutOfRange(
            "d_max: from d_min to d_min + 15 (16 candidates)",
        ));
    }
    let mut e = EstimatorConfig::new(c.ts, d_min);
    e.decimation = index(c.decimation, "decimation")?;
    e.d_max = Some(d_max);
    e.integrating = c.integrating != 0;
    e.forgetting = c.forgetting;
    e.set_prefilter_time(c.prefilter)?;
    e.min_excitation = c.excitation;
    e.validate()?;
    Ok(e)
}

pub(super) fn estimate_of<T: Real>(e: Option<Estimate<T>>) -> msp_estimate_of<T> {
    match e {
        Some(e) => msp_estimate_of {
            k: e.k,
            tau: e.tau,
            theta: e.theta,
            d: u32::try_from(e.d).unwrap_or(u32::MAX),
            evidence: e.evidence,
        },
        None => msp_estimate_of {
            k: T::nan(),
            tau: T::nan(),
            theta: T::nan(),
            d: 0,
            evidence: T::nan(),
        },
    }
}

/// `apply` with the FOPDT or IPDT `model`'s `(K, τ, θ)` on the estimator
/// behind `est`: its status.
///
/// # Safety
/// `est` is null or from `msp_estimator_init`; `model` null or valid.
pub(super) unsafe fn with_model<T: Real, E: Tagged>(
    est: *mut E,
    model: *const msp_model_of<T>,
    apply: impl FnOnce(&mut Bank<T>, T, T, T) -> Result<(), Error>,
) -> msp_status {
    // SAFETY: the caller's pointer, null-checked
    let Some(m) = (unsafe { read(model) }) else {
        return msp_status::MSP_NULL_POINTER;
    };
    // SAFETY: the caller's pointer, tag-checked
    let Some(b) = (unsafe { value::<_, Bank<T>>(est) }) else {
        return bad(est);
    };
    match fopdt_or_ipdt(&m).and_then(|(k, tau, theta)| apply(b, k, tau, theta)) {
        Ok(()) => msp_status::MSP_OK,
        Err(e) => e.into(),
    }
}

/// A model error for C (NaN before a whole response was compared).
pub(super) fn mismatch_of<T: Real>(m: Option<Mismatch<T>>) -> msp_mismatch_of<T> {
    msp_mismatch_of {
        error: m.map_or(T::nan(), |m| m.error),
        evidence: m.map_or(T::nan(), |m| m.evidence),
    }
}

/// The last of the 16 candidates from `d_min`.
pub(super) fn bank_end(d_min: u32) -> u32 {
    d_min.saturating_add(N as u32 - 1)
}

pub(super) fn estimator_default<T: Real>(
    ts: T,
    d_min: u32,
) -> Result<msp_estimator_config_of<T>, Error> {
    let e = EstimatorConfig::new(ts, 0);
    let c = msp_estimator_config_of {
        ts,
        decimation: 1,
        d_min,
        d_max: bank_end(d_min),
        integrating: 0,
        forgetting: e.forgetting,
        prefilter: T::zero(),
        excitation: e.min_excitation,
    };
    Bank::<T>::new(estimator_config(&c)?)?;
    Ok(c)
}

/// The model `(k, tau, theta)` of a C model (FOPDT or IPDT: `tau` infinite).
pub(super) fn fopdt_or_ipdt<T: Real>(m: &msp_model_of<T>) -> Result<(T, T, T), Error> {
    if m.kind == msp_model_kind::MSP_IPDT as u32 {
        Ok((m.k, T::infinity(), m.theta))
    } else if m.kind == msp_model_kind::MSP_FOPDT as u32 {
        Ok((m.k, m.tau, m.theta))
    } else {
        Err(Error::Unsupported("adaptation: a FOPDT or IPDT model"))
    }
}

/// The settings of `msp::adapt::Adaptive` for a scheme of the model `m`
/// sampled every `ts`.
pub(super) fn adaptive_config<T: Real>(
    c: &msp_adapt_config_of<T>,
    m: &msp_model_of<T>,
    ts: T,
) -> Result<AdaptiveConfig<T>, Error> {
    let (_, tau, _) = fopdt_or_ipdt(m)?;
    let est = estimator_config(&msp_estimator_config_of {
        ts,
        decimation: c.decimation,
        d_min: c.d_min,
        d_max: c.d_max,
        integrating: u32::from(tau.is_infinite()),
        forgetting: c.forgetting,
        prefilter: c.prefilter,
        excitation: c.excitation,
    })?;
    let mut a = AdaptiveConfig::new(est);
    a.min_change = c.min_change;
    a.bound = c.bound;
    a.alarm = c.alarm;
    a.band = c.band;
    a.apply = c.apply != 0;
    a.background_design = c.background_design != 0;
    a.validate()?;
    Ok(a)
}

/// The adaptation's defaults for a scheme of the model `m` whose dead time
/// is `d` samples at `ts`, as `msp run --adapt`'s: the estimator at about a
/// tenth of the dead time per sample, a whole number of its samples where
/// it can (`decimation`, `EstimatorConfig::decimation_for`), its 16 candidates from 6
/// of its samples below the model's dead time, plain differences (no
/// prefilter: a load's onset needs them).
pub(super) fn adapt_default<T: Real>(
    m: &msp_model_of<T>,
    d: T,
    ts: T,
) -> Result<msp_adapt_config_of<T>, Error> {
    let per = T::of(EstimatorConfig::<T>::decimation_for(d) as f64);
    let whole = |x: T| {
        x.to_f64()
            .filter(|x| x.is_finite() && *x >= 0.0 && *x < f64::from(u32::MAX))
            .ok_or(Error::DelayTooLong("dead time"))
    };
    // in range: checked by whole()
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let (decimation, d_min) = (
        whole(per)? as u32,
        whole(((d / per).floor() - T::of(6.0)).max(T::zero()))? as u32,
    );
    let e = EstimatorConfig::new(ts, 0);
    let a = AdaptiveConfig::new(e);
    let c = msp_adapt_config_of {
        decimation,
        d_min,
        d_max: bank_end(d_min),
        forgetting: e.forgetting,
        prefilter: T::zero(),
        excitation: e.min_excitation,
        min_change: a.min_change,
        bound: a.bound,
        alarm: a.alarm,
        band: a.band,
        apply: 1,
        lambda: T::zero(),
        background_design: u32::from(a.background_design),
    };
    adaptive_config(&c, m, ts)?;
    Ok(c)
}

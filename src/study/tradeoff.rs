//! The robustness–performance trade-off of every scheme for one plant: each
//! scheme's free tuning parameter `λ` swept, and per point the loop's
//! robustness (`Ms`, the delay margin) beside its performance (IAE of a unit
//! set-point step and of a unit input load, the control's total variation).

use std::string::{String, ToString};
use std::vec::Vec;

use super::{RunError, Scenario};
use crate::poly::TransferFunction;
use crate::sim::{Disturbance, SetpointStep};

/// One tuning of one scheme.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TradeoffPoint {
    /// The scheme.
    pub scheme: &'static str,
    /// Its `λ` (s).
    pub lambda: f64,
    /// The scheme's own tuning (the rule's `λ`).
    pub default: bool,
    /// The loop's verdict; the figures below are NaN unless it is stable.
    pub stable: Option<bool>,
    /// Sensitivity peak.
    pub ms: f64,
    /// Delay margin (s).
    pub dm: f64,
    /// IAE of a unit set-point step.
    pub iae_setpoint: f64,
    /// IAE of a unit step load at the plant input (set point 0); infinite
    /// where the load leaves an offset (the run's integral would only
    /// measure its length).
    pub iae_load: f64,
    /// The load is rejected: the output returns within 2 % of its peak
    /// deviation by the end of the run.
    pub load_rejected: Option<bool>,
    /// Total variation of the control in the set-point step.
    pub tv: f64,
}

/// The trade-off of the schemes for a plant (`msp tradeoff`, `msp.tradeoff`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Tradeoff {
    /// The plant.
    pub plant: String,
    /// The common sample period (s).
    pub ts: f64,
    /// The `λ` factors swept around each scheme's own.
    pub factors: Vec<f64>,
    /// Every point, scheme by scheme, `λ` increasing.
    pub points: Vec<TradeoffPoint>,
    /// Schemes for the plant left out, and why (no `λ`, a tuning that fails).
    pub skipped: Vec<(String, String)>,
}

/// The factors on each scheme's `λ`: `2^{k/2}`, `k = −6 … 6` (1/8 to 8).
pub fn tradeoff_factors() -> Vec<f64> {
    (-6..=6).map(|k| 2f64.powf(f64::from(k) / 2.0)).collect()
}

/// Sweeps every scheme in `schemes` (each must apply and have a `λ`: an
/// error names the one that does not; empty: every single-loop scheme for
/// the plant's kind whose tuning has a `λ`, the others listed in `skipped`) over `λ` = its own times
/// [`tradeoff_factors`], at one sample period, on the nominal plant; runs in
/// parallel with the `parallel` feature. `progress(done, total)` is called
/// after each point.
pub fn tradeoff(
    base: &Scenario,
    schemes: &[String],
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Tradeoff, RunError> {
    let (plant, model) = base.plant_and_model()?;
    if base.inner_plant.is_some() {
        return Err(RunError::Invalid(crate::error::Error::Unsupported(
            "the trade-off is for single loops (not a cascade process)",
        )));
    }
    let ts = base.ts.unwrap_or_else(|| super::choose_ts(&model));
    let names: Vec<String> = if schemes.is_empty() {
        crate::registry::SCHEMES
            .iter()
            .filter(|s| !s.is_cascade() && s.plants.contains(&model.kind()))
            .map(|s| s.name.to_string())
            .collect()
    } else {
        schemes.to_vec()
    };
    let factors = tradeoff_factors();
    let mut jobs: Vec<(Scenario, &'static str, f64, bool)> = Vec::new();
    let mut skipped = Vec::new();
    for name in &names {
        let mut sc = base.clone();
        sc.controller = Some(name.clone());
        sc.ts = Some(ts);
        sc.lambda = None;
        sc.target = None;
        // a scheme the user named must be swept: its failure is an error;
        // one of the default list that does not apply is left out, said in `skipped`
        let named = !schemes.is_empty();
        let tuned = match sc.tune_for(&model, None) {
            Ok(t) => t,
            Err(e) if named => return Err(e),
            Err(e) => {
                skipped.push((name.clone(), e.to_string()));
                continue;
            }
        };
        let Some(l0) = tuned.params.lambda().filter(|l| l.is_finite() && *l > 0.0) else {
            if named {
                return Err(RunError::Invalid(crate::error::Error::Unsupported(
                    "the trade-off sweeps a scheme's lambda, and this scheme's tuning has none",
                )));
            }
            skipped.push((
                name.clone(),
                "its tuning has no lambda to sweep".to_string(),
            ));
            continue;
        };
        for f in &factors {
            jobs.push((sc.clone(), tuned.scheme.name, l0 * f, *f == 1.0));
        }
    }
    let total = jobs.len();
    let done = core::sync::atomic::AtomicUsize::new(0);
    let one = |(sc, scheme, lambda, default): &(Scenario, &'static str, f64, bool)| {
        let p = point(sc, scheme, *lambda, *default, &plant, &model);
        progress(
            done.fetch_add(1, core::sync::atomic::Ordering::Relaxed) + 1,
            total,
        );
        p
    };
    let points = super::each(&jobs, one);
    Ok(Tradeoff {
        plant: plant.to_string(),
        ts,
        factors,
        points,
        skipped,
    })
}

/// One point: the loop tuned with `lambda`, its verdict and margins, and the
/// two runs.
fn point(
    sc: &Scenario,
    scheme: &'static str,
    lambda: f64,
    default: bool,
    plant: &TransferFunction,
    model: &TransferFunction,
) -> TradeoffPoint {
    let nan = f64::NAN;
    let mut out = TradeoffPoint {
        scheme,
        lambda,
        default,
        stable: None,
        ms: nan,
        dm: nan,
        iae_setpoint: nan,
        iae_load: nan,
        load_rejected: None,
        tv: nan,
    };
    let mut sc = sc.clone();
    sc.lambda = Some(lambda);
    let Ok(tuned) = sc.tune_for(model, None) else {
        return out;
    };
    let st = super::tuned_stability(&sc, &tuned, plant, model, None);
    out.stable = st.stable;
    if st.stable != Some(true) {
        return out;
    }
    if let Some(m) = sc.margins_of_tuned(&tuned, plant, model, 600) {
        out.ms = m.ms;
        out.dm = m.dm;
    }
    let mut step = sc.clone();
    step.setpoint = std::vec![SetpointStep {
        value: 1.0,
        at: 0.0
    }];
    step.disturbance.clear();
    if let Ok(r) = step.run_tuned(&tuned, plant.clone(), model.clone(), None) {
        out.iae_setpoint = r.metrics.indices.iae;
        out.tv = r.metrics.indices.tv;
        super::recycle(r.result);
    }
    let mut load = sc;
    load.setpoint = std::vec![SetpointStep {
        value: 0.0,
        at: 0.0
    }];
    load.disturbance = std::vec![Disturbance::input_step(1.0, 0.0)];
    if let Ok(r) = load.run_tuned(&tuned, plant.clone(), model.clone(), None) {
        let peak = r.result.y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let end = r.result.y.last().copied().unwrap_or(f64::NAN).abs();
        let rejected = end <= 0.02 * peak;
        out.load_rejected = Some(rejected);
        out.iae_load = if rejected {
            r.metrics.indices.iae
        } else {
            f64::INFINITY
        };
        super::recycle(r.result);
    }
    out
}

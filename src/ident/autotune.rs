//! Autotuning: the relay experiment on a plant, the model it identifies,
//! the controller tuned for it and the closed loop it makes (`msp autotune`).

use super::*;

/// Settings of `msp autotune`.
#[derive(Debug, Clone, PartialEq)]
pub struct AutotuneOptions {
    /// Relay amplitude.
    pub amplitude: f64,
    /// Hysteresis (default: three noise standard deviations).
    pub hysteresis: Option<f64>,
    /// Relay bias (default: 0 for integrating plants, 20 % of the amplitude otherwise).
    pub bias: Option<f64>,
    /// Measurement-noise standard deviation.
    pub noise: f64,
    /// Noise seed.
    pub seed: u64,
    /// Model to identify (default: IPDT for integrating plants, FOPDT otherwise).
    pub model: Option<ModelKind>,
    /// Controller to tune (default by the identified model's kind).
    pub controller: Option<String>,
    /// Sample period (default chosen from the plant).
    pub ts: Option<f64>,
    /// Safety band on the output.
    pub band: f64,
}

impl Default for AutotuneOptions {
    fn default() -> Self {
        AutotuneOptions {
            amplitude: 1.0,
            hysteresis: None,
            bias: None,
            noise: 0.0,
            seed: 0,
            model: None,
            controller: None,
            ts: None,
            band: f64::INFINITY,
        }
    }
}

/// What `msp autotune` found and did.
#[derive(Debug, Clone)]
pub struct AutotuneOutput {
    /// The relay's settings.
    pub relay: RelayConfig<f64>,
    /// The limit cycle.
    pub result: RelayResult<f64>,
    /// The identified model and its fit to the recorded cycles.
    pub fit: Fit,
    /// The closed loop of the tuned controller on the true plant.
    pub run: crate::study::RunOutput,
}

impl AutotuneOutput {
    /// What the relay experiment measured, as the reports give it.
    pub fn relay_report(&self) -> RelayReport {
        let (ku, tu) = self.result.ultimate();
        RelayReport {
            cycle: self.result,
            gain: self.result.gain(),
            ku,
            tu,
        }
    }
}

/// A relay experiment as `msp autotune --report` and Python's `autotune` give
/// it: the limit cycle's figures (Kaya (2003) Sec. 3.1), then the static gain
/// a biased relay gives, the describing function's ultimate gain `4h/(πa)`
/// and the ultimate period.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RelayReport {
    /// The limit cycle (its fields at the top level of the report).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub cycle: RelayResult<f64>,
    /// The static gain from a biased relay's means (`None` without a bias).
    pub gain: Option<f64>,
    /// The ultimate gain `Ku`.
    pub ku: f64,
    /// The ultimate period `Tu` (s).
    pub tu: f64,
}

/// Why autotuning failed.
#[derive(Debug)]
pub enum AutotuneError {
    /// The relay experiment stopped (the actuator is back at its initial value).
    Aborted(crate::autotune::RelayAbort),
    /// Identification failed.
    Ident(Error),
    /// Tuning or the closed loop failed.
    Run(crate::study::RunError),
}

impl core::fmt::Display for AutotuneError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            AutotuneError::Aborted(a) => write!(
                f,
                "relay experiment aborted: {a}; the actuator is back at its initial value"
            ),
            AutotuneError::Ident(e) => write!(f, "identification failed: {e}"),
            AutotuneError::Run(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for AutotuneError {}

/// Relay test on `plant`, identification, tuning, and the closed loop on `plant`.
pub fn autotune(
    plant: &TransferFunction,
    o: &AutotuneOptions,
    base: &crate::study::Scenario,
) -> Result<AutotuneOutput, AutotuneError> {
    let kind = plant.kind();
    // the candidate models: the one asked for, or the plain one and the one
    // with a lag, the lag kept where the relay data shows it; an unstable
    // process's, the unstable FOPDT
    let candidates: &[ModelKind] = match (o.model, kind) {
        (Some(ModelKind::Ipdt), _) => &[ModelKind::Ipdt],
        (Some(ModelKind::Foipdt), _) => &[ModelKind::Foipdt],
        (Some(ModelKind::Fopdt), _) => &[ModelKind::Fopdt],
        (Some(ModelKind::Sopdt), _) => &[ModelKind::Sopdt],
        (Some(ModelKind::Ufopdt), _) | (None, crate::poly::PlantKind::Unstable) => {
            &[ModelKind::Ufopdt]
        }
        (None, crate::poly::PlantKind::Integrating) => &[ModelKind::Ipdt, ModelKind::Foipdt],
        (None, _) => &[ModelKind::Fopdt, ModelKind::Sopdt],
    };
    let integrating_model = candidates
        .iter()
        .all(|k| matches!(k, ModelKind::Ipdt | ModelKind::Foipdt));
    let ts = o.ts.unwrap_or_else(|| crate::study::choose_ts(plant));
    // the relay acts against the process's direction: a reverse-acting
    // process (its output falls as its input rises) gets a negative amplitude
    let direction = match plant.kind() {
        crate::poly::PlantKind::Unstable => {
            plant.num.first().copied().unwrap_or(1.0) / plant.den.first().copied().unwrap_or(1.0)
        }
        _ => plant.gain(),
    };
    let amplitude = if direction < 0.0 {
        -o.amplitude.abs()
    } else {
        o.amplitude.abs()
    };
    let mut cfg = RelayConfig::new(amplitude, ts);
    let noise = crate::real::non_negative(o.noise, "noise").map_err(AutotuneError::Ident)?;
    if o.hysteresis.is_none() && !(3.0 * noise).is_finite() {
        return Err(AutotuneError::Ident(Error::OutOfRange("noise")));
    }
    cfg.hysteresis = o.hysteresis.unwrap_or(3.0 * noise);
    cfg.bias = match o.bias {
        // a given bias is relative to the relay's direction, as its amplitude
        Some(b) => b * amplitude.signum() * o.amplitude.signum(),
        None if integrating_model => 0.0,
        None => 0.2 * amplitude,
    };
    cfg.band = o.band;
    cfg.tolerance = if o.noise > 0.0 { 0.05 } else { 0.002 };
    let slow = plant
        .time_scales()
        .unwrap_or_default()
        .into_iter()
        .fold(plant.delay, f64::max);
    let budget = num_traits::ToPrimitive::to_u32(&(200.0 * slow / ts).clamp(1000.0, 2e7))
        .unwrap_or(20_000_000);
    cfg.max_samples = budget;
    // the experiment's plant line and its recorded samples, before they are allocated
    base.within_budget(
        (plant.delay / ts) * crate::study::PLANT_BYTES_PER_SAMPLE
            + f64::from(budget) * RELAY_BYTES_PER_SAMPLE,
        &std::format!(
            "a relay experiment of up to {budget} samples at ts = {} s",
            crate::poly::fmt_num(ts)
        ),
    )
    .map_err(AutotuneError::Run)?;
    let run = relay_experiment(plant, cfg, o.noise, o.seed).map_err(AutotuneError::Ident)?;
    let result = match run.state {
        RelayState::Done(r) => r,
        RelayState::Aborted(a) => return Err(AutotuneError::Aborted(a)),
        RelayState::Running => {
            return Err(AutotuneError::Aborted(crate::autotune::RelayAbort::Timeout))
        }
    };
    // each candidate fitted; a model with a lag only where it fits clearly
    // better (less than half the plain model's rms error)
    let mut fits = Vec::new();
    let mut last_err = None;
    for kind in candidates {
        // compared models are both fitted by least squares
        let refine = o.noise > 0.0 || candidates.len() > 1;
        match identify_relay(&run, &result, *kind, &cfg, refine) {
            Ok(f) if f.rmse.is_finite() => fits.push(f),
            Ok(_) => {}
            Err(e) => last_err = Some(e),
        }
    }
    let mut notes = Vec::new();
    let fit = match fits.as_slice() {
        [] => {
            return Err(AutotuneError::Ident(last_err.unwrap_or(Error::Numerical(
                "relay identification (no model fits the limit cycle)",
            ))))
        }
        [only] => *only,
        [plain, lag, ..] => {
            if lag.rmse < 0.5 * plain.rmse {
                notes.push(std::format!(
                    "the relay data shows a lag: {} fits with rms error {} against {}'s {}",
                    lag.model.kind(),
                    crate::poly::fmt_num(crate::poly::round_sig(lag.rmse, 3)),
                    plain.model.kind(),
                    crate::poly::fmt_num(crate::poly::round_sig(plain.rmse, 3))
                ));
                *lag
            } else {
                *plain
            }
        }
    };
    // the unstable plants' predictors take a dead time of whole samples:
    // the identified one to the nearest (within half a sample of the fit)
    let mut model = fit.model;
    if let ProcessModel::Ufopdt(u) = &mut model {
        let whole = (u.l / ts).round().max(1.0) * ts;
        if whole != u.l {
            notes.push(std::format!(
                "the identified dead time {} s is taken as {} s, a whole number of samples, for the predictor",
                crate::poly::fmt_num(crate::poly::round_sig(u.l, 6)),
                crate::poly::fmt_num(whole)
            ));
            u.l = whole;
        }
    }
    let mut sc = base.clone();
    sc.plant = Some(plant.clone());
    sc.model = Some(TransferFunction::from_model(&model));
    // the relay experiment saw the plant alone
    (sc.inner_plant, sc.inner_model) = (None, None);
    sc.controller = o.controller.clone().or(sc.controller);
    sc.ts = Some(ts);
    let mut out = sc.run().map_err(AutotuneError::Run)?;
    // the loop is checked on the process before it is handed over: unstable
    // or fragile (Ms > 2), λ is raised until it is neither
    let fragile = |o: &crate::study::RunOutput| {
        o.stability.stable == Some(false) || o.robustness.is_some_and(|m| !(m.ms <= 2.0))
    };
    if fragile(&out) {
        if let Some(l0) = out.params.lambda().filter(|l| l.is_finite() && *l > 0.0) {
            let was = match (out.stability.stable, out.robustness) {
                (Some(false), _) => String::from("unstable"),
                (_, Some(m)) => std::format!(
                    "fragile (Ms = {})",
                    crate::poly::fmt_num(crate::poly::round_sig(m.ms, 3))
                ),
                _ => String::from("fragile"),
            };
            let better = [1.5, 2.0, 3.0, 4.0, 6.0, 8.0].into_iter().find_map(|f| {
                let mut s2 = sc.clone();
                s2.lambda = Some(crate::poly::round_sig(l0 * f, 3));
                let o2 = s2.run().ok()?;
                (!fragile(&o2) && o2.stability.stable == Some(true)).then_some((s2.lambda, o2))
            });
            match better {
                Some((Some(l), o2)) => {
                    let ms = o2.robustness.map_or(f64::NAN, |m| m.ms);
                    out = o2;
                    notes.push(std::format!(
                        "the loop tuned at lambda = {} was {was} on the process: lambda raised to {} (Ms = {})",
                        crate::poly::fmt_num(crate::poly::round_sig(l0, 3)),
                        crate::poly::fmt_num(l),
                        crate::poly::fmt_num(crate::poly::round_sig(ms, 3))
                    ));
                }
                // a fragile loop's robustness warning already says what does better
                _ if out.stability.stable != Some(false) => {}
                _ => notes.push(std::format!(
                    "the loop tuned at lambda = {} is {was} on the process, and no lambda up to 8 times it does better: choose another controller or model",
                    crate::poly::fmt_num(crate::poly::round_sig(l0, 3))
                )),
            }
        }
    }
    out.notes.splice(0..0, notes);
    Ok(AutotuneOutput {
        relay: cfg,
        result,
        fit,
        run: out,
    })
}

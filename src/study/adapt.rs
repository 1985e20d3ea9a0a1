//! A scenario's adaptive dead-time compensation (`msp run --adapt`, Python
//! `run(..., adapt=True)`): the built scheme wrapped in
//! [`crate::adapt::Adaptive`], its primary retuned by the scheme's own
//! tuning rule (the scenario's λ policy) at each change.

use std::boxed::Box;

use super::{RunError, Scenario};
use crate::adapt::{Adaptive, AdaptiveConfig, EstimatorConfig};
use crate::poly::TransferFunction;
use crate::registry::DynController;
use crate::{error::Error, model::ProcessModel};

/// Candidate dead times the host's estimator compares.
pub const CANDIDATES: usize = 32;

/// The dead times searched by default, relative to the model's.
pub const DEFAULT_RANGE: (f64, f64) = (0.3, 3.0);

/// How a scenario adapts (every field optional: the defaults of
/// [`crate::adapt::AdaptiveConfig`] and [`EstimatorConfig`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct AdaptOptions {
    /// The dead times the estimator considers, `(min, max)` in seconds (at
    /// most [`CANDIDATES`] of the estimator's samples apart, a tenth of the
    /// model's dead time each); by default 0.3 to 3 times the model's.
    pub delay: Option<(f64, f64)>,
    /// The forgetting factor (default 0.999).
    pub forgetting: Option<f64>,
    /// The excitation gate: no learning unless the input moved this much
    /// within the history (default 1e-6; a move under a hundredth of the
    /// largest of late never counts, whatever this is).
    pub excitation: Option<f64>,
    /// The model changes when the gain or the time constant moves by this
    /// fraction (default 0.05).
    pub min_change: Option<f64>,
    /// The prefilter's time constant (s): the estimator sees `u` and `y`
    /// through `(1 − z⁻¹)/(1 − e^{−Ts/T}·z⁻¹)` at its period (default 0:
    /// plain differences of the block means, whose decimation has already
    /// averaged the noise; a load's onset is a pulse in them, which the
    /// estimator's onset handling assumes).
    pub prefilter: Option<f64>,
    /// Settled estimates become the model (default true); false: a
    /// model-error monitor only (`msp run --monitor`): the alarm is raised
    /// and cleared, the model stays.
    pub apply: Option<bool>,
    /// The dead zone in multiples of the measured noise (the estimator's
    /// RMS prediction error): errors within it do not update (default 0:
    /// off).
    pub dead_zone: Option<f64>,
    /// The estimates' gain and time constant stay within this factor of
    /// the commissioned model's (default 4; beyond it an estimate is
    /// warned of, never applied: [`crate::adapt::AdaptiveConfig::bound`]).
    pub bound: Option<f64>,
    /// The model error that raises the alarm (default 0.1: 10 %, with
    /// the monitor; giving it turns the monitor on).
    pub alarm: Option<f64>,
    /// A scheme rebuilt for each model (the Karan–Dey, the filtered Smith
    /// predictor) is designed between samples, as a device's background
    /// task would ([`crate::adapt::AdaptiveConfig::background_design`]):
    /// each new scheme a sample later (default false: in the update that
    /// applies its model).
    pub background_design: Option<bool>,
}

/// The scheme's own design for a model, at the scenario's λ policy: the
/// primary's gains (the Smith predictor, whose model changes at run time),
/// or the whole scheme built anew (the schemes whose other blocks are
/// designed from the model).
struct ScenarioRedesign {
    sc: Scenario,
}

impl crate::adapt::Redesign<f64, DynController> for ScenarioRedesign {
    fn gains(&mut self, k: f64, tau: f64, theta: f64) -> Option<[f64; 3]> {
        let tf = model_tf(k, tau, theta).ok()?;
        let tuned = self.sc.tune_for(&tf, None).ok()?;
        let p = &tuned.params;
        Some([
            p.get("kp")?,
            p.get("ti").unwrap_or(f64::INFINITY),
            p.get("td").unwrap_or(0.0),
        ])
    }

    /// The scheme for the model; one whose predictor holds whole samples of
    /// dead time (the filtered Smith predictor) for the model's dead time
    /// rounded to a sample (the estimate is not finer under noise).
    fn rebuild(&mut self, k: f64, tau: f64, theta: f64) -> Option<DynController> {
        let build = |theta: f64| -> Option<DynController> {
            let tf = model_tf(k, tau, theta).ok()?;
            let tuned = self.sc.tune_for(&tf, None).ok()?;
            Some(self.sc.build_tuned(&tuned, &tf, None).ok()?.controller)
        };
        build(theta).or_else(|| {
            let ts = self.sc.ts?;
            build((theta / ts).round() * ts)
        })
    }
}

/// `K/(τs + 1)` or `K/s` with the dead time `θ`: the model an estimate is.
fn model_tf(k: f64, tau: f64, theta: f64) -> Result<TransferFunction, Error> {
    if tau.is_infinite() {
        TransferFunction::new(&[k], &[1.0, 0.0], theta)
    } else {
        TransferFunction::new(&[k], &[tau, 1.0], theta)
    }
}

impl Scenario {
    /// The adaptation the scenario asks for: `adapt`'s, or with `monitor`
    /// alone a monitor that applies nothing.
    pub(super) fn adapt_options(&self) -> Option<AdaptOptions> {
        match (self.adapt, self.monitor) {
            (Some(a), _) => Some(a),
            (None, true) => Some(AdaptOptions {
                apply: Some(false),
                ..AdaptOptions::default()
            }),
            (None, false) => None,
        }
    }

    /// Controller samples per estimator sample: about a tenth of the model's
    /// dead time, a whole number of blocks where it can
    /// ([`EstimatorConfig::decimation_for`]; 1 when the dead time is under
    /// ten samples), so that the estimator works at the process's time
    /// scale whatever the controller's period.
    pub(super) fn adapt_decimation(model: &TransferFunction, ts: f64) -> usize {
        EstimatorConfig::<f64>::decimation_for(model.delay / ts)
    }

    /// The estimator's decimation, period (s) and its block's input's lag
    /// behind its output mean (s, [`EstimatorConfig::lag`]).
    pub(super) fn adapt_timing(model: &TransferFunction, ts: f64) -> (usize, f64, f64) {
        let decimation = Self::adapt_decimation(model, ts);
        let est = EstimatorConfig {
            decimation,
            ..EstimatorConfig::new(ts, 0)
        };
        (decimation, est.period(), est.lag())
    }

    /// The candidate dead times `(d_min, d_max)` in the estimator's samples
    /// (of `period` s, the first a block's input `lag` s behind its output)
    /// the scenario's adaptation considers: the range given in seconds, or
    /// 0.3 to 3 times the model's dead time.
    pub(super) fn adapt_range(
        &self,
        model: &TransferFunction,
        (period, lag): (f64, f64),
    ) -> Result<(f64, f64), RunError> {
        let (lo, hi) = match self.adapt_options().and_then(|a| a.delay) {
            Some((lo, hi)) => {
                crate::real::non_negative(lo, "adapt delay min")?;
                crate::real::finite(hi, "adapt delay max")?;
                if hi < lo {
                    return Err(RunError::Invalid(Error::OutOfRange(
                        "adapt delay: MIN..MAX with MIN <= MAX",
                    )));
                }
                (lo, hi)
            }
            None => {
                let (lo, hi) = DEFAULT_RANGE;
                let lo = ((lo * model.delay - lag).max(0.0) / period).floor();
                // a model without dead time still searches a few samples
                let hi = ((hi * model.delay - lag).max(0.0) / period)
                    .floor()
                    .max(lo + 3.0);
                return Ok((lo, hi.min(lo + (CANDIDATES - 1) as f64)));
            }
        };
        let whole = |t: f64| ((t - lag).max(0.0) / period).floor();
        Ok((whole(lo), whole(hi)))
    }

    /// `controller`, built for `model` with period `ts`, wrapped as the
    /// scenario's `adapt` asks (unchanged without it). The model must be a
    /// FOPDT or IPDT model; a scheme whose model changes at run time (the
    /// Smith predictor: [`crate::Operate::set_model`]) is retuned, any
    /// other rebuilt for each model ([`crate::adapt::Redesign`]). With it,
    /// a note where an option asked for has nothing to act on.
    pub(super) fn adaptive(
        &self,
        mut controller: DynController,
        model: &TransferFunction,
        ts: f64,
    ) -> Result<(DynController, Option<String>), RunError> {
        let Some(opts) = self.adapt_options() else {
            return Ok((controller, None));
        };
        let (k, tau, theta, integrating) = match model.exact_model() {
            Some(ProcessModel::Fopdt(m)) => (m.k, m.t, m.l, false),
            Some(ProcessModel::Ipdt(m)) => (m.k, f64::INFINITY, m.l, true),
            _ => {
                return Err(RunError::Invalid(Error::Unsupported(
                    "adaptation identifies a first-order-plus-dead-time or an integrator-plus-dead-time model: give the controller such a model (--model)",
                )))
            }
        };
        // a scheme that takes a new model at run time keeps its blocks (tried
        // with the one it has); the others are rebuilt for each model
        let in_place = match controller.set_model(k, tau) {
            Ok(()) => true,
            Err(Error::Unsupported(_)) => false,
            Err(e) => return Err(e.into()),
        };
        let note = (in_place && opts.background_design == Some(true)).then(|| {
            "--adapt-background (Python: adapt={\"background_design\": True}) has no effect on this scheme: its model changes in place within a sample's budget, and only a scheme rebuilt for each model (karan-dey, fsp) is designed in the background".into()
        });
        let (decimation, period, lag) = Self::adapt_timing(model, ts);
        // the model's dead time as the estimator counts it (its block's
        // input a block older: EstimatorConfig::lag)
        let d_model = ((theta - lag).max(0.0) / period).floor();
        let (d_min, d_max) = self.adapt_range(model, (period, lag))?;
        if d_max - d_min >= CANDIDATES as f64 {
            return Err(RunError::Limit(std::format!(
                "the adaptation's dead-time range spans {} of the estimator's samples ({} s each, a tenth of the model's dead time); it compares at most {CANDIDATES}: narrow --adapt-delay",
                d_max - d_min + 1.0,
                crate::poly::fmt_num(period)
            )));
        }
        if d_model < d_min || d_model > d_max {
            return Err(RunError::Invalid(Error::OutOfRange(
                "adapt delay: MIN..MAX around the model's dead time",
            )));
        }
        let whole = |d: f64| {
            num_traits::ToPrimitive::to_usize(&d)
                .ok_or(RunError::Invalid(Error::DelayTooLong("adapt delay")))
        };
        let d_min = whole(d_min)?;
        let mut est = EstimatorConfig::new(ts, d_min);
        est.decimation = decimation;
        // the candidates end at the range's end (the dead-time line has
        // room for no more)
        est.d_max = Some(whole(d_max)?);
        est.integrating = integrating;
        if let Some(f) = opts.forgetting {
            est.forgetting = f;
        }
        // by default plain differences of the block means: a prefilter's
        // pole would stretch an output load's pulse into a tail that no
        // model of the process explains (a load-biased estimate)
        if let Some(t) = opts.prefilter {
            est.set_prefilter_time(crate::real::non_negative(t, "adapt prefilter")?)?;
        }
        if let Some(z) = opts.dead_zone {
            est.dead_zone_ratio = crate::real::non_negative(z, "adapt dead zone")?;
        }
        if let Some(x) = opts.excitation {
            est.min_excitation = crate::real::non_negative(x, "adapt excitation")?;
        }
        let mut cfg = AdaptiveConfig::new(est);
        if let Some(m) = opts.min_change {
            cfg.min_change = crate::real::positive(m, "adapt min_change")?;
        }
        if let Some(b) = opts.bound {
            cfg.bound = crate::real::positive(b, "adapt bound")?;
        }
        if let Some(apply) = opts.apply {
            cfg.apply = apply;
        }
        cfg.background_design = opts.background_design.unwrap_or(false);
        // the alarm where the monitor is asked for
        cfg.alarm = match opts.alarm {
            Some(a) => crate::real::positive(a, "adapt alarm")?,
            None if self.monitor || opts.apply == Some(false) => cfg.alarm,
            None => f64::INFINITY,
        };
        // the error band of the oscillation detector: above the noise
        cfg.band = (3.0 * self.noise.unwrap_or(0.0)).max(
            0.02 * self
                .setpoint
                .iter()
                .fold(0.0f64, |m, s| m.max(s.value.abs())),
        );
        // the scheme's rule for the new model, at the scenario's λ policy (a
        // λ given stays; a rule's λ follows the model)
        let mut sc = self.clone();
        sc.adapt = None;
        sc.monitor = false;
        let retune = ScenarioRedesign { sc };
        let need = d_min + CANDIDATES + 2;
        // the history's length is a type parameter: the smallest of three that holds it
        macro_rules! with_history {
            ($h:literal) => {
                Box::new(Adaptive::<f64, _, _, CANDIDATES, $h>::new(
                    controller,
                    (k, tau, theta),
                    cfg,
                    retune,
                )?) as DynController
            };
        }
        let wrapped = match need {
            0..=64 => with_history!(64),
            65..=512 => with_history!(512),
            513..=4096 => with_history!(4096),
            _ => {
                return Err(RunError::Limit(std::format!(
                    "adaptation keeps up to 4094 samples of input history; the dead-time range reaches {need} samples at ts = {} s: raise --ts",
                    crate::poly::fmt_num(ts)
                )))
            }
        };
        Ok((wrapped, note))
    }
}

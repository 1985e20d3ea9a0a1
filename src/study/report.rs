//! The run report: one serde type that `msp run --report` writes and Python's
//! `run` returns (beside the signal arrays), so that both print the same keys.

use std::format;
use std::string::{String, ToString};
use std::vec::Vec;

use super::{Metrics, RunOutput, Scenario};
use crate::poly::TransferFunction;
use crate::registry::Params;

/// The controller of a report: the scheme's name and its parameters.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ControllerReport {
    /// The scheme's name.
    pub name: &'static str,
    /// Its tuned (and `--set`) parameters, by name.
    pub params: Params,
    /// How a PI/PID was tuned and what form it runs in (`null` for a
    /// scheme tuned by its source's own rule, which `source` names).
    pub tuning: Option<TuningReport>,
    /// The design target `λ` was solved for and what the loop reaches
    /// (`--target`; absent without one).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub target: Option<super::TargetReport>,
}

/// The tuning of a PI/PID scheme as a process engineer reads it: the rule
/// (with the ultimate gain and period an ultimate-cycle rule used), the form
/// of the controller, its derivative filter and set-point weights.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TuningReport {
    /// The rule: `imc`, `simc`, or an ultimate-cycle rule (`zn`, …).
    pub rule: &'static str,
    /// The ultimate gain an ultimate-cycle rule used.
    pub ku: Option<f64>,
    /// The ultimate period (s) an ultimate-cycle rule used.
    pub tu: Option<f64>,
    /// The form: `isa` (`Kp·(1 + 1/(Ti·s) + Td·s/(1 + Td·s/N))`).
    pub form: &'static str,
    /// The derivative filter ratio `N` (`Tf = Td/N`).
    pub n: f64,
    /// The proportional term's set-point weight.
    pub b: f64,
    /// The derivative term's set-point weight.
    pub c: f64,
}

impl ControllerReport {
    /// The report of scheme `name` with `params`.
    pub fn new(name: &'static str, params: Params) -> Self {
        // the filter and weights of PidConfig::isa, which the PI/PID schemes build
        let isa = crate::pid::PidConfig::<f64>::isa(1.0, 1.0, 1.0, 1.0);
        let tuning = params.rule().map(|r| TuningReport {
            rule: r.name,
            ku: r.ku,
            tu: r.tu,
            form: "isa",
            n: 1.0 / isa.tf,
            b: r.weights.map_or(isa.b, |w| w.0),
            c: r.weights.map_or(isa.c, |w| w.1),
        });
        ControllerReport {
            name,
            params,
            tuning,
            target: None,
        }
    }

    /// The same, with the design target its `λ` was solved for.
    pub fn with_target(mut self, target: Option<super::TargetReport>) -> Self {
        self.target = target;
        self
    }
}

/// The process of a loop as the reports print it (`msp run --report`,
/// `msp margins --json`, Python's `run` and `margins`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ProcessReport {
    /// The plant.
    pub plant: String,
    /// Its kind: stable, integrating or unstable.
    pub plant_kind: String,
    /// The controller's model.
    pub model: String,
    /// The secondary process of a cascade.
    pub inner_plant: Option<String>,
    /// The controller's model of the secondary process.
    pub inner_model: Option<String>,
    /// Sample period (s).
    pub ts: f64,
}

impl ProcessReport {
    /// The plant, the controller's model and a cascade's secondary process
    /// with its model, as expressions, sampled every `ts`.
    pub fn new(
        plant: &TransferFunction,
        model: &TransferFunction,
        inner: Option<&(TransferFunction, TransferFunction)>,
        ts: f64,
    ) -> Self {
        ProcessReport {
            plant: plant.to_string(),
            plant_kind: plant.kind().to_string(),
            model: model.to_string(),
            inner_plant: inner.map(|(p, _)| p.to_string()),
            inner_model: inner.map(|(_, m)| m.to_string()),
            ts,
        }
    }
}

/// An operator's event of a run and what it did to the controller's output.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct OperatorEventReport {
    /// When (s).
    pub at: f64,
    /// What.
    pub action: crate::sim::Action,
    /// `|u[k] − u[k−1]|` at the event's sample `k`: the jump of the
    /// controller's output the event caused (NaN past the run's end).
    pub output_change: f64,
}

/// A change the adaptation made during a run (`msp run --adapt`): the model
/// in use from `at` on; for a model-error alarm (`msp run --monitor` too),
/// the model the estimator sees instead.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct AdaptationReport {
    /// When (s).
    pub at: f64,
    /// What happened.
    pub kind: crate::adapt::ChangeKind,
    /// The model's gain `K`.
    pub k: f64,
    /// The model's time constant `τ` (s; infinite: integrating).
    pub tau: f64,
    /// The model's dead time `θ` (s).
    pub theta: f64,
    /// The model in use's error against the process then
    /// ([`crate::adapt::Mismatch::error`]; absent before the estimator had
    /// a model).
    pub mismatch: Option<f64>,
}

/// What a run did and how it performed.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Report {
    /// The version of msp that made the run.
    pub msp_version: &'static str,
    /// The scenario as it was given: `msp run --scenario report.json` (or
    /// `Scenario::run` on it) runs it again and gives this report again.
    pub scenario: super::Scenario,
    /// The process simulated.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub process: ProcessReport,
    /// The values msp chose because the run did not give them, of `ts`,
    /// `duration` and `lambda` (each can be given to repeat or change the run).
    pub chosen: Vec<&'static str>,
    /// Simulated time (s).
    pub duration: f64,
    /// Rows of the signals.
    pub samples: usize,
    /// The controller.
    pub controller: ControllerReport,
    /// The controller computed in `f32`.
    pub float32: bool,
    /// Metrics on `e = r − y`.
    pub metrics: Metrics,
    /// Metrics on `e = r(t − θm) − y`, time from `θm` (Bag (2022) ch. 5).
    pub metrics_delayed_reference: Metrics,
    /// The run is msp's default scenario (a unit set-point step, then an
    /// input load once it has settled; `events` says when and how large),
    /// chosen because the run named no set point, disturbance or duration.
    pub default_scenario: bool,
    /// Each set-point step's step information and each disturbance's
    /// rejection figures, over its segment (to the next event).
    pub events: Vec<super::Event>,
    /// The operator's events of the scenario (modes, dead-time changes), each
    /// with the change of the controller's output at the event's sample.
    pub operator_events: Vec<OperatorEventReport>,
    /// Every change of the model an adaptive run made (empty without
    /// adaptation).
    pub adaptation: Vec<AdaptationReport>,
    /// The adaptive controller's state at the end of the run (`--adapt` or
    /// `--monitor`; absent without adaptation): the estimate, the model in
    /// use, the estimator's counts (`learnt`: 0, nothing moved the loop
    /// enough to identify the process; `onsets`, `restarts`; `responses`
    /// and `responses_used`, the level test's), under the
    /// names the library, Python's `Controller.state` and C's
    /// `msp_adaptive_state` give them.
    pub adaptive: Option<crate::operate::AdaptiveState<f64>>,
    /// The designed quantities a paper prints beside the parameters (see
    /// [`TuneReport::design`]).
    #[cfg_attr(
        feature = "serde",
        serde(serialize_with = "crate::registry::serialize_design")
    )]
    pub design: crate::registry::DesignReport,
    /// The tuned loop's gain, phase and delay margins and sensitivity peaks
    /// (the loop broken at the plant input, the plant behind the hold).
    pub robustness: Option<crate::analysis::Margins>,
    /// The loop's verdict: `true` stable, `false` unstable, `null` when it
    /// could not be decided (`stability.reason` says why).
    pub stable: Option<bool>,
    /// The verdict from the characteristic equation, what decided it, and
    /// this run's cross-check.
    pub stability: crate::analysis::Stability,
    /// When the output diverged (s); the signals stop there.
    pub diverged_at: Option<f64>,
    /// What the user should know about the run.
    pub warnings: Vec<String>,
}

impl RunOutput {
    /// The report of this run.
    pub fn report(&self) -> Report {
        Report {
            msp_version: env!("CARGO_PKG_VERSION"),
            scenario: self.scenario.clone(),
            process: ProcessReport::new(&self.plant, &self.model, self.inner.as_ref(), self.ts),
            chosen: [
                ("ts", self.ts_chosen),
                ("duration", self.duration_chosen),
                ("lambda", self.lambda_chosen),
            ]
            .into_iter()
            .filter_map(|(k, c)| c.then_some(k))
            .collect(),
            duration: self.duration,
            samples: self.result.t.len(),
            controller: ControllerReport::new(self.controller, self.params.clone())
                .with_target(self.target.clone()),
            float32: self.float32,
            metrics: self.metrics,
            metrics_delayed_reference: self.metrics_delayed_reference,
            default_scenario: self.default_scenario,
            events: self.events.clone(),
            operator_events: self.operator_events(),
            adaptation: self.adaptation(),
            adaptive: self.result.adaptive,
            design: self.design.clone(),
            robustness: self.robustness,
            stable: self.stable(),
            stability: self.stability.clone(),
            diverged_at: self.result.diverged_at,
            warnings: self.warnings(),
        }
    }

    /// The scenario's operator events with the controller output's change at
    /// each event's sample.
    pub fn operator_events(&self) -> Vec<OperatorEventReport> {
        let m = self.result.substeps.max(1);
        let u = &self.result.u;
        self.scenario
            .events
            .iter()
            .map(|e| {
                let k = crate::sim::first_sample_at(e.at, self.ts);
                let at = |j: usize| u.get(j.saturating_mul(m)).copied();
                let change = match (k.checked_sub(1).and_then(at), at(k)) {
                    (Some(a), Some(b)) => (b - a).abs(),
                    _ => f64::NAN,
                };
                OperatorEventReport {
                    at: e.at,
                    action: e.action,
                    output_change: change,
                }
            })
            .collect()
    }

    /// The adaptation's log, read from the recorded signals: each sample at
    /// which `adapt_changes` grew, with the model in use from then on.
    pub fn adaptation(&self) -> Vec<AdaptationReport> {
        adaptation_log(&self.result)
    }

    /// The loop's verdict: the characteristic equation's, or where that is
    /// unknown and the output diverged, `false` (a divergence proves
    /// instability, a quiet run proves nothing).
    pub fn stable(&self) -> Option<bool> {
        match (self.stability.stable, self.result.diverged_at) {
            (Some(s), _) => Some(s),
            (None, Some(_)) => Some(false),
            (None, None) => None,
        }
    }

    /// Whether the output has come to rest: the step information has a
    /// settling time before the last tenth of the run, or (a loop that rests
    /// off its set point, e.g. P-only) the last tenth swings by less than
    /// 0.1 % of the largest |y|.
    pub fn has_settled(&self) -> bool {
        super::settled(&self.result.y, &self.metrics, self.duration)
    }

    /// Warnings about the run (an unstable loop, a run too short to settle).
    pub fn warnings(&self) -> Vec<String> {
        self.notes
            .iter()
            .cloned()
            .chain(self.result.diverged_at.map(|t| {
                format!(
                    "the closed loop with {} is unstable: the output diverged at t = {} s; the data and the metrics stop there (null where no sample is left)",
                    self.controller,
                    crate::poly::fmt_num(t)
                )
            }))
            .collect()
    }
}

/// What `msp tune --json` prints and Python's `tune` returns: the tuned
/// controller of a scenario, the margins of its loop and what they warn of.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TuneReport {
    /// The plant (or model) tuned for.
    pub plant: String,
    /// The secondary process of a cascade.
    pub inner_plant: Option<String>,
    /// The scheme and its parameters.
    pub controller: ControllerReport,
    /// Where the scheme comes from (publication and equations).
    pub source: &'static str,
    /// The values msp chose (`lambda` when no `--lambda` or `--set lambda=` gave it).
    pub chosen: Vec<&'static str>,
    /// The designed quantities a paper prints beside the parameters (FSP's
    /// and FSPCC's `Fr`: `kf`, `ρ`, `γ`, the poles it cancels; GPCC's `Γ`,
    /// `F2`, `F1`), at the sample period `ts`.
    #[cfg_attr(
        feature = "serde",
        serde(serialize_with = "crate::registry::serialize_design")
    )]
    pub design: crate::registry::DesignReport,
    /// The sample period the design is for (s).
    pub ts: f64,
    /// The loop's verdict on the plant (`null`: undecided, `stability` says why).
    pub stable: Option<bool>,
    /// The verdict from the characteristic equation and what decided it.
    pub stability: crate::analysis::Stability,
    /// The loop's margins and sensitivity peaks (single loops).
    pub robustness: Option<crate::analysis::Margins>,
    /// `max|T·Δ|` (García et al. (2010) Eq. 17) for the perturbation given.
    pub robust_peak: Option<f64>,
    /// `robust_peak < 1`.
    pub robustly_stable: Option<bool>,
    /// What the margins warn of.
    pub warnings: Vec<String>,
    /// The controller's transfer functions `Cr`, `Cy` and, for a single
    /// loop, the sampled plant and `L`, `S`, `T`, as coefficient lists
    /// (descending powers of `z`).
    pub transfer: Option<crate::analysis::Transfer>,
}

impl super::Scenario {
    /// Tunes the scenario's controller and reports it with its margins and,
    /// for an `uncertainty`, the robust-stability peak of Eq. 17 (discrete
    /// view, as the paper evaluates it).
    pub fn tune_report(
        &self,
        uncertainty: Option<super::Perturbation>,
    ) -> Result<TuneReport, super::RunError> {
        let (plant, model, inner, tuned, robust, stability) = self.tuned_loop()?;
        let (ts, _) = self.check_size(&model, inner.as_ref().map(|(_, m)| m))?;
        let design = tuned.scheme.design_report(
            &tuned.params,
            &model,
            inner.as_ref().map(|(_, m)| m),
            ts,
        )?;
        let robust_peak = match uncertainty {
            Some(u) => {
                let view = crate::analysis::View::Discrete;
                super::analyze_tuned(self, &tuned, view, Some(u))?.robust_peak
            }
            None => None,
        };
        let built = self.build_tuned(&tuned, &model, inner.as_ref().map(|(_, m)| m))?;
        let single = if inner.is_none() { Some(&plant) } else { None };
        let transfer = crate::analysis::transfer(&*built.controller, single, built.ts)?;
        Ok(TuneReport {
            plant: plant.to_string(),
            inner_plant: inner.as_ref().map(|(p, _)| p.to_string()),
            controller: ControllerReport::new(tuned.scheme.name, tuned.params.clone())
                .with_target(tuned.target.clone()),
            source: tuned.scheme.source,
            chosen: if tuned.lambda_chosen {
                std::vec!["lambda"]
            } else {
                Vec::new()
            },
            stable: stability.stable,
            robustness: robust.as_ref().map(|r| r.margins),
            warnings: {
                let mut w = robust.map(|r| r.warnings).unwrap_or_default();
                if stability.stable == Some(false) {
                    w.insert(
                        0,
                        std::format!("the closed loop is unstable: {}", stability.reason),
                    );
                }
                w
            },
            stability,
            design,
            ts,
            robust_peak,
            robustly_stable: robust_peak.map(|p| p < 1.0),
            transfer,
        })
    }
}

/// One tuning rule of `msp list` applied to the plant: what it gives and
/// the loop it makes ([`Scenario::rules_report`]).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RuleRow {
    /// The rule (`--rule`).
    pub rule: &'static str,
    /// The scheme it tunes: `pi` or `pid`.
    pub controller: &'static str,
    /// The scheme, its parameters and the rule's weights (absent when the
    /// rule does not apply to this plant: `error` says why).
    pub tuning: Option<ControllerReport>,
    /// The loop's verdict.
    pub stable: Option<bool>,
    /// The loop's margins and peaks (NaN for an unstable loop).
    pub robustness: Option<crate::analysis::Margins>,
    /// Why the rule gives no controller for this plant.
    pub error: Option<String>,
}

impl Scenario {
    /// Every tuning rule of the PI and PID schemes applied to the plant
    /// (IMC, SIMC, AMIGO and the ultimate-cycle rules of Bag (2022) Tables
    /// 3.2/3.3), with the robustness each one gives: `msp tune --rules`.
    pub fn rules_report(&self) -> Result<Vec<RuleRow>, super::RunError> {
        // the plant must be usable before every rule is tried on it
        self.plant_and_model()?;
        let mut rules: Vec<(&'static str, &'static str)> = std::vec![
            ("pid", "imc"),
            ("pid", "simc"),
            ("pid", "amigo"),
            ("pi", "simc"),
            ("pi", "amigo"),
        ];
        rules.extend(crate::tuning::PI_RULES.iter().map(|r| ("pi", r.name)));
        rules.extend(crate::tuning::PID_RULES.iter().map(|r| ("pid", r.name)));
        Ok(rules
            .into_iter()
            .map(|(controller, rule)| {
                let mut sc = self.clone();
                sc.controller = Some(controller.into());
                sc.rule = Some(rule.into());
                sc.lambda = self.lambda;
                match sc.tuned_loop() {
                    Ok((_, _, _, tuned, robust, stability)) => RuleRow {
                        rule,
                        controller,
                        tuning: Some(ControllerReport::new(tuned.scheme.name, tuned.params)),
                        stable: stability.stable,
                        robustness: robust.map(|r| r.margins),
                        error: None,
                    },
                    Err(e) => RuleRow {
                        rule,
                        controller,
                        tuning: None,
                        stable: None,
                        robustness: None,
                        error: Some(e.to_string()),
                    },
                }
            })
            .collect())
    }
}

/// The recorded signal `name` of a run (an adaptive controller's, see
/// [`crate::adapt::SIGNALS`]).
fn column<'a>(result: &'a crate::sim::SimResult, name: &str) -> Option<&'a [f64]> {
    result
        .signals
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| v.as_slice())
}

/// The adaptation's log of a run, read from its recorded signals: each
/// sample at which `adapt_changes` grew, with the model in use from then
/// on (the report's `adaptation`).
pub(crate) fn adaptation_log(result: &crate::sim::SimResult) -> Vec<AdaptationReport> {
    let col = |name: &str| column(result, name);
    let (Some(count), Some(kind), Some(k), Some(tau), Some(theta)) = (
        col("adapt_changes"),
        col("adapt_kind"),
        col("k_model"),
        col("tau_model"),
        col("theta_model"),
    ) else {
        return Vec::new();
    };
    let (k_hat, tau_hat, theta_hat, error) = (
        col("k_hat").unwrap_or(&[]),
        col("tau_hat").unwrap_or(&[]),
        col("theta_hat").unwrap_or(&[]),
        col("mismatch").unwrap_or(&[]),
    );
    let mut out = Vec::new();
    let mut last = 0.0;
    for (i, c) in count.iter().enumerate() {
        if *c > last {
            let get = |v: &[f64]| v.get(i).copied().unwrap_or(f64::NAN);
            let code = num_traits::ToPrimitive::to_u8(&get(kind)).unwrap_or(0);
            if let Some(kind) = crate::adapt::ChangeKind::from_code(code) {
                // an alarm and an edge warning name the process the
                // estimator sees
                let seen = matches!(
                    kind,
                    crate::adapt::ChangeKind::Alarm | crate::adapt::ChangeKind::Edge
                );
                let (k, tau, theta) = if seen {
                    (k_hat, tau_hat, theta_hat)
                } else {
                    (k, tau, theta)
                };
                out.push(AdaptationReport {
                    at: result.t.get(i).copied().unwrap_or(f64::NAN),
                    kind,
                    k: get(k),
                    tau: get(tau),
                    theta: get(theta),
                    mismatch: Some(get(error)).filter(|e| e.is_finite()),
                });
            }
            last = *c;
        }
    }
    out
}

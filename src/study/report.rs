//! The run report: one serde type that `msp run --report` writes and Python's
//! `run` returns (beside the signal arrays), so that both print the same keys.

use std::format;
use std::string::{String, ToString};
use std::vec::Vec;

use super::{Metrics, RunOutput};
use crate::registry::Params;

/// The controller of a report: the scheme's name and its parameters.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ControllerReport {
    /// The scheme's name.
    pub name: &'static str,
    /// Its tuned (and `--set`) parameters, by name.
    pub params: Params,
}

/// What a run did and how it performed.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Report {
    /// The plant simulated.
    pub plant: String,
    /// Its kind: stable, integrating or unstable.
    pub plant_kind: String,
    /// The controller's model.
    pub model: String,
    /// The secondary process of a cascade.
    pub inner_plant: Option<String>,
    /// The model of the secondary process.
    pub inner_model: Option<String>,
    /// Sample period (s).
    pub ts: f64,
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
    /// False when the output diverged.
    pub stable: bool,
    /// When the output diverged (s); the signals stop there.
    pub diverged_at: Option<f64>,
    /// What the user should know about the run.
    pub warnings: Vec<String>,
}

impl RunOutput {
    /// The report of this run.
    pub fn report(&self) -> Report {
        Report {
            plant: self.plant.to_string(),
            plant_kind: self.plant.kind().to_string(),
            model: self.model.to_string(),
            inner_plant: self.inner.as_ref().map(|(p, _)| p.to_string()),
            inner_model: self.inner.as_ref().map(|(_, m)| m.to_string()),
            ts: self.ts,
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
            controller: ControllerReport {
                name: self.controller,
                params: self.params.clone(),
            },
            float32: self.float32,
            metrics: self.metrics,
            metrics_delayed_reference: self.metrics_delayed_reference,
            stable: self.result.diverged_at.is_none(),
            diverged_at: self.result.diverged_at,
            warnings: self.warnings(),
        }
    }

    /// Whether the output has come to rest: the step information has a
    /// settling time before the last tenth of the run, or (a loop that rests
    /// off its set point, e.g. P-only) the last tenth swings by less than
    /// 0.1 % of the largest |y|.
    pub fn has_settled(&self) -> bool {
        let y = &self.result.y;
        let n = y.len();
        if self.metrics.step.settling_time <= 0.9 * self.duration {
            return true;
        }
        let tail = y.get(n - n / 10..).unwrap_or(&[]);
        let swing = tail.iter().fold(f64::MIN, |m, v| m.max(*v))
            - tail.iter().fold(f64::MAX, |m, v| m.min(*v));
        let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-12);
        n >= 10 && swing <= 1e-3 * scale
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

//! What a scenario's run gives: the result, the metrics, the events, the
//! design and the loop's analysis ([`RunOutput`]).

use super::*;

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunOutput {
    /// The plant.
    pub plant: TransferFunction,
    /// The controller's model.
    pub model: TransferFunction,
    /// Cascade processes: the secondary process and its model.
    pub inner: Option<(TransferFunction, TransferFunction)>,
    /// Sample period used.
    pub ts: f64,
    /// Whether `ts` was chosen automatically.
    pub ts_chosen: bool,
    /// Duration used.
    pub duration: f64,
    /// Whether the duration was chosen automatically.
    pub duration_chosen: bool,
    /// The figures of each set-point step and disturbance over its segment.
    pub events: Vec<metrics::Event>,
    /// The run is the default scenario ([`Scenario::run`]: a set-point step,
    /// then a load once it has settled), not one the user named.
    pub default_scenario: bool,
    /// The scenario as it was given (what msp chose is `None` or empty in
    /// it, and the run's own fields say what was chosen): run again, it gives
    /// this run again.
    pub scenario: Scenario,
    /// What the run found that the user should know, beside an instability
    /// (part of [`RunOutput::warnings`]).
    pub notes: Vec<String>,
    /// The designed quantities a paper prints beside the parameters
    /// ([`registry::Scheme::design_report`]), for a run by [`Scenario::run`].
    pub design: registry::DesignReport,
    /// The tuned loop's margins (sampled view), for a single loop run by
    /// [`Scenario::run`].
    pub robustness: Option<crate::analysis::Margins>,
    /// The loop's stability verdict ([`crate::analysis::stability`]),
    /// cross-checked by this run, for a run by [`Scenario::run`].
    pub stability: crate::analysis::Stability,
    /// Whether the tuning's `lambda` was chosen automatically.
    pub lambda_chosen: bool,
    /// The design target the tuning's `lambda` was solved for, and what the
    /// loop reaches.
    pub target: Option<TargetReport>,
    /// Controller name.
    pub controller: &'static str,
    /// Its parameters.
    pub params: Params,
    /// The signals.
    pub result: SimResult,
    /// Metrics on `e = r − y`.
    pub metrics: Metrics,
    /// Metrics on `e = r(t − θm) − y`, time from `θm`.
    pub metrics_delayed_reference: Metrics,
    /// The set-point profile used.
    pub setpoint: Vec<SetpointStep>,
    /// The disturbances used.
    pub disturbance: Vec<crate::sim::Disturbance>,
    /// The controller computed in `f32` ([`Scenario::float32`]).
    pub float32: bool,
    /// When the loop first stopped being the one built and analysed (s),
    /// and what changed it: a process drift, the controller's dead time or
    /// gains, the first model the adaptation applied (`None`: the loop ran
    /// as built to the end).
    pub loop_change: Option<(f64, &'static str)>,
}

impl RunOutput {
    /// Computes the metrics and the event figures of the run from its
    /// signals (a run of [`Scenario::run_unmeasured`]; for any other run
    /// they are computed already and come out the same).
    pub fn measure(&mut self) -> Result<(), RunError> {
        let figures = self.figures(&self.result.columns())?;
        self.set_figures(figures);
        Ok(())
    }

    /// [`RunOutput::measure`] from columns held elsewhere (the arrays a
    /// run's signals were handed to).
    pub fn measure_from(&mut self, cols: &Columns<'_>) -> Result<(), RunError> {
        let figures = self.figures(cols)?;
        self.set_figures(figures);
        Ok(())
    }

    fn figures(&self, cols: &Columns<'_>) -> Result<(Metrics, Metrics, Vec<Event>), RunError> {
        Ok(measure(
            cols,
            &self.setpoint,
            &self.disturbance,
            self.ts,
            self.model_delay(),
        )?)
    }

    fn set_figures(&mut self, (m0, m1, events): (Metrics, Metrics, Vec<Event>)) {
        self.metrics = m0;
        self.metrics_delayed_reference = m1;
        self.events = events;
    }

    /// Whether the run came to rest and did not diverge, its output `y`
    /// (its own column, or the array it was handed to): what the stability
    /// verdict is cross-checked with. Reads the measured figures.
    pub fn settled_with(&self, y: &[f64]) -> bool {
        self.result.diverged_at.is_none() && settled(y, &self.metrics, self.duration)
    }

    /// Adds the loop's analysis to a run of [`Scenario::run_unanalysed`]
    /// (or of [`Scenario::run_unmeasured`], measured first here): the
    /// stability verdict cross-checked by this run, and the robustness
    /// figures with what they warn of. Reads the signals (has the run come
    /// to rest?); [`RunOutput::analyse_settled`] takes that answer instead.
    pub fn analyse(&mut self) -> Result<(), RunError> {
        if self.metrics.indices.iae.is_nan() && self.result.diverged_at.is_none() {
            self.measure()?;
        }
        self.analyse_settled(self.settled_as_built(&self.result.t, &self.result.y));
        Ok(())
    }

    /// Whether the loop as built came to rest in the output `y` at the
    /// times `t` (the run's signals): over the run, or when the loop
    /// changes ([`RunOutput::loop_change`]) up to the change (`None`: too
    /// short a stretch before it to have come to rest in).
    pub fn settled_as_built(&self, t: &[f64], y: &[f64]) -> Option<bool> {
        match self.loop_change {
            Some((at, _)) => {
                let rows = t.iter().take_while(|t| **t < at).count();
                (rows >= 10).then(|| {
                    self.result.diverged_at.map_or(true, |d| d >= at)
                        && settled(y.get(..rows).unwrap_or(y), &self.metrics, at)
                })
            }
            None => Some(self.settled_with(y)),
        }
    }

    /// The verdict of the loop as built cross-checked by this run (`settled`:
    /// [`RunOutput::settled_as_built`]).
    pub(crate) fn cross_checked(
        &self,
        stability: crate::analysis::Stability,
        settled: Option<bool>,
    ) -> crate::analysis::Stability {
        match (self.loop_change, settled) {
            (Some((at, what)), _) => stability.as_built(settled, at, what),
            (None, Some(settled)) => stability.with_simulation(settled, self.duration),
            (None, None) => stability,
        }
    }

    /// When the loop first stops being the one built (and analysed): a
    /// process drift (`plant-gain`, `plant-lag`, `plant-dead-time`), the
    /// controller's dead time or gains changed by an event, or the first
    /// model the adaptation applied. Modes (manual, tracking) do not change
    /// the loop that returns.
    pub(super) fn find_loop_change(
        events: &[crate::sim::Operation],
        result: &SimResult,
    ) -> Option<(f64, &'static str)> {
        use crate::sim::Action;
        let event = events
            .iter()
            .filter_map(|e| {
                let what = match e.action {
                    Action::PlantGain(_)
                    | Action::PlantLag(_)
                    | Action::PlantDeadTime(_)
                    | Action::PlantDrift(..) => "the process drifts",
                    Action::DeadTime(_) | Action::DeadTimeRamp(..) => {
                        "the controller's dead time changes"
                    }
                    Action::Retune(..) => "the controller is retuned",
                    Action::Manual(_) | Action::Track(_) | Action::Auto | Action::Adapt(_) => {
                        return None
                    }
                };
                Some((e.at, what))
            })
            .fold(None, |first: Option<(f64, &str)>, e| match first {
                Some(f) if f.0 <= e.0 => Some(f),
                _ => Some(e),
            });
        // the adaptation's log: the first model it put in (an alarm or a
        // refusal leaves the loop as it is)
        let adapted = report::adaptation_log(result)
            .into_iter()
            .find(|c| {
                matches!(
                    c.kind,
                    crate::adapt::ChangeKind::Applied | crate::adapt::ChangeKind::Restored
                )
            })
            .map(|c| (c.at, "the adaptation applies a model"));
        match (event, adapted) {
            (Some(e), Some(a)) => Some(if a.0 < e.0 { a } else { e }),
            (e, a) => e.or(a),
        }
    }

    /// The tuned controller this run ran (its scheme, parameters and how
    /// `λ` was found): built again with [`Scenario::build_tuned`] it is the
    /// run's controller, without tuning it again.
    pub fn tuned(&self) -> Result<Tuned, RegistryError> {
        Ok(Tuned {
            scheme: registry::find(self.controller)?,
            params: self.params.clone(),
            lambda_chosen: self.lambda_chosen,
            target: self.target.clone(),
        })
    }

    /// [`RunOutput::analyse`] with `settled` (the loop as built came to
    /// rest and did not diverge: [`RunOutput::settled_as_built`]; `None`: no
    /// simulation to compare) given: the signals are not read.
    pub fn analyse_settled(&mut self, settled: Option<bool>) {
        let tuned = match self.tuned() {
            Ok(t) => t,
            Err(e) => {
                self.stability = crate::analysis::Stability::unknown(e.to_string());
                return;
            }
        };
        let (stability, robust) = self.scenario.loop_analysis(
            &tuned,
            &self.plant,
            &self.model,
            self.inner.as_ref(),
            super::Advice::Priced,
        );
        self.apply_analysis(stability, robust, settled);
    }

    /// The loop's verdict and robustness into the run, the verdict
    /// cross-checked by it (`settled`), and what they warn of into its notes.
    pub(super) fn apply_analysis(
        &mut self,
        stability: crate::analysis::Stability,
        robust: Option<Robustness>,
        settled: Option<bool>,
    ) {
        if let Some(r) = robust {
            self.notes.extend(r.warnings);
            if let (Some((at, what)), true) = (
                self.loop_change,
                r.margins.gm.is_finite() || r.margins.pm.is_finite(),
            ) {
                self.notes.push(std::format!(
                    "the robustness margins are the loop's as built: at {} s {what}, and they do not cover the loop after that",
                    crate::poly::fmt_num(crate::poly::round_sig(at, 3))
                ));
            }
            self.robustness = Some(r.margins);
        }
        self.stability = self.cross_checked(stability, settled);
        if self.stability.stable == Some(false) && self.result.diverged_at.is_none() {
            self.notes.push(std::format!(
                "the closed loop with {} is unstable: {}",
                self.controller,
                self.stability.reason
            ));
        }
    }

    /// The controller's dead time: the model's, plus the secondary model's for
    /// a cascade process (the delay of the delayed-reference metrics).
    pub fn model_delay(&self) -> f64 {
        self.model.delay + self.inner.as_ref().map_or(0.0, |(_, m)| m.delay)
    }
    /// The whole model from the plant input: `model`, or `model·inner model`.
    pub fn whole_model(&self) -> TransferFunction {
        match &self.inner {
            Some((_, m2)) => self.model.series(m2).unwrap_or_else(|_| self.model.clone()),
            None => self.model.clone(),
        }
    }
}

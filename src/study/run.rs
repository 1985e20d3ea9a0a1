//! Running a scenario: tuned, built, simulated, measured and analysed,
//! by itself or as the default protocol (a set-point step, then a load).

use super::*;

/// The loop a tuned run simulates: the plant, the model its controllers
/// were designed for, and a cascade's inner plant and model.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plants<'a> {
    pub(crate) plant: &'a TransferFunction,
    pub(crate) model: &'a TransferFunction,
    pub(crate) inner: Option<&'a (TransferFunction, TransferFunction)>,
}

impl Scenario {
    /// Tunes, builds and simulates; the output carries the tuned loop's
    /// robustness ([`Scenario::robustness`]).
    pub fn run(&self) -> Result<RunOutput, RunError> {
        self.run_deferring(true, Some(Advice::Priced))
    }

    /// [`Scenario::run`] as a draft: the same tuning, signals, metrics,
    /// verdict and margins, and a robustness warning that says what is
    /// wrong without the search for a better tuning and its price (the
    /// retunings and the four runs behind `--lambda … gives …, at a price`):
    /// for an interactive front end while a slider moves (the browser tuner
    /// runs [`Scenario::run`] when the slider is let go).
    pub fn run_draft(&self) -> Result<RunOutput, RunError> {
        self.run_deferring(true, Some(Advice::Omitted))
    }

    /// [`Scenario::run`] without the loop's analysis: the simulation, its
    /// metrics and the design, but no stability verdict and no robustness
    /// figures (`stability` says they were not computed, `robustness` is
    /// `None`) — for a caller that reads them later, or never
    /// ([`RunOutput::analyse`] adds them, as `run` would have).
    pub fn run_unanalysed(&self) -> Result<RunOutput, RunError> {
        self.run_deferring(true, None)
    }

    /// [`Scenario::run_unanalysed`] that also leaves the metrics and the
    /// event figures of a run of a given duration for later
    /// ([`RunOutput::measure`]): the simulation and the design only, the
    /// figures NaN and `events` empty until measured. What Python's
    /// `msp.run` computes before it returns.
    pub fn run_unmeasured(&self) -> Result<RunOutput, RunError> {
        self.run_deferring(false, None)
    }

    pub(super) fn run_deferring(
        &self,
        measure: bool,
        analyse: Option<Advice>,
    ) -> Result<RunOutput, RunError> {
        let (plant, model) = self.plant_and_model()?;
        let inner = self.inner_process()?;
        let tuned = self.tune_for(&model, inner.as_ref().map(|(_, m)| m))?;
        // the analysis before the simulation: its own runs (the advice's
        // priced alternatives) do not need memory beside the recorded columns
        let analysis =
            analyse.map(|a| self.loop_analysis(&tuned, &plant, &model, inner.as_ref(), a));
        let mut out =
            if self.setpoint.is_empty() && self.disturbance.is_empty() && self.duration.is_none() {
                self.run_default_protocol(&tuned, &plant, &model, &inner)?
            } else {
                self.run_tuned_measured(
                    &tuned,
                    Plants {
                        plant: &plant,
                        model: &model,
                        inner: inner.as_ref(),
                    },
                    if measure {
                        Keep::Measured
                    } else {
                        Keep::Signals
                    },
                )?
            };
        out.scenario = self.clone();
        out.design = tuned.scheme.design_report(
            &out.params,
            &out.model,
            out.inner.as_ref().map(|(_, m)| m),
            out.ts,
        )?;
        out.stability = crate::analysis::Stability::unknown("not analysed");
        if let Some((stability, robust)) = analysis {
            let settled = out.settled_as_built(&out.result.t, &out.result.y);
            out.apply_analysis(stability, robust, settled);
        }
        Ok(out)
    }

    /// The tuned loop's stability verdict and, for a single loop, its
    /// robustness (margins and what they warn of).
    pub(crate) fn loop_analysis(
        &self,
        tuned: &Tuned,
        plant: &TransferFunction,
        model: &TransferFunction,
        inner: Option<&(TransferFunction, TransferFunction)>,
        advice: Advice,
    ) -> (crate::analysis::Stability, Option<Robustness>) {
        let stability = super::tuned_stability(self, tuned, plant, model, inner);
        let robust = match (inner, stability.stable) {
            // an unstable loop has no margins: the verdict says why
            (None, Some(false)) => Some(Robustness {
                margins: crate::analysis::Margins::unstable(),
                warnings: Vec::new(),
            }),
            (None, _) => self.robustness_advising(tuned, plant, model, advice),
            (Some(_), _) => None,
        };
        (stability, robust)
    }

    /// The processes, the tuned controller and, for a single loop, its
    /// robustness: what [`Scenario::run`] and [`Scenario::tune_report`] start from.
    #[allow(clippy::type_complexity)]
    pub(crate) fn tuned_loop(
        &self,
    ) -> Result<
        (
            TransferFunction,
            TransferFunction,
            Option<(TransferFunction, TransferFunction)>,
            Tuned,
            Option<Robustness>,
            crate::analysis::Stability,
        ),
        RunError,
    > {
        let (plant, model) = self.plant_and_model()?;
        let inner = self.inner_process()?;
        let tuned = self.tune_for(&model, inner.as_ref().map(|(_, m)| m))?;
        let (stability, robust) =
            self.loop_analysis(&tuned, &plant, &model, inner.as_ref(), Advice::Priced);
        Ok((plant, model, inner, tuned, robust, stability))
    }

    /// The default scenario of a run that names no set point, disturbance or
    /// duration, the protocol of Bag (2022) ch. 5: a unit set-point step at
    /// 0 s, then, once its response has settled, a step load at the plant
    /// input (`−0.2/K` for a plant of gain `K`, a fifth of the step at the
    /// output in steady state; `−0.02/Kv` for an integrator `Kv/s`, the
    /// thesis's −0.1 on `0.2/s`), and a duration that ends soon after the
    /// load is rejected.
    /// The load comes at a round time after 1.25 settling times, the run ends
    /// at a round time after 1.25 recovery times (each found from a probe
    /// run); a loop that does not settle runs as the plain set-point step.
    pub(super) fn run_default_protocol(
        &self,
        tuned: &Tuned,
        plant: &TransferFunction,
        model: &TransferFunction,
        inner: &Option<(TransferFunction, TransferFunction)>,
    ) -> Result<RunOutput, RunError> {
        let mut sc = self.clone();
        sc.setpoint = std::vec![SetpointStep {
            value: 1.0,
            at: 0.0
        }];
        let run = |sc: &Scenario| sc.run_tuned(tuned, plant.clone(), model.clone(), inner.clone());
        let first = run(&sc)?;
        let settle = first.metrics.step.settling_time;
        let whole = match inner {
            Some((p2, _)) => plant.series(p2)?,
            None => plant.clone(),
        };
        let Some(load) = default_load(&whole) else {
            return Ok(first);
        };
        if first.result.diverged_at.is_some() || !settle.is_finite() {
            return Ok(first);
        }
        let at = nice_ceil(1.25 * settle.max(first.ts));
        // operator events of the scenario stay inside every run of the
        // protocol: the first run's chosen duration covers the last of them
        let cover = |d: f64| {
            if self.events.is_empty() {
                d
            } else {
                d.max(first.duration)
            }
        };
        sc.disturbance = std::vec![crate::sim::Disturbance::input_step(load, at)];
        // probes: the load's segment as long as the set point needed, doubled
        // until the load is rejected
        let mut span = first.duration.max(2.0 * settle);
        let mut recovery = f64::NAN;
        for _ in 0..4 {
            sc.duration = Some(cover(at + span));
            let Ok(probe) = run(&sc) else {
                return Ok(first);
            };
            recovery = probe
                .events
                .iter()
                .find_map(|e| match e {
                    metrics::Event::Disturbance(d) => Some(d.recovery_time),
                    metrics::Event::Setpoint(_) => None,
                })
                .unwrap_or(f64::NAN);
            let diverged = probe.result.diverged_at.is_some();
            // its buffers for the next run: memory already mapped
            super::recycle(probe.result);
            if diverged {
                return Ok(first);
            }
            if recovery.is_finite() && recovery < 0.8 * span {
                break;
            }
            span *= 2.0;
        }
        if !recovery.is_finite() {
            return Ok(first);
        }
        sc.duration = Some(cover(nice_ceil(at + 1.25 * recovery.max(settle))));
        let Ok(mut out) = run(&sc) else {
            return Ok(first);
        };
        super::recycle(first.result);
        out.duration_chosen = true;
        out.default_scenario = true;
        Ok(out)
    }

    /// [`Scenario::run`] with a controller already tuned (`tuned`) and the
    /// processes given: the scenario's plants, `controller`, `lambda`, `rule`
    /// and `set` are not read.
    ///
    /// A duration the scenario does not give is chosen from the plant
    /// ([`choose_duration`]) and, when the output has not come to rest by
    /// then, doubled up to four times (within the memory budget); a run
    /// that still has not settled says so in its warnings.
    pub fn run_tuned(
        &self,
        tuned: &Tuned,
        plant: TransferFunction,
        model: TransferFunction,
        inner: Option<(TransferFunction, TransferFunction)>,
    ) -> Result<RunOutput, RunError> {
        let plants = Plants {
            plant: &plant,
            model: &model,
            inner: inner.as_ref(),
        };
        self.run_tuned_measured(tuned, plants, Keep::Measured)
    }

    /// [`Scenario::run_tuned`] keeping `keep` (with a duration given: a
    /// chosen one needs the figures to know the run has settled).
    pub(crate) fn run_tuned_measured(
        &self,
        tuned: &Tuned,
        plants: Plants<'_>,
        keep: Keep,
    ) -> Result<RunOutput, RunError> {
        // a chosen duration is extended until the run settles: measured
        let keep = if self.duration.is_none() {
            Keep::Measured
        } else {
            keep
        };
        let mut out = self.run_once(tuned, plants, keep)?;
        if self.duration.is_some() {
            return Ok(out);
        }
        let mut longer = self.clone();
        for _ in 0..4 {
            if out.result.diverged_at.is_some() || out.has_settled() {
                return Ok(out);
            }
            longer.duration = Some(out.duration * 2.0);
            match longer.run_once(tuned, plants, keep) {
                Ok(mut o) => {
                    o.duration_chosen = true;
                    out = o;
                }
                // beyond the memory budget: keep the run there is
                Err(_) => break,
            }
        }
        if out.result.diverged_at.is_none() && !out.has_settled() {
            out.notes.push(std::format!(
                "the output had not settled after {} s (the chosen duration, extended); give --duration (Python: duration=) to run longer",
                crate::poly::fmt_num(out.duration)
            ));
        }
        Ok(out)
    }

    /// One run of [`Scenario::run_tuned`] at the scenario's duration (or the
    /// one chosen from the plant).
    pub(super) fn run_once(
        &self,
        tuned: &Tuned,
        plants: Plants<'_>,
        keep: Keep,
    ) -> Result<RunOutput, RunError> {
        let Plants {
            plant,
            model,
            inner,
        } = plants;
        let measure = keep == Keep::Measured;
        let built = self.build_tuned(tuned, model, inner.map(|(_, m)| m))?;
        let (scheme, params, mut ctrl, ts, ts_chosen) = (
            built.scheme,
            built.params,
            built.controller,
            built.ts,
            built.ts_chosen,
        );
        let (u_min, u_max) = (built.u_min, built.u_max);
        let (duration, duration_chosen) = match self.duration {
            Some(d) => {
                let d = crate::real::positive(d, "duration")?;
                self.check_duration_covers(d)?;
                (d, false)
            }
            // the plant's settling, or twenty closed-loop time constants λ
            // where the loop is slower (a delay-free integrator has no time
            // constant of its own)
            None => (
                choose_duration(
                    &match inner {
                        Some((p2, _)) => plant.series(p2)?,
                        None => plant.clone(),
                    },
                    ts,
                )
                .max(
                    20.0 * tuned
                        .params
                        .lambda()
                        .filter(|l| l.is_finite())
                        .unwrap_or(0.0),
                ),
                true,
            ),
        };
        // the chosen duration covers settling from a step at 0: from the last
        // thing scheduled as well
        let duration = match (duration_chosen, self.last_scheduled()) {
            (true, Some((at, _))) if at > 0.0 => at + duration,
            _ => duration,
        };
        let substeps = self.substeps.unwrap_or(1);
        if substeps == 0 || substeps > 1000 {
            return Err(RunError::Invalid(Error::OutOfRange("substeps")));
        }
        // the plant's delay lines and the recorded signals, before they are allocated
        let model_samples = (model.delay + inner.map_or(0.0, |(_, m)| m.delay))
            .max(self.event_dead_time(false))
            / ts;
        let plant_samples = (plant.delay + inner.map_or(0.0, |(p, _)| p.delay))
            .max(self.event_dead_time(true))
            / ts;
        self.check_operation()?;
        #[allow(clippy::cast_precision_loss)] // at most 1000
        let rows = (duration / ts + 1.0) * substeps as f64;
        // each scheduled item is held several times over (the schedule, the
        // scenario and the report's copies, the event figures)
        #[allow(clippy::cast_precision_loss)]
        let items = (self.setpoint.len() + self.disturbance.len() + self.events.len()) as f64;
        // the columns this run records: the fixed ones and the controller's
        // signals (an estimate close to what is taken, so that a process
        // limit near it is not refused for columns it never has)
        #[allow(clippy::cast_precision_loss)] // a few dozen signals
        // (u_applied only where an operator or an actuator changes what the
        // plant receives)
        let applied = if self.events.is_empty() && self.actuator.is_none() {
            0.0
        } else {
            1.0
        };
        let columns = if keep == Keep::Output {
            // the output and the input only (t, y, u; y2)
            3.0 + applied + if inner.is_some() { 1.0 } else { 0.0 }
        } else {
            RECORDED_COLUMNS - 1.0
                + applied
                + if inner.is_some() { 2.0 } else { 0.0 }
                + ctrl.signal_names().len() as f64
        };
        self.within_budget(
            model_samples * CONTROLLER_BYTES_PER_SAMPLE
                + plant_samples * PLANT_BYTES_PER_SAMPLE
                + rows * 8.0 * columns
                + items * BYTES_PER_SCHEDULED,
            &std::format!(
                "{} scheduled steps and events, {} recorded rows ({} s at ts = {} s{}) and {} samples of dead time",
                items,
                crate::poly::fmt_num(rows.ceil()),
                crate::poly::fmt_num(duration),
                crate::poly::fmt_num(ts),
                if substeps > 1 {
                    std::format!(", {substeps} substeps")
                } else {
                    String::new()
                },
                crate::poly::fmt_num(plant_samples.ceil())
            ),
        )?;
        let setpoint = if self.setpoint.is_empty() {
            std::vec![SetpointStep {
                value: 1.0,
                at: 0.0
            }]
        } else {
            self.setpoint.clone()
        };
        for s in &setpoint {
            crate::real::finite(s.value, "setpoint")?;
            crate::real::non_negative(s.at, "setpoint")?;
        }
        for d in &self.disturbance {
            crate::real::finite(d.value, "disturbance")?;
            crate::real::non_negative(d.at, "disturbance")?;
            crate::real::non_negative(d.freq, "disturbance")?;
        }
        let cfg = SimConfig {
            ts,
            duration,
            setpoint: setpoint.clone(),
            disturbances: self.disturbance.clone(),
            noise: crate::real::non_negative(self.noise.unwrap_or(0.0), "noise")?,
            seed: self.seed.unwrap_or(0),
            quantization: crate::real::non_negative(
                self.quantization.unwrap_or(0.0),
                "quantization",
            )?,
            u_min,
            u_max,
            substeps,
            record: if keep == Keep::Output {
                crate::sim::Record::OutputAndInput
            } else {
                crate::sim::Record::All
            },
            operations: self.events.clone(),
            actuator: self.actuator,
            reset_feedback: self.reset_feedback,
            setpoint_ramp: self.setpoint_ramp.unwrap_or(f64::INFINITY),
            background: self
                .adapt_options()
                .is_some_and(|a| a.background_design == Some(true)),
        };
        let result = match inner {
            Some((p2, _)) => simulate_cascade(plant, p2, &mut ctrl, &cfg)?,
            None => {
                // into the buffers a finished run on this thread gave back
                // (a sweep's rows): memory already mapped
                let mut res = spare();
                crate::sim::simulate_into(plant, &mut ctrl, &cfg, &mut res)?;
                res
            }
        };
        let model_delay = model.delay + inner.as_ref().map_or(0.0, |(_, m)| m.delay);
        let nan = metrics::Metrics {
            indices: crate::metrics::Indices {
                iae: f64::NAN,
                ise: f64::NAN,
                itae: f64::NAN,
                itse: f64::NAN,
                tv: f64::NAN,
            },
            step: crate::metrics::step_info(&[], &[], 0.0, f64::NAN, 0.0),
        };
        let (m0, m1, events) = if measure {
            metrics::measure(
                &result.columns(),
                &setpoint,
                &self.disturbance,
                ts,
                model_delay,
            )?
        } else {
            (nan, nan, Vec::new())
        };
        let loop_change = RunOutput::find_loop_change(&self.events, &result);
        let mut out = RunOutput {
            loop_change,
            plant: plant.clone(),
            model: model.clone(),
            inner: inner.cloned(),
            ts,
            ts_chosen,
            duration,
            duration_chosen,
            lambda_chosen: tuned.lambda_chosen,
            target: tuned.target.clone(),
            controller: scheme,
            params,
            result,
            metrics: m0,
            metrics_delayed_reference: m1,
            setpoint,
            disturbance: self.disturbance.clone(),
            float32: self.float32,
            events,
            default_scenario: false,
            scenario: self.clone(),
            notes: Vec::new(),
            robustness: None,
            stability: crate::analysis::Stability::unknown(
                "the run was not analysed (a run by Scenario::run is)",
            ),
            design: Vec::new(),
        };
        out.notes.extend(built.notes);
        if self.float32 {
            out.notes
                .extend(crate::sim::f32_note(&out.whole_model(), ts));
        }
        Ok(out)
    }
}

//! The adaptation's benchmark bank: families of scenarios, each run with
//! the fixed model, with `--adapt` and with the true model, compared by IAE.
//!
//! A family is a way the process lives: it does not change while the set
//! point moves or while loads come and go; its dead time steps up by 60 % or
//! down by 40 %, or drifts there; its gain or its lag doubles or halves. Each
//! family runs on stable and integrating processes, under measurement noise
//! of 0, 0.5, 2 and 5 % of the step and a 10-bit converter, at msp's chosen
//! sample period and at a coarse one (ten samples of dead time), for several
//! seeds. `scripts/adapt-bank` prints the full bank as the table in
//! `docs/adapt-bank.md`; `tests/adapt_bank.rs` runs a reduced form of it and
//! asserts items 1–3 of the adaptation's promise (no harm without a change,
//! help after one, never a loop made unstable).

use std::string::String;
use std::vec::Vec;

use super::{AdaptOptions, RunError, RunOutput, Scenario};
use crate::sim::{Disturbance, Operation, PlantParameter, SetpointStep};

/// A process of the bank: `K e^{−θs}/(τs + 1)`, or `K e^{−θs}/s` without a lag.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BankPlant {
    /// The static (or velocity) gain.
    pub k: f64,
    /// The lag (s); `None`: an integrating process.
    pub tau: Option<f64>,
    /// The dead time (s).
    pub theta: f64,
}

impl BankPlant {
    /// The plant in msp's grammar.
    pub fn expression(&self) -> String {
        match self.tau {
            Some(tau) => std::format!("{}e^-{}s/({}s+1)", self.k, self.theta, tau),
            None => std::format!("{}e^-{}s/s", self.k, self.theta),
        }
    }

    /// The plant as a transfer function.
    pub fn transfer(&self) -> Result<crate::poly::TransferFunction, RunError> {
        self.expression()
            .parse()
            .map_err(|e| RunError::Limit(std::format!("the bank's plant: {e}")))
    }

    /// One lag as long as the dead time plus the lag (the settling's scale).
    fn scale(&self) -> f64 {
        self.theta + self.tau.unwrap_or(self.theta)
    }

    /// The set point's half period in a case of this process (s): four
    /// settling scales.
    pub fn half_period(&self) -> f64 {
        4.0 * self.scale()
    }

    /// The plant after `change`.
    fn changed(&self, change: Option<Change>) -> BankPlant {
        let Some(c) = change else { return *self };
        match c.what {
            PlantParameter::DeadTime => BankPlant {
                theta: self.theta * c.factor,
                ..*self
            },
            PlantParameter::Gain => BankPlant {
                k: self.k * c.factor,
                ..*self
            },
            PlantParameter::Lag => BankPlant {
                tau: self.tau.map(|t| t * c.factor),
                ..*self
            },
        }
    }
}

/// A change of the process: a parameter times `factor`, at once or drifting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Change {
    /// What changes.
    pub what: PlantParameter,
    /// New value over old.
    pub factor: f64,
    /// Drifts there over this many settling scales (`θ + τ`); `None`: a step.
    pub drift: Option<f64>,
}

/// What moves the loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Excitation {
    /// The set point: a square wave between 0 and 1.
    Setpoint,
    /// Input load steps (output steps too on stable processes), the set
    /// point still after one step to 1.
    Loads,
    /// Loads that ramp to a new level over a half period and hold it:
    /// at the input and the output of stable processes, at the output of
    /// integrating ones (whose Smith predictor answers an input ramp with
    /// a growing error); the set point still after one step to 1.
    Ramps,
}

/// The sample period of a case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Period {
    /// The one `msp run` chooses for the plant.
    Chosen,
    /// Ten samples of dead time.
    Coarse,
}

/// One case of the bank.
#[derive(Debug, Clone, PartialEq)]
pub struct BankCase {
    /// The family's name, e.g. `dead time ×1.6`.
    pub family: String,
    /// The process as commissioned.
    pub plant: BankPlant,
    /// The change (`None`: the process stays as it is).
    pub change: Option<Change>,
    /// What moves the loop.
    pub excitation: Excitation,
    /// Measurement noise (standard deviation, in units of the step).
    pub noise: f64,
    /// A converter's bits (quantization of the measurement over ±2).
    pub bits: Option<u32>,
    /// The sample period.
    pub period: Period,
    /// The noise's seed.
    pub seed: u64,
}

/// A case's figures: the IAE of the evaluated window (the last quarter of
/// the run; the whole run without a change) of the three loops.
#[derive(Debug, Clone, PartialEq)]
pub struct BankResult {
    /// The case.
    pub case: BankCase,
    /// The sample period used (s).
    pub ts: f64,
    /// IAE of the loop with the commissioned model (∞ if it diverged).
    pub iae_fixed: f64,
    /// IAE of the adaptive loop (∞ if it diverged).
    pub iae_adaptive: f64,
    /// IAE of the loop built with the true model from the start.
    pub iae_true: f64,
    /// The largest ratio, event by event, of the adaptive loop's IAE to the
    /// fixed one's (the report's events; 1 where there are none).
    pub worst_event_ratio: f64,
    /// Models the adaptation applied (applied, emergency, detuned).
    pub applied: usize,
    /// After a change: from how many settling scales after it (its start,
    /// for a drift) every event's IAE of the adaptive loop is within 10 %
    /// of the true model's loop's, counted at the first event of that run
    /// (the events of the two loops paired by their order); `None` without
    /// a change, or where the last event is not.
    pub learnt_after: Option<f64>,
}

/// The adaptive loop's IAE counts as the true model's loop's within this
/// factor of it (item 2 of #48: within 10 %).
pub const WITHIN_TRUE: f64 = 1.1;

impl BankResult {
    /// The adaptive loop ends within [`WITHIN_TRUE`] of the true model's.
    pub fn within_true(&self) -> bool {
        self.iae_adaptive <= WITHIN_TRUE * self.iae_true
    }

    /// The first event at or after `change` (s) from which every event's
    /// IAE in `adaptive` is within 10 % of the one in `truth` (the same
    /// set points and loads: the events pair by their order), as its time
    /// after `change` in settling scales `scale`; `None` where the last is
    /// not, or there is none after `change`.
    fn learnt_after(
        adaptive: &[(f64, f64)],
        truth: &[(f64, f64)],
        change: f64,
        scale: f64,
    ) -> Option<f64> {
        let mut from = None;
        for (&(at, a), &(_, t)) in adaptive.iter().zip(truth).rev() {
            if at < change || !(a <= WITHIN_TRUE * t) {
                break;
            }
            from = Some((at - change) / scale);
        }
        from
    }
}

/// The bank's processes: three stable (lag-dominant to dead-time-dominant)
/// and two integrating.
pub const PLANTS: [BankPlant; 5] = [
    BankPlant {
        k: 1.6,
        tau: Some(10.0),
        theta: 6.0,
    },
    BankPlant {
        k: 2.3,
        tau: Some(15.0),
        theta: 8.0,
    },
    BankPlant {
        k: 0.8,
        tau: Some(4.0),
        theta: 10.0,
    },
    BankPlant {
        k: 0.15,
        tau: None,
        theta: 5.0,
    },
    BankPlant {
        k: 0.05,
        tau: None,
        theta: 6.0,
    },
];

/// The measurement conditions: noise 0, 0.5, 2, 5 % and a 10-bit converter.
pub const CONDITIONS: [(f64, Option<u32>); 5] = [
    (0.0, None),
    (0.005, None),
    (0.02, None),
    (0.05, None),
    (0.0, Some(10)),
];

/// The families: `(name, change, excitation)`.
pub fn families() -> Vec<(String, Option<Change>, Excitation)> {
    let step = |what, factor| {
        Some(Change {
            what,
            factor,
            drift: None,
        })
    };
    let drift = |what, factor| {
        Some(Change {
            what,
            factor,
            drift: Some(10.0),
        })
    };
    use PlantParameter::{DeadTime, Gain, Lag};
    let mut f = std::vec![
        ("no change, set point".into(), None, Excitation::Setpoint),
        ("no change, loads".into(), None, Excitation::Loads),
        ("no change, ramps".into(), None, Excitation::Ramps),
    ];
    for (name, change) in [
        ("dead time ×1.6", step(DeadTime, 1.6)),
        ("dead time ×0.6", step(DeadTime, 0.6)),
        ("dead time drifts ×1.5", drift(DeadTime, 1.5)),
        ("dead time drifts ×0.7", drift(DeadTime, 0.7)),
        ("gain ×2", step(Gain, 2.0)),
        ("gain ×0.5", step(Gain, 0.5)),
        ("lag ×2", step(Lag, 2.0)),
        ("lag ×0.5", step(Lag, 0.5)),
        // between the change detector's hypotheses (gains 0.5, 0.7, 1.4, 2;
        // lags 1/2, 2/3, 4/3, 2): what none of them names exactly
        ("gain ×0.6", step(Gain, 0.6)),
        ("lag ×1.6", step(Lag, 1.6)),
    ] {
        f.push((String::from(name), change, Excitation::Setpoint));
    }
    // the process changes in a loop that only loads move
    for (name, change) in [
        ("dead time ×1.6, loads", step(DeadTime, 1.6)),
        ("gain ×0.5, loads", step(Gain, 0.5)),
        ("lag ×2, loads", step(Lag, 2.0)),
        // between the hypotheses, loads only
        ("dead time ×0.7, loads", step(DeadTime, 0.7)),
        ("gain ×0.6, loads", step(Gain, 0.6)),
        ("lag ×1.6, loads", step(Lag, 1.6)),
    ] {
        f.push((String::from(name), change, Excitation::Loads));
    }
    f
}

/// Every case of the full bank (several hundred), or of `seeds` seeds only.
pub fn cases(seeds: u64) -> Vec<BankCase> {
    let mut out = Vec::new();
    for (family, change, excitation) in families() {
        for plant in PLANTS {
            if plant.tau.is_none() && change.is_some_and(|c| c.what == PlantParameter::Lag) {
                continue;
            }
            for (noise, bits) in CONDITIONS {
                for period in [Period::Chosen, Period::Coarse] {
                    for seed in 1..=seeds {
                        out.push(BankCase {
                            family: family.clone(),
                            plant,
                            change,
                            excitation,
                            noise,
                            bits,
                            period,
                            seed,
                        });
                    }
                }
            }
        }
    }
    out
}

impl BankCase {
    /// The run's length (s): learning time after the change, and a window.
    fn duration(&self) -> f64 {
        let s = self.plant.scale();
        match self.change {
            None => 120.0 * s,
            Some(c) => self.change_at() + c.drift.unwrap_or(0.0) * s + 160.0 * s,
        }
    }

    /// The scenario of one loop: `plant` (the commissioned or the true one),
    /// the change as events or not, adaptive or not.
    fn scenario(
        &self,
        plant: &BankPlant,
        events: bool,
        adapt: bool,
        ts: f64,
    ) -> Result<Scenario, RunError> {
        let s = self.plant.scale();
        let duration = self.duration();
        let half = self.plant.half_period();
        let setpoint = match self.excitation {
            Excitation::Setpoint => (0..)
                .map(|i| SetpointStep {
                    value: f64::from(i % 2 == 0),
                    at: half * f64::from(i),
                })
                .take_while(|p| p.at < duration - half)
                .collect(),
            Excitation::Loads | Excitation::Ramps => std::vec![SetpointStep {
                value: 1.0,
                at: 0.0
            }],
        };
        let disturbance = match self.excitation {
            Excitation::Setpoint => Vec::new(),
            // the same loads in the three loops: sized by the commissioned gain
            Excitation::Loads => loads(&self.plant, duration, half),
            Excitation::Ramps => ramps(&self.plant, duration, half),
        };
        let events = match (events, self.change) {
            (true, Some(c)) => std::vec![Operation {
                at: self.change_at(),
                action: action(&self.plant, c, s),
            }],
            _ => Vec::new(),
        };
        Ok(Scenario {
            plant: Some(plant.transfer()?),
            controller: Some("smith".into()),
            ts: Some(ts),
            duration: Some(duration),
            setpoint,
            disturbance,
            noise: (self.noise > 0.0).then_some(self.noise),
            quantization: self.bits.map(|b| 4.0 / f64::from(1u32 << b.min(31))),
            seed: Some(self.seed),
            events,
            adapt: adapt.then(AdaptOptions::default),
            ..Default::default()
        })
    }

    /// The sample period (s).
    pub fn ts(&self) -> Result<f64, RunError> {
        Ok(match self.period {
            Period::Chosen => super::choose_ts(&self.plant.transfer()?),
            Period::Coarse => self.plant.theta / 10.0,
        })
    }

    /// When the process changes (s): with a set-point move.
    pub fn change_at(&self) -> f64 {
        20.0 * self.plant.scale()
    }

    /// The loop with the commissioned model and the model-error monitor
    /// (`--monitor`), nothing applied.
    pub fn monitored(&self) -> Result<RunOutput, RunError> {
        Scenario {
            monitor: true,
            ..self.scenario(&self.plant, true, false, self.ts()?)?
        }
        .run()
    }

    /// The adaptive loop alone (`--adapt`), its log in the report.
    pub fn adaptive(&self) -> Result<RunOutput, RunError> {
        self.adaptive_with(AdaptOptions::default())
    }

    /// The adaptive loop with the options `adapt` in place of the
    /// defaults (a narrower dead-time range, another `min_change`), its
    /// log in the report.
    pub fn adaptive_with(&self, adapt: AdaptOptions) -> Result<RunOutput, RunError> {
        Scenario {
            adapt: Some(adapt),
            ..self.scenario(&self.plant, true, true, self.ts()?)?
        }
        .run()
    }

    /// Runs the three loops and compares them.
    pub fn run(&self) -> Result<BankResult, RunError> {
        let ts = self.ts()?;
        let fixed = self.scenario(&self.plant, true, false, ts)?.run()?;
        let adaptive = self.adaptive()?;
        let from = match self.change {
            None => 0.0,
            Some(_) => 0.75 * self.duration(),
        };
        let events = |o: &RunOutput| -> Vec<(f64, f64)> {
            o.events
                .iter()
                .map(|e| match e {
                    super::Event::Setpoint(s) => (s.at, s.iae),
                    super::Event::Disturbance(d) => (d.at, d.iae),
                })
                .collect()
        };
        let adapted = events(&adaptive);
        let (iae_true, learnt_after) = match self.change {
            None => (iae(&fixed, from), None),
            Some(_) => {
                let truth = self.plant.changed(self.change);
                let truth = self.scenario(&truth, false, false, ts)?.run()?;
                let after = BankResult::learnt_after(
                    &adapted,
                    &events(&truth),
                    self.change_at(),
                    self.plant.scale(),
                );
                (iae(&truth, from), after)
            }
        };
        let worst_event_ratio = adapted
            .iter()
            .zip(events(&fixed))
            .map(|(&(_, a), (_, f))| if f > 0.0 { a / f } else { 1.0 })
            .fold(
                1.0f64,
                |m, r| if r.is_nan() { f64::INFINITY } else { m.max(r) },
            );
        let applied = adaptive
            .report()
            .adaptation
            .iter()
            .filter(|c| {
                matches!(
                    c.kind,
                    crate::adapt::ChangeKind::Applied
                        | crate::adapt::ChangeKind::Emergency
                        | crate::adapt::ChangeKind::Detuned
                )
            })
            .count();
        Ok(BankResult {
            case: self.clone(),
            ts,
            iae_fixed: iae(&fixed, from),
            iae_adaptive: iae(&adaptive, from),
            iae_true,
            worst_event_ratio,
            applied,
            learnt_after,
        })
    }
}

/// The drift or step event of `change` on `plant` (`s`: its settling scale).
fn action(plant: &BankPlant, c: Change, s: f64) -> crate::sim::Action {
    use crate::sim::Action;
    let to = plant.changed(Some(c));
    let (from, x) = match c.what {
        PlantParameter::DeadTime => (plant.theta, to.theta),
        PlantParameter::Gain => (plant.k, to.k),
        PlantParameter::Lag => (plant.tau.unwrap_or(1.0), to.tau.unwrap_or(1.0)),
    };
    match (c.drift, c.what) {
        (Some(d), _) => Action::PlantDrift(c.what, x, (x - from).abs() / (d * s)),
        (None, PlantParameter::DeadTime) => Action::PlantDeadTime(x),
        (None, PlantParameter::Gain) => Action::PlantGain(x),
        (None, PlantParameter::Lag) => Action::PlantLag(x),
    }
}

/// Load steps every `2·half` seconds from `2·half` on: at the input ±0.2/K
/// (±0.2 s·K⁻¹ on an integrating process, whose Smith predictor rejects it
/// with a ramp's error), and on stable processes an output step ±0.3 between.
fn loads(plant: &BankPlant, duration: f64, half: f64) -> Vec<Disturbance> {
    let mut d = Vec::new();
    let mut at = 2.0 * half;
    let mut i = 0u32;
    while at < duration - 2.0 * half {
        let sign = if i % 4 < 2 { 1.0 } else { -1.0 };
        let output = plant.tau.is_some() && i % 2 == 1;
        let (location, value) = if output {
            (crate::sim::Location::Output, 0.3 * sign)
        } else {
            (crate::sim::Location::Input, 0.2 * sign / plant.k)
        };
        d.push(Disturbance {
            location,
            ..Disturbance::input_step(value, at)
        });
        at += 2.0 * half;
        i += 1;
    }
    d
}

/// Ramps every `2·half` seconds from `2·half` on, each to a new level
/// over `half` seconds (a ramp and its opposite from there): on stable
/// processes alternately at the input to ±0.2/K and at the output to
/// ±0.3, on integrating ones at the output to ±0.3.
fn ramps(plant: &BankPlant, duration: f64, half: f64) -> Vec<Disturbance> {
    let mut d = Vec::new();
    let mut at = 2.0 * half;
    let mut i = 0u32;
    while at < duration - 2.0 * half {
        let sign = if i % 4 < 2 { 1.0 } else { -1.0 };
        let output = plant.tau.is_none() || i % 2 == 1;
        let (location, level) = if output {
            (crate::sim::Location::Output, 0.3 * sign)
        } else {
            (crate::sim::Location::Input, 0.2 * sign / plant.k)
        };
        for (start, slope) in [(at, level / half), (at + half, -level / half)] {
            d.push(Disturbance {
                location,
                shape: crate::sim::Shape::Ramp,
                ..Disturbance::input_step(slope, start)
            });
        }
        at += 2.0 * half;
        i += 1;
    }
    d
}

/// `∫|r − y| dt` from `from` to the end (∞ if the run diverged).
fn iae(out: &RunOutput, from: f64) -> f64 {
    let r = &out.result;
    if r.diverged_at.is_some() {
        return f64::INFINITY;
    }
    r.t.iter()
        .zip(r.y.iter().zip(&r.r))
        .filter(|(t, _)| **t >= from)
        .map(|(_, (y, r))| (r - y).abs() * out.ts)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first event from which every later one is within 10 % of the
    /// true loop's, in scales after the change; none where the last is not
    /// (or diverged: a NaN is not within); events before the change do not
    /// count.
    #[test]
    fn learnt_after_is_the_first_event_of_the_last_run_within_10_percent() {
        let truth = [
            (0.0, 1.0),
            (10.0, 1.0),
            (20.0, 1.0),
            (30.0, 1.0),
            (40.0, 1.0),
        ];
        let adaptive = [
            (0.0, 1.0),
            (10.0, 2.0),
            (20.0, 1.05),
            (30.0, 1.2),
            (40.0, 1.1),
        ];
        assert_eq!(
            BankResult::learnt_after(&adaptive, &truth, 5.0, 5.0),
            Some(7.0)
        );
        let settled = [
            (0.0, 3.0),
            (10.0, 1.0),
            (20.0, 1.0),
            (30.0, 1.0),
            (40.0, 1.0),
        ];
        assert_eq!(
            BankResult::learnt_after(&settled, &truth, 5.0, 5.0),
            Some(1.0)
        );
        let mut diverged = adaptive;
        diverged[4].1 = f64::NAN;
        assert_eq!(BankResult::learnt_after(&diverged, &truth, 5.0, 5.0), None);
        assert_eq!(BankResult::learnt_after(&adaptive, &truth, 45.0, 5.0), None);
    }
}

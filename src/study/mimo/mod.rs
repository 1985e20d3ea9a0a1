//! A multivariable run: a scheme of [`MIMO_SCHEMES`] designed for a
//! matrix plant ([`design`]), its closed loop analysed (the sampled loop's
//! stability verdict and biggest log modulus) and run on the exact sampled
//! plant ([`crate::sim::simulate_mimo`]), with each loop's IAE and the
//! interaction of each set-point step: what `msp run --plant "[…]"` prints
//! and writes.

mod build;

pub use build::{
    analyse, controller, decoupling_of, design, find, loops_of, MimoDesign, MimoKind, MimoScheme,
    MIMO_SCHEMES,
};

use std::vec::Vec;

use super::RunError;
use crate::analysis::Stability;
use crate::poly::TransferMatrix;
use crate::sim::{
    choose_duration, choose_ts, simulate_mimo, LoopLoad, MimoEvents, MimoRun, SetpointStep,
};

/// The interaction of one set-point step: loop `step_loop`'s step at `at`
/// (s) and the largest deviation of every output after it.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Interaction {
    /// The loop whose set point stepped (0-based).
    pub step_loop: usize,
    /// When (s).
    pub at: f64,
    /// The largest deviation of each output from its value at the step, up
    /// to the next set-point change or load (the stepping loop's own
    /// included).
    pub deviation: Vec<f64>,
}

/// A multivariable design analysed (the JSON of `msp tune` and `msp
/// margins` for a matrix plant, and the head of `msp run`'s): the plant's
/// interaction measures, the scheme's design (`scheme`, `ts`, `f`, `loops`,
/// `decoupler`) and the sampled closed loop's verdict and biggest log
/// modulus.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MimoReport {
    /// The plant, as written back (`[g11, g12; g21, g22]`).
    pub plant: std::string::String,
    /// The relative gain array at steady state, by rows (Bristol (1966));
    /// `None` for a plant without one (an integrating channel: see
    /// `rga_over_frequency`).
    pub rga: Option<Vec<Vec<f64>>>,
    /// The input each output is best paired with (`None`: no pairing has
    /// every relative gain positive, or no steady-state RGA).
    pub pairing: Option<Vec<usize>>,
    /// The RGA's magnitudes over frequency (12 points, a tenth of the
    /// slowest time scale's frequency to the fastest's).
    pub rga_over_frequency: Vec<crate::analysis::mimo::RgaPoint>,
    /// `det G(0)/Π gᵢᵢ(0)` (Niederlinski (1971); `None` without steady-state
    /// gains).
    pub niederlinski: Option<f64>,
    /// The scheme's design.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub design: MimoDesign,
    /// The PI loops alone, before the detuning (`pi`: by `rule`).
    pub alone: Option<Vec<crate::analysis::mimo::PiLoop>>,
    /// The sampled closed loop's stability verdict (a run adds its
    /// cross-check).
    pub stability: Stability,
    /// The decoupler's own loop's verdict (`decoupled`).
    pub decoupler_stability: Option<Stability>,
    /// The sampled closed loop's biggest log modulus (dB).
    pub lcm: f64,
}

/// The sample period of a matrix plant's loops: the diagonal's fastest
/// loop's choice ([`choose_ts`]).
pub fn period(plant: &TransferMatrix) -> f64 {
    (0..plant.size())
        .filter_map(|i| plant.get(i, i))
        .map(choose_ts)
        .fold(f64::INFINITY, f64::min)
}

/// [`MimoReport`] of `scheme` on `plant` at `ts` ([`period`] when `None`).
pub fn report(
    plant: &TransferMatrix,
    scheme: &str,
    rule: Option<&str>,
    ts: Option<f64>,
) -> Result<MimoReport, RunError> {
    let ts = ts.unwrap_or_else(|| period(plant));
    crate::real::positive(ts, "ts").map_err(RunError::Invalid)?;
    within_samples(plant, ts)?;
    let n = plant.size();
    // the steady-state measures where the plant has steady-state gains
    let rga = crate::analysis::mimo::rga(plant).ok();
    let design = design(plant, scheme, rule, ts)?;
    let (stability, decoupler_stability, lcm) = analyse(plant, &design)?;
    Ok(MimoReport {
        plant: std::string::ToString::to_string(plant),
        pairing: rga
            .as_ref()
            .and_then(|l| crate::analysis::mimo::pairing(l, n)),
        rga: rga.map(|l| l.chunks(n).map(<[f64]>::to_vec).collect()),
        rga_over_frequency: crate::analysis::mimo::rga_over(plant, 12)
            .map_err(RunError::Invalid)?,
        niederlinski: crate::analysis::mimo::niederlinski(plant).ok(),
        alone: design.alone.clone(),
        design,
        stability,
        decoupler_stability,
        lcm,
    })
}

/// The most samples of dead time a channel may have at the period (its
/// line, the predictor's and the verdict's frequency grid grow with it).
pub const MAX_DELAY_SAMPLES: f64 = 1e6;

/// Every channel's dead time within [`MAX_DELAY_SAMPLES`] at `ts`, or an
/// error that names the channel and what to do.
fn within_samples(plant: &TransferMatrix, ts: f64) -> Result<(), RunError> {
    let n = plant.size();
    for i in 0..n {
        for j in 0..n {
            let d = plant
                .get(i, j)
                .and_then(|g| g.delay_samples(ts).ok())
                .unwrap_or(f64::INFINITY);
            if !(d <= MAX_DELAY_SAMPLES) {
                return Err(RunError::Limit(std::format!(
                    "g{}{}'s dead time is {:.3e} samples at ts = {ts} s, beyond the {MAX_DELAY_SAMPLES:.0e} a matrix plant's run holds: give a longer --ts",
                    i + 1,
                    j + 1,
                    d
                )));
            }
        }
    }
    Ok(())
}

/// A multivariable scenario: the plant, the scheme, the set points per
/// loop and the events (the input of [`MimoScenario::run`], which `msp run
/// --plant "[…]"` and Python's `msp.run` fill).
#[derive(Debug, Clone, PartialEq)]
pub struct MimoScenario {
    /// The plant.
    pub plant: TransferMatrix,
    /// The scheme's name ([`MIMO_SCHEMES`]; `pi` when `None`).
    pub controller: Option<std::string::String>,
    /// The `pi` loops' rule before the detuning (`zn`, BLT's, when `None`;
    /// `simc`).
    pub rule: Option<std::string::String>,
    /// The sample period (s; [`period`] when `None`).
    pub ts: Option<f64>,
    /// The run's duration (s; enough for the slowest loop to settle after
    /// each step when `None`).
    pub duration: Option<f64>,
    /// Each loop's set-point steps (none at all: loop `i` steps to 1 at
    /// `i/n` of the run, one after the other).
    pub setpoints: Vec<Vec<SetpointStep>>,
    /// Loads, a disturbance vector, channels' dead-time changes.
    pub events: MimoEvents,
}

/// A multivariable run's report (the JSON of `msp run --plant "[…]"`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MimoOutput {
    /// The design analysed, the verdict cross-checked by the run.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub report: MimoReport,
    /// The run's duration (s).
    pub duration: f64,
    /// Each loop's set-point steps.
    pub setpoints: Vec<Vec<SetpointStep>>,
    /// Each loop's loads.
    pub loads: Vec<LoopLoad>,
    /// Each loop's IAE over the run.
    pub iae: Vec<f64>,
    /// Each set-point step's interaction.
    pub interaction: Vec<Interaction>,
    /// Each loop's events, as a single loop's run reports them (step
    /// information of each of its set-point steps, the rejection of each of
    /// its loads), each over its segment up to the next set-point step or
    /// load of any loop.
    pub events: Vec<Vec<super::metrics::Event>>,
    /// The samples.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub run: MimoRun,
}

impl MimoScenario {
    /// Designs, analyses and runs the scenario.
    pub fn run(&self) -> Result<MimoOutput, RunError> {
        let plant = &self.plant;
        let n = plant.size();
        let ts = self.ts.unwrap_or_else(|| period(plant));
        let settle = (0..n)
            .filter_map(|i| plant.get(i, i))
            .map(|g| choose_duration(g, ts))
            .fold(0.0, f64::max);
        #[allow(clippy::cast_precision_loss)]
        let duration = self.duration.unwrap_or(settle * n as f64);
        if self.setpoints.len() > n {
            return Err(RunError::Limit(std::format!(
                "a set point for loop {} of a {n}x{n} plant",
                self.setpoints.len()
            )));
        }
        let setpoints =
            if self.setpoints.iter().all(Vec::is_empty) && self.events == MimoEvents::default() {
                #[allow(clippy::cast_precision_loss)]
                (0..n)
                    .map(|i| {
                        std::vec![SetpointStep {
                            value: 1.0,
                            at: duration * i as f64 / n as f64,
                        }]
                    })
                    .collect()
            } else {
                self.setpoints.clone()
            };
        let mut out = report(
            plant,
            self.controller.as_deref().unwrap_or("pi"),
            self.rule.as_deref(),
            Some(ts),
        )?;
        let mut c = controller(plant, &out.design)?;
        let run = simulate_mimo(plant, &mut *c, &setpoints, &self.events, ts, duration)
            .map_err(RunError::Invalid)?;
        out.stability = match self.events.dead_times.iter().map(|e| e.at).reduce(f64::min) {
            // the loop as built, cross-checked up to the first change
            Some(at) => {
                let k = crate::sim::first_sample_at(at, ts);
                let settled = (k >= 10).then(|| prefix_settles(&run, k));
                out.stability
                    .as_built(settled, at, "a channel's dead time changes")
            }
            None => cross_check(out.stability, &run, duration),
        };
        // each step's interaction, up to the next set-point change or load
        // of any loop
        let mut times: Vec<f64> = setpoints
            .iter()
            .flatten()
            .map(|s| s.at)
            .chain(self.events.loads.iter().map(|l| l.at))
            .collect();
        times.sort_by(f64::total_cmp);
        let interaction = setpoints
            .iter()
            .enumerate()
            .flat_map(|(i, s)| s.iter().map(move |s| (i, s.at)))
            .map(|(step_loop, at)| {
                let until = times.iter().copied().find(|t| *t > at).unwrap_or(duration);
                Interaction {
                    step_loop,
                    at,
                    deviation: run.interaction(at, until),
                }
            })
            .collect();
        let events = (0..n)
            .map(|i| loop_events(&run, i, &setpoints, &self.events.loads, ts))
            .collect();
        Ok(MimoOutput {
            events,
            iae: (0..n).map(|i| run.iae(i)).collect(),
            report: out,
            duration,
            setpoints,
            loads: self.events.loads.clone(),
            interaction,
            run,
        })
    }
}

/// Loop `i`'s events: its set-point steps and its loads, by the single
/// loop's measures ([`super::metrics::events`]).
fn loop_events(
    run: &MimoRun,
    i: usize,
    setpoints: &[Vec<SetpointStep>],
    loads: &[LoopLoad],
    ts: f64,
) -> Vec<super::metrics::Event> {
    let (Some(r), Some(y), Some(u)) = (run.r.get(i), run.y.get(i), run.u.get(i)) else {
        return Vec::new();
    };
    let cols = super::metrics::Columns {
        t: &run.t,
        r,
        y,
        u,
        substeps: 1,
        diverged_at: None,
    };
    let disturbances: Vec<crate::sim::Disturbance> = loads
        .iter()
        .filter(|l| l.loop_index == i)
        .map(|l| crate::sim::Disturbance {
            location: l.location,
            shape: crate::sim::Shape::Step,
            value: l.value,
            at: l.at,
            freq: 0.0,
        })
        .collect();
    let own = setpoints.get(i).map_or(&[][..], Vec::as_slice);
    // the other loops' set-point steps and loads end this loop's segments
    let others: Vec<f64> = setpoints
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != i)
        .flat_map(|(_, s)| s.iter().map(|s| s.at))
        .chain(loads.iter().filter(|l| l.loop_index != i).map(|l| l.at))
        .collect();
    super::metrics::events_within(&cols, own, &disturbances, &others, ts)
}

/// The verdict with the run's cross-check: every output and input settles
/// ([`super::metrics::settles`], the single-loop runs' test).
fn cross_check(v: Stability, run: &MimoRun, duration: f64) -> Stability {
    v.with_simulation(prefix_settles(run, run.t.len()), duration)
}

/// Every output and input of the run's first `k` samples settles.
fn prefix_settles(run: &MimoRun, k: usize) -> bool {
    run.y
        .iter()
        .chain(&run.u)
        .all(|s| super::metrics::settles(s.get(..k).unwrap_or(s)))
}

/// A matrix plant's scenario file (TOML or JSON): the CLI's flags by name,
/// each in its text form (`plant = "[g11, g12; g21, g22]"`,
/// `loop_setpoint = ["1:1@0", "2:1@50"]`, `loop_disturbance`,
/// `disturbance_plant`, `disturbance_step`, `channel_dead_time`,
/// `loop_event`), read into a [`MimoScenario`] by `TryFrom`.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct MimoScenarioFile {
    /// The plant, `[g11, g12; g21, g22]`.
    pub plant: std::string::String,
    /// The scheme (`pi`, `smith`, `decoupled`).
    pub controller: Option<std::string::String>,
    /// The `pi` loops' rule (`zn`, `simc`).
    pub rule: Option<std::string::String>,
    /// The sample period (s).
    pub ts: Option<f64>,
    /// The run's duration (s).
    pub duration: Option<f64>,
    /// `LOOP:VALUE@TIME` each.
    pub loop_setpoint: Vec<std::string::String>,
    /// `LOOP:input|output:VALUE@TIME` each.
    pub loop_disturbance: Vec<std::string::String>,
    /// `[d1; d2]`.
    pub disturbance_plant: Option<std::string::String>,
    /// `VALUE@TIME` each.
    pub disturbance_step: Vec<std::string::String>,
    /// `ROW,COL=SECONDS@TIME` each.
    pub channel_dead_time: Vec<std::string::String>,
    /// `LOOP:TIME:manual=VALUE` or `LOOP:TIME:auto` each.
    pub loop_event: Vec<std::string::String>,
    /// The measurement noise's standard deviation (every output).
    pub noise: Option<f64>,
    /// The noise's seed.
    pub seed: Option<u64>,
    /// `MIN..MAX`, every input.
    pub actuator: Option<std::string::String>,
}

impl TryFrom<MimoScenarioFile> for MimoScenario {
    type Error = std::string::String;
    /// Each text form parsed as the CLI's flag of the same name parses it;
    /// an error names the field and the entry.
    fn try_from(f: MimoScenarioFile) -> Result<Self, Self::Error> {
        use std::string::ToString;
        let plant: TransferMatrix = f.plant.parse().map_err(|e| std::format!("plant: {e}"))?;
        let n = plant.size();
        let mut setpoints = std::vec![Vec::new(); n];
        for s in &f.loop_setpoint {
            let (l, step) = crate::syntax::parse_loop_setpoint(s)
                .map_err(|e| std::format!("loop_setpoint {s:?}: {e}"))?;
            setpoints
                .get_mut(l)
                .ok_or_else(|| std::format!("loop_setpoint {s:?}: the plant has {n} loops"))?
                .push(step);
        }
        fn all<X: core::str::FromStr<Err = std::string::String>>(
            field: &str,
            v: &[std::string::String],
        ) -> Result<Vec<X>, std::string::String> {
            v.iter()
                .map(|s| s.parse().map_err(|e| std::format!("{field} {s:?}: {e}")))
                .collect()
        }
        let disturbance = match (&f.disturbance_plant, f.disturbance_step.is_empty()) {
            (Some(d), _) => Some(crate::sim::DisturbanceVector {
                channels: crate::syntax::parse_column(d)
                    .map_err(|e| std::format!("disturbance_plant: {e}"))?,
                steps: all("disturbance_step", &f.disturbance_step)?,
            }),
            (None, false) => {
                return Err("disturbance_step needs disturbance_plant (the disturbance's channel to each output)".to_string())
            }
            (None, true) => None,
        };
        Ok(MimoScenario {
            plant,
            controller: f.controller,
            rule: f.rule,
            ts: f.ts,
            duration: f.duration,
            setpoints,
            events: MimoEvents {
                loads: all("loop_disturbance", &f.loop_disturbance)?,
                disturbance,
                dead_times: all("channel_dead_time", &f.channel_dead_time)?,
                modes: all("loop_event", &f.loop_event)?,
                noise: f.noise.unwrap_or(0.0),
                seed: f.seed.unwrap_or(0),
                actuator: f
                    .actuator
                    .as_deref()
                    .map(crate::syntax::parse_actuator)
                    .transpose()
                    .map_err(|e| std::format!("actuator: {e}"))?,
            },
        })
    }
}

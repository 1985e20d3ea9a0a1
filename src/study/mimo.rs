//! A multivariable run: the BLT-tuned decentralized PI loops of a matrix
//! plant ([`crate::analysis::mimo::tuning`]) closed on the exact sampled
//! plant ([`crate::sim::simulate_decentralized`]), with each loop's IAE and
//! the interaction of each set-point step: what `msp run --plant "[…]"`
//! prints and writes.

use std::vec::Vec;

use super::RunError;
use crate::analysis::mimo::{tuning, MimoTuning};
use crate::controller::Controller;
use crate::pid::{Pid, PidConfig};
use crate::poly::TransferMatrix;
use crate::sim::{choose_duration, choose_ts, simulate_decentralized, MimoRun, SetpointStep};

/// The interaction of one set-point step: loop `step_loop`'s step at `at`
/// (s) and the largest deviation of every output after it.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Interaction {
    /// The loop whose set point stepped (0-based).
    pub step_loop: usize,
    /// When (s).
    pub at: f64,
    /// The largest deviation of each output from its value at the step
    /// (the stepping loop's own included).
    pub deviation: Vec<f64>,
}

/// A multivariable run's report (the JSON of `msp run --plant "[…]"`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MimoOutput {
    /// The analysis and the BLT loops.
    pub tuning: MimoTuning,
    /// The sample period (s).
    pub ts: f64,
    /// The run's duration (s).
    pub duration: f64,
    /// Each loop's set-point steps.
    pub setpoints: Vec<Vec<SetpointStep>>,
    /// Each loop's IAE over the run.
    pub iae: Vec<f64>,
    /// Each set-point step's interaction.
    pub interaction: Vec<Interaction>,
    /// The samples.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub run: MimoRun,
}

/// Tunes `plant`'s diagonal loops by BLT and runs them every `ts` (chosen
/// from the diagonal's fastest loop when `None`) for `duration` (enough
/// for the slowest loop to settle after each step when `None`), the set
/// points `setpoints[i]` per loop (none given: loop `i` steps to 1 at
/// `i/n` of the run, one after the other).
pub fn run_blt(
    plant: &TransferMatrix,
    setpoints: Vec<Vec<SetpointStep>>,
    ts: Option<f64>,
    duration: Option<f64>,
) -> Result<MimoOutput, RunError> {
    let n = plant.size();
    let diagonal: Vec<_> = (0..n).filter_map(|i| plant.get(i, i)).collect();
    let ts = ts.unwrap_or_else(|| {
        diagonal
            .iter()
            .map(|g| choose_ts(g))
            .fold(f64::INFINITY, f64::min)
    });
    let settle = diagonal
        .iter()
        .map(|g| choose_duration(g, ts))
        .fold(0.0, f64::max);
    let duration = duration.unwrap_or(settle * n as f64);
    let setpoints = if setpoints.iter().all(Vec::is_empty) {
        (0..n)
            .map(|i| {
                std::vec![SetpointStep {
                    value: 1.0,
                    at: duration * i as f64 / n as f64,
                }]
            })
            .collect()
    } else {
        setpoints
    };
    if setpoints.len() > n {
        return Err(RunError::Limit(std::format!(
            "a set point for loop {} of a {n}x{n} plant",
            setpoints.len()
        )));
    }
    let tuned = tuning(plant).map_err(RunError::Invalid)?;
    let mut pids = Vec::with_capacity(n);
    for l in &tuned.loops {
        pids.push(Pid::new(PidConfig::isa(l.kp, l.ti, 0.0, ts)).map_err(RunError::Invalid)?);
    }
    let mut refs: Vec<&mut dyn Controller<f64>> = pids
        .iter_mut()
        .map(|p| p as &mut dyn Controller<f64>)
        .collect();
    let run = simulate_decentralized(plant, &mut refs, &setpoints, ts, duration)
        .map_err(RunError::Invalid)?;
    let interaction = setpoints
        .iter()
        .enumerate()
        .flat_map(|(i, s)| s.iter().map(move |s| (i, s.at)))
        .map(|(step_loop, at)| Interaction {
            step_loop,
            at,
            deviation: run.interaction(at),
        })
        .collect();
    Ok(MimoOutput {
        iae: (0..n).map(|i| run.iae(i)).collect(),
        tuning: tuned,
        ts,
        duration,
        setpoints,
        interaction,
        run,
    })
}

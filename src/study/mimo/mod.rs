//! A multivariable run: a scheme of [`MIMO_SCHEMES`] designed for a
//! matrix plant ([`design`]), its closed loop analysed (the sampled loop's
//! stability verdict and biggest log modulus) and run on the exact sampled
//! plant ([`crate::sim::simulate_mimo`]), with each loop's IAE and the
//! interaction of each set-point step: what `msp run --plant "[…]"` prints
//! and writes.

mod build;

pub use build::{
    analyse, controller, decoupling_of, design, find, loops_of, MimoDesign, MimoScheme,
    MIMO_SCHEMES,
};

use std::vec::Vec;

use super::RunError;
use crate::analysis::mimo::{tuning, MimoTuning};
use crate::analysis::Stability;
use crate::poly::TransferMatrix;
use crate::sim::{choose_duration, choose_ts, simulate_mimo, MimoRun, SetpointStep};

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
    /// to the next set-point change (the stepping loop's own included).
    pub deviation: Vec<f64>,
}

/// A multivariable run's report (the JSON of `msp run --plant "[…]"`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MimoOutput {
    /// The plant's analysis (RGA, pairing, Niederlinski index) and its
    /// BLT loops.
    pub tuning: MimoTuning,
    /// The scheme's design: its loops, detuning and decoupler.
    pub design: MimoDesign,
    /// The sampled closed loop's stability verdict, cross-checked by the
    /// run.
    pub stability: Stability,
    /// The decoupler's own loop's (`decoupled` only).
    pub decoupler_stability: Option<Stability>,
    /// The sampled closed loop's biggest log modulus (dB).
    pub lcm: f64,
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

/// Designs `scheme` for `plant` and runs it every `ts` (chosen from the
/// diagonal's fastest loop when `None`) for `duration` (enough for the
/// slowest loop to settle after each step when `None`), the set points
/// `setpoints[i]` per loop (none given: loop `i` steps to 1 at `i/n` of
/// the run, one after the other).
pub fn run_mimo(
    plant: &TransferMatrix,
    scheme: &str,
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
    let design = design(plant, scheme, ts)?;
    let (stability, decoupler_stability, lcm) = analyse(plant, &design)?;
    let mut c = controller(plant, &design)?;
    let run = simulate_mimo(plant, &mut *c, &setpoints, ts, duration).map_err(RunError::Invalid)?;
    let stability = cross_check(stability, &run, duration);
    // each step's interaction, up to the next set-point change of any loop
    let mut times: Vec<f64> = setpoints.iter().flatten().map(|s| s.at).collect();
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
    Ok(MimoOutput {
        iae: (0..n).map(|i| run.iae(i)).collect(),
        tuning: tuned,
        design,
        stability,
        decoupler_stability,
        lcm,
        ts,
        duration,
        setpoints,
        interaction,
        run,
    })
}

/// The verdict with the run's cross-check: every output and input settles
/// ([`super::metrics::settles`], the single-loop runs' test).
fn cross_check(v: Stability, run: &MimoRun, duration: f64) -> Stability {
    let settled = run
        .y
        .iter()
        .chain(&run.u)
        .all(|s| super::metrics::settles(s));
    v.with_simulation(settled, duration)
}

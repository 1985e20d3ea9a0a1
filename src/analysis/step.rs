//! The open-loop step response of a plant and its step information.

use std::string::String;
use std::vec::Vec;

use crate::error::Error;
use crate::poly::TransferFunction;

/// The open-loop step response of a plant, as MATLAB's `step` and
/// `stepinfo` (python-control's `step_response` and `step_info`) give it.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct OpenLoopStep {
    /// The plant.
    pub plant: String,
    /// Its kind: stable, integrating or unstable.
    pub plant_kind: String,
    /// Sample period of `t` (s).
    pub ts: f64,
    /// Simulated time (s).
    pub duration: f64,
    /// Which of `ts` and `duration` were chosen (not given).
    pub chosen: Vec<&'static str>,
    /// The final value, the static gain `G(0)` (`None` for a plant whose
    /// response does not settle: integrating or unstable).
    pub dc_gain: Option<f64>,
    /// Rise and settling times, overshoot, peak (NaN — null in JSON — for a
    /// response that does not settle: an integrating or unstable plant).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub info: crate::metrics::StepInfo,
    /// What the user should know: a response faster than the grid can show.
    pub warnings: Vec<String>,
    /// Time (s).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub t: Vec<f64>,
    /// The output for a unit step at `t = 0`.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub y: Vec<f64>,
}

/// Samples in an open-loop step response with a chosen period.
const STEP_SAMPLES: f64 = 4000.0;
/// The most samples an open-loop step response may take.
const STEP_MAX_SAMPLES: f64 = 1e8;
/// The most samples a chosen grid is refined to.
const STEP_REFINED_SAMPLES: f64 = 4e6;

/// The sample period and duration [`step_response`] uses for `plant` with
/// the `ts` and `duration` given (each chosen when absent), checked.
pub fn step_grid(
    plant: &TransferFunction,
    ts: Option<f64>,
    duration: Option<f64>,
) -> Result<(f64, f64), Error> {
    let duration = match duration {
        Some(d) => crate::real::positive(d, "duration")?,
        None => {
            let d = crate::sim::choose_duration(plant, 0.0);
            if d > 0.0 && d.is_finite() {
                d
            } else {
                10.0
            }
        }
    };
    let ts = match ts {
        Some(ts) => crate::real::positive(ts, "ts")?,
        None => duration / STEP_SAMPLES,
    };
    Ok((ts, duration))
}

/// The unit step response of `plant` with its exact dead time: the ZOH
/// equivalent at `ts` gives the continuous response at the sample instants
/// exactly (the input is constant between them; the dead time's fraction of
/// a sample by the modified z-transform), and the step information uses
/// MATLAB's `stepinfo` definitions with the static gain as the final value.
/// `duration` defaults to [`crate::sim::choose_duration`] (ten dead times,
/// ten slowest time constants, ten times the sum of the lags; 10 s for a pure
/// integrator), `ts` to `duration/4000`.
pub fn step_response(
    plant: &TransferFunction,
    ts: Option<f64>,
    duration: Option<f64>,
) -> Result<OpenLoopStep, Error> {
    let duration_given = duration.is_some();
    let ts_given = ts.is_some();
    let (ts, duration) = step_grid(plant, ts, duration)?;
    let n = (duration / ts).round() + 1.0;
    if !(n <= STEP_MAX_SAMPLES) {
        return Err(Error::OutOfRange(
            "ts: more than 1e8 samples in the duration",
        ));
    }
    let kind = plant.kind();
    let dc_gain = (kind == crate::poly::PlantKind::Stable).then(|| plant.gain());
    let at = |ts: f64, n: f64| -> Result<(Vec<f64>, Vec<f64>, crate::metrics::StepInfo), Error> {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // at most 1e8
        let n = n as usize;
        let y = crate::sim::open_loop(plant, ts, &std::vec![1.0; n])?;
        #[allow(clippy::cast_precision_loss)]
        let t: Vec<f64> = (0..n).map(|k| k as f64 * ts).collect();
        let info = match dc_gain {
            Some(g) => crate::metrics::step_info(&t, &y, 0.0, g, 0.0),
            // no final value: no figure measures a response that does not settle
            None => crate::metrics::step_info(&[], &[], 0.0, f64::NAN, 0.0),
        };
        Ok((t, y, info))
    };
    let (mut ts, mut n) = (ts, n);
    let (mut t, mut y, mut info) = at(ts, n)?;
    let mut warnings = Vec::new();
    // a chosen grid resolves the rise: a fast mode the slow ones hid (a slow
    // pole cancelled by a zero) refines it until the rise spans 50 samples
    if !ts_given {
        for _ in 0..4 {
            let rise = info.rise_time;
            if !(rise.is_finite() && rise < 50.0 * ts) {
                break;
            }
            // as fine as that, or as fine as the sample budget allows
            let finer = (rise / 100.0).max(duration / (STEP_REFINED_SAMPLES - 1.0));
            if !(finer < 0.5 * ts) {
                break;
            }
            (ts, n) = (finer, (duration / finer).round() + 1.0);
            (t, y, info) = at(ts, n)?;
        }
    }
    if info.rise_time.is_finite() && info.rise_time < 5.0 * ts {
        warnings.push(std::format!(
            "the rise ({} s) spans fewer than 5 samples of ts = {} s: the figures are coarse",
            crate::poly::fmt_num(crate::poly::round_sig(info.rise_time, 3)),
            crate::poly::fmt_num(ts)
        ));
    }
    Ok(OpenLoopStep {
        plant: plant.to_string(),
        plant_kind: kind.to_string(),
        ts,
        duration,
        chosen: [("ts", !ts_given), ("duration", !duration_given)]
            .into_iter()
            .filter_map(|(k, c)| c.then_some(k))
            .collect(),
        dc_gain,
        info,
        warnings,
        t,
        y,
    })
}

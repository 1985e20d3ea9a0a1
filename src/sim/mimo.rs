//! The exact sampled-data closed loop of a multivariable plant under
//! decentralized control: every channel `gᵢⱼ` discretized exactly with its
//! own dead time ([`PlantStepper`]: ZOH, the delay as samples plus its
//! fraction), output `i` the sum of its row's channels, and a
//! [`MultiController`] from `r` and `y` to `u` (loop `i` on output and
//! input `i`: the pairing is the diagonal).

use std::vec::Vec;

use super::{first_sample_at, setpoint_at, Location, PlantStepper, SetpointStep};
use crate::error::Error;
use crate::mimo::MultiController;
use crate::poly::TransferFunction;
use crate::poly::TransferMatrix;

/// The longest run (samples): its columns within a few hundred megabytes.
pub const MAX_SAMPLES: usize = 10_000_000;

/// A multivariable run: per loop `i`, the set point `r[i]`, the output
/// `y[i]` and the input `u[i]` at the instants `t` (CSV columns `t, r1,
/// y1, u1, r2, y2, u2, …`).
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MimoRun {
    /// The sample instants (s).
    pub t: Vec<f64>,
    /// Each loop's set point.
    pub r: Vec<Vec<f64>>,
    /// Each loop's output (before the sample's input acts).
    pub y: Vec<Vec<f64>>,
    /// Each loop's input, held over the period.
    pub u: Vec<Vec<f64>>,
}

impl MimoRun {
    /// Loop `i`'s integral of the absolute control error `Σ|rᵢ − yᵢ|·Ts`.
    pub fn iae(&self, i: usize) -> f64 {
        let ts = match (self.t.first(), self.t.get(1)) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        match (self.r.get(i), self.y.get(i)) {
            (Some(r), Some(y)) => r.iter().zip(y).map(|(r, y)| (r - y).abs()).sum::<f64>() * ts,
            _ => f64::NAN,
        }
    }

    /// The interaction of a set-point step at `at` (s): the largest
    /// deviation of every output from its value at the step, from the step
    /// to `until` (the next set-point change, or the run's end).
    pub fn interaction(&self, at: f64, until: f64) -> Vec<f64> {
        let ts = match (self.t.first(), self.t.get(1)) {
            (Some(a), Some(b)) => b - a,
            _ => return Vec::new(),
        };
        let (k0, k1) = (first_sample_at(at, ts), first_sample_at(until, ts));
        self.y
            .iter()
            .map(|y| {
                let base = y.get(k0).copied().unwrap_or(f64::NAN);
                y.iter()
                    .take(k1)
                    .skip(k0)
                    .fold(0.0f64, |m, v| m.max((v - base).abs()))
            })
            .collect()
    }
}

/// A step load on one loop: at its input (added to `uᵢ` where the plant
/// receives it) or at its output (added to `yᵢ`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LoopLoad {
    /// The loop (0-based).
    #[cfg_attr(feature = "serde", serde(rename = "loop"))]
    pub loop_index: usize,
    /// `input` or `output`.
    pub location: Location,
    /// The step's size.
    pub value: f64,
    /// When (s).
    pub at: f64,
}

/// A measured disturbance entering every output through its own channel
/// (Wood–Berry's feed: `[3.8e^-8.1s/(14.9s+1); 4.9e^-3.4s/(13.2s+1)]`),
/// driven by steps of the disturbance variable.
#[derive(Debug, Clone, PartialEq)]
pub struct DisturbanceVector {
    /// Output `i`'s channel from the disturbance.
    pub channels: Vec<TransferFunction>,
    /// The disturbance variable's steps.
    pub steps: Vec<SetpointStep>,
}

/// A channel's dead time changing during the run (the process changes).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ChannelDeadTime {
    /// The output's row (0-based).
    pub row: usize,
    /// The input's column (0-based).
    pub col: usize,
    /// The new dead time (s; its fraction of a sample the same as before).
    pub dead_time: f64,
    /// When (s).
    pub at: f64,
}

/// An operator's switch of one loop: to manual with the plant's input held
/// at a value, or back to automatic (bumpless: the loop's controller
/// tracked the held value).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LoopMode {
    /// The loop (0-based).
    #[cfg_attr(feature = "serde", serde(rename = "loop"))]
    pub loop_index: usize,
    /// When (s).
    pub at: f64,
    /// Manual with this input, or automatic (`None`).
    pub manual: Option<f64>,
}

/// What happens to a multivariable loop besides its set points.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MimoEvents {
    /// Step loads per loop.
    pub loads: Vec<LoopLoad>,
    /// A disturbance through its own channels.
    pub disturbance: Option<DisturbanceVector>,
    /// Changes of a channel's dead time.
    pub dead_times: Vec<ChannelDeadTime>,
    /// Loops switched to manual and back.
    pub modes: Vec<LoopMode>,
    /// White measurement noise on every output (its standard deviation;
    /// the controller sees it, the recorded `y` does not), from `seed`.
    pub noise: f64,
    /// The noise generator's seed.
    pub seed: u64,
    /// Every input limited to `(min, max)` where the plant receives it (the
    /// loops take the limited value as external reset feedback: no windup).
    pub actuator: Option<(f64, f64)>,
}

/// Runs `controller` (loop `i` closes output `i` through input `i`) on
/// `plant` every `ts` seconds for `duration`, the set points
/// `setpoints[i]` per loop (absent: zero) and `events`, from rest.
pub fn simulate_mimo(
    plant: &TransferMatrix,
    controller: &mut dyn MultiController<f64>,
    setpoints: &[Vec<SetpointStep>],
    events: &MimoEvents,
    ts: f64,
    duration: f64,
) -> Result<MimoRun, Error> {
    let n = plant.size();
    if controller.loops() != n {
        return Err(Error::OutOfRange("one controller loop per output"));
    }
    crate::real::positive(ts, "ts")?;
    crate::real::positive(duration, "duration")?;
    // the instants 0, ts, …, duration, as a single loop's run has them
    let steps = num_traits::ToPrimitive::to_usize(&(duration / ts).round())
        .filter(|s| *s < MAX_SAMPLES)
        .ok_or(Error::OutOfRange("duration/ts"))?
        .saturating_add(1);
    crate::real::non_negative(events.noise, "noise")?;
    if let Some((lo, hi)) = events.actuator {
        if !(lo <= hi) {
            return Err(Error::InvalidLimits("actuator"));
        }
    }
    if events.modes.iter().any(|m| m.loop_index >= n) {
        return Err(Error::OutOfRange(
            "a mode switch of a loop the plant does not have",
        ));
    }
    if events
        .modes
        .iter()
        .any(|m| m.manual.is_some_and(|v| !v.is_finite()))
    {
        return Err(Error::NonFinite("manual"));
    }
    if events.loads.iter().any(|l| l.loop_index >= n) {
        return Err(Error::OutOfRange(
            "a load on a loop the plant does not have",
        ));
    }
    if events.loads.iter().any(|l| l.location == Location::Inner) {
        return Err(Error::Unsupported(
            "a matrix plant's loads act at a loop's input or output",
        ));
    }
    controller.reset_to_rest();
    let mut channels = Vec::new();
    channels
        .try_reserve_exact(n * n)
        .map_err(|_| Error::OutOfMemory("channels"))?;
    for i in 0..n {
        for j in 0..n {
            let g = plant
                .get(i, j)
                .ok_or(Error::OutOfRange("the matrix's size"))?;
            let room = events
                .dead_times
                .iter()
                .filter(|e| e.row == i && e.col == j)
                .fold(0.0f64, |m, e| m.max(e.dead_time));
            channels.push(PlantStepper::with_room(g, ts, room)?);
        }
    }
    if events.dead_times.iter().any(|e| e.row >= n || e.col >= n) {
        return Err(Error::OutOfRange(
            "a dead-time change of a channel the plant does not have",
        ));
    }
    let mut feed =
        match &events.disturbance {
            Some(d) if d.channels.len() != n => return Err(Error::Unsupported(
                "a disturbance vector needs one channel per output (as many rows as the plant has)",
            )),
            Some(d) => d
                .channels
                .iter()
                .map(|g| PlantStepper::new(g, ts))
                .collect::<Result<Vec<_>, _>>()?,
            None => Vec::new(),
        };
    let column = || -> Result<Vec<f64>, Error> {
        let mut v = Vec::new();
        v.try_reserve_exact(steps)
            .map_err(|_| Error::OutOfMemory("the run's columns"))?;
        Ok(v)
    };
    let mut run = MimoRun {
        t: column()?,
        ..MimoRun::default()
    };
    for _ in 0..n {
        run.r.push(column()?);
        run.y.push(column()?);
        run.u.push(column()?);
    }
    let load = |i: usize, at: Location, t: f64| -> f64 {
        events
            .loads
            .iter()
            .filter(|l| l.loop_index == i && l.location == at)
            .map(|l| {
                setpoint_at(
                    &[SetpointStep {
                        value: l.value,
                        at: l.at,
                    }],
                    t,
                )
            })
            .sum()
    };
    let mut pending: Vec<ChannelDeadTime> = events.dead_times.clone();
    pending.sort_by(|a, b| a.at.total_cmp(&b.at));
    let mut pending = pending.into_iter().peekable();
    let mut modes: Vec<LoopMode> = events.modes.clone();
    modes.sort_by(|a, b| a.at.total_cmp(&b.at));
    let mut modes = modes.into_iter().peekable();
    let mut manual: Vec<Option<f64>> = std::vec![None; n];
    let mut noise = super::Noise::new(events.seed);
    let mut measured = std::vec![0.0; n];
    let (mut r, mut y, mut u) = (std::vec![0.0; n], std::vec![0.0; n], std::vec![0.0; n]);
    for k in 0..steps {
        let t = k as f64 * ts;
        while let Some(e) = pending.next_if(|e| t >= e.at - 1e-9 * ts) {
            if let Some(ch) = channels.get_mut(e.row * n + e.col) {
                ch.set_dead_time(e.dead_time / ts)?;
            }
        }
        run.t.push(t);
        for (i, (ri, yi)) in r.iter_mut().zip(y.iter_mut()).enumerate() {
            *yi = channels
                .get(i * n..(i + 1) * n)
                .unwrap_or_default()
                .iter()
                .map(PlantStepper::output)
                .sum::<f64>()
                + feed.get(i).map_or(0.0, PlantStepper::output)
                + load(i, Location::Output, t);
            *ri = setpoints.get(i).map_or(0.0, |s| setpoint_at(s, t));
        }
        while let Some(m) = modes.next_if(|m| t >= m.at - 1e-9 * ts) {
            if let Some(x) = manual.get_mut(m.loop_index) {
                *x = m.manual;
            }
        }
        for (m, yi) in measured.iter_mut().zip(&y) {
            *m = if events.noise > 0.0 {
                yi + events.noise * noise.gaussian()
            } else {
                *yi
            };
        }
        controller.update(&r, &measured, &mut u);
        // a loop in manual: the plant receives the held value; an actuator
        // limits what it receives; the controller then tracks it
        for (i, (ui, held)) in u.iter_mut().zip(&manual).enumerate() {
            let given = held.unwrap_or(*ui);
            let applied = match events.actuator {
                Some((lo, hi)) => given.max(lo).min(hi),
                None => given,
            };
            if held.is_some() {
                *ui = applied;
                controller.applied(i, applied, crate::operate::Tracking::Full);
            } else if applied != *ui {
                *ui = applied;
                controller.applied(i, applied, crate::operate::Tracking::Reset);
            }
        }
        for (((col_r, col_y), col_u), ((ri, yi), ui)) in run
            .r
            .iter_mut()
            .zip(run.y.iter_mut())
            .zip(run.u.iter_mut())
            .zip(r.iter().zip(&y).zip(&u))
        {
            col_r.push(*ri);
            col_y.push(*yi);
            col_u.push(*ui);
        }
        for (k, ch) in channels.iter_mut().enumerate() {
            let j = k % n;
            ch.advance(u.get(j).copied().unwrap_or(0.0) + load(j, Location::Input, t));
        }
        if let Some(d) = &events.disturbance {
            let v = setpoint_at(&d.steps, t);
            feed.iter_mut().for_each(|f| f.advance(v));
        }
    }
    Ok(run)
}

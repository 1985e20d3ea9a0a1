//! The figures of a run, as the report, the CLI and Python print them.

use std::borrow::Cow;
use std::vec::Vec;

use crate::error::Error;
use crate::metrics::{step_info, Indices, IntegralIndices, StepInfo};
use crate::sim::{Disturbance, Location, SetpointStep, SimResult};

/// The metrics of a run, with the key names of the JSON report and Python:
/// the integral indices of the error and the step information of the
/// response, one flat object (`iae`, …, `tv`, `rise_time`, …, `peak_time`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Metrics {
    /// IAE, ISE, ITAE, ITSE and TV.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub indices: Indices<f64>,
    /// Rise and settling times, overshoot, peak (as MATLAB's `stepinfo`).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub step: StepInfo,
}

impl Metrics {
    /// Every figure with its report name, in report order: the integral
    /// indices, then the step information.
    pub fn fields(&self) -> impl Iterator<Item = (&'static str, f64)> {
        self.indices.fields().into_iter().chain(self.step.fields())
    }
}

/// The columns of a run the figures read, borrowed (from a [`SimResult`],
/// or from arrays that hold its columns).
#[derive(Debug, Clone, Copy)]
pub struct Columns<'a> {
    /// Time.
    pub t: &'a [f64],
    /// Set point.
    pub r: &'a [f64],
    /// Plant output.
    pub y: &'a [f64],
    /// Controller output.
    pub u: &'a [f64],
    /// Rows per controller sample.
    pub substeps: usize,
    /// When the output diverged.
    pub diverged_at: Option<f64>,
}

impl SimResult {
    /// The columns the figures read.
    pub fn columns(&self) -> Columns<'_> {
        Columns {
            t: &self.t,
            r: &self.r,
            y: &self.y,
            u: &self.u,
            substeps: self.substeps,
            diverged_at: self.diverged_at,
        }
    }
}

/// A run's figures: the metrics on `e = r − y` and on the delayed reference
/// (`e = r(t − θm) − y`, time from `θm`, `model_delay` = θm), and the figures
/// of each set-point step and disturbance.
pub fn measure(
    res: &Columns<'_>,
    setpoint: &[SetpointStep],
    disturbances: &[Disturbance],
    ts: f64,
    model_delay: f64,
) -> Result<(Metrics, Metrics, Vec<Event>), Error> {
    let next_event = next_event(setpoint, disturbances);
    let events = events(res, setpoint, disturbances, ts);
    // the two conventions are independent passes over the signals
    let both = || {
        (
            metrics(res, setpoint, next_event, ts, 0.0),
            metrics(res, setpoint, next_event, ts, model_delay),
        )
    };
    // two threads only pay off for long runs: waking a worker costs more
    // than a pass over some hundred thousand samples
    #[cfg(feature = "parallel")]
    let (m0, m1) = if res.y.len() > 500_000 {
        rayon::join(
            || metrics(res, setpoint, next_event, ts, 0.0),
            || metrics(res, setpoint, next_event, ts, model_delay),
        )
    } else {
        both()
    };
    #[cfg(not(feature = "parallel"))]
    let (m0, m1) = both();
    Ok((m0?, m1?, events))
}

/// Where the first set-point step's segment ends: at the next event (a
/// later set-point step or a disturbance), or never.
pub fn next_event(setpoint: &[SetpointStep], disturbances: &[Disturbance]) -> f64 {
    let first = setpoint.iter().map(|s| s.at).fold(f64::INFINITY, f64::min);
    setpoint
        .iter()
        .map(|s| s.at)
        .chain(disturbances.iter().map(|d| d.at))
        .filter(|t| *t > first + 1e-9 * first.abs().max(1.0))
        .fold(f64::INFINITY, f64::min)
}

/// The stability verdict of a run, from its boundedness, never from where
/// it settled (a P-only loop settles off the set point and is stable): it did
/// not diverge, and its output comes to rest — the swing (max − min) of its
/// last tenth is within 2 % of the largest |y| and no larger than the tenth
/// before (to rounding) — or its oscillation is still decaying (the last fifth's swing below
/// 0.9 of the fifth before). A ramp or a sustained oscillation fails both.
pub fn stable(out: &super::RunOutput) -> bool {
    settles(&out.result.y) && out.result.diverged_at.is_none()
}

/// The test of [`stable`] on an output sequence.
pub fn settles(y: &[f64]) -> bool {
    let n = y.len();
    if n < 10 || y.iter().any(|v| !v.is_finite()) {
        return false;
    }
    let swing = |a: usize, b: usize| y.get(a..b).map_or(0.0, swing);
    let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-12);
    // growth beyond rounding (1e-9 of the response) is not rest
    let at_rest = swing(n * 9 / 10, n) <= 0.02 * scale
        && swing(n * 9 / 10, n) <= swing(n * 8 / 10, n * 9 / 10) + 1e-9 * scale;
    at_rest || swing(n * 4 / 5, n) < 0.9 * swing(n * 3 / 5, n * 4 / 5)
}

/// The swing of a signal, `max − min` (0 for none).
pub fn swing(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.iter().fold(f64::MIN, |m, x| m.max(*x)) - v.iter().fold(f64::MAX, |m, x| m.min(*x))
}

/// Whether the output `y` of a run of `duration` with step information
/// `metrics` has come to rest: a settling time before the last tenth of the
/// run, or (a loop that rests off its set point, e.g. P-only) a last tenth
/// that swings by less than 0.1 % of the largest |y|.
pub fn settled(y: &[f64], metrics: &Metrics, duration: f64) -> bool {
    let n = y.len();
    if metrics.step.settling_time <= 0.9 * duration {
        return true;
    }
    let swing = swing(y.get(n - n / 10..).unwrap_or(&[]));
    let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-12);
    n >= 10 && swing <= 1e-3 * scale
}

/// Metrics of `res` with the error `e = r(t − shift) − y`, time counted from
/// `shift` (0 for the plain convention; the model dead time `θm` for the
/// delayed-reference convention of Bag (2022) ch. 5). The integral indices
/// cover the whole run; the step information covers the first set-point
/// step up to the next event (set-point step or disturbance, `events`' start
/// times), so a second step or a load does not count as its overshoot.
pub fn metrics(
    res: &Columns<'_>,
    setpoint: &[SetpointStep],
    next_event: f64,
    ts: f64,
    shift: f64,
) -> Result<Metrics, Error> {
    use std::borrow::Cow;
    // the controller's samples only, whatever the sub-steps
    let stride = res.substeps.max(1);
    let first_row = res
        .t
        .iter()
        .position(|t| *t >= shift - 1e-9 * ts)
        .unwrap_or(res.t.len());
    let first = first_row.div_ceil(stride).saturating_mul(stride);
    fn rows(v: &[f64], first: usize, stride: usize) -> Cow<'_, [f64]> {
        let tail = v.get(first..).unwrap_or(&[]);
        if stride == 1 {
            Cow::Borrowed(tail)
        } else {
            Cow::Owned(tail.iter().copied().step_by(stride).collect())
        }
    }
    let (tt, yy, uu) = (
        rows(res.t, first, stride),
        rows(res.y, first, stride),
        rows(res.u, first, stride),
    );
    let nan = f64::NAN;
    let unbounded = Indices {
        iae: nan,
        ise: nan,
        itae: nan,
        itse: nan,
        tv: nan,
    };
    // no sample in the window (a run that diverged before `shift`): no
    // figure, never a 0 that reads as a perfect loop
    if tt.len() < 2 {
        return Ok(Metrics {
            indices: unbounded,
            step: step_info(&[], &[], 0.0, nan, shift),
        });
    }
    let mut ind = IntegralIndices::new(ts)?;
    let mut steps: Vec<SetpointStep> = setpoint.to_vec();
    steps.sort_by(|a, b| a.at.total_cmp(&b.at));
    let mut next = 0usize;
    let mut r = 0.0;
    for ((t, y), u) in tt.iter().zip(yy.iter()).zip(uu.iter()) {
        let tr = t - shift;
        while let Some(s) = steps.get(next) {
            if s.at <= tr + 1e-9 * tr.abs().max(1.0) {
                r = s.value;
                next = next.saturating_add(1);
            } else {
                break;
            }
        }
        ind.push(r - y, *u);
    }
    // the integrals of a run that diverged grow without bound: no number
    // measures them (the sum up to the divergence would read as a figure)
    let indices = if res.diverged_at.is_some() {
        unbounded
    } else {
        ind.value()
    };
    let y0 = yy.first().copied().unwrap_or(0.0);
    let y_final = steps.last().map_or(0.0, |s| s.value);
    let first_step = steps.first().map_or(0.0, |s| s.at.max(0.0));
    let from = tt
        .iter()
        .position(|t| t - shift >= first_step - 1e-9 * ts)
        .unwrap_or(0);
    let to = tt
        .iter()
        .position(|t| t - shift >= next_event - 1e-9 * ts)
        .unwrap_or(tt.len())
        .max(from);
    // the first step's own target: the value it steps to
    let y_final = steps.first().map_or(y_final, |s| s.value);
    // nor do the step's figures of a loop that diverged: what the data
    // hold before the end are the first swings of the divergence (a "rise
    // time" of the first crossing, an "overshoot" of thousands of percent)
    let s: StepInfo = if res.diverged_at.is_some() {
        step_info(&[], &[], 0.0, nan, shift)
    } else {
        step_info(
            tt.get(from..to).unwrap_or(&[]),
            yy.get(from..to).unwrap_or(&[]),
            y0,
            y_final,
            shift,
        )
    };
    Ok(Metrics { indices, step: s })
}

/// The figures of one event of a run, from its start to the next event (or
/// the end): step information for a set-point step, load-rejection figures
/// for a disturbance, as the thesis's tables report "without" and "with load
/// disturbance" (Bag (2022) ch. 5).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
pub enum Event {
    /// A set-point step.
    Setpoint(SetpointEvent),
    /// A disturbance (a load at the input, or at the output).
    Disturbance(DisturbanceEvent),
}

/// A set-point step and the response to it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SetpointEvent {
    /// When the step happens (s).
    pub at: f64,
    /// The end of its segment: the next event or the end of the run (s).
    pub until: f64,
    /// The value the set point steps to.
    pub value: f64,
    /// `∫|r − y|dt` over the segment.
    pub iae: f64,
    /// MATLAB's `stepinfo` of the segment, times from the step.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub step: StepInfo,
}

/// A disturbance and how the loop rejects it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DisturbanceEvent {
    /// When it starts (s).
    pub at: f64,
    /// The end of its segment (s).
    pub until: f64,
    /// Where it acts.
    pub location: Location,
    /// Its size (step), slope (ramp) or amplitude (sine).
    pub value: f64,
    /// The largest deviation of `y` from its value when the disturbance
    /// started, with its sign.
    pub peak_deviation: f64,
    /// When that peak is reached, from the start (s).
    pub peak_time: f64,
    /// Time from the start after which `y` stays within 2 % of the set point
    /// (2 % of the peak deviation when the set point is 0) of its value
    /// before the disturbance (s); NaN if it does not recover in the segment.
    pub recovery_time: f64,
    /// `∫|r − y|dt` over the segment.
    pub iae: f64,
}

/// The per-event figures of a run: one entry per set-point step and per
/// disturbance, in time order, each over its segment of the controller's
/// samples (every `substeps`-th row), `ts` apart.
pub fn events(
    res: &Columns<'_>,
    setpoint: &[SetpointStep],
    disturbances: &[Disturbance],
    ts: f64,
) -> Vec<Event> {
    events_within(res, setpoint, disturbances, &[], ts)
}

/// [`events`] whose segments also end at the instants `boundaries` (the
/// other loops' events of a multivariable run, which disturb this one).
pub fn events_within(
    res: &Columns<'_>,
    setpoint: &[SetpointStep],
    disturbances: &[Disturbance],
    boundaries: &[f64],
    ts: f64,
) -> Vec<Event> {
    let stride = res.substeps.max(1);
    // the controller's samples: the columns themselves without sub-steps
    fn every(v: &[f64], stride: usize) -> Cow<'_, [f64]> {
        if stride == 1 {
            Cow::Borrowed(v)
        } else {
            Cow::Owned(v.iter().copied().step_by(stride).collect())
        }
    }
    let (t, y, r) = (
        every(res.t, stride),
        every(res.y, stride),
        every(res.r, stride),
    );
    let end = t.last().copied().unwrap_or(0.0);
    let diverged = res.diverged_at.is_some();
    let mut starts: Vec<f64> = setpoint
        .iter()
        .map(|s| s.at)
        .chain(disturbances.iter().map(|d| d.at))
        .chain(boundaries.iter().copied())
        .collect();
    starts.sort_by(f64::total_cmp);
    // the next start after `at`, by bisection: linear in the events overall
    let until = |at: f64| {
        let i = starts.partition_point(|s| *s <= at + 1e-9 * at.abs().max(1.0));
        starts.get(i).copied().unwrap_or(end).min(end)
    };
    let index = |at: f64| t.partition_point(|x| *x < at - 1e-9 * at.abs().max(1.0));
    // the run's own streaming indices over the segment (trapezoidal IAE)
    let iae = |a: usize, b: usize| -> f64 {
        let (Ok(mut ind), Some(rs), Some(ys)) =
            (IntegralIndices::new(ts), r.get(a..b), y.get(a..b))
        else {
            return f64::NAN;
        };
        for (r, y) in rs.iter().zip(ys) {
            ind.push(r - y, 0.0);
        }
        ind.value().iae
    };
    let mut out: Vec<(f64, Event)> = Vec::new();
    for s in setpoint {
        if s.at > end {
            continue;
        }
        let (a, b) = (index(s.at), index(until(s.at)).max(index(s.at)));
        let b = if until(s.at) >= end { t.len() } else { b };
        let y0 = a
            .checked_sub(1)
            .and_then(|i| y.get(i))
            .or(y.get(a))
            .copied()
            .unwrap_or(0.0);
        // no window of a loop that diverged measures the loop (its first
        // swings already grow)
        let cut = diverged;
        let b = if cut { a } else { b };
        let step = step_info(
            t.get(a..b).unwrap_or(&[]),
            y.get(a..b).unwrap_or(&[]),
            y0,
            s.value,
            s.at,
        );
        out.push((
            s.at,
            Event::Setpoint(SetpointEvent {
                at: s.at,
                until: until(s.at),
                value: s.value,
                iae: if cut { f64::NAN } else { iae(a, b) },
                step,
            }),
        ));
    }
    for d in disturbances {
        if d.at > end {
            continue;
        }
        let a = index(d.at);
        let b = if until(d.at) >= end {
            t.len()
        } else {
            index(until(d.at)).max(a)
        };
        let b = if diverged { a } else { b };
        let cut = diverged;
        // the output just before: an output disturbance shows at its own sample
        let y_ref = a
            .checked_sub(1)
            .and_then(|i| y.get(i))
            .or(y.get(a))
            .copied()
            .unwrap_or(f64::NAN);
        let r_ref = r.get(a).copied().unwrap_or(0.0);
        let (ts, ys) = (t.get(a..b).unwrap_or(&[]), y.get(a..b).unwrap_or(&[]));
        let (mut peak, mut peak_at) = (0.0f64, f64::NAN);
        for (ti, yi) in ts.iter().zip(ys) {
            if (yi - y_ref).abs() > peak.abs() {
                peak = yi - y_ref;
                peak_at = ti - d.at;
            }
        }
        let band = if r_ref != 0.0 {
            0.02 * r_ref.abs()
        } else {
            0.02 * peak.abs()
        };
        let recovery_time = match ys.iter().rposition(|yi| (yi - y_ref).abs() > band) {
            None => 0.0,
            Some(i) if i + 1 >= ys.len() => f64::NAN,
            Some(i) => ts.get(i + 1).map_or(f64::NAN, |x| x - d.at),
        };
        out.push((
            d.at,
            Event::Disturbance(DisturbanceEvent {
                at: d.at,
                until: until(d.at),
                location: d.location,
                value: d.value,
                peak_deviation: if cut { f64::NAN } else { peak },
                peak_time: if cut { f64::NAN } else { peak_at },
                recovery_time: if cut { f64::NAN } else { recovery_time },
                iae: if cut { f64::NAN } else { iae(a, b) },
            }),
        ));
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out.into_iter().map(|(_, e)| e).collect()
}

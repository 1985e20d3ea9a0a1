//! The sample loop of a closed-loop run.
//!
//! The schedules (set point, disturbances, the operator's actions) are
//! events at sample indices: the loop runs from one event to the next as a
//! segment whose scheduled inputs are constant, so a sample pays for no
//! schedule. The loop is compiled per controller type and for two
//! questions answered before the first sample: is there an operator
//! (`OPERATED`: modes, an outside actuator, reset feedback, a set-point
//! ramp), and is the run plain (`PLAIN`: one plant sampled in one piece per
//! period, no sub-steps, no noise, no ramp or sine disturbance). A plain
//! run's sample is the controller's update and one step of the plant.

use std::vec::Vec;

use super::config::{Action, Noise, PlantParameter, Process, SimConfig};
use super::drift::Drifts;
use super::result::{Columns, Zeroed};
use super::schedule::Track;
use super::SimResult;
use crate::error::Error;
use crate::operate::{feed_back, in_mode, Mode};
use crate::{controller::CascadeControl, controller::Introspect, operate::Operate};

/// What a run prepared before its first sample.
pub(super) struct Run<'a> {
    /// Controller samples.
    pub(super) n: usize,
    /// Rows a sample: the plant's output at the sample and at `m − 1`
    /// sub-step instants after it.
    pub(super) m: usize,
    pub(super) process: Process,
    /// The plant's outputs at the sub-step instants of the current period.
    pub(super) sub: Vec<f64>,
    pub(super) noise: Noise,
    /// The disturbances at the plant input (`d`, `d2`), at the output
    /// (`d_out`, `d1`) and at the secondary output (`d_inner`, `d0`).
    pub(super) inputs: Track<'a>,
    pub(super) outputs: Track<'a>,
    pub(super) middles: Track<'a>,
    /// The set point's steps as `(first sample, value)`.
    pub(super) steps: Vec<(usize, f64)>,
    /// The operator's actions as `(first sample, action)`.
    pub(super) ops: Vec<(usize, Action)>,
    pub(super) flags: Flags,
    /// The load columns the sizing left at zero.
    pub(super) zeroed: Zeroed,
}

/// What a run's samples check, fixed before the first.
#[derive(Debug, Clone, Copy)]
pub(super) struct Flags {
    /// The sample period (s).
    pub(super) ts: f64,
    /// An output beyond this is divergence.
    pub(super) bound: f64,
    /// The columns recorded (`all`: not only `y` and `u`; `cascade`: the
    /// process is a cascade, `y2` measured and recorded).
    pub(super) columns: Columns,
    /// The largest set-point change per sample the controller sees (∞: none).
    pub(super) ramp: f64,
    /// The plant may receive another value than the controller's output.
    pub(super) applies: bool,
    /// The controller's output is limited (`u_min`, `u_max` not infinite).
    pub(super) limited: bool,
}

impl Run<'_> {
    /// A plain run: see the module's documentation.
    pub(super) fn is_plain(&self, cfg: &SimConfig) -> bool {
        let one_piece = match &self.process {
            Process::Single(p) => p.is_one_piece(),
            Process::Cascade { .. } => false,
        };
        one_piece
            && cfg.noise == 0.0
            && cfg.quantization == 0.0
            && self.inputs.steps_only()
            && self.outputs.steps_only()
            && self.middles.is_empty()
    }
}

/// The operator's side of the loop: the mode, the value the plant received
/// last, the set point the controller sees.
struct Operator {
    mode: Mode<f64>,
    applied: Option<f64>,
    r_ctl: f64,
}

/// The values of one row of the record.
struct Row {
    t: f64,
    r: f64,
    y: f64,
    u: f64,
    u_plant: f64,
    y2: f64,
    d_in: f64,
    d_out: f64,
    d_mid: f64,
}

/// The columns of a record beyond `t`, `y` and `u`.
struct Others<'a> {
    u_applied: &'a mut Vec<f64>,
    y2: &'a mut Vec<f64>,
    r: &'a mut Vec<f64>,
    d: &'a mut Vec<f64>,
    d_out: &'a mut Vec<f64>,
    d_inner: &'a mut Vec<f64>,
    signals: &'a mut Vec<(std::string::String, Vec<f64>)>,
}

/// `res` as its `t`, `y`, `u` columns and the others.
fn split(res: &mut SimResult) -> ([&mut Vec<f64>; 3], Others<'_>) {
    let SimResult {
        t,
        y,
        u,
        u_applied,
        y2,
        r,
        d,
        d_out,
        d_inner,
        signals,
        ..
    } = res;
    let others = Others {
        u_applied,
        y2,
        r,
        d,
        d_out,
        d_inner,
        signals,
    };
    ([t, y, u], others)
}

/// Writes `row` as row `k` of the columns beyond `t`, `y`, `u` the run
/// records (sized to every row before the run: [`SimResult::size`]); `sig`
/// holds the controller's signals, with every column.
#[inline(always)]
fn record_others<const OPERATED: bool>(f: Flags, o: &mut Others, k: usize, row: &Row, sig: &[f64]) {
    record_varying::<OPERATED>(f, o, k, row, sig);
    if f.columns.all {
        let put = |col: &mut Vec<f64>, v: f64| {
            if let Some(x) = col.get_mut(k) {
                *x = v;
            }
        };
        put(o.r, row.r);
        put(o.d, row.d_in);
        put(o.d_out, row.d_out);
        if f.columns.cascade {
            put(o.d_inner, row.d_mid);
        }
    }
}

/// The columns of [`record_others`] that change within a segment of a
/// plain run (the applied input and the controller's signals; the set
/// point and the loads are the segment's constants, [`fill_segment`]).
#[inline(always)]
fn record_varying<const OPERATED: bool>(
    f: Flags,
    o: &mut Others,
    k: usize,
    row: &Row,
    sig: &[f64],
) {
    let put = |col: &mut Vec<f64>, v: f64| {
        if let Some(x) = col.get_mut(k) {
            *x = v;
        }
    };
    if OPERATED && f.applies {
        put(o.u_applied, row.u_plant);
    }
    if f.columns.cascade {
        put(o.y2, row.y2);
    }
    if f.columns.all {
        for ((_, v), x) in o.signals.iter_mut().zip(sig) {
            put(v, *x);
        }
    }
}

/// The set point and the loads of a plain run's segment `from..to`, each a
/// constant there: filled at once (a load column the run's sizing left at
/// zero is not touched while the load is zero, so its pages are never
/// written).
#[inline]
fn fill_segment(
    o: &mut Others,
    zeroed: Zeroed,
    (from, to): (usize, usize),
    r: f64,
    d_in: f64,
    d_out: f64,
) {
    for (col, v, zero) in [
        (&mut *o.r, r, false),
        (&mut *o.d, d_in, zeroed.d),
        (&mut *o.d_out, d_out, zeroed.d_out),
    ] {
        if zero && v == 0.0 {
            continue;
        }
        if let Some(rows) = col.get_mut(from..to) {
            rows.fill(v);
        }
    }
}

/// [`record_others`] with `t`, `y` and `u`.
#[inline(always)]
fn record<const OPERATED: bool>(f: Flags, res: &mut SimResult, k: usize, row: &Row, sig: &[f64]) {
    let ([t, y, u], mut others) = split(res);
    for (col, v) in [(t, row.t), (y, row.y), (u, row.u)] {
        if let Some(x) = col.get_mut(k) {
            *x = v;
        }
    }
    record_others::<OPERATED>(f, &mut others, k, row, sig);
}

/// The controller's sample for the measurements `y` (and `y2` for a
/// cascade): its output after the limits, and what the plant receives (the
/// operator's value in manual or tracking — the controller follows it —
/// then an outside actuator's limit).
#[inline(always)]
fn control<C, const OPERATED: bool>(
    controller: &mut C,
    cfg: &SimConfig,
    f: Flags,
    op: &mut Operator,
    y: f64,
    y2: Option<f64>,
) -> (f64, f64)
where
    C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized,
{
    if OPERATED && cfg.reset_feedback {
        feed_back(controller, op.mode, op.applied);
    }
    let r = op.r_ctl;
    let mut u = match y2 {
        Some(y2) => controller.update_cascade(r, y, y2),
        None => controller.update(r, y),
    };
    if OPERATED && cfg.background {
        controller.design();
    }
    if f.limited {
        u = crate::real::clamp(u, cfg.u_min, cfg.u_max);
    }
    let mut u_plant = u;
    if OPERATED && f.applies {
        u = in_mode(controller, op.mode, u);
        u_plant = match cfg.actuator {
            Some((lo, hi)) => u.max(lo).min(hi),
            None => u,
        };
        op.applied = Some(u_plant);
    }
    (u, u_plant)
}

/// Runs the samples of `run`, recording into `res` (sized to every row);
/// stops early (with `res.diverged_at` set) when the output diverges.
/// Returns the number of rows written.
pub(super) fn samples<C, const OPERATED: bool, const PLAIN: bool>(
    run: &mut Run,
    controller: &mut C,
    cfg: &SimConfig,
    res: &mut SimResult,
) -> Result<usize, Error>
where
    C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized,
{
    let mut op = Operator {
        mode: Mode::Auto,
        applied: None,
        r_ctl: 0.0,
    };
    let (mut next_step, mut next_op) = (0usize, 0usize);
    let mut r = 0.0;
    let mut sig = std::vec![0.0; controller.signal_names().len()];
    let ts = run.flags.ts;
    let mut drifts = Drifts::default();
    let mut i = 0usize;
    while i < run.n {
        if drifts.active() {
            drifts.advance(&mut run.process)?;
        }
        // what happens at sample i
        while let Some(&(_, value)) = run.steps.get(next_step).filter(|e| e.0 <= i) {
            r = value;
            next_step = next_step.saturating_add(1);
        }
        while let Some(&(_, action)) = run.ops.get(next_op).filter(|e| OPERATED && e.0 <= i) {
            match action {
                Action::Manual(v) => op.mode = Mode::Manual(v),
                Action::Track(v) => op.mode = Mode::Track(v),
                Action::Auto => op.mode = Mode::Auto,
                Action::DeadTime(d) => controller.set_dead_time(d / ts)?,
                Action::DeadTimeRamp(d, rate) => controller.ramp_dead_time(d / ts, rate)?,
                Action::PlantDeadTime(d) => {
                    drifts.stop(PlantParameter::DeadTime);
                    run.process.set_dead_time(d / ts)?;
                }
                Action::PlantGain(k) => {
                    drifts.stop(PlantParameter::Gain);
                    run.process.set_gain(k)?;
                }
                Action::PlantLag(tau) => {
                    drifts.stop(PlantParameter::Lag);
                    run.process.set_lag(tau)?;
                }
                Action::PlantDrift(what, to, rate) => {
                    drifts.start(&run.process, what, to, rate, ts)?;
                }
                Action::Retune(g, v) => controller.retune(g, v)?,
                Action::Adapt(on) => controller.set_adapting(on)?,
            }
            next_op = next_op.saturating_add(1);
        }
        for t in [&mut run.inputs, &mut run.outputs, &mut run.middles] {
            t.advance_to(i);
        }
        // the next event ends the segment
        let end = [
            run.steps.get(next_step).map(|e| e.0),
            run.ops.get(next_op).filter(|_| OPERATED).map(|e| e.0),
            run.inputs.next_at(),
            run.outputs.next_at(),
            run.middles.next_at(),
        ]
        .into_iter()
        .flatten()
        .fold(run.n, usize::min)
        .max(i.saturating_add(1));
        // a drift moves the process every sample
        let end = if drifts.active() {
            i.saturating_add(1)
        } else {
            end
        };
        let done = segment::<C, OPERATED, PLAIN>(
            run,
            controller,
            cfg,
            res,
            &mut op,
            (i, end),
            r,
            &mut sig,
        );
        match done {
            Ok(()) => i = end,
            Err(at) => {
                res.diverged_at = Some(at as f64 * ts);
                i = at;
                break;
            }
        }
    }
    // `m` rows a sample (its sub-steps after it), the last sample's alone;
    // none of the sample that diverged
    Ok(if i >= run.n {
        run.n
            .saturating_sub(1)
            .saturating_mul(run.m)
            .saturating_add(1)
    } else {
        i.saturating_mul(run.m)
    })
}

/// The set point the controller sees at a sample: ramped towards `r` (`r`
/// itself is recorded; from 0, where the run starts, also for a step at 0).
#[inline(always)]
fn ramped<const OPERATED: bool>(f: Flags, op: &mut Operator, r: f64) {
    op.r_ctl = if OPERATED && f.ramp.is_finite() {
        r.max(op.r_ctl - f.ramp).min(op.r_ctl + f.ramp)
    } else {
        r
    };
}

/// The samples `from..to` of a run, whose scheduled inputs (but ramps and
/// sines) are constant over them. `Err(i)`: the output diverged at sample `i`.
#[allow(clippy::too_many_arguments)] // the loop's state, passed once per segment
#[inline(always)]
fn segment<C, const OPERATED: bool, const PLAIN: bool>(
    run: &mut Run,
    controller: &mut C,
    cfg: &SimConfig,
    res: &mut SimResult,
    op: &mut Operator,
    (from, to): (usize, usize),
    r: f64,
    sig: &mut [f64],
) -> Result<(), usize>
where
    C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized,
{
    if PLAIN {
        // one plant in one piece, no noise: the update and one plant step
        let (d_in, d_out) = (run.inputs.steps(), run.outputs.steps());
        let f = run.flags;
        // one match a segment, not one a sample
        let Process::Single(p) = &mut run.process else {
            return Err(from);
        };
        // `t`, `y` and `u` of the segment as slices: no index to check a sample
        let ([t, y, u], mut others) = split(res);
        let (Some(ts), Some(ys), Some(us)) = (
            t.get_mut(from..to),
            y.get_mut(from..to),
            u.get_mut(from..to),
        ) else {
            return Err(from);
        };
        if f.columns.all {
            fill_segment(&mut others, run.zeroed, (from, to), r, d_in, d_out);
        }
        let rows = ts.iter_mut().zip(ys.iter_mut()).zip(us.iter_mut());
        for (i, ((t_out, y_out), u_out)) in (from..to).zip(rows) {
            ramped::<OPERATED>(f, op, r);
            // NaN fails `<=` too: one comparison catches NaN, ±∞ and divergence
            let y = p.output() + d_out;
            if !(y.abs() <= f.bound) {
                return Err(i);
            }
            let (u, u_plant) = control::<C, OPERATED>(controller, cfg, f, op, y, None);
            p.advance_one_piece(u_plant + d_in);
            *t_out = i as f64 * f.ts;
            *y_out = y;
            *u_out = u;
            if (OPERATED && f.applies) || f.columns.all {
                if f.columns.all {
                    controller.write_signals(sig);
                }
                let row = Row {
                    t: *t_out,
                    r,
                    y,
                    u,
                    u_plant,
                    y2: 0.0,
                    d_in,
                    d_out,
                    d_mid: 0.0,
                };
                record_varying::<OPERATED>(f, &mut others, i, &row, sig);
            }
        }
        return Ok(());
    }
    // noise, sub-steps, a cascade process, ramps and sines
    let f = run.flags;
    // the sub-step instants after a sample
    let step = f.ts / run.m as f64;
    for i in from..to {
        let t = i as f64 * f.ts;
        ramped::<OPERATED>(f, op, r);
        let d_in = run.inputs.value(t);
        let d_out = run.outputs.value(t);
        let d_mid = run.middles.value(t);
        let (y, y2) = match &run.process {
            Process::Single(p) => (p.output() + d_out, 0.0),
            Process::Cascade { p2, joint, .. } => (joint.output() + d_out, p2.output() + d_mid),
        };
        if !(y.abs() <= f.bound && y2.abs() <= f.bound) {
            return Err(i);
        }
        let mut y_meas = if cfg.noise > 0.0 {
            y + cfg.noise * run.noise.gaussian()
        } else {
            y
        };
        if cfg.quantization > 0.0 {
            y_meas = (y_meas / cfg.quantization).round() * cfg.quantization;
        }
        let y2 = f.columns.cascade.then_some(y2);
        let (u, u_plant) = control::<C, OPERATED>(controller, cfg, f, op, y_meas, y2);
        run.sub.clear();
        match &mut run.process {
            Process::Single(p) => p.advance(u_plant + d_in, &mut run.sub),
            Process::Cascade { p2, joint, sub2 } => {
                sub2.clear();
                p2.advance(u_plant + d_in, sub2);
                joint.advance(u_plant + d_in, d_mid, &mut run.sub);
            }
        }
        if f.columns.all {
            controller.write_signals(sig);
        }
        let mut row = Row {
            t,
            r,
            y,
            u,
            u_plant,
            y2: y2.unwrap_or(0.0),
            d_in,
            d_out,
            d_mid,
        };
        let k = i.saturating_mul(run.m);
        record::<OPERATED>(f, res, k, &row, sig);
        // the plant's outputs at the sub-step instants, with the same inputs
        // (none after the last sample)
        let subs = if i + 1 == run.n { 0 } else { run.sub.len() };
        for j in 0..subs {
            row.t = t + (j + 1) as f64 * step;
            row.y = run.sub.get(j).copied().unwrap_or(f64::NAN) + d_out;
            if let Process::Cascade { sub2, .. } = &run.process {
                row.y2 = sub2.get(j).copied().unwrap_or(f64::NAN) + d_mid;
            }
            record::<OPERATED>(f, res, k.saturating_add(j + 1), &row, sig);
        }
    }
    Ok(())
}

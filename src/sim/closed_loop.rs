//! The closed loop: a controller against the exact sampled process.

use std::vec::Vec;

use super::cascade::JointSim;
use super::config::{Action, Noise, PlantParameter, Process, Record, SimConfig};
use super::engine::{self, Flags, Run};
use super::plant::PlantSim;
use super::result::Columns;
use super::schedule::{first_sample_at, Track};
use super::{Location, SimResult};
use crate::error::Error;
use crate::poly::TransferFunction;
use crate::{controller::CascadeControl, controller::Introspect, operate::Operate};

/// A schedule `(time, item)` as `(first sample, item)` in time order (ties
/// keep their order).
fn by_sample<T>(items: impl Iterator<Item = (f64, T)>, ts: f64) -> Vec<(usize, T)> {
    let mut v: Vec<(usize, T)> = items.map(|(at, x)| (first_sample_at(at, ts), x)).collect();
    v.sort_by_key(|e| e.0);
    v
}

/// Runs the closed loop of `controller` on `plant`.
///
/// The loop starts at rest ([`crate::Controller::reset_to_rest`]: the
/// controller's state and every signal before the first sample zero, as
/// its transfer function from rest has them).
///
/// The plant is simulated exactly at the sample instants (its ZOH
/// equivalent, the dead time as whole samples of delay): a PI with
/// `Kp·K = 1`, `Ti = T` on `K/(Ts + 1)` makes the loop `1/(T s + 1)`, whose
/// samples `1 − e^{−kTs/T}` the run reproduces to rounding.
///
/// ```
/// use msp::sim::{simulate, SetpointStep, SimConfig};
/// let plant: msp::poly::TransferFunction = "2/(4s+1)".parse()?;
/// let mut pi = msp::Pid::new(msp::PidConfig::isa(0.5, 4.0, 0.0, 0.1))?;
/// let cfg = SimConfig {
///     setpoint: vec![SetpointStep { value: 1.0, at: 0.0 }],
///     ..SimConfig::new(0.1, 20.0)
/// };
/// let res = simulate(&plant, &mut pi, &cfg)?;
/// let (t, y) = (res.t[100], res.y[100]); // 10 s
/// assert!((y - (1.0 - (-t / 4.0f64).exp())).abs() < 0.02, "{y}");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn simulate<C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized>(
    plant: &TransferFunction,
    controller: &mut C,
    cfg: &SimConfig,
) -> Result<SimResult, Error> {
    let mut res = SimResult::default();
    simulate_process(plant, None, controller, cfg, &mut res)?;
    Ok(res)
}

/// [`simulate`] into the buffers of an earlier result: its columns are
/// overwritten and keep their allocations, so repeated runs (sweeps, Monte
/// Carlo, benchmarks) write to memory that is already mapped. On an error
/// `out` is left empty.
pub fn simulate_into<C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized>(
    plant: &TransferFunction,
    controller: &mut C,
    cfg: &SimConfig,
    out: &mut SimResult,
) -> Result<(), Error> {
    let done = simulate_process(plant, None, controller, cfg, out);
    if done.is_err() {
        out.clear();
    }
    done
}

/// Runs the closed loop of `controller` on the cascade process: primary
/// `p1` (with its dead time `L1`) fed by the secondary `p2` (dead time `L2`),
/// whose output `y2` the controller also receives
/// ([`CascadeControl::update_cascade`]). Disturbances at [`Location::Input`] act
/// at the input of `p2` (`d2`), at [`Location::Inner`] on `y2` (`d0`), at
/// [`Location::Output`] on `y` (`d1`).
pub fn simulate_cascade<C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized>(
    p1: &TransferFunction,
    p2: &TransferFunction,
    controller: &mut C,
    cfg: &SimConfig,
) -> Result<SimResult, Error> {
    let mut res = SimResult::default();
    simulate_process(p1, Some(p2), controller, cfg, &mut res)?;
    Ok(res)
}

/// Prepares the run (checks, the process, the schedules as sample indices)
/// and runs the loop compiled for it ([`super::engine`]). The columns of an
/// earlier result are sized in place: memory a reused result already holds
/// is written once, by the run.
fn simulate_process<C: CascadeControl<f64> + Introspect<f64> + Operate<f64> + ?Sized>(
    plant: &TransferFunction,
    inner: Option<&TransferFunction>,
    controller: &mut C,
    cfg: &SimConfig,
    res: &mut SimResult,
) -> Result<(), Error> {
    let ts = crate::real::positive(cfg.ts, "ts")?;
    let duration = crate::real::non_negative(cfg.duration, "duration")?;
    crate::real::non_negative(cfg.noise, "noise")?;
    crate::real::non_negative(cfg.quantization, "quantization")?;
    if cfg.u_min > cfg.u_max {
        return Err(Error::InvalidLimits("u_min"));
    }
    if cfg.setpoint_ramp.is_nan() || cfg.setpoint_ramp <= 0.0 {
        return Err(Error::NotPositive("setpoint_ramp"));
    }
    let steps = num_traits::ToPrimitive::to_usize(&(duration / ts).round())
        .ok_or(Error::OutOfRange("duration"))?;
    let n = steps.saturating_add(1);
    let m = cfg.substeps.max(1);
    let n_rows = n.saturating_mul(m);
    // room in the plant's line for the longest dead time an event sets
    let plant_room = cfg
        .operations
        .iter()
        .filter_map(|o| match o.action {
            Action::PlantDeadTime(d) | Action::PlantDrift(PlantParameter::DeadTime, d, _) => {
                Some(d)
            }
            _ => None,
        })
        .fold(0.0, f64::max);
    let process = match inner {
        None => Process::Single(PlantSim::with_room(plant, ts, m, plant_room)?),
        Some(p2) => Process::Cascade {
            p2: PlantSim::new(p2, ts, m)?,
            joint: Box::new(JointSim::with_room(plant, p2, ts, m, plant_room)?),
            sub2: Vec::with_capacity(m),
        },
    };
    let cascade = inner.is_some();
    let all = cfg.record == Record::All;
    res.substeps = m;
    // each location's disturbances as events at their first sample: a
    // schedule of 10⁶ steps costs one comparison per segment, not 10⁶
    let track =
        |loc: Location| Track::new(cfg.disturbances.iter().filter(|d| d.location == loc), ts);
    let (inputs, outputs, middles) = (
        track(Location::Input),
        track(Location::Output),
        track(Location::Inner),
    );
    if !cascade && !middles.is_empty() {
        return Err(Error::Unsupported(
            "an 'inner' (d0) disturbance needs a cascade process (an inner plant)",
        ));
    }
    let scale = cfg
        .setpoint
        .iter()
        .map(|s| s.value.abs())
        .chain(cfg.disturbances.iter().map(|d| d.value.abs()))
        .fold(1.0, f64::max);
    let ops = by_sample(cfg.operations.iter().map(|o| (o.at, o.action)), ts);
    // a run without an operator pays nothing for one, a plain run nothing
    // for sub-steps, noise or a cascade: the loop is compiled for each
    let operated = !cfg.operations.is_empty()
        || cfg.actuator.is_some()
        || cfg.reset_feedback
        || cfg.background
        || cfg.setpoint_ramp != f64::INFINITY;
    let applies = !ops.is_empty() || cfg.actuator.is_some();
    let columns = Columns {
        cascade,
        all,
        applied: operated && applies,
        d_inner: !middles.is_empty(),
    };
    let zeroed = res.size(controller.signal_names(), n_rows, columns)?;
    let mut run = Run {
        n,
        m,
        process,
        sub: Vec::with_capacity(m),
        noise: Noise::new(cfg.seed),
        inputs,
        outputs,
        middles,
        steps: by_sample(cfg.setpoint.iter().map(|s| (s.at, s.value)), ts),
        ops,
        flags: Flags {
            ts,
            bound: 1e6 * scale,
            columns,
            ramp: cfg.setpoint_ramp * ts,
            applies,
            limited: cfg.u_min > f64::NEG_INFINITY || cfg.u_max < f64::INFINITY,
        },
        zeroed,
    };
    let plain = run.is_plain(cfg);
    // the loop starts at rest: every state zero and every signal before
    // the first sample zero, the transfer functions' initial condition (a
    // PID's first update differences against zero: a step at the first
    // sample gives the transfer function's step response, sample for sample)
    controller.reset_to_rest();
    let rows = match (operated, plain) {
        (true, true) => engine::samples::<C, true, true>(&mut run, controller, cfg, res),
        (true, false) => engine::samples::<C, true, false>(&mut run, controller, cfg, res),
        (false, true) => engine::samples::<C, false, true>(&mut run, controller, cfg, res),
        (false, false) => engine::samples::<C, false, false>(&mut run, controller, cfg, res),
    };
    res.truncate(rows?);
    res.adaptive = controller.adaptive_state();
    Ok(())
}

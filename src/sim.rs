//! The exact sampled-data closed-loop simulator and the scenario that drives it.
//!
//! The controller runs every `Ts`. The plant's rational part is discretized
//! by zero-order hold at `Ts` — exact at the sample instants for the held
//! actuator value — and its dead time `θ = (k + f)·Ts` is handled exactly: the
//! plant input is the held value delayed by `θ`, so over each period it takes
//! the value `v[n−k−1]` for the first `f·Ts` and `v[n−k]` for the rest; the
//! simulator integrates the two pieces with ZOH discretizations at `f·Ts` and
//! `(1−f)·Ts` (the modified z-transform). Figures from `msp` are therefore the
//! sampled loop's own, not an integrator's error.
//!
//! Disturbances are sampled and held like the actuator (exact for steps at
//! sample instants; ramps and sines are held over each period). Output
//! disturbances and measurement noise are added at the sample instants.

use std::string::{String, ToString};
use std::vec::Vec;

use crate::delay::Delay;
use crate::dtc::Controller;
use crate::metrics::{step_info, IntegralIndices, StepInfo};
use crate::poly::{fmt_num, PlantKind, TransferFunction};
use crate::registry::{self, Build, Params, RegistryError, MAX_ORDER};
use crate::{Discretization, Error, Lti};

/// Where a disturbance acts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Location {
    /// Added to the actuator value at the plant input (a load).
    Input,
    /// Added to the plant output.
    Output,
    /// Cascade plants: added to the secondary output `y2`, which is measured
    /// and drives the primary process (`d0` of García et al. (2010)
    /// Fig. 1; `input` is its `d2`, `output` its `d1`).
    Inner,
}

/// The shape of a disturbance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Shape {
    /// `value` from time `at` on.
    #[default]
    Step,
    /// `value·(t − at)` from time `at` on (value is the slope).
    Ramp,
    /// `value·sin(2π·freq·(t − at))` from time `at` on.
    Sine,
}

/// A load or output disturbance.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Disturbance {
    /// Input (load) or output.
    pub location: Location,
    /// Step, ramp or sine.
    #[cfg_attr(feature = "serde", serde(default))]
    pub shape: Shape,
    /// Step size, ramp slope or sine amplitude.
    pub value: f64,
    /// Start time (s).
    #[cfg_attr(feature = "serde", serde(default))]
    pub at: f64,
    /// Sine frequency (Hz).
    #[cfg_attr(feature = "serde", serde(default))]
    pub freq: f64,
}

impl Disturbance {
    fn at_time(&self, t: f64) -> f64 {
        if t + 1e-9 * t.abs().max(1.0) < self.at {
            return 0.0;
        }
        let dt = (t - self.at).max(0.0);
        match self.shape {
            Shape::Step => self.value,
            Shape::Ramp => self.value * dt,
            Shape::Sine => self.value * (core::f64::consts::TAU * self.freq * dt).sin(),
        }
    }
}

/// A set-point step: the set point is `value` from time `at` on.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct SetpointStep {
    /// New set point.
    pub value: f64,
    /// Time of the step (s).
    #[cfg_attr(feature = "serde", serde(default))]
    pub at: f64,
}

/// The set point at time `t` for a profile of steps (zero before the first).
/// A step counts from its own instant: times within a relative 1e-9 of it are on it
/// (so `k·Ts` rounding never moves a step by one sample).
pub fn setpoint_at(steps: &[SetpointStep], t: f64) -> f64 {
    let t = t + 1e-9 * t.abs().max(1.0);
    steps
        .iter()
        .filter(|s| s.at <= t)
        .fold((f64::NEG_INFINITY, 0.0), |(ta, v), s| {
            if s.at >= ta {
                (s.at, s.value)
            } else {
                (ta, v)
            }
        })
        .1
}

/// Parses a finite number; the error names `what`.
pub fn parse_number(s: &str, what: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| std::format!("{what}: '{s}' is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(std::format!("{what}: '{s}' is not a finite number"))
    }
}

impl core::str::FromStr for SetpointStep {
    type Err = String;
    /// `VALUE[@TIME]`, e.g. `1@0`.
    fn from_str(s: &str) -> Result<Self, String> {
        let (v, at) = match s.split_once('@') {
            Some((v, t)) => (v, parse_number(t, "time")?),
            None => (s, 0.0),
        };
        if at < 0.0 {
            return Err("the step time must not be negative".into());
        }
        Ok(SetpointStep {
            value: parse_number(v, "set point")?,
            at,
        })
    }
}

impl core::str::FromStr for Disturbance {
    type Err = String;
    /// `input|output|inner[:step|ramp|sine]:VALUE[@TIME][~FREQ_HZ]`, e.g.
    /// `input:0.1@20`; for cascade plants `d2`, `d1`, `d0` name the same places.
    fn from_str(s: &str) -> Result<Self, String> {
        let mut parts = s.splitn(3, ':');
        let loc = match parts.next().map(str::trim) {
            Some("input") | Some("load") | Some("d2") => Location::Input,
            Some("output") | Some("d1") => Location::Output,
            Some("inner") | Some("d0") => Location::Inner,
            other => {
                return Err(std::format!(
                    "disturbance location must be 'input' (d2), 'output' (d1) or 'inner' (d0), got '{}'",
                    other.unwrap_or("")
                ))
            }
        };
        let a = parts.next().ok_or("expected LOCATION:VALUE[@TIME]")?;
        let (shape, rest) = match a.trim() {
            "step" => (
                Shape::Step,
                parts
                    .next()
                    .ok_or("expected a value after the shape")?
                    .to_string(),
            ),
            "ramp" => (
                Shape::Ramp,
                parts
                    .next()
                    .ok_or("expected a slope after 'ramp'")?
                    .to_string(),
            ),
            "sine" => (
                Shape::Sine,
                parts
                    .next()
                    .ok_or("expected an amplitude after 'sine'")?
                    .to_string(),
            ),
            _ => (
                Shape::Step,
                parts
                    .next()
                    .map_or_else(|| a.to_string(), |t| std::format!("{a}:{t}")),
            ),
        };
        let rest = rest.as_str();
        let (rest, freq) = match rest.split_once('~') {
            Some((r, f)) => (r, parse_number(f, "frequency")?),
            None => (rest, 0.0),
        };
        if shape == Shape::Sine && freq <= 0.0 {
            return Err(
                "a sine disturbance needs a frequency: input:sine:AMPLITUDE@TIME~HZ".into(),
            );
        }
        let (v, at) = match rest.split_once('@') {
            Some((v, t)) => (v, parse_number(t, "time")?),
            None => (rest, 0.0),
        };
        if at < 0.0 {
            return Err("the disturbance time must not be negative".into());
        }
        Ok(Disturbance {
            location: loc,
            shape,
            value: parse_number(v, "disturbance")?,
            at,
            freq,
        })
    }
}

/// Settings of one closed-loop simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// Sample period (s).
    pub ts: f64,
    /// Length of the run (s).
    pub duration: f64,
    /// Set-point profile.
    pub setpoint: Vec<SetpointStep>,
    /// Disturbances.
    pub disturbances: Vec<Disturbance>,
    /// Standard deviation of Gaussian measurement noise.
    pub noise: f64,
    /// Seed of the noise generator.
    pub seed: u64,
    /// Actuator lower limit.
    pub u_min: f64,
    /// Actuator upper limit.
    pub u_max: f64,
    /// Plant outputs per controller period (1: at the samples only; more for
    /// smooth intersample plots).
    pub substeps: usize,
}

impl SimConfig {
    /// A run of `duration` seconds sampled every `ts`: no set point (add steps
    /// to `setpoint`), no disturbance, no noise, no limits, no sub-steps.
    pub fn new(ts: f64, duration: f64) -> Self {
        SimConfig {
            ts,
            duration,
            setpoint: Vec::new(),
            disturbances: Vec::new(),
            noise: 0.0,
            seed: 0,
            u_min: f64::NEG_INFINITY,
            u_max: f64::INFINITY,
            substeps: 1,
        }
    }
}

/// The signals of a run, one entry per sample.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SimResult {
    /// Time (s).
    pub t: Vec<f64>,
    /// Set point.
    pub r: Vec<f64>,
    /// Plant output (with output disturbances, without noise).
    pub y: Vec<f64>,
    /// Actuator value after the limits.
    pub u: Vec<f64>,
    /// Input (load) disturbance.
    pub d: Vec<f64>,
    /// Output disturbance (all zero when there is none).
    pub d_out: Vec<f64>,
    /// Cascade plants: the secondary output `y2` as measured (empty otherwise).
    pub y2: Vec<f64>,
    /// Cascade plants: the disturbance `d0` at the secondary output (empty
    /// without one).
    pub d_inner: Vec<f64>,
    /// Internal signals of the controller, by name.
    pub signals: Vec<(String, Vec<f64>)>,
    /// Time at which the run was stopped because the output diverged.
    pub diverged_at: Option<f64>,
    /// Rows per controller period (the controller's samples are every `substeps` rows).
    pub substeps: usize,
}

impl SimResult {
    /// Empties every column, keeping the allocations.
    fn clear(&mut self) {
        for v in [
            &mut self.t,
            &mut self.r,
            &mut self.y,
            &mut self.u,
            &mut self.d,
            &mut self.d_out,
            &mut self.y2,
            &mut self.d_inner,
        ] {
            v.clear();
        }
        for (_, v) in &mut self.signals {
            v.clear();
        }
        self.diverged_at = None;
    }

    /// Room for `rows` rows of the columns a run records, and one signal
    /// column per name (reused when the names are those of the last run).
    fn reserve(&mut self, names: &[&str], rows: usize, cascade: bool) {
        let mut columns = std::vec![&mut self.t, &mut self.r, &mut self.y, &mut self.u];
        if cascade {
            columns.push(&mut self.y2);
        }
        for v in columns {
            v.reserve(rows);
        }
        let same = self.signals.len() == names.len()
            && self.signals.iter().zip(names).all(|((a, _), b)| a == b);
        if !same {
            self.signals = names.iter().map(|s| (s.to_string(), Vec::new())).collect();
        }
        for (_, v) in &mut self.signals {
            v.reserve(rows);
        }
    }
}

/// A seeded Gaussian generator (SplitMix64 + Box–Muller), reproducible everywhere.
#[derive(Debug, Clone)]
pub struct Noise {
    state: u64,
    spare: Option<f64>,
}

impl Noise {
    /// A generator with this seed.
    pub fn new(seed: u64) -> Self {
        Noise {
            state: seed,
            spare: None,
        }
    }
    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// A uniform sample in (0, 1).
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    /// A standard normal sample.
    pub fn gaussian(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = core::f64::consts::TAU * u2;
        self.spare = Some(r * a.sin());
        r * a.cos()
    }
}

/// One piece of a sampling period, integrated exactly by its own ZOH discretization.
struct Piece {
    block: Lti<f64, MAX_ORDER>,
    /// Input `v[n−k]` (true) or `v[n−k−1]` (false, before the fractional delay has passed).
    late: bool,
    /// The piece ends at an intermediate output instant (sub-step).
    record: bool,
}

/// The plant as simulated: the period is cut at the sub-step instants and at
/// the instant `f·Ts` where the delayed input changes.
struct PlantSim {
    out: Lti<f64, MAX_ORDER>,
    pieces: Vec<Piece>,
    line: Delay<f64, Vec<f64>>,
    k: usize,
    feedthrough: f64,
    last_in: f64,
}

impl PlantSim {
    fn new(plant: &TransferFunction, ts: f64, substeps: usize) -> Result<Self, Error> {
        let (kf, f) = split_delay(plant.delay_samples(ts)?);
        let out: Lti<f64, MAX_ORDER> = plant.to_lti(ts)?;
        let cuts = cuts(substeps, &[f]);
        let mut pieces = Vec::with_capacity(cuts.len());
        let mut a = 0.0;
        for (b, record) in cuts {
            let block = Lti::from_tf(&plant.num, &plant.den, (b - a) * ts, Discretization::Zoh)?;
            pieces.push(Piece {
                block,
                late: a >= f - 1e-12,
                record,
            });
            a = b;
        }
        let k = kf.to_usize_checked()?;
        // the line holds the whole delay `k` (read by `process`); its capacity
        // `k + 1` keeps `v[n−k−1]` too for a fractional delay
        let line = Delay::with_storage(vec_zeros(k.saturating_add(1)), kf)?;
        Ok(PlantSim {
            feedthrough: out.output(1.0) - out.free_output(),
            out,
            pieces,
            line,
            k,
            last_in: 0.0,
        })
    }

    /// Output at the current instant (before the new input is applied).
    #[inline]
    fn output(&self) -> f64 {
        self.out.free_output() + self.feedthrough * self.last_in
    }

    /// Applies plant input `v[n]` over one period; the outputs at the
    /// intermediate sub-step instants are appended to `sub`.
    #[inline]
    fn advance(&mut self, v: f64, sub: &mut Vec<f64>) {
        if self.pieces.len() == 1 {
            // one piece spanning the period (a whole delay, no sub-steps):
            // `out` is that very discretization, driven by `v[n−k]`
            let now = self.line.process(v);
            self.out.step(now);
            self.last_in = now;
            return;
        }
        let now = self.line.peek_back(v, self.k);
        let before = self.line.peek_back(v, self.k.saturating_add(1));
        self.line.process(v);
        let mut x = *self.out.state();
        for p in &mut self.pieces {
            let input = if p.late { now } else { before };
            p.block.set_state(&x);
            p.block.step(input);
            x = *p.block.state();
            if p.record {
                self.out.set_state(&x);
                sub.push(self.out.free_output() + self.feedthrough * input);
            }
        }
        self.out.set_state(&x);
        self.last_in = now;
    }
}

fn vec_zeros(n: usize) -> Vec<f64> {
    std::vec![0.0; n]
}

trait ToUsize {
    fn to_usize_checked(self) -> Result<usize, Error>;
}
impl ToUsize for f64 {
    fn to_usize_checked(self) -> Result<usize, Error> {
        num_traits::ToPrimitive::to_usize(&self).ok_or(Error::DelayTooLong("delay"))
    }
}

/// The exact sampled plant, stepped one held input at a time.
pub struct PlantStepper(PlantSim);

impl PlantStepper {
    /// The plant at rest, sampled every `ts`.
    pub fn new(plant: &TransferFunction, ts: f64) -> Result<Self, Error> {
        Ok(PlantStepper(PlantSim::new(plant, ts, 1)?))
    }
    /// The output now.
    pub fn output(&self) -> f64 {
        self.0.output()
    }
    /// Holds `u` for one period.
    pub fn advance(&mut self, u: f64) {
        let mut sub = Vec::new();
        self.0.advance(u, &mut sub);
    }
}

/// The exact sampled cascade process (primary `p1` fed by the secondary `p2`),
/// stepped one held input at a time (see [`simulate_cascade`]).
pub struct CascadeStepper {
    p2: PlantSim,
    joint: Box<JointSim>,
}

impl CascadeStepper {
    /// The process at rest, sampled every `ts`.
    pub fn new(p1: &TransferFunction, p2: &TransferFunction, ts: f64) -> Result<Self, Error> {
        Ok(CascadeStepper {
            p2: PlantSim::new(p2, ts, 1)?,
            joint: Box::new(JointSim::new(p1, p2, ts, 1)?),
        })
    }
    /// The primary output `y` and the secondary output `y2` now.
    pub fn outputs(&self) -> (f64, f64) {
        (self.joint.output(), self.p2.output())
    }
    /// Holds `u` for one period.
    pub fn advance(&mut self, u: f64) {
        let mut sub = Vec::new();
        self.p2.advance(u, &mut sub);
        self.joint.advance(u, 0.0, &mut sub);
    }
}

/// The plant's response at the sample instants to the held input `u[k]`
/// (exact: ZOH discretization and the modified z-transform for the dead time);
/// `y[k]` is the output at `k·ts`, before `u[k]` acts.
pub fn open_loop(plant: &TransferFunction, ts: f64, u: &[f64]) -> Result<Vec<f64>, Error> {
    let mut p = PlantSim::new(plant, ts, 1)?;
    let mut sub = Vec::new();
    let mut y = Vec::with_capacity(u.len());
    for uk in u {
        y.push(p.output());
        p.advance(*uk, &mut sub);
    }
    Ok(y)
}

/// The primary output of a cascade process, `y = P1·(P2·v(t − L1 − L2) + d0(t − L1))`,
/// as one state-space system with the two held inputs `v = u + d2` and `d0`
/// (`x = [x2; x1]`, `A = [[A2, 0], [b1·c2, A1]]`, `Bv = [b2; b1·d2]`,
/// `Bd = [0; b1]`, `C = [d1·c2, c1]`): the closed loop keeps this one state
/// bounded even when `P1` is unstable, where a sum of separately simulated
/// parts would cancel growing terms. Each period is cut where either delayed
/// input changes and at the sub-step instants; every piece is integrated
/// exactly by its own ZOH discretization.
struct JointSim {
    c: [f64; MAX_ORDER],
    dv: f64,
    dd: f64,
    pieces: Vec<JointPiece>,
    x: [f64; MAX_ORDER],
    line_v: Delay<f64, Vec<f64>>,
    line_d: Delay<f64, Vec<f64>>,
    kv: usize,
    kd: usize,
    last_v: f64,
    last_d: f64,
}

struct JointPiece {
    v: Lti<f64, MAX_ORDER>,
    gd: [f64; MAX_ORDER],
    v_late: bool,
    d_late: bool,
    record: bool,
}

/// The breakpoints of a period as fractions of it: the `m` sub-step instants
/// (recorded, but for the period's end) and where a delayed input changes
/// (the fractions `f`).
fn cuts(m: usize, fractions: &[f64]) -> Vec<(f64, bool)> {
    let m = m.max(1);
    let mut cuts: Vec<(f64, bool)> = (1..=m).map(|j| (j as f64 / m as f64, j < m)).collect();
    for f in fractions {
        if *f > 0.0 && !cuts.iter().any(|(c, _)| (c - f).abs() < 1e-12) {
            cuts.push((*f, false));
        }
    }
    cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
    cuts
}

/// Whole samples and fraction of a delay.
fn split_delay(d: f64) -> (f64, f64) {
    let mut k = d.floor();
    let mut f = d - k;
    if f >= 1.0 - 1e-12 {
        k += 1.0;
        f = 0.0;
    }
    if f <= 1e-12 {
        f = 0.0;
    }
    (k, f)
}

impl JointSim {
    fn new(p1: &TransferFunction, p2: &TransferFunction, ts: f64, m: usize) -> Result<Self, Error> {
        let (a2, b2, c2, d2, n2) = crate::lti::realize::<f64, MAX_ORDER>(&p2.num, &p2.den)?;
        let (a1, b1, c1, d1, n1) = crate::lti::realize::<f64, MAX_ORDER>(&p1.num, &p1.den)?;
        let n = n1.saturating_add(n2);
        if n > MAX_ORDER {
            return Err(Error::OrderTooHigh("cascade process"));
        }
        let mut a = [[0.0; MAX_ORDER]; MAX_ORDER];
        let (mut bv, mut bd, mut c) = ([0.0; MAX_ORDER], [0.0; MAX_ORDER], [0.0; MAX_ORDER]);
        let get = |m: &[[f64; MAX_ORDER]; MAX_ORDER], i: usize, j: usize| {
            m.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0)
        };
        let at = |v: &[f64; MAX_ORDER], i: usize| v.get(i).copied().unwrap_or(0.0);
        let put = |v: &mut [f64; MAX_ORDER], i: usize, x: f64| {
            if let Some(e) = v.get_mut(i) {
                *e = x;
            }
        };
        for (i, row) in a.iter_mut().enumerate().take(n) {
            for (j, x) in row.iter_mut().enumerate().take(n) {
                *x = match (i < n2, j < n2) {
                    (true, true) => get(&a2, i, j),
                    (false, true) => at(&b1, i - n2) * at(&c2, j),
                    (false, false) => get(&a1, i - n2, j - n2),
                    (true, false) => 0.0,
                };
            }
        }
        for i in 0..n {
            if i < n2 {
                put(&mut bv, i, at(&b2, i));
                put(&mut c, i, d1 * at(&c2, i));
            } else {
                put(&mut bv, i, at(&b1, i - n2) * d2);
                put(&mut bd, i, at(&b1, i - n2));
                put(&mut c, i, at(&c1, i - n2));
            }
        }
        let (kv, fv) = split_delay(crate::delay::samples(p1.delay + p2.delay, ts)?);
        let (kd, fd) = split_delay(crate::delay::samples(p1.delay, ts)?);
        let cuts = cuts(m, &[fv, fd]);
        let mut pieces = Vec::with_capacity(cuts.len());
        let mut start = 0.0;
        for (end, record) in cuts {
            let len = (end - start) * ts;
            let v = Lti::from_state_space(&a, &bv, &c, d1 * d2, n, len, Discretization::Zoh)?;
            let gd = Lti::<f64, MAX_ORDER>::from_state_space(
                &a,
                &bd,
                &c,
                d1,
                n,
                len,
                Discretization::Zoh,
            )?
            .input_vector();
            pieces.push(JointPiece {
                v,
                gd,
                v_late: start >= fv - 1e-12,
                d_late: start >= fd - 1e-12,
                record,
            });
            start = end;
        }
        let kv = kv.to_usize_checked()?;
        let kd = kd.to_usize_checked()?;
        Ok(JointSim {
            c,
            dv: d1 * d2,
            dd: d1,
            pieces,
            x: [0.0; MAX_ORDER],
            line_v: Delay::with_storage(vec_zeros(kv.saturating_add(2)), 0.0)?,
            line_d: Delay::with_storage(vec_zeros(kd.saturating_add(2)), 0.0)?,
            kv,
            kd,
            last_v: 0.0,
            last_d: 0.0,
        })
    }

    fn free(&self) -> f64 {
        self.c.iter().zip(&self.x).map(|(c, x)| c * x).sum()
    }

    fn output(&self) -> f64 {
        self.free() + self.dv * self.last_v + self.dd * self.last_d
    }

    fn advance(&mut self, v: f64, d: f64, sub: &mut Vec<f64>) {
        let v_now = self.line_v.peek_back(v, self.kv);
        let v_before = self.line_v.peek_back(v, self.kv.saturating_add(1));
        let d_now = self.line_d.peek_back(d, self.kd);
        let d_before = self.line_d.peek_back(d, self.kd.saturating_add(1));
        self.line_v.process(v);
        self.line_d.process(d);
        for p in &mut self.pieces {
            let vi = if p.v_late { v_now } else { v_before };
            let di = if p.d_late { d_now } else { d_before };
            p.v.set_state(&self.x);
            p.v.step(vi);
            let xv = *p.v.state();
            for ((x, a), g) in self.x.iter_mut().zip(xv.iter()).zip(p.gd.iter()) {
                *x = a + g * di;
            }
            if p.record {
                let y = self.c.iter().zip(&self.x).map(|(c, x)| c * x).sum::<f64>()
                    + self.dv * vi
                    + self.dd * di;
                sub.push(y);
            }
        }
        self.last_v = v_now;
        self.last_d = d_now;
    }
}

/// The process as simulated: one plant, or a cascade (García et al. (2010)
/// Fig. 1). With `v = u + d2` held over each period and `d0` held too,
/// `y2 = P2 e^{−L2 s}·v + d0` (its own block) and
/// `y = P1 e^{−L1 s}(P2 e^{−L2 s}·v + d0) + d1` ([`JointSim`]), both sampled exactly.
enum Process {
    Single(PlantSim),
    Cascade {
        p2: PlantSim,
        joint: Box<JointSim>,
        sub2: Vec<f64>,
    },
}

/// Runs the closed loop of `controller` on `plant`.
pub fn simulate<C: Controller<f64> + ?Sized>(
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
pub fn simulate_into<C: Controller<f64> + ?Sized>(
    plant: &TransferFunction,
    controller: &mut C,
    cfg: &SimConfig,
    out: &mut SimResult,
) -> Result<(), Error> {
    simulate_process(plant, None, controller, cfg, out)
}

/// Runs the closed loop of `controller` on the cascade process: primary
/// `p1` (with its dead time `L1`) fed by the secondary `p2` (dead time `L2`),
/// whose output `y2` the controller also receives
/// ([`Controller::update_cascade`]). Disturbances at [`Location::Input`] act
/// at the input of `p2` (`d2`), at [`Location::Inner`] on `y2` (`d0`), at
/// [`Location::Output`] on `y` (`d1`).
pub fn simulate_cascade<C: Controller<f64> + ?Sized>(
    p1: &TransferFunction,
    p2: &TransferFunction,
    controller: &mut C,
    cfg: &SimConfig,
) -> Result<SimResult, Error> {
    let mut res = SimResult::default();
    simulate_process(p1, Some(p2), controller, cfg, &mut res)?;
    Ok(res)
}

fn simulate_process<C: Controller<f64> + ?Sized>(
    plant: &TransferFunction,
    inner: Option<&TransferFunction>,
    controller: &mut C,
    cfg: &SimConfig,
    res: &mut SimResult,
) -> Result<(), Error> {
    res.clear();
    let ts = crate::real::positive(cfg.ts, "ts")?;
    let duration = crate::real::non_negative(cfg.duration, "duration")?;
    crate::real::non_negative(cfg.noise, "noise")?;
    if cfg.u_min > cfg.u_max {
        return Err(Error::InvalidLimits("u_min"));
    }
    let steps = num_traits::ToPrimitive::to_usize(&(duration / ts).round())
        .ok_or(Error::OutOfRange("duration"))?;
    let n = steps.saturating_add(1);
    let m = cfg.substeps.max(1);
    let n_rows = n.saturating_mul(m);
    let mut process = match inner {
        None => Process::Single(PlantSim::new(plant, ts, m)?),
        Some(p2) => Process::Cascade {
            p2: PlantSim::new(p2, ts, m)?,
            joint: Box::new(JointSim::new(plant, p2, ts, m)?),
            sub2: Vec::with_capacity(m),
        },
    };
    let cascade = inner.is_some();
    let mut sub = Vec::with_capacity(m);
    let mut noise = Noise::new(cfg.seed);
    let names = controller.signal_names();
    res.reserve(names, n_rows, cascade);
    res.substeps = m;
    let pick = |loc: Location| -> Vec<&Disturbance> {
        cfg.disturbances
            .iter()
            .filter(|d| d.location == loc)
            .collect()
    };
    let (inputs, outputs, middles) = (
        pick(Location::Input),
        pick(Location::Output),
        pick(Location::Inner),
    );
    if !cascade && !middles.is_empty() {
        return Err(Error::Unsupported(
            "an 'inner' (d0) disturbance needs a cascade process (an inner plant)",
        ));
    }
    let sum_at = |ds: &[&Disturbance], t: f64| -> f64 {
        if ds.is_empty() {
            0.0
        } else {
            ds.iter().fold(0.0, |acc, d| acc + d.at_time(t))
        }
    };
    let scale = cfg
        .setpoint
        .iter()
        .map(|s| s.value.abs())
        .chain(cfg.disturbances.iter().map(|d| d.value.abs()))
        .fold(1.0, f64::max);
    // the set point's schedule as sample indices: one integer test per sample
    let bound = 1e6 * scale;
    let mut steps: Vec<(usize, f64)> = cfg
        .setpoint
        .iter()
        .map(|s| (first_sample_at(s.at, ts), s.value))
        .collect();
    steps.sort_by_key(|s| s.0);
    let mut next_step = 0usize;
    let mut r = 0.0;
    let mut sig = std::vec![0.0; names.len()];
    for i in 0..n {
        let t = i as f64 * ts;
        while let Some(&(k, value)) = steps.get(next_step) {
            if k <= i {
                r = value;
                next_step = next_step.saturating_add(1);
            } else {
                break;
            }
        }
        let d_in = sum_at(&inputs, t);
        let d_out = sum_at(&outputs, t);
        let d_mid = sum_at(&middles, t);
        let (y, y2) = match &process {
            Process::Single(p) => (p.output() + d_out, 0.0),
            Process::Cascade { p2, joint, .. } => (joint.output() + d_out, p2.output() + d_mid),
        };
        // NaN fails `<=` too: one comparison per output catches NaN, ±∞ and divergence
        if !(y.abs() <= bound && y2.abs() <= bound) {
            res.diverged_at = Some(t);
            break;
        }
        let y_meas = if cfg.noise > 0.0 {
            y + cfg.noise * noise.gaussian()
        } else {
            y
        };
        let u = if cascade {
            controller.update_cascade(r, y_meas, y2)
        } else {
            controller.update(r, y_meas)
        }
        .max(cfg.u_min)
        .min(cfg.u_max);
        sub.clear();
        match &mut process {
            Process::Single(p) => p.advance(u + d_in, &mut sub),
            Process::Cascade { p2, joint, sub2 } => {
                sub2.clear();
                p2.advance(u + d_in, sub2);
                joint.advance(u + d_in, d_mid, &mut sub);
            }
        }
        if i + 1 == n {
            sub.clear(); // nothing after the last sample
        }
        controller.write_signals(&mut sig);
        // time and the disturbance columns are filled after the loop when they
        // follow from the schedule alone: fewer stores per sample
        macro_rules! push {
            ($yj:expr, $y2j:expr) => {{
                res.r.push(r);
                res.y.push($yj);
                res.u.push(u);
                if !inputs.is_empty() {
                    res.d.push(d_in);
                }
                if !outputs.is_empty() {
                    res.d_out.push(d_out);
                }
                if cascade {
                    res.y2.push($y2j);
                    if !middles.is_empty() {
                        res.d_inner.push(d_mid);
                    }
                }
                for ((_, v), x) in res.signals.iter_mut().zip(&sig) {
                    v.push(*x);
                }
            }};
        }
        push!(y, y2);
        let subs2: &[f64] = match &process {
            Process::Cascade { sub2, .. } => sub2,
            Process::Single(_) => &[],
        };
        for (j, y_sub) in sub.iter().enumerate() {
            push!(
                y_sub + d_out,
                subs2.get(j).copied().unwrap_or(f64::NAN) + d_mid
            );
        }
    }
    let rows = res.y.len();
    let step = ts / m as f64;
    if m == 1 {
        res.t.extend((0..rows).map(|k| k as f64 * ts));
    } else {
        res.t
            .extend((0..rows).map(|k| (k / m) as f64 * ts + (k % m) as f64 * step));
    }
    if inputs.is_empty() {
        res.d.resize(rows, 0.0);
    }
    if outputs.is_empty() {
        res.d_out.resize(rows, 0.0);
    }
    Ok(())
}

/// The first sample `i` (time `i·ts`) at which an event at time `at` has
/// happened, with the same tolerance as [`setpoint_at`]: `at ≤ t + 10⁻⁹·max(|t|, 1)`.
fn first_sample_at(at: f64, ts: f64) -> usize {
    let reached = |i: usize| {
        let t = i as f64 * ts;
        at <= t + 1e-9 * t.abs().max(1.0)
    };
    if reached(0) {
        return 0;
    }
    // start near the answer, then settle it exactly with the test itself
    let mut i = num_traits::ToPrimitive::to_usize(&(at / ts).floor()).unwrap_or(usize::MAX);
    while i > 0 && reached(i - 1) {
        i -= 1;
    }
    while i < usize::MAX && !reached(i) {
        i += 1;
    }
    i
}

impl SimResult {
    /// Writes the signals as CSV: `t,r,y,u,d`, then `d_out` when there is an
    /// output disturbance, `y2` for a cascade process, `d_inner` when it has a
    /// `d0` disturbance, then the controller's signals (shortest round-trip
    /// number formatting).
    pub fn write_csv<W: std::io::Write>(&self, w: &mut W) -> std::io::Result<()> {
        let with_dout = self.d_out.iter().any(|v| *v != 0.0);
        let with_y2 = !self.y2.is_empty();
        let with_dinner = !self.d_inner.is_empty();
        let mut head = std::string::String::from("t,r,y,u,d");
        if with_dout {
            head.push_str(",d_out");
        }
        if with_y2 {
            head.push_str(",y2");
        }
        if with_dinner {
            head.push_str(",d_inner");
        }
        for (n, _) in &self.signals {
            head.push(',');
            head.push_str(n);
        }
        head.push('\n');
        w.write_all(head.as_bytes())?;
        let mut buf = ryu::Buffer::new();
        let mut line: Vec<u8> = Vec::with_capacity(256);
        let mut num = |line: &mut Vec<u8>, v: f64| {
            if v == 0.0 && v.is_sign_positive() {
                // the common value of disturbance columns, without formatting
                line.push(b'0');
            } else if v.is_finite() {
                let s = buf.format_finite(v);
                // ryu writes integers as "1.0"; keep them as "1" like `{}` does
                line.extend_from_slice(s.strip_suffix(".0").unwrap_or(s).as_bytes());
            } else {
                line.extend_from_slice(std::format!("{v}").as_bytes());
            }
        };
        for i in 0..self.t.len() {
            line.clear();
            let get = |v: &Vec<f64>| v.get(i).copied().unwrap_or(f64::NAN);
            num(&mut line, get(&self.t));
            for v in [&self.r, &self.y, &self.u, &self.d] {
                line.push(b',');
                num(&mut line, get(v));
            }
            if with_dout {
                line.push(b',');
                num(&mut line, get(&self.d_out));
            }
            if with_y2 {
                line.push(b',');
                num(&mut line, get(&self.y2));
            }
            if with_dinner {
                line.push(b',');
                num(&mut line, get(&self.d_inner));
            }
            for (_, v) in &self.signals {
                line.push(b',');
                num(&mut line, get(v));
            }
            line.push(b'\n');
            w.write_all(&line)?;
        }
        Ok(())
    }
}

/// The metrics of a run, with the key names of the JSON report and Python.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Metrics {
    /// Integral of the absolute error.
    pub iae: f64,
    /// Integral of the squared error.
    pub ise: f64,
    /// Integral of time times the absolute error.
    pub itae: f64,
    /// Integral of time times the squared error.
    pub itse: f64,
    /// Total variation of the control signal.
    pub tv: f64,
    /// Rise time 10 → 90 % (s).
    pub rise_time: f64,
    /// Settling time, 2 % band (s).
    pub settling_time: f64,
    /// Minimum after the rise.
    pub settling_min: f64,
    /// Maximum after the rise.
    pub settling_max: f64,
    /// Overshoot (%).
    pub overshoot: f64,
    /// Undershoot (%).
    pub undershoot: f64,
    /// Peak of |y|.
    pub peak: f64,
    /// Time of the peak (s).
    pub peak_time: f64,
}

impl Metrics {
    /// Every figure with its report name, in report order.
    pub fn fields(&self) -> [(&'static str, f64); 13] {
        [
            ("iae", self.iae),
            ("ise", self.ise),
            ("itae", self.itae),
            ("itse", self.itse),
            ("tv", self.tv),
            ("rise_time", self.rise_time),
            ("settling_time", self.settling_time),
            ("settling_min", self.settling_min),
            ("settling_max", self.settling_max),
            ("overshoot", self.overshoot),
            ("undershoot", self.undershoot),
            ("peak", self.peak),
            ("peak_time", self.peak_time),
        ]
    }
}

/// Metrics of `res` with the error `e = r(t − shift) − y`, time counted from
/// `shift` (0 for the plain convention; the model dead time `θm` for the
/// delayed-reference convention of Bag (2022) ch. 5).
pub fn metrics(
    res: &SimResult,
    setpoint: &[SetpointStep],
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
        rows(&res.t, first, stride),
        rows(&res.y, first, stride),
        rows(&res.u, first, stride),
    );
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
    let v = ind.value();
    let y0 = yy.first().copied().unwrap_or(0.0);
    let y_final = steps.last().map_or(0.0, |s| s.value);
    let first_step = steps.first().map_or(0.0, |s| s.at.max(0.0));
    let from = tt
        .iter()
        .position(|t| t - shift >= first_step - 1e-9 * ts)
        .unwrap_or(0);
    let s: StepInfo = step_info(
        tt.get(from..).unwrap_or(&[]),
        yy.get(from..).unwrap_or(&[]),
        y0,
        y_final,
        shift,
    );
    Ok(Metrics {
        iae: v.iae,
        ise: v.ise,
        itae: v.itae,
        itse: v.itse,
        tv: v.tv,
        rise_time: s.rise_time,
        settling_time: s.settling_time,
        settling_min: s.settling_min,
        settling_max: s.settling_max,
        overshoot: s.overshoot,
        undershoot: s.undershoot,
        peak: s.peak,
        peak_time: s.peak_time,
    })
}

/// A complete run description: what `msp run` takes from its flags or from a
/// TOML/JSON file (`msp run --scenario file.toml`). Unknown fields are rejected by name.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct Scenario {
    /// Plant expression, e.g. `0.2/s*e^-7.4s`.
    pub plant: String,
    /// Model expression (defaults to the plant: a perfect model).
    pub model: Option<String>,
    /// Cascade processes: the secondary process `P2 e^{−L2 s}` whose output is
    /// measured and drives `plant` (then the primary `P1 e^{−L1 s}`).
    pub inner_plant: Option<String>,
    /// The controller's model of the secondary process (defaults to `inner_plant`).
    pub inner_model: Option<String>,
    /// Controller name from the registry (default: chosen by plant kind).
    pub controller: Option<String>,
    /// Closed-loop time constant for tuning (s).
    pub lambda: Option<f64>,
    /// A named tuning rule (for `pid`: `imc`, `simc`, or a rule of Tables 3.2/3.3).
    pub rule: Option<String>,
    /// Parameter overrides, by the names in the report (`kp = 0.05`).
    pub set: std::collections::BTreeMap<String, f64>,
    /// Sample period (s); chosen from the plant when absent.
    pub ts: Option<f64>,
    /// Duration (s); chosen from the plant when absent.
    pub duration: Option<f64>,
    /// Set-point steps (default: a unit step at t = 0).
    pub setpoint: Vec<SetpointStep>,
    /// Disturbances.
    pub disturbance: Vec<Disturbance>,
    /// Measurement-noise standard deviation.
    pub noise: Option<f64>,
    /// Noise seed.
    pub seed: Option<u64>,
    /// Actuator lower limit.
    pub umin: Option<f64>,
    /// Actuator upper limit.
    pub umax: Option<f64>,
    /// Plant outputs per controller period in the signals (smooth plots).
    pub substeps: Option<usize>,
    /// The controller computes in `f32`, as firmware does (designed in `f64`,
    /// run through [`crate::Widened`]); the plant stays exact in `f64`.
    pub float32: bool,
}

/// A tuned and built controller with its sample period.
pub struct BuiltController {
    /// The scheme's name.
    pub scheme: &'static str,
    /// Its parameters.
    pub params: Params,
    /// The controller.
    pub controller: registry::DynController,
    /// Sample period.
    pub ts: f64,
    /// Whether `ts` was chosen automatically.
    pub ts_chosen: bool,
    /// Actuator lower limit.
    pub u_min: f64,
    /// Actuator upper limit.
    pub u_max: f64,
}

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunOutput {
    /// The plant.
    pub plant: TransferFunction,
    /// The controller's model.
    pub model: TransferFunction,
    /// Cascade processes: the secondary process and its model.
    pub inner: Option<(TransferFunction, TransferFunction)>,
    /// Sample period used.
    pub ts: f64,
    /// Whether `ts` was chosen automatically.
    pub ts_chosen: bool,
    /// Duration used.
    pub duration: f64,
    /// Whether the duration was chosen automatically.
    pub duration_chosen: bool,
    /// Controller name.
    pub controller: &'static str,
    /// Its parameters.
    pub params: Params,
    /// The signals.
    pub result: SimResult,
    /// Metrics on `e = r − y`.
    pub metrics: Metrics,
    /// Metrics on `e = r(t − θm) − y`, time from `θm`.
    pub metrics_delayed_reference: Metrics,
    /// The set-point profile used.
    pub setpoint: Vec<SetpointStep>,
    /// The controller computed in `f32` ([`Scenario::float32`]).
    pub float32: bool,
}

impl RunOutput {
    /// The controller's dead time: the model's, plus the secondary model's for
    /// a cascade process (the delay of the delayed-reference metrics).
    pub fn model_delay(&self) -> f64 {
        self.model.delay + self.inner.as_ref().map_or(0.0, |(_, m)| m.delay)
    }
    /// The whole model from the plant input: `model`, or `model·inner model`.
    pub fn whole_model(&self) -> TransferFunction {
        match &self.inner {
            Some((_, m2)) => self.model.series(m2).unwrap_or_else(|_| self.model.clone()),
            None => self.model.clone(),
        }
    }
}

/// Why a scenario could not run.
#[derive(Debug)]
pub enum RunError {
    /// A plant or model expression is wrong.
    Parse {
        /// `plant` or `model`.
        field: &'static str,
        /// The parser's error.
        error: crate::parse::ParseError,
    },
    /// A controller or its parameters are wrong.
    Registry(RegistryError),
    /// A scenario value is wrong.
    Invalid(Error),
}

impl core::fmt::Display for RunError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            RunError::Parse { field, error } => write!(f, "invalid {field} expression: {error}"),
            RunError::Registry(e) => write!(f, "{e}"),
            RunError::Invalid(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for RunError {}

impl From<Error> for RunError {
    fn from(e: Error) -> Self {
        RunError::Invalid(e)
    }
}
impl From<RegistryError> for RunError {
    fn from(e: RegistryError) -> Self {
        RunError::Registry(e)
    }
}

/// A sample period for `plant`: at most a tenth of its fastest time constant
/// and 1/1000 of its dead time. The sampled loop then reproduces the continuous
/// designs of the sources to better than 1 %: a controller designed for a
/// closed-loop time constant `τ` and sampled with forward-Euler integration
/// gives `τ − Ts/2` (e.g. the Karan–Dey MSP's IAE on the delayed reference is
/// `θ/8 − Ts/2`). The dead time is a whole number of samples, chosen so the dead time is a whole number
/// of samples (then the delay is exact in the controller's model too).
pub fn choose_ts(plant: &TransferFunction) -> f64 {
    let scales = plant.time_scales().unwrap_or_default();
    let dyn_min = scales
        .iter()
        .copied()
        .filter(|s| (*s - plant.delay).abs() > 0.0 || plant.delay == 0.0)
        .fold(f64::INFINITY, f64::min);
    let mut ts = (dyn_min / 10.0).min(if plant.delay > 0.0 {
        plant.delay / 1000.0
    } else {
        f64::INFINITY
    });
    if !ts.is_finite() {
        ts = 0.01;
    }
    if plant.delay > 0.0 {
        let n = (plant.delay / ts).ceil().max(1.0);
        ts = plant.delay / n;
    }
    ts
}

/// A duration that covers settling: ten dead times or ten of the slowest time
/// constants, whichever is longer.
pub fn choose_duration(plant: &TransferFunction, ts: f64) -> f64 {
    let slow = plant
        .time_scales()
        .unwrap_or_default()
        .into_iter()
        .fold(0.0, f64::max);
    (10.0 * plant.delay.max(slow)).max(100.0 * ts)
}

impl Scenario {
    /// Chooses the controller (by name or by the model's kind) and the sample
    /// period, tunes it on `model` and builds it.
    pub fn build_controller(&self, model: &TransferFunction) -> Result<BuiltController, RunError> {
        self.build_controller_for(model, None)
    }

    /// The scheme (by name, or by the model's kind — FSPCC for a cascade
    /// process with the secondary model `inner`) and its tuned parameters, with
    /// the scenario's `lambda`, `rule` and `set` (`scheme.param` keys apply to
    /// that scheme only, for `msp compare`).
    pub fn tune_for(
        &self,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
    ) -> Result<(&'static registry::Scheme, Params), RunError> {
        let scheme = match (&self.controller, inner) {
            (Some(name), _) => registry::find(name)?,
            (None, Some(_)) => registry::find("fspcc")?,
            (None, None) => registry::default_for(model.kind())?,
        };
        let overrides: Vec<(String, f64)> = self
            .set
            .iter()
            .filter_map(|(k, v)| match k.split_once('.') {
                Some((s, name)) => (s == scheme.name || scheme.aliases.contains(&s))
                    .then(|| (name.to_string(), *v)),
                None => Some((k.clone(), *v)),
            })
            .collect();
        let params =
            scheme.tune_process(model, inner, self.lambda, self.rule.as_deref(), &overrides)?;
        Ok((scheme, params))
    }

    /// [`Scenario::build_controller`] for a cascade process with the secondary
    /// model `inner` (the default scheme is then FSPCC).
    pub fn build_controller_for(
        &self,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
    ) -> Result<BuiltController, RunError> {
        let (scheme, params) = self.tune_for(model, inner)?;
        let whole = match inner {
            Some(p2) => model.series(p2)?,
            None => model.clone(),
        };
        if whole.model_order() > MAX_ORDER {
            return Err(RunError::Invalid(Error::OrderTooHigh("model")));
        }
        let (ts, ts_chosen) = match self.ts {
            Some(ts) => (crate::real::positive(ts, "ts")?, false),
            None => (choose_ts(&whole), true),
        };
        let u_min = self.umin.unwrap_or(f64::NEG_INFINITY);
        let u_max = self.umax.unwrap_or(f64::INFINITY);
        if u_min.is_nan() {
            return Err(RunError::Invalid(Error::NonFinite("umin")));
        }
        if u_max.is_nan() {
            return Err(RunError::Invalid(Error::NonFinite("umax")));
        }
        if u_min > u_max {
            return Err(RunError::Invalid(Error::InvalidLimits("umin")));
        }
        let build = Build { ts, u_min, u_max };
        let controller: registry::DynController = if self.float32 {
            Box::new(crate::Widened(
                scheme.build_process_as::<f32>(&params, model, inner, &build)?,
            ))
        } else {
            scheme.build_process(&params, model, inner, &build)?
        };
        Ok(BuiltController {
            scheme: scheme.name,
            params,
            controller,
            ts,
            ts_chosen,
            u_min,
            u_max,
        })
    }

    /// The plant and the model, parsed.
    pub fn parse(&self) -> Result<(TransferFunction, TransferFunction), RunError> {
        plant_and_model(&self.plant, self.model.as_deref(), ("plant", "model"))
    }

    /// The secondary process and its model, parsed (cascade scenarios).
    pub fn parse_inner(&self) -> Result<Option<(TransferFunction, TransferFunction)>, RunError> {
        let Some(p2) = &self.inner_plant else {
            if self.inner_model.is_some() {
                return Err(RunError::Invalid(Error::Unsupported(
                    "an inner model without an inner plant",
                )));
            }
            return Ok(None);
        };
        plant_and_model(
            p2,
            self.inner_model.as_deref(),
            ("inner plant", "inner model"),
        )
        .map(Some)
    }

    /// Parses, tunes, builds and simulates.
    pub fn run(&self) -> Result<RunOutput, RunError> {
        let (plant, model) = self.parse()?;
        let inner = self.parse_inner()?;
        self.run_process(plant, model, inner)
    }

    /// Tunes, builds and simulates for an already parsed plant and model (the
    /// `plant` and `model` strings are ignored).
    pub fn run_with(
        &self,
        plant: TransferFunction,
        model: TransferFunction,
    ) -> Result<RunOutput, RunError> {
        self.run_process(plant, model, None)
    }

    /// [`Scenario::run_with`] for a cascade process: `inner` holds the
    /// secondary process and its model.
    pub fn run_process(
        &self,
        plant: TransferFunction,
        model: TransferFunction,
        inner: Option<(TransferFunction, TransferFunction)>,
    ) -> Result<RunOutput, RunError> {
        let built = self.build_controller_for(&model, inner.as_ref().map(|(_, m)| m))?;
        let (scheme, params, mut ctrl, ts, ts_chosen) = (
            built.scheme,
            built.params,
            built.controller,
            built.ts,
            built.ts_chosen,
        );
        let (u_min, u_max) = (built.u_min, built.u_max);
        let (duration, duration_chosen) = match self.duration {
            Some(d) => (crate::real::positive(d, "duration")?, false),
            None => (
                choose_duration(
                    &match &inner {
                        Some((p2, _)) => plant.series(p2)?,
                        None => plant.clone(),
                    },
                    ts,
                ),
                true,
            ),
        };
        if duration / ts > 1e8 {
            return Err(RunError::Invalid(Error::OutOfRange("duration")));
        }
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
            u_min,
            u_max,
            substeps: self.substeps.unwrap_or(1),
        };
        if cfg.substeps == 0 || cfg.substeps > 1000 {
            return Err(RunError::Invalid(Error::OutOfRange("substeps")));
        }
        let result = match &inner {
            Some((p2, _)) => simulate_cascade(&plant, p2, &mut ctrl, &cfg)?,
            None => simulate(&plant, &mut ctrl, &cfg)?,
        };
        let model_delay = model.delay + inner.as_ref().map_or(0.0, |(_, m)| m.delay);
        // the two conventions are independent passes over the signals
        let both = || {
            (
                metrics(&result, &setpoint, ts, 0.0),
                metrics(&result, &setpoint, ts, model_delay),
            )
        };
        // two threads only pay off for long runs: waking a worker costs more
        // than a pass over some hundred thousand samples
        #[cfg(feature = "parallel")]
        let (m0, m1) = if result.y.len() > 500_000 {
            rayon::join(
                || metrics(&result, &setpoint, ts, 0.0),
                || metrics(&result, &setpoint, ts, model_delay),
            )
        } else {
            both()
        };
        #[cfg(not(feature = "parallel"))]
        let (m0, m1) = both();
        let (m0, m1) = (m0?, m1?);
        Ok(RunOutput {
            plant,
            model,
            inner,
            ts,
            ts_chosen,
            duration,
            duration_chosen,
            controller: scheme,
            params,
            result,
            metrics: m0,
            metrics_delayed_reference: m1,
            setpoint,
            float32: self.float32,
        })
    }
}

/// A plant expression and an optional model expression (default: the plant),
/// parsed; errors name the `fields`.
fn plant_and_model(
    plant: &str,
    model: Option<&str>,
    fields: (&'static str, &'static str),
) -> Result<(TransferFunction, TransferFunction), RunError> {
    let parse = |e: &str, field| {
        crate::parse::parse_plant(e).map_err(|error| RunError::Parse { field, error })
    };
    let p = parse(plant, fields.0)?;
    let m = match model {
        Some(m) => parse(m, fields.1)?,
        None => p.clone(),
    };
    Ok((p, m))
}

/// Relative perturbations of the plant for `msp compare` (each controller keeps
/// the nominal model): `0.1` is +10 %.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct Perturbation {
    /// Gain change.
    pub gain: f64,
    /// Dead-time change.
    pub delay: f64,
    /// Time-constant change.
    pub tau: f64,
    /// Cascade processes: gain change of the secondary process (the three
    /// fields above act on the primary).
    pub inner_gain: f64,
    /// Dead-time change of the secondary process.
    pub inner_delay: f64,
    /// Time-constant change of the secondary process.
    pub inner_tau: f64,
}

impl core::str::FromStr for Perturbation {
    type Err = String;
    /// `gain=+10%,delay=-5%,tau=0.1`.
    fn from_str(s: &str) -> Result<Self, String> {
        let mut p = Perturbation::default();
        for part in s.split(',').map(str::trim).filter(|x| !x.is_empty()) {
            let (k, v) = part
                .split_once('=')
                .ok_or_else(|| std::format!("expected KEY=VALUE in '{part}'"))?;
            let v = v.trim();
            let value = match v.strip_suffix('%') {
                Some(pct) => parse_number(pct, k)? / 100.0,
                None => parse_number(v, k)?,
            };
            if value <= -1.0 {
                return Err(std::format!(
                    "{k}: a change of {v} leaves nothing of the plant"
                ));
            }
            match k.trim() {
                "gain" | "k" => p.gain = value,
                "delay" | "l" | "theta" => p.delay = value,
                "tau" | "t" => p.tau = value,
                "inner_gain" => p.inner_gain = value,
                "inner_delay" => p.inner_delay = value,
                "inner_tau" => p.inner_tau = value,
                other => {
                    return Err(std::format!(
                        "unknown perturbation '{other}': use gain, delay, tau (or inner_gain, inner_delay, inner_tau for the secondary of a cascade)"
                    ))
                }
            }
        }
        Ok(p)
    }
}

/// Runs `base` once per controller on the same (optionally perturbed) plant,
/// each controller tuned on and holding the nominal model, at one common sample period.
pub fn compare(
    base: &Scenario,
    controllers: &[String],
    perturb: Perturbation,
) -> Result<Vec<RunOutput>, RunError> {
    let (nominal, model) = base.parse()?;
    let plant = nominal.perturbed(perturb.gain, perturb.delay, perturb.tau)?;
    let inner = match base.parse_inner()? {
        Some((p2, m2)) => Some((
            p2.perturbed(perturb.inner_gain, perturb.inner_delay, perturb.inner_tau)?,
            m2,
        )),
        None => {
            if perturb.inner_gain != 0.0 || perturb.inner_delay != 0.0 || perturb.inner_tau != 0.0 {
                return Err(RunError::Invalid(Error::Unsupported(
                    "inner perturbations need a cascade process (an inner plant)",
                )));
            }
            None
        }
    };
    let (whole_model, whole_plant) = match &inner {
        Some((p2, m2)) => (model.series(m2)?, plant.series(p2)?),
        None => (model.clone(), plant.clone()),
    };
    let mut sc = base.clone();
    sc.ts = Some(match base.ts {
        Some(ts) => ts,
        None => choose_ts(&whole_model),
    });
    if sc.duration.is_none() {
        sc.duration = Some(choose_duration(&whole_plant, sc.ts.unwrap_or(1.0)));
    }
    if controllers.is_empty() {
        return Err(RunError::Invalid(Error::OutOfRange("controllers")));
    }
    controllers
        .iter()
        .map(|c| {
            let mut one = sc.clone();
            one.controller = Some(c.clone());
            one.run_process(plant.clone(), model.clone(), inner.clone())
        })
        .collect()
}

/// Shown next to a chosen value: `0.074 (chosen: 100 samples of dead time)`.
pub fn describe_ts(plant: &TransferFunction, ts: f64) -> String {
    if plant.delay > 0.0 {
        std::format!(
            "{} s ({} samples of dead time)",
            fmt_num(ts),
            fmt_num((plant.delay / ts).round())
        )
    } else {
        std::format!("{} s", fmt_num(ts))
    }
}

/// Kind of a plant, for messages.
pub fn kind_of(plant: &TransferFunction) -> PlantKind {
    plant.kind()
}

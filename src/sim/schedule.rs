//! Typed schedules of a run: set-point steps and disturbances.

use std::vec::Vec;

/// Where a disturbance acts (serialized by its name, read by any of its
/// names: [`Location::from_name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Location {
    /// Added to the actuator value at the plant input (a load).
    #[default]
    Input,
    /// Added to the plant output.
    Output,
    /// Cascade plants: added to the secondary output `y2`, which is measured
    /// and drives the primary process (`d0` of García et al. (2010)
    /// Fig. 1; `input` is its `d2`, `output` its `d1`).
    Inner,
}

impl Location {
    /// Its name in flags, files and reports: `input`, `output`, `inner`.
    pub fn name(self) -> &'static str {
        match self {
            Location::Input => "input",
            Location::Output => "output",
            Location::Inner => "inner",
        }
    }

    /// The place called `name`: `input` (or `load`, García et al. (2010)'s
    /// `d2`), `output` (`d1`) or `inner` (`d0`); an error naming them
    /// otherwise.
    pub fn from_name(name: &str) -> Result<Location, std::string::String> {
        match name {
            "input" | "load" | "d2" => Ok(Location::Input),
            "output" | "d1" => Ok(Location::Output),
            "inner" | "d0" => Ok(Location::Inner),
            _ => Err(std::format!(
                "disturbance location must be 'input' (d2), 'output' (d1) or 'inner' (d0), got '{name}'"
            )),
        }
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for Location {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = std::string::String::deserialize(d)?;
        Location::from_name(&name).map_err(serde::de::Error::custom)
    }
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
    /// Input (load), output or a cascade's inner output; input when absent.
    #[cfg_attr(feature = "serde", serde(default))]
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
    /// A step load of `value` at the plant input from `at` (s).
    pub fn input_step(value: f64, at: f64) -> Self {
        Disturbance {
            location: Location::Input,
            shape: Shape::Step,
            value,
            at,
            freq: 0.0,
        }
    }

    pub(super) fn at_time(&self, t: f64) -> f64 {
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

/// The first sample `i` (time `i·ts`) at which an event at time `at` has
/// happened, with the same tolerance as [`setpoint_at`]: `at ≤ t + 10⁻⁹·max(|t|, 1)`.
pub(crate) fn first_sample_at(at: f64, ts: f64) -> usize {
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

/// The disturbances of one location as events: each starts at its first
/// sample ([`first_sample_at`]); steps then add to a running sum, ramps and
/// sines are evaluated from then on. The cost per sample is one comparison
/// plus the started ramps and sines, whatever the number of steps.
pub(super) struct Track<'a> {
    /// `(first sample, disturbance)`, by first sample (stable: ties keep their order).
    events: Vec<(usize, &'a Disturbance)>,
    next: usize,
    steps: f64,
    moving: Vec<&'a Disturbance>,
}

impl<'a> Track<'a> {
    pub(super) fn new(ds: impl Iterator<Item = &'a Disturbance>, ts: f64) -> Self {
        let mut events: Vec<(usize, &'a Disturbance)> =
            ds.map(|d| (first_sample_at(d.at, ts), d)).collect();
        events.sort_by_key(|e| e.0);
        Track {
            events,
            next: 0,
            steps: 0.0,
            moving: Vec::new(),
        }
    }

    /// No disturbance at this location.
    pub(super) fn is_empty(&self) -> bool {
        self.events.is_empty()
    }

    /// Takes in the disturbances that have started by sample `i` (`i`
    /// never decreases): steps add to the running sum, ramps and sines move.
    pub(super) fn advance_to(&mut self, i: usize) {
        while let Some(&(k, d)) = self.events.get(self.next) {
            if k > i {
                break;
            }
            match d.shape {
                Shape::Step => self.steps += d.value,
                Shape::Ramp | Shape::Sine => self.moving.push(d),
            }
            self.next = self.next.saturating_add(1);
        }
    }

    /// The sample of the next disturbance to start, if any.
    pub(super) fn next_at(&self) -> Option<usize> {
        self.events.get(self.next).map(|e| e.0)
    }

    /// No ramp or sine in the schedule: between its events the sum is constant.
    pub(super) fn steps_only(&self) -> bool {
        self.events.iter().all(|(_, d)| d.shape == Shape::Step)
    }

    /// The sum of the steps started so far.
    #[inline]
    pub(super) fn steps(&self) -> f64 {
        self.steps
    }

    /// The sum of the disturbances started so far at time `t`.
    #[inline]
    pub(super) fn value(&self, t: f64) -> f64 {
        if self.moving.is_empty() {
            self.steps
        } else {
            self.moving
                .iter()
                .fold(self.steps, |acc, d| acc + d.at_time(t))
        }
    }
}

#[cfg(all(test, feature = "serde"))]
mod tests {
    use super::{Disturbance, Location};

    /// A structured disturbance (a scenario file's, a Python dict's) names its
    /// place as the flag does, at the plant input when it names none; an
    /// unknown place or field is refused by name.
    #[test]
    fn a_structured_disturbance_reads_the_flags_names() -> Result<(), serde_json::Error> {
        let read = |s: &str| serde_json::from_str::<Disturbance>(s);
        assert_eq!(
            read(r#"{"value": 0.1, "at": 5}"#)?.location,
            Location::Input
        );
        assert_eq!(
            read(r#"{"location": "d0", "value": 1}"#)?.location,
            Location::Inner
        );
        assert_eq!(
            read(r#"{"location": "load", "value": 1}"#)?.location,
            Location::Input
        );
        let flag: Disturbance = "d1:-0.5@100".parse().map_err(serde::de::Error::custom)?;
        assert_eq!(
            read(r#"{"location": "d1", "value": -0.5, "at": 100}"#)?,
            flag
        );
        let bad = read(r#"{"location": "middle", "value": 1}"#).map(|_| ());
        assert!(bad.is_err_and(|e| e.to_string().contains("'input' (d2)")));
        let typo = read(r#"{"valeu": 1}"#).map(|_| ());
        assert!(typo.is_err_and(|e| e.to_string().contains("unknown field `valeu`")));
        Ok(())
    }
}

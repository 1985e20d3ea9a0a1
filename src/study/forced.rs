//! The forced response: a scenario whose set point and loads are sampled
//! arrays (`msp run --input FILE.csv`, Python `msp.simulate`), held between
//! samples as the controller's hold holds them.

use std::vec::Vec;

use super::{RunError, Scenario};
use crate::error::Error;
use crate::sim::{Disturbance, Location, SetpointStep, Shape};

/// Sampled inputs of a forced response: the times (uniform, from 0: their
/// step is the controller's period), the set point `r`, and optionally the
/// loads at the plant input `d` and at its output `d_out` (empty: none).
#[derive(Debug, Clone, Copy)]
pub struct SampledInput<'a> {
    /// Times (s).
    pub t: &'a [f64],
    /// Set point at each time.
    pub r: &'a [f64],
    /// Load at the plant input at each time (empty: none).
    pub d: &'a [f64],
    /// Load at the plant output at each time (empty: none).
    pub d_out: &'a [f64],
}

impl Scenario {
    /// The scenario with its set point and loads given as arrays: each
    /// change of `r` becomes a set-point step to the new value at its time,
    /// each change of `d` or `d_out` a load step of the change, so the run
    /// is the one with those steps (the same result to the bit); the period
    /// is the times' step and the duration their end. The times must start
    /// at 0 and be uniform (within 10⁻⁶ of a step); a period given must be
    /// theirs; set-point steps or disturbances given as well are refused
    /// (the arrays say what the inputs are). Operator events still apply.
    pub fn with_input(mut self, input: SampledInput<'_>) -> Result<Self, RunError> {
        let SampledInput { t, r, d, d_out } = input;
        let n = t.len();
        if n < 2 {
            return Err(RunError::Invalid(Error::OutOfRange(
                "input: at least two samples",
            )));
        }
        if r.len() != n
            || (!d.is_empty() && d.len() != n)
            || (!d_out.is_empty() && d_out.len() != n)
        {
            return Err(RunError::Invalid(Error::Unsupported(
                "input: t, r, d and d_out must have the same length",
            )));
        }
        if t.iter()
            .chain(r)
            .chain(d)
            .chain(d_out)
            .any(|v| !v.is_finite())
        {
            return Err(RunError::Invalid(Error::NonFinite("input")));
        }
        let end = t.last().copied().unwrap_or(0.0);
        #[allow(clippy::cast_precision_loss)] // a sample count
        let ts = end / (n - 1) as f64;
        if !(ts > 0.0) {
            return Err(RunError::Invalid(Error::Unsupported(
                "input: the times must increase",
            )));
        }
        #[allow(clippy::cast_precision_loss)] // a sample index
        if let Some((k, tk)) = t
            .iter()
            .enumerate()
            .find(|(k, tk)| (**tk - *k as f64 * ts).abs() > 1e-6 * ts)
        {
            return Err(RunError::Schedule(std::format!(
                "input: the times must start at 0 and be uniform (the controller's period is their step, {} s): sample {} is at {} s",
                crate::poly::fmt_num(ts),
                k + 1,
                crate::poly::fmt_num(*tk)
            )));
        }
        if let Some(given) = self.ts {
            if (given - ts).abs() > 1e-9 * ts {
                return Err(RunError::Schedule(std::format!(
                    "input: the period {} s differs from the times' step {} s (leave ts out: the input sets it)",
                    crate::poly::fmt_num(given),
                    crate::poly::fmt_num(ts)
                )));
            }
        }
        if !self.setpoint.is_empty() || !self.disturbance.is_empty() {
            return Err(RunError::Invalid(Error::Unsupported(
                "input: the arrays give the set point and the loads; leave out set-point steps and disturbances",
            )));
        }
        if let Some(given) = self.duration {
            if (given - end).abs() > 1e-9 * end.max(ts) {
                return Err(RunError::Schedule(std::format!(
                    "input: the duration {} s differs from the times' end {} s (leave it out: the input sets it)",
                    crate::poly::fmt_num(given),
                    crate::poly::fmt_num(end)
                )));
            }
        }
        let mut setpoint = Vec::new();
        let mut last = f64::NAN;
        for (tk, rk) in t.iter().zip(r) {
            // the first value always (an empty profile would be the default step)
            if *rk != last {
                setpoint.push(SetpointStep {
                    value: *rk,
                    at: *tk,
                });
                last = *rk;
            }
        }
        let mut disturbance = Vec::new();
        for (loads, location) in [(d, Location::Input), (d_out, Location::Output)] {
            let mut prev = 0.0;
            for (tk, dk) in t.iter().zip(loads) {
                if *dk != prev {
                    disturbance.push(Disturbance {
                        location,
                        shape: Shape::Step,
                        value: dk - prev,
                        at: *tk,
                        freq: 0.0,
                    });
                    prev = *dk;
                }
            }
        }
        self.ts = Some(ts);
        self.duration = Some(end);
        self.setpoint = setpoint;
        self.disturbance = disturbance;
        Ok(self)
    }
}

//! The exact sampled-data closed loop of a multivariable plant under
//! decentralized control: every channel `gᵢⱼ` discretized exactly with its
//! own dead time ([`PlantStepper`]: ZOH, the delay as samples plus its
//! fraction), output `i` the sum of its row's channels, and a
//! [`MultiController`] from `r` and `y` to `u` (loop `i` on output and
//! input `i`: the pairing is the diagonal).

use std::vec::Vec;

use super::{first_sample_at, setpoint_at, PlantStepper, SetpointStep};
use crate::error::Error;
use crate::mimo::MultiController;
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

/// Runs `controller` (loop `i` closes output `i` through input `i`) on
/// `plant` every `ts` seconds for `duration`, the set points
/// `setpoints[i]` per loop (absent: zero), from rest.
pub fn simulate_mimo(
    plant: &TransferMatrix,
    controller: &mut dyn MultiController<f64>,
    setpoints: &[Vec<SetpointStep>],
    ts: f64,
    duration: f64,
) -> Result<MimoRun, Error> {
    let n = plant.size();
    if controller.loops() != n {
        return Err(Error::OutOfRange("one controller loop per output"));
    }
    controller.reset_to_rest();
    crate::real::positive(ts, "ts")?;
    crate::real::positive(duration, "duration")?;
    let steps = num_traits::ToPrimitive::to_usize(&(duration / ts).round())
        .filter(|s| *s <= MAX_SAMPLES)
        .ok_or(Error::OutOfRange("duration/ts"))?;
    let mut channels = Vec::new();
    channels
        .try_reserve_exact(n * n)
        .map_err(|_| Error::OutOfMemory("channels"))?;
    for i in 0..n {
        for j in 0..n {
            let g = plant
                .get(i, j)
                .ok_or(Error::OutOfRange("the matrix's size"))?;
            channels.push(PlantStepper::new(g, ts)?);
        }
    }
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
    let (mut r, mut y, mut u) = (std::vec![0.0; n], std::vec![0.0; n], std::vec![0.0; n]);
    for k in 0..steps {
        let t = k as f64 * ts;
        run.t.push(t);
        for (i, (ri, yi)) in r.iter_mut().zip(y.iter_mut()).enumerate() {
            *yi = channels
                .get(i * n..(i + 1) * n)
                .unwrap_or_default()
                .iter()
                .map(PlantStepper::output)
                .sum();
            *ri = setpoints.get(i).map_or(0.0, |s| setpoint_at(s, t));
        }
        controller.update(&r, &y, &mut u);
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
            ch.advance(u.get(k % n).copied().unwrap_or(0.0));
        }
    }
    Ok(run)
}

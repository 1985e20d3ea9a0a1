//! Sweeps: many closed-loop runs over a range of plant perturbations, in
//! parallel, with a stability verdict per run, splittable into shards.

use std::string::String;
use std::vec::Vec;

use crate::sim::Noise;
use crate::study::{choose_duration, choose_ts_as, Keep, Metrics, RunError, Scenario};

/// A relative range `lo..hi` (e.g. `-0.2..0.2` for −20 % … +20 %).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Range {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Range {
    /// The range `lo..hi` of relative changes: numbers with `lo ≤ hi` and
    /// `lo > −1` (a change of −100 % or less leaves nothing of the plant);
    /// otherwise what is wrong.
    pub fn new(lo: f64, hi: f64) -> Result<Range, &'static str> {
        if lo.is_nan() || hi.is_nan() {
            Err("an end is not a number")
        } else if lo > hi {
            Err("the lower end is above the upper end")
        } else if lo <= -1.0 {
            Err("a change of -100 % or less leaves nothing of the plant")
        } else {
            Ok(Range { lo, hi })
        }
    }
}

/// What to sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepSpec {
    /// Relative gain changes.
    pub gain: Range,
    /// Relative dead-time changes.
    pub delay: Range,
    /// Relative time-constant changes.
    pub tau: Range,
    /// Points per swept axis on a grid, or
    pub grid: usize,
    /// this many random points (uniform, seeded) instead of a grid when non-zero.
    pub samples: usize,
    /// Seed of the random points.
    pub seed: u64,
    /// This shard `(i, n)`: the runs whose index `≡ i (mod n)`.
    pub shard: (usize, usize),
}

/// One run of a sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepRow {
    /// Position in the whole sweep (shards keep it, so pieces merge back in order).
    pub index: usize,
    /// Relative gain change.
    pub gain: f64,
    /// Relative dead-time change.
    pub delay: f64,
    /// Relative time-constant change.
    pub tau: f64,
    /// The stability verdict of the perturbed loop: its characteristic
    /// equation's ([`crate::analysis::stability`]), or where that cannot be
    /// decided the run's ([`stable`]).
    pub stable: bool,
    /// Figures of the run (on `e = r − y`).
    pub metrics: Metrics,
    /// Largest actuator magnitude.
    pub max_abs_u: f64,
}

fn axis(r: Range, n: usize) -> Vec<f64> {
    if r.lo == r.hi || n <= 1 {
        return std::vec![0.5 * (r.lo + r.hi)];
    }
    (0..n)
        .map(|i| r.lo + (r.hi - r.lo) * i as f64 / (n - 1) as f64)
        .collect()
}

/// The most runs one sweep may ask for (a grid of 215 points per axis, or
/// 10⁷ random samples); beyond it a sweep is refused before any allocation.
pub const MAX_RUNS: usize = 10_000_000;

impl SweepSpec {
    /// The number of runs of the whole sweep (all shards), or why it cannot run:
    /// no points, more than [`MAX_RUNS`], or a shard that does not exist.
    pub fn runs(&self) -> Result<usize, RunError> {
        let limit = |what: &str, n: String| {
            RunError::Limit(std::format!(
                "{what} asks for {n} runs; the limit is {MAX_RUNS}"
            ))
        };
        if self.shard.1 == 0 || self.shard.0 >= self.shard.1 {
            return Err(RunError::Limit(std::format!(
                "shard {}/{}: the shard index must be below the number of shards",
                self.shard.0,
                self.shard.1
            )));
        }
        if self.samples > 0 {
            if self.samples > MAX_RUNS {
                return Err(limit("samples", self.samples.to_string()));
            }
            return Ok(self.samples);
        }
        if self.grid == 0 {
            return Err(RunError::Limit(
                "grid 0: a grid needs at least one point per axis".into(),
            ));
        }
        let axes = [self.gain, self.delay, self.tau]
            .iter()
            .filter(|r| r.lo != r.hi)
            .count();
        let total = u32::try_from(axes)
            .ok()
            .and_then(|a| self.grid.checked_pow(a))
            .filter(|t| *t <= MAX_RUNS);
        total.ok_or_else(|| limit("grid", std::format!("{}^{axes}", self.grid)))
    }
}

/// Every point of the sweep as `(index, gain, delay, tau)`, this shard only.
pub fn points(spec: &SweepSpec) -> Result<Vec<(usize, f64, f64, f64)>, RunError> {
    spec.runs()?;
    let (i, n) = (spec.shard.0, spec.shard.1.max(1));
    let all: Vec<(f64, f64, f64)> = if spec.samples > 0 {
        let mut rng = Noise::new(spec.seed);
        let pick = |r: Range, rng: &mut Noise| r.lo + (r.hi - r.lo) * rng.uniform();
        (0..spec.samples)
            .map(|_| {
                (
                    pick(spec.gain, &mut rng),
                    pick(spec.delay, &mut rng),
                    pick(spec.tau, &mut rng),
                )
            })
            .collect()
    } else {
        let mut v = Vec::new();
        for g in axis(spec.gain, spec.grid) {
            for d in axis(spec.delay, spec.grid) {
                for t in axis(spec.tau, spec.grid) {
                    v.push((g, d, t));
                }
            }
        }
        v
    };
    Ok(all
        .into_iter()
        .enumerate()
        .filter(|(k, _)| k % n == i)
        .map(|(k, (g, d, t))| (k, g, d, t))
        .collect())
}

pub use crate::study::{settles, stable, swing};

/// Runs the sweep of `base` (its plant perturbed, its model kept nominal; for a
/// cascade process the primary is perturbed, the secondary kept).
/// `progress` is called after each finished run with the count so far.
pub fn sweep(
    base: &Scenario,
    spec: &SweepSpec,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<Vec<SweepRow>, RunError> {
    spec.runs()?;
    let (nominal, model) = base.plant_and_model()?;
    let inner = base.inner_process()?;
    let whole =
        |p: &crate::poly::TransferFunction, i: Option<&crate::poly::TransferFunction>| match i {
            Some(i) => p.series(i),
            None => Ok(p.clone()),
        };
    let mut sc = base.clone();
    let ts = match base.ts {
        Some(ts) => ts,
        None => choose_ts_as(
            &whole(&model, inner.as_ref().map(|(_, m)| m))?,
            base.float32,
        ),
    };
    sc.ts = Some(ts);
    if sc.duration.is_none() {
        sc.duration = Some(choose_duration(
            &whole(&nominal, inner.as_ref().map(|(p, _)| p))?,
            ts,
        ));
    }
    // tune once on the model: every run builds the same controller from it
    let tuned = sc.tune_for(&model, inner.as_ref().map(|(_, m)| m))?;
    let pts = points(spec)?;
    let done = core::sync::atomic::AtomicUsize::new(0);
    let one = |&(index, gain, delay, tau): &(usize, f64, f64, f64)| -> Result<SweepRow, RunError> {
        let plant = nominal.perturbed(gain, delay, tau)?;
        // t, y and u, and the row's metrics only (not the delayed-reference
        // ones nor the event figures)
        let plants = crate::study::Plants {
            plant: &plant,
            model: &model,
            inner: inner.as_ref(),
        };
        let out = sc.run_tuned_measured(&tuned, plants, Keep::Output)?;
        let next = crate::study::next_event(&out.setpoint, &out.disturbance);
        let metrics =
            crate::study::metrics(&out.result.columns(), &out.setpoint, next, out.ts, 0.0)?;
        let max_abs_u = out.result.u.iter().fold(0.0f64, |m, u| m.max(u.abs()));
        let settled = stable(&out);
        // the signals are read: their buffers serve this thread's next run
        crate::study::recycle(out.result);
        // the characteristic equation's verdict; the run's where it is unknown
        let verdict = crate::study::tuned_stability(&sc, &tuned, &plant, &model, inner.as_ref())
            .stable
            .unwrap_or(settled);
        progress(done.fetch_add(1, core::sync::atomic::Ordering::Relaxed) + 1);
        Ok(SweepRow {
            index,
            gain,
            delay,
            tau,
            stable: verdict,
            metrics,
            max_abs_u,
        })
    };
    crate::study::each(&pts, one).into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::Range;

    /// A range is refused when it is not one of relative changes the plant
    /// survives, by the flag's grammar and by the constructor alike.
    #[test]
    fn ranges_are_checked_once() {
        assert_eq!(Range::new(-0.2, 0.2), Ok(Range { lo: -0.2, hi: 0.2 }));
        assert!(Range::new(0.2, -0.2).is_err_and(|e| e.contains("lower end")));
        assert!(Range::new(-1.0, 0.0).is_err_and(|e| e.contains("-100 %")));
        assert!(Range::new(f64::NAN, 0.0).is_err());
        assert_eq!(
            "-20%..+20%".parse(),
            Range::new(-0.2, 0.2).map_err(String::from)
        );
        let flag = "+20%..-20%".parse::<Range>();
        assert!(
            flag.is_err_and(|e| e == "range '+20%..-20%': the lower end is above the upper end")
        );
    }
}

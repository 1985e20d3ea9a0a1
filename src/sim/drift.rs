//! A process that drifts: a parameter moving at a rate over many samples.
//!
//! Plants age, fouling slows a heat exchanger, a conveyor's speed (and so a
//! transport delay) wanders: such changes take hundreds of samples, not one.
//! An event `plant-gain=K~RATE` (likewise `plant-lag`, `plant-dead-time`)
//! starts a drift: from the sample after the event the parameter moves by
//! `RATE·Ts` each sample until it reaches the target. A gain or a lag is set
//! every sample (the plant's output does not jump, as for a step event); a
//! dead time moves by whole samples — a transport delay sampled every `Ts`
//! reads the line one sample further as the drift passes each half sample
//! (the fraction of a sample the plant was built with stays, which keeps the
//! sub-sample pieces exact).

use super::config::{PlantParameter, Process};
use crate::error::Error;

/// One parameter on its way: where it is, where it goes, how far a sample.
#[derive(Debug, Clone, Copy)]
struct Ramp {
    from: f64,
    now: f64,
    to: f64,
    step: f64,
    /// Samples since the drift began (`now = from ± samples·step`: no sum
    /// of many steps drifts off in rounding).
    samples: f64,
    /// The dead time last given to the plant (samples).
    applied: f64,
}

/// The drifts under way, one slot per parameter.
#[derive(Debug, Default)]
pub(super) struct Drifts([Option<Ramp>; 3]);

/// A parameter's slot among the drifts.
fn slot(p: PlantParameter) -> usize {
    match p {
        PlantParameter::DeadTime => 0,
        PlantParameter::Gain => 1,
        PlantParameter::Lag => 2,
    }
}

impl Drifts {
    /// Starts moving `what` to `to` at `rate` per second. The value in the
    /// process's units; a dead time in seconds, as the event writes it.
    pub(super) fn start(
        &mut self,
        process: &Process,
        what: PlantParameter,
        to: f64,
        rate: f64,
        ts: f64,
    ) -> Result<(), Error> {
        let now = process.parameter(what)?;
        let (to, step) = match what {
            // in samples: `rate` seconds a second is `rate` samples a sample
            PlantParameter::DeadTime => {
                let to = to / ts;
                if ((to - now) - (to - now).round()).abs() > 1e-6 {
                    return Err(Error::Unsupported(
                        "a plant dead-time drift must end on the dead time's fraction of a sample (drift by whole samples)",
                    ));
                }
                (now + (to - now).round(), rate)
            }
            PlantParameter::Gain | PlantParameter::Lag => (to, rate * ts),
        };
        if let Some(slot) = self.0.get_mut(slot(what)) {
            *slot = Some(Ramp {
                from: now,
                now,
                to,
                step,
                samples: 0.0,
                applied: now,
            });
        }
        Ok(())
    }

    /// A step event of the same parameter ends its drift.
    pub(super) fn stop(&mut self, what: PlantParameter) {
        if let Some(slot) = self.0.get_mut(slot(what)) {
            *slot = None;
        }
    }

    /// Any drift under way (every sample is then a segment of its own).
    pub(super) fn active(&self) -> bool {
        self.0.iter().any(Option::is_some)
    }

    /// One sample of every drift under way: each parameter moves a step
    /// towards its target; one that arrives ends its drift.
    pub(super) fn advance(&mut self, process: &mut Process) -> Result<(), Error> {
        for (slot, what) in self.0.iter_mut().zip([
            PlantParameter::DeadTime,
            PlantParameter::Gain,
            PlantParameter::Lag,
        ]) {
            let Some(r) = slot.as_mut() else { continue };
            r.samples += 1.0;
            let on = r.from + (r.samples * r.step).copysign(r.to - r.from);
            r.now = if (on - r.from).abs() >= (r.to - r.from).abs() {
                r.to
            } else {
                on
            };
            match what {
                PlantParameter::DeadTime => {
                    // whole samples from where it was: the fraction stays
                    let whole = r.applied + (r.now - r.applied).round();
                    if whole != r.applied {
                        process.set_dead_time(whole)?;
                        r.applied = whole;
                    }
                }
                PlantParameter::Gain => process.set_gain(r.now)?,
                PlantParameter::Lag => process.set_lag(r.now)?,
            }
            if r.now == r.to {
                *slot = None;
            }
        }
        Ok(())
    }
}

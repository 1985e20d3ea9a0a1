//! The margins of a tuned loop and what they warn of, with the `λ` or the
//! scheme that would do better.

use std::string::{String, ToString};
use std::vec::Vec;

use super::{Scenario, Tuned};
use crate::poly::TransferFunction;
use crate::registry;

/// The margins of a tuned loop and the warnings they give
/// ([`Scenario::robustness`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Robustness {
    /// Gain, phase and delay margins and the sensitivity peaks.
    pub margins: crate::analysis::Margins,
    /// What they warn of, with the `λ` that would do better.
    pub warnings: Vec<String>,
}

/// Three significant digits, for numbers in messages.
fn round3(v: f64) -> f64 {
    crate::poly::round_sig(v, 3)
}

/// Frequencies of the grid a candidate's margins are screened on (the
/// loop's own are computed on 6000): the crossings and peaks are refined
/// between grid points, so a coarse grid finds the same margins where the
/// loop's response has no narrow resonance between two of its points.
const SCREEN: usize = 300;

/// How a robustness warning's advice is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Advice {
    /// The better tuning named with its price: the overshoot, settling
    /// time and load IAE now and then (four runs).
    Priced,
    /// What is wrong said, no better tuning searched for (a draft).
    Omitted,
}

/// The memory the runs that price a piece of advice may take.
const PRICE_MEMORY: u64 = 32 << 20;

/// What a tuning costs in the time domain: the set-point step's overshoot
/// (%) and settling time (s), and the IAE of a unit step load at the plant
/// input. A run that had not settled when its budget stopped it gives
/// lower bounds: its length for the settling time, its IAE so far
/// (`*_settled` false), never a figure that contradicts the run's own.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Price {
    overshoot: f64,
    settling: f64,
    load_iae: f64,
    step_settled: bool,
    load_settled: bool,
}

impl Price {
    /// `settling` and the load's IAE as text: `> x` for a lower bound.
    fn figures(&self) -> (String, String) {
        let bound = |settled: bool, v: f64| {
            let v = crate::poly::fmt_num(round3(v));
            if settled {
                v
            } else {
                std::format!("> {v}")
            }
        };
        (
            bound(self.step_settled, self.settling),
            bound(self.load_settled, self.load_iae),
        )
    }

    /// `, at a price: …` from `self` (the tuning in use) to `then`.
    fn to(&self, then: &Price) -> String {
        let ((s0, l0), (s1, l1)) = (self.figures(), then.figures());
        std::format!(
            ", at a price: overshoot {} % → {} %, settling {s0} s → {s1} s, IAE of a unit input load {l0} → {l1}",
            crate::poly::fmt_num(round3(self.overshoot)),
            crate::poly::fmt_num(round3(then.overshoot)),
        )
    }
}

impl Scenario {
    /// The [`Price`] of `tuned` on `plant`: a unit set-point step alone, then
    /// a unit input load alone, each at the durations msp chooses.
    fn price(
        &self,
        tuned: &Tuned,
        plant: &TransferFunction,
        model: &TransferFunction,
    ) -> Option<Price> {
        let mut sc = self.clone();
        (sc.disturbance, sc.events, sc.duration, sc.noise) = (Vec::new(), Vec::new(), None, None);
        // advice, not the run: a small budget (the runs stop extending at it,
        // or there is no price), so that it never weighs on the run itself
        sc.max_memory = Some(
            self.max_memory
                .unwrap_or(super::DEFAULT_MAX_MEMORY)
                .min(PRICE_MEMORY),
        );
        sc.setpoint = std::vec![crate::sim::SetpointStep {
            value: 1.0,
            at: 0.0
        }];
        let step = sc
            .run_tuned(tuned, plant.clone(), model.clone(), None)
            .ok()?;
        let step_settled = step.has_settled();
        let (overshoot, settling) = (
            step.metrics.step.overshoot,
            if step_settled {
                step.metrics.step.settling_time
            } else {
                step.duration
            },
        );
        // each run's buffers for the next: it writes into memory already mapped
        super::recycle(step.result);
        sc.setpoint = std::vec![crate::sim::SetpointStep {
            value: 0.0,
            at: 0.0
        }];
        sc.disturbance = std::vec![crate::sim::Disturbance::input_step(1.0, 0.0)];
        let load = sc
            .run_tuned(tuned, plant.clone(), model.clone(), None)
            .ok()?;
        let price = Price {
            overshoot,
            settling,
            load_iae: load.metrics.indices.iae,
            step_settled,
            load_settled: load.has_settled(),
        };
        super::recycle(load.result);
        Some(price)
    }

    /// The margins of a tuned controller on `plant` (sampled view) on a
    /// grid of `points` frequencies.
    pub(crate) fn margins_of_tuned(
        &self,
        tuned: &Tuned,
        plant: &TransferFunction,
        model: &TransferFunction,
        points: usize,
    ) -> Option<crate::analysis::Margins> {
        let built = self.build_tuned(tuned, model, None).ok()?;
        crate::analysis::margins_on(
            built.controller.as_ref(),
            plant,
            built.ts,
            crate::analysis::View::Sampled,
            points,
        )
        .ok()
    }

    /// The margins of the tuned single loop on the plant (sampled view:
    /// the plant behind the hold, exact delay) and what they warn of: a
    /// sensitivity peak `Ms > 2` (Åström & Hägglund (2006) use `Ms` as the
    /// robustness measure, with 1.2–2 as the usual design range) or a delay
    /// margin below 20 % of the dead time (msp's own threshold: a dead time
    /// 20 % longer than modelled is a common model error; no source gives
    /// one), or a parameter outside a source's stability range
    /// ([`registry::DesignValue::StableRange`]); the warning names the `λ` (the tuning rule's, retuned in steps
    /// up to 8× the present one) that gives `Ms ≤ 2` with a delay margin of
    /// at least 20 % of the dead time. `None` for a controller without a
    /// frequency response.
    pub fn robustness(
        &self,
        tuned: &Tuned,
        plant: &TransferFunction,
        model: &TransferFunction,
    ) -> Option<Robustness> {
        self.robustness_advising(tuned, plant, model, Advice::Priced)
    }

    /// [`Scenario::robustness`] with its advice, or without (a draft).
    pub(crate) fn robustness_advising(
        &self,
        tuned: &Tuned,
        plant: &TransferFunction,
        model: &TransferFunction,
        advice: Advice,
    ) -> Option<Robustness> {
        // candidates are screened on a coarser grid than the loop's own margins
        let margins_of = |t: &Tuned| self.margins_of_tuned(t, plant, model, SCREEN);
        let margins = self.margins_of_tuned(tuned, plant, model, 6000)?;
        let theta = plant.delay;
        let fine = |m: &crate::analysis::Margins| m.ms <= 2.0 && m.dm >= 0.2 * theta;
        let mut warnings = Vec::new();
        if !fine(&margins) {
            let mut what = Vec::new();
            if margins.ms > 2.0 {
                what.push(std::format!(
                    "the sensitivity peak Ms = {} is above 2",
                    crate::poly::fmt_num(round3(margins.ms))
                ));
            }
            if theta > 0.0 && margins.dm < 0.2 * theta {
                what.push(std::format!(
                    "the delay margin {} s is {} % of the dead time",
                    crate::poly::fmt_num(round3(margins.dm)),
                    crate::poly::fmt_num((100.0 * margins.dm / theta).round())
                ));
            }
            // parameters the user set are the user's choice: no advice on
            // them; a draft says what is wrong and leaves the search for later
            let advise = self.set.is_empty() && advice == Advice::Priced;
            let better = tuned.params.lambda().filter(|_| advise).and_then(|l| {
                [1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0]
                    .into_iter()
                    .map(|f| round3(l * f))
                    .find_map(|l2| {
                        let mut sc = self.clone();
                        sc.lambda = Some(l2);
                        let t = sc.tune_for(model, None).ok()?;
                        let m = margins_of(&t)?;
                        fine(&m).then_some((l2, m.ms))
                    })
            });
            // no λ of this rule will do: the scheme (default tuning) that does best
            let other = || {
                registry::SCHEMES
                    .iter()
                    .filter(|s| !s.is_cascade() && s.name != tuned.scheme.name)
                    .filter_map(|s| {
                        let mut sc = self.clone();
                        sc.controller = Some(s.name.to_string());
                        (sc.lambda, sc.rule) = (None, None);
                        sc.set.clear();
                        let t = sc.tune_for(model, None).ok()?;
                        let m = sc.margins_of_tuned(&t, plant, model, SCREEN)?;
                        fine(&m).then_some((s.name, m.ms))
                    })
                    .min_by(|a, b| a.1.total_cmp(&b.1))
            };
            let now = advise.then(|| self.price(tuned, plant, model)).flatten();
            let cost = |other: Option<Price>| match (now, other) {
                (Some(a), Some(b)) => a.to(&b),
                _ => String::new(),
            };
            let advice = match (better, (advise && better.is_none()).then(other).flatten()) {
                (Some((l, ms)), _) => {
                    let mut sc = self.clone();
                    sc.lambda = Some(l);
                    let price = sc
                        .tune_for(model, None)
                        .ok()
                        .and_then(|t| sc.price(&t, plant, model));
                    std::format!(
                        "; --lambda {} (Python: lambda_=) gives Ms = {} with a delay margin of at least 20 % of the dead time{}",
                        crate::poly::fmt_num(l),
                        crate::poly::fmt_num(round3(ms)),
                        cost(price)
                    )
                }
                (None, Some((name, ms))) => {
                    let mut sc = self.clone();
                    sc.controller = Some(name.to_string());
                    (sc.lambda, sc.rule) = (None, None);
                    sc.set.clear();
                    let price = sc
                        .tune_for(model, None)
                        .ok()
                        .and_then(|t| sc.price(&t, plant, model));
                    std::format!(
                        "; no λ of this tuning rule does better, --controller {name} (default tuning) gives Ms = {} with a delay margin of at least 20 % of the dead time{}",
                        crate::poly::fmt_num(round3(ms)),
                        cost(price)
                    )
                }
                (None, None) => String::new(),
            };
            if !what.is_empty() {
                warnings.push(std::format!(
                    "robustness: {}: a model error of that size makes the loop oscillate or diverge{advice}",
                    what.join(" and ")
                ));
            }
        }
        // a source's stability range of a parameter (Karan–Dey's γ, Bag
        // (2022) Eq. 4.49)
        if let Ok((ts, _)) = self.check_size(model, None) {
            let design = tuned
                .scheme
                .design_report(&tuned.params, model, None, ts)
                .unwrap_or_default();
            for (_, value) in &design {
                let registry::DesignValue::StableRange {
                    param,
                    low: lo,
                    high: hi,
                } = value
                else {
                    continue;
                };
                let Some(v) = tuned.params.get(param) else {
                    continue;
                };
                if !(v > *lo && v < *hi) {
                    warnings.push(std::format!(
                        "robustness: {param} = {} is outside its stability range ({}, {}) given by {}: the loop is unstable for the model",
                        crate::poly::fmt_num(round3(v)),
                        crate::poly::fmt_num(round3(*lo)),
                        crate::poly::fmt_num(round3(*hi)),
                        tuned.scheme.source
                    ));
                }
            }
        }
        Some(Robustness { margins, warnings })
    }
}

#[cfg(test)]
mod tests {
    use super::Price;

    /// A price run cut short by its budget gives lower bounds (`> x`), so
    /// that the advice never shows a settling time below the one the run
    /// itself measured (`--float32` on `5e^-6s/(100s-1)`: 1790 s in a
    /// truncated advice run against 2443 s in the run's own step line).
    #[test]
    fn a_price_run_cut_short_gives_lower_bounds() {
        let cut = Price {
            overshoot: 15.4,
            settling: 1790.0,
            load_iae: 5.44,
            step_settled: false,
            load_settled: false,
        };
        let whole = Price {
            overshoot: 18.4,
            settling: 557.0,
            load_iae: 19.5,
            step_settled: true,
            load_settled: true,
        };
        assert_eq!(
            cut.to(&whole),
            ", at a price: overshoot 15.4 % → 18.4 %, settling > 1790 s → 557 s, IAE of a unit input load > 5.44 → 19.5"
        );
        assert_eq!(
            whole.to(&whole),
            ", at a price: overshoot 18.4 % → 18.4 %, settling 557 s → 557 s, IAE of a unit input load 19.5 → 19.5"
        );
    }
}

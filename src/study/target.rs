//! Design targets (MATLAB `pidtune`'s options): the free parameter of a
//! scheme's tuning (`λ`) solved so that the loop meets a robustness or
//! bandwidth figure, on the exact analysis of the sampled loop.

use std::format;
use std::string::{String, ToString};
use std::vec::Vec;

use super::{RunError, Scenario, Tuned};
use crate::analysis::Margins;
use crate::error::Error;
use crate::poly::TransferFunction;

/// The figure a design target fixes.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Figure {
    /// The sensitivity peak `Ms`.
    Ms,
    /// The phase margin (degrees).
    Pm,
    /// The gain margin (absolute ratio).
    Gm,
    /// The delay margin (s), or as a fraction of the model's dead time
    /// (`dm=0.3θ`).
    Dm,
    /// The gain-crossover frequency (rad/s), MATLAB's `wc`.
    Wc,
}

impl Figure {
    /// The name in targets and reports.
    pub fn name(self) -> &'static str {
        match self {
            Figure::Ms => "ms",
            Figure::Pm => "pm",
            Figure::Gm => "gm",
            Figure::Dm => "dm",
            Figure::Wc => "wc",
        }
    }

    /// The figure of a loop's margins.
    pub fn of(self, m: &Margins) -> f64 {
        match self {
            Figure::Ms => m.ms,
            Figure::Pm => m.pm,
            Figure::Gm => m.gm,
            Figure::Dm => m.dm,
            Figure::Wc => m.wcp,
        }
    }

    /// True when a larger value is the more robust (slower) loop.
    fn grows_with_robustness(self) -> bool {
        !matches!(self, Figure::Ms | Figure::Wc)
    }
}

/// A design target: `ms=1.4`, `pm=60`, `gm=3`, `dm=0.3θ` (or `dm=2` s),
/// `wc=0.2` (rad/s), each solved for with the tuning's `λ`; or a crossover
/// and a phase margin together, `wc=0.006,pm=60` (`pidtune`'s two targets),
/// which design a PI or a PID at the crossover ([`crate::tuning::pi_at`]).
/// A scenario file writes it as the flag does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Target {
    /// The figure.
    pub figure: Figure,
    /// Its value (`dm` in seconds, or a fraction of the dead time with `of_dead_time`).
    pub value: f64,
    /// `dm` given as a fraction of the model's dead time.
    pub of_dead_time: bool,
    /// With `wc`: the phase margin (degrees) designed for at that
    /// crossover (two targets, `wc=…,pm=…`).
    pub pm: Option<f64>,
}

#[cfg(feature = "serde")]
impl serde::Serialize for Target {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for Target {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

impl core::str::FromStr for Target {
    type Err = String;
    /// `NAME=VALUE`: `ms`, `pm` (degrees), `gm` (ratio, or `…dB`), `dm`
    /// (seconds, or `…θ`/`…theta`: a fraction of the dead time), `wc` (rad/s).
    fn from_str(s: &str) -> Result<Self, String> {
        if let Some((a, b)) = s.split_once(',') {
            let (a, b): (Target, Target) = (a.parse()?, b.parse()?);
            let (wc, pm) = match (a.figure, b.figure) {
                (Figure::Wc, Figure::Pm) => (a, b),
                (Figure::Pm, Figure::Wc) => (b, a),
                _ => {
                    return Err(format!(
                        "two targets together are a crossover and a phase margin (wc=0.006,pm=60, as pidtune's), got '{s}'"
                    ))
                }
            };
            if wc.pm.is_some() || pm.pm.is_some() {
                return Err(format!("at most two targets, got '{s}'"));
            }
            return Ok(Target {
                pm: Some(pm.value),
                ..wc
            });
        }
        let (name, value) = s.split_once('=').ok_or_else(|| {
            format!("a target is NAME=VALUE (ms=1.4, pm=60, gm=3, dm=0.3θ, wc=0.2), got '{s}'")
        })?;
        let figure = match name.trim().to_ascii_lowercase().as_str() {
            "ms" => Figure::Ms,
            "pm" => Figure::Pm,
            "gm" => Figure::Gm,
            "dm" => Figure::Dm,
            "wc" => Figure::Wc,
            other => return Err(format!("unknown target '{other}': ms, pm, gm, dm or wc")),
        };
        let v = value.trim();
        let (num, of_dead_time, db) =
            if let Some(x) = v.strip_suffix("theta").or(v.strip_suffix('θ')) {
                (x.trim(), true, false)
            } else if let Some(x) = v.strip_suffix("dB").or(v.strip_suffix("db")) {
                (x.trim(), false, true)
            } else {
                (v.strip_suffix('s').unwrap_or(v).trim(), false, false)
            };
        if of_dead_time && figure != Figure::Dm {
            return Err(format!(
                "only dm takes a fraction of the dead time (θ), got '{s}'"
            ));
        }
        if db && figure != Figure::Gm {
            return Err(format!("only gm is given in dB, got '{s}'"));
        }
        let mut value: f64 = num
            .parse()
            .map_err(|_| format!("target {}: '{num}' is not a number", figure.name()))?;
        if db {
            value = 10f64.powf(value / 20.0);
        }
        let ok = value.is_finite()
            && match figure {
                Figure::Ms | Figure::Gm => value > 1.0,
                Figure::Pm => value > 0.0 && value < 180.0,
                Figure::Dm | Figure::Wc => value > 0.0,
            };
        if !ok {
            return Err(format!(
                "target {}: {} is out of range ({})",
                figure.name(),
                crate::poly::fmt_num(value),
                match figure {
                    Figure::Ms => "Ms > 1",
                    Figure::Gm => "a gain margin above 1 (0 dB)",
                    Figure::Pm => "0 < pm < 180 degrees",
                    Figure::Dm => "a positive delay margin",
                    Figure::Wc => "a positive frequency",
                }
            ));
        }
        Ok(Target {
            figure,
            value,
            of_dead_time,
            pm: None,
        })
    }
}

impl core::fmt::Display for Target {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let v = crate::poly::fmt_num(crate::poly::round_sig(self.value, 6));
        if self.of_dead_time {
            write!(f, "{}={}θ", self.figure.name(), v)?;
        } else {
            write!(f, "{}={}", self.figure.name(), v)?;
        }
        if let Some(pm) = self.pm {
            write!(
                f,
                ",pm={}",
                crate::poly::fmt_num(crate::poly::round_sig(pm, 6))
            )?;
        }
        Ok(())
    }
}

/// What a target gave: the `λ` found and the figures the loop reaches.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TargetReport {
    /// The target as given (`ms=1.4`).
    pub target: String,
    /// The figure.
    pub figure: Figure,
    /// The value asked for, in the figure's unit (`dm` in seconds).
    pub value: f64,
    /// The value the tuned loop reaches (from its margins).
    pub achieved: f64,
    /// The `λ` solved for (none for a design at the crossover).
    pub lambda: Option<f64>,
    /// With the crossover: the phase margin asked for (degrees) and the one
    /// the tuned loop reaches.
    pub pm: Option<f64>,
    /// The phase margin the tuned loop reaches (degrees), with `pm`.
    pub pm_achieved: Option<f64>,
    /// Said when the figure is not monotone in `λ` over the range searched:
    /// which crossing was taken.
    pub branch: Option<String>,
}

impl TargetReport {
    /// What the tuning did for the target, as the reports say it:
    /// `lambda = 6.1 gives ms = 1.4`, or for a design at the crossover
    /// `designed at the crossover: wc = 0.006, pm = 60` (the sampled loop's).
    pub fn outcome(&self) -> String {
        let fmt = |v: f64| crate::poly::fmt_num(crate::poly::round_sig(v, 4));
        match (self.lambda, self.pm_achieved) {
            (Some(l), _) => format!(
                "lambda = {} gives {} = {}",
                fmt(l),
                self.figure.name(),
                fmt(self.achieved)
            ),
            (None, pm) => format!(
                "designed at the crossover: {} = {}, pm = {}",
                self.figure.name(),
                fmt(self.achieved),
                pm.map_or_else(|| "-".to_string(), fmt)
            ),
        }
    }
}

/// The range of `λ` searched: from 1/64 to 64 times the rule's own, on a
/// logarithmic grid of this many points per factor of 2.
const OCTAVES: i32 = 6;
const PER_OCTAVE: i32 = 2;

impl Target {
    /// The value in the figure's unit for a model with dead time `theta` (s).
    pub fn resolved(&self, theta: f64) -> f64 {
        if self.of_dead_time {
            self.value * theta
        } else {
            self.value
        }
    }
}

/// The intervals of a sampled curve `(λ, figure)` (λ increasing) where the
/// figure crosses `value`, in order: more than one when it is not monotone.
fn crossings(pts: &[(f64, f64)], value: f64) -> Vec<[(f64, f64); 2]> {
    pts.windows(2)
        .filter_map(|w| {
            let (a, b) = (*w.first()?, *w.get(1)?);
            ((a.1 - value) * (b.1 - value) <= 0.0).then_some([a, b])
        })
        .collect()
}

impl Scenario {
    /// The figure of the loop tuned with `lambda` on `model` (the nominal
    /// loop: the model as the plant), or `None` where the loop is not stable
    /// (its margins do not apply) or the tuning fails.
    fn figure_at(&self, model: &TransferFunction, lambda: f64, figure: Figure) -> Option<f64> {
        let mut sc = self.clone();
        sc.lambda = Some(lambda);
        sc.target = None;
        let t = sc.tune_for(model, None).ok()?;
        let st = super::tuned_stability(&sc, &t, model, model, None);
        if st.stable != Some(true) {
            return None;
        }
        let m = sc.margins_of_tuned(&t, model, model, 600)?;
        Some(figure.of(&m)).filter(|v| v.is_finite())
    }

    /// Solves the tuning's `λ` so that the nominal loop (the model as the
    /// plant, sampled, exact delay) meets `target`: the figure is sampled on
    /// a logarithmic grid of `λ` from 1/64 to 64 times the rule's own,
    /// stable loops only, and bisected on `ln λ` in a bracket where it
    /// crosses the target. Where it crosses more than once (not monotone) the
    /// crossing of the larger `λ` (the slower, more robust branch) is taken
    /// and the report says so. A target no `λ` reaches is an error naming
    /// the best value this scheme reaches and the scheme that reaches the
    /// target, if one does.
    pub(crate) fn solve_target(
        &self,
        target: Target,
        model: &TransferFunction,
        tuned: &Tuned,
    ) -> Result<(f64, TargetReport), RunError> {
        let name = tuned.scheme.name;
        let l0 = tuned
            .params
            .lambda()
            .filter(|l| l.is_finite() && *l > 0.0)
            .ok_or(RunError::Invalid(Error::Unsupported(
                "a design target needs a scheme tuned by lambda (this scheme's tuning has no free parameter)",
            )))?;
        let value = target.resolved(model.delay);
        let pts = self.figure_curve(model, l0, target.figure);
        let reached = |p: &[(f64, f64)]| -> Option<(f64, f64)> {
            p.iter()
                .map(|x| x.1)
                .fold(None, |acc: Option<(f64, f64)>, v| match acc {
                    None => Some((v, v)),
                    Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
                })
        };
        let crossings = crossings(&pts, value);
        let Some(&[a, b]) = crossings.last() else {
            return Err(self.unreachable(target, value, model, name, reached(&pts)));
        };
        let figure = target.figure;
        let (mut lo, mut flo, mut hi) = (a.0, a.1, b.0);
        for _ in 0..40 {
            let mid = (lo * hi).sqrt();
            let Some(f) = self.figure_at(model, mid, figure) else {
                break;
            };
            if (f - value) * (flo - value) <= 0.0 {
                hi = mid;
            } else {
                (lo, flo) = (mid, f);
            }
            if hi / lo < 1.0 + 1e-6 {
                break;
            }
        }
        let lambda = (lo * hi).sqrt();
        let achieved = self.figure_at(model, lambda, figure).unwrap_or(f64::NAN);
        let branch = (crossings.len() > 1).then(|| {
            format!(
                "{} is not monotone in lambda: {} crossings of {} between lambda = {} and {}; the one at the largest lambda (the slower, more robust loop) is taken",
                figure.name(),
                crossings.len(),
                crate::poly::fmt_num(crate::poly::round_sig(value, 4)),
                crate::poly::fmt_num(crate::poly::round_sig(pts.first().map_or(f64::NAN, |p| p.0), 3)),
                crate::poly::fmt_num(crate::poly::round_sig(pts.last().map_or(f64::NAN, |p| p.0), 3)),
            )
        });
        Ok((
            lambda,
            TargetReport {
                target: target.to_string(),
                figure,
                value,
                achieved,
                lambda: Some(lambda),
                pm: None,
                pm_achieved: None,
                branch,
            },
        ))
    }

    /// The PI or PID designed at the crossover `target.value` with the
    /// phase margin `target.pm` ([`crate::tuning::pi_at`],
    /// [`crate::tuning::pid_at`], on the plant's frequency response with
    /// the exact delay, as `pidtune` designs the continuous controller),
    /// then run sampled: the report gives the crossover and the phase
    /// margin of the sampled loop (the exact analysis), which the
    /// controller's sampling moves by a fraction of `ωc·Ts`.
    pub(crate) fn design_at_crossover(
        &self,
        target: Target,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
        tuned: Tuned,
        overrides: &[(String, f64)],
    ) -> Result<Tuned, RunError> {
        let unsupported = |m: &'static str| RunError::Invalid(Error::Unsupported(m));
        let pm = target.pm.unwrap_or(60.0);
        let pid = match tuned.scheme.name {
            "pi" => false,
            "pid" => true,
            _ => {
                return Err(unsupported(
                    "a crossover with a phase margin (wc=…,pm=…) designs a PI or a PID, as pidtune does: use --controller pi or pid",
                ))
            }
        };
        if inner.is_some() {
            return Err(unsupported(
                "a design target is for a single loop (not a cascade process)",
            ));
        }
        if self.lambda.is_some() || self.rule.is_some() {
            return Err(unsupported(
                "a crossover with a phase margin designs the gains: give it or --lambda/--rule, not both",
            ));
        }
        let wc = target.value;
        let (re, im) = model.freq(wc);
        // a reverse-acting plant: designed for −G, the controller's gain
        // negative
        let sign = model.lead_sign();
        let phase = model.phase(wc).map_err(RunError::Invalid)?
            + if sign < 0.0 {
                core::f64::consts::PI
            } else {
                0.0
            };
        let gains = if pid {
            crate::tuning::pid_at(re.hypot(im), phase, wc, pm)
        } else {
            crate::tuning::pi_at(re.hypot(im), phase, wc, pm)
        }
        .map(|g| crate::tuning::PidGains {
            kp: sign * g.kp,
            ..g
        })
        .map_err(|e| match e {
            Error::Unsupported(m) => {
                RunError::Limit(format!("the target {target} is out of reach: {m}"))
            }
            other => RunError::Invalid(other),
        })?;
        let params = crate::registry::Params::of(&gains).with_rule(crate::registry::Rule {
            name: "crossover",
            ku: None,
            tu: None,
            weights: None,
        });
        // the design sets every parameter and has no λ-rule's design values
        // (lambda, alpha): a --set name is refused, never dropped
        if let Some((k, _)) = overrides.first() {
            return Err(RunError::Limit(format!(
                "a crossover with a phase margin designs {}'s kp, ti and td and nothing else: drop --set {k}=",
                tuned.scheme.name
            )));
        }
        let mut t = Tuned {
            scheme: tuned.scheme,
            params,
            lambda_chosen: false,
            target: None,
        };
        let m = self.margins_of_tuned(&t, model, model, 6000);
        t.target = Some(TargetReport {
            target: target.to_string(),
            figure: Figure::Wc,
            value: wc,
            achieved: m.as_ref().map_or(f64::NAN, |m| m.wcp),
            lambda: None,
            pm: Some(pm),
            pm_achieved: m.map(|m| m.pm),
            branch: None,
        });
        Ok(t)
    }

    /// `(λ, figure)` of the stable loops on the search grid.
    fn figure_curve(&self, model: &TransferFunction, l0: f64, figure: Figure) -> Vec<(f64, f64)> {
        (-OCTAVES * PER_OCTAVE..=OCTAVES * PER_OCTAVE)
            .filter_map(|k| {
                let l = l0 * 2f64.powf(f64::from(k) / f64::from(PER_OCTAVE));
                self.figure_at(model, l, figure).map(|f| (l, f))
            })
            .collect()
    }

    /// The error of a target scheme `name` does not reach: its range, and
    /// the other schemes for the plant that do reach it.
    fn unreachable(
        &self,
        target: Target,
        value: f64,
        model: &TransferFunction,
        name: &str,
        range: Option<(f64, f64)>,
    ) -> RunError {
        let fmt = |v: f64| crate::poly::fmt_num(crate::poly::round_sig(v, 3));
        let f = target.figure;
        let what = match range {
            Some((lo, hi)) => {
                // the value nearest the target
                let best = if (value - lo).abs() < (value - hi).abs() {
                    lo
                } else {
                    hi
                };
                let side = if (best < value) == f.grows_with_robustness() {
                    "at its most robust"
                } else {
                    "at its fastest"
                };
                format!(
                    "{name} reaches {} from {} to {} over lambda in 1/64..64 times its own ({side}: {})",
                    f.name(),
                    fmt(lo),
                    fmt(hi),
                    fmt(best)
                )
            }
            None => format!("{name} gives no stable loop over lambda in 1/64..64 times its own"),
        };
        let others: Vec<&'static str> = crate::registry::SCHEMES
            .iter()
            .filter(|s| s.name != name && !s.is_cascade() && s.plants.contains(&model.kind()))
            .filter(|s| {
                let mut sc = self.clone();
                sc.controller = Some(s.name.into());
                sc.target = None;
                sc.rule = None;
                let Ok(t) = sc.tune_for(model, None) else {
                    return false;
                };
                let Some(l0) = t.params.lambda().filter(|l| l.is_finite() && *l > 0.0) else {
                    return false;
                };
                !crossings(&sc.figure_curve(model, l0, f), value).is_empty()
            })
            .map(|s| s.name)
            .collect();
        let alt = if others.is_empty() {
            "no other scheme for this plant reaches it either".to_string()
        } else {
            format!("reached by: {}", others.join(", "))
        };
        RunError::Limit(format!(
            "the target {target} is out of reach: {what}; {alt}"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::crossings;

    /// A figure that rises and falls crosses a value twice: both intervals
    /// are found, in order, and the solver takes the last (the larger λ,
    /// the branch the report names); a monotone one crosses once; a value
    /// out of its range, never.
    #[test]
    fn crossings_of_a_non_monotone_figure() {
        let hump: Vec<(f64, f64)> = (1..=9)
            .map(|k| (f64::from(k), -(f64::from(k) - 5.0).powi(2)))
            .collect();
        let c = crossings(&hump, -2.0);
        assert_eq!(c.len(), 2);
        assert_eq!((c[0][0].0, c[1][1].0), (3.0, 7.0));
        let rising: Vec<(f64, f64)> = (1..=9).map(|k| (f64::from(k), f64::from(k))).collect();
        assert_eq!(crossings(&rising, 4.5), vec![[(4.0, 4.0), (5.0, 5.0)]]);
        assert!(crossings(&rising, 10.0).is_empty());
    }
}

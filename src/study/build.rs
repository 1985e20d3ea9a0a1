//! From a scenario to a built controller: the scheme chosen, tuned and
//! built at a sample period, within the scenario's memory budget.

use std::string::String;

use super::{choose_ts_as, RunError, Scenario, DEFAULT_MAX_MEMORY};
use crate::error::Error;
use crate::poly::TransferFunction;
use crate::registry::{self, Build, Params, MAX_ORDER};

/// Bytes per sample of the controller's dead time: a scheme holds up to four
/// lines of it (the model's, a filter's or a second model's) in `f64`.
pub(super) const CONTROLLER_BYTES_PER_SAMPLE: f64 = 32.0;
/// Bytes per sample of the plant's dead time in the simulator (two lines).
pub(crate) const PLANT_BYTES_PER_SAMPLE: f64 = 16.0;
/// The columns every run records: `t`, `y`, `u`, `u_applied`, `r`, `d`,
/// `d_out` (a cascade two more, `y2` and `d_inner`); each of the
/// controller's signals is one more, every column a `f64` a row.
pub(super) const RECORDED_COLUMNS: f64 = 7.0;
/// Bytes per scheduled set-point step, disturbance or operator event, as a
/// run holds them, rounded up (measured: 700 000 events from a TOML file ran
/// in 186 MB with their 700 000 recorded rows).
pub(super) const BYTES_PER_SCHEDULED: f64 = 256.0;

/// `bytes` as people read it: `1.5 GiB`, `12 MiB`.
fn human(bytes: f64) -> String {
    let units = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = bytes;
    let mut u = 0usize;
    while v >= 1024.0 && u + 1 < units.len() {
        v /= 1024.0;
        u += 1;
    }
    let unit = units.get(u).copied().unwrap_or("bytes");
    if v.is_finite() {
        std::format!("{} {unit}", crate::poly::fmt_num((v * 10.0).round() / 10.0))
    } else {
        "an unbounded amount".into()
    }
}

/// A scheme and its tuned parameters: the typed value the study hands from
/// tuning to construction (a sweep tunes once and builds every run from it).
#[derive(Debug, Clone)]
pub struct Tuned {
    /// The scheme.
    pub scheme: &'static registry::Scheme,
    /// Its parameters (tuned, then `--set`).
    pub params: Params,
    /// Whether `lambda` was chosen by the tuning rule (the parameters have
    /// one, and neither `--lambda` nor `--set lambda=` gave it).
    pub lambda_chosen: bool,
    /// The design target `λ` was solved for, and what the loop reaches.
    pub target: Option<super::TargetReport>,
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
    /// What the build could not do as the scenario asked (a run's notes).
    pub notes: Vec<String>,
}

/// The memory this process can still have, or `None` where none of it can
/// be read: the least of what the system can give (Linux's
/// `MemAvailable`), what the process's address-space limit leaves
/// (`RLIMIT_AS`, less its address space now: `ulimit -v`) and what its
/// control group's limit leaves (cgroup v2 `memory.max` less
/// `memory.current`: a container's).
fn available_memory() -> Option<f64> {
    let read = |path: &str| std::fs::read_to_string(path).ok();
    let field = |text: &str, key: &str| -> Option<f64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        line.get(key.len()..)?
            .split_whitespace()
            .next()?
            .parse()
            .ok()
    };
    let system = read("/proc/meminfo")
        .and_then(|t| field(&t, "MemAvailable:"))
        .map(|k| k * 1024.0);
    let address = read("/proc/self/limits")
        .and_then(|t| field(&t, "Max address space"))
        .and_then(|limit| {
            let used = read("/proc/self/status").and_then(|t| field(&t, "VmSize:"))? * 1024.0;
            Some((limit - used).max(0.0))
        });
    let group = read("/sys/fs/cgroup/memory.max").and_then(|m| {
        let max: f64 = m.trim().parse().ok()?;
        let now: f64 = read("/sys/fs/cgroup/memory.current")?.trim().parse().ok()?;
        Some((max - now).max(0.0))
    });
    [system, address, group]
        .into_iter()
        .flatten()
        .reduce(f64::min)
}

/// Refuses what needs about `bytes` (described by `what`) when that is above
/// the budget `max_memory` (default [`DEFAULT_MAX_MEMORY`]; a run among `n`
/// side by side has an `n`-th of it) or above what the machine can still
/// give: checked before anything is allocated, so that a budget raised past
/// the machine ends in this error, not in an abort.
pub fn check_budget(max_memory: Option<u64>, bytes: f64, what: &str) -> Result<(), RunError> {
    // runs side by side (a sweep, a trade-off, a comparison) share it
    let share = super::SHARE.with(core::cell::Cell::get).max(1);
    let limit = max_memory.unwrap_or(DEFAULT_MAX_MEMORY) / share;
    #[allow(clippy::cast_precision_loss)] // a budget in bytes, compared roughly
    let limit_f = limit as f64;
    if bytes.is_nan() || bytes > limit_f {
        let shared = if share > 1 {
            std::format!(" (its share: {share} runs side by side share the budget)")
        } else {
            String::new()
        };
        return Err(RunError::Limit(std::format!(
            "the run needs about {} ({what}); the limit is {}{shared}: raise it with --max-memory (Python: max_memory=)",
            human(bytes),
            human(limit_f)
        )));
    }
    // small needs pass whatever the machine has: not read for them
    if bytes <= 64.0 * 1024.0 * 1024.0 {
        return Ok(());
    }
    if let Some(free) = available_memory() {
        if bytes > free {
            return Err(RunError::Limit(std::format!(
                "the run needs about {} ({what}); this process can have {} (the machine's available memory, its address-space limit and its control group's, the least of them)",
                human(bytes),
                human(free)
            )));
        }
    }
    Ok(())
}

/// [`check_budget`] for a controller built at `ts` for a model of dead time
/// `delay` (s) that may be given dead times up to `max_dead_time` (s): its
/// delay lines, as the registry's constructors will allocate them.
pub fn check_controller_memory(
    delay: f64,
    max_dead_time: f64,
    ts: f64,
    max_memory: Option<u64>,
) -> Result<(), RunError> {
    let ts = crate::real::positive(ts, "ts")?;
    let max_dead_time = crate::real::non_negative(max_dead_time, "max_dead_time")?;
    let samples = delay.max(max_dead_time) / ts;
    check_budget(
        max_memory,
        samples * CONTROLLER_BYTES_PER_SAMPLE,
        &std::format!(
            "{} samples of dead time at ts = {} s",
            crate::poly::fmt_num(samples.ceil()),
            crate::poly::fmt_num(ts)
        ),
    )
}

impl Scenario {
    /// Refuses a run whose estimated memory (`bytes`, described by `what`)
    /// is above the scenario's budget ([`check_budget`]).
    pub(crate) fn within_budget(&self, bytes: f64, what: &str) -> Result<(), RunError> {
        check_budget(self.max_memory, bytes, what)
    }

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
    ) -> Result<Tuned, RunError> {
        let scheme = match (&self.controller, inner) {
            (Some(name), _) => registry::find(name)?,
            (None, Some(_)) => registry::find("fspcc")?,
            (None, None) => registry::default_for(model)?,
        };
        let mut overrides: Vec<(String, f64)> = Vec::with_capacity(self.set.len());
        for (k, v) in &self.set {
            match k.split_once('.') {
                // a `scheme.` prefix (name or alias) must name a scheme, even
                // one that is not running; it applies to that scheme only
                Some((prefix, name)) => {
                    if registry::find(prefix)?.name == scheme.name {
                        overrides.push((name.to_string(), *v));
                    }
                }
                None => overrides.push((k.clone(), *v)),
            }
        }
        let params =
            scheme.tune_process(model, inner, self.lambda, self.rule.as_deref(), &overrides)?;
        // a tuning that overflows (a gain of 5e-324, a λ of 5e-324) is no tuning:
        // refused here, as the run's construction would refuse it
        if let Some((name, value)) = params
            .iter()
            .find(|(n, v)| v.is_nan() || (v.is_infinite() && !(*n == "ti" && *v > 0.0)))
        {
            return Err(RunError::Limit(std::format!(
                "the tuning gives {name} = {}: the plant's numbers or lambda are beyond what the rule can use (a gain of 1e-300 asks for a controller gain of 1e300)",
                crate::poly::fmt_num(value)
            )));
        }
        let lambda_chosen = self.lambda.is_none()
            && params.lambda().is_some()
            && !overrides.iter().any(|(k, _)| k == "lambda");
        let tuned = Tuned {
            scheme,
            params,
            lambda_chosen,
            target: None,
        };
        if let Some(target) = self.target.filter(|t| t.pm.is_some()) {
            return self.design_at_crossover(target, model, inner, tuned, &overrides);
        }
        match self.target {
            // a target fixes λ where the user left it to the rule (a single
            // loop: a cascade's figures are its outer loop's, not solved here)
            Some(target) if lambda_chosen && inner.is_none() => {
                let (lambda, report) = self.solve_target(target, model, &tuned)?;
                let mut sc = self.clone();
                sc.target = None;
                sc.lambda = Some(lambda);
                let mut t = sc.tune_for(model, None)?;
                t.lambda_chosen = true;
                t.target = Some(report);
                Ok(t)
            }
            Some(_) if inner.is_some() => Err(RunError::Invalid(Error::Unsupported(
                "a design target is for a single loop (not a cascade process)",
            ))),
            Some(_) if tuned.params.lambda().is_some() => Err(RunError::Invalid(Error::Unsupported(
                "a design target solves lambda: give one or the other (no --lambda or --set lambda= with --target)",
            ))),
            Some(_) => Err(RunError::Invalid(Error::Unsupported(
                "a design target solves the tuning's lambda, and this tuning has none (an ultimate-cycle or AMIGO rule, or parameters given): drop --rule, or the target",
            ))),
            _ => Ok(tuned),
        }
    }

    /// [`Scenario::build_controller`] for a cascade process with the secondary
    /// model `inner` (the default scheme is then FSPCC).
    pub fn build_controller_for(
        &self,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
    ) -> Result<BuiltController, RunError> {
        let tuned = self.tune_for(model, inner)?;
        self.build_tuned(&tuned, model, inner)
    }

    /// The sample period (given or chosen) and whether it was chosen, after
    /// the model's order and the controller's delay lines are checked
    /// against the capacity and the memory budget.
    pub(super) fn check_size(
        &self,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
    ) -> Result<(f64, bool), RunError> {
        let whole = match inner {
            Some(p2) => model.series(p2)?,
            None => model.clone(),
        };
        if whole.model_order() > MAX_ORDER {
            return Err(RunError::Invalid(Error::OrderTooHigh("model")));
        }
        let (ts, ts_chosen) = match self.ts {
            Some(ts) => (crate::real::positive(ts, "ts")?, false),
            None => (choose_ts_as(&whole, self.float32), true),
        };
        // the controller's delay lines, before tuning or building allocates
        // them: as long as the model's dead time, or an event's, whichever is longer
        let event = self.event_dead_time(false);
        let samples = whole.delay.max(event) / ts;
        let what = if event > whole.delay {
            let at =
                self.events
                    .iter()
                    .find(|e| match e.action {
                        crate::sim::Action::DeadTime(d)
                        | crate::sim::Action::DeadTimeRamp(d, _) => d == event,
                        _ => false,
                    })
                    .map_or(0.0, |e| e.at);
            std::format!(
                "the event at {} s sets a dead time of {} s: {} samples at ts = {} s",
                crate::poly::fmt_num(at),
                crate::poly::fmt_num(event),
                crate::poly::fmt_num(samples.ceil()),
                crate::poly::fmt_num(ts)
            )
        } else {
            std::format!(
                "{} samples of the model's dead time at ts = {} s",
                crate::poly::fmt_num(samples.ceil()),
                crate::poly::fmt_num(ts)
            )
        };
        self.within_budget(samples * CONTROLLER_BYTES_PER_SAMPLE, &what)?;
        Ok((ts, ts_chosen))
    }

    /// Builds the controller of `tuned` for `model` (and the secondary model
    /// `inner`) with the scenario's period and actuator limits.
    pub fn build_tuned(
        &self,
        tuned: &Tuned,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
    ) -> Result<BuiltController, RunError> {
        let (ts, ts_chosen) = self.check_size(model, inner)?;
        let Tuned { scheme, params, .. } = tuned;
        // a limit that is given is a number; absent, there is none
        let u_min = match self.umin {
            Some(v) => crate::real::finite(v, "umin")?,
            None => f64::NEG_INFINITY,
        };
        let u_max = match self.umax {
            Some(v) => crate::real::finite(v, "umax")?,
            None => f64::INFINITY,
        };
        if u_min > u_max {
            return Err(RunError::Invalid(Error::InvalidLimits("umin")));
        }
        let build = Build {
            ts,
            u_min,
            u_max,
            // room for the dead times adaptation may set (and one sample more
            // for a fraction)
            max_dead_time: match (self.adapt_options(), inner) {
                (Some(_), None) => self.event_dead_time(false).max({
                    let (_, period, lag) = Self::adapt_timing(model, ts);
                    (self.adapt_range(model, (period, lag))?.1 + 1.0) * period + lag
                }),
                _ => self.event_dead_time(false),
            },
        };
        let controller: registry::DynController = if self.float32 {
            Box::new(crate::loop_controller::Widened(
                scheme.build_process_as::<f32>(params, model, inner, &build)?,
            ))
        } else {
            scheme.build_process(params, model, inner, &build)?
        };
        let mut notes = Vec::new();
        let controller = match inner {
            None => {
                let (c, note) = self.adaptive(controller, model, ts)?;
                notes.extend(note);
                c
            }
            Some(_) if self.adapt_options().is_some() => {
                return Err(RunError::Invalid(Error::Unsupported(
                    "adaptation is for a single loop (not a cascade process)",
                )))
            }
            Some(_) => controller,
        };
        Ok(BuiltController {
            scheme: scheme.name,
            params: params.clone(),
            controller,
            ts,
            ts_chosen,
            u_min,
            u_max,
            notes,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::check_budget;

    /// A run among `n` side by side (`SHARE`, set by `each`) has an `n`-th
    /// of the budget; alone, all of it.
    #[test]
    fn runs_side_by_side_share_the_budget() {
        assert!(check_budget(Some(1000), 300.0, "a run").is_ok());
        let outer = super::super::SHARE.with(|s| s.replace(4));
        let shared = check_budget(Some(1000), 300.0, "a run");
        super::super::SHARE.with(|s| s.set(outer));
        let why = std::format!("{shared:?}");
        assert!(why.contains("4 runs side by side"), "{why}");
        assert!(check_budget(Some(1000), 250.0, "a run").is_ok());
    }
}

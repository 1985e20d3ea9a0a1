//! The text forms of a run's schedules and perturbations, used at the edges
//! (command-line flags, scenario files, Python keywords): `V@T` set-point
//! steps, `input:V@T` disturbances, `gain=+10%` perturbations, `T:ACTION`
//! operator events and `MIN..MAX` actuator ranges.

use std::string::{String, ToString};

use crate::operate::Gain;
use crate::sim::{
    Action, ChannelDeadTime, Disturbance, Location, LoopLoad, LoopMode, Operation, PlantParameter,
    SetpointStep, Shape,
};
use crate::study::Perturbation;
use crate::sweep::Range;

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

/// A parameter value for `--set`: a finite number, or `inf` (a time
/// constant that switches its action off, `ti=inf` for no integral action);
/// the error names `what`.
pub fn parse_setting(s: &str, what: &str) -> Result<f64, String> {
    match s.trim().to_ascii_lowercase().as_str() {
        "inf" | "+inf" | "infinity" | "+infinity" => Ok(f64::INFINITY),
        _ => parse_number(s, what),
    }
}

/// `KEY=VALUE` of `--set` (a parameter or design value by its report
/// name): the key trimmed, the value as [`parse_setting`] reads it.
pub fn parse_assignment(s: &str) -> Result<(String, f64), String> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected KEY=VALUE, got '{s}'"))?;
    Ok((k.trim().to_string(), parse_setting(v, k.trim())?))
}

/// A relative change: `+10%` or `0.1` (the same); the error names `what`.
fn parse_fraction(s: &str, what: &str) -> Result<f64, String> {
    let s = s.trim();
    match s.strip_suffix('%') {
        Some(pct) => Ok(parse_number(pct, what)? / 100.0),
        None => parse_number(s, what),
    }
}

/// `VALUE[@TIME]`: the value of `what` and its time (0 when absent, not
/// negative).
fn value_at(s: &str, what: &str) -> Result<(f64, f64), String> {
    let (v, at) = match s.split_once('@') {
        Some((v, t)) => (v, parse_number(t, "time")?),
        None => (s, 0.0),
    };
    if at < 0.0 {
        return Err(std::format!("the {what} time must not be negative"));
    }
    Ok((parse_number(v, what)?, at))
}

impl core::str::FromStr for SetpointStep {
    type Err = String;
    /// `VALUE[@TIME]`, e.g. `1@0`.
    fn from_str(s: &str) -> Result<Self, String> {
        let (value, at) = value_at(s, "set point")?;
        Ok(SetpointStep { value, at })
    }
}

impl core::str::FromStr for Disturbance {
    type Err = String;
    /// `input|output|inner[:step|ramp|sine]:VALUE[@TIME][~FREQ_HZ]`, e.g.
    /// `input:0.1@20`; for cascade plants `d2`, `d1`, `d0` name the same places.
    fn from_str(s: &str) -> Result<Self, String> {
        let mut parts = s.splitn(3, ':');
        let loc = Location::from_name(parts.next().map_or("", str::trim))?;
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
        if shape != Shape::Sine && freq != 0.0 {
            return Err(
                "a frequency (~HZ) belongs to a sine disturbance only: input:sine:AMPLITUDE@TIME~HZ".into(),
            );
        }
        let (value, at) = value_at(rest, "disturbance")?;
        Ok(Disturbance {
            location: loc,
            shape,
            value,
            at,
            freq,
        })
    }
}

impl core::str::FromStr for Perturbation {
    type Err = String;
    /// `gain=+10%,delay=-5%,tau=0.1`.
    fn from_str(s: &str) -> Result<Self, String> {
        let mut p = Perturbation::default();
        if s.split(',').all(|x| x.trim().is_empty()) {
            return Err("an empty list: give KEY=VALUE pairs, e.g. gain=+10%,delay=-10%".into());
        }
        for part in s.split(',').map(str::trim).filter(|x| !x.is_empty()) {
            let (k, v) = part
                .split_once('=')
                .ok_or_else(|| std::format!("expected KEY=VALUE in '{part}'"))?;
            let v = v.trim();
            let value = parse_fraction(v, k)?;
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

impl core::str::FromStr for Range {
    type Err = String;
    /// `-20%..+20%` or `-0.2..0.2`; a single value is a range of one point.
    fn from_str(s: &str) -> Result<Self, String> {
        let one = |x: &str| parse_fraction(x, "range");
        if s.contains("...") || s.matches("..").count() > 1 {
            return Err(std::format!(
                "range '{s}': write it as LOW..HIGH, e.g. -20%..+20%"
            ));
        }
        let (lo, hi) = match s.split_once("..") {
            Some((a, b)) => (one(a)?, one(b)?),
            None => {
                let v = one(s)?;
                (v, v)
            }
        };
        Range::new(lo, hi).map_err(|why| std::format!("range '{s}': {why}"))
    }
}

impl core::str::FromStr for Operation {
    type Err = String;
    /// `TIME:ACTION` with the actions `manual=U`, `track=U`, `auto`,
    /// `dead-time=θ` (the controller's model; `dead-time=θ~RATE` moves it
    /// there at RATE seconds per second), `plant-dead-time=θ` (the
    /// process; `plant-gain=K` and `plant-lag=τ` its gain and its time
    /// constant), `adapt-freeze` and `adapt-resume` (an adaptive
    /// controller's adaptation) and `kp=V`, `ti=V`, `td=V` (online retuning), e.g.
    /// `60:manual=0.3`, `120:auto`, `60:plant-dead-time=9`, `60:kp=3`.
    fn from_str(s: &str) -> Result<Self, String> {
        let (at, action) = s.split_once(':').ok_or_else(|| {
            std::format!("event '{s}': write it as TIME:ACTION, e.g. 60:manual=0.3")
        })?;
        let at = parse_number(at, "event time")?;
        if at < 0.0 {
            return Err(std::format!("event '{s}': the time must not be negative"));
        }
        let action = action.trim();
        let (name, value) = match action.split_once('=') {
            Some((n, v)) => (n.trim(), Some(v)),
            None => (action, None),
        };
        let needs = |what: &str| -> Result<f64, String> {
            let v = value
                .ok_or_else(|| std::format!("event '{s}': '{name}' needs a value: {name}=…"))?;
            parse_number(v, what)
        };
        let seconds = |what: &str| -> Result<f64, String> {
            let v = needs(what)?;
            if v < 0.0 {
                return Err(std::format!(
                    "event '{s}': a dead time must not be negative"
                ));
            }
            Ok(v)
        };
        let action = match name {
            "manual" => Action::Manual(needs("manual output")?),
            "track" => Action::Track(needs("tracked output")?),
            "auto" if value.is_none() => Action::Auto,
            "dead-time" => match value.and_then(|v| v.split_once('~')) {
                // `θ~RATE`: moves to θ at RATE seconds of dead time per second
                Some((d, rate)) => {
                    let d = parse_number(d, "dead time")?;
                    let rate = parse_number(rate, "dead-time rate")?;
                    if d < 0.0 || rate <= 0.0 {
                        return Err(std::format!(
                            "event '{s}': a dead time must not be negative and its rate must be positive"
                        ));
                    }
                    Action::DeadTimeRamp(d, rate)
                }
                None => Action::DeadTime(seconds("dead time")?),
            },
            "plant-dead-time" | "plant-gain" | "plant-lag" => {
                // `X` steps the process, `X~RATE` drifts it at RATE per second
                let (x, rate) = match value.and_then(|v| v.split_once('~')) {
                    Some((x, rate)) => (x, Some(parse_number(rate, "drift rate")?)),
                    None => (value.unwrap_or(""), None),
                };
                if value.is_none() {
                    return Err(std::format!("event '{s}': '{name}' needs a value: {name}=…"));
                }
                if rate.is_some_and(|r| !(r.is_finite() && r > 0.0)) {
                    return Err(std::format!(
                        "event '{s}': a drift's rate (after '~') must be positive"
                    ));
                }
                let (what, x) = match name {
                    "plant-dead-time" => {
                        let d = parse_number(x, "plant dead time")?;
                        if d < 0.0 {
                            return Err(std::format!(
                                "event '{s}': a dead time must not be negative"
                            ));
                        }
                        (PlantParameter::DeadTime, d)
                    }
                    "plant-gain" => {
                        let k = parse_number(x, "plant gain")?;
                        if !(k.is_finite() && k != 0.0) {
                            return Err(std::format!(
                                "event '{s}': a plant gain must be finite and not zero"
                            ));
                        }
                        (PlantParameter::Gain, k)
                    }
                    _ => {
                        let tau = parse_number(x, "plant lag")?;
                        if !(tau.is_finite() && tau > 0.0) {
                            return Err(std::format!(
                                "event '{s}': a plant lag (time constant) must be positive"
                            ));
                        }
                        (PlantParameter::Lag, tau)
                    }
                };
                match (rate, what) {
                    (Some(rate), _) => Action::PlantDrift(what, x, rate),
                    (None, PlantParameter::DeadTime) => Action::PlantDeadTime(x),
                    (None, PlantParameter::Gain) => Action::PlantGain(x),
                    (None, PlantParameter::Lag) => Action::PlantLag(x),
                }
            }
            "adapt-freeze" if value.is_none() => Action::Adapt(false),
            "adapt-resume" if value.is_none() => Action::Adapt(true),
            "kp" => Action::Retune(Gain::Kp, needs("kp")?),
            "ti" => Action::Retune(Gain::Ti, parse_setting(value.unwrap_or(""), "ti")?),
            "td" => Action::Retune(Gain::Td, needs("td")?),
            other => {
                return Err(std::format!(
                    "event '{s}': unknown action '{other}': the actions are manual=U, track=U, auto, dead-time=θ, plant-dead-time=θ, plant-gain=K, plant-lag=τ (each plant-… also X~RATE, a drift), adapt-freeze, adapt-resume, kp=V, ti=V, td=V"
                ))
            }
        };
        Ok(Operation { at, action })
    }
}

/// An actuator's range `MIN..MAX` (e.g. `0..1`, `-inf..2`).
pub fn parse_actuator(s: &str) -> Result<(f64, f64), String> {
    let (lo, hi) = range(s, "actuator", "0..1")?;
    let end = |x: &str| match x.trim().to_ascii_lowercase().as_str() {
        "-inf" | "-infinity" => Ok(f64::NEG_INFINITY),
        _ => parse_setting(x, "actuator"),
    };
    let (lo, hi) = (end(lo)?, end(hi)?);
    if lo.is_nan() || hi.is_nan() || lo >= hi {
        return Err(std::format!("actuator '{s}': MIN must be below MAX"));
    }
    Ok((lo, hi))
}

/// A range of dead times `MIN..MAX` in seconds (e.g. `0.5..2`): finite, not
/// negative, `MIN ≤ MAX`.
pub fn parse_dead_times(s: &str) -> Result<(f64, f64), String> {
    let what = "dead times";
    let (lo, hi) = range(s, what, "0.5..2")?;
    let end = |x: &str| {
        let v = parse_number(x, &std::format!("{what} '{s}'"))?;
        if v >= 0.0 {
            Ok(v)
        } else {
            Err(std::format!("{what} '{s}': '{}' is negative", x.trim()))
        }
    };
    let (lo, hi) = (end(lo)?, end(hi)?);
    if lo > hi {
        return Err(std::format!("{what} '{s}': MIN must not be above MAX"));
    }
    Ok((lo, hi))
}

/// The two ends of `MIN..MAX` (`what` and an example name it in the error).
fn range<'a>(s: &'a str, what: &str, example: &str) -> Result<(&'a str, &'a str), String> {
    s.split_once("..")
        .filter(|_| !s.contains("...") && s.matches("..").count() == 1)
        .ok_or_else(|| std::format!("{what} '{s}': write it as MIN..MAX, e.g. {example}"))
}

/// A size in bytes: `1073741824`, `512M`, `2G`, `1.5GiB` (K, M, G, T are
/// powers of 1024; a trailing `B` or `iB` is allowed).
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let t = t
        .strip_suffix("iB")
        .or_else(|| t.strip_suffix('B'))
        .unwrap_or(t);
    let (num, scale) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let p = match c.to_ascii_uppercase() {
                'K' => 1,
                'M' => 2,
                'G' => 3,
                'T' => 4,
                _ => return Err(std::format!("size '{s}': the unit must be K, M, G or T")),
            };
            (t.get(..i).unwrap_or(""), 1024f64.powi(p))
        }
        _ => (t, 1.0),
    };
    let v = parse_number(num, "size")? * scale;
    if !(v >= 1.0) || v > 1.8e19 {
        return Err(std::format!("size '{s}': give a number of bytes from 1 up"));
    }
    num_traits::ToPrimitive::to_u64(&v.round())
        .ok_or_else(|| std::format!("size '{s}' is too large"))
}

/// Serde for a list of set-point steps or disturbances that a scenario file
/// may write in the flags' own syntax (`setpoint = ["1@0", "2@100"]`,
/// `disturbance = ["input:-0.1@1000"]`) or in the structured form
/// (`{ value = 1, at = 0 }`), item by item; written back structured.
#[cfg(feature = "serde")]
pub mod text_or_struct {
    use alloc::string::String;
    use alloc::vec::Vec;
    use core::str::FromStr;

    #[derive(serde::Deserialize)]
    #[serde(untagged)]
    enum Item<T> {
        Text(String),
        Struct(T),
    }

    /// Reads each item as flag text or as the structured form.
    pub fn deserialize<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
    where
        D: serde::Deserializer<'de>,
        T: serde::Deserialize<'de> + FromStr<Err = String>,
    {
        let items: Vec<Item<T>> = serde::Deserialize::deserialize(d)?;
        items
            .into_iter()
            .map(|i| match i {
                Item::Text(s) => T::from_str(&s).map_err(serde::de::Error::custom),
                Item::Struct(t) => Ok(t),
            })
            .collect()
    }

    /// Writes the structured form.
    pub fn serialize<S, T>(v: &[T], s: S) -> Result<S::Ok, S::Error>
    where
        S: serde::Serializer,
        T: serde::Serialize,
    {
        serde::Serialize::serialize(v, s)
    }
}

/// A `(min, max)` pair from a file's two-element list (`actuator = [0, 1]`):
/// a list of another length is an error, not a pair taken from its first
/// two values.
#[cfg(feature = "serde")]
pub mod exact_pair {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes the pair as a two-element list.
    pub fn serialize<S: Serializer>(v: &Option<(f64, f64)>, s: S) -> Result<S::Ok, S::Error> {
        v.serialize(s)
    }

    /// Reads a two-element list (or nothing).
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<(f64, f64)>, D::Error> {
        let v: Option<std::vec::Vec<f64>> = Option::deserialize(d)?;
        match v.as_deref() {
            None => Ok(None),
            Some([lo, hi]) => Ok(Some((*lo, *hi))),
            Some(other) => Err(serde::de::Error::custom(std::format!(
                "a pair [min, max] has two values, not {}",
                other.len()
            ))),
        }
    }
}

/// A 1-based loop (row, column) number, 0-based.
fn loop_number(l: &str) -> Result<usize, String> {
    l.trim()
        .parse::<usize>()
        .ok()
        .filter(|l| *l >= 1)
        .map(|l| l - 1)
        .ok_or_else(|| std::format!("'{l}' is not a loop number (1, 2, ...)"))
}

/// A matrix plant's set-point step of one loop, `LOOP:VALUE[@TIME]`
/// (1-based: `2:1@50`), as the loop (0-based) and its step.
pub fn parse_loop_setpoint(s: &str) -> Result<(usize, SetpointStep), String> {
    let (l, step) = s.split_once(':').ok_or_else(|| {
        std::format!("a loop's set point is LOOP:VALUE[@TIME] (2:1@50), got '{s}'")
    })?;
    Ok((loop_number(l)?, step.parse()?))
}

impl core::str::FromStr for LoopLoad {
    type Err = String;
    /// `LOOP:input|output:VALUE[@TIME]` (1-based: `2:input:0.1@50`).
    fn from_str(s: &str) -> Result<Self, String> {
        let mut parts = s.splitn(3, ':');
        let (Some(l), Some(loc), Some(step)) = (parts.next(), parts.next(), parts.next()) else {
            return Err(std::format!(
                "a loop's load is LOOP:input|output:VALUE[@TIME] (2:input:0.1@50), got '{s}'"
            ));
        };
        let step: SetpointStep = step.parse()?;
        Ok(LoopLoad {
            loop_index: loop_number(l)?,
            location: Location::from_name(loc.trim())?,
            value: step.value,
            at: step.at,
        })
    }
}

impl core::str::FromStr for ChannelDeadTime {
    type Err = String;
    /// `ROW,COL=SECONDS@TIME` (1-based: `1,2=5@600`).
    fn from_str(s: &str) -> Result<Self, String> {
        let form = || {
            std::format!(
                "a channel's dead-time change is ROW,COL=SECONDS@TIME (1,2=5@600), got '{s}'"
            )
        };
        let (rc, rest) = s.split_once('=').ok_or_else(form)?;
        let (r, c) = rc.split_once(',').ok_or_else(form)?;
        let (dead_time, at) = value_at(rest, "dead time")?;
        if dead_time < 0.0 {
            return Err(std::format!(
                "{}: the dead time must not be negative",
                form()
            ));
        }
        Ok(ChannelDeadTime {
            row: loop_number(r)?,
            col: loop_number(c)?,
            dead_time,
            at,
        })
    }
}

impl core::str::FromStr for LoopMode {
    type Err = String;
    /// `LOOP:TIME:manual=VALUE` or `LOOP:TIME:auto` (1-based: `2:50:manual=0.3`).
    fn from_str(s: &str) -> Result<Self, String> {
        let form = || {
            std::format!(
                "a loop's mode switch is LOOP:TIME:manual=VALUE or LOOP:TIME:auto (2:50:manual=0.3), got '{s}'"
            )
        };
        let mut parts = s.splitn(3, ':');
        let (Some(l), Some(at), Some(mode)) = (parts.next(), parts.next(), parts.next()) else {
            return Err(form());
        };
        let at = parse_number(at, "time")?;
        if at < 0.0 {
            return Err(std::format!("{}: the time must not be negative", form()));
        }
        let manual = match mode.trim().split_once('=') {
            Some(("manual", v)) => Some(parse_number(v, "manual")?),
            None if mode.trim() == "auto" => None,
            _ => return Err(form()),
        };
        Ok(LoopMode {
            loop_index: loop_number(l)?,
            at,
            manual,
        })
    }
}

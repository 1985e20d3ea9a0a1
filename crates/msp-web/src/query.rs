//! The page's scenario: pairs keyed by `msp run`'s long flag names (the
//! page's URL query), each value read by the parser the CLI's flag uses, so a
//! link, a scenario and a command line are one description.

use msp::study::Scenario;

/// The keys the page takes: `msp run`'s long flags of a single loop.
/// `setpoint`, `disturbance`, `event` and `set` repeat.
pub const KEYS: &[&str] = &[
    "plant",
    "model",
    "controller",
    "lambda",
    "target",
    "rule",
    "set",
    "ts",
    "duration",
    "setpoint",
    "disturbance",
    "event",
    "noise",
    "seed",
    "quantization",
    "umin",
    "umax",
    "actuator",
];

/// What is wrong with a pair: its key, the parser's message and, for a plant,
/// the 1-based column of the value the message points at.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Problem {
    /// The key (`plant`, `lambda`, …), or `request` for the document itself.
    pub key: String,
    /// What is wrong, as the CLI says it.
    pub message: String,
    /// The column in the value (plants and models).
    pub column: Option<usize>,
}

impl Problem {
    pub(crate) fn new(key: &str, message: impl Into<String>) -> Self {
        Problem {
            key: key.into(),
            message: message.into(),
            column: None,
        }
    }
}

/// The pairs of a request: a JSON array of `[key, value]` string pairs.
pub fn pairs(request: &str) -> Result<Vec<(String, String)>, Problem> {
    serde_json::from_str(request).map_err(|e| {
        Problem::new(
            "request",
            format!("a request is a JSON array of [key, value] pairs: {e}"),
        )
    })
}

/// A plant or a model: the CLI's grammar, its error with the column.
pub fn plant_of(key: &str, text: &str) -> Result<msp::poly::TransferFunction, Problem> {
    if text.trim_start().starts_with('[') {
        return Err(Problem::new(
            key,
            "a matrix plant is for the command line and Python (msp run --plant \"[g11, g12; g21, g22]\"); the page tunes a single loop",
        ));
    }
    msp::syntax::parse_plant(text).map_err(|e| Problem {
        key: key.into(),
        message: e.message,
        column: Some(e.column),
    })
}

/// The scenario of `pairs`; an unknown key, a repeated single key or a value
/// its flag would refuse is a [`Problem`] naming the key.
pub fn scenario(pairs: &[(String, String)]) -> Result<Scenario, Problem> {
    let mut sc = Scenario::default();
    let mut seen: Vec<&str> = Vec::new();
    for (key, value) in pairs {
        let k = key.as_str();
        let repeats = matches!(k, "setpoint" | "disturbance" | "event" | "set");
        if !repeats && seen.contains(&k) {
            return Err(Problem::new(k, format!("--{k} is given twice")));
        }
        seen.push(k);
        let fail = |m: String| Problem::new(k, m);
        let number = || -> Result<f64, Problem> {
            value
                .trim()
                .parse::<f64>()
                .map_err(|_| fail(format!("--{k}: '{value}' is not a number")))
        };
        match k {
            "plant" => sc.plant = Some(plant_of(k, value)?),
            "model" => sc.model = Some(plant_of(k, value)?),
            "controller" => {
                let scheme = msp::registry::find(value).map_err(|e| fail(e.to_string()))?;
                sc.controller = Some(scheme.name.to_string());
            }
            "lambda" => sc.lambda = Some(number()?),
            "target" => sc.target = Some(value.parse().map_err(fail)?),
            "rule" => sc.rule = Some(value.trim().to_string()),
            "set" => {
                let (name, v) = msp::syntax::parse_assignment(value).map_err(fail)?;
                sc.set.insert(name, v);
            }
            "ts" => sc.ts = Some(number()?),
            "duration" => sc.duration = Some(number()?),
            "setpoint" => sc.setpoint.push(value.parse().map_err(fail)?),
            "disturbance" => sc.disturbance.push(value.parse().map_err(fail)?),
            "event" => sc.events.push(value.parse().map_err(fail)?),
            "noise" => sc.noise = Some(number()?),
            "seed" => {
                sc.seed =
                    Some(value.trim().parse().map_err(|_| {
                        fail(format!("--seed: '{value}' is not a whole number ≥ 0"))
                    })?)
            }
            "quantization" => sc.quantization = Some(number()?),
            "umin" => sc.umin = Some(number()?),
            "umax" => sc.umax = Some(number()?),
            "actuator" => sc.actuator = Some(msp::syntax::parse_actuator(value).map_err(fail)?),
            _ => {
                return Err(fail(format!(
                    "unknown key '{k}': the page takes {}",
                    KEYS.join(", ")
                )))
            }
        }
    }
    if sc.plant.is_none() {
        return Err(Problem::new("plant", "give a plant, e.g. 0.2/s*e^-7.4s"));
    }
    Ok(sc)
}

/// The `msp run` command of `pairs`: each pair a long flag, each value
/// quoted for a POSIX shell.
pub fn command(pairs: &[(String, String)]) -> String {
    let mut s = String::from("msp run");
    for (k, v) in pairs {
        s.push_str(" --");
        s.push_str(k);
        s.push(' ');
        s.push_str(&quoted(v));
    }
    s
}

/// `v` as one word of a POSIX shell: bare where every character is safe,
/// otherwise in single quotes (a quote inside as `'\''`).
fn quoted(v: &str) -> String {
    let safe = !v.is_empty()
        && v.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_.,:@=+/".contains(c));
    if safe {
        v.to_string()
    } else {
        format!("'{}'", v.replace('\'', "'\\''"))
    }
}

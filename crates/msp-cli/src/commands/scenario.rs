//! The scenario of a run from its flags and an optional TOML/JSON file.

use std::path::Path;

use msp::study::Scenario;

use crate::cli::{PlantArg, ScenarioArgs};
use crate::error::CliError;

/// A scenario file, or the scenario a run report carries (then `true`).
pub(crate) fn load_scenario(path: &Path) -> Result<(Scenario, bool), CliError> {
    let text = crate::input::open(
        path,
        &format!("scenario file {}", path.display()),
        crate::input::SCENARIO_CAP,
    )?
    .text()?;
    // a byte-order mark (as some editors write) is not part of the document
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if is_json {
        let fail = |e: serde_json::Error| {
            CliError::Input(format!("scenario file {}: {e}", path.display()))
        };
        // a run report (msp run --report) carries the scenario it ran
        let Strict(value) = serde_json::from_str(text).map_err(fail)?;
        match value.get("scenario") {
            Some(inner) if value.get("msp_version").is_some() => {
                Ok((serde_json::from_value(inner.clone()).map_err(fail)?, true))
            }
            _ => Ok((serde_json::from_value(value).map_err(fail)?, false)),
        }
    } else {
        toml::from_str(text)
            .map(|sc| (sc, false))
            .map_err(|e| CliError::Input(format!("scenario file {}: {e}", path.display())))
    }
}

pub(crate) fn scenario_from(a: &ScenarioArgs) -> Result<Scenario, CliError> {
    let mut sc = match &a.scenario {
        Some(p) => {
            let (mut sc, report) = load_scenario(p)?;
            // a scenario file is the user's own scenario: without events it is
            // the unit set-point step, not the default scenario (a report
            // reruns as it ran)
            if !report && sc.setpoint.is_empty() && sc.disturbance.is_empty() {
                sc.setpoint.push(msp::sim::SetpointStep {
                    value: 1.0,
                    at: 0.0,
                });
            }
            sc
        }
        None => Scenario::default(),
    };
    macro_rules! over {
        ($($f:ident),*) => {$( if a.$f.is_some() { sc.$f = a.$f.clone(); } )*};
    }
    match &a.plant {
        Some(PlantArg::Single(p)) => sc.plant = Some(p.clone()),
        Some(PlantArg::Matrix(_)) => {
            return Err(CliError::Input(
                "a matrix plant is for msp run, tune, margins and compare; this command takes a single loop".into(),
            ))
        }
        None => {}
    }
    let matrix_only = [
        ("--loop-setpoint", !a.loop_setpoint.is_empty(), "--setpoint"),
        (
            "--loop-disturbance",
            !a.loop_disturbance.is_empty(),
            "--disturbance",
        ),
        (
            "--disturbance-plant",
            a.disturbance_plant.is_some(),
            "--disturbance",
        ),
        (
            "--disturbance-step",
            !a.disturbance_step.is_empty(),
            "--disturbance",
        ),
        (
            "--channel-dead-time",
            !a.channel_dead_time.is_empty(),
            "--event T:plant-dead-time=S",
        ),
        (
            "--loop-event",
            !a.loop_event.is_empty(),
            "--event T:manual=V",
        ),
    ];
    if let Some((flag, _, single)) = matrix_only.iter().find(|(_, given, _)| *given) {
        return Err(CliError::Input(format!(
            "{flag} is for a matrix plant (--plant \"[g11, g12; g21, g22]\"); a single loop takes {single}"
        )));
    }
    over!(
        model,
        inner_plant,
        inner_model,
        ts,
        duration,
        noise,
        seed,
        quantization,
        umin,
        umax,
        substeps,
        max_memory,
        actuator,
        setpoint_ramp
    );
    if a.design.lambda.is_some() {
        sc.lambda = a.design.lambda;
    }
    if a.design.target.is_some() {
        sc.target = a.design.target;
    }
    if a.design.rule.is_some() {
        sc.rule.clone_from(&a.design.rule);
    }
    for (k, v) in &a.design.set {
        sc.set.insert(k.clone(), *v);
    }
    if !a.setpoint.is_empty() {
        sc.setpoint.clone_from(&a.setpoint);
    }
    sc.disturbance.extend(a.disturbance.iter().copied());
    sc.float32 |= a.float32;
    sc.events.extend(a.events.iter().copied());
    sc.reset_feedback |= a.reset_feedback;
    let tuning = a.adapt_delay.is_some()
        || a.adapt_forgetting.is_some()
        || a.adapt_prefilter.is_some()
        || a.adapt_excitation.is_some()
        || a.adapt_dead_zone.is_some()
        || a.adapt_bound.is_some()
        || a.adapt_background
        || a.alarm.is_some();
    sc.monitor |= a.monitor;
    if tuning && !(a.adapt || sc.monitor || sc.adapt.is_some()) {
        return Err(CliError::Input(
            "--adapt-delay, --adapt-forgetting, --adapt-prefilter, --adapt-excitation, --adapt-dead-zone, --adapt-bound, --adapt-background and --alarm set up an adaptation: add --adapt or --monitor".into(),
        ));
    }
    if a.adapt || tuning {
        // options for a monitor alone keep it a monitor
        let monitor_only = sc.adapt.is_none() && !a.adapt;
        let opts = sc.adapt.get_or_insert_with(Default::default);
        if monitor_only {
            opts.apply = Some(false);
        }
        macro_rules! set {
            ($($from:ident => $to:ident),*) => {$( if a.$from.is_some() { opts.$to = a.$from; } )*};
        }
        set!(
            adapt_delay => delay,
            adapt_forgetting => forgetting,
            adapt_prefilter => prefilter,
            adapt_excitation => excitation,
            adapt_dead_zone => dead_zone,
            adapt_bound => bound,
            alarm => alarm
        );
        if a.adapt_background {
            opts.background_design = Some(true);
        }
    }
    if sc.plant.is_none() {
        return Err(CliError::Input(match &a.scenario {
            Some(p) => format!(
                "scenario file {} has no plant: add plant = \"0.2/s*e^-7.4s\" or give --plant",
                p.display()
            ),
            None => "give a plant: --plant \"0.2/s*e^-7.4s\" (or --scenario FILE)".into(),
        }));
    }
    Ok(sc)
}

/// A JSON document whose objects name no key twice: a scenario file that
/// gives `ts` twice is an error, not its last `ts` taken silently.
struct Strict(serde_json::Value);

impl<'de> serde::Deserialize<'de> for Strict {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(StrictVisitor).map(Strict)
    }
}

struct StrictVisitor;

impl<'de> serde::de::Visitor<'de> for StrictVisitor {
    type Value = serde_json::Value;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Self::Value, E> {
        Ok(v.into())
    }
    fn visit_i64<E>(self, v: i64) -> Result<Self::Value, E> {
        Ok(v.into())
    }
    fn visit_u64<E>(self, v: u64) -> Result<Self::Value, E> {
        Ok(v.into())
    }
    fn visit_f64<E>(self, v: f64) -> Result<Self::Value, E> {
        Ok(serde_json::Number::from_f64(v).map_or(serde_json::Value::Null, Into::into))
    }
    fn visit_str<E>(self, v: &str) -> Result<Self::Value, E> {
        Ok(v.into())
    }
    fn visit_string<E>(self, v: String) -> Result<Self::Value, E> {
        Ok(v.into())
    }
    fn visit_unit<E>(self) -> Result<Self::Value, E> {
        Ok(serde_json::Value::Null)
    }
    fn visit_none<E>(self) -> Result<Self::Value, E> {
        Ok(serde_json::Value::Null)
    }
    fn visit_some<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        serde::Deserialize::deserialize(d).map(|Strict(v)| v)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut a: A) -> Result<Self::Value, A::Error> {
        let mut v = Vec::new();
        while let Some(Strict(x)) = a.next_element()? {
            v.push(x);
        }
        Ok(serde_json::Value::Array(v))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut a: A) -> Result<Self::Value, A::Error> {
        let mut m = serde_json::Map::new();
        while let Some(k) = a.next_key::<String>()? {
            let Strict(v) = a.next_value()?;
            if m.contains_key(&k) {
                return Err(serde::de::Error::custom(format!(
                    "the key '{}' is given twice",
                    k.chars().take(60).collect::<String>()
                )));
            }
            m.insert(k, v);
        }
        Ok(serde_json::Value::Object(m))
    }
}

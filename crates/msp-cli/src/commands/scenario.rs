//! The scenario of a run from its flags and an optional TOML/JSON file.

use std::path::Path;

use msp::study::Scenario;

use crate::cli::ScenarioArgs;
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
        let value: serde_json::Value = serde_json::from_str(text).map_err(fail)?;
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
    over!(
        plant,
        model,
        inner_plant,
        inner_model,
        ts,
        duration,
        noise,
        seed,
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

//! `msp tune`.

use crate::cli::{PlantArg, TuneArgs};
use crate::error::CliError;
use crate::export;
use msp::study::Scenario;

pub(crate) fn tune(a: &TuneArgs) -> Result<(), CliError> {
    let plant = match &a.plant {
        PlantArg::Single(p) => p.clone(),
        PlantArg::Matrix(m) => return super::mimo::tune(m, a),
    };
    let sc = Scenario {
        plant: Some(plant),
        inner_plant: a.inner_plant.clone(),
        controller: a.controller.clone(),
        lambda: a.design.lambda,
        rule: a.design.rule.clone(),
        target: a.design.target,
        set: a.design.set.iter().cloned().collect(),
        ts: a.ts,
        ..Scenario::default()
    };
    if a.rules {
        return rules(&sc, a.json);
    }
    let r = sc.tune_report(a.uncertainty)?;
    if a.json {
        return export::print_json(&r);
    }
    let plant = sc.plant.as_ref().map(|p| (p.to_string(), p.kind()));
    if let Some((p, kind)) = plant {
        export::outln!("plant       {p} ({kind})")?;
    }
    if let Some(i) = &sc.inner_plant {
        export::outln!("inner plant {} ({})", i, i.kind())?;
    }
    export::outln!("controller  {}  [{}]", r.controller.name, r.source)?;
    for (k, v) in r.controller.params.iter() {
        let note = if k == "lambda" && r.controller.target.is_some() {
            "  [solved for the target]"
        } else if k == "lambda" && r.chosen.contains(&"lambda") {
            "  [chosen from the plant; --lambda to change]"
        } else {
            ""
        };
        export::outln!("  {k:<8} = {}{note}", export::fmt_sig(v))?;
    }
    if let Some(t) = &r.controller.tuning {
        export::print(export::text::tuning_line(t).as_bytes())?;
    }
    if let Some(t) = &r.controller.target {
        export::print(export::text::target_line(t).as_bytes())?;
    }
    export::print(export::text::design_block(&r.design).as_bytes())?;
    if let Some(m) = &r.robustness {
        export::print(export::text::robustness_line(m).as_bytes())?;
    }
    if let Some(p) = r.robust_peak {
        export::outln!(
            "robust stability max|T·Δ| = {} ({})",
            export::fmt_sig(p),
            if p < 1.0 {
                "robustly stable"
            } else {
                "not guaranteed"
            }
        )?;
    }
    for w in &r.warnings {
        export::outln!("warning: {w}")?;
    }
    Ok(())
}

/// `msp tune --rules`: a row per rule, the loop's figures beside the settings.
fn rules(sc: &Scenario, json: bool) -> Result<(), CliError> {
    let rows = export::busy("tuning by every rule", false, || sc.rules_report())?;
    if json {
        let j = serde_json::json!({
            "plant": sc.plant.as_ref().map(ToString::to_string),
            "rules": rows,
        });
        return export::print_json(&j);
    }
    if let Some(p) = &sc.plant {
        export::outln!("plant       {p} ({})", p.kind())?;
    }
    export::outln!(
        "{:<20} {:<4} {:>10} {:>10} {:>10} {:>4} {:>7} {:>8} {:>8}",
        "rule",
        "",
        "kp",
        "ti",
        "td",
        "b",
        "Ms",
        "gm",
        "pm"
    )?;
    for r in &rows {
        let (Some(t), Some(m)) = (&r.tuning, &r.robustness) else {
            let why = r.error.as_deref().unwrap_or("no controller");
            export::outln!("{:<20} {:<4} {why}", r.rule, r.controller)?;
            continue;
        };
        let get = |k: &str| t.params.get(k).map_or("-".into(), export::fmt_sig);
        let b = t
            .tuning
            .as_ref()
            .map_or("-".into(), |w| export::fmt_sig(w.b));
        let figures = if r.stable == Some(false) {
            "unstable".to_string()
        } else {
            format!(
                "{:>7} {:>8} {:>8}",
                export::fmt_sig(m.ms),
                export::fmt_sig(m.gm),
                export::fmt_sig(m.pm)
            )
        };
        export::outln!(
            "{:<20} {:<4} {:>10} {:>10} {:>10} {:>4} {figures}",
            r.rule,
            r.controller,
            get("kp"),
            get("ti"),
            get("td"),
            b
        )?;
    }
    Ok(())
}

//! `msp tune`.

use crate::cli::TuneArgs;
use crate::error::CliError;
use crate::export;
use msp::study::Scenario;

pub(crate) fn tune(a: &TuneArgs) -> Result<(), CliError> {
    let sc = Scenario {
        plant: Some(a.plant.clone()),
        inner_plant: a.inner_plant.clone(),
        controller: a.controller.clone(),
        lambda: a.design.lambda,
        rule: a.design.rule.clone(),
        set: a.design.set.iter().cloned().collect(),
        ts: a.ts,
        ..Scenario::default()
    };
    let r = sc.tune_report(a.uncertainty)?;
    if a.json {
        export::outln!(
            "{}",
            serde_json::to_string_pretty(&r).map_err(|e| CliError::Runtime(e.to_string()))?
        )?;
        return Ok(());
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
        let note = if k == "lambda" && r.chosen.contains(&"lambda") {
            "  [chosen from the plant; --lambda to change]"
        } else {
            ""
        };
        export::outln!("  {k:<8} = {}{note}", export::fmt_sig(v))?;
    }
    if let Some(t) = &r.controller.tuning {
        export::print(export::text::tuning_line(t).as_bytes())?;
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

//! `msp tune`.

use crate::cli::TuneArgs;
use crate::error::CliError;
use crate::export;
use msp::study::Scenario;

pub(crate) fn tune(a: &TuneArgs) -> Result<(), CliError> {
    let mut sc = Scenario {
        plant: Some(a.plant.clone()),
        inner_plant: a.inner_plant.clone(),
        controller: a.controller.clone(),
        lambda: a.design.lambda,
        rule: a.design.rule.clone(),
        set: a.design.set.iter().cloned().collect(),
        ts: a.ts,
        ..Scenario::default()
    };
    let (plant, model) = sc.plant_and_model()?;
    let inner = sc.inner_process()?.map(|(p2, _)| p2);
    let msp::study::Tuned {
        scheme,
        params,
        lambda_chosen,
    } = sc.tune_for(&model, inner.as_ref())?;
    // Eq. 17 on the tuned controller, when asked for
    sc.controller = Some(scheme.name.to_string());
    let robust = match a.uncertainty {
        Some(u) => msp::analysis::analyze(&sc, msp::analysis::View::Discrete, Some(u))?.robust_peak,
        None => None,
    };
    if a.json {
        let p = export::json::params_json(&params);
        let mut j = serde_json::json!({"plant": plant.to_string(), "controller": {"name": scheme.name, "params": p}});
        if let Some(i) = &inner {
            j["inner_plant"] = serde_json::json!(i.to_string());
        }
        if let Some(r) = robust {
            j["robust_peak"] = export::num(r);
            j["robustly_stable"] = serde_json::json!(r < 1.0);
        }
        export::outln!(
            "{}",
            serde_json::to_string_pretty(&j).map_err(|e| CliError::Runtime(e.to_string()))?
        )?;
    } else {
        export::outln!("plant       {} ({})", plant, plant.kind())?;
        if let Some(i) = &inner {
            export::outln!("inner plant {} ({})", i, i.kind())?;
        }
        export::outln!("controller  {}  [{}]", scheme.name, scheme.source)?;
        for (k, v) in params.iter() {
            let note = if k == "lambda" && lambda_chosen {
                "  [chosen from the plant; --lambda to change]"
            } else {
                ""
            };
            export::outln!("  {k:<8} = {}{note}", export::fmt_sig(v))?;
        }
        if let Some(r) = robust {
            export::outln!(
                "robust stability max|T·Δ| = {} ({})",
                export::fmt_sig(r),
                if r < 1.0 {
                    "robustly stable"
                } else {
                    "not guaranteed"
                }
            )?;
        }
    }
    Ok(())
}

//! `msp tune`.

use crate::cli::{PlantArg, TuneArgs};
use crate::error::CliError;
use crate::export;
use msp::study::Scenario;

pub(crate) fn tune(a: &TuneArgs) -> Result<(), CliError> {
    let plant = match &a.plant {
        PlantArg::Single(p) => p.clone(),
        PlantArg::Matrix(m) => return matrix(m, a),
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

/// `msp tune --plant "[…]"`: the RGA and its pairing, the Niederlinski
/// index and the BLT tuning of the diagonal loops (Luyben (1986)).
fn matrix(m: &msp::poly::TransferMatrix, a: &TuneArgs) -> Result<(), CliError> {
    if a.controller.is_some() || a.inner_plant.is_some() || a.rules || a.uncertainty.is_some() {
        return Err(CliError::Input(
            "a matrix plant is tuned by BLT decentralized PI loops: drop -c, --inner-plant, --rules and --uncertainty".into(),
        ));
    }
    let r = msp::analysis::mimo::tuning(m).map_err(|e| CliError::Input(e.to_string()))?;
    if a.json {
        return export::print_json(&r);
    }
    let n = m.size();
    export::outln!("plant       {} ({n}x{n})", r.plant)?;
    for (i, row) in r.rga.iter().enumerate() {
        let cells: Vec<String> = row.iter().map(|x| export::fmt_sig(*x)).collect();
        let label = if i == 0 { "rga" } else { "" };
        export::outln!("{label:<11} [{}]", cells.join(", "))?;
    }
    match &r.pairing {
        Some(p) => {
            let pairs: Vec<String> = p
                .iter()
                .enumerate()
                .map(|(i, j)| format!("y{}-u{}", i + 1, j + 1))
                .collect();
            export::outln!(
                "pairing     {} (positive relative gains nearest 1)",
                pairs.join(", ")
            )?;
        }
        None => export::outln!("pairing     none with every relative gain positive")?,
    }
    export::outln!(
        "niederlinski {}{}",
        export::fmt_sig(r.niederlinski),
        if r.niederlinski < 0.0 {
            " (negative: the diagonal loops with integral action are unstable for every tuning)"
        } else {
            ""
        }
    )?;
    export::outln!(
        "controller  decentralized PI, BLT (Luyben 1986): F = {}, biggest log modulus {} dB",
        export::fmt_sig(r.f),
        export::fmt_sig(r.lcm)
    )?;
    for (i, (l, z)) in r.loops.iter().zip(&r.ziegler_nichols).enumerate() {
        export::outln!(
            "  loop {}    kp = {}, ti = {}  (Ziegler-Nichols alone: kp = {}, ti = {})",
            i + 1,
            export::fmt_sig(l.kp),
            export::fmt_sig(l.ti),
            export::fmt_sig(z.kp),
            export::fmt_sig(z.ti)
        )?;
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

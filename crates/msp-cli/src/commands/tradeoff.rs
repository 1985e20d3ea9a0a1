//! `msp tradeoff`.

use crate::cli::TradeoffArgs;
use crate::error::CliError;
use crate::export;

pub(crate) fn tradeoff(a: &TradeoffArgs) -> Result<(), CliError> {
    let mut files =
        export::Outputs::plan(&[("--output", a.output.as_ref()), ("--plot", a.plot.as_ref())])?;
    let sc = msp::study::Scenario {
        plant: Some(a.plant.clone()),
        model: a.model.clone(),
        ts: a.ts,
        ..Default::default()
    };
    let t = export::busy("sweeping lambda for every scheme", a.quiet, || {
        msp::study::tradeoff(&sc, &a.controllers, &|_, _| {})
    })?;
    if t.points.is_empty() {
        return Err(CliError::Input(format!(
            "no scheme to sweep for this plant{}",
            t.skipped
                .iter()
                .map(|(n, why)| format!("; {n}: {why}"))
                .collect::<String>()
        )));
    }
    if let Some(p) = &a.output {
        files.add(p, table_csv(&t).into_bytes());
    }
    if let Some(p) = &a.plot {
        let svg =
            export::svg::tradeoff_svg(&t).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        files.add(p, svg.into_bytes());
    }
    files.commit()?;
    if a.json {
        let text =
            serde_json::to_string_pretty(&t).map_err(|e| CliError::Runtime(e.to_string()))?;
        export::outln!("{text}")?;
    } else if !a.output.as_ref().is_some_and(|p| export::is_stdout(p)) {
        export::print(table_text(&t).as_bytes())?;
    }
    Ok(())
}

const COLUMNS: [&str; 9] = [
    "scheme",
    "lambda",
    "default",
    "stable",
    "ms",
    "dm",
    "iae_setpoint",
    "iae_load",
    "tv",
];

fn table_csv(t: &msp::study::Tradeoff) -> String {
    let mut s = COLUMNS.join(",");
    s.push('\n');
    for p in &t.points {
        let stable = match p.stable {
            Some(true) => "true",
            Some(false) => "false",
            None => "",
        };
        s.push_str(&format!(
            "{},{},{},{stable},{},{},{},{},{}\n",
            p.scheme, p.lambda, p.default, p.ms, p.dm, p.iae_setpoint, p.iae_load, p.tv
        ));
    }
    s
}

fn table_text(t: &msp::study::Tradeoff) -> String {
    let mut s = format!(
        "plant  {}  (ts {} s; lambda from 1/8 to 8 times each scheme's own, * its own)\n",
        t.plant,
        export::fmt_sig(t.ts)
    );
    s.push_str(&format!(
        "{:<16} {:>10} {:>7} {:>9} {:>12} {:>12} {:>9}\n",
        "scheme", "lambda", "Ms", "dm", "IAE step", "IAE load", "TV"
    ));
    for p in &t.points {
        let mark = if p.default { "*" } else { " " };
        if p.stable == Some(true) {
            s.push_str(&format!(
                "{:<16} {:>9}{mark} {:>7} {:>9} {:>12} {:>12} {:>9}\n",
                p.scheme,
                export::fmt_sig(p.lambda),
                export::fmt_sig(p.ms),
                export::fmt_sig(p.dm),
                export::fmt_sig(p.iae_setpoint),
                export::fmt_sig(p.iae_load),
                export::fmt_sig(p.tv)
            ));
        } else {
            s.push_str(&format!(
                "{:<16} {:>9}{mark} {}\n",
                p.scheme,
                export::fmt_sig(p.lambda),
                if p.stable == Some(false) {
                    "unstable"
                } else {
                    "no verdict"
                }
            ));
        }
    }
    for (n, why) in &t.skipped {
        s.push_str(&format!("{n}: left out ({why})\n"));
    }
    s
}

//! `msp run`.

use super::scenario::scenario_from;
use crate::cli::{PlantArg, RunArgs};
use crate::error::CliError;
use crate::export;

pub(crate) fn run(a: &RunArgs) -> Result<(), CliError> {
    if let Some(PlantArg::Matrix(m)) = &a.scenario.plant {
        return matrix(m, a);
    }
    let mut sc = scenario_from(&a.scenario)?;
    if a.controller.is_some() {
        sc.controller.clone_from(&a.controller);
    }
    if let Some(path) = &a.input {
        sc = with_input(sc, path)?;
    }
    // every output path is checked before the run
    let planned = super::plan(
        &a.files,
        &[
            ("--input", a.input.as_ref()),
            ("--scenario", a.scenario.scenario.as_ref()),
        ],
    )?;
    let out = export::busy("simulating", a.quiet, || sc.run())?;
    let mut files = planned; // after `out`: the CSV streams from its columns
    let warnings = out.warnings();
    if let Some(p) = &a.files.report {
        let text = serde_json::to_vec_pretty(&export::json::report_json(&out))
            .map_err(|e| CliError::Runtime(e.to_string()))?;
        files.add(p, text);
    }
    if let Some(p) = &a.files.plot {
        let svg =
            export::svg::plot_svg(&[&out]).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        files.add(p, svg.into_bytes());
    }
    // on a terminal without -o, the summary alone: thousands of CSV rows are
    // for a pipe, a redirection or a file
    use std::io::IsTerminal;
    let to_terminal = a.files.output.is_none() && std::io::stdout().is_terminal();
    if !to_terminal {
        files.add_or_print(a.files.output.as_ref(), export::csv::run_csv(&out))?;
    }
    // everything is computed: now the files, all or none
    files.commit()?;
    if !a.quiet || to_terminal {
        export::noteln!("{}", export::text::summary(&out, &warnings));
    }
    if to_terminal {
        export::noteln!(
            "(the {} CSV rows go to a file with -o FILE.csv, or to standard output when it is piped or redirected)",
            out.result.t.len()
        );
    }
    Ok(())
}

/// The scenario driven by the sampled set point and loads of `path`
/// (`--input`): columns `t` (or `time`), `r`, and optionally `d`, `d_out`.
fn with_input(
    sc: msp::study::Scenario,
    path: &std::path::Path,
) -> Result<msp::study::Scenario, CliError> {
    use crate::data::{read_columns, Column};
    let name = path.display().to_string();
    let file = crate::input::open(path, &name, crate::input::CSV_CAP)?;
    let cols = read_columns(
        std::io::BufReader::new(file),
        &name,
        &[
            Column::time(None),
            Column::named("--input", "r"),
            Column::named("--input", "d").optional(),
            Column::named("--input", "d_out").optional(),
        ],
    )
    .map_err(CliError::Input)?;
    let col = |i: usize| cols.get(i).map_or(&[][..], Vec::as_slice);
    let input = msp::study::SampledInput {
        t: col(0),
        r: col(1),
        d: col(2),
        d_out: col(3),
    };
    sc.with_input(input)
        .map_err(|e| CliError::Input(format!("{name}: {e}")))
}

/// `msp run --plant "[…]"`: a multivariable scheme (`-c pi`, `smith` or
/// `decoupled`) on the exact sampled plant (`msp::study::run_mimo`); CSV
/// columns `t, r1, y1, u1, r2, y2, u2, …`, the report the library's
/// `MimoOutput`, a summary of the design, the verdict, each loop's IAE and
/// each step's interaction.
fn matrix(m: &msp::poly::TransferMatrix, a: &RunArgs) -> Result<(), CliError> {
    let s = &a.scenario;
    if !s.setpoint.is_empty() || a.input.is_some() || s.scenario.is_some() {
        return Err(CliError::Input(
            "a matrix plant's set points are per loop, by --loop-setpoint LOOP:V@T (no --setpoint, --input or --scenario yet)".into(),
        ));
    }
    let scheme = a.controller.as_deref().unwrap_or("pi");
    if a.files.plot.is_some() {
        return Err(CliError::Input(
            "a matrix plant's run has no plot yet: drop --plot".into(),
        ));
    }
    let n = m.size();
    let mut setpoints = vec![Vec::new(); n];
    for (l, step) in &s.loop_setpoint {
        setpoints
            .get_mut(*l)
            .ok_or_else(|| {
                CliError::Input(format!(
                    "--loop-setpoint {}: the plant has {n} loops",
                    l + 1
                ))
            })?
            .push(*step);
    }
    let planned = super::plan(&a.files, &[])?;
    let out = export::busy("simulating", a.quiet, || {
        msp::study::run_mimo(m, scheme, setpoints, s.ts, s.duration)
    })?;
    let mut files = planned;
    if let Some(p) = &a.files.report {
        let text = serde_json::to_vec_pretty(&out).map_err(|e| CliError::Runtime(e.to_string()))?;
        files.add(p, text);
    }
    let mut csv = String::from("t");
    for i in 1..=n {
        csv.push_str(&format!(",r{i},y{i},u{i}"));
    }
    csv.push('\n');
    let r = &out.run;
    for (k, t) in r.t.iter().enumerate() {
        csv.push_str(&export::fmt_f(*t));
        for i in 0..n {
            for col in [&r.r, &r.y, &r.u] {
                let v = col
                    .get(i)
                    .and_then(|c| c.get(k))
                    .copied()
                    .unwrap_or(f64::NAN);
                csv.push(',');
                csv.push_str(&export::fmt_f(v));
            }
        }
        csv.push('\n');
    }
    use std::io::IsTerminal;
    let to_terminal = a.files.output.is_none() && std::io::stdout().is_terminal();
    if !to_terminal {
        files.add_or_print(a.files.output.as_ref(), csv.into_bytes())?;
    }
    files.commit()?;
    if !a.quiet || to_terminal {
        let t = &out.tuning;
        export::noteln!(
            "plant       {} ({n}x{n}), ts = {} s, {} s",
            t.plant,
            export::fmt_sig(out.ts),
            export::fmt_sig(out.duration)
        );
        let d = &out.design;
        let summary = msp::study::MIMO_SCHEMES
            .iter()
            .find(|x| x.name == d.scheme)
            .map_or("", |x| x.summary);
        export::noteln!(
            "controller  {}: {summary}; F = {}",
            d.scheme,
            export::fmt_sig(d.f)
        );
        for (i, (l, iae)) in d.loops.iter().zip(&out.iae).enumerate() {
            let p: Vec<String> = l
                .iter()
                .map(|(k, v)| format!("{k} = {}", export::fmt_sig(v)))
                .collect();
            export::noteln!(
                "  loop {}    {}; IAE {}",
                i + 1,
                p.join(", "),
                export::fmt_sig(*iae)
            );
        }
        for e in &d.decoupler {
            export::noteln!("  decoupler {}", e.describe());
        }
        export::noteln!(
            "stability   {}: {}",
            out.stability.summary(),
            out.stability.reason
        );
        if let Some(v) = &out.decoupler_stability {
            export::noteln!("decoupler   {}: {}", v.summary(), v.reason);
        }
        export::noteln!(
            "Lcm         {} dB (biggest log modulus of the sampled loop)",
            export::fmt_sig(out.lcm)
        );
        for x in &out.interaction {
            let dev: Vec<String> = x.deviation.iter().map(|d| export::fmt_sig(*d)).collect();
            export::noteln!(
                "step        loop {} at {} s: largest deviation of each output {}",
                x.step_loop + 1,
                export::fmt_sig(x.at),
                dev.join(", ")
            );
        }
    }
    Ok(())
}

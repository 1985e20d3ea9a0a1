//! `msp run`.

use super::scenario::scenario_from;
use crate::cli::RunArgs;
use crate::error::CliError;
use crate::export;

pub(crate) fn run(a: &RunArgs) -> Result<(), CliError> {
    if let Some(m) = super::mimo::matrix_of(&a.scenario)? {
        return super::mimo::run(&m, a);
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

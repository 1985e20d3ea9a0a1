//! `msp run`.

use super::scenario::scenario_from;
use crate::cli::RunArgs;
use crate::error::CliError;
use crate::export;

pub(crate) fn run(a: &RunArgs) -> Result<(), CliError> {
    let mut sc = scenario_from(&a.scenario)?;
    if a.controller.is_some() {
        sc.controller.clone_from(&a.controller);
    }
    let out = sc.run()?;
    let warnings = export::text::warnings(&out);
    // everything is computed: now write, each file atomically
    let csv =
        export::csv::csv_bytes(&out).map_err(|e| CliError::Runtime(format!("writing CSV: {e}")))?;
    export::write_or_print(a.output.as_ref(), &csv)?;
    if let Some(p) = &a.report {
        let text = serde_json::to_vec_pretty(&export::json::report_json(&out, &warnings))
            .map_err(|e| CliError::Runtime(e.to_string()))?;
        export::write_atomic(p, &text)?;
    }
    if let Some(p) = &a.plot {
        let svg =
            export::svg::plot_svg(&[&out]).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        export::write_atomic(p, svg.as_bytes())?;
    }
    if !a.quiet {
        export::noteln!("{}", export::text::summary(&out, &warnings));
    }
    Ok(())
}

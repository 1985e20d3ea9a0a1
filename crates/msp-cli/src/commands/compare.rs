//! `msp compare`.

use super::scenario::scenario_from;
use crate::cli::CompareArgs;
use crate::error::CliError;
use crate::export;

pub(crate) fn compare(a: &CompareArgs) -> Result<(), CliError> {
    if let Some(m) = super::mimo::matrix_of(&a.scenario)? {
        return super::mimo::compare(&m, a);
    }
    let sc = scenario_from(&a.scenario)?;
    let mut files = super::plan(&a.files, &[("--scenario", a.scenario.scenario.as_ref())])?;
    let runs = msp::study::compare(&sc, &a.controllers, a.perturb.unwrap_or_default())?;
    // the margins each run's report carries (the library computes them)
    let margins: Vec<Option<msp::analysis::Margins>> = runs.iter().map(|r| r.robustness).collect();
    let table = export::text::compare_table(&runs, &margins, a.perturb.unwrap_or_default());
    let refs: Vec<&msp::study::RunOutput> = runs.iter().collect();
    if let Some(p) = &a.files.output {
        let csv = export::csv::compare_csv(&refs)
            .map_err(|e| CliError::Runtime(format!("writing CSV: {e}")))?;
        files.add(p, csv);
    }
    if let Some(p) = &a.files.report {
        let j: Vec<serde_json::Value> = runs.iter().map(export::json::report_json).collect();
        let text = serde_json::to_vec_pretty(&j).map_err(|e| CliError::Runtime(e.to_string()))?;
        files.add(p, text);
    }
    if let Some(p) = &a.files.plot {
        let svg =
            export::svg::plot_svg(&refs).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        files.add(p, svg.into_bytes());
    }
    files.commit()?;
    export::print(table.as_bytes())?;
    Ok(())
}

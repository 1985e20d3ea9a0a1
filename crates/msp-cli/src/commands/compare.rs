//! `msp compare`.

use super::scenario::scenario_from;
use crate::cli::CompareArgs;
use crate::error::CliError;
use crate::export;

pub(crate) fn compare(a: &CompareArgs) -> Result<(), CliError> {
    let sc = scenario_from(&a.scenario)?;
    let mut files = super::plan(&a.files, &[("--scenario", a.scenario.scenario.as_ref())])?;
    let runs = msp::study::compare(&sc, &a.controllers, a.perturb.unwrap_or_default())?;
    let margins: Vec<Option<msp::analysis::Margins>> = a
        .controllers
        .iter()
        .zip(&runs)
        .map(|(c, run)| {
            // an unstable loop has no margins
            if run.stability.stable == Some(false) {
                return Some(msp::analysis::Margins::unstable());
            }
            let mut one = sc.clone();
            one.controller = Some(c.clone());
            one.ts = Some(run.ts);
            if one.inner_plant.is_some() {
                // the cascade's loop is broken at the inner set point
                return msp::analysis::analyze(&one, msp::analysis::View::Discrete, None)
                    .ok()
                    .map(|an| an.margins);
            }
            // the controller of the run, as it was tuned for it
            let tuned = msp::study::Tuned {
                scheme: msp::registry::find(run.controller).ok()?,
                params: run.params.clone(),
                lambda_chosen: run.lambda_chosen,
                target: None,
            };
            let built = one.build_tuned(&tuned, &run.model, None).ok()?;
            msp::analysis::margins(
                built.controller.as_ref(),
                &run.plant,
                built.ts,
                msp::analysis::View::Sampled,
            )
            .ok()
        })
        .collect();
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

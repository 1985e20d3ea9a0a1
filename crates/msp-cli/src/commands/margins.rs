//! `msp margins`.

use super::scenario::scenario_from;
use crate::cli::MarginsArgs;
use crate::error::CliError;
use crate::export;

pub(crate) fn margins(a: &MarginsArgs) -> Result<(), CliError> {
    if let Some(m) = super::mimo::matrix_of(&a.scenario)? {
        return super::mimo::margins(&m, a);
    }
    let mut files = export::Outputs::plan_reading(
        &[
            ("--plot", a.plot.as_ref()),
            ("--nyquist", a.nyquist.as_ref()),
        ],
        &[("--scenario", a.scenario.scenario.as_ref())],
    )?;
    let mut sc = scenario_from(&a.scenario)?;
    if a.controller.is_some() {
        sc.controller.clone_from(&a.controller);
    }
    let view = match (a.discrete, a.continuous) {
        (true, _) => msp::analysis::View::Discrete,
        (_, true) => msp::analysis::View::Continuous,
        _ => msp::analysis::View::Sampled,
    };
    let an = export::busy("analysing", false, || {
        msp::study::analyze(&sc, view, a.uncertainty)
    })?;
    if let Some(p) = &a.plot {
        let svg =
            export::svg::bode_svg(&an).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        files.add(p, svg.into_bytes());
    }
    if let Some(p) = &a.nyquist {
        let svg =
            export::svg::nyquist_svg(&an).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        files.add(p, svg.into_bytes());
    }
    files.commit()?;
    if a.json {
        let text = serde_json::to_string_pretty(&export::json::margins_json(&an))
            .map_err(|e| CliError::Runtime(e.to_string()))?;
        export::outln!("{text}")?;
    } else {
        export::print(export::text::margins_text(&an).as_bytes())?;
    }
    Ok(())
}

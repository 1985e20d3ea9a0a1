//! `msp step`.

use crate::cli::StepArgs;
use crate::error::CliError;
use crate::export;

pub(crate) fn step(a: &StepArgs) -> Result<(), CliError> {
    let mut files =
        export::Outputs::plan(&[("--output", a.output.as_ref()), ("--plot", a.plot.as_ref())])?;
    let s = msp::analysis::step_response(&a.plant, a.ts, a.duration).map_err(|e| match e {
        msp::Error::Numerical(_) => CliError::Runtime(e.to_string()),
        _ => CliError::Input(e.to_string()),
    })?;
    if let Some(p) = &a.output {
        files.add(p, export::csv::columns_bytes(&[("t", &s.t), ("y", &s.y)]));
    }
    if let Some(p) = &a.plot {
        let svg = export::svg::step_svg(&s).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        files.add(p, svg.into_bytes());
    }
    files.commit()?;
    if a.json {
        // NaN (a figure of a response that does not settle) is null
        let text =
            serde_json::to_string_pretty(&s).map_err(|e| CliError::Runtime(e.to_string()))?;
        export::outln!("{text}")?;
    } else if !a.output.as_ref().is_some_and(|p| export::is_stdout(p)) {
        export::print(export::text::step_text(&s).as_bytes())?;
    }
    Ok(())
}

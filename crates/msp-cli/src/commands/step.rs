//! `msp step`.

use crate::cli::StepArgs;
use crate::error::CliError;
use crate::export;

pub(crate) fn step(a: &StepArgs) -> Result<(), CliError> {
    let mut files =
        export::Outputs::plan(&[("--output", a.output.as_ref()), ("--plot", a.plot.as_ref())])?;
    // the response's columns and their CSV text, before anything is computed
    let (ts, duration) = msp::analysis::step_grid(&a.plant, a.ts, a.duration)
        .map_err(|e| CliError::Input(e.to_string()))?;
    let rows = duration / ts + 2.0;
    let per_row = if a.output.is_some() {
        16.0 + 72.0
    } else {
        16.0
    };
    msp::study::check_budget(
        a.max_memory,
        rows * per_row + a.plant.delay / ts * 16.0,
        &format!(
            "{} samples of the response at ts = {} s",
            msp::poly::fmt_num(rows.ceil()),
            msp::poly::fmt_num(ts)
        ),
    )?;
    let s = msp::analysis::step_response(&a.plant, a.ts, a.duration).map_err(|e| match e {
        msp::Error::Numerical(_) => CliError::Runtime(e.to_string()),
        _ => CliError::Input(e.to_string()),
    })?;
    if let Some(p) = &a.output {
        // the rest state one sample before the step, so that the input steps
        let t: Vec<f64> = std::iter::once(-s.ts).chain(s.t.iter().copied()).collect();
        let u: Vec<f64> = std::iter::once(0.0)
            .chain(s.t.iter().map(|_| 1.0))
            .collect();
        let y: Vec<f64> = std::iter::once(0.0).chain(s.y.iter().copied()).collect();
        files.add(
            p,
            export::csv::columns_bytes(&[("t", &t), ("u", &u), ("y", &y)]),
        );
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

//! `msp identify` and `msp stepinfo`: what recorded data say.

use crate::cli::{IdentifyArgs, StepinfoArgs};
use crate::error::CliError;
use crate::export;

pub(crate) fn identify(a: &IdentifyArgs) -> Result<(), CliError> {
    let name = a.data.display().to_string();
    let file = crate::input::open(&a.data, &name, crate::input::CSV_CAP)?;
    let crate::data::StepData { t, u, y } = crate::data::read_step_data(
        std::io::BufReader::new(file),
        &name,
        a.time.as_deref(),
        &a.input,
        &a.output,
    )
    .map_err(CliError::Input)?;
    let fit = msp::ident::identify_step(a.model, &t, &u, &y).map_err(|e| match e {
        msp::Error::Unsupported(why) => CliError::Input(why.to_string()),
        e => CliError::Input(format!("identification failed: {e}")),
    })?;
    if a.json {
        export::outln!(
            "{}",
            serde_json::to_string_pretty(&fit).map_err(|e| CliError::Runtime(e.to_string()))?
        )?;
    } else {
        export::outln!(
            "model  {}",
            msp::poly::TransferFunction::from_model(&fit.model)
        )?;
        let (ps, n) = fit.model.params();
        for (k, v) in ps.iter().take(n) {
            export::outln!("  {k:<3} = {}", export::fmt_sig(*v))?;
        }
        export::outln!(
            "fit    rmse {}  r2 {}",
            export::fmt_sig(fit.rmse),
            export::fmt_sig(fit.r2)
        )?;
    }
    Ok(())
}

/// `msp stepinfo`: MATLAB's `stepinfo` of a recorded step response.
pub(crate) fn stepinfo(a: &StepinfoArgs) -> Result<(), CliError> {
    use crate::data::{read_columns, Column};
    let name = a.data.display().to_string();
    let file = crate::input::open(&a.data, &name, crate::input::CSV_CAP)?;
    let mut cols = read_columns(
        std::io::BufReader::new(file),
        &name,
        &[
            Column::time(a.time.as_deref()),
            Column::named("--output", &a.output),
        ],
    )
    .map_err(CliError::Input)?
    .into_iter();
    let (t, y) = (
        cols.next().unwrap_or_default(),
        cols.next().unwrap_or_default(),
    );
    let opts = msp::metrics::StepInfoOptions {
        settling_threshold: a.settling_threshold,
        rise_limits: a.rise_limits,
    };
    let s = msp::metrics::step_info_of_data(&t, &y, a.yinit, a.yfinal, opts)
        .map_err(|e| CliError::Input(format!("{name}: {e}")))?;
    if a.json {
        export::outln!(
            "{}",
            serde_json::to_string_pretty(&s).map_err(|e| CliError::Runtime(e.to_string()))?
        )?;
    } else {
        for (k, v) in s.fields() {
            export::outln!("{k:<14} {}", export::fmt_sig(v))?;
        }
    }
    Ok(())
}

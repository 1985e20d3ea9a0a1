//! `msp identify`.

use crate::cli::IdentifyArgs;
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

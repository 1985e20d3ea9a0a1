//! `msp autotune`.

use crate::cli::AutotuneArgs;
use crate::error::CliError;
use crate::export;
use msp::study::Scenario;

pub(crate) fn autotune(a: &AutotuneArgs) -> Result<(), CliError> {
    let planned = export::Outputs::plan(&[
        ("--output", a.output.as_ref()),
        ("--report", a.report.as_ref()),
    ])?;
    let plant = &a.plant;
    let o = msp::ident::AutotuneOptions {
        amplitude: a.relay_amplitude,
        hysteresis: a.hysteresis,
        bias: a.bias,
        noise: a.noise,
        seed: a.seed,
        model: a.model,
        controller: a.controller.clone(),
        ts: a.ts,
        band: a.band,
    };
    let base = Scenario {
        duration: a.duration,
        ..Default::default()
    };
    let out = msp::ident::autotune(plant, &o, &base).map_err(|e| match e {
        msp::ident::AutotuneError::Run(r) => CliError::from(r),
        msp::ident::AutotuneError::Ident(
            msp::Error::NotPositive(_)
            | msp::Error::Negative(_)
            | msp::Error::NonFinite(_)
            | msp::Error::OutOfRange(_),
        ) => CliError::Input(e.to_string()),
        other => CliError::Runtime(other.to_string()),
    })?;
    let report = export::json::autotune_json(plant, &out);
    let mut files = planned; // after `out`: the CSV streams from its columns
    if let Some(p) = &a.output {
        files.add(p, export::csv::run_csv(&out.run));
    }
    if let Some(p) = &a.report {
        let text =
            serde_json::to_vec_pretty(&report).map_err(|e| CliError::Runtime(e.to_string()))?;
        files.add(p, text);
    }
    files.commit()?;
    export::print(export::text::autotune_text(plant, &out).as_bytes())?;
    Ok(())
}

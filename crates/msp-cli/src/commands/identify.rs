//! `msp identify`.

use crate::cli::IdentifyArgs;
use crate::error::CliError;
use crate::export;

pub(crate) fn identify(a: &IdentifyArgs) -> Result<(), CliError> {
    let mut r = csv::Reader::from_path(&a.data)
        .map_err(|e| CliError::Input(format!("{}: {e}", a.data.display())))?;
    let head = r
        .headers()
        .map_err(|e| CliError::Input(format!("{}: {e}", a.data.display())))?
        .clone();
    let find = |name: &str| head.iter().position(|h| h.trim() == name);
    let missing = |flag: &str, name: &str| {
        CliError::Input(format!(
            "{}: no column '{name}' ({flag} names it; the columns are: {})",
            a.data.display(),
            head.iter().map(str::trim).collect::<Vec<_>>().join(", ")
        ))
    };
    let ct = match &a.time {
        Some(name) => find(name).ok_or_else(|| missing("--time", name))?,
        None => find("t")
            .or_else(|| find("time"))
            .ok_or_else(|| missing("--time", "t"))?,
    };
    let cu = find(&a.input).ok_or_else(|| missing("--input", &a.input))?;
    let cy = find(&a.output).ok_or_else(|| missing("--output", &a.output))?;
    let (mut t, mut u, mut y) = (Vec::new(), Vec::new(), Vec::new());
    for (line, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| CliError::Input(format!("{}: {e}", a.data.display())))?;
        let num = |c: usize| -> Result<f64, CliError> {
            rec.get(c)
                .and_then(|v| v.trim().parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    CliError::Input(format!(
                        "{}: row {}: not a finite number in column {}",
                        a.data.display(),
                        line + 2,
                        c + 1
                    ))
                })
        };
        t.push(num(ct)?);
        u.push(num(cu)?);
        y.push(num(cy)?);
    }
    let fit = msp::ident::identify_step(a.model, &t, &u, &y).map_err(|e| match e {
        msp::Error::Unsupported(why) => CliError::Input(why.to_string()),
        e => CliError::Input(format!("identification failed: {e}")),
    })?;
    if a.json {
        export::outln!(
            "{}",
            serde_json::to_string_pretty(&export::json::fit_json(&fit))
                .map_err(|e| CliError::Runtime(e.to_string()))?
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

//! `msp sweep`.

use super::scenario::scenario_from;
use crate::cli::SweepArgs;
use crate::error::CliError;
use crate::export;

pub(crate) fn sweep(a: &SweepArgs) -> Result<(), CliError> {
    // the output path is checked before a sweep that may take minutes
    let mut files = export::Outputs::plan_reading(
        &[("--output", a.output.as_ref())],
        &[("--scenario", a.scenario.scenario.as_ref())],
    )?;
    if !a.merge.is_empty() {
        let files_in = a
            .merge
            .iter()
            .map(|p| {
                let name = p.display().to_string();
                crate::input::open(p, &name, crate::input::CSV_CAP)
                    .map(|f| (name, std::io::BufReader::new(f)))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let csv = crate::data::merge_sweeps(files_in).map_err(CliError::Input)?;
        files.add_or_print(a.output.as_ref(), csv)?;
        return files.commit();
    }
    let mut sc = scenario_from(&a.scenario)?;
    if a.controller.is_some() {
        sc.controller.clone_from(&a.controller);
    }
    let spec = msp::sweep::SweepSpec {
        gain: a.gain,
        delay: a.delay,
        tau: a.tau,
        grid: a.grid,
        samples: a.samples,
        seed: a.sweep_seed,
        shard: a.shard,
    };
    let total = msp::sweep::points(&spec)?.len();
    use std::io::IsTerminal;
    let bar = if !a.quiet && std::io::stderr().is_terminal() {
        indicatif::ProgressBar::new(total as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let rows = msp::sweep::sweep(&sc, &spec, &|_| bar.inc(1))?;
    bar.finish_and_clear();
    let csv = export::csv::sweep_csv(&rows)
        .map_err(|e| CliError::Runtime(format!("writing CSV: {e}")))?;
    files.add_or_print(a.output.as_ref(), csv)?;
    files.commit()?;
    if !a.quiet {
        export::note(format_args!(
            "{}",
            export::text::sweep_summary(&rows).trim_end()
        ));
    }
    Ok(())
}

//! One module per subcommand; each takes its parsed arguments and writes its
//! outputs through [`crate::export`].

pub(crate) mod autotune;
pub(crate) mod compare;
pub(crate) mod identify;
pub(crate) mod list;
pub(crate) mod margins;
pub(crate) mod mimo;
pub(crate) mod run;
pub(crate) mod scenario;
pub(crate) mod serve;
pub(crate) mod step;
pub(crate) mod sweep;
pub(crate) mod tradeoff;
pub(crate) mod tune;

use std::path::PathBuf;

use crate::cli::SimulationFiles;
use crate::error::CliError;
use crate::export;

/// Every output path of a simulation (`run`, `compare`), checked before it
/// runs, none of them a file it reads (`inputs`).
pub(crate) fn plan<'a>(
    f: &'a SimulationFiles,
    inputs: &[(&str, Option<&PathBuf>)],
) -> Result<export::Outputs<'a>, CliError> {
    export::Outputs::plan_reading(
        &[
            ("--output", f.output.as_ref()),
            ("--report", f.report.as_ref()),
            ("--plot", f.plot.as_ref()),
        ],
        inputs,
    )
}

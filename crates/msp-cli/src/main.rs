//! `msp`: tune, simulate and compare dead-time compensators from the command line.
//!
//! `cli` holds the clap types, `commands` one module per subcommand,
//! `data` the CSV files it reads, `export` every output format, `error` the failures and their exit status.

mod cli;
mod commands;
mod data;
mod error;
mod export;
mod input;

use std::process::ExitCode;

use clap::Parser;

use crate::cli::{Cli, Cmd};
use crate::commands as c;
use crate::error::CliError;

fn main() -> ExitCode {
    let cli = Cli::parse();
    export::remove_temporaries_on_interrupt();
    let res = match &cli.cmd {
        Cmd::Run(a) => c::run::run(a),
        Cmd::Compare(a) => c::compare::compare(a),
        Cmd::Tune(a) => c::tune::tune(a),
        Cmd::Margins(a) => c::margins::margins(a),
        Cmd::Step(a) => c::step::step(a),
        Cmd::Sweep(a) => c::sweep::sweep(a),
        Cmd::Autotune(a) => c::autotune::autotune(a),
        Cmd::Identify(a) => c::identify::identify(a),
        Cmd::Stepinfo(a) => c::identify::stepinfo(a),
        Cmd::Tradeoff(a) => c::tradeoff::tradeoff(a),
        Cmd::List => c::list::list(),
        Cmd::Serve(a) => c::serve::serve(a),
    };
    match res {
        Ok(()) => ExitCode::SUCCESS,
        // the reader has gone (`msp list | head -1`): nothing left to say
        Err(CliError::BrokenPipe) => ExitCode::SUCCESS,
        Err(e) => {
            export::note(format_args!("error: {e}"));
            ExitCode::from(e.exit_status())
        }
    }
}

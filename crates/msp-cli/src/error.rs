//! What can go wrong, and the exit status each failure maps to.

use msp::study::RunError;

/// A failure, with the exit status it maps to.
#[derive(Debug)]
pub(crate) enum CliError {
    /// Bad input: exit status 2.
    Input(String),
    /// Failure while running: exit status 1.
    Runtime(String),
    /// Standard output was closed by its reader: the command ends quietly.
    BrokenPipe,
}

impl CliError {
    /// The process exit status: 2 for bad input, 1 for a failure while running.
    pub(crate) fn exit_status(&self) -> u8 {
        match self {
            CliError::Input(_) => 2,
            CliError::Runtime(_) => 1,
            CliError::BrokenPipe => 0,
        }
    }

    /// A failed write to standard output.
    pub(crate) fn stdout(e: &std::io::Error) -> Self {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            CliError::BrokenPipe
        } else {
            CliError::Runtime(format!("writing to standard output: {e}"))
        }
    }
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CliError::Input(m) | CliError::Runtime(m) => f.write_str(m),
            CliError::BrokenPipe => f.write_str("standard output closed"),
        }
    }
}

impl From<RunError> for CliError {
    fn from(e: RunError) -> Self {
        CliError::Input(e.to_string())
    }
}

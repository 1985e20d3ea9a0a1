//! One module per subcommand; each takes its parsed arguments and writes its
//! outputs through [`crate::export`].

pub(crate) mod autotune;
pub(crate) mod compare;
pub(crate) mod identify;
pub(crate) mod list;
pub(crate) mod margins;
pub(crate) mod run;
pub(crate) mod scenario;
pub(crate) mod step;
pub(crate) mod sweep;
pub(crate) mod tune;

//! `cosim run --isolate=run` where isolation is not available (Windows, macOS:
//! [`fmi_import::isolate::os::unsupported`]): the same functions as on Linux, which refuse.
//! `cosim` refuses `--isolate` before it loads anything; these are for other callers.

use crate::error::{Error, Result};
use crate::simulate::{Experiment, Results, Summary};
use crate::system::System;

/// The environment variable that makes a `cosim` the host of a whole run (ignored here).
pub const HOST_VARIABLE: &str = "NIGEL_COSIM_WHOLE_RUN";

/// Whether this process is the host of a whole run: never here.
pub fn is_host() -> bool {
    false
}

fn refused() -> Error {
    Error::Experiment(fmi_import::isolate::os::unsupported().unwrap_or_default())
}

/// Refused: isolation is Linux-only.
pub fn host_simulate(_system: &System, _experiment: &Experiment) -> Result<()> {
    Err(refused())
}

/// What the parent learns from a finished host (never made here).
pub struct HostRun {
    /// The rows the host wrote.
    pub results: Results,
    /// The summary and its JSON, or why there is none.
    pub outcome: std::result::Result<(Summary, serde_json::Value), Option<Error>>,
}

/// Refused: isolation is Linux-only.
pub fn simulate_in_host(_system: &System, _experiment: &Experiment, _args: &[std::ffi::OsString]) -> Result<HostRun> {
    Err(refused())
}

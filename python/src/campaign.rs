//! `run_campaign`: a campaign of the `nigel-campaign` library run from Python.

use crate::errors::CampaignError;
use crate::interrupt::interruptible;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Runs a campaign into `out`: `spec` is the description's `.toml` path, or `spec_text`
/// the description's TOML text (a dict from Python, written by the Python half in its
/// order, into a temporary file; relative paths from the current folder, as for a file). Returns (results.csv path, runs, failed runs). The runs are threads of this
/// process (`threads`, default all cores); failed runs are rows with their status.
#[pyfunction]
#[pyo3(signature = (spec, spec_text, out, threads=None, shard=None, progress=false))]
pub(crate) fn run_campaign(
    py: Python<'_>,
    spec: Option<PathBuf>,
    spec_text: Option<String>,
    out: PathBuf,
    threads: Option<usize>,
    shard: Option<(u64, u64)>,
    progress: bool,
) -> PyResult<(PathBuf, u64, u64)> {
    let campaign_error = |e: nigel_campaign::Error| CampaignError::new_err(e.to_string());
    // a description given as a dict: the same TOML a user would write, in a temporary file
    let written;
    let path = match (spec, spec_text) {
        (Some(path), None) => path,
        (None, Some(text)) => {
            let mut file = tempfile::Builder::new()
                .prefix("nigel-campaign-")
                .suffix(".toml")
                .tempfile()
                .map_err(|e| CampaignError::new_err(format!("writing the description: {e}")))?;
            std::io::Write::write_all(&mut file, text.as_bytes())
                .map_err(|e| CampaignError::new_err(format!("writing the description: {e}")))?;
            written = file;
            written.path().to_path_buf()
        }
        _ => return Err(PyValueError::new_err("give either a description path or a dict")),
    };
    let spec = nigel_campaign::spec::Spec::load(&path).map_err(campaign_error)?;
    let mut options = nigel_campaign::run::Options::new(out.clone());
    options.threads = threads;
    options.shard = shard;
    options.progress = progress;
    options.allow_failures = true;
    // Ctrl-C: no further run starts; the runs in progress finish and the rows so far are
    // written to `out` (a later run with the same `out` would resume them)
    let cancel = Arc::new(AtomicBool::new(false));
    options.cancel = Some(cancel.clone());
    let done = interruptible(py, &cancel, || nigel_campaign::run::run(&spec, &options))?.map_err(campaign_error)?;
    Ok((out.join("results.csv"), done.ran, done.failed))
}

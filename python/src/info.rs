//! `info`: what an FMU or an SSP declares, as `cosim info` prints it
//! (`nigel_cosim::info::describe`).

use pyo3::prelude::*;
use std::path::PathBuf;

/// The text `cosim info FILE` prints of the FMU or SSP `filename` (the model, its
/// interfaces and default experiment, one line per variable; an SSP's instances, applied
/// values and connections). Load errors raise the package's `LoadError`.
#[pyfunction]
pub(crate) fn info(py: Python<'_>, filename: PathBuf) -> PyResult<String> {
    let limits = nigel_cosim::UnpackLimits::default();
    py.detach(|| nigel_cosim::info::describe(&filename, &limits)).map_err(crate::errors::to_py)
}

//! The package's exception classes and the Python exception of each master error.

use nigel_cosim::Error as CosimError;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(nigel_cosim, Error, PyException, "Every error of nigel_cosim, with the master's message.");
create_exception!(
    nigel_cosim,
    LoadError,
    Error,
    "An FMU or SSP could not be loaded: a missing or malformed file, a hostile archive, a missing binary, a feature cosim does not run."
);
create_exception!(
    nigel_cosim,
    VariableError,
    Error,
    "A variable or instance name that does not exist (with a suggestion), or a value it cannot take."
);
create_exception!(
    nigel_cosim,
    SimulationError,
    Error,
    "The run failed: an FMU returned an error, crashed in its host process, or an event iteration did not converge."
);
create_exception!(
    nigel_cosim,
    ExperimentError,
    Error,
    "The experiment cannot be run as given (times, step, output interval, solver)."
);
create_exception!(nigel_cosim, RunTimeoutError, Error, "The run took longer than its `timeout`.");
create_exception!(nigel_cosim, CampaignError, Error, "A campaign description or its run failed.");

/// The Python exception of a master error.
pub(crate) fn to_py(e: CosimError) -> PyErr {
    let message = e.to_string();
    use nigel_cosim::ImportError as I;
    use CosimError as E;
    match e {
        E::Import(
            I::Io { .. }
            | I::NotRegularFile { .. }
            | I::Archive { .. }
            | I::UnsafeEntry { .. }
            | I::ArchiveLimit { .. }
            | I::ModelDescription { .. }
            | I::NoInterface { .. }
            | I::MissingBinary { .. }
            | I::LoadLibrary { .. }
            | I::MissingSymbol { .. }
            | I::Unsupported { .. }
            | I::EventMode { .. },
        )
        | E::Ssp { .. } => LoadError::new_err(message),
        E::UnknownVariable { .. }
        | E::NotInView { .. }
        | E::UnknownInstance { .. }
        | E::NoInstance { .. }
        | E::Import(I::InvalidValue { .. })
        | E::Connection { .. } => VariableError::new_err(message),
        E::Timeout { .. } => RunTimeoutError::new_err(message),
        E::Experiment(_) => ExperimentError::new_err(message),
        _ => SimulationError::new_err(message),
    }
}

/// Adds the exception classes to the module `_native`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("LoadError", py.get_type::<LoadError>())?;
    m.add("VariableError", py.get_type::<VariableError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("ExperimentError", py.get_type::<ExperimentError>())?;
    m.add("RunTimeoutError", py.get_type::<RunTimeoutError>())?;
    m.add("CampaignError", py.get_type::<CampaignError>())?;
    Ok(())
}

//! `nigel_cosim._native`: the Rust half of the Python package `nigel_cosim`.
//!
//! A thin layer over the `nigel-cosim` and `nigel-campaign` libraries: it loads an FMU or
//! an SSP once (`system::NativeSystem`), runs experiments on it with the interpreter's lock
//! released, and turns the master's errors into the package's exception classes. The
//! fmpy-compatible keyword handling, the structured arrays and the DataFrame live in the
//! Python half (`nigel_cosim/__init__.py`), where users can read them.
//!
//! A whole run happens on a worker thread while the calling thread waits without the GIL,
//! waking every 100 ms to let Python handle signals: Ctrl-C sets the run's cancel flag, the
//! run stops at its next step, its instances are freed, and `KeyboardInterrupt` is raised.
//! A run stepped from Python (`NativeRun`) is an `Execution` advanced in the calling
//! thread, the GIL released for at most 100 ms at a time between signal checks.
//!
//! One module per class or concern: `errors` (the exception classes), `run_args` (a
//! run's arguments and their experiment), `system` (`NativeSystem`), `stepped_run`
//! (`NativeRun`), `interrupt` (waiting with signals handled), `campaign`, `compare`, `info`;
//! this file only registers them. `nigel_cosim/_native.pyi` is their typed surface, checked
//! against the built module by mypy's `stubtest` (scripts/test-python-package.sh).

mod campaign;
mod compare;
mod errors;
mod info;
mod interrupt;
mod run_args;
mod stepped_run;
mod system;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<system::NativeSystem>()?;
    m.add_class::<stepped_run::NativeRun>()?;
    m.add_function(wrap_pyfunction!(campaign::run_campaign, m)?)?;
    m.add_function(wrap_pyfunction!(compare::compare, m)?)?;
    m.add_function(wrap_pyfunction!(info::info, m)?)?;
    errors::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

//! `NativeRun`: a run stepped from Python (`step_until`, `get`, `set` between steps).

use crate::errors::{to_py, Error, VariableError};
use nigel_cosim::{
    simulate::{Execution, Phase},
    Error as CosimError, Experiment, Summary, System,
};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// A run stepped from Python: an [`Execution`] advanced in the calling thread to the first
/// output point at or after the time asked for, the rows so far kept, values set between
/// steps applied before the next step ([`Execution::set`]).
#[pyclass(module = "nigel_cosim._native", frozen)]
pub(crate) struct NativeRun {
    /// Recorded columns (bare names for a single FMU) and their base types.
    names: Vec<String>,
    types: Vec<&'static str>,
    single: Option<String>,
    execution: Mutex<Execution<'static>>,
    /// The summary, once the run has reached its end and terminated its instances.
    summary: Mutex<Option<Summary>>,
}

/// Whether `t` has reached `target` (fmpy's `isclose` with its defaults for the last bit).
fn reached(t: f64, target: f64) -> bool {
    t >= target || (t - target).abs() <= 1e-9 * t.abs().max(target.abs())
}

/// How long the GIL is released at a time while a stepped run advances (then Python
/// handles its signals: Ctrl-C).
const SIGNAL_CHECK: Duration = Duration::from_millis(100);

impl NativeRun {
    pub(crate) fn start(
        py: Python<'_>,
        system: System,
        experiment: Experiment,
        names: Vec<String>,
        types: Vec<&'static str>,
        single: Option<String>,
    ) -> PyResult<NativeRun> {
        let mut execution = Execution::new(&system, &experiment).map_err(to_py)?;
        py.detach(|| execution.initialize()).map_err(to_py)?;
        let run = NativeRun { names, types, single, execution: Mutex::new(execution), summary: Mutex::new(None) };
        run.finish_at_end()?;
        Ok(run)
    }

    fn execution(&self) -> std::sync::MutexGuard<'_, Execution<'static>> {
        self.execution.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// At the end of the run (its stop time, or an FMU ended it): the instances terminated
    /// and the summary kept.
    fn finish_at_end(&self) -> PyResult<()> {
        let mut execution = self.execution();
        if execution.phase() == Phase::AtEnd {
            let summary = execution.finish().map_err(to_py)?;
            *self.summary.lock().unwrap_or_else(|p| p.into_inner()) = Some(summary);
        }
        Ok(())
    }
}

#[pymethods]
impl NativeRun {
    /// The time of the last recorded row (the run is paused there, or ended there).
    #[getter]
    fn time(&self) -> f64 {
        self.execution().last_row_time().unwrap_or(f64::NAN)
    }

    /// Whether the run has ended (its stop time, an FMU's terminate request, `terminate`).
    #[getter]
    fn finished(&self) -> bool {
        self.execution().phase() != Phase::Running
    }

    /// Runs on to the first output point at or after `time` (the stop time at most).
    fn step_until(&self, py: Python<'_>, time: f64) -> PyResult<f64> {
        if !time.is_finite() {
            return Err(PyValueError::new_err(format!("step_until({time}): the time must be finite")));
        }
        if self.finished() {
            return Err(Error::new_err("the run has ended (initialize a new one)"));
        }
        loop {
            let done = py.detach(|| -> Result<bool, CosimError> {
                let mut execution = self.execution();
                let start = Instant::now();
                loop {
                    let paused = execution.at_output_point() && reached(execution.time(), time);
                    if paused || execution.phase() != Phase::Running {
                        return Ok(true);
                    }
                    if start.elapsed() > SIGNAL_CHECK {
                        return Ok(false);
                    }
                    execution.step()?;
                }
            });
            match done {
                Ok(true) => break,
                Ok(false) => {
                    if let Err(e) = py.check_signals() {
                        self.execution().stop();
                        return Err(e);
                    }
                }
                Err(e) => return Err(to_py(e)),
            }
        }
        self.finish_at_end()?;
        Ok(self.time())
    }

    /// The recorded value of `name` at the current time.
    fn get(&self, name: &str) -> PyResult<f64> {
        let j = self.names.iter().position(|n| n == name).ok_or_else(|| {
            VariableError::new_err(format!("{name:?} is not recorded in this run (add it to output=)"))
        })?;
        let row = self.execution().last_row().ok_or_else(|| Error::new_err("the run has no row yet"))?;
        Ok(row[1 + j])
    }

    /// Sets an input or tunable parameter from the next communication step on.
    fn set(&self, name: &str, value: &str) -> PyResult<()> {
        if self.finished() {
            return Err(Error::new_err("the run has ended (initialize a new one)"));
        }
        let full = match &self.single {
            Some(instance) => format!("{instance}.{name}"),
            None => name.to_string(),
        };
        self.execution().set(&full, value).map_err(to_py)
    }

    /// (names, types, rows so far as a rows x (1 + columns) array, the exact columns as
    /// (column, text of every row)).
    #[allow(clippy::type_complexity)]
    fn results<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Vec<String>, Vec<&'static str>, Bound<'py, PyAny>, Vec<(usize, Vec<String>)>)> {
        let results = self.execution().results();
        let exact = exact_columns(&results);
        let width = self.names.len() + 1;
        let rows = results.values.len() / width;
        let array = PyArray1::from_vec(py, results.values).reshape([rows, width])?;
        Ok((self.names.clone(), self.types.clone(), array.into_any(), exact))
    }

    /// Ends the run (terminating and freeing its instances); the summary as JSON text, or
    /// None when it was ended before its stop time.
    fn terminate(&self) -> Option<String> {
        self.execution().stop();
        self.summary
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .as_ref()
            .and_then(|s| serde_json::to_string(&s.to_json()).ok())
    }
}

/// The columns of `results` whose values an f64 does not hold: (column among the names,
/// the text of every row).
pub(crate) fn exact_columns(results: &nigel_cosim::Results) -> Vec<(usize, Vec<String>)> {
    results.exact.iter().map(|e| (e.column, e.rows.clone())).collect()
}

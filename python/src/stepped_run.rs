//! `NativeRun`: a run stepped from Python (`step_until`, `get`, `set` between steps).

use crate::errors::{to_py, Error, VariableError};
use nigel_cosim::{simulate::simulate_with, Error as CosimError, Experiment, SetQueue, Summary, System};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// What the worker thread of a [`NativeRun`] tells the caller.
enum RunEvent {
    /// Paused at an output point.
    Paused,
    /// The run ended: the summary, or why it failed.
    Finished(Result<Summary, CosimError>),
}

/// How far a [`NativeRun`] is.
enum RunState {
    Paused,
    Finished(Option<Summary>),
}

/// A run stepped from outside: the master's loop on a worker thread that pauses at the
/// first output point at or after the time asked for (its row sink waits there for the
/// next target time), with the rows so far kept and values set between steps applied
/// before the next step ([`SetQueue`]).
#[pyclass(module = "nigel_cosim._native", frozen)]
pub(crate) struct NativeRun {
    system: System,
    /// Recorded columns (bare names for a single FMU) and their base types.
    names: Vec<String>,
    types: Vec<&'static str>,
    single: Option<String>,
    /// `time, v1, v2, ...` per row so far.
    rows: Arc<Mutex<Vec<f64>>>,
    queue: Arc<SetQueue>,
    cancel: Arc<AtomicBool>,
    /// Target times to the worker (NaN: stop).
    commands: Mutex<Sender<f64>>,
    events: Mutex<Receiver<RunEvent>>,
    state: Mutex<RunState>,
    worker: Mutex<Option<std::thread::JoinHandle<()>>>,
}

/// Whether `t` has reached `target` (fmpy's `isclose` with its defaults for the last bit).
fn reached(t: f64, target: f64) -> bool {
    t >= target || (t - target).abs() <= 1e-9 * t.abs().max(target.abs())
}

impl NativeRun {
    pub(crate) fn start(
        py: Python<'_>,
        system: System,
        mut experiment: Experiment,
        names: Vec<String>,
        types: Vec<&'static str>,
        single: Option<String>,
    ) -> PyResult<NativeRun> {
        let rows = Arc::new(Mutex::new(Vec::new()));
        let queue = Arc::new(SetQueue::new());
        let cancel = Arc::new(AtomicBool::new(false));
        experiment.cancel = Some(cancel.clone());
        experiment.between_steps = Some(queue.clone());
        let (command_tx, command_rx) = std::sync::mpsc::channel::<f64>();
        let (event_tx, event_rx) = std::sync::mpsc::channel::<RunEvent>();
        let worker = {
            let (system, rows, cancel) = (system.clone(), rows.clone(), cancel.clone());
            let mut target = experiment.start_time;
            std::thread::spawn(move || {
                let events = event_tx.clone();
                let mut sink = |t: f64, row: &[f64]| {
                    {
                        let mut rows = rows.lock().unwrap_or_else(|p| p.into_inner());
                        rows.push(t);
                        rows.extend_from_slice(row);
                    }
                    // wait here until asked for a later time (or to stop: the cancel flag ends
                    // the run at its next step)
                    while reached(t, target) && !cancel.load(Ordering::Relaxed) {
                        let _ = events.send(RunEvent::Paused);
                        match command_rx.recv() {
                            Ok(next) if !next.is_nan() => target = next,
                            _ => cancel.store(true, Ordering::Relaxed),
                        }
                    }
                };
                let outcome = simulate_with(&system, &experiment, None, Some(&mut sink)).map(|(_, summary)| summary);
                let _ = event_tx.send(RunEvent::Finished(outcome));
            })
        };
        let run = NativeRun {
            system,
            names,
            types,
            single,
            rows,
            queue,
            cancel,
            commands: Mutex::new(command_tx),
            events: Mutex::new(event_rx),
            state: Mutex::new(RunState::Paused),
            worker: Mutex::new(Some(worker)),
        };
        run.wait(py)?;
        Ok(run)
    }

    /// Waits for the worker's next event without the GIL, handling signals every 100 ms
    /// (Ctrl-C stops the run and raises).
    fn wait(&self, py: Python<'_>) -> PyResult<()> {
        let event = loop {
            let got = py.detach(|| {
                let events = self.events.lock().unwrap_or_else(|p| p.into_inner());
                events.recv_timeout(Duration::from_millis(100))
            });
            match got {
                Ok(event) => break event,
                Err(RecvTimeoutError::Timeout) => {
                    if let Err(e) = py.check_signals() {
                        self.stop(py);
                        return Err(e);
                    }
                }
                Err(RecvTimeoutError::Disconnected) => {
                    break RunEvent::Finished(Err(CosimError::Cancelled { time: f64::NAN }))
                }
            }
        };
        let mut state = self.state.lock().unwrap_or_else(|p| p.into_inner());
        match event {
            RunEvent::Paused => *state = RunState::Paused,
            RunEvent::Finished(Ok(summary)) => *state = RunState::Finished(Some(summary)),
            RunEvent::Finished(Err(CosimError::Cancelled { .. })) => *state = RunState::Finished(None),
            RunEvent::Finished(Err(e)) => {
                *state = RunState::Finished(None);
                return Err(to_py(e));
            }
        }
        Ok(())
    }

    /// Ends the run (the cancel flag and a stop command) and joins the worker.
    fn stop(&self, py: Python<'_>) {
        self.cancel.store(true, Ordering::Relaxed);
        let _ = self.commands.lock().unwrap_or_else(|p| p.into_inner()).send(f64::NAN);
        let worker = self.worker.lock().unwrap_or_else(|p| p.into_inner()).take();
        if let Some(w) = worker {
            let _ = py.detach(|| w.join());
        }
        let mut state = self.state.lock().unwrap_or_else(|p| p.into_inner());
        if let RunState::Paused = *state {
            *state = RunState::Finished(None);
        }
    }
}

#[pymethods]
impl NativeRun {
    /// The time of the last recorded row (the run is paused there, or ended there).
    #[getter]
    fn time(&self) -> f64 {
        let rows = self.rows.lock().unwrap_or_else(|p| p.into_inner());
        let width = self.names.len() + 1;
        rows.len().checked_sub(width).map_or(f64::NAN, |k| rows[k])
    }

    /// Whether the run has ended (its stop time, an FMU's terminate request, `terminate`).
    #[getter]
    fn finished(&self) -> bool {
        matches!(*self.state.lock().unwrap_or_else(|p| p.into_inner()), RunState::Finished(_))
    }

    /// Runs on to the first output point at or after `time` (the stop time at most).
    fn step_until(&self, py: Python<'_>, time: f64) -> PyResult<f64> {
        if !time.is_finite() {
            return Err(PyValueError::new_err(format!("step_until({time}): the time must be finite")));
        }
        if self.finished() {
            return Err(Error::new_err("the run has ended (initialize a new one)"));
        }
        if reached(self.time(), time) {
            return Ok(self.time());
        }
        self.commands
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .send(time)
            .map_err(|_| Error::new_err("the run has ended (initialize a new one)"))?;
        self.wait(py)?;
        Ok(self.time())
    }

    /// The recorded value of `name` at the current time.
    fn get(&self, name: &str) -> PyResult<f64> {
        let j = self.names.iter().position(|n| n == name).ok_or_else(|| {
            VariableError::new_err(format!("{name:?} is not recorded in this run (add it to output=)"))
        })?;
        let rows = self.rows.lock().unwrap_or_else(|p| p.into_inner());
        let width = self.names.len() + 1;
        let k = rows.len().checked_sub(width).ok_or_else(|| Error::new_err("the run has no row yet"))?;
        Ok(rows[k + 1 + j])
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
        self.queue.push_text(&self.system, &full, value).map_err(to_py)
    }

    /// (names, types, rows so far as a rows x (1 + columns) array).
    fn results<'py>(&self, py: Python<'py>) -> PyResult<(Vec<String>, Vec<&'static str>, Bound<'py, PyAny>)> {
        let values = self.rows.lock().unwrap_or_else(|p| p.into_inner()).clone();
        let width = self.names.len() + 1;
        let rows = values.len() / width;
        let array = PyArray1::from_vec(py, values).reshape([rows, width])?;
        Ok((self.names.clone(), self.types.clone(), array.into_any()))
    }

    /// Ends the run (terminating and freeing its instances); the summary as JSON text, or
    /// None when it was ended before its stop time.
    fn terminate(&self, py: Python<'_>) -> Option<String> {
        self.stop(py);
        match &*self.state.lock().unwrap_or_else(|p| p.into_inner()) {
            RunState::Finished(Some(summary)) => serde_json::to_string(&summary.to_json()).ok(),
            _ => None,
        }
    }
}

impl Drop for NativeRun {
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
        let _ = self.commands.lock().unwrap_or_else(|p| p.into_inner()).send(f64::NAN);
        if let Some(w) = self.worker.lock().unwrap_or_else(|p| p.into_inner()).take() {
            let _ = w.join();
        }
    }
}

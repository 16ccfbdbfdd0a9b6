//! Waiting for a run without the interpreter's lock while letting Python handle signals.

use crate::errors::SimulationError;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Duration;

/// Runs `f` on a worker thread while this thread waits without the GIL, handling signals
/// every 100 ms; on a Python exception (Ctrl-C) sets `cancel`, waits for the run to stop
/// and returns the exception.
pub(crate) fn interruptible<T: Send>(py: Python<'_>, cancel: &AtomicBool, f: impl FnOnce() -> T + Send) -> PyResult<T> {
    std::thread::scope(|scope| {
        let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
        // a Receiver is not Sync; the waits below borrow it from the GIL-free closures
        let done_rx = Mutex::new(done_rx);
        let worker = scope.spawn(move || {
            let out = f();
            let _ = done_tx.send(());
            out
        });
        loop {
            let finished = py.detach(|| {
                let rx = done_rx.lock().unwrap_or_else(|p| p.into_inner());
                rx.recv_timeout(Duration::from_millis(100)).is_ok() || worker.is_finished()
            });
            if finished {
                break;
            }
            if let Err(e) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                let _ = py.detach(|| worker.join());
                return Err(e);
            }
        }
        py.detach(|| worker.join()).map_err(|_| SimulationError::new_err("the run panicked (a defect of nigel_cosim)"))
    })
}

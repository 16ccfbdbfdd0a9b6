//! An FMU that ends the process with `exit()` inside one of its calls, in process.
//!
//! `exit(0)` in `fmi2DoStep` would end the master with status 0 and nothing written: a
//! failed run that looks like a success. The master registers one `atexit` handler (at
//! its first run) and marks every call into an FMU (a thread-local: instance, FMU,
//! function, time; two stores per call). When `exit()` runs while a run is in progress,
//! the handler reports the instance and the call, hands the rows recorded so far to the
//! hook the program installed ([`on_exit_inside_call`]; `cosim` writes them to its
//! `--output`), removes the temporary folders and ends the process with `_exit(1)`.
//!
//! Why this is safe enough in an `atexit` handler: handlers run in ordinary context (not
//! in a signal handler), in the thread that called `exit()`, so allocation and file
//! writes are allowed. What the handler must not do is wait: other threads keep running
//! and may hold locks, so the rows are taken with `try_lock` (the recorder holds their
//! lock only while it appends a row, never during an FMU call) and the list of temporary
//! folders likewise; a lock that is held means "not written", said so, never a hang. It
//! ends with `_exit`: calling `exit()` again from a handler is undefined, and the
//! remaining handlers (the FMU's own destructors, run while the FMU is inside a call)
//! are better not run. The marker is `fmi_import::call_site`'s (what it holds and why
//! reading it in the handler is sound is said there).

pub use fmi_import::call_site::ExitInsideCall;

use crate::simulate::Results;
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

/// What the program does with the rows when a run in this process ends the process (an
/// FMU's `exit()` during a call, or [`end_process_during_run`]): given what happened (a
/// sentence naming the call when there is one) and the rows recorded so far (`None` when
/// they could not be taken without waiting, or went to a [`crate::RowSink`]). The process
/// then ends with status 1.
pub type ExitHook = dyn Fn(&str, Option<&Results>) + Send + Sync;

static HOOK: OnceLock<Box<ExitHook>> = OnceLock::new();

/// Installs the hook called when an FMU ends the process with `exit()` during a run in
/// this process (once per process; a second call returns false and changes nothing).
/// Without a hook the call is reported on standard error. Either way the process ends
/// with status 1, not with the status the FMU gave.
pub fn on_exit_inside_call(hook: Box<ExitHook>) -> bool {
    HOOK.set(hook).is_ok()
}

/// The rows of one run, shared with the handler.
#[derive(Default)]
pub(crate) struct RunRows {
    pub(crate) results: Mutex<Results>,
}

thread_local! {
    static RUN: Cell<*const RunRows> = const { Cell::new(std::ptr::null()) };
}

/// Runs in progress in this process.
static ACTIVE: AtomicUsize = AtomicUsize::new(0);

/// A run in progress: its rows known to this thread's handler while it lives.
pub(crate) struct Registered {
    /// The rows the handler reads, kept alive while the run is registered.
    _rows: Arc<RunRows>,
    previous: *const RunRows,
}

/// The rows of the run registered last in any thread (for [`end_process_during_run`],
/// called from a thread of no run).
static LATEST: Mutex<Option<Arc<RunRows>>> = Mutex::new(None);

impl Registered {
    pub(crate) fn new(rows: Arc<RunRows>) -> Registered {
        if let Ok(mut latest) = LATEST.lock() {
            *latest = Some(rows.clone());
        }
        static ONCE: std::sync::Once = std::sync::Once::new();
        // SAFETY: registers a plain `extern "C" fn()` with the C library.
        ONCE.call_once(|| unsafe {
            libc::atexit(on_exit);
        });
        ACTIVE.fetch_add(1, Ordering::SeqCst);
        let previous = RUN.with(|r| r.replace(Arc::as_ptr(&rows)));
        Registered { _rows: rows, previous }
    }
}

/// The run this thread is in, for the threads it starts to step its instances
/// ([`RunHandle::enter`]).
pub(crate) fn current_run() -> RunHandle {
    RunHandle(RUN.with(|r| r.get()))
}

impl Drop for Registered {
    fn drop(&mut self) {
        RUN.with(|r| r.set(self.previous));
        if ACTIVE.fetch_sub(1, Ordering::SeqCst) == 1 {
            if let Ok(mut latest) = LATEST.lock() {
                *latest = None;
            }
        }
    }
}

/// Ends the process from any thread while a run is in progress in another (a call that
/// never returns past the run's time limit): `what` and the rows recorded so far go to
/// the program's hook (or `what` to standard error), the temporary folders are removed,
/// and the process ends with `_exit(1)`. Nothing here waits for a lock the stuck run
/// may hold (`try_lock`: a held lock means the rows are not written, and said so).
pub fn end_process_during_run(what: &str) -> ! {
    let rows = LATEST.try_lock().ok().and_then(|latest| latest.clone());
    let results = rows.as_ref().and_then(|r| r.results.try_lock().ok());
    report(what, results.as_deref());
    fmi_import::unpack::remove_temporary_folders_now();
    // SAFETY: ends the process at once: the stuck thread cannot be unwound.
    unsafe { libc::_exit(1) }
}

fn report(what: &str, rows: Option<&Results>) {
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match HOOK.get() {
        Some(hook) => hook(what, rows),
        None => eprintln!("{what}"),
    }));
    drop(result);
}

/// The run a worker thread steps instances of (valid while its [`Registered`] lives,
/// which outlives the run's scoped threads).
#[derive(Clone, Copy)]
pub(crate) struct RunHandle(*const RunRows);

// SAFETY: the pointer is only read, through a Mutex, while the run is registered.
unsafe impl Send for RunHandle {}
unsafe impl Sync for RunHandle {}

impl RunHandle {
    /// Makes this thread's exit() report the run's rows.
    pub(crate) fn enter(self) {
        RUN.with(|r| r.set(self.0));
    }
}

extern "C" fn on_exit() {
    if ACTIVE.load(Ordering::SeqCst) == 0 {
        return; // the program ends normally, between runs
    }
    let call = fmi_import::call_site::current_call();
    let run = RUN.try_with(|r| r.get()).unwrap_or(std::ptr::null());
    // SAFETY: a registered run's rows outlive its registration, which is in progress.
    let rows = (!run.is_null()).then(|| unsafe { &*run }).and_then(|r| r.results.try_lock().ok());
    let what = match &call {
        Some(c) => c.to_string(),
        None => "exit() was called during a run, outside an FMU call of the calling thread".to_string(),
    };
    report(&what, rows.as_deref());
    fmi_import::unpack::remove_temporary_folders_now();
    // SAFETY: ends the process at once, as the handler must (see the module's comment).
    unsafe { libc::_exit(1) };
}

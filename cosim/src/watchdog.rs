//! The run's time limit for a program that runs its FMUs in its own process (`cosim run
//! --timeout` without `--isolate`).
//!
//! The master checks the limit between calls ([`crate::Experiment::timeout`]); a call
//! that never returns never gets back to it. A thread cannot be stopped from outside in
//! a way that leaves the process sound, so the watchdog does what can be done safely:
//! when the run is still going a grace period after its limit, it names the call in
//! progress (from `fmi_import::call_site`'s marks), hands the rows recorded so far to the
//! program's exit hook, removes the temporary folders and ends the process with status
//! 1 ([`crate::exit_guard::end_process_during_run`]). For a program only: a library
//! caller (the Python package) would lose its process; it has `isolation` instead.

use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

/// How long after the limit the watchdog waits for the master's own check (between
/// calls) to stop the run, s.
pub const GRACE: Duration = Duration::from_secs(1);

/// A watchdog over one run: dropped (the run over), it stops.
pub struct Watchdog {
    done: Arc<(Mutex<bool>, Condvar)>,
    thread: Option<std::thread::JoinHandle<()>>,
}

/// The call marks the watchdog reads (leaked: marks are written to them until the
/// process ends).
fn slots() -> &'static fmi_import::call_site::CallSlots {
    static SLOTS: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    let address = *SLOTS.get_or_init(|| {
        // SAFETY: CallSlots is atomics and byte arrays: all zeros is a valid value
        let slots: &'static mut fmi_import::call_site::CallSlots =
            Box::leak(Box::new(unsafe { std::mem::zeroed::<fmi_import::call_site::CallSlots>() }));
        let pointer = slots as *mut fmi_import::call_site::CallSlots;
        // SAFETY: leaked, so valid for the rest of the process
        unsafe { fmi_import::call_site::mark_calls_in(pointer) };
        pointer as usize
    });
    // SAFETY: the leaked slots live to the end of the process
    unsafe { &*(address as *const fmi_import::call_site::CallSlots) }
}

/// Starts watching a run whose time limit is `limit` (from now).
pub fn start(limit: Duration) -> Watchdog {
    let slots = slots();
    let done = Arc::new((Mutex::new(false), Condvar::new()));
    let watched = done.clone();
    let thread = std::thread::spawn(move || {
        let (lock, cv) = &*watched;
        let Ok(guard) = lock.lock() else { return };
        let Ok((guard, _)) = cv.wait_timeout_while(guard, limit + GRACE, |done| !*done) else { return };
        if *guard {
            return;
        }
        let (instance, function, time, in_call) = slots.last_call();
        let during = if in_call {
            format!("during {function} of {instance} at t = {time} s, which has not returned")
        } else {
            "and the run has not stopped".to_string()
        };
        crate::exit_guard::end_process_during_run(&format!(
            "the run's time limit of {} s (--timeout) passed {} s ago {during}: a call in this process cannot be stopped, so the process ends (--isolate runs each FMU in a process of its own, which is killed instead)",
            limit.as_secs_f64(),
            GRACE.as_secs_f64()
        ));
    });
    Watchdog { done, thread: Some(thread) }
}

impl Drop for Watchdog {
    fn drop(&mut self) {
        let (lock, cv) = &*self.done;
        if let Ok(mut done) = lock.lock() {
            *done = true;
        }
        cv.notify_all();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

//! The callbacks of FMI 3.0 Scheduled Execution and their instance environment: a
//! [`ScheduledEnvironment`] the instance owns (boxed: its address stays put while the FMU
//! lives), holding the log sink and the flag `clockUpdate` raises. The master activates one
//! partition at a time on one thread, so nothing preempts a partition: `lockPreemption` and
//! `unlockPreemption` have nothing to lock, and the results do not depend on timing. No
//! callback can panic (atomic loads and stores; the logger catches its own).

use std::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

use fmi_sys::fmi3::fmi3InstanceEnvironment;

use crate::log::{Fmi3LogEnvironment, LogSink};

/// What the FMU's callbacks receive as their instance environment in Scheduled Execution.
#[derive(Debug, Default)]
pub(crate) struct ScheduledEnvironment {
    /// The instance's log sink (set at instantiation; it outlives the FMU instance).
    pub(super) log: AtomicPtr<LogSink>,
    /// Raised by `clockUpdate`: an output clock ticked or a countdown clock's interval is
    /// known; taken by the master after the activation that raised it.
    pub(super) clock_update: AtomicBool,
}

/// The log callback's sink (`crate::log::log_message::<ScheduledEnvironment>`).
impl Fmi3LogEnvironment for ScheduledEnvironment {
    fn sink(&self) -> *const LogSink {
        self.log.load(Ordering::Relaxed)
    }
}

/// `fmi3ClockUpdateCallback`: raises the flag (an atomic store: nothing here can panic).
pub(super) unsafe extern "C" fn clock_update(environment: fmi3InstanceEnvironment) {
    if environment.is_null() {
        return;
    }
    // SAFETY: the environment is the instance's boxed ScheduledEnvironment, alive while
    // the FMU lives.
    unsafe { &*(environment as *const ScheduledEnvironment) }.clock_update.store(true, Ordering::Release);
}

/// `fmi3LockPreemptionCallback`: nothing to lock (one partition at a time, one thread).
pub(super) unsafe extern "C" fn lock_preemption() {}

/// `fmi3UnlockPreemptionCallback`: see [`lock_preemption`].
pub(super) unsafe extern "C" fn unlock_preemption() {}

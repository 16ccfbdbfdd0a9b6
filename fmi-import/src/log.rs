//! What FMUs log: [`LogRecord`]s kept per instance in a [`LogSink`], filled by the FMI 2.0
//! logger (the shim of `fmi-sys`, [`callbacks_for`]) and the FMI 3.0 one ([`log_message`]).

use std::collections::VecDeque;
use std::ffi::{c_char, CStr};
use std::sync::Mutex;

use fmi_sys::fmi2::logger::{LogEnvironment, LogMessage, LogReceiver};
use fmi_sys::fmi3::{fmi3InstanceEnvironment, fmi3Status, fmi3String};

use crate::c_types::CallbackFunctions;
use crate::status::Status;

/// One message an FMU logged.
#[derive(Clone, Debug, PartialEq)]
pub struct LogRecord {
    /// The status the FMU gave it.
    pub status: Status,
    /// The category.
    pub category: String,
    /// The formatted message.
    pub message: String,
}

/// The last messages of one instance (at most [`LogSink::CAPACITY`]). Its address is
/// stable (boxed) while the instance logs to it.
#[derive(Debug, Default)]
pub struct LogSink {
    environment: LogEnvironment<Records>,
}

#[derive(Debug, Default)]
struct Records(Mutex<VecDeque<LogRecord>>);

impl LogReceiver for Records {
    fn receive(&self, m: &LogMessage<'_>) {
        self.push(LogRecord {
            status: Status::from_raw(m.status),
            category: m.category.to_owned(),
            message: m.message.to_owned(),
        });
    }
}

impl Records {
    fn push(&self, record: LogRecord) {
        if let Ok(mut r) = self.0.lock() {
            if r.len() == LogSink::CAPACITY {
                r.pop_front();
            }
            r.push_back(record);
        }
    }
}

impl LogSink {
    /// Messages kept per instance.
    pub const CAPACITY: usize = 64;

    /// Takes the kept messages.
    pub fn take(&self) -> Vec<LogRecord> {
        self.environment.0.lock().map(|mut r| r.drain(..).collect()).unwrap_or_default()
    }

    /// Keeps `record` (the oldest dropped beyond the capacity).
    pub(crate) fn push(&self, record: LogRecord) {
        self.environment.push(record)
    }

    /// The last messages at Warning or worse, joined, for an error message.
    pub(crate) fn recent_problems(&self) -> String {
        let Ok(records) = self.environment.0.lock() else { return String::new() };
        let v: Vec<&str> =
            records.iter().rev().filter(|r| r.status != Status::Ok).take(3).map(|r| r.message.as_str()).collect();
        v.into_iter().rev().collect::<Vec<_>>().join("; ")
    }
}

/// The FMI 2.0 callbacks of an instance whose messages go to `log` (the logger shim of
/// fmi-sys formats them).
pub(crate) fn callbacks_for(log: &LogSink) -> Box<CallbackFunctions> {
    Box::new(log.environment.callbacks())
}

fn text(p: fmi3String) -> String {
    if p.is_null() {
        return String::new();
    }
    // SAFETY: the FMU passes NUL-terminated strings valid for the call.
    unsafe { CStr::from_ptr(p as *const c_char) }.to_string_lossy().into_owned()
}

/// `fmi3LogMessageCallback`: the instance environment is the instance's [`LogSink`].
pub(crate) unsafe extern "C" fn log_message(
    environment: fmi3InstanceEnvironment,
    status: fmi3Status,
    category: fmi3String,
    message: fmi3String,
) {
    if environment.is_null() {
        return;
    }
    // no panic may cross the C boundary: a failure to record drops the message
    let _ = std::panic::catch_unwind(|| {
        // SAFETY: the environment is the instance's boxed LogSink, alive while it logs.
        let sink = unsafe { &*(environment as *const LogSink) };
        sink.push(LogRecord { status: Status::from_raw(status), category: text(category), message: text(message) });
    });
}

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
    /// The formatted message (at most [`MAX_MESSAGE_BYTES`] and the note of its cut).
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

impl LogSink {
    /// The instance's `componentEnvironment` (this log's environment), which owns the
    /// blocks the FMU allocates in the instance's calls (fmi-sys's `fmi2::guard`).
    pub(crate) fn owner(&self) -> usize {
        self.environment.as_environment() as usize
    }
}

/// The most of an FMI 2.0 message fmi-sys's logger shim formats (its buffer less the NUL):
/// it reads the FMU's strings safely, so it cannot know how long a longer one is.
const FMI2_SHIM_BYTES: usize = 4095;

impl LogReceiver for Records {
    fn receive(&self, m: &LogMessage<'_>) {
        let mut message = m.message.to_owned();
        if message.len() >= FMI2_SHIM_BYTES {
            message.push_str(&format!(" [... cut by cosim at {FMI2_SHIM_BYTES} bytes: the message may be longer]"));
        }
        self.push(LogRecord { status: Status::from_raw(m.status), category: m.category.to_owned(), message });
    }
}

/// The longest message kept, bytes: a longer one is cut there with a note of its length
/// (in process and in a host process alike; a log is for reading, and a message of
/// megabytes would flood the terminal or the region shared with a host). FMI 2.0 messages
/// come cut to 4095 bytes already (fmi-sys's shim), with a note: the bound leaves room for it.
pub const MAX_MESSAGE_BYTES: usize = 4096 + 128;
/// The longest category kept, bytes (cut likewise).
pub const MAX_CATEGORY_BYTES: usize = 256;

/// `text` cut to at most `max` bytes (at a character boundary) followed by a note of its
/// length, or as it is when it fits.
pub(crate) fn bounded(mut text: String, max: usize) -> String {
    if text.len() <= max {
        return text;
    }
    let length = text.len();
    let mut cut = max;
    while !text.is_char_boundary(cut) {
        cut -= 1;
    }
    text.truncate(cut);
    text.push_str(&format!(" [... cut by cosim at {cut} of the message's {length} bytes]"));
    text
}

impl Records {
    fn push(&self, mut record: LogRecord) {
        record.message = bounded(record.message, MAX_MESSAGE_BYTES);
        record.category = bounded(record.category, MAX_CATEGORY_BYTES);
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

    /// Keeps `record` (the oldest dropped beyond the capacity; its message and category
    /// bounded, [`MAX_MESSAGE_BYTES`]).
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

/// What an FMI 3.0 instance environment gives the log callback: the instance's log sink.
pub(crate) trait Fmi3LogEnvironment {
    /// The sink, null when there is none (yet).
    fn sink(&self) -> *const LogSink;
}

/// The environment of an instance that is only its log.
impl Fmi3LogEnvironment for LogSink {
    fn sink(&self) -> *const LogSink {
        self
    }
}

/// `fmi3LogMessageCallback` of an instance whose environment is an `E` (the instance's own,
/// alive while the FMU lives): the message to its [`LogSink`].
pub(crate) unsafe extern "C" fn log_message<E: Fmi3LogEnvironment>(
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
        // SAFETY: the environment is the instance's boxed E, alive while it logs; the sink it
        // gives outlives the FMU.
        let Some(sink) = (unsafe { (*(environment as *const E)).sink().as_ref() }) else { return };
        sink.push(LogRecord { status: Status::from_raw(status), category: text(category), message: text(message) });
    });
}

#[cfg(test)]
mod log_tests {
    use super::bounded;

    #[test]
    fn a_long_message_is_cut_at_a_character_boundary_with_its_length() {
        assert_eq!(bounded("short".into(), 10), "short");
        // "é" is two bytes: a cut at 3 bytes falls inside the second one, so 2 are kept
        assert_eq!(bounded("ééé".into(), 3), "é [... cut by cosim at 2 of the message's 6 bytes]");
        // an FMI 3.0 message (its whole length known) of 10 MB
        let cut = bounded("x".repeat(10_000_000), super::MAX_MESSAGE_BYTES);
        assert_eq!(cut, format!("{} [... cut by cosim at 4224 of the message's 10000000 bytes]", "x".repeat(4224)));
    }
}

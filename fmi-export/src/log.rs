//! The typed logger: the importer's callback (FMI 2.0's `fmi2CallbackLogger` or FMI 3.0's
//! `fmi3LogMessageCallback`) behind categories, shared by the layer and the model (a model
//! gets a clone in its [`crate::InstantiateContext`]).

use std::ffi::{c_int, CStr, CString};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use crate::ffi::{Fmi2CallbackFunctions, Fmi2Status};
use fmi_sys::fmi3::{fmi3InstanceEnvironment, Fmi3LogMessageCallback};

/// Log categories every FMU of ours offers.
pub const LOG_CATEGORIES: [(&str, &str); 4] = [
    ("logStatusError", "Errors (always logged)"),
    ("logStatusWarning", "Warnings"),
    ("logEvents", "Mode changes and events"),
    ("logCalls", "Every fmi2 call"),
];

/// The log categories every FMU of ours offers (`<LogCategories>` of the XML).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogCategory {
    /// `logStatusError`: errors, always logged.
    Error,
    /// `logStatusWarning`: warnings (the call then returns `fmi2Warning`).
    Warning,
    /// `logEvents`: mode changes and events.
    Events,
    /// `logCalls`: every fmi2 call.
    Calls,
}

impl LogCategory {
    pub const ALL: [LogCategory; 4] =
        [LogCategory::Error, LogCategory::Warning, LogCategory::Events, LogCategory::Calls];

    /// The category's name in the XML and in `fmi2SetDebugLogging`.
    pub fn name(self) -> &'static str {
        LOG_CATEGORIES[self as usize].0
    }
}

/// Where the messages go: the callback of the generation the instance was created by.
enum Sink {
    None,
    Fmi2(Fmi2CallbackFunctions),
    Fmi3 { environment: fmi3InstanceEnvironment, log_message: Fmi3LogMessageCallback },
}

struct Shared {
    callbacks: Sink,
    name: CString,
    logging_on: AtomicBool,
    enabled: [AtomicBool; 4],
    /// A warning was logged since the layer last asked (the call returns `fmi2Warning`).
    warned: AtomicBool,
}

// SAFETY: the importer's callbacks and environment pointer are only passed back to the
// importer; FMI 2.0 lets an instance be used from any one thread at a time.
unsafe impl Send for Shared {}
unsafe impl Sync for Shared {}

/// The instance's logger. Cheap to clone (shared).
#[derive(Clone)]
pub struct Logger {
    shared: Arc<Shared>,
}

impl std::fmt::Debug for Logger {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Logger({:?})", self.shared.name)
    }
}

fn c_text(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).unwrap_or_default()
}

impl Logger {
    /// A logger calling the importer's callback for instance `name`.
    pub(crate) fn new(callbacks: Fmi2CallbackFunctions, name: &CStr, logging_on: bool) -> Logger {
        Logger {
            shared: Arc::new(Shared {
                callbacks: Sink::Fmi2(callbacks),
                name: name.to_owned(),
                logging_on: AtomicBool::new(logging_on),
                enabled: [(); 4].map(|_| AtomicBool::new(true)),
                warned: AtomicBool::new(false),
            }),
        }
    }

    /// A logger calling an FMI 3.0 importer's `logMessage` (none: messages are dropped).
    pub(crate) fn new3(
        environment: fmi3InstanceEnvironment,
        log_message: Option<Fmi3LogMessageCallback>,
        name: &CStr,
        logging_on: bool,
    ) -> Logger {
        Logger {
            shared: Arc::new(Shared {
                callbacks: match log_message {
                    Some(log_message) => Sink::Fmi3 { environment, log_message },
                    None => Sink::None,
                },
                name: name.to_owned(),
                logging_on: AtomicBool::new(logging_on),
                enabled: [(); 4].map(|_| AtomicBool::new(true)),
                warned: AtomicBool::new(false),
            }),
        }
    }

    /// A logger that drops everything (for using a model outside an FMU, e.g. in tests);
    /// warnings are still counted.
    pub fn silent() -> Logger {
        Logger {
            shared: Arc::new(Shared {
                callbacks: Sink::None,
                name: CString::default(),
                logging_on: AtomicBool::new(false),
                enabled: [(); 4].map(|_| AtomicBool::new(false)),
                warned: AtomicBool::new(false),
            }),
        }
    }

    /// Whether messages of `category` reach the importer (errors always do).
    #[inline]
    pub fn enabled(&self, category: LogCategory) -> bool {
        category == LogCategory::Error
            || (self.shared.logging_on.load(Ordering::Relaxed)
                && self.shared.enabled[category as usize].load(Ordering::Relaxed))
    }

    pub(crate) fn configure(&self, logging_on: bool, enabled: [bool; 4]) {
        self.shared.logging_on.store(logging_on, Ordering::Relaxed);
        for (slot, on) in self.shared.enabled.iter().zip(enabled) {
            slot.store(on, Ordering::Relaxed);
        }
    }

    /// Logs `message` under `category` with status `fmi2OK` (Events, Calls) or the
    /// category's status (Warning, Error).
    pub fn log(&self, category: LogCategory, message: &str) {
        let status = match category {
            LogCategory::Error => Fmi2Status::Error,
            LogCategory::Warning => Fmi2Status::Warning,
            _ => Fmi2Status::Ok,
        };
        self.emit(status, category, message);
    }

    /// A warning: logged under `logStatusWarning`, and the current fmi2 call returns
    /// `fmi2Warning` (unless it fails).
    pub fn warning(&self, message: &str) {
        self.shared.warned.store(true, Ordering::Relaxed);
        self.emit(Fmi2Status::Warning, LogCategory::Warning, message);
    }

    /// An event message (`logEvents`).
    pub fn event(&self, message: &str) {
        self.emit(Fmi2Status::Ok, LogCategory::Events, message);
    }

    /// Inline: the check runs at every fmi2 call (the `logCalls` message), the call to the
    /// importer only when the category is on.
    #[inline]
    pub(crate) fn emit(&self, status: Fmi2Status, category: LogCategory, message: &str) {
        // Errors and discards always reach the importer: they explain a status.
        if !self.enabled(category) && status < Fmi2Status::Discard {
            return;
        }
        self.emit_now(status, category, message);
    }

    #[inline(never)]
    fn emit_now(&self, status: Fmi2Status, category: LogCategory, message: &str) {
        let callbacks = match &self.shared.callbacks {
            Sink::None => return,
            Sink::Fmi3 { environment, log_message } => {
                let category = c_text(category.name());
                let message = c_text(message);
                // SAFETY: the importer's fmi3LogMessageCallback, called as its C prototype says.
                unsafe { log_message(*environment, status as c_int, category.as_ptr(), message.as_ptr()) };
                return;
            }
            Sink::Fmi2(callbacks) => callbacks,
        };
        if let Some(logger) = callbacks.logger {
            let category = c_text(category.name());
            let message = c_text(message);
            // SAFETY: the importer's logger, called as its C prototype says, with "%s".
            unsafe {
                logger(
                    callbacks.component_environment,
                    self.shared.name.as_ptr(),
                    status as c_int,
                    category.as_ptr(),
                    c"%s".as_ptr(),
                    message.as_ptr(),
                )
            };
        }
    }

    /// Whether a warning was logged since the last call; clears the flag.
    pub(crate) fn take_warned(&self) -> bool {
        // a plain load first: the flag is almost always clear, and a swap is a locked
        // read-modify-write at every fmi2 call
        self.shared.warned.load(Ordering::Relaxed) && self.shared.warned.swap(false, Ordering::Relaxed)
    }
}

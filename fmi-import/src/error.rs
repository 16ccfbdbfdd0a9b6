//! The importing layer's error type: unpacking, loading, instantiating and calling an FMU,
//! and the host processes of isolated instances. Every failure names its cause.

use std::fmt;
use std::path::PathBuf;

pub use crate::status::Status;

/// Everything that can go wrong in importing an FMU and calling it.
#[derive(Debug)]
pub enum Error {
    /// A file could not be read or written.
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A path to read is not a regular file (a folder, FIFO, socket or device).
    NotRegularFile {
        /// The path.
        path: PathBuf,
        /// What it is instead.
        kind: String,
    },
    /// The archive is not a readable zip file.
    Archive {
        /// The archive.
        path: PathBuf,
        /// What the zip reader said.
        reason: String,
    },
    /// An archive entry would be written outside the unpack folder, or is a link.
    UnsafeEntry {
        /// The entry's name as stored in the archive.
        entry: String,
        /// Why it is refused.
        reason: &'static str,
    },
    /// An archive entry (declared or actual size) or the whole archive exceeds a limit.
    ArchiveLimit {
        /// The entry (or `"<total>"`, `"<entries>"`).
        entry: String,
        /// Declared or counted size (bytes or entries).
        size: u64,
        /// The limit.
        limit: u64,
        /// Which limit: the field of [`crate::UnpackLimits`] that raises it, or "the size
        /// its header declares" for an entry that inflates to more than that.
        limit_name: &'static str,
    },
    /// `modelDescription.xml` is missing or malformed.
    ModelDescription {
        /// The FMU.
        path: PathBuf,
        /// The reader's message, with line and column.
        reason: String,
    },
    /// The FMU does not implement the requested interface.
    NoInterface {
        /// The FMU.
        path: PathBuf,
        /// "CoSimulation", "ModelExchange" or "ScheduledExecution".
        interface: &'static str,
    },
    /// The FMU uses a feature the master does not run (FMI 3.0 clocks, Scheduled
    /// Execution, FMI 3.0 under isolation).
    Unsupported {
        /// The FMU.
        path: PathBuf,
        /// The feature, in words.
        feature: String,
    },
    /// The Event Mode asked for ([`crate::EventModeChoice`]) is not the FMU's to give: `on`
    /// without `hasEventMode`, `off` with clocks.
    EventMode {
        /// The FMU.
        path: PathBuf,
        /// Why, in words (naming the clocks for `off`).
        reason: String,
    },
    /// `binaries/linux64/<modelIdentifier>.so` is not in the FMU.
    MissingBinary {
        /// The path expected inside the FMU.
        expected: String,
        /// The platform folders the FMU does have under `binaries/`.
        platforms: Vec<String>,
    },
    /// The shared library could not be loaded.
    LoadLibrary {
        /// The library.
        path: PathBuf,
        /// The loader's message.
        reason: String,
    },
    /// The shared library lacks a function the chosen interface needs.
    MissingSymbol {
        /// The library.
        path: PathBuf,
        /// The function, e.g. `fmi2DoStep`.
        symbol: &'static str,
    },
    /// `fmi2Instantiate` (or `fmi3Instantiate*`) returned NULL.
    Instantiate {
        /// The instance name.
        instance: String,
        /// The function, e.g. `fmi3InstantiateCoSimulation`.
        function: &'static str,
        /// The last messages the FMU logged.
        log: String,
    },
    /// An fmi2 function returned Discard, Error, Fatal, Pending or an invalid status.
    Fmi {
        /// The instance name.
        instance: String,
        /// The function, e.g. `fmi2DoStep`.
        function: &'static str,
        /// What it returned.
        status: Status,
        /// The simulation time of the call, when it is one.
        time: Option<f64>,
        /// The last messages the FMU logged.
        log: String,
    },
    /// A call returned OK (or Warning) but what it returned breaks the standard or a bound
    /// of the master (`what` says which): the FMU did not report an error.
    Returned {
        /// The instance name.
        instance: String,
        /// The function, e.g. `fmi3DoStep`.
        function: &'static str,
        /// The status it returned.
        status_returned: Status,
        /// The simulation time of the call, s.
        time: f64,
        /// What it returned and why the master cannot take it.
        what: String,
    },
    /// An FMU returned a NaN or infinite Real with fmi2OK (refused where it came from,
    /// before it reaches another FMU or the results).
    NonFinite {
        /// The instance.
        instance: String,
        /// The function that returned it, e.g. `fmi2GetReal`, `fmi3GetFloat64`.
        function: &'static str,
        /// The FMU file.
        fmu: PathBuf,
        /// The variable.
        variable: String,
        /// The value (NaN, inf or -inf).
        value: f64,
        /// The simulation time of the value, s.
        time: f64,
    },
    /// A call made in a state where the standard forbids it (a bug of the caller).
    IllegalCall {
        /// The instance name.
        instance: String,
        /// The function.
        function: &'static str,
        /// The instance's state.
        state: &'static str,
    },
    /// An instance name is unknown, repeated or malformed.
    Instance {
        /// The name.
        name: String,
        /// What is wrong.
        reason: &'static str,
    },
    /// A value cannot be given to a variable (wrong type, unparsable, wrong causality).
    InvalidValue {
        /// `instance.variable`.
        variable: String,
        /// The value as given.
        value: String,
        /// Why.
        reason: String,
    },
    /// The host process of an isolated instance ended or was killed while the master
    /// waited for a call: the FMU crashed (a signal), exited, or overran a time limit.
    Host {
        /// The instance.
        instance: String,
        /// The fmi2 function the host was running.
        function: &'static str,
        /// The simulation time of the call (or of the instance's last timed call), s.
        time: f64,
        /// How the host ended.
        cause: HostEnd,
    },
    /// A call wrote past memory it was given or had allocated, and the master's guard
    /// caught the write (a red zone after the block, nothing else written): the call's
    /// results are not to be used.
    Overrun {
        /// The instance.
        instance: String,
        /// The function called.
        function: &'static str,
        /// Where it wrote, e.g. "8 bytes past the 8 bytes of dvUnknown".
        what: String,
    },
    /// A call of an isolated instance carries more data than the region shared with its
    /// host process holds: a limit of the master's isolation, not a failure of the FMU.
    IsolationLimit {
        /// The instance.
        instance: String,
        /// The function called.
        function: &'static str,
        /// The bytes the call needs in the region.
        needed: usize,
        /// The bytes the region holds for one call.
        available: usize,
    },
}

/// How the host process of an isolated instance ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum HostEnd {
    /// Killed by a signal (its number), e.g. 11 SIGSEGV, 6 SIGABRT.
    Signal(i32),
    /// Exited by itself with this code (the FMU called `exit`).
    Exit(i32),
    /// Killed by the master: the call took longer than this (`--timeout-call`).
    CallTimeout(std::time::Duration),
    /// Killed by the master: the run's time limit (`--timeout`) passed during the call.
    RunTimeout(std::time::Duration),
    /// The host could not be started or broke the protocol.
    Failed(String),
}

/// The name of signal `n` (as `kill -l` prints it).
pub fn signal_name(n: i32) -> &'static str {
    match n {
        1 => "SIGHUP",
        2 => "SIGINT",
        3 => "SIGQUIT",
        4 => "SIGILL",
        5 => "SIGTRAP",
        6 => "SIGABRT",
        7 => "SIGBUS",
        8 => "SIGFPE",
        9 => "SIGKILL",
        11 => "SIGSEGV",
        13 => "SIGPIPE",
        15 => "SIGTERM",
        24 => "SIGXCPU",
        25 => "SIGXFSZ",
        31 => "SIGSYS",
        _ => "signal",
    }
}

impl fmt::Display for HostEnd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            HostEnd::Signal(n) => write!(f, "was killed by signal {n} ({})", signal_name(*n)),
            HostEnd::Exit(c) => write!(f, "exited with code {c}"),
            HostEnd::CallTimeout(d) => {
                write!(f, "was killed: the call took longer than {} s (--timeout-call)", d.as_secs_f64())
            }
            HostEnd::RunTimeout(d) => {
                write!(f, "was killed: the run's time limit of {} s passed (--timeout)", d.as_secs_f64())
            }
            HostEnd::Failed(m) => write!(f, "failed: {m}"),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Error::NotRegularFile { path, kind } => {
                write!(f, "{}: is {kind}, not a regular file (only files are read)", path.display())
            }
            Error::Archive { path, reason } => write!(f, "{}: not a readable zip archive: {reason}", path.display()),
            Error::UnsafeEntry { entry, reason } => write!(f, "archive entry {entry:?} refused: {reason}"),
            Error::ArchiveLimit { entry, size, limit, limit_name } => match *limit_name {
                "max_entries" => write!(
                    f,
                    "the archive has {size} entries, more than the limit of {limit} (raise it with --max-entries)"
                ),
                "max_entry_bytes" => write!(
                    f,
                    "archive entry {entry:?} is {size} bytes uncompressed, more than the limit of {limit} \
                     (raise it with --max-entry-bytes)"
                ),
                "max_total_bytes" => write!(
                    f,
                    "the archive's entries are {size} bytes uncompressed in all, more than the limit of {limit} \
                     (raise it with --max-total-bytes)"
                ),
                "max_ratio" => write!(
                    f,
                    "archive entry {entry:?} inflates {size} times its compressed size, more than the limit of \
                     {limit} (a zip bomb? raise it with --max-ratio)"
                ),
                "max_xml_bytes" => write!(
                    f,
                    "{entry} is {size} bytes, more than the limit of {limit} for XML files (raise it with \
                     --max-xml-bytes)"
                ),
                _ => write!(
                    f,
                    "archive entry {entry:?} inflates to more than the {limit} bytes its header declares: \
                     refused at {size} bytes (a corrupt or hostile archive)"
                ),
            },
            Error::ModelDescription { path, reason } => {
                write!(f, "{}: modelDescription.xml: {reason}", path.display())
            }
            Error::NoInterface { path, interface } => {
                write!(f, "{}: the FMU has no {interface} interface", path.display())
            }
            Error::Unsupported { path, feature } => {
                write!(f, "{}: uses {feature}, which cosim does not support", path.display())
            }
            Error::EventMode { path, reason } => write!(f, "{}: {reason}", path.display()),
            Error::MissingBinary { expected, platforms } => write!(
                f,
                "the FMU has no {expected}; platforms it has: {}",
                if platforms.is_empty() { "none".to_string() } else { platforms.join(", ") }
            ),
            Error::LoadLibrary { path, reason } => write!(f, "{}: cannot load: {reason}", path.display()),
            Error::MissingSymbol { path, symbol } => write!(f, "{}: missing function {symbol}", path.display()),
            Error::Instantiate { instance, function, log } => {
                write!(f, "{instance}: {function} returned NULL{}", tail(log))
            }
            Error::Fmi { instance, function, status, time, log } => {
                write!(f, "{instance}: {function} returned {}", status.spelled_for(function))?;
                if let Some(t) = time {
                    write!(f, " at t = {t}")?;
                }
                f.write_str(&tail(log))
            }
            Error::Returned { instance, function, status_returned, time, what } => write!(
                f,
                "{instance}: {function} returned {} at t = {time} s, but {what}",
                status_returned.spelled_for(function)
            ),
            Error::NonFinite { instance, function, fmu, variable, value, time } => write!(
                f,
                "{instance} ({}): {variable} = {value} at t = {time} s, returned with {} by {function} \
                 (a non-finite value; --allow-non-finite passes such values on)",
                fmu.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(),
                Status::Ok.spelled_for(function)
            ),
            Error::IllegalCall { instance, function, state } => {
                write!(f, "{instance}: {function} is not allowed in state {state}")
            }
            Error::Instance { name, reason } => write!(f, "instance {name:?}: {reason}"),
            Error::InvalidValue { variable, value, reason } => write!(f, "{variable} = {value:?}: {reason}"),
            Error::Host { instance, function, time, cause } => {
                write!(f, "{instance}: the FMU's host process {cause} during {function} at t = {time} s")
            }
            Error::Overrun { instance, function, what } => write!(
                f,
                "{instance}: {function} wrote {what} (caught in the red zone the master keeps after it: nothing \
                 else was overwritten; the call's results are not used)"
            ),
            Error::IsolationLimit { instance, function, needed, available } => write!(
                f,
                "{instance}: {function} was not called: its data take {needed} bytes, more than the {available} bytes the master's region shared with the FMU's host process holds for one call (a limit of cosim's isolation, not of the FMU; run without --isolate)"
            ),
        }
    }
}

fn tail(log: &str) -> String {
    if log.is_empty() {
        String::new()
    } else {
        format!(" ({log})")
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

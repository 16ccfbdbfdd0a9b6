//! The one error type of the master: every failure names its cause.

use std::fmt;
use std::path::PathBuf;

/// FMI 2.0 status codes (`fmi2Status`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// `fmi2OK`.
    Ok,
    /// `fmi2Warning`.
    Warning,
    /// `fmi2Discard`.
    Discard,
    /// `fmi2Error`.
    Error,
    /// `fmi2Fatal`.
    Fatal,
    /// `fmi2Pending` (asynchronous doStep: refused by this master).
    Pending,
    /// Any other integer: a broken FMU.
    Invalid(i32),
}

impl Status {
    /// From the C integer.
    pub fn from_raw(raw: i32) -> Status {
        match raw {
            0 => Status::Ok,
            1 => Status::Warning,
            2 => Status::Discard,
            3 => Status::Error,
            4 => Status::Fatal,
            5 => Status::Pending,
            other => Status::Invalid(other),
        }
    }

    /// The C integer.
    pub fn to_raw(self) -> i32 {
        match self {
            Status::Ok => 0,
            Status::Warning => 1,
            Status::Discard => 2,
            Status::Error => 3,
            Status::Fatal => 4,
            Status::Pending => 5,
            Status::Invalid(v) => v,
        }
    }
}

impl Status {
    /// The status as the generation of `function` spells it: `fmi3Error` after an `fmi3*`
    /// call, `fmi2Error` otherwise (the two enumerations have the same values).
    pub fn spelled_for(self, function: &str) -> String {
        let name = self.to_string();
        match name.strip_prefix("fmi2") {
            Some(rest) if function.starts_with("fmi3") => format!("fmi3{rest}"),
            _ => name,
        }
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Status::Ok => f.write_str("fmi2OK"),
            Status::Warning => f.write_str("fmi2Warning"),
            Status::Discard => f.write_str("fmi2Discard"),
            Status::Error => f.write_str("fmi2Error"),
            Status::Fatal => f.write_str("fmi2Fatal"),
            Status::Pending => f.write_str("fmi2Pending"),
            Status::Invalid(v) => write!(f, "invalid status {v}"),
        }
    }
}

/// Everything that can go wrong in import, system building and simulation.
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
        /// "CoSimulation" or "ModelExchange".
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
    /// An FMU returned a NaN or infinite Real with fmi2OK (refused where it came from,
    /// before it reaches another FMU or the results).
    NonFinite {
        /// The instance.
        instance: String,
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
    /// A variable is unknown in an instance.
    UnknownVariable {
        /// The instance.
        instance: String,
        /// The variable.
        variable: String,
        /// The closest names the instance has (at most 3).
        closest: Vec<String>,
    },
    /// A variable of an FMI 3.0 FMU that the master's view leaves out (see
    /// [`crate::fmi3::LeftOut`]): it cannot be recorded, set nor connected.
    NotInView {
        /// The instance.
        instance: String,
        /// The variable.
        variable: String,
        /// Why it is left out.
        reason: crate::fmi3::LeftOut,
    },
    /// An instance name is unknown in the system.
    UnknownInstance {
        /// The name as given.
        name: String,
        /// The instances of the system.
        instances: Vec<String>,
    },
    /// A variable name without the instance it belongs to, in a system of several.
    NoInstance {
        /// The name as given.
        name: String,
        /// The instances of the system.
        instances: Vec<String>,
        /// `instance.variable` names that end in the name given.
        candidates: Vec<String>,
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
    /// A connection is illegal (type, causality, unit, duplicate).
    Connection {
        /// `instance.variable` of the source.
        from: String,
        /// `instance.variable` of the destination.
        to: String,
        /// Why.
        reason: String,
    },
    /// Direct-feedthrough dependencies form a cycle (for the `ordered` algorithm).
    AlgebraicLoop {
        /// The variables on the loop, `instance.variable`, in order.
        variables: Vec<String>,
    },
    /// The event iteration of coupled Model Exchange instances found no fixed point: after
    /// `rounds` rounds of `fmi2NewDiscreteStates` and propagation, `instances` still asked
    /// for another iteration or had their inputs changed.
    EventIteration {
        /// The event time, s.
        time: f64,
        /// Rounds done.
        rounds: usize,
        /// The instances still not settled.
        instances: Vec<String>,
    },
    /// An FMU ended the simulation itself, as FMI 2 lets it: in Co-Simulation
    /// `fmi2DoStep` returned fmi2Discard with `fmi2GetBooleanStatus(fmi2Terminated)` true,
    /// in Model Exchange `terminateSimulation` was set. `nigel_cosim::simulate()` ends the run
    /// there and returns its results (with `nigel_cosim::Summary::ended_by`); the step
    /// functions return this variant to it.
    Terminated {
        /// The instance that ended the run.
        instance: String,
        /// The time the run ends at, s (CS: `fmi2LastSuccessfulTime`; ME: the event).
        time: f64,
        /// How the FMU said so.
        reason: &'static str,
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
    /// The whole run took longer than its time limit (`--timeout`); checked between steps.
    Timeout {
        /// The limit.
        limit: std::time::Duration,
        /// The simulation time reached, s.
        time: f64,
    },
    /// The caller asked the run to stop ([`Experiment::cancel`](crate::Experiment::cancel));
    /// checked between steps.
    Cancelled {
        /// The simulation time reached, s.
        time: f64,
    },
    /// The experiment is not simulable as given (times, step, output interval).
    Experiment(String),
    /// The Model Exchange integration cannot go on with what an FMU returned with OK (a NaN
    /// state derivative, a NaN next event time, infinite derivatives): the message names
    /// the instance, its FMU, the call and the time.
    Integration(String),
    /// An SSP file is malformed or uses a part this master does not support.
    Ssp {
        /// The file.
        path: PathBuf,
        /// What is wrong or unsupported, named.
        reason: String,
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
            Error::NonFinite { instance, fmu, variable, value, time } => write!(
                f,
                "{instance} ({}): {variable} = {value} at t = {time} s, returned with fmi2OK by fmi2GetReal \
                 (a non-finite value; --allow-non-finite passes such values on)",
                fmu.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
            ),
            Error::IllegalCall { instance, function, state } => {
                write!(f, "{instance}: {function} is not allowed in state {state}")
            }
            Error::Instance { name, reason } => write!(f, "instance {name:?}: {reason}"),
            Error::UnknownVariable { instance, variable, closest } => {
                write!(f, "instance {instance:?} has no variable {variable:?}")?;
                if !closest.is_empty() {
                    let q: Vec<String> = closest.iter().map(|c| format!("{c:?}")).collect();
                    write!(f, "; did you mean {}?", q.join(" or "))?;
                }
                f.write_str(" (`cosim info` lists the variables)")
            }
            Error::NotInView { instance, variable, reason } => write!(
                f,
                "variable {variable:?} of instance {instance:?} is {}, which cosim does not record, set nor connect \
                 (FMI 3.0 String and Binary arrays are outside the master's view; `cosim info` lists what is left out)",
                reason.as_str()
            ),
            Error::UnknownInstance { name, instances } => {
                write!(f, "the system has no instance {name:?}")?;
                let close = crate::suggest::closest(name, instances.iter().map(String::as_str));
                if let Some(c) = close.first() {
                    write!(f, "; did you mean {c:?}?")?;
                }
                write!(f, " (its instances: {})", instances.join(", "))
            }
            Error::NoInstance { name, instances, candidates } => {
                write!(f, "{name:?} names no instance: in a system, variables are named instance.variable")?;
                match candidates.as_slice() {
                    [] => write!(f, " (its instances: {})", instances.join(", ")),
                    [one] => write!(f, "; did you mean {one:?}?"),
                    many => write!(f, "; {name:?} is in {}", many.join(", ")),
                }
            }
            Error::InvalidValue { variable, value, reason } => write!(f, "{variable} = {value:?}: {reason}"),
            Error::Connection { from, to, reason } => write!(f, "connection {from} -> {to}: {reason}"),
            Error::AlgebraicLoop { variables } => {
                write!(f, "algebraic loop (direct feedthrough cycle): {}", variables.join(" -> "))
            }
            Error::EventIteration { time, rounds, instances } => write!(
                f,
                "the event iteration at t = {time} s did not converge in {rounds} rounds: {} still changing",
                instances.join(", ")
            ),
            Error::Terminated { instance, time, reason } => {
                write!(f, "{instance} ended the simulation at t = {time} s ({reason})")
            }
            Error::Host { instance, function, time, cause } => {
                write!(f, "{instance}: the FMU's host process {cause} during {function} at t = {time} s")
            }
            Error::Timeout { limit, time } => {
                write!(f, "the run exceeded its time limit of {} s (--timeout) at t = {time} s", limit.as_secs_f64())
            }
            Error::Cancelled { time } => write!(f, "the run was cancelled at t = {time} s"),
            Error::Experiment(m) => write!(f, "experiment: {m}"),
            Error::Integration(m) => f.write_str(m),
            Error::Ssp { path, reason } => write!(f, "{}: {reason}", path.display()),
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

#[cfg(test)]
mod status_spelling {
    use super::Status;

    #[test]
    fn a_status_is_spelled_in_the_generation_of_the_call_that_returned_it() {
        assert_eq!(Status::Error.spelled_for("fmi3DoStep"), "fmi3Error");
        assert_eq!(Status::Discard.spelled_for("fmi3SetFloat64"), "fmi3Discard");
        assert_eq!(Status::Error.spelled_for("fmi2DoStep"), "fmi2Error");
        assert_eq!(Status::Invalid(7).spelled_for("fmi3DoStep"), "invalid status 7");
    }
}

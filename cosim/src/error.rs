//! The master's error type: a failure of the importing layer ([`ImportError`]: archives,
//! libraries, FMI calls, host processes) or one of the master's own (systems, connections,
//! algorithms, SSP files, the run's limits). Every failure names its cause.

use std::fmt;
use std::path::PathBuf;

pub use fmi_import::error::{signal_name, HostEnd};
pub use fmi_import::Error as ImportError;
pub use fmi_import::Status;

/// Everything that can go wrong in import, system building and simulation.
#[derive(Debug)]
pub enum Error {
    /// Importing, instantiating or calling an FMU failed (see [`ImportError`]).
    Import(ImportError),
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
    /// [`fmi_import::fmi3::LeftOut`]): it cannot be recorded, set nor connected.
    NotInView {
        /// The instance.
        instance: String,
        /// The variable.
        variable: String,
        /// Why it is left out.
        reason: fmi_import::fmi3::LeftOut,
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

impl From<ImportError> for Error {
    fn from(e: ImportError) -> Error {
        Error::Import(e)
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Import(e) => e.fmt(f),
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

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Import(e) => e.source(),
            _ => None,
        }
    }
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

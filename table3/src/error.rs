//! Everything that can go wrong, with the file or run it concerns.

use std::fmt;
use std::path::PathBuf;

/// An error of the table3 library or CLI.
#[derive(Debug)]
pub enum Error {
    /// A `.fmu` file that does not exist.
    MissingFmu {
        /// The path looked at.
        path: PathBuf,
    },
    /// The master refused or failed something (import, system, simulation).
    Cosim {
        /// What was being done (`loading nigel_plant.fmu`, `sim/skidpad/robust`).
        context: String,
        /// The master's error.
        source: nigel_cosim::Error,
    },
    /// The in-process benchmark refused a setting.
    Setting(nigel_benchmark::SettingError),
    /// A maneuver name that is none of `straight, lane_change, skidpad, fishhook, slalom, figure_8`.
    UnknownManeuver(String),
    /// A run whose recorded results are not what the table needs (wrong length, missing column).
    BadRun {
        /// `sim/skidpad/robust`.
        run: String,
        /// What is wrong.
        reason: String,
    },
    /// Reading or writing a file.
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// Drawing a figure.
    Plot {
        /// The file.
        path: PathBuf,
        /// What the plotting crate said.
        reason: String,
    },
    /// A bad option value (thread count, ...).
    Usage(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::MissingFmu { path } => write!(
                f,
                "{} not found: build the FMUs with `cargo run --release -p build-fmu` (or pass --fmu-dir)",
                path.display()
            ),
            Error::Cosim { context, source } => write!(f, "{context}: {source}"),
            Error::Setting(e) => write!(f, "benchmark setting: {e}"),
            Error::UnknownManeuver(name) => write!(
                f,
                "unknown maneuver {name:?} (expected one of straight, lane_change, skidpad, fishhook, slalom, figure_8)"
            ),
            Error::BadRun { run, reason } => write!(f, "run {run}: {reason}"),
            Error::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Error::Plot { path, reason } => write!(f, "drawing {}: {reason}", path.display()),
            Error::Usage(s) => f.write_str(s),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Cosim { source, .. } => Some(source),
            Error::Setting(e) => Some(e),
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl From<nigel_benchmark::SettingError> for Error {
    fn from(e: nigel_benchmark::SettingError) -> Self {
        Error::Setting(e)
    }
}

/// `Error::Io` for `path`.
pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Error {
    let path = path.into();
    move |source| Error::Io { path, source }
}

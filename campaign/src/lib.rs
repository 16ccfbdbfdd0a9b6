//! `nigel_campaign`: thousands of co-simulations from one TOML description.
//!
//! - [`spec`]: the description (system, experiment, grid, named cases, random draws,
//!   metrics), checked against the system's variables (type, declared min / max).
//! - [`rng`]: run `i`'s random values from `(seed, column, i)` only.
//! - [`metric`]: per-run metrics over `t_1 .. t_N`, accumulated point by point.
//! - [`run`]: the runs of a block on N workers (processes, [`worker`], or threads), each
//!   loading the system once; rows written as they finish; failed, crashed and timed-out
//!   runs are rows with their status and message; the stop time checked before the first run.
//! - [`results`]: the output folder's files; [`merge`] joins shards; [`slurm`] writes and
//!   submits the job array; [`report`] summarises (markdown, JSON, PNG); [`ci`] makes the
//!   runs a JUnit report.
//!
//! ```no_run
//! use nigel_campaign::{spec::Spec, run::{run, Options}};
//! let spec = Spec::load("campaigns/example.toml".as_ref())?;
//! let done = run(&spec, &Options::new("out".into()))?;
//! println!("{} runs, {} failed", done.ran, done.failed);
//! # Ok::<(), nigel_campaign::Error>(())
//! ```

#![warn(missing_docs)]

pub mod ci;
pub mod collector;
pub mod merge;
/// The metric language, shared with `cosim run --check`.
pub use nigel_cosim::metric;
pub mod report;
pub mod results;
pub mod rng;
pub mod run;
pub mod runner;
pub mod scalar;
pub mod slurm;
pub mod spec;
#[cfg(target_os = "linux")]
pub mod worker;
#[cfg(not(target_os = "linux"))]
#[path = "worker_unsupported.rs"]
pub mod worker;

/// What can go wrong, each a one-line message naming the culprit.
#[derive(Debug)]
pub enum Error {
    /// The description is malformed or does not fit the system.
    Spec(String),
    /// A command-line or folder problem.
    Usage(String),
    /// A shard is missing, foreign or overlaps another.
    Merge(String),
    /// Reading or writing a file.
    Io(String),
    /// Slurm refused or failed.
    Slurm(String),
    /// Drawing a figure.
    Plot(String),
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::Spec(m) | Error::Usage(m) | Error::Merge(m) | Error::Io(m) | Error::Slurm(m) | Error::Plot(m) => {
                f.write_str(m)
            }
        }
    }
}

impl std::error::Error for Error {}

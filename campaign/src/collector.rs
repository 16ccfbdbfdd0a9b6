//! What a block of runs did ([`Done`]) and where its rows go as they arrive ([`Collector`]),
//! whichever workers (threads or processes) ran them.

use std::path::PathBuf;
use std::time::Duration;

use crate::results::{Appender, Row, Target, STATUS_OK};
use crate::Error;

/// What an invocation did.
#[derive(Clone, Debug, Default)]
pub struct Done {
    /// Runs executed by this invocation.
    pub ran: u64,
    /// Of those, how many failed.
    pub failed: u64,
    /// Runs already present (with `--resume`).
    pub kept: u64,
    /// Every row of the target at the end (kept and new), sorted by run.
    pub rows: Vec<Row>,
    /// Worker processes started again after a crash or a timeout.
    pub restarts: u64,
    /// With [`crate::run::Options::allow_failures`]: the system's refusal of the stop time for run 0.
    pub stop_time_refused: Option<String>,
    /// Wall time.
    pub wall: Duration,
    /// Threads used.
    pub threads: usize,
    /// The rows file written.
    pub file: PathBuf,
    /// Its messages file.
    pub messages: PathBuf,
    /// Summed over the runs: time inside the co-simulation, and in the whole run (values,
    /// system, co-simulation, metrics); their difference is the per-run overhead.
    pub timing: (Duration, Duration),
}

/// Where the rows go as they arrive: the target's files (each row written at once, so a
/// killed campaign keeps every finished run), the progress bar, the counts.
pub(crate) struct Collector<'a> {
    pub(crate) appender: Appender,
    pub(crate) target: &'a Target,
    pub(crate) bar: indicatif::ProgressBar,
    pub(crate) done: Done,
    pub(crate) rows: Vec<Row>,
}

impl Collector<'_> {
    /// Writes one row; `timing`: its time inside the co-simulation and in all of the run.
    pub(crate) fn push(&mut self, row: Row, timing: (Duration, Duration)) -> Result<(), Error> {
        self.appender.push(&row).map_err(|e| Error::Io(format!("{}: {e}", self.target.rows.display())))?;
        self.done.ran += 1;
        self.done.timing.0 += timing.0;
        self.done.timing.1 += timing.1;
        if row.status != STATUS_OK {
            self.done.failed += 1;
            self.bar.set_message(format!("{} failed", self.done.failed));
        }
        self.bar.inc(1);
        self.rows.push(row);
        Ok(())
    }
}

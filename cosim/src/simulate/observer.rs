//! Observers of a run (libcosim's pattern): the algorithms step the instances and tell the
//! observers after every communication step; what is recorded and how long each FMU took
//! is theirs, not the loop's.
//!
//! - [`Recorder`]: the rows of the results at output points (told first, with the values).
//! - [`Observer`]: the others, public ([`crate::simulate::Execution::add_observer`]): the
//!   time limit, the cancel flag, the progress, a caller's own.
//!
//! The [`Profiler`] (the time spent in each instance's calls) is `profiler`'s; the
//! observers of a run carry it to the algorithms.

use crate::error::{Error, Result};
use crate::simulate::clock::Point;
use crate::simulate::profiler::Profiler;
use crate::simulate::types::Results;
use std::time::{Duration, Instant};

/// Told after every communication step of an [`Execution`](crate::simulate::Execution)
/// (libcosim's observer): the rows themselves go to the results or a
/// [`RowSink`](crate::simulate::RowSink); [`Execution::get`](crate::simulate::Execution::get)
/// reads any variable between steps.
pub trait Observer {
    /// Step `point.n` ended at `point.t_next`. An error ends the run.
    fn step_complete(&mut self, point: &Point) -> Result<()>;
}

/// Where [`Execution::with_sink`](crate::simulate::Execution::with_sink) (and `simulate_with`) hands each row: the time and the recorded values, in the order
/// of [`Experiment::record`](crate::Experiment::record), and the (column, text) of the columns an f64 does not hold
/// ([`Results::exact`](crate::Results::exact); empty when there are none).
pub type RowSink<'s> = dyn FnMut(f64, &[f64], &[(usize, String)]) + Send + 's;

/// The rows of the results: time and the recorded slots at every output point.
/// With a sink ([`crate::simulate::RowSink`]) the rows are handed to it instead of kept,
/// with the (column, text) of the exact columns ([`Results::exact`]).
pub(crate) struct Recorder<'s> {
    /// The rows, shared with the handler of an FMU's exit() ([`crate::exit_guard`]):
    /// locked only while a row is appended (about 20 ns a row).
    pub(crate) shared: std::sync::Arc<crate::exit_guard::RunRows>,
    slots: Vec<usize>,
    /// Steps completed so far.
    done: u64,
    pub(crate) sink: Option<&'s mut RowSink<'s>>,
    row: Vec<f64>,
    /// The time of the last row.
    last: Option<f64>,
    /// The recorded columns whose values an f64 does not hold (see
    /// [`Results::exact`](crate::simulate::Results::exact)), read from their instances at
    /// each row.
    exact: Vec<ExactSource>,
    /// The same per instance: (instance, its value references, their places in `exact`),
    /// read in one call each, so that an array is read once per row.
    exact_reads: Vec<(usize, Vec<u32>, Vec<usize>)>,
    /// The values of one such call.
    exact_values: Vec<crate::fmi3::Exact>,
    /// Their text at the row being recorded.
    exact_row: Vec<String>,
    /// (column, text) of that row, for the sink.
    exact_cells: Vec<(usize, String)>,
}

/// The text read by [`Recorder::read_exact`] (`row`) into the row that starts (after its
/// time) at `start` of the values; a String's value there is NaN.
#[cold]
fn push_exact(exact: &[ExactSource], row: &[String], results: &mut Results, start: usize) {
    for (k, e) in exact.iter().enumerate() {
        results.exact[k].rows.push(row.get(k).cloned().unwrap_or_default());
        if e.text {
            results.values[start + e.column] = f64::NAN;
        }
    }
}

/// Where a column of [`Recorder::exact`] comes from.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ExactSource {
    /// The column (0-based among the recorded names).
    pub(crate) column: usize,
    pub(crate) instance: usize,
    pub(crate) value_reference: u32,
    /// A String: NaN in the values.
    pub(crate) text: bool,
}

impl<'s> Recorder<'s> {
    /// A recorder of the slots `slots` under the column names `names`.
    pub(crate) fn new(names: Vec<String>, slots: Vec<usize>, exact: Vec<ExactSource>) -> Self {
        let row = Vec::with_capacity(slots.len());
        let columns =
            exact.iter().map(|e| crate::simulate::ExactColumn { column: e.column, rows: Vec::new() }).collect();
        let mut exact_reads: Vec<(usize, Vec<u32>, Vec<usize>)> = Vec::new();
        for (k, e) in exact.iter().enumerate() {
            match exact_reads.iter_mut().find(|(instance, ..)| *instance == e.instance) {
                Some((_, vrs, places)) => {
                    vrs.push(e.value_reference);
                    places.push(k);
                }
                None => exact_reads.push((e.instance, vec![e.value_reference], vec![k])),
            }
        }
        Recorder {
            shared: std::sync::Arc::new(crate::exit_guard::RunRows {
                results: std::sync::Mutex::new(Results { names, values: Vec::new(), exact: columns }),
            }),
            slots,
            done: 0,
            sink: None,
            row,
            last: None,
            exact,
            exact_reads,
            exact_values: Vec::new(),
            exact_row: Vec::new(),
            exact_cells: Vec::new(),
        }
    }

    /// Whether some recorded columns are read exactly at each row ([`Recorder::read_exact`]).
    #[inline]
    pub(crate) fn reads_exact(&self) -> bool {
        !self.exact.is_empty()
    }

    /// The text of the columns an f64 does not hold, read from the instances for the next
    /// row (`fmi3GetInt64`, `fmi3GetUInt64`, `fmi3GetBinary`, `fmi2GetString` /
    /// `fmi3GetString`).
    pub(crate) fn read_exact(&mut self, lanes: &mut [crate::simulate::lane::Lane]) -> Result<()> {
        self.exact_row.clear();
        self.exact_row.resize(self.exact.len(), String::new());
        for (instance, vrs, places) in &self.exact_reads {
            lanes[*instance].inst.get_exact_many(vrs, &mut self.exact_values)?;
            for (place, value) in places.iter().zip(&self.exact_values) {
                self.exact_row[*place] = value.to_text();
            }
        }
        Ok(())
    }

    /// Room for `rows` rows (up to 64 MiB up front: a huge run grows as it goes; nothing
    /// when the rows go to the sink).
    pub(crate) fn reserve(&mut self, rows: u64) {
        if self.sink.is_none() {
            let wanted = (rows as usize).saturating_mul(self.slots.len() + 1).min(8 << 20);
            let mut results = self.shared.results.lock().unwrap_or_else(|e| e.into_inner());
            results.values.reserve(wanted);
        }
    }

    /// The rows recorded (taken out).
    pub(crate) fn take_results(&mut self) -> Results {
        std::mem::take(&mut *self.shared.results.lock().unwrap_or_else(|e| e.into_inner()))
    }

    /// Communication steps completed.
    pub(crate) fn steps_done(&self) -> u64 {
        self.done
    }

    /// The time of the last row (kept or handed to the sink).
    pub(crate) fn last_time(&self) -> Option<f64> {
        self.last
    }

    /// The row at time `t`.
    #[inline]
    pub(crate) fn push_row(&mut self, t: f64, values: &[f64]) {
        self.last = Some(t);
        match self.sink.as_deref_mut() {
            Some(sink) => {
                self.row.clear();
                self.row.extend(self.slots.iter().map(|s| values[*s]));
                self.exact_cells.clear();
                self.exact_cells.extend(self.exact.iter().zip(&self.exact_row).map(|(e, t)| (e.column, t.clone())));
                sink(t, &self.row, &self.exact_cells);
            }
            None => {
                let mut results = self.shared.results.lock().unwrap_or_else(|e| e.into_inner());
                let start = results.values.len() + 1;
                results.values.push(t);
                results.values.extend(self.slots.iter().map(|s| values[*s]));
                if !self.exact.is_empty() {
                    push_exact(&self.exact, &self.exact_row, &mut results, start);
                }
            }
        }
    }
}

impl Recorder<'_> {
    /// Step `point.n` is complete; `values`: the value buffer of the plan, every recorded
    /// slot current at an output point.
    #[inline]
    pub(crate) fn step_complete(&mut self, point: &Point, values: &[f64]) {
        self.done = point.n + 1;
        if point.output_point {
            self.push_row(point.t_next, values);
        }
    }
}

/// Calls `report` with the fraction done (0..=1) at each output point
/// ([`Execution::on_progress`](crate::simulate::Execution::on_progress)).
pub struct Progress {
    /// Called with the fraction of the run's steps done.
    pub report: fn(f64),
    /// The run's communication steps ([`Execution::steps`](crate::simulate::Execution::steps)).
    pub steps: u64,
}

impl Observer for Progress {
    fn step_complete(&mut self, point: &Point) -> Result<()> {
        if point.output_point {
            (self.report)((point.n + 1) as f64 / self.steps as f64);
        }
        Ok(())
    }
}

/// The run's time limit, checked every [`Deadline::EVERY`] steps (a clock read is about
/// 20 ns; a step of the closed loop 2 us). A call that never returns is stopped only in a
/// host process (`isolate`), where the master waits with the same deadline.
pub(crate) struct Deadline {
    pub(crate) at: Instant,
    pub(crate) limit: Duration,
}

impl Deadline {
    const EVERY: u64 = 64;
}

impl Observer for Deadline {
    #[inline]
    fn step_complete(&mut self, point: &Point) -> Result<()> {
        if point.n.is_multiple_of(Self::EVERY) && Instant::now() > self.at {
            return Err(Error::Timeout { limit: self.limit, time: point.t_next });
        }
        Ok(())
    }
}

/// Stops the run with [`Error::Cancelled`] when its flag is set (from any thread; a Python
/// caller's Ctrl-C): one relaxed load per step.
pub struct Cancel(pub std::sync::Arc<std::sync::atomic::AtomicBool>);

impl Observer for Cancel {
    #[inline]
    fn step_complete(&mut self, point: &Point) -> Result<()> {
        if self.0.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(Error::Cancelled { time: point.t_next });
        }
        Ok(())
    }
}

/// The observers of one run: told in order after every step.
pub(crate) struct Observers<'a, 's> {
    /// The rows, told first.
    pub(crate) recorder: &'a mut Recorder<'s>,
    pub(crate) list: Vec<&'a mut dyn Observer>,
    /// The per-call profiler, when asked for.
    pub(crate) calls: Option<&'a mut Profiler>,
}

impl Observers<'_, '_> {
    /// Tells every observer that the step of `point` is complete.
    #[inline]
    pub(crate) fn step_complete(&mut self, point: &Point, values: &[f64]) -> Result<()> {
        self.recorder.step_complete(point, values);
        for o in self.list.iter_mut() {
            o.step_complete(point)?;
        }
        Ok(())
    }

    /// The profiler, if attached (reborrowed for one stretch of calls).
    #[inline]
    pub(crate) fn calls(&mut self) -> Option<&mut Profiler> {
        self.calls.as_deref_mut()
    }
}

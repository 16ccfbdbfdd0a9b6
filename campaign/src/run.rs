//! Running a block of runs on N workers, each loading the system once (one unpack of the
//! `.ssp` and its FMUs per worker; its instances reset with `fmi2Reset` between runs) and
//! taking the next run number as it finishes one; the calling thread writes each row as it
//! arrives (flushed) and draws the progress bar.
//!
//! The workers are processes ([`Workers::Processes`], what `campaign run` uses: a crash,
//! an `exit` or a hang of an FMU ends only its worker, the run is a row with the reason and
//! the worker is started again; see [`crate::worker`]) or threads of this process
//! ([`Workers::Threads`]: no crash boundary).
//!
//! Before the first run the description's stop time is put to the system itself
//! ([`Worker::check_stop_time`]): a stop time every run would fail on (past the test
//! bench's `duration`) is refused before anything runs.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use crate::collector::Collector;
use crate::results::{self, Appender, Row, Target};
use crate::spec::Spec;
use crate::Error;

/// How to run.
#[derive(Clone, Debug)]
pub struct Options {
    /// The output folder.
    pub out: PathBuf,
    /// Worker threads (default: all cores).
    pub threads: Option<usize>,
    /// Only shard `I` of `N` (contiguous blocks).
    pub shard: Option<(u64, u64)>,
    /// Run only what the target does not hold yet.
    pub resume: bool,
    /// Show a progress bar (when standard error is a terminal).
    pub progress: bool,
    /// Threads of this process or worker processes.
    pub workers: Workers,
    /// Run even when the system refuses the description's stop time for run 0 (the refusal
    /// is then in [`Done::stop_time_refused`]): for a campaign that varies what limits it.
    pub allow_failures: bool,
    /// Set to true (from any thread) to start no further run (threads only): the runs in
    /// progress finish and the rows so far are written, as for an interrupted campaign that
    /// `--resume` completes.
    pub cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// Where the runs run.
#[derive(Clone, Debug, PartialEq)]
pub enum Workers {
    /// Threads of the calling process: no crash boundary (a segfault in an FMU ends the
    /// campaign; a call that never returns holds its thread).
    Threads,
    /// Worker processes of this program (`PROGRAM worker SPEC HASH`, [`crate::worker::serve`]),
    /// each running many runs: a run that crashes, exits or passes the description's
    /// `timeout` (also inside a call) is a row with the reason, its worker started again.
    Processes(PathBuf),
}

impl Options {
    /// All runs into `out`, all cores as threads, a progress bar on a terminal.
    pub fn new(out: PathBuf) -> Options {
        Options {
            out,
            threads: None,
            shard: None,
            resume: false,
            progress: true,
            workers: Workers::Threads,
            allow_failures: false,
            cancel: None,
        }
    }
}

pub use crate::collector::Done;
pub use crate::runner::{experiment, metric_variables, Worker};

/// Parses `I/N` (`0 <= I < N`).
pub fn parse_shard(text: &str) -> Result<(u64, u64), Error> {
    let bad = || Error::Usage(format!("--shard {text}: expected I/N with 0 <= I < N (e.g. 0/4)"));
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let (i, n): (u64, u64) = (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

/// Runs the block of `options` (all runs, or a shard) into the output folder.
pub fn run(spec: &Spec, options: &Options) -> Result<Done, Error> {
    results::claim(&options.out, spec)?;
    let (range, target) = match options.shard {
        Some((i, n)) => {
            let t = Target::shard(&options.out, i, n);
            let record = t.record.clone().expect("a shard has a record");
            std::fs::create_dir_all(record.parent().expect("shards folder")).map_err(|e| Error::Io(e.to_string()))?;
            let range = spec.shard_range(i, n);
            let r = serde_json::json!({"hash": spec.hash, "shard": i, "of": n, "runs": [range.start, range.end]});
            std::fs::write(&record, r.to_string() + "\n")
                .map_err(|e| Error::Io(format!("{}: {e}", record.display())))?;
            (range, t)
        }
        None => (0..spec.runs(), Target::whole(&options.out)),
    };
    let mut have = results::read_rows(&target, spec, options.resume)?;
    if !have.is_empty() && !options.resume {
        return Err(Error::Usage(format!(
            "{} already holds {} runs of this campaign: add --resume to complete it, or choose another --out",
            target.rows.display(),
            have.len()
        )));
    }
    // the whole campaign's resume also takes what shards finished
    if options.shard.is_none() && options.resume {
        have.extend(crate::merge::shard_rows(&options.out, spec)?);
    }
    let mut present = std::collections::HashSet::new();
    have.retain(|r| range.contains(&r.run) && present.insert(r.run));
    let mut todo: Vec<u64> = range.clone().filter(|i| !present.contains(i)).collect();
    // started sample by sample across the grid points: a campaign stopped half-way holds
    // as many samples of every grid point (the rows are sorted by run at the end)
    todo.sort_by_key(|i| (i % spec.samples, i / spec.samples));
    if options.threads == Some(0) {
        return Err(Error::Usage("--threads must be at least 1".into()));
    }
    let threads = options
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .clamp(1, todo.len().max(1));
    let start = Instant::now();
    let appender = Appender::open(&target, spec)?;
    let bar = if options.progress && std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(todo.len() as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {per_sec}  ETA {eta}  {msg}")
                .expect("valid template"),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let done = Done {
        threads,
        kept: have.len() as u64,
        file: target.rows.clone(),
        messages: target.messages.clone(),
        ..Done::default()
    };
    let mut out = Collector { appender, target: &target, bar, done, rows: have };
    let refusal = |m: String| -> Result<Option<String>, Error> {
        if options.allow_failures {
            Ok(Some(m))
        } else {
            Err(Error::Spec(format!(
                "{}: {m}; checked before the first run, nothing ran (a shorter stop_time, or --allow-failures to run anyway)",
                spec.path.display()
            )))
        }
    };
    let outcome = if todo.is_empty() {
        Ok(())
    } else {
        match &options.workers {
            Workers::Threads => {
                let checker = Worker::new(spec)?;
                if let Err(m) = checker.check_stop_time() {
                    out.done.stop_time_refused = refusal(m)?;
                }
                drop(checker);
                run_threads(spec, &todo, threads, options.cancel.as_deref(), &mut out)
            }
            Workers::Processes(program) => {
                crate::worker::run_processes(spec, program, &todo, threads, &mut out, &refusal)
            }
        }
    };
    out.bar.finish_and_clear();
    outcome?;
    let Collector { appender, done, mut rows, .. } = out;
    drop(appender);
    results::write_sorted(&target, spec, &mut rows)?;
    let mut done = done;
    done.rows = rows;
    done.wall = start.elapsed();
    Ok(done)
}

/// The runs `todo` on `threads` threads of this process (none started once `cancel` is set).
fn run_threads(
    spec: &Spec,
    todo: &[u64],
    threads: usize,
    cancel: Option<&std::sync::atomic::AtomicBool>,
    out: &mut Collector,
) -> Result<(), Error> {
    let next = AtomicU64::new(0);
    let (tx, rx) = mpsc::channel::<Result<(Row, (Duration, Duration)), Error>>();
    let mut error = None;
    std::thread::scope(|scope| {
        for _ in 0..threads {
            let tx = tx.clone();
            let next = &next;
            scope.spawn(move || {
                let mut worker = match Worker::new(spec) {
                    Ok(w) => w,
                    Err(e) => {
                        let _ = tx.send(Err(e));
                        return;
                    }
                };
                loop {
                    if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                        break;
                    }
                    let k = next.fetch_add(1, Ordering::Relaxed) as usize;
                    let Some(&i) = todo.get(k) else { break };
                    let before = worker.timing;
                    let row = worker.run(i);
                    let timing = (worker.timing.0 - before.0, worker.timing.1 - before.1);
                    if tx.send(Ok((row, timing))).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        for msg in rx {
            let pushed = msg.and_then(|(row, timing)| out.push(row, timing));
            if let Err(e) = pushed {
                error.get_or_insert(e);
                next.store(u64::MAX / 2, Ordering::Relaxed);
            }
        }
    });
    error.map_or(Ok(()), Err)
}

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

use nigel_cosim::{simulate, simulate_with, Experiment, InstancePool, Results, System};

use crate::results::{
    self, Appender, Row, Target, STATUS_CHECK_FAILED, STATUS_ENDED, STATUS_FAILED, STATUS_OK, STATUS_PANICKED,
    STATUS_TIMEOUT,
};
use crate::spec::{load_system, RunValues, Spec};
use crate::Error;
use nigel_cosim::check::CheckAccumulators;
use nigel_cosim::metric::Accumulators;

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
    /// With [`Options::allow_failures`]: the system's refusal of the stop time for run 0.
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

/// The experiment of every run: the description's times and algorithm, recording only
/// the metrics' variables.
pub fn experiment(spec: &Spec, record: Vec<String>) -> Experiment {
    let mut e = Experiment::new(spec.stop_time, spec.step);
    e.algorithm = spec.algorithm;
    e.record = Some(record);
    e.timeout = spec.timeout;
    e
}

/// The variables the metrics read, then those only the checks read.
pub fn metric_variables(spec: &Spec) -> Vec<String> {
    let mut vars: Vec<String> = Vec::new();
    let read = spec.metrics.iter().map(|(_, m)| m.variables()).chain(spec.checks.iter().map(|(_, c)| c.variables()));
    for v in read.flatten() {
        if !vars.contains(&v) {
            vars.push(v);
        }
    }
    vars
}

/// A loaded system and what a run needs, reused for every run of one thread: the
/// instances go back into a pool after each run and are reset with `fmi2Reset` for the
/// next ([`nigel_cosim::simulate_with`]); the metrics take each row as it comes.
pub struct Worker<'a> {
    spec: &'a Spec,
    base: System,
    record: Vec<String>,
    experiment: Experiment,
    pool: InstancePool,
    /// Time inside the co-simulation (`simulate_with`, its reset / instantiation and
    /// initialization included) and in all of [`Worker::run`], summed over the runs.
    pub timing: (Duration, Duration),
}

impl<'a> Worker<'a> {
    /// Loads the description's system.
    pub fn new(spec: &'a Spec) -> Result<Worker<'a>, Error> {
        let base = load_system(&spec.system).map_err(Error::Spec)?;
        Ok(Worker::with_system(spec, base))
    }

    /// With the description's system already loaded.
    pub fn with_system(spec: &'a Spec, base: System) -> Worker<'a> {
        let record = metric_variables(spec);
        let experiment = experiment(spec, record.clone());
        Worker { spec, base, record, experiment, pool: InstancePool::new(), timing: Default::default() }
    }

    /// Asks the system whether it can run the description's stop time: run 0's instances
    /// are instantiated, set up with the stop time (`fmi2SetupExperiment`), given run 0's
    /// start values and initialized, then freed (FMI 2.0 lets an FMU refuse a stop time it
    /// cannot reach there; the test bench refuses one past its `duration`). An instance
    /// that refuses is asked again with the stop time left undefined: only if it then
    /// accepts is the stop time the cause, and `Err` names the instance and its message
    /// (a refusal for another reason is left to the run, whose row says it). Inputs keep
    /// their start values (no connection is propagated), so this is the instances' own
    /// verdict, not a run.
    pub fn check_stop_time(&self) -> Result<(), String> {
        use nigel_cosim::{simulate::apply_start_values, Instance};
        let Ok(system) = self.spec.system_of(&self.base, &self.spec.values(0)) else { return Ok(()) };
        let start = self.experiment.start_time;
        let init = |spec: &nigel_cosim::system::InstanceSpec, stop: Option<f64>| -> Result<(), nigel_cosim::Error> {
            let mut inst = Instance::new(&spec.fmu, &spec.name)?;
            inst.setup_experiment(None, start, stop)?;
            apply_start_values(&mut inst, spec)?;
            inst.enter_initialization_mode()?;
            inst.exit_initialization_mode()?;
            Ok(inst.terminate()?)
        };
        for spec in &system.instances {
            if let Err(e) = init(spec, Some(self.spec.stop_time)) {
                if init(spec, None).is_ok() {
                    return Err(format!(
                        "stop_time = {} s is past what the system can run: {} refuses it with run 0's values ({e})",
                        self.spec.stop_time, spec.name
                    ));
                }
            }
        }
        Ok(())
    }

    /// The system of run `values`.
    pub fn system(&self, values: &RunValues) -> Result<System, String> {
        self.spec.system_of(&self.base, values)
    }

    /// Runs one run; a failure or a panic is a row with its status and message.
    pub fn run(&mut self, i: u64) -> Row {
        let start = Instant::now();
        let values = self.spec.values(i);
        let nan_metrics = || vec![f64::NAN; self.spec.metrics.len()];
        let mut inside = Duration::ZERO;
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| -> Result<Judged, (String, bool)> {
            let system = self.spec.system_of(&self.base, &values).map_err(|e| (e, false))?;
            let mut acc = Accumulators::new(self.spec.metrics.iter().map(|(_, m)| m), &self.record);
            let checks: Vec<_> = self.spec.checks.iter().map(|(_, c)| c.clone()).collect();
            let mut judge = CheckAccumulators::new(&checks, &self.record).map_err(|e| (e, false))?;
            // the metrics: every row after the first, the communication points t_1 .. t_N;
            // the checks: every row, t_0 .. t_N (as `cosim run --check`)
            let mut first = true;
            let mut sink = |_t: f64, row: &[f64]| {
                judge.push(row);
                if first {
                    first = false;
                } else {
                    acc.push(row);
                }
            };
            // the master's time limit (checked between steps) is the run's timeout
            let (_, summary) = simulate_with(&system, &self.experiment, Some(&mut self.pool), Some(&mut sink))
                .map_err(|e| (e.to_string(), matches!(e, nigel_cosim::Error::Timeout { .. })))?;
            inside = summary.wall_time;
            // an FMU that ends the run before the stop time: the metrics cover fewer points
            let ended = summary.ended_by.map(|(instance, t, reason)| {
                format!("ended at t = {t} s by {instance} ({reason}), before the stop time")
            });
            let failed_checks: Vec<String> = self
                .spec
                .checks
                .iter()
                .zip(judge.verdicts())
                .filter(|(_, v)| !v.holds)
                .map(|((name, _), v)| format!("check {name}: {}", v.failure()))
                .collect();
            Ok((acc.values(), ended, failed_checks))
        }));
        let (status, message, metrics) = match outcome {
            Ok(Ok((m, None, failed))) if failed.is_empty() => (STATUS_OK, String::new(), m),
            // an FMU that ended the run early outranks the checks (which saw fewer points)
            Ok(Ok((m, Some(ended), _))) => (STATUS_ENDED, ended, m),
            Ok(Ok((m, None, failed))) => (STATUS_CHECK_FAILED, failed.join("; "), m),
            Ok(Err((e, true))) => (STATUS_TIMEOUT, e, nan_metrics()),
            Ok(Err((e, false))) => (STATUS_FAILED, e, nan_metrics()),
            Err(p) => {
                let what = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_else(|| "a panic".into());
                (STATUS_PANICKED, format!("panicked: {what}"), nan_metrics())
            }
        };
        let mut v = values.numbers;
        v.extend(metrics);
        self.timing.0 += inside;
        self.timing.1 += start.elapsed();
        Row { run: i, status, message, values: v }
    }

    /// Runs `i` recording every output (for `--only`), as `cosim run` would.
    pub fn run_recorded(&self, i: u64) -> Result<Results, String> {
        let system = self.system(&self.spec.values(i))?;
        let mut e = self.experiment.clone();
        e.record = None;
        simulate(&system, &e).map(|(r, _)| r).map_err(|e| e.to_string())
    }
}

/// A completed run: its metrics, how an FMU ended it early (if one did), the checks it failed.
type Judged = (Vec<f64>, Option<String>, Vec<String>);

/// Where the rows go as they arrive: the target's files (each row written at once, so a
/// killed campaign keeps every finished run), the progress bar, the counts.
pub(crate) struct Collector<'a> {
    appender: Appender,
    target: &'a Target,
    bar: indicatif::ProgressBar,
    pub(crate) done: Done,
    rows: Vec<Row>,
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

//! Running a block of runs: worker threads, each loading the system once (one unpack of
//! the `.ssp` and its FMUs per thread; a run instantiates the loaded FMUs again) and
//! taking the next run number from a shared counter; the calling thread writes each row
//! as it arrives and draws the progress bar.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use nigel_cosim::{simulate, simulate_with, Experiment, InstancePool, Results, System};

use crate::metric::Accumulators;
use crate::results::{self, Appender, Row, Target, STATUS_ENDED, STATUS_FAILED, STATUS_OK, STATUS_PANICKED};
use crate::spec::{load_system, RunValues, Spec};
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
}

impl Options {
    /// All runs into `out`, all cores, a progress bar on a terminal.
    pub fn new(out: PathBuf) -> Options {
        Options { out, threads: None, shard: None, resume: false, progress: true }
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
    /// Wall time.
    pub wall: Duration,
    /// Threads used.
    pub threads: usize,
    /// The rows file written.
    pub rows: PathBuf,
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

/// The variables the metrics read.
pub fn metric_variables(spec: &Spec) -> Vec<String> {
    let mut vars: Vec<String> = Vec::new();
    for (_, m) in &spec.metrics {
        for v in m.variables() {
            if !vars.contains(&v) {
                vars.push(v);
            }
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
        let record = metric_variables(spec);
        let experiment = experiment(spec, record.clone());
        Ok(Worker { spec, base, record, experiment, pool: InstancePool::new(), timing: Default::default() })
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
        let outcome =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| -> Result<(Vec<f64>, Option<String>), String> {
                let system = self.spec.system_of(&self.base, &values)?;
                let mut acc = Accumulators::new(self.spec.metrics.iter().map(|(_, m)| m), &self.record);
                // every row after the first: the communication points t_1 .. t_N
                let mut first = true;
                let mut sink = |_t: f64, row: &[f64]| {
                    if first {
                        first = false;
                    } else {
                        acc.push(row);
                    }
                };
                let (_, summary) = simulate_with(&system, &self.experiment, Some(&mut self.pool), Some(&mut sink))
                    .map_err(|e| e.to_string())?;
                inside = summary.wall_time;
                // an FMU that ends the run before the stop time: the metrics cover fewer points
                let ended = summary.ended_by.map(|(instance, t, reason)| {
                    format!("ended at t = {t} s by {instance} ({reason}), before the stop time")
                });
                Ok((acc.values(), ended))
            }));
        let (status, message, metrics) = match outcome {
            Ok(Ok((m, None))) => (STATUS_OK, String::new(), m),
            Ok(Ok((m, Some(ended)))) => (STATUS_ENDED, ended, m),
            Ok(Err(e)) => (STATUS_FAILED, e, nan_metrics()),
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
    let threads = options
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .clamp(1, todo.len().max(1));
    if options.threads == Some(0) {
        return Err(Error::Usage("--threads must be at least 1".into()));
    }
    let start = Instant::now();
    let mut appender = Appender::open(&target, spec)?;
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
    let next = AtomicU64::new(0);
    let (tx, rx) = mpsc::channel::<Result<Row, Error>>();
    let timing = std::sync::Mutex::new((Duration::ZERO, Duration::ZERO));
    let mut done = Done { threads, kept: have.len() as u64, rows: target.rows.clone(), ..Done::default() };
    let mut rows = have;
    let mut write_error = None;
    std::thread::scope(|scope| {
        for _ in 0..threads {
            let tx = tx.clone();
            let (todo, next, timing) = (&todo, &next, &timing);
            scope.spawn(move || {
                let mut worker = match Worker::new(spec) {
                    Ok(w) => w,
                    Err(e) => {
                        let _ = tx.send(Err(e));
                        return;
                    }
                };
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed) as usize;
                    let Some(&i) = todo.get(k) else { break };
                    if tx.send(Ok(worker.run(i))).is_err() {
                        break;
                    }
                }
                let mut t = timing.lock().unwrap_or_else(|p| p.into_inner());
                t.0 += worker.timing.0;
                t.1 += worker.timing.1;
            });
        }
        drop(tx);
        for msg in rx {
            match msg {
                Ok(row) => {
                    if let Err(e) = appender.push(&row) {
                        write_error = Some(Error::Io(format!("{}: {e}", target.rows.display())));
                        next.store(u64::MAX / 2, Ordering::Relaxed);
                        break;
                    }
                    done.ran += 1;
                    if row.status != STATUS_OK {
                        done.failed += 1;
                        bar.set_message(format!("{} failed", done.failed));
                    }
                    bar.inc(1);
                    rows.push(row);
                }
                Err(e) => {
                    write_error.get_or_insert(e);
                    next.store(u64::MAX / 2, Ordering::Relaxed);
                }
            }
        }
    });
    bar.finish_and_clear();
    if let Some(e) = write_error {
        return Err(e);
    }
    drop(appender);
    results::write_sorted(&target, spec, &mut rows)?;
    done.wall = start.elapsed();
    done.timing = timing.into_inner().unwrap_or_else(|p| p.into_inner());
    Ok(done)
}

//! `campaign`: run, shard, submit to Slurm, merge and report a campaign of co-simulations.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use nigel_campaign::report::Report;
use nigel_campaign::run::{parse_shard, Options, Worker, Workers};
use nigel_campaign::spec::Spec;
use nigel_campaign::{merge, slurm, Error};

#[derive(Parser)]
#[command(name = "campaign", version, about = "Campaigns of co-simulations from one TOML description")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the campaign (or a shard of it, or one run) into DIR.
    Run {
        /// The description (TOML).
        spec: PathBuf,
        /// The output folder.
        #[arg(long)]
        out: PathBuf,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Only shard I of N (0 <= I < N; contiguous blocks of runs).
        #[arg(long)]
        shard: Option<String>,
        /// Run only the runs the output does not hold yet.
        #[arg(long)]
        resume: bool,
        /// Run only run RUN, recording every output into DIR/run-RUN.csv, and print its row.
        #[arg(long)]
        only: Option<u64>,
        /// Exit 0 also when runs failed (crashed, timed out, refused), and run even when
        /// the system refuses the stop time before the first run.
        #[arg(long)]
        allow_failures: bool,
        /// Run the workers as threads of this process instead of worker processes: no
        /// crash boundary (an FMU's segfault ends the campaign), no timeout inside a call.
        #[arg(long)]
        in_process: bool,
        /// Write a JUnit XML report: a test case per run (failed checks are failures, runs
        /// that could not complete errors, each with its message).
        #[arg(long, value_name = "FILE.xml")]
        junit: Option<PathBuf>,
        /// Write a Markdown table of the runs (for a CI job summary).
        #[arg(long, value_name = "FILE.md")]
        summary_md: Option<PathBuf>,
    },
    /// A worker process of `campaign run` (started by it; speaks its protocol on standard
    /// input and output).
    #[command(hide = true)]
    Worker {
        /// The description (TOML).
        spec: PathBuf,
        /// Its hash, as the parent read it.
        hash: String,
    },
    /// Write the sbatch job-array script DIR/campaign.sbatch (and with --submit, submit it,
    /// wait for it and merge).
    Slurm {
        /// The description (TOML).
        spec: PathBuf,
        /// The output folder.
        #[arg(long)]
        out: PathBuf,
        /// Array tasks (shards).
        #[arg(long)]
        tasks: u64,
        /// Submit with sbatch, wait by polling squeue, then merge.
        #[arg(long)]
        submit: bool,
        /// Slurm partition.
        #[arg(long)]
        partition: Option<String>,
        /// CPUs (threads) per task.
        #[arg(long, default_value_t = 1)]
        cpus_per_task: u64,
        /// With --submit: exit 0 also when the merged results hold failed runs.
        #[arg(long)]
        allow_failures: bool,
    },
    /// Check that the shards in DIR hold every run exactly once and write DIR/results.csv.
    Merge {
        /// The output folder.
        dir: PathBuf,
        /// Exit 0 also when the merged results hold failed runs.
        #[arg(long)]
        allow_failures: bool,
    },
    /// Per group count, mean, median, p95 and worst of each metric (markdown on standard
    /// output, DIR/report.json); with --png, the figures.
    Report {
        /// The output folder.
        dir: PathBuf,
        /// Group by these varied columns.
        #[arg(long, num_args = 1..)]
        by: Vec<String>,
        /// Write the PNG figures into this folder.
        #[arg(long)]
        png: Option<PathBuf>,
        /// The metric of the figures and of the worst runs (default: the first).
        #[arg(long)]
        metric: Option<String>,
        /// How many worst runs to list.
        #[arg(long, default_value_t = 10)]
        worst: usize,
        /// Compare the values of this column run by run (same other grid values, same
        /// draws): P(metric of A < metric of B) per group of the other --by columns.
        #[arg(long)]
        pair: Option<String>,
    },
}

/// The description recorded in DIR/campaign.json.
fn spec_of_dir(dir: &std::path::Path) -> Result<Spec, Error> {
    let path = dir.join("campaign.json");
    let text = std::fs::read_to_string(&path)
        .map_err(|e| Error::Usage(format!("{}: {e} (not a campaign output folder)", path.display())))?;
    let v: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| Error::Usage(format!("{}: {e}", path.display())))?;
    let desc = v["description"].as_str().ok_or_else(|| Error::Usage(format!("{}: no description", path.display())))?;
    Spec::load(desc.as_ref())
}

/// One run's row for a reader: a line per column, names aligned, the status in words and the
/// message in full (the CSV holds only numbers: `status` as a code, `message` as 0 or 1).
fn describe_row(spec: &Spec, row: &nigel_campaign::results::Row) -> String {
    let header = spec.header();
    let status = nigel_campaign::results::status_name(row.status);
    let width = header.iter().map(|h| h.len()).max().unwrap_or(0).max("message".len());
    let mut out = format!("{:>width$} = {}\n{:>width$} = {} ({status})\n", "run", row.run, "status", row.status);
    if !row.message.is_empty() {
        out += &format!("{:>width$} = {}\n", "message", row.message);
    }
    // the header's first three names are run, status and message; then one per value, the
    // varied columns first (a case column's value is the case's index: its name is shown)
    for (i, (h, v)) in header.iter().skip(3).zip(&row.values).enumerate() {
        let case = spec.columns.get(i).map(|c| c.case_names()).unwrap_or_default();
        match case.get(*v as usize).filter(|_| v.fract() == 0.0 && *v >= 0.0) {
            Some(name) => out += &format!("{h:>width$} = {v} ({name})\n"),
            None => out += &format!("{h:>width$} = {v}\n"),
        }
    }
    out
}

/// Exit code of a campaign that completed with failed runs (1 is a campaign that could not
/// run, 2 a command line clap refused).
const EXIT_RUNS_FAILED: u8 = 3;

/// What a finished command leaves: success, or runs that failed (a one-line summary).
enum Outcome {
    Done,
    RunsFailed,
}

/// Prints the one-line account of the failed runs; whether they make the exit non-zero.
fn judge(rows: &[nigel_campaign::results::Row], messages: &std::path::Path, allow: bool) -> Outcome {
    match nigel_campaign::results::failure_summary(rows) {
        None => Outcome::Done,
        Some(line) => {
            let verdict =
                if allow { "accepted (--allow-failures)" } else { "exit status 3 (--allow-failures to accept)" };
            eprintln!("campaign: {line}; messages in {}; {verdict}", messages.display());
            if allow {
                Outcome::Done
            } else {
                Outcome::RunsFailed
            }
        }
    }
}

fn main_inner(cli: Cli) -> Result<Outcome, Error> {
    match cli.command {
        Command::Worker { spec, hash } => std::process::exit(nigel_campaign::worker::serve(&spec, &hash)),
        Command::Run { spec, out, threads, shard, resume, only, allow_failures, in_process, junit, summary_md } => {
            let spec = Spec::load(&spec)?;
            if let Some(i) = only {
                if i >= spec.runs() {
                    return Err(Error::Usage(format!("--only {i}: the campaign has runs 0 .. {}", spec.runs() - 1)));
                }
                std::fs::create_dir_all(&out).map_err(|e| Error::Io(format!("{}: {e}", out.display())))?;
                let mut worker = Worker::new(&spec)?;
                let row = worker.run(i);
                print!("{}", describe_row(&spec, &row));
                let path = out.join(format!("run-{i}.csv"));
                let recorded = worker.run_recorded(i).map_err(|e| Error::Usage(format!("run {i}: {e}")))?;
                let f = std::fs::File::create(&path).map_err(|e| Error::Io(format!("{}: {e}", path.display())))?;
                recorded
                    .write_csv(std::io::BufWriter::new(f))
                    .map_err(|e| Error::Io(format!("{}: {e}", path.display())))?;
                eprintln!("every output of run {i}: {}", path.display());
                return Ok(Outcome::Done);
            }
            let shard = shard.as_deref().map(parse_shard).transpose()?;
            // worker processes are Linux-only: elsewhere the runs go in threads, said once
            #[cfg(not(target_os = "linux"))]
            if !in_process {
                eprintln!("campaign: note: {}", nigel_campaign::worker::unsupported());
            }
            let in_process = in_process || !cfg!(target_os = "linux");
            let workers = if in_process {
                Workers::Threads
            } else {
                Workers::Processes(
                    std::env::current_exe().map_err(|e| Error::Io(format!("the campaign program: {e}")))?,
                )
            };
            let options =
                Options { out, threads, shard, resume, progress: true, workers, allow_failures, cancel: None };
            let done = nigel_campaign::run::run(&spec, &options)?;
            if let Some(m) = &done.stop_time_refused {
                eprintln!("campaign: warning: {m} (checked before the first run; run anyway: --allow-failures)");
            }
            let (inside, total) = (done.timing.0.as_secs_f64(), done.timing.1.as_secs_f64());
            eprintln!(
                "{} runs in {:.1} s on {} {} ({:.0} runs/min; {:.1} ms a run, of it {:.2} % outside the co-simulation), {} failed, {} already done: {}",
                done.ran,
                done.wall.as_secs_f64(),
                done.threads,
                if in_process { "threads" } else { "worker processes" },
                done.ran as f64 / done.wall.as_secs_f64().max(1e-9) * 60.0,
                1e3 * total / done.ran.max(1) as f64,
                100.0 * (total - inside) / total.max(1e-12),
                done.failed,
                done.kept,
                done.file.display()
            );
            if junit.is_some() || summary_md.is_some() {
                let suite = nigel_campaign::ci::suite(&spec, &done.rows, done.wall.as_secs_f64());
                let suites = std::slice::from_ref(&suite);
                if let Some(p) = &junit {
                    std::fs::write(p, nigel_cosim::junit::xml(&suite.name, suites))
                        .map_err(|e| Error::Io(format!("--junit {}: {e}", p.display())))?;
                }
                if let Some(p) = &summary_md {
                    std::fs::write(p, nigel_cosim::junit::markdown(&suite.name, suites))
                        .map_err(|e| Error::Io(format!("--summary-md {}: {e}", p.display())))?;
                }
            }
            Ok(judge(&done.rows, &done.messages, allow_failures))
        }
        Command::Slurm { spec, out, tasks, submit, partition, cpus_per_task, allow_failures } => {
            let spec = Spec::load(&spec)?;
            let program = std::env::current_exe().map_err(|e| Error::Io(format!("the campaign program: {e}")))?;
            let array = slurm::Array { out: out.clone(), tasks, partition, cpus_per_task, program };
            let script = slurm::write(&spec, &array)?;
            let per_task = spec.runs().div_ceil(tasks.max(1));
            if per_task < slurm::RUNS_PER_TASK_MIN {
                eprintln!(
                    "campaign: note: {per_task} runs per task; Slurm's start of a task (about 1 s measured on one node, about 15 runs of the 30 s closed loop) is more than 5 % of a task below {} runs",
                    slurm::RUNS_PER_TASK_MIN
                );
            }
            eprintln!("{} ({} runs in {tasks} tasks)", script.display(), spec.runs());
            if !submit {
                println!("sbatch {}", script.display());
                return Ok(Outcome::Done);
            }
            let job = slurm::submit(&script)?;
            eprintln!("submitted job {job}");
            let waited = slurm::wait(&job, |_| {})?;
            let states = slurm::task_states(&job).unwrap_or_default();
            let bad: Vec<String> =
                states.iter().filter(|(_, s)| s != "COMPLETED").map(|(t, s)| format!("task {t} {s}")).collect();
            eprintln!(
                "job {job} left the queue after {:.1} s{}",
                waited.as_secs_f64(),
                if bad.is_empty() { String::new() } else { format!(" ({})", bad.join(", ")) }
            );
            merged(&out, &spec, allow_failures)
        }
        Command::Merge { dir, allow_failures } => {
            let spec = spec_of_dir(&dir)?;
            merged(&dir, &spec, allow_failures)
        }
        Command::Report { dir, by, png, metric, worst, pair } => {
            let spec = spec_of_dir(&dir)?;
            let report = Report::load(spec, &dir, &by)?;
            let m = report.metric(metric.as_deref())?;
            print!("{}", report.markdown(m, worst));
            let mut json = report.json(m, worst);
            if let Some(column) = pair {
                let pairings = report.pairings(&column, &by, m)?;
                print!("{}", report.pairings_markdown(&pairings, &report.spec.metrics[m].0));
                json["pairs"] = pairings
                    .iter()
                    .map(|p| serde_json::json!({"group": p.group, "a": p.a, "b": p.b, "pairs": p.pairs, "p_less": p.p_less, "p_more": p.p_more, "median_ratio": p.median_ratio}))
                    .collect();
            }
            let path = dir.join("report.json");
            let text = serde_json::to_string_pretty(&json).expect("JSON of plain values");
            std::fs::write(&path, text + "\n").map_err(|e| Error::Io(format!("{}: {e}", path.display())))?;
            eprintln!("{}", path.display());
            if let Some(d) = png {
                for p in report.pngs(m, &d)? {
                    eprintln!("{}", p.display());
                }
            }
            Ok(Outcome::Done)
        }
    }
}

/// Merges the shards of `dir` and judges the merged rows.
fn merged(dir: &std::path::Path, spec: &Spec, allow_failures: bool) -> Result<Outcome, Error> {
    let m = merge::merge(dir, spec)?;
    eprintln!(
        "merged {} shards: {} runs, {} failed: {}",
        m.shards,
        m.runs,
        m.failed,
        dir.join("results.csv").display()
    );
    let rows = nigel_campaign::results::read_rows(&nigel_campaign::results::Target::whole(dir), spec, false)?;
    Ok(judge(&rows, &dir.join("messages.csv"), allow_failures))
}

fn main() -> ExitCode {
    // SIGINT, SIGTERM (Ctrl-C, scancel) and SIGHUP remove the unpacked FMUs from TMPDIR;
    // the rows written so far stay, and `--resume` completes the campaign
    let cli = Cli::parse();
    if matches!(cli.command, Command::Worker { .. }) {
        // a worker process removes the TMPDIR its parent made for it
        nigel_campaign::worker::remove_tmpdir_on_signals();
    } else {
        nigel_cosim::unpack::remove_on_signals();
    }
    match main_inner(cli) {
        Ok(Outcome::Done) => ExitCode::SUCCESS,
        Ok(Outcome::RunsFailed) => ExitCode::from(EXIT_RUNS_FAILED),
        Err(e) => {
            eprintln!("campaign: {e}");
            ExitCode::FAILURE
        }
    }
}

//! `campaign`: run, shard, submit to Slurm, merge and report a campaign of co-simulations.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use nigel_campaign::report::Report;
use nigel_campaign::run::{parse_shard, Options, Worker};
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
    },
    /// Check that the shards in DIR hold every run exactly once and write DIR/results.csv.
    Merge {
        /// The output folder.
        dir: PathBuf,
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
    use nigel_campaign::results::{STATUS_ENDED, STATUS_FAILED, STATUS_OK, STATUS_PANICKED};
    let status = match row.status {
        STATUS_OK => "ok",
        STATUS_FAILED => "failed",
        STATUS_PANICKED => "panicked",
        STATUS_ENDED => "ended by an FMU before the stop time",
        _ => "unknown",
    };
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

fn main_inner() -> Result<(), Error> {
    match Cli::parse().command {
        Command::Run { spec, out, threads, shard, resume, only } => {
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
                return Ok(());
            }
            let shard = shard.as_deref().map(parse_shard).transpose()?;
            let options = Options { out, threads, shard, resume, progress: true };
            let done = nigel_campaign::run::run(&spec, &options)?;
            let (inside, total) = (done.timing.0.as_secs_f64(), done.timing.1.as_secs_f64());
            eprintln!(
                "{} runs in {:.1} s on {} threads ({:.0} runs/min; {:.1} ms a run, of it {:.2} % outside the co-simulation), {} failed, {} already done: {}",
                done.ran,
                done.wall.as_secs_f64(),
                done.threads,
                done.ran as f64 / done.wall.as_secs_f64().max(1e-9) * 60.0,
                1e3 * total / done.ran.max(1) as f64,
                100.0 * (total - inside) / total.max(1e-12),
                done.failed,
                done.kept,
                done.rows.display()
            );
            Ok(())
        }
        Command::Slurm { spec, out, tasks, submit, partition, cpus_per_task } => {
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
                return Ok(());
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
            let m = merge::merge(&out, &spec)?;
            eprintln!(
                "merged {} shards: {} runs, {} failed: {}",
                m.shards,
                m.runs,
                m.failed,
                out.join("results.csv").display()
            );
            Ok(())
        }
        Command::Merge { dir } => {
            let spec = spec_of_dir(&dir)?;
            let m = merge::merge(&dir, &spec)?;
            eprintln!(
                "merged {} shards: {} runs, {} failed: {}",
                m.shards,
                m.runs,
                m.failed,
                dir.join("results.csv").display()
            );
            Ok(())
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
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    // SIGINT, SIGTERM (Ctrl-C, scancel) and SIGHUP remove the unpacked FMUs from TMPDIR;
    // the rows written so far stay, and `--resume` completes the campaign
    nigel_cosim::unpack::remove_on_signals();
    match main_inner() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("campaign: {e}");
            ExitCode::FAILURE
        }
    }
}

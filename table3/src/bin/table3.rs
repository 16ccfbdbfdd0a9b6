//! `table3`: Table III and Fig. 7 of the paper for one seed, from the three FMUs co-simulated
//! by the master (`ordered`, 1 ms, 30 s), or in process as a cross-check.
//!
//! `table3 [--seed N] [--json PATH] [--png DIR] [--csv DIR] [--threads N]`
//! `table3 --seeds 0..9 [--engine in-process]`: the seed study (the ratio
//! `eps(robust_tracking) / eps(robust)` per cell and seed, the largest steering command).

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use nigel_table3::engine::default_fmu_dir;
use nigel_table3::{
    csv, plot, report, run_table_with, Controller, Engine, Error, FmuEngine, InProcess, Maneuver, Options,
};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum EngineKind {
    /// The three .fmu archives through the nigel_cosim master (C ABI).
    Fmu,
    /// nigel_benchmark's loop in process (the cross-check).
    InProcess,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum AlgorithmArg {
    Ordered,
    Jacobi,
}

/// Table III and Fig. 7 (docs/benchmark.md) for one seed.
#[derive(Parser, Debug)]
#[command(name = "table3", version)]
struct Args {
    /// Noise seed (0 ..= 2147483647 for the FMU engine: the test bench's seed is an Integer).
    #[arg(long, default_value_t = 0, value_name = "N", allow_hyphen_values = true)]
    seed: u64,
    /// Run the whole table for every seed of A..B (both included, e.g. 0..9) and print the
    /// study: eps(robust_tracking) / eps(robust) per cell and seed, whether robust_tracking
    /// is lowest everywhere, the largest steering command. Replaces --seed.
    #[arg(long, value_name = "A..B", value_parser = parse_seeds, conflicts_with_all = ["seed", "json", "png", "csv", "bench", "ssp"])]
    seeds: Option<(u64, u64)>,
    /// Write the table as JSON.
    #[arg(long, value_name = "PATH")]
    json: Option<PathBuf>,
    /// Draw Fig. 7 and the time plots (PNG) into this folder.
    #[arg(long, value_name = "DIR")]
    png: Option<PathBuf>,
    /// Write every run as CSV into this folder.
    #[arg(long, value_name = "DIR")]
    csv: Option<PathBuf>,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0, value_name = "N")]
    threads: usize,
    /// Only these maneuvers (repeat; default all six).
    #[arg(long = "maneuver", value_name = "NAME", value_parser = parse_maneuver)]
    maneuvers: Vec<Maneuver>,
    /// Only these controllers (repeat; default all four: open_loop, pole_placement, robust,
    /// robust_tracking).
    #[arg(long = "controller", value_name = "NAME", value_parser = parse_controller)]
    controllers: Vec<Controller>,
    /// Also run one's own gain: a `synthesize --json` report (its "K", rows FL, FR, RL, RR,
    /// columns beta, r), as the controller `custom` (the controller FMU's tunable k_*).
    #[arg(long, value_name = "K.json")]
    gain: Option<PathBuf>,
    /// What runs the closed loops.
    #[arg(long, value_enum, default_value_t = EngineKind::Fmu)]
    engine: EngineKind,
    /// Folder of nigel_plant.fmu, nigel_controller.fmu and nigel_maneuver.fmu.
    #[arg(long, value_name = "DIR")]
    fmu_dir: Option<PathBuf>,
    /// Communication of the FMU engine.
    #[arg(long, value_enum, default_value_t = AlgorithmArg::Ordered)]
    algorithm: AlgorithmArg,
    /// Time the whole table this many times and print the median wall time.
    #[arg(long, value_name = "REPEATS", num_args = 0..=1, default_missing_value = "5")]
    bench: Option<usize>,
    /// Only write the closed loop of one job (--ssp-job) as an SSP archive to PATH and exit.
    #[arg(long, value_name = "PATH")]
    ssp: Option<PathBuf>,
    /// The job --ssp writes: column/maneuver/controller.
    #[arg(long, value_name = "JOB", default_value = "sim/lane_change/robust")]
    ssp_job: String,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

fn parse_seeds(s: &str) -> Result<(u64, u64), String> {
    let bad = || format!("{s:?} is not a seed range A..B (both included, e.g. 0..9)");
    let (a, b) = s.split_once("..").ok_or_else(bad)?;
    let (a, b): (u64, u64) = (a.trim().parse().map_err(|_| bad())?, b.trim().parse().map_err(|_| bad())?);
    if a > b {
        return Err(format!("{s:?}: the first seed is after the last"));
    }
    if b - a >= 1000 {
        return Err(format!("{s:?}: at most 1000 seeds"));
    }
    Ok((a, b))
}

fn parse_controller(s: &str) -> Result<Controller, String> {
    nigel_table3::CONTROLLERS.into_iter().find(|c| c.name() == s).ok_or_else(|| {
        let names: Vec<&str> = nigel_table3::CONTROLLERS.iter().map(|c| c.name()).collect();
        format!("unknown controller {s:?} (one of {})", names.join(", "))
    })
}

fn parse_maneuver(s: &str) -> Result<Maneuver, String> {
    nigel_table3::parse_maneuver(s).map_err(|e| e.to_string())
}

fn main() -> ExitCode {
    // SIGINT, SIGTERM and SIGHUP remove the unpacked FMUs from TMPDIR
    nigel_cosim::unpack::remove_on_signals();
    let args = Args::parse();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("table3: error: {e}");
            let mut source = std::error::Error::source(&e);
            while let Some(s) = source {
                eprintln!("  caused by: {s}");
                source = s.source();
            }
            ExitCode::FAILURE
        }
    }
}

fn engine(args: &Args) -> Result<Box<dyn Engine>, Error> {
    Ok(match args.engine {
        EngineKind::InProcess => Box::new(InProcess::new()),
        EngineKind::Fmu => {
            let dir = args.fmu_dir.clone().unwrap_or_else(default_fmu_dir);
            let algorithm = match args.algorithm {
                AlgorithmArg::Ordered => nigel_cosim::Algorithm::Ordered,
                AlgorithmArg::Jacobi => nigel_cosim::Algorithm::Jacobi,
            };
            Box::new(FmuEngine::load_dir(&dir)?.with_algorithm(algorithm))
        }
    })
}

fn run(args: &Args) -> Result<(), Error> {
    if let Some(path) = &args.ssp {
        let job = nigel_table3::parse_job(&args.ssp_job, args.seed)?;
        let dir = args.fmu_dir.clone().unwrap_or_else(default_fmu_dir);
        FmuEngine::load_dir(&dir)?.write_ssp(&job, path)?;
        eprintln!("wrote {} ({})", path.display(), job.label());
        return Ok(());
    }
    let engine = engine(args)?;
    let mut options = Options::new(args.seed);
    options.threads = args.threads;
    if !args.maneuvers.is_empty() {
        options.maneuvers = Maneuver::ALL.into_iter().filter(|m| args.maneuvers.contains(m)).collect();
    }
    if !args.controllers.is_empty() {
        options.controllers = nigel_table3::CONTROLLERS.into_iter().filter(|c| args.controllers.contains(c)).collect();
    }
    if let Some(path) = &args.gain {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io { path: path.clone(), source })?;
        let k = nigel_benchmark::gain_file::read_gain_json(&text, &path.display().to_string()).map_err(Error::Usage)?;
        options.controllers.push(Controller::Custom(k));
    }
    options.keep_runs = args.png.is_some() || args.csv.is_some();
    if let Some(repeats) = args.bench {
        return bench(engine.as_ref(), &options, repeats.max(1));
    }
    if let Some((first, last)) = args.seeds {
        return study(engine.as_ref(), &options, first, last, args.quiet);
    }
    let jobs = options.jobs().len() as u64;
    let bar = if args.quiet || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::with_draw_target(Some(jobs), ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:36}] {pos}/{len} runs, {elapsed_precise}") {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_message(engine.name());
        bar
    };
    let out = run_table_with(engine.as_ref(), &options, &|_| bar.inc(1))?;
    bar.finish_and_clear();
    print!("{}", report::markdown(&out.table));
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&report::json(&out.table))
            .map_err(|e| Error::Io { path: path.clone(), source: std::io::Error::other(e) })?;
        std::fs::write(path, text + "\n").map_err(|source| Error::Io { path: path.clone(), source })?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(dir) = &args.csv {
        let files = csv::write_all(&out.runs, dir)?;
        eprintln!("wrote {} CSV files into {}", files.len(), dir.display());
    }
    if let Some(dir) = &args.png {
        let t = Instant::now();
        let files = plot::write_all(&out.runs, dir)?;
        eprintln!("wrote {} PNG files into {} ({:.2} s)", files.len(), dir.display(), t.elapsed().as_secs_f64());
    }
    Ok(())
}

fn study(engine: &dyn Engine, options: &Options, first: u64, last: u64, quiet: bool) -> Result<(), Error> {
    let mut tables = Vec::new();
    let t = Instant::now();
    for seed in first..=last {
        let out = nigel_table3::run_table(engine, &Options { seed, ..options.clone() })?;
        if !quiet {
            eprintln!("seed {seed}: {} runs, {:.1} s", out.table.cells.len(), out.table.wall_s);
        }
        tables.push(out.table);
    }
    let study = nigel_table3::Study::of(&tables)
        .ok_or_else(|| Error::Usage("the study needs the robust and robust_tracking controllers".into()))?;
    println!("{} ({:.1} s)", engine.name(), t.elapsed().as_secs_f64());
    print!("{}", study.markdown());
    Ok(())
}

fn bench(engine: &dyn Engine, options: &Options, repeats: usize) -> Result<(), Error> {
    let mut walls = Vec::with_capacity(repeats);
    let mut jobs = 0;
    for _ in 0..repeats {
        let out = nigel_table3::run_table(engine, options)?;
        jobs = out.table.cells.len();
        walls.push(out.table.wall_s);
    }
    walls.sort_by(f64::total_cmp);
    let median = walls[repeats / 2];
    let threads = rayon::current_num_threads();
    println!(
        "{}: {jobs} runs (30 s at 1 ms each, references included) in {:.3} s wall (median of {repeats}; min {:.3} s, max {:.3} s), \
         {:.1} ms a run, threads {}; the independent numba implementation: ~52 ms a run, 1.9 s for 36",
        engine.name(),
        median,
        walls[0],
        walls[repeats - 1],
        median / jobs.max(1) as f64 * 1e3,
        if options.threads == 0 { threads } else { options.threads },
    );
    Ok(())
}

//! `cosim`: run an FMU or a system of FMUs, or list what is in one.

use clap::{Parser, Subcommand};
use nigel_cosim::defaults::GivenTimes;
use nigel_cosim::options::{cli_option_name, RunOptions};
use nigel_cosim::run_setup::{run_in_process, InProcess, RunSetup, SINGLE};
use nigel_cosim::{Error, ImportOptions, Interface, System, UnpackLimits};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "cosim",
    version,
    about = "FMI 2.0 and FMI 3.0 co-simulation master: FMUs and SSP systems, Co-Simulation and Model Exchange"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate MODEL.fmu (as a one-instance system) or SYSTEM.ssp / SYSTEM.ssd.
    Run(Box<RunArgs>),
    /// Compare RESULT.csv with BASELINE.csv signal by signal in tolerance tubes (exit
    /// status 3 when a signal leaves its tube or is missing; docs/ci.md).
    Compare(CompareArgs),
    /// List the variables (causality, type, unit, start) of an FMU, or the instances and
    /// connections of an SSP.
    Info {
        /// The .fmu, .ssp or .ssd file.
        model: PathBuf,
        #[command(flatten)]
        limits: LimitArgs,
    },
}

#[derive(clap::Args)]
struct CompareArgs {
    /// The results to judge (CSV: ours, fmpy's, Dymola's or OpenModelica's export).
    result: PathBuf,
    /// The baseline (CSV).
    baseline: PathBuf,
    /// Relative tolerance, of the baseline's magnitude at each point.
    #[arg(long, default_value_t = 1e-3)]
    rtol: f64,
    /// Absolute tolerance, in each signal's unit.
    #[arg(long, default_value_t = 1e-6)]
    atol: f64,
    /// Time tolerance, s: events shifted by up to this much pass.
    #[arg(long, default_value_t = 0.0)]
    time_tol: f64,
    #[command(flatten)]
    report: ReportArgs,
}

/// Where the verdicts of a run or a comparison go besides the terminal.
#[derive(clap::Args)]
struct ReportArgs {
    /// Compare only these signals (default: every signal of the baseline).
    #[arg(long, num_args = 1.., value_name = "NAME")]
    signals: Vec<String>,
    /// Draw one PNG per failing signal into this folder (result, baseline, tube, violations).
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    /// Write a JUnit XML report (a test case per check and per compared signal).
    #[arg(long, value_name = "FILE.xml")]
    junit: Option<PathBuf>,
    /// Write a Markdown table of the verdicts (for a CI job summary).
    #[arg(long, value_name = "FILE.md")]
    summary_md: Option<PathBuf>,
}

/// Checks and a baseline of `cosim run`.
#[derive(clap::Args)]
struct VerifyArgs {
    /// A check of the run, judged on every recorded row: a metric, a comparison, a number
    /// or metric, e.g. 'max(abs(plant.y)) < 0.6' (repeatable; docs/ci.md). Exit status 3
    /// when one fails (the results are still written).
    #[arg(long = "check", value_name = "EXPR")]
    checks: Vec<String>,
    /// Compare the results with this baseline CSV in tolerance tubes (exit status 3 when
    /// a signal leaves its tube).
    #[arg(long, value_name = "BASE.csv")]
    baseline: Option<PathBuf>,
    /// --baseline's relative tolerance (cosim compare --rtol).
    #[arg(long, default_value_t = 1e-3)]
    baseline_rtol: f64,
    /// --baseline's absolute tolerance (cosim compare --atol).
    #[arg(long, default_value_t = 1e-6)]
    baseline_atol: f64,
    /// --baseline's time tolerance, s (cosim compare --time-tol).
    #[arg(long, default_value_t = 0.0)]
    baseline_time_tol: f64,
    #[command(flatten)]
    report: ReportArgs,
}

/// Limits of the archives and XML files read; the defaults refuse zip bombs and files
/// far larger than any FMU, raise them for an archive you trust.
#[derive(clap::Args)]
struct LimitArgs {
    /// Most entries in an archive.
    #[arg(long, value_name = "N")]
    max_entries: Option<u64>,
    /// Largest uncompressed entry of an archive, bytes (default 256 MiB).
    #[arg(long, value_name = "BYTES")]
    max_entry_bytes: Option<u64>,
    /// Largest uncompressed archive in all, bytes (default 1 GiB).
    #[arg(long, value_name = "BYTES")]
    max_total_bytes: Option<u64>,
    /// Largest ratio of uncompressed to compressed size of an entry over 1 MiB (default 100).
    #[arg(long, value_name = "RATIO")]
    max_ratio: Option<u64>,
    /// Largest modelDescription.xml, .ssd or .ssv file, bytes (default 64 MiB).
    #[arg(long, value_name = "BYTES")]
    max_xml_bytes: Option<u64>,
}

impl LimitArgs {
    fn limits(&self) -> UnpackLimits {
        let d = UnpackLimits::default();
        UnpackLimits {
            max_entries: self.max_entries.unwrap_or(d.max_entries),
            max_entry_bytes: self.max_entry_bytes.unwrap_or(d.max_entry_bytes),
            max_total_bytes: self.max_total_bytes.unwrap_or(d.max_total_bytes),
            max_ratio: self.max_ratio.unwrap_or(d.max_ratio),
            max_xml_bytes: self.max_xml_bytes.unwrap_or(d.max_xml_bytes),
        }
    }
}

#[derive(clap::Args)]
struct RunArgs {
    /// The .fmu, .ssp or .ssd file.
    model: PathBuf,
    /// FMI interface: cs (Co-Simulation), me (Model Exchange) or se (FMI 3.0 Scheduled
    /// Execution, one FMU: its model partitions activated at their clocks' ticks); default: cs
    /// if the FMU has it, else me, else se.
    #[arg(long)]
    interface: Option<String>,
    /// Start time, s (negative times are times like any other; default 0, for an SSP its
    /// DefaultExperiment's startTime).
    #[arg(long, allow_negative_numbers = true)]
    start_time: Option<f64>,
    /// Stop time, s (default: the FMU's DefaultExperiment, else the start time + 1).
    #[arg(long, allow_negative_numbers = true)]
    stop_time: Option<f64>,
    /// Communication step, s (default: the FMU's DefaultExperiment stepSize, else 1e-3).
    #[arg(long)]
    step: Option<f64>,
    /// jacobi (every connection one step late, as fmpy, libcosim and ecos step) or ordered
    /// (outputs along the direct-feedthrough chains within the step: how Table III is defined).
    #[arg(long, default_value = "jacobi")]
    algorithm: String,
    /// Model Exchange solver: auto (RK4 that continues with bdf from the first step it finds
    /// stiff, with a note), rk4, dopri5, or bdf (stiff models: variable-order BDF with the
    /// FMU's Jacobian).
    #[arg(long, default_value = "auto")]
    solver: String,
    /// Relative tolerance of dopri5 and bdf (and auto's bdf; absolute: rtol / 100; default 1e-6), and the
    /// one told to Co-Simulation FMUs for their own solvers (default: each FMU's
    /// DefaultExperiment tolerance, as fmpy does).
    #[arg(long)]
    rtol: Option<f64>,
    /// Largest RK4 step (rk4, auto), s (default: the communication step).
    #[arg(long)]
    max_step: Option<f64>,
    /// The cap on the steps of a run (communication steps, and the Model Exchange
    /// integrator's internal steps): a run that would take more stops with an error.
    #[arg(long, default_value_t = nigel_cosim::simulate::DEFAULT_MAX_STEPS)]
    max_steps: u64,
    /// FMI 3.0 Co-Simulation Event Mode (`eventModeUsed`), for every FMU of the model: auto
    /// (only for an FMU with clocks, which needs it; one without handles its events inside
    /// fmi3DoStep, as fmpy runs it by default), on (every FMI 3.0 Co-Simulation FMU, each
    /// must declare hasEventMode) or off (refused for an FMU with clocks).
    #[arg(long, default_value = "auto", value_name = "auto|on|off")]
    event_mode: nigel_cosim::EventModeChoice,
    /// Crash boundaries: `--isolate` (= `--isolate=fmu`) runs every FMU in a host process
    /// of its own (`cosim-host`, one round trip per call); `--isolate=run` runs the whole
    /// run in one host process, the FMUs called in it directly (in-process speed). Either
    /// way a crash, an exit or a hang (--timeout) of an FMU is an error naming the
    /// instance, the call, the time and the signal, with the rows so far written.
    #[arg(long, value_enum, num_args = 0..=1, require_equals = true, default_missing_value = "fmu", value_name = "fmu|run")]
    isolate: Option<IsolateMode>,
    /// Wall-clock limit of one FMU call, s (needs --isolate: the host is killed).
    #[arg(long, value_name = "SECONDS")]
    timeout_call: Option<f64>,
    /// Wall-clock limit of the whole run, s. In process (no --isolate) a call that never
    /// returns cannot be stopped: 1 s past the limit the process ends, naming the call,
    /// with the rows so far written; --isolate kills only the FMU's host.
    #[arg(long, value_name = "SECONDS")]
    timeout: Option<f64>,
    /// On fmi2Discard, restore the FMU state and retry the step in halves (FMUs that can
    /// get/set their state and vary their step).
    #[arg(long)]
    retry_discard: bool,
    /// Results file: .csv (fmpy's CSV) or .mat (MAT v4 as Dymola and OpenModelica write it).
    #[arg(long, short)]
    output: Option<PathBuf>,
    /// Input signals over time: a CSV file in fmpy's input format (a time column first,
    /// then one column per input, named as in --set); Reals interpolated linearly between
    /// rows unless discrete, others held from the last row at or before the time.
    #[arg(long, value_name = "FILE.csv")]
    input: Option<PathBuf>,
    /// Pass on NaN and infinite outputs that FMUs return with fmi2OK (default: an error
    /// naming the FMU and the variable).
    #[arg(long)]
    allow_non_finite: bool,
    /// Output interval, s (a whole multiple of the step; default: every step).
    #[arg(long)]
    output_interval: Option<f64>,
    /// Start value or parameter: instance.variable=value (or variable=value for one FMU).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// A value set during the run, from the first step starting at or after TIME s: an
    /// input or tunable parameter, or a tunable FMI 3.0 structural parameter (set in
    /// Reconfiguration Mode; the arrays it sizes get columns for their largest size, NaN
    /// where an array lacks the element). Repeatable.
    #[arg(long = "set-at", num_args = 2, value_names = ["TIME", "NAME=VALUE"])]
    set_at: Vec<String>,
    /// Run the closed loop's `controller` instance with one's own gain: a `synthesize --json`
    /// report (its "K", rows FL, FR, RL, RR, columns beta, r). Sets `controller.controller=4`
    /// (custom) and `controller.k_beta_*`, `controller.k_yaw_rate_*`; `--set` applies after it.
    #[arg(long, value_name = "K.json")]
    gains: Option<PathBuf>,
    /// Variables to record (default: all outputs), repeatable.
    #[arg(long = "record", value_name = "NAME")]
    record: Vec<String>,
    /// Threads stepping the instances with `--algorithm jacobi` (default 1). Pays when
    /// instances take several microseconds per step each; results are identical.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// JSON run summary file ("-" for standard output; with the time spent in each FMU).
    #[arg(long)]
    summary: Option<PathBuf>,
    #[command(flatten)]
    verify: VerifyArgs,
    #[command(flatten)]
    limits: LimitArgs,
}

/// Why `cosim` stopped: an error of the master or a message of its own.
enum Failure {
    Cosim(Error),
    Message(String),
}

impl From<Error> for Failure {
    fn from(e: Error) -> Failure {
        Failure::Cosim(e)
    }
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Failure::Cosim(e) => e.fmt(f),
            Failure::Message(m) => f.write_str(m),
        }
    }
}

/// Exit status of a run or comparison that was done and did not pass (1: not done, 2: a
/// command line clap refused).
const EXIT_NOT_PASSED: u8 = 3;

/// Where `--isolate` draws the crash boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum IsolateMode {
    /// A host process per FMU.
    Fmu,
    /// The whole run in one host process.
    Run,
}

/// Set by the first Ctrl-C (SIGINT, SIGTERM, SIGHUP): the run stops at its next step and the
/// rows it computed are written, as after a failed run; a second signal ends at once.
static STOP: std::sync::OnceLock<std::sync::Arc<std::sync::atomic::AtomicBool>> = std::sync::OnceLock::new();

/// How long the first signal waits for the run to stop and its rows to be written.
const STOP_GRACE: std::time::Duration = std::time::Duration::from_secs(10);

fn main() -> ExitCode {
    let stop = STOP.get_or_init(Default::default).clone();
    nigel_cosim::unpack::remove_on_signals_after_stop(
        move |signal| {
            stop.store(true, std::sync::atomic::Ordering::Relaxed);
            eprintln!(
                "\ncosim: {}: stopping at the next step and writing the rows so far (again to end at once)",
                nigel_cosim::error::signal_name(signal)
            );
        },
        STOP_GRACE,
    );
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => run(*args),
        Command::Compare(args) => compare(&args),
        Command::Info { model, limits } => info(&model, &limits.limits()).map(|()| true).map_err(Failure::from),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(EXIT_NOT_PASSED),
        Err(e) => {
            eprintln!("cosim: {e}");
            ExitCode::FAILURE
        }
    }
}

fn progress(fraction: f64) {
    use std::sync::atomic::{AtomicU64, Ordering};
    static LAST: AtomicU64 = AtomicU64::new(u64::MAX);
    let pct = (fraction * 100.0).floor() as u64;
    if LAST.swap(pct, Ordering::Relaxed) != pct {
        eprint!("\r{pct:3}%");
        if pct == 100 {
            eprintln!();
        }
    }
}

/// The `--set`s that run the controller FMU of the closed loop with the gain of a
/// `synthesize --json` report: `controller = 4` (custom) and the eight `k_*` parameters.
fn custom_gain_settings(path: &Path) -> Result<Vec<(String, String)>, Error> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| Error::Import(nigel_cosim::ImportError::Io { path: path.to_path_buf(), source }))?;
    let k =
        nigel_benchmark::gain_file::read_gain_json(&text, &path.display().to_string()).map_err(Error::Experiment)?;
    let mut sets = vec![("controller.controller".to_string(), "4".to_string())];
    for (row, wheel) in k.iter().zip(["fl", "fr", "rl", "rr"]) {
        // `{:?}` prints the shortest decimal that reads back to the same f64
        sets.push((format!("controller.k_beta_{wheel}"), format!("{:?}", row[0])));
        sets.push((format!("controller.k_yaw_rate_{wheel}"), format!("{:?}", row[1])));
    }
    Ok(sets)
}

fn run(args: RunArgs) -> Result<bool, Failure> {
    let started = std::time::Instant::now();
    let interface = args.interface.as_deref().map(str::parse::<Interface>).transpose().map_err(Error::Experiment)?;
    let format = args.output.as_deref().map(OutputFormat::of).transpose()?;
    let limits = args.limits.limits();
    // isolation needs Linux's shared memory and futexes: elsewhere refused before anything loads
    if let (Some(_), Some(why)) = (args.isolate, nigel_cosim::isolate::os::unsupported()) {
        return Err(Error::Experiment(why).into());
    }
    // the parent of --isolate=run loads no FMU library (its host does)
    let host_of_run = nigel_cosim::isolate::whole::is_host();
    let isolated = args.isolate.is_some() && !host_of_run;
    let options = ImportOptions {
        interface,
        limits,
        allow_non_finite: args.allow_non_finite,
        isolated,
        event_mode: args.event_mode,
    };
    // --interface applies to every FMU of a system (one without it is refused by name)
    let mut setup = RunSetup::load(&args.model, &options)?;
    if !host_of_run {
        for note in setup.notes() {
            eprintln!("cosim: note: {note}");
        }
    }
    if let Some(path) = &args.gains {
        for (name, value) in custom_gain_settings(path)? {
            setup.set_system_name(&name, &value)?;
        }
    }
    for s in &args.set {
        let (name, value) =
            s.split_once('=').ok_or_else(|| Error::Experiment(format!("--set {s:?}: expected NAME=VALUE")))?;
        setup.set(name.trim(), value)?;
    }
    for pair in args.set_at.chunks(2) {
        let [time, setting] = pair else { unreachable!("clap gives --set-at two values") };
        let label = format!("--set-at {time} {setting}");
        let bad = |why: &str| Error::Experiment(format!("{label}: {why}"));
        let time: f64 =
            time.trim().parse().ok().filter(|t: &f64| t.is_finite()).ok_or_else(|| bad("TIME is no number"))?;
        let (name, text) = setting.split_once('=').ok_or_else(|| bad("expected NAME=VALUE"))?;
        setup.set_at(time, name.trim(), text, &label)?;
    }
    if args.isolate.is_some() && nigel_cosim::simulate::is_scheduled(setup.system()) {
        return Err(Error::Experiment(nigel_cosim::simulate::SCHEDULED_NOT_ISOLATED.into()).into());
    }
    if !setup.timed_sets().is_empty() && (args.isolate.is_some() || nigel_cosim::simulate::is_scheduled(setup.system()))
    {
        return Err(Error::Experiment(
            "--set-at is run in process by the stepping master (not with --isolate, not in Scheduled Execution)".into(),
        )
        .into());
    }
    let given = GivenTimes {
        start_time: args.start_time,
        stop_time: args.stop_time,
        step_size: args.step,
        ..Default::default()
    };
    let times = setup.times(&given);
    let prepared = setup.build();
    let run_options = RunOptions {
        start_time: times.start_time,
        stop_time: times.stop_time,
        step: times.step,
        output_interval: args.output_interval,
        algorithm: &args.algorithm,
        solver: &args.solver,
        relative_tolerance: args.rtol,
        default_relative_tolerance: nigel_cosim::me::DEFAULT_RTOL,
        max_step: args.max_step,
        timeout: args.timeout,
        threads: args.threads,
    };
    let mut experiment = prepared.experiment(&run_options, cli_option_name)?;
    let system = &prepared.system;
    if !host_of_run {
        for warning in nigel_cosim::sample_period::warnings(system, experiment.step) {
            eprintln!("cosim: warning: {warning} (use --step {})", warning.period);
        }
        // what an FMI 3.0 FMU has and the results will not: said, not silently dropped
        for note in prepared.view_notes() {
            eprintln!("cosim: note: {note}");
        }
    }

    if let Some(path) = &args.input {
        experiment.input = Some(std::sync::Arc::new(nigel_cosim::InputTable::read_csv(path)?));
    }
    experiment.retry_discard = args.retry_discard;
    // the time per FMU is only reported in the summary: measured only when one is asked for
    experiment.profile = args.summary.is_some();
    experiment.max_steps = args.max_steps;
    let seconds = |what: &str, s: f64| {
        std::time::Duration::try_from_secs_f64(s)
            .ok()
            .filter(|d| !d.is_zero())
            .ok_or_else(|| Error::Experiment(format!("{what} {s} must be a positive number of seconds")))
    };
    if args.timeout_call.is_some() && args.isolate != Some(IsolateMode::Fmu) {
        return Err(Error::Experiment(
            "--timeout-call needs --isolate (=fmu: a call in this process cannot be stopped; a host process per FMU can be killed; --isolate=run has --timeout)"
                .into(),
        ).into());
    }
    if args.isolate == Some(IsolateMode::Fmu) {
        experiment.isolation = Some(nigel_cosim::Isolation {
            instances: None,
            call_timeout: args.timeout_call.map(|s| seconds("--timeout-call", s)).transpose()?,
            host: None,
        });
    }
    if args.record.is_empty() {
        prepared.check_recordable("--record")?;
    }
    let verification = verification(&args.verify)?;
    // what the checks and the baseline read is recorded too, and left out of --output
    let checks: Vec<(String, Vec<String>)> =
        verification.checks.iter().map(|c| (format!("--check {:?}", c.text), c.variables())).collect();
    let columns = prepared.columns(&args.record, &checks, &verification.columns()).map_err(Failure::Message)?;
    let extra = columns.extra();
    if !args.record.is_empty() || extra {
        experiment.record = Some(columns.record.clone());
    }
    // Err(None): the run failed in the host of --isolate=run, which said why itself
    let mut host_json = None;
    let (results, outcome): (_, Result<_, Option<Error>>) = match args.isolate {
        Some(IsolateMode::Run) if host_of_run => {
            nigel_cosim::isolate::whole::host_simulate(system, &experiment)?;
            return Ok(true);
        }
        Some(IsolateMode::Run) => {
            let argv: Vec<std::ffi::OsString> = std::env::args_os().skip(1).collect();
            let run = nigel_cosim::isolate::whole::simulate_in_host(system, &experiment, &argv)?;
            let outcome = run.outcome.map(|(summary, json)| {
                host_json = Some(json);
                summary
            });
            (run.results, outcome)
        }
        _ => {
            // in process, an exit() inside a call is reported, and a call that never returns
            // is stopped by ending the process (a run in Scheduled Execution watches itself)
            let scheduled = prepared.is_scheduled();
            if !scheduled {
                report_exit_inside_calls(args.output.clone(), format, system);
            }
            let _watchdog =
                experiment.timeout.filter(|_| args.isolate.is_none() && !scheduled).map(nigel_cosim::watchdog::start);
            let watch = InProcess {
                pool: None,
                cancel: STOP.get().cloned(),
                progress: std::io::stderr().is_terminal().then_some(progress as fn(f64)),
            };
            let (results, outcome) = run_in_process(system, &experiment, &prepared.timed_sets, watch);
            (results, outcome.map_err(Some))
        }
    };
    if outcome.is_ok() && args.output.is_none() && args.summary.is_none() && verification.is_empty() {
        eprintln!(
            "cosim: note: no --output or --summary given: the run completed but its results were not kept \
             (add --output out.csv or --output out.mat)"
        );
    }
    let write = |path: &Path, f: &dyn Fn(std::fs::File) -> std::io::Result<()>| {
        std::fs::File::create(path)
            .and_then(f)
            .map_err(|source| Error::Import(nigel_cosim::ImportError::Io { path: path.to_path_buf(), source }))
    };
    // the rows recorded so far are written also when the run failed
    if let (Some(path), Some(format)) = (&args.output, format) {
        if outcome.is_ok() || results.rows() > 0 {
            let asked_columns: Vec<String> = columns.asked.iter().map(|n| prepared.column(n)).collect();
            let kept = if extra { results.select(&asked_columns) } else { results.clone() };
            match format {
                OutputFormat::Csv => write(path, &|f| kept.write_csv(std::io::BufWriter::new(f)))?,
                OutputFormat::Mat => {
                    let descriptions = column_descriptions(system, &kept);
                    write(path, &|f| kept.write_mat(std::io::BufWriter::new(f), &descriptions))?
                }
            }
            if outcome.is_err() {
                eprintln!("cosim: {} rows up to the last completed step written to {}", results.rows(), path.display());
            }
        }
    }
    let suite_name = format!("cosim run {}", args.model.display());
    let summary = match outcome {
        Ok(s) => s,
        Err(Some(nigel_cosim::Error::Cancelled { time })) => {
            // stopped by a signal: the rows so far are written above
            eprintln!("cosim: stopped at t = {time} s of {} s", experiment.stop_time);
            nigel_cosim::unpack::finish_stopped();
        }
        Err(failed) => {
            let message =
                failed.as_ref().map_or("the run failed in its host process (see the log)".into(), |e| e.to_string());
            let suite = nigel_cosim::verify::run_suite(
                &suite_name,
                started.elapsed().as_secs_f64(),
                Some(&message),
                &Default::default(),
                &verification,
            );
            let r = &args.verify.report;
            if let Err(e) = nigel_cosim::verify::write_reports(&suite, r.junit.as_deref(), r.summary_md.as_deref()) {
                eprintln!("cosim: {e}");
            }
            match failed {
                Some(e) => return Err(e.into()),
                None => std::process::exit(1),
            }
        }
    };
    let json = serde_json::to_string_pretty(&host_json.unwrap_or_else(|| summary.to_json())).unwrap_or_default();
    match &args.summary {
        Some(p) if p.as_os_str() == "-" => println!("{json}"),
        Some(p) => write(p, &|mut f| std::io::Write::write_all(&mut f, json.as_bytes()))?,
        None => {}
    }
    for (instance, message) in &summary.warnings {
        eprintln!("cosim: warning from {instance}: {message}");
    }
    for note in &summary.notes {
        eprintln!("cosim: note: {note}");
    }
    if let Some((instance, time, reason)) = &summary.ended_by {
        eprintln!(
            "cosim: {instance} ended the simulation at t = {time} s ({reason}); stop time {} s",
            experiment.stop_time
        );
    }
    if verification.is_empty() && args.verify.report.junit.is_none() && args.verify.report.summary_md.is_none() {
        return Ok(true);
    }
    let judged = verification.judge(&results, |v| prepared.column(&prepared.qualify(v))).map_err(Failure::Message)?;
    let to_stderr = args.summary.as_ref().is_some_and(|p| p.as_os_str() == "-");
    for line in judged.lines() {
        if to_stderr {
            eprintln!("{line}");
        } else {
            println!("{line}");
        }
    }
    report(&args.verify.report, &results, &verification, &judged, &suite_name, started)
}

/// The checks and baseline of `cosim run`.
fn verification(v: &VerifyArgs) -> Result<nigel_cosim::verify::Verification, Failure> {
    let tolerance =
        nigel_cosim::compare::Tolerance { rtol: v.baseline_rtol, atol: v.baseline_atol, time_tol: v.baseline_time_tol };
    let signals = (!v.report.signals.is_empty()).then(|| v.report.signals.clone());
    if signals.is_some() && v.baseline.is_none() {
        return Err(Failure::Message("--signals needs --baseline".into()));
    }
    nigel_cosim::verify::Verification::new(&v.checks, v.baseline.as_deref(), tolerance, signals).map_err(|e| {
        Failure::Message(
            e.replace("--rtol", "--baseline-rtol")
                .replace("--atol", "--baseline-atol")
                .replace("--time-tol", "--baseline-time-tol"),
        )
    })
}

/// The figures, the JUnit file and the Markdown summary of a judged run or comparison;
/// whether it passed.
fn report(
    r: &ReportArgs,
    results: &nigel_cosim::Results,
    verification: &nigel_cosim::verify::Verification,
    judged: &nigel_cosim::verify::Judged,
    suite_name: &str,
    started: std::time::Instant,
) -> Result<bool, Failure> {
    if let (Some(dir), Some(c), Some((_, base))) = (&r.plot, &judged.comparison, &verification.baseline) {
        for p in nigel_cosim::compare::plot::plot_failures(results, base, c, dir).map_err(Failure::Message)? {
            eprintln!("cosim: figure {}", p.display());
        }
    }
    let suite = nigel_cosim::verify::run_suite(suite_name, started.elapsed().as_secs_f64(), None, judged, verification);
    nigel_cosim::verify::write_reports(&suite, r.junit.as_deref(), r.summary_md.as_deref())
        .map_err(Failure::Message)?;
    Ok(judged.passed())
}

/// `cosim compare`: the comparison's lines; whether every signal passed.
fn compare(args: &CompareArgs) -> Result<bool, Failure> {
    let started = std::time::Instant::now();
    let tolerance = nigel_cosim::compare::Tolerance { rtol: args.rtol, atol: args.atol, time_tol: args.time_tol };
    let signals = (!args.report.signals.is_empty()).then(|| args.report.signals.clone());
    let verification = nigel_cosim::verify::Verification::new(&[], Some(&args.baseline), tolerance, signals)
        .map_err(Failure::Message)?;
    let result = nigel_cosim::compare::csv::read_results_csv(&args.result).map_err(Failure::Message)?;
    let judged = verification.judge(&result, |v| v.to_string()).map_err(Failure::Message)?;
    println!("compare {} with the baseline {}", args.result.display(), args.baseline.display());
    for line in judged.comparison.iter().flat_map(|c| c.lines()) {
        println!("{line}");
    }
    let name = format!("cosim compare {} {}", args.result.display(), args.baseline.display());
    // the comparison's cases alone: no run
    if let (Some(dir), Some(c), Some((_, base))) = (&args.report.plot, &judged.comparison, &verification.baseline) {
        for p in nigel_cosim::compare::plot::plot_failures(&result, base, c, dir).map_err(Failure::Message)? {
            eprintln!("cosim: figure {}", p.display());
        }
    }
    let suite = nigel_cosim::junit::TestSuite {
        name: name.clone(),
        time: started.elapsed().as_secs_f64(),
        cases: judged.comparison.as_ref().map(nigel_cosim::verify::comparison_cases).unwrap_or_default(),
    };
    nigel_cosim::verify::write_reports(&suite, args.report.junit.as_deref(), args.report.summary_md.as_deref())
        .map_err(Failure::Message)?;
    Ok(judged.passed())
}

/// An FMU that calls exit() inside a call (in this process) ends `cosim` with status 1,
/// naming the instance and the call, with the rows so far written to `output`.
fn report_exit_inside_calls(output: Option<PathBuf>, format: Option<OutputFormat>, system: &System) {
    // the MAT file's descriptions, by column name (the hook holds no FMU: a held `Arc<Fmu>`
    // would keep its unpacked folder to the end of the process)
    let single = system.instances.len() == 1;
    let descriptions: std::collections::HashMap<String, String> = match format {
        Some(OutputFormat::Mat) => system
            .instances
            .iter()
            .flat_map(|i| {
                i.fmu.description().model_variables.iter().map(move |v| {
                    let name = if single { v.name.clone() } else { format!("{}.{}", i.name, v.name) };
                    (name, v.description.clone().unwrap_or_default())
                })
            })
            .collect(),
        _ => Default::default(),
    };
    nigel_cosim::on_exit_inside_call(Box::new(move |what, rows| {
        eprintln!("cosim: {what}");
        let (Some(path), Some(format)) = (&output, format) else { return };
        let Some(results) = rows.filter(|r| r.rows() > 0) else {
            eprintln!("cosim: no rows to write to {}", path.display());
            return;
        };
        let written = std::fs::File::create(path).and_then(|f| match format {
            OutputFormat::Csv => results.write_csv(std::io::BufWriter::new(f)),
            OutputFormat::Mat => {
                let d: Vec<String> =
                    results.names.iter().map(|n| descriptions.get(n).cloned().unwrap_or_default()).collect();
                results.write_mat(std::io::BufWriter::new(f), &d)
            }
        });
        match written {
            Ok(()) => {
                eprintln!("cosim: {} rows up to the last completed step written to {}", results.rows(), path.display())
            }
            Err(e) => eprintln!("cosim: {}: {e}", path.display()),
        }
    }));
}

#[derive(Clone, Copy)]
enum OutputFormat {
    Csv,
    Mat,
}

impl OutputFormat {
    /// By the file's extension; anything but .csv and .mat is refused before the run.
    fn of(path: &Path) -> Result<OutputFormat, Error> {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("csv") => Ok(OutputFormat::Csv),
            Some("mat") => Ok(OutputFormat::Mat),
            _ => Err(Error::Experiment(format!(
                "--output {}: the file name must end in .csv (fmpy's CSV) or .mat (MAT v4, as Dymola writes it)",
                path.display()
            ))),
        }
    }
}

/// The variable descriptions of the result columns, for the MAT file.
fn column_descriptions(system: &System, results: &nigel_cosim::Results) -> Vec<String> {
    let single = system.instances.len() == 1;
    results
        .names
        .iter()
        .map(|n| {
            let full = if single { format!("{SINGLE}.{n}") } else { n.clone() };
            system.resolve(&full).ok().and_then(|r| system.variable(&r).description.clone()).unwrap_or_default()
        })
        .collect()
}

/// `cosim info`: [`nigel_cosim::info::describe`] on standard output; a closed pipe
/// (`cosim info X | head`) ends the listing quietly.
fn info(path: &Path, limits: &UnpackLimits) -> Result<(), Error> {
    use std::io::Write;
    let text = nigel_cosim::info::describe(path, limits)?;
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
    Ok(())
}

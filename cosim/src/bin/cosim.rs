//! `cosim`: run an FMU or a system of FMUs, or list what is in one.

use clap::{Parser, Subcommand};
use nigel_cosim::defaults::{GivenTimes, RunTimes};
use nigel_cosim::{Algorithm, Error, Experiment, Fmu, ImportOptions, Interface, System, SystemBuilder, UnpackLimits};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "cosim", version, about = "FMI 2.0 co-simulation master")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate MODEL.fmu (as a one-instance system) or SYSTEM.ssp / SYSTEM.ssd.
    Run(Box<RunArgs>),
    /// List the variables (causality, type, unit, start) of an FMU, or the instances and
    /// connections of an SSP.
    Info {
        /// The .fmu, .ssp or .ssd file.
        model: PathBuf,
        #[command(flatten)]
        limits: LimitArgs,
    },
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
    /// FMI interface: cs (Co-Simulation) or me (Model Exchange); default: cs if the FMU has it.
    #[arg(long)]
    interface: Option<String>,
    /// Start time, s (negative times are times like any other).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    start_time: f64,
    /// Stop time, s (default: the FMU's DefaultExperiment, else the start time + 1).
    #[arg(long, allow_negative_numbers = true)]
    stop_time: Option<f64>,
    /// Communication step, s (default: the FMU's DefaultExperiment stepSize, else 1e-3).
    #[arg(long)]
    step: Option<f64>,
    /// ordered or jacobi.
    #[arg(long, default_value = "jacobi")]
    algorithm: String,
    /// Model Exchange solver: rk4, dopri5, or bdf (stiff models: variable-order BDF with the
    /// FMU's Jacobian).
    #[arg(long, default_value = "rk4")]
    solver: String,
    /// Relative tolerance of dopri5 and bdf (absolute: rtol / 100).
    #[arg(long, default_value_t = 1e-6)]
    rtol: f64,
    /// Largest RK4 step, s (default: the communication step).
    #[arg(long)]
    max_step: Option<f64>,
    /// The cap on the steps of a run (communication steps, and the Model Exchange
    /// integrator's internal steps): a run that would take more stops with an error.
    #[arg(long, default_value_t = nigel_cosim::simulate::DEFAULT_MAX_STEPS)]
    max_steps: u64,
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
    /// Wall-clock limit of the whole run, s.
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
    limits: LimitArgs,
}

/// Where `--isolate` draws the crash boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum IsolateMode {
    /// A host process per FMU.
    Fmu,
    /// The whole run in one host process.
    Run,
}

fn main() -> ExitCode {
    nigel_cosim::unpack::remove_on_signals();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => run(*args),
        Command::Info { model, limits } => info(&model, &limits.limits()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cosim: {e}");
            ExitCode::FAILURE
        }
    }
}

const SINGLE: &str = "model";

/// The system name of `name`: for a single FMU its variable (an exact variable name wins,
/// so a variable called `model.beta` is not read as `beta` of the instance), else as given.
fn qualify(name: &str, single: Option<&Fmu>) -> String {
    match single {
        Some(fmu) if fmu.description().variable(name).is_some() => format!("{SINGLE}.{name}"),
        Some(_) if !name.starts_with(&format!("{SINGLE}.")) => format!("{SINGLE}.{name}"),
        _ => name.to_string(),
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

fn run(args: RunArgs) -> Result<(), Error> {
    let interface = match args.interface.as_deref() {
        None => None,
        Some("cs") => Some(Interface::CoSimulation),
        Some("me") => Some(Interface::ModelExchange),
        Some(other) => return Err(Error::Experiment(format!("unknown interface {other:?} (cs, me)"))),
    };
    let algorithm: Algorithm = args.algorithm.parse().map_err(Error::Experiment)?;
    let format = match &args.output {
        None => None,
        Some(p) => Some(OutputFormat::of(p)?),
    };
    let limits = args.limits.limits();
    // the parent of --isolate=run loads no FMU library (its host does)
    let host_of_run = nigel_cosim::isolate::whole::is_host();
    let isolated = args.isolate.is_some() && !host_of_run;
    let options = ImportOptions { interface, limits, allow_non_finite: args.allow_non_finite, isolated };
    let (mut builder, default, single, _ssp) = if is_ssp(&args.model) {
        // --interface applies to every FMU of the system (one without it is refused by name)
        let ssp = nigel_cosim::read_ssp(&args.model, &options)?;
        let builder = SystemBuilder::from_system(ssp.system.clone());
        let (start_time, stop_time) = ssp.default_start_stop;
        let default = model_description::DefaultExperiment { start_time, stop_time, ..Default::default() };
        (builder, default, None, Some(ssp))
    } else {
        let fmu = Fmu::load_with(&args.model, &options)?;
        let default = fmu.description().default_experiment.clone().unwrap_or_default();
        let mut builder = SystemBuilder::new();
        builder.add_instance(SINGLE, fmu.clone())?;
        (builder, default, Some(fmu), None)
    };
    let single = single.as_deref();
    if let Some(path) = &args.gains {
        for (name, value) in custom_gain_settings(path)? {
            builder.set_text(&name, &value)?;
        }
    }
    for s in &args.set {
        let (name, value) =
            s.split_once('=').ok_or_else(|| Error::Experiment(format!("--set {s:?}: expected NAME=VALUE")))?;
        builder.set_text(&qualify(name.trim(), single), value)?;
    }
    let system: System = builder.build();
    // the start time is --start-time's (default 0), not the DefaultExperiment's
    let given = GivenTimes {
        start_time: Some(args.start_time),
        stop_time: args.stop_time,
        step_size: args.step,
        ..Default::default()
    };
    let times = RunTimes::master(&default, &given);
    let mut experiment = Experiment::new(times.stop_time, times.step);
    experiment.start_time = times.start_time;
    check_times(&experiment)?;
    if !host_of_run {
        for warning in sample_period_warnings(&system, experiment.step) {
            eprintln!("cosim: warning: {warning}");
        }
        // what an FMI 3.0 FMU has and the results will not: said, not silently dropped
        for instance in &system.instances {
            for (name, why) in instance.fmu.not_in_view() {
                eprintln!(
                    "cosim: note: {}.{name} is {}: not recorded (outside the master's view)",
                    instance.name,
                    why.as_str()
                );
            }
        }
    }

    experiment.algorithm = algorithm;
    experiment.solver = match args.solver.as_str() {
        "rk4" => nigel_cosim::Solver::Rk4 { max_step: args.max_step },
        "dopri5" if args.rtol > 0.0 && args.rtol.is_finite() => {
            nigel_cosim::Solver::Dopri5 { rtol: args.rtol, atol: args.rtol / 100.0 }
        }
        "bdf" if args.rtol > 0.0 && args.rtol.is_finite() => {
            nigel_cosim::Solver::Bdf { rtol: args.rtol, atol: args.rtol / 100.0 }
        }
        "dopri5" | "bdf" => return Err(Error::Experiment(format!("--rtol {} must be positive", args.rtol))),
        other => return Err(Error::Experiment(format!("unknown solver {other:?} (rk4, dopri5, bdf)"))),
    };
    if args.max_step.is_some_and(|m| !(m > 0.0 && m.is_finite())) {
        return Err(Error::Experiment("--max-step must be positive".into()));
    }
    if let Some(path) = &args.input {
        experiment.input = Some(std::sync::Arc::new(nigel_cosim::InputTable::read_csv(path)?));
    }
    experiment.output_interval = args.output_interval;
    experiment.retry_discard = args.retry_discard;
    // the time per FMU is only reported in the summary: measured only when one is asked for
    experiment.profile = args.summary.is_some();
    if args.threads == 0 {
        return Err(Error::Experiment("--threads must be at least 1".into()));
    }
    experiment.threads = args.threads;
    experiment.max_steps = args.max_steps;
    let seconds = |what: &str, s: f64| {
        std::time::Duration::try_from_secs_f64(s)
            .ok()
            .filter(|d| !d.is_zero())
            .ok_or_else(|| Error::Experiment(format!("{what} {s} must be a positive number of seconds")))
    };
    if let Some(s) = args.timeout {
        experiment.timeout = Some(seconds("--timeout", s)?);
    }
    if args.timeout_call.is_some() && args.isolate != Some(IsolateMode::Fmu) {
        return Err(Error::Experiment(
            "--timeout-call needs --isolate (=fmu: a call in this process cannot be stopped; a host process per FMU can be killed; --isolate=run has --timeout)"
                .into(),
        ));
    }
    if args.isolate == Some(IsolateMode::Fmu) {
        experiment.isolation = Some(nigel_cosim::Isolation {
            instances: None,
            call_timeout: args.timeout_call.map(|s| seconds("--timeout-call", s)).transpose()?,
            host: None,
        });
    }
    if !args.record.is_empty() {
        experiment.record = Some(args.record.iter().map(|r| qualify(r, single)).collect());
    }
    if std::io::stderr().is_terminal() {
        experiment.progress = Some(progress);
    }
    // Err(None): the run failed in the host of --isolate=run, which said why itself
    let mut host_json = None;
    let (results, outcome): (_, Result<_, Option<Error>>) = match args.isolate {
        Some(IsolateMode::Run) if host_of_run => {
            return nigel_cosim::isolate::whole::host_simulate(&system, &experiment);
        }
        Some(IsolateMode::Run) => {
            let argv: Vec<std::ffi::OsString> = std::env::args_os().skip(1).collect();
            let run = nigel_cosim::isolate::whole::simulate_in_host(&system, &experiment, &argv)?;
            let outcome = run.outcome.map(|(summary, json)| {
                host_json = Some(json);
                summary
            });
            (run.results, outcome)
        }
        _ => {
            report_exit_inside_calls(args.output.clone(), format, &system);
            let (results, outcome) = nigel_cosim::simulate::simulate_recorded(&system, &experiment);
            (results, outcome.map_err(Some))
        }
    };
    if outcome.is_ok() && args.output.is_none() && args.summary.is_none() {
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
            match format {
                OutputFormat::Csv => write(path, &|f| results.write_csv(std::io::BufWriter::new(f)))?,
                OutputFormat::Mat => {
                    let descriptions = column_descriptions(&system, &results);
                    write(path, &|f| results.write_mat(std::io::BufWriter::new(f), &descriptions))?
                }
            }
            if outcome.is_err() {
                eprintln!("cosim: {} rows up to the last completed step written to {}", results.rows(), path.display());
            }
        }
    }
    let summary = match outcome {
        Ok(s) => s,
        Err(Some(e)) => return Err(e),
        Err(None) => std::process::exit(1),
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
    if let Some((instance, time, reason)) = &summary.ended_by {
        eprintln!(
            "cosim: {instance} ended the simulation at t = {time} s ({reason}); stop time {} s",
            experiment.stop_time
        );
    }
    Ok(())
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
    nigel_cosim::on_exit_inside_call(Box::new(move |call, rows| {
        match call {
            Some(c) => eprintln!("cosim: {c}"),
            None => eprintln!("cosim: exit() was called during the run, outside an FMU call of the calling thread"),
        }
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

/// Times a run cannot mean: refused before anything is loaded into an FMU.
fn check_times(e: &Experiment) -> Result<(), Error> {
    let span = e.stop_time - e.start_time;
    if span.is_nan() || span <= 0.0 {
        return Err(Error::Experiment(format!(
            "the stop time {} s must be after the start time {} s (--stop-time, --start-time)",
            e.stop_time, e.start_time
        )));
    }
    if e.step > span {
        return Err(Error::Experiment(format!(
            "the step {} s is longer than the run ({span} s from {} to {} s): choose a --step of at most {span}",
            e.step, e.start_time, e.stop_time
        )));
    }
    Ok(())
}

/// A warning for every FMU whose declared sample period (a parameter `sample_period`,
/// else, for an FMU with discrete states or outputs (Model Exchange: outputs), its DefaultExperiment stepSize) is shorter than the communication step: its
/// inputs are then held and its outputs read less often than it is meant to run.
fn sample_period_warnings(system: &System, step: f64) -> Vec<String> {
    let mut out = Vec::new();
    for spec in &system.instances {
        let md = spec.fmu.description();
        let parameter = md.model_variables.iter().enumerate().find(|(_, v)| {
            v.name == "sample_period" && v.causality == model_description::Causality::Parameter && v.is_real()
        });
        let from_parameter = parameter.and_then(|(index, v)| {
            let set = spec.start_values.iter().find(|(i, _)| *i == index).and_then(|(_, value)| match value {
                nigel_cosim::Value::Real(x) => Some(*x),
                _ => None,
            });
            let start = match v.variable_type {
                model_description::VariableType::Real { start, .. } => start,
                _ => None,
            };
            set.or(start).map(|p| (p, "its parameter sample_period"))
        });
        // the stepSize is only a suggestion of a continuous model (its integrator runs
        // within any step); it is a sample period where the FMU has discrete-time values
        // of its own, which change at its sample instants: in Co-Simulation discrete
        // states or outputs; in Model Exchange discrete outputs only (its discrete states
        // change at its events, which the master's integrator stops at within any
        // communication step; a model with discrete locals, such as the when-conditions
        // of a Modelica model, is continuous there)
        let me = spec.fmu.interface() == nigel_cosim::Interface::ModelExchange;
        let samples = md.model_variables.iter().any(|v| {
            v.variability == model_description::Variability::Discrete
                && match v.causality {
                    model_description::Causality::Output => true,
                    model_description::Causality::Input | model_description::Causality::Parameter => false,
                    _ => !me,
                }
        });
        let declared = from_parameter.or_else(|| {
            md.default_experiment
                .as_ref()
                .and_then(|d| d.step_size)
                .filter(|_| samples)
                .map(|p| (p, "its DefaultExperiment stepSize"))
        });
        if let Some((period, source)) = declared {
            // a relative margin for steps given in decimal (1e-3 vs 0.001000000000000002)
            if period > 0.0 && step > period * (1.0 + 1e-9) {
                out.push(format!(
                    "{} ({}) runs every {period} s ({source}), but the communication step is {step} s: its inputs \
                     are held and its outputs read only every {step} s (use --step {period})",
                    spec.name,
                    spec.fmu.source().file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
                ));
            }
        }
    }
    out
}

fn is_ssp(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ssp") || e.eq_ignore_ascii_case("ssd"))
}

fn info_ssp(path: &Path, limits: &UnpackLimits) -> Result<(), Error> {
    use std::io::Write;
    let ssp =
        nigel_cosim::read_ssp(path, &ImportOptions { limits: *limits, isolated: true, ..ImportOptions::default() })?;
    let s = &ssp.system;
    let mut out = std::io::stdout().lock();
    let mut lines = vec![format!(
        "system {} ({} instances, {} connections)",
        path.display(),
        s.instances.len(),
        s.connections.len()
    )];
    if let (start, Some(stop)) = ssp.default_start_stop {
        lines.push(format!("default experiment: start {} s, stop {stop} s", start.unwrap_or(0.0)));
    }
    for i in &s.instances {
        // an FMU unpacked from the .ssp is named by its place in the archive (the
        // temporary copy is gone when this command ends)
        let source = match ssp.path_in_archive(i.fmu.source()) {
            Some(inside) => format!("{} in {}", inside.display(), path.display()),
            None => i.fmu.source().display().to_string(),
        };
        lines.push(format!("instance {:<20} {source} ({})", i.name, i.fmu.interface().as_str()));
        for (index, v) in &i.start_values {
            let var = &i.fmu.description().model_variables[*index];
            let unit = var.variable_type.unit().map(|u| format!(" {u}")).unwrap_or_default();
            lines.push(format!("  start {} = {v}{unit}", var.name));
        }
    }
    for c in &s.connections {
        let unit = |r: &nigel_cosim::VariableRef| s.variable(r).variable_type.unit().unwrap_or("-").to_string();
        let mut line =
            format!("connection {} [{}] -> {} [{}]", s.name_of(&c.from), unit(&c.from), s.name_of(&c.to), unit(&c.to));
        if c.gain != 1.0 || c.offset != 0.0 {
            line.push_str(&format!("  (x {} + {})", c.gain, c.offset));
        }
        lines.push(line);
    }
    for l in lines {
        if writeln!(out, "{l}").is_err() {
            break;
        }
    }
    Ok(())
}

/// A number as a user writes it (`1e-3`, `0.35`, `inf`).
fn plain(x: f64) -> String {
    if x == f64::INFINITY {
        "inf".into()
    } else if x == f64::NEG_INFINITY {
        "-inf".into()
    } else if x != 0.0 && (x.abs() < 1e-4 || x.abs() >= 1e15) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// `cosim info`'s line of the DefaultExperiment attributes present (`None` if none is).
fn default_experiment_line(d: &model_description::DefaultExperiment) -> Option<String> {
    let parts: Vec<String> = [
        d.start_time.map(|v| format!("start {} s", plain(v))),
        d.stop_time.map(|v| format!("stop {} s", plain(v))),
        d.step_size.map(|v| format!("step {} s", plain(v))),
        d.tolerance.map(|v| format!("tolerance {}", plain(v))),
    ]
    .into_iter()
    .flatten()
    .collect();
    (!parts.is_empty()).then(|| format!("default experiment: {}", parts.join(", ")))
}

fn info(path: &Path, limits: &UnpackLimits) -> Result<(), Error> {
    if is_ssp(path) {
        return info_ssp(path, limits);
    }
    use model_description::VariableType;
    use std::io::Write;
    // a closed pipe (`cosim info X | head`) ends the listing quietly
    macro_rules! w {
        ($o:expr, $($a:tt)*) => {
            if writeln!($o, $($a)*).is_err() {
                return Ok(());
            }
        };
    }
    let mut out = std::io::stdout().lock();
    if let Some(md) = nigel_cosim::load::read_fmi3_description(path, limits)? {
        info_fmi3(&mut out, &md);
        return Ok(());
    }
    let fmu = Fmu::load_with(path, &ImportOptions { limits: *limits, isolated: true, ..ImportOptions::default() })?;
    let md = fmu.description();
    w!(out, "model {} (FMI {}), guid {}", md.model_name, md.fmi_version, md.guid);
    if let Some(d) = md.description.as_deref().filter(|d| !d.is_empty()) {
        w!(out, "{d}");
    }
    let cs = md.co_simulation.as_ref().map(|c| format!("CoSimulation ({})", c.model_identifier));
    let me = md.model_exchange.as_ref().map(|c| format!("ModelExchange ({})", c.model_identifier));
    w!(out, "interfaces: {}", [cs, me].into_iter().flatten().collect::<Vec<_>>().join(", "));
    w!(out, "continuous states: {}, event indicators: {}", md.states().len(), md.number_of_event_indicators);
    if let Some(line) = md.default_experiment.as_ref().and_then(default_experiment_line) {
        w!(out, "{line}");
    }
    w!(
        out,
        "{:<24} {:<19} {:<11} {:<8} {:<8} {:<12} {:<18} description",
        "name",
        "causality",
        "variability",
        "type",
        "unit",
        "start",
        "min .. max"
    );
    for v in &md.model_variables {
        let range = |min: Option<String>, max: Option<String>| match (min, max) {
            (None, None) => String::new(),
            (a, b) => format!("{} .. {}", a.unwrap_or_default(), b.unwrap_or_default()),
        };
        let (start, bounds) = match &v.variable_type {
            VariableType::Real { start, min, max, .. } => (start.map(plain), range(min.map(plain), max.map(plain))),
            VariableType::Integer { start, min, max } => {
                (start.map(|x| x.to_string()), range(min.map(|x| x.to_string()), max.map(|x| x.to_string())))
            }
            VariableType::Enumeration { start, declared_type, min, max } => (
                start.map(|x| {
                    let item = md.type_definitions.iter().find(|t| &t.name == declared_type).and_then(|t| t.item(x));
                    match item {
                        Some(item) => format!("{x} ({})", item.name),
                        None => x.to_string(),
                    }
                }),
                range(min.map(|x| x.to_string()), max.map(|x| x.to_string())),
            ),
            VariableType::Boolean { start } => (start.map(|x| x.to_string()), String::new()),
            VariableType::String { start } => (start.as_ref().map(|x| format!("{x:?}")), String::new()),
        };
        w!(
            out,
            "{:<24} {:<19} {:<11} {:<8} {:<8} {:<12} {:<18} {}",
            v.name,
            v.causality.as_str(),
            v.variability.as_str(),
            v.variable_type.type_name(),
            v.variable_type.unit().unwrap_or("-"),
            start.unwrap_or_else(|| "-".into()),
            bounds,
            v.description.as_deref().unwrap_or("")
        );
    }
    Ok(())
}

/// `cosim info` of an FMI 3.0 FMU: interface types with their capabilities, and every
/// variable with its type and dimensions.
fn info_fmi3(out: &mut impl std::io::Write, md: &model_description::fmi3::ModelDescription) {
    use model_description::fmi3::{Bound, Dimension, Values};
    // a closed pipe (`cosim info X | head`) ends the listing quietly
    macro_rules! w {
        ($o:expr, $($a:tt)*) => {
            if writeln!($o, $($a)*).is_err() {
                return;
            }
        };
    }
    w!(out, "model {} (FMI {}), instantiationToken {}", md.model_name, md.fmi_version, md.instantiation_token);
    if let Some(d) = md.description.as_deref().filter(|d| !d.is_empty()) {
        w!(out, "{d}");
    }
    let flags = |pairs: &[(bool, &str)]| -> String {
        let v: Vec<&str> = pairs.iter().filter(|(on, _)| *on).map(|(_, n)| *n).collect();
        if v.is_empty() {
            String::new()
        } else {
            format!("; {}", v.join(", "))
        }
    };
    let mut interfaces = Vec::new();
    if let Some(cs) = &md.co_simulation {
        interfaces.push(format!(
            "CoSimulation ({}{})",
            cs.common.model_identifier,
            flags(&[
                (cs.can_handle_variable_communication_step_size, "variable step"),
                (cs.might_return_early_from_do_step, "early return"),
                (cs.has_event_mode, "event mode"),
                (cs.common.can_get_and_set_fmu_state, "FMU state"),
                (cs.common.provides_directional_derivatives, "directional derivatives"),
            ])
        ));
    }
    if let Some(me) = &md.model_exchange {
        interfaces.push(format!(
            "ModelExchange ({}{})",
            me.common.model_identifier,
            flags(&[
                (me.needs_completed_integrator_step, "completed integrator step"),
                (me.common.can_get_and_set_fmu_state, "FMU state"),
                (me.common.provides_directional_derivatives, "directional derivatives"),
            ])
        ));
    }
    if let Some(se) = &md.scheduled_execution {
        interfaces.push(format!("ScheduledExecution ({}; not run by cosim)", se.common.model_identifier));
    }
    w!(out, "interfaces: {}", interfaces.join(", "));
    w!(
        out,
        "continuous states: {}, event indicators: {}",
        md.model_structure.continuous_state_derivatives.len(),
        md.model_structure.event_indicators.len()
    );
    if let Some(line) = md.default_experiment.as_ref().and_then(default_experiment_line) {
        w!(out, "{line}");
    }
    w!(
        out,
        "{:<24} {:<19} {:<11} {:<11} {:<10} {:<8} {:<12} {:<18} description",
        "name",
        "causality",
        "variability",
        "type",
        "dimensions",
        "unit",
        "start",
        "min .. max"
    );
    for v in &md.model_variables {
        let dims = if v.dimensions.is_empty() {
            "-".to_string()
        } else {
            let each: Vec<String> = v
                .dimensions
                .iter()
                .map(|d| match d {
                    Dimension::Fixed(n) => n.to_string(),
                    Dimension::Variable(vr) => md.variable(*vr).map_or_else(|| format!("vr {vr}"), |s| s.name.clone()),
                })
                .collect();
            format!("[{}]", each.join(","))
        };
        let start = v.start.as_ref().map(|s| {
            let items: Vec<String> = match s {
                Values::Float(x) => x.iter().map(|x| plain(*x)).collect(),
                Values::Int(x) => x.iter().map(|x| x.to_string()).collect(),
                Values::Boolean(x) => x.iter().map(|x| x.to_string()).collect(),
                Values::String(x) => x.iter().map(|x| format!("{x:?}")).collect(),
                // binary values as their size, as the results record them
                Values::Binary(x) => x.iter().map(|x| format!("{} bytes", x.len())).collect(),
            };
            if items.len() == 1 {
                items[0].clone()
            } else {
                format!("[{}]", items.join(" "))
            }
        });
        let bound = |b: Option<Bound>| match b {
            Some(Bound::Float(x)) => plain(x),
            Some(Bound::Int(i)) => i.to_string(),
            None => String::new(),
        };
        let range = if v.min.is_none() && v.max.is_none() {
            String::new()
        } else {
            format!("{} .. {}", bound(v.min), bound(v.max))
        };
        w!(
            out,
            "{:<24} {:<19} {:<11} {:<11} {:<10} {:<8} {:<12} {:<18} {}",
            v.name,
            v.causality.as_str(),
            v.variability.as_str(),
            v.value_type.element(),
            dims,
            md.unit_of(v).unwrap_or("-"),
            start.unwrap_or_else(|| "-".into()),
            range,
            v.description.as_deref().unwrap_or("")
        );
    }
    let left_out = nigel_cosim::fmi3::not_in_view(md);
    if !left_out.is_empty() {
        let each: Vec<String> = left_out.iter().map(|(name, why)| format!("{name} ({})", why.as_str())).collect();
        w!(out, "not run by cosim (neither recorded, set nor connected): {}", each.join(", "));
    }
}

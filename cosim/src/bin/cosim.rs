//! `cosim`: run an FMU or a system of FMUs, or list what is in one.

use clap::{Parser, Subcommand};
use nigel_cosim::{Algorithm, Error, Experiment, Fmu, ImportOptions, Interface, System, SystemBuilder};
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
    },
}

#[derive(clap::Args)]
struct RunArgs {
    /// The .fmu, .ssp or .ssd file.
    model: PathBuf,
    /// FMI interface: cs (Co-Simulation) or me (Model Exchange); default: cs if the FMU has it.
    #[arg(long)]
    interface: Option<String>,
    /// Start time, s.
    #[arg(long, default_value_t = 0.0)]
    start_time: f64,
    /// Stop time, s (default: the FMU's DefaultExperiment, else 1).
    #[arg(long)]
    stop_time: Option<f64>,
    /// Communication step, s (default: the FMU's DefaultExperiment stepSize, else 1e-3).
    #[arg(long)]
    step: Option<f64>,
    /// ordered or jacobi.
    #[arg(long, default_value = "jacobi")]
    algorithm: String,
    /// Model Exchange solver: rk4 or dopri5.
    #[arg(long, default_value = "rk4")]
    solver: String,
    /// Relative tolerance of dopri5 (absolute: rtol / 100).
    #[arg(long, default_value_t = 1e-6)]
    rtol: f64,
    /// Largest RK4 step, s (default: the communication step).
    #[arg(long)]
    max_step: Option<f64>,
    /// The cap on the steps of a run (communication steps, and the Model Exchange
    /// integrator's internal steps): a run that would take more stops with an error.
    #[arg(long, default_value_t = nigel_cosim::simulate::DEFAULT_MAX_STEPS)]
    max_steps: u64,
    /// Run every FMU in a host process of its own (`cosim-host`): a crash, an exit or a
    /// hang of an FMU is then an error naming it, with the rows so far written.
    #[arg(long)]
    isolate: bool,
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
    /// CSV file of the results (fmpy's format).
    #[arg(long, short)]
    output: Option<PathBuf>,
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
}

fn main() -> ExitCode {
    nigel_cosim::unpack::remove_on_signals();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => run(*args),
        Command::Info { model } => info(&model),
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

fn qualify(name: &str, single: bool) -> String {
    if single && !name.starts_with(&format!("{SINGLE}.")) {
        format!("{SINGLE}.{name}")
    } else {
        name.to_string()
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
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let k = nigel_benchmark::gain_file::read_gain_json(&text, &path.display().to_string()).map_err(Error::Experiment)?;
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
    let options = ImportOptions { interface, ..ImportOptions::default() };
    let (mut builder, default_stop, default_step, single, _ssp) = if is_ssp(&args.model) {
        let ssp = nigel_cosim::read_ssp(&args.model, &ImportOptions::default())?;
        let builder = SystemBuilder::from_system(ssp.system.clone());
        (builder, ssp.default_start_stop.1, None, false, Some(ssp))
    } else {
        let fmu = Fmu::load_with(&args.model, &options)?;
        let default = fmu.description().default_experiment.clone().unwrap_or_default();
        let mut builder = SystemBuilder::new();
        builder.add_instance(SINGLE, fmu)?;
        (builder, default.stop_time, default.step_size, true, None)
    };
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
    let mut experiment =
        Experiment::new(args.stop_time.or(default_stop).unwrap_or(1.0), args.step.or(default_step).unwrap_or(1e-3));
    experiment.start_time = args.start_time;
    experiment.algorithm = algorithm;
    experiment.solver = match args.solver.as_str() {
        "rk4" => nigel_cosim::Solver::Rk4 { max_step: args.max_step },
        "dopri5" if args.rtol > 0.0 && args.rtol.is_finite() => {
            nigel_cosim::Solver::Dopri5 { rtol: args.rtol, atol: args.rtol / 100.0 }
        }
        "dopri5" => return Err(Error::Experiment(format!("--rtol {} must be positive", args.rtol))),
        other => return Err(Error::Experiment(format!("unknown solver {other:?} (rk4, dopri5)"))),
    };
    if args.max_step.is_some_and(|m| !(m > 0.0 && m.is_finite())) {
        return Err(Error::Experiment("--max-step must be positive".into()));
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
    if args.timeout_call.is_some() && !args.isolate {
        return Err(Error::Experiment(
            "--timeout-call needs --isolate (a call in this process cannot be stopped; a host process can be killed)"
                .into(),
        ));
    }
    if args.isolate {
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
    let (results, outcome) = nigel_cosim::simulate::simulate_recorded(&system, &experiment);
    let write = |path: &Path, f: &dyn Fn(std::fs::File) -> std::io::Result<()>| {
        std::fs::File::create(path).and_then(f).map_err(|source| Error::Io { path: path.to_path_buf(), source })
    };
    // the rows recorded so far are written also when the run failed
    if let Some(path) = &args.output {
        if outcome.is_ok() || results.rows() > 0 {
            write(path, &|f| results.write_csv(std::io::BufWriter::new(f)))?;
            if outcome.is_err() {
                eprintln!("cosim: {} rows up to the last completed step written to {}", results.rows(), path.display());
            }
        }
    }
    let summary = outcome?;
    let json = serde_json::to_string_pretty(&summary.to_json()).unwrap_or_default();
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

fn is_ssp(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ssp") || e.eq_ignore_ascii_case("ssd"))
}

fn info_ssp(path: &Path) -> Result<(), Error> {
    use std::io::Write;
    let ssp = nigel_cosim::read_ssp(path, &ImportOptions::default())?;
    let s = &ssp.system;
    let mut out = std::io::stdout().lock();
    let mut lines = vec![format!(
        "system {} ({} instances, {} connections)",
        path.display(),
        s.instances.len(),
        s.connections.len()
    )];
    for i in &s.instances {
        lines.push(format!("instance {:<20} {} ({})", i.name, i.fmu.source().display(), i.fmu.interface().as_str()));
        for (index, v) in &i.start_values {
            lines.push(format!("  start {} = {v:?}", i.fmu.description().model_variables[*index].name));
        }
    }
    for c in &s.connections {
        let unit = |r: &nigel_cosim::VariableRef| s.variable(r).variable_type.unit().unwrap_or("-").to_string();
        lines.push(format!(
            "connection {} [{}] -> {} [{}]  (x {} + {})",
            s.name_of(&c.from),
            unit(&c.from),
            s.name_of(&c.to),
            unit(&c.to),
            c.gain,
            c.offset
        ));
    }
    for l in lines {
        if writeln!(out, "{l}").is_err() {
            break;
        }
    }
    Ok(())
}

fn info(path: &Path) -> Result<(), Error> {
    if is_ssp(path) {
        return info_ssp(path);
    }
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
    let fmu = Fmu::load(path)?;
    let md = fmu.description();
    w!(out, "model {} (FMI {}), guid {}", md.model_name, md.fmi_version, md.guid);
    let cs = md.co_simulation.as_ref().map(|c| c.model_identifier.as_str());
    let me = md.model_exchange.as_ref().map(|c| c.model_identifier.as_str());
    w!(
        out,
        "interfaces: {}{}",
        cs.map(|id| format!("CoSimulation ({id}) ")).unwrap_or_default(),
        me.map(|id| format!("ModelExchange ({id})")).unwrap_or_default()
    );
    w!(out, "continuous states: {}, event indicators: {}", md.states().len(), md.number_of_event_indicators);
    if let Some(d) = &md.default_experiment {
        w!(
            out,
            "default experiment: start {:?}, stop {:?}, step {:?}, tolerance {:?}",
            d.start_time,
            d.stop_time,
            d.step_size,
            d.tolerance
        );
    }
    w!(out, "{:<28} {:<20} {:<11} {:<8} {:<10} start", "name", "causality", "variability", "type", "unit");
    for v in &md.model_variables {
        let start = match &v.variable_type {
            model_description::VariableType::Real { start, .. } => start.map(|x| x.to_string()),
            model_description::VariableType::Integer { start, .. } => start.map(|x| x.to_string()),
            model_description::VariableType::Enumeration { start, declared_type, .. } => start.map(|x| {
                let item = md.type_definitions.iter().find(|t| &t.name == declared_type).and_then(|t| t.item(x));
                match item {
                    Some(item) => format!("{x} ({})", item.name),
                    None => x.to_string(),
                }
            }),
            model_description::VariableType::Boolean { start } => start.map(|x| x.to_string()),
            model_description::VariableType::String { start } => start.clone(),
        };
        w!(
            out,
            "{:<28} {:<20} {:<11} {:<8} {:<10} {}",
            v.name,
            v.causality.as_str(),
            v.variability.as_str(),
            v.variable_type.type_name(),
            v.variable_type.unit().unwrap_or("-"),
            start.unwrap_or_default()
        );
    }
    Ok(())
}

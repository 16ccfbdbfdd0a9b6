//! `nigel_cosim._native`: the Rust half of the Python package `nigel_cosim`.
//!
//! A thin layer over the `nigel-cosim` and `nigel-campaign` libraries: it loads an FMU or
//! an SSP once ([`NativeSystem`]), runs experiments on it with the interpreter's lock
//! released, and turns the master's errors into the package's exception classes. The
//! fmpy-compatible keyword handling, the structured arrays and the DataFrame live in the
//! Python half (`nigel_cosim/__init__.py`), where users can read them.
//!
//! A whole run happens on a worker thread while the calling thread waits without the GIL,
//! waking every 100 ms to let Python handle signals: Ctrl-C sets the run's cancel flag, the
//! run stops at its next step, its instances are freed, and `KeyboardInterrupt` is raised.
//! A run stepped from Python ([`NativeRun`]) is an [`Execution`] advanced in the calling
//! thread, the GIL released for at most 100 ms at a time between signal checks.

use model_description::DefaultExperiment;
use nigel_cosim::defaults::{GivenTimes, RunTimes};
use nigel_cosim::{
    simulate::{default_record, run_to_end, Execution, Phase},
    Error as CosimError, Experiment, Fmu, ImportOptions, InputTable, InstancePool, Interface, Results, Solver, Summary,
    System, SystemBuilder,
};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

create_exception!(nigel_cosim, Error, PyException, "Every error of nigel_cosim, with the master's message.");
create_exception!(
    nigel_cosim,
    LoadError,
    Error,
    "An FMU or SSP could not be loaded: a missing or malformed file, a hostile archive, a missing binary."
);
create_exception!(
    nigel_cosim,
    VariableError,
    Error,
    "A variable or instance name that does not exist (with a suggestion), or a value it cannot take."
);
create_exception!(
    nigel_cosim,
    SimulationError,
    Error,
    "The run failed: an FMU returned an error, crashed in its host process, or an event iteration did not converge."
);
create_exception!(
    nigel_cosim,
    ExperimentError,
    Error,
    "The experiment cannot be run as given (times, step, output interval, solver)."
);
create_exception!(nigel_cosim, RunTimeoutError, Error, "The run took longer than its `timeout`.");
create_exception!(nigel_cosim, CampaignError, Error, "A campaign description or its run failed.");

/// The Python exception of a master error.
fn to_py(e: CosimError) -> PyErr {
    let message = e.to_string();
    use nigel_cosim::ImportError as I;
    use CosimError as E;
    match e {
        E::Import(
            I::Io { .. }
            | I::NotRegularFile { .. }
            | I::Archive { .. }
            | I::UnsafeEntry { .. }
            | I::ArchiveLimit { .. }
            | I::ModelDescription { .. }
            | I::NoInterface { .. }
            | I::MissingBinary { .. }
            | I::LoadLibrary { .. }
            | I::MissingSymbol { .. },
        )
        | E::Ssp { .. } => LoadError::new_err(message),
        E::UnknownVariable { .. }
        | E::NotInView { .. }
        | E::UnknownInstance { .. }
        | E::NoInstance { .. }
        | E::Import(I::InvalidValue { .. })
        | E::Connection { .. } => VariableError::new_err(message),
        E::Timeout { .. } => RunTimeoutError::new_err(message),
        E::Experiment(_) => ExperimentError::new_err(message),
        _ => SimulationError::new_err(message),
    }
}

/// An FMU (one instance called `model`) or an SSP system, loaded and unpacked once.
#[pyclass(module = "nigel_cosim._native", frozen)]
struct NativeSystem {
    /// `None` once closed.
    system: Mutex<Option<System>>,
    /// Instances kept between runs (reset, not re-instantiated).
    pool: Mutex<InstancePool>,
    /// The name of the one instance of a single FMU (`None` for an SSP).
    single: Option<String>,
    /// DefaultExperiment: start, stop, step, tolerance.
    default_experiment: (Option<f64>, Option<f64>, Option<f64>, Option<f64>),
    /// `CoSimulation` / `ModelExchange` of each interface the (single) FMU offers.
    interfaces: Vec<&'static str>,
    /// What reading an SSP noted (`nigel_cosim::SspSystem::notes`; `cosim run` prints them).
    notes: Vec<String>,
}

const SINGLE: &str = "model";

fn is_ssp(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ssp") || e.eq_ignore_ascii_case("ssd"))
}

/// (start, stop, step, relative tolerance) as the Python half takes them.
fn times_tuple(t: RunTimes) -> (f64, f64, f64, Option<f64>) {
    (t.start_time, t.stop_time, t.step, t.relative_tolerance)
}

fn interface_name(i: Interface) -> &'static str {
    match i {
        Interface::CoSimulation => "CoSimulation",
        Interface::ModelExchange => "ModelExchange",
    }
}

/// The arguments of one run, resolved by the Python half.
#[derive(FromPyObject)]
struct RunArgs {
    start_time: f64,
    stop_time: f64,
    step: f64,
    output_interval: Option<f64>,
    algorithm: String,
    start_values: Vec<(String, String)>,
    input: Option<(Vec<String>, Vec<f64>, Vec<Vec<f64>>)>,
    output: Option<Vec<String>>,
    solver: String,
    /// The largest step of `rk4` (fmpy's `step_size` in Model Exchange); None: the communication step.
    max_step: Option<f64>,
    relative_tolerance: Option<f64>,
    timeout: Option<f64>,
    threads: usize,
}

impl NativeSystem {
    /// The system name of `name`: for a single FMU, `model.<name>`.
    fn qualify(&self, name: &str) -> String {
        match &self.single {
            Some(instance) => format!("{instance}.{name}"),
            None => name.to_string(),
        }
    }

    fn experiment_defaults(&self) -> DefaultExperiment {
        let (start_time, stop_time, step_size, tolerance) = self.default_experiment;
        DefaultExperiment { start_time, stop_time, step_size, tolerance }
    }

    /// The system of a run (a copy of this one with `args.start_values` set) and its experiment.
    fn run_setup(&self, args: &RunArgs) -> PyResult<(System, Experiment)> {
        let system = {
            let guard = self.system.lock().unwrap_or_else(|p| p.into_inner());
            guard.clone().ok_or_else(|| Error::new_err("the system is closed"))?
        };
        let mut builder = SystemBuilder::from_system(system);
        for (name, value) in &args.start_values {
            builder.set_text(&self.qualify(name), value).map_err(to_py)?;
        }
        Ok((builder.build(), self.experiment(args).map_err(to_py)?))
    }

    fn experiment(&self, args: &RunArgs) -> Result<Experiment, CosimError> {
        let mut experiment = Experiment::new(args.stop_time, args.step);
        experiment.start_time = args.start_time;
        experiment.output_interval = args.output_interval;
        experiment.algorithm = args.algorithm.parse().map_err(CosimError::Experiment)?;
        let rtol = args.relative_tolerance.unwrap_or(1e-5);
        if !(rtol > 0.0 && rtol.is_finite()) {
            return Err(CosimError::Experiment(format!("relative_tolerance {rtol} must be positive")));
        }
        // fmpy tells Co-Simulation FMUs the relative tolerance (given, else the
        // DefaultExperiment's, filled in by the caller)
        experiment.co_simulation_tolerance = args.relative_tolerance;
        experiment.solver = match args.solver.as_str() {
            "rk4" => {
                if args.max_step.is_some_and(|m| !(m > 0.0 && m.is_finite())) {
                    return Err(CosimError::Experiment(format!(
                        "step_size {} must be a positive number of seconds",
                        args.max_step.unwrap_or_default()
                    )));
                }
                Solver::Rk4 { max_step: args.max_step }
            }
            "dopri5" => Solver::Dopri5 { rtol, atol: rtol / 100.0 },
            "bdf" => Solver::Bdf { rtol, atol: rtol / 100.0 },
            other => {
                return Err(CosimError::Experiment(format!("unknown solver {other:?} (rk4, dopri5, bdf)")));
            }
        };
        if let Some((names, time, columns)) = &args.input {
            experiment.input = Some(Arc::new(InputTable::new(names.clone(), time.clone(), columns.clone())?));
        }
        if let Some(output) = &args.output {
            experiment.record = Some(output.iter().map(|n| self.qualify(n)).collect());
        }
        if let Some(t) = args.timeout {
            experiment.timeout =
                Some(Duration::try_from_secs_f64(t).ok().filter(|d| !d.is_zero()).ok_or_else(|| {
                    CosimError::Experiment(format!("timeout {t} must be a positive number of seconds"))
                })?);
        }
        if args.threads == 0 {
            return Err(CosimError::Experiment("threads must be at least 1".into()));
        }
        experiment.threads = args.threads;
        Ok(experiment)
    }
}

/// The base type name of each recorded column (`Real`, `Integer`, `Boolean`).
fn column_types(system: &System, results: &Results, single: Option<&str>) -> Vec<&'static str> {
    results
        .names
        .iter()
        .map(|n| {
            let full = match single {
                Some(instance) => format!("{instance}.{n}"),
                None => n.clone(),
            };
            system.resolve(&full).map(|r| r.base_type.as_str()).unwrap_or("Real")
        })
        .collect()
}

/// Runs `f` on a worker thread while this thread waits without the GIL, handling signals
/// every 100 ms; on a Python exception (Ctrl-C) sets `cancel`, waits for the run to stop
/// and returns the exception.
fn interruptible<T: Send>(py: Python<'_>, cancel: &AtomicBool, f: impl FnOnce() -> T + Send) -> PyResult<T> {
    std::thread::scope(|scope| {
        let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
        // a Receiver is not Sync; the waits below borrow it from the GIL-free closures
        let done_rx = Mutex::new(done_rx);
        let worker = scope.spawn(move || {
            let out = f();
            let _ = done_tx.send(());
            out
        });
        loop {
            let finished = py.detach(|| {
                let rx = done_rx.lock().unwrap_or_else(|p| p.into_inner());
                rx.recv_timeout(Duration::from_millis(100)).is_ok() || worker.is_finished()
            });
            if finished {
                break;
            }
            if let Err(e) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                let _ = py.detach(|| worker.join());
                return Err(e);
            }
        }
        py.detach(|| worker.join()).map_err(|_| SimulationError::new_err("the run panicked (a defect of nigel_cosim)"))
    })
}

#[pymethods]
impl NativeSystem {
    /// Loads an `.fmu` (as one instance named `model`) or an `.ssp`/`.ssd`.
    #[new]
    #[pyo3(signature = (filename, fmi_type=None))]
    fn new(py: Python<'_>, filename: PathBuf, fmi_type: Option<&str>) -> PyResult<NativeSystem> {
        let interface = match fmi_type {
            None => None,
            Some("CoSimulation") => Some(Interface::CoSimulation),
            Some("ModelExchange") => Some(Interface::ModelExchange),
            Some(other) => {
                return Err(PyValueError::new_err(format!(
                    "fmi_type must be 'CoSimulation' or 'ModelExchange', not {other:?}"
                )))
            }
        };
        let options = ImportOptions { interface, ..ImportOptions::default() };
        py.detach(|| {
            if is_ssp(&filename) {
                let ssp = nigel_cosim::read_ssp(&filename, &options)?;
                let (start, stop) = ssp.default_start_stop;
                Ok(NativeSystem {
                    system: Mutex::new(Some(ssp.system)),
                    pool: Mutex::new(InstancePool::new()),
                    single: None,
                    default_experiment: (start, stop, None, None),
                    interfaces: Vec::new(),
                    notes: ssp.notes,
                })
            } else {
                let fmu = Fmu::load_with(&filename, &options)?;
                let d = fmu.description().default_experiment.clone().unwrap_or_default();
                let md = fmu.description();
                let mut interfaces = Vec::new();
                if md.co_simulation.is_some() {
                    interfaces.push(interface_name(Interface::CoSimulation));
                }
                if md.model_exchange.is_some() {
                    interfaces.push(interface_name(Interface::ModelExchange));
                }
                let interfaces = match interface {
                    Some(i) => vec![interface_name(i)],
                    None => interfaces,
                };
                let system = System::single(SINGLE, fmu.clone())?;
                Ok(NativeSystem {
                    system: Mutex::new(Some(system)),
                    pool: Mutex::new(InstancePool::new()),
                    single: Some(SINGLE.to_string()),
                    default_experiment: (d.start_time, d.stop_time, d.step_size, d.tolerance),
                    interfaces,
                    notes: Vec::new(),
                })
            }
        })
        .map_err(to_py)
    }

    /// What reading an SSP noted: values ignored by the standard's rules, units taken as
    /// written, an SSD of the 2.0 draft (`cosim run` prints the same lines).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.notes.clone()
    }

    /// (start, stop, step, tolerance) of the DefaultExperiment, each None when absent.
    #[getter]
    fn default_experiment(&self) -> (Option<f64>, Option<f64>, Option<f64>, Option<f64>) {
        self.default_experiment
    }

    /// (start, stop, communication step, relative tolerance) of a run of the master: the
    /// arguments given (None: left out), the rest from the DefaultExperiment
    /// (`nigel_cosim::defaults::RunTimes::master`).
    #[pyo3(signature = (start_time, stop_time, step_size, relative_tolerance))]
    fn run_times(
        &self,
        start_time: Option<f64>,
        stop_time: Option<f64>,
        step_size: Option<f64>,
        relative_tolerance: Option<f64>,
    ) -> (f64, f64, f64, Option<f64>) {
        let given = GivenTimes { start_time, stop_time, step_size, output_interval: None, relative_tolerance };
        times_tuple(RunTimes::master(&self.experiment_defaults(), &given))
    }

    /// The same as fmpy's `simulate_fmu` fills it in, the communication step being fmpy's
    /// output interval (`nigel_cosim::defaults::RunTimes::fmpy`).
    #[pyo3(signature = (co_simulation, start_time, stop_time, step_size, output_interval, relative_tolerance))]
    fn fmpy_times(
        &self,
        co_simulation: bool,
        start_time: Option<f64>,
        stop_time: Option<f64>,
        step_size: Option<f64>,
        output_interval: Option<f64>,
        relative_tolerance: Option<f64>,
    ) -> (f64, f64, f64, Option<f64>) {
        let given = GivenTimes { start_time, stop_time, step_size, output_interval, relative_tolerance };
        times_tuple(RunTimes::fmpy(&self.experiment_defaults(), co_simulation, &given))
    }

    /// The interfaces a single FMU is run with (`CoSimulation` first), empty for an SSP.
    #[getter]
    fn interfaces(&self) -> Vec<&'static str> {
        self.interfaces.clone()
    }

    /// One tuple per variable: (name, type, causality, variability, start as text or None,
    /// unit or None, description or None); names are `instance.variable` for an SSP.
    fn variables(
        &self,
    ) -> PyResult<Vec<(String, String, String, String, Option<String>, Option<String>, Option<String>)>> {
        let guard = self.system.lock().unwrap_or_else(|p| p.into_inner());
        let system = guard.as_ref().ok_or_else(|| Error::new_err("the system is closed"))?;
        let mut out = Vec::new();
        for spec in &system.instances {
            let md = spec.fmu.description();
            for v in &md.model_variables {
                let name = if self.single.is_some() { v.name.clone() } else { format!("{}.{}", spec.name, v.name) };
                let start = match &v.variable_type {
                    model_description::VariableType::Real { start, .. } => start.map(|x| format!("{x:?}")),
                    model_description::VariableType::Integer { start, .. }
                    | model_description::VariableType::Enumeration { start, .. } => start.map(|x| x.to_string()),
                    model_description::VariableType::Boolean { start } => start.map(|x| x.to_string()),
                    model_description::VariableType::String { start } => start.clone(),
                };
                out.push((
                    name,
                    v.variable_type.type_name().to_string(),
                    v.causality.as_str().to_string(),
                    v.variability.as_str().to_string(),
                    start,
                    v.variable_type.unit().map(str::to_string),
                    v.description.clone(),
                ));
            }
        }
        Ok(out)
    }

    /// Runs one experiment; returns (column names, column types, values as a rows x
    /// (1 + columns) float64 array with time first, the run's summary as JSON text).
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        args: RunArgs,
    ) -> PyResult<(Vec<String>, Vec<&'static str>, Bound<'py, PyAny>, String)> {
        let (system, experiment) = self.run_setup(&args)?;
        let cancel = Arc::new(AtomicBool::new(false));
        let outcome: Result<(Results, Summary), CosimError> = interruptible(py, &cancel, || {
            let mut pool = self.pool.lock().unwrap_or_else(|p| p.into_inner());
            let mut execution = Execution::new(&system, &experiment)?.with_pool(&mut pool);
            execution.cancel_on(cancel.clone());
            let summary = run_to_end(&mut execution)?;
            Ok((execution.take_results(), summary))
        })?;
        let (results, summary) = outcome.map_err(to_py)?;
        let types = column_types(&system, &results, self.single.as_deref());
        let (rows, width) = (results.rows(), results.width());
        let array = PyArray1::from_vec(py, results.values).reshape([rows, width])?;
        let json = serde_json::to_string(&summary.to_json()).unwrap_or_default();
        Ok((results.names, types, array.into_any(), json))
    }

    /// The step-longer-than-sample-period warnings of a run with `args` (the same words as
    /// `cosim run`'s, with the keyword that sets the step): the Python side raises them as
    /// `warnings.warn`.
    fn sample_period_warnings(&self, args: RunArgs) -> PyResult<Vec<String>> {
        let (system, experiment) = self.run_setup(&args)?;
        Ok(nigel_cosim::sample_period::warnings(&system, experiment.step)
            .iter()
            .map(|w| format!("{w} (use step_size={})", w.period))
            .collect())
    }

    /// Starts a run stepped from outside ([`NativeRun`]): instantiated and initialized, paused
    /// at the start time. The recorded variables are `args.output` or every output.
    fn start(&self, py: Python<'_>, args: RunArgs) -> PyResult<NativeRun> {
        let (system, mut experiment) = self.run_setup(&args)?;
        let record: Vec<String> = match &experiment.record {
            Some(names) => names.clone(),
            None => default_record(&system).iter().map(|r| system.name_of(r)).collect(),
        };
        let mut types = Vec::with_capacity(record.len());
        for name in &record {
            types.push(system.resolve(name).map_err(to_py)?.base_type.as_str());
        }
        experiment.record = Some(record.clone());
        let names: Vec<String> = match &self.single {
            Some(instance) => {
                record.iter().map(|n| n.strip_prefix(&format!("{instance}.")).unwrap_or(n).to_string()).collect()
            }
            None => record.clone(),
        };
        NativeRun::start(py, system, experiment, names, types, self.single.clone())
    }

    /// Frees the instances and the FMUs, removing their unpacked folders; the object cannot
    /// run again.
    fn close(&self) {
        *self.pool.lock().unwrap_or_else(|p| p.into_inner()) = InstancePool::new();
        *self.system.lock().unwrap_or_else(|p| p.into_inner()) = None;
    }

    /// Whether `close` was called.
    #[getter]
    fn closed(&self) -> bool {
        self.system.lock().unwrap_or_else(|p| p.into_inner()).is_none()
    }
}

/// A run stepped from Python: an [`Execution`] advanced in the calling thread to the first
/// output point at or after the time asked for, the rows so far kept, values set between
/// steps applied before the next step ([`Execution::set`]).
#[pyclass(module = "nigel_cosim._native", frozen)]
struct NativeRun {
    /// Recorded columns (bare names for a single FMU) and their base types.
    names: Vec<String>,
    types: Vec<&'static str>,
    single: Option<String>,
    execution: Mutex<Execution<'static>>,
    /// The summary, once the run has reached its end and terminated its instances.
    summary: Mutex<Option<Summary>>,
}

/// Whether `t` has reached `target` (fmpy's `isclose` with its defaults for the last bit).
fn reached(t: f64, target: f64) -> bool {
    t >= target || (t - target).abs() <= 1e-9 * t.abs().max(target.abs())
}

/// How long the GIL is released at a time while a stepped run advances (then Python
/// handles its signals: Ctrl-C).
const SIGNAL_CHECK: Duration = Duration::from_millis(100);

impl NativeRun {
    fn start(
        py: Python<'_>,
        system: System,
        experiment: Experiment,
        names: Vec<String>,
        types: Vec<&'static str>,
        single: Option<String>,
    ) -> PyResult<NativeRun> {
        let mut execution = Execution::new(&system, &experiment).map_err(to_py)?;
        py.detach(|| execution.initialize()).map_err(to_py)?;
        let run = NativeRun { names, types, single, execution: Mutex::new(execution), summary: Mutex::new(None) };
        run.finish_at_end()?;
        Ok(run)
    }

    fn execution(&self) -> std::sync::MutexGuard<'_, Execution<'static>> {
        self.execution.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// At the end of the run (its stop time, or an FMU ended it): the instances terminated
    /// and the summary kept.
    fn finish_at_end(&self) -> PyResult<()> {
        let mut execution = self.execution();
        if execution.phase() == Phase::AtEnd {
            let summary = execution.finish().map_err(to_py)?;
            *self.summary.lock().unwrap_or_else(|p| p.into_inner()) = Some(summary);
        }
        Ok(())
    }
}

#[pymethods]
impl NativeRun {
    /// The time of the last recorded row (the run is paused there, or ended there).
    #[getter]
    fn time(&self) -> f64 {
        self.execution().last_row_time().unwrap_or(f64::NAN)
    }

    /// Whether the run has ended (its stop time, an FMU's terminate request, `terminate`).
    #[getter]
    fn finished(&self) -> bool {
        self.execution().phase() != Phase::Running
    }

    /// Runs on to the first output point at or after `time` (the stop time at most).
    fn step_until(&self, py: Python<'_>, time: f64) -> PyResult<f64> {
        if !time.is_finite() {
            return Err(PyValueError::new_err(format!("step_until({time}): the time must be finite")));
        }
        if self.finished() {
            return Err(Error::new_err("the run has ended (initialize a new one)"));
        }
        loop {
            let done = py.detach(|| -> Result<bool, CosimError> {
                let mut execution = self.execution();
                let start = Instant::now();
                loop {
                    let paused = execution.at_output_point() && reached(execution.time(), time);
                    if paused || execution.phase() != Phase::Running {
                        return Ok(true);
                    }
                    if start.elapsed() > SIGNAL_CHECK {
                        return Ok(false);
                    }
                    execution.step()?;
                }
            });
            match done {
                Ok(true) => break,
                Ok(false) => {
                    if let Err(e) = py.check_signals() {
                        self.execution().stop();
                        return Err(e);
                    }
                }
                Err(e) => return Err(to_py(e)),
            }
        }
        self.finish_at_end()?;
        Ok(self.time())
    }

    /// The recorded value of `name` at the current time.
    fn get(&self, name: &str) -> PyResult<f64> {
        let j = self.names.iter().position(|n| n == name).ok_or_else(|| {
            VariableError::new_err(format!("{name:?} is not recorded in this run (add it to output=)"))
        })?;
        let row = self.execution().last_row().ok_or_else(|| Error::new_err("the run has no row yet"))?;
        Ok(row[1 + j])
    }

    /// Sets an input or tunable parameter from the next communication step on.
    fn set(&self, name: &str, value: &str) -> PyResult<()> {
        if self.finished() {
            return Err(Error::new_err("the run has ended (initialize a new one)"));
        }
        let full = match &self.single {
            Some(instance) => format!("{instance}.{name}"),
            None => name.to_string(),
        };
        self.execution().set(&full, value).map_err(to_py)
    }

    /// (names, types, rows so far as a rows x (1 + columns) array).
    fn results<'py>(&self, py: Python<'py>) -> PyResult<(Vec<String>, Vec<&'static str>, Bound<'py, PyAny>)> {
        let values = self.execution().results().values;
        let width = self.names.len() + 1;
        let rows = values.len() / width;
        let array = PyArray1::from_vec(py, values).reshape([rows, width])?;
        Ok((self.names.clone(), self.types.clone(), array.into_any()))
    }

    /// Ends the run (terminating and freeing its instances); the summary as JSON text, or
    /// None when it was ended before its stop time.
    fn terminate(&self) -> Option<String> {
        self.execution().stop();
        self.summary
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .as_ref()
            .and_then(|s| serde_json::to_string(&s.to_json()).ok())
    }
}

/// Runs a campaign into `out`: `spec` is the description's `.toml` path, or `spec_text`
/// the description's TOML text (a dict from Python, written by the Python half in its
/// order, into a temporary file; relative paths from the current folder, as for a file). Returns (results.csv path, runs, failed runs). The runs are threads of this
/// process (`threads`, default all cores); failed runs are rows with their status.
#[pyfunction]
#[pyo3(signature = (spec, spec_text, out, threads=None, shard=None, progress=false))]
fn run_campaign(
    py: Python<'_>,
    spec: Option<PathBuf>,
    spec_text: Option<String>,
    out: PathBuf,
    threads: Option<usize>,
    shard: Option<(u64, u64)>,
    progress: bool,
) -> PyResult<(PathBuf, u64, u64)> {
    let campaign_error = |e: nigel_campaign::Error| CampaignError::new_err(e.to_string());
    // a description given as a dict: the same TOML a user would write, in a temporary file
    let written;
    let path = match (spec, spec_text) {
        (Some(path), None) => path,
        (None, Some(text)) => {
            let mut file = tempfile::Builder::new()
                .prefix("nigel-campaign-")
                .suffix(".toml")
                .tempfile()
                .map_err(|e| CampaignError::new_err(format!("writing the description: {e}")))?;
            std::io::Write::write_all(&mut file, text.as_bytes())
                .map_err(|e| CampaignError::new_err(format!("writing the description: {e}")))?;
            written = file;
            written.path().to_path_buf()
        }
        _ => return Err(PyValueError::new_err("give either a description path or a dict")),
    };
    let spec = nigel_campaign::spec::Spec::load(&path).map_err(campaign_error)?;
    let mut options = nigel_campaign::run::Options::new(out.clone());
    options.threads = threads;
    options.shard = shard;
    options.progress = progress;
    options.allow_failures = true;
    // Ctrl-C: no further run starts; the runs in progress finish and the rows so far are
    // written to `out` (a later run with the same `out` would resume them)
    let cancel = Arc::new(AtomicBool::new(false));
    options.cancel = Some(cancel.clone());
    let done = interruptible(py, &cancel, || nigel_campaign::run::run(&spec, &options))?.map_err(campaign_error)?;
    Ok((out.join("results.csv"), done.ran, done.failed))
}

/// Compares the results CSV `result` with the baseline CSV `baseline` in tolerance tubes
/// (`cosim compare`); with `plot`, a PNG per failing signal into that folder. Returns the
/// report as a dict: `passed`, `tolerance`, `signals` (per signal `name`, `passed`,
/// `points`, `violations`, `worst` (`time`, `value`, `lower`, `upper`, `excess`) or None,
/// `problem`, `detail`), `notes`, `lines` (as `cosim compare` prints them), `figures`.
#[pyfunction]
#[pyo3(signature = (result, baseline, rtol=1e-3, atol=1e-6, time_tol=0.0, signals=None, plot=None))]
#[allow(clippy::too_many_arguments)]
fn compare<'py>(
    py: Python<'py>,
    result: PathBuf,
    baseline: PathBuf,
    rtol: f64,
    atol: f64,
    time_tol: f64,
    signals: Option<Vec<String>>,
    plot: Option<PathBuf>,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    use nigel_cosim::compare;
    use pyo3::types::PyDict;
    let tolerance = compare::Tolerance { rtol, atol, time_tol };
    let bad = |e: String| PyValueError::new_err(e);
    let r = compare::csv::read_results_csv(&result).map_err(bad)?;
    let b = compare::csv::read_results_csv(&baseline).map_err(bad)?;
    let c = compare::compare(&r, &b, &tolerance, signals.as_deref()).map_err(bad)?;
    let figures = match &plot {
        Some(dir) => compare::plot::plot_failures(&r, &b, &c, dir).map_err(bad)?,
        None => Vec::new(),
    };
    let out = PyDict::new(py);
    out.set_item("passed", c.passed())?;
    let tol = PyDict::new(py);
    tol.set_item("rtol", rtol)?;
    tol.set_item("atol", atol)?;
    tol.set_item("time_tol", time_tol)?;
    out.set_item("tolerance", tol)?;
    let mut each = Vec::new();
    for s in &c.signals {
        let d = PyDict::new(py);
        d.set_item("name", &s.name)?;
        d.set_item("passed", s.passed)?;
        d.set_item("points", s.points)?;
        d.set_item("violations", s.violations)?;
        match &s.worst {
            Some(w) => {
                let wd = PyDict::new(py);
                wd.set_item("time", w.time)?;
                wd.set_item("value", w.value)?;
                wd.set_item("lower", w.lower)?;
                wd.set_item("upper", w.upper)?;
                wd.set_item("excess", w.excess)?;
                d.set_item("worst", wd)?;
            }
            None => d.set_item("worst", py.None())?,
        }
        d.set_item("problem", s.problem.clone())?;
        d.set_item("detail", s.detail())?;
        each.push(d);
    }
    out.set_item("signals", each)?;
    out.set_item("notes", c.notes.clone())?;
    out.set_item("lines", c.lines())?;
    out.set_item("figures", figures)?;
    Ok(out)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<NativeSystem>()?;
    m.add_class::<NativeRun>()?;
    m.add_function(wrap_pyfunction!(run_campaign, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add("Error", py.get_type::<Error>())?;
    m.add("LoadError", py.get_type::<LoadError>())?;
    m.add("VariableError", py.get_type::<VariableError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("ExperimentError", py.get_type::<ExperimentError>())?;
    m.add("RunTimeoutError", py.get_type::<RunTimeoutError>())?;
    m.add("CampaignError", py.get_type::<CampaignError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

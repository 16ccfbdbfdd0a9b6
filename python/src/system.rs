//! `NativeSystem`: an FMU or an SSP loaded once, run as a whole or started as a stepped run.

use crate::errors::{to_py, Error};
use crate::interrupt::interruptible;
use crate::run_args::RunArgs;
use crate::stepped_run::{exact_columns, NativeRun};
use model_description::DefaultExperiment;
use nigel_cosim::defaults::{GivenTimes, RunTimes};
use nigel_cosim::run_setup::{run_in_process, InProcess, PreparedRun, RunSetup};
use nigel_cosim::{
    simulate::default_record, Error as CosimError, Experiment, ImportOptions, InstancePool, Interface, Results,
    Summary, System, VariableRef,
};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

/// An FMU (one instance called `model`) or an SSP system, loaded and unpacked once.
#[pyclass(module = "nigel_cosim._native", frozen)]
pub(crate) struct NativeSystem {
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

/// (start, stop, step, relative tolerance) as the Python half takes them.
fn times_tuple(t: RunTimes) -> (f64, f64, f64, Option<f64>) {
    (t.start_time, t.stop_time, t.step, t.relative_tolerance)
}

impl NativeSystem {
    fn experiment_defaults(&self) -> DefaultExperiment {
        let (start_time, stop_time, step_size, tolerance) = self.default_experiment;
        DefaultExperiment { start_time, stop_time, step_size, tolerance }
    }

    /// The system of a run (a copy of this one with `args.start_values` set, by the names
    /// `cosim run --set` takes) and its experiment.
    fn run_setup(&self, args: &RunArgs) -> PyResult<(PreparedRun, Experiment)> {
        let system = {
            let guard = self.system.lock().unwrap_or_else(|p| p.into_inner());
            guard.clone().ok_or_else(|| Error::new_err("the system is closed"))?
        };
        let mut setup = RunSetup::of_system(system, self.experiment_defaults(), self.single.is_some());
        for (name, value) in &args.start_values {
            setup.set(name, value).map_err(to_py)?;
        }
        let prepared = setup.build();
        if args.output.is_none() {
            // every output left out of the master's view: a result of the time column alone
            // is not what was asked for (as `cosim run`)
            prepared.check_recordable("output").map_err(to_py)?;
        }
        let experiment = args.experiment(|n| prepared.qualify(n)).map_err(to_py)?;
        Ok((prepared, experiment))
    }
}

/// The type name of each recorded column: `Real`, `Integer`, `Boolean`, `String`, or
/// `Int64` / `UInt64` for an FMI 3.0 64-bit integer (whose values the results hold exactly,
/// as text: [`Results::exact`]).
fn column_types(system: &System, results: &Results, single: Option<&str>) -> Vec<&'static str> {
    results
        .names
        .iter()
        .map(|n| {
            let full = match single {
                Some(instance) => format!("{instance}.{n}"),
                None => n.clone(),
            };
            system.resolve(&full).map(|r| column_type(system, &r)).unwrap_or("Real")
        })
        .collect()
}

/// The type name of a recorded variable (see [`column_types`]).
pub(crate) fn column_type(system: &System, r: &VariableRef) -> &'static str {
    use nigel_cosim::fmi3::ExactKind;
    match system.instances[r.instance].fmu.exact_kind(r.value_reference) {
        Some(ExactKind::Int64) => "Int64",
        Some(ExactKind::UInt64) => "UInt64",
        _ => r.base_type.as_str(),
    }
}

#[pymethods]
impl NativeSystem {
    /// Loads an `.fmu` (as one instance named `model`) or an `.ssp`/`.ssd`;
    /// `use_event_mode` (fmpy's name): FMI 3.0 Co-Simulation Event Mode, `None` where an
    /// FMU needs it (its clocks), else always (`True`) or never (`False`).
    #[new]
    #[pyo3(signature = (filename, fmi_type=None, use_event_mode=None))]
    fn new(
        py: Python<'_>,
        filename: PathBuf,
        fmi_type: Option<&str>,
        use_event_mode: Option<bool>,
    ) -> PyResult<NativeSystem> {
        let interface = match fmi_type {
            None => None,
            Some(name) => Some(Interface::from_element_name(name).ok_or_else(|| {
                PyValueError::new_err(format!(
                    "fmi_type must be 'CoSimulation', 'ModelExchange' or 'ScheduledExecution', not {name:?}"
                ))
            })?),
        };
        let event_mode = nigel_cosim::EventModeChoice::from_flag(use_event_mode);
        let options = ImportOptions { interface, event_mode, ..ImportOptions::default() };
        py.detach(|| {
            let setup = RunSetup::load(&filename, &options)?;
            let d = setup.default_experiment().clone();
            let notes = setup.notes().to_vec();
            // the interfaces a single FMU is run with: the one asked for, else each it has
            let interfaces = match (setup.single_fmu(), interface) {
                (None, _) => Vec::new(),
                (Some(_), Some(i)) => vec![i.as_str()],
                (Some(fmu), None) => {
                    let md = fmu.description();
                    let mut interfaces = Vec::new();
                    if md.co_simulation.is_some() {
                        interfaces.push(Interface::CoSimulation.as_str());
                    }
                    if md.model_exchange.is_some() {
                        interfaces.push(Interface::ModelExchange.as_str());
                    }
                    if fmu.fmi3_description().is_some_and(|md3| md3.scheduled_execution.is_some()) {
                        interfaces.push(Interface::ScheduledExecution.as_str());
                    }
                    interfaces
                }
            };
            let single = setup.single_fmu().map(|_| nigel_cosim::run_setup::SINGLE.to_string());
            Ok::<_, CosimError>(NativeSystem {
                system: Mutex::new(Some(setup.build().system)),
                pool: Mutex::new(InstancePool::new()),
                single,
                default_experiment: (d.start_time, d.stop_time, d.step_size, d.tolerance),
                interfaces,
                notes,
            })
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
    /// (1 + columns) float64 array with time first, the run's summary as JSON text, the
    /// exact columns as (column, text of every row)).
    #[allow(clippy::type_complexity)]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        args: RunArgs,
    ) -> PyResult<(Vec<String>, Vec<&'static str>, Bound<'py, PyAny>, String, Vec<(usize, Vec<String>)>)> {
        let (prepared, experiment) = self.run_setup(&args)?;
        let system = &prepared.system;
        let cancel = Arc::new(AtomicBool::new(false));
        let outcome: Result<(Results, Summary), CosimError> = interruptible(py, &cancel, || {
            let mut pool = self.pool.lock().unwrap_or_else(|p| p.into_inner());
            let watch = InProcess { pool: Some(&mut pool), cancel: Some(cancel.clone()), progress: None };
            let (results, outcome) = run_in_process(system, &experiment, &[], watch);
            Ok((results, outcome?))
        })?;
        let (results, summary) = outcome.map_err(to_py)?;
        let types = column_types(system, &results, self.single.as_deref());
        let exact = exact_columns(&results);
        let (rows, width) = (results.rows(), results.width());
        let array = PyArray1::from_vec(py, results.values).reshape([rows, width])?;
        let json = serde_json::to_string(&summary.to_json()).unwrap_or_default();
        Ok((results.names, types, array.into_any(), json, exact))
    }

    /// The step-longer-than-sample-period warnings of a run with `args` (the same words as
    /// `cosim run`'s, with the keyword that sets the step): the Python side raises them as
    /// `warnings.warn`.
    fn sample_period_warnings(&self, args: RunArgs) -> PyResult<Vec<String>> {
        let (prepared, experiment) = self.run_setup(&args)?;
        Ok(nigel_cosim::sample_period::warnings(&prepared.system, experiment.step)
            .iter()
            .map(|w| format!("{w} (use step_size={})", w.period))
            .collect())
    }

    /// Starts a run stepped from outside ([`NativeRun`]): instantiated and initialized, paused
    /// at the start time. The recorded variables are `args.output` or every output.
    fn start(&self, py: Python<'_>, args: RunArgs) -> PyResult<NativeRun> {
        let (prepared, mut experiment) = self.run_setup(&args)?;
        let system = &prepared.system;
        let record: Vec<String> = match &experiment.record {
            Some(names) => names.clone(),
            None => default_record(system).iter().map(|r| system.name_of(r)).collect(),
        };
        let mut types = Vec::with_capacity(record.len());
        for name in &record {
            types.push(column_type(system, &system.resolve(name).map_err(to_py)?));
        }
        experiment.record = Some(record.clone());
        let names: Vec<String> = record.iter().map(|n| prepared.column(n)).collect();
        NativeRun::start(py, prepared.system, experiment, names, types, self.single.clone())
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

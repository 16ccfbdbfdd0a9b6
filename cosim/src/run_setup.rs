//! The preparation of a run as a front end asks for it (`cosim run`, the Python package):
//! the model loaded (an FMU as the one instance [`SINGLE`] of a system, or an SSP), the
//! values set by the names the user writes (bare for a single FMU), the start time rule,
//! what the results will leave out (notes) and a run that could record nothing refused, the
//! recorded columns extended by what checks and baselines read, and the run in this process
//! (stepped, or in Scheduled Execution). Front ends parse their arguments, print what this
//! returns in their own words, and write the results.

use crate::defaults::{GivenTimes, RunTimes};
use crate::error::{Error, Result};
use crate::simulate::{default_record, is_scheduled, Execution, Experiment, InstancePool, Summary, TimedSet};
use crate::{Fmu, ImportOptions, Results, SspSystem, System, SystemBuilder};
use model_description::DefaultExperiment;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// The instance name of a single FMU run as a system.
pub const SINGLE: &str = "model";

/// A model loaded for a run, its values being set: a single FMU or an SSP system.
pub struct RunSetup {
    builder: SystemBuilder,
    default: DefaultExperiment,
    single: Option<Arc<Fmu>>,
    notes: Vec<String>,
    timed_sets: Vec<TimedSet>,
    /// The SSP read (kept for as long as its system runs).
    _ssp: Option<SspSystem>,
}

impl RunSetup {
    /// Loads `model`: an `.ssp` or `.ssd` (`options.interface` applies to each of its FMUs),
    /// else an FMU as the one instance [`SINGLE`].
    pub fn load(model: &Path, options: &ImportOptions) -> Result<RunSetup> {
        let mut setup = RunSetup::load_model(model, options)?;
        // an Event Mode choice that applies to none of the model's FMUs is said, not dropped
        let instances = &setup.system().instances;
        if options.event_mode != crate::EventModeChoice::Auto && instances.iter().all(|i| i.fmu.event_mode().is_none())
        {
            setup.notes.push(format!(
                "event mode {} does not apply: it chooses eventModeUsed of FMI 3.0 Co-Simulation FMUs, and the model \
                 has none (FMI 2.0 Co-Simulation has no Event Mode; Model Exchange always has it)",
                options.event_mode.as_str()
            ));
        }
        Ok(setup)
    }

    /// [`RunSetup::load`] without its note.
    fn load_model(model: &Path, options: &ImportOptions) -> Result<RunSetup> {
        if crate::info::is_ssp(model) {
            let ssp = crate::read_ssp(model, options)?;
            let (start_time, stop_time) = ssp.default_start_stop;
            Ok(RunSetup {
                builder: SystemBuilder::from_system(ssp.system.clone()),
                default: DefaultExperiment { start_time, stop_time, ..Default::default() },
                single: None,
                notes: ssp.notes.clone(),
                timed_sets: Vec::new(),
                _ssp: Some(ssp),
            })
        } else {
            let fmu = Fmu::load_with(model, options)?;
            RunSetup::single(fmu)
        }
    }

    /// A single FMU as the one instance [`SINGLE`].
    pub fn single(fmu: Arc<Fmu>) -> Result<RunSetup> {
        let default = fmu.description().default_experiment.clone().unwrap_or_default();
        let mut builder = SystemBuilder::new();
        builder.add_instance(SINGLE, fmu.clone())?;
        Ok(RunSetup { builder, default, single: Some(fmu), notes: Vec::new(), timed_sets: Vec::new(), _ssp: None })
    }

    /// A system loaded before (`single`: it is one FMU, its instance named [`SINGLE`]), to
    /// run again with other values.
    pub fn of_system(system: System, default: DefaultExperiment, single: bool) -> RunSetup {
        let single = single.then(|| system.instances[0].fmu.clone());
        let builder = SystemBuilder::from_system(system);
        RunSetup { builder, default, single, notes: Vec::new(), timed_sets: Vec::new(), _ssp: None }
    }

    /// What reading an SSP noted ([`SspSystem::notes`]).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The DefaultExperiment: an FMU's, or an SSD's start and stop time.
    pub fn default_experiment(&self) -> &DefaultExperiment {
        &self.default
    }

    /// The FMU of a single-FMU run.
    pub fn single_fmu(&self) -> Option<&Arc<Fmu>> {
        self.single.as_ref()
    }

    /// The system as set so far.
    pub fn system(&self) -> &System {
        self.builder.system()
    }

    /// The system name of `name` as the user writes it ([`qualify`]).
    pub fn qualify(&self, name: &str) -> String {
        qualify(name, self.single.as_deref())
    }

    /// Sets `name` (as the user writes it) to `text` before the run.
    pub fn set(&mut self, name: &str, text: &str) -> Result<()> {
        let name = self.qualify(name);
        self.set_system_name(&name, text)
    }

    /// Sets the system variable `name` (`instance.variable`, also for a single FMU) to `text`.
    pub fn set_system_name(&mut self, name: &str, text: &str) -> Result<()> {
        self.builder.set_text(name, text)?;
        Ok(())
    }

    /// Sets `name` (as the user writes it) to `text` from the first step starting at or after
    /// `time` s; a structural parameter sizes its arrays for this value too. `label` is how
    /// the front end names this setting in an error (`--set-at 1 n=3`).
    pub fn set_at(&mut self, time: f64, name: &str, text: &str, label: &str) -> Result<()> {
        let name = self.qualify(name);
        let system = self.builder.system();
        if system.resolve(&name).is_ok_and(|r| system.is_structural(&r)) {
            let value: f64 = text
                .trim()
                .parse()
                .map_err(|_| Error::Experiment(format!("{label}: a structural parameter's value is a number")))?;
            self.builder.size_for(&name, value)?;
        }
        self.timed_sets.push(TimedSet { time, name, text: text.to_string() });
        Ok(())
    }

    /// The values set during the run so far.
    pub fn timed_sets(&self) -> &[TimedSet] {
        &self.timed_sets
    }

    /// The times of a run of the master with `given` ([`RunTimes::master`]); the start time is
    /// the given one, else an SSD's DefaultExperiment's (SSP 1.0 gives only start and stop),
    /// else 0: never an FMU's DefaultExperiment's.
    pub fn times(&self, given: &GivenTimes) -> RunTimes {
        let ssd_start = if self.single.is_none() { self.default.start_time } else { None };
        let given = GivenTimes { start_time: Some(given.start_time.or(ssd_start).unwrap_or(0.0)), ..*given };
        RunTimes::master(&self.default, &given)
    }

    /// The system with its values set.
    pub fn build(self) -> PreparedRun {
        PreparedRun { system: self.builder.build(), single: self.single, timed_sets: self.timed_sets, _ssp: self._ssp }
    }
}

/// The system name of `name`: for a single FMU its variable (an exact variable name wins,
/// so a variable called `model.beta` is not read as `beta` of the instance), else as given.
pub fn qualify(name: &str, single: Option<&Fmu>) -> String {
    match single {
        Some(fmu) if fmu.description().variable(name).is_some() => format!("{SINGLE}.{name}"),
        Some(_) if !name.starts_with(&format!("{SINGLE}.")) => format!("{SINGLE}.{name}"),
        _ => name.to_string(),
    }
}

/// A system ready to run, with the values to set during the run.
pub struct PreparedRun {
    /// The system.
    pub system: System,
    single: Option<Arc<Fmu>>,
    /// Values set during the run (in process only).
    pub timed_sets: Vec<TimedSet>,
    _ssp: Option<SspSystem>,
}

/// The recorded columns of a run: those asked for, and those its checks and baseline read.
#[derive(Clone, Debug, PartialEq)]
pub struct Columns {
    /// The system names asked for (given, else every output).
    pub asked: Vec<String>,
    /// `asked` and then what the checks and the baseline read.
    pub record: Vec<String>,
}

impl Columns {
    /// Whether the checks or the baseline read columns that were not asked for (left out
    /// of the results written).
    pub fn extra(&self) -> bool {
        self.record.len() > self.asked.len()
    }
}

impl PreparedRun {
    /// The FMU of a single-FMU run.
    pub fn single_fmu(&self) -> Option<&Fmu> {
        self.single.as_deref()
    }

    /// The system name of `name` as the user writes it ([`qualify`]).
    pub fn qualify(&self, name: &str) -> String {
        qualify(name, self.single.as_deref())
    }

    /// The results' column of the system variable `name` (a single FMU's columns are bare).
    pub fn column(&self, name: &str) -> String {
        match self.single {
            Some(_) => name.strip_prefix(&format!("{SINGLE}.")).unwrap_or(name).to_string(),
            None => name.to_string(),
        }
    }

    /// The experiment of `options` (times resolved, e.g. by [`RunSetup::times`]), with times
    /// a run cannot mean refused before anything is loaded into an FMU; errors name options
    /// as `option_name` spells them ([`crate::options::cli_option_name`]).
    pub fn experiment(
        &self,
        options: &crate::options::RunOptions,
        option_name: impl Fn(&str) -> String,
    ) -> Result<Experiment> {
        let experiment = options.experiment(&option_name)?;
        check_times(&experiment, &option_name)?;
        Ok(experiment)
    }

    /// What the results will not hold of the FMI 3.0 FMUs: an fmiVersion later than 3.0,
    /// variables outside the master's view (clocks are run and counted, not recorded).
    pub fn view_notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        for instance in &self.system.instances {
            if let Some(version) = instance.fmu.fmi3_description().map(|md| md.fmi_version.as_str()) {
                if version != "3.0" && !version.starts_with("3.0.") {
                    notes.push(format!(
                        "{} declares fmiVersion \"{version}\": run as FMI 3.0 (what a later version adds is unknown to cosim)",
                        instance.name
                    ));
                }
            }
            for (name, why) in instance.fmu.not_in_view().iter().filter(|(_, why)| *why != crate::fmi3::LeftOut::Clock)
            {
                notes.push(format!(
                    "{}.{name} is {}: not recorded (outside the master's view)",
                    instance.name,
                    why.as_str()
                ));
            }
        }
        notes
    }

    /// Refuses a run of every output (none named to record) whose outputs are all out of the
    /// master's view: a result of the time column alone is not what was asked for.
    /// `record_option` is the front end's option naming variables to record.
    pub fn check_recordable(&self, record_option: &str) -> Result<()> {
        if !default_record(&self.system).is_empty() {
            return Ok(());
        }
        let output = |fmu: &Fmu, name: &str| {
            fmu.fmi3_description()
                .and_then(|md| md.variable_by_name(name))
                .is_some_and(|v| v.causality == model_description::fmi3::Causality::Output)
        };
        let left_out: Vec<String> = self
            .system
            .instances
            .iter()
            .flat_map(|i| {
                i.fmu
                    .not_in_view()
                    .iter()
                    .filter(|(name, _)| output(&i.fmu, name))
                    .map(move |(name, why)| format!("{}.{name} ({})", i.name, why.as_str()))
            })
            .collect();
        if left_out.is_empty() {
            return Ok(());
        }
        Err(Error::Experiment(format!(
            "no output of the system can be recorded: {} (name variables to record with {record_option})",
            left_out.join(", ")
        )))
    }

    /// The columns of a run recording `record` (as the user writes the names; empty: every
    /// output), then the variables each check reads (`checks`: the front end's label of the
    /// check and the names it reads; one that is no variable is an error `label: why`), then
    /// the baseline's columns that are variables (`compared`; the others are reported
    /// missing by the comparison).
    pub fn columns(
        &self,
        record: &[String],
        checks: &[(String, Vec<String>)],
        compared: &[String],
    ) -> std::result::Result<Columns, String> {
        let asked: Vec<String> = if record.is_empty() {
            default_record(&self.system).iter().map(|r| self.system.name_of(r)).collect()
        } else {
            record.iter().map(|r| self.qualify(r)).collect()
        };
        let mut record = asked.clone();
        for (label, variables) in checks {
            for v in variables {
                let q = self.qualify(v);
                self.system.resolve(&q).map_err(|e| format!("{label}: {e}"))?;
                if !record.contains(&q) {
                    record.push(q);
                }
            }
        }
        for name in compared {
            let q = self.qualify(name);
            if self.system.resolve(&q).is_ok() && !record.contains(&q) {
                record.push(q);
            }
        }
        Ok(Columns { asked, record })
    }

    /// Whether the run is one FMU's model partitions in Scheduled Execution.
    pub fn is_scheduled(&self) -> bool {
        is_scheduled(&self.system)
    }
}

/// Times a run cannot mean: a stop time not after the start time, a step longer than the run.
fn check_times(e: &Experiment, option_name: impl Fn(&str) -> String) -> Result<()> {
    let span = e.stop_time - e.start_time;
    if span.is_nan() || span <= 0.0 {
        return Err(Error::Experiment(format!(
            "the stop time {} s must be after the start time {} s ({}, {})",
            e.stop_time,
            e.start_time,
            option_name("stop_time"),
            option_name("start_time")
        )));
    }
    if e.step > span {
        return Err(Error::Experiment(format!(
            "the step {} s is longer than the run ({span} s from {} to {} s): choose a {} of at most {span}",
            e.step,
            e.start_time,
            e.stop_time,
            option_name("step")
        )));
    }
    Ok(())
}

/// How a run in this process is watched: instances kept between runs, a flag that stops it
/// at its next step, a report of its progress (0 to 1).
#[derive(Default)]
pub struct InProcess<'a> {
    /// Instances reset and reused rather than instantiated (stepped runs only).
    pub pool: Option<&'a mut InstancePool>,
    /// Set to stop the run at its next step ([`Error::Cancelled`]).
    pub cancel: Option<Arc<AtomicBool>>,
    /// Called with the fraction of the run done (stepped runs only).
    pub progress: Option<fn(f64)>,
}

/// Runs `system` in this process to the end: in Scheduled Execution if it is one FMU's
/// model partitions, else stepped with `timed_sets` set on the way; the rows recorded also
/// when the run failed.
pub fn run_in_process(
    system: &System,
    experiment: &Experiment,
    timed_sets: &[TimedSet],
    how: InProcess,
) -> (Results, Result<Summary>) {
    if is_scheduled(system) {
        return crate::simulate::simulate_scheduled(system, experiment);
    }
    let execution = match Execution::new(system, experiment) {
        Ok(e) => e,
        Err(e) => return (Results::default(), Err(e)),
    };
    let mut execution = match how.pool {
        Some(pool) => execution.with_pool(pool),
        None => execution,
    };
    if let Some(report) = how.progress {
        execution.on_progress(report);
    }
    if let Some(flag) = how.cancel {
        execution.cancel_on(flag);
    }
    let outcome = crate::simulate::run_to_end_with(&mut execution, timed_sets);
    (execution.take_results(), outcome)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_a_run_cannot_mean_are_named_in_the_front_ends_spelling() {
        let mut e = Experiment::new(0.5, 1e-3);
        e.start_time = 1.0;
        let message = check_times(&e, crate::options::cli_option_name).unwrap_err().to_string();
        assert!(message.contains("the stop time 0.5 s must be after the start time 1 s (--stop-time, --start-time)"));
        // a step of 2 s in a run of 1 s (0 to 1 s)
        let e = Experiment::new(1.0, 2.0);
        let message = check_times(&e, |n| n.to_string()).unwrap_err().to_string();
        assert!(message.contains("the step 2 s is longer than the run (1 s from 0 to 1 s): choose a step of at most 1"));
        assert!(check_times(&Experiment::new(1.0, 1.0), crate::options::cli_option_name).is_ok());
    }
}

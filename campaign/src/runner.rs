//! One run after another in this process: a loaded system reused for every run of one
//! worker ([`Worker`]), the experiment every run shares and the variables its metrics read.

use std::time::{Duration, Instant};

use nigel_cosim::{simulate, simulate_with, Experiment, InstancePool, Results, System};

use crate::results::{
    Row, STATUS_CHECK_FAILED, STATUS_ENDED, STATUS_FAILED, STATUS_OK, STATUS_PANICKED, STATUS_TIMEOUT,
};
use crate::spec::{load_system, RunValues, Spec};
use crate::Error;
use nigel_cosim::check::CheckAccumulators;
use nigel_cosim::metric::Accumulators;

/// The experiment of every run: the description's times (from the SSD's start time) and
/// algorithm, recording only the metrics' variables.
pub fn experiment(spec: &Spec, record: Vec<String>) -> Experiment {
    let mut e = Experiment::new(spec.stop_time, spec.step);
    e.start_time = spec.start_time;
    e.algorithm = spec.algorithm;
    e.record = Some(record);
    e.timeout = spec.timeout;
    e
}

/// The variables the metrics read, then those only the checks read.
pub fn metric_variables(spec: &Spec) -> Vec<String> {
    let mut vars: Vec<String> = Vec::new();
    let read = spec.metrics.iter().map(|(_, m)| m.variables()).chain(spec.checks.iter().map(|(_, c)| c.variables()));
    for v in read.flatten() {
        if !vars.contains(&v) {
            vars.push(v);
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
        Ok(Worker::with_system(spec, base))
    }

    /// With the description's system already loaded.
    pub fn with_system(spec: &'a Spec, base: System) -> Worker<'a> {
        let record = metric_variables(spec);
        let experiment = experiment(spec, record.clone());
        Worker { spec, base, record, experiment, pool: InstancePool::new(), timing: Default::default() }
    }

    /// Asks the system whether it can run the description's stop time: run 0's instances
    /// are instantiated, set up with the stop time (`fmi2SetupExperiment`), given run 0's
    /// start values and initialized, then freed (FMI 2.0 lets an FMU refuse a stop time it
    /// cannot reach there; the test bench refuses one past its `duration`). An instance
    /// that refuses is asked again with the stop time left undefined: only if it then
    /// accepts is the stop time the cause, and `Err` names the instance and its message
    /// (a refusal for another reason is left to the run, whose row says it). Inputs keep
    /// their start values (no connection is propagated), so this is the instances' own
    /// verdict, not a run.
    pub fn check_stop_time(&self) -> Result<(), String> {
        use nigel_cosim::{simulate::apply_start_values, Instance};
        let Ok(system) = self.spec.system_of(&self.base, &self.spec.values(0)) else { return Ok(()) };
        let start = self.experiment.start_time;
        let init = |spec: &nigel_cosim::system::InstanceSpec, stop: Option<f64>| -> Result<(), nigel_cosim::Error> {
            let mut inst = Instance::new(&spec.fmu, &spec.name)?;
            inst.setup_experiment(None, start, stop)?;
            apply_start_values(&mut inst, spec)?;
            inst.enter_initialization_mode()?;
            inst.exit_initialization_mode()?;
            Ok(inst.terminate()?)
        };
        for spec in &system.instances {
            if let Err(e) = init(spec, Some(self.spec.stop_time)) {
                if init(spec, None).is_ok() {
                    return Err(format!(
                        "stop_time = {} s is past what the system can run: {} refuses it with run 0's values ({e})",
                        self.spec.stop_time, spec.name
                    ));
                }
            }
        }
        Ok(())
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
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| -> Result<Judged, (String, bool)> {
            let system = self.spec.system_of(&self.base, &values).map_err(|e| (e, false))?;
            let mut acc = Accumulators::new(self.spec.metrics.iter().map(|(_, m)| m), &self.record);
            let checks: Vec<_> = self.spec.checks.iter().map(|(_, c)| c.clone()).collect();
            let mut judge = CheckAccumulators::new(&checks, &self.record).map_err(|e| (e, false))?;
            // the metrics: every row after the first, the communication points t_1 .. t_N;
            // the checks: every row, t_0 .. t_N (as `cosim run --check`)
            let mut first = true;
            let mut sink = |_t: f64, row: &[f64], _: &[(usize, String)]| {
                judge.push(row);
                if first {
                    first = false;
                } else {
                    acc.push(row);
                }
            };
            // the master's time limit (checked between steps) is the run's timeout
            let (_, summary) = simulate_with(&system, &self.experiment, Some(&mut self.pool), Some(&mut sink))
                .map_err(|e| (e.to_string(), matches!(e, nigel_cosim::Error::Timeout { .. })))?;
            inside = summary.wall_time;
            // an FMU that ends the run before the stop time: the metrics cover fewer points
            let ended = summary.ended_by.map(|(instance, t, reason)| {
                format!("ended at t = {t} s by {instance} ({reason}), before the stop time")
            });
            let failed_checks: Vec<String> = self
                .spec
                .checks
                .iter()
                .zip(judge.verdicts())
                .filter(|(_, v)| !v.holds)
                .map(|((name, _), v)| format!("check {name}: {}", v.failure()))
                .collect();
            Ok((acc.values(), ended, failed_checks))
        }));
        let (status, message, metrics) = match outcome {
            Ok(Ok((m, None, failed))) if failed.is_empty() => (STATUS_OK, String::new(), m),
            // an FMU that ended the run early outranks the checks (which saw fewer points)
            Ok(Ok((m, Some(ended), _))) => (STATUS_ENDED, ended, m),
            Ok(Ok((m, None, failed))) => (STATUS_CHECK_FAILED, failed.join("; "), m),
            Ok(Err((e, true))) => (STATUS_TIMEOUT, e, nan_metrics()),
            Ok(Err((e, false))) => (STATUS_FAILED, e, nan_metrics()),
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

/// A completed run: its metrics, how an FMU ended it early (if one did), the checks it failed.
type Judged = (Vec<f64>, Option<String>, Vec<String>);

//! The loops over an [`Execution`]: [`simulate()`] and its variants run one from its
//! initialization to its end.

use crate::error::Result;
use crate::simulate::execution::{Execution, InstancePool};
use crate::simulate::observer::RowSink;
use crate::simulate::types::{Experiment, Results, Summary};
use crate::system::System;

/// Instantiates, initializes and runs `system` with fixed-step Co-Simulation.
pub fn simulate(system: &System, experiment: &Experiment) -> Result<(Results, Summary)> {
    let (results, summary) = simulate_recorded(system, experiment);
    summary.map(|s| (results, s))
}

/// [`simulate`], with the rows recorded up to the last completed step also when the run
/// fails (an FMU's error, a crashed host, a time limit): nothing recorded is lost.
pub fn simulate_recorded(system: &System, experiment: &Experiment) -> (Results, Result<Summary>) {
    match Execution::new(system, experiment) {
        Ok(mut execution) => {
            let summary = run_to_end(&mut execution);
            (execution.take_results(), summary)
        }
        Err(e) => (Results::default(), Err(e)),
    }
}

/// [`simulate()`] taking its instances from `pool` (each reset with `fmi2Reset` instead
/// of instantiated again; put back after a run that ends without error; not used for
/// isolated instances) and, with a `sink`, handing each row (time and the recorded
/// values) to it instead of keeping it: the [`Results`] then have the column names and no
/// rows. For many runs of one system (parameter studies): no new instantiation per run,
/// no recording held in memory.
pub fn simulate_with<'s>(
    system: &System,
    experiment: &Experiment,
    pool: Option<&'s mut InstancePool>,
    sink: Option<&'s mut RowSink<'s>>,
) -> Result<(Results, Summary)> {
    let mut execution = Execution::new(system, experiment)?;
    if let Some(pool) = pool {
        execution = execution.with_pool(pool);
    }
    if let Some(sink) = sink {
        execution = execution.with_sink(sink);
    }
    let summary = run_to_end(&mut execution)?;
    Ok((execution.take_results(), summary))
}

/// A value set during a run (`cosim run --set-at TIME NAME=VALUE`): `name`
/// (`instance.variable`) takes `text` before the first communication step that starts at or
/// after `time` s ([`Execution::set`]; a tunable structural parameter in Reconfiguration
/// Mode).
#[derive(Clone, Debug, PartialEq)]
pub struct TimedSet {
    /// When, s.
    pub time: f64,
    /// `instance.variable`.
    pub name: String,
    /// The value, as text of the variable's type.
    pub text: String,
}

/// [`run_to_end`] with the values `sets` set during the run, in time order.
pub fn run_to_end_with(execution: &mut Execution, sets: &[TimedSet]) -> Result<Summary> {
    execution.initialize()?;
    let mut sets: Vec<&TimedSet> = sets.iter().collect();
    sets.sort_by(|a, b| a.time.total_cmp(&b.time));
    for s in sets {
        execution.simulate_until(s.time)?;
        execution.set(&s.name, &s.text)?;
    }
    execution.simulate_to_end()?;
    execution.finish()
}

/// Initializes `execution`, steps it to its end and finishes it.
pub fn run_to_end(execution: &mut Execution) -> Result<Summary> {
    execution.initialize()?;
    execution.simulate_to_end()?;
    execution.finish()
}

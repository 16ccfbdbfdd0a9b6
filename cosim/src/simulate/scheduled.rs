//! FMI 3.0 Scheduled Execution of one FMU (`cosim run --interface se`): the master is the
//! FMU's scheduler. Each model partition (an input clock with a priority, see
//! [`crate::partitions`]) is activated with `fmi3ActivateModelPartition` at its clock's
//! ticks: periodic clocks every `intervalDecimal` from `shiftDecimal` after the start;
//! triggered clocks at the times an input file's column of the clock's name is nonzero;
//! countdown clocks when the FMU, during an activation, signals `clockUpdate` and
//! `fmi3GetIntervalDecimal` then says the interval changed: that long after the
//! activation's time. Ticks at one time go in priority order (smaller first, then document
//! order), a countdown of 0 s joining the ticks of its time. After each activation that
//! signalled `clockUpdate` the output clocks are read (`fmi3GetClock`).
//!
//! One partition runs at a time, on one thread: nothing preempts another, and the results
//! are the same on every run. Ticks are in [start, stop): a row is recorded at each time
//! some clock ticked (after all its activations), with a column per clock that is 1 when
//! it ticked then, and a last row at the stop time. The other columns of the input file
//! are set before the activations of each tick time (held from the last row at or before
//! it). The run's summary counts the activations of each partition and the ticks of each
//! output clock.

use crate::error::{Error, Result};
use crate::fmu::{Fmu, Instance, Interface};
use crate::partitions::{model_partitions, output_clocks, ModelPartition, Ticks};
use crate::simulate::{apply_start_values, Experiment, Results, Summary};
use crate::system::{BaseType, System, VariableRef};

/// Whether `system` is run in Scheduled Execution (an instance loaded for it).
pub fn is_scheduled(system: &System) -> bool {
    system.instances.iter().any(|i| i.fmu.interface() == Interface::ScheduledExecution)
}

/// A pending tick: time, priority, partition (index).
type Tick = (f64, u32, usize);

/// The schedule of the partitions' ticks not yet activated.
struct Schedule {
    pending: Vec<Tick>,
}

impl Schedule {
    /// Adds the tick (once: a clock ticks at most once at a time).
    fn push(&mut self, tick: Tick) {
        if !self.pending.iter().any(|p| p.0 == tick.0 && p.2 == tick.2) {
            self.pending.push(tick);
        }
    }

    /// The earliest tick (time, then priority, then partition), taken.
    fn pop(&mut self) -> Option<Tick> {
        let k = (0..self.pending.len()).min_by(|&a, &b| {
            let (x, y) = (self.pending[a], self.pending[b]);
            x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2))
        })?;
        Some(self.pending.swap_remove(k))
    }

    /// The time of the earliest tick.
    fn next_time(&self) -> Option<f64> {
        self.pending.iter().map(|p| p.0).min_by(f64::total_cmp)
    }
}

/// An input file's columns: the triggered clocks' ticks, and the variables set over time.
struct Inputs {
    /// (column, variable) of the columns that are variables.
    variables: Vec<(usize, VariableRef)>,
}

/// The tick `k` of a periodic clock: `start + shift + k interval` (a product, not a sum of
/// intervals: no drift).
fn periodic(start: f64, interval: f64, shift: f64, k: u64) -> f64 {
    start + shift + k as f64 * interval
}

/// Runs the one Scheduled Execution instance of `system` from `experiment.start_time` to
/// `experiment.stop_time` (see the module). The results are those recorded so far also
/// when the run fails.
pub fn simulate_scheduled(system: &System, experiment: &Experiment) -> (Results, Result<Summary>) {
    let mut results = Results::default();
    let outcome = run(system, experiment, &mut results);
    (results, outcome)
}

fn run(system: &System, experiment: &Experiment, results: &mut Results) -> Result<Summary> {
    let started = std::time::Instant::now();
    let [spec] = system.instances.as_slice() else {
        return Err(Error::Experiment(format!(
            "Scheduled Execution runs one FMU on its own; the system has {} instances",
            system.instances.len()
        )));
    };
    if experiment.isolation.is_some() {
        return Err(Error::Experiment(
            "Scheduled Execution runs in process: the FMU's callbacks are this process's (leave out --isolate)".into(),
        ));
    }
    let fmu: &std::sync::Arc<Fmu> = &spec.fmu;
    let md = fmu
        .fmi3_description()
        .ok_or_else(|| Error::Experiment(format!("{}: Scheduled Execution is FMI 3.0's", spec.name)))?;
    let bad = |m: String| Error::Experiment(format!("{}: {m}", spec.name));
    let partitions: Vec<ModelPartition> = model_partitions(md).map_err(bad)?;
    if partitions.is_empty() {
        return Err(bad("the FMU has no input clock, so no model partition to activate".into()));
    }
    let outputs = output_clocks(md);
    let (start, stop) = (experiment.start_time, experiment.stop_time);
    // the columns: the recorded variables, then a column per clock
    let record: Vec<VariableRef> = match &experiment.record {
        Some(names) => names.iter().map(|n| system.resolve(n)).collect::<Result<_>>()?,
        None => crate::simulate::default_record(system),
    };
    let bare = |r: &VariableRef| system.variable(r).name.clone();
    results.names = record.iter().map(bare).collect();
    results.names.extend(partitions.iter().map(|p| p.name.clone()));
    results.names.extend(outputs.iter().map(|(name, _)| name.clone()));
    // the input file: a column named as a triggered clock gives its ticks, the others set
    // variables
    let mut schedule = Schedule { pending: Vec::new() };
    let mut inputs = Inputs { variables: Vec::new() };
    if let Some(table) = &experiment.input {
        for (j, name) in table.names.iter().enumerate() {
            let bare_name = name.strip_prefix(&format!("{}.", spec.name)).unwrap_or(name);
            if let Some(p) = partitions.iter().position(|p| p.name == bare_name) {
                if partitions[p].ticks != Ticks::Triggered {
                    return Err(bad(format!(
                        "the input file's column {name:?} is clock {bare_name:?}, whose ticks are {} (only a triggered clock's ticks come from a file)",
                        partitions[p].ticks_text()
                    )));
                }
                for (t, v) in table.time.iter().zip(&table.columns[j]) {
                    if *v != 0.0 && *t >= start && *t < stop {
                        schedule.push((*t, partitions[p].priority, p));
                    }
                }
                continue;
            }
            let qualified = if name.contains('.') { name.clone() } else { format!("{}.{name}", spec.name) };
            inputs.variables.push((j, system.resolve(&qualified)?));
        }
    }
    let mut next_periodic: Vec<u64> = vec![0; partitions.len()];
    for (p, partition) in partitions.iter().enumerate() {
        if let Ticks::Periodic { interval, shift } = partition.ticks {
            let t = periodic(start, interval, shift, 0);
            if t < stop {
                schedule.push((t, partition.priority, p));
            }
            next_periodic[p] = 1;
        }
    }
    let mut instance = Instance::new(fmu, &spec.name)?;
    apply_start_values(&mut instance, spec)?;
    instance.setup_experiment(None, start, Some(stop))?;
    instance.enter_initialization_mode()?;
    instance.exit_initialization_mode()?;
    let mut activations = vec![0usize; partitions.len()];
    let mut output_ticks = vec![0usize; outputs.len()];
    let mut instants = 0u64;
    while let Some(t) = schedule.next_time().filter(|t| *t < stop) {
        if let Some(table) = &experiment.input {
            set_inputs(&mut instance, system, table, &inputs, t)?;
        }
        let mut ticked = vec![false; partitions.len() + outputs.len()];
        while schedule.next_time() == Some(t) {
            let Some((_, _, p)) = schedule.pop() else { break };
            let partition = &partitions[p];
            let update = instance.activate_model_partition(partition.clock, t)?;
            activations[p] += 1;
            ticked[p] = true;
            if let Ticks::Periodic { interval, shift } = partition.ticks {
                let next = periodic(start, interval, shift, next_periodic[p]);
                next_periodic[p] += 1;
                if next < stop {
                    schedule.push((next, partition.priority, p));
                }
            }
            if !update {
                continue;
            }
            for (c, countdown) in partitions.iter().enumerate().filter(|(_, c)| c.ticks == Ticks::Countdown) {
                if let Some(interval) = instance.countdown_interval(countdown.clock)? {
                    if t + interval < stop {
                        schedule.push((t + interval, countdown.priority, c));
                    }
                }
            }
            for (o, (_, clock)) in outputs.iter().enumerate() {
                if instance.output_clock_ticked(*clock)? {
                    output_ticks[o] += 1;
                    ticked[partitions.len() + o] = true;
                }
            }
        }
        instants += 1;
        record_row(&mut instance, &record, t, &ticked, results)?;
    }
    let last = results.values.len().checked_sub(results.width()).map(|k| results.values[k]);
    if last != Some(stop) {
        record_row(&mut instance, &record, stop, &vec![false; partitions.len() + outputs.len()], results)?;
    }
    instance.terminate()?;
    let counts: Vec<String> = partitions.iter().zip(&activations).map(|(p, n)| format!("{} {n}", p.name)).collect();
    let mut notes = vec![format!("Scheduled Execution: partitions activated: {}", counts.join(", "))];
    if !outputs.is_empty() {
        let ticks: Vec<String> =
            outputs.iter().zip(&output_ticks).map(|((name, _), n)| format!("{name} {n}")).collect();
        notes.push(format!("Scheduled Execution: output clocks ticked: {}", ticks.join(", ")));
    }
    let warnings = instance
        .take_log()
        .into_iter()
        .filter(|r| r.status == crate::Status::Warning)
        .map(|r| (spec.name.clone(), r.message))
        .collect();
    Ok(Summary { steps: instants, wall_time: started.elapsed(), notes, warnings, ..Summary::default() })
}

/// Sets the input file's variables to their values at `t` (held from the last row at or
/// before it; at a jump, the later row).
fn set_inputs(
    instance: &mut Instance,
    system: &System,
    table: &crate::simulate::InputTable,
    inputs: &Inputs,
    t: f64,
) -> Result<()> {
    for (j, r) in &inputs.variables {
        let x = table.value(*j, t, true, true);
        let vr = system.variable(r).value_reference;
        match r.base_type {
            BaseType::Real => instance.set_real(&[vr], &[x])?,
            BaseType::Integer => instance.set_integer(&[vr], &[x as i32])?,
            BaseType::Boolean => instance.set_boolean(&[vr], &[(x != 0.0) as i32])?,
            BaseType::String => {
                return Err(Error::Experiment(format!("input: {} is a String", system.name_of(r))));
            }
        }
    }
    Ok(())
}

/// Appends the row at `t`: the recorded variables, then 1 or 0 per clock.
fn record_row(
    instance: &mut Instance,
    record: &[VariableRef],
    t: f64,
    ticked: &[bool],
    results: &mut Results,
) -> Result<()> {
    let mut row = Vec::with_capacity(1 + record.len() + ticked.len());
    row.push(t);
    for r in record {
        let vr = [r.value_reference];
        let x = match r.base_type {
            BaseType::Real => {
                let mut v = [0.0];
                instance.get_real(&vr, &mut v)?;
                v[0]
            }
            BaseType::Integer => {
                let mut v = [0];
                instance.get_integer(&vr, &mut v)?;
                f64::from(v[0])
            }
            BaseType::Boolean => {
                let mut v = [0];
                instance.get_boolean(&vr, &mut v)?;
                f64::from(v[0])
            }
            BaseType::String => f64::NAN,
        };
        row.push(x);
    }
    row.extend(ticked.iter().map(|b| f64::from(u8::from(*b))));
    results.values.extend(row);
    Ok(())
}

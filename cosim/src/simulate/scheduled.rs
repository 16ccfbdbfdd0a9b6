//! FMI 3.0 Scheduled Execution (`cosim run --interface se`) of one FMU or of a system of
//! them (several instances, an SSP): the master is the FMUs' scheduler. Each model
//! partition (an input clock with a priority, see [`crate::partitions`]) is activated with
//! `fmi3ActivateModelPartition` at its clock's ticks: periodic clocks every interval from
//! their shift after the start (a `fixed` or `tunable` clock's interval is the one
//! `fmi3GetIntervalDecimal` gives after `fmi3ExitInitializationMode`, the description's
//! when the FMU gives none; a `tunable` clock's is read again whenever the FMU signals
//! `clockUpdate`, and a changed interval counts from that activation's time); triggered
//! clocks at the times an input file's column of the clock's name is nonzero, and when an
//! output clock connected to them ticks (at its activation's time); countdown clocks when
//! the FMU, during an activation, signals `clockUpdate` and `fmi3GetIntervalDecimal` then
//! says the interval changed: that long after the activation's time; changing clocks first
//! the interval `fmi3GetIntervalDecimal` gives in Initialization Mode after the start, then
//! each interval it gives right after an activation after that activation.
//!
//! The ticks of one time go in priority order across all instances (smaller first, then
//! the instances' order in the system, then document order), a countdown of 0 s or a
//! connected output clock's tick joining the ticks of its time (a clock is activated at most
//! once at a time). Before each activation the instance's connected inputs are set from
//! their sources' values at that moment (a clocked output holds the value of its
//! partition's last activation, a clocked input's set waits for its clock's activation), so
//! a partition sees what the partitions activated before it at the same time computed.
//! After each activation that signalled `clockUpdate` the output clocks are read
//! (`fmi3GetClock`).
//!
//! One partition runs at a time, on one thread: nothing preempts another, and the results
//! are the same on every run. Ticks are in [start, stop): a row is recorded at each time
//! some clock ticked (after all its activations), with a column per clock that is 1 when
//! it ticked then, and a last row at the stop time. The other columns of the input file
//! are set before the activations of each tick time (held from the last row at or before
//! it). The run's summary counts the activations of each partition and the ticks of each
//! output clock. With several instances, columns and counts name the instance
//! (`instance.clock`); with one, the clock's name alone.

use crate::clocks::ClockKind;
use crate::error::{Error, Result};
use crate::fmu::{Instance, Interface, Interval};
use crate::partitions::{model_partitions, output_clocks, ModelPartition, Ticks};
use crate::simulate::{apply_start_values, Experiment, InputTable, Results, Summary};
use crate::system::{BaseType, System, Value, VariableRef};

/// Why Scheduled Execution is not run isolated (`--isolate`, `--isolate=run`).
pub const NOT_ISOLATED: &str = "Scheduled Execution is run in process only (leave out --isolate): the FMU calls \
     the scheduler back from inside fmi3ActivateModelPartition (clockUpdate, lockPreemption, unlockPreemption), \
     which a host process cannot carry (it answers one call at a time and cannot call this process during one), \
     and --isolate=run streams the rows of a stepped run only";

/// Whether `system` is run in Scheduled Execution (an instance loaded for it).
pub fn is_scheduled(system: &System) -> bool {
    system.instances.iter().any(|i| i.fmu.interface() == Interface::ScheduledExecution)
}

/// A pending tick: time, priority, instance, partition (indices).
type Tick = (f64, u32, usize, usize);

/// The schedule of the partitions' ticks not yet activated.
struct Schedule {
    pending: Vec<Tick>,
}

impl Schedule {
    /// Adds the tick (once: a clock ticks at most once at a time).
    fn push(&mut self, tick: Tick) {
        if !self.pending.iter().any(|p| p.0 == tick.0 && p.2 == tick.2 && p.3 == tick.3) {
            self.pending.push(tick);
        }
    }

    /// The earliest tick (time, then priority, then instance, then partition), taken.
    fn pop(&mut self) -> Option<Tick> {
        let k = (0..self.pending.len()).min_by(|&a, &b| {
            let (x, y) = (self.pending[a], self.pending[b]);
            x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)).then(x.3.cmp(&y.3))
        })?;
        Some(self.pending.swap_remove(k))
    }

    /// The time of the earliest tick.
    fn next_time(&self) -> Option<f64> {
        self.pending.iter().map(|p| p.0).min_by(f64::total_cmp)
    }

    /// Drops the pending ticks of partition `p` of instance `m`.
    fn cancel(&mut self, m: usize, p: usize) {
        self.pending.retain(|x| !(x.2 == m && x.3 == p));
    }
}

/// The ticks of a periodic partition: `origin + k interval` for k = `next`, `next` + 1, ...
/// (a product, not a sum of intervals: no drift).
#[derive(Clone, Copy)]
struct Periodic {
    origin: f64,
    interval: f64,
    next: u64,
}

impl Periodic {
    /// The next tick's time, counted.
    fn take(&mut self) -> f64 {
        let t = self.origin + self.next as f64 * self.interval;
        self.next += 1;
        t
    }
}

/// One instance of the run: its partitions, output clocks and counts.
struct Member {
    instance: Instance,
    partitions: Vec<ModelPartition>,
    outputs: Vec<(String, u32)>,
    /// Per partition, the ticks of a periodic one.
    periodic: Vec<Option<Periodic>>,
    activations: Vec<usize>,
    output_ticks: Vec<usize>,
    /// Its first column among the clock columns.
    first_column: usize,
}

/// Runs the Scheduled Execution instances of `system` from `experiment.start_time` to
/// `experiment.stop_time` (see the module). The results are those recorded so far also
/// when the run fails.
pub fn simulate_scheduled(system: &System, experiment: &Experiment) -> (Results, Result<Summary>) {
    let mut results = Results::default();
    let outcome = run(system, experiment, &mut results);
    (results, outcome)
}

fn run(system: &System, experiment: &Experiment, results: &mut Results) -> Result<Summary> {
    let started = std::time::Instant::now();
    if experiment.isolation.is_some() {
        return Err(Error::Experiment(NOT_ISOLATED.into()));
    }
    if let Some(other) = system.instances.iter().find(|i| i.fmu.interface() != Interface::ScheduledExecution) {
        return Err(Error::Experiment(format!(
            "{} is not loaded for Scheduled Execution: a scheduled run activates partitions of FMUs loaded for it only \
             (--interface se for every FMU)",
            other.name
        )));
    }
    let single = system.instances.len() == 1;
    let mut members = Vec::with_capacity(system.instances.len());
    let mut width = 0;
    for spec in &system.instances {
        let bad = |m: String| Error::Experiment(format!("{}: {m}", spec.name));
        let md = spec.fmu.fmi3_description().ok_or_else(|| bad("Scheduled Execution is FMI 3.0's".into()))?;
        let partitions = model_partitions(md).map_err(bad)?;
        if partitions.is_empty() {
            return Err(bad("the FMU has no input clock, so no model partition to activate".into()));
        }
        let outputs = output_clocks(md);
        let first_column = width;
        width += partitions.len() + outputs.len();
        members.push((partitions, outputs, first_column));
    }
    let (start, stop) = (experiment.start_time, experiment.stop_time);
    // the columns: the recorded variables, then a column per clock
    let record: Vec<VariableRef> = match &experiment.record {
        Some(names) => names.iter().map(|n| system.resolve(n)).collect::<Result<_>>()?,
        None => crate::simulate::default_record(system),
    };
    let column =
        |i: usize, name: &str| if single { name.to_string() } else { format!("{}.{name}", system.instances[i].name) };
    results.names = record.iter().map(|r| column(r.instance, &system.variable(r).name)).collect();
    for (i, (partitions, outputs, _)) in members.iter().enumerate() {
        results.names.extend(partitions.iter().map(|p| column(i, &p.name)));
        results.names.extend(outputs.iter().map(|(name, _)| column(i, name)));
    }
    // the input file: a column named as a triggered clock gives its ticks, the others set
    // variables
    let mut schedule = Schedule { pending: Vec::new() };
    let mut input_variables: Vec<(usize, VariableRef)> = Vec::new();
    if let Some(table) = &experiment.input {
        for (j, name) in table.names.iter().enumerate() {
            let qualified = if single && !name.contains('.') {
                format!("{}.{name}", system.instances[0].name)
            } else {
                name.clone()
            };
            let clock = members.iter().enumerate().find_map(|(m, (partitions, _, _))| {
                let bare = qualified.strip_prefix(&format!("{}.", system.instances[m].name))?;
                Some((m, partitions.iter().position(|p| p.name == bare)?))
            });
            let Some((m, p)) = clock else {
                input_variables.push((j, system.resolve(&qualified)?));
                continue;
            };
            let partition = &members[m].0[p];
            if partition.ticks != Ticks::Triggered {
                return Err(Error::Experiment(format!(
                    "{}: the input file's column {name:?} is clock {:?}, whose ticks are {} (only a triggered clock's \
                     ticks come from a file)",
                    system.instances[m].name,
                    partition.name,
                    partition.ticks_text()
                )));
            }
            for (t, v) in table.time.iter().zip(&table.columns[j]) {
                if *v != 0.0 && *t >= start && *t < stop {
                    schedule.push((*t, partition.priority, m, p));
                }
            }
        }
    }
    // instantiated and initialized in the system's order, the connections carried in
    // Initialization Mode once all are in it
    let mut run: Vec<Member> = Vec::with_capacity(members.len());
    for ((partitions, outputs, first_column), spec) in members.into_iter().zip(&system.instances) {
        let mut instance = Instance::new(&spec.fmu, &spec.name)?;
        apply_start_values(&mut instance, spec)?;
        instance.setup_experiment(None, start, Some(stop))?;
        instance.enter_initialization_mode()?;
        let n = (partitions.len(), outputs.len());
        run.push(Member {
            instance,
            partitions,
            outputs,
            periodic: vec![None; n.0],
            activations: vec![0; n.0],
            output_ticks: vec![0; n.1],
            first_column,
        });
    }
    for m in 0..run.len() {
        exchange_into(system, &mut run, m)?;
    }
    for (m, member) in run.iter_mut().enumerate() {
        first_changing_ticks(member, &system.instances[m].name, start, stop, &mut schedule, m)?;
        member.instance.exit_initialization_mode()?;
        first_intervals(member, &system.instances[m].name, start)?;
        for (p, partition) in member.partitions.iter().enumerate() {
            if let Some(periodic) = member.periodic[p].as_mut() {
                let t = periodic.take();
                if t < stop {
                    schedule.push((t, partition.priority, m, p));
                }
            }
        }
    }
    let mut instants = 0u64;
    while let Some(t) = schedule.next_time().filter(|t| *t < stop) {
        if let Some(table) = &experiment.input {
            set_inputs(&mut run, system, table, &input_variables, t)?;
        }
        let mut ticked = vec![false; width];
        // (instance, partition) activated at t: a clock ticks once at a time
        let mut activated: Vec<(usize, usize)> = Vec::new();
        while schedule.next_time() == Some(t) {
            let Some((_, _, m, p)) = schedule.pop() else { break };
            activated.push((m, p));
            exchange_into(system, &mut run, m)?;
            let member = &mut run[m];
            let partition = &member.partitions[p];
            let update = member.instance.activate_model_partition(partition.clock, t)?;
            member.activations[p] += 1;
            ticked[member.first_column + p] = true;
            if let Some(periodic) = member.periodic[p].as_mut() {
                let next = periodic.take();
                if next < stop {
                    schedule.push((next, partition.priority, m, p));
                }
            }
            if partition.ticks == Ticks::Changing {
                let next = t + changing_interval(member, &system.instances[m].name, p, t)?;
                if next < stop {
                    schedule.push((next, member.partitions[p].priority, m, p));
                }
            }
            if !update {
                continue;
            }
            let mut due = after_update(member, t, &mut schedule, stop, &mut ticked, m)?;
            // an output clock's tick ticks the triggered input clocks connected to it, now
            while let Some(vr) = due.pop() {
                for c in system.clock_connections.iter().filter(|c| c.from == (m, vr)) {
                    let (to, clock) = c.to;
                    let Some(q) = run[to].partitions.iter().position(|q| q.clock == clock) else { continue };
                    if !activated.contains(&(to, q)) {
                        schedule.push((t, run[to].partitions[q].priority, to, q));
                    }
                }
            }
        }
        instants += 1;
        record_row(&mut run, &record, t, &ticked, results)?;
    }
    let last = results.values.len().checked_sub(results.width()).map(|k| results.values[k]);
    if last != Some(stop) {
        record_row(&mut run, &record, stop, &vec![false; width], results)?;
    }
    for member in &mut run {
        member.instance.terminate()?;
    }
    let mut counts = Vec::new();
    let mut ticks = Vec::new();
    let mut warnings = Vec::new();
    for (i, member) in run.iter().enumerate() {
        counts.extend(
            member.partitions.iter().zip(&member.activations).map(|(p, n)| format!("{} {n}", column(i, &p.name))),
        );
        ticks.extend(
            member.outputs.iter().zip(&member.output_ticks).map(|((name, _), n)| format!("{} {n}", column(i, name))),
        );
        warnings.extend(
            member
                .instance
                .take_log()
                .into_iter()
                .filter(|r| r.status == crate::Status::Warning)
                .map(|r| (system.instances[i].name.clone(), r.message)),
        );
    }
    let mut notes = vec![format!("Scheduled Execution: partitions activated: {}", counts.join(", "))];
    if !ticks.is_empty() {
        notes.push(format!("Scheduled Execution: output clocks ticked: {}", ticks.join(", ")));
    }
    Ok(Summary { steps: instants, wall_time: started.elapsed(), notes, warnings, ..Summary::default() })
}

/// The periodic partitions' first ticks after initialization: a `fixed` or `tunable`
/// clock's interval as `fmi3GetIntervalDecimal` gives it now (the description's when the
/// FMU says it is not yet known), the others' from the description; the first tick
/// `shift` after `start`.
fn first_intervals(member: &mut Member, name: &str, start: f64) -> Result<()> {
    let asked: Vec<usize> = (0..member.partitions.len())
        .filter(|&p| {
            matches!(member.partitions[p].ticks, Ticks::Periodic { .. })
                && matches!(member.partitions[p].kind, ClockKind::Fixed | ClockKind::Tunable)
        })
        .collect();
    let vrs: Vec<u32> = asked.iter().map(|&p| member.partitions[p].clock).collect();
    let given = if vrs.is_empty() { Vec::new() } else { member.instance.get_intervals(&vrs)? };
    for (p, partition) in member.partitions.iter().enumerate() {
        let Ticks::Periodic { interval, shift } = partition.ticks else { continue };
        let from_fmu = asked.iter().position(|&a| a == p).and_then(|k| match given[k] {
            Interval::Unchanged(i) | Interval::Changed(i) => Some(i),
            Interval::NotYetKnown => None,
        });
        let Some(interval) = from_fmu.or(interval) else {
            return Err(Error::Experiment(format!(
                "{name}: {} clock {:?} has no interval: its description gives none and fmi3GetIntervalDecimal did not \
                 give one after initialization",
                partition.kind.as_str(),
                partition.name
            )));
        };
        member.periodic[p] = Some(Periodic { origin: start + shift, interval, next: 0 });
    }
    Ok(())
}

/// The first ticks of the `changing` partitions of `member` (instance `m`, called `name`):
/// the interval `fmi3GetIntervalDecimal` gives in Initialization Mode after the start (FMI
/// 3.0: a changing clock's first interval is retrieved there and may be 0 s; no interval,
/// `fmi3IntervalNotYetKnown`, is for countdown clocks only).
fn first_changing_ticks(
    member: &mut Member,
    name: &str,
    start: f64,
    stop: f64,
    schedule: &mut Schedule,
    m: usize,
) -> Result<()> {
    let changing: Vec<usize> =
        (0..member.partitions.len()).filter(|&p| member.partitions[p].ticks == Ticks::Changing).collect();
    if changing.is_empty() {
        return Ok(());
    }
    let vrs: Vec<u32> = changing.iter().map(|&p| member.partitions[p].clock).collect();
    let given = member.instance.get_first_intervals(&vrs)?;
    for (&p, interval) in changing.iter().zip(given) {
        let partition = &member.partitions[p];
        let (Interval::Changed(delay) | Interval::Unchanged(delay)) = interval else {
            return Err(Error::Experiment(format!(
                "{name}: changing clock {:?}: fmi3GetIntervalDecimal in Initialization Mode gave no interval \
                 (fmi3IntervalNotYetKnown, which FMI 3.0 allows for countdown clocks only): its first tick is unknown",
                partition.name
            )));
        };
        if start + delay < stop {
            schedule.push((start + delay, partition.priority, m, p));
        }
    }
    Ok(())
}

/// The interval from the activation at `t` of the `changing` partition `p` of `member`
/// (called `name`) to its next: `fmi3GetIntervalDecimal` right after the activation (FMI
/// 3.0: the next interval of a changing clock is known once it was activated; the FMU says
/// `fmi3IntervalChanged`, and `fmi3IntervalUnchanged` for the interval it gave before, still
/// valid). A partition is activated once at a time, so an interval of 0 s is an error, as
/// is no interval.
fn changing_interval(member: &mut Member, name: &str, p: usize, t: f64) -> Result<f64> {
    let partition = &member.partitions[p];
    match member.instance.get_intervals(&[partition.clock])?[..] {
        [Interval::Changed(interval) | Interval::Unchanged(interval)] => Ok(interval),
        _ => Err(Error::Experiment(format!(
            "{name}: changing clock {:?}: fmi3GetIntervalDecimal after its activation at t = {t} s gave no interval \
             (fmi3IntervalNotYetKnown, which FMI 3.0 allows for countdown clocks only): its next tick is unknown",
            partition.name
        ))),
    }
}

/// After an activation of `member` at `t` in which the FMU signalled `clockUpdate`: the
/// countdown clocks it set are scheduled, the tunable clocks whose interval it changed
/// rescheduled from `t`, and the output clocks that ticked counted and marked in `ticked`;
/// those output clocks' value references returned.
fn after_update(
    member: &mut Member,
    t: f64,
    schedule: &mut Schedule,
    stop: f64,
    ticked: &mut [bool],
    m: usize,
) -> Result<Vec<u32>> {
    for (c, clock) in member.partitions.iter().enumerate() {
        match (clock.ticks, clock.kind) {
            (Ticks::Countdown, _) => {
                if let Some(interval) = member.instance.countdown_interval(clock.clock)? {
                    if t + interval < stop {
                        schedule.push((t + interval, clock.priority, m, c));
                    }
                }
            }
            (Ticks::Periodic { .. }, ClockKind::Tunable) => {
                if let [Interval::Changed(interval)] = member.instance.get_intervals(&[clock.clock])?[..] {
                    let mut periodic = Periodic { origin: t, interval, next: 1 };
                    schedule.cancel(m, c);
                    let next = periodic.take();
                    if next < stop {
                        schedule.push((next, clock.priority, m, c));
                    }
                    member.periodic[c] = Some(periodic);
                }
            }
            _ => {}
        }
    }
    let mut fired = Vec::new();
    for (o, (_, clock)) in member.outputs.iter().enumerate() {
        if member.instance.output_clock_ticked(*clock)? {
            member.output_ticks[o] += 1;
            ticked[member.first_column + member.partitions.len() + o] = true;
            fired.push(*clock);
        }
    }
    Ok(fired)
}

/// Sets the inputs of instance `m` connected to other instances' outputs from their
/// values now (times the connection's gain, plus its offset).
fn exchange_into(system: &System, run: &mut [Member], m: usize) -> Result<()> {
    for c in system.connections.iter().filter(|c| c.to.instance == m) {
        let x = get_value(&mut run[c.from.instance].instance, &c.from)?;
        let x = if c.to.base_type == BaseType::Real { c.gain * x + c.offset } else { x };
        set_value(&mut run[m].instance, system, &c.to, x)?;
    }
    Ok(())
}

/// Sets the input file's variables to their values at `t` (held from the last row at or
/// before it; at a jump, the later row).
fn set_inputs(
    run: &mut [Member],
    system: &System,
    table: &InputTable,
    variables: &[(usize, VariableRef)],
    t: f64,
) -> Result<()> {
    for (j, r) in variables {
        set_value(&mut run[r.instance].instance, system, r, table.value(*j, t, true, true))?;
    }
    Ok(())
}

/// The value of `r` as an f64 (a Boolean 0 or 1; NaN for a String, not read).
fn get_value(instance: &mut Instance, r: &VariableRef) -> Result<f64> {
    if r.base_type == BaseType::String {
        return Ok(f64::NAN);
    }
    Ok(match crate::simulate::lane::get_value(instance, r)? {
        Value::Real(x) => x,
        Value::Integer(i) => f64::from(i),
        Value::Boolean(b) => f64::from(u8::from(b)),
        Value::String(_) => f64::NAN,
    })
}

/// Sets `r` to `x` (an Integer rounded toward zero, a Boolean true when not 0).
fn set_value(instance: &mut Instance, system: &System, r: &VariableRef, x: f64) -> Result<()> {
    let vr = [r.value_reference];
    match r.base_type {
        BaseType::Real => instance.set_real(&vr, &[x])?,
        BaseType::Integer => instance.set_integer(&vr, &[x as i32])?,
        BaseType::Boolean => instance.set_boolean(&vr, &[(x != 0.0) as i32])?,
        BaseType::String => {
            return Err(Error::Experiment(format!(
                "{} is a String: Scheduled Execution sets numbers only (from an input file or a connection)",
                system.name_of(r)
            )))
        }
    }
    Ok(())
}

/// Appends the row at `t`: the recorded variables, then 1 or 0 per clock.
fn record_row(
    run: &mut [Member],
    record: &[VariableRef],
    t: f64,
    ticked: &[bool],
    results: &mut Results,
) -> Result<()> {
    let mut row = Vec::with_capacity(1 + record.len() + ticked.len());
    row.push(t);
    for r in record {
        row.push(get_value(&mut run[r.instance].instance, r)?);
    }
    row.extend(ticked.iter().map(|b| f64::from(u8::from(*b))));
    results.values.extend(row);
    Ok(())
}

//! The execution of a run (libcosim's `execution`): a system instantiated and initialized,
//! then advanced one communication step at a time by its algorithm, with observers told
//! after every step and values set between steps. [`simulate()`](crate::simulate()),
//! campaigns and the Python package are loops over it.
//!
//! Time is counted in steps: communication point `n` is at `t0 + n h` ([`Point`]), never
//! accumulated. The seams:
//! - the algorithm (`simulate/algorithm/`): how the instances are stepped and their
//!   connections carried over one step;
//! - [`Observer`]s: told after every step (the recorder of the rows, the time limit, a
//!   cancel flag, the progress; a caller's own);
//! - [`Manipulator`]s: values applied before a step (the experiment's
//!   [`InputTable`](crate::InputTable), [`Execution::set`], a [`SetQueue`] filled from
//!   another thread, a caller's own).

use crate::error::{Error, Result};
use crate::fmu::{Instance, Interface};
use crate::me::{MeUnit, Solver};
use crate::simulate::algorithm::{Communication, Core, Jacobi, Ordered, ThreadedJacobi};
use crate::simulate::between::{Manipulator, SetQueue, WithManipulator};
use crate::simulate::clock::{Clock, Point};
use crate::simulate::lane::{apply_start_values, Lane};
use crate::simulate::me_group::MeGroup;
use crate::simulate::observer::{Cancel, Deadline, ExactSource, Observer, Observers, Progress, Recorder, RowSink};
use crate::simulate::plan::{default_record, run_ops, Op, Plan};
use crate::simulate::profiler::Profiler;
use crate::simulate::ticks::Ticks;
use crate::simulate::types::{Algorithm, Experiment, Results, Summary};
use crate::system::{BaseType, System, Value, VariableRef};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where an [`Execution`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Checked and planned; no instance yet ([`Execution::initialize`] next).
    Created,
    /// Initialized, between two communication steps.
    Running,
    /// At its end: the stop time, or an FMU ended the run ([`Execution::finish`] next).
    AtEnd,
    /// A step or the initialization failed; the rows so far are kept.
    Failed,
    /// Terminated ([`Execution::finish`]); the rows are kept.
    Finished,
    /// Stopped by its caller before its end ([`Execution::stop`]): the instances freed
    /// without `fmi2Terminate`, the rows kept.
    Stopped,
}

/// A run of a [`System`] under an [`Experiment`], advanced by its caller.
///
/// ```no_run
/// use nigel_cosim::{Fmu, System, Experiment, simulate::Execution};
/// let system = System::single("plant", Fmu::load("target/fmu/nigel_plant.fmu".as_ref())?)?;
/// let mut run = Execution::new(&system, &Experiment::new(1.0, 1e-3))?;
/// run.initialize()?;
/// run.simulate_until(0.5)?;
/// run.set("plant.steering", "0.1")?; // applied before the next step
/// run.simulate_until(1.0)?;
/// let summary = run.finish()?;
/// let results = run.take_results();
/// # Ok::<(), nigel_cosim::Error>(())
/// ```
pub struct Execution<'s> {
    system: System,
    experiment: Experiment,
    wall: Instant,
    deadline: Option<(Instant, Duration)>,
    clock: Clock,
    /// The batched calls, until `initialize` hands each lane its own.
    plan: Plan,
    /// Every recorded variable, one get per instance and type (the first and the last row).
    record_gets: Vec<Op>,
    /// The coupled Model Exchange group, until `initialize` puts it in the core.
    group: Option<MeGroup>,
    algorithm: Box<dyn Communication + Send + 's>,
    recorder: Recorder<'s>,
    observers: Vec<Box<dyn Observer + Send + 's>>,
    pool: Option<&'s mut InstancePool>,
    /// Values from [`Execution::set`] for the next step.
    pending: Vec<(VariableRef, Value)>,
    /// Tunable structural parameters from [`Execution::reconfigure`] for the next step:
    /// (instance, parameter, value).
    reconfigurations: Vec<(usize, String, f64)>,
    core: Option<Core>,
    profiler: Option<Profiler>,
    /// The next communication step (`n`: the run is at `t0 + n h`).
    next: u64,
    ended_by: Option<(String, f64, &'static str)>,
    /// What the run does that a reader may not expect ([`Summary::notes`]).
    notes: Vec<String>,
    /// An algebraic loop at initialization (its connections, `a.y -> b.u`), iterated to
    /// its fixed point before Initialization Mode ends.
    init_loop: Option<Vec<String>>,
    /// The input file's columns of triggered input clocks: (instance, clock, tick times).
    clock_inputs: Vec<(usize, u32, Vec<f64>)>,
    phase: Phase,
}

impl<'s> Execution<'s> {
    /// Checks `experiment` against `system` and plans the run (the value slots, the batched
    /// calls, the algorithm); no FMU is called yet.
    pub fn new(system: &System, experiment: &Experiment) -> Result<Execution<'s>> {
        let wall = Instant::now();
        let deadline = experiment.timeout.map(|limit| (wall + limit, limit));
        if let Some(spec) = system.instances.iter().find(|i| i.fmu.interface() == Interface::ScheduledExecution) {
            return Err(Error::Experiment(format!(
                "{} is loaded for Scheduled Execution, which steps no communication points: run it on its own with simulate_scheduled (cosim run --interface se)",
                spec.name
            )));
        }
        let clock = Clock::new(experiment, system)?;
        check_solver(experiment, &clock, system)?;
        check_single_instance(system)?;
        if experiment.threads == 0 {
            return Err(Error::Experiment("threads must be at least 1".into()));
        }
        let record: Vec<VariableRef> = match &experiment.record {
            None => default_record(system),
            Some(names) => names
                .iter()
                .map(|n| system.resolve_record(n))
                .collect::<Result<Vec<_>>>()?
                .into_iter()
                .flatten()
                .collect(),
        };
        // the columns an f64 does not hold: read exactly at each row
        let exact: Vec<ExactSource> = record
            .iter()
            .enumerate()
            .filter_map(|(column, r)| {
                let text = r.base_type == BaseType::String;
                let wide = system.instances[r.instance].fmu.exact_kind(r.value_reference).is_some();
                (text || wide).then_some(ExactSource {
                    column,
                    instance: r.instance,
                    value_reference: r.value_reference,
                    text,
                })
            })
            .collect();
        let mut plan = Plan::new(system, &record, experiment.algorithm)?;
        // Model Exchange instances connected to each other are integrated together
        let mut group = MeGroup::coupled(system, experiment.max_steps)?;
        if let Some(g) = group.as_mut() {
            g.stop_time = experiment.stop_time;
        }
        let record_slots: Vec<usize> = record.iter().map(|r| plan.slot(r)).collect();
        let record_gets = plan.record_gets(&record);
        let mut algorithm: Box<dyn Communication + Send + 's> = match (experiment.algorithm, plan.ordered.take()) {
            (Algorithm::Ordered, Some(ops)) => {
                plan.ordered = Some(ops);
                let record_gets = plan.ordered_record_gets(&record);
                Box::new(Ordered { ops: plan.ordered.take().unwrap_or_default(), record_gets })
            }
            // the observers of the threaded pipeline see the values only, not the instances
            // the exact columns are read from
            _ if experiment.threads > 1 && exact.is_empty() => Box::new(ThreadedJacobi { threads: experiment.threads }),
            _ => Box::new(Jacobi),
        };
        let mut notes = Vec::new();
        let (input, clock_inputs) = match &experiment.input {
            Some(table) => {
                let (rest, clocks) = crate::simulate::ticks::clock_columns(system, table)?;
                (Some(rest), clocks)
            }
            None => (None, Vec::new()),
        };
        if let Some(table) = input.as_ref().filter(|t| !t.names.is_empty() || clock_inputs.is_empty()) {
            if experiment.threads > 1 {
                return Err(Error::Experiment("input signals are applied in one thread: use threads = 1".into()));
            }
            let with_input = crate::simulate::input::WithInput::new(algorithm, system, table, &clock)?;
            notes.extend(with_input.notes.iter().cloned());
            algorithm = Box::new(with_input);
        }
        let single = system.instances.len() == 1;
        let names: Vec<String> =
            record.iter().map(|r| if single { system.variable(r).name.clone() } else { system.name_of(r) }).collect();
        let recorder = Recorder::new(names, record_slots, exact);
        Ok(Execution {
            system: system.clone(),
            experiment: experiment.clone(),
            wall,
            deadline,
            clock,
            plan,
            record_gets,
            group,
            algorithm,
            recorder,
            observers: Vec::new(),
            pool: None,
            pending: Vec::new(),
            reconfigurations: Vec::new(),
            core: None,
            profiler: None,
            next: 0,
            ended_by: None,
            notes,
            init_loop: crate::loops::initialization_loop(system),
            clock_inputs,
            phase: Phase::Created,
        })
    }

    /// Takes the instances from `pool` (each reset with `fmi2Reset` instead of instantiated
    /// again; put back by [`Execution::finish`]; not used for isolated instances).
    pub fn with_pool(mut self, pool: &'s mut InstancePool) -> Self {
        if self.experiment.isolation.is_none() {
            self.pool = Some(pool);
        }
        self
    }

    /// Hands each row (time and the recorded values) to `sink` instead of keeping it: the
    /// results then have the column names and no rows.
    pub fn with_sink(mut self, sink: &'s mut RowSink<'s>) -> Self {
        self.recorder.sink = Some(sink);
        self
    }

    /// Tells `observer` after every communication step (after the recorder and the time
    /// limit); an error it returns ends the run.
    pub fn add_observer(&mut self, observer: Box<dyn Observer + Send + 's>) {
        self.observers.push(observer);
    }

    /// Stops the run between two steps with [`Error::Cancelled`] once `flag` is set (from
    /// any thread: a Python caller's Ctrl-C), the rows so far kept.
    pub fn cancel_on(&mut self, flag: Arc<AtomicBool>) {
        self.add_observer(Box::new(Cancel(flag)));
    }

    /// Calls `report` with the fraction done (0..=1) at each output point.
    pub fn on_progress(&mut self, report: fn(f64)) {
        self.add_observer(Box::new(Progress { report, steps: self.clock.steps }));
    }

    /// Applies the values of `queue` (filled from any thread, e.g. a row sink) before each
    /// communication step, as [`Execution::set`] does.
    pub fn with_set_queue(mut self, queue: Arc<SetQueue>) -> Self {
        self.add_manipulator(Box::new(queue));
        self
    }

    /// Applies `manipulator` before every communication step: before the experiment's input
    /// signals are applied and before the manipulators added earlier (the last added runs
    /// first); the values of [`Execution::set`] come before all of them.
    pub fn add_manipulator(&mut self, manipulator: Box<dyn Manipulator + 's>) {
        let inner = std::mem::replace(&mut self.algorithm, Box::new(Jacobi));
        self.algorithm = Box::new(WithManipulator { inner, manipulator });
    }

    /// The system run.
    pub fn system(&self) -> &System {
        &self.system
    }

    /// Where the run is.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Communication steps taken (the run is at `t0 + n h`).
    pub fn step_number(&self) -> u64 {
        self.next
    }

    /// Communication steps of the whole run.
    pub fn steps(&self) -> u64 {
        self.clock.steps
    }

    /// The time of the run: the communication point reached (or the time an FMU ended it).
    pub fn time(&self) -> f64 {
        if let Some((_, t, _)) = &self.ended_by {
            return *t;
        }
        match self.next {
            0 => self.clock.t0,
            n => self.clock.point(n - 1).t_next,
        }
    }

    /// The communication step that comes next, if the run goes on.
    pub fn next_step(&self) -> Option<Point> {
        (self.phase == Phase::Running && self.next < self.clock.steps).then(|| self.clock.point(self.next))
    }

    /// Whether the last step ended at an output point (a row was recorded there); true
    /// after initialization.
    pub fn at_output_point(&self) -> bool {
        self.next == 0 || self.clock.point(self.next - 1).output_point || self.phase != Phase::Running
    }

    /// Instantiates and initializes every instance (FMI 2.0 section 4.2.4, FMI 3.0 section
    /// 4.2.4), runs the initial event iteration of the Model Exchange instances and records
    /// the first row.
    pub fn initialize(&mut self) -> Result<()> {
        if self.phase != Phase::Created {
            return Err(Error::Experiment("the run is initialized already".into()));
        }
        self.recorder.reserve(self.clock.rows());
        let registered = crate::exit_guard::Registered::new(self.recorder.shared.clone());
        let outcome = self.initialize_inner();
        if outcome.is_err() {
            // the instances freed now, while an FMU's exit() in fmi2FreeInstance is reported
            self.core = None;
            self.phase = Phase::Failed;
        }
        drop(registered);
        outcome
    }

    fn initialize_inner(&mut self) -> Result<()> {
        let experiment = &self.experiment;
        let system = &self.system;
        let mut lanes: Vec<Lane> = Vec::with_capacity(system.instances.len());
        for (index, spec) in system.instances.iter().enumerate() {
            let inst = match self.pool.as_deref_mut().and_then(|p| p.take(index, spec)) {
                Some(mut inst) => {
                    inst.reset()?;
                    inst
                }
                None => match &experiment.isolation {
                    Some(iso) if iso.covers(&spec.name) => {
                        Instance::new_isolated(&spec.fmu, &spec.name, iso, self.deadline)?
                    }
                    _ => Instance::new(&spec.fmu, &spec.name)?,
                },
            };
            lanes.push(Lane::new(
                index,
                inst,
                std::mem::take(&mut self.plan.jacobi_gets[index]),
                std::mem::take(&mut self.plan.jacobi_gets_rec[index]),
                std::mem::take(&mut self.plan.jacobi_sets[index]),
            ));
        }
        let core = self.core.insert(Core {
            lanes,
            values: vec![0.0; self.plan.exchange_len],
            group: self.group.take(),
            solver: experiment.solver,
            clock: self.clock,
            profile: experiment.profile,
            parallel_steps: 0,
            clock_links: system.clock_connections.clone(),
            clocked: false,
        });
        let t0 = self.clock.t0;
        if self.clock.steps > 0 {
            let last_point = self.clock.point(self.clock.steps - 1).t_next;
            core.lanes.iter_mut().for_each(|lane| lane.last_point = last_point);
        }
        for (lane, spec) in core.lanes.iter_mut().zip(&system.instances) {
            let tolerance = match spec.fmu.interface() {
                Interface::CoSimulation => experiment
                    .co_simulation_tolerance
                    .or_else(|| spec.fmu.description().default_experiment.as_ref().and_then(|d| d.tolerance))
                    // a declared tolerance that is no tolerance (0, negative, NaN) is not passed on
                    .filter(|t| t.is_finite() && *t > 0.0),
                // refused by Execution::new (simulate_scheduled runs it)
                Interface::ModelExchange | Interface::ScheduledExecution => None,
            };
            lane.inst.setup_experiment(tolerance, t0, Some(experiment.stop_time))?;
            apply_start_values(&mut lane.inst, spec)?;
            lane.inst.enter_initialization_mode()?;
        }
        self.algorithm.propagate(core)?;
        // every input at its source's value when Initialization Mode ends: chains of direct
        // feedthrough settle in one sweep per link, a loop at its fixed point
        let exact = self.plan.exact_slots();
        let sweeps = super::init_loop::iterate(core, self.init_loop.as_deref().unwrap_or_default(), &exact)?;
        if let Some(cycle) = &self.init_loop {
            self.notes.push(format!(
                "the connections {} form an algebraic loop at initialization: iterated to its fixed point in {sweeps} sweep{} of the connections (to {:e} relative)",
                cycle.join(", "),
                if sweeps == 1 { "" } else { "s" },
                super::init_loop::RTOL
            ));
        }
        for lane in core.lanes.iter_mut() {
            lane.inst.exit_initialization_mode()?;
            if lane.inst.fmu().interface() == Interface::ModelExchange {
                lane.unit = Some(MeUnit::new(&lane.inst));
                if !core.group.as_ref().is_some_and(|g| g.contains(lane.index)) {
                    let mut solo = MeGroup::solo(lane.index, experiment.max_steps);
                    solo.stop_time = experiment.stop_time;
                    lane.solo = Some(solo);
                }
            }
        }
        // FMI 3.0 clocks of a Model Exchange instance: its input clocks ticking at the start
        // time are activated in the Event Mode that ends initialization, before its initial
        // event iteration (an FMU that samples at its clock's activations, and only there,
        // has its first sample in that event, as its FMI 2.0 form has at its initial event)
        let mut start_ticks: Vec<(usize, Vec<u32>)> = Vec::new();
        for (lane, spec) in core.lanes.iter_mut().zip(&system.instances) {
            let clocks = spec.fmu.clocks();
            if lane.solo.is_none() || clocks.is_empty() {
                continue;
            }
            let triggered: Vec<(u32, Vec<f64>)> =
                self.clock_inputs.iter().filter(|c| c.0 == lane.index).map(|c| (c.1, c.2.clone())).collect();
            let vrs = Ticks::at_start(&clocks, t0, self.clock.h, &triggered);
            if !vrs.is_empty() {
                lane.inst.set_clocks(&vrs)?;
                start_ticks.push((lane.index, vrs));
            }
        }
        // the initial event iteration of every Model Exchange group
        for lane in core.lanes.iter_mut() {
            if let (Some(unit), Some(solo)) = (lane.unit.as_mut(), lane.solo.as_mut()) {
                solo.iterate(&mut crate::simulate::me_group::Solo { inst: &mut lane.inst, unit }, t0)?;
            }
        }
        if let Some(g) = core.group.as_mut() {
            g.iterate(core.lanes.as_mut_slice(), t0)?;
        }
        // FMI 3.0 clocks: the ticks of the input clocks scheduled (from the intervals the
        // FMU gave in the event that ends initialization, Model Exchange's initial event
        // iteration included); the ticks at the start time are
        // the first step's
        for (lane, spec) in core.lanes.iter_mut().zip(&system.instances) {
            let clocks = spec.fmu.clocks();
            if clocks.is_empty() {
                continue;
            }
            if lane.in_group() {
                return Err(Error::Experiment(format!(
                    "{}: clocks of a Model Exchange instance connected to other Model Exchange instances, which \
                     cosim does not support (connect it through a Co-Simulation FMU, or run it alone)",
                    spec.name
                )));
            }
            let triggered: Vec<(u32, Vec<f64>)> =
                self.clock_inputs.iter().filter(|c| c.0 == lane.index).map(|c| (c.1, c.2.clone())).collect();
            let Some(mut ticks) = Ticks::new(&clocks, t0, self.clock.h, &triggered) else { continue };
            ticks.after_events(&mut lane.inst, true)?;
            if let Some((_, vrs)) = start_ticks.iter().find(|(i, _)| *i == lane.index) {
                ticks.ticked(vrs);
            }
            // Co-Simulation: the ticks at the start time open their event as those at any
            // later point do, so the first row, like every row at a tick, holds what the FMU
            // answers with the clock active (Model Exchange runs every tick whole at the
            // start of the step from it)
            if lane.unit.is_none() {
                if let Some(vrs) = ticks.at(t0) {
                    lane.inst.open_clock_event(t0, &vrs)?;
                    ticks.opened(&vrs);
                }
            }
            lane.ticks = Some(ticks);
            core.clocked = true;
        }
        for lane in core.lanes.iter_mut() {
            let fmu = lane.inst.fmu();
            let capable = fmu.interface() == Interface::CoSimulation
                && fmu.can_get_and_set_state()
                && fmu.can_handle_variable_step();
            if experiment.retry_discard && capable {
                lane.saved = Some(lane.inst.get_state()?);
            }
        }
        self.algorithm.propagate(core)?;
        run_ops(&mut self.record_gets, core.lanes.as_mut_slice(), &mut core.values, None)?;
        if self.recorder.reads_exact() {
            self.recorder.read_exact(&mut core.lanes)?;
        }
        self.recorder.push_row(t0, &core.values);
        self.profiler = Some(Profiler::new(core.lanes.len()));
        self.phase = Phase::Running;
        // an FMU may end the run in its initial event iteration
        if let Some(l) = core.lanes.iter().find(|l| l.unit.as_ref().is_some_and(|u| u.terminated)) {
            self.ended_by = Some((l.inst.name().to_string(), t0, "terminateSimulation"));
            self.phase = Phase::AtEnd;
        } else if self.clock.steps == 0 {
            self.algorithm.finish(core)?;
            self.phase = Phase::AtEnd;
        }
        Ok(())
    }

    /// One communication step. False when the run is at its end (nothing done).
    pub fn step(&mut self) -> Result<bool> {
        match self.phase {
            Phase::Running => {}
            Phase::AtEnd => return Ok(false),
            other => return Err(not_running(other)),
        }
        let n = self.next;
        self.advance(n + 1)?;
        Ok(true)
    }

    /// Steps on to the first communication point at or after `time` (to the stop time at
    /// most, or until an FMU ends the run). The time reached.
    pub fn simulate_until(&mut self, time: f64) -> Result<f64> {
        match self.phase {
            Phase::Running => {}
            Phase::AtEnd => return Ok(self.time()),
            other => return Err(not_running(other)),
        }
        if !time.is_finite() {
            return Err(Error::Experiment(format!("simulate_until({time}): the time must be finite")));
        }
        // the first point n at or after `time` (to the rounding of the points)
        let clock = self.clock;
        let point_time = |n: u64| if n == 0 { clock.t0 } else { clock.point(n - 1).t_next };
        let guess = ((time - clock.t0) / clock.h).floor().max(0.0).min(clock.steps as f64) as u64;
        let mut end = guess.max(self.next);
        while end > self.next && reached(point_time(end - 1), time) {
            end -= 1;
        }
        while end < clock.steps && !reached(point_time(end), time) {
            end += 1;
        }
        if end > self.next {
            self.advance(end)?;
        }
        Ok(self.time())
    }

    /// Every remaining step.
    pub fn simulate_to_end(&mut self) -> Result<()> {
        if self.phase == Phase::Running {
            self.advance(self.clock.steps)?;
        }
        match self.phase {
            Phase::AtEnd => Ok(()),
            other => Err(not_running(other)),
        }
    }

    /// Steps `self.next..end`, telling the observers after each.
    fn advance(&mut self, end: u64) -> Result<()> {
        let now = self.time();
        let Some(core) = self.core.as_mut() else { return Err(not_running(self.phase)) };
        let registered = crate::exit_guard::Registered::new(self.recorder.shared.clone());
        let outcome = (|| -> Result<()> {
            for (i, name, value) in std::mem::take(&mut self.reconfigurations) {
                reconfigure(core, i, &name, value, now)?;
            }
            if !self.pending.is_empty() {
                apply_values(core, std::mem::take(&mut self.pending))?;
            }
            let mut limit = self.deadline.map(|(at, limit)| Deadline { at, limit });
            let mut list: Vec<&mut dyn Observer> = Vec::with_capacity(1 + self.observers.len());
            if let Some(d) = limit.as_mut() {
                list.push(d);
            }
            for o in self.observers.iter_mut() {
                list.push(&mut **o);
            }
            let calls = if self.experiment.profile { self.profiler.as_mut() } else { None };
            let mut observers = Observers { recorder: &mut self.recorder, list, calls };
            let outcome = self.algorithm.run(core, &mut observers, self.next..end);
            self.next = self.recorder.steps_done();
            outcome?;
            if self.next == self.clock.steps {
                self.algorithm.finish(core)?;
                self.phase = Phase::AtEnd;
            }
            Ok(())
        })();
        let outcome = match outcome {
            Err(Error::Terminated { instance, time, reason }) => {
                // the row at the time the run ended, every recorded variable read as its
                // instance now has it: Co-Simulation at fmi2LastSuccessfulTime (fmpy and
                // fmusim record it too), Model Exchange at the event that set
                // terminateSimulation, after its event iteration (fmpy with record_events
                // records it too)
                let row = if time > self.recorder.last_time().unwrap_or(f64::NEG_INFINITY) {
                    run_ops(&mut self.record_gets, core.lanes.as_mut_slice(), &mut core.values, None)
                        .and_then(|()| match self.recorder.reads_exact() {
                            true => self.recorder.read_exact(&mut core.lanes),
                            false => Ok(()),
                        })
                        .map(|()| self.recorder.push_row(time, &core.values))
                } else {
                    Ok(())
                };
                self.ended_by = Some((instance, time, reason));
                self.phase = Phase::AtEnd;
                row
            }
            other => other,
        };
        if outcome.is_err() {
            // the instances freed now, while an FMU's exit() in fmi2FreeInstance is reported
            self.core = None;
            self.phase = Phase::Failed;
        }
        drop(registered);
        outcome
    }

    /// Sets an input no connection feeds, or a tunable parameter, from the next
    /// communication step on (`name`: `instance.variable`; `text`: a value of its type).
    /// A tunable structural parameter goes through Reconfiguration Mode
    /// ([`Execution::reconfigure`]).
    pub fn set(&mut self, name: &str, text: &str) -> Result<()> {
        if let Ok(r) = self.system.resolve(name) {
            if self.system.is_structural(&r) {
                let value = text.trim().parse::<f64>().map_err(|_| {
                    Error::Experiment(format!("{name} = {text:?}: a structural parameter's value is a number"))
                })?;
                return self.reconfigure(name, value);
            }
        }
        let (r, value) = crate::simulate::between::checked_value(&self.system, name, text)?;
        self.pending.push((r, value));
        Ok(())
    }

    /// Sets the FMI 3.0 tunable structural parameter `name` (`instance.parameter`) to
    /// `value` in Reconfiguration Mode before the next communication step (a Co-Simulation
    /// instance in process; see [`crate::Instance::reconfigure`]). The arrays it sizes have
    /// their new size from then on: the results keep the columns the system was built with
    /// ([`crate::SystemBuilder::size_for`] sizes them for the largest), NaN in the elements an
    /// array lacks at a row.
    pub fn reconfigure(&mut self, name: &str, value: f64) -> Result<()> {
        let r = self.system.resolve(name)?;
        self.reconfigurations.push((r.instance, self.system.variable(&r).name.clone(), value));
        Ok(())
    }

    /// The value of `name` (`instance.variable`) as its instance has it now (between
    /// steps). Real, Integer, Boolean and String variables of FMI 2.0 and the same scalars
    /// of FMI 3.0 as their FMI 2.0 counterparts.
    pub fn get(&mut self, name: &str) -> Result<Value> {
        let r = self.system.resolve(name)?;
        let Some(core) = self.core.as_mut() else { return Err(not_running(self.phase)) };
        crate::simulate::lane::get_value(&mut core.lanes[r.instance].inst, &r)
    }

    /// The last row recorded (time first), unless the rows go to a sink.
    pub fn last_row(&self) -> Option<Vec<f64>> {
        let results = self.recorder.shared.results.lock().unwrap_or_else(|e| e.into_inner());
        let width = results.width();
        let start = results.values.len().checked_sub(width)?;
        Some(results.values[start..].to_vec())
    }

    /// The time of the last row recorded.
    pub fn last_row_time(&self) -> Option<f64> {
        self.recorder.last_time()
    }

    /// Ends the run where it is, before its end: the instances are freed (no
    /// `fmi2Terminate`), the rows so far kept. Nothing happens once it has finished.
    pub fn stop(&mut self) {
        if matches!(self.phase, Phase::Created | Phase::Running | Phase::AtEnd | Phase::Failed) {
            let registered = crate::exit_guard::Registered::new(self.recorder.shared.clone());
            self.core = None;
            drop(registered);
            self.phase = Phase::Stopped;
        }
    }

    /// The rows recorded so far (a copy).
    pub fn results(&self) -> Results {
        self.recorder.shared.results.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// The rows recorded (taken out).
    pub fn take_results(&mut self) -> Results {
        self.recorder.take_results()
    }

    /// Terminates every instance at the end of the run (the stop time, or an FMU ended it)
    /// and puts them back into the pool; the run's summary.
    pub fn finish(&mut self) -> Result<Summary> {
        if self.phase != Phase::AtEnd {
            return Err(Error::Experiment(match self.phase {
                Phase::Running => format!("the run is at t = {} s, before its end: step on first", self.time()),
                other => not_running(other).to_string(),
            }));
        }
        let registered = crate::exit_guard::Registered::new(self.recorder.shared.clone());
        let outcome = self.finish_inner();
        drop(registered);
        self.phase = if outcome.is_ok() { Phase::Finished } else { Phase::Failed };
        outcome
    }

    fn finish_inner(&mut self) -> Result<Summary> {
        let Some(mut core) = self.core.take() else { return Err(not_running(self.phase)) };
        let mut profiler = self.profiler.take().unwrap_or_else(|| Profiler::new(core.lanes.len()));
        if self.experiment.profile {
            for lane in core.lanes.iter() {
                profiler.spent[lane.index] += lane.spent;
            }
        }
        let mut summary = Summary {
            steps: self.recorder.steps_done(),
            parallel_steps: core.parallel_steps,
            wall_time: Duration::ZERO,
            ended_by: self.ended_by.clone(),
            notes: std::mem::take(&mut self.notes),
            ..Summary::default()
        };
        let single = core.lanes.len() == 1;
        for lane in core.lanes.iter_mut() {
            if let Some(ticks) = &lane.ticks {
                summary.clock_ticks.extend(ticks.summary(lane.inst.name(), single));
            }
            summary.discard_retries += lane.retries;
            if let Some(state) = lane.saved.take() {
                lane.inst.free_state(state)?;
            }
            if let Some(unit) = lane.unit.take() {
                summary.integrator_steps.0 += unit.steps;
                summary.integrator_steps.1 += unit.rejected;
                summary.stiff.rhs += unit.stiff.rhs;
                summary.stiff.jacobian_rhs += unit.stiff.jacobian_rhs;
                summary.stiff.jacobians += unit.stiff.jacobians;
                summary.stiff.factorizations += unit.stiff.factorizations;
                summary.stiff.steps += unit.stiff.steps;
                summary.stiff.rejected += unit.stiff.rejected;
                summary.events.extend(unit.events);
                summary.notes.extend(unit.notes);
            }
        }
        for lane in core.lanes.iter_mut() {
            lane.inst.terminate()?;
            for rec in lane.inst.take_log() {
                if rec.status != crate::error::Status::Ok {
                    summary.warnings.push((lane.inst.name().to_string(), rec.message));
                }
            }
        }
        if let Some(pool) = self.pool.take() {
            for lane in std::mem::take(&mut core.lanes) {
                pool.put(lane.index, lane.inst);
            }
        }
        // freed here, not dropped: a host process that ends in fmi2FreeInstance (an FMU
        // that crashes in it) fails the run, its rows kept
        let mut freed = Ok(());
        for lane in std::mem::take(&mut core.lanes) {
            let result = lane.inst.free();
            if freed.is_ok() {
                freed = result;
            }
        }
        freed?;
        drop(core);
        summary.instance_time = self.system.instances.iter().map(|s| s.name.clone()).zip(profiler.spent).collect();
        summary.wall_time = self.wall.elapsed();
        Ok(summary)
    }
}

impl Drop for Execution<'_> {
    /// Frees the instances still held (a run dropped before its end) while the run is
    /// registered, so that an FMU's exit() in fmi2FreeInstance is reported with the rows.
    fn drop(&mut self) {
        if self.core.is_some() {
            let registered = crate::exit_guard::Registered::new(self.recorder.shared.clone());
            self.core = None;
            drop(registered);
        }
    }
}

/// Whether `t` has reached `target` (Python's `math.isclose` with its defaults for the last
/// bit, as fmpy compares times).
fn reached(t: f64, target: f64) -> bool {
    t >= target || (t - target).abs() <= 1e-9 * t.abs().max(target.abs())
}

fn not_running(phase: Phase) -> Error {
    Error::Experiment(
        match phase {
            Phase::Created => "the run is not initialized (Execution::initialize)",
            Phase::Failed => "the run failed: it cannot go on",
            Phase::Finished | Phase::Stopped => "the run has ended (start a new one)",
            Phase::Running | Phase::AtEnd => "the run cannot do this now",
        }
        .into(),
    )
}

/// The values of [`Execution::set`], before the next step.
/// Instance `i` sets its tunable structural parameter `name` to `value` in Reconfiguration
/// Mode at `time`: a Co-Simulation instance between steps (from Step Mode), a Model
/// Exchange one in an event of its group (Event Mode, the event iterated after and the
/// integrator restarted, as for an input event).
fn reconfigure(core: &mut Core, i: usize, name: &str, value: f64, time: f64) -> Result<()> {
    let set = [(name, value)];
    if let Some(group) = core.group.as_mut().filter(|g| g.contains(i)) {
        group.input_event(core.lanes.as_mut_slice(), time, "reconfiguration", &[i], |lanes| {
            Ok(lanes[i].inst.reconfigure(&set)?)
        })?;
        return group.ended(core.lanes.as_mut_slice(), time);
    }
    let lane = &mut core.lanes[i];
    if let (Some(unit), Some(solo)) = (lane.unit.as_mut(), lane.solo.as_mut()) {
        let mut one = crate::simulate::me_group::Solo { inst: &mut lane.inst, unit };
        solo.input_event(&mut one, time, "reconfiguration", &[i], |one| Ok(one.inst.reconfigure(&set)?))?;
        return solo.ended(&mut one, time);
    }
    Ok(lane.inst.reconfigure(&set)?)
}

fn apply_values(core: &mut Core, values: Vec<(VariableRef, Value)>) -> Result<()> {
    for (r, value) in values {
        crate::simulate::between::set_value(&mut core.lanes[r.instance].inst, &r, value)?;
    }
    Ok(())
}

/// Refuses a system with two instances of an FMU that declares
/// `canBeInstantiatedOnlyOncePerProcess`.
fn check_single_instance(system: &System) -> Result<()> {
    for (k, spec) in system.instances.iter().enumerate() {
        let md = spec.fmu.description();
        let once = match spec.fmu.interface() {
            Interface::CoSimulation => {
                md.co_simulation.as_ref().is_some_and(|c| c.can_be_instantiated_only_once_per_process)
            }
            Interface::ModelExchange => {
                md.model_exchange.as_ref().is_some_and(|m| m.can_be_instantiated_only_once_per_process)
            }
            Interface::ScheduledExecution => false,
        };
        if !once {
            continue;
        }
        if let Some(other) = system.instances[k + 1..].iter().find(|o| o.fmu.description().guid == md.guid) {
            return Err(Error::Experiment(format!(
                "{} and {} are instances of {} (GUID {}), which can be instantiated only once per process (canBeInstantiatedOnlyOncePerProcess)",
                spec.name, other.name, md.model_name, md.guid
            )));
        }
    }
    Ok(())
}

/// The smallest relative tolerance of `dopri5`: a hundred machine epsilons (2.2e-14); below
/// it the error estimate of an f64 step is rounding, and no step size meets it.
pub(crate) const MIN_RTOL: f64 = 100.0 * f64::EPSILON;

/// Refuses integrator settings that cannot progress: an RK4 `max_step` so small that the
/// run's internal steps would exceed its cap (or below the resolution of its times), a
/// `dopri5` or `bdf` tolerance no f64 step can meet (for `auto`, those of its rk4 and bdf).
fn check_solver(e: &Experiment, clock: &Clock, system: &System) -> Result<()> {
    if !system.instances.iter().any(|i| i.fmu.interface() == Interface::ModelExchange) {
        return Ok(());
    }
    // auto: its rk4's largest step and its bdf's tolerances
    let (max_step, tolerances) = match e.solver {
        Solver::Auto { max_step, rtol, atol } => (max_step, Some(("bdf", rtol, atol))),
        Solver::Rk4 { max_step } => (max_step, None),
        Solver::Dopri5 { rtol, atol } => (None, Some(("dopri5", rtol, atol))),
        Solver::Bdf { rtol, atol } => (None, Some(("bdf", rtol, atol))),
    };
    if let Some(m) = max_step {
        let resolution = 2.0 * crate::simulate::clock::ulp(clock.t0.abs().max(clock.stop.abs()));
        if !(m.is_finite() && m > 0.0) || m < resolution {
            return Err(Error::Experiment(format!(
                "the largest RK4 step {m:e} s must be finite and above the resolution of the run's times ({resolution:e} s)"
            )));
        }
        let per_step = (clock.h / m).ceil().max(1.0);
        let total = per_step * clock.steps as f64;
        if total > e.max_steps as f64 {
            return Err(Error::Experiment(format!(
                "the largest RK4 step {m:e} s makes {total:e} internal steps ({per_step:e} per communication step of {} s), over the cap of {} steps of a run (Experiment::max_steps, --max-steps)",
                clock.h, e.max_steps
            )));
        }
    }
    if let Some((name, rtol, atol)) = tolerances {
        if !(rtol.is_finite() && rtol >= MIN_RTOL) {
            return Err(Error::Experiment(format!(
                "the {name} relative tolerance {rtol:e} is below {MIN_RTOL:e} (100 machine epsilons), which no f64 step can meet"
            )));
        }
        if !(atol.is_finite() && atol >= 0.0) {
            return Err(Error::Experiment(format!("the {name} absolute tolerance {atol:e} must be finite and >= 0")));
        }
    }
    Ok(())
}

/// Instances kept between runs of one system ([`Execution::with_pool`], `simulate_with`): the instance of each
/// position, reused only for the same FMU (the same loaded archive) and name.
#[derive(Default)]
pub struct InstancePool {
    slots: Vec<Option<Instance>>,
}

impl InstancePool {
    /// An empty pool.
    pub fn new() -> InstancePool {
        InstancePool::default()
    }

    /// Instances held.
    pub fn len(&self) -> usize {
        self.slots.iter().flatten().count()
    }

    /// Whether the pool holds no instance.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub(crate) fn take(&mut self, index: usize, spec: &crate::system::InstanceSpec) -> Option<Instance> {
        let inst = self.slots.get_mut(index)?.take()?;
        (std::sync::Arc::ptr_eq(inst.fmu(), &spec.fmu) && inst.name() == spec.name).then_some(inst)
    }

    pub(crate) fn put(&mut self, index: usize, inst: Instance) {
        if self.slots.len() <= index {
            self.slots.resize_with(index + 1, || None);
        }
        self.slots[index] = Some(inst);
    }
}

//! The driver of a run: checks, the plan, instantiation and initialization (FMI 2.0
//! section 4.2.4), then the steps handed to the algorithm with the observers attached,
//! then the summary and termination.

use crate::error::{Error, Result};
use crate::fmu::{Instance, Interface};
use crate::me::{MeUnit, Solver};
use crate::simulate::algorithm::{Communication, Core, Jacobi, Ordered, ThreadedJacobi};
use crate::simulate::clock::Clock;
use crate::simulate::lane::{apply_start_values, Lane};
use crate::simulate::me_group::MeGroup;
use crate::simulate::observer::{Deadline, Observer, Observers, Profiler, Recorder};
use crate::simulate::plan::{default_record, run_ops, Plan};
use crate::simulate::types::{Algorithm, Experiment, Results, Summary};
use crate::system::{BaseType, System, VariableRef};
use std::time::{Duration, Instant};

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
/// `dopri5` tolerance no f64 step can meet.
fn check_solver(e: &Experiment, clock: &Clock, system: &System) -> Result<()> {
    if !system.instances.iter().any(|i| i.fmu.interface() == Interface::ModelExchange) {
        return Ok(());
    }
    match e.solver {
        Solver::Rk4 { max_step: Some(m) } => {
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
        Solver::Rk4 { max_step: None } => {}
        Solver::Dopri5 { rtol, atol } | Solver::Bdf { rtol, atol } => {
            let name = if matches!(e.solver, Solver::Bdf { .. }) { "bdf" } else { "dopri5" };
            if !(rtol.is_finite() && rtol >= MIN_RTOL) {
                return Err(Error::Experiment(format!(
                    "the {name} relative tolerance {rtol:e} is below {MIN_RTOL:e} (100 machine epsilons), which no f64 step can meet"
                )));
            }
            if !(atol.is_finite() && atol >= 0.0) {
                return Err(Error::Experiment(format!(
                    "the {name} absolute tolerance {atol:e} must be finite and >= 0"
                )));
            }
        }
    }
    Ok(())
}

/// Instantiates, initializes and runs `system` with fixed-step Co-Simulation.
pub fn simulate(system: &System, experiment: &Experiment) -> Result<(Results, Summary)> {
    let (results, summary) = simulate_recorded(system, experiment);
    summary.map(|s| (results, s))
}

/// [`simulate`], with the rows recorded up to the last completed step also when the run
/// fails (an FMU's error, a crashed host, a time limit): nothing recorded is lost.
pub fn simulate_recorded(system: &System, experiment: &Experiment) -> (Results, Result<Summary>) {
    let mut results = Results::default();
    let summary = run(system, experiment, &mut results, None, None);
    (results, summary)
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
    pool: Option<&mut InstancePool>,
    sink: Option<&'s mut RowSink<'s>>,
) -> Result<(Results, Summary)> {
    let mut results = Results::default();
    let pool = if experiment.isolation.is_some() { None } else { pool };
    let summary = run(system, experiment, &mut results, pool, sink)?;
    Ok((results, summary))
}

fn run<'s>(
    system: &System,
    experiment: &Experiment,
    out: &mut Results,
    mut pool: Option<&mut InstancePool>,
    sink: Option<&'s mut RowSink<'s>>,
) -> Result<Summary> {
    let wall = Instant::now();
    let deadline = experiment.timeout.map(|limit| (wall + limit, limit));
    let clock = Clock::new(experiment, system)?;
    check_solver(experiment, &clock, system)?;
    check_single_instance(system)?;
    if experiment.threads == 0 {
        return Err(Error::Experiment("threads must be at least 1".into()));
    }
    let record: Vec<VariableRef> = match &experiment.record {
        None => default_record(system),
        Some(names) => names.iter().map(|n| system.resolve(n)).collect::<Result<_>>()?,
    };
    if let Some(r) = record.iter().find(|r| r.base_type == BaseType::String) {
        return Err(Error::Import(crate::ImportError::InvalidValue {
            variable: system.name_of(r),
            value: String::new(),
            reason: "String variables cannot be recorded in CSV".into(),
        }));
    }
    let mut plan = Plan::new(system, &record, experiment.algorithm)?;
    // Model Exchange instances connected to each other are integrated together
    let mut group = MeGroup::coupled(system, experiment.max_steps)?;
    if let Some(g) = group.as_mut() {
        g.stop_time = experiment.stop_time;
    }
    let record_slots: Vec<usize> = record.iter().map(|r| plan.slot(r)).collect();
    // all recorded variables, one get per instance and type (for the first row)
    let mut record_gets = plan.record_gets(&record);
    let mut algorithm: Box<dyn Communication> = match (experiment.algorithm, plan.ordered.take()) {
        (Algorithm::Ordered, Some(ops)) => {
            plan.ordered = Some(ops);
            let record_gets = plan.ordered_record_gets(&record);
            Box::new(Ordered { ops: plan.ordered.take().unwrap_or_default(), record_gets })
        }
        _ if experiment.threads > 1 => Box::new(ThreadedJacobi { threads: experiment.threads }),
        _ => Box::new(Jacobi),
    };
    if let Some(table) = &experiment.input {
        if experiment.threads > 1 {
            return Err(Error::Experiment("input signals are applied in one thread: use threads = 1".into()));
        }
        algorithm = Box::new(crate::simulate::input::WithInput::new(algorithm, system, table, &clock)?);
    }
    if let Some(queue) = &experiment.between_steps {
        algorithm = Box::new(crate::simulate::between::WithSets { inner: algorithm, queue: queue.clone() });
    }
    let single = system.instances.len() == 1;
    let names: Vec<String> =
        record.iter().map(|r| if single { system.variable(r).name.clone() } else { system.name_of(r) }).collect();
    let mut recorder = Recorder::new(names, record_slots, clock.rows(), clock.steps, experiment.progress, sink);
    // an FMU's exit() inside a call during the run reports it with these rows
    let registered = crate::exit_guard::Registered::new(recorder.shared.clone());
    let outcome = (|| -> Result<Summary> {
        // instantiate and initialize (FMI 2.0 section 4.2.4)
        let mut lanes: Vec<Lane> = Vec::with_capacity(system.instances.len());
        for (index, spec) in system.instances.iter().enumerate() {
            let inst = match pool.as_deref_mut().and_then(|p| p.take(index, spec)) {
                Some(mut inst) => {
                    inst.reset()?;
                    inst
                }
                None => match &experiment.isolation {
                    Some(iso) if iso.covers(&spec.name) => {
                        Instance::new_isolated(&spec.fmu, &spec.name, iso, deadline)?
                    }
                    _ => Instance::new(&spec.fmu, &spec.name)?,
                },
            };
            lanes.push(Lane::new(
                index,
                inst,
                std::mem::take(&mut plan.jacobi_gets[index]),
                std::mem::take(&mut plan.jacobi_gets_rec[index]),
                std::mem::take(&mut plan.jacobi_sets[index]),
            ));
        }
        let mut core = Core {
            lanes,
            values: vec![0.0; plan.sources.len()],
            group,
            solver: experiment.solver,
            clock,
            profile: experiment.profile,
            parallel_steps: 0,
        };
        let t0 = clock.t0;
        for (lane, spec) in core.lanes.iter_mut().zip(&system.instances) {
            lane.inst.setup_experiment(None, t0, Some(experiment.stop_time))?;
            apply_start_values(&mut lane.inst, spec)?;
            lane.inst.enter_initialization_mode()?;
        }
        algorithm.propagate(&mut core)?;
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
        // the initial event iteration of every Model Exchange group
        for lane in core.lanes.iter_mut() {
            if let (Some(unit), Some(solo)) = (lane.unit.as_mut(), lane.solo.as_mut()) {
                solo.iterate(&mut crate::simulate::me_group::Solo { inst: &mut lane.inst, unit }, t0)?;
            }
        }
        if let Some(g) = core.group.as_mut() {
            g.iterate(core.lanes.as_mut_slice(), t0)?;
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
        algorithm.propagate(&mut core)?;
        run_ops(&mut record_gets, core.lanes.as_mut_slice(), &mut core.values, None)?;
        recorder.push_row(t0, &core.values);
        // an FMU may end the run in its initial event iteration
        let mut ended = core.lanes.iter().find(|l| l.unit.as_ref().is_some_and(|u| u.terminated)).map(|l| {
            Error::Terminated { instance: l.inst.name().to_string(), time: t0, reason: "terminateSimulation" }
        });

        let mut profiler = Profiler::new(core.lanes.len());
        if ended.is_none() {
            let mut limit = deadline.map(|(at, limit)| Deadline { at, limit });
            let mut list = vec![&mut recorder as &mut dyn Observer];
            if let Some(d) = limit.as_mut() {
                list.push(d);
            }
            let mut cancel = experiment.cancel.clone().map(crate::simulate::observer::Cancel);
            if let Some(c) = cancel.as_mut() {
                list.push(c);
            }
            let mut observers = Observers { list, calls: experiment.profile.then_some(&mut profiler) };
            match algorithm.run(&mut core, &mut observers) {
                Ok(()) => {}
                Err(e @ Error::Terminated { .. }) => ended = Some(e),
                Err(e) => return Err(e),
            }
        }
        let mut ended_by = None;
        if let Some(Error::Terminated { instance, time, reason }) = ended {
            // the row at the time the run ended, every recorded variable read as its
            // instance now has it: Co-Simulation at fmi2LastSuccessfulTime (fmpy and fmusim
            // record it too), Model Exchange at the event that set terminateSimulation,
            // after its event iteration (fmpy with record_events records it too)
            if time > recorder.last_time().unwrap_or(f64::NEG_INFINITY) {
                run_ops(&mut record_gets, core.lanes.as_mut_slice(), &mut core.values, None)?;
                recorder.push_row(time, &core.values);
            }
            ended_by = Some((instance, time, reason));
        }
        if experiment.profile {
            for lane in core.lanes.iter() {
                profiler.spent[lane.index] += lane.spent;
            }
        }
        let mut summary = Summary {
            steps: recorder.steps_done(),
            parallel_steps: core.parallel_steps,
            wall_time: Duration::ZERO,
            ended_by,
            ..Summary::default()
        };
        for lane in core.lanes.iter_mut() {
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
        if let Some(pool) = pool {
            for lane in std::mem::take(&mut core.lanes) {
                pool.put(lane.index, lane.inst);
            }
        }
        drop(core);
        summary.instance_time = system.instances.iter().map(|s| s.name.clone()).zip(profiler.spent).collect();
        summary.wall_time = wall.elapsed();
        Ok(summary)
    })();
    drop(registered);
    *out = recorder.take_results();
    outcome
}

/// Where [`simulate_with`] hands each row: the time and the recorded values, in the order
/// of [`Experiment::record`](crate::Experiment::record).
pub type RowSink<'s> = dyn FnMut(f64, &[f64]) + 's;

/// Instances kept between runs of one system by [`simulate_with`]: the instance of each
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

    fn take(&mut self, index: usize, spec: &crate::system::InstanceSpec) -> Option<Instance> {
        let inst = self.slots.get_mut(index)?.take()?;
        (std::sync::Arc::ptr_eq(inst.fmu(), &spec.fmu) && inst.name() == spec.name).then_some(inst)
    }

    fn put(&mut self, index: usize, inst: Instance) {
        if self.slots.len() <= index {
            self.slots.resize_with(index + 1, || None);
        }
        self.slots[index] = Some(inst);
    }
}

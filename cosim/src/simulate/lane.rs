//! A lane: one instance with everything its steps need, stepped by one thread at a time.

use crate::error::{Error, Result};
use crate::fmu::{FmuState, Instance};
use crate::me::{MeUnit, Solver};
use crate::simulate::clock::Point;
use crate::simulate::me_group::{MeGroup, Members, Solo};
use crate::simulate::plan::{Instances, Op};
use crate::simulate::ticks::Ticks;
use crate::system::{BaseType, InstanceSpec, Value, VariableRef};
use std::time::{Duration, Instant};

/// One instance with its integrator (Model Exchange), its saved state (Discard retry)
/// and, for `jacobi`, its own batched gets and sets.
pub(crate) struct Lane {
    /// Index of the instance in the system.
    pub(crate) index: usize,
    pub(crate) inst: Instance,
    /// Model Exchange: the integration state.
    pub(crate) unit: Option<MeUnit>,
    /// Model Exchange, connected to no other ME instance: its group of one (a member of
    /// the coupled group is advanced by that group).
    pub(crate) solo: Option<MeGroup>,
    pub(crate) saved: Option<FmuState>,
    pub(crate) gets: Vec<Op>,
    pub(crate) gets_rec: Vec<Op>,
    pub(crate) sets: Vec<Op>,
    /// Time in this lane's calls (`jacobi` when profiling).
    pub(crate) spent: Duration,
    pub(crate) retries: u64,
    /// The first error of this lane's last step (when stepped in a thread).
    pub(crate) error: Option<Error>,
    /// Its step was handed to its host ([`Lane::post_step`]) and waits to be collected.
    pub(crate) posted: bool,
    /// The run's last communication point, s (NaN: not known): an FMU that asks to end
    /// the simulation there has not ended it early ([`Lane::advance`]).
    pub(crate) last_point: f64,
    /// FMI 3.0 clocks: the input clocks' ticks and every clock's count (`ticks.rs`).
    pub(crate) ticks: Option<Ticks>,
}

impl Instances for [Lane] {
    #[inline]
    fn instance(&mut self, i: usize) -> &mut Instance {
        &mut self[i].inst
    }
}

impl Members for [Lane] {
    #[inline]
    fn member(&mut self, m: usize) -> Option<(&mut Instance, &mut MeUnit)> {
        let lane = &mut self[m];
        lane.unit.as_mut().map(|u| (&mut lane.inst, u))
    }
}

impl Lane {
    /// A lane for `inst`, the instance `index` of the system, with its `jacobi` calls.
    pub(crate) fn new(index: usize, inst: Instance, gets: Vec<Op>, gets_rec: Vec<Op>, sets: Vec<Op>) -> Lane {
        Lane {
            index,
            inst,
            unit: None,
            solo: None,
            saved: None,
            gets,
            gets_rec,
            sets,
            spent: Duration::ZERO,
            retries: 0,
            error: None,
            posted: false,
            last_point: f64::NAN,
            ticks: None,
        }
    }

    /// A member of the coupled Model Exchange group (advanced by the group, not alone).
    #[inline]
    pub(crate) fn in_group(&self) -> bool {
        self.unit.is_some() && self.solo.is_none()
    }

    /// `do_step` (or the integrator of its group of one over the step), with the Discard
    /// retry if enabled. A member of the coupled Model Exchange group is not advanced here.
    ///
    /// An FMU that completes the run's last step and asks to end the simulation there
    /// (FMI 3.0 `terminateSimulation`, FMI 2.0 Discard with `fmi2Terminated` at
    /// `lastSuccessfulTime` = the step's end, a Model Exchange `terminateSimulation` at
    /// the stop time) has not ended it early: the step is complete, and the other
    /// instances take theirs as in any other step.
    #[inline]
    pub(crate) fn advance(&mut self, solver: Solver, t: f64, t_next: f64) -> Result<()> {
        match self.advance_inner(solver, t, t_next) {
            Err(Error::Terminated { time, .. }) if t_next == self.last_point && ends_the_step(t, t_next, time) => {
                Ok(())
            }
            r => r,
        }
    }

    #[inline]
    fn advance_inner(&mut self, solver: Solver, t: f64, t_next: f64) -> Result<()> {
        let dt = t_next - t; // as fmpy: the step is the difference of the two points
        self.posted = false;
        if let Some(ticks) = self.ticks.as_mut() {
            return match (&mut self.unit, &mut self.solo) {
                (None, _) => step_ticking(&mut self.inst, ticks, t, t_next),
                (Some(unit), Some(group)) => me_ticking(&mut self.inst, unit, group, ticks, solver, t, t_next),
                // clocks of a coupled group's member are refused at initialization
                (Some(_), None) => Ok(()),
            };
        }
        match (&mut self.unit, &mut self.saved) {
            (None, None) => match self.inst.do_step(t, dt) {
                Ok(()) => Ok(()),
                Err(e) => Err(ended_or(&mut self.inst, e.into(), t, t_next)),
            },
            (None, Some(state)) => {
                self.retries += step_with_retry(&mut self.inst, state, t, dt, 0)?;
                Ok(())
            }
            (Some(unit), _) => match self.solo.as_mut() {
                Some(group) => group.advance(&mut Solo { inst: &mut self.inst, unit }, solver, t, t_next),
                None => Ok(()),
            },
        }
    }

    /// An isolated Co-Simulation instance without Discard retry: its step from `t` to
    /// `t_next` handed to its host, which runs it while the master goes on (to the other
    /// hosts); [`Lane::advance`] then collects it. False (nothing done) for the others.
    #[inline]
    pub(crate) fn post_step(&mut self, t: f64, t_next: f64) -> bool {
        self.posted = self.can_post() && self.inst.post_step(t, t_next - t);
        self.posted
    }

    /// Whether [`Lane::post_step`] hands the step to a host: one `fmi3DoStep`, so not an
    /// instance with clocks (its step closes and opens clock events around its steps).
    #[inline]
    pub(crate) fn can_post(&self) -> bool {
        self.unit.is_none() && self.saved.is_none() && self.ticks.is_none() && self.inst.fmu().is_isolated()
    }

    /// One `jacobi` step of this instance: its inputs set from `values` (the outputs of
    /// the previous step), the step, its outputs fetched into its get buffers. The call
    /// sequence of an instance is the same whichever thread runs it.
    #[inline]
    pub(crate) fn jacobi_step(&mut self, values: &[f64], p: Point, profile: bool, solver: Solver) -> Result<()> {
        let start = profile.then(Instant::now);
        if !self.posted {
            self.jacobi_inputs(values, p)?;
        }
        self.advance(solver, p.t, p.t_next)?;
        self.jacobi_outputs(p)?;
        if let Some(start) = start {
            self.spent += start.elapsed();
        }
        Ok(())
    }

    /// The first part of a `jacobi` step: the inputs (unless the first step).
    #[inline]
    pub(crate) fn jacobi_inputs(&mut self, values: &[f64], p: Point) -> Result<()> {
        if p.n > 0 {
            self.set_inputs(values)?;
        }
        Ok(())
    }

    /// The last part of a `jacobi` step: the outputs fetched.
    #[inline]
    pub(crate) fn jacobi_outputs(&mut self, p: Point) -> Result<()> {
        let gets = if p.output_point { &mut self.gets_rec } else { &mut self.gets };
        for op in gets.iter_mut() {
            op.fetch(&mut self.inst)?;
        }
        Ok(())
    }

    /// The outputs fetched by the last [`Lane::jacobi_step`] into their slots.
    #[inline]
    pub(crate) fn scatter(&self, values: &mut [f64], output_point: bool) {
        let gets = if output_point { &self.gets_rec } else { &self.gets };
        for op in gets {
            op.scatter(values);
        }
    }

    /// The outputs of this lane's `jacobi` gets read from the instance into `values`.
    pub(crate) fn get_outputs(&mut self, values: &mut [f64]) -> Result<()> {
        for op in self.gets.iter_mut() {
            op.run(&mut self.inst, values)?;
        }
        Ok(())
    }

    /// The inputs set from `values`.
    #[inline]
    pub(crate) fn set_inputs(&mut self, values: &[f64]) -> Result<()> {
        for op in self.sets.iter_mut() {
            op.gather(values);
            op.apply(&mut self.inst)?;
        }
        Ok(())
    }
}

/// A Co-Simulation step from `t` to `t_next` of an instance with clocks: the clock event
/// opened at `t` by the step before closed, then to each tick of its input clocks in the
/// step, the clock event there, on to the next (see `ticks.rs`); the output clocks' ticks
/// and the intervals the FMU gives taken after every event. The ticks at `t_next` open
/// their event: the exchange at `t_next` happens in it, as at any event (the clocked
/// variables of the ticking clocks read and set through the FMU), and the next step closes
/// it before it steps.
fn step_ticking(inst: &mut Instance, ticks: &mut Ticks, t: f64, t_next: f64) -> Result<()> {
    let mut at = t;
    if ticks.take_open() {
        inst.close_clock_event().map_err(|e| ended_or(inst, e.into(), at, at))?;
        ticks.after_events(inst, false)?;
    }
    loop {
        let due = ticks.due(at, t_next);
        let end = due.as_ref().map_or(t_next, |(tick, _)| *tick);
        if end > at {
            inst.do_step(at, end - at).map_err(|e| ended_or(inst, e.into(), at, end))?;
            ticks.after_events(inst, false)?;
        }
        let Some((tick, vrs)) = due else { break };
        inst.clock_event(tick, &vrs).map_err(|e| ended_or(inst, e.into(), tick, tick))?;
        ticks.ticked(&vrs);
        ticks.after_events(inst, false)?;
        at = tick;
    }
    if let Some(vrs) = ticks.at(t_next) {
        inst.open_clock_event(t_next, &vrs).map_err(|e| ended_or(inst, e.into(), t_next, t_next))?;
        ticks.opened(&vrs);
    }
    Ok(())
}

/// A Model Exchange step from `t` to `t_next` of an instance with clocks (integrated on its
/// own): integrated to each tick of its input clocks in the step, the event there (Event
/// Mode, `fmi3SetClock` of the ticking clocks, the event iteration, the integrator started
/// again from the states after it), on to the next.
fn me_ticking(
    inst: &mut Instance,
    unit: &mut MeUnit,
    group: &mut MeGroup,
    ticks: &mut Ticks,
    solver: Solver,
    t: f64,
    t_next: f64,
) -> Result<()> {
    let mut at = t;
    loop {
        let due = ticks.due(at, t_next);
        let end = due.as_ref().map_or(t_next, |(tick, _)| *tick);
        // a time event the FMU gives at a tick where this advance ends is that tick's event
        // (a clocked FMU may publish its next activation as nextEventTime): the tick runs it
        // with its clocks activated, not the integrator as a time event without them
        if unit.next_time_event.is_some_and(|te| (te - end).abs() <= ticks.tolerance()) && ticks.at(end).is_some() {
            unit.next_time_event = None;
        }
        if end > at {
            group.advance(&mut Solo { inst, unit }, solver, at, end)?;
            ticks.after_events(inst, false)?;
        }
        let Some((tick, vrs)) = due else { return Ok(()) };
        inst.set_time(tick)?;
        // an input event: the integrator starts again from the states the FMU gives after
        // it (a clocked partition may reset continuous states: valuesOfContinuousStatesChanged)
        group.input_event(&mut Solo { inst, unit }, tick, "clock", &[], |solo| Ok(solo.inst.set_clocks(&vrs)?))?;
        group.ended(&mut Solo { inst, unit }, tick)?;
        ticks.ticked(&vrs);
        ticks.after_events(inst, false)?;
        at = tick;
    }
}

/// Whether `time`, where an FMU ended the run in the step from `t` to `t_next`, is that
/// step's end: to a millionth of the step (the FMU's `t + (t_next - t)` may round away
/// from `t_next` by an ulp; an FMU that stops short of the end by more has stopped early).
fn ends_the_step(t: f64, t_next: f64, time: f64) -> bool {
    time >= t_next - 1e-6 * (t_next - t)
}

/// How the FMU said it ended the run (Co-Simulation).
pub(crate) const DISCARD_TERMINATED: &str = "fmi2DoStep returned fmi2Discard with fmi2Terminated";
/// The same end of a run by an FMI 3.0 FMU.
pub(crate) const FMI3_TERMINATED: &str = "fmi3DoStep returned terminateSimulation";

/// The error of a step from `t` to `t_end`: an fmi2Discard with
/// `fmi2GetBooleanStatus(fmi2Terminated)` true is the FMU ending the run at
/// `fmi2GetRealStatus(fmi2LastSuccessfulTime)` (`t`, the last point it reached, if it
/// cannot say), anything else is `e`. A time the FMU reports outside the step (an FMI 3.0
/// `lastSuccessfulTime` of t + 1000 s) is an error naming the FMU, the call and the times,
/// not a row at that time.
#[cold]
fn ended_or(inst: &mut Instance, e: Error, t: f64, t_end: f64) -> Error {
    if matches!(e, Error::Import(crate::ImportError::Fmi { status: crate::Status::Discard, .. }))
        && inst.terminated_status() == Some(true)
    {
        let reported = inst.last_successful_time();
        let function = if inst.is_fmi3() { "fmi3DoStep" } else { "fmi2GetRealStatus(fmi2LastSuccessfulTime)" };
        let time = match reported {
            Some(x) if x.is_finite() && x >= t && x <= t_end => x,
            None => t,
            // the FMU's statement is no time of this step: no row is written at it (an
            // Experiment error: the call itself returned what the standard allows)
            Some(x) => {
                return Error::Experiment(format!(
                    "{}: {function} ended the simulation at lastSuccessfulTime = {x} s, outside the step from {t} \
                     to {t_end} s it was asked to take: the run stops at {t} s",
                    inst.name()
                ))
            }
        };
        let reason = if inst.is_fmi3() { FMI3_TERMINATED } else { DISCARD_TERMINATED };
        return Error::Terminated { instance: inst.name().to_string(), time, reason };
    }
    e
}

/// `fmi2DoStep` with the state saved first; on fmi2Discard the state is restored and the
/// step taken as two halves (recursively, at most 10 levels), unless the FMU ended the run
/// (`fmi2Terminated`). Returns the number of retries.
fn step_with_retry(inst: &mut Instance, state: &mut FmuState, t: f64, dt: f64, depth: u32) -> Result<u64> {
    inst.update_state(state)?;
    match inst.do_step(t, dt).map_err(|e| ended_or(inst, e.into(), t, t + dt)) {
        Ok(()) => Ok(0),
        Err(Error::Import(crate::ImportError::Fmi { status: crate::Status::Discard, .. })) if depth < 10 => {
            inst.set_state(state)?;
            let half = 0.5 * dt;
            let a = step_with_retry(inst, state, t, half, depth + 1)?;
            let b = step_with_retry(inst, state, t + half, dt - half, depth + 1)?;
            Ok(1 + a + b)
        }
        Err(e) => Err(e),
    }
}

/// Sets the start values of an instance (before initialization mode), one call each.
pub fn apply_start_values(inst: &mut Instance, spec: &InstanceSpec) -> Result<()> {
    let md = spec.fmu.description();
    for (index, value) in &spec.start_values {
        let vr = md.model_variables[*index].value_reference;
        match value {
            Value::Real(x) => inst.set_real(&[vr], &[*x])?,
            Value::Integer(x) => inst.set_integer(&[vr], &[*x])?,
            Value::Boolean(x) => inst.set_boolean(&[vr], &[*x as i32])?,
            Value::String(s) => inst.set_string(vr, s)?,
        }
    }
    Ok(())
}

/// The value of `r` as its instance has it now, one call.
pub(crate) fn get_value(inst: &mut Instance, r: &VariableRef) -> Result<Value> {
    let vr = [r.value_reference];
    Ok(match r.base_type {
        BaseType::Real => {
            let mut v = [0.0];
            inst.get_real(&vr, &mut v)?;
            Value::Real(v[0])
        }
        BaseType::Integer => {
            let mut v = [0];
            inst.get_integer(&vr, &mut v)?;
            Value::Integer(v[0])
        }
        BaseType::Boolean => {
            let mut v = [0];
            inst.get_boolean(&vr, &mut v)?;
            Value::Boolean(v[0] != 0)
        }
        BaseType::String => Value::String(inst.get_string(r.value_reference)?),
    })
}

//! The one Model Exchange integrator of the master: a group of ME instances integrated
//! together, so that an event of any of them is an event of all (FMI 2.0 section 3.2.3,
//! for a system of FMUs). An ME instance connected to no other ME instance is a group of
//! one; the ME instances connected to each other form one group.
//!
//! Over a communication step the members' states are one system stepped by one
//! [`crate::integrator::Integrator`] (rk4, dopri5 or bdf: [`Solver::integrator`]), the members' inputs held
//! between events. One event loop ([`MeGroup::advance`]) handles every method alike:
//!
//! - **time events**, the input of the loop: each member's next event time
//!   ([`MeUnit::next_time_event`], from its last event iteration) caps the step, which
//!   ends exactly on it; the events due at a time (to the slack of [`time_slack`]) are
//!   handled there. A future source of time events (FMI 3.0 clock ticks) sets the same
//!   field or adds to the times [`MeGroup::next_time_event`] returns.
//! - **state events**: after each accepted step every member's event indicators are read
//!   at its end; an indicator that changed sign is located by the Illinois method on the
//!   step's dense output ([`crate::integrator::Integrator::interpolate`]) to [`EVENT_TIME_TOLERANCE`], with
//!   no re-integration; the earliest crossing of any member ends the step of all there.
//! - **step events**: `fmi2CompletedIntegratorStep` after each accepted step.
//!
//! At an event every member enters event mode at that time; then, until a fixed point,
//! outputs are carried through the connections between members in topological order and
//! every member calls `fmi2NewDiscreteStates`. The iteration ends when no member asks for
//! another one and no input changed in the last propagation; after [`MAX_EVENT_ROUNDS`]
//! rounds it stops with [`Error::EventIteration`] naming the members still changing. Then
//! every member enters continuous-time mode and the integrator starts again from the
//! states the iteration left ([`Start`]).
//!
//! A step ends at the end of each communication step (where the members' inputs may
//! change), except for a method that keeps a history ([`crate::integrator::Integrator::steps_past_points`])
//! in a group without inputs: its steps pass the points, whose states come from the
//! dense output. Between events the connections from and to Co-Simulation instances are
//! carried at communication points only.

use crate::error::{Error, Result};
use crate::fmu::{Instance, Interface};
use crate::integrator::Start;
use crate::me::{Event, MeUnit, Solver, EVENT_TIME_TOLERANCE};
use crate::simulate::plan::{exchange_len, ordered_ops, Op};
use crate::system::{Connection, System, VariableRef};

mod members;
mod system;

pub(crate) use members::{Members, Solo};
use system::{locate_on_dense_output, GroupIntegrator};

/// Rounds of the event iteration before it is declared not converging.
pub const MAX_EVENT_ROUNDS: usize = 100;

/// Model Exchange instances integrated together.
pub(crate) struct MeGroup {
    /// Instance indices of the members.
    pub(crate) members: std::sync::Arc<[usize]>,
    /// The connections between members, in topological order.
    ops: Vec<Op>,
    values: Vec<f64>,
    before: Vec<f64>,
    /// Internal steps tried (accepted and rejected) so far, and the cap on them.
    tried: u64,
    max_steps: u64,
    /// The integrator of the group (made at its first step; its history and step size
    /// kept between communication steps).
    integrator: Option<Box<GroupIntegrator>>,
    /// The stop time of the run: a method that steps past communication points does not
    /// step past it.
    pub(crate) stop_time: f64,
}

impl MeGroup {
    /// The group of one: instance `index` on its own.
    pub(crate) fn solo(index: usize, max_steps: u64) -> MeGroup {
        MeGroup {
            members: std::sync::Arc::new([index]),
            ops: Vec::new(),
            values: Vec::new(),
            before: Vec::new(),
            tried: 0,
            max_steps,
            integrator: None,
            stop_time: f64::INFINITY,
        }
    }

    /// The coupled group of `system`: all its Model Exchange instances, if two of them
    /// are connected.
    pub(crate) fn coupled(system: &System, max_steps: u64) -> Result<Option<MeGroup>> {
        let me = |i: usize| system.instances[i].fmu.interface() == Interface::ModelExchange;
        let links: Vec<Connection> =
            system.connections.iter().filter(|c| me(c.from.instance) && me(c.to.instance)).cloned().collect();
        if links.is_empty() {
            return Ok(None);
        }
        let members: std::sync::Arc<[usize]> = (0..system.instances.len()).filter(|i| me(*i)).collect();
        let sub = System { instances: system.instances.clone(), connections: links, clock_connections: Vec::new() };
        let mut sources: Vec<VariableRef> = Vec::new();
        for c in &sub.connections {
            if !sources.contains(&c.from) {
                sources.push(c.from.clone());
            }
        }
        let ops = ordered_ops(&sub, &sources, &sources)?;
        let n = exchange_len(&sub, &sources);
        Ok(Some(MeGroup {
            members,
            ops,
            values: vec![0.0; n],
            before: vec![0.0; n],
            tried: 0,
            max_steps,
            integrator: None,
            stop_time: f64::INFINITY,
        }))
    }

    /// Whether lane `i` is a member.
    pub(crate) fn contains(&self, i: usize) -> bool {
        self.members.contains(&i)
    }

    /// Carries the members' connections; returns whether any carried value changed since
    /// the last propagation, and appends the members whose inputs changed to `changed`.
    fn propagate<L: Members + ?Sized>(&mut self, lanes: &mut L, changed: &mut Vec<usize>) -> Result<bool> {
        self.before.copy_from_slice(&self.values);
        for op in self.ops.iter_mut() {
            op.run(lanes.instance(op.instance), &mut self.values)?;
        }
        let mut any = false;
        for op in &self.ops {
            let read = op.slots().iter().copied().chain(op.residual_slots());
            if op.is_set() && read.into_iter().any(|s| self.values[s].to_bits() != self.before[s].to_bits()) {
                any = true;
                if !changed.contains(&op.instance) {
                    changed.push(op.instance);
                }
            }
        }
        Ok(any)
    }

    /// The event iteration of all members, which are in event mode at `time`; ends with
    /// all of them in continuous-time mode, their states and indicators read again.
    pub(crate) fn iterate<L: Members + ?Sized>(&mut self, lanes: &mut L, time: f64) -> Result<()> {
        let mut unsettled = Vec::new();
        // the members unsettled in the last rounds (an oscillation alternates them)
        let mut recent: Vec<usize> = Vec::new();
        self.propagate(lanes, &mut unsettled)?;
        for round in 0..MAX_EVENT_ROUNDS {
            unsettled.clear();
            for &m in self.members.iter() {
                let Some((inst, unit)) = lanes.member(m) else { continue };
                let info = inst.new_discrete_states()?;
                if info.terminate_simulation != 0 {
                    unit.terminated = true;
                }
                if info.next_event_time_defined != 0 && info.next_event_time.is_nan() {
                    return Err(nan_event_time(inst, time));
                }
                unit.next_time_event = (info.next_event_time_defined != 0).then_some(info.next_event_time);
                if info.new_discrete_states_needed != 0 {
                    unsettled.push(m);
                }
            }
            let changed = self.propagate(lanes, &mut unsettled)?;
            if round + 10 >= MAX_EVENT_ROUNDS {
                for m in &unsettled {
                    if !recent.contains(m) {
                        recent.push(*m);
                    }
                }
            }
            if unsettled.is_empty() && !changed {
                for &m in self.members.iter() {
                    let Some((inst, unit)) = lanes.member(m) else { continue };
                    inst.enter_continuous_time_mode()?;
                    unit.resume(inst)?;
                }
                return Ok(());
            }
        }
        recent.sort_unstable();
        Err(Error::EventIteration {
            time,
            rounds: MAX_EVENT_ROUNDS,
            instances: recent.iter().map(|m| lanes.instance(*m).name().to_string()).collect(),
        })
    }

    /// An event at `time` caused by `who` (recorded as `kind`): all members enter event
    /// mode and iterate together.
    fn event<L: Members + ?Sized>(
        &mut self,
        lanes: &mut L,
        time: f64,
        kind: &'static str,
        who: &[usize],
    ) -> Result<()> {
        self.input_event(lanes, time, kind, who, |_| Ok(()))
    }

    /// An event at `time` caused by `who` (recorded as `kind`) in which `set` sets inputs
    /// first: all members enter Event Mode, `set` runs, and they iterate together. The
    /// discrete inputs of a Model Exchange FMU are set so when they change (Event Mode only:
    /// FMI 2.0 section 3.2.3, FMI 3.0 section 3.2.1), which restarts the bdf method.
    pub(crate) fn input_event<L: Members + ?Sized>(
        &mut self,
        lanes: &mut L,
        time: f64,
        kind: &'static str,
        who: &[usize],
        set: impl FnOnce(&mut L) -> Result<()>,
    ) -> Result<()> {
        for &m in self.members.iter() {
            lanes.instance(m).enter_event_mode()?;
        }
        set(lanes)?;
        for &m in who {
            if let Some((inst, unit)) = lanes.member(m) {
                unit.events.push(Event { instance: inst.name().to_string(), time, kind });
            }
        }
        self.iterate(lanes, time)?;
        // the states may have jumped: the method starts again from them (an input change
        // at a known time is a time event the master schedules)
        if let Some(g) = self.integrator.as_mut() {
            g.restart = Some(Start::TimeEvent);
        }
        Ok(())
    }

    /// The time events due at `t` (to `eps`), for every solver: the members whose next time
    /// event is due are recorded and all members iterate together; a time event still due
    /// after that is an error. Whether any was due.
    fn time_events_due<L: Members + ?Sized>(&mut self, lanes: &mut L, t: f64, eps: f64) -> Result<bool> {
        let next_time_event = Self::next_time_event;
        let members = self.members.clone();
        let due: Vec<usize> =
            members.iter().copied().filter(|m| next_time_event(lanes, *m).is_some_and(|te| te <= t + eps)).collect();
        if due.is_empty() {
            return Ok(false);
        }
        self.event(lanes, t, "time", &due)?;
        self.ended(lanes, t)?;
        if let Some(m) = members.iter().find(|m| next_time_event(lanes, **m).is_some_and(|te| te <= t + eps)) {
            return Err(Error::Experiment(format!(
                "{}: time event at {t} repeats at the same time",
                lanes.instance(*m).name()
            )));
        }
        Ok(true)
    }

    /// One more internal step tried at `t`; past the cap of the run, the error.
    #[inline]
    fn count_step<L: Members + ?Sized>(&mut self, lanes: &mut L, t: f64) -> Result<()> {
        self.tried += 1;
        if self.tried <= self.max_steps {
            return Ok(());
        }
        let names: Vec<String> = self.members.iter().map(|m| lanes.instance(*m).name().to_string()).collect();
        Err(Error::Experiment(format!(
            "the Model Exchange integrator of {} tried more than {} internal steps by t = {t} s (the cap on the steps of a run: Experiment::max_steps, --max-steps)",
            names.join(", "),
            self.max_steps
        )))
    }

    /// [`Error::Terminated`] at `time` if a member set `terminateSimulation`.
    pub(crate) fn ended<L: Members + ?Sized>(&self, lanes: &mut L, time: f64) -> Result<()> {
        for &m in self.members.iter() {
            if let Some((inst, u)) = lanes.member(m) {
                if u.terminated {
                    return Err(Error::Terminated {
                        instance: inst.name().to_string(),
                        time,
                        reason: "terminateSimulation",
                    });
                }
            }
        }
        Ok(())
    }

    /// The next time event of member `m`, if it has one: the input of the event loop's
    /// time events.
    pub(crate) fn next_time_event<L: Members + ?Sized>(lanes: &mut L, m: usize) -> Option<f64> {
        lanes.member(m).and_then(|(_, u)| u.next_time_event)
    }

    /// Integrates all members from `t` to `t_end` together with `solver`, their inputs
    /// held between events.
    pub(crate) fn advance<L: Members + ?Sized>(
        &mut self,
        lanes: &mut L,
        solver: Solver,
        t: f64,
        t_end: f64,
    ) -> Result<()> {
        self.pending_inputs(lanes, t)?;
        let mut g = match self.integrator.take() {
            Some(g) => g,
            None => Box::new(GroupIntegrator::new(lanes, &self.members, solver)),
        };
        let outcome = self.advance_with(lanes, &mut g, t, t_end);
        g.report(lanes, &self.members, solver);
        self.integrator = Some(g);
        outcome
    }

    /// The discrete inputs that connections set since the last step (the importing layer
    /// holds them back in Continuous-Time Mode: only continuous inputs may change there)
    /// set in an input event at `t`, the members iterating together, as an input file's.
    fn pending_inputs<L: Members + ?Sized>(&mut self, lanes: &mut L, t: f64) -> Result<()> {
        let who: Vec<usize> =
            self.members.iter().copied().filter(|m| lanes.instance(*m).has_pending_inputs()).collect();
        if who.is_empty() {
            return Ok(());
        }
        self.input_event(lanes, t, "input", &who, |lanes| {
            for &m in &who {
                lanes.instance(m).apply_pending_inputs()?;
            }
            Ok(())
        })
    }

    /// The event loop of [`MeGroup::advance`].
    fn advance_with<L: Members + ?Sized>(
        &mut self,
        lanes: &mut L,
        g: &mut GroupIntegrator,
        t: f64,
        t_end: f64,
    ) -> Result<()> {
        let mut t = t;
        let span = t_end - t;
        let eps = time_slack(t_end, span);
        let members = self.members.clone();
        let members: &[usize] = &members;
        let stop_time = self.stop_time;
        g.integrator.communication_step(span, eps);
        loop {
            self.ended(lanes, t)?;
            if t >= t_end - eps {
                return Ok(());
            }
            // time events due now: the event iteration starts the method again
            if self.time_events_due(lanes, t, eps)? {
                g.restart = Some(Start::TimeEvent);
                continue;
            }
            // a step ends at the earliest time event, at the stop time, and, unless the
            // method steps past them, at the end of the communication step
            let mut limit = if g.through { stop_time.max(t_end) } else { t_end };
            for &m in members {
                if let Some(te) = Self::next_time_event(lanes, m) {
                    if te.max(t) < limit {
                        limit = te.max(t);
                    }
                }
            }
            if g.integrator.t() <= t + eps || g.restart.is_some() {
                if g.restart.is_some() {
                    g.start_if_due(lanes, members, t, limit - t)?;
                }
                let (mut sys, integrator, _) = g.parts(lanes, members);
                integrator.step(&mut sys, limit)?;
                // the attempts of the step: one accepted, the rest rejected
                let rejected = g.integrator.work().rejected;
                for _ in 0..=(rejected - g.rejected) {
                    self.count_step(lanes, t)?;
                }
                g.rejected = rejected;
                g.crossing = self.first_crossing(lanes, g, t)?;
            }
            // where the step (or its first state event) ends
            let reached = g.crossing.as_ref().map_or(g.integrator.t(), |(te, _)| *te);
            if reached > t_end + eps {
                // the communication point within the step: the states there from the dense
                // output (the step is completed when the master reaches its end)
                self.interpolate_members(lanes, g, t_end, false)?;
                return Ok(());
            }
            if let Some((te, who)) = g.crossing.take() {
                self.interpolate_members(lanes, g, te, true)?;
                self.event(lanes, te, "state", &who)?;
                g.restart = Some(Start::StateEvent);
                t = te;
                continue;
            }
            // the step is accepted by every member
            let t_new = g.integrator.t();
            let mut step_events: Vec<usize> = Vec::new();
            for (k, &m) in members.iter().enumerate() {
                let Some((inst, u)) = lanes.member(m) else { continue };
                u.x.copy_from_slice(&g.integrator.state()[g.offsets[k]..g.offsets[k + 1]]);
                if u.complete_step(inst, t_new, g.at_step_end && !u.z.is_empty())? {
                    step_events.push(m);
                }
            }
            t = t_new;
            self.ended(lanes, t)?;
            let due_now = |lanes: &mut L, m: usize| Self::next_time_event(lanes, m).is_some_and(|te| te <= t + eps);
            if members.iter().any(|m| due_now(lanes, *m)) {
                let due: Vec<usize> =
                    members.iter().copied().filter(|m| due_now(lanes, *m) || step_events.contains(m)).collect();
                self.event(lanes, t, "time", &due)?;
                g.restart = Some(Start::TimeEvent);
            } else if !step_events.is_empty() {
                self.event(lanes, t, "step", &step_events)?;
                g.restart = Some(Start::StepEvent);
            }
        }
    }

    /// The earliest state event of any member over the last step (t0, t], located on the
    /// dense output, and the members whose crossings are at it (to
    /// [`EVENT_TIME_TOLERANCE`]); `None` when no event indicator changed sign.
    fn first_crossing<L: Members + ?Sized>(
        &self,
        lanes: &mut L,
        g: &mut GroupIntegrator,
        t0: f64,
    ) -> Result<Option<(f64, Vec<usize>)>> {
        let t1 = g.integrator.t();
        let mut crossed: Vec<usize> = Vec::new();
        for (k, &m) in self.members.iter().enumerate() {
            let Some((inst, u)) = lanes.member(m) else { continue };
            if u.z.is_empty() {
                continue;
            }
            u.xt.copy_from_slice(&g.integrator.state()[g.offsets[k]..g.offsets[k + 1]]);
            u.indicators_at(inst, t1)?;
            if MeUnit::crossed(&u.z0, &u.z) {
                crossed.push(k);
            }
        }
        g.at_step_end = crossed.is_empty();
        if crossed.is_empty() {
            return Ok(None);
        }
        let (mut sys, integrator, _) = g.parts(lanes, &self.members);
        integrator.prepare_dense_output(&mut sys)?;
        let mut found: Vec<(usize, f64)> = Vec::new();
        for k in crossed {
            let m = self.members[k];
            let Some((inst, u)) = lanes.member(m) else { continue };
            let te = locate_on_dense_output(inst, u, &*g.integrator, g.offsets[k], t0, t1, &mut g.x)?;
            found.push((m, te));
        }
        let first = found.iter().map(|(_, te)| *te).fold(f64::INFINITY, f64::min);
        let who = found.iter().filter(|(_, te)| *te <= first + EVENT_TIME_TOLERANCE).map(|(m, _)| *m).collect();
        Ok(Some((first, who)))
    }

    /// The members at `s` within the last step, from the dense output: their states set,
    /// and, at an event (`completed`), the step completed there
    /// (`fmi2CompletedIntegratorStep`, its step event left to the event iteration that
    /// follows).
    fn interpolate_members<L: Members + ?Sized>(
        &self,
        lanes: &mut L,
        g: &mut GroupIntegrator,
        s: f64,
        completed: bool,
    ) -> Result<()> {
        g.at_step_end = false;
        g.integrator.interpolate(s, &mut g.x);
        for (k, &m) in self.members.iter().enumerate() {
            let Some((inst, u)) = lanes.member(m) else { continue };
            u.x.copy_from_slice(&g.x[g.offsets[k]..g.offsets[k + 1]]);
            inst.set_time(s)?;
            MeUnit::set_states(inst, &u.x)?;
            if completed {
                u.steps += 1;
                inst.completed_integrator_step()?;
            }
        }
        Ok(())
    }
}

/// The error of a NaN next event time an FMU defined at the event iteration at `time`.
#[cold]
fn nan_event_time(inst: &Instance, time: f64) -> Error {
    let (call, ok) =
        if inst.is_fmi3() { ("fmi3UpdateDiscreteStates", "fmi3OK") } else { ("fmi2NewDiscreteStates", "fmi2OK") };
    Error::Integration(format!(
        "{} ({}): {call} returned a next event time of NaN (nextEventTimeDefined true) with {ok} at t = {time} s",
        inst.name(),
        crate::me::fmu_file(inst)
    ))
}

/// Two times closer than this within a communication step of length `span` ending at
/// `t_end` are the same time: 1e-13 of the time (at most 1e-6 of the step, so that large
/// times do not swallow the step), and at least two ulps of `t_end` (the rounding of the
/// times themselves).
fn time_slack(t_end: f64, span: f64) -> f64 {
    (1e-13 * t_end.abs().max(1.0)).min(1e-6 * span).max(2.0 * crate::simulate::clock::ulp(t_end))
}

//! The one Model Exchange integrator of the master: a group of ME instances integrated
//! together, so that an event of any of them is an event of all (FMI 2.0 section 3.2.3,
//! for a system of FMUs). An ME instance connected to no other ME instance is a group of
//! one; the ME instances connected to each other form one group.
//!
//! Over a communication step the members advance in lockstep: one common internal step
//! (RK4 with the same sub-steps; Dormand-Prince with the smallest step any member asks
//! for, rejected if any member's error is too large), each member's event indicators
//! checked after it. The earliest event of any member (a time event, the first state
//! event crossing located by the Illinois method, a step event) ends the step of all:
//! every member is integrated to that time and enters event mode; then, until a fixed
//! point, outputs are carried through the connections between members in topological
//! order and every member calls `fmi2NewDiscreteStates`. The iteration ends when no
//! member asks for another one and no input changed in the last propagation; after
//! [`MAX_EVENT_ROUNDS`] rounds it stops with [`Error::EventIteration`] naming the members
//! still changing. Then every member enters continuous-time mode.
//!
//! Between events the members' inputs are held, as for any instance over a
//! communication step; the connections from and to Co-Simulation instances are carried at
//! communication points only.

use crate::error::{Error, Result};
use crate::fmu::{Instance, Interface};
use crate::me::{nan_max, Event, MeUnit, Solver, EVENT_TIME_TOLERANCE};
use crate::simulate::plan::{ordered_ops, Instances, Op};
use crate::system::{Connection, System, VariableRef};

mod bdf;

/// Access to the members of a group: each one's instance and integration state.
pub(crate) trait Members: Instances {
    /// Member `m` (an instance index of the system), if it has its integration state.
    fn member(&mut self, m: usize) -> Option<(&mut Instance, &mut MeUnit)>;
}

/// One ME instance on its own: the members of its group of one.
pub(crate) struct Solo<'a> {
    pub(crate) inst: &'a mut Instance,
    pub(crate) unit: &'a mut MeUnit,
}

impl Instances for Solo<'_> {
    fn instance(&mut self, _: usize) -> &mut Instance {
        self.inst
    }
}

impl Members for Solo<'_> {
    fn member(&mut self, _: usize) -> Option<(&mut Instance, &mut MeUnit)> {
        Some((&mut *self.inst, &mut *self.unit))
    }
}

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
    /// The bdf solver's state (its history between communication steps).
    stiff: Option<Box<bdf::GroupBdf>>,
    /// The stop time of the run: the bdf solver steps past communication points, not
    /// past it.
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
            stiff: None,
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
        let n = sources.len();
        Ok(Some(MeGroup {
            members,
            ops,
            values: vec![0.0; n],
            before: vec![0.0; n],
            tried: 0,
            max_steps,
            stiff: None,
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
            if op.is_set() && op.slots().iter().any(|s| self.values[*s].to_bits() != self.before[*s].to_bits()) {
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
        self.restart_stiff();
        Ok(())
    }

    /// The time events due at `t` (to `eps`), for every solver: the members whose next time
    /// event is due are recorded and all members iterate together; a time event still due
    /// after that is an error. Whether any was due.
    fn time_events_due<L: Members + ?Sized>(&mut self, lanes: &mut L, t: f64, eps: f64) -> Result<bool> {
        let next_time_event = |lanes: &mut L, m: usize| lanes.member(m).and_then(|(_, u)| u.next_time_event);
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

    /// The error of a Dormand-Prince step from `t` of size `h` whose error estimate is NaN.
    #[cold]
    fn nan_error_estimate<L: Members + ?Sized>(&self, lanes: &mut L, t: f64, h: f64) -> Error {
        let names: Vec<String> = self
            .members
            .iter()
            .map(|m| {
                let inst = lanes.instance(*m);
                format!("{} ({})", inst.name(), crate::me::fmu_file(inst))
            })
            .collect();
        Error::Integration(format!(
            "{}: the dopri5 error estimate of the step from t = {t} s of {h:e} s is NaN (the state derivatives \
             the FMU returned with OK over the step are infinite or the states overflow); the step is not taken",
            names.join(", ")
        ))
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

    /// Integrates all members from `t` to `t_end` together, their inputs held between
    /// events.
    pub(crate) fn advance<L: Members + ?Sized>(
        &mut self,
        lanes: &mut L,
        solver: Solver,
        t: f64,
        t_end: f64,
    ) -> Result<()> {
        if let Solver::Bdf { rtol, atol } = solver {
            return self.advance_bdf(lanes, rtol, atol, t, t_end);
        }
        let mut t = t;
        let span = t_end - t;
        let eps = time_slack(t_end, span);
        let members = self.members.clone();
        let members: &[usize] = &members;
        for &m in members {
            if let Some((_, u)) = lanes.member(m) {
                if u.h_adaptive <= 0.0 {
                    u.h_adaptive = span * 0.1;
                }
            }
        }
        let next_time_event = |lanes: &mut L, m: usize| lanes.member(m).and_then(|(_, u)| u.next_time_event);
        loop {
            self.ended(lanes, t)?;
            if t >= t_end - eps {
                return Ok(());
            }
            if self.time_events_due(lanes, t, eps)? {
                continue;
            }
            // the end of this stretch: the earliest time event or the end of the step
            let mut target = t_end;
            let mut time_event = false;
            for &m in members {
                if let Some(te) = next_time_event(lanes, m) {
                    if te <= t_end + eps && te.max(t) <= target {
                        target = te.max(t);
                        time_event = true;
                    }
                }
            }
            let h_max = target - t;
            let mut h = match solver {
                Solver::Rk4 { max_step } => {
                    let hm = max_step.unwrap_or(span).max(1e-300);
                    h_max / ((h_max / hm) * (1.0 - 1e-12)).ceil().max(1.0)
                }
                Solver::Dopri5 { .. } | Solver::Bdf { .. } => {
                    members.iter().filter_map(|m| lanes.member(*m).map(|(_, u)| u.h_adaptive)).fold(h_max, f64::min)
                }
            };
            for &m in members {
                if let Some((inst, u)) = lanes.member(m) {
                    u.begin_step(inst, t)?;
                }
            }
            match solver {
                Solver::Dopri5 { rtol, atol } => loop {
                    let mut err = 0.0f64;
                    for &m in members {
                        if let Some((inst, u)) = lanes.member(m) {
                            err = nan_max(err, u.dopri(inst, t, h, rtol, atol)?);
                        }
                    }
                    if err.is_nan() {
                        return Err(self.nan_error_estimate(lanes, t, h));
                    }
                    let factor = if err == 0.0 { 5.0 } else { (0.9 * err.powf(-0.2)).clamp(0.2, 5.0) };
                    self.count_step(lanes, t)?;
                    if err <= 1.0 || h <= 0.1 * eps {
                        for &m in members {
                            if let Some((_, u)) = lanes.member(m) {
                                u.h_adaptive = (h * factor).min(span.max(h));
                            }
                        }
                        break;
                    }
                    if let Some((_, u)) = lanes.member(members[0]) {
                        u.rejected += 1;
                    }
                    h *= factor.min(0.9);
                },
                Solver::Rk4 { .. } | Solver::Bdf { .. } => {
                    self.count_step(lanes, t)?;
                    for &m in members {
                        if let Some((inst, u)) = lanes.member(m) {
                            u.rk4(inst, t, h)?;
                        }
                    }
                }
            }
            let t_new = if (t + h - target).abs() <= eps { target } else { t + h };
            // state events: the earliest crossing of any member
            let mut first: Option<f64> = None;
            let mut crossings: Vec<(usize, f64)> = Vec::new();
            for &m in members {
                let Some((inst, u)) = lanes.member(m) else { continue };
                u.indicators_at(inst, t_new)?;
                if MeUnit::crossed(&u.z0, &u.z) {
                    let hi = u.locate_crossing(inst, solver, t, t_new - t)?;
                    crossings.push((m, hi));
                    first = Some(first.map_or(hi, |f: f64| f.min(hi)));
                }
            }
            if let Some(hi) = first {
                let te = t + hi;
                for &m in members {
                    let Some((inst, u)) = lanes.member(m) else { continue };
                    u.one_step(inst, solver, t, hi)?;
                    inst.set_time(te)?;
                    MeUnit::set_states(inst, &u.xt)?;
                    u.x.copy_from_slice(&u.xt);
                    u.steps += 1;
                    inst.completed_integrator_step()?;
                }
                let who: Vec<usize> =
                    crossings.iter().filter(|(_, h)| *h <= hi + EVENT_TIME_TOLERANCE).map(|(m, _)| *m).collect();
                self.event(lanes, te, "state", &who)?;
                if let Solver::Dopri5 { .. } = solver {
                    for &m in members {
                        if let Some((_, u)) = lanes.member(m) {
                            u.h_adaptive = u.h_adaptive.min(span * 0.1);
                        }
                    }
                }
                t = te;
                continue;
            }
            // the step is accepted by every member
            let mut step_events: Vec<usize> = Vec::new();
            for &m in members {
                let Some((inst, u)) = lanes.member(m) else { continue };
                u.x.copy_from_slice(&u.xt);
                if u.complete_step(inst, t_new)? {
                    step_events.push(m);
                }
            }
            t = t_new;
            self.ended(lanes, t)?;
            let at_time_event = time_event && t >= target - eps;
            if at_time_event {
                let due: Vec<usize> = members
                    .iter()
                    .copied()
                    .filter(|m| next_time_event(lanes, *m).is_some_and(|te| te <= t + eps) || step_events.contains(m))
                    .collect();
                self.event(lanes, t, "time", &due)?;
            } else if !step_events.is_empty() {
                self.event(lanes, t, "step", &step_events)?;
            }
        }
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

//! The bdf solver ([`crate::bdf`]) for a group of Model Exchange instances: one system of
//! all members' states (the Jacobian block-diagonal by member, their inputs held between
//! events), with the same events as the one-step methods of the group: time events end a
//! step exactly at their time, a state event (an event indicator changing sign over an
//! accepted step) is located by the Illinois method on the step's dense output to
//! [`EVENT_TIME_TOLERANCE`], step events come from `fmi2CompletedIntegratorStep`, and
//! `terminateSimulation` ends the run. After every event the method restarts (order 1)
//! from the states the event iteration left, with the step it last asked for and its
//! Jacobian (renewed when the Newton iteration fails with it). A step ends at the end of each
//! communication step (where the members' inputs may change) and the method's history
//! is kept across it.
//!
//! The Jacobian of each member: with `providesDirectionalDerivative`, one
//! `fmi2GetDirectionalDerivative` (unknowns: the state derivatives, knowns: the states)
//! per group of columns sharing no row in the ModelStructure's derivative dependencies;
//! else one forward difference of the right-hand side per such group. At its first use
//! the FMU's Jacobian is checked against those differences ([`agrees`]); when they
//! disagree the member uses the differences for the rest of the run, and a note says so
//! (an FMU whose directional derivatives are wrong must not steer the Newton iteration).

use super::{MeGroup, Members};
use crate::bdf::{Bdf, Colouring, OdeSystem};
use crate::error::Result;
use crate::fmu::Instance;
use crate::me::{MeUnit, EVENT_TIME_TOLERANCE};
use nalgebra::DMatrix;

/// How the Jacobian of one member is evaluated.
#[derive(Debug)]
struct MemberJacobian {
    colouring: Colouring,
    derivative_vrs: Vec<u32>,
    state_vrs: Vec<u32>,
    directional: bool,
    /// The FMU's Jacobian was compared with finite differences (at its first use).
    checked: bool,
    /// The note when it disagreed (taken into the member's [`MeUnit::notes`]).
    note: Option<String>,
    seed: Vec<f64>,
    column: Vec<f64>,
    x: Vec<f64>,
    f: Vec<f64>,
}

impl MemberJacobian {
    fn new(inst: &Instance) -> MemberJacobian {
        let md = inst.fmu().description();
        let states = md.states();
        let derivatives = md.state_derivatives();
        let vr = |index: u32| md.model_variables[index as usize - 1].value_reference;
        let n = states.len();
        // the states each derivative depends on (dependencies absent: all of them)
        let rows: Vec<Vec<usize>> = derivatives
            .iter()
            .take(n)
            .map(|d| {
                let unknown = md.model_structure.derivatives.iter().find(|u| u.index == *d);
                match unknown.and_then(|u| u.dependencies.as_ref()) {
                    Some(deps) => deps.iter().filter_map(|k| states.iter().position(|s| s == k)).collect(),
                    None => (0..n).collect(),
                }
            })
            .collect();
        let directional = md.model_exchange.as_ref().is_some_and(|m| m.provides_directional_derivative)
            && inst.has_directional_derivative();
        MemberJacobian {
            colouring: Colouring::new(n, &rows),
            derivative_vrs: derivatives.iter().take(n).map(|d| vr(*d)).collect(),
            state_vrs: states.iter().map(|s| vr(*s)).collect(),
            directional,
            checked: false,
            note: None,
            seed: vec![0.0; n],
            column: vec![0.0; n],
            x: vec![0.0; n],
            f: vec![0.0; n],
        }
    }
}

/// The bdf state of a group.
#[derive(Debug)]
pub(crate) struct GroupBdf {
    bdf: Bdf,
    /// Where each member's states start in the group's state (and the end).
    offsets: Vec<usize>,
    jacobians: Vec<MemberJacobian>,
    started: bool,
    /// Right-hand sides of the finite-difference Jacobians.
    difference_rhs: u64,
    /// Right-hand sides of the first-use checks of the FMUs' Jacobians.
    check_rhs: u64,
    x: Vec<f64>,
    /// Steps may pass the communication points (no member has an input, so nothing
    /// changes there): the states at a point come from the dense output.
    through: bool,
    /// The first state event within the last step (time, members), not yet reached.
    crossing: Option<(f64, Vec<usize>)>,
}

/// The members as one ODE system.
struct GroupSystem<'a, L: Members + ?Sized> {
    lanes: &'a mut L,
    members: &'a [usize],
    offsets: &'a [usize],
    jacobians: &'a mut [MemberJacobian],
    /// The relative size of a finite-difference increment (`sqrt(eps)`) and the state
    /// magnitude below which it is taken of `floor` instead (atol / rtol).
    floor: f64,
    difference_rhs: &'a mut u64,
    /// Right-hand sides of the first-use checks of the FMUs' Jacobians.
    check_rhs: &'a mut u64,
}

impl<L: Members + ?Sized> OdeSystem for GroupSystem<'_, L> {
    fn rhs(&mut self, t: f64, x: &[f64], dx: &mut [f64]) -> Result<()> {
        for (k, &m) in self.members.iter().enumerate() {
            let (a, b) = (self.offsets[k], self.offsets[k + 1]);
            if let Some((inst, _)) = self.lanes.member(m) {
                MeUnit::derivatives(inst, t, &x[a..b], &mut dx[a..b])?;
            }
        }
        Ok(())
    }

    fn jacobian(&mut self, t: f64, x: &[f64], f: &[f64], jac: &mut DMatrix<f64>) -> Result<()> {
        jac.fill(0.0);
        for (k, &m) in self.members.iter().enumerate() {
            let (a, b) = (self.offsets[k], self.offsets[k + 1]);
            let Some((inst, _)) = self.lanes.member(m) else { continue };
            let mj = &mut self.jacobians[k];
            if mj.directional {
                inst.set_time(t)?;
                MeUnit::set_states(inst, &x[a..b])?;
                for group in &mj.colouring.groups {
                    mj.seed.fill(0.0);
                    for &j in group {
                        mj.seed[j] = 1.0;
                    }
                    inst.get_directional_derivative(&mj.derivative_vrs, &mj.state_vrs, &mj.seed, &mut mj.column)?;
                    for &j in group {
                        for &i in &mj.colouring.rows[j] {
                            jac[(a + i, a + j)] = mj.column[i];
                        }
                    }
                }
                if mj.checked {
                    continue;
                }
                mj.checked = true;
                let provided = jac.view((a, a), (b - a, b - a)).clone_owned();
                differences(inst, mj, t, &x[a..b], &f[a..b], self.floor, jac, a, self.check_rhs)?;
                let differenced = jac.view((a, a), (b - a, b - a)).clone_owned();
                match disagreement(&provided, &differenced) {
                    Some((i, j)) => {
                        mj.directional = false;
                        let name = |vrs: &[u32], k: usize| format!("value reference {}", vrs[k]);
                        mj.note = Some(format!(
                            "{}: fmi2GetDirectionalDerivative gives d der / d x = {:e} for the derivative ({}) with \
                             respect to the state ({}) at t = {t} s where finite differences give {:e}: bdf uses \
                             finite differences for it",
                            inst.name(),
                            provided[(i, j)],
                            name(&mj.derivative_vrs, i),
                            name(&mj.state_vrs, j),
                            differenced[(i, j)]
                        ));
                    }
                    // the FMU's own, as it is used from here on
                    None => jac.view_mut((a, a), (b - a, b - a)).copy_from(&provided),
                }
            } else {
                differences(inst, mj, t, &x[a..b], &f[a..b], self.floor, jac, a, self.difference_rhs)?;
            }
        }
        Ok(())
    }
}

/// One member's Jacobian by forward differences of its right-hand side at `x` (where it
/// is `f`), one per colour group, into `jac` from row and column `a`; `rhs` counts them.
#[allow(clippy::too_many_arguments)]
fn differences(
    inst: &mut Instance,
    mj: &mut MemberJacobian,
    t: f64,
    x: &[f64],
    f: &[f64],
    floor: f64,
    jac: &mut DMatrix<f64>,
    a: usize,
    rhs: &mut u64,
) -> Result<()> {
    mj.x.copy_from_slice(x);
    let rel = f64::EPSILON.sqrt();
    for group in &mj.colouring.groups {
        for &j in group {
            // an increment exact in binary: the difference of the two states
            let step = rel * (x[j].abs() + floor);
            mj.x[j] = x[j] + step;
            mj.seed[j] = mj.x[j] - x[j];
        }
        MeUnit::derivatives(inst, t, &mj.x, &mut mj.f)?;
        *rhs += 1;
        for &j in group {
            for &i in &mj.colouring.rows[j] {
                jac[(a + i, a + j)] = (mj.f[i] - f[i]) / mj.seed[j];
            }
            mj.x[j] = x[j];
        }
    }
    Ok(())
}

/// The first entry (row, column) where an FMU's Jacobian `provided` disagrees with the
/// forward differences `differenced`, if any. A forward difference with the relative
/// increment sqrt(eps) is off by about sqrt(eps) times the scale of the column's
/// curvature plus rounding of eps |f| / increment; a tolerance of 1e-3 of the larger
/// magnitude in the entry's column (and 1e-6 absolute) lets both through while a wrong
/// entry (a factor, a sign, a missing term of the column's size) does not. A non-finite
/// value from the FMU always disagrees.
fn disagreement(provided: &DMatrix<f64>, differenced: &DMatrix<f64>) -> Option<(usize, usize)> {
    for j in 0..provided.ncols() {
        let scale = (0..provided.nrows())
            .map(|i| provided[(i, j)].abs().max(differenced[(i, j)].abs()))
            .filter(|m| m.is_finite())
            .fold(0.0, f64::max);
        for i in 0..provided.nrows() {
            let (p, d) = (provided[(i, j)], differenced[(i, j)]);
            if !p.is_finite() || (d.is_finite() && (p - d).abs() > 1e-3 * scale + 1e-6) {
                return Some((i, j));
            }
        }
    }
    None
}

impl MeGroup {
    /// After an event outside the solver's own step (an input event): the method restarts
    /// (order 1) at the next step, from the states the event iteration left.
    pub(super) fn restart_stiff(&mut self) {
        if let Some(s) = self.stiff.as_mut() {
            s.started = false;
        }
    }

    /// The bdf state of the group, made on first use.
    fn stiff_state<L: Members + ?Sized>(&mut self, lanes: &mut L, rtol: f64, atol: f64) -> Box<GroupBdf> {
        if let Some(s) = self.stiff.take() {
            return s;
        }
        let mut offsets = vec![0];
        let mut jacobians = Vec::new();
        for &m in self.members.iter() {
            let Some((inst, unit)) = lanes.member(m) else {
                offsets.push(*offsets.last().unwrap_or(&0));
                jacobians.push(MemberJacobian::new(lanes.instance(m)));
                continue;
            };
            offsets.push(offsets.last().copied().unwrap_or(0) + unit.x.len());
            jacobians.push(MemberJacobian::new(inst));
        }
        let n = offsets.last().copied().unwrap_or(0);
        let through = self.members.iter().all(|m| {
            !lanes
                .instance(*m)
                .fmu()
                .description()
                .model_variables
                .iter()
                .any(|v| v.causality == model_description::Causality::Input)
        });
        Box::new(GroupBdf {
            bdf: Bdf::new(n, rtol, atol),
            offsets,
            jacobians,
            started: false,
            difference_rhs: 0,
            check_rhs: 0,
            x: vec![0.0; n],
            through,
            crossing: None,
        })
    }

    /// [`MeGroup::advance`] with the bdf solver.
    pub(super) fn advance_bdf<L: Members + ?Sized>(
        &mut self,
        lanes: &mut L,
        rtol: f64,
        atol: f64,
        t: f64,
        t_end: f64,
    ) -> Result<()> {
        let mut s = self.stiff_state(lanes, rtol, atol);
        let outcome = self.advance_bdf_with(lanes, &mut s, rtol, atol, t, t_end);
        if let Some((_, u)) = lanes.member(self.members[0]) {
            u.stiff = s.bdf.work;
            u.stiff.rhs += s.difference_rhs + s.check_rhs;
            u.stiff.jacobian_rhs = s.difference_rhs;
            u.rejected = s.bdf.work.rejected;
        }
        for (k, &m) in self.members.iter().enumerate() {
            if let (Some(note), Some((_, u))) = (s.jacobians[k].note.take(), lanes.member(m)) {
                u.notes.push(note);
            }
        }
        self.stiff = Some(s);
        outcome
    }

    #[allow(clippy::too_many_arguments)]
    fn advance_bdf_with<L: Members + ?Sized>(
        &mut self,
        lanes: &mut L,
        s: &mut GroupBdf,
        rtol: f64,
        atol: f64,
        t: f64,
        t_end: f64,
    ) -> Result<()> {
        let mut t = t;
        let span = t_end - t;
        let eps = super::time_slack(t_end, span);
        let members = self.members.clone();
        let members: &[usize] = &members;
        let next_time_event = |lanes: &mut L, m: usize| lanes.member(m).and_then(|(_, u)| u.next_time_event);
        let floor = if rtol > 0.0 { atol / rtol } else { 1.0 }.max(f64::MIN_POSITIVE);
        let stop_time = self.stop_time;
        loop {
            self.ended(lanes, t)?;
            if t >= t_end - eps {
                return Ok(());
            }
            // time events due now: the event iteration restarts the method
            if self.time_events_due(lanes, t, eps)? {
                s.started = false;
                continue;
            }
            // a step ends at the earliest time event, at the stop time, and, where an input
            // may change (a member has inputs), at the end of the communication step
            let mut limit = if s.through { stop_time.max(t_end) } else { t_end };
            for &m in members {
                if let Some(te) = next_time_event(lanes, m) {
                    if te.max(t) < limit {
                        limit = te.max(t);
                    }
                }
            }
            let GroupBdf { bdf, offsets, jacobians, started, difference_rhs, check_rhs, x, crossing, .. } = &mut *s;
            if bdf.t <= t + eps || !*started {
                let mut sys =
                    GroupSystem { lanes: &mut *lanes, members, offsets, jacobians, floor, difference_rhs, check_rhs };
                if !*started {
                    for (k, &m) in members.iter().enumerate() {
                        if let Some((_, u)) = sys.lanes.member(m) {
                            x[offsets[k]..offsets[k + 1]].copy_from_slice(&u.x);
                        }
                    }
                    if bdf.work.steps == 0 {
                        bdf.start(&mut sys, t, x, limit - t)?;
                    } else {
                        bdf.restart(&mut sys, t, x, limit - t)?;
                    }
                    *started = true;
                }
                let rejected = bdf.work.rejected;
                bdf.step(&mut sys, limit)?;
                for _ in 0..=(bdf.work.rejected - rejected) {
                    self.count_step(lanes, t)?;
                }
                // state events: the earliest crossing of any member over (t, bdf.t], on the
                // dense output
                let mut first: Option<f64> = None;
                let mut who: Vec<(usize, f64)> = Vec::new();
                for (k, &m) in members.iter().enumerate() {
                    let Some((inst, u)) = lanes.member(m) else { continue };
                    if u.z.is_empty() {
                        continue;
                    }
                    u.xt.copy_from_slice(&bdf.state()[offsets[k]..offsets[k + 1]]);
                    u.indicators_at(inst, bdf.t)?;
                    if MeUnit::crossed(&u.z0, &u.z) {
                        let te = locate_on_dense_output(inst, u, bdf, offsets[k], t, bdf.t, x)?;
                        who.push((m, te));
                        first = Some(first.map_or(te, |f: f64| f.min(te)));
                    }
                }
                *crossing = first.map(|te| {
                    let who = who.iter().filter(|(_, h)| *h <= te + EVENT_TIME_TOLERANCE).map(|(m, _)| *m).collect();
                    (te, who)
                });
            }
            // where the step (or its first state event) ends
            let reached = crossing.as_ref().map_or(bdf.t, |(te, _)| *te);
            if reached > t_end + eps {
                // the communication point within the step: the states there from the dense
                // output (the step is completed when the master reaches its end)
                bdf.interpolate(t_end, x);
                for (k, &m) in members.iter().enumerate() {
                    let Some((inst, u)) = lanes.member(m) else { continue };
                    u.x.copy_from_slice(&x[offsets[k]..offsets[k + 1]]);
                    inst.set_time(t_end)?;
                    MeUnit::set_states(inst, &u.x)?;
                }
                return Ok(());
            }
            if let Some((te, who)) = crossing.take() {
                bdf.interpolate(te, x);
                for (k, &m) in members.iter().enumerate() {
                    let Some((inst, u)) = lanes.member(m) else { continue };
                    u.x.copy_from_slice(&x[offsets[k]..offsets[k + 1]]);
                    inst.set_time(te)?;
                    MeUnit::set_states(inst, &u.x)?;
                    u.steps += 1;
                    inst.completed_integrator_step()?;
                }
                self.event(lanes, te, "state", &who)?;
                s.started = false;
                t = te;
                continue;
            }
            let t_new = bdf.t;
            let mut step_events: Vec<usize> = Vec::new();
            for (k, &m) in members.iter().enumerate() {
                let Some((inst, u)) = lanes.member(m) else { continue };
                u.x.copy_from_slice(&bdf.state()[offsets[k]..offsets[k + 1]]);
                if u.complete_step(inst, t_new)? {
                    step_events.push(m);
                }
            }
            t = t_new;
            self.ended(lanes, t)?;
            let due: Vec<usize> = members
                .iter()
                .copied()
                .filter(|m| next_time_event(lanes, *m).is_some_and(|te| te <= t + eps) || step_events.contains(m))
                .collect();
            let at_time_event = members.iter().any(|m| next_time_event(lanes, *m).is_some_and(|te| te <= t + eps));
            if at_time_event {
                self.event(lanes, t, "time", &due)?;
                s.started = false;
            } else if !step_events.is_empty() {
                self.event(lanes, t, "step", &step_events)?;
                s.started = false;
            }
        }
    }
}

/// The time just after the first crossing of an indicator of member `u` over the last
/// step (t0, t1] of `bdf`: the Illinois method on the dense output, to
/// [`EVENT_TIME_TOLERANCE`] (as the one-step methods' location, with the interpolant in
/// place of re-integration). `x` is scratch of the group's size.
fn locate_on_dense_output(
    inst: &mut Instance,
    u: &mut MeUnit,
    bdf: &Bdf,
    offset: usize,
    t0: f64,
    t1: f64,
    x: &mut [f64],
) -> Result<f64> {
    let zi = u.first_crossing();
    let (z_lo, z_hi) = (u.z0[zi], u.z[zi]);
    let n = u.xt.len();
    crate::me::illinois(t0, t1, z_lo, z_hi, |s| {
        bdf.interpolate(s, x);
        u.xt.copy_from_slice(&x[offset..offset + n]);
        u.indicators_at(inst, s)?;
        Ok((MeUnit::crossed(&u.z0, &u.z), u.z[zi]))
    })
}

//! The members of a Model Exchange group as one ODE system for the group's integrator
//! ([`GroupSystem`]: all members' states in one vector, the Jacobian block-diagonal by
//! member, their inputs held between events), the integrator's state between
//! communication steps ([`GroupIntegrator`]), and the location of a state event on the
//! integrator's dense output.
//!
//! The Jacobian of each member (for bdf): with `providesDirectionalDerivative`, one
//! `fmi2GetDirectionalDerivative` (unknowns: the state derivatives, knowns: the states)
//! per group of columns sharing no row in the ModelStructure's derivative dependencies;
//! else one forward difference of the right-hand side per such group. At its first use
//! the FMU's Jacobian is checked against those differences ([`disagreement`]); when they
//! disagree the member uses the differences for the rest of the run, and a note says so
//! (an FMU whose directional derivatives are wrong must not steer the Newton iteration).
//! A call that writes past `dvUnknown` or past a block the FMU allocated (caught in the
//! importing layer's red zones, [`ImportError::Overrun`]) does the same at any use.

use super::members::Members;
use crate::bdf::Colouring;
use crate::error::{ImportError, Result};
use crate::fmu::Instance;
use crate::integrator::{Integrator, OdeSystem, Start};
use crate::me::{MeUnit, Solver};
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

/// The integrator of a group and what it keeps between communication steps.
#[derive(Debug)]
pub(crate) struct GroupIntegrator {
    pub(crate) integrator: Box<dyn Integrator>,
    /// Where each member's states start in the group's state (and the end).
    pub(crate) offsets: Vec<usize>,
    jacobians: Vec<MemberJacobian>,
    /// The integrator is to start (from the members' states) before its next step, and why.
    pub(crate) restart: Option<Start>,
    /// Right-hand sides of the finite-difference Jacobians.
    difference_rhs: u64,
    /// Right-hand sides of the first-use checks of the FMUs' Jacobians.
    check_rhs: u64,
    /// The integrator's rejected attempts counted so far (against the cap on steps).
    pub(crate) rejected: u64,
    /// The group's states (scratch).
    pub(crate) x: Vec<f64>,
    /// The state magnitude below which a finite-difference increment is taken of it
    /// instead (atol / rtol).
    floor: f64,
    /// Steps may pass the communication points (a method that keeps a history, and no
    /// member has an input, so nothing changes there): the states at a point come from
    /// the dense output.
    pub(crate) through: bool,
    /// The first state event within the last step (time, members), not yet reached.
    pub(crate) crossing: Option<(f64, Vec<usize>)>,
    /// The members with event indicators are at the end of the last step (their
    /// indicators read there, nothing set since): completing the step sets nothing again.
    pub(crate) at_step_end: bool,
}

impl GroupIntegrator {
    /// The integrator of `solver` for the `members` of a group.
    pub(crate) fn new<L: Members + ?Sized>(lanes: &mut L, members: &[usize], solver: Solver) -> GroupIntegrator {
        let mut offsets = vec![0];
        let mut jacobians = Vec::new();
        for &m in members {
            let Some((inst, unit)) = lanes.member(m) else {
                offsets.push(*offsets.last().unwrap_or(&0));
                jacobians.push(MemberJacobian::new(lanes.instance(m)));
                continue;
            };
            offsets.push(offsets.last().copied().unwrap_or(0) + unit.x.len());
            jacobians.push(MemberJacobian::new(inst));
        }
        let n = offsets.last().copied().unwrap_or(0);
        let integrator = solver.integrator(n);
        let through = integrator.steps_past_points()
            && members.iter().all(|m| {
                !lanes
                    .instance(*m)
                    .fmu()
                    .description()
                    .model_variables
                    .iter()
                    .any(|v| v.causality == model_description::Causality::Input)
            });
        let floor = match solver {
            Solver::Bdf { rtol, atol } | Solver::Auto { rtol, atol, .. } if rtol > 0.0 => atol / rtol,
            _ => 1.0,
        }
        .max(f64::MIN_POSITIVE);
        GroupIntegrator {
            integrator,
            offsets,
            jacobians,
            restart: Some(Start::First),
            difference_rhs: 0,
            check_rhs: 0,
            rejected: 0,
            x: vec![0.0; n],
            floor,
            through,
            crossing: None,
            at_step_end: false,
        }
    }

    /// The members as one ODE system, and the integrator.
    pub(crate) fn parts<'a, L: Members + ?Sized>(
        &'a mut self,
        lanes: &'a mut L,
        members: &'a [usize],
    ) -> (GroupSystem<'a, L>, &'a mut dyn Integrator, &'a mut [f64]) {
        let GroupIntegrator { integrator, offsets, jacobians, difference_rhs, check_rhs, x, floor, .. } = self;
        let sys = GroupSystem { lanes, members, offsets, jacobians, floor: *floor, difference_rhs, check_rhs };
        (sys, &mut **integrator, x)
    }

    /// The members' states into the group's state, and a start of the integrator there
    /// when one is due; the first step at most `h_max`.
    pub(crate) fn start_if_due<L: Members + ?Sized>(
        &mut self,
        lanes: &mut L,
        members: &[usize],
        t: f64,
        h_max: f64,
    ) -> Result<()> {
        let Some(why) = self.restart.take() else {
            return Ok(());
        };
        for (k, &m) in members.iter().enumerate() {
            if let Some((_, u)) = lanes.member(m) {
                self.x[self.offsets[k]..self.offsets[k + 1]].copy_from_slice(&u.x);
            }
        }
        let (mut sys, integrator, x) = self.parts(lanes, members);
        integrator.start(&mut sys, t, x, h_max, why)
    }

    /// The method's work into the first member's counts (the bdf's in full, for its
    /// summary), and the notes on the members' Jacobians into theirs.
    pub(crate) fn report<L: Members + ?Sized>(&mut self, lanes: &mut L, members: &[usize], solver: Solver) {
        let work = self.integrator.work();
        if let Some(stiff) = self.integrator.take_switch() {
            let names: Vec<String> = members.iter().map(|m| lanes.instance(*m).name().to_string()).collect();
            let tolerance = match solver {
                Solver::Auto { rtol, .. } => format!(" (rtol {rtol:e})"),
                _ => String::new(),
            };
            if let Some((_, u)) = members.first().and_then(|m| lanes.member(*m)) {
                u.notes.push(format!(
                    "{}: stiff at t = {} s: an RK4 step of {:e} s has h*rho = {:.3e} (its stability bound: 2.785), so the \
                     default solver continues with bdf{tolerance} from there (--solver rk4|dopri5|bdf forces one method)",
                    names.join(", "),
                    stiff.t,
                    stiff.h,
                    stiff.h_rho
                ));
            }
        }
        if let Some(stiff) = self.integrator.take_found_stiff() {
            let names: Vec<String> = members.iter().map(|m| lanes.instance(*m).name().to_string()).collect();
            if let Some((_, u)) = members.first().and_then(|m| lanes.member(*m)) {
                u.notes.push(format!(
                    "{}: stiff at t = {} s: dopri5's steps are held by its stability, not its accuracy (h*lambda = \
                     {:.3e} on 15 tested steps, above its bound of 3.25; Hairer and Wanner's test), so it takes many \
                     small steps; --solver auto (the default) or bdf suits a stiff system",
                    names.join(", "),
                    stiff.t,
                    stiff.h_rho
                ));
            }
        }
        if let Some((_, u)) = members.first().and_then(|m| lanes.member(*m)) {
            if matches!(solver, Solver::Bdf { .. }) || self.integrator.switched() {
                u.stiff = work;
                u.stiff.rhs += self.difference_rhs + self.check_rhs;
                u.stiff.jacobian_rhs = self.difference_rhs;
            }
            u.rejected = work.rejected;
        }
        for (k, &m) in members.iter().enumerate() {
            if let (Some(note), Some((_, u))) = (self.jacobians[k].note.take(), lanes.member(m)) {
                u.notes.push(note);
            }
        }
    }
}

/// The members as one ODE system.
pub(crate) struct GroupSystem<'a, L: Members + ?Sized> {
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
    #[inline]
    fn rhs(&mut self, t: f64, x: &[f64], dx: &mut [f64]) -> Result<()> {
        if let [m] = *self.members {
            // a group of one (the common case): its states are the group's
            return match self.lanes.member(m) {
                Some((inst, _)) => MeUnit::derivatives(inst, t, x, dx),
                None => Ok(()),
            };
        }
        for (k, &m) in self.members.iter().enumerate() {
            let (a, b) = (self.offsets[k], self.offsets[k + 1]);
            if let Some((inst, _)) = self.lanes.member(m) {
                MeUnit::derivatives(inst, t, &x[a..b], &mut dx[a..b])?;
            }
        }
        Ok(())
    }

    fn name(&mut self) -> String {
        let names: Vec<String> = self
            .members
            .iter()
            .map(|m| {
                let inst = self.lanes.instance(*m);
                format!("{} ({})", inst.name(), crate::me::fmu_file(inst))
            })
            .collect();
        names.join(", ")
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
                if let Err(e) = provided(inst, mj, jac, a) {
                    let ImportError::Overrun { .. } = e else { return Err(e.into()) };
                    // the write went into the guard's red zone: the FMU is intact, its
                    // Jacobian is not to be trusted
                    mj.directional = false;
                    mj.checked = true;
                    mj.note = Some(format!("{e}: bdf uses finite differences for its Jacobian"));
                    differences(inst, mj, t, &x[a..b], &f[a..b], self.floor, jac, a, self.difference_rhs)?;
                    continue;
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
                        let call = if inst.is_fmi3() {
                            "fmi3GetDirectionalDerivative"
                        } else {
                            "fmi2GetDirectionalDerivative"
                        };
                        mj.note = Some(format!(
                            "{}: {call} gives d der / d x = {:e} for the derivative ({}) with \
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

/// One member's Jacobian from the FMU's directional derivatives, one call per colour
/// group, into `jac` from row and column `a`.
fn provided(
    inst: &mut Instance,
    mj: &mut MemberJacobian,
    jac: &mut DMatrix<f64>,
    a: usize,
) -> std::result::Result<(), ImportError> {
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
    Ok(())
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

/// The time just after the first crossing of an indicator of member `u` over the last
/// step (t0, t1] of `integrator`: the Illinois method on the dense output, to
/// [`crate::me::EVENT_TIME_TOLERANCE`] (SciPy's `solve_ivp` finds events on its dense output alike).
/// `offset` is where the member's states start in the group's; `x` is scratch of the
/// group's size.
pub(crate) fn locate_on_dense_output(
    inst: &mut Instance,
    u: &mut MeUnit,
    integrator: &dyn Integrator,
    offset: usize,
    t0: f64,
    t1: f64,
    x: &mut [f64],
) -> Result<f64> {
    let zi = u.first_crossing();
    let (z_lo, z_hi) = (u.z0[zi], u.z[zi]);
    let n = u.xt.len();
    crate::me::illinois(t0, t1, z_lo, z_hi, |s| {
        integrator.interpolate(s, x);
        u.xt.copy_from_slice(&x[offset..offset + n]);
        u.indicators_at(inst, s)?;
        Ok((MeUnit::crossed(&u.z0, &u.z), u.z[zi]))
    })
}

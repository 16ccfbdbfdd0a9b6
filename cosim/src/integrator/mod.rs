//! The one interface of the master's Model Exchange integrators (as SciPy's `OdeSolver`
//! and diffsol's `OdeSolverMethod`): an [`Integrator`] is started at a state, takes one
//! accepted step at a time towards a limit it never passes, gives the solution anywhere
//! within its last step from its dense output ([`Integrator::interpolate`]), and is
//! started again after an event changed the solution. The event loop of a group of Model
//! Exchange instances (`simulate/me_group.rs`) drives every method through it and locates
//! state events on the dense output.
//!
//! Implemented by [`rk4::Rk4`] (fixed step, cubic Hermite dense output),
//! [`dopri5::Dopri5`] (Dormand-Prince 5(4), its 4th-order continuous extension),
//! [`crate::bdf::Bdf`] (variable-order NDF, the interpolating polynomial of its
//! differences) and [`switching::Switching`] (the default: RK4 testing each step for
//! stiffness, bdf from the first stiff step on). A new method is a file of its own here implementing [`Integrator`] and a
//! variant of [`crate::me::Solver`] that makes it ([`crate::me::Solver::integrator`]).

pub mod dopri5;
pub mod rk4;
pub mod switching;

use crate::error::Result;
use nalgebra::DMatrix;

/// A right-hand side x' = f(t, x) and its Jacobian df/dx.
pub trait OdeSystem {
    /// f(t, x) into `dx`.
    fn rhs(&mut self, t: f64, x: &[f64], dx: &mut [f64]) -> Result<()>;
    /// The Jacobian at (t, x), where f(t, x) = `f`, into `jac` (n x n, zero outside the
    /// pattern the system declares).
    fn jacobian(&mut self, t: f64, x: &[f64], f: &[f64], jac: &mut DMatrix<f64>) -> Result<()>;
    /// What the system is, for an error of the method that names it (the master's groups:
    /// the instances and their FMUs).
    fn name(&mut self) -> String {
        "the system".into()
    }
}

/// Why an integrator starts at a point: the first start, or the event iteration that
/// ended there (each method decides what it keeps of its step size and Jacobian).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// The first start of the run.
    First,
    /// After the event iteration of a time event.
    TimeEvent,
    /// After the event iteration of a state event (an event indicator changed sign).
    StateEvent,
    /// After the event iteration of a step event (`fmi2CompletedIntegratorStep`).
    StepEvent,
}

/// The work of a method: what a `--summary` reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Work {
    /// Right-hand side evaluations (stages, Newton iterations, starting steps, and those
    /// of finite-difference Jacobians).
    pub rhs: u64,
    /// Of `rhs`, those of finite-difference Jacobians (one per column group).
    pub jacobian_rhs: u64,
    /// Jacobians evaluated.
    pub jacobians: u64,
    /// LU factorizations of `I - c J`.
    pub factorizations: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected attempts (error too large or Newton not converging).
    pub rejected: u64,
}

/// One integration method of a system of `n` states.
pub trait Integrator: std::fmt::Debug + Send {
    /// The communication step the master is about to integrate over: its length `span`
    /// (the one-step methods' scale: rk4's step where no largest step is given, dopri5's
    /// first and largest steps) and `slack`, the distance within which two times are the
    /// same time (a step ending that close to its limit ends on it).
    fn communication_step(&mut self, _span: f64, _slack: f64) {}

    /// Starts at (t, x), for `why`; the first step at most `h_max`.
    fn start(&mut self, sys: &mut dyn OdeSystem, t: f64, x: &[f64], h_max: f64, why: Start) -> Result<()>;

    /// One accepted step, not beyond `t_limit` (ending exactly there when it reaches it).
    /// After it, [`Integrator::t`] is the new time and [`Integrator::state`] the new state.
    fn step(&mut self, sys: &mut dyn OdeSystem, t_limit: f64) -> Result<()>;

    /// The time of the last accepted step (or of the start), s.
    fn t(&self) -> f64;

    /// The state at [`Integrator::t`].
    fn state(&self) -> &[f64];

    /// Makes the dense output of the last step ready for [`Integrator::interpolate`] (rk4
    /// needs the derivative at the step's end, which it evaluates only when asked: only a
    /// step with an event to locate needs it).
    fn prepare_dense_output(&mut self, _sys: &mut dyn OdeSystem) -> Result<()> {
        Ok(())
    }

    /// The dense output at `s` within the last step into `out`.
    fn interpolate(&self, s: f64, out: &mut [f64]);

    /// Whether steps may pass a communication point where nothing changes (no input):
    /// a multistep method keeps its history and gives the states at the point from its
    /// dense output; a one-step method ends a step at every point.
    fn steps_past_points(&self) -> bool {
        false
    }

    /// The work done so far.
    fn work(&self) -> Work;

    /// The step where a method that changes itself found the system stiff and switched,
    /// once, for the master's note ([`switching::Switching`]; the others never switch).
    fn take_switch(&mut self) -> Option<rk4::StiffStep> {
        None
    }

    /// The step where a method that does not change itself found the system stiff, once
    /// a run, for the master's note that another method suits it (dopri5's stiffness test).
    fn take_found_stiff(&mut self) -> Option<rk4::StiffStep> {
        None
    }

    /// Whether it has switched to bdf (its work is then reported as bdf's).
    fn switched(&self) -> bool {
        false
    }
}

/// What the one-step methods share: the step from (t_old, x0) to (t, x), and the
/// communication step's scale.
#[derive(Debug)]
pub(crate) struct Stretch {
    /// The communication step's length and time slack ([`Integrator::communication_step`]).
    pub(crate) span: f64,
    pub(crate) slack: f64,
    pub(crate) t: f64,
    pub(crate) t_old: f64,
    pub(crate) x: Vec<f64>,
    pub(crate) x0: Vec<f64>,
}

impl Stretch {
    pub(crate) fn new(n: usize) -> Stretch {
        Stretch { span: 0.0, slack: 0.0, t: 0.0, t_old: 0.0, x: vec![0.0; n], x0: vec![0.0; n] }
    }

    /// A start at (t, x).
    pub(crate) fn start(&mut self, t: f64, x: &[f64]) {
        self.t = t;
        self.t_old = t;
        self.x.copy_from_slice(x);
    }

    /// A step begins: x0 = x; its start time.
    pub(crate) fn begin(&mut self) -> f64 {
        self.x0.copy_from_slice(&self.x);
        self.t
    }

    /// The step of `h` towards `t_limit` ends: at `t_limit` when it ends within the slack
    /// of it, else at t + h.
    pub(crate) fn end(&mut self, h: f64, t_limit: f64) {
        let t = self.t;
        self.t_old = t;
        self.t = if (t + h - t_limit).abs() <= self.slack { t_limit } else { t + h };
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// x' = f(t, x) from a closure (no Jacobian: the explicit methods need none).
    pub(crate) struct Rhs<F: FnMut(f64, &[f64], &mut [f64])>(pub(crate) F);

    impl<F: FnMut(f64, &[f64], &mut [f64])> OdeSystem for Rhs<F> {
        fn rhs(&mut self, t: f64, x: &[f64], dx: &mut [f64]) -> Result<()> {
            (self.0)(t, x, dx);
            Ok(())
        }
        fn jacobian(&mut self, _: f64, _: &[f64], _: &[f64], _: &mut DMatrix<f64>) -> Result<()> {
            Ok(())
        }
    }

    /// The largest error of the dense output of one step of `h` from x(0) = 1 of
    /// x' = -x (exact: e^-t), over eight points inside the step, and its error at the
    /// step's end against the step's own end state.
    pub(crate) fn dense_error_of_one_step(method: &mut dyn Integrator, h: f64) -> (f64, f64) {
        let mut sys = Rhs(|_t: f64, x: &[f64], dx: &mut [f64]| dx[0] = -x[0]);
        // a communication step of 10 h: dopri5's first step is h, rk4's the whole stretch
        method.communication_step(10.0 * h, 0.0);
        method.start(&mut sys, 0.0, &[1.0], h, Start::First).unwrap();
        method.step(&mut sys, h).unwrap();
        assert_eq!(method.t(), h);
        method.prepare_dense_output(&mut sys).unwrap();
        let mut out = [0.0];
        let mut worst = 0.0f64;
        for k in 1..8 {
            let s = h * k as f64 / 8.0;
            method.interpolate(s, &mut out);
            worst = worst.max((out[0] - (-s).exp()).abs());
        }
        method.interpolate(h, &mut out);
        (worst, (out[0] - method.state()[0]).abs())
    }
}

//! The default Model Exchange method: RK4 (fixed step) testing each step for stiffness,
//! continuing with bdf from the start of the first step found stiff (as LSODA switches from
//! Adams to BDF and ode15s users expect of a default). Until then its steps are RK4's to the
//! bit (the test only observes the stages: [`super::rk4`]); from the switch on they are
//! bdf's, for the rest of the run. [`Integrator::take_switch`] tells the master where it
//! switched, for a note.

use super::rk4::{Rk4, StiffStep};
use super::{Integrator, OdeSystem, Start, Work};
use crate::bdf::Bdf;
use crate::error::Result;

/// RK4 until a step is stiff, bdf from there on.
#[derive(Debug)]
pub struct Switching {
    rk4: Rk4,
    /// The tolerances of the bdf it continues with.
    rtol: f64,
    atol: f64,
    /// The bdf, from the switch on.
    bdf: Option<Bdf>,
    /// The communication step last told, for the bdf made later.
    span: (f64, f64),
    /// The switch, until the master takes it.
    switch: Option<StiffStep>,
}

impl Switching {
    /// A method for `n` states: RK4 with steps of at most `max_step` s (`None`: the
    /// communication step), then bdf with `rtol`, `atol`.
    pub fn new(n: usize, max_step: Option<f64>, rtol: f64, atol: f64) -> Switching {
        Switching { rk4: Rk4::testing_stiffness(n, max_step), rtol, atol, bdf: None, span: (0.0, 0.0), switch: None }
    }

    fn active(&self) -> &dyn Integrator {
        match &self.bdf {
            Some(b) => b,
            None => &self.rk4,
        }
    }
}

impl Integrator for Switching {
    fn communication_step(&mut self, span: f64, slack: f64) {
        self.span = (span, slack);
        match &mut self.bdf {
            Some(b) => b.communication_step(span, slack),
            None => self.rk4.communication_step(span, slack),
        }
    }

    fn start(&mut self, sys: &mut dyn OdeSystem, t: f64, x: &[f64], h_max: f64, why: Start) -> Result<()> {
        match &mut self.bdf {
            Some(b) => Integrator::start(b, sys, t, x, h_max, why),
            None => self.rk4.start(sys, t, x, h_max, why),
        }
    }

    fn step(&mut self, sys: &mut dyn OdeSystem, t_limit: f64) -> Result<()> {
        if let Some(b) = &mut self.bdf {
            return b.step(sys, t_limit);
        }
        self.rk4.step(sys, t_limit)?;
        let Some(stiff) = self.rk4.take_stiff() else {
            return Ok(());
        };
        // the stiff step was not taken: bdf starts where RK4 stopped, its first step at
        // most the one RK4 tried
        let mut b = Bdf::new(self.rk4.state().len(), self.rtol, self.atol);
        b.communication_step(self.span.0, self.span.1);
        Integrator::start(&mut b, sys, stiff.t, self.rk4.state(), stiff.h, Start::First)?;
        self.switch = Some(stiff);
        let b = self.bdf.insert(b);
        b.step(sys, t_limit)
    }

    fn t(&self) -> f64 {
        self.active().t()
    }

    fn state(&self) -> &[f64] {
        self.active().state()
    }

    fn prepare_dense_output(&mut self, sys: &mut dyn OdeSystem) -> Result<()> {
        match &mut self.bdf {
            Some(b) => b.prepare_dense_output(sys),
            None => self.rk4.prepare_dense_output(sys),
        }
    }

    fn interpolate(&self, s: f64, out: &mut [f64]) {
        self.active().interpolate(s, out)
    }

    /// RK4's (each of its steps ends on a communication point), also after the switch: the
    /// master decided that when it made the method.
    fn steps_past_points(&self) -> bool {
        false
    }

    /// RK4's work and bdf's together.
    fn work(&self) -> Work {
        let a = self.rk4.work();
        let b = self.bdf.as_ref().map(|b| b.work()).unwrap_or_default();
        Work {
            rhs: a.rhs + b.rhs,
            jacobian_rhs: a.jacobian_rhs + b.jacobian_rhs,
            jacobians: a.jacobians + b.jacobians,
            factorizations: a.factorizations + b.factorizations,
            steps: a.steps + b.steps,
            rejected: a.rejected + b.rejected,
        }
    }

    fn take_switch(&mut self) -> Option<StiffStep> {
        self.switch.take()
    }

    fn switched(&self) -> bool {
        self.bdf.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::tests::Rhs;
    use nalgebra::DMatrix;

    /// Prothero and Robinson's x' = -lambda (x - cos t) - sin t, x(0) = 1: x = cos t
    /// exactly (every solution approaches it as e^(-lambda t)); Jacobian -lambda.
    struct ProtheroRobinson(f64);

    impl OdeSystem for ProtheroRobinson {
        fn rhs(&mut self, t: f64, x: &[f64], dx: &mut [f64]) -> Result<()> {
            dx[0] = -self.0 * (x[0] - t.cos()) - t.sin();
            Ok(())
        }
        fn jacobian(&mut self, _: f64, _: &[f64], _: &[f64], jac: &mut DMatrix<f64>) -> Result<()> {
            jac[(0, 0)] = -self.0;
            Ok(())
        }
    }

    #[test]
    fn before_a_stiff_step_the_steps_are_rk4_s_to_the_bit() {
        // x' = -x at h = 0.1: h rho = 0.1, far inside RK4's bound
        let f = |_t: f64, x: &[f64], dx: &mut [f64]| dx[0] = -x[0];
        let (mut a, mut b) = (Rk4::new(1, None), Switching::new(1, None, 1e-6, 1e-8));
        for m in [&mut a as &mut dyn Integrator, &mut b] {
            m.communication_step(0.1, 1e-15);
            m.start(&mut Rhs(f), 0.0, &[1.0], 0.1, Start::First).unwrap();
            for k in 1..=20 {
                m.step(&mut Rhs(f), 0.1 * k as f64).unwrap();
            }
        }
        assert_eq!((a.t().to_bits(), a.state()[0].to_bits()), (b.t().to_bits(), b.state()[0].to_bits()));
        assert!(!b.switched() && b.take_switch().is_none());
    }

    #[test]
    fn a_stiff_step_switches_to_bdf_at_its_start() {
        // lambda = 1e4 at communication steps of 0.01 s: h rho = 100 (RK4 alone amplifies
        // the error by |R(-100)| = 3.9e6 per step and is useless); from the switch on, bdf at
        // rtol 1e-6 follows cos t
        let mut sys = ProtheroRobinson(1e4);
        let mut m = Switching::new(1, None, 1e-6, 1e-8);
        m.communication_step(0.01, 1e-15);
        m.start(&mut sys, 0.0, &[1.0], 0.01, Start::First).unwrap();
        let mut worst = 0.0f64;
        for k in 1..=100 {
            let t_end = 0.01 * k as f64;
            while m.t() < t_end - 1e-15 {
                m.step(&mut sys, t_end).unwrap();
            }
            worst = worst.max((m.state()[0] - m.t().cos()).abs());
        }
        let switch = m.take_switch().expect("switched");
        // the first step was stiff: the switch is at t = 0, that step's h and h rho
        // = 2 |k3 - k2| / |k2 - k1| = 2 * (lambda h / 2) = 100 for a linear system
        assert_eq!((switch.t, switch.h), (0.0, 0.01));
        assert!((switch.h_rho - 100.0).abs() < 1e-6, "{}", switch.h_rho);
        assert!(m.switched() && m.take_switch().is_none(), "the switch is reported once");
        // the solution is of order 1 in x, the global error of bdf a few rtol (its local
        // error per step below rtol |x| + atol, damped by the stiff decay): 1e-5 = 10 rtol
        assert!(worst < 1e-5, "{worst:e}");
    }
}

//! The classical 4th-order Runge-Kutta method with a fixed step: the stretch to a limit
//! in equal steps of at most the largest step (the communication step where none is
//! given). Its dense output is the cubic Hermite interpolant of the step's end values and
//! end derivatives: RK4 has no continuous extension of its own order from its stages
//! (the classical one is of order 3, as is this one: an error of O(h^4) against the
//! method's O(h^5) per step), the Hermite interpolant is exact for the cubics RK4
//! integrates exactly, and it is continuous with its derivative across steps, so that a
//! crossing at a step's end is found once. It costs one derivative at the step's end,
//! evaluated only for a step with an event to locate.
//!
//! Its stiffness test (for the default solver, [`super::switching`]) observes each step's
//! stages: stages 2 and 3 are both at t + h/2, at the states Y2 = x0 + h/2 k1 and
//! Y3 = x0 + h/2 k2, so |k3 - k2| / |Y3 - Y2| estimates the largest eigenvalue's modulus
//! rho of the Jacobian (Hairer and Wanner, Solving ODEs II, IV.2, the test of DOPRI5 on its
//! last two stages, which share their time as these do), and h rho = 2 |k3 - k2| / |k2 - k1|.
//! Classical RK4 is stable on the negative real axis for h rho up to 2.785 (on the
//! imaginary axis 2.83); a fixed step has no step control to bring it back inside, so a step
//! beyond [`STIFF_H_RHO`] is not taken: the method stops at its start and says so
//! ([`Rk4::take_stiff`]).

#![allow(clippy::needless_range_loop)] // index loops read like the formulas

use super::{Integrator, OdeSystem, Start, Stretch, Work};
use crate::error::Result;

/// The h rho above which a step is stiff: beyond RK4's stability interval on the negative
/// real axis (2.785), where the step's amplification of the stiff component
/// |1 + z + z^2/2 + z^3/6 + z^4/24| at z = -3 is 1.375 and grows as z^4/24 from there (a
/// margin over the bound: the estimate of rho is the quotient along one direction).
pub const STIFF_H_RHO: f64 = 3.0;

/// A step found stiff: RK4's, not taken (where it stopped); dopri5's, the accepted step
/// of its last stiff test (`h_rho` its estimate of h lambda).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StiffStep {
    /// Its start, s (where the method stopped).
    pub t: f64,
    /// Its size, s.
    pub h: f64,
    /// Its estimate of h rho.
    pub h_rho: f64,
}

/// The RK4 integrator of `n` states.
#[derive(Debug)]
pub struct Rk4 {
    /// Largest step, s (`None`: the communication step).
    max_step: Option<f64>,
    s: Stretch,
    xt: Vec<f64>,
    k: [Vec<f64>; 4],
    /// f(t, x) at the end of the last step (when [`Rk4::prepare_dense_output`] made it).
    f1: Vec<f64>,
    work: Work,
    /// Whether each step's stages are tested for stiffness (the default solver).
    stiffness_test: bool,
    /// The step found stiff, not taken.
    stiff: Option<StiffStep>,
}

impl Rk4 {
    /// A method for `n` states with steps of at most `max_step` s (`None`: the
    /// communication step).
    pub fn new(n: usize, max_step: Option<f64>) -> Rk4 {
        Rk4 {
            max_step,
            s: Stretch::new(n),
            xt: vec![0.0; n],
            k: std::array::from_fn(|_| vec![0.0; n]),
            f1: vec![0.0; n],
            work: Work::default(),
            stiffness_test: false,
            stiff: None,
        }
    }

    /// The method testing each step for stiffness: a step whose h rho exceeds
    /// [`STIFF_H_RHO`] stops the method at the step's start (its time and states unchanged)
    /// and is reported by [`Rk4::take_stiff`]. The test only observes the stages: the steps
    /// it passes are those of [`Rk4::new`] to the bit.
    pub fn testing_stiffness(n: usize, max_step: Option<f64>) -> Rk4 {
        Rk4 { stiffness_test: true, ..Rk4::new(n, max_step) }
    }

    /// The step found stiff since the last call, if any.
    pub fn take_stiff(&mut self) -> Option<StiffStep> {
        self.stiff.take()
    }
}

/// h rho of an RK4 step from its first three stages: 2 |k3 - k2| / |k2 - k1| (Euclidean
/// norms); 0 where k2 = k1 (the states of stages 2 and 3 coincide: no direction to measure).
fn h_rho(k1: &[f64], k2: &[f64], k3: &[f64]) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for j in 0..k1.len() {
        num += (k3[j] - k2[j]) * (k3[j] - k2[j]);
        den += (k2[j] - k1[j]) * (k2[j] - k1[j]);
    }
    if den == 0.0 {
        return 0.0;
    }
    2.0 * (num / den).sqrt()
}

impl Integrator for Rk4 {
    fn communication_step(&mut self, span: f64, slack: f64) {
        self.s.span = span;
        self.s.slack = slack;
    }

    fn start(&mut self, _sys: &mut dyn OdeSystem, t: f64, x: &[f64], _h_max: f64, _why: Start) -> Result<()> {
        self.s.start(t, x);
        Ok(())
    }

    fn step(&mut self, sys: &mut dyn OdeSystem, t_limit: f64) -> Result<()> {
        let t = self.s.begin();
        let h_max = t_limit - t;
        let hm = self.max_step.unwrap_or(self.s.span).max(1e-300);
        let h = h_max / ((h_max / hm) * (1.0 - 1e-12)).ceil().max(1.0);
        let Stretch { x, x0, .. } = &mut self.s;
        let n = x.len();
        let [k1, k2, k3, k4] = &mut self.k;
        sys.rhs(t, x0, k1)?;
        for j in 0..n {
            self.xt[j] = x0[j] + 0.5 * h * k1[j];
        }
        sys.rhs(t + 0.5 * h, &self.xt, k2)?;
        for j in 0..n {
            self.xt[j] = x0[j] + 0.5 * h * k2[j];
        }
        sys.rhs(t + 0.5 * h, &self.xt, k3)?;
        if self.stiffness_test {
            let h_rho = h_rho(k1, k2, k3);
            // NaN (infinite stages) is stiff too: the step cannot be taken
            if h_rho.is_nan() || h_rho > STIFF_H_RHO {
                self.work.rhs += 3;
                self.stiff = Some(StiffStep { t, h, h_rho });
                return Ok(());
            }
        }
        for j in 0..n {
            self.xt[j] = x0[j] + h * k3[j];
        }
        sys.rhs(t + h, &self.xt, k4)?;
        for j in 0..n {
            x[j] = x0[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
        self.work.rhs += 4;
        self.work.steps += 1;
        self.s.end(h, t_limit);
        Ok(())
    }

    fn t(&self) -> f64 {
        self.s.t
    }

    fn prepare_dense_output(&mut self, sys: &mut dyn OdeSystem) -> Result<()> {
        self.work.rhs += 1;
        sys.rhs(self.s.t, &self.s.x, &mut self.f1)
    }

    fn state(&self) -> &[f64] {
        &self.s.x
    }

    /// The cubic Hermite interpolant on [t_old, t] of x0, x and their derivatives k1, f1.
    fn interpolate(&self, s: f64, out: &mut [f64]) {
        let Stretch { t, t_old, x, x0, .. } = &self.s;
        let h = t - t_old;
        if h <= 0.0 {
            out.copy_from_slice(x);
            return;
        }
        let u = (s - t_old) / h;
        let (h00, h10) = ((1.0 + 2.0 * u) * (1.0 - u) * (1.0 - u), u * (1.0 - u) * (1.0 - u));
        let (h01, h11) = (u * u * (3.0 - 2.0 * u), u * u * (u - 1.0));
        for j in 0..out.len() {
            out[j] = h00 * x0[j] + h10 * h * self.k[0][j] + h01 * x[j] + h11 * h * self.f1[j];
        }
    }

    fn work(&self) -> Work {
        self.work
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::tests::{dense_error_of_one_step, Rhs};

    #[test]
    fn the_hermite_dense_output_is_exact_for_cubics_and_of_fourth_local_order() {
        // x' = 3 t^2 + 1: x = t^3 + t; RK4 (Simpson's rule here) and the cubic Hermite
        // interpolant are both exact for it, up to rounding
        let mut sys = Rhs(|t: f64, _x: &[f64], dx: &mut [f64]| dx[0] = 3.0 * t * t + 1.0);
        let mut rk4 = Rk4::new(1, None);
        rk4.communication_step(0.5, 0.0);
        rk4.start(&mut sys, 0.25, &[0.25f64.powi(3) + 0.25], 0.5, Start::First).unwrap();
        rk4.step(&mut sys, 0.75).unwrap();
        rk4.prepare_dense_output(&mut sys).unwrap();
        let mut out = [0.0];
        for k in 0..=10 {
            let s = 0.25 + 0.05 * k as f64;
            rk4.interpolate(s, &mut out);
            assert!((out[0] - (s * s * s + s)).abs() < 1e-15, "x({s}) = {} vs {}", out[0], s * s * s + s);
        }
        // e^-t: the Hermite error is O(h^4) (the fourth derivative's term): halving h
        // divides it by 16 (measured 14, the higher terms not yet gone); one of O(h^3)
        // would divide it by 8. RK4's own end error is O(h^5)
        let (coarse, end_coarse) = dense_error_of_one_step(&mut Rk4::new(1, None), 0.1);
        let (fine, end_fine) = dense_error_of_one_step(&mut Rk4::new(1, None), 0.05);
        eprintln!("rk4 Hermite dense output: {coarse:e} at h = 0.1, {fine:e} at h = 0.05");
        assert!(end_coarse == 0.0 && end_fine == 0.0, "the interpolant ends on the step's state");
        assert!(coarse / fine > 12.0 && coarse / fine < 40.0, "{coarse:e} / {fine:e}");
    }
}

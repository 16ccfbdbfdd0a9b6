//! Dormand-Prince 5(4) with an adaptive step (error per state below `atol + rtol |x|`,
//! the larger of the step's two ends), and its continuous extension: the 4th-order
//! dense output of Dormand and Prince (Hairer, Norsett and Wanner, Solving ODEs I, II.6;
//! the coefficients of Shampine's form that SciPy's `RK45` uses), a polynomial in the
//! step's seven stages, exact at both ends.

#![allow(clippy::needless_range_loop)] // index loops read like the formulas

use super::{Integrator, OdeSystem, Start, Stretch, Work};
use crate::error::{Error, Result};

const C: [f64; 6] = [1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 6] = [
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0],
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
];
/// Error coefficients: the 5th-order weights minus the 4th-order weights.
const E: [f64; 7] =
    [71.0 / 57600.0, 0.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0];
/// The dense output: x(t_old + u h) = x_old + h sum_k K_k (P_k1 u + P_k2 u^2 + P_k3 u^3 +
/// P_k4 u^4); at u = 1 each row sums to the 5th-order weight of its stage.
const P: [[f64; 4]; 7] = [
    [1.0, -8048581381.0 / 2820520608.0, 8663915743.0 / 2820520608.0, -12715105075.0 / 11282082432.0],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 131558114200.0 / 32700410799.0, -68118460800.0 / 10900136933.0, 87487479700.0 / 32700410799.0],
    [0.0, -1754552775.0 / 470086768.0, 14199869525.0 / 1410260304.0, -10690763975.0 / 1880347072.0],
    [0.0, 127303824393.0 / 49829197408.0, -318862633887.0 / 49829197408.0, 701980252875.0 / 199316789632.0],
    [0.0, -282668133.0 / 205662961.0, 2019193451.0 / 616988883.0, -1453857185.0 / 822651844.0],
    [0.0, 40617522.0 / 29380423.0, -110615467.0 / 29380423.0, 69997945.0 / 29380423.0],
];

/// The Dormand-Prince integrator of `n` states.
#[derive(Debug)]
pub struct Dopri5 {
    rtol: f64,
    atol: f64,
    s: Stretch,
    /// The step the last accepted step took (its stages' step), s.
    h_taken: f64,
    /// The step the next step tries, s (0: not chosen yet).
    h: f64,
    k: [Vec<f64>; 7],
    work: Work,
}

impl Dopri5 {
    /// A method for `n` states with the tolerances `rtol`, `atol`.
    pub fn new(n: usize, rtol: f64, atol: f64) -> Dopri5 {
        Dopri5 {
            rtol,
            atol,
            s: Stretch::new(n),
            h_taken: 0.0,
            h: 0.0,
            k: std::array::from_fn(|_| vec![0.0; n]),
            work: Work::default(),
        }
    }

    /// Stages 2 to 7 of a step of size `h` from (t, x0) into `x` (k1 given in k[0]);
    /// returns the scaled error norm (<= 1: accept). k[6] holds f(t + h, x) afterwards.
    fn attempt(&mut self, sys: &mut dyn OdeSystem, t: f64, h: f64) -> Result<f64> {
        let Stretch { x, x0, .. } = &mut self.s;
        let n = x0.len();
        for s in 0..6 {
            for j in 0..n {
                let mut acc = 0.0;
                for (r, a) in A[s].iter().enumerate().take(s + 1) {
                    acc += a * self.k[r][j];
                }
                x[j] = x0[j] + h * acc;
            }
            sys.rhs(t + C[s] * h, x, &mut self.k[s + 1])?;
        }
        self.work.rhs += 6;
        // a NaN error estimate (infinite stages: inf - inf) is kept, never dropped by max, so
        // that no such step is accepted; a zero error is zero also where the scale is (a
        // state at zero with atol = 0)
        let mut err = 0.0f64;
        for j in 0..n {
            let mut e = 0.0;
            for (r, c) in E.iter().enumerate() {
                e += c * self.k[r][j];
            }
            let scale = self.atol + self.rtol * x0[j].abs().max(x[j].abs());
            let he = h * e;
            if he != 0.0 {
                err = nan_max(err, (he / scale).abs());
            }
        }
        Ok(err)
    }
}

impl Integrator for Dopri5 {
    /// The first step is a tenth of the first communication step.
    fn communication_step(&mut self, span: f64, slack: f64) {
        self.s.span = span;
        self.s.slack = slack;
        if self.h <= 0.0 {
            self.h = span * 0.1;
        }
    }

    /// After a state event the step is at most a tenth of the communication step (the
    /// solution's scale may have changed at the event); else the step it asked for last.
    fn start(&mut self, _sys: &mut dyn OdeSystem, t: f64, x: &[f64], _h_max: f64, why: Start) -> Result<()> {
        self.s.start(t, x);
        if why == Start::StateEvent {
            self.h = self.h.min(self.s.span * 0.1);
        }
        Ok(())
    }

    fn step(&mut self, sys: &mut dyn OdeSystem, t_limit: f64) -> Result<()> {
        let t = self.s.begin();
        let mut h = t_limit - t;
        h = h.min(self.h);
        sys.rhs(t, &self.s.x0, &mut self.k[0])?;
        self.work.rhs += 1;
        loop {
            let err = self.attempt(sys, t, h)?;
            if err.is_nan() {
                return Err(Error::Integration(format!(
                    "{}: the dopri5 error estimate of the step from t = {t} s of {h:e} s is NaN (the state \
                     derivatives the FMU returned with OK over the step are infinite or the states overflow); the \
                     step is not taken",
                    sys.name()
                )));
            }
            let factor = if err == 0.0 { 5.0 } else { (0.9 * err.powf(-0.2)).clamp(0.2, 5.0) };
            if err <= 1.0 || h <= 0.1 * self.s.slack {
                self.h = (h * factor).min(self.s.span.max(h));
                break;
            }
            self.work.rejected += 1;
            h *= factor.min(0.9);
        }
        self.work.steps += 1;
        self.h_taken = h;
        self.s.end(h, t_limit);
        Ok(())
    }

    fn t(&self) -> f64 {
        self.s.t
    }

    fn state(&self) -> &[f64] {
        &self.s.x
    }

    fn interpolate(&self, s: f64, out: &mut [f64]) {
        let h = self.h_taken;
        if h <= 0.0 {
            out.copy_from_slice(&self.s.x);
            return;
        }
        let u = (s - self.s.t_old) / h;
        let powers = [u, u * u, u * u * u, u * u * u * u];
        let mut b = [0.0; 7];
        for (bk, p) in b.iter_mut().zip(&P) {
            *bk = p.iter().zip(&powers).map(|(c, w)| c * w).sum();
        }
        for j in 0..out.len() {
            let mut acc = 0.0;
            for (r, bk) in b.iter().enumerate() {
                acc += bk * self.k[r][j];
            }
            out[j] = self.s.x0[j] + h * acc;
        }
    }

    fn work(&self) -> Work {
        self.work
    }
}

/// The larger of `a` and `b`, NaN if either is (`f64::max` drops a NaN).
#[inline]
pub(crate) fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::tests::dense_error_of_one_step;

    #[test]
    fn the_dense_output_is_of_fourth_order_and_exact_at_the_end() {
        // tolerances so loose that every step is accepted as it is tried
        let (coarse, end_coarse) = dense_error_of_one_step(&mut Dopri5::new(1, 1.0, 1.0), 0.2);
        let (fine, end_fine) = dense_error_of_one_step(&mut Dopri5::new(1, 1.0, 1.0), 0.1);
        eprintln!("dopri5 dense output: {coarse:e} at h = 0.2, {fine:e} at h = 0.1");
        // at the end the interpolant is the 5th-order solution: its rows sum to the
        // weights, equal up to the rounding of seven terms
        assert!(end_coarse < 1e-15 && end_fine < 1e-15, "{end_coarse:e} {end_fine:e}");
        // a 4th-order interpolant has a local error of O(h^5): halving h divides it by 32
        // (measured 36); 20 leaves room for the higher terms and fails for a 3rd-order one (16)
        assert!(coarse / fine > 20.0, "{coarse:e} / {fine:e}");
        // and its size: the error constant of e^-t's fifth derivative times h^5 (1e-5 at
        // h = 0.1 would be an interpolant of the third order)
        assert!(fine < 1e-7, "{fine:e}");
    }
}

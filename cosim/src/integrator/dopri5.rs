//! Dormand-Prince 5(4) with an adaptive step (error per state below `atol + rtol |x|`,
//! the larger of the step's two ends), and its continuous extension: the 4th-order
//! dense output of Dormand and Prince (Hairer, Norsett and Wanner, Solving ODEs I, II.6;
//! the coefficients of Shampine's form that SciPy's `RK45` uses), a polynomial in the
//! step's seven stages, exact at both ends.

#![allow(clippy::needless_range_loop)] // index loops read like the formulas

use super::rk4::StiffStep;
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

/// Hairer and Wanner's stiffness test of DOPRI5 (their Fortran code `dopri5.f`, its
/// NSTIFF and IASTI; Solving ODEs II, IV.2). After an accepted step from x0 of size h, the
/// sixth stage's state y6 = x0 + h sum_r A[4][r] k_r and the new state y1 (the seventh
/// stage's) both lie at t + h, with derivatives k6 = f(t + h, y6) and k7 = f(t + h, y1).
/// Where f is linear in x with Jacobian J (to first order in y1 - y6 otherwise),
/// k7 - k6 = J (y1 - y6), so
///     h lambda ~ h |k7 - k6| / |y1 - y6|
/// estimates h times the size of the eigenvalue of J that dominates the step's last error
/// direction, at no cost (no extra evaluation of f). DOPRI5's stability domain meets the
/// negative real axis near -3.3: a step with h lambda beyond 3.25 is held by the method's
/// stability, not by its accuracy, and the step-size controller keeps it there on a stiff
/// system. The test runs at every NSTIFF-th accepted step, and at every step while some
/// were stiff (IASTI > 0); 15 stiff tests with fewer than 6 non-stiff ones between them
/// (IASTI reaches 15 before NONSTI reaches 6) find the system stiff (their code then stops
/// with IDID = -4; here the run goes on and the master notes it once).
const STIFF_H_LAMBDA: f64 = 3.25;
/// Every how many accepted steps the test runs while none was stiff (their default).
const NSTIFF: u64 = 1000;
/// Stiff tests that find the system stiff.
const STIFF_TESTS: u32 = 15;
/// Non-stiff tests in a row that forget the stiff ones.
const NON_STIFF_TESTS: u32 = 6;

/// Hairer and Wanner's stiffness test's state (see [`STIFF_H_LAMBDA`]).
#[derive(Debug, Default)]
struct StiffnessTest {
    /// Accepted steps (NACCPT).
    accepted: u64,
    /// Stiff tests since the last 6 non-stiff ones in a row (IASTI).
    stiff: u32,
    /// Non-stiff tests in a row (NONSTI).
    non_stiff: u32,
    /// Whether it found the system stiff already (the master notes it once a run).
    found: bool,
}

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
    test: StiffnessTest,
    /// The step found stiff, until the master takes it.
    stiff: Option<StiffStep>,
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
            test: StiffnessTest::default(),
            stiff: None,
        }
    }

    /// h lambda of the accepted step of `h` just taken (see [`STIFF_H_LAMBDA`]): it only
    /// reads the step's stages and states (the method's numbers are its own without it).
    /// `None` where y1 = y6 (no direction to measure).
    fn h_lambda(&self, h: f64) -> Option<f64> {
        let Stretch { x, x0, .. } = &self.s;
        let (mut num, mut den) = (0.0f64, 0.0f64);
        for j in 0..x0.len() {
            // y6 as `attempt` formed it (the same sums in the same order)
            let mut acc = 0.0;
            for (r, a) in A[4].iter().enumerate().take(5) {
                acc += a * self.k[r][j];
            }
            let y6 = x0[j] + h * acc;
            num += (self.k[6][j] - self.k[5][j]) * (self.k[6][j] - self.k[5][j]);
            den += (x[j] - y6) * (x[j] - y6);
        }
        (den > 0.0).then(|| h * (num / den).sqrt())
    }

    /// The stiffness test after an accepted step of `h` from `t` (Hairer and Wanner's
    /// logic, [`STIFF_H_LAMBDA`]).
    fn test_stiffness(&mut self, t: f64, h: f64) {
        self.test.accepted += 1;
        if !self.test.accepted.is_multiple_of(NSTIFF) && self.test.stiff == 0 {
            return;
        }
        // where y1 = y6 their code keeps the last estimate; none here is not stiff
        let h_lambda = self.h_lambda(h).unwrap_or(0.0);
        if h_lambda > STIFF_H_LAMBDA {
            self.test.non_stiff = 0;
            self.test.stiff += 1;
            if self.test.stiff == STIFF_TESTS && !self.test.found {
                self.test.found = true;
                self.stiff = Some(StiffStep { t, h, h_rho: h_lambda });
            }
        } else {
            self.test.non_stiff += 1;
            if self.test.non_stiff == NON_STIFF_TESTS {
                self.test.stiff = 0;
            }
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
        self.test_stiffness(t, h);
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

    fn take_found_stiff(&mut self) -> Option<StiffStep> {
        self.stiff.take()
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

    /// Runs `m` from (0, x0) to `t_end` in communication steps of `span`; the accepted
    /// steps done when it reported the system stiff (each report), and the report.
    fn run_to(m: &mut Dopri5, sys: &mut dyn OdeSystem, x0: &[f64], span: f64, t_end: f64) -> Vec<(u64, StiffStep)> {
        let mut found = Vec::new();
        m.communication_step(span, 1e-15);
        m.start(sys, 0.0, x0, span, Start::First).unwrap();
        let points = (t_end / span).round() as usize;
        for k in 1..=points {
            let t_point = span * k as f64;
            while m.t() < t_point - 1e-15 {
                m.step(sys, t_point).unwrap();
                if let Some(stiff) = m.take_found_stiff() {
                    found.push((m.work().steps, stiff));
                }
            }
        }
        found
    }

    /// Prothero and Robinson's x' = -lambda (x - cos t) - sin t at lambda = 1e4 (as
    /// `switching.rs`'s tests): stiff, reported once.
    #[test]
    fn a_stiff_system_is_reported_once() {
        use crate::integrator::tests::Rhs;
        let lambda = 1e4;
        let mut sys = Rhs(|t: f64, x: &[f64], dx: &mut [f64]| dx[0] = -lambda * (x[0] - t.cos()) - t.sin());
        let mut m = Dopri5::new(1, 1e-6, 1e-8);
        let found = run_to(&mut m, &mut sys, &[1.0], 0.01, 10.0);
        // dopri5's steps are held near its stability bound: about 3000 steps a second, their
        // h lambda going up and down about 3.25 (3.0 to 3.7 measured) as the controller
        // rejects a step and grows the next, so that a test at a multiple of NSTIFF steps
        // may land on a step below the bound (measured: at 1000 to 5000, not at 6000); 10 s
        // have 30 such tests. One report (measured at the 6025th step)
        assert_eq!(found.len(), 1, "{found:?}");
        let (steps, stiff) = found[0];
        // the first test runs at the 1000th accepted step, the 15th stiff one 14 steps later
        // at the earliest
        assert!(steps >= NSTIFF + u64::from(STIFF_TESTS) - 1, "{steps}");
        assert!(stiff.h_rho > STIFF_H_LAMBDA);
        // f is linear in x: k7 - k6 = -lambda (y1 - y6) exactly but for the rounding of
        // the two differences (each of numbers near 1 differing by about the local error,
        // 1e-8 here: a relative rounding of 1e-16 / 1e-8); 1e-4 leaves a wide margin
        assert!((stiff.h_rho - stiff.h * lambda).abs() < 1e-4 * stiff.h_rho, "{stiff:?}");
        assert!(m.work().steps > steps + 100, "it went on after the report: {:?}", m.work());
        // the solution is right nevertheless (only slow): x = cos t, local errors below
        // rtol |x| + atol, damped by the stiff decay: 1e-5 = 10 rtol
        assert!((m.state()[0] - m.t().cos()).abs() < 1e-5);
    }

    /// The harmonic oscillator x'' = -x (eigenvalues +-i: h lambda = h, far below 3.25)
    /// is never reported, over more than NSTIFF steps (the test runs).
    #[test]
    fn a_non_stiff_system_is_never_reported() {
        use crate::integrator::tests::Rhs;
        let mut sys = Rhs(|_t: f64, x: &[f64], dx: &mut [f64]| {
            dx[0] = x[1];
            dx[1] = -x[0];
        });
        let mut m = Dopri5::new(2, 1e-10, 1e-12);
        let found = run_to(&mut m, &mut sys, &[1.0, 0.0], 1.0, 200.0);
        assert!(found.is_empty(), "{found:?}");
        assert!(m.work().steps > 2 * NSTIFF, "the test ran at least twice: {:?}", m.work());
        // and the run is right: x = cos t (rtol 1e-10 per step over ~3000 steps: 1e-6)
        assert!((m.state()[0] - 200f64.cos()).abs() < 1e-6, "{}", m.state()[0]);
    }
}

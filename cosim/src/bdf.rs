//! A variable-order (1 to 5), variable-step BDF method for stiff Model Exchange: the
//! numerical differentiation formulas of Shampine and Reichelt ("The MATLAB ODE Suite",
//! SIAM J. Sci. Comput. 18, 1997; the method of MATLAB's ode15s and SciPy's `BDF`) in the
//! quasi-constant step form: the solution is held as backward differences at an equal
//! spacing `h`, which are re-interpolated when the step changes. Each step solves the
//! implicit formula by a simplified Newton iteration with the matrix `I - c J`, `J` the
//! Jacobian of the right-hand side, kept (and its LU factorization reused) until the
//! iteration converges too slowly. The error estimate is the local truncation error of
//! the formula (weighted RMS norm, weights `atol + rtol |x|`); the order changes among
//! k - 1, k, k + 1 after k + 1 steps of one size. The interpolating polynomial of the
//! differences is the dense output between steps.
//!
//! The right-hand side and its Jacobian come from an [`OdeSystem`]: the master's group
//! of Model Exchange instances (`simulate/me_group/system.rs`) or, in tests, a closure. It is
//! one of the master's [`Integrator`]s.

#![allow(clippy::needless_range_loop)] // index loops read like the formulas

use crate::error::{Error, Result};
use crate::integrator::{Integrator, Start};
pub use crate::integrator::{OdeSystem, Work};
use nalgebra::DMatrix;

/// The highest order.
pub const MAX_ORDER: usize = 5;
/// Newton iterations per attempt of a step.
const NEWTON_MAX_ITERATIONS: usize = 4;
/// The bounds of a change of the step after a rejected and an accepted step.
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;

/// The NDF modifications kappa of the BDF of each order (Shampine and Reichelt, table 1;
/// order 1 is Klopfenstein's NDF1 modification, 0 keeps the plain BDF).
const KAPPA: [f64; MAX_ORDER + 1] = [0.0, -0.1850, -1.0 / 9.0, -0.0823, -0.0415, 0.0];

/// The BDF integrator of one system of `n` states.
#[derive(Debug)]
pub struct Bdf {
    n: usize,
    rtol: f64,
    atol: f64,
    /// Time of the last accepted step (or of the start).
    pub t: f64,
    /// Time of the step before it: the dense output is for [t_old, t].
    pub t_old: f64,
    h: f64,
    /// The step the method asked for last, before a limit shortened it.
    h_free: f64,
    order: usize,
    equal_steps: usize,
    /// Backward differences: d[0] = x(t), d[j] the j-th difference at spacing h
    /// (MAX_ORDER + 3 rows: two beyond the highest order for the error estimates).
    d: Vec<Vec<f64>>,
    jac: DMatrix<f64>,
    jac_current: bool,
    have_jac: bool,
    lu: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    gamma: [f64; MAX_ORDER + 2],
    alpha: [f64; MAX_ORDER + 2],
    error_const: [f64; MAX_ORDER + 2],
    // scratch
    f: Vec<f64>,
    y: Vec<f64>,
    y_predict: Vec<f64>,
    psi: Vec<f64>,
    corr: Vec<f64>,
    scale: Vec<f64>,
    rhs_buf: nalgebra::DVector<f64>,
    /// Work done so far.
    pub work: Work,
}

/// The spacing of f64 values at `x`, s.
fn ulp(x: f64) -> f64 {
    let x = x.abs();
    if x == 0.0 {
        return f64::MIN_POSITIVE;
    }
    f64::from_bits(x.to_bits() + 1) - x
}

/// Weighted RMS norm of `v / scale`.
fn norm(v: &[f64], scale: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let s: f64 = v.iter().zip(scale).map(|(a, s)| (a / s) * (a / s)).sum();
    (s / v.len() as f64).sqrt()
}

/// The (order + 1) x (order + 1) matrix that re-expresses backward differences at spacing
/// h as differences at spacing `factor` h (Shampine and Reichelt, section 2.3).
fn r_matrix(order: usize, factor: f64) -> DMatrix<f64> {
    let m = order + 1;
    let mut r = DMatrix::<f64>::zeros(m, m);
    for j in 0..m {
        r[(0, j)] = 1.0;
    }
    for i in 1..m {
        for j in 0..m {
            let entry = if j == 0 { 0.0 } else { (i as f64 - 1.0 - factor * j as f64) / i as f64 };
            // cumulative product down each column
            r[(i, j)] = r[(i - 1, j)] * entry;
        }
    }
    r
}

impl Bdf {
    /// A method for `n` states with tolerances `rtol`, `atol` (not started: [`Bdf::start`]).
    pub fn new(n: usize, rtol: f64, atol: f64) -> Bdf {
        let mut gamma = [0.0; MAX_ORDER + 2];
        let mut alpha = [0.0; MAX_ORDER + 2];
        let mut error_const = [0.0; MAX_ORDER + 2];
        for k in 1..=MAX_ORDER + 1 {
            gamma[k] = gamma[k - 1] + 1.0 / k as f64;
        }
        for k in 0..=MAX_ORDER + 1 {
            let kappa = if k <= MAX_ORDER { KAPPA[k] } else { 0.0 };
            alpha[k] = (1.0 - kappa) * gamma[k];
            error_const[k] = kappa * gamma[k] + 1.0 / (k as f64 + 1.0);
        }
        Bdf {
            n,
            rtol,
            atol,
            t: 0.0,
            t_old: 0.0,
            h: 0.0,
            h_free: 0.0,
            order: 1,
            equal_steps: 0,
            d: vec![vec![0.0; n]; MAX_ORDER + 3],
            jac: DMatrix::zeros(n, n),
            jac_current: false,
            have_jac: false,
            lu: None,
            gamma,
            alpha,
            error_const,
            f: vec![0.0; n],
            y: vec![0.0; n],
            y_predict: vec![0.0; n],
            psi: vec![0.0; n],
            corr: vec![0.0; n],
            scale: vec![0.0; n],
            rhs_buf: nalgebra::DVector::zeros(n),
            work: Work::default(),
        }
    }

    /// The current order.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The step size the next step tries, s.
    pub fn step_size(&self) -> f64 {
        self.h
    }

    /// Starts (or restarts after an event) at (t, x) with order 1 and a step chosen from
    /// f and a trial Euler step (Hairer, Norsett and Wanner, Solving ODEs I, II.4), at most
    /// `h_max`.
    pub fn start(&mut self, sys: &mut dyn OdeSystem, t: f64, x: &[f64], h_max: f64) -> Result<()> {
        self.have_jac = false;
        self.h_free = 0.0;
        self.begin(sys, t, x, h_max)
    }

    /// Restarts after an event at (t, x) with order 1, keeping the Jacobian (a new one
    /// when the Newton iteration fails with it) and trying the step the method last asked
    /// for (the error test shortens it where the event changed the solution's scale).
    pub fn restart(&mut self, sys: &mut dyn OdeSystem, t: f64, x: &[f64], h_max: f64) -> Result<()> {
        self.begin(sys, t, x, h_max)
    }

    fn begin(&mut self, sys: &mut dyn OdeSystem, t: f64, x: &[f64], h_max: f64) -> Result<()> {
        let n = self.n;
        self.t = t;
        self.t_old = t;
        self.order = 1;
        self.equal_steps = 0;
        self.jac_current = false;
        self.lu = None;
        sys.rhs(t, x, &mut self.f)?;
        self.work.rhs += 1;
        for i in 0..n {
            self.scale[i] = self.atol + self.rtol * x[i].abs();
        }
        let d0 = norm(x, &self.scale);
        let d1 = norm(&self.f, &self.scale);
        let h0 = if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 };
        let h0 = h0.min(h_max);
        for i in 0..n {
            self.y[i] = x[i] + h0 * self.f[i];
        }
        sys.rhs(t + h0, &self.y, &mut self.corr)?;
        self.work.rhs += 1;
        for i in 0..n {
            self.psi[i] = self.corr[i] - self.f[i];
        }
        let d2 = norm(&self.psi, &self.scale) / h0;
        let h1 = if d1 <= 1e-15 && d2 <= 1e-15 { (1e-6f64).max(h0 * 1e-3) } else { (0.01 / d1.max(d2)).powf(0.5) };
        self.h = (100.0 * h0).min(h1).min(h_max);
        if self.h_free > self.h {
            self.h = self.h_free.min(h_max);
        }
        if self.h.is_nan() || self.h <= 0.0 || n == 0 {
            // no states: nothing to resolve, one step to the limit
            self.h = h_max;
        }
        for row in self.d.iter_mut() {
            row.fill(0.0);
        }
        self.d[0].copy_from_slice(x);
        for i in 0..n {
            self.d[1][i] = self.h * self.f[i];
        }
        Ok(())
    }

    /// The state at the current time.
    pub fn state(&self) -> &[f64] {
        &self.d[0]
    }

    /// Re-interpolates the differences for the step `factor` h.
    fn change_step(&mut self, factor: f64) {
        let order = self.order;
        let r = r_matrix(order, factor);
        let u = r_matrix(order, 1.0);
        let ru = r * u;
        let m = order + 1;
        // D[0..m] = (R U)^T D[0..m], column by column of the state
        let mut col = vec![0.0; m];
        for i in 0..self.n {
            for j in 0..m {
                col[j] = self.d[j][i];
            }
            for j in 0..m {
                let mut acc = 0.0;
                for k in 0..m {
                    acc += ru[(k, j)] * col[k];
                }
                self.d[j][i] = acc;
            }
        }
        self.h *= factor;
        self.equal_steps = 0;
        self.lu = None;
    }

    /// The dense output at `s` (within the last step [t_old, t], or a little beyond) into
    /// `out`: the interpolating polynomial of the differences.
    pub fn interpolate(&self, s: f64, out: &mut [f64]) {
        out.copy_from_slice(&self.d[0]);
        let mut p = 1.0;
        for j in 0..self.order {
            p *= (s - (self.t - self.h * j as f64)) / (self.h * (j as f64 + 1.0));
            for i in 0..self.n {
                out[i] += self.d[j + 1][i] * p;
            }
        }
    }

    /// One accepted step, not beyond `t_limit` (ending exactly there when the step reaches
    /// it); the attempts it took are in [`Work`]. After it, [`Bdf::t`] is the new time and
    /// [`Bdf::state`] the new state.
    pub fn step(&mut self, sys: &mut dyn OdeSystem, t_limit: f64) -> Result<()> {
        let n = self.n;
        let newton_tol = (10.0 * f64::EPSILON / self.rtol).max(0.03f64.min(self.rtol.sqrt()));
        loop {
            let min_step = 10.0 * ulp(self.t);
            if self.h < min_step {
                return Err(Error::Experiment(format!(
                    "the bdf step at t = {} s fell below {min_step:e} s (the resolution of the time): the Newton iteration or the error test fails at every step size",
                    self.t
                )));
            }
            // the step ends at t_limit when it would pass it
            let remaining = t_limit - self.t;
            self.h_free = self.h;
            if self.h > remaining {
                self.change_step(remaining / self.h);
            }
            let t_new = if self.h >= remaining * (1.0 - 1e-12) { t_limit } else { self.t + self.h };
            if n == 0 {
                // nothing to solve (and no 0 x 0 factorization)
                self.work.steps += 1;
                self.t_old = self.t;
                self.t = t_new;
                return Ok(());
            }
            let order = self.order;
            for i in 0..n {
                let mut pred = 0.0;
                for j in 0..=order {
                    pred += self.d[j][i];
                }
                self.y_predict[i] = pred;
                self.scale[i] = self.atol + self.rtol * pred.abs();
                let mut psi = 0.0;
                for j in 1..=order {
                    psi += self.gamma[j] * self.d[j][i];
                }
                self.psi[i] = psi / self.alpha[order];
            }
            let c = self.h / self.alpha[order];
            let (converged, iterations) = loop {
                if self.lu.is_none() {
                    // the Jacobian is kept across steps; a new one only when the iteration
                    // fails with an old one (or at a start)
                    if !self.have_jac {
                        sys.rhs(t_new, &self.y_predict, &mut self.f)?;
                        self.work.rhs += 1;
                        sys.jacobian(t_new, &self.y_predict, &self.f, &mut self.jac)?;
                        self.work.jacobians += 1;
                        self.jac_current = true;
                        self.have_jac = true;
                    }
                    let mut m = -c * &self.jac;
                    for i in 0..n {
                        m[(i, i)] += 1.0;
                    }
                    self.lu = Some(m.lu());
                    self.work.factorizations += 1;
                }
                let (ok, it) = self.newton(sys, t_new, c, newton_tol)?;
                if ok || self.jac_current {
                    break (ok, it);
                }
                // not converging with an old Jacobian: a new one at this point
                self.lu = None;
                self.have_jac = false;
            };
            if !converged {
                // not converging with a current Jacobian either: a smaller step
                self.work.rejected += 1;
                self.change_step(0.5);
                continue;
            }
            let safety = 0.9 * (2.0 * NEWTON_MAX_ITERATIONS as f64 + 1.0)
                / (2.0 * NEWTON_MAX_ITERATIONS as f64 + iterations as f64);
            for i in 0..n {
                self.scale[i] = self.atol + self.rtol * self.y[i].abs();
            }
            let ec = self.error_const[order];
            let error_norm = {
                let mut s = 0.0;
                for i in 0..n {
                    let e = ec * self.corr[i] / self.scale[i];
                    s += e * e;
                }
                if n == 0 {
                    0.0
                } else {
                    (s / n as f64).sqrt()
                }
            };
            if error_norm > 1.0 {
                self.work.rejected += 1;
                let factor = MIN_FACTOR.max(safety * error_norm.powf(-1.0 / (order as f64 + 1.0)));
                self.change_step(factor);
                // the Jacobian stays valid for a smaller step near the same point
                continue;
            }
            // accepted: update the differences
            self.work.steps += 1;
            self.t_old = self.t;
            self.t = t_new;
            for i in 0..n {
                self.d[order + 2][i] = self.corr[i] - self.d[order + 1][i];
                self.d[order + 1][i] = self.corr[i];
            }
            for j in (0..=order).rev() {
                for i in 0..n {
                    let v = self.d[j + 1][i];
                    self.d[j][i] += v;
                }
            }
            self.jac_current = false;
            self.equal_steps += 1;
            if self.equal_steps < order + 1 {
                return Ok(());
            }
            // the order and step for the next step: the one of k - 1, k, k + 1 that allows
            // the largest step
            let weighted = |v: &[f64], k: usize| -> f64 {
                let mut s = 0.0;
                for i in 0..n {
                    let e = self.error_const[k] * v[i] / self.scale[i];
                    s += e * e;
                }
                if n == 0 {
                    0.0
                } else {
                    (s / n as f64).sqrt()
                }
            };
            let error_m = if order > 1 { weighted(&self.d[order], order - 1) } else { f64::INFINITY };
            let error_p = if order < MAX_ORDER { weighted(&self.d[order + 2], order + 1) } else { f64::INFINITY };
            let factor_of = |e: f64, k: f64| if e == 0.0 { f64::INFINITY } else { e.powf(-1.0 / k) };
            let factors = [
                factor_of(error_m, order as f64),
                factor_of(error_norm, order as f64 + 1.0),
                factor_of(error_p, order as f64 + 2.0),
            ];
            let (best, f_best) =
                factors.iter().enumerate().fold((1, factors[1]), |acc, (k, f)| if *f > acc.1 { (k, *f) } else { acc });
            self.order = (self.order + best).saturating_sub(1).clamp(1, MAX_ORDER);
            let factor = MAX_FACTOR.min(safety * f_best);
            self.change_step(factor);
            return Ok(());
        }
    }

    /// The simplified Newton iteration of one step: (converged, iterations). On
    /// convergence `y` is the new state and `corr` its difference from the prediction.
    fn newton(&mut self, sys: &mut dyn OdeSystem, t_new: f64, c: f64, tol: f64) -> Result<(bool, usize)> {
        let n = self.n;
        self.corr.fill(0.0);
        self.y.copy_from_slice(&self.y_predict);
        let mut last_norm: Option<f64> = None;
        let lu = self.lu.as_ref().expect("factorized before the iteration");
        for k in 0..NEWTON_MAX_ITERATIONS {
            sys.rhs(t_new, &self.y, &mut self.f)?;
            self.work.rhs += 1;
            if self.f.iter().any(|v| !v.is_finite()) {
                return Ok((false, k + 1));
            }
            for i in 0..n {
                self.rhs_buf[i] = c * self.f[i] - self.psi[i] - self.corr[i];
            }
            if !lu.solve_mut(&mut self.rhs_buf) {
                return Ok((false, k + 1));
            }
            let dy_norm = {
                let mut s = 0.0;
                for i in 0..n {
                    let e = self.rhs_buf[i] / self.scale[i];
                    s += e * e;
                }
                if n == 0 {
                    0.0
                } else {
                    (s / n as f64).sqrt()
                }
            };
            let rate = last_norm.map(|l| dy_norm / l);
            if let Some(rate) = rate {
                if rate >= 1.0 || rate.powi((NEWTON_MAX_ITERATIONS - k) as i32) / (1.0 - rate) * dy_norm > tol {
                    return Ok((false, k + 1));
                }
            }
            for i in 0..n {
                self.y[i] += self.rhs_buf[i];
                self.corr[i] += self.rhs_buf[i];
            }
            if dy_norm == 0.0 || rate.is_some_and(|r| r / (1.0 - r) * dy_norm < tol) {
                return Ok((true, k + 1));
            }
            last_norm = Some(dy_norm);
        }
        Ok((false, NEWTON_MAX_ITERATIONS))
    }
}

/// The interface of the event loop: a start after an event is [`Bdf::restart`] (order 1,
/// the Jacobian and the step asked for kept) once the method has taken a step, else
/// [`Bdf::start`]; steps pass communication points where nothing changes (the history is
/// worth keeping).
impl Integrator for Bdf {
    fn start(&mut self, sys: &mut dyn OdeSystem, t: f64, x: &[f64], h_max: f64, _why: Start) -> Result<()> {
        if self.work.steps == 0 {
            Bdf::start(self, sys, t, x, h_max)
        } else {
            Bdf::restart(self, sys, t, x, h_max)
        }
    }

    fn step(&mut self, sys: &mut dyn OdeSystem, t_limit: f64) -> Result<()> {
        Bdf::step(self, sys, t_limit)
    }

    fn t(&self) -> f64 {
        self.t
    }

    fn state(&self) -> &[f64] {
        Bdf::state(self)
    }

    fn interpolate(&self, s: f64, out: &mut [f64]) {
        Bdf::interpolate(self, s, out)
    }

    fn steps_past_points(&self) -> bool {
        true
    }

    fn work(&self) -> Work {
        self.work
    }
}

/// A grouping of the columns of a sparse Jacobian: columns in one group share no row, so
/// one directional derivative (or one finite difference) along the sum of their unit
/// vectors gives all of them (Curtis, Powell and Reid, 1974). Greedy colouring of the
/// column intersection graph, columns in order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Colouring {
    /// The colour of each column.
    pub colour: Vec<usize>,
    /// The columns of each colour.
    pub groups: Vec<Vec<usize>>,
    /// The rows of each column (the pattern).
    pub rows: Vec<Vec<usize>>,
}

impl Colouring {
    /// The colouring of the n x n pattern given as the columns each row depends on
    /// (`row_deps[i]`: the j with df_i/dx_j possibly nonzero).
    pub fn new(n: usize, row_deps: &[Vec<usize>]) -> Colouring {
        let mut rows = vec![Vec::new(); n];
        for (i, deps) in row_deps.iter().enumerate() {
            for &j in deps {
                if j < n && !rows[j].contains(&i) {
                    rows[j].push(i);
                }
            }
        }
        let mut colour = vec![usize::MAX; n];
        let mut groups: Vec<Vec<usize>> = Vec::new();
        // the rows taken by each colour
        let mut taken: Vec<Vec<bool>> = Vec::new();
        for j in 0..n {
            let c = (0..groups.len()).find(|c| rows[j].iter().all(|i| !taken[*c][*i])).unwrap_or_else(|| {
                groups.push(Vec::new());
                taken.push(vec![false; row_deps.len()]);
                groups.len() - 1
            });
            colour[j] = c;
            groups[c].push(j);
            for &i in &rows[j] {
                taken[c][i] = true;
            }
        }
        Colouring { colour, groups, rows }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Closure<F: FnMut(f64, &[f64], &mut [f64]), J: FnMut(f64, &[f64], &mut DMatrix<f64>)> {
        f: F,
        j: J,
    }

    impl<F: FnMut(f64, &[f64], &mut [f64]), J: FnMut(f64, &[f64], &mut DMatrix<f64>)> OdeSystem for Closure<F, J> {
        fn rhs(&mut self, t: f64, x: &[f64], dx: &mut [f64]) -> Result<()> {
            (self.f)(t, x, dx);
            Ok(())
        }
        fn jacobian(&mut self, t: f64, x: &[f64], _f: &[f64], jac: &mut DMatrix<f64>) -> Result<()> {
            (self.j)(t, x, jac);
            Ok(())
        }
    }

    #[test]
    fn colouring_groups_columns_that_share_no_row() {
        // tridiagonal: columns j, j+3, ... share no row: 3 colours
        let n = 10;
        let tri: Vec<Vec<usize>> = (0..n).map(|i: usize| (i.saturating_sub(1)..(i + 2).min(n)).collect()).collect();
        let c = Colouring::new(n, &tri);
        assert_eq!(c.groups.len(), 3);
        assert_eq!(c.colour, (0..n).map(|j| j % 3).collect::<Vec<_>>());
        // diagonal: one colour; dense: n colours
        let diag: Vec<Vec<usize>> = (0..n).map(|i| vec![i]).collect();
        assert_eq!(Colouring::new(n, &diag).groups, vec![(0..n).collect::<Vec<_>>()]);
        let dense: Vec<Vec<usize>> = (0..n).map(|_| (0..n).collect()).collect();
        assert_eq!(Colouring::new(n, &dense).groups.len(), n);
        // an arrow (row 0 full, plus the diagonal): every column has row 0: n colours
        let arrow: Vec<Vec<usize>> = (0..n).map(|i| if i == 0 { (0..n).collect() } else { vec![0, i] }).collect();
        assert_eq!(Colouring::new(n, &arrow).groups.len(), n);
        // every colouring found: no two columns of a colour share a row
        for pattern in [&tri, &diag, &dense, &arrow] {
            let c = Colouring::new(n, pattern);
            for g in &c.groups {
                for (a, &j) in g.iter().enumerate() {
                    for &k in &g[a + 1..] {
                        assert!(c.rows[j].iter().all(|i| !c.rows[k].contains(i)), "{j} and {k} share a row");
                    }
                }
            }
        }
        // block diagonal 2x2 blocks: 2 colours
        let blocks: Vec<Vec<usize>> = (0..n).map(|i| vec![i & !1, i | 1]).collect();
        assert_eq!(Colouring::new(n, &blocks).groups.len(), 2);
    }

    #[test]
    fn stiff_linear_system_matches_its_exact_solution() {
        // x1' = -1000 x1 + x2, x2' = -x2: x2 = e^-t, x1 = (1 - 1/999) e^-1000t + e^-t / 999
        let lambda = 1000.0;
        let exact = |t: f64| {
            let x2 = (-t).exp();
            let x1 = (1.0 - 1.0 / (lambda - 1.0)) * (-lambda * t).exp() + x2 / (lambda - 1.0);
            [x1, x2]
        };
        let mut sys = Closure {
            f: |_t: f64, x: &[f64], dx: &mut [f64]| {
                dx[0] = -lambda * x[0] + x[1];
                dx[1] = -x[1];
            },
            j: |_t: f64, _x: &[f64], j: &mut DMatrix<f64>| {
                j[(0, 0)] = -lambda;
                j[(0, 1)] = 1.0;
                j[(1, 1)] = -1.0;
            },
        };
        for rtol in [1e-4, 1e-6, 1e-8] {
            let mut bdf = Bdf::new(2, rtol, rtol * 1e-2);
            bdf.start(&mut sys, 0.0, &[1.0, 1.0], 1.0).unwrap();
            let mut worst = 0.0f64;
            let mut out = [0.0; 2];
            let mut next_check = 0.1;
            while bdf.t < 5.0 {
                bdf.step(&mut sys, 5.0).unwrap();
                while next_check <= bdf.t {
                    bdf.interpolate(next_check, &mut out);
                    let e = exact(next_check);
                    worst = worst.max(((out[0] - e[0]).abs()).max((out[1] - e[1]).abs()));
                    next_check += 0.1;
                }
            }
            assert_eq!(bdf.t, 5.0);
            let e = exact(5.0);
            let end = (bdf.state()[1] - e[1]).abs();
            eprintln!("rtol {rtol:e}: {:?}, worst dense error {worst:e}, end error {end:e}", bdf.work);
            // a local error per step of rtol |x| + atol (|x| <= 1) adds up over the steps,
            // damped by the decaying solution (measured 1.5 to 2.2 rtol): 10 rtol bounds it
            assert!(worst < 10.0 * rtol, "rtol {rtol}: {worst}");
            // stiff: far fewer steps than 5 s / (2 / 1000) (explicit stability bound)
            assert!(bdf.work.steps < 1000, "{:?}", bdf.work);
        }
    }
}

//! A small, typed layer of linear matrix inequalities over clarabel.
//!
//! Decision variables are scalars, symmetric matrices ([`SymVar`]) and full matrices
//! ([`MatVar`]). Every matrix-valued quantity built from them is an [`AffineExpr`]:
//! a constant matrix plus a sum of scalar decision variables times coefficient matrices.
//! Constraints say that a symmetric affine expression is negative definite (`F << 0`,
//! imposed as `F <= -margin I`) or positive definite (`F >> 0`, imposed as
//! `F >= margin I`), with the margin given explicitly.
//!
//! Each constraint of size `n` becomes one clarabel `PSDTriangleConeT(n)` (a size-1
//! constraint becomes a `NonnegativeConeT(1)`). Clarabel's standard form is
//! `min c'x  s.t.  A x + s = b, s in K`; for a constraint `S(x) = S0 + sum_k x_k S_k >= 0`
//! we set `s = svec(S(x))`, so `b = svec(S0)` and the column of `A` for `x_k` is
//! `-svec(S_k)`. `svec` is clarabel's scaled upper-triangle vectorisation: the upper
//! triangle read column by column (`(0,0), (0,1), (1,1), (0,2), (1,2), (2,2), ...`), with
//! the off-diagonal entries multiplied by `sqrt(2)` so that `svec(A)'svec(B) = trace(A B)`.
//!
//! A solve returns either an [`LmiSolution`] or a typed [`SolveError`] that carries the
//! solver's statistics; the solution is never handed out for an infeasible, unbounded,
//! stalled or iteration-limited run.

use std::collections::BTreeMap;
use std::fmt;
use std::ops::{Add, Mul, Neg, Sub};
use std::sync::Once;
use std::time::Instant;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::{DMatrix, SymmetricEigen};
use serde::Serialize;

/// A scalar decision variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScalarVar {
    index: usize,
}

/// A symmetric `n x n` matrix decision variable (`n (n + 1) / 2` scalars).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SymVar {
    first: usize,
    n: usize,
}

/// A full `rows x cols` matrix decision variable (`rows * cols` scalars).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MatVar {
    first: usize,
    rows: usize,
    cols: usize,
}

impl SymVar {
    /// Side length.
    pub fn dim(&self) -> usize {
        self.n
    }
    /// The matrix as an affine expression.
    pub fn expr(&self) -> AffineExpr {
        let mut e = AffineExpr::zeros(self.n, self.n);
        let mut k = self.first;
        for j in 0..self.n {
            for i in 0..=j {
                let mut c = DMatrix::zeros(self.n, self.n);
                c[(i, j)] = 1.0;
                c[(j, i)] = 1.0;
                e.terms.insert(k, c);
                k += 1;
            }
        }
        e
    }
}

impl MatVar {
    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }
    /// The matrix as an affine expression.
    pub fn expr(&self) -> AffineExpr {
        let mut e = AffineExpr::zeros(self.rows, self.cols);
        for j in 0..self.cols {
            for i in 0..self.rows {
                let mut c = DMatrix::zeros(self.rows, self.cols);
                c[(i, j)] = 1.0;
                e.terms.insert(self.first + j * self.rows + i, c);
            }
        }
        e
    }
}

impl ScalarVar {
    /// The variable times the `n x n` identity.
    pub fn times_identity(&self, n: usize) -> AffineExpr {
        let mut e = AffineExpr::zeros(n, n);
        e.terms.insert(self.index, DMatrix::identity(n, n));
        e
    }
    /// The variable as a `1 x 1` expression.
    pub fn expr(&self) -> AffineExpr {
        self.times_identity(1)
    }
}

/// A matrix that depends affinely on the decision variables:
/// `constant + sum_k x_k coefficient_k`.
///
/// Operations never panic: a dimension mismatch makes the result *invalid*, and the
/// problem refuses an invalid expression when it is used in a constraint or objective
/// ([`LmiError::Dimension`]).
#[derive(Clone, Debug, PartialEq)]
pub struct AffineExpr {
    rows: usize,
    cols: usize,
    constant: DMatrix<f64>,
    terms: BTreeMap<usize, DMatrix<f64>>,
    invalid: Option<String>,
}

impl AffineExpr {
    /// The zero `rows x cols` matrix.
    pub fn zeros(rows: usize, cols: usize) -> Self {
        AffineExpr { rows, cols, constant: DMatrix::zeros(rows, cols), terms: BTreeMap::new(), invalid: None }
    }

    /// A constant matrix.
    pub fn constant(m: DMatrix<f64>) -> Self {
        AffineExpr { rows: m.nrows(), cols: m.ncols(), constant: m, terms: BTreeMap::new(), invalid: None }
    }

    /// The constant `n x n` identity times `value`.
    pub fn identity(n: usize, value: f64) -> Self {
        Self::constant(DMatrix::identity(n, n) * value)
    }

    fn poisoned(rows: usize, cols: usize, why: String) -> Self {
        let mut e = Self::zeros(rows, cols);
        e.invalid = Some(why);
        e
    }

    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// Why this expression is invalid (a dimension mismatch somewhere in its making).
    pub fn invalid_reason(&self) -> Option<&str> {
        self.invalid.as_deref()
    }

    fn merge_invalid(a: &Self, b: &Self) -> Option<String> {
        a.invalid.clone().or_else(|| b.invalid.clone())
    }

    /// Transpose.
    pub fn transpose(&self) -> Self {
        AffineExpr {
            rows: self.cols,
            cols: self.rows,
            constant: self.constant.transpose(),
            terms: self.terms.iter().map(|(&k, c)| (k, c.transpose())).collect(),
            invalid: self.invalid.clone(),
        }
    }

    /// `self + self'` (the "Hermitian part" times two).
    pub fn plus_transpose(&self) -> Self {
        self + &self.transpose()
    }

    /// Left multiplication by a constant matrix: `m * self`.
    pub fn premul(&self, m: &DMatrix<f64>) -> Self {
        if m.ncols() != self.rows {
            return Self::poisoned(
                m.nrows(),
                self.cols,
                format!("premul: {}x{} times {}x{}", m.nrows(), m.ncols(), self.rows, self.cols),
            );
        }
        AffineExpr {
            rows: m.nrows(),
            cols: self.cols,
            constant: m * &self.constant,
            terms: self.terms.iter().map(|(&k, c)| (k, m * c)).collect(),
            invalid: self.invalid.clone(),
        }
    }

    /// Right multiplication by a constant matrix: `self * m`.
    pub fn postmul(&self, m: &DMatrix<f64>) -> Self {
        if m.nrows() != self.cols {
            return Self::poisoned(
                self.rows,
                m.ncols(),
                format!("postmul: {}x{} times {}x{}", self.rows, self.cols, m.nrows(), m.ncols()),
            );
        }
        AffineExpr {
            rows: self.rows,
            cols: m.ncols(),
            constant: &self.constant * m,
            terms: self.terms.iter().map(|(&k, c)| (k, c * m)).collect(),
            invalid: self.invalid.clone(),
        }
    }

    /// Scalar multiple.
    pub fn scale(&self, f: f64) -> Self {
        AffineExpr {
            rows: self.rows,
            cols: self.cols,
            constant: &self.constant * f,
            terms: self.terms.iter().map(|(&k, c)| (k, c * f)).collect(),
            invalid: self.invalid.clone(),
        }
    }

    /// Kronecker product `l ⊗ self` with a constant matrix on the left.
    pub fn kron_left(&self, l: &DMatrix<f64>) -> Self {
        AffineExpr {
            rows: l.nrows() * self.rows,
            cols: l.ncols() * self.cols,
            constant: l.kronecker(&self.constant),
            terms: self.terms.iter().map(|(&k, c)| (k, l.kronecker(c))).collect(),
            invalid: self.invalid.clone(),
        }
    }

    /// Trace, as a `1 x 1` expression.
    pub fn trace(&self) -> Self {
        if self.rows != self.cols {
            return Self::poisoned(1, 1, format!("trace of a {}x{} matrix", self.rows, self.cols));
        }
        let mut e = AffineExpr::zeros(1, 1);
        e.constant[(0, 0)] = self.constant.trace();
        for (&k, c) in &self.terms {
            e.terms.insert(k, DMatrix::from_element(1, 1, c.trace()));
        }
        e.invalid = self.invalid.clone();
        e
    }

    /// Assembles a block matrix from rows of blocks. `None` stands for a zero block whose
    /// size is taken from its row and column neighbours.
    pub fn blocks(rows: &[Vec<Option<AffineExpr>>]) -> Self {
        let nbr = rows.len();
        let nbc = rows.first().map_or(0, |r| r.len());
        if nbr == 0 || nbc == 0 || rows.iter().any(|r| r.len() != nbc) {
            return Self::poisoned(0, 0, "blocks: ragged or empty block layout".into());
        }
        let mut heights = vec![None; nbr];
        let mut widths = vec![None; nbc];
        for (i, r) in rows.iter().enumerate() {
            for (j, b) in r.iter().enumerate() {
                if let Some(b) = b {
                    if let Some(why) = &b.invalid {
                        return Self::poisoned(0, 0, why.clone());
                    }
                    for (slot, size, what) in [(&mut heights[i], b.rows, "height"), (&mut widths[j], b.cols, "width")] {
                        match slot {
                            None => *slot = Some(size),
                            Some(s) if *s != size => {
                                return Self::poisoned(
                                    0,
                                    0,
                                    format!("blocks: block ({i},{j}) has {what} {size}, expected {s}"),
                                )
                            }
                            _ => {}
                        }
                    }
                }
            }
        }
        if heights.iter().chain(widths.iter()).any(|s| s.is_none()) {
            return Self::poisoned(0, 0, "blocks: a block row or column is all zero-blocks (size unknown)".into());
        }
        let heights: Vec<usize> = heights.into_iter().map(|s| s.unwrap_or(0)).collect();
        let widths: Vec<usize> = widths.into_iter().map(|s| s.unwrap_or(0)).collect();
        let total_r: usize = heights.iter().sum();
        let total_c: usize = widths.iter().sum();
        let mut out = AffineExpr::zeros(total_r, total_c);
        let mut r0 = 0;
        for (i, r) in rows.iter().enumerate() {
            let mut c0 = 0;
            for (j, b) in r.iter().enumerate() {
                if let Some(b) = b {
                    out.constant.view_mut((r0, c0), (b.rows, b.cols)).copy_from(&b.constant);
                    for (&k, c) in &b.terms {
                        let t = out.terms.entry(k).or_insert_with(|| DMatrix::zeros(total_r, total_c));
                        t.view_mut((r0, c0), (b.rows, b.cols)).copy_from(c);
                    }
                }
                c0 += widths[j];
            }
            r0 += heights[i];
        }
        out
    }

    /// The value at a given vector of scalar decision variables.
    pub fn evaluate(&self, x: &[f64]) -> DMatrix<f64> {
        let mut m = self.constant.clone();
        for (&k, c) in &self.terms {
            if let Some(v) = x.get(k) {
                m += c * *v;
            }
        }
        m
    }

    fn asymmetry(&self) -> f64 {
        let mut worst = (&self.constant - self.constant.transpose()).amax();
        for c in self.terms.values() {
            worst = worst.max((c - c.transpose()).amax());
        }
        worst
    }

    fn scale_of(&self) -> f64 {
        let mut s = self.constant.amax();
        for c in self.terms.values() {
            s = s.max(c.amax());
        }
        s.max(1.0)
    }
}

impl Add<&AffineExpr> for &AffineExpr {
    type Output = AffineExpr;
    fn add(self, rhs: &AffineExpr) -> AffineExpr {
        if self.shape() != rhs.shape() {
            return AffineExpr::poisoned(
                self.rows,
                self.cols,
                format!("add: {}x{} plus {}x{}", self.rows, self.cols, rhs.rows, rhs.cols),
            );
        }
        let mut out = self.clone();
        out.invalid = AffineExpr::merge_invalid(self, rhs);
        out.constant += &rhs.constant;
        for (&k, c) in &rhs.terms {
            match out.terms.get_mut(&k) {
                Some(t) => *t += c,
                None => {
                    out.terms.insert(k, c.clone());
                }
            }
        }
        out
    }
}

impl Add for AffineExpr {
    type Output = AffineExpr;
    fn add(self, rhs: AffineExpr) -> AffineExpr {
        &self + &rhs
    }
}

impl Sub<&AffineExpr> for &AffineExpr {
    type Output = AffineExpr;
    fn sub(self, rhs: &AffineExpr) -> AffineExpr {
        self + &rhs.scale(-1.0)
    }
}

impl Sub for AffineExpr {
    type Output = AffineExpr;
    fn sub(self, rhs: AffineExpr) -> AffineExpr {
        &self - &rhs
    }
}

impl Neg for AffineExpr {
    type Output = AffineExpr;
    fn neg(self) -> AffineExpr {
        self.scale(-1.0)
    }
}

impl Mul<f64> for AffineExpr {
    type Output = AffineExpr;
    fn mul(self, f: f64) -> AffineExpr {
        self.scale(f)
    }
}

/// Which side of zero a constraint asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Definiteness {
    /// `F << 0`, imposed as `F <= -margin I`.
    Negative,
    /// `F >> 0`, imposed as `F >= margin I`.
    Positive,
}

/// Something the problem builder refuses.
#[derive(Clone, Debug, PartialEq)]
pub enum LmiError {
    /// Sizes do not fit together.
    Dimension(String),
    /// A constraint was given a matrix that is not symmetric.
    NotSymmetric {
        /// The constraint's label.
        label: String,
        /// `max |F - F'|` over its coefficient matrices.
        asymmetry: f64,
    },
    /// A margin or a coefficient is NaN or infinite, or a margin is negative.
    NotFinite(String),
}

impl fmt::Display for LmiError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LmiError::Dimension(s) => write!(f, "LMI dimension mismatch: {s}"),
            LmiError::NotSymmetric { label, asymmetry } => {
                write!(f, "LMI '{label}' is not symmetric (max |F - F'| = {asymmetry:e})")
            }
            LmiError::NotFinite(s) => write!(f, "LMI data not finite: {s}"),
        }
    }
}

impl std::error::Error for LmiError {}

#[derive(Clone, Debug)]
struct Constraint {
    label: String,
    expr: AffineExpr,
    side: Definiteness,
    margin: f64,
}

/// Solver settings exposed by this layer (the rest are clarabel's defaults).
#[derive(Clone, Debug, PartialEq)]
pub struct SolverSettings {
    /// Iteration limit.
    pub max_iter: u32,
    /// Relative and absolute duality-gap and feasibility tolerance.
    pub tolerance: f64,
    /// Print clarabel's iteration log.
    pub verbose: bool,
    /// Accept clarabel's `AlmostSolved` (reduced accuracy) status as a solution.
    /// The solution is still checked against every constraint (see
    /// [`SolverStats::max_constraint_violation`]).
    pub accept_reduced_accuracy: bool,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings { max_iter: 200, tolerance: 1e-8, verbose: false, accept_reduced_accuracy: true }
    }
}

/// What clarabel reported, for a solution or an error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SolverStats {
    /// Clarabel's status, as its variant name (`Solved`, `AlmostSolved`, ...).
    pub status: String,
    /// Interior-point iterations.
    pub iterations: u32,
    /// Primal residual.
    pub r_prim: f64,
    /// Dual residual.
    pub r_dual: f64,
    /// Primal objective.
    pub obj_primal: f64,
    /// Dual objective.
    pub obj_dual: f64,
    /// Clarabel's own solve time (s).
    pub solve_time_s: f64,
    /// Wall time of setup and solve (s).
    pub wall_time_s: f64,
    /// Number of scalar decision variables.
    pub n_variables: usize,
    /// Number of LMI constraints (cones).
    pub n_constraints: usize,
    /// Total rows of the conic constraint (`sum n_i (n_i + 1)/2`).
    pub n_rows: usize,
    /// Largest violation of a constraint at the returned point, measured by us, not by
    /// the solver: `max_i max(0, lambda_max(-S_i(x)))` with `S_i = F_i - margin I` (or
    /// `-F_i - margin I`) the matrix that must be PSD. Zero on exact satisfaction.
    pub max_constraint_violation: f64,
}

/// Why a solve did not produce a solution. Each carries the solver's statistics.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveError {
    /// The constraints cannot be met (clarabel found a primal infeasibility certificate).
    Infeasible(SolverStats),
    /// The objective is unbounded below (a dual infeasibility certificate).
    Unbounded(SolverStats),
    /// Clarabel stopped on its iteration or time limit.
    IterationLimit(SolverStats),
    /// Clarabel stopped on a numerical error or for lack of progress.
    NumericalTrouble(SolverStats),
    /// The problem could not be handed to clarabel.
    Setup(String),
    /// The problem was refused before solving.
    Problem(LmiError),
}

impl SolveError {
    /// The statistics, when the solver ran.
    pub fn stats(&self) -> Option<&SolverStats> {
        match self {
            SolveError::Infeasible(s)
            | SolveError::Unbounded(s)
            | SolveError::IterationLimit(s)
            | SolveError::NumericalTrouble(s) => Some(s),
            _ => None,
        }
    }

    /// True for [`SolveError::Infeasible`].
    pub fn is_infeasible(&self) -> bool {
        matches!(self, SolveError::Infeasible(_))
    }
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = |f: &mut fmt::Formatter<'_>, what: &str, s: &SolverStats| {
            write!(
                f,
                "{what} (clarabel status {}, {} iterations, primal residual {:.2e}, dual residual {:.2e})",
                s.status, s.iterations, s.r_prim, s.r_dual
            )
        };
        match self {
            SolveError::Infeasible(s) => d(f, "the LMIs are infeasible", s),
            SolveError::Unbounded(s) => d(f, "the objective is unbounded", s),
            SolveError::IterationLimit(s) => d(f, "the solver hit its iteration/time limit", s),
            SolveError::NumericalTrouble(s) => d(f, "the solver ran into numerical trouble", s),
            SolveError::Setup(m) => write!(f, "could not set up the solver: {m}"),
            SolveError::Problem(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for SolveError {}

impl From<LmiError> for SolveError {
    fn from(e: LmiError) -> Self {
        SolveError::Problem(e)
    }
}

/// An LMI problem: variables, constraints and a linear objective to minimise.
#[derive(Clone, Debug, Default)]
pub struct LmiProblem {
    n_scalars: usize,
    constraints: Vec<Constraint>,
    objective: Option<AffineExpr>,
}

/// The values of the decision variables at the solver's solution.
#[derive(Clone, Debug)]
pub struct LmiSolution {
    x: Vec<f64>,
    /// Objective value (including its constant).
    pub objective: f64,
    /// What the solver reported.
    pub stats: SolverStats,
}

impl LmiSolution {
    /// Value of a scalar variable.
    pub fn scalar(&self, v: ScalarVar) -> f64 {
        self.x[v.index]
    }
    /// Value of a symmetric variable.
    pub fn sym(&self, v: SymVar) -> DMatrix<f64> {
        v.expr().evaluate(&self.x)
    }
    /// Value of a full matrix variable.
    pub fn mat(&self, v: MatVar) -> DMatrix<f64> {
        v.expr().evaluate(&self.x)
    }
    /// Value of any affine expression.
    pub fn eval(&self, e: &AffineExpr) -> DMatrix<f64> {
        e.evaluate(&self.x)
    }
}

extern "C" {
    // Exported by every OpenBLAS build (a no-op in the serial one).
    fn openblas_set_num_threads(n: std::os::raw::c_int);
}

static BLAS_SINGLE_THREAD: Once = Once::new();

/// Runs OpenBLAS single-threaded (process-wide, once). The BLAS/LAPACK calls behind
/// clarabel's PSD cones are on matrices of size <= ~10, where BLAS threads only cost:
/// a solve is about twice as fast single-threaded, and the Pareto sweep parallelises
/// over grid points instead.
pub fn use_single_threaded_blas() {
    BLAS_SINGLE_THREAD.call_once(|| unsafe { openblas_set_num_threads(1) });
}

/// Scaled upper-triangle vectorisation of a symmetric matrix, clarabel's ordering.
pub fn svec(m: &DMatrix<f64>) -> Vec<f64> {
    let n = m.nrows();
    let mut v = Vec::with_capacity(n * (n + 1) / 2);
    for j in 0..n {
        for i in 0..=j {
            if i == j {
                v.push(m[(i, i)]);
            } else {
                v.push((m[(i, j)] + m[(j, i)]) * std::f64::consts::FRAC_1_SQRT_2);
            }
        }
    }
    v
}

impl LmiProblem {
    /// An empty problem.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of scalar decision variables so far.
    pub fn n_variables(&self) -> usize {
        self.n_scalars
    }

    /// A new scalar variable.
    pub fn scalar(&mut self) -> ScalarVar {
        let v = ScalarVar { index: self.n_scalars };
        self.n_scalars += 1;
        v
    }

    /// A new symmetric `n x n` variable.
    pub fn symmetric(&mut self, n: usize) -> SymVar {
        let v = SymVar { first: self.n_scalars, n };
        self.n_scalars += n * (n + 1) / 2;
        v
    }

    /// A new full `rows x cols` variable.
    pub fn full(&mut self, rows: usize, cols: usize) -> MatVar {
        let v = MatVar { first: self.n_scalars, rows, cols };
        self.n_scalars += rows * cols;
        v
    }

    fn push(&mut self, label: &str, expr: AffineExpr, side: Definiteness, margin: f64) -> Result<(), LmiError> {
        if let Some(why) = expr.invalid_reason() {
            return Err(LmiError::Dimension(format!("{label}: {why}")));
        }
        if expr.rows != expr.cols || expr.rows == 0 {
            return Err(LmiError::Dimension(format!("{label}: a {}x{} matrix is not square", expr.rows, expr.cols)));
        }
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(LmiError::NotFinite(format!("{label}: margin {margin}")));
        }
        if !expr.constant.iter().chain(expr.terms.values().flat_map(|c| c.iter())).all(|v| v.is_finite()) {
            return Err(LmiError::NotFinite(format!("{label}: coefficients")));
        }
        if expr.terms.keys().any(|&k| k >= self.n_scalars) {
            return Err(LmiError::Dimension(format!("{label}: uses a variable of another problem")));
        }
        let asym = expr.asymmetry();
        if asym > 1e-12 * expr.scale_of() {
            return Err(LmiError::NotSymmetric { label: label.to_string(), asymmetry: asym });
        }
        self.constraints.push(Constraint { label: label.to_string(), expr, side, margin });
        Ok(())
    }

    /// `expr << 0`, imposed as `expr <= -margin I`.
    pub fn negative_definite(&mut self, label: &str, expr: AffineExpr, margin: f64) -> Result<(), LmiError> {
        self.push(label, expr, Definiteness::Negative, margin)
    }

    /// `expr >> 0`, imposed as `expr >= margin I`.
    pub fn positive_definite(&mut self, label: &str, expr: AffineExpr, margin: f64) -> Result<(), LmiError> {
        self.push(label, expr, Definiteness::Positive, margin)
    }

    /// Minimise a `1 x 1` affine expression (without this, the problem is a
    /// feasibility problem with a zero objective).
    pub fn minimize(&mut self, expr: AffineExpr) -> Result<(), LmiError> {
        if let Some(why) = expr.invalid_reason() {
            return Err(LmiError::Dimension(format!("objective: {why}")));
        }
        if expr.shape() != (1, 1) {
            return Err(LmiError::Dimension(format!("objective must be 1x1, is {:?}", expr.shape())));
        }
        self.objective = Some(expr);
        Ok(())
    }

    /// The matrix that must be PSD for constraint `c`: `F - margin I` or `-F - margin I`.
    fn psd_form(c: &Constraint) -> AffineExpr {
        let n = c.expr.rows;
        match c.side {
            Definiteness::Positive => &c.expr - &AffineExpr::identity(n, c.margin),
            Definiteness::Negative => &c.expr.scale(-1.0) - &AffineExpr::identity(n, c.margin),
        }
    }

    /// Largest violation of any constraint at `x` (0 when all hold).
    fn max_violation(&self, x: &[f64]) -> f64 {
        let mut worst: f64 = 0.0;
        for c in &self.constraints {
            let s = Self::psd_form(c).evaluate(x);
            let s = (&s + s.transpose()) * 0.5;
            let min_eig = SymmetricEigen::new(s).eigenvalues.min();
            worst = worst.max(-min_eig);
        }
        worst
    }

    /// Hands the problem to clarabel.
    pub fn solve(&self, settings: &SolverSettings) -> Result<LmiSolution, SolveError> {
        let t0 = Instant::now();
        use_single_threaded_blas();
        if self.n_scalars == 0 {
            return Err(SolveError::Setup("no decision variables".into()));
        }
        if !(settings.tolerance.is_finite() && settings.tolerance > 0.0) {
            return Err(SolveError::Setup(format!("tolerance {} must be > 0", settings.tolerance)));
        }
        let n = self.n_scalars;
        let mut rows_i = Vec::new();
        let mut cols_j = Vec::new();
        let mut vals = Vec::new();
        let mut b = Vec::new();
        let mut cones = Vec::with_capacity(self.constraints.len());
        for c in &self.constraints {
            let s = Self::psd_form(c);
            let dim = s.rows;
            let row0 = b.len();
            b.extend(svec(&s.constant));
            for (&k, coeff) in &s.terms {
                for (r, v) in svec(coeff).into_iter().enumerate() {
                    if v != 0.0 {
                        rows_i.push(row0 + r);
                        cols_j.push(k);
                        vals.push(-v);
                    }
                }
            }
            cones.push(if dim == 1 {
                SupportedConeT::NonnegativeConeT(1)
            } else {
                SupportedConeT::PSDTriangleConeT(dim)
            });
        }
        let m = b.len();
        let a = CscMatrix::new_from_triplets(m, n, rows_i, cols_j, vals);
        let p = CscMatrix::zeros((n, n));
        let mut q = vec![0.0; n];
        let mut obj_const = 0.0;
        if let Some(obj) = &self.objective {
            obj_const = obj.constant[(0, 0)];
            for (&k, c) in &obj.terms {
                q[k] += c[(0, 0)];
            }
        }
        let clarabel_settings: DefaultSettings<f64> = DefaultSettingsBuilder::default()
            .verbose(settings.verbose)
            .max_iter(settings.max_iter)
            .tol_gap_abs(settings.tolerance)
            .tol_gap_rel(settings.tolerance)
            .tol_feas(settings.tolerance)
            .build()
            .map_err(|e| SolveError::Setup(e.to_string()))?;
        let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, clarabel_settings)
            .map_err(|e| SolveError::Setup(e.to_string()))?;
        solver.solve();
        let sol = &solver.solution;
        let violation = if sol.x.iter().all(|v| v.is_finite()) { self.max_violation(&sol.x) } else { f64::INFINITY };
        let stats = SolverStats {
            status: format!("{:?}", sol.status),
            iterations: sol.iterations,
            r_prim: sol.r_prim,
            r_dual: sol.r_dual,
            obj_primal: sol.obj_val + obj_const,
            obj_dual: sol.obj_val_dual + obj_const,
            solve_time_s: sol.solve_time,
            wall_time_s: t0.elapsed().as_secs_f64(),
            n_variables: n,
            n_constraints: self.constraints.len(),
            n_rows: m,
            max_constraint_violation: violation,
        };
        match sol.status {
            SolverStatus::Solved => {}
            SolverStatus::AlmostSolved if settings.accept_reduced_accuracy => {}
            SolverStatus::AlmostSolved => return Err(SolveError::NumericalTrouble(stats)),
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                return Err(SolveError::Infeasible(stats))
            }
            SolverStatus::DualInfeasible | SolverStatus::AlmostDualInfeasible => {
                return Err(SolveError::Unbounded(stats))
            }
            SolverStatus::MaxIterations | SolverStatus::MaxTime => return Err(SolveError::IterationLimit(stats)),
            _ => return Err(SolveError::NumericalTrouble(stats)),
        }
        if !violation.is_finite() {
            return Err(SolveError::NumericalTrouble(stats));
        }
        Ok(LmiSolution { x: sol.x.clone(), objective: sol.obj_val + obj_const, stats })
    }

    /// Labels of the constraints, in order (for diagnostics).
    pub fn constraint_labels(&self) -> Vec<&str> {
        self.constraints.iter().map(|c| c.label.as_str()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn svec_matches_clarabel_ordering() {
        let m = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 4.0, 2.0, 3.0, 5.0, 4.0, 5.0, 6.0]);
        let s = svec(&m);
        let r2 = 2f64.sqrt();
        assert_eq!(s, vec![1.0, 2.0 * r2, 3.0, 4.0 * r2, 5.0 * r2, 6.0]);
    }

    #[test]
    fn smallest_eigenvalue_as_sdp() {
        // max t s.t. M - t I >= 0  ->  t = lambda_min(M)
        let m = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 3.0]);
        let mut p = LmiProblem::new();
        let t = p.scalar();
        p.positive_definite("M - tI", &AffineExpr::constant(m.clone()) - &t.times_identity(2), 0.0).unwrap();
        p.minimize(t.expr().scale(-1.0)).unwrap();
        let s = p.solve(&SolverSettings::default()).unwrap();
        let expect = SymmetricEigen::new(m).eigenvalues.min();
        assert!((s.scalar(t) - expect).abs() < 1e-7, "{} vs {}", s.scalar(t), expect);
    }

    #[test]
    fn infeasible_is_typed() {
        let mut p = LmiProblem::new();
        let x = p.symmetric(2);
        p.positive_definite("X > 0", x.expr(), 1e-6).unwrap();
        p.negative_definite("X < 0", x.expr(), 1e-6).unwrap();
        match p.solve(&SolverSettings::default()) {
            Err(SolveError::Infeasible(s)) => assert!(s.iterations > 0),
            other => panic!("expected Infeasible, got {other:?}"),
        }
    }

    #[test]
    fn dimension_mismatch_is_refused() {
        let mut p = LmiProblem::new();
        let x = p.symmetric(2);
        let bad = &x.expr() + &AffineExpr::identity(3, 1.0);
        assert!(matches!(p.negative_definite("bad", bad, 0.0), Err(LmiError::Dimension(_))));
        let y = p.full(2, 3);
        assert!(matches!(p.negative_definite("Y", y.expr(), 0.0), Err(LmiError::Dimension(_))));
        let z = p.full(2, 2);
        assert!(matches!(p.negative_definite("Z", z.expr(), 0.0), Err(LmiError::NotSymmetric { .. })));
    }
}

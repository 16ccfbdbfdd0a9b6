//! The synthesis problems: minimum H-inf bound, minimum H2 bound under an H-inf bound,
//! the weighted trade-off, the authors' Pareto sweep, and the pole-placement baseline.
//!
//! All designs are state feedback `u = K x` with one common Lyapunov matrix for every
//! vertex of the polytope (quadratic stability), variables `X = X' > 0`, `Y = K X`, and
//! `K = Y X^-1`. With `M_j = A_j X + B_j Y` and `Z = C X + D_u Y` (`z = C x + D_u u`: the
//! paper's `z = [x; u]`, or the tracking model's weighted outputs, see
//! [`crate::plant::DesignModel`]); every problem is the same for any number of states:
//!
//! * D-stability, for each region part `(L, M)`: `L ⊗ X + M ⊗ M_j + M' ⊗ M_j' < 0`.
//! * H-inf, **gamma-squared form** (as MATLAB's `msfsyn`, which the authors used):
//!   `[[M_j + M_j', B_w, Z'], [B_w', -I, 0], [Z, 0, -gamma^2 I]] < 0`. It certifies that the
//!   induced L2 gain from `w` to `z` is below `gamma` at every point of the polytope;
//!   **the reported `gamma` is that bound on the L2 gain** (not its square).
//! * H2: `[[M_j + M_j', B_w], [B_w', -I]] < 0`, `[[Q, Z], [Z', X]] > 0`,
//!   `trace(Q) < nu^2`; `nu` bounds the H2 norm from `w` to `z`.
//!
//! **Strictness margin.** Every strict inequality `F < 0` (and `X > 0`) is imposed as
//! `F <= -eps I` with the absolute margin [`SynthesisOptions::margin`], default
//! `eps = 1e-7` (see [`DEFAULT_MARGIN`]).
//!
//! **Mirror symmetry.** The car is its own mirror image: reflecting it in its longitudinal
//! axis swaps FL with FR and RL with RR (their friction coefficients and steering inputs) and
//! flips the sign of every state (`beta`, `r`, and the tracking errors `e_y`, `e_psi`), of
//! every steering angle and of the lateral disturbance force. With `T = -I` on the states,
//! `P` the wheel swap on the inputs and `sigma` the vertex swap, the vertices satisfy
//! `A_sigma(j) = A_j` and `B_sigma(j) = B_j P`, and the performance outputs map by the
//! orthogonal `-P_z` (`P` on the input part of `z`). So if `(X, Y, gamma^2, Q)` satisfies
//! every LMI, `(T X T', -P Y T', gamma^2, P_z Q P_z') = (X, P Y, gamma^2, P_z Q P_z')`
//! satisfies them too (each LMI at vertex `j` is congruent, by an orthogonal matrix, to the
//! same LMI at vertex `sigma(j)`, margins included), with the same objective. The LMIs are
//! convex, so the average `(X, (Y + P Y)/2, ...)` is feasible and optimal as well: an optimum
//! with `Y = P Y` exists, and imposing `Y = P Y` on the variables (one row of `Y` per mirror
//! pair of wheels) loses nothing. It removes a direction in which the optimum is flat, where
//! without it the solver's last digits (about 1e-6 in `K`) follow the BLAS kernel's rounding.
//! `K = Y X^-1` then has equal rows for FL and FR and for RL and RR by construction.
//! The symmetry is imposed only when [`mirror_pairs`] finds it in the vertices given
//! (a car with different left and right tires is solved in full), it can be turned off
//! with [`SynthesisOptions::mirror_symmetry`], and the pole-placement baseline, a feasibility
//! problem whose answer is wherever the solver stops, keeps its full problem.

use std::fmt;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use nalgebra::DMatrix;
use serde::Serialize;

use crate::lmi::{AffineExpr, LmiError, LmiProblem, MatVar, SolveError, SolverSettings, SolverStats, SymVar};
use crate::plant::{PlantError, PlantSpec, Polytope, Vertex};
use crate::region::{PoleRegion, Region, RegionError};

/// Default strictness margin `eps` of every strict LMI (`F <= -eps I`).
pub const DEFAULT_MARGIN: f64 = 1e-7;

/// Options shared by all problems.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthesisOptions {
    /// Strictness margin `eps` (absolute): `F < 0` is imposed as `F <= -eps I`.
    pub margin: f64,
    /// Solver settings.
    pub solver: SolverSettings,
    /// Impose the car's mirror symmetry on `Y` when the vertices have it (see the module
    /// documentation); `false` solves over every `Y`.
    pub mirror_symmetry: bool,
}

impl Default for SynthesisOptions {
    fn default() -> Self {
        SynthesisOptions { margin: DEFAULT_MARGIN, solver: SolverSettings::default(), mirror_symmetry: true }
    }
}

/// Why a synthesis did not produce a gain.
#[derive(Clone, Debug, PartialEq)]
pub enum SynthesisError {
    /// The plant specification was refused.
    Plant(PlantError),
    /// The pole region was refused.
    Region(RegionError),
    /// A problem parameter (bound, weight, grid) was refused.
    Invalid(String),
    /// The LMI layer refused the problem (a bug, not bad input).
    Lmi(LmiError),
    /// The solver did not certify a solution (infeasible, numerical trouble, ...).
    Solve(SolveError),
    /// `X` came back singular, so `K = Y X^-1` does not exist.
    SingularLyapunov,
}

impl SynthesisError {
    /// True when the solver proved the LMIs infeasible.
    pub fn is_infeasible(&self) -> bool {
        matches!(self, SynthesisError::Solve(e) if e.is_infeasible())
    }
}

impl fmt::Display for SynthesisError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SynthesisError::Plant(e) => write!(f, "{e}"),
            SynthesisError::Region(e) => write!(f, "{e}"),
            SynthesisError::Invalid(s) => write!(f, "{s}"),
            SynthesisError::Lmi(e) => write!(f, "{e}"),
            SynthesisError::Solve(e) => write!(f, "{e}"),
            SynthesisError::SingularLyapunov => write!(f, "the Lyapunov matrix X is singular; no gain K = Y X^-1"),
        }
    }
}

impl std::error::Error for SynthesisError {}

/// `From` each wrapped error for `?`: `(error type, variant)` pairs.
macro_rules! synthesis_error_from {
    ($(($error:ty, $variant:ident)),* $(,)?) => {
        $(
            impl From<$error> for SynthesisError {
                fn from(e: $error) -> Self {
                    SynthesisError::$variant(e)
                }
            }
        )*
    };
}

synthesis_error_from!((PlantError, Plant), (RegionError, Region), (LmiError, Lmi), (SolveError, Solve));

/// A state-feedback gain with what the solver certified about it.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// `K`, n_inputs x n_states (rows follow the steered wheels, columns the states:
    /// `[beta, r]` for the paper's model, see [`Polytope::state_names`]).
    pub gain: DMatrix<f64>,
    /// The common Lyapunov matrix `X` (n_states x n_states).
    pub lyapunov: DMatrix<f64>,
    /// Certified bound on the induced L2 gain `w -> z` over the polytope, if constrained.
    pub gamma: Option<f64>,
    /// Certified bound on the H2 norm `w -> z` over the polytope, if constrained.
    pub nu: Option<f64>,
    /// Whether the mirror symmetry was imposed, so that the rows of mirror wheels of `gain`
    /// are equal by construction.
    pub mirror_symmetric: bool,
    /// What the solver reported.
    pub stats: SolverStats,
}

/// How the H-inf LMI enters a problem.
#[derive(Clone, Copy, Debug)]
enum HinfTerm {
    /// No H-inf constraint.
    None,
    /// `gamma <= g` with `g` given.
    Fixed(f64),
    /// `gamma^2` is a decision variable.
    Free,
}

struct Built {
    problem: LmiProblem,
    x: SymVar,
    /// The free rows of `Y`: one per mirror pair of inputs when the symmetry is imposed,
    /// else one per input.
    y_free: MatVar,
    /// `Y = expand * y_free` (n_inputs x rows of `y_free`): a 0/1 matrix that copies each
    /// pair's row to both of its inputs, or the identity.
    expand: DMatrix<f64>,
    gamma_sq: Option<crate::lmi::ScalarVar>,
    q: Option<SymVar>,
}

fn check_inputs(poly: &Polytope, region: &PoleRegion, opts: &SynthesisOptions) -> Result<(), SynthesisError> {
    poly.validate()?;
    region.validate()?;
    if !(opts.margin.is_finite() && opts.margin >= 0.0) {
        return Err(SynthesisError::Invalid(format!("margin {} must be finite and >= 0", opts.margin)));
    }
    Ok(())
}

/// Relative tolerance of the mirror-symmetry check on the vertex matrices. They are computed
/// by the same code from swapped friction vectors, so mirror entries agree up to the rounding
/// of a sum of four products taken in another order (a few ulp, about 1e-15 relative); 1e-12
/// accepts that on any machine and refuses any physical left/right difference, which is at
/// least a part in a thousand for a real car's parameters.
const MIRROR_TOLERANCE: f64 = 1e-12;

/// The mirror pairs of the inputs, when the car's mirror symmetry maps `vertices` onto
/// themselves (see the module documentation): for every vertex `j` there is a vertex
/// `sigma(j)` with the left and right friction coefficients swapped, `A_sigma(j) = A_j` and
/// `B_sigma(j) = B_j P` (`P` swaps the columns of FL and FR and of RL and RR), and the
/// performance outputs `z = C x + D_u u` satisfy `P_z C = C` and `P_z D_u = D_u P` (`P_z`
/// swaps the outputs that weigh mirror inputs). Returns the input index pairs `(left, right)`,
/// or `None` when any of this fails.
pub fn mirror_pairs(poly: &Polytope, vertices: &[Vertex]) -> Option<Vec<(usize, usize)>> {
    let wheels = poly.spec.architecture.steered_wheels();
    let m = wheels.len();
    // wheel order FL, FR, RL, RR: the mirror of wheel w is w ^ 1
    let partner: Option<Vec<usize>> = wheels.iter().map(|&w| wheels.iter().position(|&v| v == w ^ 1)).collect();
    let partner = partner?;
    let perm = DMatrix::from_fn(m, m, |i, j| if partner[j] == i { 1.0 } else { 0.0 });
    let close = |a: &DMatrix<f64>, b: &DMatrix<f64>| {
        a.shape() == b.shape() && (a - b).amax() <= MIRROR_TOLERANCE * a.amax().max(b.amax()).max(f64::MIN_POSITIVE)
    };
    for v in vertices {
        let mirrored_mu = [v.mu[1], v.mu[0], v.mu[3], v.mu[2]];
        let image = vertices.iter().find(|u| u.mu == mirrored_mu)?;
        if !(close(&image.a, &v.a) && close(&image.b, &(&v.b * &perm))) {
            return None;
        }
    }
    let (c, d_u) = (poly.c(), poly.d_u());
    let nz = c.nrows();
    if nz < m {
        return None;
    }
    // P_z: the identity on the state part of z, P on its last m rows (the weighted inputs)
    let mut perm_z = DMatrix::identity(nz, nz);
    perm_z.view_mut((nz - m, nz - m), (m, m)).copy_from(&perm);
    if !(close(&(&perm_z * &c), &c) && close(&(&perm_z * &d_u), &(&d_u * &perm))) {
        return None;
    }
    Some((0..m).filter(|&i| i < partner[i]).map(|i| (i, partner[i])).collect())
}

/// `L ⊗ X + M ⊗ N + M' ⊗ N'` for one region part.
fn region_lmi(part: &Region, x: &AffineExpr, n: &AffineExpr) -> AffineExpr {
    let (l, m) = part.characteristic();
    let mt = m.transpose();
    &(&x.kron_left(&l) + &n.kron_left(&m)) + &n.transpose().kron_left(&mt)
}

fn build(
    poly: &Polytope,
    vertices: &[Vertex],
    region: &PoleRegion,
    hinf: HinfTerm,
    h2: bool,
    opts: &SynthesisOptions,
) -> Result<Built, SynthesisError> {
    let eps = opts.margin;
    let (n, m, nz) = (poly.n_states(), poly.n_inputs(), poly.n_outputs());
    let mut p = LmiProblem::new();
    let x = p.symmetric(n);
    let pairs = if opts.mirror_symmetry { mirror_pairs(poly, vertices) } else { None };
    let expand = match &pairs {
        Some(pairs) => {
            let mut e = DMatrix::zeros(m, pairs.len());
            for (row, &(left, right)) in pairs.iter().enumerate() {
                e[(left, row)] = 1.0;
                e[(right, row)] = 1.0;
            }
            e
        }
        None => DMatrix::identity(m, m),
    };
    let y_free = p.full(expand.ncols(), n);
    let xe = x.expr();
    let ye = y_free.expr().premul(&expand);
    p.positive_definite("X > 0", xe.clone(), eps)?;
    let bw = AffineExpr::constant(poly.bw.clone());
    let nw = poly.bw.ncols();
    let z = &xe.premul(&poly.c()) + &ye.premul(&poly.d_u());
    let gamma_sq = match hinf {
        HinfTerm::Free => Some(p.scalar()),
        _ => None,
    };
    for (j, v) in vertices.iter().enumerate() {
        let mj = &xe.premul(&v.a) + &ye.premul(&v.b);
        let sym = mj.plus_transpose();
        for (ri, part) in region.parts.iter().enumerate() {
            p.negative_definite(&format!("region {ri} at vertex {j}"), region_lmi(part, &xe, &mj), eps)?;
        }
        let hinf_corner = match (hinf, gamma_sq) {
            (HinfTerm::Fixed(g), _) => Some(AffineExpr::identity(nz, -g * g)),
            (HinfTerm::Free, Some(s)) => Some(s.times_identity(nz).scale(-1.0)),
            _ => None,
        };
        if let Some(corner) = hinf_corner {
            let lmi = AffineExpr::blocks(&[
                vec![Some(sym.clone()), Some(bw.clone()), Some(z.transpose())],
                vec![Some(bw.transpose()), Some(AffineExpr::identity(nw, -1.0)), None],
                vec![Some(z.clone()), None, Some(corner)],
            ]);
            p.negative_definite(&format!("H-inf at vertex {j}"), lmi, eps)?;
        }
        if h2 {
            let lmi = AffineExpr::blocks(&[
                vec![Some(sym.clone()), Some(bw.clone())],
                vec![Some(bw.transpose()), Some(AffineExpr::identity(nw, -1.0))],
            ]);
            p.negative_definite(&format!("H2 at vertex {j}"), lmi, eps)?;
        }
    }
    let q = if h2 {
        let q = p.symmetric(nz);
        let lmi =
            AffineExpr::blocks(&[vec![Some(q.expr()), Some(z.clone())], vec![Some(z.transpose()), Some(xe.clone())]]);
        p.positive_definite("[[Q, Z], [Z', X]] > 0", lmi, eps)?;
        Some(q)
    } else {
        None
    };
    Ok(Built { problem: p, x, y_free, expand, gamma_sq, q })
}

/// `K = Y X^-1`, computed as `expand (Y_free X^-1)` so that mirror rows are equal bit for bit.
fn extract(built: &Built, sol: &crate::lmi::LmiSolution) -> Result<(DMatrix<f64>, DMatrix<f64>), SynthesisError> {
    let x = sol.sym(built.x);
    let y_free = sol.mat(built.y_free);
    let xinv = x.clone().try_inverse().ok_or(SynthesisError::SingularLyapunov)?;
    // a 0/1 matrix with one 1 per row times a finite matrix copies rows exactly (1 a + 0 b = a)
    let k = &built.expand * (&y_free * xinv);
    if !k.iter().all(|v| v.is_finite()) {
        return Err(SynthesisError::SingularLyapunov);
    }
    Ok((k, x))
}

impl Built {
    fn mirror_symmetric(&self) -> bool {
        self.expand.ncols() < self.expand.nrows()
    }
}

/// `gamma* = min gamma` subject to D-stability and the H-inf LMIs at every vertex.
pub fn min_hinf(poly: &Polytope, region: &PoleRegion, opts: &SynthesisOptions) -> Result<Design, SynthesisError> {
    check_inputs(poly, region, opts)?;
    let mut b = build(poly, &poly.vertices, region, HinfTerm::Free, false, opts)?;
    let s = b.gamma_sq.ok_or_else(|| SynthesisError::Invalid("internal: no gamma variable".into()))?;
    b.problem.minimize(s.expr())?;
    let sol = b.problem.solve(&opts.solver)?;
    let (gain, lyapunov) = extract(&b, &sol)?;
    let gamma = sol.scalar(s).max(0.0).sqrt();
    Ok(Design {
        gain,
        lyapunov,
        gamma: Some(gamma),
        nu: None,
        mirror_symmetric: b.mirror_symmetric(),
        stats: sol.stats,
    })
}

/// `min nu` subject to D-stability, the H2 LMIs and, if `hinf_bound` is given, the H-inf
/// LMIs with `gamma = hinf_bound`.
pub fn min_h2(
    poly: &Polytope,
    region: &PoleRegion,
    hinf_bound: Option<f64>,
    opts: &SynthesisOptions,
) -> Result<Design, SynthesisError> {
    check_inputs(poly, region, opts)?;
    if let Some(g) = hinf_bound {
        if !(g.is_finite() && g > 0.0) {
            return Err(SynthesisError::Invalid(format!("H-inf bound {g} must be finite and > 0")));
        }
    }
    let hinf = hinf_bound.map_or(HinfTerm::None, HinfTerm::Fixed);
    let mut b = build(poly, &poly.vertices, region, hinf, true, opts)?;
    let q = b.q.ok_or_else(|| SynthesisError::Invalid("internal: no Q variable".into()))?;
    b.problem.minimize(q.expr().trace())?;
    let sol = b.problem.solve(&opts.solver)?;
    let (gain, lyapunov) = extract(&b, &sol)?;
    let nu = sol.eval(&q.expr().trace())[(0, 0)].max(0.0).sqrt();
    Ok(Design {
        gain,
        lyapunov,
        gamma: hinf_bound,
        nu: Some(nu),
        mirror_symmetric: b.mirror_symmetric(),
        stats: sol.stats,
    })
}

/// `min a gamma^2 + b nu^2` subject to D-stability, the H-inf and the H2 LMIs.
pub fn weighted(
    poly: &Polytope,
    region: &PoleRegion,
    weight_hinf: f64,
    weight_h2: f64,
    opts: &SynthesisOptions,
) -> Result<Design, SynthesisError> {
    check_inputs(poly, region, opts)?;
    for (name, w) in [("H-inf weight", weight_hinf), ("H2 weight", weight_h2)] {
        if !(w.is_finite() && w >= 0.0) {
            return Err(SynthesisError::Invalid(format!("{name} {w} must be finite and >= 0")));
        }
    }
    if weight_hinf == 0.0 && weight_h2 == 0.0 {
        return Err(SynthesisError::Invalid("at least one weight must be > 0".into()));
    }
    let mut b = build(poly, &poly.vertices, region, HinfTerm::Free, true, opts)?;
    let s = b.gamma_sq.ok_or_else(|| SynthesisError::Invalid("internal: no gamma variable".into()))?;
    let q = b.q.ok_or_else(|| SynthesisError::Invalid("internal: no Q variable".into()))?;
    b.problem.minimize(&s.expr().scale(weight_hinf) + &q.expr().trace().scale(weight_h2))?;
    let sol = b.problem.solve(&opts.solver)?;
    let (gain, lyapunov) = extract(&b, &sol)?;
    let gamma = sol.scalar(s).max(0.0).sqrt();
    let nu = sol.eval(&q.expr().trace())[(0, 0)].max(0.0).sqrt();
    Ok(Design {
        gain,
        lyapunov,
        gamma: Some(gamma),
        nu: Some(nu),
        mirror_symmetric: b.mirror_symmetric(),
        stats: sol.stats,
    })
}

/// The grid of the authors' Pareto sweep.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepOptions {
    /// Grid step in `g` (0.01).
    pub step: f64,
    /// Last grid value (inclusive up to rounding: `g <= g_max`), 0.5.
    pub g_max: f64,
    /// `k = 0` sits on the feasibility boundary; it is solved at `gamma* (1 + boundary_factor)`.
    pub boundary_factor: f64,
    /// Worker threads for the grid (1 = serial; 0 = as many as the machine has).
    pub threads: usize,
}

impl Default for SweepOptions {
    fn default() -> Self {
        SweepOptions { step: 0.01, g_max: 0.5, boundary_factor: 1e-5, threads: 0 }
    }
}

/// One point of the Pareto sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct ParetoPoint {
    /// Grid index: `g = gamma* + k step` (k = 0 at `gamma* (1 + boundary_factor)`).
    pub k: usize,
    /// The H-inf bound imposed.
    pub g: f64,
    /// The design, or why the point failed.
    pub result: Result<Design, SynthesisError>,
}

impl ParetoPoint {
    /// `nu` of the point when it was solved.
    pub fn nu(&self) -> Option<f64> {
        self.result.as_ref().ok().and_then(|d| d.nu)
    }
    /// `sqrt(g^2 + nu^2)` when solved.
    pub fn distance(&self) -> Option<f64> {
        self.nu().map(|nu| self.g.hypot(nu))
    }
}

/// Progress of a sweep, for a progress line.
#[derive(Clone, Copy, Debug)]
pub struct SweepProgress {
    /// Points finished so far.
    pub done: usize,
    /// Points in the grid.
    pub total: usize,
    /// The point just finished.
    pub k: usize,
    /// Its bound.
    pub g: f64,
    /// Its `nu`, if solved.
    pub nu: Option<f64>,
}

/// The result of the authors' Pareto sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct ParetoSweep {
    /// The minimum H-inf design (`gamma*` and its gain).
    pub hinf_optimum: Design,
    /// The grid points in order of `k`.
    pub points: Vec<ParetoPoint>,
    /// Index into `points` of the point nearest the origin.
    pub chosen: usize,
    /// Wall time of the whole sweep, including `gamma*` (s).
    pub wall_time_s: f64,
}

impl ParetoSweep {
    /// `gamma*`.
    pub fn gamma_star(&self) -> f64 {
        self.hinf_optimum.gamma.unwrap_or(f64::NAN)
    }
    /// The chosen point.
    pub fn chosen_point(&self) -> &ParetoPoint {
        &self.points[self.chosen]
    }
    /// The chosen design (always solved: only solved points can be chosen).
    pub fn chosen_design(&self) -> Option<&Design> {
        self.points[self.chosen].result.as_ref().ok()
    }
    /// `nu(g)` on the curve by linear interpolation between solved grid points
    /// (`None` outside the solved range).
    pub fn nu_at(&self, g: f64) -> Option<f64> {
        let pts: Vec<(f64, f64)> = self.points.iter().filter_map(|p| p.nu().map(|nu| (p.g, nu))).collect();
        pts.windows(2).find(|w| w[0].0 <= g && g <= w[1].0).map(|w| {
            let t = (g - w[0].0) / (w[1].0 - w[0].0);
            w[0].1 + t * (w[1].1 - w[0].1)
        })
    }
}

/// The grid values `g_k` of the sweep for a given `gamma*`.
pub fn sweep_grid(gamma_star: f64, sweep: &SweepOptions) -> Vec<f64> {
    let mut grid = vec![gamma_star * (1.0 + sweep.boundary_factor)];
    let mut k = 1usize;
    loop {
        let g = gamma_star + k as f64 * sweep.step;
        if g > sweep.g_max + 1e-12 {
            break;
        }
        grid.push(g);
        k += 1;
    }
    grid
}

/// The authors' Pareto sweep: `gamma*`, then `min nu` at each `g` of the grid
/// `gamma*, gamma* + step, ..., <= g_max`, and the point minimising `sqrt(g^2 + nu^2)`.
///
/// Points are solved on `sweep.threads` threads; `progress` is called after each one.
pub fn pareto_sweep(
    poly: &Polytope,
    region: &PoleRegion,
    sweep: &SweepOptions,
    opts: &SynthesisOptions,
    progress: Option<&(dyn Fn(SweepProgress) + Sync)>,
) -> Result<ParetoSweep, SynthesisError> {
    let t0 = Instant::now();
    if !(sweep.step.is_finite() && sweep.step > 0.0 && sweep.g_max.is_finite()) {
        return Err(SynthesisError::Invalid(format!("sweep step {} / g_max {} invalid", sweep.step, sweep.g_max)));
    }
    if !(sweep.boundary_factor.is_finite() && sweep.boundary_factor >= 0.0) {
        return Err(SynthesisError::Invalid(format!("boundary factor {} invalid", sweep.boundary_factor)));
    }
    let hinf_optimum = min_hinf(poly, region, opts)?;
    let gamma_star = hinf_optimum.gamma.unwrap_or(f64::NAN);
    let grid = sweep_grid(gamma_star, sweep);
    if grid.len() > 100_000 {
        return Err(SynthesisError::Invalid(format!("sweep grid has {} points", grid.len())));
    }
    let total = grid.len();
    let threads = match sweep.threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        t => t,
    }
    .clamp(1, total.max(1));
    let slots: Vec<Mutex<Option<ParetoPoint>>> = (0..total).map(|_| Mutex::new(None)).collect();
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let work = || loop {
        let k = next.fetch_add(1, Ordering::SeqCst);
        if k >= total {
            break;
        }
        let g = grid[k];
        let result = min_h2(poly, region, Some(g), opts);
        let nu = result.as_ref().ok().and_then(|d| d.nu);
        if let Ok(mut slot) = slots[k].lock() {
            *slot = Some(ParetoPoint { k, g, result });
        }
        let d = done.fetch_add(1, Ordering::SeqCst) + 1;
        if let Some(cb) = progress {
            cb(SweepProgress { done: d, total, k, g, nu });
        }
    };
    if threads == 1 {
        work();
    } else {
        std::thread::scope(|s| {
            for _ in 0..threads {
                s.spawn(work);
            }
        });
    }
    let points: Vec<ParetoPoint> = slots
        .into_iter()
        .enumerate()
        .map(|(k, m)| {
            m.into_inner().ok().flatten().unwrap_or(ParetoPoint {
                k,
                g: grid[k],
                result: Err(SynthesisError::Invalid("grid point was not solved".into())),
            })
        })
        .collect();
    let chosen = points
        .iter()
        .enumerate()
        .filter_map(|(i, p)| p.distance().map(|d| (i, d)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i);
    let chosen = match chosen {
        Some(i) => i,
        None => {
            return Err(points
                .into_iter()
                .find_map(|p| p.result.err())
                .unwrap_or_else(|| SynthesisError::Invalid("empty sweep grid".into())))
        }
    };
    Ok(ParetoSweep { hinf_optimum, points, chosen, wall_time_s: t0.elapsed().as_secs_f64() })
}

/// The non-robust baseline of the paper: pole placement `Re(s) < alpha` (paper: -2) by
/// the half-plane LMI alone on the nominal model `mu_i = mu_nominal` (paper: 0.4), no norm
/// objective. The feasibility problem has many solutions (`K = 0` is one); it is made
/// deterministic by `X >= I` and a zero objective (the interior-point solution).
#[derive(Clone, Debug, PartialEq)]
pub struct Baseline {
    /// The gain.
    pub design: Design,
    /// Nominal friction used.
    pub mu_nominal: f64,
    /// Half-plane abscissa used.
    pub alpha: f64,
    /// Largest closed-loop real part over the 16 vertices of the polytope.
    pub max_real_part_over_vertices: f64,
    /// Whether the gain stabilises all 16 vertices.
    pub stabilises_all_vertices: bool,
}

/// See [`Baseline`].
pub fn pole_placement_baseline(
    poly: &Polytope,
    mu_nominal: f64,
    alpha: f64,
    opts: &SynthesisOptions,
) -> Result<Baseline, SynthesisError> {
    poly.validate()?;
    if !(mu_nominal.is_finite() && mu_nominal > 0.0) {
        return Err(SynthesisError::Invalid(format!("nominal friction {mu_nominal} must be finite and > 0")));
    }
    let region = PoleRegion { parts: vec![Region::half_plane(alpha)] };
    region.validate()?;
    let nominal = poly.at([mu_nominal; 4]);
    // A feasibility problem: its answer is the solver's interior point, not an optimum, so
    // restricting the variables would move it; the full problem is kept (the symmetric data
    // give mirror rows equal to the last bit on every OpenBLAS kernel measured).
    let full = SynthesisOptions { mirror_symmetry: false, ..opts.clone() };
    let mut b = build(poly, std::slice::from_ref(&nominal), &region, HinfTerm::None, false, &full)?;
    let n = poly.n_states();
    b.problem.positive_definite("X >= I", &b.x.expr() - &AffineExpr::identity(n, 1.0), 0.0)?;
    let sol = b.problem.solve(&opts.solver)?;
    let (gain, lyapunov) = extract(&b, &sol)?;
    let max_re = poly
        .vertices
        .iter()
        .map(|v| crate::verify::ClosedLoop::new(v, &poly.bw, &gain).max_real_part())
        .fold(f64::NEG_INFINITY, f64::max);
    Ok(Baseline {
        design: Design {
            gain,
            lyapunov,
            gamma: None,
            nu: None,
            mirror_symmetric: b.mirror_symmetric(),
            stats: sol.stats,
        },
        mu_nominal,
        alpha,
        max_real_part_over_vertices: max_re,
        stabilises_all_vertices: max_re < 0.0,
    })
}

/// Convenience: build the polytope from a spec and run the Pareto sweep.
pub fn pareto_sweep_for(
    spec: &PlantSpec,
    region: &PoleRegion,
    sweep: &SweepOptions,
    opts: &SynthesisOptions,
) -> Result<ParetoSweep, SynthesisError> {
    let poly = spec.polytope()?;
    pareto_sweep(&poly, region, sweep, opts, None)
}

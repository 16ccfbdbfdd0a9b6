//! Verification that does not trust the solver.
//!
//! For a gain `K`, the closed loop at a plant `(A, B)` is `x' = (A + B K) x + B_w w`,
//! `z = C x + D_u u = (C + D_u K) x` (no feedthrough; the paper's `z = [x; u] = [I; K] x`).
//! This module computes, from `K` alone:
//!
//! * the closed-loop poles and their position relative to a [`PoleRegion`];
//! * the H-inf norm by bisection on the Hamiltonian
//!   `H(g) = [[A, B_w B_w'/g^2], [-C'C, -A']]` (which has an eigenvalue on the imaginary
//!   axis exactly when `g` is a singular value of `G(jw)` for some `w`), and a second
//!   time by a dense frequency sweep of `sigma_max(G(jw))` refined by golden section;
//! * the H2 norm from the controllability Gramian (Lyapunov equation
//!   `A W + W A' + B_w B_w' = 0`, `||G||_2^2 = trace(C W C')`), a second time by
//!   integrating the Gramian `int_0^inf e^{At} B_w B_w' e^{A't} dt` directly (Van Loan's
//!   exponential for a short interval, then interval doubling), and a third time from the
//!   dual (observability) Lyapunov equation.
//!
//! [`verify_design`] runs all of it at the 16 vertices and at random interior points of
//! the friction box (deterministic seed) and compares with the certified bounds.

use std::fmt;

use nalgebra::{Complex, DMatrix};
use serde::Serialize;

use crate::plant::{Polytope, Vertex};
use crate::region::{Complex64, PoleRegion};

/// A norm could not be computed.
#[derive(Clone, Debug, PartialEq)]
pub enum NormError {
    /// The closed loop is not Hurwitz (the norm is infinite).
    Unstable {
        /// Largest real part of the closed-loop poles.
        max_real_part: f64,
    },
    /// A linear system was singular or an iteration did not converge.
    Numerical(String),
}

impl fmt::Display for NormError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NormError::Unstable { max_real_part } => {
                write!(f, "closed loop is unstable (max real part {max_real_part:e}); the norm is infinite")
            }
            NormError::Numerical(s) => write!(f, "norm computation failed: {s}"),
        }
    }
}

impl std::error::Error for NormError {}

/// `x' = A x + B_w w`, `z = C x` (no feedthrough).
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedLoop {
    /// `A + B K`.
    pub a: DMatrix<f64>,
    /// `B_w`.
    pub bw: DMatrix<f64>,
    /// `[I; K]`.
    pub c: DMatrix<f64>,
}

/// Result of the Hamiltonian bisection: the norm lies in `[lower, upper]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HinfBracket {
    /// A value of `sigma_max(G(jw))` actually attained (a true lower bound).
    pub lower: f64,
    /// A level at which the Hamiltonian has no imaginary eigenvalue (an upper bound).
    pub upper: f64,
}

fn cplx(m: &DMatrix<f64>) -> DMatrix<Complex<f64>> {
    m.map(|v| Complex::new(v, 0.0))
}

impl ClosedLoop {
    /// The closed loop of plant `v` with gain `k` (`u = K x`).
    pub fn new(v: &Vertex, bw: &DMatrix<f64>, k: &DMatrix<f64>) -> Self {
        let n = v.a.nrows();
        let a = &v.a + &v.b * k;
        let mut c = DMatrix::zeros(n + k.nrows(), n);
        c.view_mut((0, 0), (n, n)).fill_with_identity();
        c.view_mut((n, 0), (k.nrows(), n)).copy_from(k);
        ClosedLoop { a, bw: bw.clone(), c }
    }

    /// The closed loop of plant `v` with gain `k` and performance output
    /// `z = c x + d_u u`: `C_cl = c + d_u k`.
    pub fn with_outputs(v: &Vertex, bw: &DMatrix<f64>, k: &DMatrix<f64>, c: &DMatrix<f64>, d_u: &DMatrix<f64>) -> Self {
        ClosedLoop { a: &v.a + &v.b * k, bw: bw.clone(), c: c + d_u * k }
    }

    /// Eigenvalues of `A + B K`.
    pub fn poles(&self) -> Vec<Complex64> {
        self.a.complex_eigenvalues().iter().copied().collect()
    }

    /// Largest real part of the poles.
    pub fn max_real_part(&self) -> f64 {
        self.poles().iter().map(|p| p.re).fold(f64::NEG_INFINITY, f64::max)
    }

    fn require_stable(&self) -> Result<(), NormError> {
        let m = self.max_real_part();
        if m < 0.0 && m.is_finite() {
            Ok(())
        } else {
            Err(NormError::Unstable { max_real_part: m })
        }
    }

    /// `sigma_max(G(jw))`, `G(s) = C (sI - A)^-1 B_w`.
    pub fn sigma_max(&self, w: f64) -> f64 {
        let n = self.a.nrows();
        let jw = DMatrix::<Complex<f64>>::identity(n, n) * Complex::new(0.0, w);
        let m = jw - cplx(&self.a);
        let Some(sol) = m.lu().solve(&cplx(&self.bw)) else {
            return f64::INFINITY;
        };
        let g = cplx(&self.c) * sol;
        if g.ncols() == 1 {
            g.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt()
        } else {
            g.singular_values().max()
        }
    }

    /// Whether the level `g` is reached: `Some(sigma)` with the largest
    /// `sigma_max(G(jw)) >= g` found at the frequencies of the Hamiltonian's (nearly)
    /// imaginary eigenvalues and at the midpoints between them (Bruinsma-Steinbuch), or
    /// `None` if no such frequency reaches `g`.
    fn level_reached(&self, g: f64) -> Option<f64> {
        let n = self.a.nrows();
        let mut h = DMatrix::zeros(2 * n, 2 * n);
        h.view_mut((0, 0), (n, n)).copy_from(&self.a);
        h.view_mut((0, n), (n, n)).copy_from(&(&self.bw * self.bw.transpose() / (g * g)));
        h.view_mut((n, 0), (n, n)).copy_from(&(-(self.c.transpose() * &self.c)));
        h.view_mut((n, n), (n, n)).copy_from(&(-self.a.transpose()));
        let eig = h.complex_eigenvalues();
        let scale = eig.iter().map(|z| z.norm()).fold(1e-300, f64::max);
        // Candidates: eigenvalues near the imaginary axis relative to their own size
        // (loosely: near the peak two imaginary eigenvalues are about to meet and rounding
        // pushes them off the axis by ~sqrt(eps)). A candidate only counts through the
        // value of sigma_max actually attained at its frequency.
        let mut freqs: Vec<f64> =
            eig.iter().filter(|z| z.re.abs() <= 1e-3 * z.norm() + 1e-10 * scale).map(|z| z.im.abs()).collect();
        if freqs.is_empty() {
            return None;
        }
        freqs.sort_by(f64::total_cmp);
        let mids: Vec<f64> = freqs.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        let best = freqs.iter().chain(mids.iter()).map(|&w| self.sigma_max(w)).fold(0.0, f64::max);
        (best >= g).then_some(best)
    }

    /// The H-inf norm by Hamiltonian bisection to relative width `rel_tol`.
    ///
    /// `H(g) = [[A, B B'/g^2], [-C'C, -A']]` has an eigenvalue `j w` exactly when `g` is a
    /// singular value of `G(jw)`. At each level the frequencies of the (nearly) imaginary
    /// eigenvalues and their midpoints are evaluated: if one reaches the level, `lower`
    /// rises to the value attained there (so `lower` is always an attained value),
    /// otherwise `upper` drops to the level.
    pub fn hinf_norm_hamiltonian(&self, rel_tol: f64) -> Result<HinfBracket, NormError> {
        self.require_stable()?;
        // lower bound: sigma at 0 and at the pole frequencies
        let mut lower = self.sigma_max(0.0);
        for p in self.poles() {
            lower = lower.max(self.sigma_max(p.im.abs())).max(self.sigma_max(p.norm()));
        }
        if lower == 0.0 {
            return Ok(HinfBracket { lower: 0.0, upper: 0.0 });
        }
        let mut upper = 2.0 * lower;
        let mut tries = 0;
        while let Some(reached) = self.level_reached(upper) {
            lower = lower.max(reached);
            upper = 2.0 * lower;
            tries += 1;
            if tries > 200 {
                return Err(NormError::Numerical("no upper bound for the H-inf norm".into()));
            }
        }
        let tol = rel_tol.max(1e-14);
        let mut iters = 0;
        while upper - lower > tol * upper {
            let mid = 0.5 * (lower + upper);
            match self.level_reached(mid) {
                Some(reached) => lower = lower.max(reached),
                None => upper = mid,
            }
            if lower > upper {
                upper = lower;
            }
            iters += 1;
            if iters > 300 {
                break;
            }
        }
        Ok(HinfBracket { lower, upper })
    }

    /// The H-inf norm by a dense logarithmic frequency sweep (0 and 4000 frequencies
    /// spanning six decades around the pole magnitudes), refined by golden-section search
    /// around the best grid point. A lower bound, accurate to ~1e-10 relative.
    pub fn hinf_norm_frequency_sweep(&self) -> Result<f64, NormError> {
        self.require_stable()?;
        let mags: Vec<f64> = self.poles().iter().map(|p| p.norm()).collect();
        let lo = mags.iter().copied().fold(f64::INFINITY, f64::min).max(1e-12) * 1e-3;
        let hi = mags.iter().copied().fold(0.0, f64::max).max(1e-12) * 1e3;
        let n = 4000;
        let mut grid = vec![0.0];
        let ratio = (hi / lo).ln();
        for i in 0..n {
            grid.push(lo * (ratio * i as f64 / (n - 1) as f64).exp());
        }
        let vals: Vec<f64> = grid.iter().map(|&w| self.sigma_max(w)).collect();
        let (ibest, mut best) =
            vals.iter().copied().enumerate().fold((0, 0.0), |acc, (i, v)| if v > acc.1 { (i, v) } else { acc });
        // golden section on [grid[i-1], grid[i+1]]
        let mut a = grid[ibest.saturating_sub(1)];
        let mut b = grid[(ibest + 1).min(grid.len() - 1)];
        let phi = 0.5 * (5f64.sqrt() - 1.0);
        let mut c = b - phi * (b - a);
        let mut d = a + phi * (b - a);
        let (mut fc, mut fd) = (self.sigma_max(c), self.sigma_max(d));
        for _ in 0..200 {
            if (b - a) <= 1e-13 * b.max(1e-300) {
                break;
            }
            if fc > fd {
                b = d;
                d = c;
                fd = fc;
                c = b - phi * (b - a);
                fc = self.sigma_max(c);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + phi * (b - a);
                fd = self.sigma_max(d);
            }
        }
        best = best.max(fc).max(fd);
        Ok(best)
    }

    /// Solves `A W + W A' + Q = 0` by Kronecker vectorisation.
    fn lyapunov(a: &DMatrix<f64>, q: &DMatrix<f64>) -> Result<DMatrix<f64>, NormError> {
        let n = a.nrows();
        let i = DMatrix::<f64>::identity(n, n);
        let op = i.kronecker(a) + a.kronecker(&i);
        let rhs = DMatrix::from_column_slice(n * n, 1, (-q).as_slice());
        let sol = op.lu().solve(&rhs).ok_or_else(|| NormError::Numerical("singular Lyapunov operator".into()))?;
        let w = DMatrix::from_column_slice(n, n, sol.as_slice());
        Ok((&w + w.transpose()) * 0.5)
    }

    /// The H2 norm from the controllability Gramian (Lyapunov equation).
    pub fn h2_norm_lyapunov(&self) -> Result<f64, NormError> {
        self.require_stable()?;
        let w = Self::lyapunov(&self.a, &(&self.bw * self.bw.transpose()))?;
        Ok((&self.c * w * self.c.transpose()).trace().max(0.0).sqrt())
    }

    /// The H2 norm from the observability Gramian (the dual Lyapunov equation
    /// `A'P + P A + C'C = 0`, `||G||_2^2 = trace(B_w' P B_w)`).
    pub fn h2_norm_dual_lyapunov(&self) -> Result<f64, NormError> {
        self.require_stable()?;
        let p = Self::lyapunov(&self.a.transpose(), &(self.c.transpose() * &self.c))?;
        Ok((self.bw.transpose() * p * &self.bw).trace().max(0.0).sqrt())
    }

    /// The H2 norm by integrating the impulse-response Gramian
    /// `W = int_0^inf e^{At} B_w B_w' e^{A't} dt` without a Lyapunov solve: the integral
    /// over a short interval `h` from Van Loan's block exponential, then
    /// `W(2T) = W(T) + e^{AT} W(T) e^{A'T}` until `e^{AT}` has decayed to nothing.
    pub fn h2_norm_gramian_integration(&self) -> Result<f64, NormError> {
        self.require_stable()?;
        let n = self.a.nrows();
        let rho = self.poles().iter().map(|p| p.norm()).fold(1e-300, f64::max);
        let h = 1e-3 / rho;
        let mut big = DMatrix::zeros(2 * n, 2 * n);
        big.view_mut((0, 0), (n, n)).copy_from(&(-&self.a * h));
        big.view_mut((0, n), (n, n)).copy_from(&(&self.bw * self.bw.transpose() * h));
        big.view_mut((n, n), (n, n)).copy_from(&(self.a.transpose() * h));
        let e = big.exp();
        let f12 = e.view((0, n), (n, n)).into_owned();
        let f22 = e.view((n, n), (n, n)).into_owned();
        let mut phi = f22.transpose(); // e^{A h}
        let mut w = &phi * f12; // W(h) = F22' F12
        for _ in 0..200 {
            let next = &w + &phi * &w * phi.transpose();
            phi = &phi * &phi;
            w = next;
            if phi.amax() < 1e-17 {
                let h2 = (&self.c * &w * self.c.transpose()).trace();
                return Ok(h2.max(0.0).sqrt());
            }
        }
        Err(NormError::Numerical("Gramian integration did not converge".into()))
    }
}

/// Where a checked plant came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PointKind {
    /// A vertex of the friction box.
    Vertex,
    /// A random interior point.
    Interior,
}

/// The checks at one plant of the polytope.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PointCheck {
    /// Vertex or interior point.
    pub kind: PointKind,
    /// Friction FL, FR, RL, RR.
    pub mu: [f64; 4],
    /// Closed-loop poles `[re, im]`.
    pub poles: Vec<[f64; 2]>,
    /// Smallest margin of a pole inside the region (positive = inside).
    pub region_margin: f64,
    /// H-inf norm by Hamiltonian bisection (upper end of the bracket); infinite if unstable.
    pub hinf: f64,
    /// H-inf norm by the frequency sweep.
    pub hinf_sweep: f64,
    /// H2 norm by the Lyapunov equation.
    pub h2: f64,
    /// H2 norm by Gramian integration.
    pub h2_integrated: f64,
    /// H2 norm by the dual Lyapunov equation.
    pub h2_dual: f64,
}

/// How to verify.
#[derive(Clone, Debug, PartialEq)]
pub struct VerifyOptions {
    /// Number of random interior points of the friction box.
    pub interior_points: usize,
    /// Seed of the deterministic generator.
    pub seed: u64,
    /// Relative tolerance of the Hamiltonian bisection.
    pub bisection_tol: f64,
}

impl Default for VerifyOptions {
    fn default() -> Self {
        VerifyOptions { interior_points: 64, seed: 0x005E_ED0F_4157, bisection_tol: 1e-10 }
    }
}

/// Summary of a verification.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VerificationReport {
    /// The 16 vertices.
    pub vertices: Vec<PointCheck>,
    /// Random interior points.
    pub interior: Vec<PointCheck>,
    /// Certified H-inf bound (if any).
    pub gamma_bound: Option<f64>,
    /// Certified H2 bound (if any).
    pub nu_bound: Option<f64>,
    /// Worst H-inf norm over all checked plants.
    pub worst_hinf: f64,
    /// Worst H2 norm over all checked plants.
    pub worst_h2: f64,
    /// Smallest region margin over all checked poles (positive = all inside).
    pub worst_region_margin: f64,
    /// Largest real part of any checked pole.
    pub max_real_part: f64,
    /// Largest relative difference between the two H-inf computations.
    pub hinf_methods_rel_diff: f64,
    /// Largest relative difference between the H2 computations.
    pub h2_methods_rel_diff: f64,
    /// Every checked plant is stable.
    pub all_stable: bool,
    /// Every checked pole is inside the region.
    pub poles_in_region: bool,
    /// `worst_hinf <= gamma_bound` (true without a bound).
    pub hinf_within_bound: bool,
    /// `worst_h2 <= nu_bound` (true without a bound).
    pub h2_within_bound: bool,
}

impl VerificationReport {
    /// All checks hold.
    pub fn passed(&self) -> bool {
        self.all_stable && self.poles_in_region && self.hinf_within_bound && self.h2_within_bound
    }
}

/// A small deterministic generator (SplitMix64).
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// Seeded generator.
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn rel_diff(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / a.abs().max(b.abs())
    }
}

/// Checks one plant with the paper's performance output `z = [x; u]`.
pub fn check_point(
    plant: &Vertex,
    bw: &DMatrix<f64>,
    gain: &DMatrix<f64>,
    region: &PoleRegion,
    kind: PointKind,
    opts: &VerifyOptions,
) -> PointCheck {
    check_closed_loop(ClosedLoop::new(plant, bw, gain), plant.mu, region, kind, opts)
}

fn check_closed_loop(
    cl: ClosedLoop,
    mu: [f64; 4],
    region: &PoleRegion,
    kind: PointKind,
    opts: &VerifyOptions,
) -> PointCheck {
    let poles = cl.poles();
    let region_margin = if region.parts.is_empty() {
        -poles.iter().map(|p| p.re).fold(f64::NEG_INFINITY, f64::max)
    } else {
        poles.iter().map(|&p| region.margin(p)).fold(f64::INFINITY, f64::min)
    };
    let inf = f64::INFINITY;
    PointCheck {
        kind,
        mu,
        poles: poles.iter().map(|p| [p.re, p.im]).collect(),
        region_margin,
        hinf: cl.hinf_norm_hamiltonian(opts.bisection_tol).map_or(inf, |b| b.upper),
        hinf_sweep: cl.hinf_norm_frequency_sweep().unwrap_or(inf),
        h2: cl.h2_norm_lyapunov().unwrap_or(inf),
        h2_integrated: cl.h2_norm_gramian_integration().unwrap_or(inf),
        h2_dual: cl.h2_norm_dual_lyapunov().unwrap_or(inf),
    }
}

/// Verifies a gain at the 16 vertices and at `opts.interior_points` random interior
/// points of the friction box, against the region and the certified bounds. The norms are
/// those of `w -> z` with the polytope's own performance output ([`Polytope::c`],
/// [`Polytope::d_u`]).
pub fn verify_design(
    poly: &Polytope,
    region: &PoleRegion,
    gain: &DMatrix<f64>,
    gamma_bound: Option<f64>,
    nu_bound: Option<f64>,
    opts: &VerifyOptions,
) -> VerificationReport {
    let (c, d_u) = (poly.c(), poly.d_u());
    let check = |plant: &Vertex, kind: PointKind| {
        check_closed_loop(ClosedLoop::with_outputs(plant, &poly.bw, gain, &c, &d_u), plant.mu, region, kind, opts)
    };
    let vertices: Vec<PointCheck> = poly.vertices.iter().map(|v| check(v, PointKind::Vertex)).collect();
    let mut rng = SplitMix64::new(opts.seed);
    let (lo, hi) = (poly.spec.mu_min, poly.spec.mu_max);
    let interior: Vec<PointCheck> = (0..opts.interior_points)
        .map(|_| {
            let mut mu = [0.0; 4];
            for m in mu.iter_mut() {
                *m = lo + (hi - lo) * rng.next_f64();
            }
            check(&poly.at(mu), PointKind::Interior)
        })
        .collect();
    let all: Vec<&PointCheck> = vertices.iter().chain(interior.iter()).collect();
    let worst_hinf = all.iter().map(|p| p.hinf).fold(0.0, f64::max);
    let worst_h2 = all.iter().map(|p| p.h2).fold(0.0, f64::max);
    let worst_region_margin = all.iter().map(|p| p.region_margin).fold(f64::INFINITY, f64::min);
    let max_real_part = all.iter().flat_map(|p| p.poles.iter().map(|z| z[0])).fold(f64::NEG_INFINITY, f64::max);
    let hinf_methods_rel_diff = all.iter().map(|p| rel_diff(p.hinf, p.hinf_sweep)).fold(0.0, f64::max);
    let h2_methods_rel_diff =
        all.iter().map(|p| rel_diff(p.h2, p.h2_integrated).max(rel_diff(p.h2, p.h2_dual))).fold(0.0, f64::max);
    let all_stable = max_real_part < 0.0 && worst_hinf.is_finite();
    VerificationReport {
        gamma_bound,
        nu_bound,
        worst_hinf,
        worst_h2,
        worst_region_margin,
        max_real_part,
        hinf_methods_rel_diff,
        h2_methods_rel_diff,
        all_stable,
        poles_in_region: worst_region_margin > 0.0,
        hinf_within_bound: gamma_bound.map_or(true, |g| worst_hinf <= g),
        h2_within_bound: nu_bound.map_or(true, |nu| worst_h2 <= nu),
        vertices,
        interior,
    }
}

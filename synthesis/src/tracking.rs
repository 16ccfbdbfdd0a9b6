//! The robust tracking design: mixed H2/H-inf state feedback with D-stability on
//! the tracking error model, over the same 16-vertex friction polytope as the paper's design.
//!
//! # Model
//!
//! States `e = [e_y, e_psi, beta - beta_ref, r - r_ref]` (m, rad, rad, rad/s), inputs the
//! steering corrections `u = delta - delta_ff` (rad, FL, FR, RL, RR), disturbance the lateral
//! force `w` (N) at the geometric centre (the wind, `F_sw`), see [`nigel_vehicle::tracking`]
//! for the definitions, the derivation and the linearization
//! `e' = A_t(mu) e + B_t(mu) u + d_t w`, checked against the dual-number Jacobian of the
//! nonlinear model (`vehicle/tests/tracking.rs`). The design model is [`TrackingSpec`]:
//! Table II, the physical disturbance column `d = [1/(m v), x_c/I_z]`, `v = 0.35 m/s`,
//! `mu_i in [0.1, 1.0]`.
//!
//! # Performance outputs (weights)
//!
//! `z = [q_y e_y; q_psi e_psi; r_u u]` for both the H-inf and the H2 channel `w -> z`, with
//! Bryson-style weights ([`TrackingWeights`](crate::TrackingWeights)): each is the reciprocal of the size that is
//! "as bad as" the others. [`TrackingWeights::chosen`](crate::TrackingWeights::chosen): 2 cm lateral, 0.1 rad heading,
//! 0.1 rad steering correction (`q_y = 50 /m`, `q_psi = 10 /rad`, `r_u = 10 /rad`).
//!
//! They come from the study `cargo run --release -p nigel-synthesis --example
//! tracking_study` (lateral allowances 10, 5, 2 and 1 cm times steering allowances 0.1, 0.25
//! and 0.5 rad, heading 0.1 rad; each the full Pareto design on the region below, verified),
//! judged on the linear model, worst of the 16 vertices, by: the steady lateral offset under
//! a 0.25 N wind step (the benchmark's wind), and the steering correction and steering
//! *rate* asked for when recovering from a 2 cm lateral offset (the size of the errors the
//! maneuvers leave), which must stay below the servo's 5.51 rad/s rate limit so that the
//! servo follows the command instead of saturating. Measured (worst vertex):
//!
//! | allowances e_y / u | wind offset | 2 cm recovery: u, rate | slowest pole | with servo |
//! |---|---|---|---|---|
//! | 10 cm / 0.1 rad | 17.4 mm | 0.03 rad, 0.6 rad/s | -0.59 | -0.59 |
//! | 10 cm / 0.5 rad | 6.6 mm | 0.11 rad, 4.4 rad/s | -1.21 | -1.24 |
//! | 5 cm / 0.1 rad | 12.5 mm | 0.05 rad, 1.0 rad/s | -0.79 | -0.80 |
//! | 5 cm / 0.25 rad | 6.4 mm | 0.11 rad, 3.8 rad/s | -1.34 | -1.37 |
//! | 5 cm / 0.5 rad | 3.8 mm | 0.19 rad, 9.4 rad/s | -1.94 | -2.02 |
//! | **2 cm / 0.1 rad** | **6.5 mm** | **0.11 rad, 3.3 rad/s** | **-1.54** | **-1.55** |
//! | 2 cm / 0.25 rad | 3.1 mm | 0.24 rad, 11.8 rad/s | -2.51 | -2.58 |
//! | 1 cm / 0.1 rad | 3.8 mm | 0.20 rad, 8.6 rad/s | -2.59 | -2.60 |
//! | 1 cm / 0.5 rad | 0.9 mm | 0.72 rad, 79 rad/s | -5.40 | -5.73 |
//!
//! Every design that reduces the wind offset below about 6.4 mm asks for more than the
//! rate limit; of the three at 6.4 to 6.6 mm that stay below it, the chosen one asks the
//! lowest rate (3.3 rad/s) and has the fastest slowest pole. It is not tuned to a seed:
//! neither the study nor the choice uses the maneuvers, friction or noise realisations.
//! Every design of the study was verified (poles, H-inf, H2 within their bounds).
//!
//! On the benchmark maneuvers of `docs/benchmark.md` (implemented once, in
//! `nigel-benchmark`, where the controller also gets the along-track speed correction) the
//! gain is the controller FMU's `robust_tracking` mode; Table III's fourth column and the
//! seed study (`table3 --seeds 0..9`) give, over seeds 0..9 and both columns, epsilon
//! 0.014 to 0.32 times the paper's robust controller's, the lowest of the four controllers
//! in every row and seed, with steering at most 0.63 rad.
//!
//! # Pole region, and why it is not faster than the servo
//!
//! [`tracking_region`]: `Re(s) < -0.5` (every tracking error decays at least with a 2 s
//! time constant at every friction vertex, versus the paper's `-0.1`) and the paper's
//! 135-degree sector (damping ratio at least `cos(67.5 deg) = 0.38`). No disk: the tire
//! modes of the open loop are themselves at up to ~96 rad/s on high friction, and a disk
//! that pulled them inside the servo bandwidth would need gain to *slow* the car's own
//! dynamics. What must stay below the servo's bandwidth (`1/T_s = 33 rad/s`) is what the
//! feedback adds: the tracking poles the controller creates (slowest at -1.54 rad/s, the
//! tracking pair a few rad/s, more than ten times slower than the servo's corner) and the
//! loop's gain at that corner, which the steering weight bounds. The check is explicit:
//! [`servo_loop_max_real_part`] inserts the first-order servo into the loop at every vertex
//! (the slowest pole moves from -1.540 to -1.546 rad/s), and the steering rate the
//! benchmark's 0.25 N wind step asks for is 0.08 rad/s, 70 times below the servo's rate
//! limit.
//!
//! # Sign conventions (for the controller)
//!
//! `K_track` is 4x4, rows FL, FR, RL, RR (the wheel order of the plant), columns
//! `[e_y, e_psi, beta - beta_ref, r - r_ref]`, and the steering command is
//! `delta = delta_ff + K_track e`, where `delta_ff` is the reference car's steering, the
//! errors are [`nigel_vehicle::tracking_errors`] of the measured car relative to the
//! reference car (`e_y > 0`: the car is left of the reference, `e_psi > 0`: turned
//! counter-clockwise of it), and every angle is positive counter-clockwise (steering left).

use nalgebra::DMatrix;
use serde::Serialize;

use crate::design::{pareto_sweep, ParetoSweep, SweepOptions, SweepProgress, SynthesisError, SynthesisOptions};
use crate::plant::{Polytope, TrackingSpec, Vertex};
use crate::region::{PoleRegion, Region};
use crate::verify::{verify_design, VerificationReport, VerifyOptions};

/// The tracking design's pole region: `Re(s) < -0.5` and the 135-degree sector.
pub fn tracking_region() -> PoleRegion {
    PoleRegion { parts: vec![Region::half_plane(-0.5), Region::sector_inner_angle_deg(135.0)] }
}

/// The Pareto grid of the tracking design, relative to its `gamma*` (the weighted outputs
/// have no natural absolute scale, so the paper's absolute step of 0.01 would mean nothing):
/// `gamma* (1 + 1e-5)`, then `gamma* (1 + 0.05 k)` up to `3 gamma*` (41 points).
pub fn tracking_sweep_options(gamma_star: f64, threads: usize) -> SweepOptions {
    SweepOptions { step: 0.05 * gamma_star, g_max: 3.0 * gamma_star * (1.0 + 1e-9), boundary_factor: 1e-5, threads }
}

/// The tracking gain with what was certified and what was verified.
#[derive(Clone, Debug)]
pub struct TrackingDesign {
    /// The design model it was made for.
    pub spec: TrackingSpec,
    /// The pole region imposed.
    pub region: PoleRegion,
    /// The Pareto sweep (`gamma*`, the grid, the chosen point).
    pub sweep: ParetoSweep,
    /// `K_track`: rows FL, FR, RL, RR (zero rows for unsteered wheels), columns
    /// `[e_y, e_psi, beta - beta_ref, r - r_ref]`; `delta = delta_ff + K_track e`.
    pub k_track: [[f64; 4]; 4],
    /// Certified bound on the induced L2 gain `w -> z` over the polytope.
    pub gamma: f64,
    /// Certified bound on the H2 norm `w -> z` over the polytope.
    pub nu: f64,
    /// The independent verification (poles, H-inf two ways, H2 three ways).
    pub verification: VerificationReport,
}

/// The full 4x4 gain (zero rows for unsteered wheels) from the designed `n_inputs x 4` one.
pub fn full_tracking_gain(spec: &TrackingSpec, gain: &DMatrix<f64>) -> [[f64; 4]; 4] {
    let mut k = [[0.0; 4]; 4];
    for (row, &wheel) in spec.plant.architecture.steered_wheels().iter().enumerate() {
        for (col, v) in k[wheel].iter_mut().enumerate() {
            *v = gain[(row, col)];
        }
    }
    k
}

/// Runs the tracking design: `gamma*`, the Pareto sweep on [`tracking_sweep_options`], the
/// nearest point to the origin, and the verification of its gain.
pub fn design_tracking(
    spec: &TrackingSpec,
    region: &PoleRegion,
    options: &SynthesisOptions,
    verify: &VerifyOptions,
    threads: usize,
    progress: Option<&(dyn Fn(SweepProgress) + Sync)>,
) -> Result<TrackingDesign, SynthesisError> {
    let poly = spec.polytope()?;
    let gamma_star = crate::design::min_hinf(&poly, region, options)?
        .gamma
        .ok_or_else(|| SynthesisError::Invalid("internal: no gamma*".into()))?;
    let sweep = pareto_sweep(&poly, region, &tracking_sweep_options(gamma_star, threads), options, progress)?;
    let chosen =
        sweep.chosen_design().cloned().ok_or_else(|| SynthesisError::Invalid("chosen point has no design".into()))?;
    let gamma = sweep.chosen_point().g;
    let nu = chosen.nu.ok_or_else(|| SynthesisError::Invalid("internal: no nu".into()))?;
    let verification = verify_design(&poly, region, &chosen.gain, Some(gamma), Some(nu), verify);
    Ok(TrackingDesign {
        spec: *spec,
        region: region.clone(),
        k_track: full_tracking_gain(spec, &chosen.gain),
        gamma,
        nu,
        verification,
        sweep,
    })
}

/// The linear closed loop `[e; delta_applied]` with a first-order steering servo of time
/// constant `t_s` between the command `K e` and the plant:
/// `e' = A e + B delta_a`, `delta_a' = (K e - delta_a) / t_s`.
pub fn servo_closed_loop(plant: &Vertex, gain: &DMatrix<f64>, t_s: f64) -> DMatrix<f64> {
    let (n, m) = (plant.a.nrows(), plant.b.ncols());
    let mut a = DMatrix::zeros(n + m, n + m);
    a.view_mut((0, 0), (n, n)).copy_from(&plant.a);
    a.view_mut((0, n), (n, m)).copy_from(&plant.b);
    a.view_mut((n, 0), (m, n)).copy_from(&(gain / t_s));
    a.view_mut((n, n), (m, m)).fill_with_identity();
    let mut lower = a.view_mut((n, n), (m, m));
    lower /= -t_s;
    a
}

/// Largest real part of the closed-loop poles with the servo inserted, over the vertices.
pub fn servo_loop_max_real_part(poly: &Polytope, gain: &DMatrix<f64>, t_s: f64) -> f64 {
    poly.vertices
        .iter()
        .flat_map(|v| servo_closed_loop(v, gain, t_s).complex_eigenvalues().iter().map(|z| z.re).collect::<Vec<_>>())
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Peaks of a linear closed-loop response (state feedback `u = K e`, no servo).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ResponsePeaks {
    /// Largest `|e_y|` \[m\].
    pub lateral_peak: f64,
    /// `e_y` at the end of the run \[m\].
    pub lateral_final: f64,
    /// Largest `|e_psi|` \[rad\].
    pub heading_peak: f64,
    /// Largest steering correction `|u_i|` \[rad\].
    pub steering_peak: f64,
    /// Largest steering rate `|du_i/dt|` [rad/s].
    pub steering_rate_peak: f64,
}

/// Simulates `e' = (A + B K) e + d w` from `e0` with constant `w` for `duration` seconds
/// (exact discretisation with step `dt`, the matrix exponential) and returns the peaks.
pub fn linear_response(
    plant: &Vertex,
    bw: &DMatrix<f64>,
    gain: &DMatrix<f64>,
    e0: &[f64],
    w: f64,
    duration: f64,
    dt: f64,
) -> ResponsePeaks {
    let n = plant.a.nrows();
    let acl = &plant.a + &plant.b * gain;
    // Van Loan: exp([[A, b], [0, 0]] dt) = [[Phi, Gamma], [0, 1]]
    let mut big = DMatrix::zeros(n + 1, n + 1);
    big.view_mut((0, 0), (n, n)).copy_from(&(&acl * dt));
    big.view_mut((0, n), (n, 1)).copy_from(&(bw * (w * dt)));
    let e = big.exp();
    let phi = e.view((0, 0), (n, n)).into_owned();
    let gamma = e.view((0, n), (n, 1)).into_owned();
    let mut x = DMatrix::from_column_slice(n, 1, e0);
    let mut peaks = ResponsePeaks {
        lateral_peak: 0.0,
        lateral_final: 0.0,
        heading_peak: 0.0,
        steering_peak: 0.0,
        steering_rate_peak: 0.0,
    };
    let steps = (duration / dt).round() as usize;
    for _ in 0..=steps {
        let u = gain * &x;
        let xdot = &acl * &x + bw * w;
        let udot = gain * xdot;
        peaks.lateral_peak = peaks.lateral_peak.max(x[0].abs());
        peaks.heading_peak = peaks.heading_peak.max(x[1].abs());
        peaks.steering_peak = peaks.steering_peak.max(u.amax());
        peaks.steering_rate_peak = peaks.steering_rate_peak.max(udot.amax());
        peaks.lateral_final = x[0];
        x = &phi * &x + &gamma;
    }
    peaks
}

/// The worst peaks over the vertices after a step of lateral force `force` \[N\] from zero
/// error, over `duration` seconds (the last value is the slowest vertex's offset).
pub fn wind_step(poly: &Polytope, gain: &DMatrix<f64>, force: f64, duration: f64) -> ResponsePeaks {
    worst(poly.vertices.iter().map(|v| linear_response(v, &poly.bw, gain, &[0.0; 4], force, duration, 1e-3)))
}

/// The worst peaks over the vertices while recovering from a lateral offset `offset` \[m\]
/// (no wind), over `duration` seconds.
pub fn offset_recovery(poly: &Polytope, gain: &DMatrix<f64>, offset: f64, duration: f64) -> ResponsePeaks {
    worst(
        poly.vertices.iter().map(|v| linear_response(v, &poly.bw, gain, &[offset, 0.0, 0.0, 0.0], 0.0, duration, 1e-3)),
    )
}

fn worst(it: impl Iterator<Item = ResponsePeaks>) -> ResponsePeaks {
    it.fold(
        ResponsePeaks {
            lateral_peak: 0.0,
            lateral_final: 0.0,
            heading_peak: 0.0,
            steering_peak: 0.0,
            steering_rate_peak: 0.0,
        },
        |a, b| ResponsePeaks {
            lateral_peak: a.lateral_peak.max(b.lateral_peak),
            lateral_final: if b.lateral_final.abs() > a.lateral_final.abs() {
                b.lateral_final
            } else {
                a.lateral_final
            },
            heading_peak: a.heading_peak.max(b.heading_peak),
            steering_peak: a.steering_peak.max(b.steering_peak),
            steering_rate_peak: a.steering_rate_peak.max(b.steering_rate_peak),
        },
    )
}

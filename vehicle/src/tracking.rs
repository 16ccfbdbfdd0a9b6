//! The path-tracking error model: the car's errors relative to a *reference car*
//! that drives the reference path, and their small-error linearization.
//!
//! # Definitions (nonlinear, exact)
//!
//! The reference car runs the same nonlinear model ([`crate::evaluate`]) at the nominal
//! friction with the feed-forward steering `delta_ff`; its pose is `(X_ref, Y_ref, psi_ref)`.
//! The errors of the car `(X, Y, psi, v_x, v_y, r)` are taken in the reference car's body
//! frame (x forward, y left, `psi` counter-clockwise), all SI / rad:
//!
//! ```text
//! e_x   =  cos(psi_ref) (X - X_ref) + sin(psi_ref) (Y - Y_ref)   along-track error [m], + = ahead
//! e_y   = -sin(psi_ref) (X - X_ref) + cos(psi_ref) (Y - Y_ref)   lateral error [m],     + = car left of the reference
//! e_psi =  psi - psi_ref   (wrapped to (-pi, pi])                heading error [rad],   + = car turned counter-clockwise
//! e_beta = beta - beta_ref,  beta = atan2(v_y, v_x)              sideslip error [rad]
//! e_r    = r - r_ref                                             yaw-rate error [rad/s]
//! ```
//!
//! The feedback state is `e = [e_y, e_psi, e_beta, e_r]` ([`TRACKING_STATE_NAMES`]); `e_x`
//! is left to a speed correction (it does not enter the lateral dynamics to first order).
//!
//! # Error dynamics
//!
//! Differentiating the definitions along both cars' motions (with `(Xd, Yd)` the world
//! velocities of the cars):
//!
//! ```text
//! de_y/dt   = -r_ref e_x + [-sin(psi_ref) (Xd - Xd_ref) + cos(psi_ref) (Yd - Yd_ref)]
//! de_psi/dt = r - r_ref
//! de_beta/dt = beta_dot - beta_dot_ref,   beta_dot = (v_x dv_y/dt - v_y dv_x/dt) / (v_x^2 + v_y^2)
//! de_r/dt   = dr/dt - dr_ref/dt
//! ```
//!
//! ([`tracking_error_rates`] evaluates exactly this, generic over [`Scalar`], so that its
//! Jacobian can be taken with dual numbers.) The bracket in `de_y/dt` is the car's world
//! velocity minus the reference's, projected on the reference's lateral axis:
//! `v sin(e_psi + beta) - v_ref sin(beta_ref)` when both run at speed `v`.
//!
//! # Linearization (small errors around straight running)
//!
//! Around the reference car running straight at speed `v` (`beta_ref = r_ref = 0`,
//! `delta_ff = 0`), with `e_x = 0` and the car at the same speed, to first order in `e`,
//! in the steering correction `u = delta - delta_ff` (FL, FR, RL, RR) and in a lateral
//! force `w` \[N\] along the reference's left axis at the geometric centre:
//!
//! ```text
//! de_y/dt   = v (e_psi + e_beta)
//! de_psi/dt = e_r
//! [de_beta/dt; de_r/dt] = A(mu) [e_beta; e_r] + B(mu) u + d w        (Eq. 2.2 of the paper)
//! ```
//!
//! i.e. `e' = A_t(mu) e + B_t(mu) u + d_t w` with
//!
//! ```text
//!       [ 0  v  v    0   ]         [   0    ]         [ 0  ]
//! A_t = [ 0  0  0    1   ]   B_t = [   0    ]   d_t = [ 0  ]
//!       [ 0  0  a11  a12 ]         [ B(mu)  ]         [ d1 ]
//!       [ 0  0  a21  a22 ]                            [ d2 ]
//! ```
//!
//! `A(mu)`, `B(mu)` and `d` are those of [`crate::linear_model`]: affine in the car's four
//! friction coefficients, so the tracking model is too, and the 16-vertex friction polytope
//! carries over unchanged. The reference car's nominal friction drops out at this operating
//! point (its state and steering are zero there); along a curved reference
//! `(A(mu) - A(mu_nom)) x_ref + (B(mu) - B(mu_nom)) delta_ff` is the mismatch the robust
//! design must absorb, like the wind.
//!
//! # Sign conventions for the controller
//!
//! With `K_track` (4x4, rows FL, FR, RL, RR, columns `[e_y, e_psi, e_beta, e_r]`) from the
//! synthesis (`u = K_track e`), the steering command is
//! `delta = delta_ff + K_track e`, with `e` computed by [`tracking_errors`] from the measured
//! car and the reference car, each `delta_i` positive counter-clockwise (to the left) as in
//! the plant. E.g. a car left of its reference (`e_y > 0`) is steered back to the right: the
//! synthesized `K_track` has a negative `e_y` column on the front wheels (checked on the
//! nonlinear car in `synthesis/tests/tracking.rs`).

use crate::dynamics::{evaluate, idx, Inputs, State};
use crate::linear::{linear_model, DisturbanceColumn};
use crate::params::VehicleParams;
use crate::scalar::Scalar;
use nalgebra::{Matrix4, Vector4};

/// Number of feedback states of the tracking model.
pub const N_TRACKING_STATES: usize = 4;

/// Names of the tracking states, in order (the columns of `K_track`).
pub const TRACKING_STATE_NAMES: [&str; N_TRACKING_STATES] = ["e_y", "e_psi", "beta - beta_ref", "r - r_ref"];

/// The errors of a car relative to its reference car (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackingErrors<T> {
    /// Along-track error `e_x` \[m\] (positive: the car is ahead of the reference).
    pub along: T,
    /// Lateral error `e_y` \[m\] (positive: the car is left of the reference).
    pub lateral: T,
    /// Heading error `e_psi = psi - psi_ref` \[rad\], wrapped to `(-pi, pi]`.
    pub heading: T,
    /// Sideslip error `beta - beta_ref` \[rad\].
    pub sideslip: T,
    /// Yaw-rate error `r - r_ref` [rad/s].
    pub yaw_rate: T,
}

impl<T: Copy> TrackingErrors<T> {
    /// The feedback state `[e_y, e_psi, beta - beta_ref, r - r_ref]`.
    pub fn feedback(&self) -> [T; N_TRACKING_STATES] {
        [self.lateral, self.heading, self.sideslip, self.yaw_rate]
    }
}

/// `a - b` wrapped to `(-pi, pi]` (the branch is chosen on the value; the derivative is 1).
fn angle_difference<T: Scalar>(a: T, b: T) -> T {
    let d = a - b;
    let turns = (d.value() / core::f64::consts::TAU).round();
    let w = d - turns * core::f64::consts::TAU;
    if w.value() <= -core::f64::consts::PI {
        w + core::f64::consts::TAU
    } else {
        w
    }
}

/// The pose errors `(e_x, e_y, e_psi)` of a car at `(x, y, psi)` relative to a reference
/// pose `(x_ref, y_ref, psi_ref)` (world frame, headings unwrapped or not): along-track and
/// lateral error in the reference's frame, heading error wrapped to `(-pi, pi]` (see the
/// module documentation). What the sampled controller computes from its pose inputs.
pub fn pose_errors<T: Scalar>(x: T, y: T, psi: T, x_ref: T, y_ref: T, psi_ref: T) -> (T, T, T) {
    let (sr, cr) = (psi_ref.sin(), psi_ref.cos());
    let (dx, dy) = (x - x_ref, y - y_ref);
    (cr * dx + sr * dy, cr * dy - sr * dx, angle_difference(psi, psi_ref))
}

/// The errors of `car` relative to `reference` (plant state vectors, [`crate::State`]).
pub fn tracking_errors<T: Scalar>(car: &State<T>, reference: &State<T>) -> TrackingErrors<T> {
    let (along, lateral, heading) =
        pose_errors(car[idx::X], car[idx::Y], car[idx::PSI], reference[idx::X], reference[idx::Y], reference[idx::PSI]);
    let beta = car[idx::V_Y].atan2(car[idx::V_X]);
    let beta_ref = reference[idx::V_Y].atan2(reference[idx::V_X]);
    TrackingErrors {
        along,
        lateral,
        heading,
        sideslip: beta - beta_ref,
        yaw_rate: car[idx::YAW_RATE] - reference[idx::YAW_RATE],
    }
}

/// Exact time derivatives of the feedback errors `[e_y, e_psi, e_beta, e_r]` when the car
/// (inputs `car_inputs`) and the reference car (`reference_inputs`, typically the nominal
/// friction and the feed-forward steering) both run the nonlinear model with parameters `p`.
pub fn tracking_error_rates<T: Scalar>(
    p: &VehicleParams,
    car: &State<T>,
    car_inputs: &Inputs<T>,
    reference: &State<T>,
    reference_inputs: &Inputs<T>,
) -> [T; N_TRACKING_STATES] {
    let f = evaluate(p, car, car_inputs).derivatives;
    let f_ref = evaluate(p, reference, reference_inputs).derivatives;
    let e = tracking_errors(car, reference);
    let (sr, cr) = (reference[idx::PSI].sin(), reference[idx::PSI].cos());
    let r_ref = reference[idx::YAW_RATE];
    let lateral_rate = cr * (f[idx::Y] - f_ref[idx::Y]) - sr * (f[idx::X] - f_ref[idx::X]) - r_ref * e.along;
    let beta_rate = |s: &State<T>, d: &State<T>| {
        let (vx, vy) = (s[idx::V_X], s[idx::V_Y]);
        (vx * d[idx::V_Y] - vy * d[idx::V_X]) / (vx * vx + vy * vy)
    };
    [
        lateral_rate,
        car[idx::YAW_RATE] - r_ref,
        beta_rate(car, &f) - beta_rate(reference, &f_ref),
        f[idx::YAW_RATE] - f_ref[idx::YAW_RATE],
    ]
}

/// `e' = A e + B u + d w` for `e = [e_y, e_psi, e_beta, e_r]`, `u` the steering correction
/// (FL, FR, RL, RR), `w` the lateral force \[N\] at the geometric centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackingModel {
    /// `A_t(mu)`, 4x4.
    pub a: Matrix4<f64>,
    /// `B_t(mu)`, 4x4 (columns FL, FR, RL, RR).
    pub b: Matrix4<f64>,
    /// `d_t`, with the chosen disturbance column in the last two rows.
    pub d: Vector4<f64>,
}

/// The linearized tracking model at speed `v` and car friction `mu` (FL, FR, RL, RR),
/// see the module documentation. Affine in `mu`.
pub fn tracking_model(p: &VehicleParams, mu: [f64; 4], v: f64, column: DisturbanceColumn) -> TrackingModel {
    let lm = linear_model(p, mu, v);
    let mut a = Matrix4::zeros();
    a[(0, 1)] = v;
    a[(0, 2)] = v;
    a[(1, 3)] = 1.0;
    a.fixed_view_mut::<2, 2>(2, 2).copy_from(&lm.a);
    let mut b = Matrix4::zeros();
    b.fixed_view_mut::<2, 4>(2, 0).copy_from(&lm.b);
    let dc = lm.disturbance(column);
    TrackingModel { a, b, d: Vector4::new(0.0, 0.0, dc[0], dc[1]) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_of_a_displaced_car_in_the_reference_frame() {
        // reference heading 30 deg at (1, 2); the car 0.1 m to its left, 0.2 m ahead, turned 0.05 rad
        let psi_ref: f64 = 30f64.to_radians();
        let mut reference = crate::straight_running(0.35);
        reference[idx::X] = 1.0;
        reference[idx::Y] = 2.0;
        reference[idx::PSI] = psi_ref;
        let mut car = reference;
        car[idx::X] += 0.2 * psi_ref.cos() - 0.1 * psi_ref.sin();
        car[idx::Y] += 0.2 * psi_ref.sin() + 0.1 * psi_ref.cos();
        car[idx::PSI] += 0.05;
        let e = tracking_errors(&car, &reference);
        assert!((e.along - 0.2).abs() < 1e-15 && (e.lateral - 0.1).abs() < 1e-15, "{e:?}");
        assert!((e.heading - 0.05).abs() < 1e-15);
        // headings a full turn apart are no error; pi - 0.1 and -(pi - 0.1) are 0.2 apart
        car[idx::PSI] = psi_ref + core::f64::consts::TAU;
        assert!(tracking_errors(&car, &reference).heading.abs() < 1e-15);
        car[idx::PSI] = core::f64::consts::PI - 0.1;
        reference[idx::PSI] = -(core::f64::consts::PI - 0.1);
        assert!((tracking_errors(&car, &reference).heading + 0.2).abs() < 1e-12);
    }
}

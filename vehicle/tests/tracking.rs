//! The tracking error model's closed-form linearization against the Jacobian of the
//! nonlinear model (two cars, forward-mode dual numbers, no finite differences).

#![allow(clippy::needless_range_loop)] // matrix index loops mirror the equations

use nigel_vehicle::dynamics::idx;
use nigel_vehicle::{
    tracking_error_rates, tracking_errors, tracking_model, DisturbanceColumn, Dual, Inputs, Scalar, State,
    VehicleParams, N_STATES,
};

/// One operating point: the reference car runs straight at speed `v` with heading
/// `psi_ref` through `(x_ref, y_ref)` on the nominal friction; the car has friction `mu`.
struct OperatingPoint {
    mu: [f64; 4],
    v: f64,
    psi_ref: f64,
    x_ref: f64,
    y_ref: f64,
}

const MU_NOMINAL: f64 = 0.4;

/// The Jacobian of the exact error rates with respect to the errors `e` (4 directions),
/// the steering correction `u` (4) and the lateral force `w` (1), at `e = 0, u = 0, w = 0`.
///
/// The car is placed from the errors by inverting their definition independently of the
/// library: `X = X_ref - sin(psi_ref) e_y`, `Y = Y_ref + cos(psi_ref) e_y`,
/// `psi = psi_ref + e_psi`, velocity `v` at sideslip `e_beta` (the reference's is 0),
/// `r = e_r`. The force `w` acts along the reference's left axis, i.e. world wind
/// `(wind_x, wind_y) = w (-sin psi_ref, cos psi_ref)`.
fn jacobian(p: &VehicleParams, op: &OperatingPoint) -> ([[f64; 4]; 4], [[f64; 4]; 4], [f64; 4]) {
    let column = |dir: usize| -> [f64; 4] {
        let seed = |k: usize| Dual::new(0.0, if k == dir { 1.0 } else { 0.0 });
        let (e_y, e_psi, e_beta, e_r) = (seed(0), seed(1), seed(2), seed(3));
        let w = seed(8);
        let (sr, cr) = op.psi_ref.sin_cos();
        let mut reference: State<Dual> = [Dual::constant(0.0); N_STATES];
        reference[idx::X] = Dual::constant(op.x_ref);
        reference[idx::Y] = Dual::constant(op.y_ref);
        reference[idx::PSI] = Dual::constant(op.psi_ref);
        reference[idx::V_X] = Dual::constant(op.v);
        let mut car: State<Dual> = [Dual::constant(0.0); N_STATES];
        car[idx::X] = e_y * (-sr) + op.x_ref;
        car[idx::Y] = e_y * cr + op.y_ref;
        car[idx::PSI] = e_psi + op.psi_ref;
        car[idx::V_X] = e_beta.cos() * op.v;
        car[idx::V_Y] = e_beta.sin() * op.v;
        car[idx::YAW_RATE] = e_r;
        let reference_inputs = Inputs::<Dual>::coasting(MU_NOMINAL);
        let mut car_inputs = Inputs::<Dual>::coasting(0.0);
        for i in 0..4 {
            car_inputs.mu[i] = Dual::constant(op.mu[i]);
            car_inputs.delta[i] = seed(4 + i);
        }
        car_inputs.wind_x = w * (-sr);
        car_inputs.wind_y = w * cr;
        let rates = tracking_error_rates(p, &car, &car_inputs, &reference, &reference_inputs);
        rates.map(|r| r.d)
    };
    let mut a = [[0.0; 4]; 4];
    let mut b = [[0.0; 4]; 4];
    for j in 0..4 {
        let ca = column(j);
        let cb = column(4 + j);
        for i in 0..4 {
            a[i][j] = ca[i];
            b[i][j] = cb[i];
        }
    }
    (a, b, column(8))
}

/// Entries agree to `1e-6` relative; an entry the closed form says is exactly zero must be
/// zero to `1e-12` absolute (rounding in the rotation by `psi_ref`).
fn assert_close(what: &str, got: f64, want: f64) {
    let ok = if want == 0.0 { got.abs() < 1e-12 } else { (got - want).abs() <= 1e-6 * want.abs() };
    assert!(ok, "{what}: Jacobian {got:e} vs closed form {want:e}");
}

#[test]
fn tracking_linearization_equals_the_jacobian_of_the_nonlinear_model() {
    let p = VehicleParams::table2();
    let points = [
        OperatingPoint { mu: [0.4; 4], v: 0.35, psi_ref: 0.0, x_ref: 0.0, y_ref: 0.0 },
        OperatingPoint { mu: [1.0, 0.7, 0.3, 0.55], v: 0.5, psi_ref: 0.7, x_ref: 1.2, y_ref: -0.4 },
        OperatingPoint { mu: [0.1, 0.9, 0.6, 0.15], v: 1.3, psi_ref: -2.5, x_ref: -3.0, y_ref: 2.0 },
    ];
    for op in &points {
        let (a, b, d) = jacobian(&p, op);
        let lin = tracking_model(&p, op.mu, op.v, DisturbanceColumn::Physical);
        let at = format!("mu {:?}, v {}, psi_ref {}", op.mu, op.v, op.psi_ref);
        for i in 0..4 {
            for j in 0..4 {
                assert_close(&format!("{at}: A[{i}{j}]"), a[i][j], lin.a[(i, j)]);
                assert_close(&format!("{at}: B[{i}{j}]"), b[i][j], lin.b[(i, j)]);
            }
            assert_close(&format!("{at}: d[{i}]"), d[i], lin.d[i]);
        }
        // the structure the issue states: de_y/dt = v (e_psi + e_beta), de_psi/dt = e_r
        assert_close(&format!("{at}: de_y/de_psi = v"), a[0][1], op.v);
        assert_close(&format!("{at}: de_y/de_beta = v"), a[0][2], op.v);
        assert_close(&format!("{at}: de_psi/de_r = 1"), a[1][3], 1.0);
    }
}

#[test]
fn the_error_rates_vanish_when_the_car_is_the_reference() {
    // the same car on the same road as the reference, turning: every error rate is zero
    let p = VehicleParams::table2();
    let mut s = nigel_vehicle::straight_running(0.35);
    s[idx::PSI] = 0.4;
    s[idx::V_Y] = 0.02;
    s[idx::YAW_RATE] = 0.3;
    let mut u = Inputs::coasting(0.6);
    u.delta = [0.2, 0.2, -0.1, -0.1];
    let rates = tracking_error_rates(&p, &s, &u, &s, &u);
    assert_eq!(rates, [0.0; 4]);
    let e = tracking_errors(&s, &s);
    assert_eq!(e.feedback(), [0.0; 4]);
}

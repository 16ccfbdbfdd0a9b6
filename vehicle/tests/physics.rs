//! Physics checks against independent derivations: Eq. 2.2 of the paper, the linear
//! steady state, and straight running.

#![allow(clippy::needless_range_loop)] // per-wheel and matrix index loops mirror the equations

use nalgebra::{Matrix2, Vector2, Vector4};
use nigel_vehicle::dynamics::idx;
use nigel_vehicle::{evaluate, integrate, linear_model, Dual, Inputs, Scalar, State, VehicleParams, N_STATES};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-12)
}

/// Jacobian of `[beta_dot, r_dot]` w.r.t. `x = [beta, r]`, `u = delta`, `w = F_sw` at straight
/// running, by forward-mode AD of the nonlinear model (no finite differences).
fn nonlinear_jacobian(p: &VehicleParams, mu: [f64; 4], v: f64) -> (Matrix2<f64>, [[f64; 4]; 2], [f64; 2]) {
    // direction: 0 = beta, 1 = r, 2..6 = delta_i, 6 = F_sw
    let column = |dir: usize| -> [f64; 2] {
        let seed = |k: usize| if k == dir { 1.0 } else { 0.0 };
        let beta = Dual::new(0.0, seed(0));
        let mut s: State<Dual> = [Dual::constant(0.0); N_STATES];
        s[idx::V_X] = beta.cos() * v;
        s[idx::V_Y] = beta.sin() * v;
        s[idx::YAW_RATE] = Dual::new(0.0, seed(1));
        let mut u = Inputs::<Dual>::coasting(0.0);
        for i in 0..4 {
            u.mu[i] = Dual::constant(mu[i]);
            u.delta[i] = Dual::new(0.0, seed(2 + i));
        }
        u.wind_side = Dual::new(0.0, seed(6));
        let e = evaluate(p, &s, &u);
        let (vx, vy) = (s[idx::V_X], s[idx::V_Y]);
        let (dvx, dvy) = (e.derivatives[idx::V_X], e.derivatives[idx::V_Y]);
        let beta_dot = (vx * dvy - vy * dvx) / (vx * vx + vy * vy);
        [beta_dot.d, e.derivatives[idx::YAW_RATE].d]
    };
    let c0 = column(0);
    let c1 = column(1);
    let a = Matrix2::new(c0[0], c1[0], c0[1], c1[1]);
    let mut b = [[0.0; 4]; 2];
    for i in 0..4 {
        let c = column(2 + i);
        b[0][i] = c[0];
        b[1][i] = c[1];
    }
    (a, b, column(6))
}

#[test]
fn closed_form_matches_the_numbers_in_the_spec() {
    // docs/vehicle-model.md: mu = 0.4, v = 0.35
    let lm = linear_model(&VehicleParams::table2(), [0.4; 4], 0.35);
    let expected_a = [[-38.3400, -0.06724], [15.7523, -26.8591]];
    for r in 0..2 {
        for c in 0..2 {
            assert!(rel(lm.a[(r, c)], expected_a[r][c]) < 2e-4, "A[{r}{c}] = {}", lm.a[(r, c)]);
        }
    }
    for (i, e) in [28.794, 28.794, -36.670, -36.670].into_iter().enumerate() {
        assert!(rel(lm.b[(1, i)], e) < 1e-4, "B[1{i}] = {}", lm.b[(1, i)]);
    }
    assert!(rel(lm.d_physical[0], 1.0661) < 1e-4);
    assert!(rel(lm.d_physical[1], -0.43801) < 1e-4);
    // the printed (paper) d2 is the moment arm alone
    assert!(rel(lm.d_paper[1], (0.06226 - 0.07929) / 2.0) < 1e-12);
}

#[test]
fn jacobian_at_straight_running_equals_eq_2_2() {
    let p = VehicleParams::table2();
    let points: [([f64; 4], f64); 4] =
        [([0.4; 4], 0.35), ([0.1; 4], 0.2), ([1.0, 0.7, 0.3, 0.55], 0.5), ([0.25, 0.9, 0.6, 0.15], 1.3)];
    for (mu, v) in points {
        let lm = linear_model(&p, mu, v);
        let (a, b, d) = nonlinear_jacobian(&p, mu, v);
        for r in 0..2 {
            for c in 0..2 {
                assert!(
                    rel(a[(r, c)], lm.a[(r, c)]) < 1e-6,
                    "mu {mu:?} v {v}: A[{r}{c}] {} vs {}",
                    a[(r, c)],
                    lm.a[(r, c)]
                );
            }
            for c in 0..4 {
                assert!(rel(b[r][c], lm.b[(r, c)]) < 1e-6, "mu {mu:?} v {v}: B[{r}{c}]");
            }
            assert!(rel(d[r], lm.d_physical[r]) < 1e-6, "mu {mu:?} v {v}: d[{r}] {} vs {}", d[r], lm.d_physical[r]);
        }
    }
}

/// Simulates with a stiff proportional speed hold so that `v` stays at the design speed.
fn simulate_held(p: &VehicleParams, mut u: Inputs<f64>, v: f64, seconds: f64) -> State<f64> {
    let mut s = nigel_vehicle::straight_running(v);
    let dt = 1e-3;
    for _ in 0..(seconds / dt) as usize {
        let speed = s[idx::V_X].hypot(s[idx::V_Y]);
        let force = 200.0 * (v - speed);
        u.tau = [force * p.r_wheel / 4.0; 4];
        s = integrate(p, &s, &u, dt, 5e-4);
    }
    s
}

#[test]
fn steady_cornering_matches_the_linear_steady_state() {
    let p = VehicleParams::table2();
    let v = 0.35;
    let steer = [0.01, 0.01, -0.01, -0.01];
    let mut u = Inputs::coasting(0.4);
    u.delta = steer;
    let s = simulate_held(&p, u, v, 3.0);
    let lm = linear_model(&p, [0.4; 4], v);
    let x_ss: Vector2<f64> = -lm.a.try_inverse().unwrap() * lm.b * Vector4::from(steer);
    let beta = s[idx::V_Y].atan2(s[idx::V_X]);
    let r = s[idx::YAW_RATE];
    assert!(rel(beta, x_ss[0]) < 1e-2, "beta {beta} vs linear {}", x_ss[0]);
    assert!(rel(r, x_ss[1]) < 1e-2, "r {r} vs linear {}", x_ss[1]);
    assert!(r > 0.0, "positive front steer turns left");
}

#[test]
fn no_forces_gives_straight_uniform_motion() {
    let p = VehicleParams::table2();
    let mut s = nigel_vehicle::straight_running(0.35);
    s[idx::PSI] = 0.3;
    let u = Inputs::coasting(0.4);
    let end = integrate(&p, &s, &u, 2.0, 1e-3);
    assert!((end[idx::X] - 0.7 * 0.3f64.cos()).abs() < 1e-12);
    assert!((end[idx::Y] - 0.7 * 0.3f64.sin()).abs() < 1e-12);
    assert_eq!(end[idx::V_Y], 0.0);
    assert_eq!(end[idx::YAW_RATE], 0.0);
    assert_eq!(end[idx::PSI], 0.3);
}

#[test]
fn standstill_and_reversing_are_well_defined() {
    let p = VehicleParams::real_fidelity();
    let mut u = Inputs::coasting(0.4);
    u.delta = [1.5, -1.5, 0.3, 2.0];
    u.tau = [0.05, -0.05, 0.0, 0.1];
    let at_rest = [0.0; N_STATES];
    let e = evaluate(&p, &at_rest, &u);
    assert!(e.derivatives.iter().all(|d| d.is_finite()));
    assert_eq!(e.force_lat, [0.0; 4], "no lateral tire force at rest");
    // reversing while sliding sideways: the tire force must oppose the sliding (no energy pumped in)
    let mut s = [0.0; N_STATES];
    s[idx::V_X] = -0.3;
    s[idx::V_Y] = 0.1;
    let u = Inputs::coasting(0.4);
    let e = evaluate(&VehicleParams::table2(), &s, &u);
    let lateral_force: f64 = e.force_lat.iter().sum();
    assert!(lateral_force * s[idx::V_Y] < 0.0, "force {lateral_force} must oppose sliding");
    let p = VehicleParams::table2();
    let mut s2 = s;
    let mut energy = 0.5 * p.m * (s[idx::V_X].powi(2) + s[idx::V_Y].powi(2));
    for _ in 0..2000 {
        s2 = integrate(&p, &s2, &u, 1e-3, 5e-4);
        let e_now = 0.5 * p.m * (s2[idx::V_X].powi(2) + s2[idx::V_Y].powi(2)) + 0.5 * p.i_z * s2[idx::YAW_RATE].powi(2);
        assert!(e_now <= energy + 1e-12, "energy grew while coasting backwards");
        assert!(s2.iter().all(|x| x.is_finite()));
        energy = e_now;
    }
}

#[test]
fn impossible_parameters_are_refused_with_the_name() {
    let mut p = VehicleParams::table2();
    p.m = 0.0;
    assert_eq!(p.validate().unwrap_err().name, "m");
    let mut p = VehicleParams::table2();
    p.c[2] = -1.0;
    assert_eq!(p.validate().unwrap_err().name, "c_rl");
    let mut p = VehicleParams::table2();
    p.l_r = f64::NAN;
    assert!(p.validate().unwrap_err().to_string().contains("l_r"));
    assert!(VehicleParams::table2().validate().is_ok());
    assert!(VehicleParams::real_fidelity().validate().is_ok());
}

#[test]
fn friction_circle_caps_the_combined_force() {
    let p = VehicleParams { friction_circle: true, ..VehicleParams::table2() };
    let mut s = nigel_vehicle::straight_running(0.35);
    s[idx::V_Y] = 0.2;
    let mut u = Inputs::coasting(0.4);
    u.tau = [1.0; 4];
    let e = evaluate(&p, &s, &u);
    let loads = p.normal_loads();
    for i in 0..4 {
        let h = e.force_drive[i].hypot(e.force_lat[i]);
        assert!(h <= 0.4 * loads[i] * (1.0 + 1e-12), "wheel {i}: {h}");
    }
}

#[test]
fn servo_follows_with_rate_limit() {
    let p = VehicleParams::real_fidelity();
    let s = nigel_vehicle::straight_running(0.35);
    let mut u = Inputs::coasting(0.4);
    u.delta = [0.5, 0.001, 0.0, -0.5];
    let e = evaluate(&p, &s, &u);
    assert_eq!(e.derivatives[idx::SERVO], 5.51);
    assert!((e.derivatives[idx::SERVO + 1] - 0.001 / 0.03).abs() < 1e-12);
    assert_eq!(e.derivatives[idx::SERVO + 3], -5.51);
    assert_eq!(e.delta_applied, [0.0; 4]);
}

#[test]
fn a_car_coasting_to_rest_ends_exactly_at_rest_not_in_subnormals() {
    let p = VehicleParams::table2();
    // sliding sideways and spinning, wheels straight: the tires stop the car
    let mut s = [0.0; N_STATES];
    s[idx::V_Y] = 0.01;
    s[idx::YAW_RATE] = 0.05;
    let u = Inputs::coasting(0.4);
    for step in 0..5_000 {
        s = integrate(&p, &s, &u, 1e-3, 5e-4);
        assert!(s.iter().all(|x| x.is_normal() || *x == 0.0), "subnormal state at step {step}: {s:?}");
    }
    // (v_x keeps the small forward speed the spin handed it: the model has no rolling resistance)
    for k in [idx::V_Y, idx::YAW_RATE] {
        assert_eq!(s[k], 0.0, "sliding and spinning stopped exactly: state {k} = {:e}", s[k]);
    }
    assert!(s.iter().all(|x| x.is_normal() || *x == 0.0), "no subnormal states: {s:?}");
}

/// World-frame wind is the body-frame wind rotated with the instantaneous heading, at every
/// evaluation (so at every RK4 stage): a car turning in place with constant world wind.
#[test]
fn world_frame_wind_is_rotated_at_every_stage() {
    use nigel_vehicle::dynamics::{derivatives_of, idx, rk4_step, Inputs, N_STATES};
    use nigel_vehicle::VehicleParams;
    let p = VehicleParams::table2();
    let (fx, fy) = (0.3, -0.2);
    let mut s = [0.0; N_STATES];
    s[idx::V_X] = 0.2;
    s[idx::YAW_RATE] = 2.0;
    for psi in [0.0, 0.7, 2.5, -1.9] {
        s[idx::PSI] = psi;
        let mut world = Inputs::<f64>::coasting(0.5);
        world.delta = [0.3, 0.3, -0.3, -0.3];
        world.wind_x = fx;
        world.wind_y = fy;
        let mut body = world;
        body.wind_x = 0.0;
        body.wind_y = 0.0;
        body.wind_head = -(fx * psi.cos() + fy * psi.sin());
        body.wind_side = -fx * psi.sin() + fy * psi.cos();
        let (a, b) = (derivatives_of(&p, &s, &world), derivatives_of(&p, &s, &body));
        for j in 0..N_STATES {
            assert!((a[j] - b[j]).abs() <= 1e-15 * (1.0 + b[j].abs()), "psi {psi}, state {j}: {} vs {}", a[j], b[j]);
        }
    }
    // An RK4 step with world wind is not a step with the wind frozen at the initial heading:
    // the heading moves by r h = 0.2 rad over the step.
    s[idx::PSI] = 0.0;
    let mut world = Inputs::<f64>::coasting(0.5);
    world.wind_y = 1.0;
    let mut frozen = Inputs::<f64>::coasting(0.5);
    frozen.wind_side = 1.0;
    let (a, b) = (rk4_step(&p, &s, &world, 0.1), rk4_step(&p, &s, &frozen, 0.1));
    assert!((a[idx::V_X] - b[idx::V_X]).abs() > 1e-4, "{} vs {}", a[idx::V_X], b[idx::V_X]);
}

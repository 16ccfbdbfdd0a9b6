//! The along-track correction of the robust tracking controller: a car
//! started behind its reference car catches up with the time constant of the linear
//! argument in `control.rs`, without overshoot, and the commanded speed stays inside its
//! clamp however far behind the car starts.

mod common {
    pub use nigel_benchmark::ControllerInputs;
    pub mod inputs;
}

use nigel_benchmark::control::{ALONG_TRACK_SPEED_MAX, KI_SPEED, KP_SPEED, K_ALONG_TRACK};
use nigel_benchmark::{Controller, ControllerInputs, SampledController, DEFAULT_SPEED, SAMPLE_PERIOD};
use nigel_vehicle::dynamics::idx;
use nigel_vehicle::{integrate, straight_running, Inputs, VehicleParams};

struct Catch {
    /// `e_x` at every sample (car minus reference along +X) [m].
    along: Vec<f64>,
    speed: Vec<f64>,
    speed_command: Vec<f64>,
    saturated: bool,
    lateral: f64,
}

/// The table-2 car at `v = 0.35` started `behind` metres behind a reference car that runs
/// straight along +X at 0.35 m/s from the origin, under the robust tracking controller.
fn catch_up(behind: f64, seconds: f64) -> Catch {
    let p = VehicleParams::table2();
    let mut controller = SampledController::new(Controller::RobustTracking.settings()).unwrap();
    let mut s = straight_running(DEFAULT_SPEED);
    s[idx::X] = -behind;
    let n = (seconds / SAMPLE_PERIOD).round() as usize;
    let mut out = Catch { along: vec![], speed: vec![], speed_command: vec![], saturated: false, lateral: 0.0 };
    for k in 0..=n {
        let x_ref = DEFAULT_SPEED * k as f64 * SAMPLE_PERIOD;
        let speed = s[idx::V_X].hypot(s[idx::V_Y]);
        let inputs = ControllerInputs {
            beta: s[idx::V_Y].atan2(s[idx::V_X]),
            yaw_rate: s[idx::YAW_RATE],
            speed,
            beta_ref: 0.0,
            yaw_rate_ref: 0.0,
            speed_ref: DEFAULT_SPEED,
            delta_ff: [0.0; 4],
            x: s[idx::X],
            y: s[idx::Y],
            psi: s[idx::PSI],
            x_ref,
            y_ref: 0.0,
            psi_ref: 0.0,
        };
        out.along.push(s[idx::X] - x_ref);
        out.speed.push(speed);
        out.speed_command.push(controller.speed_command(&inputs));
        out.lateral = out.lateral.max(s[idx::Y].abs());
        let c = controller.step(&inputs);
        out.saturated |= c.saturated;
        let mut u = Inputs::<f64>::coasting(0.4);
        u.delta = c.delta;
        u.tau = c.tau;
        s = integrate(&p, &s, &u, SAMPLE_PERIOD, 0.5e-3);
    }
    out
}

/// The dominant (real) root of `s^3 + (kp/m) s^2 + (ki/m + k kp/m) s + k ki/m`: the outer
/// loop `de_x/dt = v - v_ref` around the PI loop `m dv/dt = kp e + ki I` (Newton from -k).
fn dominant_pole(m: f64, k: f64) -> f64 {
    let (a2, a1, a0) = (KP_SPEED / m, KI_SPEED / m + k * KP_SPEED / m, k * KI_SPEED / m);
    let mut s = -k;
    for _ in 0..50 {
        s -= (((s + a2) * s + a1) * s + a0) / ((3.0 * s + 2.0 * a2) * s + a1);
    }
    s
}

#[test]
fn a_car_started_behind_catches_up_with_the_designed_time_constant() {
    let lambda = dominant_pole(VehicleParams::table2().m, K_ALONG_TRACK);
    // the linear argument of control.rs: a pole near -k_along_track
    assert!((lambda + 0.988).abs() < 1e-3, "{lambda}");
    let run = catch_up(0.1, 10.0);
    let at = |t: f64| run.along[(t / SAMPLE_PERIOD).round() as usize];
    assert_eq!(at(0.0), -0.1);
    // once the inner loop has settled (its poles are near -10 /s), e_x decays at the dominant pole
    let rate = (at(6.0) / at(3.0)).ln() / 3.0;
    assert!((rate - lambda).abs() < 0.01 * lambda.abs(), "measured decay rate {rate} /s, designed {lambda} /s");
    // and e(t) follows -0.1 exp(lambda t) within 5 % of the initial error from the first second on
    for t in [1.0, 2.0, 4.0, 8.0] {
        let expected = -0.1 * (lambda * t).exp();
        assert!((at(t) - expected).abs() < 5e-3, "t = {t}: e_x = {} vs {expected}", at(t));
    }
    assert!(at(10.0).abs() < 1e-4 * 0.1 * 10.0, "{}", at(10.0));
    // never ahead of the reference car (no overshoot), never saturating the drive
    let ahead = run.along.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    assert!(ahead <= 1e-6, "the car overtook the reference by {ahead} m");
    assert!(!run.saturated);
    // the commanded speed: 0.35 + 0.1 at the start, back to 0.35, never outside the clamp
    assert!((run.speed_command[0] - (DEFAULT_SPEED + K_ALONG_TRACK * 0.1)).abs() < 1e-12);
    assert!(run.speed_command.iter().all(|&v| (DEFAULT_SPEED..=DEFAULT_SPEED + ALONG_TRACK_SPEED_MAX).contains(&v)));
    // the car's speed stays below what the PI's step response (20 s + 100)/(s + 10)^2 makes
    // of a 0.1 m/s step, 1 + e^-2 of it (the command decays meanwhile, so less: 0.4537 seen)
    let v_max = run.speed.iter().cloned().fold(0.0, f64::max);
    assert!(v_max <= DEFAULT_SPEED + 0.1 * (1.0 + (-2.0f64).exp()), "{v_max}");
    assert!(v_max > DEFAULT_SPEED + 0.05, "{v_max}");
    // straight: the pose feedback keeps the car on the line
    assert!(run.lateral < 1e-12, "{}", run.lateral);
}

#[test]
fn far_behind_the_speed_command_is_clamped_and_the_car_overshoots_it_only_as_the_pi_does() {
    // 2 m behind: k e = 2 m/s would be asked without the clamp
    let run = catch_up(2.0, 30.0);
    let max_cmd = run.speed_command.iter().cloned().fold(0.0, f64::max);
    assert_eq!(max_cmd, DEFAULT_SPEED + ALONG_TRACK_SPEED_MAX);
    assert!(run.speed_command.iter().all(|&v| v >= DEFAULT_SPEED - ALONG_TRACK_SPEED_MAX));
    // the PI's step response (20 s + 100)/(s + 10)^2 peaks at 1 + e^-2 of the step at t = 0.2 s
    let v_max = run.speed.iter().cloned().fold(0.0, f64::max);
    let bound = DEFAULT_SPEED + ALONG_TRACK_SPEED_MAX * (1.0 + (-2.0f64).exp());
    assert!(v_max <= bound + 1e-3, "{v_max} > {bound}");
    assert!(v_max > DEFAULT_SPEED + 0.9 * ALONG_TRACK_SPEED_MAX, "{v_max}");
    assert!(!run.saturated);
    // it catches up: 0.1 m/s for ~19 s, then the linear decay
    assert!(run.along.last().unwrap().abs() < 1e-3, "{}", run.along.last().unwrap());
    let ahead = run.along.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    assert!(ahead <= 1e-3, "overtook by {ahead} m");
}

#[test]
fn the_paper_controllers_ignore_the_pose() {
    // the pose inputs change nothing for open loop, pole placement and robust
    for c in Controller::TABLE {
        let ctl = SampledController::new(c.settings()).unwrap();
        let x = common::inputs::off_reference();
        let moved = ControllerInputs { x: 3.0, y: -1.0, psi: 2.0, x_ref: 1.0, ..x };
        assert_eq!(ctl.outputs(&x), ctl.outputs(&moved), "{c}");
        assert_eq!(ctl.increment(&x), ctl.increment(&moved), "{c}");
        assert!(!c.settings().uses_pose());
    }
    assert!(Controller::RobustTracking.settings().uses_pose());
}

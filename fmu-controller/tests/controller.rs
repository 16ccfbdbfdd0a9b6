//! The controller FMU through the layer's C entry points: the law by hand in every mode,
//! saturation and anti-windup, direct feedthrough, sample timing (Co-Simulation and Model
//! Exchange), a 10 ms step equal to ten 1 ms steps bit for bit, tunable custom gains,
//! FMU state, and bad input.

// The by-hand law clamps with max/min and indexes wheels and columns on purpose: it is
// written out independently of nigel_benchmark's code.
#![allow(clippy::manual_clamp, clippy::needless_range_loop)]

use std::f64::consts::FRAC_PI_2;

use fmi_export::testing::{Fmu, DISCARD, ERR, OK};
use fmi_export::Model;
use nigel_benchmark::gains::{POLE_PLACEMENT, ROBUST, ROBUST_TRACKING};
use nigel_controller::{mode, Controller};

/// The value reference of the variable `name` (by name, as an importer finds it).
fn vr(name: &str) -> u32 {
    Controller::declaration().value_reference(name).unwrap_or_else(|| panic!("no variable {name}"))
}

type C = Fmu<Controller>;

const T: f64 = 1e-3;
const R_WHEEL: f64 = 0.0325;

/// One set of inputs: beta, yaw_rate, speed, beta_ref, yaw_rate_ref, speed_ref, delta_ff.
#[derive(Clone, Copy, Debug)]
struct In {
    beta: f64,
    yaw_rate: f64,
    speed: f64,
    beta_ref: f64,
    yaw_rate_ref: f64,
    speed_ref: f64,
    ff: [f64; 4],
}

const SETS: [In; 4] = [
    In {
        beta: 0.02,
        yaw_rate: -0.1,
        speed: 0.34,
        beta_ref: 0.01,
        yaw_rate_ref: 0.05,
        speed_ref: 0.35,
        ff: [0.1, 0.1, -0.1, -0.1],
    },
    In { beta: -0.3, yaw_rate: 1.2, speed: 0.36, beta_ref: 0.0, yaw_rate_ref: 0.0, speed_ref: 0.35, ff: [0.0; 4] },
    In {
        beta: 0.0,
        yaw_rate: 0.0,
        speed: 0.35,
        beta_ref: 0.0,
        yaw_rate_ref: 0.0,
        speed_ref: 0.35,
        ff: [0.5, -0.2, 0.3, 1.5],
    },
    // far off: the steering clamps at pi/2
    In {
        beta: 1.0,
        yaw_rate: -4.0,
        speed: 0.3,
        beta_ref: -1.0,
        yaw_rate_ref: 4.0,
        speed_ref: 0.35,
        ff: [1.5, -1.5, 1.5, -1.5],
    },
];

fn set_inputs(c: &C, x: &In) {
    for (r, v) in [
        (vr("beta"), x.beta),
        (vr("yaw_rate"), x.yaw_rate),
        (vr("speed"), x.speed),
        (vr("beta_ref"), x.beta_ref),
        (vr("yaw_rate_ref"), x.yaw_rate_ref),
        (vr("speed_ref"), x.speed_ref),
    ] {
        assert_eq!(c.set_real(r, v), OK, "{}", c.last_error());
    }
    for i in 0..4 {
        assert_eq!(c.set_real(vr("delta_ff_fl") + i as u32, x.ff[i]), OK);
    }
}

fn deltas(c: &C) -> [f64; 4] {
    std::array::from_fn(|i| c.real(vr("delta_fl") + i as u32))
}

fn taus(c: &C) -> [f64; 4] {
    std::array::from_fn(|i| c.real(vr("tau_fl") + i as u32))
}

/// The law written out by hand (docs/benchmark.md), independent of nigel_benchmark's code.
fn by_hand(k: &[[f64; 2]; 4], x: &In, integral: f64) -> ([f64; 4], f64) {
    let delta = std::array::from_fn(|i| {
        let d = x.ff[i] + k[i][0] * (x.beta - x.beta_ref) + k[i][1] * (x.yaw_rate - x.yaw_rate_ref);
        d.max(-FRAC_PI_2).min(FRAC_PI_2)
    });
    let f = 53.6 * (x.speed_ref - x.speed) + 268.0 * integral;
    (delta, f.max(-20.0).min(20.0))
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-14 * (1.0 + b.abs())
}

#[test]
fn outputs_are_the_law_in_every_mode() {
    let custom = [[0.3, -0.2], [1.0, 0.0], [-0.7, 0.25], [0.0, 2.0]];
    for m in [mode::OPEN_LOOP, mode::POLE_PLACEMENT, mode::ROBUST, mode::CUSTOM] {
        let gain = match m {
            mode::OPEN_LOOP => [[0.0; 2]; 4],
            mode::POLE_PLACEMENT => POLE_PLACEMENT,
            mode::ROBUST => ROBUST,
            _ => custom,
        };
        let c = C::cs();
        assert_eq!(c.set_int(vr("controller"), m), OK);
        for i in 0..4 {
            for j in 0..2 {
                assert_eq!(c.set_real(vr("k_beta_fl") + (2 * i + j) as u32, custom[i][j]), OK);
            }
        }
        c.init();
        // the gains in use are readable
        for i in 0..4 {
            for j in 0..2 {
                assert_eq!(c.real(vr("gain_beta_fl") + (2 * i + j) as u32), gain[i][j], "mode {m}");
            }
        }
        let mut integral = 0.0;
        for (n, x) in SETS.iter().enumerate() {
            let t = n as f64 * T;
            set_inputs(&c, x);
            // read before the step: the law on the inputs just set (direct feedthrough)
            let (delta, force) = by_hand(&gain, x, integral);
            let got = deltas(&c);
            for i in 0..4 {
                assert!(close(got[i], delta[i]), "mode {m} set {n} wheel {i}: {} vs {}", got[i], delta[i]);
            }
            for tau in taus(&c) {
                assert!(close(tau, force * R_WHEEL / 4.0), "mode {m} set {n}: tau {tau} vs F {force}");
            }
            assert!(close(c.real(vr("drive_force")), force));
            assert_eq!(c.step(t, T), OK, "{}", c.last_error());
            if force.abs() < 20.0 {
                integral += (x.speed_ref - x.speed) * T;
            }
            assert!(close(c.real(vr("speed_integral")), integral), "{} vs {integral}", c.real(vr("speed_integral")));
        }
        // the last set drives the steering into the clamp (the by-hand law clamps too)
        if m != mode::OPEN_LOOP {
            assert!(deltas(&c).iter().any(|d| d.abs() == FRAC_PI_2), "{:?}", deltas(&c));
        }
    }
}

#[test]
fn force_saturates_and_the_integrator_freezes() {
    let c = C::cs();
    c.init();
    let mut x = SETS[2];
    x.speed = 0.0; // e = 0.35: F = 18.76 < 20
    set_inputs(&c, &x);
    assert!(close(c.real(vr("drive_force")), 53.6 * 0.35));
    assert_eq!(c.step(0.0, T), OK);
    let i1 = c.real(vr("speed_integral"));
    assert!(close(i1, 0.35e-3));
    // F = 18.76 + 268 * 0.35e-3 = 18.8538, still linear; then 1 m/s short: saturates
    x.speed_ref = 1.0;
    set_inputs(&c, &x);
    assert_eq!(c.real(vr("drive_force")), 20.0);
    assert_eq!(taus(&c), [20.0 * R_WHEEL / 4.0; 4]);
    for k in 1..50 {
        assert_eq!(c.step(k as f64 * T, T), OK);
        assert_eq!(c.real(vr("speed_integral")), i1, "frozen while saturated (sample {k})");
    }
    // negative saturation too, still frozen
    x.speed = 3.0;
    set_inputs(&c, &x);
    assert_eq!(c.real(vr("drive_force")), -20.0);
    assert_eq!(c.step(50.0 * T, T), OK);
    assert_eq!(c.real(vr("speed_integral")), i1);
    // back in the linear range the integrator runs again
    x.speed = 0.99;
    set_inputs(&c, &x);
    let f = c.real(vr("drive_force"));
    assert!(close(f, 53.6 * 0.01 + 268.0 * i1), "{f}");
    assert_eq!(c.step(51.0 * T, T), OK);
    assert!(close(c.real(vr("speed_integral")), i1 + 0.01 * T));
}

#[test]
fn outputs_follow_inputs_set_at_the_sample_instant_and_hold_between_samples() {
    let c = C::cs();
    c.init();
    set_inputs(&c, &SETS[0]);
    let a = deltas(&c);
    // the importer changes its mind at the same instant: the outputs follow
    set_inputs(&c, &SETS[1]);
    let b = deltas(&c);
    assert_ne!(a, b);
    assert!(close(b[0], by_hand(&ROBUST, &SETS[1], 0.0).0[0]));
    // half a sample: the inputs change, the held outputs do not
    assert_eq!(c.step(0.0, 0.5 * T), OK);
    set_inputs(&c, &SETS[2]);
    assert_eq!(deltas(&c), b);
    assert_eq!(c.step(0.5 * T, 0.5 * T), OK);
    // at t_1 the new inputs apply
    assert!(close(deltas(&c)[3], by_hand(&ROBUST, &SETS[2], 0.0).0[3]));
    // the integrator moved with the inputs of t_0 (SETS[1]: e = -0.01)
    assert!(close(c.real(vr("speed_integral")), -0.01 * T));
}

#[test]
fn one_10ms_step_equals_ten_1ms_steps_bit_for_bit() {
    let big = C::cs();
    let small = C::cs();
    for c in [&big, &small] {
        assert_eq!(c.set_int(vr("controller"), mode::POLE_PLACEMENT), OK);
        c.init();
    }
    let mut t = 0.0;
    for x in SETS.iter().chain(SETS.iter()) {
        set_inputs(&big, x);
        set_inputs(&small, x);
        assert_eq!(big.step(t, 10.0 * T), OK);
        for k in 0..10 {
            assert_eq!(small.step(t + k as f64 * T, T), OK, "{}", small.last_error());
        }
        t += 10.0 * T;
        let read = |c: &C| {
            let mut v = c.reals(&[vr("speed_integral"), vr("drive_force")]);
            v.extend(deltas(c));
            v.extend(taus(c));
            v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>()
        };
        assert_eq!(read(&big), read(&small), "t = {t}");
    }
}

#[test]
fn custom_gains_can_change_between_steps() {
    let c = C::cs();
    assert_eq!(c.set_int(vr("controller"), mode::CUSTOM), OK);
    c.init();
    let x = SETS[0];
    set_inputs(&c, &x);
    let before = deltas(&c);
    assert!(close(before[0], by_hand(&ROBUST, &x, 0.0).0[0]), "custom starts at the robust gain");
    assert_eq!(c.step(0.0, T), OK);
    let mut k = ROBUST;
    k[0] = [2.0, -1.0];
    assert_eq!(c.set_real(vr("k_beta_fl"), 2.0), OK, "{}", c.last_error());
    assert_eq!(c.set_real(vr("k_beta_fl") + 1, -1.0), OK);
    assert_eq!(c.real(vr("gain_beta_fl")), 2.0);
    let after = deltas(&c);
    assert!(close(after[0], by_hand(&k, &x, 0.0).0[0]), "{} vs {}", after[0], by_hand(&k, &x, 0.0).0[0]);
    assert_eq!(after[1..], before[1..]);
    // the settings are validated once per change, not per sample: a second change later
    // takes effect too, and the gain stays put over the samples in between
    assert_eq!(c.step(T, T), OK);
    assert!(close(deltas(&c)[0], by_hand(&k, &x, 0.0).0[0]));
    k[0] = [-0.5, 0.25];
    assert_eq!(c.set_real(vr("k_beta_fl"), -0.5), OK);
    assert_eq!(c.set_real(vr("k_beta_fl") + 1, 0.25), OK);
    assert_eq!(c.step(2.0 * T, T), OK);
    let again = deltas(&c);
    assert!(close(again[0], by_hand(&k, &x, 0.0).0[0]), "{} vs {}", again[0], by_hand(&k, &x, 0.0).0[0]);
    assert_eq!(again[1..], before[1..]);
    // a gain the layer lets through but the law refuses (not finite) is still refused
    assert_eq!(c.set_real(vr("k_beta_fl"), f64::INFINITY), ERR);
    assert!(c.last_error().contains("k_beta_fl"), "{}", c.last_error());
    // a fixed parameter cannot change after initialization
    assert_eq!(c.set_int(vr("controller"), mode::ROBUST), ERR);
}

#[test]
fn model_exchange_samples_are_time_events() {
    let c = C::me();
    c.init();
    set_inputs(&c, &SETS[0]);
    // the initial event at t = 0 (event mode after initialization)
    assert_eq!(c.new_discrete_states(), Some(T));
    assert_eq!(c.enter_continuous_time_mode(), OK);
    let d0 = deltas(&c);
    assert!(close(d0[0], by_hand(&ROBUST, &SETS[0], 0.0).0[0]));
    // inputs move in continuous time: the outputs hold until the event at t_1
    for (n, t) in [0.2e-3, 0.5e-3, 0.99e-3].into_iter().enumerate() {
        assert_eq!(c.set_time(t), OK);
        set_inputs(&c, &SETS[1 + n % 2]);
        assert_eq!(deltas(&c), d0, "t = {t}");
    }
    assert_eq!(c.set_time(T), OK);
    set_inputs(&c, &SETS[1]);
    assert_eq!(deltas(&c), d0, "before the event is handled");
    assert_eq!(c.enter_event_mode(), OK);
    assert_eq!(c.new_discrete_states(), Some(2.0 * T));
    let d1 = deltas(&c);
    assert!(close(d1[2], by_hand(&ROBUST, &SETS[1], 0.01 * T).0[2]));
    // at t_1 the integrator holds I_1: one sample of SETS[0] (e = 0.01)
    assert!(close(c.real(vr("speed_integral")), 0.01 * T), "{}", c.real(vr("speed_integral")));
}

#[test]
fn fmu_state_round_trip_reproduces_the_run() {
    let c = C::cs();
    c.init();
    let mut t = 0.0;
    for x in &SETS[..2] {
        set_inputs(&c, x);
        assert_eq!(c.step(t, T), OK);
        t += T;
    }
    let saved = c.serialized_state();
    let run = |c: &C, t0: f64| {
        let mut out = Vec::new();
        let mut t = t0;
        for x in &SETS {
            set_inputs(c, x);
            assert_eq!(c.step(t, T), OK);
            t += T;
            out.extend(deltas(c).map(f64::to_bits));
            out.push(c.real(vr("speed_integral")).to_bits());
        }
        out
    };
    let first = run(&c, t);
    assert_eq!(c.restore_serialized(&saved), OK, "{}", c.last_error());
    assert_eq!(run(&c, t), first);
}

#[test]
fn bad_input_is_refused_naming_the_variable_and_reset_recovers() {
    let c = C::cs();
    // out-of-range enumerations
    for value in [7, 6] {
        c.assert_refused_then_reset(c.set_int(vr("controller"), value), "controller");
    }
    for (reference, value, named) in [
        (vr("sample_period"), -1e-3, "sample_period"), // negative
        (vr("sample_period"), 0.0, "sample_period"),   // zero is refused too (by the model)
        (vr("k_beta_fl") + 3, f64::NAN, "k_yaw_rate_fr"), // NaN gains
        (vr("beta"), f64::INFINITY, "beta"),
        (vr("delta_max"), 2.0, "delta_max"),
    ] {
        c.assert_refused_then_reset(c.set_real(reference, value), named);
    }
    // after reset: the start values and a normal run
    c.init();
    assert_eq!(c.int(vr("controller")), mode::ROBUST);
    assert_eq!(c.real(vr("sample_period")), T);
    set_inputs(&c, &SETS[0]);
    assert_eq!(c.step(0.0, T), OK);
    assert!(close(c.real(vr("speed_integral")), 0.01 * T));
}

#[test]
fn declaration_has_feedthrough_and_the_interfaces() {
    use fmi_export::Model;
    let md = Controller::declaration().model_description();
    assert!(md.validate().is_empty(), "{:?}", md.validate());
    assert!(md.model_exchange.is_some() && md.co_simulation.is_some());
    let index = |n: &str| md.model_variables.iter().position(|v| v.name == n).unwrap() as u32 + 1;
    let out = md.model_structure.outputs.iter().find(|u| u.index == index("delta_rl")).unwrap();
    let pose = ["x", "y", "psi", "x_ref", "y_ref", "psi_ref"].map(index);
    let mut expect =
        vec![index("beta"), index("yaw_rate"), index("beta_ref"), index("yaw_rate_ref"), index("delta_ff_rl")];
    expect.extend(pose);
    expect.sort();
    assert_eq!(out.dependencies.as_ref(), Some(&expect));
    // the speed loop: the along-track error reads x, y and the whole reference pose, not psi
    let out = md.model_structure.outputs.iter().find(|u| u.index == index("tau_fl")).unwrap();
    let mut expect = vec![index("speed"), index("speed_ref"), index("x"), index("y")];
    expect.extend(["x_ref", "y_ref", "psi_ref"].map(index));
    expect.sort();
    assert_eq!(out.dependencies.as_ref(), Some(&expect));
    // controller is an Integer 1 ..= 5, robust_tracking the last value (the others unchanged),
    // every value named in its description
    let v = md.model_variables.iter().find(|v| v.name == "controller").unwrap();
    let fmi_export::model_description::VariableType::Integer { start, min, max, .. } = &v.variable_type else {
        panic!("controller is {:?}", v.variable_type)
    };
    assert_eq!((*start, *min, *max), (Some(mode::ROBUST), Some(1), Some(mode::ROBUST_TRACKING)));
    assert_eq!(mode::ROBUST_TRACKING, 5);
    let text = v.description.as_deref().unwrap_or_default();
    for item in ["1 open_loop", "2 pole_placement", "3 robust", "4 custom", "5 robust_tracking"] {
        assert!(text.contains(item), "{item} not in {text:?}");
    }
}

/// The tracking law written out by hand from its definition, independent of
/// nigel_vehicle's and nigel_benchmark's code: the errors in the reference's frame.
fn tracking_by_hand(x: &In, pose: [f64; 6], integral: f64) -> ([f64; 4], f64) {
    let [px, py, psi, x_ref, y_ref, psi_ref] = pose;
    let (dx, dy) = (px - x_ref, py - y_ref);
    let e_x = psi_ref.cos() * dx + psi_ref.sin() * dy;
    let e_y = -psi_ref.sin() * dx + psi_ref.cos() * dy;
    let mut e_psi = (psi - psi_ref) % std::f64::consts::TAU;
    if e_psi > std::f64::consts::PI {
        e_psi -= std::f64::consts::TAU;
    } else if e_psi <= -std::f64::consts::PI {
        e_psi += std::f64::consts::TAU;
    }
    let e = [e_y, e_psi, x.beta - x.beta_ref, x.yaw_rate - x.yaw_rate_ref];
    let k = ROBUST_TRACKING;
    let delta = std::array::from_fn(|i| {
        let d = x.ff[i] + (0..4).map(|j| k[i][j] * e[j]).sum::<f64>();
        d.max(-FRAC_PI_2).min(FRAC_PI_2)
    });
    let speed_command = x.speed_ref - (1.0 * e_x).max(-0.1).min(0.1);
    let f = 53.6 * (speed_command - x.speed) + 268.0 * integral;
    (delta, f.max(-20.0).min(20.0))
}

#[test]
fn robust_tracking_feeds_back_the_pose_and_corrects_the_speed() {
    let c = C::cs();
    assert_eq!(c.setup(), OK);
    assert_eq!(c.enter_init(), OK);
    assert_eq!(c.set_int(vr("controller"), mode::ROBUST_TRACKING), OK, "{}", c.last_error());
    assert_eq!(c.exit_init(), OK, "{}", c.last_error());
    for i in 0..4 {
        let gains = [vr("gain_e_y_fl"), vr("gain_e_y_fl") + 1, vr("gain_beta_fl"), vr("gain_beta_fl") + 1];
        let got: Vec<f64> = gains.iter().map(|&g| c.real(g + 2 * i as u32)).collect();
        assert_eq!(got, ROBUST_TRACKING[i].to_vec(), "wheel {i}");
    }
    // poses: the reference at 30 deg, the car left, behind and turned; unwrapped headings a
    // few turns apart; the car ahead by more than the clamp; headings across +-pi
    let poses = [
        [1.0, 2.05, 0.6, 1.03, 2.0, 30f64.to_radians()],
        [5.0, -1.0, 0.2 + 4.0 * std::f64::consts::PI, 5.01, -1.0, 0.1],
        [3.0, 0.0, 0.0, 2.5, 0.0, 0.0],
        [0.0, 0.0, 3.1, 0.0, 0.01, -3.1],
    ];
    let mut integral = 0.0;
    let mut t = 0.0;
    for (x, pose) in SETS.iter().zip(poses) {
        set_inputs(&c, x);
        for (r, v) in [vr("x"), vr("y"), vr("psi"), vr("x_ref"), vr("y_ref"), vr("psi_ref")].into_iter().zip(pose) {
            assert_eq!(c.set_real(r, v), OK, "{}", c.last_error());
        }
        let (delta, force) = tracking_by_hand(x, pose, integral);
        let got = deltas(&c);
        for i in 0..4 {
            assert!(close(got[i], delta[i]), "{pose:?} wheel {i}: {} vs {}", got[i], delta[i]);
        }
        assert!(close(c.real(vr("drive_force")), force), "{} vs {force}", c.real(vr("drive_force")));
        assert_eq!(c.step(t, T), OK);
        t += T;
        if force.abs() < 20.0 {
            integral += force_error(force, integral) * T;
        }
        assert!(close(c.real(vr("speed_integral")), integral), "{} vs {integral}", c.real(vr("speed_integral")));
    }
    // a lateral offset to the left steers the front wheels right
    assert!(tracking_by_hand(&SETS[2], [0.0, 0.02, 0.0, 0.0, 0.0, 0.0], 0.0).0[0] < SETS[2].ff[0]);
    // the along-track loop's parameters are checked
    assert_eq!(c.set_real(vr("k_along_track"), -1.0), ERR);
    assert!(c.last_error().contains("k_along_track"), "{}", c.last_error());
}

/// The speed error `e` behind a force `kp e + ki I` (undoes the PI for the integrator's step).
fn force_error(force: f64, integral: f64) -> f64 {
    (force - 268.0 * integral) / 53.6
}

#[test]
fn a_step_of_astronomically_many_samples_is_refused_not_run() {
    let c = C::cs();
    c.init();
    set_inputs(&c, &SETS[0]);
    // 10^9 s at 1 ms would be 10^12 samples: refused before any work, nothing changed
    assert_eq!(c.step(0.0, 1e9), DISCARD);
    assert!(c.last_message().contains("1000000000000 samples"), "{}", c.last_message());
    assert_eq!(c.last_successful_time(), 0.0);
    assert_eq!(c.reset(), OK);
    // a tiny sample period is refused up front
    assert_eq!(c.set_real(vr("sample_period"), 5e-324), ERR);
    assert!(c.last_error().contains("sample_period"), "{}", c.last_error());
    assert_eq!(c.reset(), OK);
    c.init();
    // 300 s in 100 s steps with a read between them is a normal run
    for k in 0..3 {
        assert_eq!(c.step(k as f64 * 100.0, 100.0), OK, "{}", c.last_error());
        assert!(c.real(vr("speed_integral")).is_finite());
    }
}

/// The switch is a plain Integer parameter (libcosim and ecos do not see FMI Enumerations):
/// declared min/max 1 .. 5, its values listed in its description, the values unchanged
/// (1-based, as the Enumeration had them), and no type definition left behind.
#[test]
fn controller_switch_is_an_integer_parameter_listing_its_values() {
    use fmi_export::model_description::{Causality, VariableType};
    use fmi_export::Model;
    let md = Controller::declaration().model_description();
    let v = md.variable("controller").expect("controller is declared");
    assert_eq!(v.causality, Causality::Parameter);
    assert_eq!(v.value_reference, vr("controller"));
    assert_eq!(v.variable_type, VariableType::Integer { start: Some(3), min: Some(1), max: Some(5) });
    let text = v.description.as_deref().unwrap_or("");
    for (value, name) in [(1, "open_loop"), (2, "pole_placement"), (3, "robust"), (4, "custom"), (5, "robust_tracking")]
    {
        assert!(text.contains(&format!("{value} {name} (")), "{name} = {value} missing from {text:?}");
    }
    assert_eq!(
        (mode::OPEN_LOOP, mode::POLE_PLACEMENT, mode::ROBUST, mode::CUSTOM, mode::ROBUST_TRACKING),
        (1, 2, 3, 4, 5)
    );
    assert!(md.type_definitions.is_empty());
    let xml = Controller::declaration().xml();
    assert!(!xml.contains("Enumeration"), "no Enumeration left in the description");
    // the bounds are enforced: 0 and 6 refused naming the variable, 1 .. 5 accepted
    for bad in [0, 6] {
        let c = C::cs();
        assert_eq!(c.set_int(vr("controller"), bad), ERR);
        assert!(c.last_error().contains("controller"), "{}", c.last_error());
    }
    for good in 1..=5 {
        let c = C::cs();
        assert_eq!(c.set_int(vr("controller"), good), OK);
        c.init();
        assert_eq!(c.int(vr("controller")), good);
    }
}

/// The law is validated once and kept until a parameter changes: in initialization mode an
/// importer may read the outputs (which runs the law), then set a parameter and the
/// controller switch, and the outputs follow every change.
#[test]
fn outputs_follow_parameters_set_after_a_read() {
    let c = C::cs();
    assert_eq!(c.setup(), OK);
    assert_eq!(c.enter_init(), OK);
    let x = SETS[0];
    set_inputs(&c, &x);
    // robust: e = 0.01, F = 53.6 e
    assert!(close(c.real(vr("drive_force")), 53.6 * 0.01));
    assert!(close(deltas(&c)[0], by_hand(&ROBUST, &x, 0.0).0[0]));
    assert_eq!(c.set_real(vr("kp_speed"), 100.0), OK);
    assert!(close(c.real(vr("drive_force")), 100.0 * 0.01), "{}", c.real(vr("drive_force")));
    assert_eq!(c.set_real(vr("r_wheel"), 0.05), OK);
    assert!(close(taus(&c)[0], 100.0 * 0.01 * 0.05 / 4.0), "{:?}", taus(&c));
    assert_eq!(c.set_int(vr("controller"), mode::POLE_PLACEMENT), OK);
    assert!(close(deltas(&c)[0], by_hand(&POLE_PLACEMENT, &x, 0.0).0[0]));
    assert_eq!(c.set_real(vr("delta_max"), 0.05), OK);
    assert_eq!(deltas(&c)[0], 0.05f64.min(by_hand(&POLE_PLACEMENT, &x, 0.0).0[0]).max(-0.05));
    assert_eq!(c.exit_init(), OK);
    assert_eq!(c.step(0.0, T), OK);
    assert!(close(c.real(vr("speed_integral")), 0.01 * T));
}

/// The outputs and the integrator of a Co-Simulation run from `start` with steps of `h`
/// (the master's communication points `start + n h`, one rounding each), the inputs
/// changing at every 1 ms sample instant.
fn run_from(start: f64, h: f64, samples: usize) -> Vec<[f64; 6]> {
    let c = C::cs();
    c.init_at(start);
    let per_step = (h / T).round() as usize;
    let mut rows = Vec::new();
    for n in 0..samples / per_step {
        set_inputs(&c, &SETS[n % 3]);
        let d = deltas(&c);
        rows.push([
            d[0],
            d[3],
            c.real(vr("tau_fl")),
            c.real(vr("drive_force")),
            c.real(vr("speed_integral")),
            n as f64,
        ]);
        assert_eq!(c.step(start + n as f64 * h, h), OK, "start {start}: {}", c.last_error());
    }
    rows
}

/// Samples are counted as integers from the start time and communication points compared
/// on the scale of an f64 at that time, never of 1e-12 |t| (1.7 ms at 1.7e9 s, more than a
/// period): a run started at a Unix time gives the run started at 0, bit for bit, in 1 ms
/// steps and in 10 ms steps (ten samples inside each); 1e12 s still resolves 1 ms to
/// 1.2e-4 s. The inputs change every step, so a sample run early or late shows.
#[test]
fn large_start_times_give_the_same_run_bit_for_bit() {
    for h in [T, 10.0 * T] {
        let at_zero = run_from(0.0, h, 600);
        assert!(at_zero.windows(2).any(|w| w[0][0] != w[1][0]), "the steering changes from step to step");
        for start in [1e6, 1.7e9, 1e12] {
            assert_eq!(run_from(start, h, 600), at_zero, "start time {start} s, steps of {h} s");
        }
    }
}

/// A start time at which an f64 cannot resolve the sample period is refused when
/// initialization ends, with the reason, instead of running samples at the wrong time.
#[test]
fn a_start_time_that_cannot_hold_the_sample_grid_is_refused() {
    let c = C::cs();
    assert_eq!(c.setup_at(1e14, None), OK);
    assert_eq!(c.enter_init(), OK);
    assert_eq!(c.exit_init(), ERR);
    assert!(c.last_error().contains("cannot resolve the sample period 0.001 s"), "{}", c.last_error());
}

/// Co-Simulation time is the importer's: each step ends at currentCommunicationPoint +
/// communicationStepSize to the bit, and fmi2LastSuccessfulTime reports it, whether the
/// master accumulates `t += h` or computes `n h` (which differ by rounding after a few
/// steps of 0.1 ms, by 1e-12 s and more after 10^4).
#[test]
fn co_simulation_time_is_the_communication_point_plus_the_step() {
    let h = 1e-4;
    let c = C::cs();
    c.init();
    let mut accumulated = 0.0;
    let mut differed = 0;
    for n in 0..20_000u32 {
        // alternate the two masters' arithmetic
        let t = if n % 2 == 0 { accumulated } else { f64::from(n) * h };
        differed += (t != f64::from(n) * h || accumulated != f64::from(n) * h) as u32;
        assert_eq!(c.step(t, h), OK, "{}", c.last_error());
        assert_eq!(c.last_successful_time().to_bits(), (t + h).to_bits(), "step {n} from {t}");
        accumulated = t + h;
    }
    assert!(differed > 1000, "the two arithmetics differ often: {differed}");
    // a communication point off by more than the f64 resolution (plus 1 ns) is refused
    let now = c.last_successful_time();
    assert_eq!(c.step(now + 1e-6, h), ERR);
    assert!(c.last_error().contains("currentCommunicationPoint"), "{}", c.last_error());
}

/// Every parameter has a physically meaningful range in the description, refused at the
/// set with the function, the variable and the bound: no value the law cannot use (a
/// wheel radius of 1e308 m gave an infinite torque at the next read).
#[test]
fn parameters_out_of_their_range_are_refused_at_the_set() {
    let xml = Controller::declaration().xml();
    for name in [
        "sample_period",
        "kp_speed",
        "ki_speed",
        "force_max",
        "r_wheel",
        "delta_max",
        "k_along_track",
        "along_track_speed_max",
        "k_beta_fl",
        "k_yaw_rate_rr",
    ] {
        let at = xml.find(&format!("name=\"{name}\"")).unwrap_or_else(|| panic!("{name} declared"));
        let real = &xml[at..at + xml[at..].find("/>").unwrap()];
        assert!(real.contains("min=\"") && real.contains("max=\""), "{name}: {real}");
    }
    for (r, bad, name) in [
        (vr("r_wheel"), 1e308, "r_wheel"),
        (vr("sample_period"), 1e308, "sample_period"),
        (vr("delta_max"), 5e-324, "delta_max"),
        (vr("force_max"), 0.0, "force_max"),
        (vr("k_beta_fl"), -1e6, "k_beta_fl"),
    ] {
        let c = C::cs();
        assert_eq!(c.set_real(r, bad), ERR, "{name} = {bad}");
        let e = c.last_error();
        assert!(e.starts_with("fmi2SetReal: ") && e.contains(name) && e.contains("refused"), "{e}");
        assert!(!e.contains("Var::") && !e.contains("Real("), "no Rust debug text: {e}");
    }
}

/// A serialized state whose sample clock disagrees with its time or its next event is
/// refused naming what disagrees (a sample index of 20000 at t = 6 ms, a next event at
/// 1e300 s), where the unchanged state restores; an FMU state carries the clock exactly.
#[test]
fn an_inconsistent_sample_clock_in_a_state_is_refused() {
    let c = C::cs();
    c.init();
    for n in 0..6 {
        set_inputs(&c, &SETS[n % 3]);
        assert_eq!(c.step(n as f64 * T, T), OK);
    }
    let _ = c.real(vr("delta_fl")); // runs the sample at 6 ms lazily
    let bytes = c.serialized_state();
    let guid = Controller::declaration().guid().len();
    let at = |i: usize| 8 + 4 + 4 + guid + 8 + 8 * i;
    let number = |b: &[u8], i: usize| f64::from_le_bytes(b[at(i)..at(i) + 8].try_into().unwrap());
    // the layer's numbers: 1 time, 5 next event, 8 clock start, 9 period, 10 next sample
    assert_eq!((number(&bytes, 1), number(&bytes, 10)), (6.0 * T, 6.0));
    let g = C::cs();
    assert_eq!(g.restore_serialized(&bytes), OK, "{}", g.last_error());
    assert_eq!(g.real(vr("delta_fl")), c.real(vr("delta_fl")));
    for (i, value, what) in [
        (10, 20_000.0, "sample"),
        (10, 2.5, "sample"),
        (5, 1e300, "next event"),
        (1, 0.5, "time"),
        (8, 1e-3, "time"),
        (9, 2e-3, "period"),
        (11, 1.0, "before-first-sample"),
    ] {
        let mut b = bytes.clone();
        b[at(i)..at(i) + 8].copy_from_slice(&f64::to_le_bytes(value));
        let g = C::cs();
        assert_eq!(g.restore_serialized(&b), ERR, "number {i} = {value}");
        let e = g.last_error();
        assert!(e.contains("fmi2DeSerializeFMUstate") && e.contains(what), "number {i} = {value}: {e}");
    }
}

/// The value references the layer assigned, pinned: a change shows in review.
#[test]
fn value_references_are_the_pinned_ones() {
    fmi_export::testing::assert_pinned_value_references::<Controller>(env!("CARGO_MANIFEST_DIR"));
}

/// The controller through FMI 3.0: every output equal to the FMI 2.0 run to the bit, with
/// inputs that change at every step.
#[test]
fn fmi3_co_simulation_equals_the_fmi2_run_bit_for_bit() {
    let compared = fmi_export::testing::assert_cs_runs_agree::<Controller>(0.0, 0.004, 200, false, |k, name| {
        let phase = name.bytes().map(|b| b as f64).sum::<f64>();
        let wave = 0.1 * (0.05 * k as f64 + phase).sin();
        Some(match name {
            "speed" | "speed_ref" => 0.3 + wave,
            _ => wave,
        })
    });
    assert!(compared > 1000, "{compared}");
}

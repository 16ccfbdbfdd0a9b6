//! The plant FMU's physics and hardening through the C ABI: world-frame wind, the
//! stability-limited Co-Simulation sub-step, hostile serialized states, non-finite
//! directional derivatives.

use std::ffi::{c_char, c_void};
use std::ptr::null_mut;
use std::sync::OnceLock;

use model_description::Causality;
use nigel_integration_tests::{built_fmu, Fmu, Instance, CO_SIMULATION, ERROR, OK};
use nigel_vehicle::dynamics::{derivatives_of, idx, stable_rk4_step, Inputs, State, N_STATES};
use nigel_vehicle::VehicleParams;

fn fmu() -> &'static Fmu {
    static FMU: OnceLock<Fmu> = OnceLock::new();
    FMU.get_or_init(|| Fmu::load(&built_fmu("nigel_plant").unwrap()).unwrap())
}

fn vrs(names: &[&str]) -> Vec<u32> {
    names.iter().map(|n| fmu().vr(n)).collect()
}

const BODY: [&str; 6] = ["x", "y", "psi", "v_x", "v_y", "yaw_rate"];

/// Classical RK4 of the body-frame model, the world wind rotated into body axes with the
/// heading of each stage (written out here, independent of the plant's integrator).
fn rk4_with_rotated_wind(
    p: &VehicleParams,
    s: &State<f64>,
    u: &Inputs<f64>,
    (fx, fy): (f64, f64),
    h: f64,
) -> State<f64> {
    let f = |x: &State<f64>| {
        let psi = x[idx::PSI];
        let mut body = *u;
        body.wind_head = -(fx * psi.cos() + fy * psi.sin());
        body.wind_side = -fx * psi.sin() + fy * psi.cos();
        derivatives_of(p, x, &body)
    };
    let add = |x: &State<f64>, k: &State<f64>, a: f64| -> State<f64> { std::array::from_fn(|j| x[j] + a * k[j]) };
    let k1 = f(s);
    let k2 = f(&add(s, &k1, h / 2.0));
    let k3 = f(&add(s, &k2, h / 2.0));
    let k4 = f(&add(s, &k3, h));
    std::array::from_fn(|j| s[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]))
}

#[test]
fn world_wind_on_a_car_turning_in_place_is_the_body_wind_rotated_at_every_stage() {
    let p = VehicleParams::table2();
    // wheels tangent to the circle about the CG: delta_i = atan(x_i / -y_i)
    let (xf, xr, half) = (p.l_f, -p.l_r, p.track / 2.0);
    let delta = [(xf / -half).atan(), (xf / half).atan(), (xr / -half).atan(), (xr / half).atan()];
    let tau = [-0.02, 0.02, -0.02, 0.02];
    let wind = (0.3, -0.2);
    let (i, log) = fmu().instantiate("wind", CO_SIMULATION, fmu().guid());
    let i = i.unwrap();
    let inputs = vrs(&[
        "delta_fl", "delta_fr", "delta_rl", "delta_rr", "tau_fl", "tau_fr", "tau_rl", "tau_rr", "wind_x", "wind_y",
    ]);
    let mut values = delta.to_vec();
    values.extend(tau);
    values.extend([wind.0, wind.1]);
    assert_eq!(i.set_real(&inputs, &values), OK);
    assert_eq!(i.set_real(&vrs(&["yaw_rate_start"]), &[3.0]), OK);
    i.initialize();

    let mut u = Inputs::<f64>::coasting(0.4);
    u.delta = delta;
    u.tau = tau;
    let mut s = [0.0; N_STATES];
    s[idx::YAW_RATE] = 3.0;
    let substep = nigel_plant::DEFAULT_CS_SUBSTEP_MAX.min(stable_rk4_step(&p, &u));
    let h = 1e-3;
    let n = nigel_vehicle::dynamics::substeps(h, substep);
    let body = vrs(&BODY);
    let mut worst: f64 = 0.0;
    for k in 0..1500 {
        assert_eq!(i.do_step(k as f64 * h, h), OK, "{:?}", log.last_error());
        for _ in 0..n {
            s = rk4_with_rotated_wind(&p, &s, &u, wind, h / n as f64);
        }
        let got = i.get_real(&body).unwrap();
        for j in 0..6 {
            worst = worst.max((got[j] - s[j]).abs() / (1.0 + s[j].abs()));
        }
    }
    println!("world wind vs body wind rotated per stage: largest relative difference {worst:e}, psi {}", s[idx::PSI]);
    assert!(worst <= 1e-12, "largest relative difference {worst:e}");
    // the car turned more than a full circle, so the wind went all the way round the body
    assert!(s[idx::PSI].abs() > 2.0 * std::f64::consts::PI, "psi = {}", s[idx::PSI]);
    // and it drifted downwind (world frame), which a body-frame wind would not do
    assert!(s[idx::X] > 1e-4 && s[idx::Y] < -1e-4, "x = {}, y = {}", s[idx::X], s[idx::Y]);
}

fn kinetic_energy(i: &Instance) -> f64 {
    let p = VehicleParams::table2();
    let v = i.get_real(&vrs(&["v_x", "v_y", "yaw_rate"])).unwrap();
    0.5 * p.m * (v[0] * v[0] + v[1] * v[1]) + 0.5 * p.i_z * v[2] * v[2]
}

#[test]
fn coasting_never_gains_energy_at_the_highest_friction_even_with_a_long_substep_limit() {
    // A slow car coasting to rest: inside the fade zone (|v| < v_fade) the tires are
    // stiffest. Before the stability bound, mu above ~3.5 with the default 0.5 ms sub-step
    // (or mu above ~1 with a 2 ms one) made it gain energy with fmi2OK.
    for (mu, substep_max) in [(3.0, 1e-2), (1.0, 2e-3), (3.0, 5e-4), (0.4, 1e-2)] {
        let (i, log) = fmu().instantiate("coast", CO_SIMULATION, fmu().guid());
        let i = i.unwrap();
        let names = ["mu_fl", "mu_fr", "mu_rl", "mu_rr", "v_x_start", "v_y_start", "yaw_rate_start", "cs_substep_max"];
        assert_eq!(i.set_real(&vrs(&names), &[mu, mu, mu, mu, 0.0, 0.015, 0.3, substep_max]), OK);
        i.initialize();
        let mut energy = kinetic_energy(&i);
        let start = energy;
        for k in 0..2000 {
            assert_eq!(i.do_step(k as f64 * 1e-3, 1e-3), OK, "{:?}", log.last_error());
            let e = kinetic_energy(&i);
            assert!(
                e <= energy * (1.0 + 1e-12),
                "mu {mu}, cs_substep_max {substep_max}: energy {energy} -> {e} at step {k}"
            );
            energy = e;
        }
        assert!(energy < 0.5 * start, "mu {mu}: the sliding is damped ({start} -> {energy})");
    }
    // friction above the declared physical maximum is refused
    let (i, log) = fmu().instantiate("mu", CO_SIMULATION, fmu().guid());
    let i = i.unwrap();
    assert_eq!(i.set_real(&vrs(&["mu_fl"]), &[3.5]), ERROR);
    assert!(log.last_error().unwrap().contains("mu_fl = 3.5 refused: above its maximum 3"));
}

/// The saved variables in the order of the serialized state (the layer's rule: parameters,
/// inputs, continuous states; the plant has no discrete variables).
fn saved_names() -> Vec<String> {
    let md = &fmu().description;
    let states: Vec<u32> = md.states();
    md.model_variables
        .iter()
        .enumerate()
        .filter(|(k, v)| {
            matches!(v.causality, Causality::Parameter | Causality::Input) || states.contains(&(*k as u32 + 1))
        })
        .map(|(_, v)| v.name.clone())
        .collect()
}

#[test]
fn hostile_serialized_states_are_refused_like_the_setters_would() {
    let (i, log) = fmu().instantiate("state", CO_SIMULATION, fmu().guid());
    let i = i.unwrap();
    i.initialize();
    assert_eq!(i.do_step(0.0, 1e-3), OK);
    let f = i.f();
    let mut state: *mut c_void = null_mut();
    let bytes = unsafe {
        assert_eq!((f.get_fmu_state.unwrap())(i.c, &mut state), OK);
        let mut size = 0;
        assert_eq!((f.serialized_fmu_state_size.unwrap())(i.c, state, &mut size), OK);
        let mut b = vec![0u8; size];
        assert_eq!((f.serialize_fmu_state.unwrap())(i.c, state, b.as_mut_ptr() as *mut c_char, size), OK);
        b
    };
    let names = saved_names();
    let first = bytes.len() - 8 * names.len();
    let patched = |name: &str, x: f64| {
        let k = names.iter().position(|n| n == name).unwrap_or_else(|| panic!("{name} not saved"));
        let mut b = bytes.clone();
        b[first + 8 * k..first + 8 * k + 8].copy_from_slice(&x.to_le_bytes());
        b
    };
    // the unpatched bytes are accepted
    let mut ok_state = null_mut();
    unsafe {
        assert_eq!(
            (f.deserialize_fmu_state.unwrap())(i.c, bytes.as_ptr() as *const c_char, bytes.len(), &mut ok_state),
            OK
        );
    }
    let cases = [
        ("mu_rl", -0.5, "mu_rl"),
        ("wind_x", f64::NAN, "wind_x"),
        ("wind_side", f64::INFINITY, "wind_side"),
        ("cs_substep_max", f64::INFINITY, "cs_substep_max"),
        ("servo_time_constant", -1.0, "servo_time_constant"),
        ("motor_taper", 0.0, "motor_taper"),
        ("steering_servo", 2.0, "steering_servo"),
        ("m", -2.68, "m"),
        ("delta_max", 4.0, "delta_max"),
    ];
    for (name, x, expect) in cases {
        let bad = patched(name, x);
        let mut s = null_mut();
        let status =
            unsafe { (f.deserialize_fmu_state.unwrap())(i.c, bad.as_ptr() as *const c_char, bad.len(), &mut s) };
        assert_eq!(status, ERROR, "{name} = {x} accepted");
        assert!(s.is_null());
        let msg = log.last_error().unwrap();
        assert!(msg.contains("fmi2DeSerializeFMUstate") && msg.contains(expect), "{name}: {msg}");
        assert_eq!(i.reset(), OK);
    }
    // an impossible servo parameter is refused by the setter too, with the servo off
    assert_eq!(i.set_real(&vrs(&["servo_time_constant"]), &[0.0]), ERROR);
    assert!(log.last_error().unwrap().contains("servo_time_constant"));
}

#[test]
fn directional_derivatives_never_hand_out_non_finite_numbers() {
    let (i, log) = fmu().instantiate("dd", CO_SIMULATION, fmu().guid());
    let i = i.unwrap();
    assert_eq!(i.set_real(&vrs(&["v_x_start"]), &[0.3]), OK);
    i.initialize();
    let f = i.f();
    let (unknown, known) = (fmu().vr("der(v_y)"), fmu().vr("v_y"));
    let mut out = [0.0];
    // a finite seed gives the finite slope
    let s = unsafe { (f.get_directional_derivative.unwrap())(i.c, &unknown, 1, &known, 1, &1.0, out.as_mut_ptr()) };
    assert_eq!(s, OK);
    assert!(out[0] < -10.0 && out[0].is_finite(), "{}", out[0]);
    // a huge one overflows: refused, not handed out with fmi2OK
    let s = unsafe { (f.get_directional_derivative.unwrap())(i.c, &unknown, 1, &known, 1, &1e308, out.as_mut_ptr()) };
    assert_eq!(s, ERROR, "a huge seed overflows: {}", out[0]);
    let msg = log.last_error().unwrap();
    assert!(msg.contains("fmi2GetDirectionalDerivative") && msg.contains("der(v_y)"), "{msg}");
    assert_eq!(i.reset(), OK);
}

#[test]
fn the_stable_substep_keeps_coasting_dissipative_over_random_vehicles() {
    use nigel_vehicle::dynamics::rk4_step;
    // Random vehicles (mass, inertia, stiffness, fade speed, friction up to the maximum),
    // slow random sliding states (inside the fade zone, where the tires are stiffest):
    // with the stability-limited step no coasting step may add energy.
    let mut seed = 0x5eed_u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut cases = 0;
    for _ in 0..300 {
        let mut p = VehicleParams::table2();
        p.m *= 0.3 + 2.0 * rnd();
        p.i_z *= 0.3 + 2.0 * rnd();
        p.c = [0, 1, 2, 3].map(|_| 22.4768 * (0.2 + 3.0 * rnd()));
        p.v_fade = 0.005 + 0.05 * rnd();
        let mut u = Inputs::<f64>::coasting(0.0);
        u.mu = [0, 1, 2, 3].map(|_| nigel_plant::MU_MAX * rnd());
        u.delta = [0, 1, 2, 3].map(|_| (rnd() - 0.5) * 3.0);
        let h = stable_rk4_step(&p, &u);
        let mut s = [0.0; N_STATES];
        s[idx::V_X] = (rnd() - 0.5) * 2.0 * p.v_fade;
        s[idx::V_Y] = (rnd() - 0.5) * 2.0 * p.v_fade;
        s[idx::YAW_RATE] = (rnd() - 0.5) * 2.0;
        let energy = |s: &State<f64>| {
            0.5 * p.m * (s[idx::V_X].powi(2) + s[idx::V_Y].powi(2)) + 0.5 * p.i_z * s[idx::YAW_RATE].powi(2)
        };
        let mut e = energy(&s);
        for k in 0..400 {
            s = rk4_step(&p, &s, &u, h);
            let next = energy(&s);
            assert!(next <= e * (1.0 + 1e-9) + 1e-300, "case {cases}, step {k}: {e} -> {next} (h = {h})");
            e = next;
        }
        cases += 1;
    }
    assert_eq!(cases, 300);
}

/// The initial body state is given by the fixed parameters `x_start .. yaw_rate_start` (a
/// binding of an SSP applies to parameters and inputs only, in libcosim); the states are
/// outputs with `initial="calculated"`: not settable before initialization, equal to their
/// `*_start` from instantiation on, free to move after it, restored from a saved FMU state
/// (not from the start parameters).
#[test]
fn initial_state_comes_from_the_start_parameters() {
    use model_description::{Initial, VariableType};
    let md = &fmu().description;
    let starts: Vec<String> = BODY.iter().map(|n| format!("{n}_start")).collect();
    for (state, start) in BODY.iter().zip(&starts) {
        let s = md.variable(state).unwrap();
        assert_eq!((s.causality, s.initial), (Causality::Output, Some(Initial::Calculated)), "{state}");
        assert!(matches!(s.variable_type, VariableType::Real { start: None, .. }), "{state} has no start value");
        let p = md.variable(start).unwrap();
        assert_eq!((p.causality, p.initial), (Causality::Parameter, Some(Initial::Exact)), "{start}");
        assert!(matches!(p.variable_type, VariableType::Real { start: Some(0.0), .. }), "{start} starts at 0");
        assert_eq!(p.variable_type.unit(), s.variable_type.unit(), "{start} has the unit of {state}");
    }
    let values = [1.5, -2.0, 0.3, 0.35, 0.01, -0.2];
    let starts: Vec<&str> = starts.iter().map(String::as_str).collect();
    let (i, log) = fmu().instantiate("starts", CO_SIMULATION, fmu().guid());
    let i = i.unwrap();
    // the state itself is calculated: refused, naming it
    assert_eq!(i.set_real(&vrs(&["v_x"]), &[0.35]), ERROR);
    assert!(log.last_error().unwrap().contains("v_x"), "{:?}", log.last_error());
    assert_eq!(i.reset(), OK);
    assert_eq!(i.set_real(&vrs(&starts), &values), OK);
    assert_eq!(i.setup(0.0), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.get_real(&vrs(&BODY)).unwrap(), values, "during initialization");
    assert_eq!(i.exit_init(), OK);
    assert_eq!(i.get_real(&vrs(&BODY)).unwrap(), values, "after initialization");
    // the dynamics from there are the model's from that state, unchanged
    let p = VehicleParams::table2();
    let u = Inputs::coasting(0.4);
    let mut s: State<f64> = [0.0; N_STATES];
    s[..6].copy_from_slice(&values);
    for k in 0..100 {
        assert_eq!(i.do_step(k as f64 * 1e-3, 1e-3), OK);
        let h = fmu_plant_substep(&p, &u);
        s = nigel_vehicle::integrate(&p, &s, &u, 1e-3, h);
    }
    let body = i.get_real(&vrs(&BODY)).unwrap();
    assert_eq!(body, s[..6].to_vec(), "the plant's own RK4 from the start state, bit for bit");
    assert_eq!(i.get_real(&vrs(&starts)).unwrap(), values, "the start parameters stay");
    // a saved FMU state restores the states, not the start values
    let f = i.f();
    let mut saved: *mut c_void = null_mut();
    unsafe { assert_eq!((f.get_fmu_state.unwrap())(i.c, &mut saved), OK) };
    assert_eq!(i.do_step(0.1, 1e-3), OK);
    unsafe { assert_eq!((f.set_fmu_state.unwrap())(i.c, saved), OK) };
    assert_eq!(i.get_real(&vrs(&BODY)).unwrap(), body);
    let bytes = unsafe {
        let mut size = 0;
        assert_eq!((f.serialized_fmu_state_size.unwrap())(i.c, saved, &mut size), OK);
        let mut b = vec![0u8; size];
        assert_eq!((f.serialize_fmu_state.unwrap())(i.c, saved, b.as_mut_ptr() as *mut c_char, size), OK);
        assert_eq!((f.free_fmu_state.unwrap())(i.c, &mut saved), OK);
        b
    };
    let (j, log) = fmu().instantiate("restored", CO_SIMULATION, fmu().guid());
    let j = j.unwrap();
    j.initialize();
    let mut restored: *mut c_void = null_mut();
    unsafe {
        assert_eq!(
            (f.deserialize_fmu_state.unwrap())(j.c, bytes.as_ptr() as *const c_char, bytes.len(), &mut restored),
            OK
        );
        assert_eq!((f.set_fmu_state.unwrap())(j.c, restored), OK);
        assert_eq!((f.free_fmu_state.unwrap())(j.c, &mut restored), OK);
    }
    assert_eq!(j.get_real(&vrs(&BODY)).unwrap(), body, "restored into a fresh instance");
    assert_eq!(j.get_real(&vrs(&starts)).unwrap(), values);
    // a fixed parameter after initialization: refused, naming it
    assert_eq!(j.set_real(&vrs(&["v_x_start"]), &[1.0]), ERROR);
    assert!(log.last_error().unwrap().contains("v_x_start"), "{:?}", log.last_error());
}

fn fmu_plant_substep(p: &VehicleParams, u: &Inputs<f64>) -> f64 {
    nigel_plant::DEFAULT_CS_SUBSTEP_MAX.min(stable_rk4_step(p, u))
}

/// The InitialUnknowns depend only on what is known at initialization (FMI 2.0 section
/// 2.2.8: inputs and variables with initial="exact"): the calculated body states on their
/// `*_start` parameters, not on themselves; the derivatives not on the calculated states.
#[test]
fn initial_unknowns_depend_only_on_initialization_knowns() {
    let md = &fmu().description;
    let var = |index: u32| &md.model_variables[index as usize - 1];
    let index_of = |name: &str| md.model_variables.iter().position(|v| v.name == name).unwrap() as u32 + 1;
    assert!(!md.model_structure.initial_unknowns.is_empty());
    for u in &md.model_structure.initial_unknowns {
        let deps = u.dependencies.as_ref().expect("declared dependencies");
        for &d in deps {
            let k = var(d);
            assert!(
                k.causality == Causality::Input || k.effective_initial() == Some(model_description::Initial::Exact),
                "{} depends on {} at initialization",
                var(u.index).name,
                k.name
            );
        }
    }
    for state in BODY {
        let u = md.model_structure.initial_unknowns.iter().find(|u| u.index == index_of(state)).unwrap();
        let deps = u.dependencies.as_ref().unwrap();
        assert!(deps.contains(&index_of(&format!("{state}_start"))), "{state}");
        assert!(!deps.contains(&index_of(state)), "{state} on itself");
    }
}

/// In Initialization Mode the exact start values are knowns (FMI 2.0 section 2.2.8): the
/// directional derivatives with respect to them go through the initial-state calculation
/// (the state is its start value) and agree with central differences of the InitialUnknowns
/// (the derivatives, whose dependence on the state is smooth at this point).
#[test]
fn initialization_mode_directional_derivatives_with_respect_to_the_start_values() {
    let (i, log) = fmu().instantiate("dd-init", CO_SIMULATION, fmu().guid());
    let i = i.unwrap();
    let starts = ["v_x_start", "v_y_start", "yaw_rate_start", "psi_start"];
    let point = [0.35, 0.02, 0.4, 0.3];
    assert_eq!(i.setup(0.0), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.set_real(&vrs(&starts), &point), OK);
    let unknowns = vrs(&["der(x)", "der(y)", "der(v_x)", "der(v_y)", "der(yaw_rate)", "v_y"]);
    for (k, start) in starts.iter().enumerate() {
        let known = fmu().vr(start);
        let (s, exact) = i.directional_derivative(&unknowns, known);
        assert_eq!(s, OK, "{start}: {:?}", log.last_error());
        // central differences, h = 1e-6: truncation O(h^2 f''') ~ 1e-10 relative on these
        // smooth terms, rounding O(eps / h) ~ 1e-10; 1e-6 relative (+1e-8 absolute) holds
        // on any x86-64 libm
        let h = 1e-6;
        let at = |x: f64| {
            let mut p = point;
            p[k] = x;
            assert_eq!(i.set_real(&vrs(&starts), &p), OK);
            i.get_real(&unknowns).unwrap()
        };
        let (up, down) = (at(point[k] + h), at(point[k] - h));
        assert_eq!(i.set_real(&vrs(&starts), &point), OK);
        let mut nonzero = 0;
        for (j, e) in exact.iter().enumerate() {
            let fd = (up[j] - down[j]) / (2.0 * h);
            assert!((e - fd).abs() <= 1e-6 * fd.abs() + 1e-8, "d unknown {j} / d {start}: {e} vs {fd}");
            nonzero += (*e != 0.0) as usize;
        }
        assert!(nonzero > 0, "{start} moves something");
    }
}

/// The other exact knowns of Initialization Mode, the parameters: the directional
/// derivatives (dual numbers through the right-hand side, the parameters as dual numbers)
/// agree with central differences for every continuous parameter, with the real-fidelity
/// switches on (servo, motor limit, friction circle) at a point inside their smooth regions
/// (the servo at its rate limit, the drive inside the friction circle, the wheels below the
/// motor taper). After initialization a parameter is no known: refused, naming it.
#[test]
fn initialization_mode_directional_derivatives_with_respect_to_the_parameters() {
    let (i, log) = fmu().instantiate("dd-params", CO_SIMULATION, fmu().guid());
    let i = i.unwrap();
    let f = i.f();
    assert_eq!(i.setup(0.0), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.set_boolean(&vrs(&["friction_circle", "steering_servo", "motor_speed_limit"]), &[true; 3]), OK);
    let inputs =
        ["delta_fl", "delta_fr", "delta_rl", "delta_rr", "tau_fl", "tau_fr", "tau_rl", "tau_rr", "mu_fl", "mu_rr"];
    let values = [0.2, 0.15, -0.05, 0.0, 0.004, 0.004, 0.003, 0.003, 0.6, 0.5];
    assert_eq!(i.set_real(&vrs(&inputs), &values), OK);
    assert_eq!(i.set_real(&vrs(&["v_x_start", "v_y_start", "yaw_rate_start"]), &[0.35, 0.02, 0.4]), OK);
    // delta_max starts at its maximum pi/2, where p + h would be refused
    assert_eq!(i.set_real(&vrs(&["delta_max"]), &[1.0]), OK);
    let parameters = [
        "m",
        "I_z",
        "l_f",
        "l_r",
        "track",
        "r_wheel",
        "c_fl",
        "c_fr",
        "c_rl",
        "c_rr",
        "g",
        "v_fade",
        "delta_max",
        "servo_time_constant",
        "servo_rate_max",
        "wheel_speed_max",
        "motor_taper",
        "cs_substep_max",
    ];
    let unknowns = vrs(&[
        "der(v_x)",
        "der(v_y)",
        "der(yaw_rate)",
        "der(servo_angle_fl)",
        "lateral_accel",
        "slip_angle_fl",
        "force_lat_fl",
        "force_lat_rr",
        "force_drive_fl",
    ]);
    let mut moved = std::collections::BTreeSet::new();
    for name in parameters {
        let known = fmu().vr(name);
        let p0 = i.get_real(&[known]).unwrap()[0];
        let (s, exact) = i.directional_derivative(&unknowns, known);
        assert_eq!(s, OK, "{name}: {:?}", log.last_error());
        // central differences with h = 1e-6 |p|: truncation O(h^2 f''') is about 1e-12 of
        // the derivative's scale on these smooth terms; rounding is eps |f| / h, at most
        // 1e-8 here (|f| < 10, |p| > 1e-3): 1e-6 relative plus 1e-7 absolute holds on any
        // x86-64 libm
        let h = 1e-6 * p0.abs();
        let at = |x: f64| {
            assert_eq!(i.set_real(&[known], &[x]), OK, "{name}");
            i.get_real(&unknowns).unwrap()
        };
        let (up, down) = (at(p0 + h), at(p0 - h));
        assert_eq!(i.set_real(&[known], &[p0]), OK);
        for (j, e) in exact.iter().enumerate() {
            let fd = (up[j] - down[j]) / (2.0 * h);
            assert!((e - fd).abs() <= 1e-6 * fd.abs() + 1e-7, "d unknown {j} / d {name}: {e} vs {fd}");
            if *e != 0.0 {
                moved.insert(name);
            }
        }
    }
    // the parameters of the terms active at this point move something (the servo runs at
    // its rate limit: 0.2 rad from its angle 0 is more than servo_rate_max servo_time_constant);
    // the limits not reached and the integrator's sub-step do not
    for name in ["m", "I_z", "l_f", "l_r", "track", "r_wheel", "c_fl", "c_rr", "servo_rate_max"] {
        assert!(moved.contains(name), "{name} moves nothing: {moved:?}");
    }
    for name in ["delta_max", "servo_time_constant", "wheel_speed_max", "motor_taper", "cs_substep_max", "g", "v_fade"]
    {
        assert!(!moved.contains(name), "{name} moves something: {moved:?}");
    }
    assert_eq!(i.exit_init(), OK);
    let (unknown, param) = (fmu().vr("der(v_y)"), fmu().vr("l_f"));
    let mut out = [0.0];
    let s = unsafe { (f.get_directional_derivative.unwrap())(i.c, &unknown, 1, &param, 1, &1.0, out.as_mut_ptr()) };
    assert_eq!(s, ERROR);
    let msg = log.last_error().unwrap();
    assert!(msg.contains("fmi2GetDirectionalDerivative") && msg.contains("l_f"), "{msg}");
    assert!(!msg.contains("Param(") && !msg.contains("StateStart("), "{msg}");
}

//! The plant FMU's C ABI, abused on purpose through a real `dlopen` of the built `.fmu`:
//! null pointers, illegal call orders, NaN, wrong GUID, hostile FMU states, many instances.

use std::ptr::{null, null_mut};
use std::sync::OnceLock;

use nigel_integration_tests::{built_fmu, Fmu, Instance, CO_SIMULATION, DISCARD, ERROR, MODEL_EXCHANGE, OK, SYMBOLS};

fn fmu() -> &'static Fmu {
    static FMU: OnceLock<Fmu> = OnceLock::new();
    FMU.get_or_init(|| Fmu::load(&built_fmu("nigel_plant").unwrap()).unwrap())
}

fn cs() -> (Instance<'static>, Box<nigel_integration_tests::Log>) {
    let (i, log) = fmu().instantiate("cs", CO_SIMULATION, fmu().guid());
    (i.expect("instantiate CS"), log)
}

#[test]
fn all_44_functions_resolve_and_report_the_version() {
    assert_eq!(SYMBOLS.len(), 44);
    let f = &fmu().functions;
    let version = unsafe { std::ffi::CStr::from_ptr((f.get_version)()) };
    assert_eq!(version.to_str().unwrap(), "2.0");
    let platform = unsafe { std::ffi::CStr::from_ptr((f.get_types_platform.unwrap())()) };
    assert_eq!(platform.to_str().unwrap(), "default");
}

#[test]
fn wrong_guid_is_refused_with_a_logged_reason() {
    let (i, log) = fmu().instantiate("bad", CO_SIMULATION, "{00000000-0000-0000-0000-000000000000}");
    assert!(i.is_none());
    let msg = log.last_error().expect("an error was logged");
    assert!(msg.contains("fmi2Instantiate") && msg.contains("fmuGUID"), "{msg}");
}

#[test]
fn instantiate_refuses_null_callbacks_names_and_bad_types() {
    let f = &fmu().functions;
    let guid = std::ffi::CString::new(fmu().guid()).unwrap();
    let name = c"x";
    // no callback struct at all: NULL, nothing to log to
    let c = unsafe { (f.instantiate)(name.as_ptr(), CO_SIMULATION, guid.as_ptr(), null(), null(), 0, 0) };
    assert!(c.is_null());
    let (i, log) = fmu().instantiate("", CO_SIMULATION, fmu().guid());
    assert!(i.is_none());
    assert!(log.last_error().unwrap().contains("instanceName"));
    let (i, log) = fmu().instantiate("x", 7, fmu().guid());
    assert!(i.is_none());
    assert!(log.last_error().unwrap().contains("fmuType"));
}

#[test]
fn a_null_component_gives_error_everywhere_and_never_crashes() {
    let f = &fmu().functions;
    let c = null_mut();
    let mut x = [0.0; 10];
    let vr = [0u32];
    unsafe {
        assert_eq!((f.setup_experiment)(c, 0, 0.0, 0.0, 0, 0.0), ERROR);
        assert_eq!((f.enter_initialization_mode)(c), ERROR);
        assert_eq!((f.exit_initialization_mode)(c), ERROR);
        assert_eq!((f.terminate)(c), ERROR);
        assert_eq!((f.reset.unwrap())(c), ERROR);
        assert_eq!((f.get_real)(c, vr.as_ptr(), 1, x.as_mut_ptr()), ERROR);
        assert_eq!((f.set_real)(c, vr.as_ptr(), 1, x.as_ptr()), ERROR);
        assert_eq!((f.do_step.unwrap())(c, 0.0, 1e-3, 1), ERROR);
        assert_eq!((f.get_derivatives.unwrap())(c, x.as_mut_ptr(), 10), ERROR);
        assert_eq!((f.set_time.unwrap())(c, 0.0), ERROR);
        assert_eq!((f.get_fmu_state.unwrap())(c, null_mut()), ERROR);
        (f.free_instance)(c);
    }
}

#[test]
fn null_arrays_unknown_references_and_wrong_sizes_are_errors_with_messages() {
    let (i, log) = cs();
    i.initialize();
    let f = i.f();
    unsafe {
        assert_eq!((f.get_real)(i.c, null(), 2, [0.0; 2].as_mut_ptr()), ERROR);
    }
    assert!(log.last_error().unwrap().contains("vr is NULL"), "{:?}", log.last_error());
    assert_eq!(i.reset(), OK);
    i.initialize();
    assert_eq!(i.get_real(&[9999]), Err(ERROR));
    assert!(log.last_error().unwrap().contains("unknown Real value reference 9999"));
    assert_eq!(i.reset(), OK);
    i.initialize();
    let s = unsafe { (f.get_boolean)(i.c, [77u32].as_ptr(), 1, [0].as_mut_ptr()) };
    assert_eq!(s, ERROR);
}

#[test]
fn illegal_call_orders_are_refused_and_only_reset_recovers() {
    let (i, log) = cs();
    let x = fmu().vr("x");
    // before initialization mode no values can be read
    assert_eq!(i.get_real(&[x]), Err(ERROR));
    assert!(log.last_error().unwrap().contains("not allowed in state Instantiated"));
    // in the error state, nothing but reset/free (and gets) works
    assert_eq!(i.enter_init(), ERROR);
    assert_eq!(i.reset(), OK);
    assert_eq!(i.do_step(0.0, 1e-3), ERROR, "doStep before initialization");
    assert_eq!(i.reset(), OK);
    i.initialize();
    assert_eq!(i.enter_init(), ERROR, "enterInitializationMode twice");
    assert_eq!(i.reset(), OK);
    i.initialize();
    assert_eq!(i.do_step(0.0, 0.0), ERROR, "h = 0");
    assert!(log.last_error().unwrap().contains("communicationStepSize"));
    assert_eq!(i.reset(), OK);
    i.initialize();
    assert_eq!(i.do_step(0.0, -1e-3), ERROR, "h < 0");
    assert_eq!(i.reset(), OK);
    i.initialize();
    assert_eq!(i.do_step(0.0, 1e9), DISCARD, "a step that would take 2e12 sub-steps is discarded, not run");
    assert!(log.last_error().unwrap().contains("take shorter communication steps"));
    assert_eq!(i.reset(), OK);
    // a vanishing sub-step is refused at the set (its declared minimum is 1 us) ...
    assert_eq!(i.set_real(&[fmu().vr("cs_substep_max")], &[1e-300]), ERROR);
    let e = log.last_error().unwrap();
    assert!(e.contains("fmi2SetReal") && e.contains("cs_substep_max") && e.contains("below its minimum"), "{e}");
    assert_eq!(i.reset(), OK);
    // ... and at the smallest one, a step of more than 10^6 sub-steps is discarded before it starts
    assert_eq!(i.set_real(&[fmu().vr("cs_substep_max")], &[1e-6]), OK);
    i.initialize();
    assert_eq!(i.do_step(0.0, 1e-3), OK, "1000 sub-steps");
    assert_eq!(i.do_step(1e-3, 10.0), DISCARD, "10^7 sub-steps");
    assert!(log.last_error().unwrap().contains("take shorter communication steps"));
    assert_eq!(i.reset(), OK);
    i.initialize();
    assert_eq!(i.do_step(0.0, 1e-3), OK);
    assert_eq!(i.do_step(0.5, 1e-3), ERROR, "start time is not the previous end time");
    assert!(log.last_error().unwrap().contains("not the end of the previous step"));
    assert_eq!(i.reset(), OK);
    i.initialize();
    assert_eq!(i.do_step(0.0, 1e-3), OK);
    assert_eq!(i.terminate(), OK);
    assert_eq!(i.do_step(1e-3, 1e-3), ERROR, "doStep after terminate");
    assert!(log.last_error().unwrap().contains("fmi2DoStep"));
    // Model Exchange calls on a Co-Simulation instance
    assert_eq!(i.reset(), OK);
    i.initialize();
    assert_eq!(unsafe { (i.f().enter_continuous_time_mode.unwrap())(i.c) }, ERROR);
    let msg = log.last_error().unwrap();
    assert!(
        msg.contains("fmi2EnterContinuousTimeMode: not available: this instance was created for CoSimulation"),
        "{msg}"
    );
    // a fixed parameter cannot change after initialization
    assert_eq!(i.reset(), OK);
    i.initialize();
    assert_eq!(i.set_real(&[fmu().vr("m")], &[3.0]), ERROR);
    let msg = log.last_error().unwrap();
    assert!(msg.contains("m cannot be set after initialization (a fixed parameter"), "{msg}");
    // after reset the instance runs normally again
    assert_eq!(i.reset(), OK);
    i.initialize();
    assert_eq!(i.do_step(0.0, 1e-3), OK);
}

#[test]
fn nan_and_inf_are_refused_and_not_applied() {
    let (i, log) = cs();
    i.initialize();
    let delta = fmu().vr("delta_fl");
    let tau = fmu().vr("tau_fl");
    assert_eq!(i.set_real(&[delta], &[0.1]), OK);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        // the good value in the same call is not applied either (all or nothing)
        assert_eq!(i.set_real(&[tau, delta], &[0.01, bad]), ERROR);
        assert!(log.last_error().unwrap().contains("delta_fl"));
        assert_eq!(
            i.get_real(&[delta, tau]).unwrap(),
            vec![0.1, 0.0],
            "values unchanged (read in the error state for diagnosis)"
        );
        assert_eq!(i.reset(), OK);
        i.initialize();
        assert_eq!(i.set_real(&[delta], &[0.1]), OK);
    }
}

#[test]
fn impossible_parameters_give_error_with_the_reason() {
    for (name, value, expect) in
        [("m", -1.0, "m = -1"), ("l_f", 0.0, "l_f"), ("c_rr", -5.0, "c_rr"), ("delta_max", 4.0, "delta_max")]
    {
        let (i, log) = cs();
        assert_eq!(i.set_real(&[fmu().vr(name)], &[value]), ERROR, "{name}");
        let msg = log.last_error().unwrap();
        assert!(msg.contains(expect), "{msg}");
    }
    let (i, log) = cs();
    i.initialize();
    assert_eq!(i.set_real(&[fmu().vr("mu_rl")], &[-0.1]), ERROR);
    let msg = log.last_error().unwrap();
    assert!(msg.contains("mu_rl = -0.1 refused: below its minimum 0"), "{msg}");
}

#[test]
fn co_simulation_agrees_exactly_with_the_in_process_model() {
    use nigel_vehicle::{integrate, Inputs, VehicleParams};
    let (i, _log) = cs();
    let names = ["v_x_start", "delta_fl", "delta_fr", "delta_rl", "delta_rr", "tau_fl", "mu_rr"];
    let vrs: Vec<u32> = names.iter().map(|n| fmu().vr(n)).collect();
    assert_eq!(i.setup(0.0), OK);
    assert_eq!(i.set_real(&vrs[..1], &[0.35]), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.exit_init(), OK);
    let p = VehicleParams::table2();
    let mut s = nigel_vehicle::straight_running(0.35);
    let mut u = Inputs::coasting(0.4);
    let h = 1e-3;
    for k in 0..2000 {
        let t = k as f64 * h;
        let steer = if t >= 0.5 { 0.3 } else { 0.0 };
        u.delta = [steer, steer, -steer, -steer];
        u.tau[0] = 0.01;
        u.mu[3] = if t >= 1.0 { 0.8 } else { 0.4 };
        assert_eq!(i.set_real(&vrs[1..], &[steer, steer, -steer, -steer, 0.01, u.mu[3]]), OK);
        assert_eq!(i.do_step(t, h), OK);
        s = integrate(&p, &s, &u, h, fmu_plant_substep(&p, &u));
    }
    let state_vrs: Vec<u32> = ["x", "y", "psi", "v_x", "v_y", "yaw_rate"].iter().map(|n| fmu().vr(n)).collect();
    let got = i.get_real(&state_vrs).unwrap();
    assert_eq!(got, s[..6].to_vec(), "bit-identical to nigel_vehicle::integrate");
    assert!(got[5] > 0.1, "the car turns left: yaw rate {}", got[5]);
}

/// The plant's sub-step rule, restated: the default maximum or the tires' stability limit.
fn fmu_plant_substep(p: &nigel_vehicle::VehicleParams, u: &nigel_vehicle::Inputs<f64>) -> f64 {
    nigel_plant::DEFAULT_CS_SUBSTEP_MAX.min(nigel_vehicle::dynamics::stable_rk4_step(p, u))
}

#[test]
fn every_declared_variable_answers_at_its_value_reference() {
    // The GUID check proves the XML and the binary come from one declaration; this checks
    // the value references one by one: parameters and inputs read back what was set,
    // calculated outputs equal the in-process model.
    use model_description::{Causality, VariableType};
    let (i, _log) = cs();
    assert_eq!(i.setup(0.0), OK);
    assert_eq!(i.enter_init(), OK);
    let md = &fmu().description;
    for (k, v) in md.model_variables.iter().enumerate() {
        if let VariableType::Real { start: Some(start), .. } = v.variable_type {
            if matches!(v.causality, Causality::Input | Causality::Parameter | Causality::Output | Causality::Local) {
                let value = if start == 0.0 { 1e-3 * (k as f64 + 1.0) } else { start * 0.99 };
                assert_eq!(i.set_real(&[v.value_reference], &[value]), OK, "{}", v.name);
                assert_eq!(i.get_real(&[v.value_reference]).unwrap(), vec![value], "{}", v.name);
            }
        }
    }
    assert_eq!(i.exit_init(), OK);
    // outputs against the in-process model at the same point
    let mut plant = nigel_plant::Plant::default();
    use fmi_export::Model;
    for v in &md.model_variables {
        if let VariableType::Real { start: Some(_), .. } = v.variable_type {
            let value = i.get_real(&[v.value_reference]).unwrap()[0];
            let row = nigel_plant::Plant::declaration().row(fmi_export::BaseType::Real, v.value_reference).unwrap();
            plant.set_real(nigel_plant::Plant::declaration().variable(row).binding, value).unwrap();
        }
    }
    for v in md.model_variables.iter().filter(|v| v.causality == Causality::Output) {
        let row = nigel_plant::Plant::declaration().row(fmi_export::BaseType::Real, v.value_reference).unwrap();
        let expected = plant.get_real(nigel_plant::Plant::declaration().variable(row).binding).unwrap();
        assert_eq!(i.get_real(&[v.value_reference]).unwrap()[0], expected, "{}", v.name);
    }
}

#[test]
fn fmu_state_round_trips_through_bytes_bit_identically_and_refuses_garbage() {
    let (i, log) = cs();
    let f = i.f();
    i.initialize();
    let steer = fmu().vr("delta_fl");
    let y = fmu().vr("y");
    assert_eq!(i.set_real(&[fmu().vr("tau_fl")], &[0.02]), OK);
    for k in 0..300 {
        assert_eq!(i.do_step(k as f64 * 1e-3, 1e-3), OK);
    }
    let mut state = null_mut();
    assert_eq!(unsafe { (f.get_fmu_state.unwrap())(i.c, &mut state) }, OK);
    let mut size = 0usize;
    assert_eq!(unsafe { (f.serialized_fmu_state_size.unwrap())(i.c, state, &mut size) }, OK);
    let mut bytes = vec![0i8; size];
    assert_eq!(unsafe { (f.serialize_fmu_state.unwrap())(i.c, state, bytes.as_mut_ptr(), size) }, OK);
    let run = |inst: &Instance, from: usize| -> Vec<f64> {
        let mut out = vec![];
        for k in from..from + 500 {
            assert_eq!(inst.set_real(&[steer], &[0.2 * (k as f64 * 0.01).sin()]), OK);
            assert_eq!(inst.do_step(k as f64 * 1e-3, 1e-3), OK);
            out.push(inst.get_real(&[y]).unwrap()[0]);
        }
        out
    };
    let first = run(&i, 300);
    // restore from the bytes into a brand-new instance
    let (j, _log2) = cs();
    let mut restored = null_mut();
    assert_eq!(unsafe { (f.deserialize_fmu_state.unwrap())(j.c, bytes.as_ptr(), size, &mut restored) }, OK);
    assert_eq!(unsafe { (f.set_fmu_state.unwrap())(j.c, restored) }, OK);
    let second = run(&j, 300);
    assert_eq!(first, second, "bit-identical continuation");
    // and in the same instance, through the in-memory state
    assert_eq!(unsafe { (f.set_fmu_state.unwrap())(i.c, state) }, OK);
    assert_eq!(run(&i, 300), first);
    unsafe {
        assert_eq!((f.free_fmu_state.unwrap())(i.c, &mut state), OK);
        assert!(state.is_null());
        assert_eq!((f.free_fmu_state.unwrap())(j.c, &mut restored), OK);
    }
    // hostile bytes: truncated, flipped magic, wrong length, random
    let mut junk = null_mut();
    for bad in [&bytes[..size / 2], &bytes[..3], &[0i8; 64][..]] {
        assert_eq!(unsafe { (f.deserialize_fmu_state.unwrap())(i.c, bad.as_ptr(), bad.len(), &mut junk) }, ERROR);
        assert!(junk.is_null());
        assert_eq!(i.reset(), OK);
    }
    let mut flipped = bytes.clone();
    flipped[20] ^= 0x55; // inside the GUID
    assert_eq!(unsafe { (f.deserialize_fmu_state.unwrap())(i.c, flipped.as_ptr(), size, &mut junk) }, ERROR);
    assert!(log.last_error().unwrap().contains("fmi2DeSerializeFMUstate"));
    assert!(junk.is_null());
}

#[test]
fn instances_in_parallel_threads_are_independent() {
    let simulate = |steer: f64| -> Vec<f64> {
        let (i, _log) = cs();
        let vrs: Vec<u32> = ["delta_fl", "delta_fr", "v_x_start"].iter().map(|n| fmu().vr(n)).collect();
        assert_eq!(i.set_real(&vrs, &[steer, steer, 0.35]), OK);
        i.initialize();
        for k in 0..3000 {
            assert_eq!(i.do_step(k as f64 * 1e-3, 1e-3), OK);
        }
        i.get_real(&[fmu().vr("x"), fmu().vr("y"), fmu().vr("psi")]).unwrap()
    };
    let steers = [0.0, 0.1, -0.2, 0.3, 0.05, -0.05, 0.25, -0.3];
    let sequential: Vec<Vec<f64>> = steers.iter().map(|&s| simulate(s)).collect();
    let parallel: Vec<Vec<f64>> = std::thread::scope(|scope| {
        let handles: Vec<_> = steers.iter().map(|&s| scope.spawn(move || simulate(s))).collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(sequential, parallel);
    assert!(sequential[1][2] > 0.0 && sequential[2][2] < 0.0);
}

#[test]
fn model_exchange_walks_the_state_machine_and_derivatives_match_the_model() {
    let (i, log) = fmu().instantiate("me", MODEL_EXCHANGE, fmu().guid());
    let i = i.unwrap();
    let f = i.f();
    assert_eq!(i.set_real(&[fmu().vr("v_x_start"), fmu().vr("delta_fl")], &[0.35, 0.1]), OK);
    i.initialize();
    let mut info = nigel_integration_tests::EventInfo::default();
    unsafe {
        assert_eq!((f.new_discrete_states.unwrap())(i.c, &mut info), OK);
        assert_eq!(info.new_discrete_states_needed, 0);
        assert_eq!((f.enter_continuous_time_mode.unwrap())(i.c), OK);
        let mut x = [0.0; 10];
        let mut dx = [0.0; 10];
        assert_eq!((f.get_continuous_states.unwrap())(i.c, x.as_mut_ptr(), 10), OK);
        assert_eq!(x[3], 0.35);
        assert_eq!((f.get_derivatives.unwrap())(i.c, dx.as_mut_ptr(), 10), OK);
        let mut u = nigel_vehicle::Inputs::coasting(0.4);
        u.delta[0] = 0.1;
        let expected = nigel_vehicle::evaluate(&nigel_vehicle::VehicleParams::table2(), &x, &u).derivatives;
        assert_eq!(dx, expected);
        assert_eq!((f.get_derivatives.unwrap())(i.c, dx.as_mut_ptr(), 9), ERROR, "wrong nx");
        assert!(log.last_error().unwrap().contains("nx = 9"));
        assert_eq!(i.reset(), OK);
        i.initialize();
        assert_eq!((f.enter_continuous_time_mode.unwrap())(i.c), OK);
        // a state so large that the right-hand side overflows: the derivatives are refused
        x[3] = 1e300;
        x[5] = 1e300;
        assert_eq!((f.set_continuous_states.unwrap())(i.c, x.as_ptr(), 10), OK);
        assert_eq!((f.get_derivatives.unwrap())(i.c, dx.as_mut_ptr(), 10), ERROR);
        assert!(log.last_error().unwrap().contains("evaluated to"), "{:?}", log.last_error());
        assert_eq!(i.reset(), OK);
        i.initialize();
        assert_eq!((f.enter_continuous_time_mode.unwrap())(i.c), OK);
        x[4] = f64::NAN;
        assert_eq!((f.set_continuous_states.unwrap())(i.c, x.as_ptr(), 10), ERROR);
        assert_eq!(i.reset(), OK);
        i.initialize();
        assert_eq!(i.do_step(0.0, 1e-3), ERROR, "doStep on a Model Exchange instance");
    }
}

#[test]
fn declared_dependencies_equal_the_numerical_sparsity() {
    use model_description::Causality;
    // At random points (every combination of the fidelity switches), the nonzero partial derivatives
    // of each output and state derivative are exactly its declared dependencies.
    let md = &fmu().description;
    let (i, _log) = fmu().instantiate("me", MODEL_EXCHANGE, fmu().guid());
    let i = i.unwrap();
    let switches: Vec<u32> =
        ["friction_circle", "steering_servo", "motor_speed_limit"].iter().map(|n| fmu().vr(n)).collect();
    assert_eq!(i.set_boolean(&switches, &[true, true, true]), OK);
    let knowns: Vec<(u32, u32)> = md
        .model_variables
        .iter()
        .enumerate()
        .filter(|(k, v)| v.causality == Causality::Input || md.states().contains(&(*k as u32 + 1)))
        .map(|(k, v)| (k as u32 + 1, v.value_reference))
        .collect();
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    // the body states are calculated from their parameters `*_start` (set those); the servo
    // angles and the inputs are set themselves
    let kv: Vec<u32> = knowns
        .iter()
        .map(|&(index, vr)| {
            let name = &md.model_variables[index as usize - 1].name;
            md.variable(&format!("{name}_start")).map_or(vr, |p| p.value_reference)
        })
        .collect();
    // the union of the nonzero partials over a few random points
    let unknowns: Vec<_> = md.model_structure.outputs.iter().chain(&md.model_structure.derivatives).collect();
    let mut measured = vec![std::collections::BTreeSet::new(); unknowns.len()];
    // the structural dependencies are the union over the fidelity switches (with the servo
    // on the outputs see the servo angle, with it off the steering command)
    let configurations = [[true, true, true], [false, false, false], [true, false, true], [false, true, false]];
    for k in 0..16 {
        // torques small enough that the drive force is not always at its friction limit
        // (so that the friction circle couples it to the lateral force)
        let point: Vec<f64> = knowns
            .iter()
            .map(|&(index, _)| {
                let r = rnd();
                if md.model_variables[index as usize - 1].name.starts_with("tau_") {
                    0.005 + 0.03 * r
                } else {
                    0.3 + r * 0.5
                }
            })
            .collect();
        assert_eq!(i.reset(), OK);
        assert_eq!(i.set_boolean(&switches, &configurations[k % 4]), OK);
        assert_eq!(i.setup(0.0), OK);
        assert_eq!(i.enter_init(), OK);
        assert_eq!(i.set_real(&kv, &point), OK);
        for (k, u) in unknowns.iter().enumerate() {
            let uv = md.model_variables[u.index as usize - 1].value_reference;
            for &(index, vr) in &knowns {
                let mut out = [0.0];
                let s =
                    unsafe { (i.f().get_directional_derivative.unwrap())(i.c, &uv, 1, &vr, 1, &1.0, out.as_mut_ptr()) };
                assert_eq!(s, OK);
                if out[0] != 0.0 {
                    measured[k].insert(index);
                }
            }
        }
    }
    let name = |index: u32| md.model_variables[index as usize - 1].name.clone();
    let mut differences = Vec::new();
    let mut checked = 0;
    for (k, u) in unknowns.iter().enumerate() {
        let declared: std::collections::BTreeSet<u32> =
            u.dependencies.clone().expect("dependencies declared").into_iter().collect();
        checked += measured[k].len();
        for missing in measured[k].difference(&declared) {
            differences.push(format!("{} depends on {} but does not declare it", name(u.index), name(*missing)));
        }
        for extra in declared.difference(&measured[k]) {
            differences.push(format!("{} declares {} but does not depend on it", name(u.index), name(*extra)));
        }
    }
    assert!(differences.is_empty(), "{}", differences.join("\n"));
    assert!(checked > 100, "only {checked} nonzero partials seen");
}

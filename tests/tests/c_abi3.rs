//! The FMI 3.0 C ABI of the built plant library (the FMI 2.0 archive's: one library, both
//! generations), abused on purpose through a real `dlopen`: wrong tokens, refused
//! instantiation options, NULL instances and arguments, bad `nValues`, and an FMU state
//! that crosses generations.

use std::ptr::{null, null_mut};
use std::sync::OnceLock;

use nigel_integration_tests::{built_fmu, Fmu, CO_SIMULATION, ERROR, OK};

fn fmu() -> &'static Fmu {
    static FMU: OnceLock<Fmu> = OnceLock::new();
    FMU.get_or_init(|| Fmu::load(&built_fmu("nigel_plant").unwrap()).unwrap())
}

#[test]
fn all_75_functions_resolve_and_report_the_version() {
    let f = &fmu().functions3;
    assert!(f.missing().is_empty(), "{:?}", f.missing());
    let version = unsafe { std::ffi::CStr::from_ptr((f.get_version)()) };
    assert_eq!(version.to_str().unwrap(), "3.0");
}

#[test]
fn wrong_token_and_refused_options_give_null_with_a_logged_reason() {
    let (i, log) = fmu().instantiate3("bad", true, "{00000000-0000-0000-0000-000000000000}");
    assert!(i.is_none());
    let msg = log.0.last_error().expect("an error was logged");
    assert!(msg.starts_with("fmi3InstantiateCoSimulation: instantiationToken"), "{msg}");
    let (i, log) = fmu().instantiate3("bad", false, "");
    assert!(i.is_none());
    assert!(log.0.last_error().unwrap().starts_with("fmi3InstantiateModelExchange"));
    let f = &fmu().functions3;
    let token = std::ffi::CString::new(fmu().guid()).unwrap();
    unsafe {
        // eventModeUsed, required intermediate variables, no logger: NULL, no crash
        let c = (f.instantiate_co_simulation.unwrap())(
            c"x".as_ptr(),
            token.as_ptr(),
            null(),
            0,
            0,
            1,
            0,
            null(),
            0,
            null_mut(),
            None,
            None,
        );
        assert!(c.is_null());
        let vr = [1u32];
        let c = (f.instantiate_co_simulation.unwrap())(
            c"x".as_ptr(),
            token.as_ptr(),
            null(),
            0,
            0,
            0,
            1,
            vr.as_ptr(),
            1,
            null_mut(),
            None,
            None,
        );
        assert!(c.is_null());
        let c = (f.instantiate_scheduled_execution.unwrap())(
            c"x".as_ptr(),
            token.as_ptr(),
            null(),
            0,
            0,
            null_mut(),
            None,
            None,
            None,
            None,
        );
        assert!(c.is_null());
        // NULL name and token
        let c = (f.instantiate_model_exchange.unwrap())(null(), null(), null(), 0, 0, null_mut(), None);
        assert!(c.is_null());
    }
}

#[test]
fn a_null_instance_gives_error_everywhere_and_never_crashes() {
    let (f, c) = (&fmu().functions3, null_mut());
    let (mut x, vr) = ([0.0; 4], [1u32]);
    let (mut b1, mut b2, mut b3, mut t) = (0u8, 0u8, 0u8, 0.0);
    unsafe {
        assert_eq!((f.enter_initialization_mode)(c, 0, 0.0, 0.0, 0, 0.0), ERROR);
        assert_eq!((f.exit_initialization_mode)(c), ERROR);
        assert_eq!((f.get_float64)(c, vr.as_ptr(), 1, x.as_mut_ptr(), 1), ERROR);
        assert_eq!((f.set_float64)(c, vr.as_ptr(), 1, x.as_ptr(), 1), ERROR);
        assert_eq!((f.do_step.unwrap())(c, 0.0, 1e-3, 1, &mut b1, &mut b2, &mut b3, &mut t), ERROR);
        assert_eq!((f.get_continuous_state_derivatives.unwrap())(c, x.as_mut_ptr(), 4), ERROR);
        assert_eq!((f.enter_configuration_mode.unwrap())(c), ERROR);
        assert_eq!((f.terminate)(c), ERROR);
        (f.free_instance)(c);
    }
}

#[test]
fn null_arguments_and_bad_counts_are_errors_naming_the_function() {
    let (i, log) = fmu().instantiate3("args", true, fmu().guid());
    let i = i.unwrap();
    let f = i.f();
    let vr = ["delta_fl", "tau_fl"].map(|n| fmu().description.index_of(n).unwrap());
    let mut x = [0.0; 2];
    unsafe {
        assert_eq!((f.enter_initialization_mode)(i.c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!((f.get_float64)(i.c, vr.as_ptr(), 2, x.as_mut_ptr(), 3), ERROR);
        let msg = log.0.last_error().unwrap();
        assert!(msg.starts_with("fmi3GetFloat64: nValues = 3"), "{msg}");
        assert_eq!((f.reset.unwrap())(i.c), OK);
        assert_eq!((f.enter_initialization_mode)(i.c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!((f.get_float64)(i.c, null(), 2, x.as_mut_ptr(), 2), ERROR);
        assert!(log.0.last_error().unwrap().contains("valueReferences is NULL"));
        assert_eq!((f.reset.unwrap())(i.c), OK);
        assert_eq!((f.enter_initialization_mode)(i.c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!((f.exit_initialization_mode)(i.c), OK);
        let (mut b1, mut b2, mut b3) = (0u8, 0u8, 0u8);
        assert_eq!((f.do_step.unwrap())(i.c, 0.0, 1e-3, 1, &mut b1, &mut b2, &mut b3, null_mut()), ERROR);
        assert!(log.0.last_error().unwrap().starts_with("fmi3DoStep: lastSuccessfulTime is NULL"));
    }
}

/// An FMU state serialized by an FMI 2.0 instance restores into an FMI 3.0 instance of the
/// same library (one format), and the continued runs agree to the bit.
#[test]
fn a_serialized_state_crosses_generations() {
    let (i2, _log2) = fmu().instantiate("two", CO_SIMULATION, fmu().guid());
    let i2 = i2.unwrap();
    i2.initialize();
    let inputs = ["delta_fl", "delta_fr", "tau_fl", "tau_fr"];
    let vr2: Vec<u32> = inputs.iter().map(|n| fmu().vr(n)).collect();
    assert_eq!(i2.set_real(&vr2, &[0.1, 0.1, 0.003, 0.003]), OK);
    assert_eq!(i2.do_step(0.0, 0.05), OK);
    let f2 = i2.f();
    let bytes = unsafe {
        let mut s = null_mut();
        assert_eq!((f2.get_fmu_state.unwrap())(i2.c, &mut s), OK);
        let mut n = 0usize;
        assert_eq!((f2.serialized_fmu_state_size.unwrap())(i2.c, s, &mut n), OK);
        let mut bytes = vec![0u8; n];
        assert_eq!((f2.serialize_fmu_state.unwrap())(i2.c, s, bytes.as_mut_ptr() as *mut std::ffi::c_char, n), OK);
        assert_eq!((f2.free_fmu_state.unwrap())(i2.c, &mut s), OK);
        bytes
    };
    let (i3, log3) = fmu().instantiate3("three", true, fmu().guid());
    let i3 = i3.unwrap();
    let f3 = i3.f();
    unsafe {
        let mut s = null_mut();
        assert_eq!(
            (f3.deserialize_fmu_state.unwrap())(i3.c, bytes.as_ptr(), bytes.len(), &mut s),
            OK,
            "{:?}",
            log3.0.last_error()
        );
        assert_eq!((f3.set_fmu_state.unwrap())(i3.c, s), OK);
        assert_eq!((f3.free_fmu_state.unwrap())(i3.c, &mut s), OK);
        let (mut b1, mut b2, mut b3, mut t) = (0u8, 0u8, 0u8, 0.0);
        assert_eq!((f3.do_step.unwrap())(i3.c, 0.05, 0.05, 1, &mut b1, &mut b2, &mut b3, &mut t), OK);
        assert_eq!(t, 0.1);
    }
    assert_eq!(i2.do_step(0.05, 0.05), OK);
    // FMI 2.0 variable index i is FMI 3.0 value reference i
    let outputs = ["x", "y", "psi", "v_x", "yaw_rate"];
    let two = i2.get_real(&outputs.map(|n| fmu().vr(n))).unwrap();
    let vr3: Vec<u32> = outputs.iter().map(|n| fmu().description.index_of(n).unwrap()).collect();
    let mut three = vec![0.0; vr3.len()];
    unsafe {
        assert_eq!((f3.get_float64)(i3.c, vr3.as_ptr(), vr3.len(), three.as_mut_ptr(), vr3.len()), OK);
        for (a, b) in two.iter().zip(&three) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
        // truncated: refused with the reason
        let mut s = null_mut();
        assert_eq!((f3.deserialize_fmu_state.unwrap())(i3.c, bytes.as_ptr(), bytes.len() / 2, &mut s), ERROR);
        assert!(log3.0.last_error().unwrap().starts_with("fmi3DeserializeFMUState"));
    }
}

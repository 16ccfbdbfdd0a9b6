//! Speed of the plant: the right-hand side, one Co-Simulation `fmi2DoStep` of 1 ms and one
//! Model Exchange `fmi2GetDerivatives`, both through the C ABI entry points of the layer.

use std::ffi::{c_char, c_int, c_void, CString};
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use fmi_export::abi;
use fmi_export::ffi::{Fmi2CallbackFunctions, Fmi2CallbackLogger, Fmi2Status};
use fmi_export::Model;
use nigel_plant::Plant;
use nigel_vehicle::{derivatives_of, Inputs, VehicleParams};

unsafe extern "C" fn silent(_: *mut c_void, _: *const c_char, _: c_int, _: *const c_char, _: *const c_char) {}

fn component(kind: c_int) -> *mut c_void {
    // The logger is never called in these benches (no errors); a non-variadic function
    // stands in for the importer's variadic one.
    let logger: Fmi2CallbackLogger = unsafe { std::mem::transmute(silent as unsafe extern "C" fn(_, _, _, _, _)) };
    let callbacks = Box::leak(Box::new(Fmi2CallbackFunctions {
        logger: Some(logger),
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: std::ptr::null_mut(),
    }));
    let guid = CString::new(Plant::declaration().guid()).unwrap();
    let c = unsafe {
        abi::instantiate::<Plant>(
            fmi_export::Function::Instantiate,
            c"bench".as_ptr(),
            kind,
            guid.as_ptr(),
            std::ptr::null(),
            callbacks,
            0,
            0,
        )
    };
    assert!(!c.is_null());
    let d = Plant::declaration();
    let refs = ["v_x_start", "delta_fl", "delta_fr", "delta_rl", "delta_rr"].map(|n| d.value_reference(n).unwrap());
    let values = [0.35, 0.2, 0.2, -0.2, -0.2];
    unsafe {
        assert_eq!(
            abi::set::<Plant, abi::value::Real>(
                fmi_export::Function::SetReal,
                c,
                refs.as_ptr(),
                refs.len(),
                values.as_ptr()
            ),
            Fmi2Status::Ok
        );
        assert_eq!(
            abi::setup_experiment::<Plant>(fmi_export::Function::SetupExperiment, c, 0, 0.0, 0.0, 0, 0.0),
            Fmi2Status::Ok
        );
        assert_eq!(
            abi::enter_initialization_mode::<Plant>(fmi_export::Function::EnterInitializationMode, c),
            Fmi2Status::Ok
        );
        assert_eq!(
            abi::exit_initialization_mode::<Plant>(fmi_export::Function::ExitInitializationMode, c),
            Fmi2Status::Ok
        );
    }
    c
}

fn benches(cr: &mut Criterion) {
    let p = VehicleParams::table2();
    let mut s = nigel_vehicle::straight_running(0.35);
    s[4] = 0.01;
    s[5] = 0.1;
    let mut u = Inputs::coasting(0.4);
    u.delta = [0.2, 0.2, -0.2, -0.2];
    u.tau = [0.01; 4];
    cr.bench_function("rhs (derivatives only, paper fidelity)", |b| {
        b.iter(|| derivatives_of(black_box(&p), black_box(&s), black_box(&u)))
    });
    let real = VehicleParams::real_fidelity();
    cr.bench_function("rhs (derivatives only, real fidelity)", |b| {
        b.iter(|| derivatives_of(black_box(&real), black_box(&s), black_box(&u)))
    });
    cr.bench_function("rhs + all outputs", |b| {
        b.iter(|| nigel_vehicle::evaluate(black_box(&p), black_box(&s), black_box(&u)))
    });

    // Steps are timed in runs of 1000 (1 s of driving) from the same saved state, so the
    // benchmark stays at a realistic operating point (a coasting car that has come to rest
    // would drift into subnormal numbers, which are far slower on x86).
    let cs = component(1);
    let mut saved = std::ptr::null_mut();
    unsafe {
        assert_eq!(abi::get_fmu_state::<Plant>(fmi_export::Function::GetFMUstate, cs, &mut saved), Fmi2Status::Ok)
    };
    cr.bench_function("fmi2DoStep 1 ms (CS, 2 RK4 sub-steps)", |b| {
        b.iter_custom(|iters| {
            let mut total = std::time::Duration::ZERO;
            let mut done = 0;
            while done < iters {
                unsafe {
                    assert_eq!(
                        abi::set_fmu_state::<Plant>(fmi_export::Function::SetFMUstate, cs, saved),
                        Fmi2Status::Ok
                    )
                };
                let run = (iters - done).min(1000);
                let start = std::time::Instant::now();
                for k in 0..run {
                    let status =
                        unsafe { abi::do_step::<Plant>(fmi_export::Function::DoStep, cs, k as f64 * 1e-3, 1e-3, 1) };
                    if status != Fmi2Status::Ok {
                        panic!("fmi2DoStep failed at step {k}");
                    }
                }
                total += start.elapsed();
                done += run;
            }
            total
        })
    });
    let me = component(0);
    unsafe {
        assert_eq!(
            abi::enter_continuous_time_mode::<Plant>(fmi_export::Function::EnterContinuousTimeMode, me),
            Fmi2Status::Ok
        )
    };
    let mut x = [0.0; 10];
    let mut dx = [0.0; 10];
    unsafe {
        assert_eq!(
            abi::get_continuous_states::<Plant>(fmi_export::Function::GetContinuousStates, me, x.as_mut_ptr(), 10),
            Fmi2Status::Ok
        )
    };
    cr.bench_function("fmi2SetContinuousStates + fmi2GetDerivatives (ME)", |b| {
        b.iter(|| unsafe {
            x[5] += 1e-12;
            abi::set_continuous_states::<Plant>(fmi_export::Function::SetContinuousStates, me, x.as_ptr(), 10);
            black_box(abi::get_derivatives::<Plant>(fmi_export::Function::GetDerivatives, me, dx.as_mut_ptr(), 10))
        })
    });
    unsafe {
        abi::free_fmu_state::<Plant>(fmi_export::Function::FreeFMUstate, cs, &mut saved);
        abi::free_instance::<Plant>(fmi_export::Function::FreeInstance, cs);
        abi::free_instance::<Plant>(fmi_export::Function::FreeInstance, me);
    }
}

criterion_group!(plant, benches);
criterion_main!(plant);

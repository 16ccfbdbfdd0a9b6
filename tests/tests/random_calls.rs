//! Seeded random call sequences over all 44 functions of every FMU in `build-fmu`'s list,
//! in every state, with hostile arguments (unknown value references, NULL arrays,
//! NaN/Inf, huge steps, stale and foreign FMU states, corrupted serialized states).
//! Checked after every call: no crash, a defined status, the allowed-state table of
//! `fmi_export::states` respected (a call it forbids returns fmi2Error), and no
//! non-finite number handed out with fmi2OK.
//!
//! `NIGEL_RANDOM_SEQUENCES` sets the number of sequences per FMU and interface
//! (default 150,000: some 1.2 million calls per interface for the plant, a few seconds).

use std::ffi::{c_char, c_int};
use std::ptr::{null, null_mut};

use fmi_export::states::{Function, Machine, Scope};
use model_description::ModelDescription;
use nigel_integration_tests::{EventInfo, Fmu, CO_SIMULATION, ERROR, MODEL_EXCHANGE, OK};

mod random;
use random::{every_fmu_and_interface, Experiment, Moves, Rng, Shadow, HOSTILE};

/// The FMI 2.0 functions that move the importer's view of the state.
const MOVES: Moves = Moves {
    do_step: Function::DoStep,
    enter_initialization_mode: Function::EnterInitializationMode,
    exit_initialization_mode: Function::ExitInitializationMode,
    terminate: Function::Terminate,
    reset: Function::Reset,
    enter_event_mode: Function::EnterEventMode,
    enter_continuous_time_mode: Function::EnterContinuousTimeMode,
    set_fmu_state: Function::SetFMUstate,
    discard_fails_the_step: true,
    ok: "fmi2OK",
};

struct Pools {
    real: Vec<u32>,
    integer: Vec<u32>,
    boolean: Vec<u32>,
    nx: usize,
}

fn pools(md: &ModelDescription) -> Pools {
    let of = |t: &str| -> Vec<u32> {
        let mut v: Vec<u32> =
            md.model_variables.iter().filter(|v| v.variable_type.type_name() == t).map(|v| v.value_reference).collect();
        v.extend([9999, u32::MAX]);
        v
    };
    Pools { real: of("Real"), integer: of("Integer"), boolean: of("Boolean"), nx: md.model_structure.derivatives.len() }
}

/// The importer side of one instance: what it believes the state is.
fn run(fmu: &Fmu, kind: c_int, sequences: usize, seed: u64) -> [usize; 4] {
    let md = &fmu.description;
    let p = pools(md);
    let f = &fmu.functions;
    let mut rng = Rng(seed);
    let mut counts = [0usize; 4];
    let interface_scope = if kind == CO_SIMULATION { Scope::CoSimulation } else { Scope::ModelExchange };
    for _ in 0..sequences {
        let (instance, _log) = fmu.instantiate("random", kind, fmu.guid());
        let i = instance.expect("instantiate");
        let c = i.c;
        let mut sh = Shadow::instantiated();
        let calls = 1 + rng.below(16);
        for _ in 0..calls {
            // 40 %: a call that makes progress from the current state (so that sequences
            // reach the deeper states), else any of the 44
            let progress: &[Function] = match sh.machine {
                Some(Machine::Instantiated) => &[Function::SetupExperiment, Function::EnterInitializationMode],
                Some(Machine::InitializationMode) => &[Function::ExitInitializationMode, Function::SetReal],
                Some(Machine::StepComplete) => &[Function::DoStep, Function::SetReal, Function::GetFMUstate],
                Some(Machine::EventMode) => &[Function::NewDiscreteStates, Function::EnterContinuousTimeMode],
                Some(Machine::ContinuousTimeMode) => &[
                    Function::SetTime,
                    Function::SetContinuousStates,
                    Function::GetDerivatives,
                    Function::EnterEventMode,
                ],
                _ => &[Function::Reset, Function::SetFMUstate],
            };
            let function = if rng.chance(40) { rng.pick(progress) } else { rng.pick(&Function::FMI2) };
            if matches!(function, Function::Instantiate | Function::FreeInstance) {
                continue;
            }
            let n = rng.below(4);
            let null_array = rng.chance(3);
            let vrs = |rng: &mut Rng, pool: &[u32]| -> Vec<u32> { (0..n).map(|_| rng.pick(pool)).collect() };
            let ptr = |v: &Vec<u32>| if null_array { null() } else { v.as_ptr() };
            // at least one slot: fmi2GetRealStatus writes one value (an FMU may have nx = 0)
            let mut reals_out = vec![f64::NAN; n.max(p.nx).max(1)];
            let mut check_reals: Option<usize> = None;
            let mut new_time = None;
            let mut restored: Option<Option<Machine>> = None;
            let status = unsafe {
                match function {
                    Function::GetTypesPlatform => {
                        assert!(!(f.get_types_platform.unwrap())().is_null());
                        continue;
                    }
                    Function::GetVersion => {
                        assert!(!(f.get_version)().is_null());
                        continue;
                    }
                    Function::SetDebugLogging => {
                        let cats = [c"logEvents".as_ptr(), c"noSuchCategory".as_ptr()];
                        (f.set_debug_logging.unwrap())(c, 0, rng.below(3), cats.as_ptr())
                    }
                    Function::SetupExperiment => {
                        let e = Experiment::draw(&mut rng);
                        let s = (f.setup_experiment)(
                            c,
                            e.tolerance_defined as c_int,
                            e.tolerance,
                            e.start,
                            e.stop_defined as c_int,
                            e.stop,
                        );
                        if s == OK {
                            new_time = Some(e.start);
                        }
                        s
                    }
                    Function::EnterInitializationMode => (f.enter_initialization_mode)(c),
                    Function::ExitInitializationMode => (f.exit_initialization_mode)(c),
                    Function::Terminate => (f.terminate)(c),
                    Function::Reset => (f.reset.unwrap())(c),
                    Function::GetReal => {
                        let v = vrs(&mut rng, &p.real);
                        check_reals = Some(n);
                        (f.get_real)(c, ptr(&v), n, reals_out.as_mut_ptr())
                    }
                    Function::GetInteger => {
                        let v = vrs(&mut rng, &p.integer);
                        let mut out = [0 as c_int; 4];
                        (f.get_integer)(c, ptr(&v), n, out.as_mut_ptr())
                    }
                    Function::GetBoolean => {
                        let v = vrs(&mut rng, &p.boolean);
                        let mut out = [0 as c_int; 4];
                        (f.get_boolean)(c, ptr(&v), n, out.as_mut_ptr())
                    }
                    Function::GetString => {
                        let v = vrs(&mut rng, &p.real);
                        let mut out = [null(); 4];
                        (f.get_string)(c, ptr(&v), n, out.as_mut_ptr())
                    }
                    Function::SetReal => {
                        let v = vrs(&mut rng, &p.real);
                        let x: Vec<f64> = (0..n).map(|_| rng.pick(&HOSTILE)).collect();
                        (f.set_real)(c, ptr(&v), n, x.as_ptr())
                    }
                    Function::SetInteger => {
                        let v = vrs(&mut rng, &p.integer);
                        let x: Vec<c_int> = (0..n).map(|_| rng.pick(&[0, 1, 2, 3, -1, 7, c_int::MAX])).collect();
                        (f.set_integer)(c, ptr(&v), n, x.as_ptr())
                    }
                    Function::SetBoolean => {
                        let v = vrs(&mut rng, &p.boolean);
                        let x: Vec<c_int> = (0..n).map(|_| rng.pick(&[0, 1, 2, -1])).collect();
                        (f.set_boolean)(c, ptr(&v), n, x.as_ptr())
                    }
                    Function::SetString => {
                        let v = vrs(&mut rng, &p.real);
                        let x = [c"a".as_ptr(); 4];
                        (f.set_string)(c, ptr(&v), n, x.as_ptr())
                    }
                    Function::GetFMUstate => sh.get_state(&mut rng, |s| (f.get_fmu_state.unwrap())(c, s)),
                    Function::SetFMUstate => {
                        sh.set_state(&mut rng, &mut restored, |s| (f.set_fmu_state.unwrap())(c, s))
                    }
                    Function::FreeFMUstate => sh.free_state(&mut rng, |s| (f.free_fmu_state.unwrap())(c, s)),
                    Function::SerializedFMUstateSize => {
                        let mut size = 0usize;
                        (f.serialized_fmu_state_size.unwrap())(c, sh.state_arg(&mut rng), &mut size)
                    }
                    Function::SerializeFMUstate => sh.serialize_state(
                        &mut rng,
                        |s, size| (f.serialized_fmu_state_size.unwrap())(c, s, size),
                        |s, buf| (f.serialize_fmu_state.unwrap())(c, s, buf.as_mut_ptr() as *mut c_char, buf.len()),
                    ),
                    Function::DeSerializeFMUstate => sh.deserialize_state(&mut rng, false, |bytes, s| {
                        (f.deserialize_fmu_state.unwrap())(c, bytes.as_ptr() as *const c_char, bytes.len(), s)
                    }),
                    Function::GetDirectionalDerivative => {
                        let unknown = vrs(&mut rng, &p.real);
                        let known = vrs(&mut rng, &p.real);
                        let seeds: Vec<f64> = (0..n).map(|_| rng.pick(&HOSTILE)).collect();
                        check_reals = Some(n);
                        (f.get_directional_derivative.unwrap())(
                            c,
                            ptr(&unknown),
                            n,
                            ptr(&known),
                            n,
                            seeds.as_ptr(),
                            reals_out.as_mut_ptr(),
                        )
                    }
                    Function::SetRealInputDerivatives => {
                        let v = vrs(&mut rng, &p.real);
                        let order = [1 as c_int; 4];
                        let x = [1.0; 4];
                        (f.set_real_input_derivatives.unwrap())(c, ptr(&v), n, order.as_ptr(), x.as_ptr())
                    }
                    Function::GetRealOutputDerivatives => {
                        let v = vrs(&mut rng, &p.real);
                        let order = [1 as c_int; 4];
                        let mut x = [0.0; 4];
                        (f.get_real_output_derivatives.unwrap())(c, ptr(&v), n, order.as_ptr(), x.as_mut_ptr())
                    }
                    Function::DoStep => {
                        let t = rng.time(sh.time);
                        let h = rng.pick(&[1e-3, 1e-3, 0.02, 0.1, 0.0, -1e-3, f64::NAN, 1e9, 1e-300]);
                        let s = (f.do_step.unwrap())(c, t, h, 1);
                        if s == OK || s == 1 {
                            new_time = Some(t + h);
                        }
                        s
                    }
                    Function::CancelStep => (f.cancel_step.unwrap())(c),
                    Function::GetStatus => {
                        let mut v = 0;
                        (f.get_status.unwrap())(c, rng.below(5) as c_int, &mut v)
                    }
                    Function::GetRealStatus => {
                        check_reals = Some(1);
                        (f.get_real_status.unwrap())(c, rng.below(5) as c_int, reals_out.as_mut_ptr())
                    }
                    Function::GetIntegerStatus => {
                        let mut v = 0;
                        (f.get_integer_status.unwrap())(c, rng.below(5) as c_int, &mut v)
                    }
                    Function::GetBooleanStatus => {
                        let mut v = 0;
                        (f.get_boolean_status.unwrap())(c, rng.below(5) as c_int, &mut v)
                    }
                    Function::GetStringStatus => {
                        let mut v = null();
                        (f.get_string_status.unwrap())(c, rng.below(5) as c_int, &mut v)
                    }
                    Function::EnterEventMode => (f.enter_event_mode.unwrap())(c),
                    Function::NewDiscreteStates => {
                        let mut info = EventInfo::default();
                        let s = (f.new_discrete_states.unwrap())(c, &mut info);
                        if s == OK && info.next_event_time_defined != 0 {
                            assert!(info.next_event_time.is_finite());
                        }
                        s
                    }
                    Function::EnterContinuousTimeMode => (f.enter_continuous_time_mode.unwrap())(c),
                    Function::CompletedIntegratorStep => {
                        let (mut a, mut b) = (0, 0);
                        (f.completed_integrator_step.unwrap())(c, 1, &mut a, &mut b)
                    }
                    Function::SetTime => {
                        let t = rng.time(sh.time + 1e-3);
                        let s = (f.set_time.unwrap())(c, t);
                        if s == OK || s == 1 {
                            new_time = Some(t);
                        }
                        s
                    }
                    Function::SetContinuousStates => {
                        let nx = if rng.chance(80) { p.nx } else { n };
                        let x: Vec<f64> = (0..nx).map(|_| rng.pick(&HOSTILE)).collect();
                        (f.set_continuous_states.unwrap())(c, if null_array { null() } else { x.as_ptr() }, nx)
                    }
                    Function::GetDerivatives
                    | Function::GetContinuousStates
                    | Function::GetNominalsOfContinuousStates
                    | Function::GetEventIndicators => {
                        let nx = if rng.chance(80) { p.nx } else { n };
                        let out = if null_array { null_mut() } else { reals_out.as_mut_ptr() };
                        check_reals = Some(nx);
                        match function {
                            Function::GetDerivatives => (f.get_derivatives.unwrap())(c, out, nx),
                            Function::GetContinuousStates => (f.get_continuous_states.unwrap())(c, out, nx),
                            Function::GetNominalsOfContinuousStates => {
                                (f.get_nominals_of_continuous_states.unwrap())(c, out, nx)
                            }
                            _ => (f.get_event_indicators.unwrap())(c, out, nx),
                        }
                    }
                    // the FMI 3.0 functions: tests/random_calls3.rs
                    _ => unreachable!("{function:?}"),
                }
            };
            assert!((0..=3).contains(&status), "{function:?} returned {status}");
            counts[status as usize] += 1;
            // the state table: a call it forbids is an error
            if let Some(m) = sh.machine {
                let wrong_interface = function.scope() != Scope::Common && function.scope() != interface_scope;
                if wrong_interface || !function.allowed_in(m) {
                    assert_eq!(status, ERROR, "{function:?} in {m:?} ({})", if kind == 1 { "CS" } else { "ME" });
                }
            }
            sh.after(&MOVES, function, status, check_reals, &reals_out, new_time, restored, kind == CO_SIMULATION);
        }
        // the instance is freed with its live FMU states (the allocator would report a double free)
    }
    counts
}

#[test]
fn random_call_sequences_respect_the_state_table_and_never_hand_out_non_finite_numbers() {
    let sequences: usize = std::env::var("NIGEL_RANDOM_SEQUENCES").ok().and_then(|s| s.parse().ok()).unwrap_or(150_000);
    // the plant's counts per interface, which docs/testing.md prints
    let plant = every_fmu_and_interface("", sequences, 0x9E37_79B9_7F4A_7C15, "nigel_plant", |fmu, cs, seed| {
        run(fmu, if cs { CO_SIMULATION } else { MODEL_EXCHANGE }, sequences, seed)
    });
    if sequences == 150_000 {
        readme_prints_the_plant_counts(&plant);
    }
}

/// The figures docs/testing.md prints of the default run (see "Figures in the docs" there): the plant's
/// calls in millions to the printed two digits, its Discards exactly.
fn readme_prints_the_plant_counts(plant: &[[usize; 4]]) {
    let [cs, me] = plant else { panic!("the plant offers CS and ME: {plant:?}") };
    // "0.41 M OK, 310 Discard, 0.80 M Error": OK and Error in millions, the rare ones counted
    let text = |c: &[usize; 4]| {
        let mut parts = vec![format!("{:.2} M OK", c[0] as f64 / 1e6)];
        parts.extend(
            [(c[1], "Warning"), (c[2], "Discard")].iter().filter(|(n, _)| *n > 0).map(|(n, w)| format!("{n} {w}")),
        );
        parts.push(format!("{:.2} M Error", c[3] as f64 / 1e6));
        parts.join(", ")
    };
    let total: usize = cs.iter().chain(me.iter()).sum();
    let expected = [
        format!(
            "150,000 seeded sequences per interface over all 44 functions with hostile arguments, {:.1} million",
            total as f64 / 1e6
        ),
        format!("calls for the plant (CS: {}; ME: {})", text(cs), text(me)),
        format!(
            "150,000 sequences over all 44 functions per FMU and interface, about {:.1} million calls",
            cs.iter().sum::<usize>() as f64 / 1e6
        ),
    ];
    // docs/testing.md prints the default run's counts, docs/reference.md the sequences a new FMU gets
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let words = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let docs: String = ["docs/testing.md", "docs/reference.md"]
        .iter()
        .map(|d| words(&std::fs::read_to_string(root.join(d)).unwrap_or_else(|e| panic!("{d}: {e}"))))
        .collect::<Vec<_>>()
        .join(" ");
    for e in expected {
        assert!(
            docs.contains(&words(&e)),
            "docs/testing.md or docs/reference.md no longer prints {e:?}: these are the counts now"
        );
    }
}

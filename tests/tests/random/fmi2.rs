//! The FMI 2.0 side of the random call sequences: all 44 `fmi2*` functions with hostile
//! arguments (unknown value references, NULL arrays, NaN/Inf, huge steps, stale and foreign
//! FMU states, corrupted serialized states).

use std::ffi::{c_char, c_int};
use std::ptr::{null, null_mut};

use fmi_export::states::{Function, Machine};
use model_description::ModelDescription;
use nigel_integration_tests::{EventInfo, Fmu, Instance, Log, CO_SIMULATION, MODEL_EXCHANGE, OK};

use super::{Call, Experiment, Generation, Rng, Shadow, HOSTILE};

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

/// The FMI 2.0 ABI of one FMU, Co-Simulation or Model Exchange.
pub struct Fmi2<'f> {
    fmu: &'f Fmu,
    kind: c_int,
    p: Pools,
}

impl<'f> Fmi2<'f> {
    pub fn new(fmu: &'f Fmu, co_simulation: bool) -> Fmi2<'f> {
        Fmi2 { fmu, kind: if co_simulation { CO_SIMULATION } else { MODEL_EXCHANGE }, p: pools(&fmu.description) }
    }
}

impl<'f> Generation for Fmi2<'f> {
    type Live = (Instance<'f>, Box<Log>);

    const FUNCTIONS: &'static [Function] = &Function::FMI2;

    fn instantiate(&self) -> Self::Live {
        let (instance, log) = self.fmu.instantiate("random", self.kind, self.fmu.guid());
        (instance.expect("instantiate"), log)
    }

    fn progress(machine: Option<Machine>) -> &'static [Function] {
        match machine {
            Some(Machine::Instantiated) => &[Function::SetupExperiment, Function::EnterInitializationMode],
            Some(Machine::InitializationMode) => &[Function::ExitInitializationMode, Function::SetReal],
            Some(Machine::StepComplete) => &[Function::DoStep, Function::SetReal, Function::GetFMUstate],
            Some(Machine::EventMode) => &[Function::NewDiscreteStates, Function::EnterContinuousTimeMode],
            Some(Machine::ContinuousTimeMode) => {
                &[Function::SetTime, Function::SetContinuousStates, Function::GetDerivatives, Function::EnterEventMode]
            }
            _ => &[Function::Reset, Function::SetFMUstate],
        }
    }

    fn left_out(function: Function) -> bool {
        matches!(function, Function::Instantiate | Function::FreeInstance)
    }

    unsafe fn call(&self, live: &Self::Live, function: Function, rng: &mut Rng, sh: &mut Shadow) -> Option<Call> {
        let (p, f, c) = (&self.p, &self.fmu.functions, live.0.c);
        let n = rng.below(4);
        let null_array = rng.chance(3);
        let vrs = |rng: &mut Rng, pool: &[u32]| -> Vec<u32> { (0..n).map(|_| rng.pick(pool)).collect() };
        let ptr = |v: &Vec<u32>| if null_array { null() } else { v.as_ptr() };
        // at least one slot: fmi2GetRealStatus writes one value (an FMU may have nx = 0)
        let mut reals_out = vec![f64::NAN; n.max(p.nx).max(1)];
        let mut check_reals: Option<usize> = None;
        let mut new_time = None;
        let mut restored: Option<Option<Machine>> = None;
        let status = {
            match function {
                Function::GetTypesPlatform => {
                    assert!(!(f.get_types_platform.unwrap())().is_null());
                    return None;
                }
                Function::GetVersion => {
                    assert!(!(f.get_version)().is_null());
                    return None;
                }
                Function::SetDebugLogging => {
                    let cats = [c"logEvents".as_ptr(), c"noSuchCategory".as_ptr()];
                    (f.set_debug_logging.unwrap())(c, 0, rng.below(3), cats.as_ptr())
                }
                Function::SetupExperiment => {
                    let e = Experiment::draw(rng);
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
                    let v = vrs(rng, &p.real);
                    check_reals = Some(n);
                    (f.get_real)(c, ptr(&v), n, reals_out.as_mut_ptr())
                }
                Function::GetInteger => {
                    let v = vrs(rng, &p.integer);
                    let mut out = [0 as c_int; 4];
                    (f.get_integer)(c, ptr(&v), n, out.as_mut_ptr())
                }
                Function::GetBoolean => {
                    let v = vrs(rng, &p.boolean);
                    let mut out = [0 as c_int; 4];
                    (f.get_boolean)(c, ptr(&v), n, out.as_mut_ptr())
                }
                Function::GetString => {
                    let v = vrs(rng, &p.real);
                    let mut out = [null(); 4];
                    (f.get_string)(c, ptr(&v), n, out.as_mut_ptr())
                }
                Function::SetReal => {
                    let v = vrs(rng, &p.real);
                    let x: Vec<f64> = (0..n).map(|_| rng.pick(&HOSTILE)).collect();
                    (f.set_real)(c, ptr(&v), n, x.as_ptr())
                }
                Function::SetInteger => {
                    let v = vrs(rng, &p.integer);
                    let x: Vec<c_int> = (0..n).map(|_| rng.pick(&[0, 1, 2, 3, -1, 7, c_int::MAX])).collect();
                    (f.set_integer)(c, ptr(&v), n, x.as_ptr())
                }
                Function::SetBoolean => {
                    let v = vrs(rng, &p.boolean);
                    let x: Vec<c_int> = (0..n).map(|_| rng.pick(&[0, 1, 2, -1])).collect();
                    (f.set_boolean)(c, ptr(&v), n, x.as_ptr())
                }
                Function::SetString => {
                    let v = vrs(rng, &p.real);
                    let x = [c"a".as_ptr(); 4];
                    (f.set_string)(c, ptr(&v), n, x.as_ptr())
                }
                Function::GetFMUstate => sh.get_state(rng, |s| (f.get_fmu_state.unwrap())(c, s)),
                Function::SetFMUstate => sh.set_state(rng, &mut restored, |s| (f.set_fmu_state.unwrap())(c, s)),
                Function::FreeFMUstate => sh.free_state(rng, |s| (f.free_fmu_state.unwrap())(c, s)),
                Function::SerializedFMUstateSize => {
                    let mut size = 0usize;
                    (f.serialized_fmu_state_size.unwrap())(c, sh.state_arg(rng), &mut size)
                }
                Function::SerializeFMUstate => sh.serialize_state(
                    rng,
                    |s, size| (f.serialized_fmu_state_size.unwrap())(c, s, size),
                    |s, buf| (f.serialize_fmu_state.unwrap())(c, s, buf.as_mut_ptr() as *mut c_char, buf.len()),
                ),
                Function::DeSerializeFMUstate => sh.deserialize_state(rng, false, |bytes, s| {
                    (f.deserialize_fmu_state.unwrap())(c, bytes.as_ptr() as *const c_char, bytes.len(), s)
                }),
                Function::GetDirectionalDerivative => {
                    let unknown = vrs(rng, &p.real);
                    let known = vrs(rng, &p.real);
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
                    let v = vrs(rng, &p.real);
                    let order = [1 as c_int; 4];
                    let x = [1.0; 4];
                    (f.set_real_input_derivatives.unwrap())(c, ptr(&v), n, order.as_ptr(), x.as_ptr())
                }
                Function::GetRealOutputDerivatives => {
                    let v = vrs(rng, &p.real);
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
                // the FMI 3.0 functions: fmi3.rs
                _ => unreachable!("{function:?}"),
            }
        };
        Some(Call { status, check_reals, reals_out, new_time, restored })
    }
}

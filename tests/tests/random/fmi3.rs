//! The FMI 3.0 side of the random call sequences: all 75 `fmi3*` functions with hostile
//! arguments (unknown value references and the independent variable, every type's getter and
//! setter, wrong `nValues`, NULL arrays, NaN/Inf, huge steps, stale and foreign FMU states,
//! corrupted serialized states, the functions of undeclared features), and now and then an
//! `fmi2*` call on the FMI 3.0 instance; a refused call's message names the function.

use std::ptr::{null, null_mut};

use fmi_export::states::{Function, Machine};
use model_description::{ModelDescription, VariableType};
use nigel_integration_tests::{Fmu, Instance3, Log3, ERROR, OK};

use super::{Call, Experiment, Generation, Rng, Shadow, HOSTILE};

/// FMI 3.0 value references by type (FMI 2.0 variable index i is FMI 3.0 value reference
/// i; `time` is 0), each pool with foreign ones mixed in.
struct Pools {
    float64: Vec<u32>,
    int32: Vec<u32>,
    int64: Vec<u32>,
    boolean: Vec<u32>,
    any: Vec<u32>,
    nx: usize,
}

fn pools(md: &ModelDescription) -> Pools {
    let of = |keep: fn(&VariableType) -> bool| -> Vec<u32> {
        let mut v: Vec<u32> = md
            .model_variables
            .iter()
            .enumerate()
            .filter(|(_, v)| keep(&v.variable_type))
            .map(|(row, _)| row as u32 + 1)
            .collect();
        v.extend([9999, u32::MAX]);
        v
    };
    let mut float64 = of(|t| matches!(t, VariableType::Real { .. }));
    float64.push(0);
    Pools {
        float64,
        int32: of(|t| matches!(t, VariableType::Integer { .. })),
        int64: of(|t| matches!(t, VariableType::Enumeration { .. })),
        boolean: of(|t| matches!(t, VariableType::Boolean { .. })),
        any: (0..md.model_variables.len() as u32 + 2).collect(),
        nx: md.model_structure.derivatives.len(),
    }
}

/// The FMI 3.0 ABI of one FMU (the FMI 2.0 archive's library: one library, both
/// generations), Co-Simulation or Model Exchange.
pub struct Fmi3<'f> {
    fmu: &'f Fmu,
    co_simulation: bool,
    p: Pools,
    /// a model that declares a clock (the controller's sample clock) offers the clock
    /// functions, which the others refuse as undeclared (the layer's rule, fmi-export's
    /// `Instance::call_allowed`)
    clocked: bool,
}

impl<'f> Fmi3<'f> {
    pub fn new(fmu: &'f Fmu, co_simulation: bool) -> Fmi3<'f> {
        let identifier = fmu.description.co_simulation.as_ref().map(|cs| cs.model_identifier.clone());
        let clocked = build_fmu::targets().iter().any(|t| {
            Some(&t.model_identifier) == identifier.as_ref()
                && t.description3
                    .model_variables
                    .iter()
                    .any(|v| v.value_type == model_description::fmi3::ValueType::Clock)
        });
        Fmi3 { fmu, co_simulation, p: pools(&fmu.description), clocked }
    }
}

impl<'f> Generation for Fmi3<'f> {
    type Live = (Instance3<'f>, Box<Log3>);

    const FUNCTIONS: &'static [Function] = &Function::FMI3;

    fn instantiate(&self) -> Self::Live {
        let (instance, log) = self.fmu.instantiate3("random3", self.co_simulation, self.fmu.guid());
        (instance.expect("instantiate"), log)
    }

    fn progress(machine: Option<Machine>) -> &'static [Function] {
        match machine {
            Some(Machine::Instantiated) => &[Function::Fmi3EnterInitializationMode, Function::Fmi3SetFloat64],
            Some(Machine::InitializationMode) => &[Function::Fmi3ExitInitializationMode, Function::Fmi3SetFloat64],
            Some(Machine::StepComplete) => &[Function::Fmi3DoStep, Function::Fmi3SetFloat64, Function::Fmi3GetFMUState],
            Some(Machine::EventMode) => &[Function::Fmi3UpdateDiscreteStates, Function::Fmi3EnterContinuousTimeMode],
            Some(Machine::ContinuousTimeMode) => &[
                Function::Fmi3SetTime,
                Function::Fmi3SetContinuousStates,
                Function::Fmi3GetContinuousStateDerivatives,
                Function::Fmi3EnterEventMode,
            ],
            _ => &[Function::Fmi3Reset, Function::Fmi3SetFMUState],
        }
    }

    fn left_out(function: Function) -> bool {
        matches!(
            function,
            Function::Fmi3InstantiateCoSimulation
                | Function::Fmi3InstantiateModelExchange
                | Function::Fmi3InstantiateScheduledExecution
                | Function::Fmi3FreeInstance
        )
    }

    unsafe fn call(&self, live: &Self::Live, function: Function, rng: &mut Rng, sh: &mut Shadow) -> Option<Call> {
        let (p, f, c) = (&self.p, &self.fmu.functions3, live.0.c);
        let n = rng.below(4);
        // nValues: mostly right, sometimes one off
        let n_values = if rng.chance(10) { n + 1 } else { n };
        let null_array = rng.chance(3);
        let vrs = |rng: &mut Rng, pool: &[u32]| -> Vec<u32> { (0..n).map(|_| rng.pick(pool)).collect() };
        let ptr = |v: &Vec<u32>| if null_array { null() } else { v.as_ptr() };
        let mut reals_out = vec![f64::NAN; n_values.max(p.nx).max(1)];
        let mut check_reals: Option<usize> = None;
        let mut new_time = None;
        let mut restored: Option<Option<Machine>> = None;
        let (mut b1, mut b2, mut b3, mut b4, mut b5) = (7u8, 7u8, 7u8, 7u8, 7u8);
        let mut t_out = f64::NAN;
        // one type's values of `pool`: got into a zeroed buffer, or set to values picked
        // from `picks`
        macro_rules! get {
            ($getter:expr, $pool:expr, $zero:expr) => {{
                let v = vrs(rng, $pool);
                let mut out = [$zero; 5];
                ($getter)(c, ptr(&v), n, out.as_mut_ptr(), n_values)
            }};
        }
        macro_rules! set {
            ($setter:expr, $pool:expr, $picks:expr) => {{
                let v = vrs(rng, $pool);
                let x: Vec<_> = (0..n_values).map(|_| rng.pick($picks)).collect();
                ($setter)(c, ptr(&v), n, x.as_ptr(), n_values)
            }};
        }
        let status = {
            use Function::*;
            match function {
                Fmi3GetVersion => {
                    assert!(!(f.get_version)().is_null());
                    return None;
                }
                Fmi3SetDebugLogging => {
                    let cats = [c"logEvents".as_ptr(), c"noSuchCategory".as_ptr()];
                    (f.set_debug_logging.unwrap())(c, 0, rng.below(3), cats.as_ptr())
                }
                Fmi3EnterInitializationMode => {
                    let e = Experiment::draw(rng);
                    let s = (f.enter_initialization_mode)(
                        c,
                        e.tolerance_defined as u8,
                        e.tolerance,
                        e.start,
                        e.stop_defined as u8,
                        e.stop,
                    );
                    if s == OK {
                        new_time = Some(e.start);
                    }
                    s
                }
                Fmi3ExitInitializationMode => (f.exit_initialization_mode)(c),
                Fmi3Terminate => (f.terminate)(c),
                Fmi3Reset => (f.reset.unwrap())(c),
                Fmi3EnterEventMode => (f.enter_event_mode.unwrap())(c),
                Fmi3GetFloat64 => {
                    let v = vrs(rng, &p.float64);
                    check_reals = Some(n.min(n_values));
                    (f.get_float64)(c, ptr(&v), n, reals_out.as_mut_ptr(), n_values)
                }
                Fmi3SetFloat64 => set!(f.set_float64, &p.float64, &HOSTILE),
                Fmi3GetInt32 => get!(f.get_int32.unwrap(), &p.int32, 0i32),
                Fmi3SetInt32 => set!(f.set_int32.unwrap(), &p.int32, &[0, 1, 2, 3, -1, 7, i32::MAX]),
                Fmi3GetInt64 => get!(f.get_int64.unwrap(), &p.int64, 0i64),
                Fmi3SetInt64 => set!(f.set_int64.unwrap(), &p.int64, &[0, 1, 2, 3, -1, 1 << 40, i64::MIN]),
                Fmi3GetBoolean => get!(f.get_boolean.unwrap(), &p.boolean, 0u8),
                Fmi3SetBoolean => set!(f.set_boolean.unwrap(), &p.boolean, &[0, 1, 2, 255]),
                // the types the FMUs have no variable of: any value reference
                Fmi3GetFloat32 | Fmi3SetFloat32 => {
                    let v = vrs(rng, &p.any);
                    let mut out = [0f32; 5];
                    if function == Fmi3GetFloat32 {
                        (f.get_float32.unwrap())(c, ptr(&v), n, out.as_mut_ptr(), n_values)
                    } else {
                        (f.set_float32.unwrap())(c, ptr(&v), n, out.as_ptr(), n_values)
                    }
                }
                Fmi3GetInt8 | Fmi3GetUInt8 | Fmi3SetInt8 | Fmi3SetUInt8 | Fmi3GetInt16 | Fmi3GetUInt16
                | Fmi3SetInt16 | Fmi3SetUInt16 | Fmi3GetUInt32 | Fmi3SetUInt32 | Fmi3GetUInt64 | Fmi3SetUInt64 => {
                    let v = vrs(rng, &p.any);
                    let mut out = [0u64; 5];
                    let o = out.as_mut_ptr();
                    match function {
                        Fmi3GetInt8 => (f.get_int8.unwrap())(c, ptr(&v), n, o as *mut i8, n_values),
                        Fmi3GetUInt8 => (f.get_uint8.unwrap())(c, ptr(&v), n, o as *mut u8, n_values),
                        Fmi3SetInt8 => (f.set_int8.unwrap())(c, ptr(&v), n, o as *const i8, n_values),
                        Fmi3SetUInt8 => (f.set_uint8.unwrap())(c, ptr(&v), n, o as *const u8, n_values),
                        Fmi3GetInt16 => (f.get_int16.unwrap())(c, ptr(&v), n, o as *mut i16, n_values),
                        Fmi3GetUInt16 => (f.get_uint16.unwrap())(c, ptr(&v), n, o as *mut u16, n_values),
                        Fmi3SetInt16 => (f.set_int16.unwrap())(c, ptr(&v), n, o as *const i16, n_values),
                        Fmi3SetUInt16 => (f.set_uint16.unwrap())(c, ptr(&v), n, o as *const u16, n_values),
                        Fmi3GetUInt32 => (f.get_uint32.unwrap())(c, ptr(&v), n, o as *mut u32, n_values),
                        Fmi3SetUInt32 => (f.set_uint32.unwrap())(c, ptr(&v), n, o as *const u32, n_values),
                        Fmi3GetUInt64 => (f.get_uint64.unwrap())(c, ptr(&v), n, o, n_values),
                        _ => (f.set_uint64.unwrap())(c, ptr(&v), n, o, n_values),
                    }
                }
                Fmi3GetString | Fmi3SetString => {
                    let v = vrs(rng, &p.any);
                    let mut out = [c"a".as_ptr(); 5];
                    if function == Fmi3GetString {
                        (f.get_string.unwrap())(c, ptr(&v), n, out.as_mut_ptr(), n_values)
                    } else {
                        (f.set_string.unwrap())(c, ptr(&v), n, out.as_ptr(), n_values)
                    }
                }
                Fmi3GetBinary | Fmi3SetBinary => {
                    let v = vrs(rng, &p.any);
                    let mut sizes = [1usize; 5];
                    let mut out = [c"a".as_ptr() as *const u8; 5];
                    if function == Fmi3GetBinary {
                        (f.get_binary.unwrap())(c, ptr(&v), n, sizes.as_mut_ptr(), out.as_mut_ptr(), n_values)
                    } else {
                        (f.set_binary.unwrap())(c, ptr(&v), n, sizes.as_ptr(), out.as_ptr(), n_values)
                    }
                }
                Fmi3GetClock | Fmi3SetClock => {
                    let v = vrs(rng, &p.any);
                    let mut out = [1u8; 5];
                    if function == Fmi3GetClock {
                        (f.get_clock.unwrap())(c, ptr(&v), n, out.as_mut_ptr())
                    } else {
                        (f.set_clock.unwrap())(c, ptr(&v), n, out.as_ptr())
                    }
                }
                Fmi3GetNumberOfVariableDependencies => {
                    let mut k = 0usize;
                    (f.get_number_of_variable_dependencies.unwrap())(c, rng.pick(&p.any), &mut k)
                }
                Fmi3GetVariableDependencies => {
                    let (mut e, mut on, mut eon, mut kind) = ([0usize; 64], [0u32; 64], [0usize; 64], [0i32; 64]);
                    let k = rng.pick(&[0, 1, 3, 64]);
                    (f.get_variable_dependencies.unwrap())(
                        c,
                        rng.pick(&p.any),
                        e.as_mut_ptr(),
                        on.as_mut_ptr(),
                        eon.as_mut_ptr(),
                        kind.as_mut_ptr(),
                        k,
                    )
                }
                Fmi3GetFMUState => sh.get_state(rng, |s| (f.get_fmu_state.unwrap())(c, s)),
                Fmi3SetFMUState => sh.set_state(rng, &mut restored, |s| (f.set_fmu_state.unwrap())(c, s)),
                Fmi3FreeFMUState => sh.free_state(rng, |s| (f.free_fmu_state.unwrap())(c, s)),
                Fmi3SerializedFMUStateSize => {
                    let mut size = 0usize;
                    (f.serialized_fmu_state_size.unwrap())(c, sh.state_arg(rng), &mut size)
                }
                Fmi3SerializeFMUState => sh.serialize_state(
                    rng,
                    |s, size| (f.serialized_fmu_state_size.unwrap())(c, s, size),
                    |s, buf| (f.serialize_fmu_state.unwrap())(c, s, buf.as_mut_ptr(), buf.len()),
                ),
                Fmi3DeserializeFMUState => sh.deserialize_state(rng, true, |bytes, s| {
                    (f.deserialize_fmu_state.unwrap())(c, bytes.as_ptr(), bytes.len(), s)
                }),
                Fmi3GetDirectionalDerivative | Fmi3GetAdjointDerivative => {
                    let unknown = vrs(rng, &p.float64);
                    let known = vrs(rng, &p.float64);
                    let seeds: Vec<f64> = (0..n_values).map(|_| rng.pick(&HOSTILE)).collect();
                    check_reals = Some(n.min(n_values));
                    let g = if function == Fmi3GetDirectionalDerivative {
                        f.get_directional_derivative.unwrap()
                    } else {
                        f.get_adjoint_derivative.unwrap()
                    };
                    g(c, ptr(&unknown), n, ptr(&known), n, seeds.as_ptr(), n_values, reals_out.as_mut_ptr(), n_values)
                }
                Fmi3EnterConfigurationMode => (f.enter_configuration_mode.unwrap())(c),
                Fmi3ExitConfigurationMode => (f.exit_configuration_mode.unwrap())(c),
                _ if function.is_clock_timing_function() => {
                    let v = vrs(rng, &p.any);
                    let (mut x, mut a, mut b, mut q) = ([0.0; 5], [0u64; 5], [0u64; 5], [0i32; 5]);
                    match function {
                        Fmi3GetIntervalDecimal => {
                            (f.get_interval_decimal.unwrap())(c, ptr(&v), n, x.as_mut_ptr(), q.as_mut_ptr())
                        }
                        Fmi3GetIntervalFraction => (f.get_interval_fraction.unwrap())(
                            c,
                            ptr(&v),
                            n,
                            a.as_mut_ptr(),
                            b.as_mut_ptr(),
                            q.as_mut_ptr(),
                        ),
                        Fmi3GetShiftDecimal => (f.get_shift_decimal.unwrap())(c, ptr(&v), n, x.as_mut_ptr()),
                        Fmi3GetShiftFraction => {
                            (f.get_shift_fraction.unwrap())(c, ptr(&v), n, a.as_mut_ptr(), b.as_mut_ptr())
                        }
                        Fmi3SetIntervalDecimal => (f.set_interval_decimal.unwrap())(c, ptr(&v), n, x.as_ptr()),
                        Fmi3SetIntervalFraction => {
                            (f.set_interval_fraction.unwrap())(c, ptr(&v), n, a.as_ptr(), b.as_ptr())
                        }
                        Fmi3SetShiftDecimal => (f.set_shift_decimal.unwrap())(c, ptr(&v), n, x.as_ptr()),
                        _ => (f.set_shift_fraction.unwrap())(c, ptr(&v), n, a.as_ptr(), b.as_ptr()),
                    }
                }
                Fmi3EvaluateDiscreteStates => (f.evaluate_discrete_states.unwrap())(c),
                Fmi3UpdateDiscreteStates => {
                    let s =
                        (f.update_discrete_states.unwrap())(c, &mut b1, &mut b2, &mut b3, &mut b4, &mut b5, &mut t_out);
                    if s == OK && b5 != 0 {
                        assert!(t_out.is_finite());
                    }
                    s
                }
                Fmi3EnterContinuousTimeMode => (f.enter_continuous_time_mode.unwrap())(c),
                Fmi3CompletedIntegratorStep => (f.completed_integrator_step.unwrap())(c, 1, &mut b1, &mut b2),
                Fmi3SetTime => {
                    let t = rng.time(sh.time + 1e-3);
                    let s = (f.set_time.unwrap())(c, t);
                    if s == OK || s == 1 {
                        new_time = Some(t);
                    }
                    s
                }
                Fmi3SetContinuousStates => {
                    let nx = if rng.chance(80) { p.nx } else { n };
                    let x: Vec<f64> = (0..nx).map(|_| rng.pick(&HOSTILE)).collect();
                    (f.set_continuous_states.unwrap())(c, if null_array { null() } else { x.as_ptr() }, nx)
                }
                Fmi3GetContinuousStateDerivatives
                | Fmi3GetContinuousStates
                | Fmi3GetNominalsOfContinuousStates
                | Fmi3GetEventIndicators => {
                    let nx = if rng.chance(80) { p.nx } else { n };
                    let out = if null_array { null_mut() } else { reals_out.as_mut_ptr() };
                    check_reals = Some(nx);
                    match function {
                        Fmi3GetContinuousStateDerivatives => (f.get_continuous_state_derivatives.unwrap())(c, out, nx),
                        Fmi3GetContinuousStates => (f.get_continuous_states.unwrap())(c, out, nx),
                        Fmi3GetNominalsOfContinuousStates => (f.get_nominals_of_continuous_states.unwrap())(c, out, nx),
                        _ => (f.get_event_indicators.unwrap())(c, out, nx),
                    }
                }
                Fmi3GetNumberOfEventIndicators => {
                    let mut k = 7usize;
                    let s = (f.get_number_of_event_indicators.unwrap())(c, &mut k);
                    assert!(s != OK || k == 0);
                    s
                }
                Fmi3GetNumberOfContinuousStates => {
                    let mut k = 7usize;
                    let s = (f.get_number_of_continuous_states.unwrap())(c, &mut k);
                    assert!(s != OK || k == p.nx);
                    s
                }
                Fmi3EnterStepMode => (f.enter_step_mode.unwrap())(c),
                Fmi3GetOutputDerivatives => {
                    let v = vrs(rng, &p.float64);
                    let order = [1i32; 5];
                    (f.get_output_derivatives.unwrap())(c, ptr(&v), n, order.as_ptr(), reals_out.as_mut_ptr(), n)
                }
                Fmi3DoStep => {
                    let t = rng.time(sh.time);
                    let h = rng.pick(&[1e-3, 1e-3, 0.02, 0.1, 0.0, -1e-3, f64::NAN, 1e9, 1e-300]);
                    let s = (f.do_step.unwrap())(c, t, h, 1, &mut b1, &mut b2, &mut b3, &mut t_out);
                    if s == OK || s == 1 {
                        assert_eq!((b1, b3), (0, 0), "no event handling, no early return");
                        new_time = Some(t + h);
                    }
                    s
                }
                Fmi3ActivateModelPartition => (f.activate_model_partition.unwrap())(c, rng.pick(&p.any), 0.0),
                _ => unreachable!("{function:?}"),
            }
        };
        Some(Call { status, check_reals, reals_out, new_time, restored })
    }

    /// Event Mode is Model Exchange's in a Co-Simulation instance without eventModeUsed; the
    /// functions of a feature the model does not declare are refused (a clocked model's clock
    /// functions are declared).
    fn refuses(&self, function: Function) -> bool {
        let event_mode_in_cs =
            self.co_simulation && matches!(function, Function::Fmi3EnterEventMode | Function::Fmi3UpdateDiscreteStates);
        event_mode_in_cs || (function.undeclared_feature().is_some() && !(self.clocked && function.is_clock_function()))
    }

    fn after_call(&self, live: &Self::Live, function: Function, status: i32, rng: &mut Rng, sh: &mut Shadow) {
        if status == ERROR {
            let records = live.1 .0.records.lock().unwrap();
            let last = records.iter().rev().find(|r| r.status == ERROR).map(|r| r.message.as_str());
            assert!(
                last.is_some_and(|m| m.starts_with(function.name())),
                "{function:?}: an error without its message ({last:?})"
            );
        }
        // now and then an FMI 2.0 function on the FMI 3.0 instance: refused
        if rng.chance(2) {
            let s = unsafe { (self.fmu.functions.terminate)(live.0.c) };
            assert_eq!(s, ERROR, "fmi2Terminate on an FMI 3.0 instance");
            sh.machine = Some(Machine::Error);
        }
    }
}

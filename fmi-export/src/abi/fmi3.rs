//! The FMI 3.0 C ABI: the 75 `fmi3*` functions over the one instance. Each translates
//! pointers to slices and FMI 3.0 value references to the variable table's rows; the
//! state machine, the checks and the semantics are the instance's, shared with FMI 2.0.
//!
//! The FMUs of this layer offer Model Exchange and Co-Simulation (without Event Mode, early
//! return or intermediate update), scalar variables of the types Float64, Int32, Boolean
//! and Enumeration (as Int64), FMU state and its serialization, directional and adjoint
//! derivatives as declared. Every other function (Scheduled Execution, clocks,
//! Configuration Mode, ...) answers `fmi3Error` with a logged message naming it, as does
//! a Get/Set of a type the FMU has no variable of.
#![allow(clippy::missing_safety_doc, clippy::too_many_arguments, non_snake_case)]

use std::collections::HashSet;
use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use fmi_sys::fmi3::*;
use model_description::fmi3::ValueType;

use super::{c_text, out_ptr, panic_text, slice, slice_mut, string, with, Component};
use crate::ffi::{Fmi2Status, FMI2_FALSE, FMI2_TRUE};
use crate::instance::{Function, Generation, Instance, OpResult};
use crate::log::{LogCategory, Logger, LOG_CATEGORIES};
use crate::model::{InstantiateContext, Interface, Model, ModelError};

/// The layer's status as FMI 3.0's (the same numbers; FMI 2.0's `fmi2Pending` never occurs).
fn status3(s: Fmi2Status) -> Fmi3Status {
    match s {
        Fmi2Status::Ok => Fmi3Status::Ok,
        Fmi2Status::Warning => Fmi3Status::Warning,
        Fmi2Status::Discard => Fmi3Status::Discard,
        Fmi2Status::Error | Fmi2Status::Pending => Fmi3Status::Error,
        Fmi2Status::Fatal => Fmi3Status::Fatal,
    }
}

/// Runs `f` on the instance behind `instance` for `function` (see [`super::with`]).
unsafe fn with3<M: Model>(
    instance: fmi3Instance,
    function: Function,
    f: impl FnOnce(&mut Component<M>) -> OpResult,
) -> Fmi3Status {
    status3(with::<M>(instance, function, f))
}

fn truth(b: bool) -> fmi3Boolean {
    if b {
        FMI3_TRUE
    } else {
        FMI3_FALSE
    }
}

/// Scalars only: one value per value reference.
fn check_n_values(n_value_references: usize, n_values: usize) -> OpResult {
    if n_values == n_value_references {
        Ok(())
    } else {
        Err(format!(
            "nValues = {n_values}, but the {n_value_references} value references are all scalars: nValues must be \
             {n_value_references}"
        )
        .into())
    }
}

// ------------------------------------------------------------------ inquire, log, instantiate

pub fn get_version() -> *const c_char {
    c"3.0".as_ptr()
}

pub unsafe fn set_debug_logging<M: Model>(
    instance: fmi3Instance,
    logging_on: fmi3Boolean,
    n: usize,
    categories: *const fmi3String,
) -> Fmi3Status {
    let on = if logging_on != FMI3_FALSE { FMI2_TRUE } else { FMI2_FALSE };
    status3(super::set_debug_logging_as::<M>(Function::Fmi3SetDebugLogging, instance, on, n, categories))
}

/// Logs `message` through an importer's `logMessage` for a call without an instance.
unsafe fn emit3(environment: fmi3InstanceEnvironment, log_message: Option<Fmi3LogMessageCallback>, message: &str) {
    if let Some(log) = log_message {
        let category = c_text(LOG_CATEGORIES[0].0);
        let message = c_text(message);
        log(environment, Fmi3Status::Error as fmi3Status, category.as_ptr(), message.as_ptr());
    }
}

/// The resource path of FMI 3.0: a native path (ending in a separator), or NULL.
unsafe fn resource_path(path: fmi3String) -> Option<PathBuf> {
    string(path).filter(|p| !p.is_empty()).map(PathBuf::from)
}

/// The instantiation shared by Model Exchange and Co-Simulation.
unsafe fn instantiate3<M: Model>(
    function: Function,
    interface: Interface,
    instance_name: fmi3String,
    instantiation_token: fmi3String,
    resource_location: fmi3String,
    logging_on: fmi3Boolean,
    environment: fmi3InstanceEnvironment,
    log_message: Option<Fmi3LogMessageCallback>,
    refuse: impl FnOnce() -> Result<(), String>,
) -> fmi3Instance {
    let fn_name = function.name();
    let result = catch_unwind(AssertUnwindSafe(|| -> Result<Box<Component<M>>, String> {
        let given_name =
            string(instance_name).filter(|s| !s.is_empty()).ok_or("instanceName is NULL, empty or not UTF-8")?;
        refuse()?;
        let declaration = M::declaration();
        let offered = declaration.spec.interfaces;
        let supported = match interface {
            Interface::ModelExchange => offered.model_exchange,
            Interface::CoSimulation => offered.co_simulation,
        };
        if !supported {
            return Err(format!("{} does not offer {interface:?}", declaration.spec.model_identifier));
        }
        let given = string(instantiation_token).ok_or("instantiationToken is NULL or not UTF-8")?;
        if given != declaration.guid() {
            return Err(format!("instantiationToken {given} does not match this binary's {}", declaration.guid()));
        }
        let name = c_text(given_name);
        let logger = Logger::new3(environment, log_message, &name, logging_on != FMI3_FALSE);
        let context = InstantiateContext {
            instance_name: given_name.to_string(),
            interface,
            resource_path: resource_path(resource_location),
            logger: logger.clone(),
        };
        let instance = Instance::<M>::new_for(context, Generation::Fmi3).map_err(|e| e.to_string())?;
        Ok(Box::new(Component { instance, logger, live_states: HashSet::new() }))
    }));
    match result {
        Ok(Ok(component)) => Box::into_raw(component) as fmi3Instance,
        Ok(Err(message)) => {
            emit3(environment, log_message, &format!("{fn_name}: {message}"));
            std::ptr::null_mut()
        }
        Err(payload) => {
            emit3(environment, log_message, &format!("{fn_name}: internal error (panic): {}", panic_text(&*payload)));
            std::ptr::null_mut()
        }
    }
}

pub unsafe fn instantiate_model_exchange<M: Model>(
    instance_name: fmi3String,
    instantiation_token: fmi3String,
    resource_path: fmi3String,
    _visible: fmi3Boolean,
    logging_on: fmi3Boolean,
    environment: fmi3InstanceEnvironment,
    log_message: Option<Fmi3LogMessageCallback>,
) -> fmi3Instance {
    instantiate3::<M>(
        Function::Fmi3InstantiateModelExchange,
        Interface::ModelExchange,
        instance_name,
        instantiation_token,
        resource_path,
        logging_on,
        environment,
        log_message,
        || Ok(()),
    )
}

pub unsafe fn instantiate_co_simulation<M: Model>(
    instance_name: fmi3String,
    instantiation_token: fmi3String,
    resource_path: fmi3String,
    _visible: fmi3Boolean,
    logging_on: fmi3Boolean,
    event_mode_used: fmi3Boolean,
    _early_return_allowed: fmi3Boolean,
    _required_intermediate_variables: *const fmi3ValueReference,
    n_required_intermediate_variables: usize,
    environment: fmi3InstanceEnvironment,
    log_message: Option<Fmi3LogMessageCallback>,
    _intermediate_update: Option<Fmi3IntermediateUpdateCallback>,
) -> fmi3Instance {
    // earlyReturnAllowed needs nothing: fmi3DoStep never returns early
    instantiate3::<M>(
        Function::Fmi3InstantiateCoSimulation,
        Interface::CoSimulation,
        instance_name,
        instantiation_token,
        resource_path,
        logging_on,
        environment,
        log_message,
        || {
            if event_mode_used != FMI3_FALSE {
                return Err("eventModeUsed = true refused: the FMU declares no Event Mode for Co-Simulation \
                            (hasEventMode is false)"
                    .into());
            }
            if n_required_intermediate_variables != 0 {
                return Err(format!(
                    "{n_required_intermediate_variables} required intermediate variables refused: the FMU provides no \
                     intermediate update (providesIntermediateUpdate is false)"
                ));
            }
            Ok(())
        },
    )
}

pub unsafe fn instantiate_scheduled_execution<M: Model>(
    _instance_name: fmi3String,
    _instantiation_token: fmi3String,
    _resource_path: fmi3String,
    _visible: fmi3Boolean,
    _logging_on: fmi3Boolean,
    environment: fmi3InstanceEnvironment,
    log_message: Option<Fmi3LogMessageCallback>,
    _clock_update: Option<Fmi3ClockUpdateCallback>,
    _lock_preemption: Option<Fmi3LockPreemptionCallback>,
    _unlock_preemption: Option<Fmi3UnlockPreemptionCallback>,
) -> fmi3Instance {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        emit3(
            environment,
            log_message,
            &format!(
                "fmi3InstantiateScheduledExecution: {} does not offer Scheduled Execution (only Model Exchange and \
                 Co-Simulation)",
                M::declaration().spec.model_identifier
            ),
        )
    }));
    std::ptr::null_mut()
}

pub unsafe fn free_instance<M: Model>(instance: fmi3Instance) {
    super::fmi2::free_instance::<M>(instance)
}

// ------------------------------------------------------------------ modes

pub unsafe fn enter_initialization_mode<M: Model>(
    instance: fmi3Instance,
    tolerance_defined: fmi3Boolean,
    tolerance: fmi3Float64,
    start_time: fmi3Float64,
    stop_time_defined: fmi3Boolean,
    stop_time: fmi3Float64,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3EnterInitializationMode, |comp| {
        let tol = (tolerance_defined != FMI3_FALSE).then_some(tolerance);
        let stop = (stop_time_defined != FMI3_FALSE).then_some(stop_time);
        comp.instance.setup_experiment(tol, start_time, stop)?;
        comp.instance.enter_initialization_mode()
    })
}

pub unsafe fn exit_initialization_mode<M: Model>(instance: fmi3Instance) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3ExitInitializationMode, |comp| {
        comp.instance.exit_initialization_mode()?;
        comp.log(
            Fmi2Status::Ok,
            LogCategory::Events,
            &format!("initialization done, now {:?}", comp.instance.machine()),
        );
        Ok(())
    })
}

pub unsafe fn enter_event_mode<M: Model>(instance: fmi3Instance) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3EnterEventMode, |comp| comp.instance.enter_event_mode())
}

pub unsafe fn terminate<M: Model>(instance: fmi3Instance) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3Terminate, |comp| comp.instance.terminate())
}

pub unsafe fn reset<M: Model>(instance: fmi3Instance) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3Reset, |comp| comp.instance.reset())
}

/// A function of a feature the FMU does not declare: refused by the instance's gate with
/// the reason ([`Function::undeclared_feature`]).
pub unsafe fn undeclared<M: Model>(instance: fmi3Instance, function: Function) -> Fmi3Status {
    with3::<M>(instance, function, |_| {
        Err(format!("not supported by {}", M::declaration().spec.model_identifier).into())
    })
}

// ------------------------------------------------------------------ getting and setting values

pub unsafe fn get_float64<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *mut fmi3Float64,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetFloat64, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        let out = slice_mut(values, n_values, "values")?;
        comp.instance.get_float64(vr, out)
    })
}

pub unsafe fn set_float64<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *const fmi3Float64,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3SetFloat64, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        let values = slice(values, n_values, "values")?;
        comp.instance.set_float64(vr, values)
    })
}

pub unsafe fn get_int32<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *mut fmi3Int32,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetInt32, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        let out = slice_mut(values, n_values, "values")?;
        comp.instance.get_int(vr, ValueType::Int32, out)
    })
}

pub unsafe fn set_int32<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *const fmi3Int32,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3SetInt32, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        let values: Vec<i64> = slice(values, n_values, "values")?.iter().map(|&x| x as i64).collect();
        comp.instance.set_int(vr, ValueType::Int32, &values)
    })
}

/// `fmi3GetInt64`: the Enumerations (FMI 3.0 accesses them as Int64).
pub unsafe fn get_int64<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *mut fmi3Int64,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetInt64, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        let out = slice_mut(values, n_values, "values")?;
        let mut narrow = vec![0i32; vr.len()];
        comp.instance.get_int(vr, ValueType::Enumeration, &mut narrow)?;
        for (o, x) in out.iter_mut().zip(narrow) {
            *o = x as i64;
        }
        Ok(())
    })
}

/// `fmi3SetInt64`: the Enumerations.
pub unsafe fn set_int64<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *const fmi3Int64,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3SetInt64, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        let values = slice(values, n_values, "values")?;
        comp.instance.set_int(vr, ValueType::Enumeration, values)
    })
}

pub unsafe fn get_boolean<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *mut fmi3Boolean,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetBoolean, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        let out = slice_mut(values, n_values, "values")?;
        let mut bools = vec![false; vr.len()];
        comp.instance.get_boolean3(vr, &mut bools)?;
        for (o, b) in out.iter_mut().zip(bools) {
            *o = truth(b);
        }
        Ok(())
    })
}

pub unsafe fn set_boolean<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *const fmi3Boolean,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3SetBoolean, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        let values: Vec<bool> = slice(values, n_values, "values")?.iter().map(|&b| b != FMI3_FALSE).collect();
        comp.instance.set_boolean3(vr, &values)
    })
}

/// A Get or Set of a type the FMU has no variable of (Float32, the 8/16-bit and unsigned
/// integers, UInt64, String, Binary, Clock): every value reference is refused, naming its
/// actual type; an empty call is fine. `n_values` is `None` for the calls without it.
unsafe fn other_type<M: Model>(
    instance: fmi3Instance,
    function: Function,
    accessed: ValueType,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    n_values: Option<usize>,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
        if let Some(n_values) = n_values {
            check_n_values(n_vr, n_values)?;
        }
        let vr = slice(vr, n_vr, "valueReferences")?;
        comp.instance.fmi2_references(vr, accessed).map(|_| ())
    })
}

macro_rules! other_types {
    ($($get:ident, $set:ident, $gf:ident, $sf:ident, $t:ty, $vt:ident;)*) => {$(
        pub unsafe fn $get<M: Model>(
            instance: fmi3Instance,
            vr: *const fmi3ValueReference,
            n_vr: usize,
            _values: *mut $t,
            n_values: usize,
        ) -> Fmi3Status {
            other_type::<M>(instance, Function::$gf, ValueType::$vt, vr, n_vr, Some(n_values))
        }
        pub unsafe fn $set<M: Model>(
            instance: fmi3Instance,
            vr: *const fmi3ValueReference,
            n_vr: usize,
            _values: *const $t,
            n_values: usize,
        ) -> Fmi3Status {
            other_type::<M>(instance, Function::$sf, ValueType::$vt, vr, n_vr, Some(n_values))
        }
    )*};
}

other_types! {
    get_float32, set_float32, Fmi3GetFloat32, Fmi3SetFloat32, fmi3Float32, Float32;
    get_int8, set_int8, Fmi3GetInt8, Fmi3SetInt8, fmi3Int8, Int8;
    get_uint8, set_uint8, Fmi3GetUInt8, Fmi3SetUInt8, fmi3UInt8, UInt8;
    get_int16, set_int16, Fmi3GetInt16, Fmi3SetInt16, fmi3Int16, Int16;
    get_uint16, set_uint16, Fmi3GetUInt16, Fmi3SetUInt16, fmi3UInt16, UInt16;
    get_uint32, set_uint32, Fmi3GetUInt32, Fmi3SetUInt32, fmi3UInt32, UInt32;
    get_uint64, set_uint64, Fmi3GetUInt64, Fmi3SetUInt64, fmi3UInt64, UInt64;
    get_string, set_string, Fmi3GetString, Fmi3SetString, fmi3String, String;
}

pub unsafe fn get_binary<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    _value_sizes: *mut usize,
    _values: *mut fmi3Binary,
    n_values: usize,
) -> Fmi3Status {
    other_type::<M>(instance, Function::Fmi3GetBinary, ValueType::Binary, vr, n_vr, Some(n_values))
}

pub unsafe fn set_binary<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    _value_sizes: *const usize,
    _values: *const fmi3Binary,
    n_values: usize,
) -> Fmi3Status {
    other_type::<M>(instance, Function::Fmi3SetBinary, ValueType::Binary, vr, n_vr, Some(n_values))
}

pub unsafe fn get_clock<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    _values: *mut fmi3Clock,
) -> Fmi3Status {
    other_type::<M>(instance, Function::Fmi3GetClock, ValueType::Clock, vr, n_vr, None)
}

pub unsafe fn set_clock<M: Model>(
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    _values: *const fmi3Clock,
) -> Fmi3Status {
    other_type::<M>(instance, Function::Fmi3SetClock, ValueType::Clock, vr, n_vr, None)
}

// ------------------------------------------------------------------ variable dependencies

pub unsafe fn get_number_of_variable_dependencies<M: Model>(
    instance: fmi3Instance,
    vr: fmi3ValueReference,
    n: *mut usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetNumberOfVariableDependencies, |comp| {
        let out = out_ptr(n, "nDependencies")?;
        *out = comp.instance.variable_dependencies(vr)?.len();
        Ok(())
    })
}

pub unsafe fn get_variable_dependencies<M: Model>(
    instance: fmi3Instance,
    dependent: fmi3ValueReference,
    element_indices_of_dependent: *mut usize,
    independents: *mut fmi3ValueReference,
    element_indices_of_independents: *mut usize,
    dependency_kinds: *mut fmi3DependencyKind,
    n_dependencies: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetVariableDependencies, |comp| {
        let on = comp.instance.variable_dependencies(dependent)?;
        if n_dependencies != on.len() {
            return Err(format!(
                "nDependencies = {n_dependencies}, but value reference {dependent} has {} dependencies \
                 (fmi3GetNumberOfVariableDependencies)",
                on.len()
            )
            .into());
        }
        let element_of_dependent = slice_mut(element_indices_of_dependent, on.len(), "elementIndicesOfDependent")?;
        let vrs = slice_mut(independents, on.len(), "independents")?;
        let element_of_independent =
            slice_mut(element_indices_of_independents, on.len(), "elementIndicesOfIndependents")?;
        let kinds = slice_mut(dependency_kinds, on.len(), "dependencyKinds")?;
        for (k, &vr) in on.iter().enumerate() {
            // scalars: element index 0; no dependenciesKind declared: "dependent"
            element_of_dependent[k] = 0;
            vrs[k] = vr;
            element_of_independent[k] = 0;
            kinds[k] = FMI3_DEPENDENT;
        }
        Ok(())
    })
}

// ------------------------------------------------------------------ FMU state

pub unsafe fn get_fmu_state<M: Model>(instance: fmi3Instance, state: *mut fmi3FMUState) -> Fmi3Status {
    status3(super::get_fmu_state_as::<M>(Function::Fmi3GetFMUState, instance, state))
}

pub unsafe fn set_fmu_state<M: Model>(instance: fmi3Instance, state: fmi3FMUState) -> Fmi3Status {
    status3(super::set_fmu_state_as::<M>(Function::Fmi3SetFMUState, instance, state))
}

pub unsafe fn free_fmu_state<M: Model>(instance: fmi3Instance, state: *mut fmi3FMUState) -> Fmi3Status {
    status3(super::free_fmu_state_as::<M>(Function::Fmi3FreeFMUState, instance, state))
}

pub unsafe fn serialized_fmu_state_size<M: Model>(
    instance: fmi3Instance,
    state: fmi3FMUState,
    size: *mut usize,
) -> Fmi3Status {
    status3(super::serialized_fmu_state_size_as::<M>(Function::Fmi3SerializedFMUStateSize, instance, state, size))
}

pub unsafe fn serialize_fmu_state<M: Model>(
    instance: fmi3Instance,
    state: fmi3FMUState,
    bytes: *mut fmi3Byte,
    size: usize,
) -> Fmi3Status {
    status3(super::serialize_fmu_state_as::<M>(
        Function::Fmi3SerializeFMUState,
        instance,
        state,
        bytes as *mut crate::ffi::fmi2Byte,
        size,
    ))
}

pub unsafe fn deserialize_fmu_state<M: Model>(
    instance: fmi3Instance,
    bytes: *const fmi3Byte,
    size: usize,
    state: *mut fmi3FMUState,
) -> Fmi3Status {
    status3(super::deserialize_fmu_state_as::<M>(
        Function::Fmi3DeserializeFMUState,
        instance,
        bytes as *const crate::ffi::fmi2Byte,
        size,
        state,
    ))
}

// ------------------------------------------------------------------ partial derivatives

/// `fmi3GetDirectionalDerivative`: `sensitivity = J seed`, `J` the partial derivatives of
/// the unknowns with respect to the knowns.
pub unsafe fn get_directional_derivative<M: Model>(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    n_unknowns: usize,
    knowns: *const fmi3ValueReference,
    n_knowns: usize,
    seed: *const fmi3Float64,
    n_seed: usize,
    sensitivity: *mut fmi3Float64,
    n_sensitivity: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetDirectionalDerivative, |comp| {
        if n_seed != n_knowns || n_sensitivity != n_unknowns {
            return Err(format!(
                "nSeed = {n_seed} and nSensitivity = {n_sensitivity} refused: the {n_knowns} knowns and \
                 {n_unknowns} unknowns are scalars, so nSeed must be {n_knowns} and nSensitivity {n_unknowns}"
            )
            .into());
        }
        let unknowns = comp.instance.real_references(slice(unknowns, n_unknowns, "unknowns")?)?;
        let knowns = comp.instance.real_references(slice(knowns, n_knowns, "knowns")?)?;
        let seed = slice(seed, n_seed, "seed")?;
        let out = slice_mut(sensitivity, n_sensitivity, "sensitivity")?;
        comp.instance.directional_derivative(&unknowns, &knowns, seed, out)
    })
}

/// `fmi3GetAdjointDerivative`: `sensitivity = J^T seed` (seed per unknown, sensitivity per
/// known), exact from J's columns ([`Instance::adjoint_derivative`]).
pub unsafe fn get_adjoint_derivative<M: Model>(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    n_unknowns: usize,
    knowns: *const fmi3ValueReference,
    n_knowns: usize,
    seed: *const fmi3Float64,
    n_seed: usize,
    sensitivity: *mut fmi3Float64,
    n_sensitivity: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetAdjointDerivative, |comp| {
        if n_seed != n_unknowns || n_sensitivity != n_knowns {
            return Err(format!(
                "nSeed = {n_seed} and nSensitivity = {n_sensitivity} refused: the {n_unknowns} unknowns and \
                 {n_knowns} knowns are scalars, so nSeed must be {n_unknowns} and nSensitivity {n_knowns}"
            )
            .into());
        }
        let unknowns = comp.instance.real_references(slice(unknowns, n_unknowns, "unknowns")?)?;
        let knowns = comp.instance.real_references(slice(knowns, n_knowns, "knowns")?)?;
        let seed = slice(seed, n_seed, "seed")?;
        let out = slice_mut(sensitivity, n_sensitivity, "sensitivity")?;
        comp.instance.adjoint_derivative(&unknowns, &knowns, seed, out)
    })
}

// ------------------------------------------------------------------ Model Exchange

pub unsafe fn update_discrete_states<M: Model>(
    instance: fmi3Instance,
    discrete_states_need_update: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
    nominals_changed: *mut fmi3Boolean,
    values_changed: *mut fmi3Boolean,
    next_event_time_defined: *mut fmi3Boolean,
    next_event_time: *mut fmi3Float64,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3UpdateDiscreteStates, |comp| {
        let need = out_ptr(discrete_states_need_update, "discreteStatesNeedUpdate")?;
        let terminate = out_ptr(terminate_simulation, "terminateSimulation")?;
        let nominals = out_ptr(nominals_changed, "nominalsOfContinuousStatesChanged")?;
        let values = out_ptr(values_changed, "valuesOfContinuousStatesChanged")?;
        let defined = out_ptr(next_event_time_defined, "nextEventTimeDefined")?;
        let time = out_ptr(next_event_time, "nextEventTime")?;
        let update = comp.instance.new_discrete_states()?;
        *need = truth(update.new_discrete_states_needed);
        *terminate = truth(update.terminate_simulation);
        *nominals = FMI3_FALSE;
        *values = truth(update.values_of_continuous_states_changed);
        *defined = truth(update.next_event_time.is_some());
        *time = update.next_event_time.unwrap_or(0.0);
        if let Some(t) = update.next_event_time {
            comp.log(Fmi2Status::Ok, LogCategory::Events, &format!("next time event at {t}"));
        }
        Ok(())
    })
}

pub unsafe fn enter_continuous_time_mode<M: Model>(instance: fmi3Instance) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3EnterContinuousTimeMode, |comp| comp.instance.enter_continuous_time_mode())
}

pub unsafe fn completed_integrator_step<M: Model>(
    instance: fmi3Instance,
    _no_set_prior: fmi3Boolean,
    enter_event_mode: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3CompletedIntegratorStep, |_| {
        let enter = out_ptr(enter_event_mode, "enterEventMode")?;
        let terminate = out_ptr(terminate_simulation, "terminateSimulation")?;
        *enter = FMI3_FALSE;
        *terminate = FMI3_FALSE;
        Ok(())
    })
}

pub unsafe fn set_time<M: Model>(instance: fmi3Instance, time: fmi3Float64) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3SetTime, |comp| comp.instance.set_time(time))
}

pub unsafe fn set_continuous_states<M: Model>(instance: fmi3Instance, x: *const fmi3Float64, nx: usize) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3SetContinuousStates, |comp| {
        let x = slice(x, nx, "continuousStates")?;
        comp.instance.set_continuous_states(x)
    })
}

pub unsafe fn get_continuous_state_derivatives<M: Model>(
    instance: fmi3Instance,
    dx: *mut fmi3Float64,
    nx: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetContinuousStateDerivatives, |comp| {
        let out = slice_mut(dx, nx, "derivatives")?;
        comp.instance.get_derivatives(out)
    })
}

pub unsafe fn get_event_indicators<M: Model>(instance: fmi3Instance, z: *mut fmi3Float64, n: usize) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetEventIndicators, |comp| {
        let out = slice_mut(z, n, "eventIndicators")?;
        comp.instance.get_event_indicators(out)
    })
}

pub unsafe fn get_continuous_states<M: Model>(instance: fmi3Instance, x: *mut fmi3Float64, nx: usize) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetContinuousStates, |comp| {
        let out = slice_mut(x, nx, "continuousStates")?;
        comp.instance.get_continuous_states(out)
    })
}

pub unsafe fn get_nominals_of_continuous_states<M: Model>(
    instance: fmi3Instance,
    x: *mut fmi3Float64,
    nx: usize,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetNominalsOfContinuousStates, |comp| {
        let out = slice_mut(x, nx, "nominals")?;
        comp.instance.get_nominals(out)
    })
}

pub unsafe fn get_number_of_event_indicators<M: Model>(instance: fmi3Instance, n: *mut usize) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetNumberOfEventIndicators, |_| {
        // no state events: the ModelStructure lists no <EventIndicator>
        *out_ptr(n, "nEventIndicators")? = 0;
        Ok(())
    })
}

pub unsafe fn get_number_of_continuous_states<M: Model>(instance: fmi3Instance, n: *mut usize) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3GetNumberOfContinuousStates, |_| {
        *out_ptr(n, "nContinuousStates")? = M::declaration().number_of_states();
        Ok(())
    })
}

// ------------------------------------------------------------------ Co-Simulation

/// `fmi3DoStep`: the step of [`Instance::do_step`]; never an early return, never an event
/// to handle (no Event Mode); `terminateSimulation` when the run ends at the step's end
/// (a sampled model's last sample is due) or the model asked to end it (a Discard then, as
/// in FMI 2.0); `lastSuccessfulTime` the instance's time after the call.
pub unsafe fn do_step<M: Model>(
    instance: fmi3Instance,
    current: fmi3Float64,
    step: fmi3Float64,
    _no_set_prior: fmi3Boolean,
    event_handling_needed: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
    early_return: *mut fmi3Boolean,
    last_successful_time: *mut fmi3Float64,
) -> Fmi3Status {
    with3::<M>(instance, Function::Fmi3DoStep, |comp| {
        let event = out_ptr(event_handling_needed, "eventHandlingNeeded")?;
        let terminate = out_ptr(terminate_simulation, "terminateSimulation")?;
        let early = out_ptr(early_return, "earlyReturn")?;
        let last = out_ptr(last_successful_time, "lastSuccessfulTime")?;
        let outcome = comp.instance.do_step(current, step);
        *event = FMI3_FALSE;
        *early = FMI3_FALSE;
        *last = comp.instance.time();
        *terminate = truth(match &outcome {
            Ok(()) => comp.instance.run_ends(),
            Err(ModelError::Discard(_)) => comp.instance.core.terminate_requested,
            Err(ModelError::Error(_)) => false,
        });
        outcome
    })
}

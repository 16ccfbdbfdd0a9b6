//! The FMI 3.0 C ABI: the 75 `fmi3*` functions over the one instance. Each translates
//! pointers to slices and FMI 3.0 value references to the variable table's rows; the
//! state machine, the checks and the semantics are the instance's, shared with FMI 2.0.
//!
//! The FMUs of this layer offer Model Exchange and Co-Simulation (without Event Mode, early
//! return or intermediate update), scalar variables of the types Float64, Int32, Boolean
//! and Enumeration (as Int64), FMU state and its serialization, directional and adjoint
//! derivatives as declared; with a declared clock, the clock functions and Co-Simulation with
//! Event Mode. Every other function (Scheduled Execution, Configuration Mode, ...) answers
//! `fmi3Error` with a logged message naming it, as does a Get/Set of a type the FMU has no
//! variable of.
#![allow(clippy::missing_safety_doc, clippy::too_many_arguments, non_snake_case)]

use std::collections::HashSet;
use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use fmi_sys::fmi3::*;
use model_description::fmi3::ValueType;

use super::{c_text, out_ptr, panic_text, slice, slice_mut, string, with, Component};
use crate::ffi::{Fmi2Status, FMI2_FALSE, FMI2_TRUE};
use crate::instance::{Function, Generation, Instance, IntervalQualifier, OpResult};
use crate::log::{LogCategory, Logger, LOG_CATEGORIES};
use crate::model::{InstantiateContext, Interface, Model, ModelError};

/// The layer's status as FMI 3.0's (the same numbers; FMI 2.0's `fmi2Pending` never occurs).
pub fn status3(s: Fmi2Status) -> Fmi3Status {
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

pub fn get_version<M>(_: Function) -> *const c_char {
    c"3.0".as_ptr()
}

pub unsafe fn set_debug_logging<M: Model>(
    function: Function,
    instance: fmi3Instance,
    logging_on: fmi3Boolean,
    n: usize,
    categories: *const fmi3String,
) -> Fmi3Status {
    let on = if logging_on != FMI3_FALSE { FMI2_TRUE } else { FMI2_FALSE };
    status3(super::shared::set_debug_logging::<M>(function, instance, on, n, categories))
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
    event_mode_used: bool,
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
            // the model partition of Scheduled Execution is the declared clock's
            Interface::ScheduledExecution => declaration.clock().is_some(),
        };
        if !supported {
            let why = if interface == Interface::ScheduledExecution { " (it declares no clock)" } else { "" };
            return Err(format!("{} does not offer {interface:?}{why}", declaration.spec.model_identifier));
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
        let mut instance = Instance::<M>::new_for(context, Generation::Fmi3).map_err(|e| e.to_string())?;
        if !event_mode_used && interface == Interface::CoSimulation && declaration.clock().is_some() {
            let why = instance.sample_without_event_mode().map_err(|e| e.to_string())?;
            logger.log(LogCategory::Events, &format!("{fn_name}: {why}"));
        }
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
    function: Function,
    instance_name: fmi3String,
    instantiation_token: fmi3String,
    resource_path: fmi3String,
    _visible: fmi3Boolean,
    logging_on: fmi3Boolean,
    environment: fmi3InstanceEnvironment,
    log_message: Option<Fmi3LogMessageCallback>,
) -> fmi3Instance {
    instantiate3::<M>(
        function,
        Interface::ModelExchange,
        instance_name,
        instantiation_token,
        resource_path,
        logging_on,
        environment,
        log_message,
        true,
        || Ok(()),
    )
}

pub unsafe fn instantiate_co_simulation<M: Model>(
    function: Function,
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
        function,
        Interface::CoSimulation,
        instance_name,
        instantiation_token,
        resource_path,
        logging_on,
        environment,
        log_message,
        event_mode_used != FMI3_FALSE,
        || {
            // eventModeUsed = false with a clock: the instance samples by time itself
            // (Instance::sample_without_event_mode, in instantiate3)
            if event_mode_used != FMI3_FALSE && M::declaration().clock().is_none() {
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

/// `fmi3InstantiateScheduledExecution`: offered by a model with a declared clock, whose
/// model partition `fmi3ActivateModelPartition` runs. The FMU calls none of the callbacks:
/// its one clock is an input clock (no `clockUpdate`), and its one partition shares no data
/// with another that could preempt it (no `lockPreemption`).
pub unsafe fn instantiate_scheduled_execution<M: Model>(
    function: Function,
    instance_name: fmi3String,
    instantiation_token: fmi3String,
    resource_path: fmi3String,
    _visible: fmi3Boolean,
    logging_on: fmi3Boolean,
    environment: fmi3InstanceEnvironment,
    log_message: Option<Fmi3LogMessageCallback>,
    _clock_update: Option<Fmi3ClockUpdateCallback>,
    _lock_preemption: Option<Fmi3LockPreemptionCallback>,
    _unlock_preemption: Option<Fmi3UnlockPreemptionCallback>,
) -> fmi3Instance {
    instantiate3::<M>(
        function,
        Interface::ScheduledExecution,
        instance_name,
        instantiation_token,
        resource_path,
        logging_on,
        environment,
        log_message,
        true,
        || Ok(()),
    )
}

// ------------------------------------------------------------------ modes

pub unsafe fn enter_initialization_mode<M: Model>(
    function: Function,
    instance: fmi3Instance,
    tolerance_defined: fmi3Boolean,
    tolerance: fmi3Float64,
    start_time: fmi3Float64,
    stop_time_defined: fmi3Boolean,
    stop_time: fmi3Float64,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
        let tol = (tolerance_defined != FMI3_FALSE).then_some(tolerance);
        let stop = (stop_time_defined != FMI3_FALSE).then_some(stop_time);
        comp.instance.setup_experiment(tol, start_time, stop)?;
        comp.instance.enter_initialization_mode()
    })
}

/// A function of a feature the FMU does not declare: refused by the instance's gate with
/// the reason ([`Function::undeclared_feature`]).
pub unsafe fn undeclared<M: Model>(function: Function, instance: fmi3Instance) -> Fmi3Status {
    with3::<M>(instance, function, |_| {
        Err(format!("not supported by {}", M::declaration().spec.model_identifier).into())
    })
}

// ------------------------------------------------------------------ getting and setting values

/// The FMI 3.0 value types, the type argument of [`get`] and [`set`] (`fmi3GetFloat64` is
/// `get::<M, value::Float64>`; `fmi3GetInt64` reads the Enumerations).
pub mod value {
    pub struct Float64;
    pub struct Int32;
    pub struct Enumeration;
    pub struct Boolean;
    pub struct Float32;
    pub struct Int8;
    pub struct UInt8;
    pub struct Int16;
    pub struct UInt16;
    pub struct UInt32;
    pub struct UInt64;
    pub struct String;
}

/// An FMI 3.0 value type as its `fmi3Get*`/`fmi3Set*` pass it: the C element, the
/// variable type it accesses and the instance's access. A type the FMUs have no variable
/// of keeps the defaults: every value reference is refused naming its actual type (before
/// the values are looked at), an empty call is fine.
pub trait Value {
    type C: Copy;
    const ACCESSED: ValueType;
    fn check<M: Model>(instance: &Instance<M>, vr: &[u32]) -> OpResult {
        instance.fmi2_references(vr, Self::ACCESSED).map(|_| ())
    }
    fn get<M: Model>(_: &mut Instance<M>, _: &[u32], _: &mut [Self::C]) -> OpResult {
        Ok(())
    }
    fn set<M: Model>(_: &mut Instance<M>, _: &[u32], _: &[Self::C]) -> OpResult {
        Ok(())
    }
}

impl Value for value::Float64 {
    type C = fmi3Float64;
    const ACCESSED: ValueType = ValueType::Float64;
    fn check<M: Model>(_: &Instance<M>, _: &[u32]) -> OpResult {
        Ok(())
    }
    fn get<M: Model>(instance: &mut Instance<M>, vr: &[u32], out: &mut [f64]) -> OpResult {
        instance.get_float64(vr, out)
    }
    fn set<M: Model>(instance: &mut Instance<M>, vr: &[u32], values: &[f64]) -> OpResult {
        instance.set_float64(vr, values)
    }
}

impl Value for value::Int32 {
    type C = fmi3Int32;
    const ACCESSED: ValueType = ValueType::Int32;
    fn check<M: Model>(_: &Instance<M>, _: &[u32]) -> OpResult {
        Ok(())
    }
    fn get<M: Model>(instance: &mut Instance<M>, vr: &[u32], out: &mut [i32]) -> OpResult {
        instance.get_int(vr, Self::ACCESSED, out)
    }
    fn set<M: Model>(instance: &mut Instance<M>, vr: &[u32], values: &[i32]) -> OpResult {
        let values: Vec<i64> = values.iter().map(|&x| x as i64).collect();
        instance.set_int(vr, Self::ACCESSED, &values)
    }
}

/// The Enumerations, which FMI 3.0 reads and writes as Int64.
impl Value for value::Enumeration {
    type C = fmi3Int64;
    const ACCESSED: ValueType = ValueType::Enumeration;
    fn check<M: Model>(_: &Instance<M>, _: &[u32]) -> OpResult {
        Ok(())
    }
    fn get<M: Model>(instance: &mut Instance<M>, vr: &[u32], out: &mut [i64]) -> OpResult {
        let mut narrow = vec![0i32; vr.len()];
        instance.get_int(vr, Self::ACCESSED, &mut narrow)?;
        for (o, x) in out.iter_mut().zip(narrow) {
            *o = x as i64;
        }
        Ok(())
    }
    fn set<M: Model>(instance: &mut Instance<M>, vr: &[u32], values: &[i64]) -> OpResult {
        instance.set_int(vr, Self::ACCESSED, values)
    }
}

impl Value for value::Boolean {
    type C = fmi3Boolean;
    const ACCESSED: ValueType = ValueType::Boolean;
    fn check<M: Model>(_: &Instance<M>, _: &[u32]) -> OpResult {
        Ok(())
    }
    fn get<M: Model>(instance: &mut Instance<M>, vr: &[u32], out: &mut [fmi3Boolean]) -> OpResult {
        let mut bools = vec![false; vr.len()];
        instance.get_boolean3(vr, &mut bools)?;
        for (o, b) in out.iter_mut().zip(bools) {
            *o = truth(b);
        }
        Ok(())
    }
    fn set<M: Model>(instance: &mut Instance<M>, vr: &[u32], values: &[fmi3Boolean]) -> OpResult {
        let values: Vec<bool> = values.iter().map(|&b| b != FMI3_FALSE).collect();
        instance.set_boolean3(vr, &values)
    }
}

macro_rules! no_variables_of {
    ($($marker:ident: $c:ty;)*) => {$(
        impl Value for value::$marker {
            type C = $c;
            const ACCESSED: ValueType = ValueType::$marker;
        }
    )*};
}

no_variables_of! {
    Float32: fmi3Float32;
    Int8: fmi3Int8;
    UInt8: fmi3UInt8;
    Int16: fmi3Int16;
    UInt16: fmi3UInt16;
    UInt32: fmi3UInt32;
    UInt64: fmi3UInt64;
    String: fmi3String;
}

/// `fmi3Get<T>` for every value type but Binary and Clock.
pub unsafe fn get<M: Model, T: Value>(
    function: Function,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *mut T::C,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        T::check(&comp.instance, vr)?;
        let out = slice_mut(values, n_values, "values")?;
        T::get(&mut comp.instance, vr, out)
    })
}

/// `fmi3Set<T>` for every value type but Binary and Clock.
pub unsafe fn set<M: Model, T: Value>(
    function: Function,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *const T::C,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        T::check(&comp.instance, vr)?;
        let values = slice(values, n_values, "values")?;
        T::set(&mut comp.instance, vr, values)
    })
}

/// `fmi3GetBinary`, `fmi3SetBinary`: the FMUs have no Binary variables (see [`Value`]).
pub unsafe fn binary<M: Model>(
    function: Function,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    n_values: usize,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
        check_n_values(n_vr, n_values)?;
        let vr = slice(vr, n_vr, "valueReferences")?;
        comp.instance.fmi2_references(vr, ValueType::Binary).map(|_| ())
    })
}

// ------------------------------------------------------------------ clocks (a model with a declared clock)

/// `fmi3GetClock`: whether the clock is active.
pub unsafe fn get_clock<M: Model>(
    function: Function,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *mut fmi3Clock,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
        let vr = slice(vr, n_vr, "valueReferences")?;
        let out = slice_mut(values, n_vr, "values")?;
        let active = comp.instance.get_clock(vr)?;
        out.fill(if active { FMI3_CLOCK_ACTIVE } else { FMI3_CLOCK_INACTIVE });
        Ok(())
    })
}

/// `fmi3SetClock`: activates the clock (a value other than 0 or 1 is refused).
pub unsafe fn set_clock<M: Model>(
    function: Function,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    values: *const fmi3Clock,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
        let vr = slice(vr, n_vr, "valueReferences")?;
        let values = slice(values, n_vr, "values")?;
        if let Some(k) = values.iter().position(|&v| v != FMI3_CLOCK_ACTIVE && v != FMI3_CLOCK_INACTIVE) {
            return Err(format!(
                "values[{k}] = {} for value reference {} is neither fmi3ClockActive (1) nor fmi3ClockInactive (0)",
                values[k], vr[k]
            )
            .into());
        }
        // (no buffer: called at every activation)
        comp.instance.set_clock(vr, values.iter().map(|&v| v == FMI3_CLOCK_ACTIVE))
    })
}

/// `fmi3GetIntervalDecimal`: the clock's interval and its qualifier.
pub unsafe fn get_interval_decimal<M: Model>(
    function: Function,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    intervals: *mut fmi3Float64,
    qualifiers: *mut fmi3IntervalQualifier,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
        let vr = slice(vr, n_vr, "valueReferences")?;
        let intervals = slice_mut(intervals, n_vr, "intervals")?;
        let qualifiers = slice_mut(qualifiers, n_vr, "qualifiers")?;
        let mut values = vec![(0.0, IntervalQualifier::Unchanged); vr.len()];
        comp.instance.clock_intervals(vr, &mut values)?;
        for ((i, q), (interval, qualifier)) in intervals.iter_mut().zip(qualifiers.iter_mut()).zip(values) {
            *i = interval;
            *q = match qualifier {
                IntervalQualifier::Unchanged => FMI3_INTERVAL_UNCHANGED,
                IntervalQualifier::Changed => FMI3_INTERVAL_CHANGED,
            };
        }
        Ok(())
    })
}

/// `fmi3GetShiftDecimal`: the clock's shift (0: the first activation is at the start time).
pub unsafe fn get_shift_decimal<M: Model>(
    function: Function,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
    shifts: *mut fmi3Float64,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
        let vr = slice(vr, n_vr, "valueReferences")?;
        let out = slice_mut(shifts, n_vr, "shifts")?;
        comp.instance.clock_shifts(vr, out)
    })
}

/// `fmi3GetIntervalFraction`, `fmi3GetShiftFraction`: refused (`supportsFraction` is false).
pub unsafe fn clock_fraction<M: Model>(
    function: Function,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| comp.instance.refuse_clock_fraction(slice(vr, n_vr, "valueReferences")?))
}

/// `fmi3SetIntervalDecimal`/`Fraction`, `fmi3SetShiftDecimal`/`Fraction`: refused, the
/// clock's timing is the FMU's.
pub unsafe fn clock_timing<M: Model>(
    function: Function,
    instance: fmi3Instance,
    vr: *const fmi3ValueReference,
    n_vr: usize,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| comp.instance.refuse_clock_timing(slice(vr, n_vr, "valueReferences")?))
}

/// `fmi3ActivateModelPartition` (Scheduled Execution): the declared clock's partition (the
/// model's sample) at `activationTime`.
pub unsafe fn activate_model_partition<M: Model>(
    function: Function,
    instance: fmi3Instance,
    clock: fmi3ValueReference,
    activation_time: fmi3Float64,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| comp.instance.activate_model_partition(clock, activation_time))
}

/// `fmi3EnterStepMode` (Co-Simulation with Event Mode): from Event Mode to Step Mode.
pub unsafe fn enter_step_mode<M: Model>(function: Function, instance: fmi3Instance) -> Fmi3Status {
    with3::<M>(instance, function, |comp| comp.instance.enter_step_mode())
}

// ------------------------------------------------------------------ variable dependencies

pub unsafe fn get_number_of_variable_dependencies<M: Model>(
    function: Function,
    instance: fmi3Instance,
    vr: fmi3ValueReference,
    n: *mut usize,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
        let out = out_ptr(n, "nDependencies")?;
        *out = comp.instance.variable_dependencies(vr)?.len();
        Ok(())
    })
}

pub unsafe fn get_variable_dependencies<M: Model>(
    function: Function,
    instance: fmi3Instance,
    dependent: fmi3ValueReference,
    element_indices_of_dependent: *mut usize,
    independents: *mut fmi3ValueReference,
    element_indices_of_independents: *mut usize,
    dependency_kinds: *mut fmi3DependencyKind,
    n_dependencies: usize,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
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

// ------------------------------------------------------------------ partial derivatives

/// `fmi3GetDirectionalDerivative` (`sensitivity = J seed`, a seed per known) and
/// `fmi3GetAdjointDerivative` (`sensitivity = J^T seed`, a seed per unknown, exact from J's
/// columns: [`Instance::adjoint_derivative`]), `J` the partial derivatives of the unknowns
/// with respect to the knowns.
pub unsafe fn get_partial_derivatives<M: Model>(
    function: Function,
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
    let adjoint = function == Function::Fmi3GetAdjointDerivative;
    with3::<M>(instance, function, |comp| {
        let ((seeded, n_seeded), (sensed, n_sensed)) = if adjoint {
            (("unknowns", n_unknowns), ("knowns", n_knowns))
        } else {
            (("knowns", n_knowns), ("unknowns", n_unknowns))
        };
        if n_seed != n_seeded || n_sensitivity != n_sensed {
            return Err(format!(
                "nSeed = {n_seed} and nSensitivity = {n_sensitivity} refused: the {n_seeded} {seeded} and \
                 {n_sensed} {sensed} are scalars, so nSeed must be {n_seeded} and nSensitivity {n_sensed}"
            )
            .into());
        }
        let unknowns = comp.instance.real_references(slice(unknowns, n_unknowns, "unknowns")?)?;
        let knowns = comp.instance.real_references(slice(knowns, n_knowns, "knowns")?)?;
        let seed = slice(seed, n_seed, "seed")?;
        let out = slice_mut(sensitivity, n_sensitivity, "sensitivity")?;
        if adjoint {
            comp.instance.adjoint_derivative(&unknowns, &knowns, seed, out)
        } else {
            comp.instance.directional_derivative(&unknowns, &knowns, seed, out)
        }
    })
}

// ------------------------------------------------------------------ Model Exchange

pub unsafe fn update_discrete_states<M: Model>(
    function: Function,
    instance: fmi3Instance,
    discrete_states_need_update: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
    nominals_changed: *mut fmi3Boolean,
    values_changed: *mut fmi3Boolean,
    next_event_time_defined: *mut fmi3Boolean,
    next_event_time: *mut fmi3Float64,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
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

pub unsafe fn get_number_of_event_indicators<M: Model>(
    function: Function,
    instance: fmi3Instance,
    n: *mut usize,
) -> Fmi3Status {
    with3::<M>(instance, function, |_| {
        // no state events: the ModelStructure lists no <EventIndicator>
        *out_ptr(n, "nEventIndicators")? = 0;
        Ok(())
    })
}

pub unsafe fn get_number_of_continuous_states<M: Model>(
    function: Function,
    instance: fmi3Instance,
    n: *mut usize,
) -> Fmi3Status {
    with3::<M>(instance, function, |_| {
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
    function: Function,
    instance: fmi3Instance,
    current: fmi3Float64,
    step: fmi3Float64,
    _no_set_prior: fmi3Boolean,
    event_handling_needed: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
    early_return: *mut fmi3Boolean,
    last_successful_time: *mut fmi3Float64,
) -> Fmi3Status {
    with3::<M>(instance, function, |comp| {
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

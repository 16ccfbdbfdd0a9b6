//! The FMI 2.0 C ABI: the 44 `fmi2*` functions over the one instance.
#![allow(clippy::missing_safety_doc, clippy::too_many_arguments, non_snake_case)]

use std::collections::HashSet;
use std::ffi::{c_char, c_int, c_void, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

use super::{c_text, emit, out_ptr, panic_text, slice, slice_mut, string, with, Component};
use crate::ffi::*;
use crate::instance::{Function, Instance, Machine, OpResult};
use crate::log::{LogCategory, Logger, LOG_CATEGORIES};
use crate::model::{InstantiateContext, Interface, Model};

// ------------------------------------------------------------------ common functions

pub fn get_types_platform<M>(_: Function) -> *const c_char {
    c"default".as_ptr()
}

pub fn get_version<M>(_: Function) -> *const c_char {
    c"2.0".as_ptr()
}

pub unsafe fn instantiate<M: Model>(
    _: Function,
    instance_name: fmi2String,
    fmu_type: c_int,
    guid: fmi2String,
    resource_location: fmi2String,
    functions: *const Fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    let Some(callbacks) = functions.as_ref().copied() else { return std::ptr::null_mut() };
    if callbacks.logger.is_none() {
        return std::ptr::null_mut();
    }
    let fallback_name = c"(unnamed instance)";
    let name = string(instance_name).map(c_text).unwrap_or_else(|| fallback_name.to_owned());
    let result = catch_unwind(AssertUnwindSafe(|| -> Result<Box<Component<M>>, String> {
        let given_name =
            string(instance_name).filter(|s| !s.is_empty()).ok_or("instanceName is NULL, empty or not UTF-8")?;
        let interface = match fmu_type {
            0 => Interface::ModelExchange,
            1 => Interface::CoSimulation,
            other => return Err(format!("fmuType {other} is neither fmi2ModelExchange (0) nor fmi2CoSimulation (1)")),
        };
        let declaration = M::declaration();
        let offered = declaration.spec.interfaces;
        let supported = match interface {
            Interface::ModelExchange => offered.model_exchange,
            Interface::CoSimulation => offered.co_simulation,
            // not an FMI 2.0 interface (fmuType above is 0 or 1)
            Interface::ScheduledExecution => false,
        };
        if !supported {
            return Err(format!("{} does not offer {interface:?}", declaration.spec.model_identifier));
        }
        let given = string(guid).ok_or("fmuGUID is NULL or not UTF-8")?;
        if given != declaration.guid() {
            return Err(format!("fmuGUID {given} does not match this binary's {}", declaration.guid()));
        }
        let logger = Logger::new(callbacks, &name, logging_on != FMI2_FALSE);
        let resource_path = string(resource_location).and_then(crate::uri::resource_path);
        let context = InstantiateContext {
            instance_name: given_name.to_string(),
            interface,
            resource_path,
            logger: logger.clone(),
        };
        let instance = Instance::<M>::new(context).map_err(|e| e.to_string())?;
        Ok(Box::new(Component { instance, logger, live_states: HashSet::new() }))
    }));
    match result {
        Ok(Ok(component)) => {
            if component.instance.context.resource_path.is_none() && !resource_location.is_null() {
                let given = CStr::from_ptr(resource_location).to_string_lossy();
                component.log(
                    Fmi2Status::Warning,
                    LogCategory::Warning,
                    &format!("fmi2Instantiate: resource location {given:?} is not a usable file URI"),
                );
            }
            Box::into_raw(component) as fmi2Component
        }
        Ok(Err(message)) => {
            emit(&callbacks, &name, Fmi2Status::Error, LOG_CATEGORIES[0].0, &format!("fmi2Instantiate: {message}"));
            std::ptr::null_mut()
        }
        Err(payload) => {
            let message = format!("fmi2Instantiate: internal error (panic): {}", panic_text(&*payload));
            emit(&callbacks, &name, Fmi2Status::Error, LOG_CATEGORIES[0].0, &message);
            std::ptr::null_mut()
        }
    }
}

pub unsafe fn setup_experiment<M: Model>(
    function: Function,
    c: fmi2Component,
    tolerance_defined: fmi2Boolean,
    tolerance: f64,
    start_time: f64,
    stop_time_defined: fmi2Boolean,
    stop_time: f64,
) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let tol = (tolerance_defined != FMI2_FALSE).then_some(tolerance);
        let stop = (stop_time_defined != FMI2_FALSE).then_some(stop_time);
        comp.instance.setup_experiment(tol, start_time, stop)
    })
}

/// The FMI 2.0 base types, the type argument of [`get`] and [`set`] (`fmi2GetReal` is
/// `get::<M, value::Real>`).
pub mod value {
    pub struct Real;
    pub struct Integer;
    pub struct Boolean;
    pub struct String;
}

/// An FMI 2.0 base type as its `fmi2Get*`/`fmi2Set*` pass it: the C element and the
/// instance's access.
pub trait Value {
    type C: Copy;
    /// Refuses the value references before the values are looked at (the model has no
    /// variable of this type).
    fn check(_vr: &[u32]) -> OpResult {
        Ok(())
    }
    fn get<M: Model>(instance: &mut Instance<M>, vr: &[u32], out: &mut [Self::C]) -> OpResult;
    fn set<M: Model>(instance: &mut Instance<M>, vr: &[u32], values: &[Self::C]) -> OpResult;
}

/// The base types the instance holds as their C type: (type, C type, the instance's getter
/// and setter) a row.
macro_rules! value_as_is {
    ($($t:ident: $c:ty, $get:ident, $set:ident;)*) => {$(
        impl Value for value::$t {
            type C = $c;
            fn get<M: Model>(instance: &mut Instance<M>, vr: &[u32], out: &mut [$c]) -> OpResult {
                instance.$get(vr, out)
            }
            fn set<M: Model>(instance: &mut Instance<M>, vr: &[u32], values: &[$c]) -> OpResult {
                instance.$set(vr, values)
            }
        }
    )*};
}

value_as_is! {
    Real: fmi2Real, get_real, set_real;
    Integer: fmi2Integer, get_integer, set_integer;
}

impl Value for value::Boolean {
    type C = fmi2Boolean;
    fn get<M: Model>(instance: &mut Instance<M>, vr: &[u32], out: &mut [fmi2Boolean]) -> OpResult {
        let mut values = vec![false; out.len()];
        instance.get_boolean(vr, &mut values)?;
        for (o, v) in out.iter_mut().zip(values) {
            *o = if v { FMI2_TRUE } else { FMI2_FALSE };
        }
        Ok(())
    }
    fn set<M: Model>(instance: &mut Instance<M>, vr: &[u32], values: &[fmi2Boolean]) -> OpResult {
        let values: Vec<bool> = values.iter().map(|&b| b != FMI2_FALSE).collect();
        instance.set_boolean(vr, &values)
    }
}

/// No String variables: every value reference is refused, an empty call is fine.
impl Value for value::String {
    type C = fmi2String;
    fn check(vr: &[u32]) -> OpResult {
        match vr.first() {
            None => Ok(()),
            Some(v) => Err(format!("unknown String value reference {v} (the model has no String variables)").into()),
        }
    }
    fn get<M: Model>(_: &mut Instance<M>, _: &[u32], _: &mut [fmi2String]) -> OpResult {
        Ok(())
    }
    fn set<M: Model>(_: &mut Instance<M>, _: &[u32], _: &[fmi2String]) -> OpResult {
        Ok(())
    }
}

/// `fmi2GetReal`, `fmi2GetInteger`, `fmi2GetBoolean`, `fmi2GetString`.
pub unsafe fn get<M: Model, T: Value>(
    function: Function,
    c: fmi2Component,
    vr: *const u32,
    n: usize,
    values: *mut T::C,
) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let vr = slice(vr, n, "vr")?;
        T::check(vr)?;
        let out = slice_mut(values, n, "value")?;
        T::get(&mut comp.instance, vr, out)
    })
}

/// `fmi2SetReal`, `fmi2SetInteger`, `fmi2SetBoolean`, `fmi2SetString`.
pub unsafe fn set<M: Model, T: Value>(
    function: Function,
    c: fmi2Component,
    vr: *const u32,
    n: usize,
    values: *const T::C,
) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let vr = slice(vr, n, "vr")?;
        T::check(vr)?;
        let values = slice(values, n, "value")?;
        T::set(&mut comp.instance, vr, values)
    })
}

// ------------------------------------------------------------------ FMU state

pub unsafe fn get_directional_derivative<M: Model>(
    function: Function,
    c: fmi2Component,
    unknown: *const u32,
    n_unknown: usize,
    known: *const u32,
    n_known: usize,
    dv_known: *const f64,
    dv_unknown: *mut f64,
) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let unknowns = slice(unknown, n_unknown, "vUnknown_ref")?;
        let knowns = slice(known, n_known, "vKnown_ref")?;
        let dv_k = slice(dv_known, n_known, "dvKnown")?;
        let out = slice_mut(dv_unknown, n_unknown, "dvUnknown")?;
        comp.instance.directional_derivative(unknowns, knowns, dv_k, out)
    })
}

// ------------------------------------------------------------------ Co-Simulation

pub unsafe fn set_real_input_derivatives<M: Model>(function: Function, c: fmi2Component) -> Fmi2Status {
    with::<M>(c, function, |_| Err("not supported (canInterpolateInputs is false)".into()))
}

pub unsafe fn get_real_output_derivatives<M: Model>(function: Function, c: fmi2Component) -> Fmi2Status {
    with::<M>(c, function, |_| Err("not supported (maxOutputDerivativeOrder is 0)".into()))
}

pub unsafe fn do_step<M: Model>(
    function: Function,
    c: fmi2Component,
    current: f64,
    step: f64,
    _no_set_prior: fmi2Boolean,
) -> Fmi2Status {
    with::<M>(c, function, |comp| comp.instance.do_step(current, step))
}

pub unsafe fn cancel_step<M: Model>(function: Function, c: fmi2Component) -> Fmi2Status {
    with::<M>(c, function, |_| Err("not supported: fmi2DoStep never returns fmi2Pending".into()))
}

pub unsafe fn get_status<M: Model>(function: Function, c: fmi2Component, kind: c_int, value: *mut c_int) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let out = out_ptr(value, "value")?;
        match kind {
            FMI2_DO_STEP_STATUS => {
                *out = if comp.instance.machine() == Machine::StepFailed { Fmi2Status::Discard } else { Fmi2Status::Ok }
                    as c_int;
                Ok(())
            }
            _ => Err(format!("status kind {kind} is not available (steps are synchronous)").into()),
        }
    })
}

/// `fmi2Get<Type>Status` of a kind with a value: `read` of the instance when `kind` is
/// `available`, else an error naming the type (`type_name`).
unsafe fn status_value<M: Model, T>(
    (function, c, kind, value): (Function, fmi2Component, c_int, *mut T),
    (available, type_name): (c_int, &str),
    read: impl FnOnce(&Component<M>) -> T,
) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let out = out_ptr(value, "value")?;
        if kind == available {
            *out = read(comp);
            Ok(())
        } else {
            Err(format!("status kind {kind} has no {type_name} value").into())
        }
    })
}

pub unsafe fn get_real_status<M: Model>(
    function: Function,
    c: fmi2Component,
    kind: c_int,
    value: *mut f64,
) -> Fmi2Status {
    status_value::<M, _>((function, c, kind, value), (FMI2_LAST_SUCCESSFUL_TIME, "Real"), |comp| comp.instance.time())
}

pub unsafe fn get_integer_status<M: Model>(function: Function, c: fmi2Component, kind: c_int) -> Fmi2Status {
    with::<M>(c, function, |_| Err(format!("status kind {kind} has no Integer value").into()))
}

pub unsafe fn get_boolean_status<M: Model>(
    function: Function,
    c: fmi2Component,
    kind: c_int,
    value: *mut fmi2Boolean,
) -> Fmi2Status {
    // true after a Discard because the model asked to end the simulation
    status_value::<M, _>((function, c, kind, value), (FMI2_TERMINATED, "Boolean"), |comp| {
        if comp.instance.core.terminate_requested {
            FMI2_TRUE
        } else {
            FMI2_FALSE
        }
    })
}

pub unsafe fn get_string_status<M: Model>(function: Function, c: fmi2Component, kind: c_int) -> Fmi2Status {
    with::<M>(c, function, |_| Err(format!("status kind {kind} has no String value (no pending step)").into()))
}

// ------------------------------------------------------------------ Model Exchange

pub unsafe fn new_discrete_states<M: Model>(
    function: Function,
    c: fmi2Component,
    info: *mut Fmi2EventInfo,
) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let info = out_ptr(info, "fmi2EventInfo")?;
        let update = comp.instance.new_discrete_states()?;
        let b = |x: bool| if x { FMI2_TRUE } else { FMI2_FALSE };
        *info = Fmi2EventInfo {
            new_discrete_states_needed: b(update.new_discrete_states_needed),
            terminate_simulation: b(update.terminate_simulation),
            nominals_of_continuous_states_changed: FMI2_FALSE,
            values_of_continuous_states_changed: b(update.values_of_continuous_states_changed),
            next_event_time_defined: b(update.next_event_time.is_some()),
            next_event_time: update.next_event_time.unwrap_or(0.0),
        };
        if let Some(t) = update.next_event_time {
            comp.log(Fmi2Status::Ok, LogCategory::Events, &format!("next time event at {t}"));
        }
        Ok(())
    })
}

#[doc(hidden)]
pub type Void = c_void;

//! The C ABI: every `fmi2*` function as a generic `unsafe fn` over the model type. The
//! [`crate::export_fmi2!`] macro instantiates them as unmangled `extern "C"` symbols.
//!
//! Rules kept here, and only here: null pointers and lengths are checked before a slice
//! is made, panics are caught at every entry point, every error is logged through the
//! importer's logger (as `"%s"`, message) with the function name, and an `fmi2Error`
//! moves the instance to the error state.
#![allow(clippy::missing_safety_doc, non_snake_case)]

use std::collections::HashSet;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::ffi::*;
use crate::instance::{Function, Instance, Machine, OpResult, SavedState};
use crate::log::{LogCategory, Logger, LOG_CATEGORIES};
use crate::model::{InstantiateContext, Interface, Model, ModelError};

/// Largest `nvr` (or `nx`, `nUnknown`, ...) accepted: far above any sensible request,
/// far below what would make a slice or an allocation from a wrong length dangerous.
pub const MAX_ARRAY_LENGTH: usize = 1 << 24;

/// What `fmi2Component` points to.
pub struct Component<M: Model> {
    pub instance: Instance<M>,
    logger: Logger,
    /// The FMU states this instance handed out and has not freed: only these are
    /// accepted back (a freed or foreign pointer is refused, never dereferenced).
    live_states: HashSet<usize>,
}

impl<M: Model> Drop for Component<M> {
    fn drop(&mut self) {
        for state in self.live_states.drain() {
            // SAFETY: every entry came from Box::into_raw of a SavedState<M> and is freed once.
            drop(unsafe { Box::from_raw(state as *mut SavedState<M>) });
        }
    }
}

fn c_text(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).unwrap_or_default()
}

/// Calls the importer's variadic logger with format `"%s"` (for calls without an instance).
unsafe fn emit(callbacks: &Fmi2CallbackFunctions, name: &CStr, status: Fmi2Status, category: &str, message: &str) {
    if let Some(logger) = callbacks.logger {
        let category = c_text(category);
        let message = c_text(message);
        logger(
            callbacks.component_environment,
            name.as_ptr(),
            status as c_int,
            category.as_ptr(),
            c"%s".as_ptr(),
            message.as_ptr(),
        );
    }
}

impl<M: Model> Component<M> {
    fn log(&self, status: Fmi2Status, category: LogCategory, message: &str) {
        self.logger.emit(status, category, message);
    }

    fn own_state(&self, state: fmi2FMUstate) -> OpResult<*mut SavedState<M>> {
        if state.is_null() {
            Err("FMUstate is NULL".into())
        } else if self.live_states.contains(&(state as usize)) {
            Ok(state as *mut SavedState<M>)
        } else {
            Err("FMUstate was not made by this instance or was already freed".into())
        }
    }

    /// Stores `saved` in `*slot`: into the state already there when it is one of ours,
    /// else as a new state.
    unsafe fn put_state(&mut self, slot: &mut fmi2FMUstate, saved: SavedState<M>) -> OpResult {
        if slot.is_null() {
            let ptr = Box::into_raw(Box::new(saved));
            self.live_states.insert(ptr as usize);
            *slot = ptr as fmi2FMUstate;
        } else {
            *self.own_state(*slot)? = saved;
        }
        Ok(())
    }
}

fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".into()
    }
}

/// Runs `f` on the instance behind `c`: null check, the state table, panic guard,
/// logging, and the status: `fmi2Error` (to the error state), `fmi2Discard` (a failed
/// step goes to stepFailed), `fmi2Warning` when the model logged a warning.
unsafe fn with<M: Model>(
    c: fmi2Component,
    function: Function,
    f: impl FnOnce(&mut Component<M>) -> OpResult,
) -> Fmi2Status {
    if c.is_null() {
        return Fmi2Status::Error;
    }
    let component = &mut *(c as *mut Component<M>);
    component.log(Fmi2Status::Ok, LogCategory::Calls, function.name());
    component.logger.take_warned();
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        component.instance.check_call(function)?;
        f(component)
    }));
    let (status, message) = match outcome {
        Ok(Ok(())) => {
            return if component.logger.take_warned() { Fmi2Status::Warning } else { Fmi2Status::Ok };
        }
        Ok(Err(ModelError::Discard(message))) => (Fmi2Status::Discard, message),
        Ok(Err(ModelError::Error(message))) => (Fmi2Status::Error, message),
        Err(payload) => {
            (Fmi2Status::Error, format!("internal error (panic caught at the C boundary): {}", panic_text(&*payload)))
        }
    };
    let function_name = function.name();
    if status == Fmi2Status::Discard {
        if function == Function::DoStep {
            component.instance.core.machine = Machine::StepFailed;
        }
        component.log(Fmi2Status::Discard, LogCategory::Warning, &format!("{function_name}: {message}"));
    } else {
        component.instance.core.machine = Machine::Error;
        component.log(Fmi2Status::Error, LogCategory::Error, &format!("{function_name}: {message}"));
    }
    status
}

/// A slice from a C array, refusing a null pointer unless the length is 0, and an
/// implausible length before anything is read or allocated.
unsafe fn slice<'a, T>(ptr: *const T, n: usize, what: &str) -> OpResult<&'a [T]> {
    if n == 0 {
        Ok(&[])
    } else if n > MAX_ARRAY_LENGTH {
        Err(format!("{what}: length {n} refused (more than {MAX_ARRAY_LENGTH})").into())
    } else if ptr.is_null() {
        Err(format!("{what} is NULL with length {n}").into())
    } else {
        Ok(std::slice::from_raw_parts(ptr, n))
    }
}

unsafe fn slice_mut<'a, T>(ptr: *mut T, n: usize, what: &str) -> OpResult<&'a mut [T]> {
    if n == 0 {
        Ok(&mut [])
    } else if n > MAX_ARRAY_LENGTH {
        Err(format!("{what}: length {n} refused (more than {MAX_ARRAY_LENGTH})").into())
    } else if ptr.is_null() {
        Err(format!("{what} is NULL with length {n}").into())
    } else {
        Ok(std::slice::from_raw_parts_mut(ptr, n))
    }
}

unsafe fn out_ptr<'a, T>(ptr: *mut T, what: &str) -> OpResult<&'a mut T> {
    ptr.as_mut().ok_or_else(|| format!("{what} is NULL").into())
}

unsafe fn string<'a>(ptr: fmi2String) -> Option<&'a str> {
    if ptr.is_null() {
        None
    } else {
        CStr::from_ptr(ptr).to_str().ok()
    }
}

// ------------------------------------------------------------------ common functions

pub fn get_types_platform() -> *const c_char {
    c"default".as_ptr()
}

pub fn get_version() -> *const c_char {
    c"2.0".as_ptr()
}

pub unsafe fn set_debug_logging<M: Model>(
    c: fmi2Component,
    logging_on: fmi2Boolean,
    n: usize,
    categories: *const fmi2String,
) -> Fmi2Status {
    with::<M>(c, Function::SetDebugLogging, |comp| {
        let names = slice(categories, n, "categories")?;
        let mut enabled = [n == 0; LOG_CATEGORIES.len()];
        for &name in names {
            let name = string(name).ok_or_else(|| ModelError::from("a category name is NULL or not UTF-8"))?;
            let k = LOG_CATEGORIES
                .iter()
                .position(|(c, _)| *c == name)
                .ok_or_else(|| format!("unknown log category {name:?}"))?;
            enabled[k] = true;
        }
        comp.logger.configure(logging_on != FMI2_FALSE, enabled);
        Ok(())
    })
}

pub unsafe fn instantiate<M: Model>(
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

pub unsafe fn free_instance<M: Model>(c: fmi2Component) {
    if !c.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(c as *mut Component<M>))));
    }
}

pub unsafe fn setup_experiment<M: Model>(
    c: fmi2Component,
    tolerance_defined: fmi2Boolean,
    tolerance: f64,
    start_time: f64,
    stop_time_defined: fmi2Boolean,
    stop_time: f64,
) -> Fmi2Status {
    with::<M>(c, Function::SetupExperiment, |comp| {
        let tol = (tolerance_defined != FMI2_FALSE).then_some(tolerance);
        let stop = (stop_time_defined != FMI2_FALSE).then_some(stop_time);
        comp.instance.setup_experiment(tol, start_time, stop)
    })
}

pub unsafe fn enter_initialization_mode<M: Model>(c: fmi2Component) -> Fmi2Status {
    with::<M>(c, Function::EnterInitializationMode, |comp| comp.instance.enter_initialization_mode())
}

pub unsafe fn exit_initialization_mode<M: Model>(c: fmi2Component) -> Fmi2Status {
    with::<M>(c, Function::ExitInitializationMode, |comp| {
        comp.instance.exit_initialization_mode()?;
        comp.log(
            Fmi2Status::Ok,
            LogCategory::Events,
            &format!("initialization done, now {:?}", comp.instance.machine()),
        );
        Ok(())
    })
}

pub unsafe fn terminate<M: Model>(c: fmi2Component) -> Fmi2Status {
    with::<M>(c, Function::Terminate, |comp| comp.instance.terminate())
}

pub unsafe fn reset<M: Model>(c: fmi2Component) -> Fmi2Status {
    with::<M>(c, Function::Reset, |comp| comp.instance.reset())
}

pub unsafe fn get_real<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut f64) -> Fmi2Status {
    with::<M>(c, Function::GetReal, |comp| {
        let vr = slice(vr, n, "vr")?;
        let out = slice_mut(value, n, "value")?;
        comp.instance.get_real(vr, out)
    })
}

pub unsafe fn get_integer<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut c_int) -> Fmi2Status {
    with::<M>(c, Function::GetInteger, |comp| {
        let vr = slice(vr, n, "vr")?;
        let out = slice_mut(value, n, "value")?;
        comp.instance.get_integer(vr, out)
    })
}

pub unsafe fn get_boolean<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut fmi2Boolean) -> Fmi2Status {
    with::<M>(c, Function::GetBoolean, |comp| {
        let vr = slice(vr, n, "vr")?;
        let out = slice_mut(value, n, "value")?;
        let mut values = vec![false; n];
        comp.instance.get_boolean(vr, &mut values)?;
        for (o, v) in out.iter_mut().zip(values) {
            *o = if v { FMI2_TRUE } else { FMI2_FALSE };
        }
        Ok(())
    })
}

fn no_strings(vr: &[u32]) -> OpResult {
    match vr.first() {
        None => Ok(()),
        Some(v) => Err(format!("unknown String value reference {v} (the model has no String variables)").into()),
    }
}

pub unsafe fn get_string<M: Model>(c: fmi2Component, vr: *const u32, n: usize, _value: *mut fmi2String) -> Fmi2Status {
    with::<M>(c, Function::GetString, |_| no_strings(slice(vr, n, "vr")?))
}

pub unsafe fn set_real<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *const f64) -> Fmi2Status {
    with::<M>(c, Function::SetReal, |comp| {
        let vr = slice(vr, n, "vr")?;
        let values = slice(value, n, "value")?;
        comp.instance.set_real(vr, values)
    })
}

pub unsafe fn set_integer<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *const c_int) -> Fmi2Status {
    with::<M>(c, Function::SetInteger, |comp| {
        let vr = slice(vr, n, "vr")?;
        let values = slice(value, n, "value")?;
        comp.instance.set_integer(vr, values)
    })
}

pub unsafe fn set_boolean<M: Model>(
    c: fmi2Component,
    vr: *const u32,
    n: usize,
    value: *const fmi2Boolean,
) -> Fmi2Status {
    with::<M>(c, Function::SetBoolean, |comp| {
        let vr = slice(vr, n, "vr")?;
        let values: Vec<bool> = slice(value, n, "value")?.iter().map(|&b| b != FMI2_FALSE).collect();
        comp.instance.set_boolean(vr, &values)
    })
}

pub unsafe fn set_string<M: Model>(
    c: fmi2Component,
    vr: *const u32,
    n: usize,
    _value: *const fmi2String,
) -> Fmi2Status {
    with::<M>(c, Function::SetString, |_| no_strings(slice(vr, n, "vr")?))
}

// ------------------------------------------------------------------ FMU state

pub unsafe fn get_fmu_state<M: Model>(c: fmi2Component, state: *mut fmi2FMUstate) -> Fmi2Status {
    with::<M>(c, Function::GetFMUstate, |comp| {
        let slot = out_ptr(state, "FMUstate")?;
        let saved = comp.instance.save_state();
        comp.put_state(slot, saved)
    })
}

pub unsafe fn set_fmu_state<M: Model>(c: fmi2Component, state: fmi2FMUstate) -> Fmi2Status {
    with::<M>(c, Function::SetFMUstate, |comp| {
        let saved = &*comp.own_state(state)?;
        comp.instance.restore_state(saved)
    })
}

pub unsafe fn free_fmu_state<M: Model>(c: fmi2Component, state: *mut fmi2FMUstate) -> Fmi2Status {
    with::<M>(c, Function::FreeFMUstate, |comp| {
        let slot = out_ptr(state, "FMUstate")?;
        if !slot.is_null() {
            let ptr = comp.own_state(*slot)?;
            comp.live_states.remove(&(ptr as usize));
            drop(Box::from_raw(ptr));
            *slot = std::ptr::null_mut();
        }
        Ok(())
    })
}

pub unsafe fn serialized_fmu_state_size<M: Model>(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> Fmi2Status {
    with::<M>(c, Function::SerializedFMUstateSize, |comp| {
        let saved = &*comp.own_state(state)?;
        *out_ptr(size, "size")? = Instance::serialize(saved)?.len();
        Ok(())
    })
}

pub unsafe fn serialize_fmu_state<M: Model>(
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> Fmi2Status {
    with::<M>(c, Function::SerializeFMUstate, |comp| {
        let saved = &*comp.own_state(state)?;
        let data = Instance::serialize(saved)?;
        if size < data.len() {
            return Err(format!("buffer of {size} bytes is too small for {} bytes", data.len()).into());
        }
        let out = slice_mut(bytes as *mut u8, data.len(), "serializedState")?;
        out.copy_from_slice(&data);
        Ok(())
    })
}

pub unsafe fn deserialize_fmu_state<M: Model>(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> Fmi2Status {
    with::<M>(c, Function::DeSerializeFMUstate, |comp| {
        let data = slice(bytes as *const u8, size, "serializedState")?;
        let slot = out_ptr(state, "FMUstate")?;
        if !slot.is_null() {
            comp.own_state(*slot)?;
        }
        let saved = comp.instance.deserialize(data)?;
        comp.put_state(slot, saved)
    })
}

pub unsafe fn get_directional_derivative<M: Model>(
    c: fmi2Component,
    unknown: *const u32,
    n_unknown: usize,
    known: *const u32,
    n_known: usize,
    dv_known: *const f64,
    dv_unknown: *mut f64,
) -> Fmi2Status {
    with::<M>(c, Function::GetDirectionalDerivative, |comp| {
        let unknowns = slice(unknown, n_unknown, "vUnknown_ref")?;
        let knowns = slice(known, n_known, "vKnown_ref")?;
        let dv_k = slice(dv_known, n_known, "dvKnown")?;
        let out = slice_mut(dv_unknown, n_unknown, "dvUnknown")?;
        comp.instance.directional_derivative(unknowns, knowns, dv_k, out)
    })
}

// ------------------------------------------------------------------ Co-Simulation

pub unsafe fn set_real_input_derivatives<M: Model>(
    c: fmi2Component,
    _vr: *const u32,
    _n: usize,
    _order: *const c_int,
    _value: *const f64,
) -> Fmi2Status {
    with::<M>(c, Function::SetRealInputDerivatives, |_| Err("not supported (canInterpolateInputs is false)".into()))
}

pub unsafe fn get_real_output_derivatives<M: Model>(
    c: fmi2Component,
    _vr: *const u32,
    _n: usize,
    _order: *const c_int,
    _value: *mut f64,
) -> Fmi2Status {
    with::<M>(c, Function::GetRealOutputDerivatives, |_| Err("not supported (maxOutputDerivativeOrder is 0)".into()))
}

pub unsafe fn do_step<M: Model>(c: fmi2Component, current: f64, step: f64, _no_set_prior: fmi2Boolean) -> Fmi2Status {
    with::<M>(c, Function::DoStep, |comp| comp.instance.do_step(current, step))
}

pub unsafe fn cancel_step<M: Model>(c: fmi2Component) -> Fmi2Status {
    with::<M>(c, Function::CancelStep, |_| Err("not supported: fmi2DoStep never returns fmi2Pending".into()))
}

pub unsafe fn get_status<M: Model>(c: fmi2Component, kind: c_int, value: *mut c_int) -> Fmi2Status {
    with::<M>(c, Function::GetStatus, |comp| {
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

pub unsafe fn get_real_status<M: Model>(c: fmi2Component, kind: c_int, value: *mut f64) -> Fmi2Status {
    with::<M>(c, Function::GetRealStatus, |comp| {
        let out = out_ptr(value, "value")?;
        if kind == FMI2_LAST_SUCCESSFUL_TIME {
            *out = comp.instance.time();
            Ok(())
        } else {
            Err(format!("status kind {kind} has no Real value").into())
        }
    })
}

pub unsafe fn get_integer_status<M: Model>(c: fmi2Component, kind: c_int, _value: *mut c_int) -> Fmi2Status {
    with::<M>(c, Function::GetIntegerStatus, |_| Err(format!("status kind {kind} has no Integer value").into()))
}

pub unsafe fn get_boolean_status<M: Model>(c: fmi2Component, kind: c_int, value: *mut fmi2Boolean) -> Fmi2Status {
    with::<M>(c, Function::GetBooleanStatus, |comp| {
        let out = out_ptr(value, "value")?;
        if kind == FMI2_TERMINATED {
            // after a Discard because the model asked to end the simulation
            *out = if comp.instance.core.terminate_requested { FMI2_TRUE } else { FMI2_FALSE };
            Ok(())
        } else {
            Err(format!("status kind {kind} has no Boolean value").into())
        }
    })
}

pub unsafe fn get_string_status<M: Model>(c: fmi2Component, kind: c_int, _value: *mut fmi2String) -> Fmi2Status {
    with::<M>(c, Function::GetStringStatus, |_| {
        Err(format!("status kind {kind} has no String value (no pending step)").into())
    })
}

// ------------------------------------------------------------------ Model Exchange

pub unsafe fn enter_event_mode<M: Model>(c: fmi2Component) -> Fmi2Status {
    with::<M>(c, Function::EnterEventMode, |comp| comp.instance.enter_event_mode())
}

/// `fmi2EventInfo` (from `fmi-sys`).
pub use crate::ffi::Fmi2EventInfo;

pub unsafe fn new_discrete_states<M: Model>(c: fmi2Component, info: *mut Fmi2EventInfo) -> Fmi2Status {
    with::<M>(c, Function::NewDiscreteStates, |comp| {
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

pub unsafe fn enter_continuous_time_mode<M: Model>(c: fmi2Component) -> Fmi2Status {
    with::<M>(c, Function::EnterContinuousTimeMode, |comp| comp.instance.enter_continuous_time_mode())
}

pub unsafe fn completed_integrator_step<M: Model>(
    c: fmi2Component,
    _no_set_prior: fmi2Boolean,
    enter_event_mode: *mut fmi2Boolean,
    terminate_simulation: *mut fmi2Boolean,
) -> Fmi2Status {
    with::<M>(c, Function::CompletedIntegratorStep, |_| {
        let enter = out_ptr(enter_event_mode, "enterEventMode")?;
        let terminate = out_ptr(terminate_simulation, "terminateSimulation")?;
        *enter = FMI2_FALSE;
        *terminate = FMI2_FALSE;
        Ok(())
    })
}

pub unsafe fn set_time<M: Model>(c: fmi2Component, time: f64) -> Fmi2Status {
    with::<M>(c, Function::SetTime, |comp| comp.instance.set_time(time))
}

pub unsafe fn set_continuous_states<M: Model>(c: fmi2Component, x: *const f64, nx: usize) -> Fmi2Status {
    with::<M>(c, Function::SetContinuousStates, |comp| {
        let x = slice(x, nx, "x")?;
        comp.instance.set_continuous_states(x)
    })
}

pub unsafe fn get_derivatives<M: Model>(c: fmi2Component, dx: *mut f64, nx: usize) -> Fmi2Status {
    with::<M>(c, Function::GetDerivatives, |comp| {
        let out = slice_mut(dx, nx, "derivatives")?;
        comp.instance.get_derivatives(out)
    })
}

pub unsafe fn get_event_indicators<M: Model>(c: fmi2Component, z: *mut f64, ni: usize) -> Fmi2Status {
    with::<M>(c, Function::GetEventIndicators, |comp| {
        let out = slice_mut(z, ni, "eventIndicators")?;
        comp.instance.get_event_indicators(out)
    })
}

pub unsafe fn get_continuous_states<M: Model>(c: fmi2Component, x: *mut f64, nx: usize) -> Fmi2Status {
    with::<M>(c, Function::GetContinuousStates, |comp| {
        let out = slice_mut(x, nx, "x")?;
        comp.instance.get_continuous_states(out)
    })
}

pub unsafe fn get_nominals_of_continuous_states<M: Model>(c: fmi2Component, x: *mut f64, nx: usize) -> Fmi2Status {
    with::<M>(c, Function::GetNominalsOfContinuousStates, |comp| {
        let out = slice_mut(x, nx, "x_nominal")?;
        comp.instance.get_nominals(out)
    })
}

#[doc(hidden)]
pub type Void = c_void;

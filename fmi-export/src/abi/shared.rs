//! The layer functions both generations' rows of [`super::table`] call where FMI 2.0 and
//! FMI 3.0 differ only in the names of the C types (the same pointers, integers and
//! doubles): the row passes its generation's parameters, and the names a refusal gives
//! them, to one function here. Each returns the layer's status, whose numbers are FMI
//! 3.0's too (`fmi2Pending` never occurs: every step is synchronous).
#![allow(clippy::missing_safety_doc)]

use std::panic::{catch_unwind, AssertUnwindSafe};

use super::{out_ptr, slice, slice_mut, string, with, Component};
use crate::ffi::*;
use crate::instance::{Function, Generation, Instance, OpResult};
use crate::log::{LogCategory, LOG_CATEGORIES};
use crate::model::{Model, ModelError};

/// A C byte of a serialized FMU state: `fmi2Byte` (a C `char`) or `fmi3Byte` (`uint8_t`).
pub trait Byte: Copy {}
impl Byte for i8 {}
impl Byte for u8 {}

// ------------------------------------------------------------------ instance, modes

pub unsafe fn free_instance<M: Model>(_: Function, c: fmi2Component) {
    if !c.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(c as *mut Component<M>))));
    }
}

/// The calls that are one method of the instance, of the same name.
macro_rules! instance_calls {
    ($($name:ident),*) => {$(
        #[doc = concat!("`", stringify!($name), "` of the instance.")]
        pub unsafe fn $name<M: Model>(function: Function, c: fmi2Component) -> Fmi2Status {
            with::<M>(c, function, |comp| comp.instance.$name())
        }
    )*};
}

instance_calls!(enter_initialization_mode, enter_event_mode, enter_continuous_time_mode, terminate, reset);

pub unsafe fn exit_initialization_mode<M: Model>(function: Function, c: fmi2Component) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        comp.instance.exit_initialization_mode()?;
        comp.log(
            Fmi2Status::Ok,
            LogCategory::Events,
            &format!("initialization done, now {:?}", comp.instance.machine()),
        );
        Ok(())
    })
}

pub unsafe fn set_debug_logging<M: Model>(
    function: Function,
    c: fmi2Component,
    logging_on: fmi2Boolean,
    n: usize,
    categories: *const fmi2String,
) -> Fmi2Status {
    with::<M>(c, function, |comp| {
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

// ------------------------------------------------------------------ Model Exchange

pub unsafe fn set_time<M: Model>(function: Function, c: fmi2Component, time: f64) -> Fmi2Status {
    with::<M>(c, function, |comp| comp.instance.set_time(time))
}

/// The name of a parameter in `function`'s generation of the standard.
fn named(function: Function, fmi2: &'static str, fmi3: &'static str) -> &'static str {
    match function.generation() {
        Generation::Fmi2 => fmi2,
        Generation::Fmi3 => fmi3,
    }
}

pub unsafe fn set_continuous_states<M: Model>(
    function: Function,
    c: fmi2Component,
    x: *const f64,
    n: usize,
) -> Fmi2Status {
    let what = named(function, "x", "continuousStates");
    with::<M>(c, function, |comp| comp.instance.set_continuous_states(slice(x, n, what)?))
}

/// The Model Exchange calls that fill the caller's array of `n` reals from one of the
/// instance's getters: the function, the getter, the array's name in FMI 2.0 and in FMI 3.0.
macro_rules! real_array_getters {
    ($($name:ident: $getter:ident, $fmi2:literal, $fmi3:literal;)*) => {$(
        pub unsafe fn $name<M: Model>(function: Function, c: fmi2Component, values: *mut f64, n: usize) -> Fmi2Status {
            get_reals::<M>(function, c, values, n, named(function, $fmi2, $fmi3), Instance::$getter)
        }
    )*};
}

real_array_getters! {
    get_derivatives: get_derivatives, "derivatives", "derivatives";
    get_event_indicators: get_event_indicators, "eventIndicators", "eventIndicators";
    get_continuous_states: get_continuous_states, "x", "continuousStates";
    get_nominals_of_continuous_states: get_nominals, "x_nominal", "nominals";
}

/// The body of both generations' Model Exchange calls that fill the caller's array of `n`
/// reals at `ptr` (named `what` in a refusal) from the instance: continuous states, their
/// derivatives, their nominals, the event indicators (`get`, one of [`Instance`]'s getters).
unsafe fn get_reals<M: Model>(
    function: Function,
    c: fmi2Component,
    ptr: *mut f64,
    n: usize,
    what: &str,
    get: fn(&mut Instance<M>, &mut [f64]) -> OpResult,
) -> Fmi2Status {
    with::<M>(c, function, |comp| get(&mut comp.instance, slice_mut(ptr, n, what)?))
}

/// Never an event nor the end of the run at an integrator step: no state events.
pub unsafe fn completed_integrator_step<M: Model>(
    function: Function,
    c: fmi2Component,
    _no_set_prior: impl Copy,
    enter_event_mode: *mut impl From<u8>,
    terminate_simulation: *mut impl From<u8>,
) -> Fmi2Status {
    with::<M>(c, function, |_| {
        let enter = out_ptr(enter_event_mode, "enterEventMode")?;
        let terminate = out_ptr(terminate_simulation, "terminateSimulation")?;
        *enter = 0.into();
        *terminate = 0.into();
        Ok(())
    })
}

// ------------------------------------------------------------------ FMU state
// (an `fmi3FMUState` is the same pointer as an `fmi2FMUstate`)

pub unsafe fn get_fmu_state<M: Model>(function: Function, c: fmi2Component, state: *mut fmi2FMUstate) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let slot = out_ptr(state, "FMUstate")?;
        let saved = comp.instance.save_state();
        comp.put_state(slot, saved)
    })
}

pub unsafe fn set_fmu_state<M: Model>(function: Function, c: fmi2Component, state: fmi2FMUstate) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let saved = &*comp.own_state(state)?;
        comp.instance.restore_state(saved)
    })
}

pub unsafe fn free_fmu_state<M: Model>(function: Function, c: fmi2Component, state: *mut fmi2FMUstate) -> Fmi2Status {
    with::<M>(c, function, |comp| {
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
    function: Function,
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let saved = &*comp.own_state(state)?;
        *out_ptr(size, "size")? = Instance::serialize(saved)?.len();
        Ok(())
    })
}

pub unsafe fn serialize_fmu_state<M: Model>(
    function: Function,
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut impl Byte,
    size: usize,
) -> Fmi2Status {
    with::<M>(c, function, |comp| {
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
    function: Function,
    c: fmi2Component,
    bytes: *const impl Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> Fmi2Status {
    with::<M>(c, function, |comp| {
        let data = slice(bytes as *const u8, size, "serializedState")?;
        let slot = out_ptr(state, "FMUstate")?;
        if !slot.is_null() {
            comp.own_state(*slot)?;
        }
        let saved = comp.instance.deserialize(data)?;
        comp.put_state(slot, saved)
    })
}

//! The two thin C ABIs over the one instance ([`crate::instance::Instance`]): the layer
//! functions of the `fmi2*` calls in [`fmi2`], of the `fmi3*` calls in [`fmi3`], and those
//! both generations' calls share (the same pointers under other C names) in [`shared`],
//! each a generic `unsafe fn` over the model type taking the [`Function`] it serves first;
//! [`table`] lists which one serves which symbol, and [`crate::export_fmi!`] instantiates
//! the table as unmangled `extern "C"` symbols of one library. The FMI 2.0 and shared ones
//! are re-exported here too (`abi::get` is `abi::fmi2::get`, `abi::terminate`
//! `abi::shared::terminate`).
//!
//! Rules kept here, and only here: null pointers and lengths are checked before a slice
//! is made, panics are caught at every entry point, every error is logged through the
//! importer's logger with the function name, and an error status moves the instance to
//! the error state.
#![allow(clippy::missing_safety_doc, non_snake_case)]

pub mod fmi2;
pub mod fmi3;
pub mod shared;
pub mod table;

/// `fmi2EventInfo` (from `fmi-sys`).
pub use crate::ffi::Fmi2EventInfo;
pub use fmi2::*;
pub use shared::*;

use std::collections::HashSet;
use std::ffi::{c_int, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::ffi::*;
use crate::instance::{Function, Instance, Machine, OpResult, SavedState};
use crate::log::{LogCategory, Logger};
use crate::model::{Model, ModelError};

/// Largest `nvr` (or `nx`, `nUnknown`, ...) accepted: far above any sensible request,
/// far below what would make a slice or an allocation from a wrong length dangerous.
pub const MAX_ARRAY_LENGTH: usize = 1 << 24;

/// What `fmi2Component` points to.
pub struct Component<M: Model> {
    pub instance: Instance<M>,
    pub(crate) logger: Logger,
    /// The FMU states this instance handed out and has not freed: only these are
    /// accepted back (a freed or foreign pointer is refused, never dereferenced).
    pub(crate) live_states: HashSet<usize>,
}

impl<M: Model> Drop for Component<M> {
    fn drop(&mut self) {
        for state in self.live_states.drain() {
            // SAFETY: every entry came from Box::into_raw of a SavedState<M> and is freed once.
            drop(unsafe { Box::from_raw(state as *mut SavedState<M>) });
        }
    }
}

pub(crate) fn c_text(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).unwrap_or_default()
}

/// Calls the importer's variadic logger with format `"%s"` (for calls without an instance).
pub(crate) unsafe fn emit(
    callbacks: &Fmi2CallbackFunctions,
    name: &CStr,
    status: Fmi2Status,
    category: &str,
    message: &str,
) {
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
    pub(crate) fn log(&self, status: Fmi2Status, category: LogCategory, message: &str) {
        self.logger.emit(status, category, message);
    }

    pub(crate) fn own_state(&self, state: fmi2FMUstate) -> OpResult<*mut SavedState<M>> {
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
    pub(crate) unsafe fn put_state(&mut self, slot: &mut fmi2FMUstate, saved: SavedState<M>) -> OpResult {
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

pub(crate) fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
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
pub(crate) unsafe fn with<M: Model>(
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
        // FMI 2.0's stepFailed; FMI 3.0 has no such state: after a Discard of fmi3DoStep
        // the FMU stays in Step Mode (the importer may retry with other arguments)
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

/// Whether a C array of length `n` holds anything to read, refusing a null pointer unless
/// the length is 0, and an implausible length before anything is read or allocated.
fn array_filled(is_null: bool, n: usize, what: &str) -> OpResult<bool> {
    if n == 0 {
        Ok(false)
    } else if n > MAX_ARRAY_LENGTH {
        Err(format!("{what}: length {n} refused (more than {MAX_ARRAY_LENGTH})").into())
    } else if is_null {
        Err(format!("{what} is NULL with length {n}").into())
    } else {
        Ok(true)
    }
}

/// A slice from a C array (see [`array_filled`]).
pub(crate) unsafe fn slice<'a, T>(ptr: *const T, n: usize, what: &str) -> OpResult<&'a [T]> {
    Ok(if array_filled(ptr.is_null(), n, what)? { std::slice::from_raw_parts(ptr, n) } else { &[] })
}

/// A mutable slice from a C array (see [`array_filled`]).
pub(crate) unsafe fn slice_mut<'a, T>(ptr: *mut T, n: usize, what: &str) -> OpResult<&'a mut [T]> {
    Ok(if array_filled(ptr.is_null(), n, what)? { std::slice::from_raw_parts_mut(ptr, n) } else { &mut [] })
}

pub(crate) unsafe fn out_ptr<'a, T>(ptr: *mut T, what: &str) -> OpResult<&'a mut T> {
    ptr.as_mut().ok_or_else(|| format!("{what} is NULL").into())
}

pub(crate) unsafe fn string<'a>(ptr: fmi2String) -> Option<&'a str> {
    if ptr.is_null() {
        None
    } else {
        CStr::from_ptr(ptr).to_str().ok()
    }
}

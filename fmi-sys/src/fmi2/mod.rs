//! The FMI 2.0 C API in Rust, for both sides of it: the FMU that exports the 44 `fmi2*`
//! functions and the importer that loads them from a shared library.
//!
//! - The types of `fmi2TypesPlatform.h` and `fmi2FunctionTypes.h`: [`fmi2Component`],
//!   [`fmi2Real`], ..., the statuses ([`fmi2Status`] as an importer receives it, any `int`;
//!   [`Fmi2Status`] as an FMU returns it), [`Fmi2Type`], the status kinds, the callbacks
//!   struct [`Fmi2CallbackFunctions`] and [`Fmi2EventInfo`].
//! - [`functions`]: the C function type of each of the 44 functions (`fmi2DoStepTYPE`, ...),
//!   their symbol names by interface, and one function table [`Fmi2Functions`] with its
//!   loader from a shared library (feature `import`).
//! - [`logger`] (feature `import`): the importer's logger callback. FMI's logger is
//!   C-variadic and printf-style, which stable Rust cannot define; a C shim formats the
//!   FMU's message, refusing formats that could write to or read arbitrary memory (`%n`,
//!   `*` widths, positional arguments, wide strings; a `%s` argument is copied only if it
//!   points to readable memory outside the importer's program image), and hands the text
//!   to a Rust [`logger::LogReceiver`].
//! - [`guard`] (feature `import`): the importer's memory callbacks, calloc and free with a
//!   red zone after every block, in which an FMU's write past a block lands and is seen.

use std::ffi::{c_char, c_int, c_uint, c_void};

pub mod functions;
#[cfg(feature = "import")]
pub mod guard;
#[cfg(feature = "import")]
pub mod logger;

pub use functions::*;

pub type fmi2Component = *mut c_void;
pub type fmi2ComponentEnvironment = *mut c_void;
pub type fmi2FMUstate = *mut c_void;
pub type fmi2ValueReference = c_uint;
pub type fmi2Real = f64;
pub type fmi2Integer = c_int;
pub type fmi2Boolean = c_int;
pub type fmi2Char = c_char;
pub type fmi2String = *const c_char;
pub type fmi2Byte = c_char;

pub const FMI2_TRUE: fmi2Boolean = 1;
pub const FMI2_FALSE: fmi2Boolean = 0;

/// `fmi2Status` as an importer receives it from a function pointer: a C `int`, since an
/// FMU may return a value outside the enum and reading one into a Rust enum would be
/// undefined behaviour. [`Fmi2Status::from_raw`] classifies it.
pub type fmi2Status = c_int;

crate::table::status_enum! {
    /// `fmi2Status` as an FMU returns it (same ABI as the C enum, an `int`).
    Fmi2Status, fmi2Status {
        Ok = 0,
        Warning = 1,
        Discard = 2,
        Error = 3,
        Fatal = 4,
        Pending = 5,
    }
}

/// `fmi2Type`: the interface `fmi2Instantiate` is asked for.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fmi2Type {
    ModelExchange = 0,
    CoSimulation = 1,
}

/// `fmi2StatusKind` values (the `s` of `fmi2Get*Status`).
pub type fmi2StatusKind = c_int;
pub const FMI2_DO_STEP_STATUS: fmi2StatusKind = 0;
pub const FMI2_PENDING_STATUS: fmi2StatusKind = 1;
pub const FMI2_LAST_SUCCESSFUL_TIME: fmi2StatusKind = 2;
pub const FMI2_TERMINATED: fmi2StatusKind = 3;

/// `fmi2CallbackLogger`: C-variadic, printf-style `(env, instanceName, status, category,
/// message, ...)`.
pub type Fmi2CallbackLogger =
    unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
/// `fmi2CallbackAllocateMemory`: calloc's contract.
pub type Fmi2CallbackAllocateMemory = unsafe extern "C" fn(usize, usize) -> *mut c_void;
/// `fmi2CallbackFreeMemory`: free's contract.
pub type Fmi2CallbackFreeMemory = unsafe extern "C" fn(*mut c_void);
/// `fmi2StepFinished` (asynchronous `fmi2DoStep`, which no FMU here offers).
pub type Fmi2StepFinished = unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2Status);

/// `fmi2CallbackFunctions`. Each pointer is nullable in the ABI (`None` is NULL); FMI 2.0
/// requires the importer to pass a logger, an allocator and a free function.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct Fmi2CallbackFunctions {
    pub logger: Option<Fmi2CallbackLogger>,
    pub allocate_memory: Option<Fmi2CallbackAllocateMemory>,
    pub free_memory: Option<Fmi2CallbackFreeMemory>,
    pub step_finished: Option<Fmi2StepFinished>,
    pub component_environment: fmi2ComponentEnvironment,
}

/// `fmi2EventInfo`, the result of `fmi2NewDiscreteStates`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fmi2EventInfo {
    /// `newDiscreteStatesNeeded`.
    pub new_discrete_states_needed: fmi2Boolean,
    /// `terminateSimulation`.
    pub terminate_simulation: fmi2Boolean,
    /// `nominalsOfContinuousStatesChanged`.
    pub nominals_of_continuous_states_changed: fmi2Boolean,
    /// `valuesOfContinuousStatesChanged`.
    pub values_of_continuous_states_changed: fmi2Boolean,
    /// `nextEventTimeDefined`.
    pub next_event_time_defined: fmi2Boolean,
    /// `nextEventTime`, s.
    pub next_event_time: fmi2Real,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The struct layouts of the FMI 2.0 headers on a 64-bit platform (LP64 and LLP64
    /// alike: `int` 4 bytes, pointers and `size_t` 8, `double` 8 aligned to 8).
    #[test]
    fn layouts_are_those_of_the_c_headers() {
        assert_eq!(std::mem::size_of::<Fmi2CallbackFunctions>(), 5 * 8);
        assert_eq!(std::mem::size_of::<Fmi2EventInfo>(), 5 * 4 + 4 + 8);
        assert_eq!(std::mem::offset_of!(Fmi2EventInfo, next_event_time), 24);
        assert_eq!(std::mem::size_of::<Fmi2Status>(), std::mem::size_of::<c_int>());
        assert_eq!(std::mem::size_of::<Fmi2Type>(), std::mem::size_of::<c_int>());
    }

    #[test]
    fn raw_statuses_outside_the_enum_are_not_statuses() {
        assert_eq!(Fmi2Status::from_raw(2), Some(Fmi2Status::Discard));
        assert_eq!(Fmi2Status::from_raw(5), Some(Fmi2Status::Pending));
        assert_eq!(Fmi2Status::from_raw(6), None);
        assert_eq!(Fmi2Status::from_raw(-1), None);
    }
}

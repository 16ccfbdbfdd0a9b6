//! The FMI 3.0 C API in Rust, for both sides of it.
//!
//! - The types of `fmi3PlatformTypes.h` and `fmi3FunctionTypes.h`: [`fmi3Instance`],
//!   [`fmi3Float64`], ..., the statuses ([`fmi3Status`] as an importer receives it, any
//!   `int`; [`Fmi3Status`] as an FMU returns it), the dependency kinds, the interval
//!   qualifiers and the callbacks' C types.
//! - [`functions`]: the C type of each of the 75 functions (`fmi3DoStepTYPE`, ...), their
//!   symbol names by interface type, and one function table [`Fmi3Functions`] with its
//!   loader from a shared library (feature `import`).
//!
//! `fmi3Boolean` and `fmi3Clock` are C `bool` (one byte, 0 or 1). An FMU receives them from
//! an importer that may pass other byte values; both sides of this workspace read such
//! bytes as `u8` (through [`fmi3BooleanByte`]) and treat any nonzero as true, so that no
//! foreign byte becomes an invalid Rust `bool`.

use std::ffi::{c_char, c_int, c_void};

pub mod functions;

pub use functions::*;

pub type fmi3Instance = *mut c_void;
pub type fmi3InstanceEnvironment = *mut c_void;
pub type fmi3FMUState = *mut c_void;
pub type fmi3ValueReference = u32;
pub type fmi3Float32 = f32;
pub type fmi3Float64 = f64;
pub type fmi3Int8 = i8;
pub type fmi3UInt8 = u8;
pub type fmi3Int16 = i16;
pub type fmi3UInt16 = u16;
pub type fmi3Int32 = i32;
pub type fmi3UInt32 = u32;
pub type fmi3Int64 = i64;
pub type fmi3UInt64 = u64;
/// C `bool` in the ABI. In the function types it is declared as a byte so that a value
/// other than 0 or 1 from the other side is no undefined behaviour: 0 is false, any
/// other value true.
pub type fmi3Boolean = u8;
/// The byte behind an `fmi3Boolean` (the same type, named for what it is read as).
pub type fmi3BooleanByte = u8;
pub type fmi3Char = c_char;
pub type fmi3String = *const c_char;
pub type fmi3Byte = u8;
pub type fmi3Binary = *const u8;
/// C `bool` in the ABI, read as a byte (see [`fmi3Boolean`]).
pub type fmi3Clock = u8;

pub const FMI3_TRUE: fmi3Boolean = 1;
pub const FMI3_FALSE: fmi3Boolean = 0;
pub const FMI3_CLOCK_ACTIVE: fmi3Clock = 1;
pub const FMI3_CLOCK_INACTIVE: fmi3Clock = 0;

/// `fmi3Status` as an importer receives it from a function pointer: a C `int` (an enum's
/// ABI), since an FMU may return a value outside the enum. [`Fmi3Status::from_raw`]
/// classifies it.
pub type fmi3Status = c_int;

crate::table::status_enum! {
    /// `fmi3Status` as an FMU returns it (same ABI as the C enum, an `int`).
    Fmi3Status, fmi3Status {
        Ok = 0,
        Warning = 1,
        Discard = 2,
        Error = 3,
        Fatal = 4,
    }
}

/// `fmi3DependencyKind` (a C enum: an `int`), as `fmi3GetVariableDependencies` writes it.
pub type fmi3DependencyKind = c_int;
pub const FMI3_INDEPENDENT: fmi3DependencyKind = 0;
pub const FMI3_CONSTANT: fmi3DependencyKind = 1;
pub const FMI3_FIXED: fmi3DependencyKind = 2;
pub const FMI3_TUNABLE: fmi3DependencyKind = 3;
pub const FMI3_DISCRETE: fmi3DependencyKind = 4;
pub const FMI3_DEPENDENT: fmi3DependencyKind = 5;

/// `fmi3IntervalQualifier` (a C enum: an `int`).
pub type fmi3IntervalQualifier = c_int;
pub const FMI3_INTERVAL_NOT_YET_KNOWN: fmi3IntervalQualifier = 0;
pub const FMI3_INTERVAL_UNCHANGED: fmi3IntervalQualifier = 1;
pub const FMI3_INTERVAL_CHANGED: fmi3IntervalQualifier = 2;

/// `fmi3LogMessageCallback(instanceEnvironment, status, category, message)`: not variadic,
/// the message is already formatted.
pub type Fmi3LogMessageCallback = unsafe extern "C" fn(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String);
/// `fmi3ClockUpdateCallback` (Scheduled Execution).
pub type Fmi3ClockUpdateCallback = unsafe extern "C" fn(fmi3InstanceEnvironment);
/// `fmi3IntermediateUpdateCallback(env, intermediateUpdateTime, intermediateVariableSetRequested,
/// intermediateVariableGetAllowed, intermediateStepFinished, canReturnEarly,
/// *earlyReturnRequested, *earlyReturnTime)`.
pub type Fmi3IntermediateUpdateCallback = unsafe extern "C" fn(
    fmi3InstanceEnvironment,
    fmi3Float64,
    fmi3Boolean,
    fmi3Boolean,
    fmi3Boolean,
    fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Float64,
);
/// `fmi3LockPreemptionCallback` (Scheduled Execution).
pub type Fmi3LockPreemptionCallback = unsafe extern "C" fn();
/// `fmi3UnlockPreemptionCallback` (Scheduled Execution).
pub type Fmi3UnlockPreemptionCallback = unsafe extern "C" fn();

/// The `fmiVersion` an FMI 3.0 library's `fmi3GetVersion` returns.
pub const FMI3_VERSION: &str = "3.0";

/// The FMI 3.0 platform folder (`binaries/<arch>-<os>/`) of a Rust target triple, or
/// `None` for a target FMI 3.0 names no folder for.
pub fn platform_folder(target_triple: &str) -> Option<&'static str> {
    let arch = if target_triple.starts_with("x86_64") {
        "x86_64"
    } else if target_triple.starts_with("aarch64") {
        "aarch64"
    } else {
        return None;
    };
    let os = if target_triple.contains("linux") {
        "linux"
    } else if target_triple.contains("windows") {
        "windows"
    } else if target_triple.contains("darwin") || target_triple.contains("apple") {
        "darwin"
    } else {
        return None;
    };
    Some(match (arch, os) {
        ("x86_64", "linux") => "x86_64-linux",
        ("x86_64", "windows") => "x86_64-windows",
        ("x86_64", "darwin") => "x86_64-darwin",
        ("aarch64", "linux") => "aarch64-linux",
        ("aarch64", "windows") => "aarch64-windows",
        _ => "aarch64-darwin",
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raw_statuses_outside_the_enum_are_not_statuses() {
        assert_eq!(Fmi3Status::from_raw(2), Some(Fmi3Status::Discard));
        assert_eq!(Fmi3Status::from_raw(4), Some(Fmi3Status::Fatal));
        assert_eq!(Fmi3Status::from_raw(5), None);
        assert_eq!(Fmi3Status::from_raw(-1), None);
        assert_eq!(std::mem::size_of::<Fmi3Status>(), std::mem::size_of::<c_int>());
    }

    #[test]
    fn platform_folders_are_those_of_the_standard() {
        assert_eq!(platform_folder("x86_64-unknown-linux-gnu"), Some("x86_64-linux"));
        assert_eq!(platform_folder("x86_64-pc-windows-gnu"), Some("x86_64-windows"));
        assert_eq!(platform_folder("aarch64-unknown-linux-gnu"), Some("aarch64-linux"));
        assert_eq!(platform_folder("x86_64-apple-darwin"), Some("x86_64-darwin"));
        assert_eq!(platform_folder("aarch64-apple-darwin"), Some("aarch64-darwin"));
        assert_eq!(platform_folder("riscv64gc-unknown-linux-gnu"), None);
    }
}

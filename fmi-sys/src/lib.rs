//! The FMI C APIs in Rust, both generations, for both sides of each: the FMU that exports
//! the functions and the importer that loads them from a shared library.
//!
//! - [`fmi2`]: FMI 2.0 (`fmi2TypesPlatform.h`, `fmi2FunctionTypes.h`): the types, the 44
//!   functions' C types, their table and loader, and the importer's printf-style logger
//!   callback (a C shim: FMI 2.0's logger is C-variadic).
//! - [`fmi3`]: FMI 3.0 (`fmi3PlatformTypes.h`, `fmi3FunctionTypes.h`): the types, the
//!   functions' C types, their table and loader. FMI 3.0's log callback is a plain C
//!   function, so it needs no shim.
//!
//! The crate is thin on purpose: no state, no FMI state machine (that lives in
//! `fmi-export` for the FMUs and in the importing layer for the master). Everything a C
//! caller can get wrong stays `unsafe` here; the safe wrappers are the layers' business.
#![allow(non_camel_case_types)]

mod table;

pub use table::FunctionTable;

pub mod fmi2;
pub mod fmi3;

//! The C-side types the importing layer hands to FMU libraries and gets back from them
//! (declared in `fmi-sys`, named here once for the layer).

/// An instance as the C functions see it (`fmi2Component`, `fmi3Instance`).
pub(crate) type Component = fmi_sys::fmi2::fmi2Component;

/// A status as the C functions return it (`fmi2Status`, `fmi3Status`: the same values).
pub(crate) type RawStatus = fmi_sys::fmi2::fmi2Status;

/// `fmi2CallbackFunctions`.
pub(crate) type CallbackFunctions = fmi_sys::fmi2::Fmi2CallbackFunctions;

/// `fmi2EventInfo` (FMI 3.0's `fmi3UpdateDiscreteStates` outputs are returned in it too).
pub use fmi_sys::fmi2::Fmi2EventInfo as EventInfo;

/// The fmi2 functions of a library: the ones every interface needs, the rest optional
/// (absent when the library lacks them; calling one is then an error naming it).
pub(crate) use fmi_sys::fmi2::Fmi2Functions as Functions;

/// The fmi3 functions of a library (the core ones required, the rest optional).
pub(crate) use fmi_sys::fmi3::Fmi3Functions;

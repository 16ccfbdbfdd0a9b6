//! The C types of the FMI 2.0 API, from `fmi-sys` (the one binding of the workspace),
//! under the paths the layer and the `export_fmi!` expansion use.
pub use fmi_sys::fmi2::{
    fmi2Boolean, fmi2Byte, fmi2Char, fmi2Component, fmi2ComponentEnvironment, fmi2FMUstate, fmi2Integer, fmi2Real,
    fmi2String, fmi2ValueReference, Fmi2CallbackAllocateMemory, Fmi2CallbackFreeMemory, Fmi2CallbackFunctions,
    Fmi2CallbackLogger, Fmi2EventInfo, Fmi2Status, Fmi2StepFinished, Fmi2Type, FMI2_DO_STEP_STATUS, FMI2_FALSE,
    FMI2_LAST_SUCCESSFUL_TIME, FMI2_PENDING_STATUS, FMI2_TERMINATED, FMI2_TRUE,
};

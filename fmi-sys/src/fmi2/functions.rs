//! The 44 functions of FMI 2.0: their C types (`fmi2FunctionTypes.h`), their symbol names
//! by interface, and one table of function pointers loaded from a shared library.
//!
//! FMI 2.0 asks an FMU's library to export every function of each interface it
//! implements: the 25 common ones and the 9 of Co-Simulation or the 10 of Model Exchange;
//! a function whose capability flag is false still exists and returns `fmi2Error`.
//! Libraries in the wild omit some. So the table holds as plain function pointers the 15
//! that no importer can run an FMU without (version, instantiation and the four
//! initialization calls, terminate, get and set of the four types) and every other one as
//! an `Option`. [`Fmi2Functions::load`] requires the 15; [`Fmi2Functions::missing`] lists
//! what FMI 2.0 requires for an interface and the library lacks, for a strict importer
//! (fmpy refuses such a library) or one that names what it will call
//! ([`Fmi2Functions::has`]).
#![allow(non_snake_case)]

use super::*;

/// The part of FMI 2.0 a function belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fmi2Part {
    /// Both interfaces (25 functions).
    Common,
    /// Co-Simulation only (9).
    CoSimulation,
    /// Model Exchange only (10).
    ModelExchange,
}

pub use crate::table::MissingSymbol;
use std::ffi::c_int;

crate::table::function_table! {
    /// The C type of each function, named as in `fmi2FunctionTypes.h`. The `fmuType` of
    /// `fmi2Instantiate` is a C `int` (an [`Fmi2Type`] value), so that an importer can pass
    /// what its user asked for and hear the FMU refuse it.
    mod types;
    /// The 44 functions of an FMI 2.0 library: the 15 every importer calls as function
    /// pointers, the others as `Option` (`None`: the library does not export it).
    pub struct Fmi2Functions: Fmi2Part, 44 symbols of "FMI 2.0";
    core {
        get_version: fmi2GetVersionTYPE = "fmi2GetVersion", Common => fn() -> fmi2String;
        instantiate: fmi2InstantiateTYPE = "fmi2Instantiate", Common => fn(fmi2String, c_int, fmi2String, fmi2String, *const Fmi2CallbackFunctions, fmi2Boolean, fmi2Boolean) -> fmi2Component;
        free_instance: fmi2FreeInstanceTYPE = "fmi2FreeInstance", Common => fn(fmi2Component);
        setup_experiment: fmi2SetupExperimentTYPE = "fmi2SetupExperiment", Common => fn(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real) -> fmi2Status;
        enter_initialization_mode: fmi2EnterInitializationModeTYPE = "fmi2EnterInitializationMode", Common => fn(fmi2Component) -> fmi2Status;
        exit_initialization_mode: fmi2ExitInitializationModeTYPE = "fmi2ExitInitializationMode", Common => fn(fmi2Component) -> fmi2Status;
        terminate: fmi2TerminateTYPE = "fmi2Terminate", Common => fn(fmi2Component) -> fmi2Status;
        get_real: fmi2GetRealTYPE = "fmi2GetReal", Common => fn(fmi2Component, *const fmi2ValueReference, usize, *mut fmi2Real) -> fmi2Status;
        get_integer: fmi2GetIntegerTYPE = "fmi2GetInteger", Common => fn(fmi2Component, *const fmi2ValueReference, usize, *mut fmi2Integer) -> fmi2Status;
        get_boolean: fmi2GetBooleanTYPE = "fmi2GetBoolean", Common => fn(fmi2Component, *const fmi2ValueReference, usize, *mut fmi2Boolean) -> fmi2Status;
        get_string: fmi2GetStringTYPE = "fmi2GetString", Common => fn(fmi2Component, *const fmi2ValueReference, usize, *mut fmi2String) -> fmi2Status;
        set_real: fmi2SetRealTYPE = "fmi2SetReal", Common => fn(fmi2Component, *const fmi2ValueReference, usize, *const fmi2Real) -> fmi2Status;
        set_integer: fmi2SetIntegerTYPE = "fmi2SetInteger", Common => fn(fmi2Component, *const fmi2ValueReference, usize, *const fmi2Integer) -> fmi2Status;
        set_boolean: fmi2SetBooleanTYPE = "fmi2SetBoolean", Common => fn(fmi2Component, *const fmi2ValueReference, usize, *const fmi2Boolean) -> fmi2Status;
        set_string: fmi2SetStringTYPE = "fmi2SetString", Common => fn(fmi2Component, *const fmi2ValueReference, usize, *const fmi2String) -> fmi2Status;
    }
    optional {
        get_types_platform: fmi2GetTypesPlatformTYPE = "fmi2GetTypesPlatform", Common => fn() -> fmi2String;
        set_debug_logging: fmi2SetDebugLoggingTYPE = "fmi2SetDebugLogging", Common => fn(fmi2Component, fmi2Boolean, usize, *const fmi2String) -> fmi2Status;
        reset: fmi2ResetTYPE = "fmi2Reset", Common => fn(fmi2Component) -> fmi2Status;
        get_fmu_state: fmi2GetFMUstateTYPE = "fmi2GetFMUstate", Common => fn(fmi2Component, *mut fmi2FMUstate) -> fmi2Status;
        set_fmu_state: fmi2SetFMUstateTYPE = "fmi2SetFMUstate", Common => fn(fmi2Component, fmi2FMUstate) -> fmi2Status;
        free_fmu_state: fmi2FreeFMUstateTYPE = "fmi2FreeFMUstate", Common => fn(fmi2Component, *mut fmi2FMUstate) -> fmi2Status;
        serialized_fmu_state_size: fmi2SerializedFMUstateSizeTYPE = "fmi2SerializedFMUstateSize", Common => fn(fmi2Component, fmi2FMUstate, *mut usize) -> fmi2Status;
        serialize_fmu_state: fmi2SerializeFMUstateTYPE = "fmi2SerializeFMUstate", Common => fn(fmi2Component, fmi2FMUstate, *mut fmi2Byte, usize) -> fmi2Status;
        deserialize_fmu_state: fmi2DeSerializeFMUstateTYPE = "fmi2DeSerializeFMUstate", Common => fn(fmi2Component, *const fmi2Byte, usize, *mut fmi2FMUstate) -> fmi2Status;
        get_directional_derivative: fmi2GetDirectionalDerivativeTYPE = "fmi2GetDirectionalDerivative", Common => fn(fmi2Component, *const fmi2ValueReference, usize, *const fmi2ValueReference, usize, *const fmi2Real, *mut fmi2Real) -> fmi2Status;
        set_real_input_derivatives: fmi2SetRealInputDerivativesTYPE = "fmi2SetRealInputDerivatives", CoSimulation => fn(fmi2Component, *const fmi2ValueReference, usize, *const fmi2Integer, *const fmi2Real) -> fmi2Status;
        get_real_output_derivatives: fmi2GetRealOutputDerivativesTYPE = "fmi2GetRealOutputDerivatives", CoSimulation => fn(fmi2Component, *const fmi2ValueReference, usize, *const fmi2Integer, *mut fmi2Real) -> fmi2Status;
        do_step: fmi2DoStepTYPE = "fmi2DoStep", CoSimulation => fn(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean) -> fmi2Status;
        cancel_step: fmi2CancelStepTYPE = "fmi2CancelStep", CoSimulation => fn(fmi2Component) -> fmi2Status;
        get_status: fmi2GetStatusTYPE = "fmi2GetStatus", CoSimulation => fn(fmi2Component, fmi2StatusKind, *mut fmi2Status) -> fmi2Status;
        get_real_status: fmi2GetRealStatusTYPE = "fmi2GetRealStatus", CoSimulation => fn(fmi2Component, fmi2StatusKind, *mut fmi2Real) -> fmi2Status;
        get_integer_status: fmi2GetIntegerStatusTYPE = "fmi2GetIntegerStatus", CoSimulation => fn(fmi2Component, fmi2StatusKind, *mut fmi2Integer) -> fmi2Status;
        get_boolean_status: fmi2GetBooleanStatusTYPE = "fmi2GetBooleanStatus", CoSimulation => fn(fmi2Component, fmi2StatusKind, *mut fmi2Boolean) -> fmi2Status;
        get_string_status: fmi2GetStringStatusTYPE = "fmi2GetStringStatus", CoSimulation => fn(fmi2Component, fmi2StatusKind, *mut fmi2String) -> fmi2Status;
        enter_event_mode: fmi2EnterEventModeTYPE = "fmi2EnterEventMode", ModelExchange => fn(fmi2Component) -> fmi2Status;
        new_discrete_states: fmi2NewDiscreteStatesTYPE = "fmi2NewDiscreteStates", ModelExchange => fn(fmi2Component, *mut Fmi2EventInfo) -> fmi2Status;
        enter_continuous_time_mode: fmi2EnterContinuousTimeModeTYPE = "fmi2EnterContinuousTimeMode", ModelExchange => fn(fmi2Component) -> fmi2Status;
        completed_integrator_step: fmi2CompletedIntegratorStepTYPE = "fmi2CompletedIntegratorStep", ModelExchange => fn(fmi2Component, fmi2Boolean, *mut fmi2Boolean, *mut fmi2Boolean) -> fmi2Status;
        set_time: fmi2SetTimeTYPE = "fmi2SetTime", ModelExchange => fn(fmi2Component, fmi2Real) -> fmi2Status;
        set_continuous_states: fmi2SetContinuousStatesTYPE = "fmi2SetContinuousStates", ModelExchange => fn(fmi2Component, *const fmi2Real, usize) -> fmi2Status;
        get_derivatives: fmi2GetDerivativesTYPE = "fmi2GetDerivatives", ModelExchange => fn(fmi2Component, *mut fmi2Real, usize) -> fmi2Status;
        get_event_indicators: fmi2GetEventIndicatorsTYPE = "fmi2GetEventIndicators", ModelExchange => fn(fmi2Component, *mut fmi2Real, usize) -> fmi2Status;
        get_continuous_states: fmi2GetContinuousStatesTYPE = "fmi2GetContinuousStates", ModelExchange => fn(fmi2Component, *mut fmi2Real, usize) -> fmi2Status;
        get_nominals_of_continuous_states: fmi2GetNominalsOfContinuousStatesTYPE = "fmi2GetNominalsOfContinuousStates", ModelExchange => fn(fmi2Component, *mut fmi2Real, usize) -> fmi2Status;
    }
}

impl Fmi2Functions {
    /// The functions FMI 2.0 requires of a library offering `interface` (the common ones
    /// and the interface's) that this one does not export, in the order of [`SYMBOLS`].
    pub fn missing(&self, interface: Fmi2Type) -> Vec<&'static str> {
        let part = match interface {
            Fmi2Type::CoSimulation => Fmi2Part::CoSimulation,
            Fmi2Type::ModelExchange => Fmi2Part::ModelExchange,
        };
        SYMBOLS
            .iter()
            .filter(|(s, p)| (*p == Fmi2Part::Common || *p == part) && !self.has(s))
            .map(|(s, _)| *s)
            .collect()
    }
}

/// The counts of the FMI 2.0 standard, section 2.1 (common), 4.2 (Co-Simulation), 3.2
/// (Model Exchange), in the order of the table.
#[test]
fn the_44_symbols_are_25_common_9_co_simulation_10_model_exchange() {
    let parts = [Fmi2Part::Common, Fmi2Part::CoSimulation, Fmi2Part::ModelExchange];
    assert_eq!(parts.map(|p| symbols_of(p).count()), [25, 9, 10]);
    assert_eq!((SYMBOLS[0].0, SYMBOLS[43].0), ("fmi2GetVersion", "fmi2GetNominalsOfContinuousStates"));
    assert!(SYMBOLS.iter().any(|(s, _)| *s == "fmi2DeSerializeFMUstate"));
}

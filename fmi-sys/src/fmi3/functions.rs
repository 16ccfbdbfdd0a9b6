//! The functions of FMI 3.0: their C types (`fmi3FunctionTypes.h`), their symbol names by
//! interface, and one table of function pointers loaded from a shared library.
//!
//! FMI 3.0 asks an FMU's library to export every `fmi3*` function, also those of interface
//! types and features it does not declare (they return `fmi3Error`). Libraries in the wild
//! omit some, so the table holds as plain function pointers the 7 that no importer can run
//! an FMU without (version, free, the two initialization calls, terminate, get and set of
//! Float64) and every other one as an `Option`. [`Fmi3Functions::missing`] lists what the
//! standard requires and the library lacks.
#![allow(non_snake_case)]

use super::*;
use std::ffi::c_char;

/// The part of FMI 3.0 a function belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fmi3Part {
    /// Every interface type.
    Common,
    /// Model Exchange only.
    ModelExchange,
    /// Co-Simulation only.
    CoSimulation,
    /// Scheduled Execution only.
    ScheduledExecution,
}

pub use crate::table::MissingSymbol;

crate::table::function_table! {
    /// The C type of each function, named as in `fmi3FunctionTypes.h`. The Booleans are C
    /// `bool`s; an importer reads what an FMU wrote through an `fmi3Boolean*` as a byte
    /// (any value but 0 is true), never as a Rust `bool`.
    mod types;
    /// The functions of an FMI 3.0 library: the 7 every importer calls as function
    /// pointers, the others as `Option` (`None`: the library does not export it).
    pub struct Fmi3Functions: Fmi3Part, 75 symbols of "FMI 3.0";
    core {
        get_version: fmi3GetVersionTYPE = "fmi3GetVersion", Common => fn() -> *const c_char;
        free_instance: fmi3FreeInstanceTYPE = "fmi3FreeInstance", Common => fn(fmi3Instance);
        enter_initialization_mode: fmi3EnterInitializationModeTYPE = "fmi3EnterInitializationMode", Common => fn(fmi3Instance, fmi3Boolean, fmi3Float64, fmi3Float64, fmi3Boolean, fmi3Float64) -> fmi3Status;
        exit_initialization_mode: fmi3ExitInitializationModeTYPE = "fmi3ExitInitializationMode", Common => fn(fmi3Instance) -> fmi3Status;
        terminate: fmi3TerminateTYPE = "fmi3Terminate", Common => fn(fmi3Instance) -> fmi3Status;
        get_float64: fmi3GetFloat64TYPE = "fmi3GetFloat64", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Float64, usize) -> fmi3Status;
        set_float64: fmi3SetFloat64TYPE = "fmi3SetFloat64", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Float64, usize) -> fmi3Status;
    }
    optional {
        set_debug_logging: fmi3SetDebugLoggingTYPE = "fmi3SetDebugLogging", Common => fn(fmi3Instance, fmi3Boolean, usize, *const fmi3String) -> fmi3Status;
        instantiate_model_exchange: fmi3InstantiateModelExchangeTYPE = "fmi3InstantiateModelExchange", Common => fn(fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean, fmi3InstanceEnvironment, Option<Fmi3LogMessageCallback>) -> fmi3Instance;
        instantiate_co_simulation: fmi3InstantiateCoSimulationTYPE = "fmi3InstantiateCoSimulation", Common => fn(fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean, fmi3Boolean, fmi3Boolean, *const fmi3ValueReference, usize, fmi3InstanceEnvironment, Option<Fmi3LogMessageCallback>, Option<Fmi3IntermediateUpdateCallback>) -> fmi3Instance;
        instantiate_scheduled_execution: fmi3InstantiateScheduledExecutionTYPE = "fmi3InstantiateScheduledExecution", Common => fn(fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean, fmi3InstanceEnvironment, Option<Fmi3LogMessageCallback>, Option<Fmi3ClockUpdateCallback>, Option<Fmi3LockPreemptionCallback>, Option<Fmi3UnlockPreemptionCallback>) -> fmi3Instance;
        enter_event_mode: fmi3EnterEventModeTYPE = "fmi3EnterEventMode", Common => fn(fmi3Instance) -> fmi3Status;
        reset: fmi3ResetTYPE = "fmi3Reset", Common => fn(fmi3Instance) -> fmi3Status;
        get_float32: fmi3GetFloat32TYPE = "fmi3GetFloat32", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Float32, usize) -> fmi3Status;
        get_int8: fmi3GetInt8TYPE = "fmi3GetInt8", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Int8, usize) -> fmi3Status;
        get_uint8: fmi3GetUInt8TYPE = "fmi3GetUInt8", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3UInt8, usize) -> fmi3Status;
        get_int16: fmi3GetInt16TYPE = "fmi3GetInt16", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Int16, usize) -> fmi3Status;
        get_uint16: fmi3GetUInt16TYPE = "fmi3GetUInt16", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3UInt16, usize) -> fmi3Status;
        get_int32: fmi3GetInt32TYPE = "fmi3GetInt32", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Int32, usize) -> fmi3Status;
        get_uint32: fmi3GetUInt32TYPE = "fmi3GetUInt32", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3UInt32, usize) -> fmi3Status;
        get_int64: fmi3GetInt64TYPE = "fmi3GetInt64", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Int64, usize) -> fmi3Status;
        get_uint64: fmi3GetUInt64TYPE = "fmi3GetUInt64", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3UInt64, usize) -> fmi3Status;
        get_boolean: fmi3GetBooleanTYPE = "fmi3GetBoolean", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Boolean, usize) -> fmi3Status;
        get_string: fmi3GetStringTYPE = "fmi3GetString", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3String, usize) -> fmi3Status;
        get_binary: fmi3GetBinaryTYPE = "fmi3GetBinary", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut usize, *mut fmi3Binary, usize) -> fmi3Status;
        get_clock: fmi3GetClockTYPE = "fmi3GetClock", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Clock) -> fmi3Status;
        set_float32: fmi3SetFloat32TYPE = "fmi3SetFloat32", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Float32, usize) -> fmi3Status;
        set_int8: fmi3SetInt8TYPE = "fmi3SetInt8", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Int8, usize) -> fmi3Status;
        set_uint8: fmi3SetUInt8TYPE = "fmi3SetUInt8", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3UInt8, usize) -> fmi3Status;
        set_int16: fmi3SetInt16TYPE = "fmi3SetInt16", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Int16, usize) -> fmi3Status;
        set_uint16: fmi3SetUInt16TYPE = "fmi3SetUInt16", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3UInt16, usize) -> fmi3Status;
        set_int32: fmi3SetInt32TYPE = "fmi3SetInt32", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Int32, usize) -> fmi3Status;
        set_uint32: fmi3SetUInt32TYPE = "fmi3SetUInt32", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3UInt32, usize) -> fmi3Status;
        set_int64: fmi3SetInt64TYPE = "fmi3SetInt64", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Int64, usize) -> fmi3Status;
        set_uint64: fmi3SetUInt64TYPE = "fmi3SetUInt64", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3UInt64, usize) -> fmi3Status;
        set_boolean: fmi3SetBooleanTYPE = "fmi3SetBoolean", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Boolean, usize) -> fmi3Status;
        set_string: fmi3SetStringTYPE = "fmi3SetString", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3String, usize) -> fmi3Status;
        set_binary: fmi3SetBinaryTYPE = "fmi3SetBinary", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const usize, *const fmi3Binary, usize) -> fmi3Status;
        set_clock: fmi3SetClockTYPE = "fmi3SetClock", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Clock) -> fmi3Status;
        get_number_of_variable_dependencies: fmi3GetNumberOfVariableDependenciesTYPE = "fmi3GetNumberOfVariableDependencies", Common => fn(fmi3Instance, fmi3ValueReference, *mut usize) -> fmi3Status;
        get_variable_dependencies: fmi3GetVariableDependenciesTYPE = "fmi3GetVariableDependencies", Common => fn(fmi3Instance, fmi3ValueReference, *mut usize, *mut fmi3ValueReference, *mut usize, *mut fmi3DependencyKind, usize) -> fmi3Status;
        get_fmu_state: fmi3GetFMUStateTYPE = "fmi3GetFMUState", Common => fn(fmi3Instance, *mut fmi3FMUState) -> fmi3Status;
        set_fmu_state: fmi3SetFMUStateTYPE = "fmi3SetFMUState", Common => fn(fmi3Instance, fmi3FMUState) -> fmi3Status;
        free_fmu_state: fmi3FreeFMUStateTYPE = "fmi3FreeFMUState", Common => fn(fmi3Instance, *mut fmi3FMUState) -> fmi3Status;
        serialized_fmu_state_size: fmi3SerializedFMUStateSizeTYPE = "fmi3SerializedFMUStateSize", Common => fn(fmi3Instance, fmi3FMUState, *mut usize) -> fmi3Status;
        serialize_fmu_state: fmi3SerializeFMUStateTYPE = "fmi3SerializeFMUState", Common => fn(fmi3Instance, fmi3FMUState, *mut fmi3Byte, usize) -> fmi3Status;
        deserialize_fmu_state: fmi3DeserializeFMUStateTYPE = "fmi3DeserializeFMUState", Common => fn(fmi3Instance, *const fmi3Byte, usize, *mut fmi3FMUState) -> fmi3Status;
        get_directional_derivative: fmi3GetDirectionalDerivativeTYPE = "fmi3GetDirectionalDerivative", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3ValueReference, usize, *const fmi3Float64, usize, *mut fmi3Float64, usize) -> fmi3Status;
        get_adjoint_derivative: fmi3GetAdjointDerivativeTYPE = "fmi3GetAdjointDerivative", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3ValueReference, usize, *const fmi3Float64, usize, *mut fmi3Float64, usize) -> fmi3Status;
        enter_configuration_mode: fmi3EnterConfigurationModeTYPE = "fmi3EnterConfigurationMode", Common => fn(fmi3Instance) -> fmi3Status;
        exit_configuration_mode: fmi3ExitConfigurationModeTYPE = "fmi3ExitConfigurationMode", Common => fn(fmi3Instance) -> fmi3Status;
        get_interval_decimal: fmi3GetIntervalDecimalTYPE = "fmi3GetIntervalDecimal", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Float64, *mut fmi3IntervalQualifier) -> fmi3Status;
        get_interval_fraction: fmi3GetIntervalFractionTYPE = "fmi3GetIntervalFraction", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3UInt64, *mut fmi3UInt64, *mut fmi3IntervalQualifier) -> fmi3Status;
        get_shift_decimal: fmi3GetShiftDecimalTYPE = "fmi3GetShiftDecimal", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Float64) -> fmi3Status;
        get_shift_fraction: fmi3GetShiftFractionTYPE = "fmi3GetShiftFraction", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3UInt64, *mut fmi3UInt64) -> fmi3Status;
        set_interval_decimal: fmi3SetIntervalDecimalTYPE = "fmi3SetIntervalDecimal", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Float64) -> fmi3Status;
        set_interval_fraction: fmi3SetIntervalFractionTYPE = "fmi3SetIntervalFraction", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3UInt64, *const fmi3UInt64) -> fmi3Status;
        set_shift_decimal: fmi3SetShiftDecimalTYPE = "fmi3SetShiftDecimal", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Float64) -> fmi3Status;
        set_shift_fraction: fmi3SetShiftFractionTYPE = "fmi3SetShiftFraction", Common => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3UInt64, *const fmi3UInt64) -> fmi3Status;
        evaluate_discrete_states: fmi3EvaluateDiscreteStatesTYPE = "fmi3EvaluateDiscreteStates", Common => fn(fmi3Instance) -> fmi3Status;
        update_discrete_states: fmi3UpdateDiscreteStatesTYPE = "fmi3UpdateDiscreteStates", Common => fn(fmi3Instance, *mut fmi3Boolean, *mut fmi3Boolean, *mut fmi3Boolean, *mut fmi3Boolean, *mut fmi3Boolean, *mut fmi3Float64) -> fmi3Status;
        enter_continuous_time_mode: fmi3EnterContinuousTimeModeTYPE = "fmi3EnterContinuousTimeMode", ModelExchange => fn(fmi3Instance) -> fmi3Status;
        completed_integrator_step: fmi3CompletedIntegratorStepTYPE = "fmi3CompletedIntegratorStep", ModelExchange => fn(fmi3Instance, fmi3Boolean, *mut fmi3Boolean, *mut fmi3Boolean) -> fmi3Status;
        set_time: fmi3SetTimeTYPE = "fmi3SetTime", ModelExchange => fn(fmi3Instance, fmi3Float64) -> fmi3Status;
        set_continuous_states: fmi3SetContinuousStatesTYPE = "fmi3SetContinuousStates", ModelExchange => fn(fmi3Instance, *const fmi3Float64, usize) -> fmi3Status;
        get_continuous_state_derivatives: fmi3GetContinuousStateDerivativesTYPE = "fmi3GetContinuousStateDerivatives", ModelExchange => fn(fmi3Instance, *mut fmi3Float64, usize) -> fmi3Status;
        get_event_indicators: fmi3GetEventIndicatorsTYPE = "fmi3GetEventIndicators", ModelExchange => fn(fmi3Instance, *mut fmi3Float64, usize) -> fmi3Status;
        get_continuous_states: fmi3GetContinuousStatesTYPE = "fmi3GetContinuousStates", ModelExchange => fn(fmi3Instance, *mut fmi3Float64, usize) -> fmi3Status;
        get_nominals_of_continuous_states: fmi3GetNominalsOfContinuousStatesTYPE = "fmi3GetNominalsOfContinuousStates", ModelExchange => fn(fmi3Instance, *mut fmi3Float64, usize) -> fmi3Status;
        get_number_of_event_indicators: fmi3GetNumberOfEventIndicatorsTYPE = "fmi3GetNumberOfEventIndicators", ModelExchange => fn(fmi3Instance, *mut usize) -> fmi3Status;
        get_number_of_continuous_states: fmi3GetNumberOfContinuousStatesTYPE = "fmi3GetNumberOfContinuousStates", ModelExchange => fn(fmi3Instance, *mut usize) -> fmi3Status;
        enter_step_mode: fmi3EnterStepModeTYPE = "fmi3EnterStepMode", CoSimulation => fn(fmi3Instance) -> fmi3Status;
        get_output_derivatives: fmi3GetOutputDerivativesTYPE = "fmi3GetOutputDerivatives", CoSimulation => fn(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Int32, *mut fmi3Float64, usize) -> fmi3Status;
        do_step: fmi3DoStepTYPE = "fmi3DoStep", CoSimulation => fn(fmi3Instance, fmi3Float64, fmi3Float64, fmi3Boolean, *mut fmi3Boolean, *mut fmi3Boolean, *mut fmi3Boolean, *mut fmi3Float64) -> fmi3Status;
        activate_model_partition: fmi3ActivateModelPartitionTYPE = "fmi3ActivateModelPartition", ScheduledExecution => fn(fmi3Instance, fmi3ValueReference, fmi3Float64) -> fmi3Status;
    }
}

impl Fmi3Functions {
    /// The functions FMI 3.0 requires of every library (all of them: an FMU exports each
    /// `fmi3*` function, a feature it lacks answering `fmi3Error`) that this one does not
    /// export, in the order of [`SYMBOLS`].
    pub fn missing(&self) -> Vec<&'static str> {
        SYMBOLS.iter().filter(|(s, _)| !self.has(s)).map(|(s, _)| *s).collect()
    }
}

/// The function counts of `fmi3FunctionTypes.h` (3.0.2): 61 common (with the three
/// instantiation functions), 10 Model Exchange, 3 Co-Simulation, 1 Scheduled Execution.
#[test]
fn the_symbols_are_those_of_the_header() {
    use Fmi3Part::*;
    assert_eq!(
        [Common, ModelExchange, CoSimulation, ScheduledExecution].map(|p| symbols_of(p).count()),
        [61, 10, 3, 1]
    );
    for name in ["fmi3GetAdjointDerivative", "fmi3GetContinuousStateDerivatives"] {
        assert!(SYMBOLS.iter().any(|(s, _)| *s == name), "{name}");
    }
}

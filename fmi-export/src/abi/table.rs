//! The one table of the 119 C entry points (44 `fmi2*`, 75 `fmi3*`): per function its
//! symbol, its C type in `fmi-sys` (`fmi_sys::fmi2::types::fmi2GetRealTYPE`, ...), its
//! [`Function`](crate::states::Function) variant and the layer function that implements it,
//! with the C parameters. Everything per function is generated from here:
//!
//! - [`crate::export_fmi!`] expands the table into one `#[no_mangle] extern "C"` wrapper
//!   per row, which calls the layer function `abi::<generation>::<function>::<Model>` with
//!   the row's `Function` and the parameters, and checks at compile time that the wrapper
//!   has the row's C type (`const _: fmi3DoStepTYPE = fmi3DoStep;`);
//! - [`crate::states`] expands it into `Function` (its variants in table order, the C
//!   name, the generation, the lists of each generation).
//!
//! A row: `symbol: CTYPE = Variant => generation::layer_function(parameters) -> return;`,
//! the parameters in the C order. The layer function gets the row's `Function` and every
//! parameter, or, when the function name is followed by `[a, b]`, only those (the
//! functions of features the FMUs do not declare need no more than the instance); a
//! `::<T>` after the name is a second type argument (the value type of `get`/`set`). The
//! table macro hands the rows to a callback macro, so the table is written once and read
//! by both expansions.
//!
//! Adding an FMI function: one row here (its variant then exists; give it its row of the
//! state table in `states.rs` if it differs from the default) and the layer function in
//! `abi/shared.rs` (when both generations' rows can call it) or in `abi/fmi2.rs` or
//! `abi/fmi3.rs`, taking the `Function` first.

/// Hands the table to the callback macro `$callback` (a path in brackets) with `$head`
/// (one token tree, passed through) in front: `{head} fmi2 { rows } fmi3 { rows }`.
#[doc(hidden)]
#[macro_export]
macro_rules! __fmi_function_table {
    ([$($callback:tt)*] $head:tt) => {
        $($callback)*! { $head
            fmi2 {
                fmi2GetTypesPlatform: fmi2GetTypesPlatformTYPE = GetTypesPlatform => fmi2::get_types_platform() -> fmi2String;
                fmi2GetVersion: fmi2GetVersionTYPE = GetVersion => fmi2::get_version() -> fmi2String;
                fmi2SetDebugLogging: fmi2SetDebugLoggingTYPE = SetDebugLogging => shared::set_debug_logging(c: fmi2Component, on: fmi2Boolean, n: usize, categories: *const fmi2String) -> fmi2Status;
                fmi2Instantiate: fmi2InstantiateTYPE = Instantiate => fmi2::instantiate(name: fmi2String, kind: c_int, guid: fmi2String, resources: fmi2String, functions: *const Fmi2CallbackFunctions, visible: fmi2Boolean, logging_on: fmi2Boolean) -> fmi2Component;
                fmi2FreeInstance: fmi2FreeInstanceTYPE = FreeInstance => shared::free_instance(c: fmi2Component);
                fmi2SetupExperiment: fmi2SetupExperimentTYPE = SetupExperiment => fmi2::setup_experiment(c: fmi2Component, tolerance_defined: fmi2Boolean, tolerance: fmi2Real, start: fmi2Real, stop_defined: fmi2Boolean, stop: fmi2Real) -> fmi2Status;
                fmi2EnterInitializationMode: fmi2EnterInitializationModeTYPE = EnterInitializationMode => shared::enter_initialization_mode(c: fmi2Component) -> fmi2Status;
                fmi2ExitInitializationMode: fmi2ExitInitializationModeTYPE = ExitInitializationMode => shared::exit_initialization_mode(c: fmi2Component) -> fmi2Status;
                fmi2Terminate: fmi2TerminateTYPE = Terminate => shared::terminate(c: fmi2Component) -> fmi2Status;
                fmi2Reset: fmi2ResetTYPE = Reset => shared::reset(c: fmi2Component) -> fmi2Status;
                fmi2GetReal: fmi2GetRealTYPE = GetReal => fmi2::get::<Real>(c: fmi2Component, vr: *const fmi2ValueReference, n: usize, values: *mut fmi2Real) -> fmi2Status;
                fmi2GetInteger: fmi2GetIntegerTYPE = GetInteger => fmi2::get::<Integer>(c: fmi2Component, vr: *const fmi2ValueReference, n: usize, values: *mut fmi2Integer) -> fmi2Status;
                fmi2GetBoolean: fmi2GetBooleanTYPE = GetBoolean => fmi2::get::<Boolean>(c: fmi2Component, vr: *const fmi2ValueReference, n: usize, values: *mut fmi2Boolean) -> fmi2Status;
                fmi2GetString: fmi2GetStringTYPE = GetString => fmi2::get::<String>(c: fmi2Component, vr: *const fmi2ValueReference, n: usize, values: *mut fmi2String) -> fmi2Status;
                fmi2SetReal: fmi2SetRealTYPE = SetReal => fmi2::set::<Real>(c: fmi2Component, vr: *const fmi2ValueReference, n: usize, values: *const fmi2Real) -> fmi2Status;
                fmi2SetInteger: fmi2SetIntegerTYPE = SetInteger => fmi2::set::<Integer>(c: fmi2Component, vr: *const fmi2ValueReference, n: usize, values: *const fmi2Integer) -> fmi2Status;
                fmi2SetBoolean: fmi2SetBooleanTYPE = SetBoolean => fmi2::set::<Boolean>(c: fmi2Component, vr: *const fmi2ValueReference, n: usize, values: *const fmi2Boolean) -> fmi2Status;
                fmi2SetString: fmi2SetStringTYPE = SetString => fmi2::set::<String>(c: fmi2Component, vr: *const fmi2ValueReference, n: usize, values: *const fmi2String) -> fmi2Status;
                fmi2GetFMUstate: fmi2GetFMUstateTYPE = GetFMUstate => shared::get_fmu_state(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status;
                fmi2SetFMUstate: fmi2SetFMUstateTYPE = SetFMUstate => shared::set_fmu_state(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status;
                fmi2FreeFMUstate: fmi2FreeFMUstateTYPE = FreeFMUstate => shared::free_fmu_state(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status;
                fmi2SerializedFMUstateSize: fmi2SerializedFMUstateSizeTYPE = SerializedFMUstateSize => shared::serialized_fmu_state_size(c: fmi2Component, state: fmi2FMUstate, size: *mut usize) -> fmi2Status;
                fmi2SerializeFMUstate: fmi2SerializeFMUstateTYPE = SerializeFMUstate => shared::serialize_fmu_state(c: fmi2Component, state: fmi2FMUstate, bytes: *mut fmi2Byte, size: usize) -> fmi2Status;
                fmi2DeSerializeFMUstate: fmi2DeSerializeFMUstateTYPE = DeSerializeFMUstate => shared::deserialize_fmu_state(c: fmi2Component, bytes: *const fmi2Byte, size: usize, state: *mut fmi2FMUstate) -> fmi2Status;
                fmi2GetDirectionalDerivative: fmi2GetDirectionalDerivativeTYPE = GetDirectionalDerivative => fmi2::get_directional_derivative(c: fmi2Component, unknowns: *const fmi2ValueReference, n_unknowns: usize, knowns: *const fmi2ValueReference, n_knowns: usize, dv_known: *const fmi2Real, dv_unknown: *mut fmi2Real) -> fmi2Status;
                fmi2EnterEventMode: fmi2EnterEventModeTYPE = EnterEventMode => shared::enter_event_mode(c: fmi2Component) -> fmi2Status;
                fmi2NewDiscreteStates: fmi2NewDiscreteStatesTYPE = NewDiscreteStates => fmi2::new_discrete_states(c: fmi2Component, info: *mut Fmi2EventInfo) -> fmi2Status;
                fmi2EnterContinuousTimeMode: fmi2EnterContinuousTimeModeTYPE = EnterContinuousTimeMode => shared::enter_continuous_time_mode(c: fmi2Component) -> fmi2Status;
                fmi2CompletedIntegratorStep: fmi2CompletedIntegratorStepTYPE = CompletedIntegratorStep => shared::completed_integrator_step(c: fmi2Component, no_set_prior: fmi2Boolean, enter_event_mode: *mut fmi2Boolean, terminate_simulation: *mut fmi2Boolean) -> fmi2Status;
                fmi2SetTime: fmi2SetTimeTYPE = SetTime => shared::set_time(c: fmi2Component, time: fmi2Real) -> fmi2Status;
                fmi2SetContinuousStates: fmi2SetContinuousStatesTYPE = SetContinuousStates => shared::set_continuous_states(c: fmi2Component, x: *const fmi2Real, nx: usize) -> fmi2Status;
                fmi2GetDerivatives: fmi2GetDerivativesTYPE = GetDerivatives => shared::get_derivatives(c: fmi2Component, dx: *mut fmi2Real, nx: usize) -> fmi2Status;
                fmi2GetEventIndicators: fmi2GetEventIndicatorsTYPE = GetEventIndicators => shared::get_event_indicators(c: fmi2Component, z: *mut fmi2Real, ni: usize) -> fmi2Status;
                fmi2GetContinuousStates: fmi2GetContinuousStatesTYPE = GetContinuousStates => shared::get_continuous_states(c: fmi2Component, x: *mut fmi2Real, nx: usize) -> fmi2Status;
                fmi2GetNominalsOfContinuousStates: fmi2GetNominalsOfContinuousStatesTYPE = GetNominalsOfContinuousStates => shared::get_nominals_of_continuous_states(c: fmi2Component, x: *mut fmi2Real, nx: usize) -> fmi2Status;
                fmi2SetRealInputDerivatives: fmi2SetRealInputDerivativesTYPE = SetRealInputDerivatives => fmi2::set_real_input_derivatives[c](c: fmi2Component, vr: *const fmi2ValueReference, n: usize, order: *const fmi2Integer, values: *const fmi2Real) -> fmi2Status;
                fmi2GetRealOutputDerivatives: fmi2GetRealOutputDerivativesTYPE = GetRealOutputDerivatives => fmi2::get_real_output_derivatives[c](c: fmi2Component, vr: *const fmi2ValueReference, n: usize, order: *const fmi2Integer, values: *mut fmi2Real) -> fmi2Status;
                fmi2DoStep: fmi2DoStepTYPE = DoStep => fmi2::do_step(c: fmi2Component, current: fmi2Real, step: fmi2Real, no_set_prior: fmi2Boolean) -> fmi2Status;
                fmi2CancelStep: fmi2CancelStepTYPE = CancelStep => fmi2::cancel_step(c: fmi2Component) -> fmi2Status;
                fmi2GetStatus: fmi2GetStatusTYPE = GetStatus => fmi2::get_status(c: fmi2Component, kind: fmi2StatusKind, value: *mut fmi2Status) -> fmi2Status;
                fmi2GetRealStatus: fmi2GetRealStatusTYPE = GetRealStatus => fmi2::get_real_status(c: fmi2Component, kind: fmi2StatusKind, value: *mut fmi2Real) -> fmi2Status;
                fmi2GetIntegerStatus: fmi2GetIntegerStatusTYPE = GetIntegerStatus => fmi2::get_integer_status[c, kind](c: fmi2Component, kind: fmi2StatusKind, value: *mut fmi2Integer) -> fmi2Status;
                fmi2GetBooleanStatus: fmi2GetBooleanStatusTYPE = GetBooleanStatus => fmi2::get_boolean_status(c: fmi2Component, kind: fmi2StatusKind, value: *mut fmi2Boolean) -> fmi2Status;
                fmi2GetStringStatus: fmi2GetStringStatusTYPE = GetStringStatus => fmi2::get_string_status[c, kind](c: fmi2Component, kind: fmi2StatusKind, value: *mut fmi2String) -> fmi2Status;
            }
            fmi3 {
                fmi3GetVersion: fmi3GetVersionTYPE = Fmi3GetVersion => fmi3::get_version() -> *const c_char;
                fmi3EnterInitializationMode: fmi3EnterInitializationModeTYPE = Fmi3EnterInitializationMode => fmi3::enter_initialization_mode(instance: fmi3Instance, tolerance_defined: fmi3Boolean, tolerance: fmi3Float64, start: fmi3Float64, stop_defined: fmi3Boolean, stop: fmi3Float64) -> fmi3Status;
                fmi3ExitInitializationMode: fmi3ExitInitializationModeTYPE = Fmi3ExitInitializationMode => shared::exit_initialization_mode(instance: fmi3Instance) -> fmi3Status;
                fmi3Terminate: fmi3TerminateTYPE = Fmi3Terminate => shared::terminate(instance: fmi3Instance) -> fmi3Status;
                fmi3FreeInstance: fmi3FreeInstanceTYPE = Fmi3FreeInstance => shared::free_instance(instance: fmi3Instance);
                fmi3GetFloat64: fmi3GetFloat64TYPE = Fmi3GetFloat64 => fmi3::get::<Float64>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3Float64, n_values: usize) -> fmi3Status;
                fmi3SetFloat64: fmi3SetFloat64TYPE = Fmi3SetFloat64 => fmi3::set::<Float64>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3Float64, n_values: usize) -> fmi3Status;
                fmi3SetDebugLogging: fmi3SetDebugLoggingTYPE = Fmi3SetDebugLogging => fmi3::set_debug_logging(instance: fmi3Instance, on: fmi3Boolean, n: usize, categories: *const fmi3String) -> fmi3Status;
                fmi3InstantiateModelExchange: fmi3InstantiateModelExchangeTYPE = Fmi3InstantiateModelExchange => fmi3::instantiate_model_exchange(name: fmi3String, token: fmi3String, resources: fmi3String, visible: fmi3Boolean, logging_on: fmi3Boolean, environment: fmi3InstanceEnvironment, log_message: Option<Fmi3LogMessageCallback>) -> fmi3Instance;
                fmi3InstantiateCoSimulation: fmi3InstantiateCoSimulationTYPE = Fmi3InstantiateCoSimulation => fmi3::instantiate_co_simulation(name: fmi3String, token: fmi3String, resources: fmi3String, visible: fmi3Boolean, logging_on: fmi3Boolean, event_mode_used: fmi3Boolean, early_return_allowed: fmi3Boolean, intermediate: *const fmi3ValueReference, n_intermediate: usize, environment: fmi3InstanceEnvironment, log_message: Option<Fmi3LogMessageCallback>, intermediate_update: Option<Fmi3IntermediateUpdateCallback>) -> fmi3Instance;
                fmi3InstantiateScheduledExecution: fmi3InstantiateScheduledExecutionTYPE = Fmi3InstantiateScheduledExecution => fmi3::instantiate_scheduled_execution(name: fmi3String, token: fmi3String, resources: fmi3String, visible: fmi3Boolean, logging_on: fmi3Boolean, environment: fmi3InstanceEnvironment, log_message: Option<Fmi3LogMessageCallback>, clock_update: Option<Fmi3ClockUpdateCallback>, lock: Option<Fmi3LockPreemptionCallback>, unlock: Option<Fmi3UnlockPreemptionCallback>) -> fmi3Instance;
                fmi3EnterEventMode: fmi3EnterEventModeTYPE = Fmi3EnterEventMode => shared::enter_event_mode(instance: fmi3Instance) -> fmi3Status;
                fmi3Reset: fmi3ResetTYPE = Fmi3Reset => shared::reset(instance: fmi3Instance) -> fmi3Status;
                fmi3GetFloat32: fmi3GetFloat32TYPE = Fmi3GetFloat32 => fmi3::get::<Float32>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3Float32, n_values: usize) -> fmi3Status;
                fmi3GetInt8: fmi3GetInt8TYPE = Fmi3GetInt8 => fmi3::get::<Int8>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3Int8, n_values: usize) -> fmi3Status;
                fmi3GetUInt8: fmi3GetUInt8TYPE = Fmi3GetUInt8 => fmi3::get::<UInt8>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3UInt8, n_values: usize) -> fmi3Status;
                fmi3GetInt16: fmi3GetInt16TYPE = Fmi3GetInt16 => fmi3::get::<Int16>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3Int16, n_values: usize) -> fmi3Status;
                fmi3GetUInt16: fmi3GetUInt16TYPE = Fmi3GetUInt16 => fmi3::get::<UInt16>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3UInt16, n_values: usize) -> fmi3Status;
                fmi3GetInt32: fmi3GetInt32TYPE = Fmi3GetInt32 => fmi3::get::<Int32>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3Int32, n_values: usize) -> fmi3Status;
                fmi3GetUInt32: fmi3GetUInt32TYPE = Fmi3GetUInt32 => fmi3::get::<UInt32>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3UInt32, n_values: usize) -> fmi3Status;
                fmi3GetInt64: fmi3GetInt64TYPE = Fmi3GetInt64 => fmi3::get::<Enumeration>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3Int64, n_values: usize) -> fmi3Status;
                fmi3GetUInt64: fmi3GetUInt64TYPE = Fmi3GetUInt64 => fmi3::get::<UInt64>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3UInt64, n_values: usize) -> fmi3Status;
                fmi3GetBoolean: fmi3GetBooleanTYPE = Fmi3GetBoolean => fmi3::get::<Boolean>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3Boolean, n_values: usize) -> fmi3Status;
                fmi3GetString: fmi3GetStringTYPE = Fmi3GetString => fmi3::get::<String>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3String, n_values: usize) -> fmi3Status;
                fmi3GetBinary: fmi3GetBinaryTYPE = Fmi3GetBinary => fmi3::binary[instance, vr, n_vr, n_values](instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, sizes: *mut usize, values: *mut fmi3Binary, n_values: usize) -> fmi3Status;
                fmi3GetClock: fmi3GetClockTYPE = Fmi3GetClock => fmi3::get_clock(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *mut fmi3Clock) -> fmi3Status;
                fmi3SetFloat32: fmi3SetFloat32TYPE = Fmi3SetFloat32 => fmi3::set::<Float32>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3Float32, n_values: usize) -> fmi3Status;
                fmi3SetInt8: fmi3SetInt8TYPE = Fmi3SetInt8 => fmi3::set::<Int8>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3Int8, n_values: usize) -> fmi3Status;
                fmi3SetUInt8: fmi3SetUInt8TYPE = Fmi3SetUInt8 => fmi3::set::<UInt8>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3UInt8, n_values: usize) -> fmi3Status;
                fmi3SetInt16: fmi3SetInt16TYPE = Fmi3SetInt16 => fmi3::set::<Int16>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3Int16, n_values: usize) -> fmi3Status;
                fmi3SetUInt16: fmi3SetUInt16TYPE = Fmi3SetUInt16 => fmi3::set::<UInt16>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3UInt16, n_values: usize) -> fmi3Status;
                fmi3SetInt32: fmi3SetInt32TYPE = Fmi3SetInt32 => fmi3::set::<Int32>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3Int32, n_values: usize) -> fmi3Status;
                fmi3SetUInt32: fmi3SetUInt32TYPE = Fmi3SetUInt32 => fmi3::set::<UInt32>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3UInt32, n_values: usize) -> fmi3Status;
                fmi3SetInt64: fmi3SetInt64TYPE = Fmi3SetInt64 => fmi3::set::<Enumeration>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3Int64, n_values: usize) -> fmi3Status;
                fmi3SetUInt64: fmi3SetUInt64TYPE = Fmi3SetUInt64 => fmi3::set::<UInt64>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3UInt64, n_values: usize) -> fmi3Status;
                fmi3SetBoolean: fmi3SetBooleanTYPE = Fmi3SetBoolean => fmi3::set::<Boolean>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3Boolean, n_values: usize) -> fmi3Status;
                fmi3SetString: fmi3SetStringTYPE = Fmi3SetString => fmi3::set::<String>(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3String, n_values: usize) -> fmi3Status;
                fmi3SetBinary: fmi3SetBinaryTYPE = Fmi3SetBinary => fmi3::binary[instance, vr, n_vr, n_values](instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, sizes: *const usize, values: *const fmi3Binary, n_values: usize) -> fmi3Status;
                fmi3SetClock: fmi3SetClockTYPE = Fmi3SetClock => fmi3::set_clock(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, values: *const fmi3Clock) -> fmi3Status;
                fmi3GetNumberOfVariableDependencies: fmi3GetNumberOfVariableDependenciesTYPE = Fmi3GetNumberOfVariableDependencies => fmi3::get_number_of_variable_dependencies(instance: fmi3Instance, vr: fmi3ValueReference, n: *mut usize) -> fmi3Status;
                fmi3GetVariableDependencies: fmi3GetVariableDependenciesTYPE = Fmi3GetVariableDependencies => fmi3::get_variable_dependencies(instance: fmi3Instance, dependent: fmi3ValueReference, element_of_dependent: *mut usize, independents: *mut fmi3ValueReference, element_of_independents: *mut usize, kinds: *mut fmi3DependencyKind, n: usize) -> fmi3Status;
                fmi3GetFMUState: fmi3GetFMUStateTYPE = Fmi3GetFMUState => shared::get_fmu_state(instance: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status;
                fmi3SetFMUState: fmi3SetFMUStateTYPE = Fmi3SetFMUState => shared::set_fmu_state(instance: fmi3Instance, state: fmi3FMUState) -> fmi3Status;
                fmi3FreeFMUState: fmi3FreeFMUStateTYPE = Fmi3FreeFMUState => shared::free_fmu_state(instance: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status;
                fmi3SerializedFMUStateSize: fmi3SerializedFMUStateSizeTYPE = Fmi3SerializedFMUStateSize => shared::serialized_fmu_state_size(instance: fmi3Instance, state: fmi3FMUState, size: *mut usize) -> fmi3Status;
                fmi3SerializeFMUState: fmi3SerializeFMUStateTYPE = Fmi3SerializeFMUState => shared::serialize_fmu_state(instance: fmi3Instance, state: fmi3FMUState, bytes: *mut fmi3Byte, size: usize) -> fmi3Status;
                fmi3DeserializeFMUState: fmi3DeserializeFMUStateTYPE = Fmi3DeserializeFMUState => shared::deserialize_fmu_state(instance: fmi3Instance, bytes: *const fmi3Byte, size: usize, state: *mut fmi3FMUState) -> fmi3Status;
                fmi3GetDirectionalDerivative: fmi3GetDirectionalDerivativeTYPE = Fmi3GetDirectionalDerivative => fmi3::get_partial_derivatives(instance: fmi3Instance, unknowns: *const fmi3ValueReference, n_unknowns: usize, knowns: *const fmi3ValueReference, n_knowns: usize, seed: *const fmi3Float64, n_seed: usize, sensitivity: *mut fmi3Float64, n_sensitivity: usize) -> fmi3Status;
                fmi3GetAdjointDerivative: fmi3GetAdjointDerivativeTYPE = Fmi3GetAdjointDerivative => fmi3::get_partial_derivatives(instance: fmi3Instance, unknowns: *const fmi3ValueReference, n_unknowns: usize, knowns: *const fmi3ValueReference, n_knowns: usize, seed: *const fmi3Float64, n_seed: usize, sensitivity: *mut fmi3Float64, n_sensitivity: usize) -> fmi3Status;
                fmi3EnterConfigurationMode: fmi3EnterConfigurationModeTYPE = Fmi3EnterConfigurationMode => fmi3::undeclared[instance](instance: fmi3Instance) -> fmi3Status;
                fmi3ExitConfigurationMode: fmi3ExitConfigurationModeTYPE = Fmi3ExitConfigurationMode => fmi3::undeclared[instance](instance: fmi3Instance) -> fmi3Status;
                fmi3GetIntervalDecimal: fmi3GetIntervalDecimalTYPE = Fmi3GetIntervalDecimal => fmi3::get_interval_decimal(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, intervals: *mut fmi3Float64, qualifiers: *mut fmi3IntervalQualifier) -> fmi3Status;
                fmi3GetIntervalFraction: fmi3GetIntervalFractionTYPE = Fmi3GetIntervalFraction => fmi3::clock_fraction[instance, vr, n_vr](instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, counters: *mut fmi3UInt64, resolutions: *mut fmi3UInt64, qualifiers: *mut fmi3IntervalQualifier) -> fmi3Status;
                fmi3GetShiftDecimal: fmi3GetShiftDecimalTYPE = Fmi3GetShiftDecimal => fmi3::get_shift_decimal(instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, shifts: *mut fmi3Float64) -> fmi3Status;
                fmi3GetShiftFraction: fmi3GetShiftFractionTYPE = Fmi3GetShiftFraction => fmi3::clock_fraction[instance, vr, n_vr](instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, counters: *mut fmi3UInt64, resolutions: *mut fmi3UInt64) -> fmi3Status;
                fmi3SetIntervalDecimal: fmi3SetIntervalDecimalTYPE = Fmi3SetIntervalDecimal => fmi3::clock_timing[instance, vr, n_vr](instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, intervals: *const fmi3Float64) -> fmi3Status;
                fmi3SetIntervalFraction: fmi3SetIntervalFractionTYPE = Fmi3SetIntervalFraction => fmi3::clock_timing[instance, vr, n_vr](instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, counters: *const fmi3UInt64, resolutions: *const fmi3UInt64) -> fmi3Status;
                fmi3SetShiftDecimal: fmi3SetShiftDecimalTYPE = Fmi3SetShiftDecimal => fmi3::clock_timing[instance, vr, n_vr](instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, shifts: *const fmi3Float64) -> fmi3Status;
                fmi3SetShiftFraction: fmi3SetShiftFractionTYPE = Fmi3SetShiftFraction => fmi3::clock_timing[instance, vr, n_vr](instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, counters: *const fmi3UInt64, resolutions: *const fmi3UInt64) -> fmi3Status;
                fmi3EvaluateDiscreteStates: fmi3EvaluateDiscreteStatesTYPE = Fmi3EvaluateDiscreteStates => fmi3::undeclared[instance](instance: fmi3Instance) -> fmi3Status;
                fmi3UpdateDiscreteStates: fmi3UpdateDiscreteStatesTYPE = Fmi3UpdateDiscreteStates => fmi3::update_discrete_states(instance: fmi3Instance, need_update: *mut fmi3Boolean, terminate_simulation: *mut fmi3Boolean, nominals_changed: *mut fmi3Boolean, values_changed: *mut fmi3Boolean, next_time_defined: *mut fmi3Boolean, next_time: *mut fmi3Float64) -> fmi3Status;
                fmi3EnterContinuousTimeMode: fmi3EnterContinuousTimeModeTYPE = Fmi3EnterContinuousTimeMode => shared::enter_continuous_time_mode(instance: fmi3Instance) -> fmi3Status;
                fmi3CompletedIntegratorStep: fmi3CompletedIntegratorStepTYPE = Fmi3CompletedIntegratorStep => shared::completed_integrator_step(instance: fmi3Instance, no_set_prior: fmi3Boolean, enter_event_mode: *mut fmi3Boolean, terminate_simulation: *mut fmi3Boolean) -> fmi3Status;
                fmi3SetTime: fmi3SetTimeTYPE = Fmi3SetTime => shared::set_time(instance: fmi3Instance, time: fmi3Float64) -> fmi3Status;
                fmi3SetContinuousStates: fmi3SetContinuousStatesTYPE = Fmi3SetContinuousStates => shared::set_continuous_states(instance: fmi3Instance, x: *const fmi3Float64, nx: usize) -> fmi3Status;
                fmi3GetContinuousStateDerivatives: fmi3GetContinuousStateDerivativesTYPE = Fmi3GetContinuousStateDerivatives => shared::get_derivatives(instance: fmi3Instance, dx: *mut fmi3Float64, nx: usize) -> fmi3Status;
                fmi3GetEventIndicators: fmi3GetEventIndicatorsTYPE = Fmi3GetEventIndicators => shared::get_event_indicators(instance: fmi3Instance, z: *mut fmi3Float64, ni: usize) -> fmi3Status;
                fmi3GetContinuousStates: fmi3GetContinuousStatesTYPE = Fmi3GetContinuousStates => shared::get_continuous_states(instance: fmi3Instance, x: *mut fmi3Float64, nx: usize) -> fmi3Status;
                fmi3GetNominalsOfContinuousStates: fmi3GetNominalsOfContinuousStatesTYPE = Fmi3GetNominalsOfContinuousStates => shared::get_nominals_of_continuous_states(instance: fmi3Instance, x: *mut fmi3Float64, nx: usize) -> fmi3Status;
                fmi3GetNumberOfEventIndicators: fmi3GetNumberOfEventIndicatorsTYPE = Fmi3GetNumberOfEventIndicators => fmi3::get_number_of_event_indicators(instance: fmi3Instance, n: *mut usize) -> fmi3Status;
                fmi3GetNumberOfContinuousStates: fmi3GetNumberOfContinuousStatesTYPE = Fmi3GetNumberOfContinuousStates => fmi3::get_number_of_continuous_states(instance: fmi3Instance, n: *mut usize) -> fmi3Status;
                fmi3EnterStepMode: fmi3EnterStepModeTYPE = Fmi3EnterStepMode => fmi3::enter_step_mode(instance: fmi3Instance) -> fmi3Status;
                fmi3GetOutputDerivatives: fmi3GetOutputDerivativesTYPE = Fmi3GetOutputDerivatives => fmi3::undeclared[instance](instance: fmi3Instance, vr: *const fmi3ValueReference, n_vr: usize, orders: *const fmi3Int32, values: *mut fmi3Float64, n_values: usize) -> fmi3Status;
                fmi3DoStep: fmi3DoStepTYPE = Fmi3DoStep => fmi3::do_step(instance: fmi3Instance, current: fmi3Float64, step: fmi3Float64, no_set_prior: fmi3Boolean, event_handling_needed: *mut fmi3Boolean, terminate_simulation: *mut fmi3Boolean, early_return: *mut fmi3Boolean, last_successful_time: *mut fmi3Float64) -> fmi3Status;
                fmi3ActivateModelPartition: fmi3ActivateModelPartitionTYPE = Fmi3ActivateModelPartition => fmi3::activate_model_partition(instance: fmi3Instance, clock: fmi3ValueReference, activation_time: fmi3Float64) -> fmi3Status;
            }
        }
    };
}

//! The FMI 3.0 state machine of the layer, cell by cell, against the standard's lists of
//! allowed function calls, written down here from FMI 3.0.2 and not from the layer:
//! section 2.3 (super states FMU State Settable and Initialized; states Instantiated,
//! Initialization Mode, Event Mode, Terminated), 3.2 (Continuous-Time Mode) and 4.2 (Step
//! Mode), with the standard's erratum that adds `fmi3Get{VariableType}` to Instantiated
//! and the variable dependency functions to every state. Each of the 71 functions that take
//! an instance, in each state either interface of the plant can be in, for Co-Simulation
//! and Model Exchange, must be allowed by the layer ([`Instance::call_allowed`], the gate
//! of every call) exactly when the standard allows it for an FMU that declares what the
//! plant's modelDescription.xml declares.

use fmi_export::instance::{Function, Generation, Instance, Machine};
use fmi_export::model::{Interface, Model as _};
use nigel_plant::Plant;

/// `fmi3Get{VariableType}` and `fmi3Set{VariableType}` (section 2.2.6; the Clock
/// functions are described with the Clocks and listed separately in the states).
const VARIABLE_TYPES: [&str; 13] = [
    "Float32", "Float64", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64", "Boolean",
    "String", "Binary",
];

/// The states of FMI 3.0 an FMU without Clocks, Event Mode in Co-Simulation or
/// Configuration Mode can be in.
#[derive(Clone, Copy, Debug, PartialEq)]
enum State {
    Instantiated,
    InitializationMode,
    EventMode,
    ContinuousTimeMode,
    StepMode,
    Terminated,
}

/// The functions the standard lists as allowed in `state` (section and super states in
/// the comments), before the interface and the FMU's declared features are looked at.
fn listed(state: State) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    let mut add = |list: &[&str]| names.extend(list.iter().map(|n| format!("fmi3{n}")));
    // super state FMU State Settable (2.3.1): every state here
    add(&[
        "SetDebugLogging",
        "Reset",
        "FreeInstance",
        "GetFMUState",
        "SetFMUState",
        "FreeFMUState",
        "SerializedFMUStateSize",
        "SerializeFMUState",
        "DeserializeFMUState",
    ]);
    // the erratum: in every state of the super state
    add(&["GetNumberOfVariableDependencies", "GetVariableDependencies"]);
    let getters: Vec<String> = VARIABLE_TYPES.iter().map(|t| format!("Get{t}")).collect();
    let setters: Vec<String> = VARIABLE_TYPES.iter().map(|t| format!("Set{t}")).collect();
    let getters: Vec<&str> = getters.iter().map(String::as_str).collect();
    let setters: Vec<&str> = setters.iter().map(String::as_str).collect();
    // super state Initialized (2.3.6): Event Mode, Continuous-Time Mode, Step Mode
    let initialized = ["GetNominalsOfContinuousStates", "Terminate"];
    match state {
        State::Instantiated => {
            // 2.3.2 (the getters: the erratum, and the state's table of equations)
            add(&setters);
            add(&getters);
            add(&[
                "EnterConfigurationMode",
                "GetNumberOfContinuousStates",
                "GetNumberOfEventIndicators",
                "EnterInitializationMode",
            ]);
        }
        State::InitializationMode => {
            // 2.3.5
            add(&setters);
            add(&getters);
            add(&[
                "GetContinuousStateDerivatives",
                "GetContinuousStates",
                "GetNominalsOfContinuousStates",
                "GetDirectionalDerivative",
                "GetAdjointDerivative",
                "GetEventIndicators",
                "GetShiftDecimal",
                "GetShiftFraction",
                "GetIntervalDecimal",
                "GetIntervalFraction",
                "SetShiftDecimal",
                "SetShiftFraction",
                "SetIntervalDecimal",
                "SetIntervalFraction",
                "ExitInitializationMode",
            ]);
        }
        State::EventMode => {
            // 2.3.7
            add(&setters);
            add(&getters);
            add(&[
                "SetClock",
                "GetClock",
                "GetIntervalDecimal",
                "GetIntervalFraction",
                "GetDirectionalDerivative",
                "GetAdjointDerivative",
                "GetContinuousStates",
                "GetContinuousStateDerivatives",
                "GetEventIndicators",
                "GetNumberOfContinuousStates",
                "GetNumberOfEventIndicators",
                "EvaluateDiscreteStates",
                "UpdateDiscreteStates",
                "EnterConfigurationMode",
                "EnterContinuousTimeMode",
                "EnterStepMode",
            ]);
            add(&initialized);
        }
        State::ContinuousTimeMode => {
            // 3.2.1; fmi3Set{VariableType} for continuous-time inputs only, and only Float32
            // and Float64 variables can have variability continuous (2.4.7.4)
            add(&["SetTime", "SetFloat32", "SetFloat64"]);
            add(&getters);
            add(&[
                "SetContinuousStates",
                "GetContinuousStates",
                "GetContinuousStateDerivatives",
                "GetEventIndicators",
                "CompletedIntegratorStep",
                "EnterEventMode",
                "GetDirectionalDerivative",
                "GetAdjointDerivative",
            ]);
            add(&initialized);
        }
        State::StepMode => {
            // 4.2.1
            add(&setters);
            add(&getters);
            add(&[
                "GetOutputDerivatives",
                "GetDirectionalDerivative",
                "GetAdjointDerivative",
                "DoStep",
                "EnterEventMode",
                "EnterConfigurationMode",
            ]);
            add(&initialized);
        }
        State::Terminated => {
            // 2.3.10
            add(&getters);
            add(&[
                "GetContinuousStateDerivatives",
                "GetContinuousStates",
                "GetNominalsOfContinuousStates",
                "GetEventIndicators",
                "GetDirectionalDerivative",
                "GetAdjointDerivative",
                "GetOutputDerivatives",
            ]);
        }
    }
    names
}

/// "Not allowed in Co-Simulation" / "can only be called in Model Exchange" and the
/// functions of the Co-Simulation and Scheduled Execution sections.
fn interface_allows(name: &str, interface: Interface) -> bool {
    const MODEL_EXCHANGE_ONLY: [&str; 10] = [
        "fmi3GetContinuousStateDerivatives",
        "fmi3GetContinuousStates",
        "fmi3GetNominalsOfContinuousStates",
        "fmi3GetEventIndicators",
        "fmi3GetNumberOfContinuousStates",
        "fmi3GetNumberOfEventIndicators",
        "fmi3SetTime",
        "fmi3SetContinuousStates",
        "fmi3CompletedIntegratorStep",
        "fmi3EnterContinuousTimeMode",
    ];
    const CO_SIMULATION_ONLY: [&str; 3] = ["fmi3DoStep", "fmi3GetOutputDerivatives", "fmi3EnterStepMode"];
    match interface {
        Interface::CoSimulation => !MODEL_EXCHANGE_ONLY.contains(&name),
        Interface::ModelExchange => !CO_SIMULATION_ONLY.contains(&name),
        // the plant declares no clock, so it offers no Scheduled Execution
        Interface::ScheduledExecution => false,
    }
}

/// Whether the FMU declares what `name` needs, read from the plant's FMI 3.0
/// modelDescription (no Clocks, no structural parameters, no Scheduled Execution, the
/// capability flags).
fn declared(name: &str, interface: Interface) -> bool {
    let md = Plant::declaration().model_description3();
    let clocks = md.model_variables.iter().any(|v| v.value_type == model_description::fmi3::ValueType::Clock);
    let structural =
        md.model_variables.iter().any(|v| v.causality == model_description::fmi3::Causality::StructuralParameter);
    let cs = md.co_simulation.as_ref().expect("the plant offers Co-Simulation");
    let me = md.model_exchange.as_ref().expect("the plant offers Model Exchange");
    let common = match interface {
        Interface::CoSimulation => &cs.common,
        Interface::ModelExchange => &me.common,
        Interface::ScheduledExecution => panic!("the plant offers no Scheduled Execution"),
    };
    let evaluate_discrete_states = match interface {
        Interface::CoSimulation => cs.provides_evaluate_discrete_states,
        Interface::ModelExchange => me.provides_evaluate_discrete_states,
        Interface::ScheduledExecution => false,
    };
    match name {
        "fmi3GetClock"
        | "fmi3SetClock"
        | "fmi3GetIntervalDecimal"
        | "fmi3GetIntervalFraction"
        | "fmi3GetShiftDecimal"
        | "fmi3GetShiftFraction"
        | "fmi3SetIntervalDecimal"
        | "fmi3SetIntervalFraction"
        | "fmi3SetShiftDecimal"
        | "fmi3SetShiftFraction" => clocks,
        "fmi3EnterConfigurationMode" | "fmi3ExitConfigurationMode" => structural,
        "fmi3EvaluateDiscreteStates" => evaluate_discrete_states,
        "fmi3GetOutputDerivatives" => cs.max_output_derivative_order > 0,
        // Co-Simulation: only with eventModeUsed, which hasEventMode = false forbids
        "fmi3EnterEventMode" | "fmi3UpdateDiscreteStates" | "fmi3EnterStepMode"
            if interface == Interface::CoSimulation =>
        {
            cs.has_event_mode
        }
        "fmi3ActivateModelPartition" => md.scheduled_execution.is_some(),
        "fmi3GetFMUState" | "fmi3SetFMUState" | "fmi3FreeFMUState" => common.can_get_and_set_fmu_state,
        "fmi3SerializedFMUStateSize" | "fmi3SerializeFMUState" | "fmi3DeserializeFMUState" => {
            common.can_serialize_fmu_state
        }
        "fmi3GetDirectionalDerivative" => common.provides_directional_derivatives,
        "fmi3GetAdjointDerivative" => common.provides_adjoint_derivatives,
        _ => true,
    }
}

/// The FMI 3.0 state an instance of the layer in `machine` is in, `None` where it cannot
/// be there: an fmi3Error leads to Terminated (2.3.1), which the layer keeps as its Error
/// state; StepFailed is FMI 2.0's; Event Mode and Continuous-Time Mode are Model
/// Exchange's here, Step Mode Co-Simulation's.
fn fmi3_state(machine: Machine, interface: Interface) -> Option<State> {
    let cs = interface == Interface::CoSimulation;
    Some(match machine {
        Machine::Instantiated => State::Instantiated,
        Machine::InitializationMode => State::InitializationMode,
        Machine::StepComplete if cs => State::StepMode,
        Machine::EventMode if !cs => State::EventMode,
        Machine::ContinuousTimeMode if !cs => State::ContinuousTimeMode,
        Machine::Terminated | Machine::Error => State::Terminated,
        _ => return None,
    })
}

#[test]
fn every_cell_of_the_fmi3_state_table_is_the_standards() {
    // the functions without an instance (fmi3GetVersion, fmi3Instantiate*) have no state
    let without_instance = ["fmi3GetVersion", "fmi3InstantiateModelExchange", "fmi3InstantiateCoSimulation"];
    let mut differences = Vec::new();
    let mut cells = 0;
    for interface in [Interface::CoSimulation, Interface::ModelExchange] {
        for machine in Machine::ALL {
            let Some(state) = fmi3_state(machine, interface) else { continue };
            let allowed = listed(state);
            for f in Function::FMI3 {
                let name = f.name();
                if without_instance.contains(&name) || name == "fmi3InstantiateScheduledExecution" {
                    continue;
                }
                let standard =
                    allowed.iter().any(|a| a == name) && interface_allows(name, interface) && declared(name, interface);
                let layer = Instance::<Plant>::call_allowed(Generation::Fmi3, interface, f, machine).is_ok();
                cells += 1;
                if standard != layer {
                    differences.push(format!(
                        "{name} in {state:?} ({interface:?}, layer state {machine:?}): the standard {}, the layer {}",
                        if standard { "allows it" } else { "forbids it" },
                        if layer { "allows it" } else { "refuses it" }
                    ));
                }
            }
        }
    }
    // 71 functions with an instance; CS: 4 layer states (Terminated and Error both
    // Terminated), ME: 5
    assert_eq!(cells, 71 * (4 + 1 + 5 + 1));
    assert!(differences.is_empty(), "{} cells differ:\n{}", differences.len(), differences.join("\n"));
}

/// The names this test spells are the header's: every listed name is an FMI 3.0 function.
#[test]
fn the_listed_names_are_fmi3_functions() {
    let known: Vec<&str> = Function::FMI3.iter().map(|f| f.name()).collect();
    for state in [
        State::Instantiated,
        State::InitializationMode,
        State::EventMode,
        State::ContinuousTimeMode,
        State::StepMode,
        State::Terminated,
    ] {
        for name in listed(state) {
            assert!(known.contains(&name.as_str()), "{name} (listed in {state:?}) is no fmi3 function");
        }
    }
}

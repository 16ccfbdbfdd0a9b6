//! The FMI 2.0 instance states and, in one table, where each of the 44 functions may be
//! called: the standard's state tables for Model Exchange (section 3.2.3) and
//! Co-Simulation (section 4.2.4), read row by row.

use model_description::{Causality, Initial, Variability};

/// The FMI 2.0 instance states a synchronous FMU can be in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Machine {
    Instantiated,
    InitializationMode,
    /// Co-Simulation, between steps.
    StepComplete,
    /// Co-Simulation, after `fmi2DoStep` returned `fmi2Discard`.
    StepFailed,
    /// Model Exchange.
    EventMode,
    /// Model Exchange.
    ContinuousTimeMode,
    Terminated,
    /// After any `fmi2Error`: only reset, free, FMU state restore and diagnostic gets.
    Error,
}

impl Machine {
    pub const ALL: [Machine; 8] = [
        Machine::Instantiated,
        Machine::InitializationMode,
        Machine::StepComplete,
        Machine::StepFailed,
        Machine::EventMode,
        Machine::ContinuousTimeMode,
        Machine::Terminated,
        Machine::Error,
    ];

    pub(crate) fn code(self) -> f64 {
        self as u8 as f64
    }

    pub(crate) fn from_code(c: f64) -> Option<Machine> {
        Machine::ALL.into_iter().find(|m| m.code() == c)
    }

    pub(crate) const fn bit(self) -> u16 {
        1 << self as u16
    }
}

/// Which interface a function belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scope {
    Common,
    ModelExchange,
    CoSimulation,
}

macro_rules! functions {
    ($($name:ident),* $(,)?) => {
        /// The 44 functions of FMI 2.0.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Function { $($name),* }
        impl Function {
            pub const ALL: [Function; 44] = [$(Function::$name),*];
            /// The C name, e.g. `"fmi2GetReal"`.
            pub fn name(self) -> &'static str {
                match self { $(Function::$name => concat!("fmi2", stringify!($name))),* }
            }
        }
    };
}

functions!(
    GetTypesPlatform,
    GetVersion,
    SetDebugLogging,
    Instantiate,
    FreeInstance,
    SetupExperiment,
    EnterInitializationMode,
    ExitInitializationMode,
    Terminate,
    Reset,
    GetReal,
    GetInteger,
    GetBoolean,
    GetString,
    SetReal,
    SetInteger,
    SetBoolean,
    SetString,
    GetFMUstate,
    SetFMUstate,
    FreeFMUstate,
    SerializedFMUstateSize,
    SerializeFMUstate,
    DeSerializeFMUstate,
    GetDirectionalDerivative,
    EnterEventMode,
    NewDiscreteStates,
    EnterContinuousTimeMode,
    CompletedIntegratorStep,
    SetTime,
    SetContinuousStates,
    GetDerivatives,
    GetEventIndicators,
    GetContinuousStates,
    GetNominalsOfContinuousStates,
    SetRealInputDerivatives,
    GetRealOutputDerivatives,
    DoStep,
    CancelStep,
    GetStatus,
    GetRealStatus,
    GetIntegerStatus,
    GetBooleanStatus,
    GetStringStatus,
);

use Machine::*;

const fn mask(states: &[Machine]) -> u16 {
    let mut m = 0;
    let mut i = 0;
    while i < states.len() {
        m |= states[i].bit();
        i += 1;
    }
    m
}

/// Every state an instance can be in.
const ANY: u16 = mask(&Machine::ALL);
/// Values can be read once initialization has started, also after a failed step, after
/// termination and in the error state (for diagnosis).
const READ: u16 =
    mask(&[InitializationMode, EventMode, ContinuousTimeMode, StepComplete, StepFailed, Terminated, Error]);

impl Function {
    /// The interface the function belongs to.
    pub fn scope(self) -> Scope {
        use Function::*;
        match self {
            EnterEventMode
            | NewDiscreteStates
            | EnterContinuousTimeMode
            | CompletedIntegratorStep
            | SetTime
            | SetContinuousStates
            | GetDerivatives
            | GetEventIndicators
            | GetContinuousStates
            | GetNominalsOfContinuousStates => Scope::ModelExchange,
            SetRealInputDerivatives
            | GetRealOutputDerivatives
            | DoStep
            | CancelStep
            | GetStatus
            | GetRealStatus
            | GetIntegerStatus
            | GetBooleanStatus
            | GetStringStatus => Scope::CoSimulation,
            _ => Scope::Common,
        }
    }

    /// The states in which the standard allows the call (for the function's own interface).
    fn allowed_mask(self) -> u16 {
        use Function::*;
        match self {
            // no instance involved
            GetTypesPlatform | GetVersion | Instantiate => ANY,
            SetDebugLogging | FreeInstance | Reset => ANY,
            GetFMUstate
            | SetFMUstate
            | FreeFMUstate
            | SerializedFMUstateSize
            | SerializeFMUstate
            | DeSerializeFMUstate => ANY,
            SetupExperiment | EnterInitializationMode => mask(&[Instantiated]),
            ExitInitializationMode => mask(&[InitializationMode]),
            Terminate => mask(&[EventMode, ContinuousTimeMode, StepComplete, StepFailed]),
            GetReal | GetInteger | GetBoolean | GetString => READ,
            // Reals: continuous-time mode only for continuous inputs (checked per variable)
            SetReal => mask(&[Instantiated, InitializationMode, EventMode, ContinuousTimeMode, StepComplete]),
            SetInteger | SetBoolean | SetString => mask(&[Instantiated, InitializationMode, EventMode, StepComplete]),
            GetDirectionalDerivative => READ,
            // Model Exchange
            EnterEventMode => mask(&[EventMode, ContinuousTimeMode]),
            NewDiscreteStates | EnterContinuousTimeMode => mask(&[EventMode]),
            CompletedIntegratorStep | SetContinuousStates => mask(&[ContinuousTimeMode]),
            SetTime => mask(&[EventMode, ContinuousTimeMode]),
            GetEventIndicators | GetContinuousStates => {
                mask(&[InitializationMode, EventMode, ContinuousTimeMode, Terminated, Error])
            }
            GetDerivatives => mask(&[EventMode, ContinuousTimeMode, Terminated, Error]),
            GetNominalsOfContinuousStates => mask(&[Instantiated, EventMode, ContinuousTimeMode, Terminated, Error]),
            // Co-Simulation
            SetRealInputDerivatives => mask(&[Instantiated, InitializationMode, StepComplete]),
            GetRealOutputDerivatives => mask(&[StepComplete, StepFailed, Terminated, Error]),
            DoStep => mask(&[StepComplete]),
            // only in stepInProgress, which a synchronous FMU never enters
            CancelStep => 0,
            GetStatus | GetRealStatus | GetIntegerStatus | GetBooleanStatus | GetStringStatus => {
                mask(&[StepComplete, StepFailed, Terminated])
            }
        }
    }

    /// Whether the standard allows the call in `machine`.
    pub fn allowed_in(self, machine: Machine) -> bool {
        self.allowed_mask() & machine.bit() != 0
    }
}

/// Whether variable `v` may be set in instance state `machine` (FMI 2.0 section 2.2.7 and
/// the state tables); the reason when not. [`Declaration`] keeps the answer for every state
/// as a bit mask, the fast path of `fmi2Set*`.
pub(crate) fn settable_in(
    name: &str,
    causality: Causality,
    variability: Variability,
    initial: Option<Initial>,
    machine: Machine,
) -> Result<(), String> {
    let why = |reason: &str| Err(format!("{name} cannot be set {reason}"));
    if variability == Variability::Constant {
        return why("(a constant)");
    }
    if matches!(causality, Causality::Independent | Causality::CalculatedParameter) {
        return why("(calculated)");
    }
    let has_start = matches!(initial, Some(Initial::Exact) | Some(Initial::Approx));
    match machine {
        Machine::Instantiated | Machine::InitializationMode => {
            if has_start || causality == Causality::Input {
                Ok(())
            } else {
                why("(no start value: it is calculated)")
            }
        }
        Machine::StepComplete | Machine::EventMode => match (causality, variability) {
            (Causality::Input, _) | (Causality::Parameter, Variability::Tunable) => Ok(()),
            (Causality::Parameter, _) => why("after initialization (a fixed parameter; only tunable ones can)"),
            _ => why(&format!("in {machine:?} (only inputs and tunable parameters)")),
        },
        Machine::ContinuousTimeMode => {
            if causality == Causality::Input && variability == Variability::Continuous {
                Ok(())
            } else {
                why("in ContinuousTimeMode (only continuous inputs)")
            }
        }
        _ => why(&format!("in {machine:?}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_the_c_symbols_and_unique() {
        let names: std::collections::HashSet<_> = Function::ALL.iter().map(|f| f.name()).collect();
        assert_eq!(names.len(), 44);
        assert!(names.contains("fmi2GetNominalsOfContinuousStates"));
        assert!(names.contains("fmi2DeSerializeFMUstate"));
    }

    #[test]
    fn rows_the_hardening_found_wrong() {
        use Function::*;
        // too strict before
        assert!(GetNominalsOfContinuousStates.allowed_in(Instantiated));
        assert!(GetDirectionalDerivative.allowed_in(Error));
        // too permissive before
        for f in [SetTime, GetDerivatives, GetNominalsOfContinuousStates] {
            assert!(!f.allowed_in(InitializationMode), "{f:?}");
        }
        assert!(!SetContinuousStates.allowed_in(EventMode));
        for f in [GetStatus, GetRealStatus, GetIntegerStatus, GetBooleanStatus, GetStringStatus] {
            assert!(!f.allowed_in(Instantiated), "{f:?}");
            assert_eq!(f.scope(), Scope::CoSimulation);
        }
        // Discard leaves stepFailed: reads, status, terminate, restore and reset remain
        for f in [GetReal, GetRealStatus, Terminate, SetFMUstate, Reset, FreeInstance] {
            assert!(f.allowed_in(StepFailed), "{f:?}");
        }
        for f in [DoStep, SetReal, SetInteger, ExitInitializationMode] {
            assert!(!f.allowed_in(StepFailed), "{f:?}");
        }
    }
}

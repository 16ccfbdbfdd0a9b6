//! The instance states and, in one table, where each of the 44 FMI 2.0 and the 75 FMI 3.0
//! functions may be called: the state tables of FMI 2.0 (Model Exchange section 3.2.3,
//! Co-Simulation section 4.2.4) and FMI 3.0 (section 3.2, Model Exchange 3.3,
//! Co-Simulation 4.3), read row by row.
//!
//! One machine serves both generations. FMI 3.0's states are FMI 2.0's where they
//! coincide: Instantiated, Initialization Mode, Event Mode and Continuous-Time Mode (Model
//! Exchange) and Terminated; FMI 3.0's Step Mode is [`Machine::StepComplete`]. FMI 2.0's
//! stepFailed ([`Machine::StepFailed`]), after a step that returned Discard (the importer may
//! then read, terminate, restore an FMU state or reset, but not step), does not exist in FMI
//! 3.0: there a Discard of `fmi3DoStep` leaves the FMU in Step Mode. FMI 2.0's error state
//! ([`Machine::Error`]) is, for FMI 3.0, the Terminated that an `fmi3Error` leads to: the two
//! have the same row. An FMU of ours declares no Configuration Mode; Event Mode in
//! Co-Simulation only with a declared clock ([`crate::ClockDecl`]), in which case
//! [`Machine::EventMode`] is Co-Simulation's Event Mode too. An FMI 3.0 function that
//! does the same as an FMI 2.0 one has that one's row ([`Function::counterpart`]) unless
//! FMI 3.0 lists it in other states ([`Function::fmi3_row`]); tests/tests/fmi3_state_table.rs
//! compares every FMI 3.0 cell with the standard's lists.

use model_description::{Causality, Initial, Variability};

/// The instance states a synchronous FMU can be in (FMI 2.0's names; FMI 3.0's in the
/// module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Machine {
    Instantiated,
    InitializationMode,
    /// Co-Simulation, between steps.
    StepComplete,
    /// Co-Simulation, after `fmi2DoStep` returned `fmi2Discard`.
    StepFailed,
    /// Model Exchange; Co-Simulation with a declared clock.
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
    /// FMI 3.0 Scheduled Execution (not offered by the layer).
    ScheduledExecution,
}

/// The generation of the FMI C API an instance was created by (`fmi2Instantiate` or an
/// `fmi3Instantiate*`): only that generation's functions may be called on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Generation {
    Fmi2,
    Fmi3,
}

/// `Function` from the rows of [`crate::abi::table`], in their order.
macro_rules! function_enum {
    ({}
     fmi2 { $($f2:ident : $_t2:ident = $n2:ident => $_m2:ident :: $_l2:ident $(::<$_v2:ident>)?
                $([$($_a2:ident),*])? ( $($_p2:ident : $_pt2:ty),* ) $(-> $_r2:ty)? ;)* }
     fmi3 { $($f3:ident : $_t3:ident = $n3:ident => $_m3:ident :: $_l3:ident $(::<$_v3:ident>)?
                $([$($_a3:ident),*])? ( $($_p3:ident : $_pt3:ty),* ) $(-> $_r3:ty)? ;)* }) => {
        /// The 44 functions of FMI 2.0 and the 75 of FMI 3.0, one enum: one table of where
        /// each may be called ([`Function::allowed_in`]). An FMI 3.0 function's variant is
        /// its C name with `Fmi3` in front (`Function::Fmi3DoStep` is `fmi3DoStep`).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Function { $($n2,)* $($n3,)* }
        impl Function {
            pub const ALL: [Function; 119] = [$(Function::$n2,)* $(Function::$n3,)*];
            /// The 44 FMI 2.0 functions.
            pub const FMI2: [Function; 44] = [$(Function::$n2),*];
            /// The 75 FMI 3.0 functions.
            pub const FMI3: [Function; 75] = [$(Function::$n3),*];
            /// The C name, e.g. `"fmi2GetReal"`, `"fmi3GetFloat64"`.
            pub fn name(self) -> &'static str {
                match self {
                    $(Function::$n2 => stringify!($f2),)*
                    $(Function::$n3 => stringify!($f3),)*
                }
            }
            /// The FMI generation (2 or 3) the function belongs to.
            pub fn generation(self) -> Generation {
                match self {
                    $(Function::$n2 => Generation::Fmi2,)*
                    $(Function::$n3 => Generation::Fmi3,)*
                }
            }
        }
    };
}

crate::__fmi_function_table!([function_enum] {});

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
    /// The FMI 2.0 function an FMI 3.0 one does the same as (its row of the table, its
    /// scope); `None` for an FMI 2.0 function and for an FMI 3.0 one without counterpart.
    pub fn counterpart(self) -> Option<Function> {
        use Function::*;
        Some(match self {
            Fmi3GetVersion => GetVersion,
            Fmi3SetDebugLogging => SetDebugLogging,
            Fmi3InstantiateModelExchange | Fmi3InstantiateCoSimulation => Instantiate,
            Fmi3FreeInstance => FreeInstance,
            Fmi3EnterInitializationMode => EnterInitializationMode,
            Fmi3ExitInitializationMode => ExitInitializationMode,
            Fmi3Terminate => Terminate,
            Fmi3Reset => Reset,
            Fmi3GetFloat64 | Fmi3GetFloat32 => GetReal,
            Fmi3GetInt8 | Fmi3GetUInt8 | Fmi3GetInt16 | Fmi3GetUInt16 | Fmi3GetInt32 | Fmi3GetUInt32 | Fmi3GetInt64
            | Fmi3GetUInt64 => GetInteger,
            Fmi3GetBoolean | Fmi3GetClock => GetBoolean,
            Fmi3GetString | Fmi3GetBinary => GetString,
            Fmi3SetFloat64 | Fmi3SetFloat32 => SetReal,
            Fmi3SetInt8 | Fmi3SetUInt8 | Fmi3SetInt16 | Fmi3SetUInt16 | Fmi3SetInt32 | Fmi3SetUInt32 | Fmi3SetInt64
            | Fmi3SetUInt64 => SetInteger,
            Fmi3SetBoolean | Fmi3SetClock => SetBoolean,
            Fmi3SetString | Fmi3SetBinary => SetString,
            Fmi3GetFMUState => GetFMUstate,
            Fmi3SetFMUState => SetFMUstate,
            Fmi3FreeFMUState => FreeFMUstate,
            Fmi3SerializedFMUStateSize => SerializedFMUstateSize,
            Fmi3SerializeFMUState => SerializeFMUstate,
            Fmi3DeserializeFMUState => DeSerializeFMUstate,
            // J^T w is computed from J's columns: where J is, J^T is
            Fmi3GetDirectionalDerivative | Fmi3GetAdjointDerivative => GetDirectionalDerivative,
            Fmi3EnterEventMode => EnterEventMode,
            Fmi3UpdateDiscreteStates => NewDiscreteStates,
            Fmi3EnterContinuousTimeMode => EnterContinuousTimeMode,
            Fmi3CompletedIntegratorStep => CompletedIntegratorStep,
            Fmi3SetTime => SetTime,
            Fmi3SetContinuousStates => SetContinuousStates,
            Fmi3GetContinuousStateDerivatives => GetDerivatives,
            Fmi3GetEventIndicators => GetEventIndicators,
            Fmi3GetContinuousStates => GetContinuousStates,
            Fmi3GetNominalsOfContinuousStates => GetNominalsOfContinuousStates,
            Fmi3DoStep => DoStep,
            _ => return None,
        })
    }

    /// The FMI 3.0 features the layer's FMUs do not declare, with what is missing: the
    /// call is refused (`fmi3Error`, logged) in every state, except the clock functions,
    /// `fmi3EnterStepMode` (Co-Simulation) and `fmi3ActivateModelPartition` (Scheduled
    /// Execution) of a model that declares a clock ([`crate::ClockDecl`]).
    pub fn undeclared_feature(self) -> Option<&'static str> {
        use Function::*;
        Some(match self {
            Fmi3InstantiateScheduledExecution | Fmi3ActivateModelPartition => "Scheduled Execution is not offered",
            Fmi3EnterConfigurationMode | Fmi3ExitConfigurationMode => {
                "no structural parameters, so no Configuration Mode"
            }
            f if f.is_clock_function() => "no clocks are declared",
            Fmi3EvaluateDiscreteStates => "providesEvaluateDiscreteStates is false",
            Fmi3GetOutputDerivatives => "maxOutputDerivativeOrder is 0",
            Fmi3EnterStepMode => "hasEventMode is false: a Co-Simulation instance never leaves Step Mode",
            _ => return None,
        })
    }

    /// The functions of FMI 3.0 clocks: offered when the model declares a clock
    /// ([`crate::ClockDecl`]), else refused as [`Function::undeclared_feature`]s.
    pub fn is_clock_function(self) -> bool {
        matches!(self, Function::Fmi3GetClock | Function::Fmi3SetClock) || self.is_clock_timing_function()
    }

    /// The functions of FMI 3.0 clocks' intervals and shifts (the `fmi3Get`/`fmi3Set`
    /// `Interval`/`Shift` `Decimal`/`Fraction` eight): the [`Function::is_clock_function`]s
    /// but fmi3GetClock and fmi3SetClock.
    pub fn is_clock_timing_function(self) -> bool {
        use Function::*;
        matches!(
            self,
            Fmi3GetIntervalDecimal
                | Fmi3GetIntervalFraction
                | Fmi3GetShiftDecimal
                | Fmi3GetShiftFraction
                | Fmi3SetIntervalDecimal
                | Fmi3SetIntervalFraction
                | Fmi3SetShiftDecimal
                | Fmi3SetShiftFraction
        )
    }

    /// The interface the function belongs to.
    pub fn scope(self) -> Scope {
        use Function::*;
        if let Some(f) = self.counterpart() {
            // fmi3EnterEventMode and fmi3UpdateDiscreteStates are common to all interfaces
            // in FMI 3.0, but Co-Simulation without Event Mode (ours) has no use for them
            return f.scope();
        }
        match self {
            Fmi3GetNumberOfEventIndicators | Fmi3GetNumberOfContinuousStates => return Scope::ModelExchange,
            Fmi3EnterStepMode | Fmi3GetOutputDerivatives => return Scope::CoSimulation,
            Fmi3ActivateModelPartition => return Scope::ScheduledExecution,
            _ => {}
        }
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
        if let Some(m) = self.fmi3_row() {
            return m;
        }
        if let Some(f) = self.counterpart() {
            return f.allowed_mask();
        }
        // FMI 3.0 without an FMI 2.0 counterpart: the structure queries (the numbers of
        // states and event indicators, the variable dependencies) in every state;
        // undeclared features are refused by the instance before this table is asked
        if self.generation() == Generation::Fmi3 {
            return ANY;
        }
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
            // the FMI 3.0 functions, answered above
            _ => ANY,
        }
    }

    /// The FMI 3.0 rows that differ from their FMI 2.0 counterpart's, from the lists of
    /// allowed calls per state in FMI 3.0.2 (sections 2.3, 3.2 and 4.2, with the erratum that
    /// lists the getters in Instantiated). An fmi3Error leads to Terminated there, so the
    /// layer's Error state has Terminated's row; Step Discarded does not exist (a Discard
    /// of fmi3DoStep leaves the FMU in Step Mode), so StepFailed never occurs.
    fn fmi3_row(self) -> Option<u16> {
        use Function::*;
        Some(match self {
            // the start values (or those set) in Instantiated, as in every later state
            Fmi3GetFloat64 | Fmi3GetFloat32 | Fmi3GetInt8 | Fmi3GetUInt8 | Fmi3GetInt16 | Fmi3GetUInt16
            | Fmi3GetInt32 | Fmi3GetUInt32 | Fmi3GetInt64 | Fmi3GetUInt64 | Fmi3GetBoolean | Fmi3GetString
            | Fmi3GetBinary => READ | mask(&[Instantiated]),
            // Clocks are active in Event Mode only
            Fmi3GetClock | Fmi3SetClock => mask(&[EventMode]),
            // the intervals and shifts of time-based clocks: Initialization Mode and Event
            // Mode (Scheduled Execution's Clock Activation Mode is not offered)
            f if f.is_clock_function() => mask(&[InitializationMode, EventMode]),
            // Co-Simulation with Event Mode (an FMU with clocks): Event Mode back to Step Mode
            Fmi3EnterStepMode => mask(&[EventMode]),
            // Scheduled Execution's Clock Activation Mode (the layer's StepComplete)
            Fmi3ActivateModelPartition => mask(&[StepComplete]),
            // Model Exchange: from Continuous-Time Mode only (FMI 2.0 also in Event Mode);
            // Co-Simulation with Event Mode: from Step Mode
            Fmi3EnterEventMode => mask(&[ContinuousTimeMode, StepComplete]),
            Fmi3SetTime => mask(&[ContinuousTimeMode]),
            // also in Initialization Mode (not in FMI 2.0)
            Fmi3GetContinuousStateDerivatives => {
                mask(&[InitializationMode, EventMode, ContinuousTimeMode, Terminated, Error])
            }
            // Initialization Mode, the Initialized super state and Terminated; not in
            // Instantiated (FMI 2.0 allows it there)
            Fmi3GetNominalsOfContinuousStates => {
                mask(&[InitializationMode, EventMode, ContinuousTimeMode, Terminated, Error])
            }
            // listed in Instantiated and Event Mode only
            Fmi3GetNumberOfContinuousStates | Fmi3GetNumberOfEventIndicators => mask(&[Instantiated, EventMode]),
            _ => return None,
        })
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

    /// The names are the C symbols of both headers, as `fmi-sys` lists them, each once.
    #[test]
    fn names_are_the_c_symbols_and_unique() {
        let names: std::collections::HashSet<_> = Function::ALL.iter().map(|f| f.name()).collect();
        assert_eq!(names.len(), 44 + 75);
        let fmi2: std::collections::BTreeSet<_> = Function::FMI2.iter().map(|f| f.name()).collect();
        let fmi3: std::collections::BTreeSet<_> = Function::FMI3.iter().map(|f| f.name()).collect();
        assert_eq!(fmi2, fmi_sys::fmi2::SYMBOLS.iter().map(|(s, _)| *s).collect());
        assert_eq!(fmi3, fmi_sys::fmi3::SYMBOLS.iter().map(|(s, _)| *s).collect());
        assert!(Function::FMI2.iter().all(|f| f.generation() == Generation::Fmi2));
        assert!(Function::FMI3.iter().all(|f| f.generation() == Generation::Fmi3));
    }

    /// An FMI 3.0 function with an FMI 2.0 counterpart has its row unless FMI 3.0 lists it
    /// elsewhere; the scopes are those of `fmi-sys` except the Event Mode calls, which only
    /// our Model Exchange has.
    #[test]
    fn fmi3_rows_are_their_fmi2_counterparts() {
        use Function::*;
        for f in Function::FMI3 {
            if let (Some(g), None) = (f.counterpart(), f.fmi3_row()) {
                assert_eq!(g.generation(), Generation::Fmi2, "{f:?}");
                for m in Machine::ALL {
                    assert_eq!(f.allowed_in(m), g.allowed_in(m), "{f:?} in {m:?}");
                }
            }
        }
        // the rows FMI 3.0 changes
        assert!(Fmi3GetFloat64.allowed_in(Instantiated) && !GetReal.allowed_in(Instantiated));
        assert!(!Fmi3SetTime.allowed_in(EventMode) && SetTime.allowed_in(EventMode));
        assert!(!Fmi3EnterEventMode.allowed_in(EventMode) && EnterEventMode.allowed_in(EventMode));
        assert!(Fmi3GetContinuousStateDerivatives.allowed_in(InitializationMode));
        assert!(!Fmi3GetNominalsOfContinuousStates.allowed_in(Instantiated));
        assert!(Fmi3DoStep.allowed_in(StepComplete) && !Fmi3DoStep.allowed_in(StepFailed));
        assert!(!Fmi3ExitInitializationMode.allowed_in(Instantiated));
        assert!(
            Fmi3EnterInitializationMode.allowed_in(Instantiated) && !Fmi3EnterInitializationMode.allowed_in(EventMode)
        );
        assert_eq!(Fmi3UpdateDiscreteStates.scope(), Scope::ModelExchange);
        assert_eq!(Fmi3GetNumberOfContinuousStates.scope(), Scope::ModelExchange);
        assert_eq!(Fmi3EnterStepMode.scope(), Scope::CoSimulation);
        assert_eq!(Fmi3GetFloat64.scope(), Scope::Common);
        for (symbol, part) in fmi_sys::fmi3::SYMBOLS {
            let f = *Function::FMI3.iter().find(|f| f.name() == symbol).unwrap();
            let expected = match part {
                fmi_sys::fmi3::Fmi3Part::Common => Scope::Common,
                fmi_sys::fmi3::Fmi3Part::ModelExchange => Scope::ModelExchange,
                fmi_sys::fmi3::Fmi3Part::CoSimulation => Scope::CoSimulation,
                fmi_sys::fmi3::Fmi3Part::ScheduledExecution => Scope::ScheduledExecution,
            };
            let event_mode = matches!(f, Fmi3EnterEventMode | Fmi3UpdateDiscreteStates);
            assert!(f.scope() == expected || event_mode, "{symbol}");
        }
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

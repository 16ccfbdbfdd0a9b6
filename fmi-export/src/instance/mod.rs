//! One FMU instance in safe Rust, the same for both generations of the C API: the state
//! machine (one table, [`crate::states`]), variable access checks (one variable table, the
//! [`Declaration`], addressed by FMI 2.0 value references per base type or by FMI 3.0
//! value references), time events, FMU state handling, directional and adjoint
//! derivatives. The C ABIs in [`crate::abi`] only translate pointers to slices.
//!
//! Here: the instance, its construction, the gate every call passes and the calls of
//! initialization; by concern in the submodules: `values` (get and set, both
//! generations' value references), `events` (time events, sampling and the
//! Co-Simulation step), `model_exchange` (the Model Exchange calls), `derivatives`
//! (partial derivatives and variable dependencies), `fmu_state` (save, restore,
//! serialize), `call_memo` (the lookups of the arrays a master sends at every step),
//! `clocks` (FMI 3.0 clocks).

mod call_memo;
mod clocks;
mod derivatives;
mod events;
mod fmu_state;
mod model_exchange;
mod values;

use crate::decl::{Declaration, Start};
use crate::model::{InstantiateContext, Interface, Model, ModelError};
use crate::sampled::{instant_tolerance, SampleClock};
pub use crate::states::{Function, Generation, Machine, Scope};
use call_memo::CallMemos;
pub use clocks::IntervalQualifier;

/// Result of the fallible instance operations: the message is logged by the ABI layer.
pub type OpResult<T = ()> = Result<T, ModelError>;

/// Most event iterations at one time instant before the layer gives up (a model that
/// keeps asking for another iteration, or keeps scheduling events at the same time).
pub const MAX_EVENT_ITERATIONS: usize = 1000;

/// The part of an instance a saved FMU state holds (never the callbacks).
#[derive(Clone)]
pub struct Core<M> {
    pub machine: Machine,
    pub time: f64,
    pub stop_time: Option<f64>,
    /// The next time event; in both interfaces the start time right after initialization
    /// (the initial event).
    pub next_event: Option<f64>,
    /// Model Exchange: the model asked for another event iteration.
    pub iteration_pending: bool,
    /// The model asked to end the simulation (`fmi2GetBooleanStatus(fmi2Terminated)`).
    pub terminate_requested: bool,
    pub model: M,
    /// A sampled model's clock, from the end of initialization on.
    pub clock: Option<SampleClock>,
    /// A sampled model before its sample 0: reads of its discrete outputs run sample 0
    /// on a copy of the model.
    pub presample: bool,
    /// FMI 3.0 with a declared clock: the importer activated it (`fmi3SetClock`) at this
    /// instant and `fmi3UpdateDiscreteStates` has not ended the activation yet.
    pub clock_active: bool,
    /// Co-Simulation: the instance before the events at the current time were run
    /// (lazily, at the first read or step). Setting an input afterwards restores it, so
    /// the events see the inputs of their own time instant. Held inline (not boxed): a
    /// sampled model takes this copy at every communication point.
    pre_event: Option<PreEvent<M>>,
}

/// What the events at one instant change, kept to undo them ([`Core`]'s `pre_event`).
#[derive(Clone)]
struct PreEvent<M> {
    model: M,
    next_event: Option<f64>,
    clock: Option<SampleClock>,
    presample: bool,
    terminate_requested: bool,
}

impl<M: Model> Core<M> {
    /// What the events at the current instant may change, as it is before them.
    fn pre_event(&self) -> PreEvent<M> {
        PreEvent {
            model: self.model.clone(),
            next_event: self.next_event,
            clock: self.clock,
            presample: self.presample,
            terminate_requested: self.terminate_requested,
        }
    }

    fn new(model: M) -> Self {
        let presample = model.sample_period().is_some();
        Core {
            machine: Machine::Instantiated,
            time: 0.0,
            stop_time: None,
            next_event: None,
            iteration_pending: false,
            terminate_requested: false,
            model,
            clock: None,
            presample,
            clock_active: false,
            pre_event: None,
        }
    }
}

/// A saved FMU state (`fmi2FMUstate`).
pub type SavedState<M> = Core<M>;

/// One instance of model `M`.
pub struct Instance<M: Model> {
    pub context: InstantiateContext,
    /// The C API the instance was created by: only its functions pass the gate.
    pub generation: Generation,
    pub core: Core<M>,
    /// An FMI 3.0 instance of a model with a clock whose importer drives it: the samples run
    /// at the importer's activations of the clock (`fmi3SetClock`), not at time events of the
    /// layer's own. False for Co-Simulation instantiated with `eventModeUsed = false`
    /// ([`Instance::sample_without_event_mode`]): that instance samples by time.
    pub clocked: bool,
    /// A clocked Model Exchange instance whose importer reached `fmi3UpdateDiscreteStates`
    /// at a sample time without activating the clock: it samples by its time events since
    /// ([`Instance::sample_by_time_events`]), and `fmi3SetClock` is refused.
    pub undriven_clock: bool,
    /// Per [`Function`], the instance states in which [`Instance::check_call`] lets it
    /// through (0 for another interface's function or a capability the model did not
    /// declare): the gate of every call as one table lookup; the reasons come from the
    /// full checks, run only when the table says no.
    allowed: [u16; Function::ALL.len()],
    get_memo: CallMemos<M::Binding>,
    set_memo: CallMemos<M::Binding>,
}

fn decl<M: Model>() -> &'static Declaration<M::Binding> {
    M::declaration()
}

fn err<T>(message: impl Into<String>) -> OpResult<T> {
    Err(ModelError::Error(message.into()))
}

/// Time tolerance for "this event is now" ([`instant_tolerance`]).
fn time_eps(t: f64) -> f64 {
    instant_tolerance(t)
}

impl<M: Model> Instance<M> {
    /// A new instance with every declared start value applied.
    pub fn new(context: InstantiateContext) -> OpResult<Self> {
        Self::new_for(context, Generation::Fmi2)
    }

    /// A new instance for the C API of `generation`.
    pub fn new_for(context: InstantiateContext, generation: Generation) -> OpResult<Self> {
        let model = Self::fresh_model(&context)?;
        let clocked = generation == Generation::Fmi3 && decl::<M>().clock().is_some();
        let allowed = Self::allowed_table(generation, context.interface, clocked);
        Ok(Instance {
            allowed,
            clocked,
            undriven_clock: false,
            generation,
            get_memo: CallMemos::new(),
            set_memo: CallMemos::new(),
            context,
            core: Core::new(model),
        })
    }

    pub fn machine(&self) -> Machine {
        self.core.machine
    }

    pub fn time(&self) -> f64 {
        self.core.time
    }

    pub fn model(&mut self) -> &mut M {
        &mut self.core.model
    }

    pub(super) fn fresh_model(context: &InstantiateContext) -> OpResult<M> {
        let mut model = M::instantiate(context)?;
        for v in &decl::<M>().spec.variables {
            let r = match v.start {
                Start::None => Ok(()),
                Start::Real(x) => model.set_real(v.binding, x),
                Start::Integer(x) => model.set_integer(v.binding, x),
                Start::Boolean(x) => model.set_boolean(v.binding, x),
            };
            r.map_err(|e| format!("start value of {} refused: {e}", v.name))?;
        }
        Ok(model)
    }

    /// The one gate every call passes: the function belongs to this instance's interface,
    /// the model opted in to it, and the standard allows it in the current state.
    #[inline]
    pub fn check_call(&self, function: Function) -> OpResult {
        if self.allowed[function as usize] & self.core.machine.bit() != 0 {
            Ok(())
        } else {
            self.refuse_call(function)
        }
    }

    /// Per function, the states in which it passes [`Instance::check_call`] for `interface`
    /// (`clock_driven`: the importer drives the declared clock in Event Mode).
    fn allowed_table(generation: Generation, interface: Interface, clock_driven: bool) -> [u16; Function::ALL.len()] {
        Function::ALL.map(|function| {
            Machine::ALL
                .into_iter()
                .filter(|&m| Self::call_allowed_driven(generation, interface, clock_driven, function, m).is_ok())
                .fold(0, |mask, m| mask | m.bit())
        })
    }

    /// Why `function` is refused now (the table of [`Instance::check_call`] said so).
    #[cold]
    #[inline(never)]
    fn refuse_call(&self, function: Function) -> OpResult {
        Self::call_allowed_driven(
            self.generation,
            self.context.interface,
            self.clocked || decl::<M>().clock().is_none(),
            function,
            self.core.machine,
        )?;
        err(format!(
            "{} refused in state {:?} (internal: the call table and the rules disagree)",
            function.name(),
            self.core.machine
        ))
    }

    /// The full rules of [`Instance::check_call`], with the reason: the function's
    /// generation, interface and declared features, the model's capabilities and the state
    /// table of [`crate::states`].
    pub fn call_allowed(
        generation: Generation,
        interface: Interface,
        function: Function,
        machine: Machine,
    ) -> OpResult {
        Self::call_allowed_driven(generation, interface, true, function, machine)
    }

    /// [`Instance::call_allowed`] for an instance whose importer drives the declared clock
    /// (`clock_driven`) or not (Co-Simulation with `eventModeUsed = false`: no Event Mode).
    fn call_allowed_driven(
        generation: Generation,
        interface: Interface,
        clock_driven: bool,
        function: Function,
        machine: Machine,
    ) -> OpResult {
        if function.generation() != generation {
            return err(match generation {
                Generation::Fmi2 => "not available: this instance was created by fmi2Instantiate (FMI 2.0)",
                Generation::Fmi3 => "not available: this instance was created by an fmi3Instantiate function (FMI 3.0)",
            });
        }
        // a model with a clock offers the clock functions and, in Co-Simulation, Event Mode
        // unless the importer instantiated it with eventModeUsed = false (see abi::fmi3)
        let clocked = decl::<M>().clock().is_some();
        let event_mode_cs = clocked && interface == Interface::CoSimulation;
        if event_mode_cs
            && !clock_driven
            && matches!(
                function,
                Function::Fmi3EnterEventMode | Function::Fmi3UpdateDiscreteStates | Function::Fmi3EnterStepMode
            )
        {
            return err("not available: the instance was created with eventModeUsed = false (no Event Mode), so the \
                        FMU samples by time itself");
        }
        let scheduled = interface == Interface::ScheduledExecution;
        let declared_by_clock = (clocked && function.is_clock_function())
            || (event_mode_cs && function == Function::Fmi3EnterStepMode)
            || (scheduled && function == Function::Fmi3ActivateModelPartition);
        if let Some(missing) = function.undeclared_feature().filter(|_| !declared_by_clock) {
            return err(format!("not supported: {missing}"));
        }
        if scheduled {
            Self::scheduled_call_allowed(function, machine)?;
            return Self::capability_declared(function);
        }
        let cs_event_mode_call = interface == Interface::CoSimulation
            && matches!(function, Function::Fmi3EnterEventMode | Function::Fmi3UpdateDiscreteStates);
        if cs_event_mode_call && !event_mode_cs {
            return err("not available: this Co-Simulation FMU declares no Event Mode (hasEventMode is false)");
        }
        match (function.scope(), interface) {
            (Scope::ModelExchange, Interface::CoSimulation) if cs_event_mode_call => {}
            (Scope::ModelExchange, Interface::CoSimulation)
            | (Scope::CoSimulation, Interface::ModelExchange)
            | (Scope::ScheduledExecution, _) => {
                return err(format!("not available: this instance was created for {interface:?}"));
            }
            _ => {}
        }
        Self::capability_declared(function)?;
        if !function.allowed_in(machine) {
            return err(format!("not allowed in state {machine:?}"));
        }
        Ok(())
    }

    /// The model declared the capability `function` belongs to (FMU state, its
    /// serialization, directional derivatives).
    fn capability_declared(function: Function) -> OpResult {
        let caps = decl::<M>().spec.capabilities;
        let supported = match function.counterpart().unwrap_or(function) {
            Function::GetFMUstate | Function::SetFMUstate | Function::FreeFMUstate => caps.fmu_state,
            Function::SerializedFMUstateSize | Function::SerializeFMUstate | Function::DeSerializeFMUstate => {
                caps.serialize_fmu_state
            }
            Function::GetDirectionalDerivative => caps.directional_derivatives,
            _ => true,
        };
        if !supported {
            return err(format!(
                "not supported: {} did not declare this capability",
                decl::<M>().spec.model_identifier
            ));
        }
        Ok(())
    }

    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start_time: f64, stop_time: Option<f64>) -> OpResult {
        if !start_time.is_finite() {
            return err(format!("startTime {start_time} is not finite"));
        }
        if let Some(stop) = stop_time {
            if !stop.is_finite() || !(stop >= start_time) {
                return err(format!("stopTime {stop} must be finite and not before startTime {start_time}"));
            }
        }
        if let Some(tol) = tolerance {
            if !(tol > 0.0) || !tol.is_finite() {
                return err(format!("tolerance {tol} must be finite and > 0"));
            }
        }
        // an f64 time must resolve an instant there: at |t| = f64::MAX the next double is
        // infinity and every later time would pass as "now"
        for (what, t) in [("startTime", Some(start_time)), ("stopTime", stop_time)] {
            if let Some(t) = t.filter(|t| !instant_tolerance(*t).is_finite()) {
                return err(format!("{what} {t} s is too large: an f64 cannot resolve a later time there"));
            }
        }
        // a stop time past a sampled model's last sample is refused when initialization
        // ends: the parameter that sets the last sample may still be set before that
        self.core.time = start_time;
        self.core.stop_time = stop_time;
        self.core.model.set_time(start_time);
        Ok(())
    }

    /// A sampled model with a last sample: `stop` must not be past it.
    fn check_stop_within_samples(&self, start: f64, stop: f64) -> OpResult {
        let model = &self.core.model;
        let (Some(period), Some(end)) = (model.sample_period(), model.sample_end()) else { return Ok(()) };
        let clock = SampleClock { start, period, next: 0, end: Some(end) };
        let end_time = clock.end_time().unwrap_or(start);
        if stop > end_time + time_eps(end_time) {
            return err(format!(
                "stopTime = {stop} s is past the model's last sample at t = {end_time} s \
                 (sample {} of {period} s from startTime = {start} s, set by {})",
                end.last, end.variable
            ));
        }
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> OpResult {
        self.core.machine = Machine::InitializationMode;
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> OpResult {
        let start = self.core.time;
        // the stop time against the last sample with the parameters as set (start values
        // come after fmi2SetupExperiment), before the model's own work at the end of
        // initialization
        let clock = match self.core.model.sample_period() {
            Some(period) => {
                if !(period > 0.0 && period.is_finite()) {
                    return err(format!("the sample period {period} s is not finite and > 0"));
                }
                let clock = SampleClock { start, period, next: 0, end: self.core.model.sample_end() };
                clock.check_resolution(start)?;
                if let Some(stop) = self.core.stop_time {
                    self.check_stop_within_samples(start, stop)?;
                    clock.check_resolution(stop)?;
                }
                Some(clock)
            }
            None => None,
        };
        if self.clocked {
            self.check_clock_interval(clock.map(|c| c.period))?;
        }
        self.core.model.exit_initialization()?;
        if let Some(clock) = clock {
            self.core.clock = Some(clock);
            self.core.presample = true;
        }
        self.core.machine = match self.context.interface {
            // Co-Simulation with Event Mode (a clocked FMU) starts in Event Mode too
            Interface::CoSimulation if !self.clocked => Machine::StepComplete,
            // Scheduled Execution's Clock Activation Mode
            Interface::ScheduledExecution => Machine::StepComplete,
            _ => Machine::EventMode,
        };
        // the initial event, at the start time; a clocked instance's samples are the
        // importer's activations of its clock, no time events of the layer's
        self.core.next_event = (!self.clocked).then_some(start);
        Ok(())
    }

    pub fn terminate(&mut self) -> OpResult {
        self.core.machine = Machine::Terminated;
        Ok(())
    }

    /// Back to `Instantiated` with the start values, keeping name, interface and callbacks.
    pub fn reset(&mut self) -> OpResult {
        let model = Self::fresh_model(&self.context)?;
        self.core = Core::new(model);
        // the importer of the next run may drive the clock
        if self.undriven_clock {
            self.undriven_clock = false;
            self.clocked = true;
        }
        Ok(())
    }
}

//! One FMU instance in safe Rust, the same for both generations of the C API: the state
//! machine (one table, [`crate::states`]), variable access checks (one variable table, the
//! [`Declaration`], addressed by FMI 2.0 value references per base type or by FMI 3.0
//! value references), time events, FMU state handling, directional and adjoint
//! derivatives. The C ABIs in [`crate::abi`] only translate pointers to slices.

use model_description::fmi3::ValueType as ValueType3;

use crate::decl::{BaseType, Causality, Declaration, HotRow, Initial, SetAccess, Start, Variability};
use crate::fmu_state::{self, LayerNumbers};
use crate::model::{EventUpdate, InstantiateContext, Interface, Model, ModelError};
use crate::sampled::{instant_tolerance, SampleClock, MAX_SAMPLES_PER_STEP};
use crate::states::settable_in;
pub use crate::states::{Function, Generation, Machine, Scope};

/// Result of the fallible instance operations: the message is logged by the ABI layer.
pub type OpResult<T = ()> = Result<T, ModelError>;

/// Most event iterations at one time instant before the layer gives up (a model that
/// keeps asking for another iteration, or keeps scheduling events at the same time).
pub const MAX_EVENT_ITERATIONS: usize = 1000;

/// Values of one `fmi2Set*` call whose earlier values are kept for the way back without
/// copying the model (a longer call copies the model once, at its 33rd value).
const SET_UNDO_CAPACITY: usize = 32;

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
            pre_event: None,
        }
    }
}

/// A saved FMU state (`fmi2FMUstate`).
pub type SavedState<M> = Core<M>;

/// The value references of the last `fmi2GetReal` or `fmi2SetReal` call and their rows
/// of the declaration: a master sends the same arrays at every communication point, so
/// the lookups run once per array, not once per value and call. Only the lookups are
/// kept: every check still runs on every value of every call.
struct CallMemo<B> {
    vrs: Vec<u32>,
    rows: Vec<MemoRow<B>>,
    /// Whether the model may refuse one of them ([`Model::setter_may_refuse`]).
    may_refuse: bool,
}

#[derive(Clone, Copy)]
struct MemoRow<B> {
    row: usize,
    hot: HotRow<B>,
}

/// Longest call whose lookups are kept (the memo is allocated once, with the instance).
const MEMO_CAPACITY: usize = 64;
/// Arrays kept per direction (a master reads an instance's connected outputs and its
/// recorded variables in two calls, say).
const MEMO_ARRAYS: usize = 4;

/// The last [`MEMO_ARRAYS`] arrays, the oldest replaced first.
struct CallMemos<B> {
    arrays: [CallMemo<B>; MEMO_ARRAYS],
    next: usize,
}

impl<B: Copy> CallMemos<B> {
    fn new() -> Self {
        CallMemos { arrays: std::array::from_fn(|_| CallMemo::new()), next: 0 }
    }

    /// The kept array equal to `vrs`.
    #[inline]
    fn find(&self, vrs: &[u32]) -> Option<usize> {
        self.arrays.iter().position(|m| m.matches(vrs))
    }

    /// Keeps the lookups of `vrs` in place of the oldest.
    fn fill(&mut self, d: &Declaration<B>, vrs: &[u32], may_refuse: impl Fn(B) -> bool) {
        self.arrays[self.next].fill(d, vrs, may_refuse);
        self.next = (self.next + 1) % MEMO_ARRAYS;
    }
}

impl<B: Copy> CallMemo<B> {
    fn new() -> Self {
        CallMemo { vrs: Vec::with_capacity(MEMO_CAPACITY), rows: Vec::with_capacity(MEMO_CAPACITY), may_refuse: true }
    }

    #[inline]
    fn matches(&self, vrs: &[u32]) -> bool {
        !self.vrs.is_empty() && self.vrs.as_slice() == vrs
    }

    /// Keeps the lookups of `vrs` (all known Reals: the caller checked).
    fn fill(&mut self, d: &Declaration<B>, vrs: &[u32], may_refuse: impl Fn(B) -> bool) {
        self.vrs.clear();
        self.rows.clear();
        if vrs.len() > MEMO_CAPACITY {
            return;
        }
        for &vr in vrs {
            let Some(row) = d.row(BaseType::Real, vr) else {
                self.vrs.clear();
                self.rows.clear();
                return;
            };
            self.rows.push(MemoRow { row, hot: *d.hot(row) });
        }
        self.vrs.extend_from_slice(vrs);
        self.may_refuse = self.rows.iter().any(|r| may_refuse(r.hot.binding));
    }
}

/// One instance of model `M`.
pub struct Instance<M: Model> {
    pub context: InstantiateContext,
    /// The C API the instance was created by: only its functions pass the gate.
    pub generation: Generation,
    pub core: Core<M>,
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
        let allowed = Function::ALL.map(|f| Self::allowed_states(generation, context.interface, f));
        Ok(Instance {
            allowed,
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

    fn fresh_model(context: &InstantiateContext) -> OpResult<M> {
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

    /// The states in which `function` passes [`Instance::check_call`] for `interface`.
    fn allowed_states(generation: Generation, interface: Interface, function: Function) -> u16 {
        Machine::ALL
            .into_iter()
            .filter(|&m| Self::call_allowed(generation, interface, function, m).is_ok())
            .fold(0, |mask, m| mask | m.bit())
    }

    /// Why `function` is refused now (the table of [`Instance::check_call`] said so).
    #[cold]
    #[inline(never)]
    fn refuse_call(&self, function: Function) -> OpResult {
        Self::call_allowed(self.generation, self.context.interface, function, self.core.machine)?;
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
        if function.generation() != generation {
            return err(match generation {
                Generation::Fmi2 => "not available: this instance was created by fmi2Instantiate (FMI 2.0)",
                Generation::Fmi3 => "not available: this instance was created by an fmi3Instantiate function (FMI 3.0)",
            });
        }
        if let Some(missing) = function.undeclared_feature() {
            return err(format!("not supported: {missing}"));
        }
        if interface == Interface::CoSimulation
            && matches!(function, Function::Fmi3EnterEventMode | Function::Fmi3UpdateDiscreteStates)
        {
            return err("not available: this Co-Simulation FMU declares no Event Mode (hasEventMode is false)");
        }
        match (function.scope(), interface) {
            (Scope::ModelExchange, Interface::CoSimulation) | (Scope::CoSimulation, Interface::ModelExchange) => {
                return err(format!("not available: this instance was created for {interface:?}"));
            }
            _ => {}
        }
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
        if !function.allowed_in(machine) {
            return err(format!("not allowed in state {machine:?}"));
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
        self.core.model.exit_initialization()?;
        if let Some(clock) = clock {
            self.core.clock = Some(clock);
            self.core.presample = true;
        }
        self.core.machine = match self.context.interface {
            Interface::CoSimulation => Machine::StepComplete,
            Interface::ModelExchange => Machine::EventMode,
        };
        // the initial event, at the start time
        self.core.next_event = Some(start);
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
        Ok(())
    }

    /// The row of value reference `vr` of `base_type` in declaration `d` (fetched once per call).
    #[inline(always)]
    fn row_in(d: &Declaration<M::Binding>, base_type: BaseType, vr: u32) -> OpResult<usize> {
        match d.row(base_type, vr) {
            Some(row) => Ok(row),
            None => Self::unknown_value_reference(base_type, vr),
        }
    }

    #[cold]
    #[inline(never)]
    fn unknown_value_reference(base_type: BaseType, vr: u32) -> OpResult<usize> {
        err(format!("unknown {base_type:?} value reference {vr}"))
    }

    /// Refuses the whole call if one value reference is unknown (before anything is read
    /// or changed). The rows are looked up again where they are used: a table lookup is
    /// cheaper than a vector allocated per call.
    #[inline(always)]
    fn check_rows(d: &Declaration<M::Binding>, base_type: BaseType, vrs: &[u32]) -> OpResult {
        for &vr in vrs {
            Self::row_in(d, base_type, vr)?;
        }
        Ok(())
    }

    /// Co-Simulation: runs the events due at the current time (lazily, so that they see
    /// the inputs set for this instant), remembering the model from before them.
    /// The check is inline (nothing is due at almost every read); the events are not.
    #[inline]
    fn settle_events(&mut self) -> OpResult {
        if self.context.interface != Interface::CoSimulation || self.core.machine != Machine::StepComplete {
            return Ok(());
        }
        let now = self.core.time;
        if matches!(self.core.next_event, Some(te) if te <= now + time_eps(now)) {
            self.run_due_events(now)
        } else {
            Ok(())
        }
    }

    #[inline(never)]
    fn run_due_events(&mut self, now: f64) -> OpResult {
        if self.core.pre_event.is_none() {
            let c = &self.core;
            self.core.pre_event = Some(PreEvent {
                model: c.model.clone(),
                next_event: c.next_event,
                clock: c.clock,
                presample: c.presample,
                terminate_requested: c.terminate_requested,
            });
        }
        self.run_events_at(now)
    }

    /// Before a set in Co-Simulation: undo the events run lazily at this instant.
    fn unsettle_events(&mut self) {
        if let Some(pre) = self.core.pre_event.take() {
            self.core.model = pre.model;
            self.core.next_event = pre.next_event;
            self.core.clock = pre.clock;
            self.core.presample = pre.presample;
            self.core.terminate_requested = pre.terminate_requested;
        }
    }

    /// The event iteration at `time`, until the model needs no more and its next event
    /// is later.
    fn run_events_at(&mut self, time: f64) -> OpResult {
        for _ in 0..MAX_EVENT_ITERATIONS {
            let update = self.event_update(time)?;
            if update.terminate_simulation {
                self.core.terminate_requested = true;
                if self.core.clock.is_some() {
                    // the end of the samples: the last values stand; the next step is refused
                    return Ok(());
                }
                return Err(ModelError::Discard(format!("the model asked to terminate the simulation at t = {time}")));
            }
            let due = matches!(self.core.next_event, Some(te) if te <= time + time_eps(time));
            if !update.new_discrete_states_needed && !due {
                return Ok(());
            }
        }
        err(format!("no end of the event iteration at t = {time} after {MAX_EVENT_ITERATIONS} iterations"))
    }

    /// One call of the model's event update, with its next event time checked.
    fn event_update(&mut self, time: f64) -> OpResult<EventUpdate> {
        self.core.model.set_time(time);
        if let Some(mut clock) = self.core.clock {
            return self.sample(&mut clock, time);
        }
        let update = self.core.model.event_update(time)?;
        if let Some(te) = update.next_event_time {
            if !te.is_finite() || !(te > time) {
                return err(format!("the model's next event time {te} is not after the current time {time}"));
            }
        }
        self.core.next_event = update.next_event_time;
        self.core.iteration_pending = update.new_discrete_states_needed;
        self.core.terminate_requested |= update.terminate_simulation;
        Ok(update)
    }

    /// The event of a sampled model at `time` = its next sample (or the end of its samples).
    fn sample(&mut self, clock: &mut SampleClock, time: f64) -> OpResult<EventUpdate> {
        self.core.iteration_pending = false;
        if !clock.has_next() {
            return err(format!("no sample after sample {} at t = {time} s", clock.next));
        }
        self.core.model.sample(clock.next, time)?;
        clock.next += 1;
        self.core.clock = Some(*clock);
        self.core.presample = false;
        self.core.next_event = clock.next_event();
        // after the last sample: the end of the simulation
        let terminate_simulation = self.core.next_event.is_none();
        self.core.terminate_requested |= terminate_simulation;
        Ok(EventUpdate { next_event_time: self.core.next_event, terminate_simulation, ..Default::default() })
    }

    /// Reads before sample 0 of a sampled model: the discrete outputs from what sample 0
    /// will latch (run on a copy), everything else from the model.
    #[cold]
    #[inline(never)]
    fn get_real_presample(&mut self, vrs: &[u32], out: &mut [f64]) -> OpResult {
        let d = decl::<M>();
        Self::check_rows(d, BaseType::Real, vrs)?;
        let mut sampled: Option<M> = None;
        for (o, &vr) in out.iter_mut().zip(vrs) {
            let row = Self::row_in(d, BaseType::Real, vr)?;
            let v = d.variable(row);
            let latched = v.variability == Variability::Discrete && v.initial == Some(Initial::Calculated);
            let model = if latched {
                if sampled.is_none() {
                    let mut copy = self.core.model.clone();
                    copy.sample(0, self.core.time)?;
                    sampled = Some(copy);
                }
                sampled.as_mut().unwrap_or(&mut self.core.model)
            } else {
                &mut self.core.model
            };
            let x = model.get_real(v.binding)?;
            if !x.is_finite() {
                return Self::not_finite(row, x);
            }
            *o = x;
        }
        Ok(())
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> OpResult {
        let d = decl::<M>();
        self.settle_events()?;
        if self.core.presample {
            return self.get_real_presample(vrs, out);
        }
        if let Some(m) = self.get_memo.find(vrs) {
            // the same value references as a recent call: their rows are known
            for (o, r) in out.iter_mut().zip(&self.get_memo.arrays[m].rows) {
                let x = self.core.model.get_real(r.hot.binding)?;
                if !x.is_finite() {
                    return Self::not_finite(r.row, x);
                }
                *o = x;
            }
            return Ok(());
        }
        Self::check_rows(d, BaseType::Real, vrs)?;
        self.get_memo.fill(d, vrs, |_| true);
        for (o, &vr) in out.iter_mut().zip(vrs) {
            let row = Self::row_in(d, BaseType::Real, vr)?;
            let x = self.core.model.get_real(d.hot(row).binding)?;
            if !x.is_finite() {
                return Self::not_finite(row, x);
            }
            *o = x;
        }
        Ok(())
    }

    /// A Real of the model, refusing a non-finite result (an overflowed state, say)
    /// rather than handing NaN or Inf to the importer's solver.
    fn finite_real(&mut self, row: usize) -> OpResult<f64> {
        let x = self.core.model.get_real(decl::<M>().variable(row).binding)?;
        if x.is_finite() {
            Ok(x)
        } else {
            Self::not_finite(row, x)
        }
    }

    #[cold]
    #[inline(never)]
    fn not_finite<T>(row: usize, x: f64) -> OpResult<T> {
        let name = decl::<M>().variable(row).name;
        err(format!("{name} evaluated to {x} (the state or inputs are out of the model's range)"))
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> OpResult {
        let d = decl::<M>();
        Self::check_rows(d, BaseType::Integer, vrs)?;
        self.settle_events()?;
        for (o, &vr) in out.iter_mut().zip(vrs) {
            let row = Self::row_in(d, BaseType::Integer, vr)?;
            *o = self.core.model.get_integer(d.hot(row).binding)?;
        }
        Ok(())
    }

    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [bool]) -> OpResult {
        let d = decl::<M>();
        Self::check_rows(d, BaseType::Boolean, vrs)?;
        self.settle_events()?;
        for (o, &vr) in out.iter_mut().zip(vrs) {
            let row = Self::row_in(d, BaseType::Boolean, vr)?;
            *o = self.core.model.get_boolean(d.hot(row).binding)?;
        }
        Ok(())
    }

    /// Whether `value` fits variable `row` (min/max of the declaration, enumeration items).
    fn check_value(row: usize, value: f64) -> Result<(), String> {
        decl::<M>().check_value(row, value)
    }

    /// Sets all or nothing: every value reference, permission and value is checked first
    /// (from the declaration's tables), then the values are applied in order. If the model
    /// refuses one, the values this call set before it are put back, newest first, with
    /// the values their getters returned before the call (the contract of
    /// [`Model::set_real`]): the model is as before the call. No copy of the model is made
    /// unless a getter fails (then from that value on the call keeps a copy to go back to);
    /// no earlier value is kept when the model refuses none of the call's variables
    /// ([`Model::setter_may_refuse`]).
    fn set_values<T: Copy + Into<f64>>(
        &mut self,
        base_type: BaseType,
        vrs: &[u32],
        values: &[T],
        mut read: impl FnMut(&mut M, M::Binding) -> OpResult<T>,
        mut apply: impl FnMut(&mut M, M::Binding, T) -> OpResult,
    ) -> OpResult {
        let d = decl::<M>();
        let machine_bit = self.core.machine.bit();
        let n = vrs.len().min(values.len());
        // the same Real value references as a recent call: their rows are known
        let memo = if base_type == BaseType::Real { self.set_memo.find(vrs) } else { None };
        let may_refuse = if let Some(m) = memo {
            for (r, &value) in self.set_memo.arrays[m].rows.iter().zip(values) {
                Self::check_set(r.row, r.hot.access, machine_bit, value.into(), self.core.machine)?;
            }
            self.set_memo.arrays[m].may_refuse
        } else {
            let mut may_refuse = false;
            for (&vr, &value) in vrs.iter().zip(values) {
                let row = Self::row_in(d, base_type, vr)?;
                let hot = d.hot(row);
                may_refuse |= M::setter_may_refuse(hot.binding);
                Self::check_set(row, hot.access, machine_bit, value.into(), self.core.machine)?;
            }
            if base_type == BaseType::Real {
                self.set_memo.fill(d, vrs, M::setter_may_refuse);
            }
            may_refuse
        };
        self.unsettle_events();
        if !may_refuse || n == 1 {
            // nothing to put back: the model refuses none of these (or only this one value,
            // which then leaves it unchanged)
            if let Some(m) = memo {
                for (r, &value) in self.set_memo.arrays[m].rows.iter().zip(values) {
                    apply(&mut self.core.model, r.hot.binding, value).map_err(|e| Self::named(r.row, e))?;
                }
                return Ok(());
            }
            for (&vr, &value) in vrs.iter().zip(values) {
                let row = Self::row_in(d, base_type, vr)?;
                apply(&mut self.core.model, d.hot(row).binding, value).map_err(|e| Self::named(row, e))?;
            }
            return Ok(());
        }
        // here n >= 2 and some value may be refused: the earlier values, for the way back
        let Some(&first) = values.first() else { return Ok(()) };
        let mut earlier = [first; SET_UNDO_CAPACITY];
        // from this index on, the way back is a copy of the model (when a getter failed or
        // the call is longer than `earlier`)
        let mut copy: Option<(usize, M)> = None;
        for k in 0..n {
            let row = Self::row_in(d, base_type, vrs[k])?;
            let binding = d.hot(row).binding;
            if copy.is_none() {
                match (k < SET_UNDO_CAPACITY).then(|| read(&mut self.core.model, binding)) {
                    Some(Ok(old)) => earlier[k] = old,
                    _ => copy = Some((k, self.core.model.clone())),
                }
            }
            if let Err(e) = apply(&mut self.core.model, binding, values[k]) {
                let e = Self::named(row, e);
                let undo_to = match copy.take() {
                    Some((from, model)) => {
                        self.core.model = model;
                        from
                    }
                    None => k,
                };
                for j in (0..undo_to).rev() {
                    let row = Self::row_in(d, base_type, vrs[j])?;
                    if let Err(undo) = apply(&mut self.core.model, d.hot(row).binding, earlier[j]) {
                        return err(format!(
                            "{}; putting back {} failed too ({undo}): the model broke the setter contract",
                            e.message(),
                            d.variable(row).name
                        ));
                    }
                }
                return Err(e);
            }
        }
        Ok(())
    }

    /// The checks of one value of `fmi2Set*`: the common case from the precomputed tables,
    /// the full checks (which give the reason) only when these do not accept at once.
    #[inline(always)]
    fn check_set(row: usize, access: SetAccess, machine_bit: u16, x: f64, machine: Machine) -> OpResult {
        if access.settable_in & machine_bit == 0 {
            let v = decl::<M>().variable(row);
            settable_in(v.name, v.causality, v.variability, v.initial, machine)?;
        }
        if !(access.plain && x >= access.lowest && x <= access.highest) {
            Self::check_value(row, x)?;
        }
        Ok(())
    }

    /// A model's refusal, with the variable's name in front.
    #[cold]
    #[inline(never)]
    fn named(row: usize, e: ModelError) -> ModelError {
        let name = decl::<M>().variable(row).name;
        match e {
            ModelError::Error(m) => ModelError::Error(format!("{name}: {m}")),
            ModelError::Discard(m) => ModelError::Discard(format!("{name}: {m}")),
        }
    }

    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> OpResult {
        self.set_values(BaseType::Real, vrs, values, |m, b| m.get_real(b), |m, b, x| m.set_real(b, x))
    }

    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> OpResult {
        self.set_values(BaseType::Integer, vrs, values, |m, b| m.get_integer(b), |m, b, x| m.set_integer(b, x))
    }

    pub fn set_boolean(&mut self, vrs: &[u32], values: &[bool]) -> OpResult {
        let as_f64: Vec<BoolAsF64> = values.iter().map(|&b| BoolAsF64(b)).collect();
        self.set_values(
            BaseType::Boolean,
            vrs,
            &as_f64,
            |m, b| m.get_boolean(b).map(BoolAsF64),
            |m, b, x| m.set_boolean(b, x.0),
        )
    }

    // ---------------------------------------------------------------- Co-Simulation

    /// `fmi2DoStep`: the model's time events inside the step run in order at their time
    /// (those at the step's start with the inputs just set); the continuous part is
    /// integrated between them; events exactly at the step's end wait for the next
    /// read or step (so that they see the inputs of that instant). The step starts at the
    /// importer's `currentCommunicationPoint` and ends at `currentCommunicationPoint +
    /// communicationStepSize` exactly (FMI 2.0 section 4.2.2), so the FMU's time is the
    /// importer's and `fmi2LastSuccessfulTime` its arithmetic.
    pub fn do_step(&mut self, current_time: f64, step: f64) -> OpResult {
        if self.core.terminate_requested && self.core.clock.is_none() {
            // the Discard with terminateSimulation of the step that ended the run (FMI 3.0
            // stays in Step Mode after it; FMI 2.0's stepFailed refuses the step before)
            return err(format!(
                "the model asked to terminate the simulation at t = {} s: no step after it (terminate or reset)",
                self.core.time
            ));
        }
        if !(step > 0.0) || !step.is_finite() {
            return err(format!("communicationStepSize = {step} s refused: must be finite and > 0"));
        }
        let now = self.core.time;
        if !current_time.is_finite() || (current_time - now).abs() > time_eps(now) {
            return err(format!(
                "currentCommunicationPoint = {current_time} s is not the end of the previous step ({now} s)"
            ));
        }
        let end = current_time + step;
        if !(end > current_time) || !end.is_finite() {
            return err(format!(
                "communicationStepSize = {step} s does not advance currentCommunicationPoint = {current_time} s \
                 (an f64 resolves {:e} s there)",
                crate::sampled::ulp(current_time)
            ));
        }
        if let Some(stop) = self.core.stop_time {
            if end > stop + time_eps(stop) {
                return err(format!(
                    "the step would end at {end} s, after the stopTime {stop} s of fmi2SetupExperiment"
                ));
            }
        }
        if let Some(clock) = self.core.clock {
            // refused before any work: too many samples, or a time that cannot hold the grid
            // a model with a last sample stops there
            let until = clock.end_time().map_or(end, |t_end| end.min(t_end));
            let samples = (until - clock.time_of(clock.next)) / clock.period;
            if samples > MAX_SAMPLES_PER_STEP {
                return Err(ModelError::Discard(format!(
                    "the step of {step} s would run {samples:.0} samples of {} s, more than the {MAX_SAMPLES_PER_STEP} \
                     one fmi2DoStep may run: take shorter steps",
                    clock.period
                )));
            }
            clock.check_resolution(end).map_err(ModelError::Discard)?;
        }
        self.core.time = current_time;
        self.settle_events()?;
        self.core.pre_event = None;
        if self.core.terminate_requested && self.core.clock.is_some() {
            return Err(self.past_the_samples());
        }
        loop {
            match self.core.next_event {
                Some(te) if te < end - time_eps(end) => {
                    let t = self.core.time;
                    if te > t {
                        self.core.model.do_step(t, te - t)?;
                        self.core.time = te;
                    }
                    self.run_events_at(te)?;
                    if self.core.terminate_requested && self.core.clock.is_some() {
                        return Err(self.past_the_samples());
                    }
                }
                _ => {
                    let t = self.core.time;
                    // without an event inside, exactly the importer's step size
                    let rest = if t == current_time { step } else { end - t };
                    if rest > 0.0 {
                        self.core.model.do_step(t, rest)?;
                    }
                    self.core.time = end;
                    return Ok(());
                }
            }
        }
    }

    /// The `fmi2Discard` of a step past a sampled model's last sample (the instance is at
    /// the end of its samples: `fmi2LastSuccessfulTime`).
    #[cold]
    fn past_the_samples(&self) -> ModelError {
        let what = match self.core.model.sample_end() {
            Some(e) => format!(
                "sample {} of {} s is the last, set by {}",
                e.last,
                self.core.clock.map_or(0.0, |c| c.period),
                e.variable
            ),
            None => "the model's last sample".to_string(),
        };
        ModelError::Discard(format!(
            "the simulation ends at t = {} s ({what}): fmi2Terminated is true, fmi2LastSuccessfulTime is that time",
            self.core.time
        ))
    }

    // ---------------------------------------------------------------- Model Exchange

    pub fn set_time(&mut self, time: f64) -> OpResult {
        if !time.is_finite() {
            return err(format!("time {time} is not finite"));
        }
        if let Some(stop) = self.core.stop_time {
            // Variable-step integrators (CVode in fmpy, say) evaluate the right-hand side
            // past the output time and interpolate back, so a time past stopTime is not an
            // error in Model Exchange; it is a warning (fmi2Warning, logged). A
            // Co-Simulation step past stopTime is an error.
            if time > stop + time_eps(stop) {
                self.context
                    .logger
                    .warning(&format!("fmi2SetTime: time {time} is after the stopTime {stop} of fmi2SetupExperiment"));
            }
        }
        self.core.time = time;
        self.core.model.set_time(time);
        Ok(())
    }

    pub fn enter_event_mode(&mut self) -> OpResult {
        self.core.machine = Machine::EventMode;
        Ok(())
    }

    pub fn enter_continuous_time_mode(&mut self) -> OpResult {
        self.core.machine = Machine::ContinuousTimeMode;
        Ok(())
    }

    /// `fmi2NewDiscreteStates`: one event iteration when a time event is due (or the
    /// model asked for another); the next event time for the importer.
    pub fn new_discrete_states(&mut self) -> OpResult<EventUpdate> {
        let now = self.core.time;
        let due = matches!(self.core.next_event, Some(te) if te <= now + time_eps(now));
        if due || self.core.iteration_pending {
            let update = self.event_update(now)?;
            Ok(update)
        } else {
            Ok(EventUpdate {
                next_event_time: self.core.next_event,
                terminate_simulation: self.core.terminate_requested,
                ..Default::default()
            })
        }
    }

    fn check_state_count(&self, n: usize) -> OpResult {
        let expected = decl::<M>().number_of_states();
        if n == expected {
            Ok(())
        } else {
            err(format!("nx = {n}, the model has {expected} continuous states"))
        }
    }

    pub fn get_continuous_states(&mut self, out: &mut [f64]) -> OpResult {
        self.check_state_count(out.len())?;
        self.read_rows(&decl::<M>().state_rows, out)
    }

    /// Reads the Reals of `rows` into `out` (the state or derivative vector).
    fn read_rows(&mut self, rows: &[usize], out: &mut [f64]) -> OpResult {
        for (o, &row) in out.iter_mut().zip(rows) {
            *o = self.finite_real(row)?;
        }
        Ok(())
    }

    pub fn set_continuous_states(&mut self, x: &[f64]) -> OpResult {
        self.check_state_count(x.len())?;
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return err(format!(
                "state {} = {} refused: not a finite number",
                decl::<M>().variable(decl::<M>().state_rows[i]).name,
                x[i]
            ));
        }
        let backup = self.core.model.clone();
        for (&value, &row) in x.iter().zip(&decl::<M>().state_rows) {
            if let Err(e) = self.core.model.set_real(decl::<M>().variable(row).binding, value) {
                self.core.model = backup;
                return Err(e);
            }
        }
        Ok(())
    }

    pub fn get_derivatives(&mut self, out: &mut [f64]) -> OpResult {
        self.check_state_count(out.len())?;
        self.read_rows(&decl::<M>().derivative_rows, out)
    }

    pub fn get_nominals(&mut self, out: &mut [f64]) -> OpResult {
        self.check_state_count(out.len())?;
        for (o, &row) in out.iter_mut().zip(&decl::<M>().state_rows) {
            *o = decl::<M>().variable(row).nominal.unwrap_or(1.0);
        }
        Ok(())
    }

    pub fn get_event_indicators(&mut self, out: &mut [f64]) -> OpResult {
        if out.is_empty() {
            Ok(())
        } else {
            err(format!("ni = {}, the model has no event indicators", out.len()))
        }
    }

    // ---------------------------------------------------------------- derivatives

    pub fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        out: &mut [f64],
    ) -> OpResult {
        if let Some(x) = dv_known.iter().find(|x| !x.is_finite()) {
            return err(format!("dvKnown contains {x}"));
        }
        let binding = |vr: u32| -> OpResult<M::Binding> {
            decl::<M>()
                .row(BaseType::Real, vr)
                .map(|r| decl::<M>().variable(r).binding)
                .ok_or_else(|| format!("unknown Real value reference {vr}").into())
        };
        let d = decl::<M>();
        // before fmi3ExitInitializationMode the initial dependencies (FMI 3.0 section 2.2.11)
        let initialization = matches!(self.core.machine, Machine::Instantiated | Machine::InitializationMode);
        for &vr in knowns {
            let row = Self::row_in(d, BaseType::Real, vr)?;
            let v = d.variable(row);
            // the knowns of FMI 2.0 section 2.2.8: inputs and continuous states, and in
            // Initialization Mode the variables with initial="exact" (a state calculated
            // from its start value stays a known there too: its partials are defined)
            let known = v.causality == Causality::Input
                || d.state_rows.contains(&row)
                || (initialization && v.initial == Some(Initial::Exact));
            if !known {
                return err(format!(
                    "known {} is not an input, a continuous state or (in Initialization Mode) exact",
                    v.name
                ));
            }
            if !M::provides_derivative_with_respect_to(v.binding, initialization) {
                return err(format!(
                    "derivatives with respect to {} are not provided ({} in Initialization Mode)",
                    v.name,
                    if initialization {
                        "only inputs, continuous states and their start values"
                    } else {
                        "only inputs and continuous states"
                    }
                ));
            }
        }
        for &vr in unknowns {
            let row = Self::row_in(d, BaseType::Real, vr)?;
            let v = d.variable(row);
            let unknown =
                v.causality == Causality::Output || d.state_rows.contains(&row) || d.derivative_rows.contains(&row);
            if !unknown {
                return err(format!("unknown {} is not an output, a continuous state or a derivative", v.name));
            }
        }
        let u: Vec<_> = unknowns.iter().map(|&vr| binding(vr)).collect::<OpResult<_>>()?;
        let k: Vec<_> = knowns.iter().map(|&vr| binding(vr)).collect::<OpResult<_>>()?;
        self.core.model.directional_derivative(&u, &k, dv_known, out)?;
        if let Some(i) = out.iter().position(|x| !x.is_finite()) {
            let name = decl::<M>().row(BaseType::Real, unknowns[i]).map(|r| decl::<M>().variable(r).name);
            return err(format!(
                "the derivative of {} evaluated to {} (seed or state out of the model's range)",
                name.unwrap_or("?"),
                out[i]
            ));
        }
        Ok(())
    }

    /// Adjoint derivatives `out = J^T w` (`out[j] = sum_i w_i dUnknown_i/dKnown_j`) from the
    /// columns of `J`: one directional derivative per known (`J e_j`, exact as the model's
    /// directional derivatives are), then the transposed product. Generic: every model with
    /// directional derivatives has it, in the same modes and with the same checks.
    pub fn adjoint_derivative(&mut self, unknowns: &[u32], knowns: &[u32], seed: &[f64], out: &mut [f64]) -> OpResult {
        if let Some(x) = seed.iter().find(|x| !x.is_finite()) {
            return err(format!("seed contains {x}"));
        }
        let mut column = vec![0.0; unknowns.len()];
        for (o, &known) in out.iter_mut().zip(knowns) {
            self.directional_derivative(unknowns, &[known], &[1.0], &mut column)?;
            *o = seed.iter().zip(&column).map(|(w, c)| w * c).sum();
        }
        Ok(())
    }

    // ---------------------------------------------------------------- FMI 3.0 access

    /// The FMI 2.0 value reference (of the base type that `accessed` is in FMI 2.0) of the
    /// FMI 3.0 value reference `vr`, checked to be a variable of type `accessed`. `time` (0)
    /// is refused: the callers that accept it handle it before.
    fn fmi2_reference(vr: u32, accessed: ValueType3) -> OpResult<u32> {
        let d = decl::<M>();
        // the declaration's table answers every accepted reference; the checks below only
        // say why a reference is refused
        if let Some(vr2) = d.fmi2_of_fmi3(vr, accessed) {
            return Ok(vr2);
        }
        let Some(v) = d.variable3(vr) else {
            return err(format!("unknown value reference {vr} (the FMU's are 0 ..= {})", d.spec.variables.len()));
        };
        if v.value_type != accessed {
            return err(format!(
                "value reference {vr} is {}, a {} variable, not a {} one",
                v.name,
                v.value_type.element(),
                accessed.element()
            ));
        }
        match d.row3(vr) {
            Some(row) => Ok(d.variable(row).value_reference),
            None => err(format!("value reference {vr} is {}, the independent variable", v.name)),
        }
    }

    /// [`Instance::fmi2_reference`] of each of `vrs`, all checked before any is used.
    pub fn fmi2_references(&self, vrs: &[u32], accessed: ValueType3) -> OpResult<Vec<u32>> {
        vrs.iter().map(|&vr| Self::fmi2_reference(vr, accessed)).collect()
    }

    /// Runs `f` with the FMI 2.0 value references of `vrs` ([`Instance::fmi2_references`]):
    /// on the stack for the calls a master makes at every communication point (up to 64
    /// values), so that the FMI 3.0 getters and setters allocate no more than FMI 2.0's.
    fn with_fmi2_references<T>(
        &mut self,
        vrs: &[u32],
        accessed: ValueType3,
        f: impl FnOnce(&mut Self, &[u32]) -> OpResult<T>,
    ) -> OpResult<T> {
        const ON_STACK: usize = 64;
        if vrs.len() <= ON_STACK {
            let mut buffer = [0u32; ON_STACK];
            for (slot, &vr) in buffer.iter_mut().zip(vrs) {
                *slot = Self::fmi2_reference(vr, accessed)?;
            }
            f(self, &buffer[..vrs.len()])
        } else {
            let vrs2 = self.fmi2_references(vrs, accessed)?;
            f(self, &vrs2)
        }
    }

    /// Before Initialization Mode an FMI 3.0 getter returns start values (FMI 3.0 section
    /// 2.3.2): a variable without one, calculated in Initialization Mode, is refused.
    fn check_start_values(&self, vrs: &[u32]) -> OpResult {
        if self.core.machine != Machine::Instantiated {
            return Ok(());
        }
        let d = decl::<M>();
        for &vr in vrs {
            let Some(row) = d.row3(vr) else { continue };
            let v = d.variable(row);
            if !matches!(v.initial, Some(Initial::Exact) | Some(Initial::Approx)) && v.causality != Causality::Input {
                return err(format!(
                    "{} (value reference {vr}) has no start value: it is calculated in Initialization Mode, so it \
                     cannot be read in Instantiated",
                    v.name
                ));
            }
        }
        Ok(())
    }

    /// `fmi3GetFloat64`: the Float64 variables, `time` (value reference 0) included.
    pub fn get_float64(&mut self, vrs: &[u32], out: &mut [f64]) -> OpResult {
        self.check_start_values(vrs)?;
        if !vrs.contains(&0) {
            return self.with_fmi2_references(vrs, ValueType3::Float64, |i, vrs2| i.get_real(vrs2, out));
        }
        let others: Vec<u32> = vrs.iter().copied().filter(|&vr| vr != 0).collect();
        let vrs2 = self.fmi2_references(&others, ValueType3::Float64)?;
        let mut values = vec![0.0; vrs2.len()];
        self.get_real(&vrs2, &mut values)?;
        let mut values = values.into_iter();
        for (o, &vr) in out.iter_mut().zip(vrs) {
            if vr == 0 {
                *o = self.core.time;
            } else if let Some(x) = values.next() {
                *o = x;
            }
        }
        Ok(())
    }

    /// `fmi3SetFloat64` (`time` is refused: it is the independent variable).
    pub fn set_float64(&mut self, vrs: &[u32], values: &[f64]) -> OpResult {
        if vrs.contains(&0) {
            return err("time (value reference 0) cannot be set: it is the independent variable, \
                 advanced by fmi3DoStep or set by fmi3SetTime");
        }
        self.with_fmi2_references(vrs, ValueType3::Float64, |i, vrs2| i.set_real(vrs2, values))
    }

    /// `fmi3GetInt32` (Integers) or `fmi3GetInt64` (Enumerations).
    pub fn get_int(&mut self, vrs: &[u32], accessed: ValueType3, out: &mut [i32]) -> OpResult {
        self.check_start_values(vrs)?;
        self.with_fmi2_references(vrs, accessed, |i, vrs2| i.get_integer(vrs2, out))
    }

    /// `fmi3SetInt32` (Integers) or `fmi3SetInt64` (Enumerations): values outside the
    /// 32-bit range of the variables are refused before the declaration's checks.
    pub fn set_int(&mut self, vrs: &[u32], accessed: ValueType3, values: &[i64]) -> OpResult {
        let vrs2 = self.fmi2_references(vrs, accessed)?;
        let narrow: Vec<i32> = values
            .iter()
            .zip(vrs)
            .map(|(&x, &vr)| {
                i32::try_from(x).map_err(|_| {
                    let name = decl::<M>().variable3(vr).map_or("?", |v| v.name.as_str());
                    ModelError::from(format!("{name} = {x} refused: outside the 32-bit range of its values"))
                })
            })
            .collect::<OpResult<_>>()?;
        self.set_integer(&vrs2, &narrow)
    }

    /// `fmi3GetBoolean`.
    pub fn get_boolean3(&mut self, vrs: &[u32], out: &mut [bool]) -> OpResult {
        self.check_start_values(vrs)?;
        let vrs2 = self.fmi2_references(vrs, ValueType3::Boolean)?;
        self.get_boolean(&vrs2, out)
    }

    /// `fmi3SetBoolean`.
    pub fn set_boolean3(&mut self, vrs: &[u32], values: &[bool]) -> OpResult {
        let vrs2 = self.fmi2_references(vrs, ValueType3::Boolean)?;
        self.set_boolean(&vrs2, values)
    }

    /// The FMI 3.0 value references of the Float64 unknowns or knowns of a derivative
    /// call, as FMI 2.0 Real value references.
    pub fn real_references(&self, vrs: &[u32]) -> OpResult<Vec<u32>> {
        if vrs.contains(&0) {
            return err("time (value reference 0) is no unknown or known of a partial derivative here");
        }
        self.fmi2_references(vrs, ValueType3::Float64)
    }

    /// Whether the run ends at the current time: the model asked to end it, or a sampled
    /// model's last sample is due now (it runs at the next read or step).
    pub fn run_ends(&self) -> bool {
        let now = self.core.time;
        self.core.terminate_requested
            || self.core.clock.is_some_and(|c| c.end_time().is_some_and(|end| end <= now + time_eps(now)))
    }

    /// `fmi3GetVariableDependencies`: the knowns the unknown `vr` depends on in the current
    /// state (the `<InitialUnknown>` entry in Initialization Mode, else the `<Output>` or
    /// `<ContinuousStateDerivative>` entry), as FMI 3.0 value references; an entry without
    /// `dependencies` depends on every known of the mode (FMI 3.0 section 2.4.8).
    pub fn variable_dependencies(&self, vr: u32) -> OpResult<Vec<u32>> {
        let d = decl::<M>();
        let Some(v) = d.variable3(vr) else { return err(format!("unknown value reference {vr}")) };
        let s = &d.model_description3().model_structure;
        // before fmi3ExitInitializationMode the initial dependencies (FMI 3.0 section 2.2.11)
        let initialization = matches!(self.core.machine, Machine::Instantiated | Machine::InitializationMode);
        let entry = if initialization {
            s.initial_unknowns.iter().find(|u| u.value_reference == vr)
        } else {
            s.outputs.iter().chain(&s.continuous_state_derivatives).find(|u| u.value_reference == vr)
        };
        let Some(entry) = entry else {
            return err(format!(
                "{} (value reference {vr}) is no unknown of the ModelStructure {}",
                v.name,
                if initialization { "in Initialization Mode" } else { "after initialization" }
            ));
        };
        Ok(match &entry.dependencies {
            Some(on) => on.clone(),
            None => (0..d.spec.variables.len())
                .filter(|&row| {
                    let k = d.variable(row);
                    k.causality == Causality::Input
                        || if initialization { k.initial == Some(Initial::Exact) } else { d.state_rows.contains(&row) }
                })
                .map(Declaration::<M::Binding>::value_reference3)
                .collect(),
        })
    }

    // ---------------------------------------------------------------- FMU state

    pub fn save_state(&self) -> SavedState<M> {
        self.core.clone()
    }

    /// Restores a saved state (the callbacks stay the current instance's).
    pub fn restore_state(&mut self, state: &SavedState<M>) -> OpResult {
        let fits = match state.machine {
            // FMI 3.0 has no stepFailed state: a Discarded fmi3DoStep stays in Step Mode
            Machine::StepFailed if self.generation == Generation::Fmi3 => false,
            Machine::StepComplete | Machine::StepFailed => self.context.interface == Interface::CoSimulation,
            Machine::EventMode | Machine::ContinuousTimeMode => self.context.interface == Interface::ModelExchange,
            _ => true,
        };
        if !fits {
            return err(format!(
                "a state saved in {:?} cannot be restored into a {:?} {:?} instance",
                state.machine, self.generation, self.context.interface
            ));
        }
        self.core = state.clone();
        Ok(())
    }

    /// The declared variables a serialized state holds (none when the model overrides).
    fn saved_rows() -> &'static [usize] {
        if M::SAVE_DECLARED_VARIABLES {
            &decl::<M>().saved_rows
        } else {
            &[]
        }
    }

    /// Bytes of a saved state ([`crate::fmu_state`]): the layer's numbers, the declared
    /// variables of [`Declaration::saved_rows`] and the model's internal numbers. Events
    /// run lazily at the current time are saved as not run.
    pub fn serialize(state: &SavedState<M>) -> OpResult<Vec<u8>> {
        let (mut model, next_event, clock, presample) = match &state.pre_event {
            Some(pre) => (pre.model.clone(), pre.next_event, pre.clock, pre.presample),
            None => (state.model.clone(), state.next_event, state.clock, state.presample),
        };
        let mut numbers = Vec::new();
        LayerNumbers {
            machine: state.machine,
            time: state.time,
            stop_time: state.stop_time,
            next_event,
            iteration_pending: state.iteration_pending,
            clock: clock.map(|c| (c.start, c.period, c.next as f64)),
            presample,
        }
        .push_to(&mut numbers);
        for &row in Self::saved_rows() {
            let v = decl::<M>().variable(row);
            numbers.push(match v.base_type {
                BaseType::Real => model.get_real(v.binding)?,
                BaseType::Integer => model.get_integer(v.binding)? as f64,
                BaseType::Boolean => fmu_state::flag(model.get_boolean(v.binding)?),
            });
        }
        model.save_internal(&mut numbers);
        Ok(fmu_state::encode(decl::<M>().guid(), &numbers))
    }

    /// Parses bytes from [`Instance::serialize`]; refuses anything else with the reason.
    /// The variables go through the same checks and setters as `fmi2Set*`, and a state
    /// past initialization through the model's `exit_initialization` check.
    pub fn deserialize(&self, bytes: &[u8]) -> OpResult<SavedState<M>> {
        let saved = Self::saved_rows().len();
        let numbers = fmu_state::decode(decl::<M>().guid(), bytes, LayerNumbers::COUNT + saved)?;
        let LayerNumbers { machine, time, stop_time, next_event, iteration_pending, clock, presample } =
            LayerNumbers::read(&numbers, time_eps)?;
        let (has_clock, (clock_start, period, next_sample)) = (clock.is_some(), clock.unwrap_or_default());
        let flag = |x: f64, what: &str| -> OpResult<bool> { Ok(fmu_state::read_flag(x, what)?) };
        let mut model = Self::fresh_model(&self.context)?;
        let values = &numbers[LayerNumbers::COUNT..LayerNumbers::COUNT + saved];
        for (&row, &x) in Self::saved_rows().iter().zip(values) {
            let v = decl::<M>().variable(row);
            Self::check_value(row, x).map_err(|e| format!("serialized state: {e}"))?;
            let r = match v.base_type {
                BaseType::Real => model.set_real(v.binding, x),
                BaseType::Integer => {
                    if x != (x as i32) as f64 {
                        return err(format!("serialized state: {} = {x} is not an Integer", v.name));
                    }
                    model.set_integer(v.binding, x as i32)
                }
                BaseType::Boolean => model.set_boolean(v.binding, flag(x, v.name)?),
            };
            r.map_err(|e| format!("serialized state: {}: {e}", v.name))?;
        }
        model.load_internal(&numbers[LayerNumbers::COUNT + saved..])?;
        let initialized = !matches!(machine, Machine::Instantiated | Machine::InitializationMode);
        if initialized {
            model.exit_initialization().map_err(|e| format!("serialized state: {e}"))?;
        }
        let clock = if has_clock {
            Some(SampleClock { start: clock_start, period, next: 0, end: model.sample_end() })
        } else {
            None
        };
        let clock = Self::consistent_clock(&model, initialized, clock, next_sample, time, next_event, presample)
            .map_err(|e| ModelError::Error(format!("serialized state: {e}")))?;
        Ok(Core {
            machine,
            time,
            stop_time,
            next_event,
            iteration_pending,
            terminate_requested: clock.is_some_and(|c| !c.has_next()),
            model,
            clock,
            presample,
            pre_event: None,
        })
    }

    /// A loaded sample clock agrees with the model and the instance: the model is sampled
    /// exactly when the state has a clock past initialization, with the period of its
    /// parameters; the sample count is an integer within the model's samples; the time
    /// lies between the last sample run and the next; the next event is the next sample
    /// (or the end of the samples) to the bit; "before the first sample" is "no sample run".
    fn consistent_clock(
        model: &M,
        initialized: bool,
        clock: Option<SampleClock>,
        next_sample: f64,
        time: f64,
        next_event: Option<f64>,
        presample: bool,
    ) -> Result<Option<SampleClock>, String> {
        let period = model.sample_period();
        let Some(mut clock) = clock else {
            if initialized && period.is_some() {
                return Err("a sampled model past initialization without its sample clock".into());
            }
            if presample != (period.is_some()) {
                return Err(format!("the before-first-sample flag {presample} disagrees with the model"));
            }
            return Ok(None);
        };
        if !initialized {
            return Err("a sample clock before initialization ended".into());
        }
        if period != Some(clock.period) {
            return Err(format!(
                "the sample clock's period {} s disagrees with the model's {period:?} s",
                clock.period
            ));
        }
        if !(clock.start.is_finite() && next_sample >= 0.0 && next_sample.fract() == 0.0 && next_sample < 9e15) {
            return Err(format!(
                "the sample clock (start {} s, sample {next_sample}) is not a finite start and a sample count",
                clock.start
            ));
        }
        clock.next = next_sample as u64;
        if let Some(end) = clock.end {
            if clock.next > end.last + 1 {
                return Err(format!(
                    "sample {} is past the model's last sample {} (set by {})",
                    clock.next, end.last, end.variable
                ));
            }
        }
        if presample != (clock.next == 0) {
            return Err(format!("the before-first-sample flag {presample} disagrees with sample count {}", clock.next));
        }
        let (earliest, latest) = match clock.next {
            0 => (clock.start, clock.start),
            k => (clock.time_of(k - 1), clock.time_of(k)),
        };
        if !(time >= earliest - time_eps(earliest) && time <= latest + time_eps(latest)) {
            return Err(format!(
                "time {time} s is not between the last sample run and the next ({earliest} s .. {latest} s, sample {})",
                clock.next
            ));
        }
        let expected = clock.next_event();
        if next_event.map(f64::to_bits) != expected.map(f64::to_bits) {
            return Err(format!(
                "the next event time {next_event:?} s disagrees with the sample clock: sample {} is due at {:?} s",
                clock.next, expected
            ));
        }
        Ok(Some(clock))
    }
}

/// A Boolean seen as a number for the shared value check (always finite, no bounds).
#[derive(Clone, Copy)]
struct BoolAsF64(bool);

impl From<BoolAsF64> for f64 {
    fn from(b: BoolAsF64) -> f64 {
        b.0 as u8 as f64
    }
}

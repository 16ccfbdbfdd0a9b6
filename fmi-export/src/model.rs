//! The small safe trait a model implements. It never sees a raw pointer, a C string or
//! the FMI state machine: the layer owns those.

use std::path::PathBuf;

use crate::decl::Declaration;
use crate::log::Logger;
use crate::sampled::SampleEnd;

/// What the model learns at instantiation.
#[derive(Clone, Debug)]
pub struct InstantiateContext {
    pub instance_name: String,
    pub interface: Interface,
    /// The FMU's `resources/` folder, when the importer gave a usable `file:` URI.
    pub resource_path: Option<PathBuf>,
    /// The instance's logger (categories, Warning status); clone it to keep it.
    pub logger: Logger,
}

/// The interface an instance was created for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interface {
    ModelExchange,
    CoSimulation,
    /// FMI 3.0 Scheduled Execution: offered by a model with a declared clock (its model
    /// partition), activated by the importer with `fmi3ActivateModelPartition`.
    ScheduledExecution,
}

/// Why a model call failed.
///
/// `Error` puts the instance in the error state (only reset, free, FMU-state restore and
/// diagnostic gets remain). `Discard` is the standard's "this step or value cannot be
/// computed, the instance is still sound": `fmi2DoStep` then moves to `stepFailed` (the
/// importer continues after `fmi2SetFMUstate` or `fmi2Reset`), elsewhere the state stays.
/// Both carry the reason, which the layer logs with the function's name.
///
/// `From<String>` and `From<&str>` give an `Error`, so `Err(format!(..).into())` and `?`
/// on `Result<_, String>` work.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ModelError {
    Error(String),
    Discard(String),
}

impl ModelError {
    pub fn message(&self) -> &str {
        match self {
            ModelError::Error(m) | ModelError::Discard(m) => m,
        }
    }
}

impl From<String> for ModelError {
    fn from(m: String) -> Self {
        ModelError::Error(m)
    }
}

impl From<&str> for ModelError {
    fn from(m: &str) -> Self {
        ModelError::Error(m.to_string())
    }
}

impl std::fmt::Display for ModelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.message())
    }
}

/// Result of a model call.
pub type ModelResult<T = ()> = Result<T, ModelError>;

/// What an event update reports (FMI 2.0 `fmi2EventInfo`, from the model's side).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct EventUpdate {
    /// The next time event (e.g. the next sample instant), if any. Must be later than the
    /// current time; the layer refuses anything else.
    pub next_event_time: Option<f64>,
    /// Another event iteration at the same time is needed (the layer calls
    /// [`Model::event_update`] again at the same time).
    pub new_discrete_states_needed: bool,
    /// The model changed its continuous states (Model Exchange importers re-read them).
    pub values_of_continuous_states_changed: bool,
    /// The model asks the importer to stop the simulation.
    pub terminate_simulation: bool,
}

impl EventUpdate {
    /// Nothing more to do; the next time event at `t`.
    pub fn next_at(t: f64) -> Self {
        EventUpdate { next_event_time: Some(t), ..Default::default() }
    }
}

/// How the layer reads and writes the variable a binding stands for, in model `M`.
///
/// The layer's own binding [`crate::Field`] (a variable declared with
/// [`crate::Variables`] and the model field it reads and writes) implements every method,
/// so a model declared that way writes no getter or setter at all. A model that keeps its
/// own binding enum (its `get_real` .. `set_boolean` dispatch on it) implements this trait
/// with nothing in it: `impl Access<MyModel> for MyBinding {}`.
pub trait Access<M>: Copy + std::fmt::Debug + Send + Sync + 'static {
    fn get_real(self, _model: &mut M) -> ModelResult<f64> {
        Err("not a Real".into())
    }
    fn set_real(self, _model: &mut M, _value: f64) -> ModelResult {
        Err("not a Real".into())
    }
    fn get_integer(self, _model: &mut M) -> ModelResult<i32> {
        Err("not an Integer".into())
    }
    fn set_integer(self, _model: &mut M, _value: i32) -> ModelResult {
        Err("not an Integer".into())
    }
    fn get_boolean(self, _model: &mut M) -> ModelResult<bool> {
        Err("not a Boolean".into())
    }
    fn set_boolean(self, _model: &mut M, _value: bool) -> ModelResult {
        Err("not a Boolean".into())
    }
    /// See [`Model::setter_may_refuse`]. Default: `true` (safe).
    fn may_refuse(self) -> bool {
        true
    }
}

/// A model behind the FMI layer.
///
/// Variables are addressed by the model's own `Binding` (taken from its [`Declaration`]);
/// the layer has already checked the value reference, the base type, whether the
/// variable may be set now, that a Real is finite, that a Boolean is 0 or 1 and that an
/// Enumeration value is one of its items. Errors are [`ModelError`]s: the layer logs them
/// with the function's name and returns the status.
///
/// Only [`Model::declaration`] and [`Model::instantiate`] are required; everything else
/// has a default:
/// - the getters and setters go through the binding ([`Access`]): with the layer's
///   [`crate::Field`] they read and write the fields the declaration names, and a set of a
///   parameter calls [`Model::parameters_changed`];
/// - a model without continuous states needs no `do_step`: the layer runs its time events
///   ([`Model::event_update`]) inside `fmi2DoStep`;
/// - FMU state save/load comes from the declaration (every parameter, input, continuous
///   and discrete variable through the getters and setters) plus
///   [`Model::save_internal`] / [`Model::load_internal`] for data not declared as a variable.
pub trait Model: Clone + Send + Sized + 'static {
    type Binding: Access<Self>;

    /// The declaration (variables, units, interfaces, capabilities), built once: write
    /// [`crate::declare_model!`] in place of this function.
    fn declaration() -> &'static Declaration<Self::Binding>;

    /// A fresh instance. The layer then applies every declared start value through the
    /// setters, so the declaration is the one place start values live.
    fn instantiate(context: &InstantiateContext) -> ModelResult<Self>;

    #[inline(always)]
    fn get_real(&mut self, binding: Self::Binding) -> ModelResult<f64> {
        binding.get_real(self)
    }

    /// Sets one variable. The contract of every setter (`set_real`, `set_integer`,
    /// `set_boolean`), on which the layer's all-or-nothing `fmi2Set*` rests (it makes no
    /// copy of the model per call):
    /// - a setter that returns `Err` leaves the model unchanged;
    /// - a setter changes its variable and at most what is calculated from it (a state
    ///   from its start parameter, a cache), so that setting a settable variable back to
    ///   the value its getter returned before undoes the set.
    ///
    /// When the model refuses the k-th value of a call, the layer puts values 1 .. k-1
    /// back that way, newest first (states the model accepted on the way in). A call
    /// whose variables the model never refuses ([`Model::setter_may_refuse`]) keeps no
    /// earlier values at all.
    #[inline(always)]
    fn set_real(&mut self, binding: Self::Binding, value: f64) -> ModelResult {
        binding.set_real(self, value)
    }

    /// Called by the layer's [`crate::Field`] binding after a parameter (fixed or tunable)
    /// was set: the one place a model learns that a parameter changed (to empty a cache of
    /// what it computed from them). Default: nothing.
    fn parameters_changed(&mut self) {}

    /// Whether a setter of `binding` can refuse a value that passed the layer's checks
    /// (known value reference, base type, settable in the current state, finite, declared
    /// min/max, enumeration items). Answer `false` only where the setter has no check of
    /// its own beyond those (an input without a model-side range, a state): `fmi2Set*` of
    /// such variables only then skips keeping their earlier values for the way back, which
    /// is the all-or-nothing rule's whole cost on the hot path. Default: the binding's
    /// answer ([`Access::may_refuse`]: a [`crate::Field`] knows it).
    #[inline(always)]
    fn setter_may_refuse(binding: Self::Binding) -> bool {
        binding.may_refuse()
    }

    /// Integers and Enumerations.
    fn get_integer(&mut self, binding: Self::Binding) -> ModelResult<i32> {
        binding.get_integer(self)
    }
    fn set_integer(&mut self, binding: Self::Binding, value: i32) -> ModelResult {
        binding.set_integer(self, value)
    }
    fn get_boolean(&mut self, binding: Self::Binding) -> ModelResult<bool> {
        binding.get_boolean(self)
    }
    fn set_boolean(&mut self, binding: Self::Binding, value: bool) -> ModelResult {
        binding.set_boolean(self, value)
    }

    /// Checks the parameters as a whole when initialization ends, and after a serialized
    /// FMU state was loaded (so a state file cannot hold what the setters would refuse).
    fn exit_initialization(&mut self) -> ModelResult {
        Ok(())
    }

    /// An event at `time`: the initial event (at the start time, right after
    /// initialization in both interfaces), and every time the `next_event_time` it
    /// returned is reached. A sampled model computes its sample here and returns the next
    /// sample instant. Default: no events.
    fn event_update(&mut self, _time: f64) -> ModelResult<EventUpdate> {
        Ok(EventUpdate::default())
    }

    /// A sampled model's period \[s\] ([`crate::sampled`]): the layer then keeps the sample
    /// clock and calls [`Model::sample`] instead of [`Model::event_update`]. Read when
    /// initialization ends (a period parameter is fixed from then on). Default: not sampled.
    fn sample_period(&self) -> Option<f64> {
        None
    }

    /// The last sample of a sampled model, if it has one (a reference of finite length).
    fn sample_end(&self) -> Option<SampleEnd> {
        None
    }

    /// Sample `k` at `time` = start + k period, with the inputs and tunable parameters of
    /// that instant: compute and latch the held outputs. Before sample 0 has run, the
    /// layer answers reads of the discrete outputs by running sample 0 on a copy of the
    /// model (in Initialization Mode too: `sample(0, ..)` must then work with the
    /// parameters alone).
    fn sample(&mut self, _k: u64, _time: f64) -> ModelResult {
        Ok(())
    }

    /// Co-Simulation: advance the continuous states from `time` by `step` with inputs held.
    /// The layer has already split the communication step at the time events, so there
    /// is no event strictly inside `(time, time + step)`. The default serves models
    /// without continuous states (it does nothing).
    fn do_step(&mut self, _time: f64, _step: f64) -> ModelResult {
        if Self::declaration().number_of_states() == 0 {
            Ok(())
        } else {
            Err("the model has continuous states but implements no Co-Simulation do_step".into())
        }
    }

    /// Model Exchange: the importer's time (for time-dependent models).
    fn set_time(&mut self, _time: f64) {}

    /// Whether [`Model::directional_derivative`] takes `known` as a known (the layer has
    /// checked that it is one of the current mode: an input, a continuous state, or in
    /// Initialization Mode a variable with `initial="exact"`); if not, the layer refuses the
    /// call naming the variable. Default: every known.
    fn provides_derivative_with_respect_to(_known: Self::Binding, _initialization: bool) -> bool {
        true
    }

    /// Exact directional derivative `dv_unknown = J dv_known`, J = d unknowns / d knowns.
    /// Called only when the declaration opts in to `directional_derivatives`, with knowns
    /// and unknowns the layer checked (see [`Model::provides_derivative_with_respect_to`]).
    fn directional_derivative(
        &mut self,
        _unknowns: &[Self::Binding],
        _knowns: &[Self::Binding],
        _dv_known: &[f64],
        _dv_unknown: &mut [f64],
    ) -> ModelResult {
        Err("not supported (providesDirectionalDerivative is false)".into())
    }

    /// Whether the serialized FMU state holds the declared variables (through the getters
    /// and setters, with the setters' checks). A model that keeps its whole state its own
    /// way sets this to `false` and writes everything in [`Model::save_internal`] /
    /// [`Model::load_internal`] (the override; `exit_initialization` still checks the result).
    const SAVE_DECLARED_VARIABLES: bool = true;

    /// Internal data that is not a declared variable (a sample counter, say), appended
    /// to the FMU state after the declared variables. Bit-exact as f64.
    fn save_internal(&self, _out: &mut Vec<f64>) {}
    /// Restores what [`Model::save_internal`] wrote (exactly those numbers).
    fn load_internal(&mut self, data: &[f64]) -> ModelResult {
        if data.is_empty() {
            Ok(())
        } else {
            Err(format!("{} internal numbers, the model keeps none", data.len()).into())
        }
    }
}

/// [`Model::declaration`] from a [`DeclarationSpec`](crate::DeclarationSpec): the function
/// that builds the declaration once per process (in a `OnceLock`, at the first call) from
/// the expression `$spec` and returns it from then on. Written in the `impl Model` with the
/// model's binding type: `fmi_export::declare_model!(Field<MyModel>, build_declaration());`.
/// An invalid declaration is a programming error: the first call panics with the reason
/// (every FMU crate's tests call it).
#[macro_export]
macro_rules! declare_model {
    ($binding:ty, $spec:expr) => {
        fn declaration() -> &'static $crate::Declaration<$binding> {
            static DECLARATION: ::std::sync::OnceLock<$crate::Declaration<$binding>> = ::std::sync::OnceLock::new();
            DECLARATION.get_or_init(|| {
                $crate::Declaration::new($spec)
                    .unwrap_or_else(|e| panic!("the declaration of {} is invalid: {e}", stringify!($binding)))
            })
        }
    };
}

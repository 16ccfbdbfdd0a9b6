//! The one shared FMI export layer of nigel-fmi, for FMI 2.0 and FMI 3.0 from one
//! declaration.
//!
//! A model implements the safe [`Model`] trait and declares its variables once in a
//! [`DeclarationSpec`]; this crate owns everything else: both C ABIs (the 44 `fmi2*` and
//! the 75 `fmi3*` functions, one table [`abi::table`], exported unmangled from one library
//! by [`export_fmi!`]), the
//! instance state machine (one table of allowed states for both generations, [`states`]),
//! the GUID / instantiation-token check, typed logging through the importer's callback
//! ([`Logger`]), time events and event iteration, FMU state get/set/serialize, directional
//! and adjoint derivatives, and the generation of both `modelDescription.xml` files from
//! the same declaration the binary dispatches on.
//!
//! # One declaration, two generations
//!
//! The shape of the layer: one [`instance::Instance`] (the state machine, the variable
//! table, the semantics) under two thin C ABIs, [`abi::fmi2`] and [`abi::fmi3`], which
//! only turn pointers into slices and value references into rows. A model gets both
//! generations without writing anything per generation:
//!
//! - [`Declaration::xml`] is the FMI 2.0 `modelDescription.xml`, [`Declaration::xml3`]
//!   the FMI 3.0 one ([`Declaration::model_description3`] as types): the same variables,
//!   names, causalities, variabilities, initial, units, ranges, starts and descriptions as
//!   typed elements (Real as `Float64`, Integer as `Int32`, Boolean, an enumeration as
//!   `Enumeration` with its `<EnumerationType>`), the independent variable `time` at value
//!   reference 0 and declaration row `r` at value reference `r + 1` (pinned next to the
//!   FMI 2.0 ones in each FMU's value-reference table), the FMI 2.0 GUID as
//!   `instantiationToken` (one library checks either), the ModelStructure by value
//!   reference, `providesAdjointDerivatives` wherever directional derivatives are declared.
//! - FMI 3.0 reads and writes an Enumeration through `fmi3GetInt64`/`fmi3SetInt64`; any
//!   type the model has no variable of (Float32, the 8/16-bit and unsigned integers,
//!   String, Binary, Clock) is an error naming the value reference and its actual type.
//! - `fmi3GetAdjointDerivative` is `J^T w` computed by the layer from the columns of `J`
//!   (one [`Model::directional_derivative`] per known, then the transposed product: exact
//!   to rounding), in every mode the directional derivatives are offered.
//! - Co-Simulation without Event Mode, early return or intermediate update; Model Exchange
//!   with `fmi3UpdateDiscreteStates` in place of `fmi2NewDiscreteStates`. The functions of
//!   features the FMUs do not declare (Scheduled Execution, clocks, Configuration Mode,
//!   `fmi3EvaluateDiscreteStates`, `fmi3GetOutputDerivatives`, `fmi3EnterStepMode`) answer
//!   `fmi3Error` with a logged message naming the function.
//! - Clocks: a sampled model may declare its sample clock once ([`ClockDecl`] in
//!   [`DeclarationSpec::clocks`]: a periodic input clock, its interval constant or fixed,
//!   the discrete outputs it governs, its priority). The FMI 3.0 description then has the
//!   `<Clock>` (after every variable), the `clocks` attribute of the clocked outputs and
//!   `hasEventMode` in Co-Simulation; an FMI 3.0 instance samples at the importer's
//!   activations (`fmi3SetClock` in Event Mode, then `fmi3UpdateDiscreteStates`), with the
//!   same results as FMI 2.0's time events ([`instance`]'s `clocks`). The FMI 2.0
//!   description is unchanged.
//! - A serialized FMU state has one format: bytes from either generation restore into an
//!   instance of the other.
//!
//! # Where things go
//!
//! - **A new FMU** (a model): a crate of its own, as in "Writing a new FMU" below: the
//!   model type with `impl Model`, its declaration through [`declare_model!`], its symbols
//!   through [`export_fmi!`], and one entry in `build-fmu`'s list. Nothing in this crate
//!   changes.
//! - **A new FMI function** (or one that starts doing something): one row of the table in
//!   [`abi::table`] (symbol, its C type in `fmi-sys`, its [`Function`] variant, the layer
//!   function and the C parameters): the exported wrapper, its compile-time signature check
//!   and the `Function` variant come from that row. Then the layer function in
//!   [`abi::shared`] (both generations), [`abi::fmi2`] or [`abi::fmi3`] (the `Function`
//!   first, pointers to slices, one call of the instance under the shared guard: null checks, the state table, the panic catch,
//!   the logged message naming the function); the function's row of the allowed-states
//!   table in [`states`] where the standard lists it in other states than its FMI 2.0
//!   counterpart; what it does in the [`instance`] module of its concern (values, events
//!   and sampling, Model Exchange, derivatives, FMU state).
//! - **A new value type** for `fmi3Get*`/`fmi3Set*`: its `abi::fmi3::Value` implementation
//!   (the C element and the instance's access); the rows already name it.
//!
//! # Writing a new FMU
//!
//! 1. A crate `fmu-xyz` with `[lib] name = "<model identifier>"`,
//!    `crate-type = ["rlib", "cdylib"]` and a feature `fmi-export = []` (the symbols are
//!    exported only with it, so several FMU crates can be linked into one test binary).
//! 2. The declaration ([`variables`]): every variable once, with causality, start value,
//!    unit, min/max, description, and the model field it reads and writes, e.g.
//!    `v.real("beta").input(0.0).unit("rad").field(|m, _| &mut m.inputs.beta)`, which
//!    returns the variable's [`VarHandle`]; dependencies (the ModelStructure) are lists of
//!    those handles. The unit is written once, on the variable, in Modelica's syntax
//!    (`"N.m"`, `"m/s2"`): the layer derives its `<UnitDefinitions>` entry from the name
//!    ([`units`]). The layer assigns the value references (per base type, in declaration
//!    order: appending keeps the earlier ones) and each FMU pins them in a checked-in table
//!    ([`Declaration::check_pinned_value_references`]). A family `{stem}_{suffix}` (the four
//!    wheels) is one call of [`Variables::family`] (a matrix: [`Variables::family_columns`]);
//!    a value computed on reading is `.computed(..)`, a setter that checks what the
//!    declaration cannot say `.get_set(..)`; enumerations are Integers with a named type
//!    ([`Variables::enumeration`], [`enumeration_type`]); capabilities (directional
//!    derivatives, FMU state, serialization) are opt-in in [`Capabilities`]; interfaces in
//!    [`Interfaces`]. A model with special needs (the plant's states, derivatives and
//!    directional derivatives) keeps its own binding: `.bind(MyBinding::X)` and its own
//!    `get_real` .. `set_boolean` ([`Access`]).
//! 3. `impl Model`: [`Model::declaration`] as
//!    `fmi_export::declare_model!(Field<MyModel>, build_declaration());` (built once per
//!    process from the spec) and [`Model::instantiate`]; the getters and
//!    setters come from the declaration, and [`Model::parameters_changed`] is the one hook
//!    for a model that caches what it computes from its parameters.
//!    A sampled (discrete-time) model answers [`Model::sample_period`] and implements
//!    [`Model::sample`] (latch the outputs of sample `k`); the layer keeps the clock
//!    ([`sampled`]: `t_k = start + k period` counted as integers, exact at any start time,
//!    the reads before sample 0, the clock's part of the FMU state, checked when loaded) and
//!    [`Model::sample_end`] ends the run the FMI way at a last sample. A model with other
//!    time events implements [`Model::event_update`]: it is called at the initial event
//!    (the start time) and whenever the `next_event_time` it returned is reached. Either way:
//!    - Model Exchange: `fmi2NewDiscreteStates` calls it and reports
//!      `nextEventTimeDefined`/`nextEventTime`; `newDiscreteStatesNeeded` iterates;
//!    - Co-Simulation: `fmi2DoStep` runs the events inside the step in order (a model
//!      without continuous states needs no `do_step`). Events at a step's start run with
//!      the inputs set just before it; an event exactly at a step's end runs lazily at the
//!      next read or step, and setting a value at that instant redoes it, so a sample at
//!      `t_k` always sees the inputs (and tunable parameters) of `t_k`: outputs with direct
//!      feed-through work with Gauss-Seidel and Jacobi masters alike;
//!    - FMU state save/load comes from the declaration: every parameter, input, continuous
//!      state and discrete variable through your getters and setters (so discrete outputs
//!      and discrete states must be settable by binding), plus [`Model::save_internal`] /
//!      [`Model::load_internal`] for data that is no variable (a sample counter). A loaded
//!      state goes through the same checks as `fmi2Set*` and `exit_initialization`.
//! 4. `fmi_export::export_fmi!(MyModel);` under `#[cfg(feature = "fmi-export")]` (the
//!    fmi2* and fmi3* symbols), and one entry `FmuTarget::of::<MyModel>("fmu-xyz",
//!    EQUATIONS_HTML)` in `build-fmu`'s list: the identifier, interfaces and documentation
//!    come from the declaration, and the generic C-ABI and fmpy tests then cover the new
//!    FMU in both generations (`testing::assert_cs_runs_agree` compares its two
//!    Co-Simulation runs to the bit).
//!
//! The layer checks value references, base types, the state table, who may be set when
//! (fixed parameters only before initialization ends, tunable ones between steps and in
//! event mode, continuous-time mode only continuous inputs), finite Reals, min/max, Boolean
//! 0/1 and enumeration items before the model sees a value. Errors are [`ModelError`]s:
//! `Error` (instance to the error state), `Discard` (a failed `fmi2DoStep` goes to
//! stepFailed; continue with `fmi2SetFMUstate` or `fmi2Reset`); a warning logged through
//! [`Logger::warning`] makes the call return `fmi2Warning`.
//!
//! A toy FMU with three variables, `y_k = gain u(t_k)` sampled every 10 ms:
//!
//! ```
//! use fmi_export::*;
//!
//! #[derive(Clone, Debug, Default)]
//! struct Sampler { u: f64, gain: f64, y: f64 }
//!
//! impl Model for Sampler {
//!     type Binding = Field<Sampler>;
//!     // `fn declaration()`, built once from this DeclarationSpec
//!     declare_model!(Field<Sampler>, {
//!         let mut v = Variables::<Field<Sampler>>::new();
//!         let u = v.real("u").input(0.0).field(|m, _| &mut m.u);
//!         v.real("gain").tunable_parameter(1.0).min(0.0).field(|m, _| &mut m.gain);
//!         v.real("y").discrete_output([u]).describe("gain u at the last sample").field(|m, _| &mut m.y);
//!         DeclarationSpec {
//!             model_name: "sampler",
//!             model_identifier: "sampler",
//!             description: "y_k = gain u(t_k) at t_k = k 10 ms, held",
//!             version: "1",
//!             interfaces: Interfaces { model_exchange: true, co_simulation: true },
//!             capabilities: Capabilities { fmu_state: true, serialize_fmu_state: true, ..Default::default() },
//!             variables: v.into_vec(),
//!             ..Default::default()
//!         }
//!     });
//!     fn instantiate(_: &InstantiateContext) -> ModelResult<Self> {
//!         Ok(Sampler::default())
//!     }
//!     fn sample_period(&self) -> Option<f64> {
//!         Some(0.01)
//!     }
//!     fn sample(&mut self, _k: u64, _time: f64) -> ModelResult {
//!         self.y = self.gain * self.u;
//!         Ok(())
//!     }
//! }
//! // in the FMU crate: #[cfg(feature = "fmi-export")] fmi_export::export_fmi!(Sampler);
//!
//! let d = Sampler::declaration();
//! assert_eq!(d.value_reference_table(), "u 0 1\ngain 1 2\ny 2 3\n");
//! assert!(d.xml3().contains(r#"<Output valueReference="3" dependencies="1"/>"#), "{}", d.xml3());
//! assert!(d.xml().contains(r#"<Unknown index="3" dependencies="1"/>"#), "{}", d.xml());
//! ```

//!
//! # Modules
//!
//! Each uses only those before it (no import circle): [`ffi`] (the C types), [`states`]
//! (the instance states, the allowed-calls table, who may be set when), [`sampled`] (the
//! sample clock), [`uri`], [`units`] (unit definitions from a unit's name); [`log`]
//! (categories, the logger); [`fmu_state`] (the byte format of a serialized FMU state);
//! [`decl`] (the declaration and the generated XML); [`model`] (the trait a model
//! implements); [`variables`] (declaring each variable once); [`instance`] (one instance:
//! the FMI semantics over a model, one submodule per concern); [`abi`] (the C entry points:
//! the table [`abi::table`], the layer functions [`abi::fmi2`], [`abi::fmi3`], [`abi::shared`]); with the
//! feature `testing`, `testing` (the in-process importer of the FMU crates' tests, both
//! generations). The `Function` enum of [`states`] is expanded from [`abi::table`] (a
//! macro, not an import: no circle).

// `!(x > 0.0)` is deliberate throughout: it refuses NaN together with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod abi;
pub mod decl;
pub mod ffi;
pub mod fmu_state;
pub mod instance;
pub mod log;
pub mod model;
pub mod sampled;
pub mod states;
#[cfg(feature = "testing")]
pub mod testing;
pub mod units;
pub mod uri;
pub mod variables;

pub use decl::{
    declared_name, enumeration_type, BaseType, Capabilities, Causality, ClockDecl, ClockInterval, Declaration,
    DeclarationSpec, Dependencies, Initial, Interfaces, RealReference, Start, VarDecl, VarHandle, Variability,
};
pub use fmi_sys;
pub use instance::Instance;
pub use log::{LogCategory, Logger};
pub use model::{Access, EventUpdate, InstantiateContext, Interface, Model, ModelError, ModelResult};
pub use model_description;
pub use sampled::{SampleClock, SampleEnd};
pub use states::{Function, Machine};
pub use units::si_unit;
pub use variables::{Accessor, Family, Field, FieldValue, Pending, Variables};

/// Exports the 44 FMI 2.0 and the 75 FMI 3.0 functions for model type `$model` from the
/// calling crate (which should be a `cdylib`): one library serves both generations'
/// archives. Invoke it once per shared library. The functions are the rows of
/// [`abi::table`]; each symbol is checked at compile time against its C type in `fmi-sys`
/// (`fmi2GetRealTYPE`, `fmi3DoStepTYPE`, ...).
#[macro_export]
macro_rules! export_fmi {
    ($model:ty) => {
        $crate::__fmi_function_table!([$crate::__fmi_exports] { $model });
    };
}

/// The expansion of [`export_fmi!`]: one `#[no_mangle] extern "C"` wrapper per row of the
/// table and the check of its C type.
#[doc(hidden)]
#[macro_export]
macro_rules! __fmi_exports {
    ({ $model:ty } $($generation:ident {
        $($symbol:ident : $c_type:ident = $function:ident => $module:ident :: $layer:ident $(::<$value:ident>)?
            $([$($argument:ident),*])? ( $($parameter:ident : $parameter_type:ty),* ) $(-> $return:ty)? ;)*
    })*) => {
        const _: () = {
            use ::std::ffi::{c_char, c_int};
            use $crate::fmi_sys::fmi2::{
                fmi2Boolean, fmi2Byte, fmi2Component, fmi2FMUstate, fmi2Integer, fmi2Real, fmi2Status, fmi2StatusKind,
                fmi2String, fmi2ValueReference, Fmi2CallbackFunctions, Fmi2EventInfo,
            };
            use $crate::fmi_sys::fmi3::{
                fmi3Binary, fmi3Boolean, fmi3Byte, fmi3Clock, fmi3DependencyKind, fmi3FMUState, fmi3Float32,
                fmi3Float64, fmi3Instance, fmi3InstanceEnvironment, fmi3Int16, fmi3Int32, fmi3Int64, fmi3Int8,
                fmi3IntervalQualifier, fmi3Status, fmi3String, fmi3UInt16, fmi3UInt32, fmi3UInt64, fmi3UInt8,
                fmi3ValueReference, Fmi3ClockUpdateCallback, Fmi3IntermediateUpdateCallback,
                Fmi3LockPreemptionCallback, Fmi3LogMessageCallback, Fmi3UnlockPreemptionCallback,
            };
            $($(
                #[no_mangle]
                #[allow(unused_variables, clippy::unnecessary_cast)]
                pub unsafe extern "C" fn $symbol($($parameter: $parameter_type),*) $(-> $return)? {
                    $crate::__fmi_call!(
                        [$crate::abi::$module::$layer::<$model $(, $crate::abi::$module::value::$value)?>]
                        [$crate::states::Function::$function] [$($parameter),*] $([$($argument),*])?
                    ) $(as $return)?
                }
                const _: $crate::fmi_sys::$generation::types::$c_type = $symbol;
            )*)*
        };
    };
}

/// A layer function called with the row's `Function` and the wrapper's parameters (all,
/// or those the row names in brackets).
#[doc(hidden)]
#[macro_export]
macro_rules! __fmi_call {
    ([$($layer:tt)*] [$($function:tt)*] [$($parameter:ident),*]) => {
        $($layer)*($($function)*, $($parameter),*)
    };
    ([$($layer:tt)*] [$($function:tt)*] [$($parameter:ident),*] [$($argument:ident),*]) => {
        $($layer)*($($function)*, $($argument),*)
    };
}

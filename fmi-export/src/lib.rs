//! The one shared FMI 2.0 export layer of nigel-fmi.
//!
//! A model implements the safe [`Model`] trait and declares its variables once in a
//! [`DeclarationSpec`]; this crate owns everything else: the C ABI (all 44 `fmi2*`
//! functions, exported unmangled by [`export_fmi2!`]), the instance state machine (one
//! table of allowed states, [`states`]), the GUID check, typed logging through the
//! importer's callback ([`Logger`]), time events and event iteration, FMU state
//! get/set/serialize, and the generation of `modelDescription.xml` from the same
//! declaration the binary dispatches on.
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
//! 3. `impl Model`: [`Model::declaration`] and [`Model::instantiate`]; the getters and
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
//! 4. `fmi_export::export_fmi2!(MyModel);` under `#[cfg(feature = "fmi-export")]`, and one
//!    entry `FmuTarget::of::<MyModel>("fmu-xyz", EQUATIONS_HTML)` in `build-fmu`'s list:
//!    the identifier, interfaces and documentation come from the declaration, and the
//!    generic C-ABI and fmpy tests then cover the new FMU.
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
//! use std::sync::OnceLock;
//! use fmi_export::*;
//!
//! #[derive(Clone, Debug, Default)]
//! struct Sampler { u: f64, gain: f64, y: f64 }
//!
//! impl Model for Sampler {
//!     type Binding = Field<Sampler>;
//!     fn declaration() -> &'static Declaration<Field<Sampler>> {
//!         static D: OnceLock<Declaration<Field<Sampler>>> = OnceLock::new();
//!         D.get_or_init(|| {
//!             let mut v = Variables::<Field<Sampler>>::new();
//!             let u = v.real("u").input(0.0).field(|m, _| &mut m.u);
//!             v.real("gain").tunable_parameter(1.0).min(0.0).field(|m, _| &mut m.gain);
//!             v.real("y").discrete_output([u]).describe("gain u at the last sample").field(|m, _| &mut m.y);
//!             Declaration::new(DeclarationSpec {
//!                 model_name: "sampler",
//!                 model_identifier: "sampler",
//!                 description: "y_k = gain u(t_k) at t_k = k 10 ms, held",
//!                 version: "1",
//!                 interfaces: Interfaces { model_exchange: true, co_simulation: true },
//!                 capabilities: Capabilities { fmu_state: true, serialize_fmu_state: true, ..Default::default() },
//!                 variables: v.into_vec(),
//!                 ..Default::default()
//!             })
//!             .expect("valid declaration")
//!         })
//!     }
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
//! // in the FMU crate: #[cfg(feature = "fmi-export")] fmi_export::export_fmi2!(Sampler);
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
//! the FMI semantics over a model); [`abi`] (the C entry points); with the feature
//! `testing`, `testing` (the in-process importer of the FMU crates' tests).

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
    declared_name, enumeration_type, si_unit, BaseType, Capabilities, Causality, Declaration, DeclarationSpec,
    Dependencies, Initial, Interfaces, RealReference, Start, VarDecl, VarHandle, Variability,
};
pub use instance::Instance;
pub use log::{LogCategory, Logger};
pub use model::{Access, EventUpdate, InstantiateContext, Interface, Model, ModelError, ModelResult};
pub use model_description;
pub use sampled::{SampleClock, SampleEnd};
pub use states::{Function, Machine};
pub use variables::{Accessor, Family, Field, FieldValue, Pending, Variables};

/// Exports the 44 FMI 2.0 functions for model type `$model` from the calling crate
/// (which should be a `cdylib`). Invoke it once per shared library.
#[macro_export]
macro_rules! export_fmi2 {
    ($model:ty) => {
        const _: () = {
            use ::std::ffi::{c_char, c_int};
            use $crate::abi;
            use $crate::ffi::*;
            type M = $model;

            #[no_mangle]
            pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
                abi::get_types_platform()
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetVersion() -> *const c_char {
                abi::get_version()
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetDebugLogging(
                c: fmi2Component,
                on: fmi2Boolean,
                n: usize,
                cats: *const fmi2String,
            ) -> Fmi2Status {
                abi::set_debug_logging::<M>(c, on, n, cats)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Instantiate(
                name: fmi2String,
                kind: c_int,
                guid: fmi2String,
                resources: fmi2String,
                functions: *const Fmi2CallbackFunctions,
                visible: fmi2Boolean,
                logging_on: fmi2Boolean,
            ) -> fmi2Component {
                abi::instantiate::<M>(name, kind, guid, resources, functions, visible, logging_on)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
                abi::free_instance::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetupExperiment(
                c: fmi2Component,
                tol_def: fmi2Boolean,
                tol: f64,
                start: f64,
                stop_def: fmi2Boolean,
                stop: f64,
            ) -> Fmi2Status {
                abi::setup_experiment::<M>(c, tol_def, tol, start, stop_def, stop)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> Fmi2Status {
                abi::enter_initialization_mode::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> Fmi2Status {
                abi::exit_initialization_mode::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> Fmi2Status {
                abi::terminate::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> Fmi2Status {
                abi::reset::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetReal(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *mut f64,
            ) -> Fmi2Status {
                abi::get_real::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetInteger(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *mut c_int,
            ) -> Fmi2Status {
                abi::get_integer::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBoolean(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *mut fmi2Boolean,
            ) -> Fmi2Status {
                abi::get_boolean::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetString(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *mut fmi2String,
            ) -> Fmi2Status {
                abi::get_string::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetReal(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *const f64,
            ) -> Fmi2Status {
                abi::set_real::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetInteger(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *const c_int,
            ) -> Fmi2Status {
                abi::set_integer::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetBoolean(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *const fmi2Boolean,
            ) -> Fmi2Status {
                abi::set_boolean::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetString(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *const fmi2String,
            ) -> Fmi2Status {
                abi::set_string::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, s: *mut fmi2FMUstate) -> Fmi2Status {
                abi::get_fmu_state::<M>(c, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, s: fmi2FMUstate) -> Fmi2Status {
                abi::set_fmu_state::<M>(c, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeFMUstate(c: fmi2Component, s: *mut fmi2FMUstate) -> Fmi2Status {
                abi::free_fmu_state::<M>(c, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
                c: fmi2Component,
                s: fmi2FMUstate,
                size: *mut usize,
            ) -> Fmi2Status {
                abi::serialized_fmu_state_size::<M>(c, s, size)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializeFMUstate(
                c: fmi2Component,
                s: fmi2FMUstate,
                bytes: *mut fmi2Byte,
                size: usize,
            ) -> Fmi2Status {
                abi::serialize_fmu_state::<M>(c, s, bytes, size)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
                c: fmi2Component,
                bytes: *const fmi2Byte,
                size: usize,
                s: *mut fmi2FMUstate,
            ) -> Fmi2Status {
                abi::deserialize_fmu_state::<M>(c, bytes, size, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
                c: fmi2Component,
                unknown: *const u32,
                n_unknown: usize,
                known: *const u32,
                n_known: usize,
                dv_known: *const f64,
                dv_unknown: *mut f64,
            ) -> Fmi2Status {
                abi::get_directional_derivative::<M>(c, unknown, n_unknown, known, n_known, dv_known, dv_unknown)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                order: *const c_int,
                v: *const f64,
            ) -> Fmi2Status {
                abi::set_real_input_derivatives::<M>(c, vr, n, order, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                order: *const c_int,
                v: *mut f64,
            ) -> Fmi2Status {
                abi::get_real_output_derivatives::<M>(c, vr, n, order, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DoStep(
                c: fmi2Component,
                t: f64,
                h: f64,
                no_set_prior: fmi2Boolean,
            ) -> Fmi2Status {
                abi::do_step::<M>(c, t, h, no_set_prior)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> Fmi2Status {
                abi::cancel_step::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStatus(c: fmi2Component, kind: c_int, v: *mut c_int) -> Fmi2Status {
                abi::get_status::<M>(c, kind, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealStatus(c: fmi2Component, kind: c_int, v: *mut f64) -> Fmi2Status {
                abi::get_real_status::<M>(c, kind, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetIntegerStatus(c: fmi2Component, kind: c_int, v: *mut c_int) -> Fmi2Status {
                abi::get_integer_status::<M>(c, kind, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBooleanStatus(
                c: fmi2Component,
                kind: c_int,
                v: *mut fmi2Boolean,
            ) -> Fmi2Status {
                abi::get_boolean_status::<M>(c, kind, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStringStatus(
                c: fmi2Component,
                kind: c_int,
                v: *mut fmi2String,
            ) -> Fmi2Status {
                abi::get_string_status::<M>(c, kind, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> Fmi2Status {
                abi::enter_event_mode::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2NewDiscreteStates(
                c: fmi2Component,
                info: *mut abi::Fmi2EventInfo,
            ) -> Fmi2Status {
                abi::new_discrete_states::<M>(c, info)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> Fmi2Status {
                abi::enter_continuous_time_mode::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
                c: fmi2Component,
                no_set_prior: fmi2Boolean,
                enter: *mut fmi2Boolean,
                terminate: *mut fmi2Boolean,
            ) -> Fmi2Status {
                abi::completed_integrator_step::<M>(c, no_set_prior, enter, terminate)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, t: f64) -> Fmi2Status {
                abi::set_time::<M>(c, t)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetContinuousStates(c: fmi2Component, x: *const f64, nx: usize) -> Fmi2Status {
                abi::set_continuous_states::<M>(c, x, nx)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetDerivatives(c: fmi2Component, dx: *mut f64, nx: usize) -> Fmi2Status {
                abi::get_derivatives::<M>(c, dx, nx)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetEventIndicators(c: fmi2Component, z: *mut f64, ni: usize) -> Fmi2Status {
                abi::get_event_indicators::<M>(c, z, ni)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetContinuousStates(c: fmi2Component, x: *mut f64, nx: usize) -> Fmi2Status {
                abi::get_continuous_states::<M>(c, x, nx)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
                c: fmi2Component,
                x: *mut f64,
                nx: usize,
            ) -> Fmi2Status {
                abi::get_nominals_of_continuous_states::<M>(c, x, nx)
            }
        };
    };
}

//! The one shared FMI export layer of nigel-fmi, for FMI 2.0 and FMI 3.0 from one
//! declaration.
//!
//! A model implements the safe [`Model`] trait and declares its variables once in a
//! [`DeclarationSpec`]; this crate owns everything else: both C ABIs (the 44 `fmi2*` and
//! the 75 `fmi3*` functions, exported unmangled from one library by [`export_fmi!`]), the
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
//! - A serialized FMU state has one format: bytes from either generation restore into an
//!   instance of the other.
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
//! the FMI semantics over a model); [`abi`] (the C entry points: [`abi::fmi2`],
//! [`abi::fmi3`]); with the feature `testing`, `testing` (the in-process importer of the
//! FMU crates' tests, both generations).

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
pub use fmi_sys;
pub use instance::Instance;
pub use log::{LogCategory, Logger};
pub use model::{Access, EventUpdate, InstantiateContext, Interface, Model, ModelError, ModelResult};
pub use model_description;
pub use sampled::{SampleClock, SampleEnd};
pub use states::{Function, Machine};
pub use variables::{Accessor, Family, Field, FieldValue, Pending, Variables};

/// Exports the 44 FMI 2.0 and the 75 FMI 3.0 functions for model type `$model` from the
/// calling crate (which should be a `cdylib`): one library serves both generations'
/// archives. Invoke it once per shared library. Each `fmi3*` symbol is checked at compile
/// time against its C type in `fmi-sys` (`fmi3DoStepTYPE`, ...).
#[macro_export]
macro_rules! export_fmi {
    ($model:ty) => {
        const _: () = {
            use ::std::ffi::{c_char, c_int};
            use $crate::abi;
            use $crate::ffi::*;
            use $crate::fmi_sys::fmi3::{
                fmi3Binary, fmi3Boolean, fmi3Byte, fmi3Clock, fmi3DependencyKind, fmi3FMUState, fmi3Float32,
                fmi3Float64, fmi3Instance, fmi3InstanceEnvironment, fmi3Int16, fmi3Int32, fmi3Int64, fmi3Int8,
                fmi3IntervalQualifier, fmi3Status, fmi3String, fmi3UInt16, fmi3UInt32, fmi3UInt64, fmi3UInt8,
                fmi3ValueReference, types, Fmi3ClockUpdateCallback, Fmi3IntermediateUpdateCallback,
                Fmi3LockPreemptionCallback, Fmi3LogMessageCallback, Fmi3UnlockPreemptionCallback,
            };
            use $crate::states::Function;
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

            // ---------------------------------------------------------------- FMI 3.0
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetVersion() -> *const c_char {
                abi::fmi3::get_version()
            }
            const _: types::fmi3GetVersionTYPE = fmi3GetVersion;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3FreeInstance(a0: fmi3Instance) {
                abi::fmi3::free_instance::<M>(a0)
            }
            const _: types::fmi3FreeInstanceTYPE = fmi3FreeInstance;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterInitializationMode(
                a0: fmi3Instance,
                a1: fmi3Boolean,
                a2: fmi3Float64,
                a3: fmi3Float64,
                a4: fmi3Boolean,
                a5: fmi3Float64,
            ) -> fmi3Status {
                abi::fmi3::enter_initialization_mode::<M>(a0, a1, a2, a3, a4, a5) as fmi3Status
            }
            const _: types::fmi3EnterInitializationModeTYPE = fmi3EnterInitializationMode;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3ExitInitializationMode(a0: fmi3Instance) -> fmi3Status {
                abi::fmi3::exit_initialization_mode::<M>(a0) as fmi3Status
            }
            const _: types::fmi3ExitInitializationModeTYPE = fmi3ExitInitializationMode;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3Terminate(a0: fmi3Instance) -> fmi3Status {
                abi::fmi3::terminate::<M>(a0) as fmi3Status
            }
            const _: types::fmi3TerminateTYPE = fmi3Terminate;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetFloat64(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3Float64,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_float64::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetFloat64TYPE = fmi3GetFloat64;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetFloat64(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Float64,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_float64::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetFloat64TYPE = fmi3SetFloat64;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetDebugLogging(
                a0: fmi3Instance,
                a1: fmi3Boolean,
                a2: usize,
                a3: *const fmi3String,
            ) -> fmi3Status {
                abi::fmi3::set_debug_logging::<M>(a0, a1, a2, a3) as fmi3Status
            }
            const _: types::fmi3SetDebugLoggingTYPE = fmi3SetDebugLogging;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3InstantiateModelExchange(
                a0: fmi3String,
                a1: fmi3String,
                a2: fmi3String,
                a3: fmi3Boolean,
                a4: fmi3Boolean,
                a5: fmi3InstanceEnvironment,
                a6: Option<Fmi3LogMessageCallback>,
            ) -> fmi3Instance {
                abi::fmi3::instantiate_model_exchange::<M>(a0, a1, a2, a3, a4, a5, a6)
            }
            const _: types::fmi3InstantiateModelExchangeTYPE = fmi3InstantiateModelExchange;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
                a0: fmi3String,
                a1: fmi3String,
                a2: fmi3String,
                a3: fmi3Boolean,
                a4: fmi3Boolean,
                a5: fmi3Boolean,
                a6: fmi3Boolean,
                a7: *const fmi3ValueReference,
                a8: usize,
                a9: fmi3InstanceEnvironment,
                a10: Option<Fmi3LogMessageCallback>,
                a11: Option<Fmi3IntermediateUpdateCallback>,
            ) -> fmi3Instance {
                abi::fmi3::instantiate_co_simulation::<M>(a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10, a11)
            }
            const _: types::fmi3InstantiateCoSimulationTYPE = fmi3InstantiateCoSimulation;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
                a0: fmi3String,
                a1: fmi3String,
                a2: fmi3String,
                a3: fmi3Boolean,
                a4: fmi3Boolean,
                a5: fmi3InstanceEnvironment,
                a6: Option<Fmi3LogMessageCallback>,
                a7: Option<Fmi3ClockUpdateCallback>,
                a8: Option<Fmi3LockPreemptionCallback>,
                a9: Option<Fmi3UnlockPreemptionCallback>,
            ) -> fmi3Instance {
                abi::fmi3::instantiate_scheduled_execution::<M>(a0, a1, a2, a3, a4, a5, a6, a7, a8, a9)
            }
            const _: types::fmi3InstantiateScheduledExecutionTYPE = fmi3InstantiateScheduledExecution;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterEventMode(a0: fmi3Instance) -> fmi3Status {
                abi::fmi3::enter_event_mode::<M>(a0) as fmi3Status
            }
            const _: types::fmi3EnterEventModeTYPE = fmi3EnterEventMode;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3Reset(a0: fmi3Instance) -> fmi3Status {
                abi::fmi3::reset::<M>(a0) as fmi3Status
            }
            const _: types::fmi3ResetTYPE = fmi3Reset;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetFloat32(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3Float32,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_float32::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetFloat32TYPE = fmi3GetFloat32;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetInt8(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3Int8,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_int8::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetInt8TYPE = fmi3GetInt8;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetUInt8(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3UInt8,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_uint8::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetUInt8TYPE = fmi3GetUInt8;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetInt16(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3Int16,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_int16::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetInt16TYPE = fmi3GetInt16;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetUInt16(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3UInt16,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_uint16::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetUInt16TYPE = fmi3GetUInt16;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetInt32(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3Int32,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_int32::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetInt32TYPE = fmi3GetInt32;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetUInt32(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3UInt32,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_uint32::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetUInt32TYPE = fmi3GetUInt32;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetInt64(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3Int64,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_int64::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetInt64TYPE = fmi3GetInt64;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetUInt64(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3UInt64,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_uint64::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetUInt64TYPE = fmi3GetUInt64;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetBoolean(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3Boolean,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_boolean::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetBooleanTYPE = fmi3GetBoolean;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetString(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3String,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::get_string::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3GetStringTYPE = fmi3GetString;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetBinary(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut usize,
                a4: *mut fmi3Binary,
                a5: usize,
            ) -> fmi3Status {
                abi::fmi3::get_binary::<M>(a0, a1, a2, a3, a4, a5) as fmi3Status
            }
            const _: types::fmi3GetBinaryTYPE = fmi3GetBinary;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetClock(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3Clock,
            ) -> fmi3Status {
                abi::fmi3::get_clock::<M>(a0, a1, a2, a3) as fmi3Status
            }
            const _: types::fmi3GetClockTYPE = fmi3GetClock;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetFloat32(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Float32,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_float32::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetFloat32TYPE = fmi3SetFloat32;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetInt8(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Int8,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_int8::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetInt8TYPE = fmi3SetInt8;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetUInt8(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3UInt8,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_uint8::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetUInt8TYPE = fmi3SetUInt8;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetInt16(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Int16,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_int16::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetInt16TYPE = fmi3SetInt16;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetUInt16(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3UInt16,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_uint16::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetUInt16TYPE = fmi3SetUInt16;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetInt32(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Int32,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_int32::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetInt32TYPE = fmi3SetInt32;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetUInt32(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3UInt32,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_uint32::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetUInt32TYPE = fmi3SetUInt32;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetInt64(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Int64,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_int64::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetInt64TYPE = fmi3SetInt64;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetUInt64(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3UInt64,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_uint64::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetUInt64TYPE = fmi3SetUInt64;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetBoolean(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Boolean,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_boolean::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetBooleanTYPE = fmi3SetBoolean;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetString(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3String,
                a4: usize,
            ) -> fmi3Status {
                abi::fmi3::set_string::<M>(a0, a1, a2, a3, a4) as fmi3Status
            }
            const _: types::fmi3SetStringTYPE = fmi3SetString;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetBinary(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const usize,
                a4: *const fmi3Binary,
                a5: usize,
            ) -> fmi3Status {
                abi::fmi3::set_binary::<M>(a0, a1, a2, a3, a4, a5) as fmi3Status
            }
            const _: types::fmi3SetBinaryTYPE = fmi3SetBinary;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetClock(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Clock,
            ) -> fmi3Status {
                abi::fmi3::set_clock::<M>(a0, a1, a2, a3) as fmi3Status
            }
            const _: types::fmi3SetClockTYPE = fmi3SetClock;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
                a0: fmi3Instance,
                a1: fmi3ValueReference,
                a2: *mut usize,
            ) -> fmi3Status {
                abi::fmi3::get_number_of_variable_dependencies::<M>(a0, a1, a2) as fmi3Status
            }
            const _: types::fmi3GetNumberOfVariableDependenciesTYPE = fmi3GetNumberOfVariableDependencies;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetVariableDependencies(
                a0: fmi3Instance,
                a1: fmi3ValueReference,
                a2: *mut usize,
                a3: *mut fmi3ValueReference,
                a4: *mut usize,
                a5: *mut fmi3DependencyKind,
                a6: usize,
            ) -> fmi3Status {
                abi::fmi3::get_variable_dependencies::<M>(a0, a1, a2, a3, a4, a5, a6) as fmi3Status
            }
            const _: types::fmi3GetVariableDependenciesTYPE = fmi3GetVariableDependencies;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetFMUState(a0: fmi3Instance, a1: *mut fmi3FMUState) -> fmi3Status {
                abi::fmi3::get_fmu_state::<M>(a0, a1) as fmi3Status
            }
            const _: types::fmi3GetFMUStateTYPE = fmi3GetFMUState;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetFMUState(a0: fmi3Instance, a1: fmi3FMUState) -> fmi3Status {
                abi::fmi3::set_fmu_state::<M>(a0, a1) as fmi3Status
            }
            const _: types::fmi3SetFMUStateTYPE = fmi3SetFMUState;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3FreeFMUState(a0: fmi3Instance, a1: *mut fmi3FMUState) -> fmi3Status {
                abi::fmi3::free_fmu_state::<M>(a0, a1) as fmi3Status
            }
            const _: types::fmi3FreeFMUStateTYPE = fmi3FreeFMUState;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
                a0: fmi3Instance,
                a1: fmi3FMUState,
                a2: *mut usize,
            ) -> fmi3Status {
                abi::fmi3::serialized_fmu_state_size::<M>(a0, a1, a2) as fmi3Status
            }
            const _: types::fmi3SerializedFMUStateSizeTYPE = fmi3SerializedFMUStateSize;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SerializeFMUState(
                a0: fmi3Instance,
                a1: fmi3FMUState,
                a2: *mut fmi3Byte,
                a3: usize,
            ) -> fmi3Status {
                abi::fmi3::serialize_fmu_state::<M>(a0, a1, a2, a3) as fmi3Status
            }
            const _: types::fmi3SerializeFMUStateTYPE = fmi3SerializeFMUState;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3DeserializeFMUState(
                a0: fmi3Instance,
                a1: *const fmi3Byte,
                a2: usize,
                a3: *mut fmi3FMUState,
            ) -> fmi3Status {
                abi::fmi3::deserialize_fmu_state::<M>(a0, a1, a2, a3) as fmi3Status
            }
            const _: types::fmi3DeserializeFMUStateTYPE = fmi3DeserializeFMUState;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3ValueReference,
                a4: usize,
                a5: *const fmi3Float64,
                a6: usize,
                a7: *mut fmi3Float64,
                a8: usize,
            ) -> fmi3Status {
                abi::fmi3::get_directional_derivative::<M>(a0, a1, a2, a3, a4, a5, a6, a7, a8) as fmi3Status
            }
            const _: types::fmi3GetDirectionalDerivativeTYPE = fmi3GetDirectionalDerivative;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetAdjointDerivative(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3ValueReference,
                a4: usize,
                a5: *const fmi3Float64,
                a6: usize,
                a7: *mut fmi3Float64,
                a8: usize,
            ) -> fmi3Status {
                abi::fmi3::get_adjoint_derivative::<M>(a0, a1, a2, a3, a4, a5, a6, a7, a8) as fmi3Status
            }
            const _: types::fmi3GetAdjointDerivativeTYPE = fmi3GetAdjointDerivative;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterConfigurationMode(a0: fmi3Instance) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3EnterConfigurationMode) as fmi3Status
            }
            const _: types::fmi3EnterConfigurationModeTYPE = fmi3EnterConfigurationMode;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3ExitConfigurationMode(a0: fmi3Instance) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3ExitConfigurationMode) as fmi3Status
            }
            const _: types::fmi3ExitConfigurationModeTYPE = fmi3ExitConfigurationMode;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetIntervalDecimal(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3Float64,
                a4: *mut fmi3IntervalQualifier,
            ) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3GetIntervalDecimal) as fmi3Status
            }
            const _: types::fmi3GetIntervalDecimalTYPE = fmi3GetIntervalDecimal;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetIntervalFraction(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3UInt64,
                a4: *mut fmi3UInt64,
                a5: *mut fmi3IntervalQualifier,
            ) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3GetIntervalFraction) as fmi3Status
            }
            const _: types::fmi3GetIntervalFractionTYPE = fmi3GetIntervalFraction;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetShiftDecimal(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3Float64,
            ) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3GetShiftDecimal) as fmi3Status
            }
            const _: types::fmi3GetShiftDecimalTYPE = fmi3GetShiftDecimal;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetShiftFraction(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *mut fmi3UInt64,
                a4: *mut fmi3UInt64,
            ) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3GetShiftFraction) as fmi3Status
            }
            const _: types::fmi3GetShiftFractionTYPE = fmi3GetShiftFraction;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetIntervalDecimal(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Float64,
            ) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3SetIntervalDecimal) as fmi3Status
            }
            const _: types::fmi3SetIntervalDecimalTYPE = fmi3SetIntervalDecimal;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetIntervalFraction(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3UInt64,
                a4: *const fmi3UInt64,
            ) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3SetIntervalFraction) as fmi3Status
            }
            const _: types::fmi3SetIntervalFractionTYPE = fmi3SetIntervalFraction;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetShiftDecimal(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Float64,
            ) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3SetShiftDecimal) as fmi3Status
            }
            const _: types::fmi3SetShiftDecimalTYPE = fmi3SetShiftDecimal;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetShiftFraction(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3UInt64,
                a4: *const fmi3UInt64,
            ) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3SetShiftFraction) as fmi3Status
            }
            const _: types::fmi3SetShiftFractionTYPE = fmi3SetShiftFraction;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(a0: fmi3Instance) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3EvaluateDiscreteStates) as fmi3Status
            }
            const _: types::fmi3EvaluateDiscreteStatesTYPE = fmi3EvaluateDiscreteStates;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
                a0: fmi3Instance,
                a1: *mut fmi3Boolean,
                a2: *mut fmi3Boolean,
                a3: *mut fmi3Boolean,
                a4: *mut fmi3Boolean,
                a5: *mut fmi3Boolean,
                a6: *mut fmi3Float64,
            ) -> fmi3Status {
                abi::fmi3::update_discrete_states::<M>(a0, a1, a2, a3, a4, a5, a6) as fmi3Status
            }
            const _: types::fmi3UpdateDiscreteStatesTYPE = fmi3UpdateDiscreteStates;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(a0: fmi3Instance) -> fmi3Status {
                abi::fmi3::enter_continuous_time_mode::<M>(a0) as fmi3Status
            }
            const _: types::fmi3EnterContinuousTimeModeTYPE = fmi3EnterContinuousTimeMode;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
                a0: fmi3Instance,
                a1: fmi3Boolean,
                a2: *mut fmi3Boolean,
                a3: *mut fmi3Boolean,
            ) -> fmi3Status {
                abi::fmi3::completed_integrator_step::<M>(a0, a1, a2, a3) as fmi3Status
            }
            const _: types::fmi3CompletedIntegratorStepTYPE = fmi3CompletedIntegratorStep;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetTime(a0: fmi3Instance, a1: fmi3Float64) -> fmi3Status {
                abi::fmi3::set_time::<M>(a0, a1) as fmi3Status
            }
            const _: types::fmi3SetTimeTYPE = fmi3SetTime;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetContinuousStates(
                a0: fmi3Instance,
                a1: *const fmi3Float64,
                a2: usize,
            ) -> fmi3Status {
                abi::fmi3::set_continuous_states::<M>(a0, a1, a2) as fmi3Status
            }
            const _: types::fmi3SetContinuousStatesTYPE = fmi3SetContinuousStates;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(
                a0: fmi3Instance,
                a1: *mut fmi3Float64,
                a2: usize,
            ) -> fmi3Status {
                abi::fmi3::get_continuous_state_derivatives::<M>(a0, a1, a2) as fmi3Status
            }
            const _: types::fmi3GetContinuousStateDerivativesTYPE = fmi3GetContinuousStateDerivatives;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetEventIndicators(
                a0: fmi3Instance,
                a1: *mut fmi3Float64,
                a2: usize,
            ) -> fmi3Status {
                abi::fmi3::get_event_indicators::<M>(a0, a1, a2) as fmi3Status
            }
            const _: types::fmi3GetEventIndicatorsTYPE = fmi3GetEventIndicators;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetContinuousStates(
                a0: fmi3Instance,
                a1: *mut fmi3Float64,
                a2: usize,
            ) -> fmi3Status {
                abi::fmi3::get_continuous_states::<M>(a0, a1, a2) as fmi3Status
            }
            const _: types::fmi3GetContinuousStatesTYPE = fmi3GetContinuousStates;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(
                a0: fmi3Instance,
                a1: *mut fmi3Float64,
                a2: usize,
            ) -> fmi3Status {
                abi::fmi3::get_nominals_of_continuous_states::<M>(a0, a1, a2) as fmi3Status
            }
            const _: types::fmi3GetNominalsOfContinuousStatesTYPE = fmi3GetNominalsOfContinuousStates;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(a0: fmi3Instance, a1: *mut usize) -> fmi3Status {
                abi::fmi3::get_number_of_event_indicators::<M>(a0, a1) as fmi3Status
            }
            const _: types::fmi3GetNumberOfEventIndicatorsTYPE = fmi3GetNumberOfEventIndicators;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(a0: fmi3Instance, a1: *mut usize) -> fmi3Status {
                abi::fmi3::get_number_of_continuous_states::<M>(a0, a1) as fmi3Status
            }
            const _: types::fmi3GetNumberOfContinuousStatesTYPE = fmi3GetNumberOfContinuousStates;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterStepMode(a0: fmi3Instance) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3EnterStepMode) as fmi3Status
            }
            const _: types::fmi3EnterStepModeTYPE = fmi3EnterStepMode;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetOutputDerivatives(
                a0: fmi3Instance,
                a1: *const fmi3ValueReference,
                a2: usize,
                a3: *const fmi3Int32,
                a4: *mut fmi3Float64,
                a5: usize,
            ) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3GetOutputDerivatives) as fmi3Status
            }
            const _: types::fmi3GetOutputDerivativesTYPE = fmi3GetOutputDerivatives;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3DoStep(
                a0: fmi3Instance,
                a1: fmi3Float64,
                a2: fmi3Float64,
                a3: fmi3Boolean,
                a4: *mut fmi3Boolean,
                a5: *mut fmi3Boolean,
                a6: *mut fmi3Boolean,
                a7: *mut fmi3Float64,
            ) -> fmi3Status {
                abi::fmi3::do_step::<M>(a0, a1, a2, a3, a4, a5, a6, a7) as fmi3Status
            }
            const _: types::fmi3DoStepTYPE = fmi3DoStep;
            #[no_mangle]
            pub unsafe extern "C" fn fmi3ActivateModelPartition(
                a0: fmi3Instance,
                a1: fmi3ValueReference,
                a2: fmi3Float64,
            ) -> fmi3Status {
                abi::fmi3::undeclared::<M>(a0, Function::Fmi3ActivateModelPartition) as fmi3Status
            }
            const _: types::fmi3ActivateModelPartitionTYPE = fmi3ActivateModelPartition;
        };
    };
}

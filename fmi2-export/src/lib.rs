//! The one shared FMI 2.0 export layer of nigel-fmi.
//!
//! A model implements the safe [`Model`] trait and declares its variables once in a
//! [`Declaration`]; this crate owns everything else: the C ABI (all 44 `fmi2*` functions,
//! exported unmangled by [`export_fmi2!`]), the instance state machine, the GUID check,
//! logging through the importer's callback, FMU state get/set/serialize, and the
//! generation of `modelDescription.xml` from the same declaration the binary dispatches on.

// `!(x > 0.0)` is deliberate throughout: it refuses NaN together with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod abi;
pub mod decl;
pub mod ffi;
pub mod instance;
pub mod model;
pub mod uri;

pub use decl::{
    si_unit, BaseType, Causality, Declaration, DeclarationSpec, Dependencies, Initial, Interfaces, Start, VarDecl,
    Variability,
};
pub use instance::{Instance, Machine};
pub use model::{InstantiateContext, Interface, Model};
pub use model_description;

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

//! A tiny in-process importer over the layer's C entry points (`fmi_export::abi`, what
//! `export_fmi!` exports from the shared library; [`Fmu`] for FMI 2.0, [`Fmu3`] for FMI
//! 3.0), for the tests of the layer and of the FMU crates: it instantiates a model type directly, without building or loading a
//! library, and records the log (through the logger shim of `fmi-sys`, as a real importer
//! receives it) so that tests can check the messages. Behind the feature `testing`, which
//! the FMU crates enable from their dev-dependencies.
#![allow(clippy::missing_safety_doc, clippy::new_without_default)]

use std::cell::RefCell;
use std::ffi::{c_int, CString};
use std::ptr::null_mut;

use crate::abi::{self, Fmi2EventInfo};
use crate::ffi::*;
use crate::{Function, Model};
use fmi_sys::fmi2::logger::{LogEnvironment, LogMessage, LogReceiver};

/// Asserts that `M`'s value references are the ones pinned in the file
/// `value_references.txt` of the crate at `crate_dir` (its `CARGO_MANIFEST_DIR`).
pub fn assert_pinned_value_references<M: Model>(crate_dir: &str) {
    let pinned = std::path::Path::new(crate_dir).join("value_references.txt");
    M::declaration().check_pinned_value_references(&pinned).unwrap_or_else(|e| panic!("{e}"));
}

/// The log of one instance: (status, category, message), in the order logged.
#[derive(Debug, Default)]
pub struct Log(pub RefCell<Vec<(c_int, String, String)>>);

impl LogReceiver for Log {
    fn receive(&self, m: &LogMessage<'_>) {
        self.0.borrow_mut().push((m.status, m.category.to_owned(), m.message.to_owned()));
    }
}

impl Log {
    /// A boxed log to instantiate with ([`LogEnvironment::callbacks`] gives the callbacks).
    pub fn environment() -> Box<LogEnvironment<Log>> {
        Box::default()
    }
}

pub const OK: Fmi2Status = Fmi2Status::Ok;
pub const ERR: Fmi2Status = Fmi2Status::Error;
pub const DISCARD: Fmi2Status = Fmi2Status::Discard;

/// One instance of `M`, freed on drop.
pub struct Fmu<M: Model> {
    pub c: fmi2Component,
    pub log: Box<LogEnvironment<Log>>,
    _callbacks: Box<Fmi2CallbackFunctions>,
    _m: std::marker::PhantomData<M>,
}

impl<M: Model> Fmu<M> {
    /// Instantiates `M` as `kind` (`Fmi2Type` as an int) with logging on; panics with the
    /// log if the layer refuses.
    pub fn new(kind: c_int) -> Self {
        let log = Log::environment();
        let callbacks = Box::new(log.callbacks());
        let name = CString::new("test").unwrap();
        let guid = CString::new(M::declaration().guid()).unwrap();
        let c = unsafe {
            abi::instantiate::<M>(
                Function::Instantiate,
                name.as_ptr(),
                kind,
                guid.as_ptr(),
                null_mut(),
                &*callbacks,
                0,
                1,
            )
        };
        assert!(!c.is_null(), "{:?}", log.0.borrow());
        Fmu { c, log, _callbacks: callbacks, _m: std::marker::PhantomData }
    }
    pub fn cs() -> Self {
        Self::new(1)
    }
    pub fn me() -> Self {
        Self::new(0)
    }
    /// The last message logged with status Error or worse.
    pub fn last_error(&self) -> String {
        self.log.0.borrow().iter().rev().find(|r| r.0 >= 3).map(|r| r.2.clone()).unwrap_or_default()
    }
    /// The last message logged with status Discard or worse.
    pub fn last_message(&self) -> String {
        self.log.0.borrow().iter().rev().find(|r| r.0 >= 2).map(|r| r.2.clone()).unwrap_or_default()
    }
    pub fn setup(&self) -> Fmi2Status {
        unsafe { abi::setup_experiment::<M>(Function::SetupExperiment, self.c, 0, 0.0, 0.0, 0, 0.0) }
    }
    /// setup at `start` with an optional stop time, enter and exit initialization, all Ok.
    pub fn init_until(&self, start: f64, stop: Option<f64>) {
        assert_eq!(self.setup_at(start, stop), OK, "{}", self.last_error());
        assert_eq!(self.enter_init(), OK, "{}", self.last_error());
        assert_eq!(self.exit_init(), OK, "{}", self.last_error());
    }
    /// `fmi2SetupExperiment` with a start time and an optional stop time.
    pub fn setup_at(&self, start: f64, stop: Option<f64>) -> Fmi2Status {
        unsafe {
            abi::setup_experiment::<M>(
                Function::SetupExperiment,
                self.c,
                0,
                0.0,
                start,
                stop.is_some() as i32,
                stop.unwrap_or(0.0),
            )
        }
    }
    /// setup at `start`, enter and exit initialization, all Ok.
    pub fn init_at(&self, start: f64) {
        assert_eq!(self.setup_at(start, None), OK, "{}", self.last_error());
        assert_eq!(self.enter_init(), OK, "{}", self.last_error());
        assert_eq!(self.exit_init(), OK, "{}", self.last_error());
    }
    /// `fmi2GetRealStatus(fmi2LastSuccessfulTime)`.
    pub fn last_successful_time(&self) -> f64 {
        let mut t = f64::NAN;
        assert_eq!(
            unsafe { abi::get_real_status::<M>(Function::GetRealStatus, self.c, FMI2_LAST_SUCCESSFUL_TIME, &mut t) },
            OK,
            "{}",
            self.last_error()
        );
        t
    }
    /// `fmi2GetBooleanStatus(fmi2Terminated)`.
    pub fn terminated(&self) -> bool {
        let mut b = -1;
        assert_eq!(
            unsafe { abi::get_boolean_status::<M>(Function::GetBooleanStatus, self.c, FMI2_TERMINATED, &mut b) },
            OK,
            "{}",
            self.last_error()
        );
        b == 1
    }
    pub fn enter_init(&self) -> Fmi2Status {
        unsafe { abi::enter_initialization_mode::<M>(Function::EnterInitializationMode, self.c) }
    }
    pub fn exit_init(&self) -> Fmi2Status {
        unsafe { abi::exit_initialization_mode::<M>(Function::ExitInitializationMode, self.c) }
    }
    /// setup, enter and exit initialization, all Ok.
    pub fn init(&self) {
        assert_eq!(self.setup(), OK, "{}", self.last_error());
        assert_eq!(self.enter_init(), OK, "{}", self.last_error());
        assert_eq!(self.exit_init(), OK, "{}", self.last_error());
    }
    pub fn real(&self, vr: u32) -> f64 {
        let mut x = f64::NAN;
        let s = unsafe { abi::get::<M, abi::value::Real>(Function::GetReal, self.c, &vr, 1, &mut x) };
        assert_eq!(s, OK, "get_real({vr}): {}", self.last_error());
        x
    }
    pub fn reals(&self, vrs: &[u32]) -> Vec<f64> {
        vrs.iter().map(|&vr| self.real(vr)).collect()
    }
    pub fn int(&self, vr: u32) -> i32 {
        let mut x = -7;
        let s = unsafe { abi::get::<M, abi::value::Integer>(Function::GetInteger, self.c, &vr, 1, &mut x) };
        assert_eq!(s, OK, "{}", self.last_error());
        x
    }
    pub fn set_real(&self, vr: u32, x: f64) -> Fmi2Status {
        unsafe { abi::set::<M, abi::value::Real>(Function::SetReal, self.c, &vr, 1, &x) }
    }
    pub fn set_int(&self, vr: u32, x: i32) -> Fmi2Status {
        unsafe { abi::set::<M, abi::value::Integer>(Function::SetInteger, self.c, &vr, 1, &x) }
    }
    pub fn set_bool(&self, vr: u32, x: bool) -> Fmi2Status {
        let v = x as fmi2Boolean;
        unsafe { abi::set::<M, abi::value::Boolean>(Function::SetBoolean, self.c, &vr, 1, &v) }
    }
    pub fn step(&self, t: f64, h: f64) -> Fmi2Status {
        unsafe { abi::do_step::<M>(Function::DoStep, self.c, t, h, 1) }
    }
    pub fn reset(&self) -> Fmi2Status {
        unsafe { abi::reset::<M>(Function::Reset, self.c) }
    }
    /// Asserts that `status` (of a set of bad input) is fmi2Error with a message naming
    /// `name`, then that fmi2Reset recovers the instance.
    pub fn assert_refused_then_reset(&self, status: Fmi2Status, name: &str) {
        assert_eq!(status, ERR, "{name}");
        assert!(self.last_error().contains(name), "{}", self.last_error());
        assert_eq!(self.reset(), OK);
    }
    // Model Exchange
    pub fn set_time(&self, t: f64) -> Fmi2Status {
        unsafe { abi::set_time::<M>(Function::SetTime, self.c, t) }
    }
    pub fn enter_event_mode(&self) -> Fmi2Status {
        unsafe { abi::enter_event_mode::<M>(Function::EnterEventMode, self.c) }
    }
    pub fn enter_continuous_time_mode(&self) -> Fmi2Status {
        unsafe { abi::enter_continuous_time_mode::<M>(Function::EnterContinuousTimeMode, self.c) }
    }
    /// One event iteration; the next event time if defined.
    pub fn new_discrete_states(&self) -> Option<f64> {
        self.event_iteration().0
    }
    /// One event iteration: the next event time if defined, and terminateSimulation.
    pub fn event_iteration(&self) -> (Option<f64>, bool) {
        let mut info = Fmi2EventInfo::default();
        let s = unsafe { abi::new_discrete_states::<M>(Function::NewDiscreteStates, self.c, &mut info) };
        assert_eq!(s, OK, "{}", self.last_error());
        assert_eq!(info.new_discrete_states_needed, 0);
        ((info.next_event_time_defined != 0).then_some(info.next_event_time), info.terminate_simulation != 0)
    }
    /// FMU state round trip through serialization.
    pub fn serialized_state(&self) -> Vec<u8> {
        unsafe {
            let mut s: fmi2FMUstate = null_mut();
            assert_eq!(abi::get_fmu_state::<M>(Function::GetFMUstate, self.c, &mut s), OK, "{}", self.last_error());
            let mut n = 0usize;
            assert_eq!(abi::serialized_fmu_state_size::<M>(Function::SerializedFMUstateSize, self.c, s, &mut n), OK);
            let mut bytes = vec![0u8; n];
            assert_eq!(
                abi::serialize_fmu_state::<M>(
                    Function::SerializeFMUstate,
                    self.c,
                    s,
                    bytes.as_mut_ptr() as *mut fmi2Byte,
                    n
                ),
                OK
            );
            assert_eq!(abi::free_fmu_state::<M>(Function::FreeFMUstate, self.c, &mut s), OK);
            bytes
        }
    }
    pub fn restore_serialized(&self, bytes: &[u8]) -> Fmi2Status {
        unsafe {
            let mut s: fmi2FMUstate = null_mut();
            let st = abi::deserialize_fmu_state::<M>(
                Function::DeSerializeFMUstate,
                self.c,
                bytes.as_ptr() as *const fmi2Byte,
                bytes.len(),
                &mut s,
            );
            if st != OK {
                return st;
            }
            let st = abi::set_fmu_state::<M>(Function::SetFMUstate, self.c, s);
            abi::free_fmu_state::<M>(Function::FreeFMUstate, self.c, &mut s);
            st
        }
    }
}

impl<M: Model> Drop for Fmu<M> {
    fn drop(&mut self) {
        unsafe { abi::free_instance::<M>(Function::FreeInstance, self.c) }
    }
}

// ------------------------------------------------------------------ FMI 3.0

use crate::abi::fmi3::value::Float64;
use crate::abi::fmi3::{self as abi3, status3};
pub use fmi_sys::fmi3::Fmi3Status;
use fmi_sys::fmi3::{fmi3FMUState, fmi3Instance, fmi3Status, FMI3_FALSE, FMI3_TRUE};

pub const OK3: Fmi3Status = Fmi3Status::Ok;
pub const ERR3: Fmi3Status = Fmi3Status::Error;
pub const DISCARD3: Fmi3Status = Fmi3Status::Discard;

/// The importer's `fmi3LogMessageCallback`: the environment is the instance's [`Log`].
pub unsafe extern "C" fn log_message(
    environment: *mut std::ffi::c_void,
    status: fmi3Status,
    category: *const std::ffi::c_char,
    message: *const std::ffi::c_char,
) {
    let text = |p: *const std::ffi::c_char| match p.is_null() {
        true => String::new(),
        false => std::ffi::CStr::from_ptr(p).to_string_lossy().into_owned(),
    };
    if let Some(log) = (environment as *const Log).as_ref() {
        log.0.borrow_mut().push((status, text(category), text(message)));
    }
}

/// What `fmi3DoStep` reported besides its status.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutcome {
    pub status: Fmi3Status,
    pub event_handling_needed: bool,
    pub terminate_simulation: bool,
    pub early_return: bool,
    pub last_successful_time: f64,
}

/// What `fmi3UpdateDiscreteStates` reported.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscreteUpdate {
    pub discrete_states_need_update: bool,
    pub terminate_simulation: bool,
    pub next_event_time: Option<f64>,
}

/// One FMI 3.0 instance of `M` through the layer's `fmi3*` entry points, freed on drop.
pub struct Fmu3<M: Model> {
    pub c: fmi3Instance,
    pub log: Box<Log>,
    _m: std::marker::PhantomData<M>,
}

impl<M: Model> Fmu3<M> {
    /// `fmi3InstantiateCoSimulation` with `token` and `eventModeUsed`; `None` (and the log)
    /// when the layer refuses.
    pub fn try_cs(token: &str, event_mode_used: bool) -> Result<Self, Box<Log>> {
        Self::try_instantiate(token, |name, token, env| unsafe {
            abi3::instantiate_co_simulation::<M>(
                Function::Fmi3InstantiateCoSimulation,
                name,
                token,
                std::ptr::null(),
                FMI3_FALSE,
                FMI3_TRUE,
                event_mode_used as u8,
                FMI3_FALSE,
                std::ptr::null(),
                0,
                env,
                Some(log_message),
                None,
            )
        })
    }

    /// `fmi3InstantiateModelExchange` with `token`.
    pub fn try_me(token: &str) -> Result<Self, Box<Log>> {
        Self::try_instantiate(token, |name, token, env| unsafe {
            abi3::instantiate_model_exchange::<M>(
                Function::Fmi3InstantiateModelExchange,
                name,
                token,
                std::ptr::null(),
                FMI3_FALSE,
                FMI3_TRUE,
                env,
                Some(log_message),
            )
        })
    }

    /// An instance from `instantiate(instanceName, instantiationToken, instanceEnvironment)`,
    /// its log the environment; the log when the layer refuses.
    fn try_instantiate(
        token: &str,
        instantiate: impl FnOnce(*const std::ffi::c_char, *const std::ffi::c_char, *mut std::ffi::c_void) -> fmi3Instance,
    ) -> Result<Self, Box<Log>> {
        let log = Box::<Log>::default();
        let name = CString::new("test3").unwrap();
        let token = CString::new(token).unwrap();
        let env = &*log as *const Log as *mut std::ffi::c_void;
        let c = instantiate(name.as_ptr(), token.as_ptr(), env);
        if c.is_null() {
            Err(log)
        } else {
            Ok(Fmu3 { c, log, _m: std::marker::PhantomData })
        }
    }

    /// A Co-Simulation instance with the right token; panics with the log if refused.
    pub fn cs() -> Self {
        Self::try_cs(M::declaration().guid(), false).unwrap_or_else(|log| panic!("{:?}", log.0.borrow()))
    }

    /// A Model Exchange instance with the right token; panics with the log if refused.
    pub fn me() -> Self {
        Self::try_me(M::declaration().guid()).unwrap_or_else(|log| panic!("{:?}", log.0.borrow()))
    }

    /// The last message logged with status Error or worse.
    pub fn last_error(&self) -> String {
        self.log.0.borrow().iter().rev().find(|r| r.0 >= 3).map(|r| r.2.clone()).unwrap_or_default()
    }

    /// `fmi3EnterInitializationMode(start, stop)` (no tolerance).
    pub fn enter_init(&self, start: f64, stop: Option<f64>) -> Fmi3Status {
        unsafe {
            abi3::enter_initialization_mode::<M>(
                Function::Fmi3EnterInitializationMode,
                self.c,
                FMI3_FALSE,
                0.0,
                start,
                stop.is_some() as u8,
                stop.unwrap_or(0.0),
            )
        }
    }

    pub fn exit_init(&self) -> Fmi3Status {
        unsafe { status3(abi::exit_initialization_mode::<M>(Function::Fmi3ExitInitializationMode, self.c)) }
    }

    /// Enter and exit initialization at `start` with an optional stop time, all Ok.
    pub fn init_until(&self, start: f64, stop: Option<f64>) {
        assert_eq!(self.enter_init(start, stop), OK3, "{}", self.last_error());
        assert_eq!(self.exit_init(), OK3, "{}", self.last_error());
    }

    pub fn get_float64(&self, vrs: &[u32], out: &mut [f64]) -> Fmi3Status {
        let (vr, n_vr) = (vrs.as_ptr(), vrs.len());
        unsafe { abi3::get::<M, Float64>(Function::Fmi3GetFloat64, self.c, vr, n_vr, out.as_mut_ptr(), out.len()) }
    }

    pub fn float64(&self, vr: u32) -> f64 {
        let mut x = [f64::NAN];
        assert_eq!(self.get_float64(&[vr], &mut x), OK3, "fmi3GetFloat64({vr}): {}", self.last_error());
        x[0]
    }

    pub fn set_float64(&self, vrs: &[u32], values: &[f64]) -> Fmi3Status {
        let (vr, n_vr) = (vrs.as_ptr(), vrs.len());
        unsafe { abi3::set::<M, Float64>(Function::Fmi3SetFloat64, self.c, vr, n_vr, values.as_ptr(), values.len()) }
    }

    pub fn int32(&self, vr: u32) -> i32 {
        let mut x = [-7];
        let s =
            unsafe { abi3::get::<M, abi3::value::Int32>(Function::Fmi3GetInt32, self.c, &vr, 1, x.as_mut_ptr(), 1) };
        assert_eq!(s, OK3, "{}", self.last_error());
        x[0]
    }

    pub fn set_int32(&self, vr: u32, x: i32) -> Fmi3Status {
        unsafe { abi3::set::<M, abi3::value::Int32>(Function::Fmi3SetInt32, self.c, &vr, 1, &x, 1) }
    }

    pub fn int64(&self, vr: u32) -> i64 {
        let mut x = [-7];
        let s = unsafe {
            abi3::get::<M, abi3::value::Enumeration>(Function::Fmi3GetInt64, self.c, &vr, 1, x.as_mut_ptr(), 1)
        };
        assert_eq!(s, OK3, "{}", self.last_error());
        x[0]
    }

    pub fn set_int64(&self, vr: u32, x: i64) -> Fmi3Status {
        unsafe { abi3::set::<M, abi3::value::Enumeration>(Function::Fmi3SetInt64, self.c, &vr, 1, &x, 1) }
    }

    pub fn boolean(&self, vr: u32) -> bool {
        let mut x = [7u8];
        let s = unsafe {
            abi3::get::<M, abi3::value::Boolean>(Function::Fmi3GetBoolean, self.c, &vr, 1, x.as_mut_ptr(), 1)
        };
        assert_eq!(s, OK3, "{}", self.last_error());
        x[0] != 0
    }

    pub fn set_boolean(&self, vr: u32, x: bool) -> Fmi3Status {
        let b = x as u8;
        unsafe { abi3::set::<M, abi3::value::Boolean>(Function::Fmi3SetBoolean, self.c, &vr, 1, &b, 1) }
    }

    /// `fmi3DoStep` and its outputs.
    pub fn step(&self, t: f64, h: f64) -> StepOutcome {
        let (mut event, mut terminate, mut early, mut last) = (7u8, 7u8, 7u8, f64::NAN);
        let status = unsafe {
            abi3::do_step::<M>(
                Function::Fmi3DoStep,
                self.c,
                t,
                h,
                FMI3_TRUE,
                &mut event,
                &mut terminate,
                &mut early,
                &mut last,
            )
        };
        StepOutcome {
            status,
            event_handling_needed: event != 0,
            terminate_simulation: terminate != 0,
            early_return: early != 0,
            last_successful_time: last,
        }
    }

    pub fn terminate(&self) -> Fmi3Status {
        unsafe { status3(abi::terminate::<M>(Function::Fmi3Terminate, self.c)) }
    }

    pub fn reset(&self) -> Fmi3Status {
        unsafe { status3(abi::reset::<M>(Function::Fmi3Reset, self.c)) }
    }

    // Model Exchange
    pub fn set_time(&self, t: f64) -> Fmi3Status {
        unsafe { status3(abi::set_time::<M>(Function::Fmi3SetTime, self.c, t)) }
    }

    pub fn enter_event_mode(&self) -> Fmi3Status {
        unsafe { status3(abi::enter_event_mode::<M>(Function::Fmi3EnterEventMode, self.c)) }
    }

    pub fn enter_continuous_time_mode(&self) -> Fmi3Status {
        unsafe { status3(abi::enter_continuous_time_mode::<M>(Function::Fmi3EnterContinuousTimeMode, self.c)) }
    }

    /// `fmi3UpdateDiscreteStates`, which must return Ok.
    pub fn update_discrete_states(&self) -> DiscreteUpdate {
        let (mut need, mut terminate, mut nominals, mut values, mut defined, mut next) =
            (7u8, 7u8, 7u8, 7u8, 7u8, f64::NAN);
        let s = unsafe {
            abi3::update_discrete_states::<M>(
                Function::Fmi3UpdateDiscreteStates,
                self.c,
                &mut need,
                &mut terminate,
                &mut nominals,
                &mut values,
                &mut defined,
                &mut next,
            )
        };
        assert_eq!(s, OK3, "{}", self.last_error());
        DiscreteUpdate {
            discrete_states_need_update: need != 0,
            terminate_simulation: terminate != 0,
            next_event_time: (defined != 0).then_some(next),
        }
    }

    pub fn continuous_states(&self) -> Vec<f64> {
        let mut x = vec![f64::NAN; M::declaration().number_of_states()];
        let s = unsafe {
            status3(abi::get_continuous_states::<M>(Function::Fmi3GetContinuousStates, self.c, x.as_mut_ptr(), x.len()))
        };
        assert_eq!(s, OK3, "{}", self.last_error());
        x
    }

    pub fn set_continuous_states(&self, x: &[f64]) -> Fmi3Status {
        unsafe {
            status3(abi::set_continuous_states::<M>(Function::Fmi3SetContinuousStates, self.c, x.as_ptr(), x.len()))
        }
    }

    pub fn derivatives(&self) -> Vec<f64> {
        let mut dx = vec![f64::NAN; M::declaration().number_of_states()];
        let s = unsafe {
            status3(abi::get_derivatives::<M>(
                Function::Fmi3GetContinuousStateDerivatives,
                self.c,
                dx.as_mut_ptr(),
                dx.len(),
            ))
        };
        assert_eq!(s, OK3, "{}", self.last_error());
        dx
    }

    /// `fmi3GetDirectionalDerivative`: `J seed` or the status.
    pub fn directional(&self, unknowns: &[u32], knowns: &[u32], seed: &[f64]) -> Result<Vec<f64>, Fmi3Status> {
        self.partial_derivatives(Function::Fmi3GetDirectionalDerivative, unknowns, knowns, seed, unknowns.len())
    }

    /// `fmi3GetAdjointDerivative`: `J^T seed` or the status.
    pub fn adjoint(&self, unknowns: &[u32], knowns: &[u32], seed: &[f64]) -> Result<Vec<f64>, Fmi3Status> {
        self.partial_derivatives(Function::Fmi3GetAdjointDerivative, unknowns, knowns, seed, knowns.len())
    }

    /// `function` (directional or adjoint) with a sensitivity of `n` values.
    fn partial_derivatives(
        &self,
        function: Function,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        n: usize,
    ) -> Result<Vec<f64>, Fmi3Status> {
        let mut out = vec![f64::NAN; n];
        let s = unsafe {
            abi3::get_partial_derivatives::<M>(
                function,
                self.c,
                unknowns.as_ptr(),
                unknowns.len(),
                knowns.as_ptr(),
                knowns.len(),
                seed.as_ptr(),
                seed.len(),
                out.as_mut_ptr(),
                out.len(),
            )
        };
        if s == OK3 {
            Ok(out)
        } else {
            Err(s)
        }
    }

    /// FMU state round trip through serialization: the bytes.
    pub fn serialized_state(&self) -> Vec<u8> {
        unsafe {
            let mut s: fmi3FMUState = null_mut();
            assert_eq!(
                status3(abi::get_fmu_state::<M>(Function::Fmi3GetFMUState, self.c, &mut s)),
                OK3,
                "{}",
                self.last_error()
            );
            let mut n = 0usize;
            assert_eq!(
                status3(abi::serialized_fmu_state_size::<M>(Function::Fmi3SerializedFMUStateSize, self.c, s, &mut n)),
                OK3
            );
            let mut bytes = vec![0u8; n];
            assert_eq!(
                status3(abi::serialize_fmu_state::<M>(
                    Function::Fmi3SerializeFMUState,
                    self.c,
                    s,
                    bytes.as_mut_ptr(),
                    n
                )),
                OK3
            );
            assert_eq!(status3(abi::free_fmu_state::<M>(Function::Fmi3FreeFMUState, self.c, &mut s)), OK3);
            bytes
        }
    }

    /// Deserializes `bytes` and sets the state: the first status that is not Ok, else Ok.
    pub fn restore_serialized(&self, bytes: &[u8]) -> Fmi3Status {
        unsafe {
            let mut s: fmi3FMUState = null_mut();
            let st = status3(abi::deserialize_fmu_state::<M>(
                Function::Fmi3DeserializeFMUState,
                self.c,
                bytes.as_ptr(),
                bytes.len(),
                &mut s,
            ));
            if st != OK3 {
                return st;
            }
            let st = status3(abi::set_fmu_state::<M>(Function::Fmi3SetFMUState, self.c, s));
            abi::free_fmu_state::<M>(Function::Fmi3FreeFMUState, self.c, &mut s);
            st
        }
    }
}

impl<M: Model> Drop for Fmu3<M> {
    fn drop(&mut self) {
        unsafe { abi::free_instance::<M>(Function::Fmi3FreeInstance, self.c) }
    }
}

/// Runs `M` in Co-Simulation through both ABIs side by side from `start` with `steps`
/// steps of `h` (stop time `start + steps h`), setting before each step the Real inputs
/// `input(k, name)` gives a value for, and asserts that every Real, Integer and Boolean
/// output, the time and the step's FMI 3.0 outputs agree to the bit with the FMI 2.0 run
/// (`terminateSimulation` only at the last step, when `ends_at_stop`). Returns the number
/// of values compared.
pub fn assert_cs_runs_agree<M: Model>(
    start: f64,
    h: f64,
    steps: usize,
    ends_at_stop: bool,
    input: impl Fn(usize, &str) -> Option<f64>,
) -> usize {
    use crate::decl::{BaseType, Causality};
    let d = M::declaration();
    let stop = start + steps as f64 * h;
    let f2 = Fmu::<M>::cs();
    f2.init_until(start, Some(stop));
    let f3 = Fmu3::<M>::cs();
    f3.init_until(start, Some(stop));
    let mut compared = 0;
    let mut t = start;
    for k in 0..steps {
        for (row, v) in d.spec.variables.iter().enumerate() {
            if v.causality != Causality::Input || v.base_type != BaseType::Real {
                continue;
            }
            if let Some(x) = input(k, v.name) {
                let vr3 = crate::Declaration::<M::Binding>::value_reference3(row);
                assert_eq!(f2.set_real(v.value_reference, x), OK, "{}", f2.last_error());
                assert_eq!(f3.set_float64(&[vr3], &[x]), OK3, "{}", f3.last_error());
            }
        }
        assert_eq!(f2.step(t, h), OK, "{}", f2.last_error());
        let s = f3.step(t, h);
        assert_eq!(s.status, OK3, "{}", f3.last_error());
        t = start + (k + 1) as f64 * h;
        assert!(!s.event_handling_needed && !s.early_return);
        assert_eq!(s.terminate_simulation, ends_at_stop && k + 1 == steps, "terminateSimulation after step {k}");
        assert_eq!(s.last_successful_time.to_bits(), f2.last_successful_time().to_bits());
        for (row, v) in d.spec.variables.iter().enumerate() {
            if v.causality != Causality::Output {
                continue;
            }
            let vr3 = crate::Declaration::<M::Binding>::value_reference3(row);
            let same = match v.base_type {
                BaseType::Real => f2.real(v.value_reference).to_bits() == f3.float64(vr3).to_bits(),
                BaseType::Integer if v.declared_type.is_some() => f2.int(v.value_reference) as i64 == f3.int64(vr3),
                BaseType::Integer => f2.int(v.value_reference) == f3.int32(vr3),
                BaseType::Boolean => {
                    let mut b = -1;
                    let s = unsafe {
                        abi::get::<M, abi::value::Boolean>(Function::GetBoolean, f2.c, &v.value_reference, 1, &mut b)
                    };
                    assert_eq!(s, OK);
                    (b != 0) == f3.boolean(vr3)
                }
            };
            assert!(same, "{} differs after step {k} (t = {t})", v.name);
            compared += 1;
        }
    }
    compared
}

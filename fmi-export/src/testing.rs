//! A tiny in-process importer over the layer's C entry points (`fmi_export::abi`, what
//! `export_fmi!` exports from the shared library), for the tests of the layer and of the
//! FMU crates: it instantiates a model type directly, without building or loading a
//! library, and records the log (through the logger shim of `fmi-sys`, as a real importer
//! receives it) so that tests can check the messages. Behind the feature `testing`, which
//! the FMU crates enable from their dev-dependencies.
#![allow(clippy::missing_safety_doc, clippy::new_without_default)]

use std::cell::RefCell;
use std::ffi::{c_int, CString};
use std::ptr::null_mut;

use crate::abi::{self, Fmi2EventInfo};
use crate::ffi::*;
use crate::Model;
use fmi_sys::fmi2::logger::{LogEnvironment, LogMessage, LogReceiver};

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
        let c = unsafe { abi::instantiate::<M>(name.as_ptr(), kind, guid.as_ptr(), null_mut(), &*callbacks, 0, 1) };
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
        unsafe { abi::setup_experiment::<M>(self.c, 0, 0.0, 0.0, 0, 0.0) }
    }
    /// setup at `start` with an optional stop time, enter and exit initialization, all Ok.
    pub fn init_until(&self, start: f64, stop: Option<f64>) {
        assert_eq!(self.setup_at(start, stop), OK, "{}", self.last_error());
        assert_eq!(self.enter_init(), OK, "{}", self.last_error());
        assert_eq!(self.exit_init(), OK, "{}", self.last_error());
    }
    /// `fmi2SetupExperiment` with a start time and an optional stop time.
    pub fn setup_at(&self, start: f64, stop: Option<f64>) -> Fmi2Status {
        unsafe { abi::setup_experiment::<M>(self.c, 0, 0.0, start, stop.is_some() as i32, stop.unwrap_or(0.0)) }
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
            unsafe { abi::get_real_status::<M>(self.c, FMI2_LAST_SUCCESSFUL_TIME, &mut t) },
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
            unsafe { abi::get_boolean_status::<M>(self.c, FMI2_TERMINATED, &mut b) },
            OK,
            "{}",
            self.last_error()
        );
        b == 1
    }
    pub fn enter_init(&self) -> Fmi2Status {
        unsafe { abi::enter_initialization_mode::<M>(self.c) }
    }
    pub fn exit_init(&self) -> Fmi2Status {
        unsafe { abi::exit_initialization_mode::<M>(self.c) }
    }
    /// setup, enter and exit initialization, all Ok.
    pub fn init(&self) {
        assert_eq!(self.setup(), OK, "{}", self.last_error());
        assert_eq!(self.enter_init(), OK, "{}", self.last_error());
        assert_eq!(self.exit_init(), OK, "{}", self.last_error());
    }
    pub fn real(&self, vr: u32) -> f64 {
        let mut x = f64::NAN;
        let s = unsafe { abi::get_real::<M>(self.c, &vr, 1, &mut x) };
        assert_eq!(s, OK, "get_real({vr}): {}", self.last_error());
        x
    }
    pub fn reals(&self, vrs: &[u32]) -> Vec<f64> {
        vrs.iter().map(|&vr| self.real(vr)).collect()
    }
    pub fn int(&self, vr: u32) -> i32 {
        let mut x = -7;
        let s = unsafe { abi::get_integer::<M>(self.c, &vr, 1, &mut x) };
        assert_eq!(s, OK, "{}", self.last_error());
        x
    }
    pub fn set_real(&self, vr: u32, x: f64) -> Fmi2Status {
        unsafe { abi::set_real::<M>(self.c, &vr, 1, &x) }
    }
    pub fn set_int(&self, vr: u32, x: i32) -> Fmi2Status {
        unsafe { abi::set_integer::<M>(self.c, &vr, 1, &x) }
    }
    pub fn set_bool(&self, vr: u32, x: bool) -> Fmi2Status {
        let v = x as fmi2Boolean;
        unsafe { abi::set_boolean::<M>(self.c, &vr, 1, &v) }
    }
    pub fn step(&self, t: f64, h: f64) -> Fmi2Status {
        unsafe { abi::do_step::<M>(self.c, t, h, 1) }
    }
    pub fn reset(&self) -> Fmi2Status {
        unsafe { abi::reset::<M>(self.c) }
    }
    // Model Exchange
    pub fn set_time(&self, t: f64) -> Fmi2Status {
        unsafe { abi::set_time::<M>(self.c, t) }
    }
    pub fn enter_event_mode(&self) -> Fmi2Status {
        unsafe { abi::enter_event_mode::<M>(self.c) }
    }
    pub fn enter_continuous_time_mode(&self) -> Fmi2Status {
        unsafe { abi::enter_continuous_time_mode::<M>(self.c) }
    }
    /// One event iteration; the next event time if defined.
    pub fn new_discrete_states(&self) -> Option<f64> {
        self.event_iteration().0
    }
    /// One event iteration: the next event time if defined, and terminateSimulation.
    pub fn event_iteration(&self) -> (Option<f64>, bool) {
        let mut info = Fmi2EventInfo::default();
        let s = unsafe { abi::new_discrete_states::<M>(self.c, &mut info) };
        assert_eq!(s, OK, "{}", self.last_error());
        assert_eq!(info.new_discrete_states_needed, 0);
        ((info.next_event_time_defined != 0).then_some(info.next_event_time), info.terminate_simulation != 0)
    }
    /// FMU state round trip through serialization.
    pub fn serialized_state(&self) -> Vec<u8> {
        unsafe {
            let mut s: fmi2FMUstate = null_mut();
            assert_eq!(abi::get_fmu_state::<M>(self.c, &mut s), OK, "{}", self.last_error());
            let mut n = 0usize;
            assert_eq!(abi::serialized_fmu_state_size::<M>(self.c, s, &mut n), OK);
            let mut bytes = vec![0u8; n];
            assert_eq!(abi::serialize_fmu_state::<M>(self.c, s, bytes.as_mut_ptr() as *mut fmi2Byte, n), OK);
            assert_eq!(abi::free_fmu_state::<M>(self.c, &mut s), OK);
            bytes
        }
    }
    pub fn restore_serialized(&self, bytes: &[u8]) -> Fmi2Status {
        unsafe {
            let mut s: fmi2FMUstate = null_mut();
            let st = abi::deserialize_fmu_state::<M>(self.c, bytes.as_ptr() as *const fmi2Byte, bytes.len(), &mut s);
            if st != OK {
                return st;
            }
            let st = abi::set_fmu_state::<M>(self.c, s);
            abi::free_fmu_state::<M>(self.c, &mut s);
            st
        }
    }
}

impl<M: Model> Drop for Fmu<M> {
    fn drop(&mut self) {
        unsafe { abi::free_instance::<M>(self.c) }
    }
}

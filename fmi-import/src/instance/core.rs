//! What an instance is whatever its generation: the component and the FMU, the life-cycle
//! state and how a call's status moves it, the log, the time its values are at; and
//! [`Calls`], the calls each generation makes on it (`fmi2.rs`, `fmi3.rs`).

use std::ffi::c_void;
use std::sync::Arc;

use crate::c_types::{Component, EventInfo, RawStatus};
use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::log::LogSink;
use crate::status::Status;

/// Life-cycle state of an instance (what the standard allows next).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InstanceState {
    /// After `fmi2Instantiate`.
    Instantiated,
    /// After `fmi2EnterInitializationMode`.
    Initialization,
    /// After `fmi2ExitInitializationMode` (step complete / event mode; Model Exchange after
    /// `fmi2EnterEventMode`).
    Running,
    /// Model Exchange after `fmi2EnterContinuousTimeMode`, until `fmi2EnterEventMode`: only
    /// continuous inputs may change (FMI 2.0 section 3.2.3, FMI 3.0 section 3.2.1).
    ContinuousTime,
    /// After `fmi2Terminate`.
    Terminated,
    /// After an `fmi2Error`: only free is called.
    Errored,
    /// After an `fmi2Fatal`: nothing is called any more, not even free.
    Fatal,
}

impl InstanceState {
    /// Whether it runs: after initialization, in any mode, before termination or an error.
    #[inline]
    pub fn is_running(self) -> bool {
        matches!(self, InstanceState::Running | InstanceState::ContinuousTime)
    }

    pub(crate) fn as_str(self) -> &'static str {
        match self {
            InstanceState::Instantiated => "instantiated",
            InstanceState::Initialization => "initialization mode",
            InstanceState::Running => "running",
            InstanceState::ContinuousTime => "continuous-time mode",
            InstanceState::Terminated => "terminated",
            InstanceState::Errored => "errored",
            InstanceState::Fatal => "fatal",
        }
    }
}

/// The part of an instance every call reads or moves, whatever the generation.
pub(crate) struct Core {
    pub(crate) component: Component,
    pub(crate) state: InstanceState,
    pub(crate) name: String,
    pub(crate) log: Box<LogSink>,
    pub(crate) fmu: Arc<Fmu>,
    /// The time the FMU's values are at (the last setup, step end or `fmi2SetTime`), for
    /// [`Error::NonFinite`].
    pub(crate) time: f64,
    /// Isolated: the host process the calls go to (the component is its address).
    pub(crate) host: Option<Box<crate::isolate::channel::Channel>>,
    /// The saved FMU states not freed yet (freed with the instance).
    pub(crate) saved: Vec<*mut c_void>,
    /// The status of the last call (OK or Warning when it went on), for
    /// [`Error::Returned`].
    pub(crate) last_status: Status,
}

/// Calls the C function `$f` (an expression using the component copied beforehand) named
/// `$name` of `$core`'s instance at the time `$time` (`None`: the instance's time), marked
/// as the call in progress; its status as [`Core::status`] takes it.
macro_rules! call {
    ($core:expr, $name:expr, $time:expr, $f:expr) => {{
        let core: &mut $crate::instance::core::Core = $core;
        core.check_callable($name)?;
        let time: Option<f64> = $time;
        // the blocks the FMU allocates in the call are this instance's (fmi-sys's guard)
        let mark =
            $crate::call_site::enter(&core.name, &core.fmu.source, $name, time.unwrap_or(core.time), core.log.owner());
        // SAFETY: the component is live (not freed), the arguments are valid for the call.
        let raw = unsafe { $f };
        drop(mark);
        core.status($name, raw, time)
    }};
}
pub(crate) use call;

impl Core {
    pub(crate) fn check_callable(&self, function: &'static str) -> Result<()> {
        match self.state {
            InstanceState::Errored | InstanceState::Fatal | InstanceState::Terminated => {
                Err(Error::IllegalCall { instance: self.name.clone(), function, state: self.state.as_str() })
            }
            _ => Ok(()),
        }
    }

    /// `Ok` for OK and Warning; else the error, the state moved (Error, Pending or an
    /// invalid status: errored; Fatal: fatal).
    pub(crate) fn status(&mut self, function: &'static str, raw: RawStatus, time: Option<f64>) -> Result<()> {
        let status = Status::from_raw(raw);
        self.last_status = status;
        match status {
            Status::Ok | Status::Warning => return Ok(()),
            Status::Discard => {}
            Status::Error | Status::Pending | Status::Invalid(_) => self.state = InstanceState::Errored,
            Status::Fatal => self.state = InstanceState::Fatal,
        }
        if let Some((needed, available)) = self.host.as_mut().and_then(|h| h.over_limit.take()) {
            return Err(Error::IsolationLimit { instance: self.name.clone(), function, needed, available });
        }
        if let Some(cause) = self.host.as_ref().and_then(|h| h.failure.clone()) {
            let time = time.unwrap_or(self.host.as_ref().map_or(0.0, |h| h.last_time));
            return Err(Error::Host { instance: self.name.clone(), function, time, cause });
        }
        Err(Error::Fmi { instance: self.name.clone(), function, status, time, log: self.log.recent_problems() })
    }

    /// Marks a call of `function` made outside `call!` (reset, free), whose status is not
    /// read: the exit guard names it, and it is owned by the call it is inside.
    pub(crate) fn mark_call(&self, function: &'static str) -> crate::call_site::InCall {
        crate::call_site::enter(&self.name, &self.fmu.source, function, self.time, crate::call_site::owner_of_call())
    }

    /// The function `f` of the table, or the error naming it as missing.
    pub(crate) fn optional<T>(&self, f: Option<T>, function: &'static str) -> Result<T> {
        f.ok_or_else(|| Error::MissingSymbol { path: self.fmu.source.clone(), symbol: function })
    }

    /// The error of what `function`, called at `time`, returned with the status of the last
    /// call (OK or Warning) but the standard or a bound of the master does not take (`what`
    /// says why); the caller moves the state.
    #[cold]
    pub(crate) fn returned(&self, function: &'static str, time: f64, what: String) -> Error {
        Error::Returned { instance: self.name.clone(), function, status_returned: self.last_status, time, what }
    }
}

/// A directional derivative's arguments but its result: d(`unknowns`)/d(`knowns`) times
/// `dv_known` (one seed per known).
#[derive(Clone, Copy)]
pub(crate) struct Seed<'a> {
    pub(crate) unknowns: &'a [u32],
    pub(crate) knowns: &'a [u32],
    pub(crate) dv_known: &'a [f64],
}

/// The calls of one generation's C API on an instance: everything [`crate::Instance`]
/// does that differs between FMI 2.0 and FMI 3.0. The state transitions that do not
/// differ are the instance's.
pub(crate) trait Calls: Send {
    /// The instantiate function of `interface` (`fmi2Instantiate`, `fmi3Instantiate*`).
    fn instantiate_function(&self, interface: crate::fmu::Interface) -> &'static str;
    /// Instantiates `fmu` in process as `name` (`name_c`), logging off, the messages to
    /// `log` (FMI 2.0: through `callbacks`); both outlive the instance.
    fn instantiate(
        &self,
        fmu: &Fmu,
        name: &str,
        name_c: &std::ffi::CString,
        callbacks: &crate::c_types::CallbackFunctions,
        log: &LogSink,
    ) -> Result<Component>;
    /// Instantiates `fmu` in the host of `channel`; the status.
    fn instantiate_in(
        &self,
        fmu: &Fmu,
        channel: &mut crate::isolate::channel::Channel,
        name_c: &std::ffi::CString,
    ) -> Result<i32>;
    /// The reset function's name.
    fn reset_name(&self) -> &'static str;
    /// FMI 3.0: Configuration Mode for the structural parameters the FMU was configured
    /// with, in Instantiated (after instantiation and after a reset).
    fn configure(&mut self, _core: &mut Core) -> Result<()> {
        Ok(())
    }
    /// FMI 3.0 Scheduled Execution (`instance/scheduled.rs`); other interfaces: an error.
    fn activate_model_partition(&mut self, core: &mut Core, _clock: u32, _time: f64) -> Result<bool> {
        Err(Error::Instance { name: core.name.clone(), reason: "it is not instantiated for Scheduled Execution" })
    }
    /// See [`Calls::activate_model_partition`].
    fn countdown_interval(&mut self, core: &mut Core, _clock: u32) -> Result<Option<f64>> {
        Err(Error::Instance { name: core.name.clone(), reason: "it is not instantiated for Scheduled Execution" })
    }
    /// See [`Calls::activate_model_partition`].
    fn output_clock_ticked(&mut self, core: &mut Core, _clock: u32) -> Result<bool> {
        Err(Error::Instance { name: core.name.clone(), reason: "it is not instantiated for Scheduled Execution" })
    }
    /// Whether the view's variable `vr` is an array element the array does not have now (FMI
    /// 3.0: a structural parameter made it smaller; read as NaN).
    fn absent_element(&self, _vr: u32) -> bool {
        false
    }
    /// FMI 3.0 Reconfiguration Mode (`instance/configuration.rs`); others: an error.
    fn reconfigure(&mut self, core: &mut Core, _values: &[(&str, f64)]) -> Result<()> {
        Err(Error::Instance {
            name: core.name.clone(),
            reason:
                "Reconfiguration Mode is run for FMI 3.0 instances in this process only (not FMI 2.0, not isolated)",
        })
    }
    /// The name of the function that starts the experiment (for a call out of order).
    fn setup_function(&self) -> &'static str;
    /// `fmi2SetupExperiment`; FMI 3.0 keeps the arguments for initialization.
    fn setup_experiment(
        &mut self,
        core: &mut Core,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> Result<()>;
    fn enter_initialization_mode(&mut self, core: &mut Core) -> Result<()>;
    fn exit_initialization_mode(&mut self, core: &mut Core) -> Result<()>;
    fn terminate(&mut self, core: &mut Core) -> Result<()>;
    /// The reset function, or the error that it is missing.
    fn reset_function(&self, core: &Core) -> Result<ResetFunction>;
    /// What the generation keeps per run is forgotten (after a reset).
    fn forget_run(&mut self) {}
    fn get_real(&mut self, core: &mut Core, vrs: &[u32], values: &mut [f64]) -> Result<()>;
    fn set_real(&mut self, core: &mut Core, vrs: &[u32], values: &[f64]) -> Result<()>;
    fn get_integer(&mut self, core: &mut Core, vrs: &[u32], values: &mut [i32]) -> Result<()>;
    fn set_integer(&mut self, core: &mut Core, vrs: &[u32], values: &[i32]) -> Result<()>;
    fn get_boolean(&mut self, core: &mut Core, vrs: &[u32], values: &mut [i32]) -> Result<()>;
    fn set_boolean(&mut self, core: &mut Core, vrs: &[u32], values: &[i32]) -> Result<()>;
    /// The string of `vr` as the FMU returns it (valid until its next call).
    fn get_string(&mut self, core: &mut Core, vr: u32) -> Result<*const std::ffi::c_char>;
    fn set_string(&mut self, core: &mut Core, vr: u32, value: *const std::ffi::c_char) -> Result<()>;
    /// The exact values of variables of [`crate::Fmu::exact_kind`], appended to `values`
    /// (FMI 3.0 only): an array read once for all its elements among `vrs`.
    fn get_exact(&mut self, core: &mut Core, vrs: &[u32], values: &mut Vec<crate::fmi3::Exact>) -> Result<()>;
    /// Sets a 64-bit integer variable of [`crate::Fmu::exact_kind`] exactly (FMI 3.0 only).
    fn set_exact_integer(&mut self, core: &mut Core, vr: u32, value: i128) -> Result<()>;
    fn do_step(&mut self, core: &mut Core, time: f64, step: f64) -> Result<()>;
    /// Isolated: the operation and step size of the first call of `do_step`, if the
    /// table has the function.
    fn posted_step(&self, time: f64, step: f64) -> Option<(crate::isolate::protocol::Op, f64)>;
    fn get_state(&mut self, core: &mut Core, state: &mut *mut c_void) -> Result<()>;
    fn set_state(&mut self, core: &mut Core, state: *mut c_void) -> Result<()>;
    fn free_state(&mut self, core: &mut Core, state: &mut *mut c_void) -> Result<()>;
    fn set_time(&mut self, core: &mut Core, time: f64) -> Result<()>;
    fn set_continuous_states(&mut self, core: &mut Core, x: &[f64]) -> Result<()>;
    fn get_continuous_states(&mut self, core: &mut Core, x: &mut [f64]) -> Result<()>;
    fn get_derivatives(&mut self, core: &mut Core, dx: &mut [f64]) -> Result<()>;
    fn get_event_indicators(&mut self, core: &mut Core, z: &mut [f64]) -> Result<()>;
    fn has_directional_derivative(&self) -> bool;
    fn get_directional_derivative(&mut self, core: &mut Core, seed: Seed, dv_unknown: &mut [f64]) -> Result<()>;
    fn enter_event_mode(&mut self, core: &mut Core) -> Result<()>;
    fn new_discrete_states(&mut self, core: &mut Core) -> Result<EventInfo>;
    fn enter_continuous_time_mode(&mut self, core: &mut Core) -> Result<()>;
    fn completed_integrator_step(&mut self, core: &mut Core) -> Result<(bool, bool)>;
    fn terminated_status(&mut self, core: &mut Core) -> Option<bool>;
    fn last_successful_time(&mut self, core: &mut Core) -> Option<f64>;
    /// The functions that free a saved state and the instance, and the latter's name.
    fn free_functions(&self) -> (Option<FreeStateFunction>, FreeInstanceFunction, &'static str);
    /// Whether this is FMI 3.0.
    fn is_fmi3(&self) -> bool;
    /// The clock calls (FMI 3.0 only; see `instance/clocks.rs`).
    fn clock_calls(&mut self) -> Option<&mut dyn ClockCalls> {
        None
    }
}

/// `fmi2Reset` / `fmi3Reset`: both take the instance only.
pub(crate) type ResetFunction = unsafe extern "C" fn(Component) -> RawStatus;
/// `fmi2FreeFMUstate` / `fmi3FreeFMUState`: both take (instance, *mut state).
pub(crate) type FreeStateFunction = unsafe extern "C" fn(Component, *mut *mut c_void) -> RawStatus;
/// `fmi2FreeInstance` / `fmi3FreeInstance`.
pub(crate) type FreeInstanceFunction = unsafe extern "C" fn(Component);

// The clock calls' types live here, beside the calls of every generation (`Calls`), so
// that the generations' modules and `clocks.rs` (the calls on an `Instance`) import them
// one way.

/// What the FMU said of a clock's interval (`fmi3IntervalQualifier`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Interval {
    /// `fmi3IntervalNotYetKnown`: a countdown clock that is not counting down.
    NotYetKnown,
    /// `fmi3IntervalUnchanged`: as before (the value is the interval the master has).
    Unchanged(f64),
    /// `fmi3IntervalChanged`: the clock ticks this many seconds after now.
    Changed(f64),
}

/// An output clock's tick: when and which (the FMU's value reference).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutputTick {
    /// The time of the event it ticked in, s.
    pub time: f64,
    /// The clock's value reference (the FMU's).
    pub value_reference: u32,
}

/// The clock calls of one generation (FMI 3.0 only).
pub(crate) trait ClockCalls {
    fn set_clocks(&mut self, core: &mut Core, vrs: &[u32]) -> Result<()>;
    fn get_clocks(&mut self, core: &mut Core, vrs: &[u32], ticks: &mut [bool]) -> Result<()>;
    /// `zero`: an interval of 0 s is one (the delay to a changing clock's first tick at the
    /// start), else an error.
    fn get_intervals(&mut self, core: &mut Core, vrs: &[u32], zero: bool) -> Result<Vec<Interval>>;
    fn get_shifts(&mut self, core: &mut Core, vrs: &[u32]) -> Result<Vec<f64>>;
    fn set_intervals(&mut self, core: &mut Core, vrs: &[u32], intervals: &[f64]) -> Result<()>;
    /// The start of a clock event at `time`: Event Mode entered and the input clocks `vrs`
    /// set (active until the close).
    fn open_clock_event(&mut self, core: &mut Core, time: f64, vrs: &[u32]) -> Result<()>;
    /// The end of the open clock event: the discrete states updated until settled, the
    /// output clocks read, Step Mode again.
    fn close_clock_event(&mut self, core: &mut Core) -> Result<()>;
    /// The output clocks' ticks since the last call (in Event Mode entered by a tick or by
    /// the FMU's own event in `fmi3DoStep`).
    fn take_output_ticks(&mut self) -> Vec<OutputTick>;
    /// What the FMU said of its input clocks' intervals in the events since the last call.
    fn take_intervals(&mut self) -> Vec<(f64, u32, Interval)>;
}

//! [`Instance`]: one instance of an FMU, the same typed calls for both generations. The
//! life-cycle state and the status of every call are handled once (`core.rs`); each
//! generation's C calls are a module of their own (`fmi2.rs`, `fmi3.rs`, the FMI 3.0
//! view's types and arrays included) behind [`core::Calls`]. An instance terminates and
//! frees itself on drop.

mod callbacks;
mod clocked;
mod clocks;
mod configuration;
pub(crate) mod core;
mod discrete_inputs;
mod fmi2;
mod fmi3;
mod scheduled;

use std::ffi::{c_void, CStr, CString};
use std::sync::Arc;

pub use self::core::InstanceState;
use self::core::{Calls, Core, Seed};
pub use self::core::{Interval, OutputTick};
use self::discrete_inputs::{DiscreteInputs, Held, Kind};
use crate::c_types::{CallbackFunctions, EventInfo};
use crate::error::{Error, Result};
use crate::fmu::{Abi, Fmu};
use crate::log::{callbacks_for, LogRecord, LogSink};
use crate::status::Status;

/// A saved FMU state (`fmi2FMUstate`), freed by [`Instance::free_state`] or with the instance.
#[derive(Debug)]
pub struct FmuState(*mut c_void);

// SAFETY: a saved state is only passed back to the instance it came from, which is
// itself never called concurrently (see `Instance`); it moves between threads with it.
unsafe impl Send for FmuState {}

/// One instance of an FMU. Every call returns `Ok` for fmi2OK and fmi2Warning (the
/// warning stays in the log), else a typed [`Error::Fmi`] with the FMU's last messages.
/// Dropping it terminates it (unless it errored or is not initialized) and frees it
/// (unless it had a fatal error).
pub struct Instance {
    core: Core,
    calls: Box<dyn Calls>,
    _name_c: CString,
    _callbacks: Box<CallbackFunctions>,
    /// Model Exchange: the discrete inputs set in Continuous-Time Mode, waiting for Event Mode.
    discrete: Option<Box<DiscreteInputs>>,
}

// SAFETY: an FMI instance may be used from any thread as long as calls to it are not
// concurrent (the standard's rule); `&mut self` on every call guarantees that.
unsafe impl Send for Instance {}

impl std::fmt::Debug for Instance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Instance").field("name", &self.core.name).field("state", &self.core.state).finish()
    }
}

/// The calls of `fmu`'s generation.
fn calls_of(fmu: &Fmu) -> Box<dyn Calls> {
    match &fmu.abi {
        Abi::Fmi2(t) => Box::new(fmi2::Fmi2::new(t.clone())),
        Abi::Fmi3(a) => Box::new(fmi3::Fmi3::new(a.clone(), fmu.interface, fmu.event_mode().is_some_and(|e| e.used))),
    }
}

/// The values of the red zone after dvUnknown (a NaN no FMU computes by arithmetic) and
/// their number (64 bytes).
const DV_RED_ZONE: f64 = f64::from_bits(0x7ff8_dead_beef_0001);
const DV_RED_ZONE_LEN: usize = 8;

/// Typed getters and setters of [`Instance`], one value per value reference, a set through
/// [`Instance::set_passing`]: (getter, setter, value type, the discrete inputs' kind and
/// held value) a row.
macro_rules! get_set {
    ($($(#[$get_doc:meta])* $get:ident; $(#[$set_doc:meta])* $set:ident; $t:ty, $kind:expr, $held:expr;)*) => {$(
        $(#[$get_doc])*
        #[inline]
        pub fn $get(&mut self, vrs: &[u32], values: &mut [$t]) -> Result<()> {
            assert_eq!(vrs.len(), values.len(), concat!(stringify!($get), ": one value per value reference"));
            self.calls.$get(&mut self.core, vrs, values)
        }

        $(#[$set_doc])*
        #[inline]
        pub fn $set(&mut self, vrs: &[u32], values: &[$t]) -> Result<()> {
            assert_eq!(vrs.len(), values.len(), concat!(stringify!($set), ": one value per value reference"));
            self.set_passing(($kind, $held), vrs, values, <dyn Calls>::$set)
        }
    )*};
}

impl Instance {
    /// `fmi2Instantiate` / `fmi3Instantiate*` with the FMU's interface, logging off
    /// (warnings and errors are still logged by the FMU and kept); an FMU
    /// [configured](Fmu::configured) with structural parameters then goes through
    /// Configuration Mode to set them.
    pub fn new(fmu: &Arc<Fmu>, name: &str) -> Result<Instance> {
        if fmu.is_isolated() {
            return Err(Error::Instance {
                name: name.into(),
                reason: "its FMU was imported isolated (its library is not loaded in this process): instantiate it in a host process (Instance::new_isolated, Experiment::isolation)",
            });
        }
        let name_c = CString::new(name).map_err(|_| Error::Instance { name: name.into(), reason: "NUL in name" })?;
        let log = Box::<LogSink>::default();
        let callbacks = callbacks_for(&log);
        let calls = calls_of(fmu);
        let component = calls.instantiate(fmu, name, &name_c, &callbacks, &log)?;
        let mut instance = Instance::with(component, calls, name, name_c, log, callbacks, fmu.clone(), None);
        instance.calls.configure(&mut instance.core)?;
        Ok(instance)
    }

    #[allow(clippy::too_many_arguments)]
    fn with(
        component: crate::c_types::Component,
        calls: Box<dyn Calls>,
        name: &str,
        name_c: CString,
        log: Box<LogSink>,
        callbacks: Box<CallbackFunctions>,
        fmu: Arc<Fmu>,
        host: Option<Box<crate::isolate::channel::Channel>>,
    ) -> Instance {
        let discrete = DiscreteInputs::new(&fmu.description, fmu.interface());
        Instance {
            discrete,
            core: Core {
                component,
                state: InstanceState::Instantiated,
                name: name.into(),
                log,
                fmu,
                time: 0.0,
                host,
                saved: Vec::new(),
                last_status: Status::Ok,
            },
            calls,
            _name_c: name_c,
            _callbacks: callbacks,
        }
    }

    /// `fmi2Instantiate` / `fmi3InstantiateCoSimulation` in a host process of its own
    /// (`isolation` names the host binary and the per-call time limit; `run_deadline`: the
    /// run's deadline and its limit); FMI 3.0 Model Exchange by `fmi3InstantiateModelExchange`.
    pub fn new_isolated(
        fmu: &Arc<Fmu>,
        name: &str,
        isolation: &crate::isolate::Isolation,
        run_deadline: Option<(std::time::Instant, std::time::Duration)>,
    ) -> Result<Instance> {
        use crate::error::HostEnd;
        let fmu = fmu.isolated();
        let calls = calls_of(&fmu);
        let instantiate = calls.instantiate_function(fmu.interface);
        let name_c = CString::new(name).map_err(|_| Error::Instance { name: name.into(), reason: "NUL in name" })?;
        let failed = |m: String| Error::Host {
            instance: name.into(),
            function: instantiate,
            time: 0.0,
            cause: HostEnd::Failed(m),
        };
        let host = crate::isolate::channel::find_host(isolation.host.as_deref()).map_err(failed)?;
        // the region holds the largest call this FMU can make: every scalar value (array
        // elements one by one), every event indicator, the instantiation's strings (the
        // resource URI: the folder's path percent-encoded, 3 bytes a byte at most)
        let md = &fmu.description;
        let strings = name.len() + md.guid.len() + 3 * fmu.unpacked_dir().as_os_str().len() + 64;
        let layout = crate::isolate::protocol::Layout::for_fmu(
            md.model_variables.len(),
            md.number_of_event_indicators as usize,
            strings,
        );
        let mut channel = Box::new(
            crate::isolate::channel::Channel::start(
                &host,
                &fmu.library_path,
                calls.is_fmi3(),
                layout,
                isolation.call_timeout,
                run_deadline,
                crate::isolate::protocol::Spin::of_run(),
            )
            .map_err(|cause| Error::Host {
                instance: name.into(),
                function: match instantiate {
                    "fmi2Instantiate" => "fmi2Instantiate (loading the library)",
                    "fmi3InstantiateCoSimulation" => "fmi3InstantiateCoSimulation (loading the library)",
                    _ => "fmi3InstantiateModelExchange (loading the library)",
                },
                time: 0.0,
                cause,
            })?,
        );
        let log = Box::<LogSink>::default();
        channel.log = &*log as *const LogSink;
        let status = calls.instantiate_in(&fmu, &mut channel, &name_c)?;
        if status != 0 {
            if let Some((needed, available)) = channel.over_limit.take() {
                return Err(Error::IsolationLimit { instance: name.into(), function: instantiate, needed, available });
            }
            if let Some(cause) = channel.failure.clone() {
                return Err(Error::Host { instance: name.into(), function: instantiate, time: 0.0, cause });
            }
            return Err(Error::Instantiate {
                instance: name.into(),
                function: instantiate,
                log: log.recent_problems(),
            });
        }
        let callbacks = callbacks_for(&log);
        let component = &mut *channel as *mut crate::isolate::channel::Channel as *mut c_void;
        let mut instance = Instance::with(component, calls, name, name_c, log, callbacks, fmu, Some(channel));
        instance.calls.configure(&mut instance.core)?;
        Ok(instance)
    }

    /// The instance name.
    pub fn name(&self) -> &str {
        &self.core.name
    }

    /// The FMU.
    pub fn fmu(&self) -> &Arc<Fmu> {
        &self.core.fmu
    }

    /// The instance's time as last set or reached (s).
    pub fn time(&self) -> f64 {
        self.core.time
    }

    /// The life-cycle state.
    pub fn state(&self) -> InstanceState {
        self.core.state
    }

    /// Takes the messages the FMU logged (the last [`LogSink::CAPACITY`]).
    pub fn take_log(&self) -> Vec<LogRecord> {
        self.core.log.take()
    }

    /// Whether the FMU is an FMI 3.0 one.
    pub fn is_fmi3(&self) -> bool {
        self.calls.is_fmi3()
    }

    /// `fmi2SetupExperiment`; FMI 3.0: kept for `fmi3EnterInitializationMode`.
    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start_time: f64, stop_time: Option<f64>) -> Result<()> {
        if self.core.state != InstanceState::Instantiated {
            let (instance, state) = (self.core.name.clone(), self.core.state.as_str());
            return Err(Error::IllegalCall { instance, function: self.calls.setup_function(), state });
        }
        self.core.time = start_time;
        self.calls.setup_experiment(&mut self.core, tolerance, start_time, stop_time)
    }

    /// `fmi2EnterInitializationMode`; FMI 3.0: `fmi3EnterInitializationMode` with the
    /// experiment of [`Instance::setup_experiment`].
    pub fn enter_initialization_mode(&mut self) -> Result<()> {
        self.calls.enter_initialization_mode(&mut self.core)?;
        self.core.state = InstanceState::Initialization;
        Ok(())
    }

    /// `fmi2ExitInitializationMode` / `fmi3ExitInitializationMode`.
    pub fn exit_initialization_mode(&mut self) -> Result<()> {
        self.calls.exit_initialization_mode(&mut self.core)?;
        self.core.state = InstanceState::Running;
        Ok(())
    }

    /// Model Exchange: whether the instance is in Continuous-Time Mode (discrete inputs
    /// wait for Event Mode then).
    #[inline]
    fn in_continuous_time(&self) -> bool {
        self.core.state == InstanceState::ContinuousTime
    }

    /// Model Exchange: whether discrete inputs set in Continuous-Time Mode wait for Event
    /// Mode (FMI 2.0 section 3.2.3, FMI 3.0 section 3.2.1 let only continuous inputs
    /// change there; a set of a value the FMU already holds is dropped, not kept).
    pub fn has_pending_inputs(&self) -> bool {
        self.discrete.as_deref().is_some_and(|d| !d.pending.is_empty())
    }

    /// The discrete inputs that wait (see [`Instance::has_pending_inputs`]) set, in the
    /// order they were set; in Event Mode (after [`Instance::enter_event_mode`]).
    pub fn apply_pending_inputs(&mut self) -> Result<()> {
        if self.in_continuous_time() {
            let instance = self.core.name.clone();
            return Err(Error::IllegalCall {
                instance,
                function: "a set of a discrete input",
                state: "Continuous-Time Mode",
            });
        }
        let Some(d) = self.discrete.as_deref_mut() else { return Ok(()) };
        for (_, vr, value) in std::mem::take(&mut d.pending) {
            match value {
                Held::Real(bits) => self.set_real(&[vr], &[f64::from_bits(bits)])?,
                Held::Integer(v) => self.set_integer(&[vr], &[v])?,
                Held::Boolean(v) => self.set_boolean(&[vr], &[v as i32])?,
                Held::String(v) => self.set_string(vr, &v)?,
                Held::Exact(v) => self.set_exact_integer(vr, v)?,
            }
        }
        Ok(())
    }

    /// Sets `values` with `set`: all of them (noted where discrete), or those left when the
    /// discrete ones that wait or that the FMU already holds are taken out (see
    /// `discrete_inputs.rs`; none left: no call).
    #[inline]
    fn set_passing<T: Copy>(
        &mut self,
        (kind, held): (Kind, impl Fn(T) -> Held),
        vrs: &[u32],
        values: &[T],
        set: impl Fn(&mut (dyn Calls + 'static), &mut Core, &[u32], &[T]) -> Result<()>,
    ) -> Result<()> {
        let continuous_time = self.in_continuous_time();
        if let Some(d) = self.discrete.as_deref_mut() {
            if d.any_deferred(continuous_time, kind, vrs) {
                let (vrs, values): (Vec<u32>, Vec<T>) = vrs
                    .iter()
                    .zip(values)
                    .filter(|(vr, v)| !d.defer(continuous_time, kind, **vr, held(**v)))
                    .map(|(vr, v)| (*vr, *v))
                    .unzip();
                if vrs.is_empty() {
                    return Ok(());
                }
                return set(self.calls.as_mut(), &mut self.core, &vrs, &values);
            }
            if !continuous_time {
                for (vr, v) in vrs.iter().zip(values) {
                    d.defer(false, kind, *vr, held(*v));
                }
            }
        }
        set(self.calls.as_mut(), &mut self.core, vrs, values)
    }

    /// `fmi2Terminate` / `fmi3Terminate` (only from initialization or running; otherwise
    /// nothing to do).
    pub fn terminate(&mut self) -> Result<()> {
        if !matches!(
            self.core.state,
            InstanceState::Running | InstanceState::ContinuousTime | InstanceState::Initialization
        ) {
            return Ok(());
        }
        self.calls.terminate(&mut self.core)?;
        self.core.state = InstanceState::Terminated;
        Ok(())
    }

    /// `fmi2Reset` / `fmi3Reset`: back to instantiated (also after an error; a configured
    /// FMU's structural parameters set again in Configuration Mode).
    pub fn reset(&mut self) -> Result<()> {
        if self.core.state == InstanceState::Fatal {
            let function = self.calls.reset_name();
            return Err(Error::IllegalCall { instance: self.core.name.clone(), function, state: "fatal" });
        }
        let function = self.calls.reset_name();
        let f = self.calls.reset_function(&self.core)?;
        let mark = self.core.mark_call(function);
        // SAFETY: live component; both generations' reset take the instance only.
        let raw = unsafe { f(self.core.component) };
        drop(mark);
        self.core.state = InstanceState::Instantiated;
        self.calls.forget_run();
        self.discrete = DiscreteInputs::new(&self.core.fmu.description, self.core.fmu.interface());
        self.core.status(function, raw, None)?;
        self.calls.configure(&mut self.core)
    }

    /// `fmi2GetReal` / `fmi3GetFloat64` of `vrs` into `values` (same length). A NaN or
    /// infinite value is [`Error::NonFinite`] unless the FMU was imported with
    /// `allow_non_finite`. FMI 3.0: Float32, UInt32, Int64, UInt64 (the nearest f64, exact
    /// up to 2^53: [`Instance::get_exact`] reads them exactly), Binary (its size) and array
    /// elements by their own getters.
    #[inline]
    pub fn get_real(&mut self, vrs: &[u32], values: &mut [f64]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "get_real: one value per value reference");
        self.calls.get_real(&mut self.core, vrs, values)?;
        // all exponent bits set: Inf or NaN. An OR of integer compares over the values
        // just read, without a branch per value (the compiler vectorizes it).
        const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
        let any = values.iter().fold(false, |any, v| any | (v.to_bits() & EXPONENT == EXPONENT));
        if any && !self.core.fmu.allow_non_finite {
            return self.non_finite(vrs, values).map_or(Ok(()), Err);
        }
        Ok(())
    }

    /// The error of the first value that is not finite, `None` when each is the NaN of an
    /// array element that is not there now (a structural parameter made the array smaller
    /// than the view).
    #[cold]
    fn non_finite(&self, vrs: &[u32], values: &[f64]) -> Option<Error> {
        let k = vrs.iter().zip(values).position(|(vr, v)| !v.is_finite() && !self.calls.absent_element(*vr))?;
        let variable = self
            .core
            .fmu
            .description
            .model_variables
            .iter()
            .find(|v| v.is_real() && v.value_reference == vrs[k])
            .map_or_else(|| format!("<Real value reference {}>", vrs[k]), |v| v.name.clone());
        // the getter of the variable's type (an array element of the view: its array's)
        let function = match self.core.fmu.fmi3_description() {
            None => "fmi2GetReal",
            Some(md) => match md.model_variables.iter().find(|v| v.value_reference == vrs[k]) {
                Some(v) if v.value_type == model_description::fmi3::ValueType::Float32 => "fmi3GetFloat32",
                _ => "fmi3GetFloat64",
            },
        };
        Some(Error::NonFinite {
            instance: self.core.name.clone(),
            function,
            fmu: self.core.fmu.source.clone(),
            variable,
            value: values[k],
            time: self.core.time,
        })
    }

    /// `fmi2SetReal` / `fmi3SetFloat64` (the other FMI 3.0 types as for [`Instance::get_real`]).
    #[inline]
    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "set_real: one value per value reference");
        self.set_passing((Kind::Real, |v: f64| Held::Real(v.to_bits())), vrs, values, <dyn Calls>::set_real)
    }

    get_set! {
        /// `fmi2GetInteger`; FMI 3.0: `fmi3GetInt32`, Enumerations by `fmi3GetInt64`, Int8 ..
        /// UInt16 and array elements by their own getters.
        get_integer;
        /// `fmi2SetInteger`; FMI 3.0: `fmi3SetInt32`, the other types as for
        /// [`Instance::get_integer`].
        set_integer;
        i32, Kind::Integer, Held::Integer;

        /// `fmi2GetBoolean` (fmi2Boolean is a C int: 0 false, else true); FMI 3.0:
        /// `fmi3GetBoolean` (a C `bool`, read as a byte: nonzero is true), as 0 or 1.
        get_boolean;
        /// `fmi2SetBoolean` / `fmi3SetBoolean` (nonzero is true).
        set_boolean;
        i32, Kind::Boolean, |v: i32| Held::Boolean(v != 0);
    }

    /// `fmi2GetString` / `fmi3GetString` of one variable (copied).
    pub fn get_string(&mut self, vr: u32) -> Result<String> {
        let p = self.calls.get_string(&mut self.core, vr)?;
        if p.is_null() {
            return Ok(String::new());
        }
        // SAFETY: the FMU returns a NUL-terminated string valid until the next call.
        Ok(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
    }

    /// The value of `vr` as the FMU holds it, where the view's f64 is not it
    /// ([`Fmu::exact_kind`]: `fmi3GetInt64`, `fmi3GetUInt64`, `fmi3GetBinary` of the
    /// element), or a String's text.
    pub fn get_exact(&mut self, vr: u32) -> Result<crate::fmi3::Exact> {
        let mut values = Vec::with_capacity(1);
        self.get_exact_many(&[vr], &mut values)?;
        Ok(values.pop().expect("one value per value reference"))
    }

    /// [`Instance::get_exact`] of each of `vrs` into `values` (cleared first, then one per
    /// value reference): each array is read once for all its elements among `vrs`, so
    /// that a row of the results costs time linear in the elements.
    pub fn get_exact_many(&mut self, vrs: &[u32], values: &mut Vec<crate::fmi3::Exact>) -> Result<()> {
        values.clear();
        let mut rest = vrs;
        while let Some(&first) = rest.first() {
            if self.is_string(first) {
                values.push(self.get_string(first).map(crate::fmi3::Exact::Text)?);
                rest = &rest[1..];
                continue;
            }
            // the run of values up to the next String, in one call
            let run = rest.iter().position(|vr| self.is_string(*vr)).unwrap_or(rest.len());
            self.calls.get_exact(&mut self.core, &rest[..run], values)?;
            rest = &rest[run..];
        }
        Ok(())
    }

    /// Whether the view's variable `vr` is a String (an Int64, UInt64 or Binary found in
    /// the view's map first: no scan of the variables per element of an array).
    fn is_string(&self, vr: u32) -> bool {
        self.core.fmu.exact_kind(vr).is_none()
            && self.core.fmu.description.model_variables.iter().any(|v| {
                v.value_reference == vr && matches!(v.variable_type, model_description::VariableType::String { .. })
            })
    }

    /// `fmi3SetInt64` / `fmi3SetUInt64` of `vr` exactly (a variable of
    /// [`Fmu::exact_kind`] Int64 or UInt64); a value outside its type's range is refused.
    pub fn set_exact_integer(&mut self, vr: u32, value: i128) -> Result<()> {
        let continuous_time = self.in_continuous_time();
        if let Some(d) = self.discrete.as_deref_mut() {
            if d.defer(continuous_time, Kind::Exact, vr, Held::Exact(value)) {
                return Ok(());
            }
        }
        self.calls.set_exact_integer(&mut self.core, vr, value)
    }

    /// `fmi2SetString` / `fmi3SetString` of one variable.
    pub fn set_string(&mut self, vr: u32, value: &str) -> Result<()> {
        let s = CString::new(value).map_err(|_| Error::InvalidValue {
            variable: format!("{}.<vr {vr}>", self.core.name),
            value: value.into(),
            reason: "NUL in string".into(),
        })?;
        let continuous_time = self.in_continuous_time();
        if let Some(d) = self.discrete.as_deref_mut() {
            if d.defer(continuous_time, Kind::String, vr, Held::String(value.into())) {
                return Ok(());
            }
        }
        self.calls.set_string(&mut self.core, vr, s.as_ptr())
    }

    /// `fmi2DoStep` / `fmi3DoStep` from `time` over `step` (Co-Simulation).
    ///
    /// FMI 3.0: an early return (`earlyReturn` with `lastSuccessfulTime` before the step's
    /// end) is continued from the time reached until the step's end, so that the caller
    /// sees the step it asked for; a return that makes no progress is an error naming the
    /// time. `terminateSimulation` is reported as FMI 2.0 reports it, a Discard with
    /// [`Instance::terminated_status`] true and [`Instance::last_successful_time`] the time
    /// reached, which ends the run there.
    #[inline]
    pub fn do_step(&mut self, time: f64, step: f64) -> Result<()> {
        self.calls.do_step(&mut self.core, time, step)
    }

    /// Isolated: hands `fmi2DoStep(time, step)` (or `fmi3DoStep`) to the host without waiting for it, so
    /// that the hosts of several instances step at the same time; the next
    /// [`Instance::do_step`] with the same arguments takes its answer. False (nothing done)
    /// in process, and when the instance cannot step in its state (`do_step` then says why).
    pub fn post_step(&mut self, time: f64, step: f64) -> bool {
        let Some((op, step)) = self.calls.posted_step(time, step) else { return false };
        let Some(host) = self.core.host.as_deref_mut() else { return false };
        if !self.core.state.is_running() {
            return false;
        }
        crate::isolate::proxy::post_step(host, op, time, step);
        true
    }

    /// `fmi2GetFMUstate` / `fmi3GetFMUState`: saves the current state.
    pub fn get_state(&mut self) -> Result<FmuState> {
        let mut s: *mut c_void = std::ptr::null_mut();
        self.calls.get_state(&mut self.core, &mut s)?;
        self.core.saved.push(s);
        Ok(FmuState(s))
    }

    /// `fmi2GetFMUstate` / `fmi3GetFMUState` into an existing state (overwritten).
    pub fn update_state(&mut self, state: &mut FmuState) -> Result<()> {
        let mut s = state.0;
        self.calls.get_state(&mut self.core, &mut s)?;
        if s != state.0 {
            self.core.saved.retain(|p| *p != state.0);
            self.core.saved.push(s);
            state.0 = s;
        }
        Ok(())
    }

    /// `fmi2SetFMUstate` / `fmi3SetFMUState`: restores a saved state.
    pub fn set_state(&mut self, state: &FmuState) -> Result<()> {
        self.calls.set_state(&mut self.core, state.0)?;
        // the FMU holds the inputs of the state now: a later set is not compared with ours
        if let Some(d) = self.discrete.as_deref_mut() {
            d.forget_given();
        }
        Ok(())
    }

    /// `fmi2FreeFMUstate` / `fmi3FreeFMUState`.
    pub fn free_state(&mut self, state: FmuState) -> Result<()> {
        self.core.saved.retain(|p| *p != state.0);
        let mut s = state.0;
        self.calls.free_state(&mut self.core, &mut s)
    }

    /// `fmi2SetTime` / `fmi3SetTime` (Model Exchange).
    #[inline]
    pub fn set_time(&mut self, time: f64) -> Result<()> {
        self.core.time = time;
        self.calls.set_time(&mut self.core, time)
    }

    /// `fmi2SetContinuousStates` / `fmi3SetContinuousStates`.
    #[inline]
    pub fn set_continuous_states(&mut self, x: &[f64]) -> Result<()> {
        self.calls.set_continuous_states(&mut self.core, x)
    }

    /// `fmi2GetContinuousStates` / `fmi3GetContinuousStates`.
    pub fn get_continuous_states(&mut self, x: &mut [f64]) -> Result<()> {
        self.calls.get_continuous_states(&mut self.core, x)
    }

    /// `fmi2GetDerivatives` / `fmi3GetContinuousStateDerivatives`.
    #[inline]
    pub fn get_derivatives(&mut self, dx: &mut [f64]) -> Result<()> {
        self.calls.get_derivatives(&mut self.core, dx)
    }

    /// `fmi2GetEventIndicators` / `fmi3GetEventIndicators`.
    #[inline]
    pub fn get_event_indicators(&mut self, z: &mut [f64]) -> Result<()> {
        self.calls.get_event_indicators(&mut self.core, z)
    }

    /// Whether the FMU's library has `fmi2GetDirectionalDerivative` /
    /// `fmi3GetDirectionalDerivative` (an isolated instance's host does not forward it).
    pub fn has_directional_derivative(&self) -> bool {
        self.calls.has_directional_derivative()
    }

    /// The directional derivative at the instance's current point: `dv_unknown` =
    /// d(unknowns)/d(knowns) `dv_known` (FMI 2.0 section 2.1.9, FMI 3.0 section 2.2.11).
    /// [`Error::Overrun`] when the FMU wrote past the `nUnknown` values of `dvUnknown` (FMI
    /// 3.0: the `nSensitivity` values of `sensitivity`), or
    /// (FMI 2.0) past a block it allocated through `allocateMemory`: the guard's red zone
    /// took the write; the instance is still usable, the values are not.
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<()> {
        assert_eq!(knowns.len(), dv_known.len(), "get_directional_derivative: one seed per known");
        assert_eq!(unknowns.len(), dv_unknown.len(), "get_directional_derivative: one value per unknown");
        // dvUnknown with a red zone after it: a write past its nUnknown values is seen
        // there (and overwrites nothing of the master's)
        let n = dv_unknown.len();
        let zone = |v: &[f64]| v[n..].iter().rposition(|x| x.to_bits() != DV_RED_ZONE.to_bits());
        let mut out = vec![DV_RED_ZONE; n + DV_RED_ZONE_LEN];
        self.calls.get_directional_derivative(&mut self.core, Seed { unknowns, knowns, dv_known }, &mut out[..n])?;
        dv_unknown.copy_from_slice(&out[..n]);
        match zone(&out) {
            Some(k) => {
                // each generation's names of the call and its buffer
                let (function, buffer, count) = match self.core.fmu.abi {
                    Abi::Fmi2(_) => ("fmi2GetDirectionalDerivative", "dvUnknown", "nUnknown"),
                    Abi::Fmi3(_) => ("fmi3GetDirectionalDerivative", "sensitivity", "nSensitivity"),
                };
                Err(Error::Overrun {
                    instance: self.core.name.clone(),
                    function,
                    what: format!("{} bytes past the {} bytes of {buffer} ({count} = {n})", 8 * (k + 1), 8 * n),
                })
            }
            None => Ok(()),
        }
    }

    /// `fmi2EnterEventMode` / `fmi3EnterEventMode`.
    pub fn enter_event_mode(&mut self) -> Result<()> {
        self.calls.enter_event_mode(&mut self.core)?;
        if self.core.state == InstanceState::ContinuousTime {
            self.core.state = InstanceState::Running;
        }
        Ok(())
    }

    /// `fmi2NewDiscreteStates`; FMI 3.0: `fmi3UpdateDiscreteStates`, its outputs as the
    /// FMI 2.0 event info (`discreteStatesNeedUpdate` is `newDiscreteStatesNeeded`).
    pub fn new_discrete_states(&mut self) -> Result<EventInfo> {
        self.calls.new_discrete_states(&mut self.core)
    }

    /// `fmi2EnterContinuousTimeMode` / `fmi3EnterContinuousTimeMode`.
    pub fn enter_continuous_time_mode(&mut self) -> Result<()> {
        self.calls.enter_continuous_time_mode(&mut self.core)?;
        if self.core.state == InstanceState::Running {
            self.core.state = InstanceState::ContinuousTime;
        }
        Ok(())
    }

    /// `fmi2CompletedIntegratorStep` / `fmi3CompletedIntegratorStep`: (enter event mode,
    /// terminate simulation).
    pub fn completed_integrator_step(&mut self) -> Result<(bool, bool)> {
        self.calls.completed_integrator_step(&mut self.core)
    }

    /// `fmi2GetBooleanStatus(fmi2Terminated)` after a Discard: whether the FMU wants to
    /// stop; FMI 3.0: whether the last `fmi3DoStep` said `terminateSimulation`.
    pub fn terminated_status(&mut self) -> Option<bool> {
        self.calls.terminated_status(&mut self.core)
    }

    /// `fmi2GetRealStatus(fmi2LastSuccessfulTime)`; FMI 3.0: the `lastSuccessfulTime` of
    /// the `fmi3DoStep` that said `terminateSimulation`.
    pub fn last_successful_time(&mut self) -> Option<f64> {
        self.calls.last_successful_time(&mut self.core)
    }
}

impl Instance {
    /// Terminates (if not yet) and frees the instance, as dropping it does; for an
    /// isolated instance, the end of its host process during the free (an FMU that
    /// crashes in its free function) is the error, naming the function.
    pub fn free(mut self) -> Result<()> {
        let failed_before = self.core.host.as_ref().is_some_and(|h| h.failure.is_some());
        self.release();
        let function = self.calls.free_functions().2;
        let cause = self.core.host.as_ref().and_then(|h| h.failure.clone()).filter(|_| !failed_before);
        // freed: the drop calls nothing more
        self.core.state = InstanceState::Fatal;
        match cause {
            Some(cause) => Err(Error::Host { instance: self.core.name.clone(), function, time: self.core.time, cause }),
            None => Ok(()),
        }
    }

    fn release(&mut self) {
        if self.core.state == InstanceState::Fatal {
            return; // the standard: nothing may be called after a fatal error
        }
        let _ = self.terminate();
        let (free_state, free_instance, function) = self.calls.free_functions();
        if let Some(free_state) = free_state {
            for mut s in std::mem::take(&mut self.core.saved) {
                // SAFETY: states we obtained from this instance and did not free; both
                // generations' functions take (instance, *mut state).
                unsafe { free_state(self.core.component, &mut s) };
            }
        }
        let _mark = self.core.mark_call(function);
        // SAFETY: the component came from the instantiate call and is freed once (the
        // state is Fatal after, and nothing is called then).
        unsafe { free_instance(self.core.component) };
        self.core.state = InstanceState::Fatal;
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        self.release();
    }
}

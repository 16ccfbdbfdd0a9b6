//! An instance's calls of the FMI 3.0 C API, the FMI 3.0 view included: the view's Reals,
//! Integers and Booleans of the other FMI 3.0 types and the elements of arrays (see
//! [`crate::fmi3`]) go by their own getters and setters, an array element set alone with
//! the array's other elements as set before; `fmi3DoStep`'s early returns, events and
//! `terminateSimulation` become the step FMI 2.0 reports.

use std::collections::HashMap;
use std::ffi::{c_char, c_int, c_void, CString};
use std::sync::Arc;

use super::clocked::HeldNumber;
use super::core::{call, Calls, ClockCalls, Core, FreeInstanceFunction, FreeStateFunction, ResetFunction, Seed};
use crate::c_types::{Component, EventInfo};
use crate::error::{Error, Result};
use crate::fmi3::{Access, Fmi3Abi};
use crate::fmu::{Fmu, Interface};
use crate::instance::core::InstanceState;
use crate::log::LogSink;
use crate::status::Status;

/// The FMI 3.0 calls: the library's table and description, and what an instance keeps
/// that FMI 2.0 has no place for.
pub(crate) struct Fmi3 {
    pub(super) a: Arc<Fmi3Abi>,
    /// What `setup_experiment` was given (tolerance, start, stop), passed on by
    /// `fmi3EnterInitializationMode`.
    experiment: (Option<f64>, f64, Option<f64>),
    /// The time `fmi3DoStep` reported `terminateSimulation` at.
    terminate_requested: Option<f64>,
    /// Booleans as the bytes the ABI has (reused).
    bytes: Vec<u8>,
    /// The values of arrays set element by element, by value reference.
    arrays: HashMap<u32, Vec<f64>>,
    /// Those of the Int64 and UInt64 arrays, as the integers themselves (an f64 holds them
    /// exactly only up to 2^53).
    wide_arrays: HashMap<u32, Vec<i128>>,
    /// The arrays whose size now is not the view's (a structural parameter changed in
    /// Reconfiguration Mode, or to be): by the FMU's value reference, the view's dimensions
    /// and those of now (`structural::resized_arrays`); empty almost always.
    pub(super) resized: HashMap<u32, (Vec<u64>, Vec<u64>)>,
    /// The structural parameters whose value now is not the view's (value reference, value).
    pub(super) sizes_now: Vec<(u32, f64)>,
    /// Co-Simulation with `eventModeUsed` (as [`crate::Fmu::event_mode`] decided: an FMU
    /// with clocks, or asked for; false again when an FMU without clocks refused to be
    /// instantiated with it and accepted without).
    event_mode: std::cell::Cell<bool>,
    /// The FMU's output clocks (value references), read by `fmi3GetClock` in every event.
    pub(super) output_clocks: Vec<u32>,
    /// The output clocks' ticks not yet taken (`instance/clocks.rs`).
    pub(super) output_ticks: Vec<super::core::OutputTick>,
    /// The input clocks whose interval the FMU gives (tunable, changing, countdown), read
    /// by `fmi3GetIntervalDecimal` in every event.
    interval_clocks: Vec<u32>,
    /// The fixed input clocks: their interval read in the first event of a run (the one
    /// that ends initialization) only, as it cannot change afterwards.
    fixed_clocks: Vec<u32>,
    /// The fixed clocks' intervals were read in this run.
    fixed_read: bool,
    /// What the FMU said of their intervals, not yet taken: (event time, clock, interval).
    pub(super) intervals: Vec<(f64, u32, super::core::Interval)>,
    /// Scheduled Execution: the environment of the FMU's callbacks (boxed: its address is
    /// the FMU's for as long as the instance lives).
    scheduled: Option<Box<super::callbacks::ScheduledEnvironment>>,
    /// The clocked variables: held between their clocks' ticks, sets queued to the next
    /// (`clocked.rs`).
    pub(super) clocked: super::clocked::ClockedExchange,
    /// The input clocks set (`fmi3SetClock`) in the current event: their clocked variables
    /// are read when it settles.
    pub(super) ticked_inputs: Vec<u32>,
    /// The output clocks `fmi3GetClock` reported active as the current event opened (an FMU
    /// may activate one in `fmi3SetClock`): counted then, their variables read from the FMU
    /// while it is open, not counted again when it settles.
    pub(super) opened_outputs: Vec<u32>,
}

/// A function of the FMI 3.0 table that may be absent, or the error naming it.
macro_rules! f3 {
    ($core:expr, $a:expr, $field:ident, $name:literal) => {
        $core.optional($a.functions.$field, $name)?
    };
}

// the view's reads and sets, and the typed calls with clocked values (after `f3!`, which they use)
mod arrays;
mod typed;

impl Fmi3 {
    /// The calls of an instance of `interface`; `event_mode`: Co-Simulation with
    /// `eventModeUsed` (the FMU's decision, [`crate::Fmu::event_mode`]).
    pub(crate) fn new(a: Arc<Fmi3Abi>, interface: Interface, event_mode: bool) -> Fmi3 {
        let event_mode = interface == Interface::CoSimulation && event_mode;
        use crate::clocks::{ClockCausality, ClockKind};
        // Scheduled Execution runs the clocks through its own calls (`scheduled.rs`)
        let clocks = if interface == Interface::ScheduledExecution {
            Vec::new()
        } else {
            crate::clocks::clocks_of(&a.description)
        };
        let output_clocks =
            clocks.iter().filter(|c| c.causality == ClockCausality::Output).map(|c| c.value_reference).collect();
        let given = |fixed: bool| -> Vec<u32> {
            clocks
                .iter()
                .filter(|c| {
                    c.causality == ClockCausality::Input
                        && !matches!(c.kind, ClockKind::Constant | ClockKind::Triggered)
                        && (c.kind == ClockKind::Fixed) == fixed
                })
                .map(|c| c.value_reference)
                .collect()
        };
        let (interval_clocks, fixed_clocks) = (given(false), given(true));
        Fmi3 {
            experiment: (None, 0.0, None),
            terminate_requested: None,
            bytes: Vec::new(),
            arrays: HashMap::new(),
            wide_arrays: HashMap::new(),
            resized: HashMap::new(),
            sizes_now: Vec::new(),
            event_mode: std::cell::Cell::new(event_mode),
            output_clocks,
            output_ticks: Vec::new(),
            interval_clocks,
            fixed_clocks,
            fixed_read: false,
            intervals: Vec::new(),
            scheduled: (interface == Interface::ScheduledExecution).then(Box::default),
            clocked: super::clocked::ClockedExchange::new(&a.description, &a.special),
            ticked_inputs: Vec::new(),
            opened_outputs: Vec::new(),
            a,
        }
    }

    /// The FMU's table and description.
    pub(super) fn abi(&self) -> &Fmi3Abi {
        &self.a
    }

    /// `terminateSimulation` from `function` (called at `at`) at the time `reached`,
    /// reported as FMI 2.0 reports it: a Discard, with `terminated_status` true and
    /// `last_successful_time` `reached`.
    pub(super) fn terminated_at(&mut self, core: &mut Core, function: &'static str, at: f64, reached: f64) -> Error {
        core.time = reached;
        self.terminate_requested = Some(reached);
        Error::Fmi {
            instance: core.name.clone(),
            function,
            status: Status::Discard,
            time: Some(at),
            log: format!("terminateSimulation at t = {reached} s"),
        }
    }

    /// The event a Co-Simulation `fmi3DoStep` asked for (`eventHandlingNeeded`) at `time`:
    /// Event Mode, `fmi3UpdateDiscreteStates` until no new discrete states are needed (at
    /// most 1000 times), back to Step Mode. `Some(time)` when the FMU asked to terminate.
    fn cs_event(&mut self, core: &mut Core, time: f64) -> Result<Option<f64>> {
        self.enter_event_mode(core)?;
        self.settle_event(core, time)
    }

    /// In Event Mode at `time`: `fmi3UpdateDiscreteStates` until no new discrete states are
    /// needed (at most 1000 times), then `fmi3EnterStepMode`. `Some(time)` when the FMU asked
    /// to terminate.
    pub(super) fn settle_event(&mut self, core: &mut Core, time: f64) -> Result<Option<f64>> {
        for _ in 0..1000 {
            let info = self.new_discrete_states(core)?;
            if info.terminate_simulation != 0 {
                return Ok(Some(time));
            }
            if info.new_discrete_states_needed == 0 {
                let f = f3!(core, self.a, enter_step_mode, "fmi3EnterStepMode");
                let c = core.component;
                call!(core, "fmi3EnterStepMode", Some(time), f(c))?;
                return Ok(None);
            }
        }
        core.state = InstanceState::Errored;
        Err(core.returned(
            "fmi3UpdateDiscreteStates",
            time,
            "it asked for new discrete states (newDiscreteStatesNeeded = true) for the 1000th time in one event: \
             1000 updates in one event is cosim's bound"
                .into(),
        ))
    }
}

/// The warning of a second instantiation without Event Mode after `function` refused it.
fn refused_event_mode(function: &str) -> String {
    format!(
        "{function} returned NULL with eventModeUsed = true although the FMU declares hasEventMode: instantiated \
         again without Event Mode (the FMU handles its events inside fmi3DoStep)"
    )
}

/// The error of a Scheduled Execution call on an instance of another interface.
#[cold]
pub(super) fn not_scheduled(name: &str) -> Error {
    Error::Instance { name: name.into(), reason: "it is not instantiated for Scheduled Execution (--interface se)" }
}

/// The error of an exact read or set of `vr`, which is no 64-bit integer or Binary.
#[cold]
fn not_exact(core: &Core, vr: u32, value: String) -> Error {
    Error::InvalidValue {
        variable: format!("{}.<value reference {vr}>", core.name),
        value,
        reason: "not an Int64, UInt64 or Binary of the FMU's: its value is the view's".into(),
    }
}

/// The typed getters and setters of [`Calls`]: the FMU's own calls, but while the instance
/// runs with clocked variables, their values held between ticks (read) and queued until
/// their clock ticks (set). (getter, setter, value type, the FMU's getter and setter) a row.
macro_rules! get_set {
    ($($get:ident, $set:ident, $t:ty, $fmu_get:ident, $fmu_set:ident;)*) => {$(
        #[inline]
        fn $get(&mut self, core: &mut Core, vrs: &[u32], values: &mut [$t]) -> Result<()> {
            if !self.clocked.is_empty() && core.state.is_running() {
                return self.get_held(core, vrs, values, Self::$fmu_get);
            }
            self.$fmu_get(core, vrs, values)
        }

        #[inline]
        fn $set(&mut self, core: &mut Core, vrs: &[u32], values: &[$t]) -> Result<()> {
            if !self.clocked.is_empty() && core.state.is_running() {
                return self.set_queued(core, vrs, values, Self::$fmu_set);
            }
            self.$fmu_set(core, vrs, values)
        }
    )*};
}

impl Calls for Fmi3 {
    /// The instantiate function of `interface`.
    fn instantiate_function(&self, interface: Interface) -> &'static str {
        match interface {
            Interface::CoSimulation => "fmi3InstantiateCoSimulation",
            Interface::ModelExchange => "fmi3InstantiateModelExchange",
            Interface::ScheduledExecution => "fmi3InstantiateScheduledExecution",
        }
    }

    /// `fmi3InstantiateCoSimulation` (early return allowed, `eventModeUsed` as the FMU's
    /// decision says, no intermediate update) or `fmi3InstantiateModelExchange`, logging off, the
    /// messages to `log` (which outlives the instance).
    fn instantiate(
        &self,
        fmu: &Fmu,
        name: &str,
        name_c: &CString,
        _callbacks: &crate::c_types::CallbackFunctions,
        log: &LogSink,
    ) -> Result<Component> {
        let a = &self.a;
        let environment = log as *const LogSink as *mut c_void;
        let logger: Option<fmi_sys::fmi3::Fmi3LogMessageCallback> = Some(crate::log::log_message::<LogSink>);
        let missing = |symbol| Error::MissingSymbol { path: fmu.source.clone(), symbol };
        let function = self.instantiate_function(fmu.interface);
        let component = match fmu.interface {
            Interface::CoSimulation => {
                let f = a.functions.instantiate_co_simulation.ok_or(missing(function))?;
                let _mark =
                    crate::call_site::enter(name, &fmu.source, function, 0.0, crate::call_site::owner_of_call());
                // SAFETY: every pointer is valid for the call; the log outlives the instance.
                unsafe {
                    f(
                        name_c.as_ptr(),
                        a.token.as_ptr(),
                        a.resource_path.as_ptr(),
                        0,
                        0,
                        self.event_mode.get() as u8,
                        1,
                        std::ptr::null(),
                        0,
                        environment,
                        logger,
                        None,
                    )
                }
            }
            Interface::ModelExchange => {
                let f = a.functions.instantiate_model_exchange.ok_or(missing(function))?;
                let _mark =
                    crate::call_site::enter(name, &fmu.source, function, 0.0, crate::call_site::owner_of_call());
                // SAFETY: as above.
                unsafe { f(name_c.as_ptr(), a.token.as_ptr(), a.resource_path.as_ptr(), 0, 0, environment, logger) }
            }
            Interface::ScheduledExecution => match self.scheduled.as_deref() {
                Some(scheduled) => self.instantiate_scheduled(fmu, name, name_c, log, scheduled)?,
                None => return Err(not_scheduled(name)),
            },
        };
        if component.is_null()
            && fmu.interface == Interface::CoSimulation
            && self.event_mode.get()
            && crate::clocks::clocks_of(&a.description).is_empty()
        {
            // an FMU that declares hasEventMode may still refuse eventModeUsed (the Reference
            // FMUs' Roberts does): without clocks, which need Event Mode, a second try
            // without it, the run then stepping without Event Mode as for an FMU without it
            self.event_mode.set(false);
            log.push(crate::log::LogRecord {
                status: Status::Warning,
                category: "cosim".into(),
                message: refused_event_mode(function),
            });
            return self.instantiate(fmu, name, name_c, _callbacks, log);
        }
        if component.is_null() {
            return Err(Error::Instantiate { instance: name.into(), function, log: log.recent_problems() });
        }
        Ok(component)
    }

    /// `fmi3Instantiate*` in the host of `channel`; the status.
    fn instantiate_in(
        &self,
        fmu: &Fmu,
        channel: &mut crate::isolate::channel::Channel,
        name_c: &CString,
    ) -> Result<i32> {
        if fmu.interface == Interface::ScheduledExecution {
            return Err(Error::Instance {
                name: String::from_utf8_lossy(name_c.as_bytes()).into_owned(),
                reason: "Scheduled Execution is not run in a host process: the FMU calls this process back (clockUpdate, lockPreemption) from inside fmi3ActivateModelPartition, and a host answers one call at a time: run it without isolation",
            });
        }
        let event_mode = (fmu.interface == Interface::CoSimulation).then_some(self.event_mode.get());
        let status =
            crate::isolate::proxy3::instantiate_in(channel, name_c, &self.a.token, &self.a.resource_path, event_mode);
        let refused = status != 0 && channel.failure.is_none() && channel.over_limit.is_none();
        if refused && event_mode == Some(true) && crate::clocks::clocks_of(&self.a.description).is_empty() {
            // the second try of `instantiate`, in the host
            self.event_mode.set(false);
            channel.push_log(Status::Warning, refused_event_mode("fmi3InstantiateCoSimulation"));
            return self.instantiate_in(fmu, channel, name_c);
        }
        Ok(status)
    }

    fn reset_name(&self) -> &'static str {
        "fmi3Reset"
    }

    fn configure(&mut self, core: &mut Core) -> Result<()> {
        self.configure_structural(core)
    }

    fn activate_model_partition(&mut self, core: &mut Core, clock: u32, time: f64) -> Result<bool> {
        let scheduled = self.scheduled.take().ok_or_else(|| not_scheduled(&core.name))?;
        let r = self.activate(core, &scheduled, clock, time);
        self.scheduled = Some(scheduled);
        r
    }

    fn reconfigure(&mut self, core: &mut Core, values: &[(&str, f64)]) -> Result<()> {
        self.reconfigure_between_steps(core, values)
    }

    fn absent_element(&self, vr: u32) -> bool {
        !self.resized.is_empty() && self.special(vr).is_some_and(|access| self.now(access).1.is_none())
    }

    fn countdown_interval(&mut self, core: &mut Core, clock: u32) -> Result<Option<f64>> {
        self.scheduled.as_ref().ok_or_else(|| not_scheduled(&core.name))?;
        self.changed_interval(core, clock)
    }

    fn output_clock_ticked(&mut self, core: &mut Core, clock: u32) -> Result<bool> {
        self.scheduled.as_ref().ok_or_else(|| not_scheduled(&core.name))?;
        self.clock_ticked(core, clock)
    }

    fn setup_function(&self) -> &'static str {
        "fmi3EnterInitializationMode"
    }

    fn setup_experiment(&mut self, _: &mut Core, tolerance: Option<f64>, start: f64, stop: Option<f64>) -> Result<()> {
        self.experiment = (tolerance, start, stop);
        Ok(())
    }

    fn enter_initialization_mode(&mut self, core: &mut Core) -> Result<()> {
        let (c, f) = (core.component, self.a.functions.enter_initialization_mode);
        let (tolerance, start, stop) = self.experiment;
        call!(
            core,
            "fmi3EnterInitializationMode",
            Some(start),
            f(c, tolerance.is_some() as u8, tolerance.unwrap_or(0.0), start, stop.is_some() as u8, stop.unwrap_or(0.0))
        )
    }

    fn exit_initialization_mode(&mut self, core: &mut Core) -> Result<()> {
        // the clocked variables the master reads hold what initialization computed until
        // their clocks' first ticks (read while Initialization Mode allows it)
        for (slot, access) in self.clocked.unheld() {
            let values = self.get_all(core, access)?;
            self.clocked.hold(slot, values);
        }
        let (c, f) = (core.component, self.a.functions.exit_initialization_mode);
        call!(core, "fmi3ExitInitializationMode", None, f(c))?;
        // instantiated with eventModeUsed, the FMU is in Event Mode now (FMI 3.0's
        // Co-Simulation state machine): its discrete states are settled and it enters Step
        // Mode before the first fmi3DoStep
        if self.event_mode.get() {
            let time = core.time;
            if let Some(t) = self.settle_event(core, time)? {
                return Err(self.terminated_at(core, "fmi3UpdateDiscreteStates", t, t));
            }
        }
        Ok(())
    }

    fn terminate(&mut self, core: &mut Core) -> Result<()> {
        let (c, f) = (core.component, self.a.functions.terminate);
        call!(core, "fmi3Terminate", None, f(c))
    }

    fn reset_function(&self, core: &Core) -> Result<ResetFunction> {
        core.optional(self.a.functions.reset, "fmi3Reset")
    }

    fn forget_run(&mut self) {
        self.clocked.forget_run(&self.a.description);
        self.ticked_inputs.clear();
        self.opened_outputs.clear();
        self.fixed_read = false;
        self.output_ticks.clear();
        self.intervals.clear();
        self.terminate_requested = None;
    }

    get_set! {
        get_real, set_real, f64, fmu_get_real, fmu_set_real;
        get_integer, set_integer, i32, fmu_get_integer, fmu_set_integer;
        get_boolean, set_boolean, i32, fmu_get_boolean, fmu_set_boolean;
    }

    fn get_string(&mut self, core: &mut Core, vr: u32) -> Result<*const c_char> {
        let mut p: *const c_char = std::ptr::null();
        let c = core.component;
        let f = f3!(core, self.a, get_string, "fmi3GetString");
        call!(core, "fmi3GetString", None, f(c, &vr, 1, &mut p, 1))?;
        Ok(p)
    }

    fn set_string(&mut self, core: &mut Core, vr: u32, p: *const c_char) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, set_string, "fmi3SetString");
        call!(core, "fmi3SetString", None, f(c, &vr, 1, &p, 1))
    }

    fn get_exact(&mut self, core: &mut Core, vrs: &[u32], values: &mut Vec<crate::fmi3::Exact>) -> Result<()> {
        // each array read once for all its elements asked here (a row of the results):
        // the FMU does not change in between, and a row costs time linear in the elements
        let mut arrays: HashMap<u32, Vec<crate::fmi3::Exact>> = HashMap::new();
        for &vr in vrs {
            let Some(access) = self.special(vr) else { return Err(not_exact(core, vr, String::new())) };
            let (n, element) = self.now(access);
            let Some(k) = element else { return Err(self.absent_element(core, access, n, String::new())) };
            if access.count <= 1 {
                values.extend(self.exact_all(core, access)?);
                continue;
            }
            let all = match arrays.entry(access.vr) {
                std::collections::hash_map::Entry::Occupied(read) => read.into_mut(),
                std::collections::hash_map::Entry::Vacant(unread) => unread.insert(self.exact_all(core, access)?),
            };
            values.push(all[k].clone());
        }
        Ok(())
    }

    fn set_exact_integer(&mut self, core: &mut Core, vr: u32, value: i128) -> Result<()> {
        use model_description::fmi3::ValueType as T;
        match self.special(vr) {
            Some(a) if a.count == 1 && matches!(a.value_type, T::Int64 | T::UInt64) => self.set_wide(core, a, &[value]),
            Some(a) if matches!(a.value_type, T::Int64 | T::UInt64) => self.set_wide_element(core, a, value),
            _ => Err(not_exact(core, vr, value.to_string())),
        }
    }

    /// An early return (`earlyReturn` with `lastSuccessfulTime` before the step's end) is
    /// continued from the time reached until the step's end; a return that makes no
    /// progress is an error naming the time.
    fn do_step(&mut self, core: &mut Core, time: f64, step: f64) -> Result<()> {
        let f = f3!(core, self.a, do_step, "fmi3DoStep");
        let c = core.component;
        let end = time + step;
        let mut at = time;
        // each early return must make progress; a bound on the returns per step besides,
        // so that an FMU creeping forward by ulps cannot hold the run forever
        for _ in 0..1000 {
            let (mut event, mut terminate, mut early, mut reached) = (0u8, 0u8, 0u8, at);
            call!(
                core,
                "fmi3DoStep",
                Some(at),
                f(c, at, end - at, 1, &mut event, &mut terminate, &mut early, &mut reached)
            )?;
            if terminate != 0 {
                let reached = if early != 0 && reached.is_finite() { reached } else { end };
                return Err(self.terminated_at(core, "fmi3DoStep", at, reached));
            }
            if event != 0 && self.event_mode.get() {
                let reached = if early != 0 { reached } else { end };
                core.time = reached;
                if let Some(t) = self.cs_event(core, reached)? {
                    return Err(self.terminated_at(core, "fmi3UpdateDiscreteStates", t, t));
                }
            }
            if early == 0 {
                core.time = end;
                return Ok(());
            }
            // an early return at the time already reached is progress when it was to handle
            // an event there: in Event Mode, entered and left above, or, instantiated without
            // it, inside the FMU, which said so (Dymola 2025x CoupledClutches with Dassl
            // returns early so at t = 0 and steps on from there, as in fmpy's loop): the next
            // fmi3DoStep goes on from the settled discrete states (at most 1000 returns a step)
            let settled_here = event != 0 && reached == at;
            let progressed = settled_here || (reached > at && reached <= end);
            if !progressed {
                core.state = InstanceState::Errored;
                return Err(core.returned(
                    "fmi3DoStep",
                    at,
                    format!(
                        "earlyReturn = true with lastSuccessfulTime = {reached} s made no progress from {at} s toward the step's end {end} s"
                    ),
                ));
            }
            if reached == end {
                core.time = end;
                return Ok(());
            }
            at = reached;
        }
        core.state = InstanceState::Errored;
        Err(core.returned(
            "fmi3DoStep",
            at,
            format!(
                "it returned early (earlyReturn = true) for the 1000th time in the step from {time} s to {end} s: \
                 1000 early returns in one step is cosim's bound"
            ),
        ))
    }

    fn posted_step(&self, time: f64, step: f64) -> Option<(crate::isolate::protocol::Op, f64)> {
        // the arguments of the first fmi3DoStep of `do_step`
        self.a.functions.do_step.is_some().then_some((crate::isolate::protocol::Op::DoStep3, (time + step) - time))
    }

    fn get_state(&mut self, core: &mut Core, s: &mut *mut c_void) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, get_fmu_state, "fmi3GetFMUState");
        call!(core, "fmi3GetFMUState", None, f(c, s))
    }

    fn set_state(&mut self, core: &mut Core, s: *mut c_void) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, set_fmu_state, "fmi3SetFMUState");
        call!(core, "fmi3SetFMUState", None, f(c, s))
    }

    fn free_state(&mut self, core: &mut Core, s: &mut *mut c_void) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, free_fmu_state, "fmi3FreeFMUState");
        call!(core, "fmi3FreeFMUState", None, f(c, s))
    }

    #[inline]
    fn set_time(&mut self, core: &mut Core, time: f64) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, set_time, "fmi3SetTime");
        call!(core, "fmi3SetTime", Some(time), f(c, time))
    }

    #[inline]
    fn set_continuous_states(&mut self, core: &mut Core, x: &[f64]) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, set_continuous_states, "fmi3SetContinuousStates");
        call!(core, "fmi3SetContinuousStates", None, f(c, x.as_ptr(), x.len()))
    }

    fn get_continuous_states(&mut self, core: &mut Core, x: &mut [f64]) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, get_continuous_states, "fmi3GetContinuousStates");
        call!(core, "fmi3GetContinuousStates", None, f(c, x.as_mut_ptr(), x.len()))
    }

    #[inline]
    fn get_derivatives(&mut self, core: &mut Core, dx: &mut [f64]) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, get_continuous_state_derivatives, "fmi3GetContinuousStateDerivatives");
        call!(core, "fmi3GetContinuousStateDerivatives", None, f(c, dx.as_mut_ptr(), dx.len()))
    }

    #[inline]
    fn get_event_indicators(&mut self, core: &mut Core, z: &mut [f64]) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, get_event_indicators, "fmi3GetEventIndicators");
        call!(core, "fmi3GetEventIndicators", None, f(c, z.as_mut_ptr(), z.len()))
    }

    fn has_directional_derivative(&self) -> bool {
        self.a.functions.get_directional_derivative.is_some()
    }

    fn get_directional_derivative(&mut self, core: &mut Core, seed: Seed, dv_unknown: &mut [f64]) -> Result<()> {
        let Seed { unknowns, knowns, dv_known } = seed;
        let c = core.component;
        let f = f3!(core, self.a, get_directional_derivative, "fmi3GetDirectionalDerivative");
        call!(
            core,
            "fmi3GetDirectionalDerivative",
            None,
            f(
                c,
                unknowns.as_ptr(),
                unknowns.len(),
                knowns.as_ptr(),
                knowns.len(),
                dv_known.as_ptr(),
                dv_known.len(),
                dv_unknown.as_mut_ptr(),
                dv_unknown.len()
            )
        )
    }

    fn enter_event_mode(&mut self, core: &mut Core) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, enter_event_mode, "fmi3EnterEventMode");
        call!(core, "fmi3EnterEventMode", None, f(c))
    }

    /// `fmi3UpdateDiscreteStates`, its outputs as the FMI 2.0 event info
    /// (`discreteStatesNeedUpdate` is `newDiscreteStatesNeeded`).
    fn new_discrete_states(&mut self, core: &mut Core) -> Result<EventInfo> {
        let c = core.component;
        let mut info = EventInfo::default();
        let f = f3!(core, self.a, update_discrete_states, "fmi3UpdateDiscreteStates");
        let (mut update, mut terminate, mut nominals, mut values, mut defined) = (0u8, 0u8, 0u8, 0u8, 0u8);
        let mut next = 0.0;
        call!(
            core,
            "fmi3UpdateDiscreteStates",
            None,
            f(c, &mut update, &mut terminate, &mut nominals, &mut values, &mut defined, &mut next)
        )?;
        info.new_discrete_states_needed = (update != 0) as c_int;
        info.terminate_simulation = (terminate != 0) as c_int;
        info.nominals_of_continuous_states_changed = (nominals != 0) as c_int;
        info.values_of_continuous_states_changed = (values != 0) as c_int;
        info.next_event_time_defined = (defined != 0) as c_int;
        info.next_event_time = next;
        // the event settled: the output clocks and the intervals the FMU gives read while
        // still in Event Mode (both interface types)
        if update == 0 && terminate == 0 {
            let time = core.time;
            self.read_output_clocks(core, time)?;
        }
        Ok(info)
    }

    fn enter_continuous_time_mode(&mut self, core: &mut Core) -> Result<()> {
        let c = core.component;
        let f = f3!(core, self.a, enter_continuous_time_mode, "fmi3EnterContinuousTimeMode");
        call!(core, "fmi3EnterContinuousTimeMode", None, f(c))
    }

    fn completed_integrator_step(&mut self, core: &mut Core) -> Result<(bool, bool)> {
        let c = core.component;
        let f = f3!(core, self.a, completed_integrator_step, "fmi3CompletedIntegratorStep");
        let (mut event, mut terminate) = (0u8, 0u8);
        call!(core, "fmi3CompletedIntegratorStep", None, f(c, 1, &mut event, &mut terminate))?;
        Ok((event != 0, terminate != 0))
    }

    /// Whether the last `fmi3DoStep` said `terminateSimulation`.
    fn terminated_status(&mut self, _: &mut Core) -> Option<bool> {
        Some(self.terminate_requested.is_some())
    }

    /// The `lastSuccessfulTime` of the `fmi3DoStep` that said `terminateSimulation`.
    fn last_successful_time(&mut self, _: &mut Core) -> Option<f64> {
        self.terminate_requested
    }

    fn free_functions(&self) -> (Option<FreeStateFunction>, FreeInstanceFunction, &'static str) {
        (self.a.functions.free_fmu_state, self.a.functions.free_instance, "fmi3FreeInstance")
    }

    fn is_fmi3(&self) -> bool {
        true
    }

    fn clock_calls(&mut self) -> Option<&mut dyn ClockCalls> {
        Some(self)
    }
}

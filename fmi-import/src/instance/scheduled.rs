//! FMI 3.0 Scheduled Execution (section 5): `fmi3InstantiateScheduledExecution` with the
//! `clockUpdate`, `lockPreemption` and `unlockPreemption` callbacks, and the calls a
//! scheduler makes on the instance: [`Instance::activate_model_partition`], the interval of
//! a countdown clock once the FMU has signalled it ([`Instance::countdown_interval`]), and
//! whether an output clock ticked ([`Instance::output_clock_ticked`]).
//!
//! The callbacks and their environment are `callbacks.rs`.

use std::ffi::{c_void, CString};
use std::sync::atomic::Ordering;

use super::callbacks::{clock_update, lock_preemption, unlock_preemption, ScheduledEnvironment};
use super::core::ClockCalls;
use super::core::{call, Core};
use super::fmi3::Fmi3;
use super::Instance;
use crate::c_types::Component;
use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::log::LogSink;

impl Fmi3 {
    /// `fmi3InstantiateScheduledExecution` (logging off, the messages to `log`), the
    /// callbacks' environment `environment`.
    pub(super) fn instantiate_scheduled(
        &self,
        fmu: &Fmu,
        name: &str,
        name_c: &CString,
        log: &LogSink,
        environment: &ScheduledEnvironment,
    ) -> Result<Component> {
        let a = self.abi();
        let function = "fmi3InstantiateScheduledExecution";
        let f = a
            .functions
            .instantiate_scheduled_execution
            .ok_or(Error::MissingSymbol { path: fmu.source.clone(), symbol: function })?;
        environment.log.store(log as *const LogSink as *mut LogSink, Ordering::Relaxed);
        let env = environment as *const ScheduledEnvironment as *mut c_void;
        let _mark = crate::call_site::enter(name, &fmu.source, function, 0.0, crate::call_site::owner_of_call());
        // SAFETY: every pointer is valid for the call; the environment (owned by the
        // instance's calls, boxed) and the log outlive the FMU instance.
        Ok(unsafe {
            f(
                name_c.as_ptr(),
                a.token.as_ptr(),
                a.resource_path.as_ptr(),
                0,
                0,
                env,
                Some(crate::log::log_message::<ScheduledEnvironment>),
                Some(clock_update),
                Some(lock_preemption),
                Some(unlock_preemption),
            )
        })
    }

    /// `fmi3ActivateModelPartition(clock, time)`; whether the FMU called `clockUpdate`
    /// during it.
    pub(super) fn activate(
        &mut self,
        core: &mut Core,
        environment: &ScheduledEnvironment,
        clock: u32,
        time: f64,
    ) -> Result<bool> {
        let f = core.optional(self.abi().functions.activate_model_partition, "fmi3ActivateModelPartition")?;
        let c = core.component;
        environment.clock_update.store(false, Ordering::Release);
        core.time = time;
        // the partition's clocked inputs set before its activation, its clocked outputs
        // read after it (held until its next)
        self.apply_queued(core, &[clock])?;
        call!(core, "fmi3ActivateModelPartition", Some(time), f(c, clock, time))?;
        self.read_clocked(core, &[clock])?;
        Ok(environment.clock_update.swap(false, Ordering::Acquire))
    }

    /// `fmi3GetIntervalDecimal` of `clock`: the interval when its qualifier is
    /// `fmi3IntervalChanged`, else `None`.
    pub(super) fn changed_interval(&mut self, core: &mut Core, clock: u32) -> Result<Option<f64>> {
        let (values, qualifiers) = self.interval_call(core, &[clock])?;
        if qualifiers[0] != fmi_sys::fmi3::FMI3_INTERVAL_CHANGED {
            return Ok(None);
        }
        let interval = values[0];
        if !(interval.is_finite() && interval >= 0.0) {
            core.state = super::core::InstanceState::Errored;
            let time = core.time;
            return Err(core.returned(
                "fmi3GetIntervalDecimal",
                time,
                format!("the interval of clock {clock} is {interval} s: a countdown is finite and not negative"),
            ));
        }
        Ok(Some(interval))
    }

    /// `fmi3GetClock` of the output clock `clock`: whether it ticked.
    pub(super) fn clock_ticked(&mut self, core: &mut Core, clock: u32) -> Result<bool> {
        let mut ticked = [false];
        ClockCalls::get_clocks(self, core, &[clock], &mut ticked)?;
        Ok(ticked[0])
    }
}

impl Instance {
    /// Scheduled Execution: `fmi3ActivateModelPartition` of the partition of the input
    /// clock `clock` (its value reference) at `time`; whether the FMU signalled
    /// `clockUpdate` (an output clock ticked or a countdown clock's interval is known: ask
    /// [`Instance::output_clock_ticked`] and [`Instance::countdown_interval`]).
    pub fn activate_model_partition(&mut self, clock: u32, time: f64) -> Result<bool> {
        self.calls.activate_model_partition(&mut self.core, clock, time)
    }

    /// Scheduled Execution: the interval of the countdown clock `clock` when the FMU has
    /// set it since it was last asked (`fmi3GetIntervalDecimal` with
    /// `fmi3IntervalChanged`), s; else `None`.
    pub fn countdown_interval(&mut self, clock: u32) -> Result<Option<f64>> {
        self.calls.countdown_interval(&mut self.core, clock)
    }

    /// Scheduled Execution: whether the output clock `clock` ticked (`fmi3GetClock`, which
    /// resets it).
    pub fn output_clock_ticked(&mut self, clock: u32) -> Result<bool> {
        self.calls.output_clock_ticked(&mut self.core, clock)
    }
}

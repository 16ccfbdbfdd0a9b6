//! An instance's calls of the FMI 2.0 C API (in process, or the isolation proxy's table).

use std::ffi::{c_char, c_int, c_void, CString};
use std::sync::Arc;

use super::core::{call, Calls, Core, FreeInstanceFunction, FreeStateFunction, ResetFunction, Seed};
use crate::c_types::{Component, EventInfo, Functions};
use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::log::LogSink;

/// The FMI 2.0 calls: the library's table.
pub(crate) struct Fmi2 {
    t: Arc<Functions>,
}

impl Fmi2 {
    pub(crate) fn new(t: Arc<Functions>) -> Fmi2 {
        Fmi2 { t }
    }
}

/// The typed getters and setters of [`Calls`], one C call each: (getter, setter, value type,
/// their FMI names) a row.
macro_rules! get_set {
    ($($get:ident, $set:ident, $t:ty, $get_name:literal, $set_name:literal;)*) => {$(
        #[inline]
        fn $get(&mut self, core: &mut Core, vrs: &[u32], values: &mut [$t]) -> Result<()> {
            let (c, f) = (core.component, self.t.$get);
            call!(core, $get_name, None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()))
        }

        #[inline]
        fn $set(&mut self, core: &mut Core, vrs: &[u32], values: &[$t]) -> Result<()> {
            let (c, f) = (core.component, self.t.$set);
            call!(core, $set_name, None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr()))
        }
    )*};
}

impl Calls for Fmi2 {
    fn instantiate_function(&self, _: crate::fmu::Interface) -> &'static str {
        "fmi2Instantiate"
    }

    /// `fmi2Instantiate` with the FMU's interface, logging off (warnings and errors are
    /// still logged by the FMU and kept); the callbacks and the log outlive the instance.
    fn instantiate(
        &self,
        fmu: &Fmu,
        name: &str,
        name_c: &CString,
        callbacks: &crate::c_types::CallbackFunctions,
        log: &LogSink,
    ) -> Result<Component> {
        let guid = CString::new(fmu.description.guid.as_str())
            .map_err(|_| Error::ModelDescription { path: fmu.source.clone(), reason: "NUL in guid".into() })?;
        // the guard reads the owner of a block from the call's mark (once a process)
        fmi_sys::fmi2::guard::owners_from(crate::call_site::owner_of_call);
        let mark = crate::call_site::enter(name, &fmu.source, "fmi2Instantiate", 0.0, log.owner());
        // SAFETY: every pointer is valid for the call; callbacks and log live as long as the instance.
        let component = unsafe {
            (self.t.instantiate)(
                name_c.as_ptr(),
                fmu.interface.fmi_type(),
                guid.as_ptr(),
                fmu.resource_uri.as_ptr(),
                callbacks,
                0,
                0,
            )
        };
        drop(mark);
        if component.is_null() {
            return Err(Error::Instantiate {
                instance: name.into(),
                function: "fmi2Instantiate",
                log: log.recent_problems(),
            });
        }
        Ok(component)
    }

    /// `fmi2Instantiate` in the host of `channel`; the status.
    fn instantiate_in(
        &self,
        fmu: &Fmu,
        channel: &mut crate::isolate::channel::Channel,
        name_c: &CString,
    ) -> Result<i32> {
        let guid = CString::new(fmu.description.guid.as_str())
            .map_err(|_| Error::ModelDescription { path: fmu.source.clone(), reason: "NUL in guid".into() })?;
        Ok(crate::isolate::proxy::instantiate_in(channel, name_c, fmu.interface.fmi_type(), &guid, &fmu.resource_uri))
    }

    fn reset_name(&self) -> &'static str {
        "fmi2Reset"
    }

    fn setup_function(&self) -> &'static str {
        "fmi2SetupExperiment"
    }

    fn setup_experiment(
        &mut self,
        core: &mut Core,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Result<()> {
        let c = core.component;
        let f = self.t.setup_experiment;
        call!(
            core,
            "fmi2SetupExperiment",
            Some(start_time),
            f(
                c,
                tolerance.is_some() as c_int,
                tolerance.unwrap_or(0.0),
                start_time,
                stop_time.is_some() as c_int,
                stop_time.unwrap_or(0.0)
            )
        )
    }

    fn enter_initialization_mode(&mut self, core: &mut Core) -> Result<()> {
        let (c, f) = (core.component, self.t.enter_initialization_mode);
        call!(core, "fmi2EnterInitializationMode", None, f(c))
    }

    fn exit_initialization_mode(&mut self, core: &mut Core) -> Result<()> {
        let (c, f) = (core.component, self.t.exit_initialization_mode);
        call!(core, "fmi2ExitInitializationMode", None, f(c))
    }

    fn terminate(&mut self, core: &mut Core) -> Result<()> {
        let (c, f) = (core.component, self.t.terminate);
        call!(core, "fmi2Terminate", None, f(c))
    }

    fn reset_function(&self, core: &Core) -> Result<ResetFunction> {
        core.optional(self.t.reset, "fmi2Reset")
    }

    get_set! {
        get_real, set_real, f64, "fmi2GetReal", "fmi2SetReal";
        get_integer, set_integer, i32, "fmi2GetInteger", "fmi2SetInteger";
        get_boolean, set_boolean, i32, "fmi2GetBoolean", "fmi2SetBoolean";
    }

    fn get_string(&mut self, core: &mut Core, vr: u32) -> Result<*const c_char> {
        let mut p: *const c_char = std::ptr::null();
        let (c, f) = (core.component, self.t.get_string);
        call!(core, "fmi2GetString", None, f(c, &vr, 1, &mut p))?;
        Ok(p)
    }

    fn set_string(&mut self, core: &mut Core, vr: u32, p: *const c_char) -> Result<()> {
        let (c, f) = (core.component, self.t.set_string);
        call!(core, "fmi2SetString", None, f(c, &vr, 1, &p))
    }

    fn get_exact(&mut self, core: &mut Core, vrs: &[u32], _values: &mut Vec<crate::fmi3::Exact>) -> Result<()> {
        Err(no_exact(core, vrs.first().copied().unwrap_or_default(), String::new()))
    }

    fn set_exact_integer(&mut self, core: &mut Core, vr: u32, value: i128) -> Result<()> {
        Err(no_exact(core, vr, value.to_string()))
    }

    #[inline]
    fn do_step(&mut self, core: &mut Core, time: f64, step: f64) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.do_step, "fmi2DoStep")?;
        call!(core, "fmi2DoStep", Some(time), f(c, time, step, 1))?;
        core.time = time + step;
        Ok(())
    }

    fn posted_step(&self, _time: f64, step: f64) -> Option<(crate::isolate::protocol::Op, f64)> {
        self.t.do_step.is_some().then_some((crate::isolate::protocol::Op::DoStep, step))
    }

    fn get_state(&mut self, core: &mut Core, s: &mut *mut c_void) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.get_fmu_state, "fmi2GetFMUstate")?;
        call!(core, "fmi2GetFMUstate", None, f(c, s))
    }

    fn set_state(&mut self, core: &mut Core, s: *mut c_void) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.set_fmu_state, "fmi2SetFMUstate")?;
        call!(core, "fmi2SetFMUstate", None, f(c, s))
    }

    fn free_state(&mut self, core: &mut Core, s: &mut *mut c_void) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.free_fmu_state, "fmi2FreeFMUstate")?;
        call!(core, "fmi2FreeFMUstate", None, f(c, s))
    }

    #[inline]
    fn set_time(&mut self, core: &mut Core, time: f64) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.set_time, "fmi2SetTime")?;
        call!(core, "fmi2SetTime", Some(time), f(c, time))
    }

    #[inline]
    fn set_continuous_states(&mut self, core: &mut Core, x: &[f64]) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.set_continuous_states, "fmi2SetContinuousStates")?;
        call!(core, "fmi2SetContinuousStates", None, f(c, x.as_ptr(), x.len()))
    }

    fn get_continuous_states(&mut self, core: &mut Core, x: &mut [f64]) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.get_continuous_states, "fmi2GetContinuousStates")?;
        call!(core, "fmi2GetContinuousStates", None, f(c, x.as_mut_ptr(), x.len()))
    }

    #[inline]
    fn get_derivatives(&mut self, core: &mut Core, dx: &mut [f64]) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.get_derivatives, "fmi2GetDerivatives")?;
        call!(core, "fmi2GetDerivatives", None, f(c, dx.as_mut_ptr(), dx.len()))
    }

    #[inline]
    fn get_event_indicators(&mut self, core: &mut Core, z: &mut [f64]) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.get_event_indicators, "fmi2GetEventIndicators")?;
        call!(core, "fmi2GetEventIndicators", None, f(c, z.as_mut_ptr(), z.len()))
    }

    fn has_directional_derivative(&self) -> bool {
        self.t.get_directional_derivative.is_some()
    }

    fn get_directional_derivative(&mut self, core: &mut Core, seed: Seed, dv_unknown: &mut [f64]) -> Result<()> {
        let Seed { unknowns, knowns, dv_known } = seed;
        let c = core.component;
        let f = core.optional(self.t.get_directional_derivative, "fmi2GetDirectionalDerivative")?;
        // a write past a block the FMU allocated through allocateMemory lands in its red
        // zone (MapleSim 2023's ControlledTemperature writes 16 bytes past one here); only
        // this instance's blocks are read
        let owner = core.log.owner();
        let before = fmi_sys::fmi2::guard::overruns_of(owner).count;
        call!(
            core,
            "fmi2GetDirectionalDerivative",
            None,
            f(
                c,
                unknowns.as_ptr(),
                unknowns.len(),
                knowns.as_ptr(),
                knowns.len(),
                dv_known.as_ptr(),
                dv_unknown.as_mut_ptr()
            )
        )?;
        let after = fmi_sys::fmi2::guard::overruns_of(owner);
        match after.first {
            Some((size, past)) if after.count > before => Err(Error::Overrun {
                instance: core.name.clone(),
                function: "fmi2GetDirectionalDerivative",
                what: format!(
                    "{past} bytes past the end of a block of {size} bytes that the FMU allocated through allocateMemory{}",
                    if before > 0 { " (or past another of its blocks: the first write seen in this instance)" } else { "" }
                ),
            }),
            _ => Ok(()),
        }
    }

    fn enter_event_mode(&mut self, core: &mut Core) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.enter_event_mode, "fmi2EnterEventMode")?;
        call!(core, "fmi2EnterEventMode", None, f(c))
    }

    fn new_discrete_states(&mut self, core: &mut Core) -> Result<EventInfo> {
        let c = core.component;
        let mut info = EventInfo::default();
        let f = core.optional(self.t.new_discrete_states, "fmi2NewDiscreteStates")?;
        call!(core, "fmi2NewDiscreteStates", None, f(c, &mut info))?;
        Ok(info)
    }

    fn enter_continuous_time_mode(&mut self, core: &mut Core) -> Result<()> {
        let c = core.component;
        let f = core.optional(self.t.enter_continuous_time_mode, "fmi2EnterContinuousTimeMode")?;
        call!(core, "fmi2EnterContinuousTimeMode", None, f(c))
    }

    fn completed_integrator_step(&mut self, core: &mut Core) -> Result<(bool, bool)> {
        let c = core.component;
        let f = core.optional(self.t.completed_integrator_step, "fmi2CompletedIntegratorStep")?;
        let (mut event, mut terminate) = (0, 0);
        call!(core, "fmi2CompletedIntegratorStep", None, f(c, 1, &mut event, &mut terminate))?;
        Ok((event != 0, terminate != 0))
    }

    fn terminated_status(&mut self, core: &mut Core) -> Option<bool> {
        let f = self.t.get_boolean_status?;
        let mut v: c_int = 0;
        // SAFETY: live component, valid out pointer; 3 = fmi2Terminated.
        let raw = unsafe { f(core.component, 3, &mut v) };
        (raw == 0).then_some(v != 0)
    }

    fn last_successful_time(&mut self, core: &mut Core) -> Option<f64> {
        let f = self.t.get_real_status?;
        let mut v = 0.0;
        // SAFETY: live component, valid out pointer; 2 = fmi2LastSuccessfulTime.
        let raw = unsafe { f(core.component, 2, &mut v) };
        (raw == 0).then_some(v)
    }

    fn free_functions(&self) -> (Option<FreeStateFunction>, FreeInstanceFunction, &'static str) {
        (self.t.free_fmu_state, self.t.free_instance, "fmi2FreeInstance")
    }

    fn is_fmi3(&self) -> bool {
        false
    }
}

/// An FMI 2.0 FMU has no variable whose values an f64 (or its Integer, Boolean, String)
/// does not hold: no exact value to read or set.
#[cold]
fn no_exact(core: &Core, vr: u32, value: String) -> Error {
    Error::InvalidValue {
        variable: format!("{}.<value reference {vr}>", core.name),
        value,
        reason: "FMI 2.0 has no 64-bit integers or Binaries: nothing to read or set exactly".into(),
    }
}

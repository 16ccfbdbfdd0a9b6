//! The FMI 3.0 clock calls of an instance (`fmi3SetClock`, `fmi3GetClock`,
//! `fmi3GetIntervalDecimal`/`Fraction`, `fmi3GetShiftDecimal`/`Fraction`,
//! `fmi3SetIntervalDecimal`) and the clock event the master runs at a tick, each call's
//! status handled as every other call's. An FMI 2.0 instance has no clocks: each call is
//! an error naming it.

use super::core::{call, Calls, ClockCalls, Core, Interval, OutputTick};
use super::fmi3::Fmi3;
use super::Instance;
use crate::error::{Error, Result};

impl ClockCalls for Fmi3 {
    fn set_clocks(&mut self, core: &mut Core, vrs: &[u32]) -> Result<()> {
        let f = core.optional(self.a.functions.set_clock, "fmi3SetClock")?;
        let c = core.component;
        let on = vec![1u8; vrs.len()];
        call!(core, "fmi3SetClock", None, f(c, vrs.as_ptr(), vrs.len(), on.as_ptr()))?;
        // the clocks are active until fmi3UpdateDiscreteStates: their clocked inputs set,
        // their clocked outputs read
        self.apply_queued(core, vrs)?;
        self.ticked_inputs.extend_from_slice(vrs);
        self.clocked.activate(vrs);
        Ok(())
    }

    fn get_clocks(&mut self, core: &mut Core, vrs: &[u32], ticks: &mut [bool]) -> Result<()> {
        let f = core.optional(self.a.functions.get_clock, "fmi3GetClock")?;
        let c = core.component;
        let mut raw = vec![0u8; vrs.len()];
        call!(core, "fmi3GetClock", None, f(c, vrs.as_ptr(), vrs.len(), raw.as_mut_ptr()))?;
        for (t, r) in ticks.iter_mut().zip(&raw) {
            *t = *r != 0;
        }
        Ok(())
    }

    fn get_intervals(&mut self, core: &mut Core, vrs: &[u32], zero: bool) -> Result<Vec<Interval>> {
        let (values, qualifiers) = self.interval_call(core, vrs)?;
        let least = if zero { "no time (negative or not finite)" } else { "no positive time" };
        vrs.iter()
            .zip(values.iter().zip(&qualifiers))
            .map(|(vr, (v, q))| match q {
                0 => Ok(Interval::NotYetKnown),
                1 | 2 if !(v.is_finite() && (*v > 0.0 || zero && *v == 0.0)) => Err(core.returned(
                    "fmi3GetIntervalDecimal",
                    core.time,
                    format!("the interval {v} s of clock {vr} is {least}"),
                )),
                1 => Ok(Interval::Unchanged(*v)),
                2 => Ok(Interval::Changed(*v)),
                other => Err(core.returned(
                    "fmi3GetIntervalDecimal",
                    core.time,
                    format!(
                        "the qualifier {other} of clock {vr} is none of fmi3IntervalNotYetKnown, fmi3IntervalUnchanged, \
                         fmi3IntervalChanged"
                    ),
                )),
            })
            .collect()
    }

    fn get_shifts(&mut self, core: &mut Core, vrs: &[u32]) -> Result<Vec<f64>> {
        let mut values = vec![0.0; vrs.len()];
        let c = core.component;
        match (self.a.functions.get_shift_decimal, self.a.functions.get_shift_fraction) {
            (Some(f), _) => {
                call!(core, "fmi3GetShiftDecimal", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()))?
            }
            (None, Some(f)) => {
                values = fraction_seconds(vrs.len(), |counters, resolutions| {
                    call!(core, "fmi3GetShiftFraction", None, f(c, vrs.as_ptr(), vrs.len(), counters, resolutions))
                })?
            }
            (None, None) => return Err(core.optional(None::<()>, "fmi3GetShiftDecimal").unwrap_err()),
        }
        if let Some((vr, v)) = vrs.iter().zip(&values).find(|(_, v)| !(v.is_finite() && **v >= 0.0)) {
            return Err(core.returned(
                "fmi3GetShiftDecimal",
                core.time,
                format!("the shift {v} s of clock {vr} is no time (negative or not finite)"),
            ));
        }
        Ok(values)
    }

    fn set_intervals(&mut self, core: &mut Core, vrs: &[u32], intervals: &[f64]) -> Result<()> {
        let f = core.optional(self.a.functions.set_interval_decimal, "fmi3SetIntervalDecimal")?;
        let c = core.component;
        call!(core, "fmi3SetIntervalDecimal", None, f(c, vrs.as_ptr(), vrs.len(), intervals.as_ptr()))
    }

    fn open_clock_event(&mut self, core: &mut Core, time: f64, vrs: &[u32]) -> Result<()> {
        core.time = time;
        Calls::enter_event_mode(self, core)?;
        if !vrs.is_empty() {
            self.set_clocks(core, vrs)?;
        }
        // the output clocks the ticks activated: their variables read at the open event,
        // as the input clocks' are (fmi3GetClock resets an output clock it reports, so each is
        // counted here or, when it becomes active in fmi3UpdateDiscreteStates, as the event
        // settles)
        if !self.output_clocks.is_empty() {
            let outputs = self.output_clocks.clone();
            let mut ticks = vec![false; outputs.len()];
            self.get_clocks(core, &outputs, &mut ticks)?;
            for (vr, _) in outputs.into_iter().zip(ticks).filter(|(_, t)| *t) {
                self.output_ticks.push(OutputTick { time, value_reference: vr });
                self.clocked.activate(&[vr]);
                self.opened_outputs.push(vr);
            }
        }
        Ok(())
    }

    fn close_clock_event(&mut self, core: &mut Core) -> Result<()> {
        let time = core.time;
        match self.settle_event(core, time)? {
            None => Ok(()),
            Some(t) => Err(self.terminated_at(core, "fmi3UpdateDiscreteStates", t, t)),
        }
    }

    fn take_output_ticks(&mut self) -> Vec<OutputTick> {
        std::mem::take(&mut self.output_ticks)
    }

    fn take_intervals(&mut self) -> Vec<(f64, u32, Interval)> {
        std::mem::take(&mut self.intervals)
    }
}

impl Fmi3 {
    /// The raw interval call: `fmi3GetIntervalDecimal` (or `Fraction` where only it is
    /// present, its counter over its resolution, NaN for resolution 0): the values and the
    /// qualifiers, each use reading them as it needs.
    pub(super) fn interval_call(&mut self, core: &mut Core, vrs: &[u32]) -> Result<(Vec<f64>, Vec<i32>)> {
        let mut values = vec![0.0; vrs.len()];
        let mut qualifiers = vec![0i32; vrs.len()];
        let c = core.component;
        match (self.a.functions.get_interval_decimal, self.a.functions.get_interval_fraction) {
            (Some(f), _) => call!(
                core,
                "fmi3GetIntervalDecimal",
                None,
                f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), qualifiers.as_mut_ptr())
            )?,
            (None, Some(f)) => {
                let q = qualifiers.as_mut_ptr();
                values = fraction_seconds(vrs.len(), |counters, resolutions| {
                    call!(
                        core,
                        "fmi3GetIntervalFraction",
                        None,
                        f(c, vrs.as_ptr(), vrs.len(), counters, resolutions, q)
                    )
                })?
            }
            (None, None) => return Err(core.optional(None::<()>, "fmi3GetIntervalDecimal").unwrap_err()),
        }
        Ok((values, qualifiers))
    }
}

/// The times of an FMI 3.0 `*Fraction` call of `n` clocks, each its counter over its
/// resolution (NaN for resolution 0): `call` writes the counters and the resolutions.
fn fraction_seconds(n: usize, call: impl FnOnce(*mut u64, *mut u64) -> Result<()>) -> Result<Vec<f64>> {
    let (mut counters, mut resolutions) = (vec![0u64; n], vec![0u64; n]);
    call(counters.as_mut_ptr(), resolutions.as_mut_ptr())?;
    Ok(counters.iter().zip(&resolutions).map(|(c, r)| if *r == 0 { f64::NAN } else { *c as f64 / *r as f64 }).collect())
}

/// The error of a clock call on an instance whose generation has no clocks.
fn no_clocks(inst: &Instance) -> Error {
    Error::Instance { name: inst.core.name.clone(), reason: "an FMI 2.0 instance has no clocks (a clock call)" }
}

impl Instance {
    /// `fmi3SetClock`: the input clocks `vrs` tick now (in Event Mode).
    pub fn set_clocks(&mut self, vrs: &[u32]) -> Result<()> {
        match self.calls.clock_calls() {
            Some(c) => c.set_clocks(&mut self.core, vrs),
            None => Err(no_clocks(self)),
        }
    }

    /// `fmi3GetClock`: whether each of the output clocks `vrs` ticked (in Event Mode).
    pub fn get_clocks(&mut self, vrs: &[u32], ticks: &mut [bool]) -> Result<()> {
        assert_eq!(vrs.len(), ticks.len(), "get_clocks: one answer per clock");
        match self.calls.clock_calls() {
            Some(c) => c.get_clocks(&mut self.core, vrs, ticks),
            None => Err(no_clocks(self)),
        }
    }

    /// `fmi3GetIntervalDecimal` (or `Fraction` where only it is present): the intervals of
    /// the clocks `vrs` and what the FMU says of each.
    pub fn get_intervals(&mut self, vrs: &[u32]) -> Result<Vec<Interval>> {
        match self.calls.clock_calls() {
            Some(c) => c.get_intervals(&mut self.core, vrs, false),
            None => Err(no_clocks(self)),
        }
    }

    /// The same, an interval of 0 s included: the delay from the start to a `changing`
    /// clock's first tick, which may be at the start (in Initialization Mode).
    pub fn get_first_intervals(&mut self, vrs: &[u32]) -> Result<Vec<Interval>> {
        match self.calls.clock_calls() {
            Some(c) => c.get_intervals(&mut self.core, vrs, true),
            None => Err(no_clocks(self)),
        }
    }

    /// `fmi3GetShiftDecimal` (or `Fraction`): the shifts of the clocks `vrs`, s.
    pub fn get_shifts(&mut self, vrs: &[u32]) -> Result<Vec<f64>> {
        match self.calls.clock_calls() {
            Some(c) => c.get_shifts(&mut self.core, vrs),
            None => Err(no_clocks(self)),
        }
    }

    /// `fmi3SetIntervalDecimal`: the intervals of the clocks `vrs` (fixed and tunable
    /// input clocks), s.
    pub fn set_intervals(&mut self, vrs: &[u32], intervals: &[f64]) -> Result<()> {
        assert_eq!(vrs.len(), intervals.len(), "set_intervals: one interval per clock");
        match self.calls.clock_calls() {
            Some(c) => c.set_intervals(&mut self.core, vrs, intervals),
            None => Err(no_clocks(self)),
        }
    }

    /// A clock event at `time` (Co-Simulation with Event Mode, the instance at `time`):
    /// `fmi3EnterEventMode`, `fmi3SetClock` of the input clocks `vrs` that tick,
    /// `fmi3UpdateDiscreteStates` until settled (at most 1000 times), `fmi3GetClock` of the
    /// output clocks ([`Instance::take_output_ticks`]), `fmi3EnterStepMode`. An FMU that asks
    /// to terminate in it ends the run as `fmi3DoStep`'s `terminateSimulation` does.
    pub fn clock_event(&mut self, time: f64, vrs: &[u32]) -> Result<()> {
        self.open_clock_event(time, vrs)?;
        self.close_clock_event()
    }

    /// The first half of [`Instance::clock_event`]: `fmi3EnterEventMode` at `time` and
    /// `fmi3SetClock` of the input clocks `vrs`, the queued sets of their clocked inputs
    /// applied. Until [`Instance::close_clock_event`] the clocks are active: the master may
    /// exchange values at the tick (a get of a clocked variable of an active clock and a set
    /// of a clocked input of one go to the FMU, the values held), as it does at any event.
    pub fn open_clock_event(&mut self, time: f64, vrs: &[u32]) -> Result<()> {
        match self.calls.clock_calls() {
            Some(c) => c.open_clock_event(&mut self.core, time, vrs),
            None => Err(no_clocks(self)),
        }
    }

    /// The second half of [`Instance::clock_event`]: `fmi3UpdateDiscreteStates` until
    /// settled, the output clocks and intervals read, the clocked variables of the event's
    /// clocks read and held, `fmi3EnterStepMode`.
    pub fn close_clock_event(&mut self) -> Result<()> {
        match self.calls.clock_calls() {
            Some(c) => c.close_clock_event(&mut self.core),
            None => Err(no_clocks(self)),
        }
    }

    /// The output clocks' ticks since the last call, in time order (each read by
    /// `fmi3GetClock` in an event: a tick's, or one the FMU asked for in `fmi3DoStep`).
    pub fn take_output_ticks(&mut self) -> Vec<OutputTick> {
        self.calls.clock_calls().map(|c| c.take_output_ticks()).unwrap_or_default()
    }

    /// What the FMU said of its input clocks' intervals (fixed, tunable, changing,
    /// countdown; `fmi3GetIntervalDecimal` in every event, initialization's included) since
    /// the last call: (event time, clock, interval).
    pub fn take_intervals(&mut self) -> Vec<(f64, u32, Interval)> {
        self.calls.clock_calls().map(|c| c.take_intervals()).unwrap_or_default()
    }
}

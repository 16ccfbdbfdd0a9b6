//! FMI 3.0 clocks: the declared clock ([`crate::ClockDecl`]) of a sampled model as a
//! periodic input clock the importer activates.
//!
//! The samples of a clocked instance are the importer's activations: it enters Event Mode
//! at `t_k = start + k interval` (the layer's [`crate::sampled::SampleClock`] counts `k`),
//! sets the inputs of `t_k`, activates the clock with `fmi3SetClock`, reads the clocked
//! outputs and ends the activation with `fmi3UpdateDiscreteStates`. The sample
//! ([`crate::Model::sample`]) runs at the first read while the clock is active, or at
//! `fmi3UpdateDiscreteStates`, with the inputs set by then; an input set after the sample
//! ran undoes it (it runs again at the next read), as the lazy events of Co-Simulation do
//! for FMI 2.0: so the sample `k` of a clocked instance is the FMI 2.0 one to the bit.
//! Between activations the clocked variables hold their values (an importer may record
//! them there); a step past an activation, an activation at another time than the next
//! `t_k` and deactivating the clock (`canBeDeactivated` is false) are errors naming the
//! clock and the times.

use super::{decl, err, time_eps, Function, Instance, OpResult};
use crate::decl::{ClockDecl, ClockInterval};
use crate::model::Model;
use crate::states::Machine;

/// How `fmi3GetIntervalDecimal` qualifies an interval (FMI 3.0 `fmi3IntervalQualifier`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntervalQualifier {
    /// `fmi3IntervalUnchanged`: the interval the importer knows stands.
    Unchanged,
    /// `fmi3IntervalChanged`: an interval the importer did not know before.
    Changed,
}

impl<M: Model> Instance<M> {
    /// The declared clock (the gate lets the clock functions through only when there is one).
    fn declared_clock() -> OpResult<(&'static ClockDecl, u32)> {
        match decl::<M>().clock() {
            Some(c) => Ok(c),
            None => err("no clock is declared"),
        }
    }

    /// Each of `vrs` is the clock's value reference; the reason naming the variable if not.
    fn check_clock_references(vrs: &[u32]) -> OpResult<&'static ClockDecl> {
        let (clock, clock_vr) = Self::declared_clock()?;
        for &vr in vrs {
            if vr != clock_vr {
                let what = match decl::<M>().variable3(vr) {
                    Some(v) => format!("{}, a {} variable", v.name, v.value_type.element()),
                    None => "no variable".to_string(),
                };
                return err(format!(
                    "value reference {vr} is {what}, not a clock (the FMU's clock is {}, value reference {clock_vr})",
                    clock.name
                ));
            }
        }
        Ok(clock)
    }

    /// When initialization ends: the model is sampled, and a constant interval is its
    /// sample period to the bit.
    pub(super) fn check_clock_interval(&self, period: Option<f64>) -> OpResult {
        let (clock, _) = Self::declared_clock()?;
        let Some(period) = period else {
            return err(format!("clock {} is declared, but the model answers no sample period", clock.name));
        };
        match clock.interval {
            ClockInterval::Constant(t) if t.to_bits() != period.to_bits() => {
                err(format!("the sample period {period} s is not the constant interval {t} s of clock {}", clock.name))
            }
            _ => Ok(()),
        }
    }

    /// Co-Simulation instantiated with `eventModeUsed = false` (fmpy's `simulate_fmu` does
    /// so): the importer cannot enter Event Mode, so it cannot activate the clock. FMI 3.0
    /// requires `eventModeUsed = true` of an importer of an FMU with clocks but asks the FMU
    /// to raise an error only for `eventModeUsed = true` without `hasEventMode`; without Event
    /// Mode it has the FMU "detect and handle events internally" (`hasEventMode`) and its
    /// discrete variables change "at communication points" (`variability`). So the instance
    /// samples by time as the FMI 2.0 archive does (the same time events, the same lazy
    /// samples at the communication points), and the Event Mode calls are refused. The
    /// message to log (once, at instantiation) says so.
    pub fn sample_without_event_mode(&mut self) -> OpResult<String> {
        let (clock, _) = Self::declared_clock()?;
        self.clocked = false;
        self.allowed = Self::allowed_table(self.generation, self.context.interface, false);
        Ok(format!(
            "eventModeUsed = false: {} is not driven by the importer; the FMU samples by time itself at start + k \
             sample_period, as its FMI 2.0 archive does (FMI 3.0 asks eventModeUsed = true of an importer of an FMU \
             with clocks; without Event Mode an FMU handles its events internally)",
            clock.name
        ))
    }

    /// Whether the clock's next activation is due at the current time.
    pub(super) fn sample_due_now(&self) -> bool {
        let now = self.core.time;
        self.core.clock.is_some_and(|c| c.has_next() && (c.time_of(c.next) - now).abs() <= time_eps(now))
    }

    /// Model Exchange: the next activation time `t_(k+1)` as the `nextEventTime` of
    /// `fmi3UpdateDiscreteStates` (an importer that drives the clock enters Event Mode then
    /// anyway; one that does not handles it as a time event: [`Instance::sample_by_time_events`]).
    pub(super) fn next_activation_to_publish(&self) -> Option<f64> {
        if self.context.interface != crate::model::Interface::ModelExchange {
            return None;
        }
        self.core.clock.filter(|c| c.has_next()).map(|c| c.time_of(c.next))
    }

    /// Model Exchange has no `eventModeUsed`: an importer that reaches
    /// `fmi3UpdateDiscreteStates` at an activation time `t_k` (the initial event included)
    /// without having activated the clock with `fmi3SetClock` in that Event Mode does not
    /// drive clocks (fmpy's Model Exchange does not). FMI 3.0 has the importer activate
    /// time-based clocks, so that importer already broke the standard's premise; rather than
    /// never sampling, the instance samples from then on at its time events (the sample now,
    /// then `nextEventTime` = each next sample time), exactly as the FMI 2.0 archive does.
    /// Logged once (`logEvents`); a later `fmi3SetClock` is an error naming the clock.
    pub(super) fn sample_by_time_events(&mut self) -> OpResult {
        let (clock, _) = Self::declared_clock()?;
        self.clocked = false;
        self.undriven_clock = true;
        // the sample due now is the FMI 2.0 archive's time event at this instant
        self.core.next_event = Some(self.core.time);
        self.context.logger.log(
            crate::log::LogCategory::Events,
            &format!(
                "fmi3UpdateDiscreteStates: {} not activated (fmi3SetClock) at its activation time t = {} s: the \
                 importer does not drive clocks, so the FMU samples by time events from now on (nextEventTime = \
                 start + k sample_period), as its FMI 2.0 archive does",
                clock.name, self.core.time
            ),
        );
        Ok(())
    }

    /// `fmi3SetClock`: activates the clock at its next activation time (a clock that
    /// cannot be deactivated refuses `fmi3ClockInactive` while active).
    pub fn set_clock(&mut self, vrs: &[u32], active: impl IntoIterator<Item = bool>) -> OpResult {
        let clock = Self::check_clock_references(vrs)?;
        if self.undriven_clock {
            return err(format!(
                "{} activated, but the instance samples by time events since fmi3UpdateDiscreteStates ran at an \
                 activation time without fmi3SetClock: an importer drives the clock at every activation or never",
                clock.name
            ));
        }
        for on in active {
            if on == self.core.clock_active {
                continue;
            }
            if !on {
                return err(format!(
                    "{} cannot be deactivated (canBeDeactivated is false): fmi3UpdateDiscreteStates ends its \
                     activation",
                    clock.name
                ));
            }
            let Some(samples) = self.core.clock.filter(|c| c.has_next()) else {
                return err(format!("{} has no activation after its last at t = {} s", clock.name, self.core.time));
            };
            let now = self.core.time;
            let due = samples.time_of(samples.next);
            if (now - due).abs() > time_eps(now) {
                return err(format!(
                    "{} activated at t = {now} s, but its next activation is at t = {due} s (activation {}: \
                     start {} s + {} x {} s)",
                    clock.name, samples.next, samples.start, samples.next, samples.period
                ));
            }
            self.core.clock_active = true;
        }
        Ok(())
    }

    /// `fmi3GetClock`: whether the clock (each of `vrs`) is active.
    pub fn get_clock(&self, vrs: &[u32]) -> OpResult<bool> {
        Self::check_clock_references(vrs)?;
        Ok(self.core.clock_active)
    }

    /// `fmi3GetIntervalDecimal`: the clock's interval; a fixed interval (from a parameter) is
    /// new to the importer in Initialization Mode and unchanged afterwards, a constant one
    /// is always unchanged (the importer read it from the description).
    pub fn clock_intervals(&self, vrs: &[u32], out: &mut [(f64, IntervalQualifier)]) -> OpResult {
        let clock = Self::check_clock_references(vrs)?;
        let value = match (clock.interval, self.core.clock) {
            (ClockInterval::Constant(t), _) => (t, IntervalQualifier::Unchanged),
            (ClockInterval::Fixed, Some(samples)) => (samples.period, IntervalQualifier::Unchanged),
            (ClockInterval::Fixed, None) => match self.core.model.sample_period() {
                Some(t) if t > 0.0 && t.is_finite() => (t, IntervalQualifier::Changed),
                other => {
                    return err(format!(
                        "the interval of {} is the sample period, which is {other:?} s: not finite and > 0",
                        clock.name
                    ))
                }
            },
        };
        out.fill(value);
        Ok(())
    }

    /// `fmi3GetShiftDecimal`: the first activation is at the start time (shift 0).
    pub fn clock_shifts(&self, vrs: &[u32], out: &mut [f64]) -> OpResult {
        Self::check_clock_references(vrs)?;
        out.fill(0.0);
        Ok(())
    }

    /// `fmi3SetIntervalDecimal`/`Fraction`, `fmi3SetShiftDecimal`/`Fraction`: the clock's
    /// interval and shift are the FMU's, not the importer's.
    pub fn refuse_clock_timing(&self, vrs: &[u32]) -> OpResult {
        let clock = Self::check_clock_references(vrs)?;
        let kind = match clock.interval {
            ClockInterval::Constant(_) => "constant, declared by intervalDecimal",
            ClockInterval::Fixed => "fixed, the sample period, without intervalDecimal",
        };
        err(format!(
            "the interval and shift of {} are the FMU's (intervalVariability: {kind}; shift 0): read them with \
             fmi3GetIntervalDecimal and fmi3GetShiftDecimal",
            clock.name
        ))
    }

    /// `fmi3GetIntervalFraction`, `fmi3GetShiftFraction`: not offered.
    pub fn refuse_clock_fraction(&self, vrs: &[u32]) -> OpResult {
        let clock = Self::check_clock_references(vrs)?;
        err(format!("{} declares supportsFraction = false: use the Decimal functions", clock.name))
    }

    /// Before a read of a clocked instance: the sample of an active clock runs (once per
    /// activation, with the inputs set by then; a later set undoes it). A clocked variable
    /// read while its clock is inactive answers its value of the last activation (held
    /// until the next): FMI 3.0 section 2.2.9 lets importers read clocked variables only
    /// while their clock is active, and an importer that records them between activations
    /// (as a master recording rows at its communication points does) gets what they hold.
    pub(super) fn settle_clock(&mut self) -> OpResult {
        if self.core.clock_active {
            return self.sample_at_activation();
        }
        Ok(())
    }

    /// The sample of the current activation, unless it ran (the model from before it is kept
    /// to undo it when an input is set afterwards).
    fn sample_at_activation(&mut self) -> OpResult {
        if self.core.pre_event.is_some() {
            return Ok(());
        }
        self.core.pre_event = Some(self.core.pre_event());
        let now = self.core.time;
        self.core.model.set_time(now);
        let Some(mut samples) = self.core.clock else { return err("the sample clock is not running") };
        self.sample(&mut samples, now)?;
        // the next activation is the importer's to make: no time event
        self.core.next_event = None;
        Ok(())
    }

    /// `fmi3UpdateDiscreteStates` of a clocked instance: the sample of an active clock, then
    /// the end of its activation. No time events: the next activation is the importer's.
    pub(super) fn end_clock_activation(&mut self) -> OpResult {
        if self.core.clock_active {
            self.sample_at_activation()?;
            self.core.pre_event = None;
            self.core.clock_active = false;
        }
        Ok(())
    }

    /// `fmi3EnterStepMode`: from Event Mode with the clock's activation ended.
    pub fn enter_step_mode(&mut self) -> OpResult {
        if self.core.clock_active {
            let (clock, _) = Self::declared_clock()?;
            return err(format!(
                "{} is still active: fmi3UpdateDiscreteStates ends its activation before Step Mode",
                clock.name
            ));
        }
        self.core.machine = Machine::StepComplete;
        Ok(())
    }

    /// Before a step of a clocked Co-Simulation instance from `current` to `end`: no
    /// activation of the clock is due before `end` (the importer steps to it and activates
    /// the clock in Event Mode).
    pub(super) fn check_no_activation_before(&self, current: f64, end: f64) -> OpResult {
        let Some(samples) = self.core.clock.filter(|c| c.has_next()) else { return Ok(()) };
        let due = samples.time_of(samples.next);
        if due < end - time_eps(end) {
            let (clock, _) = Self::declared_clock()?;
            return err(format!(
                "the step from {current} s to {end} s passes activation {} of {} at t = {due} s: step to it, then \
                 activate the clock in Event Mode (fmi3EnterEventMode, fmi3SetClock, fmi3UpdateDiscreteStates, \
                 fmi3EnterStepMode)",
                samples.next, clock.name
            ));
        }
        Ok(())
    }

    /// The state table of a Scheduled Execution instance (the layer's `StepComplete` is its
    /// Clock Activation Mode): the common calls as in Co-Simulation's Step Mode, the
    /// partition's activation and the interval and shift queries there, never the calls of
    /// Model Exchange and Co-Simulation nor `fmi3SetClock`/`fmi3GetClock` (an input clock's
    /// partition is activated, not the clock).
    pub(super) fn scheduled_call_allowed(function: Function, machine: Machine) -> OpResult {
        use crate::states::Scope;
        let allowed = match function {
            Function::Fmi3GetClock | Function::Fmi3SetClock => {
                return err("not available in Scheduled Execution: fmi3ActivateModelPartition activates the clock's \
                            model partition");
            }
            Function::Fmi3ActivateModelPartition => machine == Machine::StepComplete,
            f if f.is_clock_function() => matches!(machine, Machine::InitializationMode | Machine::StepComplete),
            f => match f.scope() {
                Scope::ModelExchange | Scope::CoSimulation => {
                    return err("not available: this instance was created for ScheduledExecution");
                }
                _ => f.allowed_in(machine),
            },
        };
        if allowed {
            Ok(())
        } else {
            err(format!("not allowed in state {machine:?}"))
        }
    }

    /// `fmi3ActivateModelPartition`: the partition of the declared clock, its sample, at the
    /// clock's next activation time, with the inputs set before.
    pub fn activate_model_partition(&mut self, clock_vr: u32, activation_time: f64) -> OpResult {
        let clock = Self::check_clock_references(&[clock_vr])?;
        let Some(mut samples) = self.core.clock.filter(|c| c.has_next()) else {
            return err(format!("{} has no activation after its last at t = {} s", clock.name, self.core.time));
        };
        let due = samples.time_of(samples.next);
        if !activation_time.is_finite() || (activation_time - due).abs() > time_eps(due) {
            return err(format!(
                "activationTime = {activation_time} s for {}, but its next activation is at t = {due} s (activation \
                 {}: start {} s + {} x {} s)",
                clock.name, samples.next, samples.start, samples.next, samples.period
            ));
        }
        self.core.time = activation_time;
        self.core.model.set_time(activation_time);
        self.sample(&mut samples, activation_time)?;
        self.core.next_event = None;
        Ok(())
    }
}

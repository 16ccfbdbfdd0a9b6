//! Time events and sampling: the event iteration at an instant, the sample clock of a
//! sampled model, the lazy events of Co-Simulation and the Co-Simulation step.

use super::{err, time_eps, Instance, OpResult, MAX_EVENT_ITERATIONS};
use crate::model::{EventUpdate, Interface, Model, ModelError};
use crate::sampled::{SampleClock, MAX_SAMPLES_PER_STEP};
use crate::states::Machine;
impl<M: Model> Instance<M> {
    /// Co-Simulation: runs the events due at the current time (lazily, so that they see
    /// the inputs set for this instant), remembering the model from before them.
    /// The check is inline (nothing is due at almost every read); the events are not.
    #[inline]
    pub(super) fn settle_events(&mut self) -> OpResult {
        if self.context.interface != Interface::CoSimulation || self.core.machine != Machine::StepComplete {
            return Ok(());
        }
        let now = self.core.time;
        if matches!(self.core.next_event, Some(te) if te <= now + time_eps(now)) {
            self.run_due_events(now)
        } else {
            Ok(())
        }
    }

    #[inline(never)]
    fn run_due_events(&mut self, now: f64) -> OpResult {
        if self.core.pre_event.is_none() {
            self.core.pre_event = Some(self.core.pre_event());
        }
        self.run_events_at(now)
    }

    /// Before a set in Co-Simulation: undo the events run lazily at this instant.
    pub(super) fn unsettle_events(&mut self) {
        if let Some(pre) = self.core.pre_event.take() {
            self.core.model = pre.model;
            self.core.next_event = pre.next_event;
            self.core.clock = pre.clock;
            self.core.presample = pre.presample;
            self.core.terminate_requested = pre.terminate_requested;
        }
    }

    /// The event iteration at `time`, until the model needs no more and its next event
    /// is later.
    fn run_events_at(&mut self, time: f64) -> OpResult {
        for _ in 0..MAX_EVENT_ITERATIONS {
            let update = self.event_update(time)?;
            if update.terminate_simulation {
                self.core.terminate_requested = true;
                if self.core.clock.is_some() {
                    // the end of the samples: the last values stand; the next step is refused
                    return Ok(());
                }
                return Err(ModelError::Discard(format!("the model asked to terminate the simulation at t = {time}")));
            }
            let due = matches!(self.core.next_event, Some(te) if te <= time + time_eps(time));
            if !update.new_discrete_states_needed && !due {
                return Ok(());
            }
        }
        err(format!("no end of the event iteration at t = {time} after {MAX_EVENT_ITERATIONS} iterations"))
    }

    /// One call of the model's event update, with its next event time checked.
    pub(super) fn event_update(&mut self, time: f64) -> OpResult<EventUpdate> {
        self.core.model.set_time(time);
        if let Some(mut clock) = self.core.clock {
            return self.sample(&mut clock, time);
        }
        let update = self.core.model.event_update(time)?;
        if let Some(te) = update.next_event_time {
            if !te.is_finite() || !(te > time) {
                return err(format!("the model's next event time {te} is not after the current time {time}"));
            }
        }
        self.core.next_event = update.next_event_time;
        self.core.iteration_pending = update.new_discrete_states_needed;
        self.core.terminate_requested |= update.terminate_simulation;
        Ok(update)
    }

    /// The event of a sampled model at `time` = its next sample (or the end of its samples).
    pub(super) fn sample(&mut self, clock: &mut SampleClock, time: f64) -> OpResult<EventUpdate> {
        self.core.iteration_pending = false;
        if !clock.has_next() {
            return err(format!("no sample after sample {} at t = {time} s", clock.next));
        }
        self.core.model.sample(clock.next, time)?;
        clock.next += 1;
        self.core.clock = Some(*clock);
        self.core.presample = false;
        self.core.next_event = clock.next_event();
        // after the last sample: the end of the simulation
        let terminate_simulation = self.core.next_event.is_none();
        self.core.terminate_requested |= terminate_simulation;
        Ok(EventUpdate { next_event_time: self.core.next_event, terminate_simulation, ..Default::default() })
    }

    /// `fmi2DoStep`: the model's time events inside the step run in order at their time
    /// (those at the step's start with the inputs just set); the continuous part is
    /// integrated between them; events exactly at the step's end wait for the next
    /// read or step (so that they see the inputs of that instant). The step starts at the
    /// importer's `currentCommunicationPoint` and ends at `currentCommunicationPoint +
    /// communicationStepSize` exactly (FMI 2.0 section 4.2.2), so the FMU's time is the
    /// importer's and `fmi2LastSuccessfulTime` its arithmetic.
    pub fn do_step(&mut self, current_time: f64, step: f64) -> OpResult {
        if self.core.terminate_requested && self.core.clock.is_none() {
            // the Discard with terminateSimulation of the step that ended the run (FMI 3.0
            // stays in Step Mode after it; FMI 2.0's stepFailed refuses the step before)
            return err(format!(
                "the model asked to terminate the simulation at t = {} s: no step after it (terminate or reset)",
                self.core.time
            ));
        }
        if !(step > 0.0) || !step.is_finite() {
            return err(format!("communicationStepSize = {step} s refused: must be finite and > 0"));
        }
        let now = self.core.time;
        if !current_time.is_finite() || (current_time - now).abs() > time_eps(now) {
            return err(format!(
                "currentCommunicationPoint = {current_time} s is not the end of the previous step ({now} s)"
            ));
        }
        let end = current_time + step;
        if !(end > current_time) || !end.is_finite() {
            return err(format!(
                "communicationStepSize = {step} s does not advance currentCommunicationPoint = {current_time} s \
                 (an f64 resolves {:e} s there)",
                crate::sampled::ulp(current_time)
            ));
        }
        if let Some(stop) = self.core.stop_time {
            if end > stop + time_eps(stop) {
                return err(format!(
                    "the step would end at {end} s, after the stopTime {stop} s of fmi2SetupExperiment"
                ));
            }
        }
        if let Some(clock) = self.core.clock {
            // refused before any work: too many samples, or a time that cannot hold the grid
            // a model with a last sample stops there
            let until = clock.end_time().map_or(end, |t_end| end.min(t_end));
            let samples = (until - clock.time_of(clock.next)) / clock.period;
            if samples > MAX_SAMPLES_PER_STEP {
                return Err(ModelError::Discard(format!(
                    "the step of {step} s would run {samples:.0} samples of {} s, more than the {MAX_SAMPLES_PER_STEP} \
                     one fmi2DoStep may run: take shorter steps",
                    clock.period
                )));
            }
            clock.check_resolution(end).map_err(ModelError::Discard)?;
        }
        if self.clocked {
            self.check_no_activation_before(current_time, end)?;
        }
        self.core.time = current_time;
        self.settle_events()?;
        self.core.pre_event = None;
        if self.core.terminate_requested && self.core.clock.is_some() {
            return Err(self.past_the_samples());
        }
        loop {
            match self.core.next_event {
                Some(te) if te < end - time_eps(end) => {
                    let t = self.core.time;
                    if te > t {
                        self.core.model.do_step(t, te - t)?;
                        self.core.time = te;
                    }
                    self.run_events_at(te)?;
                    if self.core.terminate_requested && self.core.clock.is_some() {
                        return Err(self.past_the_samples());
                    }
                }
                _ => {
                    let t = self.core.time;
                    // without an event inside, exactly the importer's step size
                    let rest = if t == current_time { step } else { end - t };
                    if rest > 0.0 {
                        self.core.model.do_step(t, rest)?;
                    }
                    self.core.time = end;
                    return Ok(());
                }
            }
        }
    }

    /// The `fmi2Discard` of a step past a sampled model's last sample (the instance is at
    /// the end of its samples: `fmi2LastSuccessfulTime`).
    #[cold]
    fn past_the_samples(&self) -> ModelError {
        let what = match self.core.model.sample_end() {
            Some(e) => format!(
                "sample {} of {} s is the last, set by {}",
                e.last,
                self.core.clock.map_or(0.0, |c| c.period),
                e.variable
            ),
            None => "the model's last sample".to_string(),
        };
        ModelError::Discard(format!(
            "the simulation ends at t = {} s ({what}): fmi2Terminated is true, fmi2LastSuccessfulTime is that time",
            self.core.time
        ))
    }

    /// Whether the run ends at the current time: the model asked to end it, or a sampled
    /// model's last sample is due now (it runs at the next read or step).
    pub fn run_ends(&self) -> bool {
        let now = self.core.time;
        self.core.terminate_requested
            || self.core.clock.is_some_and(|c| c.end_time().is_some_and(|end| end <= now + time_eps(now)))
    }
}

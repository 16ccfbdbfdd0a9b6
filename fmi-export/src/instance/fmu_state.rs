//! FMU state: save and restore, and the byte format's serialize and deserialize with
//! every check a loaded state passes.

use super::{decl, err, time_eps, Core, Generation, Instance, OpResult, SavedState};
use crate::decl::BaseType;
use crate::fmu_state::{self, LayerNumbers};
use crate::model::{Interface, Model, ModelError};
use crate::sampled::SampleClock;
use crate::states::Machine;
impl<M: Model> Instance<M> {
    pub fn save_state(&self) -> SavedState<M> {
        self.core.clone()
    }

    /// Restores a saved state (the callbacks stay the current instance's).
    pub fn restore_state(&mut self, state: &SavedState<M>) -> OpResult {
        let fits = match state.machine {
            // FMI 3.0 has no stepFailed state: a Discarded fmi3DoStep stays in Step Mode
            Machine::StepFailed if self.generation == Generation::Fmi3 => false,
            // Step Mode, or Scheduled Execution's Clock Activation Mode
            Machine::StepComplete => self.context.interface != Interface::ModelExchange,
            Machine::StepFailed => self.context.interface == Interface::CoSimulation,
            // Co-Simulation with Event Mode: a clocked FMI 3.0 instance
            Machine::EventMode => self.context.interface == Interface::ModelExchange || self.clocked,
            Machine::ContinuousTimeMode => self.context.interface == Interface::ModelExchange,
            _ => true,
        };
        if !fits {
            return err(format!(
                "a state saved in {:?} cannot be restored into a {:?} {:?} instance",
                state.machine, self.generation, self.context.interface
            ));
        }
        self.core = state.clone();
        Ok(())
    }

    /// The declared variables a serialized state holds (none when the model overrides).
    fn saved_rows() -> &'static [usize] {
        if M::SAVE_DECLARED_VARIABLES {
            &decl::<M>().saved_rows
        } else {
            &[]
        }
    }

    /// Bytes of a saved state ([`crate::fmu_state`]): the layer's numbers, the declared
    /// variables of [`crate::Declaration::saved_rows`] and the model's internal numbers. Events
    /// run lazily at the current time are saved as not run.
    pub fn serialize(state: &SavedState<M>) -> OpResult<Vec<u8>> {
        let (mut model, next_event, clock, presample) = match &state.pre_event {
            Some(pre) => (pre.model.clone(), pre.next_event, pre.clock, pre.presample),
            None => (state.model.clone(), state.next_event, state.clock, state.presample),
        };
        let mut numbers = Vec::new();
        LayerNumbers {
            machine: state.machine,
            time: state.time,
            stop_time: state.stop_time,
            next_event,
            iteration_pending: state.iteration_pending,
            clock: clock.map(|c| (c.start, c.period, c.next as f64)),
            presample,
        }
        .push_to(&mut numbers);
        for &row in Self::saved_rows() {
            let v = decl::<M>().variable(row);
            numbers.push(match v.base_type {
                BaseType::Real => model.get_real(v.binding)?,
                BaseType::Integer => model.get_integer(v.binding)? as f64,
                BaseType::Boolean => fmu_state::flag(model.get_boolean(v.binding)?),
            });
        }
        model.save_internal(&mut numbers);
        Ok(fmu_state::encode(decl::<M>().guid(), &numbers))
    }

    /// Parses bytes from [`Instance::serialize`]; refuses anything else with the reason.
    /// The variables go through the same checks and setters as `fmi2Set*`, and a state
    /// past initialization through the model's `exit_initialization` check.
    pub fn deserialize(&self, bytes: &[u8]) -> OpResult<SavedState<M>> {
        let saved = Self::saved_rows().len();
        let numbers = fmu_state::decode(decl::<M>().guid(), bytes, LayerNumbers::COUNT + saved)?;
        let LayerNumbers { machine, time, stop_time, next_event, iteration_pending, clock, presample } =
            LayerNumbers::read(&numbers, time_eps)?;
        let (has_clock, (clock_start, period, next_sample)) = (clock.is_some(), clock.unwrap_or_default());
        let flag = |x: f64, what: &str| -> OpResult<bool> { Ok(fmu_state::read_flag(x, what)?) };
        let mut model = Self::fresh_model(&self.context)?;
        let values = &numbers[LayerNumbers::COUNT..LayerNumbers::COUNT + saved];
        for (&row, &x) in Self::saved_rows().iter().zip(values) {
            let v = decl::<M>().variable(row);
            Self::check_value(row, x).map_err(|e| format!("serialized state: {e}"))?;
            let r = match v.base_type {
                BaseType::Real => model.set_real(v.binding, x),
                BaseType::Integer => {
                    if x != (x as i32) as f64 {
                        return err(format!("serialized state: {} = {x} is not an Integer", v.name));
                    }
                    model.set_integer(v.binding, x as i32)
                }
                BaseType::Boolean => model.set_boolean(v.binding, flag(x, v.name)?),
            };
            r.map_err(|e| format!("serialized state: {}: {e}", v.name))?;
        }
        model.load_internal(&numbers[LayerNumbers::COUNT + saved..])?;
        let initialized = !matches!(machine, Machine::Instantiated | Machine::InitializationMode);
        if initialized {
            model.exit_initialization().map_err(|e| format!("serialized state: {e}"))?;
        }
        let clock = if has_clock {
            Some(SampleClock { start: clock_start, period, next: 0, end: model.sample_end() })
        } else {
            None
        };
        let clock =
            Self::consistent_clock(&model, initialized, clock, next_sample, time, next_event, presample, self.clocked)
                .map_err(|e| ModelError::Error(format!("serialized state: {e}")))?;
        Ok(Core {
            machine,
            time,
            stop_time,
            next_event,
            iteration_pending,
            terminate_requested: clock.is_some_and(|c| !c.has_next()),
            model,
            clock,
            presample,
            // an activation of the clock is not part of a state: the importer activates it again
            clock_active: false,
            pre_event: None,
        })
    }

    /// A loaded sample clock agrees with the model and the instance: the model is sampled
    /// exactly when the state has a clock past initialization, with the period of its
    /// parameters; the sample count is an integer within the model's samples; the time
    /// lies between the last sample run and the next; the next event is the next sample
    /// (or the end of the samples) to the bit; "before the first sample" is "no sample run".
    #[allow(clippy::too_many_arguments)]
    fn consistent_clock(
        model: &M,
        initialized: bool,
        clock: Option<SampleClock>,
        next_sample: f64,
        time: f64,
        next_event: Option<f64>,
        presample: bool,
        clocked: bool,
    ) -> Result<Option<SampleClock>, String> {
        let period = model.sample_period();
        let Some(mut clock) = clock else {
            if initialized && period.is_some() {
                return Err("a sampled model past initialization without its sample clock".into());
            }
            if presample != (period.is_some()) {
                return Err(format!("the before-first-sample flag {presample} disagrees with the model"));
            }
            return Ok(None);
        };
        if !initialized {
            return Err("a sample clock before initialization ended".into());
        }
        if period != Some(clock.period) {
            return Err(format!(
                "the sample clock's period {} s disagrees with the model's {period:?} s",
                clock.period
            ));
        }
        if !(clock.start.is_finite() && next_sample >= 0.0 && next_sample.fract() == 0.0 && next_sample < 9e15) {
            return Err(format!(
                "the sample clock (start {} s, sample {next_sample}) is not a finite start and a sample count",
                clock.start
            ));
        }
        clock.next = next_sample as u64;
        if let Some(end) = clock.end {
            if clock.next > end.last + 1 {
                return Err(format!(
                    "sample {} is past the model's last sample {} (set by {})",
                    clock.next, end.last, end.variable
                ));
            }
        }
        if presample != (clock.next == 0) {
            return Err(format!("the before-first-sample flag {presample} disagrees with sample count {}", clock.next));
        }
        let (earliest, latest) = match clock.next {
            0 => (clock.start, clock.start),
            k => (clock.time_of(k - 1), clock.time_of(k)),
        };
        if !(time >= earliest - time_eps(earliest) && time <= latest + time_eps(latest)) {
            return Err(format!(
                "time {time} s is not between the last sample run and the next ({earliest} s .. {latest} s, sample {})",
                clock.next
            ));
        }
        // a clocked instance's samples are the importer's activations, no time events
        let expected = if clocked { None } else { clock.next_event() };
        if next_event.map(f64::to_bits) != expected.map(f64::to_bits) {
            return Err(format!(
                "the next event time {next_event:?} s disagrees with the sample clock: sample {} is due at {:?} s",
                clock.next, expected
            ));
        }
        Ok(Some(clock))
    }
}

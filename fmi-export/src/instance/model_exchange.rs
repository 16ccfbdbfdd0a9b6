//! The Model Exchange calls: time, the modes, discrete states, continuous states and
//! their derivatives.

use super::{decl, err, time_eps, Instance, OpResult};
use crate::model::{EventUpdate, Interface, Model};
use crate::states::Machine;
impl<M: Model> Instance<M> {
    pub fn set_time(&mut self, time: f64) -> OpResult {
        if !time.is_finite() {
            return err(format!("time {time} is not finite"));
        }
        if let Some(stop) = self.core.stop_time {
            // Variable-step integrators (CVode in fmpy, say) evaluate the right-hand side
            // past the output time and interpolate back, so a time past stopTime is not an
            // error in Model Exchange; it is a warning (fmi2Warning, logged). A
            // Co-Simulation step past stopTime is an error.
            if time > stop + time_eps(stop) {
                self.context
                    .logger
                    .warning(&format!("fmi2SetTime: time {time} is after the stopTime {stop} of fmi2SetupExperiment"));
            }
        }
        self.core.time = time;
        self.core.model.set_time(time);
        Ok(())
    }

    pub fn enter_event_mode(&mut self) -> OpResult {
        self.core.machine = Machine::EventMode;
        Ok(())
    }

    pub fn enter_continuous_time_mode(&mut self) -> OpResult {
        self.core.machine = Machine::ContinuousTimeMode;
        Ok(())
    }

    /// `fmi2NewDiscreteStates`: one event iteration when a time event is due (or the
    /// model asked for another); the next event time for the importer.
    pub fn new_discrete_states(&mut self) -> OpResult<EventUpdate> {
        if self.clocked {
            if self.context.interface == Interface::ModelExchange && !self.core.clock_active && self.sample_due_now() {
                self.sample_by_time_events()?;
                return self.new_discrete_states();
            }
            self.end_clock_activation()?;
            return Ok(EventUpdate {
                next_event_time: self.next_activation_to_publish(),
                terminate_simulation: self.core.terminate_requested,
                ..Default::default()
            });
        }
        let now = self.core.time;
        let due = matches!(self.core.next_event, Some(te) if te <= now + time_eps(now));
        if due || self.core.iteration_pending {
            let update = self.event_update(now)?;
            Ok(update)
        } else {
            Ok(EventUpdate {
                next_event_time: self.core.next_event,
                terminate_simulation: self.core.terminate_requested,
                ..Default::default()
            })
        }
    }

    fn check_state_count(&self, n: usize) -> OpResult {
        let expected = decl::<M>().number_of_states();
        if n == expected {
            Ok(())
        } else {
            err(format!("nx = {n}, the model has {expected} continuous states"))
        }
    }

    pub fn get_continuous_states(&mut self, out: &mut [f64]) -> OpResult {
        self.check_state_count(out.len())?;
        self.read_rows(&decl::<M>().state_rows, out)
    }

    /// Reads the Reals of `rows` into `out` (the state or derivative vector).
    fn read_rows(&mut self, rows: &[usize], out: &mut [f64]) -> OpResult {
        for (o, &row) in out.iter_mut().zip(rows) {
            *o = self.finite_real(row)?;
        }
        Ok(())
    }

    pub fn set_continuous_states(&mut self, x: &[f64]) -> OpResult {
        self.check_state_count(x.len())?;
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return err(format!(
                "state {} = {} refused: not a finite number",
                decl::<M>().variable(decl::<M>().state_rows[i]).name,
                x[i]
            ));
        }
        let backup = self.core.model.clone();
        for (&value, &row) in x.iter().zip(&decl::<M>().state_rows) {
            if let Err(e) = self.core.model.set_real(decl::<M>().variable(row).binding, value) {
                self.core.model = backup;
                return Err(e);
            }
        }
        Ok(())
    }

    pub fn get_derivatives(&mut self, out: &mut [f64]) -> OpResult {
        self.check_state_count(out.len())?;
        self.read_rows(&decl::<M>().derivative_rows, out)
    }

    pub fn get_nominals(&mut self, out: &mut [f64]) -> OpResult {
        self.check_state_count(out.len())?;
        for (o, &row) in out.iter_mut().zip(&decl::<M>().state_rows) {
            *o = decl::<M>().variable(row).nominal.unwrap_or(1.0);
        }
        Ok(())
    }

    pub fn get_event_indicators(&mut self, out: &mut [f64]) -> OpResult {
        if out.is_empty() {
            Ok(())
        } else {
            err(format!("ni = {}, the model has no event indicators", out.len()))
        }
    }
}

//! Values set while a run is in progress ([`Experiment::between_steps`](crate::Experiment::between_steps)):
//! a caller that steps a run from outside (the Python `System.step_until`) queues values for
//! inputs and tunable parameters; they are applied before the next communication step, as
//! input signals are ([`crate::InputTable`]).

use crate::error::{Error, Result};
use crate::simulate::algorithm::{Communication, Core};
use crate::simulate::clock::Point;
use crate::simulate::observer::Profiler;
use crate::system::{BaseType, System, Value, VariableRef};
use model_description::{Causality, Variability};
use std::sync::Mutex;

/// Values waiting for the next communication step of a run in progress.
#[derive(Debug, Default)]
pub struct SetQueue {
    pending: Mutex<Vec<(VariableRef, Value)>>,
}

impl SetQueue {
    /// An empty queue.
    pub fn new() -> SetQueue {
        SetQueue::default()
    }

    /// Queues `text` for the variable `name` of `system` (`instance.variable`), checked now:
    /// it must be an input no connection feeds, or a tunable parameter, and `text` a value
    /// of its type.
    pub fn push_text(&self, system: &System, name: &str, text: &str) -> Result<()> {
        let r = system.resolve(name)?;
        let v = system.variable(&r);
        let bad = |reason: String| {
            Error::Import(crate::ImportError::InvalidValue {
                variable: name.to_string(),
                value: text.to_string(),
                reason,
            })
        };
        if !(v.causality == Causality::Input || v.variability == Variability::Tunable) {
            return Err(bad(format!(
                "a {} {} variable cannot be set during a run (only inputs and tunable parameters)",
                v.variability.as_str(),
                v.causality.as_str()
            )));
        }
        if system.connections.iter().any(|c| c.to == r) {
            return Err(bad("the input is fed by a connection".into()));
        }
        let value = Value::parse(r.base_type, text).map_err(bad)?;
        self.pending.lock().unwrap_or_else(|p| p.into_inner()).push((r, value));
        Ok(())
    }

    fn take(&self) -> Vec<(VariableRef, Value)> {
        std::mem::take(&mut *self.pending.lock().unwrap_or_else(|p| p.into_inner()))
    }
}

/// The algorithm with the queued values applied before each step.
pub(crate) struct WithSets {
    pub(crate) inner: Box<dyn Communication>,
    pub(crate) queue: std::sync::Arc<SetQueue>,
}

impl WithSets {
    fn apply(&self, core: &mut Core) -> Result<()> {
        for (r, value) in self.queue.take() {
            let inst = &mut core.lanes[r.instance].inst;
            let vr = [r.value_reference];
            match (r.base_type, value) {
                (BaseType::Real, Value::Real(x)) => inst.set_real(&vr, &[x])?,
                (BaseType::Integer, Value::Integer(x)) => inst.set_integer(&vr, &[x])?,
                (BaseType::Boolean, Value::Boolean(x)) => inst.set_boolean(&vr, &[x as i32])?,
                (BaseType::String, Value::String(x)) => inst.set_string(r.value_reference, &x)?,
                // push_text parsed the value for the variable's type
                (_, other) => {
                    return Err(Error::Experiment(format!("a queued value {other:?} does not fit its variable")))
                }
            }
        }
        Ok(())
    }
}

impl Communication for WithSets {
    fn propagate(&mut self, core: &mut Core) -> Result<()> {
        self.inner.propagate(core)
    }

    fn step(&mut self, core: &mut Core, p: Point, calls: Option<&mut Profiler>) -> Result<()> {
        self.apply(core)?;
        self.inner.step(core, p, calls)
    }

    fn finish(&mut self, core: &mut Core) -> Result<()> {
        self.inner.finish(core)
    }
}

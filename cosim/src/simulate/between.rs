//! Values set while a run is in progress: [`Execution::set`](crate::simulate::Execution::set)
//! between steps, or a [`SetQueue`] filled from any thread (a row sink) and attached with
//! [`Execution::with_set_queue`](crate::simulate::Execution::with_set_queue). Inputs and
//! tunable parameters; applied before the next communication step, as input signals are
//! ([`crate::InputTable`]).

use crate::error::{Error, Result};
use crate::fmu::Instance;
use crate::simulate::algorithm::{Communication, Core};
use crate::simulate::clock::Point;
use crate::simulate::profiler::Profiler;
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
        let (r, value) = checked_value(system, name, text)?;
        self.pending.lock().unwrap_or_else(|p| p.into_inner()).push((r, value));
        Ok(())
    }

    fn take(&self) -> Vec<(VariableRef, Value)> {
        std::mem::take(&mut *self.pending.lock().unwrap_or_else(|p| p.into_inner()))
    }
}

/// `text` for the variable `name` of `system` (`instance.variable`), checked: it must be an
/// input no connection feeds, or a tunable parameter, and `text` a value of its type.
pub(crate) fn checked_value(system: &System, name: &str, text: &str) -> Result<(VariableRef, Value)> {
    let r = system.resolve(name)?;
    let v = system.variable(&r);
    let bad = |reason: String| {
        Error::Import(crate::ImportError::InvalidValue { variable: name.to_string(), value: text.to_string(), reason })
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
    Ok((r, value))
}

/// Sets `value` (checked by [`checked_value`]) on `inst`.
pub(crate) fn set_value(inst: &mut Instance, r: &VariableRef, value: Value) -> Result<()> {
    let vr = [r.value_reference];
    match (r.base_type, value) {
        (BaseType::Real, Value::Real(x)) => Ok(inst.set_real(&vr, &[x])?),
        (BaseType::Integer, Value::Integer(x)) => Ok(inst.set_integer(&vr, &[x])?),
        (BaseType::Boolean, Value::Boolean(x)) => Ok(inst.set_boolean(&vr, &[x as i32])?),
        (BaseType::String, Value::String(x)) => Ok(inst.set_string(r.value_reference, &x)?),
        // checked_value parsed the value for the variable's type
        (_, other) => Err(Error::Experiment(format!("a queued value {other:?} does not fit its variable"))),
    }
}

/// Applied before every communication step of an [`Execution`](crate::simulate::Execution)
/// (libcosim's manipulator): sets inputs and tunable parameters of the instances
/// ([`Execution::add_manipulator`](crate::simulate::Execution::add_manipulator)). A
/// [`SetQueue`] is one; the experiment's [`InputTable`](crate::InputTable) is applied before
/// them.
pub trait Manipulator: Send {
    /// Before the step `point` (from `point.t` to `point.t_next`). An error ends the run.
    fn before_step(&mut self, point: &Point, instances: &mut StepInstances<'_>) -> Result<()>;
}

/// The instances of a run, as a [`Manipulator`] sees them before a step.
pub struct StepInstances<'a> {
    pub(crate) core: &'a mut Core,
}

impl StepInstances<'_> {
    /// The instance `index` of the system (the order of [`System::instances`]).
    pub fn instance(&mut self, index: usize) -> &mut Instance {
        &mut self.core.lanes[index].inst
    }

    /// Sets `value` on the variable `r` (a value of its type).
    pub fn set(&mut self, r: &VariableRef, value: Value) -> Result<()> {
        set_value(&mut self.core.lanes[r.instance].inst, r, value)
    }
}

impl Manipulator for std::sync::Arc<SetQueue> {
    fn before_step(&mut self, _point: &Point, instances: &mut StepInstances<'_>) -> Result<()> {
        for (r, value) in self.take() {
            instances.set(&r, value)?;
        }
        Ok(())
    }
}

/// The algorithm with a manipulator applied before each step.
pub(crate) struct WithManipulator<'s> {
    pub(crate) inner: Box<dyn Communication + Send + 's>,
    pub(crate) manipulator: Box<dyn Manipulator + 's>,
}

impl Communication for WithManipulator<'_> {
    fn propagate(&mut self, core: &mut Core) -> Result<()> {
        self.inner.propagate(core)
    }

    fn step(&mut self, core: &mut Core, p: Point, calls: Option<&mut Profiler>) -> Result<()> {
        self.manipulator.before_step(&p, &mut StepInstances { core })?;
        self.inner.step(core, p, calls)
    }

    fn finish(&mut self, core: &mut Core) -> Result<()> {
        self.inner.finish(core)
    }
}

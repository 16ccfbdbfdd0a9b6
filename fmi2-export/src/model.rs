//! The small safe trait a model implements. It never sees a raw pointer, a C string or
//! the FMI state machine: the layer owns those.

use std::path::PathBuf;

use crate::decl::Declaration;

/// What the model learns at instantiation.
#[derive(Clone, Debug, PartialEq)]
pub struct InstantiateContext {
    pub instance_name: String,
    pub interface: Interface,
    /// The FMU's `resources/` folder, when the importer gave a usable `file:` URI.
    pub resource_path: Option<PathBuf>,
}

/// The interface an instance was created for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interface {
    ModelExchange,
    CoSimulation,
}

/// A model behind the FMI layer.
///
/// Variables are addressed by the model's own `Binding` (taken from its [`Declaration`]);
/// the layer has already checked the value reference, the base type, whether the
/// variable may be set now, and that a Real is finite. Errors are plain messages: the
/// layer logs them with the function's name and returns `fmi2Error`.
pub trait Model: Clone + Send + Sized + 'static {
    type Binding: Copy + std::fmt::Debug + Send + Sync + 'static;

    /// The declaration (variables, units, interfaces), built once.
    fn declaration() -> &'static Declaration<Self::Binding>;

    /// A fresh instance. The layer then applies every declared start value through the
    /// setters, so the declaration is the one place start values live.
    fn instantiate(context: &InstantiateContext) -> Result<Self, String>;

    fn get_real(&mut self, binding: Self::Binding) -> Result<f64, String>;
    fn set_real(&mut self, binding: Self::Binding, value: f64) -> Result<(), String>;

    fn get_integer(&mut self, binding: Self::Binding) -> Result<i32, String> {
        Err(format!("{binding:?} is not an Integer"))
    }
    fn set_integer(&mut self, binding: Self::Binding, _value: i32) -> Result<(), String> {
        Err(format!("{binding:?} is not an Integer"))
    }
    fn get_boolean(&mut self, binding: Self::Binding) -> Result<bool, String> {
        Err(format!("{binding:?} is not a Boolean"))
    }
    fn set_boolean(&mut self, binding: Self::Binding, _value: bool) -> Result<(), String> {
        Err(format!("{binding:?} is not a Boolean"))
    }

    /// Checks the parameters as a whole when initialization ends.
    fn exit_initialization(&mut self) -> Result<(), String> {
        Ok(())
    }

    /// Co-Simulation: advance from `time` by `step` with inputs held.
    fn do_step(&mut self, time: f64, step: f64) -> Result<(), String>;

    /// Model Exchange: the importer's time (for time-dependent models).
    fn set_time(&mut self, _time: f64) {}

    /// Exact directional derivative `dv_unknown = J dv_known`, J = d unknowns / d knowns.
    fn directional_derivative(
        &mut self,
        unknowns: &[Self::Binding],
        knowns: &[Self::Binding],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<(), String>;

    /// The whole model state as numbers (bit-exact; Booleans as 0/1), for serialization.
    fn save(&self, out: &mut Vec<f64>);
    /// Restores what [`Model::save`] wrote; refuses data of the wrong length or content.
    fn load(&mut self, data: &[f64]) -> Result<(), String>;
}

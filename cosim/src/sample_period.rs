//! The step-longer-than-sample-period warning: an FMU that declares how often it runs (a
//! parameter `sample_period`, else, for an FMU with discrete-time values of its own, its
//! DefaultExperiment stepSize) and a communication step longer than that. The run is still
//! what was asked for (the FMU runs its samples inside the step), but its inputs are held
//! and its outputs read less often than it is meant to run, which changes a closed loop's
//! result. `cosim run` and the Python package (`warnings.warn`) say the same words.

use model_description::{Causality, Variability, VariableType};

use crate::{Interface, System, Value};

/// One FMU whose declared sample period is shorter than the communication step.
#[derive(Clone, Debug, PartialEq)]
pub struct SamplePeriodWarning {
    /// The instance's name in the system.
    pub instance: String,
    /// The FMU's file name.
    pub file: String,
    /// The declared sample period [s].
    pub period: f64,
    /// Where the period was read: "its parameter sample_period" or "its DefaultExperiment stepSize".
    pub source: &'static str,
    /// The communication step [s].
    pub step: f64,
}

impl std::fmt::Display for SamplePeriodWarning {
    /// The warning without a remedy: each front end names its own option for the step
    /// (`--step`, `step_size=`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (name, file, period, source, step) = (&self.instance, &self.file, self.period, self.source, self.step);
        write!(
            f,
            "{name} ({file}) runs every {period} s ({source}), but the communication step is {step} s: its inputs \
             are held and its outputs read only every {step} s"
        )
    }
}

/// A warning for every FMU of `system` whose declared sample period (a parameter
/// `sample_period`, else, for an FMU with discrete states or outputs (Model Exchange:
/// outputs), its DefaultExperiment stepSize) is shorter than the communication step `step`.
pub fn warnings(system: &System, step: f64) -> Vec<SamplePeriodWarning> {
    let mut out = Vec::new();
    for spec in &system.instances {
        let md = spec.fmu.description();
        let parameter = md
            .model_variables
            .iter()
            .enumerate()
            .find(|(_, v)| v.name == "sample_period" && v.causality == Causality::Parameter && v.is_real());
        let from_parameter = parameter.and_then(|(index, v)| {
            let set = spec.start_values.iter().find(|(i, _)| *i == index).and_then(|(_, value)| match value {
                Value::Real(x) => Some(*x),
                _ => None,
            });
            let start = match v.variable_type {
                VariableType::Real { start, .. } => start,
                _ => None,
            };
            set.or(start).map(|p| (p, "its parameter sample_period"))
        });
        // the stepSize is only a suggestion of a continuous model (its integrator runs
        // within any step); it is a sample period where the FMU has discrete-time values
        // of its own, which change at its sample instants: in Co-Simulation discrete
        // states or outputs; in Model Exchange discrete outputs only (its discrete states
        // change at its events, which the master's integrator stops at within any
        // communication step; a model with discrete locals, such as the when-conditions
        // of a Modelica model, is continuous there)
        let me = spec.fmu.interface() == Interface::ModelExchange;
        let samples = md.model_variables.iter().any(|v| {
            v.variability == Variability::Discrete
                && match v.causality {
                    Causality::Output => true,
                    Causality::Input | Causality::Parameter => false,
                    _ => !me,
                }
        });
        let declared = from_parameter.or_else(|| {
            md.default_experiment
                .as_ref()
                .and_then(|d| d.step_size)
                .filter(|_| samples)
                .map(|p| (p, "its DefaultExperiment stepSize"))
        });
        if let Some((period, source)) = declared {
            // a relative margin for steps given in decimal (1e-3 vs 0.001000000000000002)
            if period > 0.0 && step > period * (1.0 + 1e-9) {
                out.push(SamplePeriodWarning {
                    instance: spec.name.clone(),
                    file: spec.fmu.source().file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(),
                    period,
                    source,
                    step,
                });
            }
        }
    }
    out
}

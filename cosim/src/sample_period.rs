//! The step-longer-than-sample-period warning: an FMU that declares how often it runs, read
//! from what any FMU can declare (FMI 3.0 periodic clocks, and the DefaultExperiment stepSize
//! of an FMU with discrete-time values of its own), never from a variable's name, and a
//! communication step longer than that. The run is still what was asked for (the FMU runs its
//! samples inside the step), but its inputs are held and its outputs read less often than it
//! is meant to run, which changes a closed loop's result. `cosim run` and the Python package
//! (`warnings.warn`) say the same words.

use model_description::{Causality, Variability};

use crate::{Interface, System};

/// One FMU whose declared sample period is shorter than the communication step.
#[derive(Clone, Debug, PartialEq)]
pub struct SamplePeriodWarning {
    /// The instance's name in the system.
    pub instance: String,
    /// The FMU's file name.
    pub file: String,
    /// The declared sample period [s].
    pub period: f64,
    /// Where the period was read: "its periodic clock" or "its DefaultExperiment stepSize".
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

/// Where a declared sample period comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PeriodSource {
    /// The shortest interval of the FMU's periodic (constant, fixed or tunable) clocks.
    Clock,
    /// The DefaultExperiment stepSize of an FMU with discrete outputs (Co-Simulation:
    /// also discrete states or locals).
    DefaultExperiment,
}

impl PeriodSource {
    /// The words of a warning.
    pub fn as_str(self) -> &'static str {
        match self {
            PeriodSource::Clock => "its periodic clock",
            PeriodSource::DefaultExperiment => "its DefaultExperiment stepSize",
        }
    }
}

/// The shortest interval, s, of an FMI 3.0 FMU's periodic clocks (`intervalDecimal`, else
/// `intervalCounter / resolution`), if it has any.
fn clock_period(md: &model_description::fmi3::ModelDescription) -> Option<f64> {
    md.model_variables
        .iter()
        .filter_map(|v| v.clock.as_ref())
        .filter(|c| matches!(c.interval_variability.as_deref(), Some("constant" | "fixed" | "tunable")))
        .filter_map(|c| {
            c.interval_decimal.or(match (c.interval_counter, c.resolution) {
                (Some(n), Some(r)) if r > 0 => Some(n as f64 / r as f64),
                _ => None,
            })
        })
        .filter(|p| *p > 0.0 && p.is_finite())
        .min_by(f64::total_cmp)
}

/// The sample period `fmu` declares of itself, if any.
pub fn declared_period(fmu: &crate::Fmu) -> Option<(f64, PeriodSource)> {
    if let Some(p) = fmu.fmi3_description().and_then(clock_period) {
        return Some((p, PeriodSource::Clock));
    }
    let md = fmu.description();
    // the stepSize is only a suggestion of a continuous model (its integrator runs within
    // any step); it is a sample period where the FMU has discrete-time values of its own,
    // which change at its sample instants: in Co-Simulation discrete states or outputs; in
    // Model Exchange discrete outputs only (its discrete states change at its events, which
    // the master's integrator stops at within any communication step; a model with discrete
    // locals, such as the when-conditions of a Modelica model, is continuous there)
    let me = fmu.interface() == Interface::ModelExchange;
    let samples = md.model_variables.iter().any(|v| {
        v.variability == Variability::Discrete
            && match v.causality {
                Causality::Output => true,
                Causality::Input | Causality::Parameter => false,
                _ => !me,
            }
    });
    md.default_experiment
        .as_ref()
        .and_then(|d| d.step_size)
        .filter(|p| samples && *p > 0.0 && p.is_finite())
        .map(|p| (p, PeriodSource::DefaultExperiment))
}

/// A warning for every FMU of `system` whose declared sample period ([`declared_period`]) is
/// shorter than the communication step `step`.
pub fn warnings(system: &System, step: f64) -> Vec<SamplePeriodWarning> {
    let mut out = Vec::new();
    for spec in &system.instances {
        if let Some((period, source)) = declared_period(&spec.fmu) {
            // a relative margin for steps given in decimal (1e-3 vs 0.001000000000000002)
            if step > period * (1.0 + 1e-9) {
                out.push(SamplePeriodWarning {
                    instance: spec.name.clone(),
                    file: spec.fmu.source().file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(),
                    period,
                    source: source.as_str(),
                    step,
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::clock_period;
    use model_description::fmi3::ModelDescription;

    /// An FMI 3.0 description with `clocks` among its variables.
    fn with_clocks(clocks: &str) -> ModelDescription {
        let xml = format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="m" instantiationToken="{{0}}">
  <ScheduledExecution modelIdentifier="m"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    {clocks}
  </ModelVariables>
  <ModelStructure/>
</fmiModelDescription>"#
        );
        ModelDescription::from_xml(&xml).unwrap()
    }

    #[test]
    fn the_shortest_periodic_clock_is_the_sample_period() {
        // intervalDecimal 0.01 s and 0.002 s: the shorter one
        let md = with_clocks(
            r#"<Clock name="slow" valueReference="1" causality="input" variability="discrete" intervalVariability="constant" intervalDecimal="0.01"/>
    <Clock name="fast" valueReference="2" causality="input" variability="discrete" intervalVariability="fixed" intervalDecimal="0.002"/>"#,
        );
        assert_eq!(clock_period(&md), Some(0.002));
        // intervalCounter 5 of a resolution of 1000 per second: 5 / 1000 = 0.005 s
        let md = with_clocks(
            r#"<Clock name="c" valueReference="1" causality="input" variability="discrete" intervalVariability="tunable" intervalCounter="5" resolution="1000"/>"#,
        );
        assert_eq!(clock_period(&md), Some(5.0 / 1000.0));
        // a triggered clock ticks when something happens: no period
        let md = with_clocks(
            r#"<Clock name="c" valueReference="1" causality="input" variability="discrete" intervalVariability="triggered"/>"#,
        );
        assert_eq!(clock_period(&md), None);
    }
}

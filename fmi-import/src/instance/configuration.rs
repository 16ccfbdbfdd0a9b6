//! Configuration Mode (FMI 3.0 section 3.2.2): the structural parameters an FMU was
//! configured with ([`crate::Fmu::configured`]) set between `fmi3EnterConfigurationMode`
//! and `fmi3ExitConfigurationMode`, right after instantiation (and after a reset), before
//! any other value is set: an FMU sizes its arrays when it leaves Configuration Mode.
//! Reconfiguration Mode ([`Instance::reconfigure`]): a tunable structural parameter set the
//! same way between two communication steps of a Co-Simulation instance (from Step Mode) or
//! in an event of a Model Exchange instance (from Event Mode), the arrays it sizes read and
//! set with their new size from then on.

use super::core::{call, Core};
use super::fmi3::Fmi3;
use super::Instance;
use crate::error::{Error, Result};
use crate::fmi3::Access;
use crate::fmu::Interface;
use model_description::fmi3;

impl Fmi3 {
    /// Enters Configuration Mode, sets the configured structural parameters and leaves it;
    /// nothing when the FMU was configured with none. The arrays have the sizes the instance
    /// starts with (`Fmi3Abi::initial_sizes`).
    pub(super) fn configure_structural(&mut self, core: &mut Core) -> Result<()> {
        self.resize(self.abi().initial_sizes.clone());
        let configuration = self.abi().configuration.clone();
        if configuration.is_empty() {
            return Ok(());
        }
        if core.host.is_some() {
            return Err(Error::Instance {
                name: core.name.clone(),
                reason: "its FMU has structural parameters set, and Configuration Mode is not forwarded to a host process: run it without isolation",
            });
        }
        self.in_configuration_mode(core, configuration)
    }

    /// `fmi3EnterConfigurationMode`, each (variable, value) of `sets` set, and
    /// `fmi3ExitConfigurationMode`.
    fn in_configuration_mode(&mut self, core: &mut Core, sets: impl IntoIterator<Item = (Access, f64)>) -> Result<()> {
        let enter = core.optional(self.abi().functions.enter_configuration_mode, "fmi3EnterConfigurationMode")?;
        let exit = core.optional(self.abi().functions.exit_configuration_mode, "fmi3ExitConfigurationMode")?;
        let c = core.component;
        call!(core, "fmi3EnterConfigurationMode", None, enter(c))?;
        for (access, value) in sets {
            self.set_all(core, access, &[value])?;
        }
        call!(core, "fmi3ExitConfigurationMode", None, exit(c))
    }

    /// Reconfiguration Mode: the tunable structural parameters `values` (name, value) set
    /// between `fmi3EnterConfigurationMode` and `fmi3ExitConfigurationMode` (see
    /// [`Instance::reconfigure`]).
    pub(super) fn reconfigure_between_steps(&mut self, core: &mut Core, values: &[(&str, f64)]) -> Result<()> {
        let bad = |name: &str, value: f64, reason: String| Error::InvalidValue {
            variable: format!("{}.{name}", core.name),
            value: value.to_string(),
            reason,
        };
        let Some((first, x)) = values.first() else { return Ok(()) };
        if core.host.is_some() {
            return Err(bad(
                first,
                *x,
                "Reconfiguration Mode is not forwarded to a host process: run without isolation".into(),
            ));
        }
        if core.fmu.interface() == Interface::ScheduledExecution {
            return Err(bad(
                first,
                *x,
                "Reconfiguration Mode is run for Co-Simulation and Model Exchange instances (not Scheduled Execution)"
                    .into(),
            ));
        }
        if !core.state.is_running() {
            return Err(bad(
                first,
                *x,
                format!("Reconfiguration Mode is entered between steps, not in {:?}", core.state),
            ));
        }
        let mut now = self.sizes_now.clone();
        let mut sets = Vec::with_capacity(values.len());
        for (name, value) in values {
            let md = &self.abi().description;
            let v = md
                .model_variables
                .iter()
                .find(|v| v.name == *name && v.causality == fmi3::Causality::StructuralParameter)
                .ok_or_else(|| bad(name, *value, "not a structural parameter of the FMU".into()))?;
            if v.variability != fmi3::Variability::Tunable {
                return Err(bad(
                    name,
                    *value,
                    format!(
                        "a {} structural parameter is set before initialization only (Reconfiguration Mode changes tunable ones)",
                        v.variability.as_str()
                    ),
                ));
            }
            crate::structural::checked_value(&core.name, v, *value)?;
            let vr = v.value_reference;
            now.retain(|(p, _)| *p != vr);
            let view = match &v.start {
                Some(fmi3::Values::Int(s)) if s.len() == 1 => s[0] as f64,
                Some(fmi3::Values::Float(s)) if s.len() == 1 => s[0],
                _ => f64::NAN,
            };
            if *value != view {
                now.push((vr, *value));
            }
            // the arrays it sizes fit the view's columns
            let resized = crate::structural::resized_arrays(md, &now);
            if let Some((array, (view, dims))) =
                resized.iter().find(|(_, (view, dims))| view.iter().zip(dims.iter()).any(|(a, b)| b > a))
            {
                let array = md.variable(*array).map_or("?", |a| a.name.as_str());
                return Err(bad(
                    name,
                    *value,
                    format!(
                        "{array} would have dimensions {dims:?}, beyond the {view:?} the run's results were sized for \
                         (size the FMU for it before the run: Fmu::sized_for)"
                    ),
                ));
            }
            // Model Exchange: the integrator keeps the states and event indicators it has
            if core.fmu.interface() == Interface::ModelExchange {
                let structure = &md.model_structure;
                let states: Vec<u32> = structure
                    .continuous_state_derivatives
                    .iter()
                    .chain(&structure.event_indicators)
                    .map(|u| u.value_reference)
                    .chain(md.model_variables.iter().filter_map(|d| d.derivative))
                    .collect();
                let sized = md.model_variables.iter().filter(|a| a.dimensions.contains(&fmi3::Dimension::Variable(vr)));
                if let Some(array) = sized.map(|a| (a.value_reference, &a.name)).find(|(a, _)| states.contains(a)) {
                    let array = array.1;
                    return Err(bad(
                        name,
                        *value,
                        format!(
                            "it sizes {array}, a continuous state, derivative or event indicator of a Model Exchange \
                             FMU: the integrator cannot change its number of states during the run"
                        ),
                    ));
                }
            }
            sets.push((Access { vr, value_type: v.value_type, element: 0, count: 1 }, *value));
        }
        self.in_configuration_mode(core, sets)?;
        self.resize(now);
        Ok(())
    }
}

impl Instance {
    /// Reconfiguration Mode between two communication steps of a Co-Simulation instance
    /// (from Step Mode) or of a Model Exchange instance in Event Mode (the caller enters it
    /// and iterates the event after): `fmi3EnterConfigurationMode`, the setters of the
    /// tunable structural parameters `values` (name, value), `fmi3ExitConfigurationMode`. The arrays they size
    /// have their new size from then on: the elements of the view they lack read as NaN,
    /// and a set of one is an error naming it. A parameter that is not tunable, a size beyond
    /// the view's (see [`crate::Fmu::sized_for`]), a Scheduled Execution or isolated instance
    /// are errors naming the parameter and the reason.
    pub fn reconfigure(&mut self, values: &[(&str, f64)]) -> Result<()> {
        self.calls.reconfigure(&mut self.core, values)
    }
}

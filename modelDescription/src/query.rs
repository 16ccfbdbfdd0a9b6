//! Look-ups by name and index, and the ModelStructure the standard expects.

use crate::types::*;

impl ModelDescription {
    /// 1-based index of the variable called `name` (the first one, if names repeat).
    pub fn index_of(&self, name: &str) -> Option<u32> {
        self.model_variables.iter().position(|v| v.name == name).and_then(|i| u32::try_from(i + 1).ok())
    }

    /// The variable called `name` (the first one, if names repeat).
    pub fn variable(&self, name: &str) -> Option<&ScalarVariable> {
        self.model_variables.iter().find(|v| v.name == name)
    }

    /// The variable with 1-based `index`.
    pub fn variable_at(&self, index: u32) -> Option<&ScalarVariable> {
        (index as usize).checked_sub(1).and_then(|i| self.model_variables.get(i))
    }

    /// Value reference of the Real variable called `name` (`None` if there is none or it
    /// is not Real).
    pub fn real_value_reference(&self, name: &str) -> Option<u32> {
        self.variable(name).filter(|v| v.is_real()).map(|v| v.value_reference)
    }

    /// 1-based indices of the state derivatives, in the order of the continuous states:
    /// the ModelStructure's `<Derivatives>` (FMI 2.0 section 2.2.8: the list is the state
    /// vector and its order; a variable with a `derivative` attribute outside it is no
    /// state derivative, as Dymola declares derivatives of variables that are no states),
    /// each a variable with a `derivative` attribute; for a description that lists none,
    /// the Real continuous variables with a `derivative` attribute, in ModelVariables order.
    pub fn state_derivatives(&self) -> Vec<u32> {
        let listed: Vec<u32> = self
            .model_structure
            .derivatives
            .iter()
            .map(|u| u.index)
            .filter(|&k| self.variable_at(k).is_some_and(|v| v.variable_type.derivative().is_some()))
            .collect();
        if listed.is_empty() {
            self.declared_derivatives()
        } else {
            listed
        }
    }

    /// 1-based indices of the Real continuous variables with a `derivative` attribute, in
    /// ModelVariables order (what `<Derivatives>` lists in a description we write).
    fn declared_derivatives(&self) -> Vec<u32> {
        self.model_variables
            .iter()
            .enumerate()
            .filter(|(_, v)| v.variability == Variability::Continuous && v.variable_type.derivative().is_some())
            .filter_map(|(i, _)| u32::try_from(i + 1).ok())
            .collect()
    }

    /// 1-based indices of the continuous states: the targets of the `derivative`
    /// attributes of the state derivatives ([`ModelDescription::state_derivatives`]),
    /// in that order, without repeats, only those in range. (A `derivative` attribute on
    /// a non-continuous variable, as on the parameter `g` of the Reference FMU
    /// BouncingBall, does not make a state.)
    pub fn states(&self) -> Vec<u32> {
        let mut out: Vec<u32> = Vec::new();
        for d in self.state_derivatives() {
            let Some(s) = self.variable_at(d).and_then(|v| v.variable_type.derivative()) else {
                continue;
            };
            if self.variable_at(s).is_some() && !out.contains(&s) {
                out.push(s);
            }
        }
        out
    }

    /// The ModelStructure the standard requires for these variables, with all
    /// `dependencies` absent ("depends on all knowns"): Outputs = the causality=output
    /// variables in order; Derivatives = [`ModelDescription::state_derivatives`];
    /// InitialUnknowns = outputs with initial approx/calculated, calculated parameters,
    /// and states and state derivatives with initial approx/calculated, sorted by index.
    pub fn expected_model_structure(&self) -> ModelStructure {
        let unknown = |index: u32| Unknown { index, dependencies: None, dependencies_kind: None };
        let indexed =
            || self.model_variables.iter().enumerate().filter_map(|(i, v)| u32::try_from(i + 1).ok().map(|k| (k, v)));
        let outputs: Vec<Unknown> =
            indexed().filter(|(_, v)| v.causality == Causality::Output).map(|(k, _)| unknown(k)).collect();
        let ders = self.declared_derivatives();
        let not_exact =
            |v: &ScalarVariable| matches!(v.effective_initial(), Some(Initial::Approx | Initial::Calculated));
        let mut init: std::collections::BTreeSet<u32> = indexed()
            .filter(|(_, v)| {
                (v.causality == Causality::Output && not_exact(v)) || v.causality == Causality::CalculatedParameter
            })
            .map(|(k, _)| k)
            .collect();
        for k in ders.iter().copied().chain(self.states()) {
            if self.variable_at(k).is_some_and(not_exact) {
                init.insert(k);
            }
        }
        ModelStructure {
            outputs,
            derivatives: ders.into_iter().map(unknown).collect(),
            initial_unknowns: init.into_iter().map(unknown).collect(),
        }
    }
}

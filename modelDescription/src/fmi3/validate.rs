//! Checks of an FMI 3.0 [`ModelDescription`] against the rules of the standard importers
//! enforce (fmpy's `validate`, the FMI 3.0 schema's key constraints, section 2.4).

use std::collections::{BTreeSet, HashMap, HashSet};
use std::fmt;

use super::*;
use crate::validate::{
    duplicate_unit_messages, enumeration_messages, initial_not_allowed_message, model_identifier_messages,
};

crate::validate::rules! {
    /// The number of start values must be the number of elements (1 for a scalar; an
    /// array may also give one value for all its elements).
    StartCount => "start-count",
    /// Only Float32/Float64 variables may be continuous.
    ContinuousNonFloat => "continuous-non-float",
    /// A `<Dimension valueReference>` must name an integer structural parameter or
    /// constant.
    Dimension => "dimension",
    /// `previous` and `clocks` must name variables of the right kind.
    Reference => "reference",
    /// A ModelStructure entry or dependency must be the value reference of a variable.
    UnknownValueReference => "unknown-value-reference",
    /// `<ContinuousStateDerivative>` must name variables with a `derivative` attribute.
    ContinuousStateDerivatives => "continuous-state-derivatives",
    /// `<EventIndicator>` must name continuous Float variables.
    EventIndicators => "event-indicators",
}

/// One violation found by [`ModelDescription::validate`].
pub type Problem = crate::validate::Problem<Rule>;

/// The FMI 2.0 table of section 2.2.7 is FMI 3.0's too; a structural parameter is a
/// parameter there.
fn as_fmi2(c: Causality) -> crate::Causality {
    c.to_fmi2().unwrap_or(crate::Causality::Parameter)
}

fn bound_value(b: Bound) -> f64 {
    match b {
        Bound::Float(x) => x,
        Bound::Int(i) => i as f64,
    }
}

impl ModelDescription {
    /// The number of elements of `v` (1 for a scalar): the product of its dimensions, a
    /// `valueReference` dimension taking the start value of the variable it names. `None`
    /// if a dimension names no integer variable with one start value.
    pub fn element_count(&self, v: &Variable) -> Option<u64> {
        v.dimensions.iter().try_fold(1u64, |n, d| {
            let size = match *d {
                Dimension::Fixed(size) => size,
                Dimension::Variable(vr) => match &self.variable(vr)?.start {
                    Some(Values::Int(s)) if s.len() == 1 => u64::try_from(s[0]).ok()?,
                    _ => return None,
                },
            };
            n.checked_mul(size)
        })
    }

    /// Checks the description against the FMI 3.0 rules (see [`Rule`]); an empty vector
    /// means no problem was found. Problems come in a deterministic order.
    pub fn validate(&self) -> Vec<Problem> {
        let mut problems = Vec::new();
        let mut push = |rule: Rule, variable: Option<&str>, message: String| {
            problems.push(Problem { rule, variable: variable.map(str::to_string), message })
        };
        let by_vr: HashMap<u32, &Variable> = self.model_variables.iter().map(|v| (v.value_reference, v)).collect();

        // Header.
        if !self.fmi_version.starts_with("3.") {
            push(Rule::FmiVersion, None, format!("fmiVersion is \"{}\", must be 3.x", self.fmi_version));
        }
        let interfaces = [
            ("ModelExchange", self.model_exchange.as_ref().map(|i| &i.common)),
            ("CoSimulation", self.co_simulation.as_ref().map(|i| &i.common)),
            ("ScheduledExecution", self.scheduled_execution.as_ref().map(|i| &i.common)),
        ];
        if interfaces.iter().all(|(_, i)| i.is_none()) {
            push(Rule::NoInterface, None, "no <ModelExchange>, <CoSimulation> or <ScheduledExecution>".into());
        }
        let ids = interfaces.iter().filter_map(|(element, i)| i.map(|i| (*element, i.model_identifier.as_str())));
        for message in model_identifier_messages(ids) {
            push(Rule::ModelIdentifier, None, message);
        }
        for message in duplicate_unit_messages(&self.unit_definitions) {
            push(Rule::DuplicateUnit, None, message);
        }
        let unit_names: HashSet<&str> = self.unit_definitions.iter().map(|u| u.name.as_str()).collect();
        let mut type_names = HashSet::new();
        for t in &self.type_definitions {
            if !type_names.insert(t.name.as_str()) {
                push(Rule::DeclaredType, None, format!("type \"{}\" is defined more than once", t.name));
            }
            if let TypeKind::Enumeration { items, .. } = &t.kind {
                for message in enumeration_messages(&t.name, items.iter().map(|i| (i.name.as_str(), i.value))) {
                    push(Rule::DeclaredType, None, message);
                }
            }
        }

        // Variables.
        let mut names: HashMap<&str, usize> = HashMap::new();
        let mut vrs: HashMap<u32, &str> = HashMap::new();
        let mut independents = Vec::new();
        for (i, v) in self.model_variables.iter().enumerate() {
            let name = Some(v.name.as_str());
            let element = v.value_type.element();
            if v.name.is_empty() {
                push(Rule::EmptyName, None, format!("variable {} (0-based {i}) has an empty name", i + 1));
            } else if let Some(first) = names.get(v.name.as_str()) {
                push(Rule::DuplicateName, name, format!("name used by variables {} and {}", first + 1, i + 1));
            } else {
                names.insert(v.name.as_str(), i);
            }
            if let Some(other) = vrs.get(&v.value_reference) {
                push(
                    Rule::DuplicateValueReference,
                    name,
                    format!("valueReference {} is also used by \"{other}\"", v.value_reference),
                );
            } else {
                vrs.insert(v.value_reference, v.name.as_str());
            }

            let (c2, var) = (as_fmi2(v.causality), v.variability);
            let legal = crate::legal_combination(c2, var);
            if !legal {
                push(
                    Rule::CausalityVariability,
                    name,
                    format!(
                        "causality=\"{}\" with variability=\"{}\" is not allowed",
                        v.causality.as_str(),
                        var.as_str()
                    ),
                );
            }
            let allowed = Initial::allowed(c2, var);
            if let Some(init) = v.initial {
                if matches!(v.causality, Causality::Input | Causality::Independent) {
                    push(Rule::Initial, name, initial_not_allowed_message(v.causality.as_str(), init));
                } else if legal && !allowed.contains(&init) {
                    push(
                        Rule::Initial,
                        name,
                        format!(
                            "initial=\"{}\" is not allowed for causality=\"{}\", variability=\"{}\"",
                            init.as_str(),
                            v.causality.as_str(),
                            var.as_str()
                        ),
                    );
                }
            }
            let initial = v.initial.or_else(|| Initial::default_for(c2, var));
            let start_required = v.value_type != ValueType::Clock
                && (v.causality == Causality::Input || matches!(initial, Some(Initial::Exact | Initial::Approx)));
            let start_forbidden = v.causality == Causality::Independent || initial == Some(Initial::Calculated);
            match (&v.start, start_required && !start_forbidden, start_forbidden) {
                (None, true, _) => push(Rule::StartRequired, name, "a start value is required here".into()),
                (Some(_), _, true) => push(
                    Rule::StartForbidden,
                    name,
                    if v.causality == Causality::Independent {
                        "the independent variable must not have a start value".into()
                    } else {
                        "initial=\"calculated\" must not have a start value".into()
                    },
                ),
                _ => {}
            }
            if let Some(start) = &v.start {
                match self.element_count(v) {
                    Some(n) if start.len() as u64 != n && !(v.is_array() && start.len() == 1) => push(
                        Rule::StartCount,
                        name,
                        format!("{} start values, the variable has {n} element(s)", start.len()),
                    ),
                    _ => {}
                }
            }
            if v.causality == Causality::Independent {
                independents.push(v.name.as_str());
                if !v.value_type.is_float() || var != Variability::Continuous || v.is_array() {
                    push(
                        Rule::Independent,
                        name,
                        format!(
                            "the independent variable must be a continuous scalar Float, is {element} {}",
                            var.as_str()
                        ),
                    );
                }
            }
            if var == Variability::Continuous && !v.value_type.is_float() {
                push(Rule::ContinuousNonFloat, name, format!("{element} variables cannot be continuous"));
            }
            if let Some(unit) = &v.unit {
                if !unit_names.contains(unit.as_str()) {
                    push(Rule::UndeclaredUnit, name, format!("unit \"{unit}\" is not in <UnitDefinitions>"));
                }
            }
            if let Some(d) = v.derivative {
                match by_vr.get(&d) {
                    Some(s) if s.value_type.is_float() && s.variability == Variability::Continuous => {}
                    Some(s) => push(
                        Rule::Derivative,
                        name,
                        format!("derivative={d} names \"{}\", which is not a continuous Float", s.name),
                    ),
                    None => push(Rule::Derivative, name, format!("derivative={d} names no variable")),
                }
            }
            if let (Some(lo), Some(hi)) = (v.min, v.max) {
                if bound_value(lo) > bound_value(hi) {
                    push(Rule::Bounds, name, format!("min {} > max {}", bound_value(lo), bound_value(hi)));
                }
            }
            let starts: Vec<f64> = match &v.start {
                Some(Values::Float(s)) => s.clone(),
                Some(Values::Int(s)) => s.iter().map(|&x| x as f64).collect(),
                _ => Vec::new(),
            };
            for s in starts {
                let below = v.min.is_some_and(|m| s < bound_value(m));
                let above = v.max.is_some_and(|m| s > bound_value(m));
                if below || above {
                    push(Rule::Bounds, name, format!("start {s} is outside [min, max]"));
                }
            }
            if let Some(nominal) = v.nominal {
                if !(nominal > 0.0) {
                    push(Rule::Nominal, name, format!("nominal {nominal} is not > 0"));
                }
            }
            for d in &v.dimensions {
                let Dimension::Variable(vr) = *d else { continue };
                match by_vr.get(&vr) {
                    Some(s)
                        if s.value_type.is_integer()
                            && s.value_type != ValueType::Enumeration
                            && !s.is_array()
                            && (s.causality == Causality::StructuralParameter || s.variability == Variability::Constant) => {}
                    Some(s) => push(
                        Rule::Dimension,
                        name,
                        format!(
                            "Dimension valueReference={vr} names \"{}\", which is not an integer structural parameter or constant",
                            s.name
                        ),
                    ),
                    None => push(Rule::Dimension, name, format!("Dimension valueReference={vr} names no variable")),
                }
            }
            if let Some(p) = v.previous {
                match by_vr.get(&p) {
                    Some(s) if s.value_type == v.value_type => {}
                    Some(s) => {
                        push(Rule::Reference, name, format!("previous={p} names \"{}\" of another type", s.name))
                    }
                    None => push(Rule::Reference, name, format!("previous={p} names no variable")),
                }
            }
            for &c in &v.clocks {
                if by_vr.get(&c).map(|s| s.value_type) != Some(ValueType::Clock) {
                    push(Rule::Reference, name, format!("clocks entry {c} is not the value reference of a Clock"));
                }
            }
            if let Some(t) = &v.declared_type {
                match self.type_definition(t) {
                    None => push(Rule::DeclaredType, name, format!("declaredType \"{t}\" is not in <TypeDefinitions>")),
                    Some(def) => {
                        let def_type = match &def.kind {
                            TypeKind::Float { value_type, .. }
                            | TypeKind::Integer { value_type, .. }
                            | TypeKind::Other { value_type } => *value_type,
                            TypeKind::Enumeration { .. } => ValueType::Enumeration,
                        };
                        if def_type != v.value_type {
                            push(
                                Rule::DeclaredType,
                                name,
                                format!(
                                    "declaredType \"{t}\" is a {}Type, the variable is {element}",
                                    def_type.element()
                                ),
                            );
                        } else if let (TypeKind::Enumeration { items, .. }, Some(Values::Int(s))) =
                            (&def.kind, &v.start)
                        {
                            for x in s {
                                if !items.iter().any(|item| item.value as i128 == *x) {
                                    push(Rule::DeclaredType, name, format!("start {x} is no item of \"{t}\""));
                                }
                            }
                        }
                    }
                }
            }
        }
        match independents.len() {
            1 => {}
            0 => push(Rule::Independent, None, "no variable has causality=\"independent\" (exactly one must)".into()),
            _ => push(
                Rule::Independent,
                None,
                format!("{} independent variables: {}", independents.len(), independents.join(", ")),
            ),
        }

        // ModelStructure.
        let ms = &self.model_structure;
        let lists: [(&str, &Vec<Unknown>); 5] = [
            ("Output", &ms.outputs),
            ("ContinuousStateDerivative", &ms.continuous_state_derivatives),
            ("ClockedState", &ms.clocked_states),
            ("InitialUnknown", &ms.initial_unknowns),
            ("EventIndicator", &ms.event_indicators),
        ];
        for (element, list) in lists {
            for u in list {
                let Some(v) = by_vr.get(&u.value_reference) else {
                    push(
                        Rule::UnknownValueReference,
                        None,
                        format!("<{element} valueReference=\"{}\"> names no variable", u.value_reference),
                    );
                    continue;
                };
                let name = Some(v.name.as_str());
                for d in u.dependencies.iter().flatten() {
                    if !by_vr.contains_key(d) {
                        push(
                            Rule::UnknownValueReference,
                            name,
                            format!("<{element}> dependency {d} names no variable"),
                        );
                    }
                }
                match (&u.dependencies, &u.dependencies_kind) {
                    (Some(d), Some(k)) if d.len() != k.len() => push(
                        Rule::DependenciesKind,
                        name,
                        format!("<{element}>: {} dependencies, {} dependenciesKind", d.len(), k.len()),
                    ),
                    (None, Some(_)) => push(
                        Rule::DependenciesKind,
                        name,
                        format!("<{element}>: dependenciesKind without dependencies"),
                    ),
                    _ => {}
                }
                match element {
                    "ContinuousStateDerivative" if v.derivative.is_none() => push(
                        Rule::ContinuousStateDerivatives,
                        name,
                        "listed as a <ContinuousStateDerivative> but has no derivative attribute".into(),
                    ),
                    "EventIndicator" if !(v.value_type.is_float() && v.variability == Variability::Continuous) => {
                        push(Rule::EventIndicators, name, "an <EventIndicator> must be a continuous Float".into())
                    }
                    _ => {}
                }
            }
        }
        let outputs: Vec<u32> = self
            .model_variables
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .map(|v| v.value_reference)
            .collect();
        let listed: Vec<u32> = ms.outputs.iter().map(|u| u.value_reference).collect();
        if outputs != listed {
            push(
                Rule::Outputs,
                None,
                format!("<Output> entries are {listed:?}, the causality=output variables are {outputs:?} (in order)"),
            );
        }
        let states: HashSet<u32> = self.states().into_iter().collect();
        let derivatives: HashSet<u32> = ms.continuous_state_derivatives.iter().map(|u| u.value_reference).collect();
        let expected: BTreeSet<u32> = self
            .model_variables
            .iter()
            .filter(|v| {
                let initial = v.initial.or_else(|| Initial::default_for(as_fmi2(v.causality), v.variability));
                let open = matches!(initial, Some(Initial::Approx | Initial::Calculated));
                v.causality == Causality::CalculatedParameter
                    || (open
                        && (v.causality == Causality::Output
                            || states.contains(&v.value_reference)
                            || derivatives.contains(&v.value_reference)))
            })
            .map(|v| v.value_reference)
            .collect();
        let listed: BTreeSet<u32> = ms.initial_unknowns.iter().map(|u| u.value_reference).collect();
        // a clocked variable is an InitialUnknown only if the FMU initializes it in
        // Initialization Mode (FMI 3.0.2 section 2.4.8): listed or not, both are right
        let clocked: BTreeSet<u32> =
            self.model_variables.iter().filter(|v| !v.clocks.is_empty()).map(|v| v.value_reference).collect();
        let listed_unclocked: BTreeSet<u32> = listed.difference(&clocked).copied().collect();
        let expected_unclocked: BTreeSet<u32> = expected.difference(&clocked).copied().collect();
        let extra_clocked = listed.intersection(&clocked).any(|vr| !expected.contains(vr));
        if expected_unclocked != listed_unclocked || extra_clocked || listed.len() != ms.initial_unknowns.len() {
            push(
                Rule::InitialUnknowns,
                None,
                format!("<InitialUnknown> entries are {listed:?} (once each), expected {expected:?}"),
            );
        }
        problems
    }
}

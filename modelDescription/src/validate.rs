//! Checks of a [`ModelDescription`] against the FMI 2.0 rules importers enforce.

use std::collections::{BTreeSet, HashMap, HashSet};
use std::fmt;

use crate::types::*;

/// `Rule`, the rule a [`Problem`] breaks, of one generation's checks: the rules both
/// generations share (below, once) and the generation's own (`$own`), each with its short
/// stable identifier ([`Rule::as_str`]) and `Display`.
macro_rules! rules {
    (@all $($(#[$doc:meta])* $variant:ident => $text:literal,)*) => {
        /// The rule a [`Problem`] breaks.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Rule {
            $($(#[$doc])* $variant,)*
        }

        impl Rule {
            /// A short stable identifier, e.g. `"start-required"`.
            pub fn as_str(self) -> &'static str {
                match self {
                    $(Rule::$variant => $text,)*
                }
            }
        }

        impl fmt::Display for Rule {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.as_str())
            }
        }
    };
    ($($own:tt)*) => {
        $crate::validate::rules!(@all
            /// `fmiVersion` must be the generation's: "2.0" (FMI 2.0), a 3.x version (FMI 3.0).
            FmiVersion => "fmi-version",
            /// At least one interface type must be present: `<ModelExchange>`, `<CoSimulation>` (FMI
            /// 3.0 also `<ScheduledExecution>`).
            NoInterface => "no-interface",
            /// `modelIdentifier` must be a non-empty C identifier.
            ModelIdentifier => "model-identifier",
            /// Variable names must be non-empty.
            EmptyName => "empty-name",
            /// Variable names must be unique.
            DuplicateName => "duplicate-name",
            /// Value references must be unique: per base type (Real, Integer, Boolean, String) in
            /// FMI 2.0, across all variables of all types in FMI 3.0.
            DuplicateValueReference => "duplicate-value-reference",
            /// Unit names must be unique.
            DuplicateUnit => "duplicate-unit",
            /// The (causality, variability) pair must be legal (FMI 2.0 section 2.2.7 table, FMI
            /// 3.0's too).
            CausalityVariability => "causality-variability",
            /// `initial` must be one the table allows for (causality, variability), and absent
            /// for inputs and the independent variable.
            Initial => "initial",
            /// A start value is required (initial exact/approx, inputs, parameters, constants).
            StartRequired => "start-required",
            /// A start value is forbidden (initial calculated, the independent variable).
            StartForbidden => "start-forbidden",
            /// The independent variable must be a continuous Real (FMI 3.0: Float); FMI 2.0 allows at
            /// most one, FMI 3.0 requires exactly one.
            Independent => "independent",
            /// A `unit` (FMI 3.0: or `displayUnit`) must be declared in `<UnitDefinitions>`.
            UndeclaredUnit => "undeclared-unit",
            /// `derivative` must name a continuous Real (Float) variable: in FMI 2.0 by its index, in
            /// FMI 3.0 by its value reference.
            Derivative => "derivative",
            /// `min <= max` and `min <= start <= max`.
            Bounds => "bounds",
            /// `nominal > 0`.
            Nominal => "nominal",
            /// `<Outputs>` (FMI 3.0: the `<Output>` entries) must list exactly the causality=output
            /// variables, in order.
            Outputs => "outputs",
            /// The initial unknowns (FMI 2.0 `<InitialUnknowns>`, sorted by index; FMI 3.0
            /// `<InitialUnknown>` entries) must list exactly the required set: the outputs, continuous
            /// states and state derivatives with initial approx or calculated, and the calculated
            /// parameters.
            InitialUnknowns => "initial-unknowns",
            /// `dependenciesKind` needs `dependencies` of the same length.
            DependenciesKind => "dependencies-kind",
            /// A `declaredType` must name a type definition of the variable's type (FMI 2.0: an
            /// Enumeration's an enumeration type); enumeration items must be unique and a start value
            /// one of them.
            DeclaredType => "declared-type",
            $($own)*
        );
    };
}
pub(crate) use rules;

rules! {
    /// Only Real variables may be continuous.
    ContinuousNonReal => "continuous-non-real",
    /// `<Derivatives>` must list exactly the state derivatives, once each.
    Derivatives => "derivatives",
    /// An `index` or `dependencies` entry is outside `1..=n`.
    IndexOutOfRange => "index-out-of-range",
    /// `dependencies` must be sorted ascending without duplicates.
    DependencyOrder => "dependency-order",
    /// `dependencies` may only refer to knowns.
    DependencyNotKnown => "dependency-not-known",
}

/// One violation found by [`ModelDescription::validate`] (`R` = [`Rule`]) or by
/// [`crate::fmi3::ModelDescription::validate`] (`R` = [`crate::fmi3::Rule`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Problem<R = Rule> {
    /// The rule broken.
    pub rule: R,
    /// The variable concerned, if any.
    pub variable: Option<String>,
    /// What is wrong, in words.
    pub message: String,
}

impl<R: fmt::Display> fmt::Display for Problem<R> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.variable {
            Some(v) => write!(f, "[{}] variable \"{}\": {}", self.rule, v, self.message),
            None => write!(f, "[{}] {}", self.rule, self.message),
        }
    }
}

/// Whether `s` is a C identifier (`[A-Za-z_][A-Za-z0-9_]*`).
pub fn is_c_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    match chars.next() {
        Some(c) if c.is_ascii_alphabetic() || c == '_' => {}
        _ => return false,
    }
    chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The problem of an `initial` attribute on an input or the independent variable (of
/// causality `causality`), which both generations forbid.
pub(crate) fn initial_not_allowed_message(causality: &str, initial: Initial) -> String {
    format!("causality=\"{causality}\" must not define initial (has \"{}\")", initial.as_str())
}

/// For each interface element whose `modelIdentifier` is not a C identifier, what is wrong
/// (`(element, modelIdentifier)` of the interfaces present).
pub(crate) fn model_identifier_messages<'a>(interfaces: impl IntoIterator<Item = (&'a str, &'a str)>) -> Vec<String> {
    interfaces
        .into_iter()
        .filter(|(_, id)| !is_c_identifier(id))
        .map(|(element, id)| format!("<{element}> modelIdentifier \"{id}\" is not a C identifier"))
        .collect()
}

/// For each unit defined again, what is wrong.
pub(crate) fn duplicate_unit_messages(units: &[Unit]) -> Vec<String> {
    let mut seen = HashSet::new();
    units
        .iter()
        .filter(|u| !seen.insert(u.name.as_str()))
        .map(|u| format!("unit \"{}\" is defined more than once", u.name))
        .collect()
}

/// What is wrong with the items `(name, value)` of the enumeration type `name`: none at
/// all, or an item whose name or value another has.
pub(crate) fn enumeration_messages<'a, V: Copy + Eq + std::hash::Hash + fmt::Display>(
    name: &str,
    items: impl ExactSizeIterator<Item = (&'a str, V)>,
) -> Vec<String> {
    let mut messages = Vec::new();
    if items.len() == 0 {
        messages.push(format!("enumeration \"{name}\" has no items"));
    }
    let (mut names, mut values) = (HashSet::new(), HashSet::new());
    for (item, value) in items {
        if !names.insert(item) || !values.insert(value) {
            messages.push(format!("enumeration \"{name}\": item {item} = {value} is not unique"));
        }
    }
    messages
}

struct Checker<'a> {
    md: &'a ModelDescription,
    problems: Vec<Problem>,
}

impl Checker<'_> {
    fn push(&mut self, rule: Rule, variable: Option<&str>, message: String) {
        self.problems.push(Problem { rule, variable: variable.map(str::to_string), message });
    }

    fn var_name(&self, index: u32) -> Option<&str> {
        let i = (index as usize).checked_sub(1)?;
        self.md.model_variables.get(i).map(|v| v.name.as_str())
    }

    fn describe(&self, index: u32) -> String {
        match self.var_name(index) {
            Some(n) => format!("{index} (\"{n}\")"),
            None => index.to_string(),
        }
    }
}

impl ModelDescription {
    /// Checks the description against the FMI 2.0 rules (see [`Rule`]); an empty
    /// vector means no problem was found. Problems come in a deterministic order.
    pub fn validate(&self) -> Vec<Problem> {
        let mut c = Checker { md: self, problems: Vec::new() };
        self.check_header(&mut c);
        self.check_variables(&mut c);
        self.check_structure(&mut c);
        c.problems
    }

    fn check_header(&self, c: &mut Checker) {
        if self.fmi_version != "2.0" {
            c.push(Rule::FmiVersion, None, format!("fmiVersion is \"{}\", must be \"2.0\"", self.fmi_version));
        }
        if self.model_exchange.is_none() && self.co_simulation.is_none() {
            c.push(Rule::NoInterface, None, "neither <ModelExchange> nor <CoSimulation> is present".into());
        }
        let ids = [
            self.model_exchange.as_ref().map(|m| ("ModelExchange", m.model_identifier.as_str())),
            self.co_simulation.as_ref().map(|m| ("CoSimulation", m.model_identifier.as_str())),
        ];
        for message in model_identifier_messages(ids.into_iter().flatten()) {
            c.push(Rule::ModelIdentifier, None, message);
        }
        for message in duplicate_unit_messages(&self.unit_definitions) {
            c.push(Rule::DuplicateUnit, None, message);
        }
        let mut type_names = HashSet::new();
        for t in &self.type_definitions {
            if !type_names.insert(t.name.as_str()) {
                c.push(Rule::DeclaredType, None, format!("type \"{}\" is defined more than once", t.name));
            }
            for message in enumeration_messages(&t.name, t.items.iter().map(|i| (i.name.as_str(), i.value))) {
                c.push(Rule::DeclaredType, None, message);
            }
        }
    }

    fn check_variables(&self, c: &mut Checker) {
        let n = self.model_variables.len();
        let units: HashSet<&str> = self.unit_definitions.iter().map(|u| u.name.as_str()).collect();
        let mut names: HashMap<&str, usize> = HashMap::new();
        let mut vrs: HashMap<(&'static str, u32), usize> = HashMap::new();
        let mut independent: Option<usize> = None;

        for (i, v) in self.model_variables.iter().enumerate() {
            let name = Some(v.name.as_str());
            let index = i + 1;
            if v.name.is_empty() {
                c.push(Rule::EmptyName, None, format!("variable {index} has an empty name"));
            } else if let Some(first) = names.insert(v.name.as_str(), index) {
                names.insert(v.name.as_str(), first);
                c.push(Rule::DuplicateName, name, format!("name used by variables {first} and {index}"));
            }
            let base = v.variable_type.type_name();
            if let Some(first) = vrs.get(&(base, v.value_reference)) {
                let other = &self.model_variables[*first - 1].name;
                c.push(
                    Rule::DuplicateValueReference,
                    name,
                    format!("{base} valueReference {} is also used by \"{other}\"", v.value_reference),
                );
            } else {
                vrs.insert((base, v.value_reference), index);
            }

            // (causality, variability, initial), section 2.2.7.
            let legal = legal_combination(v.causality, v.variability);
            if !legal {
                c.push(
                    Rule::CausalityVariability,
                    name,
                    format!(
                        "causality=\"{}\" with variability=\"{}\" is not allowed",
                        v.causality.as_str(),
                        v.variability.as_str()
                    ),
                );
            }
            if let Some(init) = v.initial {
                if matches!(v.causality, Causality::Input | Causality::Independent) {
                    c.push(Rule::Initial, name, initial_not_allowed_message(v.causality.as_str(), init));
                } else if legal && !Initial::allowed(v.causality, v.variability).contains(&init) {
                    let allowed: Vec<&str> =
                        Initial::allowed(v.causality, v.variability).iter().map(|i| i.as_str()).collect();
                    c.push(
                        Rule::Initial,
                        name,
                        format!(
                            "initial=\"{}\" is not allowed for causality=\"{}\", variability=\"{}\" (allowed: {})",
                            init.as_str(),
                            v.causality.as_str(),
                            v.variability.as_str(),
                            allowed.join(", ")
                        ),
                    );
                }
            }
            let eff = v.effective_initial();
            let has_start = v.variable_type.has_start();
            let start_required =
                v.causality == Causality::Input || matches!(eff, Some(Initial::Exact | Initial::Approx));
            let start_forbidden = v.causality == Causality::Independent || eff == Some(Initial::Calculated);
            if start_required && !start_forbidden && !has_start {
                let why = match (v.causality, eff) {
                    (Causality::Input, _) => "inputs need a start value".to_string(),
                    (_, Some(i)) if v.initial.is_none() => {
                        format!("initial defaults to \"{}\" here, which needs a start value", i.as_str())
                    }
                    (_, Some(i)) => format!("initial=\"{}\" needs a start value", i.as_str()),
                    _ => "a start value is required".to_string(),
                };
                c.push(Rule::StartRequired, name, why);
            }
            if start_forbidden && has_start {
                let why = if v.causality == Causality::Independent {
                    "the independent variable must not have a start value".to_string()
                } else {
                    "initial=\"calculated\" must not have a start value".to_string()
                };
                c.push(Rule::StartForbidden, name, why);
            }
            if v.causality == Causality::Independent {
                if !v.is_real() {
                    c.push(Rule::Independent, name, format!("the independent variable must be Real, is {base}"));
                }
                if let Some(first) = independent {
                    let other = &self.model_variables[first - 1].name;
                    c.push(Rule::Independent, name, format!("second independent variable (first is \"{other}\")"));
                } else {
                    independent = Some(index);
                }
            }
            if v.variability == Variability::Continuous && !v.is_real() {
                c.push(Rule::ContinuousNonReal, name, format!("{base} variables cannot be continuous"));
            }

            match &v.variable_type {
                VariableType::Real { start, unit, derivative, min, max, nominal } => {
                    if let Some(u) = unit {
                        if !units.contains(u.as_str()) {
                            c.push(
                                Rule::UndeclaredUnit,
                                name,
                                format!("unit \"{u}\" is not declared in UnitDefinitions"),
                            );
                        }
                    }
                    if let Some(d) = *derivative {
                        match (d as usize).checked_sub(1).and_then(|k| self.model_variables.get(k)) {
                            None => {
                                c.push(Rule::Derivative, name, format!("derivative=\"{d}\" is not an index in 1..={n}"))
                            }
                            Some(_) if d as usize == index => {
                                c.push(Rule::Derivative, name, format!("derivative=\"{d}\" refers to itself"))
                            }
                            Some(s) if !s.is_real() || s.variability != Variability::Continuous => c.push(
                                Rule::Derivative,
                                name,
                                format!(
                                    "derivative=\"{d}\" refers to \"{}\", which is not a Real continuous variable",
                                    s.name
                                ),
                            ),
                            Some(_) => {}
                        }
                    }
                    check_bounds(c, name, *min, *max, *start);
                    if let Some(nom) = *nominal {
                        if nom.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                            c.push(Rule::Nominal, name, format!("nominal={nom} must be > 0"));
                        }
                    }
                }
                VariableType::Integer { start, min, max } => {
                    check_bounds(c, name, min.map(f64::from), max.map(f64::from), start.map(f64::from));
                }
                VariableType::Enumeration { declared_type, start, min, max } => {
                    check_bounds(c, name, min.map(f64::from), max.map(f64::from), start.map(f64::from));
                    match self.type_definitions.iter().find(|t| &t.name == declared_type) {
                        None => c.push(
                            Rule::DeclaredType,
                            name,
                            format!("declaredType \"{declared_type}\" is not an enumeration type of TypeDefinitions"),
                        ),
                        Some(t) => {
                            if let Some(s) = start.filter(|&s| t.item(s).is_none()) {
                                c.push(
                                    Rule::DeclaredType,
                                    name,
                                    format!("start={s} is not a value of the enumeration \"{declared_type}\""),
                                );
                            }
                        }
                    }
                }
                _ => {}
            }
        }
    }

    fn check_structure(&self, c: &mut Checker) {
        let ms = &self.model_structure;
        let vars = &self.model_variables;
        let n = vars.len() as u32;
        let in_range = |i: u32| i >= 1 && i <= n;

        // Indices and dependency lists (range, order, kinds).
        for (list_name, list) in
            [("Outputs", &ms.outputs), ("Derivatives", &ms.derivatives), ("InitialUnknowns", &ms.initial_unknowns)]
        {
            for u in list {
                let who = c.var_name(u.index).map(str::to_string);
                let who = who.as_deref();
                if !in_range(u.index) {
                    c.push(
                        Rule::IndexOutOfRange,
                        None,
                        format!("<{list_name}> Unknown index={} is not in 1..={n}", u.index),
                    );
                }
                if let Some(deps) = &u.dependencies {
                    for &d in deps {
                        if !in_range(d) {
                            c.push(
                                Rule::IndexOutOfRange,
                                who,
                                format!("<{list_name}> Unknown {}: dependency {d} is not in 1..={n}", u.index),
                            );
                        }
                    }
                    if deps.windows(2).any(|w| w[0] >= w[1]) {
                        c.push(
                            Rule::DependencyOrder,
                            who,
                            format!(
                                "<{list_name}> Unknown {}: dependencies must be ascending without duplicates",
                                u.index
                            ),
                        );
                    }
                }
                match (&u.dependencies, &u.dependencies_kind) {
                    (None, Some(_)) => c.push(
                        Rule::DependenciesKind,
                        who,
                        format!("<{list_name}> Unknown {}: dependenciesKind without dependencies", u.index),
                    ),
                    (Some(d), Some(k)) if d.len() != k.len() => c.push(
                        Rule::DependenciesKind,
                        who,
                        format!(
                            "<{list_name}> Unknown {}: {} dependencies but {} dependenciesKind",
                            u.index,
                            d.len(),
                            k.len()
                        ),
                    ),
                    _ => {}
                }
            }
        }

        let expected = self.expected_model_structure();

        // Outputs: exactly the outputs, in ModelVariables order.
        self.check_list(c, Rule::Outputs, &ms.outputs, &expected.outputs, |listed, wanted| {
            format!("<Outputs> lists {listed} but the causality=\"output\" variables are {wanted}")
        });

        // Derivatives: exactly the state derivatives, each once (any order).
        let ders: Vec<u32> = ms.derivatives.iter().map(|u| u.index).collect();
        let der_set: BTreeSet<u32> = ders.iter().copied().collect();
        let want_ders: BTreeSet<u32> = expected.derivatives.iter().map(|u| u.index).collect();
        if der_set.len() != ders.len() || der_set != want_ders {
            c.push(
                Rule::Derivatives,
                None,
                format!(
                    "<Derivatives> lists {} but the state derivatives (Real continuous variables with a derivative attribute) are {}",
                    self.names_of(&ders),
                    self.names_of(&want_ders.iter().copied().collect::<Vec<_>>())
                ),
            );
        }

        // InitialUnknowns: exactly the required set, sorted by index.
        self.check_list(c, Rule::InitialUnknowns, &ms.initial_unknowns, &expected.initial_unknowns, |listed, wanted| {
            format!(
                "<InitialUnknowns> lists {listed} but must list, sorted by index, {wanted} (outputs with initial approx/calculated, calculated parameters, states and derivatives with initial approx/calculated)"
            )
        });

        // Dependencies refer to knowns only.
        let states: HashSet<u32> = self.states().into_iter().collect();
        let is_run_known = |d: u32| -> bool {
            let Some(v) = vars.get((d as usize).wrapping_sub(1)) else {
                return true;
            };
            matches!(v.causality, Causality::Input | Causality::Independent) || states.contains(&d)
        };
        let is_init_known = |d: u32| -> bool {
            let Some(v) = vars.get((d as usize).wrapping_sub(1)) else {
                return true;
            };
            is_run_known(d) || v.causality == Causality::Parameter || v.effective_initial() == Some(Initial::Exact)
        };
        for (list_name, list, init) in [
            ("Outputs", &ms.outputs, false),
            ("Derivatives", &ms.derivatives, false),
            ("InitialUnknowns", &ms.initial_unknowns, true),
        ] {
            for u in list {
                let Some(deps) = &u.dependencies else {
                    continue;
                };
                for &d in deps {
                    let known = if init { is_init_known(d) } else { is_run_known(d) };
                    if !known {
                        let allowed = if init {
                            "inputs, states, parameters, variables with initial=\"exact\" and the independent variable"
                        } else {
                            "inputs, continuous states and the independent variable"
                        };
                        let who = c.var_name(u.index).map(str::to_string);
                        let dep = c.describe(d);
                        c.push(
                            Rule::DependencyNotKnown,
                            who.as_deref(),
                            format!(
                                "<{list_name}> Unknown {}: dependency {dep} is not a known (allowed: {allowed})",
                                u.index
                            ),
                        );
                    }
                }
            }
        }
    }

    /// A problem of `rule` (its text from the names of the `listed` and the `wanted` indices)
    /// unless the ModelStructure list `listed` holds exactly the `wanted` entries, in order.
    fn check_list(
        &self,
        c: &mut Checker,
        rule: Rule,
        listed: &[Unknown],
        wanted: &[Unknown],
        message: impl FnOnce(String, String) -> String,
    ) {
        let listed: Vec<u32> = listed.iter().map(|u| u.index).collect();
        let wanted: Vec<u32> = wanted.iter().map(|u| u.index).collect();
        if listed != wanted {
            c.push(rule, None, message(self.names_of(&listed), self.names_of(&wanted)));
        }
    }

    fn names_of(&self, indices: &[u32]) -> String {
        let parts: Vec<String> = indices
            .iter()
            .map(|&i| match (i as usize).checked_sub(1).and_then(|k| self.model_variables.get(k)) {
                Some(v) => format!("{i} \"{}\"", v.name),
                None => i.to_string(),
            })
            .collect();
        format!("[{}]", parts.join(", "))
    }
}

fn check_bounds(c: &mut Checker, name: Option<&str>, min: Option<f64>, max: Option<f64>, start: Option<f64>) {
    if let (Some(lo), Some(hi)) = (min, max) {
        if lo > hi {
            c.push(Rule::Bounds, name, format!("min={lo} > max={hi}"));
        }
    }
    if let Some(s) = start {
        if let Some(lo) = min {
            if s < lo {
                c.push(Rule::Bounds, name, format!("start={s} < min={lo}"));
            }
        }
        if let Some(hi) = max {
            if s > hi {
                c.push(Rule::Bounds, name, format!("start={s} > max={hi}"));
            }
        }
    }
}

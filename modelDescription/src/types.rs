//! FMI 2.0 `modelDescription.xml` as Rust types (the subset an FMU of ours and the
//! importers we test against use; unknown elements are kept out, not guessed).
//!
//! Indices into ModelVariables (`derivative`, `Unknown::index`, `dependencies`) are
//! 1-based, exactly as in the XML.

use serde::{Deserialize, Serialize};

/// `ALL` (the values, in the order given), `as_str` (the XML spelling) and `parse` (its
/// inverse, exact and case-sensitive) of an enum of XML attribute values.
macro_rules! xml_spellings {
    ($t:ident, $all_doc:literal, $example:literal, { $($variant:ident => $spelling:literal),+ $(,)? }) => {
        impl $t {
            #[doc = $all_doc]
            pub const ALL: [$t; [$($spelling),+].len()] = [$($t::$variant),+];

            #[doc = concat!("The XML spelling, e.g. `\"", $example, "\"`.")]
            pub fn as_str(self) -> &'static str {
                match self {
                    $($t::$variant => $spelling),+
                }
            }

            /// Parses the XML spelling (exact, case-sensitive).
            pub fn parse(s: &str) -> Option<$t> {
                $t::ALL.into_iter().find(|x| x.as_str() == s)
            }
        }
    };
}
pub(crate) use xml_spellings;

/// `causality` of a ScalarVariable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum Causality {
    /// Independent parameter, set by the environment before/during initialization.
    Parameter,
    /// Parameter computed by the FMU from other parameters.
    CalculatedParameter,
    /// Value provided from outside the FMU.
    Input,
    /// Value computed by the FMU and exposed for connections.
    Output,
    /// Internal variable (the default when the attribute is absent).
    Local,
    /// The independent variable (time); at most one, Real, continuous, no start.
    Independent,
}

/// `variability` of a ScalarVariable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum Variability {
    /// Never changes.
    Constant,
    /// Changes only before initialization is finished.
    Fixed,
    /// Constant between external events (may be re-set by the environment).
    Tunable,
    /// Changes only at events.
    Discrete,
    /// May change at any time (the default when the attribute is absent; Real only).
    Continuous,
}

/// `initial` of a ScalarVariable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum Initial {
    /// Initialized with the start value.
    Exact,
    /// The start value is a guess the FMU may change during initialization.
    Approx,
    /// Computed during initialization; no start value allowed.
    Calculated,
}

/// The typed part of a ScalarVariable (`<Real>`, `<Integer>`, `<Boolean>`, `<String>`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum VariableType {
    /// `<Real>`.
    Real {
        /// `start` attribute.
        start: Option<f64>,
        /// `unit` attribute: must name a `<Unit>` of `<UnitDefinitions>`.
        unit: Option<String>,
        /// 1-based index of the state this variable is the derivative of.
        derivative: Option<u32>,
        /// `min` attribute (may be infinite).
        min: Option<f64>,
        /// `max` attribute (may be infinite).
        max: Option<f64>,
        /// `nominal` attribute (> 0).
        nominal: Option<f64>,
    },
    /// `<Integer>` (the reader also maps `<Enumeration>` here).
    Integer {
        /// `start` attribute.
        start: Option<i32>,
        /// `min` attribute.
        min: Option<i32>,
        /// `max` attribute.
        max: Option<i32>,
    },
    /// `<Enumeration declaredType=..>`: an Integer (same value-reference space, accessed
    /// through `fmi2GetInteger`/`fmi2SetInteger`) whose values are the items of the
    /// [`EnumerationType`] named `declared_type` in `<TypeDefinitions>`.
    Enumeration {
        /// `declaredType` attribute: the name of a `<SimpleType>` with an `<Enumeration>`.
        declared_type: String,
        /// `start` attribute.
        start: Option<i32>,
        /// `min` attribute.
        min: Option<i32>,
        /// `max` attribute.
        max: Option<i32>,
    },
    /// `<Boolean>`.
    Boolean {
        /// `start` attribute.
        start: Option<bool>,
    },
    /// `<String>`.
    String {
        /// `start` attribute.
        start: Option<String>,
    },
}

/// One `<ScalarVariable>`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScalarVariable {
    /// Unique name.
    pub name: String,
    /// Value reference, unique per base type.
    pub value_reference: u32,
    /// Optional description.
    pub description: Option<String>,
    /// `causality` (absent in XML means `Local`).
    pub causality: Causality,
    /// `variability` (absent in XML means `Continuous`).
    pub variability: Variability,
    /// `initial`; `None` means the attribute is absent (the standard's default applies,
    /// see [`ScalarVariable::effective_initial`]).
    pub initial: Option<Initial>,
    /// The type element and its attributes.
    pub variable_type: VariableType,
}

/// `<BaseUnit>` exponents and factor/offset (`value_SI = factor * value + offset`).
///
/// `Default` gives all exponents 0, `factor` 1 and `offset` 0 (the XML defaults).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BaseUnit {
    /// Exponent of kilogram.
    pub kg: i32,
    /// Exponent of metre.
    pub m: i32,
    /// Exponent of second.
    pub s: i32,
    /// Exponent of ampere (XML attribute `A`).
    pub a: i32,
    /// Exponent of kelvin (XML attribute `K`).
    pub k: i32,
    /// Exponent of mole.
    pub mol: i32,
    /// Exponent of candela.
    pub cd: i32,
    /// Exponent of radian.
    pub rad: i32,
    /// `factor` (XML default 1).
    pub factor: f64,
    /// `offset` (XML default 0).
    pub offset: f64,
}

impl Default for BaseUnit {
    fn default() -> Self {
        BaseUnit { kg: 0, m: 0, s: 0, a: 0, k: 0, mol: 0, cd: 0, rad: 0, factor: 1.0, offset: 0.0 }
    }
}

/// One `<Unit>` of `<UnitDefinitions>`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Unit {
    /// Unit name as used by the `unit` attribute of variables.
    pub name: String,
    /// Optional SI base-unit definition.
    pub base_unit: Option<BaseUnit>,
}

/// One `<Item>` of an enumeration type.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnumerationItem {
    /// Item name (unique in its type).
    pub name: String,
    /// Its Integer value (unique in its type).
    pub value: i32,
    /// Optional description.
    pub description: Option<String>,
}

/// A `<SimpleType name=..><Enumeration>..</Enumeration></SimpleType>` of `<TypeDefinitions>`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnumerationType {
    /// The type name, used as `declaredType` by variables.
    pub name: String,
    /// Optional description.
    pub description: Option<String>,
    /// The named items.
    pub items: Vec<EnumerationItem>,
}

impl EnumerationType {
    /// The item with this value.
    pub fn item(&self, value: i32) -> Option<&EnumerationItem> {
        self.items.iter().find(|i| i.value == value)
    }
}

/// One `<Category>` of `<LogCategories>`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LogCategory {
    /// Category name.
    pub name: String,
    /// Optional description.
    pub description: Option<String>,
}

/// `<DefaultExperiment>`.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct DefaultExperiment {
    /// `startTime`.
    pub start_time: Option<f64>,
    /// `stopTime`.
    pub stop_time: Option<f64>,
    /// `tolerance`.
    pub tolerance: Option<f64>,
    /// `stepSize`.
    pub step_size: Option<f64>,
}

impl DefaultExperiment {
    /// From 0 to `stop_time` s in communication steps of `step_size` s, no tolerance: the
    /// default run of a sampled model, its step the sample period.
    pub fn fixed_step(stop_time: f64, step_size: f64) -> Self {
        DefaultExperiment {
            start_time: Some(0.0),
            stop_time: Some(stop_time),
            tolerance: None,
            step_size: Some(step_size),
        }
    }
}

/// `<CoSimulation>` capability flags.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct CoSimulation {
    /// `modelIdentifier`: a C identifier, the shared library's base name.
    pub model_identifier: String,
    /// `needsExecutionTool`.
    pub needs_execution_tool: bool,
    /// `canHandleVariableCommunicationStepSize`.
    pub can_handle_variable_communication_step_size: bool,
    /// `canInterpolateInputs`.
    pub can_interpolate_inputs: bool,
    /// `maxOutputDerivativeOrder` (written only when non-zero).
    pub max_output_derivative_order: u32,
    /// `canRunAsynchronuously` (sic, the standard's spelling).
    pub can_run_asynchronuously: bool,
    /// `canBeInstantiatedOnlyOncePerProcess`.
    pub can_be_instantiated_only_once_per_process: bool,
    /// `canNotUseMemoryManagementFunctions`.
    pub can_not_use_memory_management_functions: bool,
    /// `canGetAndSetFMUstate`.
    pub can_get_and_set_fmu_state: bool,
    /// `canSerializeFMUstate`.
    pub can_serialize_fmu_state: bool,
    /// `providesDirectionalDerivative`.
    pub provides_directional_derivative: bool,
}

/// `<ModelExchange>` capability flags.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct ModelExchange {
    /// `modelIdentifier`: a C identifier, the shared library's base name.
    pub model_identifier: String,
    /// `needsExecutionTool`.
    pub needs_execution_tool: bool,
    /// `completedIntegratorStepNotNeeded`.
    pub completed_integrator_step_not_needed: bool,
    /// `canBeInstantiatedOnlyOncePerProcess`.
    pub can_be_instantiated_only_once_per_process: bool,
    /// `canNotUseMemoryManagementFunctions`.
    pub can_not_use_memory_management_functions: bool,
    /// `canGetAndSetFMUstate`.
    pub can_get_and_set_fmu_state: bool,
    /// `canSerializeFMUstate`.
    pub can_serialize_fmu_state: bool,
    /// `providesDirectionalDerivative`.
    pub provides_directional_derivative: bool,
}

/// The kind of a dependency (`dependenciesKind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum DependencyKind {
    /// No particular structure.
    Dependent,
    /// Constant factor.
    Constant,
    /// Fixed factor.
    Fixed,
    /// Tunable factor.
    Tunable,
    /// Discrete factor.
    Discrete,
}

/// One `<Unknown>` of the ModelStructure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Unknown {
    /// 1-based index into ModelVariables.
    pub index: u32,
    /// `None`: attribute absent (depends on all knowns); `Some(vec![])`: depends on nothing.
    /// Entries are 1-based indices into ModelVariables.
    pub dependencies: Option<Vec<u32>>,
    /// Same length as `dependencies` when present.
    pub dependencies_kind: Option<Vec<DependencyKind>>,
}

/// `<ModelStructure>`.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct ModelStructure {
    /// `<Outputs>`: every causality=output variable, in ModelVariables order.
    pub outputs: Vec<Unknown>,
    /// `<Derivatives>`: the state derivatives.
    pub derivatives: Vec<Unknown>,
    /// `<InitialUnknowns>`: sorted by index.
    pub initial_unknowns: Vec<Unknown>,
}

/// The whole `<fmiModelDescription>`.
/// (`Default`: no attribute, no element; a base for `..Default::default()`.)
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct ModelDescription {
    /// Always "2.0" for what we write; checked on read.
    pub fmi_version: String,
    /// `modelName`.
    pub model_name: String,
    /// `guid` (see [`ModelDescription::content_guid`]).
    pub guid: String,
    /// `description`.
    pub description: Option<String>,
    /// `author`.
    pub author: Option<String>,
    /// `version` of the FMU.
    pub version: Option<String>,
    /// `copyright`.
    pub copyright: Option<String>,
    /// `license`.
    pub license: Option<String>,
    /// `generationTool`.
    pub generation_tool: Option<String>,
    /// Deliberately no generationDateAndTime by default: the archive must be byte-identical on rebuild.
    pub generation_date_and_time: Option<String>,
    /// "flat" or "structured".
    pub variable_naming_convention: Option<String>,
    /// `numberOfEventIndicators` (always written).
    pub number_of_event_indicators: u32,
    /// `<ModelExchange>`, if the FMU supports Model Exchange.
    pub model_exchange: Option<ModelExchange>,
    /// `<CoSimulation>`, if the FMU supports Co-Simulation.
    pub co_simulation: Option<CoSimulation>,
    /// `<UnitDefinitions>` (element omitted when empty).
    pub unit_definitions: Vec<Unit>,
    /// Enumeration types of `<TypeDefinitions>` (element omitted when empty).
    #[serde(default)]
    pub type_definitions: Vec<EnumerationType>,
    /// `<LogCategories>` (element omitted when empty).
    pub log_categories: Vec<LogCategory>,
    /// `<DefaultExperiment>`.
    pub default_experiment: Option<DefaultExperiment>,
    /// `<ModelVariables>`; position `i` (0-based) has index `i + 1`.
    pub model_variables: Vec<ScalarVariable>,
    /// `<ModelStructure>`.
    pub model_structure: ModelStructure,
}

xml_spellings!(Causality, "All values, in the order of the standard's table columns.", "calculatedParameter", {
    Parameter => "parameter",
    CalculatedParameter => "calculatedParameter",
    Input => "input",
    Output => "output",
    Local => "local",
    Independent => "independent",
});

xml_spellings!(Variability, "All values, in the order of the standard's table rows.", "tunable", {
    Constant => "constant",
    Fixed => "fixed",
    Tunable => "tunable",
    Discrete => "discrete",
    Continuous => "continuous",
});

xml_spellings!(Initial, "All values.", "approx", {
    Exact => "exact",
    Approx => "approx",
    Calculated => "calculated",
});

impl Initial {
    /// The `initial` values the standard (FMI 2.0, section 2.2.7) allows for a
    /// (causality, variability) pair, default first. Empty when the attribute must be
    /// absent: inputs, the independent variable, and illegal combinations.
    pub fn allowed(causality: Causality, variability: Variability) -> &'static [Initial] {
        use Causality as C;
        use Variability as V;
        const A: &[Initial] = &[Initial::Exact];
        const B: &[Initial] = &[Initial::Calculated, Initial::Approx];
        const CC: &[Initial] = &[Initial::Calculated, Initial::Exact, Initial::Approx];
        if !legal_combination(causality, variability) {
            return &[];
        }
        match (causality, variability) {
            (C::Parameter, _) => A,
            (C::CalculatedParameter, _) => B,
            (C::Input, _) | (C::Independent, _) => &[],
            (C::Output | C::Local, V::Constant) => A,
            (C::Output | C::Local, V::Fixed | V::Tunable) => B,
            (C::Output | C::Local, V::Discrete | V::Continuous) => CC,
        }
    }

    /// The default `initial` for a (causality, variability) pair (`None` where the
    /// attribute is not allowed).
    pub fn default_for(causality: Causality, variability: Variability) -> Option<Initial> {
        Initial::allowed(causality, variability).first().copied()
    }
}

/// Whether a (causality, variability) combination is legal (FMI 2.0, section 2.2.7, table).
pub fn legal_combination(causality: Causality, variability: Variability) -> bool {
    use Causality as C;
    use Variability as V;
    matches!(
        (causality, variability),
        (C::Parameter, V::Fixed | V::Tunable)
            | (C::CalculatedParameter, V::Fixed | V::Tunable)
            | (C::Input, V::Discrete | V::Continuous)
            | (C::Output, V::Constant | V::Discrete | V::Continuous)
            | (C::Local, _)
            | (C::Independent, V::Continuous)
    )
}

xml_spellings!(DependencyKind, "All values.", "dependent", {
    Dependent => "dependent",
    Constant => "constant",
    Fixed => "fixed",
    Tunable => "tunable",
    Discrete => "discrete",
});

impl VariableType {
    /// The base type: `"Real"`, `"Integer"`, `"Boolean"` or `"String"` (an Enumeration is an
    /// `"Integer"`: it shares the Integer value-reference space and access functions).
    pub fn type_name(&self) -> &'static str {
        match self {
            VariableType::Real { .. } => "Real",
            VariableType::Integer { .. } | VariableType::Enumeration { .. } => "Integer",
            VariableType::Boolean { .. } => "Boolean",
            VariableType::String { .. } => "String",
        }
    }

    /// Whether a `start` attribute is present.
    pub fn has_start(&self) -> bool {
        match self {
            VariableType::Real { start, .. } => start.is_some(),
            VariableType::Integer { start, .. } | VariableType::Enumeration { start, .. } => start.is_some(),
            VariableType::Boolean { start } => start.is_some(),
            VariableType::String { start } => start.is_some(),
        }
    }

    /// The `derivative` attribute (Real only).
    pub fn derivative(&self) -> Option<u32> {
        match self {
            VariableType::Real { derivative, .. } => *derivative,
            _ => None,
        }
    }

    /// The `unit` attribute (Real only).
    pub fn unit(&self) -> Option<&str> {
        match self {
            VariableType::Real { unit, .. } => unit.as_deref(),
            _ => None,
        }
    }
}

impl ScalarVariable {
    /// `initial` as given, or the standard's default for this variable's
    /// (causality, variability); `None` for inputs, the independent variable and
    /// illegal combinations without an explicit `initial`.
    pub fn effective_initial(&self) -> Option<Initial> {
        self.initial.or_else(|| Initial::default_for(self.causality, self.variability))
    }

    /// Whether this is a Real variable.
    pub fn is_real(&self) -> bool {
        matches!(self.variable_type, VariableType::Real { .. })
    }
}

impl Unit {
    /// A unit defined by SI exponents (factor 1, offset 0).
    pub fn si(name: &str, kg: i32, m: i32, s: i32, rad: i32) -> Unit {
        Unit { name: name.to_string(), base_unit: Some(BaseUnit { kg, m, s, rad, ..BaseUnit::default() }) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn enum_spellings_round_trip() {
        for c in Causality::ALL {
            assert_eq!(Causality::parse(c.as_str()), Some(c));
        }
        for v in Variability::ALL {
            assert_eq!(Variability::parse(v.as_str()), Some(v));
        }
        for i in Initial::ALL {
            assert_eq!(Initial::parse(i.as_str()), Some(i));
        }
        for k in DependencyKind::ALL {
            assert_eq!(DependencyKind::parse(k.as_str()), Some(k));
        }
        assert_eq!(Causality::parse("Output"), None);
    }

    #[test]
    fn default_initial() {
        use Causality as C;
        use Variability as V;
        assert_eq!(Initial::default_for(C::Parameter, V::Fixed), Some(Initial::Exact));
        assert_eq!(Initial::default_for(C::CalculatedParameter, V::Tunable), Some(Initial::Calculated));
        assert_eq!(Initial::default_for(C::Output, V::Continuous), Some(Initial::Calculated));
        assert_eq!(Initial::default_for(C::Local, V::Constant), Some(Initial::Exact));
        assert_eq!(Initial::default_for(C::Input, V::Continuous), None);
        assert_eq!(Initial::default_for(C::Independent, V::Continuous), None);
        assert_eq!(Initial::default_for(C::Parameter, V::Continuous), None);
    }

    #[test]
    fn base_unit_default_is_the_xml_default() {
        let b = BaseUnit::default();
        assert_eq!((b.factor, b.offset, b.m), (1.0, 0.0, 0));
    }
}

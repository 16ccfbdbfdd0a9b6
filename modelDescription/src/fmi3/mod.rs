//! FMI 3.0 `modelDescription.xml` as Rust types: [`ModelDescription`], its variables
//! ([`Variable`], one per typed element `<Float64>`, `<Int32>`, ..., `<Clock>`), its
//! interface types and its `ModelStructure`, keyed by value reference as in the XML.
//!
//! The FMI 2.0 types of the crate root are reused where FMI 3.0 has the same thing
//! ([`Variability`], [`Initial`], [`DependencyKind`], [`Unit`], [`LogCategory`],
//! [`DefaultExperiment`]); FMI 3.0's causalities add `structuralParameter`, so they have
//! their own [`Causality`].

use serde::{Deserialize, Serialize};

pub mod read;
pub mod validate;
pub mod write;

pub use crate::read::{Position, ReadError};
pub use read::fmi_version_of;
pub use validate::{Problem, Rule};

pub use crate::{BaseUnit, DefaultExperiment, DependencyKind, Initial, LogCategory, Unit, Variability};

/// `causality` of an FMI 3.0 variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum Causality {
    /// Independent parameter.
    Parameter,
    /// Parameter computed by the FMU from other parameters.
    CalculatedParameter,
    /// A parameter that may change array sizes (Configuration Mode).
    StructuralParameter,
    /// Value provided from outside the FMU.
    Input,
    /// Value computed by the FMU and exposed for connections.
    Output,
    /// Internal variable (the default when the attribute is absent).
    Local,
    /// The independent variable (exactly one per FMU; Float64 or Float32, continuous).
    Independent,
}

crate::types::xml_spellings!(Causality, "All values.", "structuralParameter", {
    Parameter => "parameter",
    CalculatedParameter => "calculatedParameter",
    StructuralParameter => "structuralParameter",
    Input => "input",
    Output => "output",
    Local => "local",
    Independent => "independent",
});

impl Causality {
    /// The FMI 2.0 causality of the same name (`None` for `structuralParameter`).
    pub fn to_fmi2(self) -> Option<crate::Causality> {
        Some(match self {
            Causality::Parameter => crate::Causality::Parameter,
            Causality::CalculatedParameter => crate::Causality::CalculatedParameter,
            Causality::StructuralParameter => return None,
            Causality::Input => crate::Causality::Input,
            Causality::Output => crate::Causality::Output,
            Causality::Local => crate::Causality::Local,
            Causality::Independent => crate::Causality::Independent,
        })
    }

    /// The FMI 3.0 causality of an FMI 2.0 one (every FMI 2.0 causality has one).
    pub fn from_fmi2(c: crate::Causality) -> Causality {
        match c {
            crate::Causality::Parameter => Causality::Parameter,
            crate::Causality::CalculatedParameter => Causality::CalculatedParameter,
            crate::Causality::Input => Causality::Input,
            crate::Causality::Output => Causality::Output,
            crate::Causality::Local => Causality::Local,
            crate::Causality::Independent => Causality::Independent,
        }
    }
}

/// The type element of a variable (its XML element name), which selects the
/// `fmi3Get*`/`fmi3Set*` pair that accesses it. An Enumeration is accessed as Int64.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ValueType {
    /// `<Float32>`.
    Float32,
    /// `<Float64>`.
    Float64,
    /// `<Int8>`.
    Int8,
    /// `<UInt8>`.
    UInt8,
    /// `<Int16>`.
    Int16,
    /// `<UInt16>`.
    UInt16,
    /// `<Int32>`.
    Int32,
    /// `<UInt32>`.
    UInt32,
    /// `<Int64>`.
    Int64,
    /// `<UInt64>`.
    UInt64,
    /// `<Boolean>`.
    Boolean,
    /// `<String>` (start values as `<Start value=".."/>` children).
    String,
    /// `<Binary>` (start values as hex strings).
    Binary,
    /// `<Enumeration declaredType="..">`: Int64 values, items in `<TypeDefinitions>`.
    Enumeration,
    /// `<Clock>`.
    Clock,
}

impl ValueType {
    /// All values, in the order of the schema's choice.
    pub const ALL: [ValueType; 15] = [
        ValueType::Float32,
        ValueType::Float64,
        ValueType::Int8,
        ValueType::UInt8,
        ValueType::Int16,
        ValueType::UInt16,
        ValueType::Int32,
        ValueType::UInt32,
        ValueType::Int64,
        ValueType::UInt64,
        ValueType::Boolean,
        ValueType::String,
        ValueType::Binary,
        ValueType::Enumeration,
        ValueType::Clock,
    ];

    /// The XML element name, e.g. `"Float64"`.
    pub fn element(self) -> &'static str {
        match self {
            ValueType::Float32 => "Float32",
            ValueType::Float64 => "Float64",
            ValueType::Int8 => "Int8",
            ValueType::UInt8 => "UInt8",
            ValueType::Int16 => "Int16",
            ValueType::UInt16 => "UInt16",
            ValueType::Int32 => "Int32",
            ValueType::UInt32 => "UInt32",
            ValueType::Int64 => "Int64",
            ValueType::UInt64 => "UInt64",
            ValueType::Boolean => "Boolean",
            ValueType::String => "String",
            ValueType::Binary => "Binary",
            ValueType::Enumeration => "Enumeration",
            ValueType::Clock => "Clock",
        }
    }

    /// Parses an element name (exact).
    pub fn parse(element: &str) -> Option<ValueType> {
        ValueType::ALL.into_iter().find(|t| t.element() == element)
    }

    /// Float32 or Float64.
    pub fn is_float(self) -> bool {
        matches!(self, ValueType::Float32 | ValueType::Float64)
    }

    /// One of the eight integer types or Enumeration.
    pub fn is_integer(self) -> bool {
        matches!(
            self,
            ValueType::Int8
                | ValueType::UInt8
                | ValueType::Int16
                | ValueType::UInt16
                | ValueType::Int32
                | ValueType::UInt32
                | ValueType::Int64
                | ValueType::UInt64
                | ValueType::Enumeration
        )
    }

    /// The range of an integer type (`None` for the others); Enumeration is Int64.
    pub fn integer_range(self) -> Option<(i128, i128)> {
        Some(match self {
            ValueType::Int8 => (i8::MIN as i128, i8::MAX as i128),
            ValueType::UInt8 => (0, u8::MAX as i128),
            ValueType::Int16 => (i16::MIN as i128, i16::MAX as i128),
            ValueType::UInt16 => (0, u16::MAX as i128),
            ValueType::Int32 => (i32::MIN as i128, i32::MAX as i128),
            ValueType::UInt32 => (0, u32::MAX as i128),
            ValueType::Int64 | ValueType::Enumeration => (i64::MIN as i128, i64::MAX as i128),
            ValueType::UInt64 => (0, u64::MAX as i128),
            _ => return None,
        })
    }
}

/// A `min`/`max` bound: a float for Float32/64, an integer (wide enough for Int64 and
/// UInt64 alike) for the integer types and Enumeration.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Bound {
    /// Float32/Float64 (may be infinite).
    Float(f64),
    /// Integer types and Enumeration.
    Int(i128),
}

/// Start values: one for a scalar, the flattened (row-major) elements of an array.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Values {
    /// Float32/Float64 (a Float32's values are exactly representable as f64).
    Float(Vec<f64>),
    /// Integer types and Enumeration.
    Int(Vec<i128>),
    /// Boolean.
    Boolean(Vec<bool>),
    /// String.
    String(Vec<String>),
    /// Binary (the bytes the hex start string stands for).
    Binary(Vec<Vec<u8>>),
}

impl Values {
    /// The number of values.
    pub fn len(&self) -> usize {
        match self {
            Values::Float(v) => v.len(),
            Values::Int(v) => v.len(),
            Values::Boolean(v) => v.len(),
            Values::String(v) => v.len(),
            Values::Binary(v) => v.len(),
        }
    }

    /// No values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One `<Dimension>` of an array variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Dimension {
    /// `start="n"`: a fixed size.
    Fixed(u64),
    /// `valueReference="vr"`: the size is the value of this (structural parameter or
    /// constant) integer variable.
    Variable(u32),
}

/// The attributes of a `<Clock>` variable.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct ClockAttributes {
    /// `canBeDeactivated`.
    pub can_be_deactivated: bool,
    /// `priority`.
    pub priority: Option<u32>,
    /// `intervalVariability` (`constant`, `fixed`, `tunable`, `changing`, `countdown`,
    /// `triggered`).
    pub interval_variability: Option<String>,
    /// `intervalDecimal`, s.
    pub interval_decimal: Option<f64>,
    /// `shiftDecimal`, s.
    pub shift_decimal: Option<f64>,
    /// `supportsFraction`.
    pub supports_fraction: bool,
    /// `resolution`.
    pub resolution: Option<u64>,
    /// `intervalCounter`.
    pub interval_counter: Option<u64>,
    /// `shiftCounter`.
    pub shift_counter: Option<u64>,
}

/// One FMI 3.0 variable (a typed element of `<ModelVariables>`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Variable {
    /// Unique name.
    pub name: String,
    /// Value reference, unique across all types.
    pub value_reference: u32,
    /// Optional description.
    pub description: Option<String>,
    /// The element, which selects the getter and setter.
    pub value_type: ValueType,
    /// `causality` (absent in XML means `Local`).
    pub causality: Causality,
    /// `variability` (absent in XML means `Continuous` for Float32/64, `Discrete` otherwise).
    pub variability: Variability,
    /// `initial`; `None` when the attribute is absent.
    pub initial: Option<Initial>,
    /// `canHandleMultipleSetPerTimeInstant` (inputs of Model Exchange FMUs).
    pub can_handle_multiple_set_per_time_instant: Option<bool>,
    /// `intermediateUpdate`.
    pub intermediate_update: bool,
    /// `previous`: the value reference of the variable this one is the previous value of.
    pub previous: Option<u32>,
    /// `clocks`: the value references of the clocks this variable belongs to.
    pub clocks: Vec<u32>,
    /// `declaredType`: a type of `<TypeDefinitions>` (required for Enumeration).
    pub declared_type: Option<String>,
    /// `quantity`.
    pub quantity: Option<String>,
    /// `unit` (Float only): names a `<Unit>` of `<UnitDefinitions>`.
    pub unit: Option<String>,
    /// `displayUnit` (Float only).
    pub display_unit: Option<String>,
    /// `relativeQuantity` (Float only).
    pub relative_quantity: bool,
    /// `unbounded` (Float only).
    pub unbounded: bool,
    /// `min`.
    pub min: Option<Bound>,
    /// `max`.
    pub max: Option<Bound>,
    /// `nominal` (Float only, > 0).
    pub nominal: Option<f64>,
    /// Start value(s): one for a scalar, the flattened elements of an array.
    pub start: Option<Values>,
    /// `derivative` (Float only): the value reference of the state this is the derivative of.
    pub derivative: Option<u32>,
    /// `reinit` (Float only, continuous states in Model Exchange).
    pub reinit: bool,
    /// `<Dimension>` children, outermost first; empty for a scalar.
    pub dimensions: Vec<Dimension>,
    /// `mimeType` (Binary only).
    pub mime_type: Option<String>,
    /// `maxSize` (Binary only), bytes.
    pub max_size: Option<u64>,
    /// Clock attributes (Clock only).
    pub clock: Option<ClockAttributes>,
    /// `<Alias>` children: other names of the same variable.
    #[serde(default)]
    pub aliases: Vec<Alias>,
}

/// An `<Alias>` of a variable (FMI 3.0 section 2.4.7.5): another name for the same
/// variable, with its own description and display unit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Alias {
    /// Unique name (among all variables and aliases).
    pub name: String,
    /// Optional description.
    pub description: Option<String>,
    /// `displayUnit` (Float only).
    pub display_unit: Option<String>,
}

impl Variable {
    /// A scalar with only the required attributes set (the others absent or false).
    pub fn new(
        name: impl Into<String>,
        value_reference: u32,
        value_type: ValueType,
        causality: Causality,
        variability: Variability,
    ) -> Variable {
        Variable {
            name: name.into(),
            value_reference,
            description: None,
            value_type,
            causality,
            variability,
            initial: None,
            can_handle_multiple_set_per_time_instant: None,
            intermediate_update: false,
            previous: None,
            clocks: Vec::new(),
            declared_type: None,
            quantity: None,
            unit: None,
            display_unit: None,
            relative_quantity: false,
            unbounded: false,
            min: None,
            max: None,
            nominal: None,
            start: None,
            derivative: None,
            reinit: false,
            dimensions: Vec::new(),
            mime_type: None,
            max_size: None,
            clock: None,
            aliases: Vec::new(),
        }
    }

    /// Whether the variable is an array (has `<Dimension>` children).
    pub fn is_array(&self) -> bool {
        !self.dimensions.is_empty()
    }
}

/// The attributes every interface type element shares.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct InterfaceCommon {
    /// `modelIdentifier`: the library's file name and the function prefix.
    pub model_identifier: String,
    /// `needsExecutionTool`.
    pub needs_execution_tool: bool,
    /// `canBeInstantiatedOnlyOncePerProcess`.
    pub can_be_instantiated_only_once_per_process: bool,
    /// `canGetAndSetFMUState`.
    pub can_get_and_set_fmu_state: bool,
    /// `canSerializeFMUState`.
    pub can_serialize_fmu_state: bool,
    /// `providesDirectionalDerivatives`.
    pub provides_directional_derivatives: bool,
    /// `providesAdjointDerivatives`.
    pub provides_adjoint_derivatives: bool,
    /// `providesPerElementDependencies`.
    pub provides_per_element_dependencies: bool,
}

/// `<ModelExchange>`.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct ModelExchange {
    /// The shared attributes.
    pub common: InterfaceCommon,
    /// `needsCompletedIntegratorStep`.
    pub needs_completed_integrator_step: bool,
    /// `providesEvaluateDiscreteStates`.
    pub provides_evaluate_discrete_states: bool,
}

/// `<CoSimulation>`.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct CoSimulation {
    /// The shared attributes.
    pub common: InterfaceCommon,
    /// `canHandleVariableCommunicationStepSize`.
    pub can_handle_variable_communication_step_size: bool,
    /// `fixedInternalStepSize`, s.
    pub fixed_internal_step_size: Option<f64>,
    /// `maxOutputDerivativeOrder`.
    pub max_output_derivative_order: u32,
    /// `recommendedIntermediateInputSmoothness`.
    pub recommended_intermediate_input_smoothness: i32,
    /// `providesIntermediateUpdate`.
    pub provides_intermediate_update: bool,
    /// `mightReturnEarlyFromDoStep`.
    pub might_return_early_from_do_step: bool,
    /// `canReturnEarlyAfterIntermediateUpdate`.
    pub can_return_early_after_intermediate_update: bool,
    /// `hasEventMode`.
    pub has_event_mode: bool,
    /// `providesEvaluateDiscreteStates`.
    pub provides_evaluate_discrete_states: bool,
}

/// `<ScheduledExecution>`.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct ScheduledExecution {
    /// The shared attributes.
    pub common: InterfaceCommon,
}

/// One `<Item>` of an FMI 3.0 enumeration type (Int64 values).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnumerationItem {
    /// Item name (unique in its type).
    pub name: String,
    /// Its value (unique in its type).
    pub value: i64,
    /// Optional description.
    pub description: Option<String>,
}

/// What a type definition of `<TypeDefinitions>` defines.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum TypeKind {
    /// `<Float32Type>`/`<Float64Type>`: defaults for variables declaring it.
    Float {
        /// Float32 or Float64.
        value_type: ValueType,
        /// `quantity`.
        quantity: Option<String>,
        /// `unit`.
        unit: Option<String>,
        /// `displayUnit`.
        display_unit: Option<String>,
        /// `min`.
        min: Option<f64>,
        /// `max`.
        max: Option<f64>,
        /// `nominal`.
        nominal: Option<f64>,
    },
    /// `<Int8Type>` .. `<UInt64Type>`.
    Integer {
        /// The integer type.
        value_type: ValueType,
        /// `quantity`.
        quantity: Option<String>,
        /// `min`.
        min: Option<i128>,
        /// `max`.
        max: Option<i128>,
    },
    /// `<EnumerationType>` with its items.
    Enumeration {
        /// `quantity`.
        quantity: Option<String>,
        /// The items.
        items: Vec<EnumerationItem>,
    },
    /// `<BooleanType>`, `<StringType>`, `<BinaryType>` or `<ClockType>` (kept by element).
    Other {
        /// The element's value type (Boolean, String, Binary or Clock).
        value_type: ValueType,
    },
}

/// One type definition of `<TypeDefinitions>`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TypeDefinition {
    /// The type name, used as `declaredType` by variables.
    pub name: String,
    /// Optional description.
    pub description: Option<String>,
    /// What it defines.
    pub kind: TypeKind,
}

/// One entry of `<ModelStructure>` (`<Output>`, `<ContinuousStateDerivative>`,
/// `<ClockedState>`, `<InitialUnknown>`, `<EventIndicator>`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Unknown {
    /// The value reference of the unknown.
    pub value_reference: u32,
    /// `dependencies`: value references of the knowns it depends on (`None`: the
    /// attribute is absent, dependence on all knowns is to be assumed; `Some([])`: none).
    pub dependencies: Option<Vec<u32>>,
    /// `dependenciesKind`, one per dependency.
    pub dependencies_kind: Option<Vec<DependencyKind>>,
}

/// `<ModelStructure>`.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct ModelStructure {
    /// `<Output>` entries, in the order of the outputs' declaration.
    pub outputs: Vec<Unknown>,
    /// `<ContinuousStateDerivative>` entries: their order is the order of the states.
    pub continuous_state_derivatives: Vec<Unknown>,
    /// `<ClockedState>` entries.
    pub clocked_states: Vec<Unknown>,
    /// `<InitialUnknown>` entries.
    pub initial_unknowns: Vec<Unknown>,
    /// `<EventIndicator>` entries: their order is the order of the event indicators.
    pub event_indicators: Vec<Unknown>,
}

/// An FMI 3.0 `modelDescription.xml`.
/// (`Default`: no attribute, no element; a base for `..Default::default()`.)
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct ModelDescription {
    /// `fmiVersion` ("3.0", or "3.0.x").
    pub fmi_version: String,
    /// `modelName`.
    pub model_name: String,
    /// `instantiationToken` (FMI 2.0's guid).
    pub instantiation_token: String,
    /// `description`.
    pub description: Option<String>,
    /// `author`.
    pub author: Option<String>,
    /// `version`.
    pub version: Option<String>,
    /// `copyright`.
    pub copyright: Option<String>,
    /// `license`.
    pub license: Option<String>,
    /// `generationTool`.
    pub generation_tool: Option<String>,
    /// `generationDateAndTime`.
    pub generation_date_and_time: Option<String>,
    /// `variableNamingConvention` (`flat` or `structured`).
    pub variable_naming_convention: Option<String>,
    /// `<ModelExchange>`, if offered.
    pub model_exchange: Option<ModelExchange>,
    /// `<CoSimulation>`, if offered.
    pub co_simulation: Option<CoSimulation>,
    /// `<ScheduledExecution>`, if offered.
    pub scheduled_execution: Option<ScheduledExecution>,
    /// `<UnitDefinitions>`.
    pub unit_definitions: Vec<Unit>,
    /// `<TypeDefinitions>`.
    pub type_definitions: Vec<TypeDefinition>,
    /// `<LogCategories>`.
    pub log_categories: Vec<LogCategory>,
    /// `<DefaultExperiment>`.
    pub default_experiment: Option<DefaultExperiment>,
    /// `<ModelVariables>`, in document order.
    pub model_variables: Vec<Variable>,
    /// `<ModelStructure>`.
    pub model_structure: ModelStructure,
}

impl ModelDescription {
    /// The variable with this value reference.
    pub fn variable(&self, value_reference: u32) -> Option<&Variable> {
        self.model_variables.iter().find(|v| v.value_reference == value_reference)
    }

    /// The variable with this name.
    pub fn variable_by_name(&self, name: &str) -> Option<&Variable> {
        self.model_variables.iter().find(|v| v.name == name)
    }

    /// The continuous states, in the order of `<ContinuousStateDerivative>`: the value
    /// reference each derivative's `derivative` attribute names.
    pub fn states(&self) -> Vec<u32> {
        self.model_structure
            .continuous_state_derivatives
            .iter()
            .filter_map(|u| self.variable(u.value_reference).and_then(|v| v.derivative))
            .collect()
    }

    /// The type definition with this name.
    pub fn type_definition(&self, name: &str) -> Option<&TypeDefinition> {
        self.type_definitions.iter().find(|t| t.name == name)
    }
}

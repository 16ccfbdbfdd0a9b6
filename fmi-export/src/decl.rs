//! The Rust declaration of a model's variables: the one source of truth from which the
//! layer dispatches value references AND generates `modelDescription.xml`.

use std::collections::HashMap;

use model_description as md;

use crate::log::LOG_CATEGORIES;
use crate::states::{settable_in, Machine};
pub use model_description::{Causality, Initial, Variability};

/// Base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BaseType {
    Real,
    Integer,
    Boolean,
}

/// A declared variable, as [`crate::Variables`] returned it: what dependencies refer to,
/// and how a test or an importer addresses it (`fmi2GetReal(value_reference)` for a Real).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct VarHandle {
    pub base_type: BaseType,
    pub value_reference: u32,
}

/// Start value (its variant also fixes the base type).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    None,
    Real(f64),
    Integer(i32),
    Boolean(bool),
}

impl From<f64> for Start {
    fn from(x: f64) -> Self {
        Start::Real(x)
    }
}
impl From<i32> for Start {
    fn from(x: i32) -> Self {
        Start::Integer(x)
    }
}
impl From<bool> for Start {
    fn from(x: bool) -> Self {
        Start::Boolean(x)
    }
}

/// What an Unknown of the ModelStructure depends on.
#[derive(Clone, Debug, PartialEq)]
pub enum Dependencies {
    /// Attribute absent: depends on all knowns.
    All,
    /// Value references (of Reals) of the knowns it depends on; empty: none.
    On(Vec<u32>),
    /// The knowns it depends on, as [`Variables`](crate::Variables) returned them (Reals).
    Variables(Vec<VarHandle>),
}

impl From<Vec<VarHandle>> for Dependencies {
    fn from(on: Vec<VarHandle>) -> Self {
        Dependencies::Variables(on)
    }
}
impl From<&[VarHandle]> for Dependencies {
    fn from(on: &[VarHandle]) -> Self {
        Dependencies::Variables(on.to_vec())
    }
}
impl<const N: usize> From<[VarHandle; N]> for Dependencies {
    fn from(on: [VarHandle; N]) -> Self {
        Dependencies::Variables(on.to_vec())
    }
}

/// A reference to a Real state: its value reference or its handle.
pub trait RealReference {
    fn real_value_reference(&self) -> u32;
}
impl RealReference for u32 {
    fn real_value_reference(&self) -> u32 {
        *self
    }
}
impl RealReference for VarHandle {
    fn real_value_reference(&self) -> u32 {
        self.value_reference
    }
}

/// One declared variable, bound to the model's own handle `B` for it.
#[derive(Clone, Debug)]
pub struct VarDecl<B> {
    pub name: &'static str,
    pub value_reference: u32,
    pub base_type: BaseType,
    pub description: &'static str,
    pub causality: Causality,
    pub variability: Variability,
    pub initial: Option<Initial>,
    pub start: Start,
    pub unit: Option<&'static str>,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub nominal: Option<f64>,
    /// Value reference of the state this variable is the time derivative of.
    pub derivative_of: Option<u32>,
    /// For outputs and derivatives: what they depend on (ModelStructure).
    pub dependencies: Dependencies,
    /// For an Enumeration (base type Integer): the name of its type in
    /// [`DeclarationSpec::enumerations`].
    pub declared_type: Option<&'static str>,
    /// The binding's base type is not the variable's (a `bool` field for a Real): a slip
    /// [`Declaration::new`] refuses.
    pub(crate) mismatched_accessor: bool,
    pub binding: B,
}

impl<B> VarDecl<B> {
    fn new(name: &'static str, value_reference: u32, base_type: BaseType, binding: B) -> Self {
        VarDecl {
            name,
            value_reference,
            base_type,
            description: "",
            causality: Causality::Local,
            variability: Variability::Continuous,
            initial: None,
            start: Start::None,
            unit: None,
            min: None,
            max: None,
            nominal: None,
            derivative_of: None,
            dependencies: Dependencies::All,
            declared_type: None,
            mismatched_accessor: false,
            binding,
        }
    }

    /// A variable without its final binding yet (for [`crate::Variables`]).
    pub(crate) fn unbound(name: &'static str, value_reference: u32, base_type: BaseType, binding: B) -> Self {
        Self::new(name, value_reference, base_type, binding)
    }

    /// The same variable with another binding, and the binding it had.
    pub(crate) fn with_binding<C>(self, binding: C) -> (VarDecl<C>, B) {
        macro_rules! rebind {
            ($($field:ident),*) => {{
                let VarDecl { $($field,)* binding: old } = self;
                (VarDecl { $($field,)* binding }, old)
            }};
        }
        rebind!(
            name,
            value_reference,
            base_type,
            description,
            causality,
            variability,
            initial,
            start,
            unit,
            min,
            max,
            nominal,
            derivative_of,
            dependencies,
            declared_type,
            mismatched_accessor
        )
    }

    /// A Real variable.
    pub fn real(name: &'static str, value_reference: u32, binding: B) -> Self {
        Self::new(name, value_reference, BaseType::Real, binding)
    }

    /// A Boolean variable.
    pub fn boolean(name: &'static str, value_reference: u32, binding: B) -> Self {
        Self::new(name, value_reference, BaseType::Boolean, binding)
    }

    /// An Integer variable.
    pub fn integer(name: &'static str, value_reference: u32, binding: B) -> Self {
        Self::new(name, value_reference, BaseType::Integer, binding)
    }

    /// An Enumeration variable of the type `type_name` (declared in
    /// [`DeclarationSpec::enumerations`]). It is an Integer for the C API (same value
    /// references, `fmi2GetInteger`/`fmi2SetInteger`); the layer refuses values that are
    /// not items of the type.
    pub fn enumeration(name: &'static str, value_reference: u32, type_name: &'static str, binding: B) -> Self {
        let mut v = Self::new(name, value_reference, BaseType::Integer, binding);
        v.declared_type = Some(type_name);
        v
    }

    pub fn describe(mut self, text: &'static str) -> Self {
        self.description = text;
        self
    }
    /// The unit, in Modelica's syntax (its definition derived from the name, or listed in
    /// [`DeclarationSpec::units`]); `""` is no unit (for tables of variables some of which
    /// have none).
    pub fn unit(mut self, unit: &'static str) -> Self {
        self.unit = (!unit.is_empty()).then_some(unit);
        self
    }
    pub fn min(mut self, v: f64) -> Self {
        self.min = Some(v);
        self
    }
    pub fn max(mut self, v: f64) -> Self {
        self.max = Some(v);
        self
    }
    pub fn nominal(mut self, v: f64) -> Self {
        self.nominal = Some(v);
        self
    }

    /// `causality="parameter" variability="fixed" initial="exact"` with a start value.
    pub fn parameter(self, start: impl Into<Start>) -> Self {
        VarDecl { start: start.into(), ..self.kind(Causality::Parameter, Variability::Fixed, Some(Initial::Exact)) }
    }

    /// `causality="parameter" variability="tunable" initial="exact"`: settable between
    /// Co-Simulation steps and in Model Exchange event mode too.
    pub fn tunable_parameter(mut self, start: impl Into<Start>) -> Self {
        self = self.parameter(start);
        self.variability = Variability::Tunable;
        self
    }

    /// A discrete state (`causality="local" variability="discrete" initial="exact"`): it
    /// changes only at events; saved with the FMU state through the model's setter.
    pub fn discrete_state(self, start: impl Into<Start>) -> Self {
        VarDecl { start: start.into(), ..self.kind(Causality::Local, Variability::Discrete, Some(Initial::Exact)) }
    }

    /// A discrete output (`variability="discrete"`, `initial="calculated"`): held between
    /// events, computed by the model at events; saved with the FMU state through the
    /// model's setter (a held value is not a function of the current inputs).
    pub fn discrete_output(self, dependencies: impl Into<Dependencies>) -> Self {
        let dependencies = dependencies.into();
        VarDecl { dependencies, ..self.kind(Causality::Output, Variability::Discrete, Some(Initial::Calculated)) }
    }

    /// Sets the start value and `initial` (e.g. a discrete output with an exact start
    /// value: `.discrete_output(deps).start_value(Start::Real(0.0), Initial::Exact)`).
    pub fn start_value(mut self, start: impl Into<Start>, initial: Initial) -> Self {
        self.start = start.into();
        self.initial = Some(initial);
        self
    }

    /// `causality="input"` (continuous for Reals, discrete otherwise) with a start value.
    pub fn input(self, start: impl Into<Start>) -> Self {
        let variability =
            if self.base_type == BaseType::Real { Variability::Continuous } else { Variability::Discrete };
        VarDecl { start: start.into(), ..self.kind(Causality::Input, variability, None) }
    }

    /// A continuous state whose start value (`initial="exact"`) is the initial condition;
    /// `output` makes it a model output too.
    pub fn state(self, start: f64, output: bool) -> Self {
        let causality = if output { Causality::Output } else { Causality::Local };
        let mut state = VarDecl {
            start: Start::Real(start),
            ..self.kind(causality, Variability::Continuous, Some(Initial::Exact))
        };
        if output {
            state.dependencies = Dependencies::On(vec![state.value_reference]);
        }
        state
    }

    /// The derivative of the state `state` (its handle or Real value reference; local, calculated).
    pub fn derivative(self, state: impl RealReference, dependencies: impl Into<Dependencies>) -> Self {
        let (derivative_of, dependencies) = (Some(state.real_value_reference()), dependencies.into());
        VarDecl {
            derivative_of,
            dependencies,
            ..self.kind(Causality::Local, Variability::Continuous, Some(Initial::Calculated))
        }
    }

    /// `causality="calculatedParameter" variability="tunable" initial="calculated"`: a
    /// value the model computes from the parameters (recomputed when a tunable one changes).
    pub fn calculated_parameter(self) -> Self {
        self.kind(Causality::CalculatedParameter, Variability::Tunable, Some(Initial::Calculated))
    }

    /// A calculated continuous output.
    pub fn output(self, dependencies: impl Into<Dependencies>) -> Self {
        let dependencies = dependencies.into();
        VarDecl { dependencies, ..self.kind(Causality::Output, Variability::Continuous, Some(Initial::Calculated)) }
    }

    /// The variable with `causality`, `variability` and `initial`.
    fn kind(self, causality: Causality, variability: Variability, initial: Option<Initial>) -> Self {
        VarDecl { causality, variability, initial, ..self }
    }
}

/// Interfaces an FMU offers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Interfaces {
    pub model_exchange: bool,
    pub co_simulation: bool,
}

/// Optional capabilities, all opt-in: the XML flags follow them, and a call of a function
/// the model did not opt in to gets `fmi2Error` with a logged "not supported".
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Capabilities {
    /// `providesDirectionalDerivative`: the model implements [`crate::Model::directional_derivative`].
    pub directional_derivatives: bool,
    /// `canGetAndSetFMUstate`: `fmi2GetFMUstate`, `fmi2SetFMUstate`, `fmi2FreeFMUstate`.
    pub fmu_state: bool,
    /// `canSerializeFMUstate` (needs `fmu_state`).
    pub serialize_fmu_state: bool,
}

/// How the interval of a declared clock is known (FMI 3.0 `intervalVariability`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ClockInterval {
    /// `intervalVariability="constant"` with `intervalDecimal` = this interval \[s\]: the
    /// model's [`crate::Model::sample_period`] must answer it (checked when initialization
    /// ends).
    Constant(f64),
    /// `intervalVariability="fixed"` without `intervalDecimal`: the interval is the model's
    /// [`crate::Model::sample_period`] (from a fixed parameter), which the importer reads
    /// with `fmi3GetIntervalDecimal` in Initialization Mode.
    Fixed,
}

/// A periodic input clock of the FMI 3.0 description: the sample clock of a sampled model
/// ([`crate::sampled`]) as the importer's to activate. Its activations are the samples
/// `t_k = start + k interval` (shift 0); at each the importer calls `fmi3SetClock` in
/// Event Mode and the layer runs [`crate::Model::sample`] with the inputs of `t_k`. The
/// FMI 2.0 description has no clocks: that archive keeps sampling by time.
#[derive(Clone, Debug, PartialEq)]
pub struct ClockDecl {
    /// The name of the `<Clock>` variable.
    pub name: &'static str,
    pub description: &'static str,
    pub interval: ClockInterval,
    /// The variables the clock governs (its clocked variables: `clocks` attribute), discrete
    /// outputs that change only at its activations.
    pub governs: Vec<VarHandle>,
    /// `priority` (Scheduled Execution orders the model partitions by it; 0 is the highest).
    pub priority: u32,
}

/// Everything the layer needs to know about a model, and all that goes into the XML.
#[derive(Clone, Debug)]
pub struct DeclarationSpec<B> {
    pub model_name: &'static str,
    pub model_identifier: &'static str,
    pub description: &'static str,
    pub version: &'static str,
    pub interfaces: Interfaces,
    /// Optional capabilities (none by default).
    pub capabilities: Capabilities,
    /// Enumeration types (`<TypeDefinitions>`), referred to by [`VarDecl::enumeration`].
    pub enumerations: Vec<md::EnumerationType>,
    /// Unit definitions beyond those the layer derives from the variables' unit names
    /// ([`crate::units::derived_unit`]: `"N.m"`, `"m/s2"`, `"1/s"` ...); needed only for a
    /// unit with a prefix or a factor (`"mm"`, `"deg"`). A unit neither listed nor derivable
    /// is a build error naming the variable.
    pub units: Vec<md::Unit>,
    pub default_experiment: Option<md::DefaultExperiment>,
    pub variables: Vec<VarDecl<B>>,
    /// FMI 3.0 clocks (at most one: the sample clock of a sampled model); none by default.
    pub clocks: Vec<ClockDecl>,
}

impl<B> Default for DeclarationSpec<B> {
    /// Empty: no interfaces, no capabilities, no variables (fill in with `..Default::default()`).
    fn default() -> Self {
        DeclarationSpec {
            model_name: "",
            model_identifier: "",
            description: "",
            version: "",
            interfaces: Interfaces::default(),
            capabilities: Capabilities::default(),
            enumerations: Vec::new(),
            units: Vec::new(),
            default_experiment: None,
            variables: Vec::new(),
            clocks: Vec::new(),
        }
    }
}

/// An enumeration type with items `(name, value, description)`.
pub fn enumeration_type(name: &str, description: &str, items: &[(&str, i32, &str)]) -> md::EnumerationType {
    md::EnumerationType {
        name: name.to_string(),
        description: (!description.is_empty()).then(|| description.to_string()),
        items: items
            .iter()
            .map(|&(n, v, d)| md::EnumerationItem {
                name: n.to_string(),
                value: v,
                description: (!d.is_empty()).then(|| d.to_string()),
            })
            .collect(),
    }
}

/// A checked declaration with lookup tables, the generated description and its GUID.
#[derive(Debug)]
pub struct Declaration<B> {
    pub spec: DeclarationSpec<B>,
    lookup: HashMap<(BaseType, u32), usize>,
    /// `dense[base type][vr]` = row (or `NO_ROW`), for value references below
    /// `DENSE_VR_LIMIT`: the lookup of every get/set, without hashing.
    dense: [Vec<u32>; 3],
    /// Rows of the continuous states, in the order of the state vector (= Derivatives order).
    pub state_rows: Vec<usize>,
    /// Rows of the derivatives, same order.
    pub derivative_rows: Vec<usize>,
    /// Rows saved with the FMU state, in declaration order: parameters, inputs,
    /// continuous states and discrete variables (locals and outputs).
    pub saved_rows: Vec<usize>,
    /// Per row, the binding and what `fmi2Set*` checks, in one compact table (the per-value
    /// path of `fmi2Get*`/`fmi2Set*` reads this, not the whole [`VarDecl`]).
    hot: Vec<HotRow<B>>,
    description: md::ModelDescription,
    xml: String,
    description3: md::fmi3::ModelDescription,
    xml3: String,
    /// `fmi2_of_fmi3[vr]`: the FMI 3.0 type of value reference `vr` and its FMI 2.0 value
    /// reference (`NO_ROW` for `time`): the translation of every FMI 3.0 get/set, one load
    /// per value reference.
    fmi2_of_fmi3: Vec<(md::fmi3::ValueType, u32)>,
    /// Per row: governed by the declared clock (a clocked variable of FMI 3.0).
    clocked: Vec<bool>,
}

/// One row of [`Declaration`]'s compact table: the model's binding and the set checks.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HotRow<B> {
    pub binding: B,
    pub access: SetAccess,
}

/// The checks of `fmi2Set*` for one variable as tables: a value inside them is accepted
/// without running the full checks (which run, and give the reason, for anything else).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SetAccess {
    /// Bit `Machine::bit()` set: the variable may be set in that state.
    pub settable_in: u16,
    /// Not an Enumeration (whose values must also be items).
    pub plain: bool,
    /// The declared minimum, else the most negative finite f64.
    pub lowest: f64,
    /// The declared maximum, else the largest finite f64.
    pub highest: f64,
}

/// Value references below this are looked up in a table; larger ones (legal, but rare) in
/// the hash map.
const DENSE_VR_LIMIT: u32 = 1 << 16;
const NO_ROW: u32 = u32::MAX;

fn base_type_slot(base_type: BaseType) -> usize {
    match base_type {
        BaseType::Real => 0,
        BaseType::Integer => 1,
        BaseType::Boolean => 2,
    }
}

impl<B: Copy> Declaration<B> {
    /// Checks the spec (unique names and value references, derivatives refer to Real states,
    /// dependencies refer to declared Reals), builds the lookup tables and generates the
    /// description, then runs the modelDescription validator over it.
    pub fn new(spec: DeclarationSpec<B>) -> Result<Self, String> {
        let mut lookup = HashMap::new();
        let mut names = HashMap::new();
        for (row, v) in spec.variables.iter().enumerate() {
            if lookup.insert((v.base_type, v.value_reference), row).is_some() {
                return Err(format!(
                    "duplicate value reference {} ({:?}) at {}",
                    v.value_reference, v.base_type, v.name
                ));
            }
            if names.insert(v.name, row).is_some() {
                return Err(format!("duplicate variable name {}", v.name));
            }
            if v.mismatched_accessor {
                return Err(format!("{}: the accessor's value type is not a {:?}", v.name, v.base_type));
            }
        }
        let real_row = |vr: u32| lookup.get(&(BaseType::Real, vr)).copied();
        let mut state_rows = Vec::new();
        let mut derivative_rows = Vec::new();
        for (row, v) in spec.variables.iter().enumerate() {
            if let Some(state_vr) = v.derivative_of {
                let state = real_row(state_vr)
                    .ok_or_else(|| format!("{}: derivative of unknown Real vr {state_vr}", v.name))?;
                state_rows.push(state);
                derivative_rows.push(row);
            }
        }
        let index = |row: usize| row as u32 + 1;
        let deps = |v: &VarDecl<B>| -> Result<Option<Vec<u32>>, String> {
            match &v.dependencies {
                Dependencies::All => Ok(None),
                Dependencies::On(_) | Dependencies::Variables(_) => {
                    let on: Vec<u32> = match &v.dependencies {
                        Dependencies::Variables(handles) => {
                            if let Some(h) = handles.iter().find(|h| h.base_type != BaseType::Real) {
                                return Err(format!("{}: dependency on a {:?}, not a Real", v.name, h.base_type));
                            }
                            handles.iter().map(|h| h.value_reference).collect()
                        }
                        Dependencies::On(vrs) => vrs.clone(),
                        Dependencies::All => Vec::new(),
                    };
                    on.iter()
                        .map(|&vr| {
                            real_row(vr)
                                .map(index)
                                .ok_or_else(|| format!("{}: dependency on unknown Real vr {vr}", v.name))
                        })
                        .collect::<Result<Vec<_>, _>>()
                        .map(|mut d| {
                            d.sort_unstable();
                            d.dedup();
                            Some(d)
                        })
                }
            }
        };
        // One dependency declaration per unknown, over everything its value is computed from;
        // each list of the ModelStructure keeps the knowns of its own modes (FMI 2.0 section
        // 2.2.8): after initialization the inputs and the continuous states (a discrete
        // state is no known there), at initialization the inputs and the exact variables.
        let later_known = |index: &u32| {
            let row = *index as usize - 1;
            spec.variables[row].causality == Causality::Input || state_rows.contains(&row)
        };
        let later_deps = |v: &VarDecl<B>| -> Result<Option<Vec<u32>>, String> {
            Ok(deps(v)?.map(|mut d| {
                d.retain(later_known);
                d
            }))
        };
        let mut structure = md::ModelStructure::default();
        for (row, v) in spec.variables.iter().enumerate() {
            if v.causality == Causality::Output {
                structure.outputs.push(md::Unknown {
                    index: index(row),
                    dependencies: later_deps(v)?,
                    dependencies_kind: None,
                });
            }
        }
        for &row in &derivative_rows {
            let v = &spec.variables[row];
            structure.derivatives.push(md::Unknown {
                index: index(row),
                dependencies: later_deps(v)?,
                dependencies_kind: None,
            });
        }
        // InitialUnknowns: outputs with initial approx/calculated, calculated parameters, and
        // states/derivatives with initial approx/calculated (FMI 2.0 section 2.2.8), ascending.
        let is_state = |row: usize| state_rows.contains(&row);
        let is_derivative = |row: usize| derivative_rows.contains(&row);
        for (row, v) in spec.variables.iter().enumerate() {
            let approx_or_calc = matches!(v.initial, Some(Initial::Approx) | Some(Initial::Calculated));
            let listed = (v.causality == Causality::Output && approx_or_calc)
                || v.causality == Causality::CalculatedParameter
                || ((is_state(row) || is_derivative(row)) && approx_or_calc);
            if listed {
                // At initialization the knowns are the inputs and the variables with
                // initial="exact" (FMI 2.0 section 2.2.8): a declared dependency on a state
                // that is itself calculated (from parameters) is not one, and is covered by
                // every exact parameter, which is added.
                let init_known = |index: &u32| {
                    let k = &spec.variables[*index as usize - 1];
                    k.causality == Causality::Input || k.initial == Some(Initial::Exact)
                };
                let dependencies = deps(v)?.map(|mut d| {
                    d.retain(init_known);
                    d.extend(
                        spec.variables
                            .iter()
                            .enumerate()
                            .filter(|(_, p)| p.causality == Causality::Parameter && p.initial == Some(Initial::Exact))
                            .map(|(k, _)| index(k)),
                    );
                    d.sort_unstable();
                    d.dedup();
                    d
                });
                structure.initial_unknowns.push(md::Unknown {
                    index: index(row),
                    dependencies,
                    dependencies_kind: None,
                });
            }
        }

        let variables = spec
            .variables
            .iter()
            .map(|v| md::ScalarVariable {
                name: v.name.to_string(),
                value_reference: v.value_reference,
                description: (!v.description.is_empty()).then(|| v.description.to_string()),
                causality: v.causality,
                variability: v.variability,
                initial: v.initial,
                variable_type: match v.base_type {
                    BaseType::Real => md::VariableType::Real {
                        start: match v.start {
                            Start::Real(x) => Some(x),
                            _ => None,
                        },
                        unit: v.unit.map(str::to_string),
                        derivative: v.derivative_of.and_then(real_row).map(index),
                        min: v.min,
                        max: v.max,
                        nominal: v.nominal,
                    },
                    BaseType::Integer => {
                        let start = match v.start {
                            Start::Integer(x) => Some(x),
                            _ => None,
                        };
                        let (min, max) = (v.min.map(|x| x as i32), v.max.map(|x| x as i32));
                        match v.declared_type {
                            Some(t) => md::VariableType::Enumeration { declared_type: t.to_string(), start, min, max },
                            None => md::VariableType::Integer { start, min, max },
                        }
                    }
                    BaseType::Boolean => md::VariableType::Boolean {
                        start: match v.start {
                            Start::Boolean(x) => Some(x),
                            _ => None,
                        },
                    },
                },
            })
            .collect();

        let caps = spec.capabilities;
        if caps.serialize_fmu_state && !caps.fmu_state {
            return Err(format!("{}: serialize_fmu_state needs fmu_state", spec.model_name));
        }
        for v in &spec.variables {
            if let Some(t) = v.declared_type {
                if !spec.enumerations.iter().any(|e| e.name == t) {
                    return Err(format!("{}: enumeration type {t} is not declared", v.name));
                }
            }
        }
        // the capability flags both interfaces' elements have, and each one's own
        macro_rules! capabilities {
            ($interface:ident { $($own:ident),* }) => {
                md::$interface {
                    model_identifier: spec.model_identifier.to_string(),
                    can_not_use_memory_management_functions: true,
                    can_get_and_set_fmu_state: caps.fmu_state,
                    can_serialize_fmu_state: caps.serialize_fmu_state,
                    provides_directional_derivative: caps.directional_derivatives,
                    $($own: true,)*
                    ..Default::default()
                }
            };
        }
        let capabilities_cs = capabilities!(CoSimulation { can_handle_variable_communication_step_size });
        let capabilities_me = capabilities!(ModelExchange { completed_integrator_step_not_needed });
        let description = md::ModelDescription {
            fmi_version: "2.0".into(),
            model_name: spec.model_name.into(),
            guid: String::new(),
            description: Some(spec.description.into()),
            author: Some("nigel-fmi".into()),
            version: Some(spec.version.into()),
            copyright: None,
            license: Some("MIT OR Apache-2.0".into()),
            generation_tool: Some(format!("nigel-fmi fmi-export {}", env!("CARGO_PKG_VERSION"))),
            generation_date_and_time: None,
            variable_naming_convention: Some("structured".into()),
            number_of_event_indicators: 0,
            model_exchange: spec.interfaces.model_exchange.then_some(capabilities_me),
            co_simulation: spec.interfaces.co_simulation.then_some(capabilities_cs),
            unit_definitions: unit_definitions(&spec)?,
            type_definitions: spec.enumerations.clone(),
            log_categories: LOG_CATEGORIES
                .iter()
                .map(|(n, d)| md::LogCategory { name: n.to_string(), description: Some(d.to_string()) })
                .collect(),
            default_experiment: spec.default_experiment.clone(),
            model_variables: variables,
            model_structure: structure,
        }
        .with_content_guid();
        valid(&spec, "FMI 2.0", &description.validate())?;
        let xml = description.to_xml();
        let clocked_rows = clocked_rows(&spec, &lookup)?;
        let mut description3 = fmi3_description(&description, spec.capabilities);
        add_clocks(&mut description3, &spec.clocks, &clocked_rows);
        valid(&spec, "FMI 3.0", &description3.validate())?;
        let xml3 = description3.to_xml();
        let saved_rows = (0..spec.variables.len())
            .filter(|&row| {
                let v = &spec.variables[row];
                matches!(v.causality, Causality::Parameter | Causality::Input)
                    || state_rows.contains(&row)
                    || (v.variability == Variability::Discrete
                        && matches!(v.causality, Causality::Local | Causality::Output))
            })
            .collect();
        let mut dense: [Vec<u32>; 3] = Default::default();
        for (&(base_type, vr), &row) in &lookup {
            if vr < DENSE_VR_LIMIT {
                let table = &mut dense[base_type_slot(base_type)];
                if table.len() <= vr as usize {
                    table.resize(vr as usize + 1, NO_ROW);
                }
                table[vr as usize] = row as u32;
            }
        }
        let hot = spec
            .variables
            .iter()
            .map(|v| HotRow {
                binding: v.binding,
                access: SetAccess {
                    settable_in: Machine::ALL
                        .into_iter()
                        .filter(|&m| settable_in(v.name, v.causality, v.variability, v.initial, m).is_ok())
                        .fold(0, |mask, m| mask | m.bit()),
                    plain: v.declared_type.is_none(),
                    lowest: v.min.unwrap_or(f64::MIN),
                    highest: v.max.unwrap_or(f64::MAX),
                },
            })
            .collect();
        let fmi2_of_fmi3 = description3
            .model_variables
            .iter()
            .enumerate()
            .map(|(vr, v)| {
                // as `variable3` and `row3`: value reference vr is variable vr, row vr - 1
                let row = vr.checked_sub(1).filter(|&r| r < spec.variables.len());
                (v.value_type, row.map_or(NO_ROW, |r| spec.variables[r].value_reference))
            })
            .collect();
        Ok(Declaration {
            fmi2_of_fmi3,
            clocked: (0..spec.variables.len()).map(|row| clocked_rows.contains(&row)).collect(),
            spec,
            lookup,
            dense,
            state_rows,
            derivative_rows,
            saved_rows,
            hot,
            description,
            xml,
            description3,
            xml3,
        })
    }
}

impl<B> Declaration<B> {
    /// Row of the variable with this base type and value reference.
    #[inline]
    pub fn row(&self, base_type: BaseType, vr: u32) -> Option<usize> {
        if vr < DENSE_VR_LIMIT {
            match self.dense[base_type_slot(base_type)].get(vr as usize) {
                Some(&row) if row != NO_ROW => Some(row as usize),
                _ => None,
            }
        } else {
            self.lookup.get(&(base_type, vr)).copied()
        }
    }

    #[inline]
    pub(crate) fn hot(&self, row: usize) -> &HotRow<B> {
        &self.hot[row]
    }

    #[inline]
    pub fn variable(&self, row: usize) -> &VarDecl<B> {
        &self.spec.variables[row]
    }

    /// The generated description (with its content GUID).
    pub fn model_description(&self) -> &md::ModelDescription {
        &self.description
    }

    /// The generated `modelDescription.xml`.
    pub fn xml(&self) -> &str {
        &self.xml
    }

    /// The generated FMI 3.0 description: the same variables (names, causalities,
    /// variabilities, initial, units, ranges, starts, descriptions) as typed elements,
    /// `time` at value reference 0 and declaration row `r` at value reference `r + 1`,
    /// the FMI 2.0 GUID as `instantiationToken`.
    pub fn model_description3(&self) -> &md::fmi3::ModelDescription {
        &self.description3
    }

    /// The generated FMI 3.0 `modelDescription.xml`.
    pub fn xml3(&self) -> &str {
        &self.xml3
    }

    /// The FMI 3.0 value reference of declaration row `row` (`time` is 0).
    #[inline]
    pub fn value_reference3(row: usize) -> u32 {
        row as u32 + 1
    }

    /// The declaration row of FMI 3.0 value reference `vr` (`None` for `time`, 0, and for
    /// value references past the variables).
    #[inline]
    pub fn row3(&self, vr: u32) -> Option<usize> {
        let row = (vr as usize).checked_sub(1)?;
        (row < self.spec.variables.len()).then_some(row)
    }

    /// The FMI 2.0 value reference of the FMI 3.0 value reference `vr` if that is a variable
    /// of type `accessed` other than `time`.
    #[inline]
    pub fn fmi2_of_fmi3(&self, vr: u32, accessed: md::fmi3::ValueType) -> Option<u32> {
        match self.fmi2_of_fmi3.get(vr as usize) {
            Some(&(t, vr2)) if t == accessed && vr2 != NO_ROW => Some(vr2),
            _ => None,
        }
    }

    /// The FMI 3.0 variable of value reference `vr` (`time` for 0).
    #[inline]
    pub fn variable3(&self, vr: u32) -> Option<&md::fmi3::Variable> {
        self.description3.model_variables.get(vr as usize)
    }

    /// The declared clock (at most one) and its FMI 3.0 value reference (after the
    /// variables: appending it keeps theirs).
    pub fn clock(&self) -> Option<(&ClockDecl, u32)> {
        self.spec.clocks.first().map(|c| (c, self.spec.variables.len() as u32 + 1))
    }

    /// Whether row `row` is a clocked variable (governed by the declared clock).
    #[inline]
    pub fn is_clocked(&self, row: usize) -> bool {
        self.clocked.get(row).copied().unwrap_or(false)
    }

    pub fn guid(&self) -> &str {
        &self.description.guid
    }

    pub fn number_of_states(&self) -> usize {
        self.state_rows.len()
    }

    /// The value reference of the variable `name` (its base type is the declaration's).
    pub fn value_reference(&self, name: &str) -> Option<u32> {
        self.spec.variables.iter().find(|v| v.name == name).map(|v| v.value_reference)
    }

    /// `name fmi2_value_reference fmi3_value_reference` per line, in declaration order:
    /// the table each FMU pins in a checked-in file, so that a change of a value reference
    /// of either generation shows in review.
    pub fn value_reference_table(&self) -> String {
        self.spec
            .variables
            .iter()
            .enumerate()
            .map(|(row, v)| format!("{} {} {}\n", v.name, v.value_reference, Self::value_reference3(row)))
            // a clock has no FMI 2.0 value reference
            .chain(self.clock().map(|(c, vr)| format!("{} - {vr}\n", c.name)))
            .collect()
    }

    /// Checks [`Declaration::value_reference_table`] against the checked-in file `path`:
    /// `Err` with both tables when they differ. With `UPDATE_VALUE_REFERENCES=1` in the
    /// environment it writes the file instead (then review its diff: a changed value
    /// reference breaks every importer's saved setup that refers to it by number).
    pub fn check_pinned_value_references(&self, path: &std::path::Path) -> Result<(), String> {
        let table = self.value_reference_table();
        if std::env::var_os("UPDATE_VALUE_REFERENCES").is_some_and(|v| v == "1") {
            return std::fs::write(path, &table).map_err(|e| format!("{}: {e}", path.display()));
        }
        let pinned = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        if pinned == table {
            return Ok(());
        }
        let changed: Vec<String> = table
            .lines()
            .filter(|line| !pinned.lines().any(|p| p == *line))
            .map(|line| format!("  now {line}"))
            .chain(pinned.lines().filter(|p| !table.lines().any(|l| l == *p)).map(|p| format!("  was {p}")))
            .collect();
        Err(format!(
            "the value references of {} differ from {} (UPDATE_VALUE_REFERENCES=1 rewrites it):\n{}",
            self.spec.model_name,
            path.display(),
            changed.join("\n")
        ))
    }

    /// Whether `value` fits variable `row` of declaration `d` (finite, min/max, enumeration
    /// items); the reason when not.
    pub(crate) fn check_value(&self, row: usize, value: f64) -> Result<(), String> {
        let v = self.variable(row);
        if !value.is_finite() {
            return Err(format!("{} = {value} refused: not a finite number", v.name));
        }
        if let Some(e) = self.enumeration_of(row) {
            if e.item(value as i32).is_none() {
                let items: Vec<String> = e.items.iter().map(|i| format!("{} = {}", i.name, i.value)).collect();
                return Err(format!("{} = {value} refused: not an item of {} ({})", v.name, e.name, items.join(", ")));
            }
        }
        if let Some(min) = v.min.filter(|&m| value < m) {
            return Err(format!("{} = {value} refused: below its minimum {min}", v.name));
        }
        if let Some(max) = v.max.filter(|&m| value > m) {
            return Err(format!("{} = {value} refused: above its maximum {max}", v.name));
        }
        Ok(())
    }

    /// The enumeration type of variable `row`, if it is an Enumeration.
    pub fn enumeration_of(&self, row: usize) -> Option<&md::EnumerationType> {
        let t = self.variable(row).declared_type?;
        self.spec.enumerations.iter().find(|e| e.name == t)
    }
}

/// The FMI 3.0 description of the same variables as the FMI 2.0 `description` (which the
/// declaration generated): FMI 2.0's 1-based variable index `i` is FMI 3.0 value
/// reference `i` (row `i - 1`), so the ModelStructure carries over entry by entry; `time`
/// is added at value reference 0. Adjoint derivatives come with directional ones (the
/// layer computes `J^T w` from the columns of `J`).
fn fmi3_description(d2: &md::ModelDescription, caps: Capabilities) -> md::fmi3::ModelDescription {
    use md::fmi3 as f3;
    let common = |model_identifier: &str| f3::InterfaceCommon {
        model_identifier: model_identifier.to_string(),
        can_get_and_set_fmu_state: caps.fmu_state,
        can_serialize_fmu_state: caps.serialize_fmu_state,
        provides_directional_derivatives: caps.directional_derivatives,
        provides_adjoint_derivatives: caps.directional_derivatives,
        ..Default::default()
    };
    let mut time =
        f3::Variable::new("time", 0, f3::ValueType::Float64, f3::Causality::Independent, Variability::Continuous);
    time.description = Some("Simulation time".into());
    let mut variables = vec![time];
    for (row, v) in d2.model_variables.iter().enumerate() {
        let vr = row as u32 + 1;
        let (value_type, start, min, max) = match &v.variable_type {
            md::VariableType::Real { start, min, max, .. } => (
                f3::ValueType::Float64,
                start.map(|x| f3::Values::Float(vec![x])),
                min.map(f3::Bound::Float),
                max.map(f3::Bound::Float),
            ),
            md::VariableType::Integer { start, min, max } => (
                f3::ValueType::Int32,
                start.map(|x| f3::Values::Int(vec![x as i128])),
                min.map(|x| f3::Bound::Int(x as i128)),
                max.map(|x| f3::Bound::Int(x as i128)),
            ),
            md::VariableType::Enumeration { start, min, max, .. } => (
                f3::ValueType::Enumeration,
                start.map(|x| f3::Values::Int(vec![x as i128])),
                min.map(|x| f3::Bound::Int(x as i128)),
                max.map(|x| f3::Bound::Int(x as i128)),
            ),
            md::VariableType::Boolean { start } => {
                (f3::ValueType::Boolean, start.map(|x| f3::Values::Boolean(vec![x])), None, None)
            }
            md::VariableType::String { start } => {
                (f3::ValueType::String, start.clone().map(|x| f3::Values::String(vec![x])), None, None)
            }
        };
        let mut w =
            f3::Variable::new(v.name.clone(), vr, value_type, f3::Causality::from_fmi2(v.causality), v.variability);
        w.description = v.description.clone();
        w.initial = v.initial;
        w.start = start;
        w.min = min;
        w.max = max;
        match &v.variable_type {
            md::VariableType::Real { unit, derivative, nominal, .. } => {
                w.unit = unit.clone();
                w.nominal = *nominal;
                w.derivative = *derivative;
            }
            md::VariableType::Enumeration { declared_type, .. } => w.declared_type = Some(declared_type.clone()),
            _ => {}
        }
        variables.push(w);
    }
    let unknowns = |list: &[md::Unknown]| -> Vec<f3::Unknown> {
        list.iter()
            .map(|u| f3::Unknown {
                value_reference: u.index,
                dependencies: u.dependencies.clone(),
                dependencies_kind: u.dependencies_kind.clone(),
            })
            .collect()
    };
    let s2 = &d2.model_structure;
    f3::ModelDescription {
        fmi_version: "3.0".into(),
        model_name: d2.model_name.clone(),
        instantiation_token: d2.guid.clone(),
        description: d2.description.clone(),
        author: d2.author.clone(),
        version: d2.version.clone(),
        copyright: d2.copyright.clone(),
        license: d2.license.clone(),
        generation_tool: d2.generation_tool.clone(),
        generation_date_and_time: None,
        variable_naming_convention: d2.variable_naming_convention.clone(),
        model_exchange: d2
            .model_exchange
            .as_ref()
            .map(|me| f3::ModelExchange { common: common(&me.model_identifier), ..Default::default() }),
        co_simulation: d2.co_simulation.as_ref().map(|cs| f3::CoSimulation {
            common: common(&cs.model_identifier),
            can_handle_variable_communication_step_size: true,
            ..Default::default()
        }),
        scheduled_execution: None,
        unit_definitions: d2.unit_definitions.clone(),
        type_definitions: d2
            .type_definitions
            .iter()
            .map(|t| f3::TypeDefinition {
                name: t.name.clone(),
                description: t.description.clone(),
                kind: f3::TypeKind::Enumeration {
                    quantity: None,
                    items: t
                        .items
                        .iter()
                        .map(|i| f3::EnumerationItem {
                            name: i.name.clone(),
                            value: i.value as i64,
                            description: i.description.clone(),
                        })
                        .collect(),
                },
            })
            .collect(),
        log_categories: d2
            .log_categories
            .iter()
            .map(|c| md::LogCategory {
                name: c.name.clone(),
                description: c.description.as_ref().map(|d| d.replace("fmi2", "fmi3")),
            })
            .collect(),
        default_experiment: d2.default_experiment.clone(),
        model_variables: variables,
        model_structure: f3::ModelStructure {
            outputs: unknowns(&s2.outputs),
            continuous_state_derivatives: unknowns(&s2.derivatives),
            clocked_states: Vec::new(),
            initial_unknowns: unknowns(&s2.initial_unknowns),
            // the layer's models declare no event indicators (state events)
            event_indicators: Vec::new(),
        },
    }
}

/// The rows each declared clock governs, after checking the clocks: at most one (the sample
/// clock), a name of its own, a finite positive constant interval, and discrete outputs as
/// its clocked variables (a clocked local state would need FMI 3.0's `previous`).
fn clocked_rows<B>(spec: &DeclarationSpec<B>, lookup: &HashMap<(BaseType, u32), usize>) -> Result<Vec<usize>, String> {
    let Some(clock) = spec.clocks.first() else { return Ok(Vec::new()) };
    if spec.clocks.len() > 1 {
        return Err(format!(
            "{}: {} clocks declared; the layer runs one, the sample clock of a sampled model",
            spec.model_name,
            spec.clocks.len()
        ));
    }
    if spec.variables.iter().any(|v| v.name == clock.name) || clock.name == "time" {
        return Err(format!("clock {}: a variable has that name", clock.name));
    }
    if let ClockInterval::Constant(interval) = clock.interval {
        if !(interval > 0.0 && interval.is_finite()) {
            return Err(format!("clock {}: the constant interval {interval} s is not finite and > 0", clock.name));
        }
    }
    let mut rows = Vec::new();
    for h in &clock.governs {
        let row = *lookup.get(&(h.base_type, h.value_reference)).ok_or_else(|| {
            format!("clock {}: governs an unknown {:?} vr {}", clock.name, h.base_type, h.value_reference)
        })?;
        let v = &spec.variables[row];
        if v.causality != Causality::Output || v.variability != Variability::Discrete {
            return Err(format!(
                "clock {}: governs {}, which is not a discrete output (only those can be its clocked variables)",
                clock.name, v.name
            ));
        }
        rows.push(row);
    }
    rows.sort_unstable();
    rows.dedup();
    Ok(rows)
}

/// Adds the declared clock to the FMI 3.0 description: the `<Clock>` variable after the
/// others (an input clock, periodic, its interval constant or fixed), the `clocks`
/// attribute of its clocked variables, Event Mode for Co-Simulation (FMI 3.0 requires it of
/// an FMU with clocks) and `<ScheduledExecution>` (the clock's model partition).
fn add_clocks(d3: &mut md::fmi3::ModelDescription, clocks: &[ClockDecl], clocked_rows: &[usize]) {
    use md::fmi3 as f3;
    let Some(clock) = clocks.first() else { return };
    let vr = d3.model_variables.len() as u32;
    let mut c = f3::Variable::new(clock.name, vr, f3::ValueType::Clock, f3::Causality::Input, Variability::Discrete);
    c.description = (!clock.description.is_empty()).then(|| clock.description.to_string());
    c.clock = Some(f3::ClockAttributes {
        priority: Some(clock.priority),
        interval_variability: Some(
            match clock.interval {
                ClockInterval::Constant(_) => "constant",
                ClockInterval::Fixed => "fixed",
            }
            .into(),
        ),
        interval_decimal: match clock.interval {
            ClockInterval::Constant(t) => Some(t),
            ClockInterval::Fixed => None,
        },
        ..Default::default()
    });
    for &row in clocked_rows {
        d3.model_variables[row + 1].clocks = vec![vr];
    }
    // a clocked variable gets its value at its clock's activations: no InitialUnknown (FMI
    // 3.0 leaves it optional; fmpy's validation expects it left out)
    let clocked_vrs: Vec<u32> = clocked_rows.iter().map(|&row| row as u32 + 1).collect();
    d3.model_structure.initial_unknowns.retain(|u| !clocked_vrs.contains(&u.value_reference));
    d3.model_variables.push(c);
    // Scheduled Execution: the clock's model partition, with the capabilities of the other
    // interfaces (one library, one instance type)
    let common = d3.co_simulation.as_ref().map(|cs| &cs.common).or(d3.model_exchange.as_ref().map(|me| &me.common));
    d3.scheduled_execution = common.map(|c| f3::ScheduledExecution { common: c.clone() });
    if let Some(cs) = d3.co_simulation.as_mut() {
        cs.has_event_mode = true;
    }
}

/// A variable name built at run time (`format!("delta_{wheel}")`) for a declaration, which
/// holds `&'static str`: declarations are built once per process (in a `OnceLock`), so the
/// few hundred bytes are kept for its life on purpose.
pub fn declared_name(name: String) -> &'static str {
    Box::leak(name.into_boxed_str())
}

/// Refuses a declaration whose `generation` description has `problems` (listed).
fn valid<B>(spec: &DeclarationSpec<B>, generation: &str, problems: &[impl std::fmt::Display]) -> Result<(), String> {
    if problems.is_empty() {
        return Ok(());
    }
    let list: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
    Err(format!("the declaration of {} is not a valid {generation} description: {}", spec.model_name, list.join("; ")))
}

/// The `<UnitDefinitions>`: the units the spec lists, then those the variables use in the
/// order of first use, derived from their names.
fn unit_definitions<B>(spec: &DeclarationSpec<B>) -> Result<Vec<md::Unit>, String> {
    let mut units = spec.units.clone();
    for v in &spec.variables {
        if let Some(unit) = v.unit {
            if !units.iter().any(|u| u.name == unit) {
                units.push(crate::units::derived_unit(unit).map_err(|e| format!("{}: {e}", v.name))?);
            }
        }
    }
    Ok(units)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::si_unit;

    fn spec(variables: Vec<VarDecl<u8>>) -> DeclarationSpec<u8> {
        DeclarationSpec {
            model_name: "toy",
            model_identifier: "toy",
            description: "a toy",
            version: "0",
            interfaces: Interfaces { model_exchange: true, co_simulation: true },
            units: vec![si_unit("m", 0, 1, 0, 0), si_unit("m/s", 0, 1, -1, 0)],
            variables,
            ..Default::default()
        }
    }

    fn toy() -> Vec<VarDecl<u8>> {
        vec![
            VarDecl::real("u", 5, 0).input(Start::Real(0.0)),
            VarDecl::real("x", 1, 1).state(0.0, true).unit("m"),
            VarDecl::real("der(x)", 2, 2).derivative(1, Dependencies::On(vec![5])).unit("m/s"),
            VarDecl::real("k", 3, 3).parameter(Start::Real(2.0)),
            VarDecl::boolean("on", 1, 4).parameter(Start::Boolean(true)),
        ]
    }

    #[test]
    fn value_references_are_found_per_base_type_below_and_above_the_table_limit() {
        let mut v = toy();
        v.push(VarDecl::real("far", DENSE_VR_LIMIT + 7, 5).parameter(Start::Real(1.0)));
        v.push(VarDecl::integer("n", 5, 6).parameter(Start::Integer(3)));
        let d = Declaration::new(spec(v)).unwrap();
        for (row, var) in d.spec.variables.iter().enumerate() {
            assert_eq!(d.row(var.base_type, var.value_reference), Some(row), "{}", var.name);
        }
        assert_eq!(d.row(BaseType::Real, 4), None); // a gap in the table
        assert_eq!(d.row(BaseType::Real, 6), None); // past the table's end
        assert_eq!(d.row(BaseType::Boolean, 5), None); // Real 5 and Integer 5 exist, Boolean 5 does not
        assert_eq!(d.row(BaseType::Real, DENSE_VR_LIMIT + 8), None);
        assert_eq!(d.row(BaseType::Integer, u32::MAX), None);
    }

    /// The precomputed set checks accept a value only where the full checks do (which
    /// give the reason for everything else), and the settable mask is the full rule in
    /// every instance state: the fast path of `fmi2Set*` changes no outcome.
    #[test]
    fn precomputed_set_checks_agree_with_the_full_checks() {
        let mut v = toy();
        v.push(VarDecl::real("bounded", 7, 5).tunable_parameter(Start::Real(0.5)).min(-1.0).max(2.0));
        v.push(VarDecl::real("above", 8, 6).input(Start::Real(0.0)).min(0.0));
        v.push(VarDecl::integer("n", 5, 7).parameter(Start::Integer(3)).min(0.0));
        v.push(VarDecl::enumeration("mode", 6, "Mode", 8).parameter(Start::Integer(1)));
        v.push(VarDecl::real("y", 9, 9).output(Dependencies::On(vec![5])));
        let mut s = spec(v);
        s.enumerations = vec![enumeration_type("Mode", "", &[("a", 1, ""), ("b", 2, ""), ("c", 4, "")])];
        let d = Declaration::new(s).unwrap();
        let tiny = f64::MIN_POSITIVE;
        let values = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
            0.0,
            -0.0,
            1.0,
            2.0,
            3.0,
            4.0,
            -1.0,
            f64::from_bits(2.0f64.to_bits() + 1),
            f64::from_bits((-1.0f64).to_bits() + 1),
            -tiny,
            tiny,
            0.5,
            1e300,
            -1e300,
        ];
        let mut fast_accepted = 0;
        for row in 0..d.spec.variables.len() {
            let hot = d.hot(row);
            assert_eq!(hot.binding, d.variable(row).binding);
            for m in Machine::ALL {
                let v = d.variable(row);
                let full = settable_in(v.name, v.causality, v.variability, v.initial, m).is_ok();
                assert_eq!(hot.access.settable_in & m.bit() != 0, full, "{} in {m:?}", d.variable(row).name);
            }
            for x in values {
                let a = hot.access;
                if a.plain && x >= a.lowest && x <= a.highest {
                    fast_accepted += 1;
                    assert_eq!(d.check_value(row, x), Ok(()), "{} = {x}", d.variable(row).name);
                }
            }
            // what the full checks refuse, the fast path refuses too (it then runs them)
            for x in values.into_iter().filter(|&x| d.check_value(row, x).is_err()) {
                let a = hot.access;
                assert!(!(a.plain && x >= a.lowest && x <= a.highest), "{} = {x}", d.variable(row).name);
            }
        }
        assert!(fast_accepted > 50, "{fast_accepted}");
        // the enumeration never takes the fast path: its items are checked in full
        assert!(!d.hot(d.row(BaseType::Integer, 6).unwrap()).access.plain);
        assert!(d.check_value(d.row(BaseType::Integer, 6).unwrap(), 3.0).is_err());
    }

    #[test]
    fn structure_is_derived_with_one_based_indices() {
        let d = Declaration::new(spec(toy())).unwrap();
        let md = d.model_description();
        assert_eq!(md.model_structure.outputs[0].index, 2);
        assert_eq!(md.model_structure.outputs[0].dependencies, Some(vec![2]));
        assert_eq!(md.model_structure.derivatives[0].index, 3);
        assert_eq!(md.model_structure.derivatives[0].dependencies, Some(vec![1]));
        // der(x) at initialization: the input and the exact parameters k and on
        assert_eq!(md.model_structure.initial_unknowns[0].dependencies, Some(vec![1, 4, 5]));
        assert_eq!(d.state_rows, vec![1]);
        assert_eq!(d.row(BaseType::Boolean, 1), Some(4));
        assert_eq!(d.row(BaseType::Real, 4), None);
        assert_eq!(md.guid, md.content_guid());
        assert!(d.xml().contains(&md.guid));
    }

    /// The FMI 3.0 description of the toy: `time` at 0, row r at r + 1 with the element of
    /// its base type, the FMI 2.0 GUID as token, the ModelStructure by value reference
    /// (FMI 2.0 index i = FMI 3.0 value reference i), the same names and causalities.
    #[test]
    fn the_fmi3_description_has_the_same_variables_by_value_reference() {
        use md::fmi3::{Causality as C3, ValueType};
        let d = Declaration::new(spec(toy())).unwrap();
        let d2 = d.model_description();
        let d3 = d.model_description3();
        assert_eq!(d3.instantiation_token, d2.guid);
        assert_eq!(d3.model_variables[0].name, "time");
        assert_eq!(d3.model_variables[0].causality, C3::Independent);
        assert_eq!(d3.model_variables[0].value_reference, 0);
        let types: Vec<_> =
            d3.model_variables.iter().map(|v| (v.name.as_str(), v.value_reference, v.value_type)).collect();
        assert_eq!(
            types,
            [
                ("time", 0, ValueType::Float64),
                ("u", 1, ValueType::Float64),
                ("x", 2, ValueType::Float64),
                ("der(x)", 3, ValueType::Float64),
                ("k", 4, ValueType::Float64),
                ("on", 5, ValueType::Boolean),
            ]
        );
        for (v2, v3) in d2.model_variables.iter().zip(&d3.model_variables[1..]) {
            assert_eq!(
                (v3.causality.to_fmi2(), v3.variability, v3.initial),
                (Some(v2.causality), v2.variability, v2.initial)
            );
        }
        assert_eq!(d3.variable(3).unwrap().derivative, Some(2));
        assert_eq!(d3.states(), vec![2]);
        assert_eq!(d3.model_structure.outputs[0].value_reference, 2);
        assert_eq!(d3.model_structure.outputs[0].dependencies, Some(vec![2]));
        assert_eq!(d3.model_structure.continuous_state_derivatives[0].dependencies, Some(vec![1]));
        assert_eq!(d3.model_structure.initial_unknowns[0].dependencies, Some(vec![1, 4, 5]));
        assert_eq!((d.row3(0), d.row3(1), d.row3(5), d.row3(6)), (None, Some(0), Some(4), None));
        assert!(
            d.xml3().contains(r#"<ContinuousStateDerivative valueReference="3" dependencies="1"/>"#),
            "{}",
            d.xml3()
        );
    }

    #[test]
    fn bad_declarations_are_refused_with_the_reason() {
        let mut v = toy();
        v[3].value_reference = 1; // clashes with x
        assert!(Declaration::new(spec(v)).unwrap_err().contains("duplicate value reference 1"));
        let mut v = toy();
        v[2].derivative_of = Some(42);
        assert!(Declaration::new(spec(v)).unwrap_err().contains("derivative of unknown Real vr 42"));
        let mut v = toy();
        v[0] = VarDecl::real("u", 5, 0).input(Start::None);
        assert!(Declaration::new(spec(v)).unwrap_err().contains("not a valid FMI 2.0 description"));
        let mut v = toy();
        v[1].unit = Some("furlong");
        assert!(Declaration::new(spec(v)).unwrap_err().contains("furlong"));
    }
}

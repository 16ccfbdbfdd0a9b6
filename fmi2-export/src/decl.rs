//! The Rust declaration of a model's variables: the one source of truth from which the
//! layer dispatches value references AND generates `modelDescription.xml`.

use std::collections::HashMap;

use model_description as md;
pub use model_description::{Causality, Initial, Variability};

/// Base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BaseType {
    Real,
    Integer,
    Boolean,
}

/// Start value (its variant also fixes the base type).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    None,
    Real(f64),
    Integer(i32),
    Boolean(bool),
}

/// What an Unknown of the ModelStructure depends on.
#[derive(Clone, Debug, PartialEq)]
pub enum Dependencies {
    /// Attribute absent: depends on all knowns.
    All,
    /// Value references (of Reals) of the knowns it depends on; empty: none.
    On(Vec<u32>),
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
            binding,
        }
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
    pub fn unit(mut self, unit: &'static str) -> Self {
        self.unit = Some(unit);
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
    pub fn parameter(mut self, start: Start) -> Self {
        self.causality = Causality::Parameter;
        self.variability = Variability::Fixed;
        self.initial = Some(Initial::Exact);
        self.start = start;
        self
    }

    /// `causality="parameter" variability="tunable" initial="exact"`: settable between
    /// Co-Simulation steps and in Model Exchange event mode too.
    pub fn tunable_parameter(mut self, start: Start) -> Self {
        self = self.parameter(start);
        self.variability = Variability::Tunable;
        self
    }

    /// A discrete state (`causality="local" variability="discrete" initial="exact"`): it
    /// changes only at events; saved with the FMU state through the model's setter.
    pub fn discrete_state(mut self, start: Start) -> Self {
        self.causality = Causality::Local;
        self.variability = Variability::Discrete;
        self.initial = Some(Initial::Exact);
        self.start = start;
        self
    }

    /// A discrete output (`variability="discrete"`, `initial="calculated"`): held between
    /// events, computed by the model at events; saved with the FMU state through the
    /// model's setter (a held value is not a function of the current inputs).
    pub fn discrete_output(mut self, dependencies: Dependencies) -> Self {
        self.causality = Causality::Output;
        self.variability = Variability::Discrete;
        self.initial = Some(Initial::Calculated);
        self.dependencies = dependencies;
        self
    }

    /// Sets the start value and `initial` (e.g. a discrete output with an exact start
    /// value: `.discrete_output(deps).start_value(Start::Real(0.0), Initial::Exact)`).
    pub fn start_value(mut self, start: Start, initial: Initial) -> Self {
        self.start = start;
        self.initial = Some(initial);
        self
    }

    /// `causality="input"` (continuous for Reals, discrete otherwise) with a start value.
    pub fn input(mut self, start: Start) -> Self {
        self.causality = Causality::Input;
        self.variability =
            if self.base_type == BaseType::Real { Variability::Continuous } else { Variability::Discrete };
        self.initial = None;
        self.start = start;
        self
    }

    /// A continuous state whose start value (`initial="exact"`) is the initial condition;
    /// `output` makes it a model output too.
    pub fn state(mut self, start: f64, output: bool) -> Self {
        self.causality = if output { Causality::Output } else { Causality::Local };
        self.variability = Variability::Continuous;
        self.initial = Some(Initial::Exact);
        self.start = Start::Real(start);
        if output {
            self.dependencies = Dependencies::On(vec![self.value_reference]);
        }
        self
    }

    /// The derivative of the state with value reference `state_vr` (local, calculated).
    pub fn derivative(mut self, state_vr: u32, dependencies: Dependencies) -> Self {
        self.causality = Causality::Local;
        self.variability = Variability::Continuous;
        self.initial = Some(Initial::Calculated);
        self.derivative_of = Some(state_vr);
        self.dependencies = dependencies;
        self
    }

    /// `causality="calculatedParameter" variability="tunable" initial="calculated"`: a
    /// value the model computes from the parameters (recomputed when a tunable one changes).
    pub fn calculated_parameter(mut self) -> Self {
        self.causality = Causality::CalculatedParameter;
        self.variability = Variability::Tunable;
        self.initial = Some(Initial::Calculated);
        self
    }

    /// A calculated continuous output.
    pub fn output(mut self, dependencies: Dependencies) -> Self {
        self.causality = Causality::Output;
        self.variability = Variability::Continuous;
        self.initial = Some(Initial::Calculated);
        self.dependencies = dependencies;
        self
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
    /// Units used by the variables (`(name, base unit)`); undeclared units are a build error.
    pub units: Vec<md::Unit>,
    pub default_experiment: Option<md::DefaultExperiment>,
    pub variables: Vec<VarDecl<B>>,
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

/// Log categories every FMU of ours offers.
pub const LOG_CATEGORIES: [(&str, &str); 4] = [
    ("logStatusError", "Errors (always logged)"),
    ("logStatusWarning", "Warnings"),
    ("logEvents", "Mode changes and events"),
    ("logCalls", "Every fmi2 call"),
];

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
                Dependencies::On(vrs) => vrs
                    .iter()
                    .map(|&vr| {
                        real_row(vr).map(index).ok_or_else(|| format!("{}: dependency on unknown Real vr {vr}", v.name))
                    })
                    .collect::<Result<Vec<_>, _>>()
                    .map(|mut d| {
                        d.sort_unstable();
                        Some(d)
                    }),
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
        let capabilities_cs = md::CoSimulation {
            model_identifier: spec.model_identifier.to_string(),
            can_handle_variable_communication_step_size: true,
            can_not_use_memory_management_functions: true,
            can_get_and_set_fmu_state: caps.fmu_state,
            can_serialize_fmu_state: caps.serialize_fmu_state,
            provides_directional_derivative: caps.directional_derivatives,
            ..Default::default()
        };
        let capabilities_me = md::ModelExchange {
            model_identifier: spec.model_identifier.to_string(),
            completed_integrator_step_not_needed: true,
            can_not_use_memory_management_functions: true,
            can_get_and_set_fmu_state: caps.fmu_state,
            can_serialize_fmu_state: caps.serialize_fmu_state,
            provides_directional_derivative: caps.directional_derivatives,
            ..Default::default()
        };
        let description = md::ModelDescription {
            fmi_version: "2.0".into(),
            model_name: spec.model_name.into(),
            guid: String::new(),
            description: Some(spec.description.into()),
            author: Some("nigel-fmi".into()),
            version: Some(spec.version.into()),
            copyright: None,
            license: Some("MIT OR Apache-2.0".into()),
            generation_tool: Some(format!("nigel-fmi fmi2-export {}", env!("CARGO_PKG_VERSION"))),
            generation_date_and_time: None,
            variable_naming_convention: Some("structured".into()),
            number_of_event_indicators: 0,
            model_exchange: spec.interfaces.model_exchange.then_some(capabilities_me),
            co_simulation: spec.interfaces.co_simulation.then_some(capabilities_cs),
            unit_definitions: spec.units.clone(),
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
        let problems = description.validate();
        if !problems.is_empty() {
            let list: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
            return Err(format!(
                "the declaration of {} is not a valid FMI 2.0 description: {}",
                spec.model_name,
                list.join("; ")
            ));
        }
        let xml = description.to_xml();
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
                    settable_in: crate::states::Machine::ALL
                        .into_iter()
                        .filter(|&m| crate::instance::settable_in(v, m).is_ok())
                        .fold(0, |mask, m| mask | m.bit()),
                    plain: v.declared_type.is_none(),
                    lowest: v.min.unwrap_or(f64::MIN),
                    highest: v.max.unwrap_or(f64::MAX),
                },
            })
            .collect();
        Ok(Declaration { spec, lookup, dense, state_rows, derivative_rows, saved_rows, hot, description, xml })
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

    pub fn guid(&self) -> &str {
        &self.description.guid
    }

    pub fn number_of_states(&self) -> usize {
        self.state_rows.len()
    }

    /// The enumeration type of variable `row`, if it is an Enumeration.
    pub fn enumeration_of(&self, row: usize) -> Option<&md::EnumerationType> {
        let t = self.variable(row).declared_type?;
        self.spec.enumerations.iter().find(|e| e.name == t)
    }
}

/// A variable name built at run time (`format!("delta_{wheel}")`) for a declaration, which
/// holds `&'static str`: declarations are built once per process (in a `OnceLock`), so the
/// few hundred bytes are kept for its life on purpose.
pub fn declared_name(name: String) -> &'static str {
    Box::leak(name.into_boxed_str())
}

/// The wheels, in the order of every per-wheel array of the models (front-left,
/// front-right, rear-left, rear-right): the suffixes of the per-wheel variable names.
pub const WHEELS: [&str; 4] = ["fl", "fr", "rl", "rr"];

/// A family of 4 per-wheel variables `{stem}_fl .. {stem}_rr` (in [`WHEELS`] order), with
/// value references `base .. base + 3` and bindings `binding(i)`; `build(variable, i)`
/// applies the builder chain to the Real variable of wheel `i`.
///
/// `per_wheel("tau", vr::TAU, Var::Torque, |v, _| v.input(Start::Real(0.0)).unit("N.m"))`
/// declares `tau_fl` (vr `TAU`, `Var::Torque(0)`) .. `tau_rr` (vr `TAU + 3`, `Var::Torque(3)`).
pub fn per_wheel<B>(
    stem: &str,
    base: u32,
    binding: impl Fn(usize) -> B,
    build: impl Fn(VarDecl<B>, usize) -> VarDecl<B>,
) -> Vec<VarDecl<B>> {
    per_wheel_columns(&[stem], base, |i, _| binding(i), |v, i, _| build(v, i))
}

/// Per-wheel families stored wheel-major, e.g. a gain matrix with a row per wheel and a
/// column per `stems[j]`: for each wheel `i` (in [`WHEELS`] order), for each column `j`,
/// the Real variable `{stems[j]}_{WHEELS[i]}` with value reference
/// `base + stems.len() * i + j` and binding `binding(i, j)`, built by `build(variable, i, j)`.
/// With one stem it is [`per_wheel`].
pub fn per_wheel_columns<B>(
    stems: &[&str],
    base: u32,
    binding: impl Fn(usize, usize) -> B,
    build: impl Fn(VarDecl<B>, usize, usize) -> VarDecl<B>,
) -> Vec<VarDecl<B>> {
    let columns = stems.len();
    WHEELS
        .iter()
        .enumerate()
        .flat_map(|(i, wheel)| stems.iter().enumerate().map(move |(j, stem)| (i, j, *wheel, *stem)))
        .map(|(i, j, wheel, stem)| {
            let name = declared_name(format!("{stem}_{wheel}"));
            build(VarDecl::real(name, base + (columns * i + j) as u32, binding(i, j)), i, j)
        })
        .collect()
}

/// A unit with base-unit exponents `[kg, m, s, rad]`.
pub fn si_unit(name: &str, kg: i32, m: i32, s: i32, rad: i32) -> md::Unit {
    md::Unit {
        name: name.to_string(),
        base_unit: Some(md::BaseUnit { kg, m, s, rad, factor: 1.0, ..Default::default() }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        use crate::instance::{check_value_in, settable_in};
        use crate::states::Machine;
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
                let full = settable_in(d.variable(row), m).is_ok();
                assert_eq!(hot.access.settable_in & m.bit() != 0, full, "{} in {m:?}", d.variable(row).name);
            }
            for x in values {
                let a = hot.access;
                if a.plain && x >= a.lowest && x <= a.highest {
                    fast_accepted += 1;
                    assert_eq!(check_value_in(&d, row, x), Ok(()), "{} = {x}", d.variable(row).name);
                }
            }
            // what the full checks refuse, the fast path refuses too (it then runs them)
            for x in values.into_iter().filter(|&x| check_value_in(&d, row, x).is_err()) {
                let a = hot.access;
                assert!(!(a.plain && x >= a.lowest && x <= a.highest), "{} = {x}", d.variable(row).name);
            }
        }
        assert!(fast_accepted > 50, "{fast_accepted}");
        // the enumeration never takes the fast path: its items are checked in full
        assert!(!d.hot(d.row(BaseType::Integer, 6).unwrap()).access.plain);
        assert!(check_value_in(&d, d.row(BaseType::Integer, 6).unwrap(), 3.0).is_err());
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

    #[test]
    fn per_wheel_families_have_the_wheel_names_consecutive_references_and_the_chain() {
        let torques = per_wheel("tau", 20, |i| 100 + i as u8, |v, i| v.input(Start::Real(i as f64)).unit("N.m"));
        let names: Vec<&str> = torques.iter().map(|v| v.name).collect();
        assert_eq!(names, ["tau_fl", "tau_fr", "tau_rl", "tau_rr"]);
        let vrs: Vec<u32> = torques.iter().map(|v| v.value_reference).collect();
        assert_eq!(vrs, [20, 21, 22, 23]);
        let bindings: Vec<u8> = torques.iter().map(|v| v.binding).collect();
        assert_eq!(bindings, [100, 101, 102, 103]);
        for (i, v) in torques.iter().enumerate() {
            assert_eq!(
                (v.base_type, v.causality, v.variability),
                (BaseType::Real, Causality::Input, Variability::Continuous)
            );
            assert_eq!((v.start, v.unit, v.initial), (Start::Real(i as f64), Some("N.m"), None));
        }

        // wheel-major matrix: k_a_fl, k_b_fl, k_a_fr, ... at base + 2 i + j
        let gains = per_wheel_columns(
            &["k_a", "k_b"],
            40,
            |i, j| (10 * i + j) as u8,
            |v, i, j| v.tunable_parameter(Start::Real((10 * i + j) as f64)),
        );
        let rows: Vec<(&str, u32, u8)> = gains.iter().map(|v| (v.name, v.value_reference, v.binding)).collect();
        assert_eq!(
            rows,
            [
                ("k_a_fl", 40, 0),
                ("k_b_fl", 41, 1),
                ("k_a_fr", 42, 10),
                ("k_b_fr", 43, 11),
                ("k_a_rl", 44, 20),
                ("k_b_rl", 45, 21),
                ("k_a_rr", 46, 30),
                ("k_b_rr", 47, 31),
            ]
        );
        assert!(gains
            .iter()
            .all(|v| v.variability == Variability::Tunable && v.start == Start::Real(v.binding as f64)));

        // a declaration of them is valid, and each is found by its value reference
        let mut v = toy();
        v.extend(torques);
        v.extend(gains);
        v.push(VarDecl::real("g", 50, 200).calculated_parameter());
        let mut s = spec(v);
        s.units.push(si_unit("N.m", 1, 2, -2, 0));
        let d = Declaration::new(s).unwrap();
        assert_eq!(d.variable(d.row(BaseType::Real, 23).unwrap()).name, "tau_rr");
        assert_eq!(d.variable(d.row(BaseType::Real, 45).unwrap()).name, "k_b_rl");
        let g = d.variable(d.row(BaseType::Real, 50).unwrap());
        assert_eq!(
            (g.causality, g.variability, g.initial),
            (Causality::CalculatedParameter, Variability::Tunable, Some(Initial::Calculated))
        );
        // a calculated parameter is an InitialUnknown
        let g_index = d.row(BaseType::Real, 50).unwrap() as u32 + 1;
        assert!(d.model_description().model_structure.initial_unknowns.iter().any(|u| u.index == g_index));
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

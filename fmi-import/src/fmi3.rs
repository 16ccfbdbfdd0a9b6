//! What an FMI 3.0 FMU needs beyond the FMI 2.0 import: its function table, its own model
//! description, the view of it the master's systems, observers and writers see, and what
//! is refused at load. The calls on the view's variables are `instance/fmi3.rs`.
//!
//! The view is an FMI 2.0-shaped [`ModelDescription`] of the FMU's variables, with the same
//! names, value references, causalities, variabilities, units and ModelStructure (indices
//! into the view): Float64, Float32, UInt32, Int64 and UInt64 as Real (the 64-bit integers
//! exact up to 2^53; [`crate::Instance::get_exact`] reads them exactly), Int8 .. Int32 as Integer,
//! Boolean, String, Enumeration (Int64 values of i32 items), a Binary as a Real holding its
//! size in bytes (read-only); an array as one variable per element, `y[1]`, `y[2]`, ...
//! (`A[1,2]`: 1-based, row-major, as FMI 2.0 names array elements) with value references
//! of the view's own above the FMU's; an `<Alias>` as one more variable of the same value
//! reference (after all others, out of the ModelStructure, as FMI 2.0 aliases are). An [`Instance`] translates each call on them to the
//! FMI 3.0 function of the variable's type (an element set alone: the array's other
//! elements as set before, or its start values). Variables the view cannot hold (String
//! and Binary arrays, clocks) are listed by [`Fmu::not_in_view`].
//!
//! [`Instance`]: crate::Instance
//! [`Fmu::not_in_view`]: crate::Fmu::not_in_view

use std::collections::HashMap;
use std::ffi::CString;

use crate::c_types::Fmi3Functions;
use model_description::fmi3;
use model_description::*;

/// An FMI 3.0 FMU's functions and description.
pub(crate) struct Fmi3Abi {
    /// The library's functions.
    pub(crate) functions: Fmi3Functions,
    /// The FMU's own model description.
    pub(crate) description: fmi3::ModelDescription,
    /// The view's variables that are not plain scalars of the FMI 2.0 types, by the view's
    /// value reference.
    pub(crate) special: HashMap<u32, Access>,
    /// `instantiationToken`.
    pub(crate) token: CString,
    /// `resourcePath`: the unpacked `resources/` folder, a native path ending in `/`.
    pub(crate) resource_path: CString,
    /// The structural parameters set in Configuration Mode before initialization (the FMU's
    /// variable and the value; empty: Configuration Mode is not entered). See
    /// [`crate::structural`].
    pub(crate) configuration: Vec<(Access, f64)>,
    /// The structural parameters whose value at the start (after Configuration Mode) is
    /// not the one the view is sized for (the FMU's value reference and the value; empty
    /// but for an FMU [sized for](crate::Fmu::sized_for) a change in Reconfiguration Mode):
    /// the arrays they size have fewer elements than the view until then.
    pub(crate) initial_sizes: Vec<(u32, f64)>,
}

/// What the master cannot run yet, named for the error at load; `None`: nothing.
/// `scheduled`: run in Scheduled Execution, which runs the clocks (its model partitions);
/// elsewhere the clocks are run by the master (see [`crate::clocks`]).
pub(crate) fn unsupported_feature(md: &fmi3::ModelDescription, scheduled: bool) -> Option<String> {
    if scheduled {
        return None;
    }
    if let Some(clock) = crate::clocks::unreadable_clock(md) {
        return Some(clock);
    }
    if md.co_simulation.is_none() && md.model_exchange.is_none() && md.scheduled_execution.is_some() {
        return Some("Scheduled Execution (the FMU offers no other interface type)".into());
    }
    None
}

fn int32(v: Option<i128>) -> Option<i32> {
    v.and_then(|x| i32::try_from(x).ok())
}

fn int_bound(b: Option<fmi3::Bound>) -> Option<i128> {
    match b {
        Some(fmi3::Bound::Int(i)) => Some(i),
        _ => None,
    }
}

/// How the master reaches one variable of the view that is not a plain scalar of the type
/// FMI 2.0 has: an element of an array, or a type the view holds as another.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Access {
    /// The FMU's value reference.
    pub(crate) vr: u32,
    /// The FMU variable's type.
    pub(crate) value_type: fmi3::ValueType,
    /// The element (0-based, row-major) and the variable's element count (1 for a scalar).
    pub(crate) element: usize,
    pub(crate) count: usize,
}

/// The kind of a variable of the view whose values an f64 does not hold exactly: its
/// Real in the view is the nearest f64 (a Binary: its size in bytes), and
/// [`crate::Instance::get_exact`] reads the value itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExactKind {
    /// An FMI 3.0 Int64 (beyond 2^53 an f64 rounds it).
    Int64,
    /// An FMI 3.0 UInt64.
    UInt64,
    /// An FMI 3.0 Binary.
    Binary,
}

/// A value as the FMU holds it, where the view's f64 is not it: a 64-bit integer, a
/// String's text, a Binary's bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Exact {
    /// An Int64 or UInt64.
    Integer(i128),
    /// A String.
    Text(String),
    /// A Binary.
    Bytes(Vec<u8>),
}

impl Exact {
    /// As fmpy writes it in a CSV file: an integer in decimal, a text as it is, bytes in
    /// lower-case hex (Python's `bytes.hex()`).
    pub fn to_text(&self) -> String {
        match self {
            Exact::Integer(i) => i.to_string(),
            Exact::Text(s) => s.clone(),
            Exact::Bytes(b) => {
                use std::fmt::Write;
                let mut s = String::with_capacity(2 * b.len());
                for x in b {
                    let _ = write!(s, "{x:02x}");
                }
                s
            }
        }
    }
}

/// The type of an integer variable of the view, as the FMU declares it: its name and the
/// range of its values (an FMI 2.0 Integer or Enumeration is an Int32; an FMI 3.0
/// Enumeration in the view holds Int32 items). A connection between integers carries the
/// value as an integer and checks it against this range ([`crate::Fmu::integer_type`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IntegerType {
    /// The FMI type's name (`Int8` .. `UInt64`, `Enumeration`).
    pub name: &'static str,
    /// The smallest value.
    pub min: i128,
    /// The largest value.
    pub max: i128,
}

impl IntegerType {
    /// FMI 2.0's Integer.
    pub const INT32: IntegerType = IntegerType { name: "Int32", min: i32::MIN as i128, max: i32::MAX as i128 };

    /// Of an FMI 3.0 variable of `value_type` (`None`: no integer).
    pub(crate) fn of(value_type: fmi3::ValueType) -> Option<IntegerType> {
        use fmi3::ValueType as T;
        let (name, min, max) = match value_type {
            T::Int8 => ("Int8", i8::MIN as i128, i8::MAX as i128),
            T::UInt8 => ("UInt8", 0, u8::MAX as i128),
            T::Int16 => ("Int16", i16::MIN as i128, i16::MAX as i128),
            T::UInt16 => ("UInt16", 0, u16::MAX as i128),
            T::Int32 => return Some(IntegerType::INT32),
            T::UInt32 => ("UInt32", 0, u32::MAX as i128),
            T::Int64 => ("Int64", i64::MIN as i128, i64::MAX as i128),
            T::UInt64 => ("UInt64", 0, u64::MAX as i128),
            T::Enumeration => ("Enumeration", i32::MIN as i128, i32::MAX as i128),
            _ => return None,
        };
        Some(IntegerType { name, min, max })
    }

    /// Whether `value` is one of the type's.
    pub fn holds(&self, value: i128) -> bool {
        (self.min..=self.max).contains(&value)
    }
}

impl ExactKind {
    /// The kind of a variable of `value_type`, if its values need it.
    pub(crate) fn of(value_type: fmi3::ValueType) -> Option<ExactKind> {
        match value_type {
            fmi3::ValueType::Int64 => Some(ExactKind::Int64),
            fmi3::ValueType::UInt64 => Some(ExactKind::UInt64),
            fmi3::ValueType::Binary => Some(ExactKind::Binary),
            _ => None,
        }
    }
}

/// Arrays with more elements than this are left out of the view (one column each would
/// make results no one reads).
const MAX_ELEMENTS: u64 = 100_000;

/// The size of each dimension of `v` (a `valueReference` dimension: the start value of
/// the variable it names).
pub(crate) fn sizes(md: &fmi3::ModelDescription, v: &fmi3::Variable) -> Option<Vec<u64>> {
    v.dimensions
        .iter()
        .map(|d| match *d {
            fmi3::Dimension::Fixed(n) => Some(n),
            fmi3::Dimension::Variable(vr) => match &md.variable(vr)?.start {
                Some(fmi3::Values::Int(s)) if s.len() == 1 => u64::try_from(s[0]).ok(),
                _ => None,
            },
        })
        .collect()
}

/// `name[i]`, `name[i,j]`, ... of element `k` (row-major, 1-based), as FMI 2.0 names the
/// elements of arrays.
fn element_name(name: &str, sizes: &[u64], k: u64) -> String {
    let mut rest = k;
    let mut index = vec![0u64; sizes.len()];
    for (i, n) in sizes.iter().enumerate().rev() {
        index[i] = rest % n + 1;
        rest /= n;
    }
    let index: Vec<String> = index.iter().map(u64::to_string).collect();
    format!("{name}[{}]", index.join(","))
}

/// The largest integer up to which every integer is an f64.
const EXACT: i128 = 1 << 53;

/// Why a variable of an FMI 3.0 FMU is not in the master's view: it is neither recorded,
/// set nor connected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeftOut {
    /// A String array.
    StringArray,
    /// A Binary array.
    BinaryArray,
    /// A clock (run by the master through the clock calls; listed by `Fmu::clocks`).
    Clock,
    /// An array of more than 100,000 elements.
    TooLarge,
    /// An array whose size its description does not give (a dimension naming a variable
    /// without one integer start value).
    UnknownSize,
}

impl LeftOut {
    /// What it is, for messages.
    pub fn as_str(self) -> &'static str {
        match self {
            LeftOut::StringArray => "a String array",
            LeftOut::BinaryArray => "a Binary array",
            LeftOut::Clock => "a clock",
            LeftOut::TooLarge => "an array of more than 100,000 elements",
            LeftOut::UnknownSize => "an array whose size the model description does not give",
        }
    }
}

/// The variables of `md` the master's view leaves out, with the reason (what
/// [`crate::Fmu::not_in_view`] lists once the FMU is loaded).
pub fn not_in_view(md: &fmi3::ModelDescription) -> Vec<(String, LeftOut)> {
    fmi2_view(md).2
}

/// The FMI 2.0-shaped view of `md` (see the module): its variables, how to reach those that
/// are not plain scalars of the types FMI 2.0 has (by the view's value reference), and the
/// variables it leaves out, with the reason.
pub(crate) fn fmi2_view(
    md: &fmi3::ModelDescription,
) -> (ModelDescription, HashMap<u32, Access>, Vec<(String, LeftOut)>) {
    use fmi3::ValueType as T;
    let mut special = HashMap::new();
    let mut left_out = Vec::new();
    // value references for array elements: the numbers the FMU does not use, lowest first
    // (an FMU may use any u32, up to 4294967295 as Dymola does: the free ones are not all
    // above its largest)
    let used: std::collections::HashSet<u32> = md.model_variables.iter().map(|v| v.value_reference).collect();
    let mut free_vrs = (0..=u32::MAX).filter(move |vr| !used.contains(vr));
    let mut free_left = (u32::MAX as u64 + 1).saturating_sub(md.model_variables.len() as u64);
    // (FMU value reference, element) of each variable of the view
    let mut elements: Vec<(u32, usize)> = Vec::new();
    let mut variables: Vec<ScalarVariable> = Vec::new();
    // the <Alias> names, after all variables (the ModelStructure's indices stay theirs)
    let mut alias_variables: Vec<ScalarVariable> = Vec::new();
    for v in &md.model_variables {
        let dims = if v.is_array() { sizes(md, v) } else { Some(Vec::new()) };
        // a product of sizes beyond u64 is too large, not a wrapped-around small one
        let count = dims.as_ref().map(|d| d.iter().try_fold(1u64, |a, &n| a.checked_mul(n)).unwrap_or(u64::MAX));
        let unsupported = match v.value_type {
            T::String if v.is_array() => Some(LeftOut::StringArray),
            T::Binary if v.is_array() => Some(LeftOut::BinaryArray),
            T::Clock => Some(LeftOut::Clock),
            _ => None,
        };
        if let Some(reason) = unsupported {
            left_out.push((v.name.clone(), reason));
            continue;
        }
        let (Some(dims), Some(count)) = (dims, count) else {
            left_out.push((v.name.clone(), LeftOut::UnknownSize));
            continue;
        };
        if count > MAX_ELEMENTS || (v.is_array() && count > free_left) {
            left_out.push((v.name.clone(), LeftOut::TooLarge));
            continue;
        }
        if v.is_array() {
            free_left -= count;
        }
        let plain = !v.is_array() && matches!(v.value_type, T::Float64 | T::Int32 | T::Boolean | T::String);
        // a structural parameter is set in Configuration Mode only: read-only here
        let causality = v.causality.to_fmi2().unwrap_or(Causality::CalculatedParameter);
        let initial = if v.causality == fmi3::Causality::StructuralParameter { None } else { v.initial };
        let start_values = v.start.as_ref();
        for k in 0..count as usize {
            // element k's start value, or the one value given for all elements
            let pick = |n: usize| if n == 1 { 0 } else { k };
            let float = |b: Option<fmi3::Bound>| match b {
                Some(fmi3::Bound::Float(x)) => Some(x),
                Some(fmi3::Bound::Int(i)) if i.abs() <= EXACT => Some(i as f64),
                _ => None,
            };
            // an Integer's or an Enumeration's start value
            let int32_start = || match start_values {
                Some(fmi3::Values::Int(x)) => int32(x.get(pick(x.len())).copied()),
                _ => None,
            };
            let variable_type = match v.value_type {
                T::Float64 | T::Float32 | T::UInt32 | T::Int64 | T::UInt64 => VariableType::Real {
                    start: match start_values {
                        Some(fmi3::Values::Float(x)) => x.get(pick(x.len())).copied(),
                        Some(fmi3::Values::Int(x)) => {
                            x.get(pick(x.len())).filter(|i| i.abs() <= EXACT).map(|i| *i as f64)
                        }
                        _ => None,
                    },
                    unit: md.unit_of(v).map(str::to_string),
                    derivative: None, // an index into the view, set below
                    min: float(v.min),
                    max: float(v.max),
                    nominal: v.nominal,
                },
                T::Int8 | T::UInt8 | T::Int16 | T::UInt16 | T::Int32 => VariableType::Integer {
                    start: int32_start(),
                    min: int32(int_bound(v.min)),
                    max: int32(int_bound(v.max)),
                },
                T::Enumeration => VariableType::Enumeration {
                    declared_type: v.declared_type.clone().unwrap_or_default(),
                    start: int32_start(),
                    min: int32(int_bound(v.min)),
                    max: int32(int_bound(v.max)),
                },
                T::Boolean => VariableType::Boolean {
                    start: match start_values {
                        Some(fmi3::Values::Boolean(b)) => b.get(pick(b.len())).copied(),
                        _ => None,
                    },
                },
                T::String => VariableType::String {
                    start: match start_values {
                        Some(fmi3::Values::String(s)) => s.first().cloned(),
                        _ => None,
                    },
                },
                // a Binary is recorded as its size in bytes
                T::Binary => VariableType::Real {
                    start: match start_values {
                        Some(fmi3::Values::Binary(b)) => b.first().map(|b| b.len() as f64),
                        _ => None,
                    },
                    unit: None,
                    derivative: None,
                    min: None,
                    max: None,
                    nominal: None,
                },
                T::Clock => unreachable!("left out above"),
            };
            let (name, value_reference) = if v.is_array() {
                let vr = free_vrs.next().expect("counted in free_left");
                (element_name(&v.name, &dims, k as u64), vr)
            } else {
                (v.name.clone(), v.value_reference)
            };
            if !plain {
                special.insert(
                    value_reference,
                    Access { vr: v.value_reference, value_type: v.value_type, element: k, count: count as usize },
                );
            }
            elements.push((v.value_reference, k));
            // an <Alias>: the same value reference under its own name, out of the
            // ModelStructure (as FMI 2.0 lists one variable of an alias set there)
            for alias in &v.aliases {
                alias_variables.push(ScalarVariable {
                    name: if v.is_array() { element_name(&alias.name, &dims, k as u64) } else { alias.name.clone() },
                    value_reference,
                    description: alias.description.clone().or_else(|| v.description.clone()),
                    causality,
                    variability: v.variability,
                    initial: None,
                    variable_type: without_start(&variable_type),
                });
            }
            variables.push(ScalarVariable {
                name,
                value_reference,
                description: v.description.clone(),
                causality,
                variability: v.variability,
                initial,
                variable_type,
            });
        }
    }
    let element_index: HashMap<(u32, usize), u32> =
        elements.iter().enumerate().map(|(i, e)| (*e, i as u32 + 1)).collect();
    let mut indices_of: HashMap<u32, Vec<u32>> = HashMap::new();
    for (i, (vr, _)) in elements.iter().enumerate() {
        indices_of.entry(*vr).or_default().push(i as u32 + 1);
    }
    for (sv, (vr, k)) in variables.iter_mut().zip(&elements) {
        if let (VariableType::Real { derivative, .. }, Some(state)) =
            (&mut sv.variable_type, md.variable(*vr).and_then(|v| v.derivative))
        {
            *derivative = element_index.get(&(state, *k)).copied();
        }
    }
    let unknowns = |list: &[fmi3::Unknown]| -> Vec<Unknown> {
        let mut out = Vec::new();
        for u in list {
            // knowns outside the view cannot be set by the master: no ordering to keep
            let (dependencies, dependencies_kind) = match (&u.dependencies, &u.dependencies_kind) {
                (Some(d), kinds) => {
                    let mut deps = Vec::new();
                    let mut deps_kind = Vec::new();
                    for (j, vr) in d.iter().enumerate() {
                        for index in indices_of.get(vr).into_iter().flatten() {
                            deps.push(*index);
                            if let Some(kind) = kinds.as_ref().and_then(|ks| ks.get(j)) {
                                deps_kind.push(*kind);
                            }
                        }
                    }
                    let kinds = kinds.as_ref().map(|_| deps_kind);
                    (Some(deps), kinds)
                }
                (None, _) => (None, None),
            };
            for index in indices_of.get(&u.value_reference).into_iter().flatten() {
                out.push(Unknown {
                    index: *index,
                    dependencies: dependencies.clone(),
                    dependencies_kind: dependencies_kind.clone(),
                });
            }
        }
        out
    };
    let model_structure = ModelStructure {
        outputs: unknowns(&md.model_structure.outputs),
        derivatives: unknowns(&md.model_structure.continuous_state_derivatives),
        initial_unknowns: unknowns(&md.model_structure.initial_unknowns),
    };
    let number_of_event_indicators = md
        .model_structure
        .event_indicators
        .iter()
        .map(|u| indices_of.get(&u.value_reference).map_or(0, Vec::len) as u32)
        .sum();
    let co_simulation = md.co_simulation.as_ref().map(|cs| CoSimulation {
        model_identifier: cs.common.model_identifier.clone(),
        needs_execution_tool: cs.common.needs_execution_tool,
        can_handle_variable_communication_step_size: cs.can_handle_variable_communication_step_size,
        can_interpolate_inputs: false,
        max_output_derivative_order: 0,
        can_run_asynchronuously: false,
        can_be_instantiated_only_once_per_process: cs.common.can_be_instantiated_only_once_per_process,
        can_not_use_memory_management_functions: true,
        can_get_and_set_fmu_state: cs.common.can_get_and_set_fmu_state,
        can_serialize_fmu_state: cs.common.can_serialize_fmu_state,
        provides_directional_derivative: cs.common.provides_directional_derivatives,
    });
    let model_exchange = md.model_exchange.as_ref().map(|me| ModelExchange {
        model_identifier: me.common.model_identifier.clone(),
        needs_execution_tool: me.common.needs_execution_tool,
        completed_integrator_step_not_needed: !me.needs_completed_integrator_step,
        can_be_instantiated_only_once_per_process: me.common.can_be_instantiated_only_once_per_process,
        can_not_use_memory_management_functions: true,
        can_get_and_set_fmu_state: me.common.can_get_and_set_fmu_state,
        can_serialize_fmu_state: me.common.can_serialize_fmu_state,
        provides_directional_derivative: me.common.provides_directional_derivatives,
    });
    let type_definitions = md
        .type_definitions
        .iter()
        .filter_map(|t| match &t.kind {
            fmi3::TypeKind::Enumeration { items, .. } => Some(EnumerationType {
                name: t.name.clone(),
                description: t.description.clone(),
                items: items
                    .iter()
                    .filter_map(|i| {
                        Some(EnumerationItem {
                            name: i.name.clone(),
                            value: i32::try_from(i.value).ok()?,
                            description: i.description.clone(),
                        })
                    })
                    .collect(),
            }),
            _ => None,
        })
        .collect();
    let view = ModelDescription {
        fmi_version: md.fmi_version.clone(),
        model_name: md.model_name.clone(),
        guid: md.instantiation_token.clone(),
        description: md.description.clone(),
        author: md.author.clone(),
        version: md.version.clone(),
        copyright: md.copyright.clone(),
        license: md.license.clone(),
        generation_tool: md.generation_tool.clone(),
        generation_date_and_time: md.generation_date_and_time.clone(),
        variable_naming_convention: md.variable_naming_convention.clone(),
        number_of_event_indicators,
        model_exchange,
        co_simulation,
        unit_definitions: md.unit_definitions.clone(),
        type_definitions,
        log_categories: md.log_categories.clone(),
        default_experiment: md.default_experiment.clone(),
        model_variables: variables.into_iter().chain(alias_variables).collect(),
        model_structure,
    };
    (view, special, left_out)
}

/// `t` without its start value (an alias has none of its own: FMI 2.0 gives a start to
/// one variable of an alias set).
fn without_start(t: &VariableType) -> VariableType {
    let mut t = t.clone();
    match &mut t {
        VariableType::Real { start, derivative, .. } => {
            *start = None;
            *derivative = None;
        }
        VariableType::Integer { start, .. } | VariableType::Enumeration { start, .. } => *start = None,
        VariableType::Boolean { start } => *start = None,
        VariableType::String { start } => *start = None,
    }
    t
}

/// The resource path FMI 3.0 wants: an absolute native path ending in a separator.
pub(crate) fn resource_path(dir: &std::path::Path) -> Option<CString> {
    let mut s = dir.join("resources").to_string_lossy().into_owned();
    s.push(std::path::MAIN_SEPARATOR);
    CString::new(s).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    const XML: &str = r#"<fmiModelDescription fmiVersion="3.0" modelName="m" instantiationToken="{tok}">
  <ModelExchange modelIdentifier="m" needsCompletedIntegratorStep="true"/>
  <CoSimulation modelIdentifier="m" canHandleVariableCommunicationStepSize="true"/>
  <UnitDefinitions><Unit name="m"/></UnitDefinitions>
  <TypeDefinitions>
    <Float64Type name="Length" unit="m"/>
    <EnumerationType name="E"><Item name="a" value="1"/><Item name="b" value="5000000000"/></EnumerationType>
  </TypeDefinitions>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent"/>
    <Float64 name="x" valueReference="1" causality="output" declaredType="Length" start="1" initial="exact"/>
    <Float64 name="der(x)" valueReference="2" derivative="1"/>
    <Float32 name="f" valueReference="3" causality="input" start="0"/>
    <Int32 name="k" valueReference="4" causality="input" start="-3"/>
    <Enumeration name="e" valueReference="5" causality="parameter" variability="fixed" declaredType="E" start="1"/>
    <Boolean name="b" valueReference="6" causality="input" start="true"/>
    <Float64 name="y" valueReference="7" causality="output"><Dimension start="2"/></Float64>
    <UInt64 name="n" valueReference="8" causality="structuralParameter" variability="fixed" start="2"/>
    <Float64 name="z" valueReference="9"/>
  </ModelVariables>
  <ModelStructure>
    <Output valueReference="1"/>
    <Output valueReference="7" dependencies="3 4" dependenciesKind="dependent constant"/>
    <ContinuousStateDerivative valueReference="2" dependencies="1 3 4" dependenciesKind="fixed dependent constant"/>
    <InitialUnknown valueReference="2"/>
    <EventIndicator valueReference="9"/>
  </ModelStructure>
</fmiModelDescription>"#;

    #[test]
    fn the_view_holds_every_variable_with_a_value() {
        let md = fmi3::ModelDescription::from_xml(XML).unwrap();
        let (view, special, left_out) = fmi2_view(&md);
        assert!(left_out.is_empty(), "{left_out:?}");
        let names: Vec<&str> = view.model_variables.iter().map(|v| v.name.as_str()).collect();
        assert_eq!(names, ["time", "x", "der(x)", "f", "k", "e", "b", "y[1]", "y[2]", "n", "z"]);
        assert_eq!(view.guid, "{tok}");
        // f (Float32), e (Enumeration), the elements of y (value references above the
        // FMU's 9) and n (UInt64) go by their own getters
        let access = |vr: u32| special.get(&vr).map(|a| (a.vr, a.value_type, a.element, a.count));
        assert_eq!(special.len(), 5);
        assert_eq!(access(3), Some((3, fmi3::ValueType::Float32, 0, 1)));
        assert_eq!(access(5), Some((5, fmi3::ValueType::Enumeration, 0, 1)));
        assert_eq!(view.variable("y[2]").unwrap().value_reference, 11);
        assert_eq!(access(11), Some((7, fmi3::ValueType::Float64, 1, 2)));
        assert_eq!(access(8), Some((8, fmi3::ValueType::UInt64, 0, 1)));
        assert_eq!(view.variable("n").unwrap().variable_type.type_name(), "Real");
        assert_eq!(view.variable("f").unwrap().variable_type.type_name(), "Real");
        let x = view.variable("x").unwrap();
        assert_eq!(x.variable_type.unit(), Some("m"), "from the declaredType");
        // der(x) is variable 3 of the view, its state x variable 2
        assert_eq!(view.variable("der(x)").unwrap().variable_type.derivative(), Some(2));
        assert_eq!(view.states(), vec![2]);
        // the output y is its two elements, each depending on f (4) and k (5)
        let outputs: Vec<(u32, Option<Vec<u32>>)> =
            view.model_structure.outputs.iter().map(|u| (u.index, u.dependencies.clone())).collect();
        assert_eq!(outputs, vec![(2, None), (8, Some(vec![4, 5])), (9, Some(vec![4, 5]))]);
        let der = &view.model_structure.derivatives[0];
        assert_eq!(der.dependencies, Some(vec![2, 4, 5]));
        assert_eq!(
            der.dependencies_kind,
            Some(vec![DependencyKind::Fixed, DependencyKind::Dependent, DependencyKind::Constant])
        );
        assert_eq!(view.number_of_event_indicators, 1);
        assert!(view.model_exchange.as_ref().is_some_and(|m| !m.completed_integrator_step_not_needed));
        // the item of 5e9 does not fit FMI 2.0's Integer
        assert_eq!(view.type_definitions[0].items.len(), 1);
        assert_eq!(view.variable("b").unwrap().variable_type, VariableType::Boolean { start: Some(true) });
    }

    #[test]
    fn what_the_view_leaves_out_is_named_with_the_reason() {
        let extra = r#"<Float64 name="z" valueReference="9"/>
    <String name="names" valueReference="20" causality="parameter" variability="fixed"><Dimension start="2"/><Start value="a"/><Start value="b"/></String>
    <Binary name="blobs" valueReference="21" causality="output"><Dimension start="3"/></Binary>
    <Float64 name="huge" valueReference="22" causality="output"><Dimension start="100001"/></Float64>
    <Float64 name="sized_by_z" valueReference="23" causality="output"><Dimension valueReference="9"/></Float64>
    <Float64 name="fine" valueReference="24" causality="output"><Dimension start="100000"/></Float64>"#;
        let md =
            fmi3::ModelDescription::from_xml(&XML.replace(r#"<Float64 name="z" valueReference="9"/>"#, extra)).unwrap();
        let (view, _, left_out) = fmi2_view(&md);
        assert_eq!(
            left_out,
            vec![
                ("names".to_string(), LeftOut::StringArray),
                ("blobs".to_string(), LeftOut::BinaryArray),
                ("huge".to_string(), LeftOut::TooLarge),
                ("sized_by_z".to_string(), LeftOut::UnknownSize),
            ]
        );
        assert_eq!(not_in_view(&md), left_out);
        // 100,000 elements are kept, one variable each
        assert_eq!(view.model_variables.len(), 11 + 100_000);
        assert!(view.variable("fine[100000]").is_some() && view.variable("names").is_none());
    }

    #[test]
    fn array_elements_are_named_row_major_from_one() {
        assert_eq!(element_name("A", &[2, 3], 0), "A[1,1]");
        assert_eq!(element_name("A", &[2, 3], 2), "A[1,3]");
        assert_eq!(element_name("A", &[2, 3], 3), "A[2,1]");
        assert_eq!(element_name("y", &[4], 3), "y[4]");
    }

    #[test]
    fn clocks_and_scheduled_execution_are_named() {
        let md = fmi3::ModelDescription::from_xml(XML).unwrap();
        assert_eq!(unsupported_feature(&md, false), None);
        let clock = XML.replace(
            r#"<Float64 name="z" valueReference="9"/>"#,
            r#"<Float64 name="z" valueReference="9"/><Clock name="tick" valueReference="10" causality="input" intervalVariability="constant" intervalDecimal="0.1"/>"#,
        );
        let md = fmi3::ModelDescription::from_xml(&clock).unwrap();
        assert_eq!(unsupported_feature(&md, false), None, "clocks are run (in Co-Simulation with Event Mode)");
        let md = fmi3::ModelDescription::from_xml(
            &clock.replace(r#"intervalVariability="constant""#, r#"intervalVariability="often""#),
        )
        .unwrap();
        assert!(unsupported_feature(&md, false).unwrap().contains("intervalVariability \"often\""));
        let se =
            XML.replace(r#"<ModelExchange modelIdentifier="m" needsCompletedIntegratorStep="true"/>"#, "").replace(
                r#"<CoSimulation modelIdentifier="m" canHandleVariableCommunicationStepSize="true"/>"#,
                r#"<ScheduledExecution modelIdentifier="m"/>"#,
            );
        let md = fmi3::ModelDescription::from_xml(&se).unwrap();
        assert!(unsupported_feature(&md, false).unwrap().starts_with("Scheduled Execution"));
        assert_eq!(unsupported_feature(&md, true), None);
    }

    #[test]
    fn resource_path_ends_in_a_separator() {
        let p = resource_path(std::path::Path::new("/tmp/nigel-cosim-x")).unwrap();
        assert_eq!(p.to_str().unwrap(), "/tmp/nigel-cosim-x/resources/");
    }
}

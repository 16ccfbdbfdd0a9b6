//! What an FMI 3.0 FMU needs beyond the FMI 2.0 import: its function table, its own model
//! description, the view of it the master's systems, observers and writers see, the log
//! callback, and what is refused at load.
//!
//! The view is an FMI 2.0-shaped [`ModelDescription`] of the FMU's scalar variables of the
//! types both generations have (Float64 as Real, Int32 as Integer, Boolean, String,
//! Enumeration as Enumeration), with the same names, value references, causalities,
//! variabilities, units and ModelStructure (indices into the view). An [`Instance`]
//! translates each call on them to the FMI 3.0 function of the variable's type.
//! Variables the view cannot hold (arrays, Float32, the other integer types, Binary) are
//! listed by [`Fmu::not_in_view`]; they are neither recorded nor settable yet.
//!
//! [`Instance`]: crate::Instance
//! [`Fmu::not_in_view`]: crate::Fmu::not_in_view

use std::collections::{HashMap, HashSet};
use std::ffi::{c_char, CStr, CString};

use fmi_sys::fmi3::{fmi3InstanceEnvironment, fmi3Status, fmi3String, Fmi3Functions};
use model_description::fmi3;
use model_description::*;

use crate::error::Status;
use crate::fmu::{LogRecord, LogSink};

/// An FMI 3.0 FMU's functions and description.
pub(crate) struct Fmi3Abi {
    /// The library's functions.
    pub(crate) functions: Fmi3Functions,
    /// The FMU's own model description.
    pub(crate) description: fmi3::ModelDescription,
    /// Value references of the view's Enumeration variables (accessed as Int64).
    pub(crate) enumerations: HashSet<u32>,
    /// `instantiationToken`.
    pub(crate) token: CString,
    /// `resourcePath`: the unpacked `resources/` folder, a native path ending in `/`.
    pub(crate) resource_path: CString,
}

/// What the master cannot run yet, named for the error at load; `None`: nothing.
pub(crate) fn unsupported_feature(md: &fmi3::ModelDescription) -> Option<String> {
    if let Some(clock) = md.model_variables.iter().find(|v| v.value_type == fmi3::ValueType::Clock) {
        return Some(format!("clocks (Clock variable {:?})", clock.name));
    }
    if md.co_simulation.is_none() && md.model_exchange.is_none() && md.scheduled_execution.is_some() {
        return Some("Scheduled Execution (the FMU offers no other interface type)".into());
    }
    None
}

fn floats(v: &Option<fmi3::Values>) -> Option<f64> {
    match v {
        Some(fmi3::Values::Float(x)) if x.len() == 1 => Some(x[0]),
        _ => None,
    }
}

fn int32(v: Option<i128>) -> Option<i32> {
    v.and_then(|x| i32::try_from(x).ok())
}

fn ints(v: &Option<fmi3::Values>) -> Option<i128> {
    match v {
        Some(fmi3::Values::Int(x)) if x.len() == 1 => Some(x[0]),
        _ => None,
    }
}

fn int_bound(b: Option<fmi3::Bound>) -> Option<i128> {
    match b {
        Some(fmi3::Bound::Int(i)) => Some(i),
        _ => None,
    }
}

fn float_bound(b: Option<fmi3::Bound>) -> Option<f64> {
    match b {
        Some(fmi3::Bound::Float(x)) => Some(x),
        _ => None,
    }
}

/// The FMI 2.0-shaped view of `md` (see the module), the value references of its
/// Enumeration variables, and the names of the variables it leaves out.
pub(crate) fn fmi2_view(md: &fmi3::ModelDescription) -> (ModelDescription, HashSet<u32>, Vec<String>) {
    let mut variables = Vec::new();
    let mut enumerations = HashSet::new();
    let mut left_out = Vec::new();
    for v in &md.model_variables {
        let variable_type = match v.value_type {
            _ if v.is_array() => None,
            fmi3::ValueType::Float64 => Some(VariableType::Real {
                start: floats(&v.start),
                unit: md.unit_of(v).map(str::to_string),
                derivative: None, // an index into the view, set below
                min: float_bound(v.min),
                max: float_bound(v.max),
                nominal: v.nominal,
            }),
            fmi3::ValueType::Int32 => Some(VariableType::Integer {
                start: int32(ints(&v.start)),
                min: int32(int_bound(v.min)),
                max: int32(int_bound(v.max)),
            }),
            fmi3::ValueType::Enumeration => {
                let fits = ints(&v.start).is_none_or(|s| i32::try_from(s).is_ok());
                fits.then(|| {
                    enumerations.insert(v.value_reference);
                    VariableType::Enumeration {
                        declared_type: v.declared_type.clone().unwrap_or_default(),
                        start: int32(ints(&v.start)),
                        min: int32(int_bound(v.min)),
                        max: int32(int_bound(v.max)),
                    }
                })
            }
            fmi3::ValueType::Boolean => Some(VariableType::Boolean {
                start: match &v.start {
                    Some(fmi3::Values::Boolean(b)) if b.len() == 1 => Some(b[0]),
                    _ => None,
                },
            }),
            fmi3::ValueType::String => Some(VariableType::String {
                start: match &v.start {
                    Some(fmi3::Values::String(s)) if s.len() == 1 => Some(s[0].clone()),
                    _ => None,
                },
            }),
            _ => None,
        };
        let Some(variable_type) = variable_type else {
            left_out.push(v.name.clone());
            continue;
        };
        // a structural parameter is set in Configuration Mode only: read-only here
        let causality = v.causality.to_fmi2().unwrap_or(Causality::CalculatedParameter);
        let initial = if v.causality == fmi3::Causality::StructuralParameter { None } else { v.initial };
        variables.push((
            v.value_reference,
            ScalarVariable {
                name: v.name.clone(),
                value_reference: v.value_reference,
                description: v.description.clone(),
                causality,
                variability: v.variability,
                initial,
                variable_type,
            },
        ));
    }
    let view_index: HashMap<u32, u32> = variables.iter().enumerate().map(|(i, (vr, _))| (*vr, i as u32 + 1)).collect();
    for (vr, sv) in variables.iter_mut() {
        if let (VariableType::Real { derivative, .. }, Some(state)) =
            (&mut sv.variable_type, md.variable(*vr).and_then(|v| v.derivative))
        {
            *derivative = view_index.get(&state).copied();
        }
    }
    let unknowns = |list: &[fmi3::Unknown]| -> Vec<Unknown> {
        list.iter()
            .filter_map(|u| {
                let index = *view_index.get(&u.value_reference)?;
                // knowns outside the view cannot be set by the master: no ordering to keep
                let (dependencies, dependencies_kind) = match (&u.dependencies, &u.dependencies_kind) {
                    (Some(d), kinds) => {
                        let kept: Vec<(u32, Option<DependencyKind>)> = d
                            .iter()
                            .enumerate()
                            .filter_map(|(k, vr)| {
                                Some((*view_index.get(vr)?, kinds.as_ref().and_then(|ks| ks.get(k).copied())))
                            })
                            .collect();
                        let kinds = kinds.as_ref().map(|_| kept.iter().filter_map(|(_, k)| *k).collect());
                        (Some(kept.into_iter().map(|(i, _)| i).collect()), kinds)
                    }
                    (None, _) => (None, None),
                };
                Some(Unknown { index, dependencies, dependencies_kind })
            })
            .collect()
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
        .map(|u| md.variable(u.value_reference).and_then(|v| md.element_count(v)).unwrap_or(1) as u32)
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
        provides_directional_derivative: false,
    });
    let model_exchange = md.model_exchange.as_ref().map(|me| ModelExchange {
        model_identifier: me.common.model_identifier.clone(),
        needs_execution_tool: me.common.needs_execution_tool,
        completed_integrator_step_not_needed: !me.needs_completed_integrator_step,
        can_be_instantiated_only_once_per_process: me.common.can_be_instantiated_only_once_per_process,
        can_not_use_memory_management_functions: true,
        can_get_and_set_fmu_state: me.common.can_get_and_set_fmu_state,
        can_serialize_fmu_state: me.common.can_serialize_fmu_state,
        provides_directional_derivative: false,
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
        model_variables: variables.into_iter().map(|(_, v)| v).collect(),
        model_structure,
    };
    (view, enumerations, left_out)
}

fn text(p: fmi3String) -> String {
    if p.is_null() {
        return String::new();
    }
    // SAFETY: the FMU passes NUL-terminated strings valid for the call.
    unsafe { CStr::from_ptr(p as *const c_char) }.to_string_lossy().into_owned()
}

/// `fmi3LogMessageCallback`: the instance environment is the instance's [`LogSink`].
pub(crate) unsafe extern "C" fn log_message(
    environment: fmi3InstanceEnvironment,
    status: fmi3Status,
    category: fmi3String,
    message: fmi3String,
) {
    if environment.is_null() {
        return;
    }
    // no panic may cross the C boundary: a failure to record drops the message
    let _ = std::panic::catch_unwind(|| {
        // SAFETY: the environment is the instance's boxed LogSink, alive while it logs.
        let sink = unsafe { &*(environment as *const LogSink) };
        sink.push(LogRecord { status: Status::from_raw(status), category: text(category), message: text(message) });
    });
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
    fn the_view_holds_the_scalars_both_generations_have() {
        let md = fmi3::ModelDescription::from_xml(XML).unwrap();
        let (view, enumerations, left_out) = fmi2_view(&md);
        assert_eq!(left_out, vec!["f", "y", "n"]);
        let names: Vec<&str> = view.model_variables.iter().map(|v| v.name.as_str()).collect();
        assert_eq!(names, ["time", "x", "der(x)", "k", "e", "b", "z"]);
        assert_eq!(view.guid, "{tok}");
        assert_eq!(enumerations, HashSet::from([5]));
        let x = view.variable("x").unwrap();
        assert_eq!(x.variable_type.unit(), Some("m"), "from the declaredType");
        // der(x) is variable 3 of the view, its state x variable 2
        assert_eq!(view.variable("der(x)").unwrap().variable_type.derivative(), Some(2));
        assert_eq!(view.states(), vec![2]);
        assert_eq!(view.model_structure.outputs.len(), 1, "y is not in the view");
        let der = &view.model_structure.derivatives[0];
        // dependencies on x (index 2) and k (index 4) stay, with their kinds; f is gone
        assert_eq!(der.dependencies, Some(vec![2, 4]));
        assert_eq!(der.dependencies_kind, Some(vec![DependencyKind::Fixed, DependencyKind::Constant]));
        assert_eq!(view.number_of_event_indicators, 1);
        assert!(view.model_exchange.as_ref().is_some_and(|m| !m.completed_integrator_step_not_needed));
        // the item of 5e9 does not fit FMI 2.0's Integer
        assert_eq!(view.type_definitions[0].items.len(), 1);
        assert_eq!(view.variable("b").unwrap().variable_type, VariableType::Boolean { start: Some(true) });
    }

    #[test]
    fn clocks_and_scheduled_execution_are_named() {
        let md = fmi3::ModelDescription::from_xml(XML).unwrap();
        assert_eq!(unsupported_feature(&md), None);
        let clock = XML.replace(
            r#"<Float64 name="z" valueReference="9"/>"#,
            r#"<Float64 name="z" valueReference="9"/><Clock name="tick" valueReference="10" causality="input" intervalVariability="constant" intervalDecimal="0.1"/>"#,
        );
        let md = fmi3::ModelDescription::from_xml(&clock).unwrap();
        assert_eq!(unsupported_feature(&md).as_deref(), Some("clocks (Clock variable \"tick\")"));
        let se =
            XML.replace(r#"<ModelExchange modelIdentifier="m" needsCompletedIntegratorStep="true"/>"#, "").replace(
                r#"<CoSimulation modelIdentifier="m" canHandleVariableCommunicationStepSize="true"/>"#,
                r#"<ScheduledExecution modelIdentifier="m"/>"#,
            );
        let md = fmi3::ModelDescription::from_xml(&se).unwrap();
        assert!(unsupported_feature(&md).unwrap().starts_with("Scheduled Execution"));
    }

    #[test]
    fn resource_path_ends_in_a_separator() {
        let p = resource_path(std::path::Path::new("/tmp/nigel-cosim-x")).unwrap();
        assert_eq!(p.to_str().unwrap(), "/tmp/nigel-cosim-x/resources/");
    }
}

//! The FMI 3.0 writer: `modelDescription.xml` text in the element order of
//! `fmi3ModelDescription.xsd`, with the FMI 2.0 writer's escaping and number format
//! ([`crate::format_f64`]).

use super::*;
use crate::format_f64;
use crate::write::{
    document_attributes, item_elem, join_u32, write_log_categories_and_experiment, write_units, Elem, Out,
};

fn join<T>(values: &[T], f: impl Fn(&T) -> String) -> String {
    values.iter().map(f).collect::<Vec<_>>().join(" ")
}

/// The `start` attribute text of a numeric or Boolean start (space-separated for an array).
fn start_text(values: &Values) -> Option<String> {
    Some(match values {
        Values::Float(v) => join(v, |x| format_f64(*x)),
        Values::Int(v) => join(v, |x| x.to_string()),
        Values::Boolean(v) => join(v, |x| x.to_string()),
        Values::String(_) | Values::Binary(_) => return None,
    })
}

fn bound_text(b: &Bound) -> String {
    match b {
        Bound::Float(x) => format_f64(*x),
        Bound::Int(i) => i.to_string(),
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The interface element `name` (`<ModelExchange>`, `<CoSimulation>`,
/// `<ScheduledExecution>`) with the attributes the three share.
fn interface_elem(name: &'static str, c: &InterfaceCommon) -> Elem {
    let mut e = Elem::new(name);
    e.attr("modelIdentifier", &c.model_identifier)
        .flag("needsExecutionTool", c.needs_execution_tool)
        .flag("canBeInstantiatedOnlyOncePerProcess", c.can_be_instantiated_only_once_per_process)
        .flag("canGetAndSetFMUState", c.can_get_and_set_fmu_state)
        .flag("canSerializeFMUState", c.can_serialize_fmu_state)
        .flag("providesDirectionalDerivatives", c.provides_directional_derivatives)
        .flag("providesAdjointDerivatives", c.provides_adjoint_derivatives)
        .flag("providesPerElementDependencies", c.provides_per_element_dependencies);
    e
}

fn unknown_elem(name: &'static str, u: &Unknown) -> Elem {
    let mut e = Elem::new(name);
    e.attr("valueReference", &u.value_reference.to_string()).dependencies(&u.dependencies, &u.dependencies_kind);
    e
}

fn variable_elem(v: &Variable) -> Elem {
    let mut e = Elem::new(v.value_type.element());
    e.attr("name", &v.name)
        .attr("valueReference", &v.value_reference.to_string())
        .opt_str("description", &v.description);
    if v.causality != Causality::Local {
        e.attr("causality", v.causality.as_str());
    }
    e.attr("variability", v.variability.as_str());
    if let Some(init) = v.initial {
        e.attr("initial", init.as_str());
    }
    if let Some(m) = v.can_handle_multiple_set_per_time_instant {
        e.attr("canHandleMultipleSetPerTimeInstant", if m { "true" } else { "false" });
    }
    if !v.clocks.is_empty() {
        e.attr("clocks", &join_u32(&v.clocks));
    }
    e.flag("intermediateUpdate", v.intermediate_update)
        .opt_disp("previous", v.previous)
        .opt_str("declaredType", &v.declared_type)
        .opt_str("quantity", &v.quantity)
        .opt_str("unit", &v.unit)
        .opt_str("displayUnit", &v.display_unit)
        .flag("relativeQuantity", v.relative_quantity)
        .flag("unbounded", v.unbounded);
    if let Some(b) = &v.min {
        e.attr("min", &bound_text(b));
    }
    if let Some(b) = &v.max {
        e.attr("max", &bound_text(b));
    }
    e.opt_f64("nominal", v.nominal);
    if let Some(s) = v.start.as_ref().and_then(start_text) {
        e.attr("start", &s);
    }
    e.opt_disp("derivative", v.derivative).flag("reinit", v.reinit);
    e.opt_str("mimeType", &v.mime_type).opt_disp("maxSize", v.max_size);
    if let Some(c) = &v.clock {
        e.flag("canBeDeactivated", c.can_be_deactivated)
            .opt_disp("priority", c.priority)
            .opt_str("intervalVariability", &c.interval_variability)
            .opt_f64("intervalDecimal", c.interval_decimal)
            .opt_f64("shiftDecimal", c.shift_decimal)
            .flag("supportsFraction", c.supports_fraction)
            .opt_disp("resolution", c.resolution)
            .opt_disp("intervalCounter", c.interval_counter)
            .opt_disp("shiftCounter", c.shift_counter);
    }
    e
}

impl ModelDescription {
    /// Writes `modelDescription.xml` (FMI 3.0): UTF-8, two-space indentation, elements in
    /// the order fixed by `fmi3ModelDescription.xsd`, optional attributes only when set,
    /// capability flags only when true, `causality` omitted for `local` (its default),
    /// `variability` always. Equal descriptions give byte-identical output; floats parse
    /// back to the identical `f64` ([`format_f64`]).
    pub fn to_xml(&self) -> String {
        let mut o = Out::document();

        let mut root = Elem::new("fmiModelDescription");
        root.attr("fmiVersion", &self.fmi_version)
            .attr("modelName", &self.model_name)
            .attr("instantiationToken", &self.instantiation_token);
        document_attributes!(root, self);
        o.open(root);

        if let Some(me) = &self.model_exchange {
            let mut e = interface_elem("ModelExchange", &me.common);
            e.flag("needsCompletedIntegratorStep", me.needs_completed_integrator_step)
                .flag("providesEvaluateDiscreteStates", me.provides_evaluate_discrete_states);
            o.empty(e);
        }
        if let Some(cs) = &self.co_simulation {
            let mut e = interface_elem("CoSimulation", &cs.common);
            e.flag("canHandleVariableCommunicationStepSize", cs.can_handle_variable_communication_step_size)
                .opt_f64("fixedInternalStepSize", cs.fixed_internal_step_size);
            if cs.max_output_derivative_order != 0 {
                e.attr("maxOutputDerivativeOrder", &cs.max_output_derivative_order.to_string());
            }
            if cs.recommended_intermediate_input_smoothness != 0 {
                e.attr(
                    "recommendedIntermediateInputSmoothness",
                    &cs.recommended_intermediate_input_smoothness.to_string(),
                );
            }
            e.flag("providesIntermediateUpdate", cs.provides_intermediate_update)
                .flag("mightReturnEarlyFromDoStep", cs.might_return_early_from_do_step)
                .flag("canReturnEarlyAfterIntermediateUpdate", cs.can_return_early_after_intermediate_update)
                .flag("hasEventMode", cs.has_event_mode)
                .flag("providesEvaluateDiscreteStates", cs.provides_evaluate_discrete_states);
            o.empty(e);
        }
        if let Some(se) = &self.scheduled_execution {
            let e = interface_elem("ScheduledExecution", &se.common);
            o.empty(e);
        }

        write_units(&mut o, &self.unit_definitions);

        if !self.type_definitions.is_empty() {
            o.open(Elem::new("TypeDefinitions"));
            for t in &self.type_definitions {
                match &t.kind {
                    TypeKind::Float { value_type, quantity, unit, display_unit, min, max, nominal } => {
                        let mut e =
                            Elem::new(if *value_type == ValueType::Float32 { "Float32Type" } else { "Float64Type" });
                        e.attr("name", &t.name)
                            .opt_str("description", &t.description)
                            .opt_str("quantity", quantity)
                            .opt_str("unit", unit)
                            .opt_str("displayUnit", display_unit)
                            .opt_f64("min", *min)
                            .opt_f64("max", *max)
                            .opt_f64("nominal", *nominal);
                        o.empty(e);
                    }
                    TypeKind::Integer { value_type, quantity, min, max } => {
                        let element = match value_type {
                            ValueType::Int8 => "Int8Type",
                            ValueType::UInt8 => "UInt8Type",
                            ValueType::Int16 => "Int16Type",
                            ValueType::UInt16 => "UInt16Type",
                            ValueType::UInt32 => "UInt32Type",
                            ValueType::Int64 => "Int64Type",
                            ValueType::UInt64 => "UInt64Type",
                            _ => "Int32Type",
                        };
                        let mut e = Elem::new(element);
                        e.attr("name", &t.name)
                            .opt_str("description", &t.description)
                            .opt_str("quantity", quantity)
                            .opt_disp("min", *min)
                            .opt_disp("max", *max);
                        o.empty(e);
                    }
                    TypeKind::Enumeration { quantity, items } => {
                        let mut e = Elem::new("EnumerationType");
                        e.attr("name", &t.name).opt_str("description", &t.description).opt_str("quantity", quantity);
                        o.open(e);
                        for item in items {
                            o.empty(item_elem(&item.name, item.value, &item.description));
                        }
                        o.close("EnumerationType");
                    }
                    TypeKind::Other { value_type } => {
                        let element = match value_type {
                            ValueType::Boolean => "BooleanType",
                            ValueType::String => "StringType",
                            ValueType::Binary => "BinaryType",
                            _ => "ClockType",
                        };
                        let mut e = Elem::new(element);
                        e.attr("name", &t.name).opt_str("description", &t.description);
                        o.empty(e);
                    }
                }
            }
            o.close("TypeDefinitions");
        }

        write_log_categories_and_experiment(&mut o, &self.log_categories, self.default_experiment.as_ref());

        if o.open_unless_empty("ModelVariables", self.model_variables.is_empty()) {
            for v in &self.model_variables {
                let e = variable_elem(v);
                let starts: Vec<String> = match &v.start {
                    Some(Values::String(s)) => s.clone(),
                    Some(Values::Binary(b)) => b.iter().map(|b| hex(b)).collect(),
                    _ => Vec::new(),
                };
                if v.dimensions.is_empty() && starts.is_empty() && v.aliases.is_empty() {
                    o.empty(e);
                    continue;
                }
                o.open(e);
                for d in &v.dimensions {
                    let mut de = Elem::new("Dimension");
                    match d {
                        Dimension::Fixed(n) => de.attr("start", &n.to_string()),
                        Dimension::Variable(vr) => de.attr("valueReference", &vr.to_string()),
                    };
                    o.empty(de);
                }
                for s in &starts {
                    let mut se = Elem::new("Start");
                    se.attr("value", s);
                    o.empty(se);
                }
                for a in &v.aliases {
                    let mut ae = Elem::new("Alias");
                    ae.attr("name", &a.name);
                    if let Some(d) = &a.description {
                        ae.attr("description", d);
                    }
                    if let Some(u) = &a.display_unit {
                        ae.attr("displayUnit", u);
                    }
                    o.empty(ae);
                }
                o.close(v.value_type.element());
            }
            o.close("ModelVariables");
        }

        let ms = &self.model_structure;
        let lists: [(&'static str, &Vec<Unknown>); 5] = [
            ("Output", &ms.outputs),
            ("ContinuousStateDerivative", &ms.continuous_state_derivatives),
            ("ClockedState", &ms.clocked_states),
            ("InitialUnknown", &ms.initial_unknowns),
            ("EventIndicator", &ms.event_indicators),
        ];
        if lists.iter().all(|(_, l)| l.is_empty()) {
            o.empty(Elem::new("ModelStructure"));
        } else {
            o.open(Elem::new("ModelStructure"));
            for (name, list) in lists {
                for u in list {
                    o.empty(unknown_elem(name, u));
                }
            }
            o.close("ModelStructure");
        }

        o.close("fmiModelDescription");
        o.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> ModelDescription {
        let mut time = Variable::new("time", 0, ValueType::Float64, Causality::Independent, Variability::Continuous);
        time.description = Some("a <b> & \"c\"".into());
        let mut x = Variable::new("x", 1, ValueType::Float64, Causality::Output, Variability::Continuous);
        x.initial = Some(Initial::Exact);
        x.start = Some(Values::Float(vec![0.1]));
        x.unit = Some("m".into());
        x.min = Some(Bound::Float(f64::NEG_INFINITY));
        let mut dx = Variable::new("der(x)", 2, ValueType::Float64, Causality::Local, Variability::Continuous);
        dx.derivative = Some(1);
        let mut mode = Variable::new("mode", 3, ValueType::Enumeration, Causality::Parameter, Variability::Fixed);
        mode.declared_type = Some("Mode".into());
        mode.start = Some(Values::Int(vec![2]));
        mode.initial = Some(Initial::Exact);
        let mut s = Variable::new("label", 4, ValueType::String, Causality::Parameter, Variability::Fixed);
        s.start = Some(Values::String(vec!["a&b".into()]));
        ModelDescription {
            fmi_version: "3.0".into(),
            model_name: "m".into(),
            instantiation_token: "{t}".into(),
            co_simulation: Some(CoSimulation {
                common: InterfaceCommon {
                    model_identifier: "m".into(),
                    provides_adjoint_derivatives: true,
                    ..Default::default()
                },
                can_handle_variable_communication_step_size: true,
                ..Default::default()
            }),
            unit_definitions: vec![Unit { name: "m".into(), base_unit: Some(BaseUnit { m: 1, ..Default::default() }) }],
            type_definitions: vec![TypeDefinition {
                name: "Mode".into(),
                description: None,
                kind: TypeKind::Enumeration {
                    quantity: None,
                    items: vec![EnumerationItem { name: "a".into(), value: 2, description: None }],
                },
            }],
            default_experiment: Some(DefaultExperiment { stop_time: Some(0.1 + 0.2), ..Default::default() }),
            model_variables: vec![time, x, dx, mode, s],
            model_structure: ModelStructure {
                outputs: vec![Unknown { value_reference: 1, dependencies: Some(vec![1]), dependencies_kind: None }],
                continuous_state_derivatives: vec![Unknown {
                    value_reference: 2,
                    dependencies: Some(vec![]),
                    dependencies_kind: None,
                }],
                initial_unknowns: vec![Unknown { value_reference: 2, dependencies: None, dependencies_kind: None }],
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// The whole document, element by element, in the order of `fmi3ModelDescription.xsd`
    /// (interface, units, types, experiment, variables, structure), escaped, with the
    /// shortest round-trip floats.
    #[test]
    fn writes_the_schema_order_with_escaping_and_round_trip_floats() {
        let xml = small().to_xml();
        let expected = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="m" instantiationToken="{t}">
  <CoSimulation modelIdentifier="m" providesAdjointDerivatives="true" canHandleVariableCommunicationStepSize="true"/>
  <UnitDefinitions>
    <Unit name="m">
      <BaseUnit m="1"/>
    </Unit>
  </UnitDefinitions>
  <TypeDefinitions>
    <EnumerationType name="Mode">
      <Item name="a" value="2"/>
    </EnumerationType>
  </TypeDefinitions>
  <DefaultExperiment stopTime="0.30000000000000004"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" description="a &lt;b&gt; &amp; &quot;c&quot;" causality="independent" variability="continuous"/>
    <Float64 name="x" valueReference="1" causality="output" variability="continuous" initial="exact" unit="m" min="-INF" start="0.1"/>
    <Float64 name="der(x)" valueReference="2" variability="continuous" derivative="1"/>
    <Enumeration name="mode" valueReference="3" causality="parameter" variability="fixed" initial="exact" declaredType="Mode" start="2"/>
    <String name="label" valueReference="4" causality="parameter" variability="fixed">
      <Start value="a&amp;b"/>
    </String>
  </ModelVariables>
  <ModelStructure>
    <Output valueReference="1" dependencies="1"/>
    <ContinuousStateDerivative valueReference="2" dependencies=""/>
    <InitialUnknown valueReference="2"/>
  </ModelStructure>
</fmiModelDescription>
"#;
        assert_eq!(xml, expected);
        assert_eq!(small().to_xml(), xml, "deterministic");
    }
}

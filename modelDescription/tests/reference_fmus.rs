//! The reader on other tools' XML: FMI 2.0 Reference FMUs (tests/fixtures).

mod common;

use common::*;
use model_description::*;

#[test]
fn bouncing_ball() {
    let md = ModelDescription::from_xml(&fixture("BouncingBall.xml")).unwrap();
    assert_eq!(md.fmi_version, "2.0");
    assert_eq!(md.model_name, "BouncingBall");
    assert_eq!(md.guid, "{8c4e810f-3df3-4a00-8276-176fa3c9f003}");
    assert_eq!(md.number_of_event_indicators, 1);
    let me = md.model_exchange.as_ref().unwrap();
    assert_eq!(me.model_identifier, "BouncingBall");
    assert!(me.can_not_use_memory_management_functions && me.can_get_and_set_fmu_state && me.can_serialize_fmu_state);
    assert!(!me.provides_directional_derivative);
    let cs = md.co_simulation.as_ref().unwrap();
    assert!(cs.can_handle_variable_communication_step_size);
    assert_eq!(md.unit_definitions.len(), 3);
    assert_eq!(md.unit_definitions[2].base_unit, Some(BaseUnit { m: 1, s: -2, ..BaseUnit::default() }));
    assert_eq!(md.log_categories.len(), 2);
    assert_eq!(
        md.default_experiment,
        Some(DefaultExperiment { start_time: Some(0.0), stop_time: Some(3.0), tolerance: None, step_size: Some(1e-3) })
    );
    assert_eq!(md.model_variables.len(), 7);

    // Units come from the declaredType (TypeDefinitions is otherwise skipped).
    let h = md.variable("h").unwrap();
    assert_eq!(h.causality, Causality::Output);
    assert_eq!(h.initial, Some(Initial::Exact));
    assert_eq!(h.description.as_deref(), Some("Position of the ball"));
    assert_eq!(
        h.variable_type,
        VariableType::Real {
            start: Some(1.0),
            unit: Some("m".into()),
            derivative: None,
            min: None,
            max: None,
            nominal: None
        }
    );
    assert_eq!(md.variable("der(v)").unwrap().variable_type.unit(), Some("m/s2"));
    // v_min has no causality attribute: local.
    let v_min = md.variable("v_min").unwrap();
    assert_eq!((v_min.causality, v_min.variability, v_min.initial), (Causality::Local, Variability::Constant, None));
    let e = md.variable("e").unwrap();
    assert!(matches!(e.variable_type, VariableType::Real { min: Some(0.5), max: Some(1.0), start: Some(0.7), .. }));

    assert_eq!(md.index_of("v"), Some(3));
    assert_eq!(md.real_value_reference("g"), Some(5));
    // The quirk: the parameter g carries derivative="2" (of der(h)); it is not a state derivative.
    assert_eq!(md.variable("g").unwrap().variable_type.derivative(), Some(2));
    assert_eq!(md.state_derivatives(), vec![2, 4]);
    assert_eq!(md.states(), vec![1, 3]);

    let ms = &md.model_structure;
    assert_eq!(ms.outputs.iter().map(|u| u.index).collect::<Vec<_>>(), vec![1, 3]);
    assert_eq!(ms.outputs[0].dependencies, None);
    assert_eq!(ms.derivatives.iter().map(|u| u.index).collect::<Vec<_>>(), vec![2, 4]);
    assert_eq!(ms.initial_unknowns[1], unknown(4, Some(vec![5]), Some(vec![DependencyKind::Constant])));

    assert_eq!(md.validate(), vec![], "BouncingBall should validate");
}

#[test]
fn van_der_pol() {
    let md = ModelDescription::from_xml(&fixture("VanDerPol.xml")).unwrap();
    assert_eq!(md.model_name, "Van der Pol oscillator");
    assert!(md.unit_definitions.is_empty());
    assert_eq!(md.states(), vec![1, 3]);
    let ms = &md.model_structure;
    // dependencies="" is "depends on nothing", not absent.
    assert_eq!(ms.outputs[0].dependencies, Some(vec![]));
    assert_eq!(ms.outputs[0].dependencies_kind, None);
    assert_eq!(
        ms.derivatives[1],
        unknown(4, Some(vec![1, 3]), Some(vec![DependencyKind::Dependent, DependencyKind::Dependent]))
    );
    assert_eq!(ms.initial_unknowns[1].dependencies, Some(vec![1, 3, 5]));
    assert_eq!(md.validate(), vec![]);
}

#[test]
fn feedthrough() {
    // Declares encoding="ISO-8859-1" (its content is ASCII); all four base types.
    let md = ModelDescription::from_xml(&fixture("Feedthrough.xml")).unwrap();
    assert_eq!(md.model_variables.len(), 11);
    // Absent variability means continuous, absent causality means local.
    let rci = md.variable("real_continuous_in").unwrap();
    assert_eq!((rci.causality, rci.variability), (Causality::Input, Variability::Continuous));
    assert_eq!(rci.description.as_deref(), Some(""));
    assert_eq!(
        md.variable("int_in").unwrap().variable_type,
        VariableType::Integer { start: Some(0), min: None, max: None }
    );
    assert_eq!(md.variable("bool_in").unwrap().variable_type, VariableType::Boolean { start: Some(false) });
    assert_eq!(
        md.variable("string_param").unwrap().variable_type,
        VariableType::String { start: Some("Set me!".into()) }
    );
    assert_eq!(
        md.variable("int_out").unwrap().variable_type,
        VariableType::Integer { start: None, min: None, max: None }
    );
    assert_eq!(md.default_experiment.as_ref().unwrap().stop_time, Some(2.0));
    assert!(md.model_structure.derivatives.is_empty());
    assert_eq!(md.real_value_reference("int_in"), None); // not Real

    // The quirk: Outputs says real_continuous_out (4) depends on index 1, the parameter
    // real_fixed_param, which is not a known for Outputs (inputs, states, time).
    let problems = md.validate();
    assert_eq!(problems.len(), 1, "{problems:#?}");
    assert_eq!(problems[0].rule, Rule::DependencyNotKnown);
    assert_eq!(problems[0].variable.as_deref(), Some("real_continuous_out"));
    assert!(problems[0].to_string().contains("\"real_fixed_param\""), "{}", problems[0]);
}

#[test]
fn reference_fmus_survive_our_writer() {
    for f in ["BouncingBall.xml", "VanDerPol.xml", "Feedthrough.xml"] {
        let md = ModelDescription::from_xml(&fixture(f)).unwrap();
        let xml = md.to_xml();
        let back = ModelDescription::from_xml(&xml).unwrap_or_else(|e| panic!("{f}: {e}\n{xml}"));
        assert_eq!(back, md, "{f}");
        assert_eq!(back.to_xml(), xml, "{f}");
    }
}

#[test]
fn tolerant_of_order_whitespace_comments_and_unknown_elements() {
    let xml = r#"<?xml version="1.0" encoding="UTF-8"?>
<!-- leading comment -->
<fmiModelDescription xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
    guid  =  '{g}'   modelName="M" fmiVersion="2.0" someToolAttribute="x">
  <?some-pi data?>
  <ModelStructure>
    <InitialUnknowns><Unknown dependencies="  " index=" 2 "/></InitialUnknowns>
    <Outputs>
      <!-- comment inside -->
      <Unknown index="2" dependenciesKind="dependent" dependencies="1"/>
    </Outputs>
  </ModelStructure>
  <VendorAnnotations><Tool name="t"><Deep><Deeper><Deepest a="1"/></Deeper></Deep></Tool></VendorAnnotations>
  <ModelVariables>
    <ScalarVariable valueReference="7" name="in" causality="input">
      <Annotations><Tool name="x"/></Annotations>
      <Real start="1.5E0" unit="u" relativeQuantity="false"/>
    </ScalarVariable>
    <ScalarVariable name="out" causality="output" valueReference="8" initial="calculated"><Real/></ScalarVariable>
  </ModelVariables>
  <TypeDefinitions><SimpleType name="T"><Real unit="v" min="0"/></SimpleType></TypeDefinitions>
  <UnitDefinitions><Unit name="u"><BaseUnit factor="2"/><DisplayUnit name="d"/></Unit></UnitDefinitions>
  <CoSimulation modelIdentifier="M" canHandleVariableCommunicationStepSize="1"><SourceFiles><File name="a.c"/></SourceFiles></CoSimulation>
  <UnknownFutureElement/>
</fmiModelDescription>
<!-- trailing comment -->
"#;
    let md = ModelDescription::from_xml(xml).unwrap();
    assert_eq!(md.model_name, "M");
    assert_eq!(md.guid, "{g}");
    assert!(md.co_simulation.as_ref().unwrap().can_handle_variable_communication_step_size);
    assert_eq!(md.unit_definitions[0].base_unit.as_ref().unwrap().factor, 2.0);
    assert_eq!(md.model_variables[0].value_reference, 7);
    assert!(matches!(md.model_variables[0].variable_type, VariableType::Real { start: Some(s), .. } if s == 1.5));
    assert_eq!(md.model_structure.outputs, vec![unknown(2, Some(vec![1]), Some(vec![DependencyKind::Dependent]))]);
    assert_eq!(md.model_structure.initial_unknowns, vec![unknown(2, Some(vec![]), None)]);
    assert_eq!(md.validate(), vec![]);
}

#[test]
fn declared_type_defaults_and_enumerations() {
    let xml = r#"<fmiModelDescription fmiVersion="2.0" modelName="M" guid="g">
  <TypeDefinitions>
    <SimpleType name="Angle"><Real unit="rad" min="-3.5" max="3.5" nominal="2"/></SimpleType>
    <SimpleType name="Count"><Integer min="0" max="9"/></SimpleType>
    <SimpleType name="Mode"><Enumeration><Item name="a" value="1"/><Item name="b" value="2"/></Enumeration></SimpleType>
  </TypeDefinitions>
  <ModelVariables>
    <ScalarVariable name="a" valueReference="0"><Real declaredType="Angle" max="1"/></ScalarVariable>
    <ScalarVariable name="n" valueReference="0" variability="discrete"><Integer declaredType="Count"/></ScalarVariable>
    <ScalarVariable name="mode" valueReference="1" variability="discrete" causality="parameter"><Enumeration declaredType="Mode" start="2"/></ScalarVariable>
    <ScalarVariable name="x" valueReference="1"><Real declaredType="NoSuchType"/></ScalarVariable>
  </ModelVariables>
</fmiModelDescription>"#;
    let md = ModelDescription::from_xml(xml).unwrap();
    assert_eq!(
        md.model_variables[0].variable_type,
        VariableType::Real {
            start: None,
            unit: Some("rad".into()),
            derivative: None,
            min: Some(-3.5),
            max: Some(1.0),
            nominal: Some(2.0)
        }
    );
    assert_eq!(md.model_variables[1].variable_type, VariableType::Integer { start: None, min: Some(0), max: Some(9) });
    assert_eq!(
        md.model_variables[2].variable_type,
        VariableType::Enumeration { declared_type: "Mode".into(), start: Some(2), min: None, max: None }
    );
    assert_eq!(md.type_definitions.len(), 1, "only the enumeration is kept as a type");
    assert_eq!(md.type_definitions[0].item(2).map(|i| i.name.as_str()), Some("b"));
    assert_eq!(md.model_variables[3].variable_type.unit(), None);
}

//! The FMI 3.0 reader and validation on documents written from the FMI 3.0.2 standard
//! (sections 2.4.x): every interface type, every variable type, arrays with fixed and
//! structural-parameter dimensions, the ModelStructure; and what must be refused.

use model_description::fmi3::*;
use model_description::{DependencyKind, Initial, Variability};

/// A bouncing ball (Model Exchange and Co-Simulation; two states, one event indicator).
const BALL: &str = include_str!("fixtures/fmi3_ball.xml");

/// One variable of every type, scalars and arrays, a structural parameter sizing an array.
const TYPES: &str = include_str!("fixtures/fmi3_types.xml");

fn read(xml: &str) -> ReadError {
    ModelDescription::from_xml(xml).expect_err("must be refused")
}

fn rules(md: &ModelDescription) -> Vec<Rule> {
    md.validate().into_iter().map(|p| p.rule).collect()
}

#[test]
fn ball_reads_every_section() {
    let md = ModelDescription::from_xml(BALL).unwrap();
    assert_eq!(md.validate(), vec![], "a valid description");
    assert_eq!(md.fmi_version, "3.0");
    assert_eq!(md.instantiation_token, "{1b2e6c1a-0000-4000-8000-000000000001}");
    assert_eq!(md.variable_naming_convention.as_deref(), Some("flat"));
    let me = md.model_exchange.as_ref().unwrap();
    assert!(
        me.common.can_get_and_set_fmu_state && me.common.can_serialize_fmu_state && !me.needs_completed_integrator_step
    );
    let cs = md.co_simulation.as_ref().unwrap();
    assert_eq!(cs.common.model_identifier, "ball");
    assert!(cs.can_handle_variable_communication_step_size && cs.has_event_mode && cs.might_return_early_from_do_step);
    assert_eq!(cs.fixed_internal_step_size, Some(1e-3));
    assert!(md.scheduled_execution.is_none());
    assert_eq!(md.unit_definitions.len(), 4);
    assert_eq!(md.unit_definitions[1].base_unit.as_ref().unwrap().s, -1);
    assert_eq!(md.log_categories[0].name, "logEvents");
    assert_eq!(md.default_experiment.as_ref().unwrap().stop_time, Some(3.0));
    assert_eq!(md.model_variables.len(), 9);

    let time = md.variable(0).unwrap();
    assert_eq!(
        (time.causality, time.value_type, time.variability),
        (Causality::Independent, ValueType::Float64, Variability::Continuous)
    );
    let h = md.variable_by_name("h").unwrap();
    assert_eq!(h.start, Some(Values::Float(vec![1.0])));
    assert_eq!(h.initial, Some(Initial::Exact));
    assert_eq!(h.unit, None, "read as written");
    assert_eq!(md.unit_of(h), Some("m"), "from the declaredType");
    assert!(md.variable(3).unwrap().reinit);
    // Absent causality and variability: local, continuous (Float).
    let ind = md.variable_by_name("h_indicator").unwrap();
    assert_eq!((ind.causality, ind.variability), (Causality::Local, Variability::Continuous));
    let e = md.variable(6).unwrap();
    assert_eq!((e.min, e.max), (Some(Bound::Float(0.5)), Some(Bound::Float(1.0))));

    assert_eq!(md.states(), vec![1, 3]);
    let ms = &md.model_structure;
    assert_eq!(ms.outputs.iter().map(|u| u.value_reference).collect::<Vec<_>>(), vec![1, 3]);
    assert_eq!(ms.continuous_state_derivatives[1].dependencies, Some(vec![5]));
    assert_eq!(ms.continuous_state_derivatives[1].dependencies_kind, Some(vec![DependencyKind::Constant]));
    assert_eq!(ms.continuous_state_derivatives[0].dependencies, None, "absent: depends on all knowns");
    assert_eq!(ms.initial_unknowns.len(), 2);
    assert_eq!(ms.event_indicators[0].value_reference, 8);
}

#[test]
fn every_type_and_arrays() {
    let md = ModelDescription::from_xml(TYPES).unwrap();
    assert_eq!(md.validate(), vec![]);
    let start = |name: &str| md.variable_by_name(name).unwrap().start.clone().unwrap();
    // 0.1 as Float32, widened: the FMU holds the f32 nearest to 0.1, not the f64.
    assert_eq!(start("f32"), Values::Float(vec![0.1f32 as f64]));
    assert_ne!(0.1f32 as f64, 0.1);
    assert_eq!(start("i8"), Values::Int(vec![-128]));
    assert_eq!(start("u8"), Values::Int(vec![255]));
    assert_eq!(start("u16"), Values::Int(vec![65535]));
    assert_eq!(start("i32"), Values::Int(vec![i32::MIN as i128]));
    assert_eq!(start("u32"), Values::Int(vec![u32::MAX as i128]));
    assert_eq!(start("i64"), Values::Int(vec![i64::MIN as i128]));
    assert_eq!(start("u64"), Values::Int(vec![u64::MAX as i128]));
    assert_eq!(start("b"), Values::Boolean(vec![true]));
    assert_eq!(start("s"), Values::String(vec!["a & b".into()]));
    assert_eq!(start("bin"), Values::Binary(vec![vec![0x00, 0xff, 0x10]]));
    assert_eq!(md.variable_by_name("bin").unwrap().max_size, Some(4));
    assert_eq!(start("mode"), Values::Int(vec![4]));
    assert_eq!(md.variable_by_name("i8").unwrap().min, Some(Bound::Int(-128)));
    // Integer and other non-Float variables default to discrete.
    assert_eq!(md.variable_by_name("i16").unwrap().variability, Variability::Discrete);

    let y = md.variable(21).unwrap();
    assert_eq!(y.dimensions, vec![Dimension::Variable(20)]);
    assert_eq!(md.element_count(y), Some(3));
    let a = md.variable(22).unwrap();
    assert_eq!(a.dimensions, vec![Dimension::Fixed(2), Dimension::Variable(20)]);
    assert_eq!(md.element_count(a), Some(6));
    assert_eq!(a.start, Some(Values::Float(vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0])));
    assert_eq!(start("flags"), Values::Boolean(vec![true, false, true]));
    assert_eq!(start("names"), Values::String(vec!["x".into(), String::new()]));
    assert_eq!(md.element_count(md.variable(1).unwrap()), Some(1), "a scalar has one element");

    let mode = md.type_definition("Mode").unwrap();
    let TypeKind::Enumeration { items, .. } = &mode.kind else { panic!("{mode:?}") };
    assert_eq!(items.iter().map(|i| (i.name.as_str(), i.value)).collect::<Vec<_>>(), vec![("off", -1), ("on", 4)]);
    assert_eq!(
        md.type_definition("Count").unwrap().kind,
        TypeKind::Integer { value_type: ValueType::Int16, quantity: None, min: Some(0), max: Some(100) }
    );
}

#[test]
fn fmi_version_of_picks_the_reader() {
    assert_eq!(fmi_version_of(BALL).as_deref(), Some("3.0"));
    assert_eq!(fmi_version_of(r#"<fmiModelDescription fmiVersion=" 2.0 " guid="g"/>"#).as_deref(), Some("2.0"));
    assert_eq!(fmi_version_of("<other fmiVersion='3.0'/>"), None);
    assert_eq!(fmi_version_of("<fmiModelDescription/>"), None);
    assert_eq!(fmi_version_of("not xml <"), None);
}

#[test]
fn wrong_generation_is_refused_both_ways() {
    let e = read(r#"<fmiModelDescription fmiVersion="2.0" modelName="m" guid="g"/>"#);
    let ReadError::UnsupportedFmiVersion { found, expected, .. } = &e else { panic!("{e:?}") };
    assert_eq!((found.as_str(), *expected), ("2.0", "3.0"));
    let e = model_description::ModelDescription::from_xml(BALL).unwrap_err();
    assert!(matches!(&e, ReadError::UnsupportedFmiVersion { found, .. } if found == "3.0"), "{e:?}");
    assert!(e.to_string().contains("only \"2.0\""), "{e}");
    // not a version: refused naming what the FMI 3.0 reader takes
    let e = read(r#"<fmiModelDescription fmiVersion="3.0abc" modelName="m" instantiationToken="t"/>"#);
    let text = e.to_string();
    assert!(text.contains("fmiVersion=\"3.0abc\"") && text.contains("a later minor version such as \"3.1\""), "{text}");
}

#[test]
fn unknown_variable_and_type_elements_are_refused_by_name() {
    let xml = BALL.replace(
        r#"<Float64 name="h_indicator" valueReference="8"/>"#,
        r#"<Real name="h_indicator" valueReference="8"/>"#,
    );
    let e = read(&xml);
    let ReadError::UnknownElement { element, parent, position } = &e else { panic!("{e:?}") };
    assert_eq!((element.as_str(), parent.as_str()), ("Real", "ModelVariables"));
    assert_eq!(position.byte, xml.find("<Real").unwrap());
    assert!(e.to_string().contains("unknown element <Real> in <ModelVariables>"), "{e}");

    let e = read(&BALL.replace("<Float64Type name=\"Velocity\"", "<Float128Type name=\"Velocity\""));
    assert!(
        matches!(&e, ReadError::UnknownElement { element, parent, .. } if element == "Float128Type" && parent == "TypeDefinitions"),
        "{e:?}"
    );
    let e = read(&BALL.replace("<EventIndicator ", "<Derivative "));
    assert!(matches!(&e, ReadError::UnknownElement { element, .. } if element == "Derivative"), "{e:?}");
}

#[test]
fn numbers_outside_their_type_are_refused() {
    for (from, to, attribute) in [
        ("start=\"-128\" min", "start=\"-129\" min", "start"),
        ("start=\"255\"", "start=\"256\"", "start"),
        ("start=\"18446744073709551615\"", "start=\"18446744073709551616\"", "start"),
        ("start=\"4294967295\"", "start=\"-1\"", "start"),
        ("start=\"0.1\"", "start=\"1e39\"", "start"),
        ("start=\"true\"", "start=\"yes\"", "start"),
        ("<Start value=\"00ff10\"/>", "<Start value=\"0ff\"/>", "value"),
        ("start=\"1 2 3 4 5 6\"", "start=\"1 2 x 4 5 6\"", "start"),
        ("<Dimension start=\"2\"/>", "<Dimension start=\"-2\"/>", "start"),
        ("value=\"-1\"", "value=\"one\"", "value"),
        ("maxSize=\"4\"", "maxSize=\"big\"", "maxSize"),
        ("valueReference=\"13\"", "valueReference=\"-13\"", "valueReference"),
    ] {
        assert!(TYPES.contains(from), "{from}");
        let e = read(&TYPES.replacen(from, to, 1));
        match &e {
            ReadError::BadNumber { attribute: a, .. } | ReadError::UnknownEnumValue { attribute: a, .. } => {
                assert_eq!(a, attribute, "{to}: {e}")
            }
            _ => panic!("{to}: {e:?}"),
        }
    }
}

#[test]
fn structural_errors_are_refused() {
    let e = read(&TYPES.replace("<Dimension start=\"3\"/>", "<Dimension/>"));
    assert!(matches!(&e, ReadError::Invalid { message, .. } if message.contains("neither")), "{e:?}");
    let e = read(&TYPES.replace("<Dimension start=\"3\"/>", "<Dimension start=\"3\" valueReference=\"20\"/>"));
    assert!(matches!(&e, ReadError::Invalid { message, .. } if message.contains("both")), "{e:?}");
    let e = read(&TYPES.replace(" declaredType=\"Mode\"", ""));
    assert!(matches!(&e, ReadError::MissingAttribute { attribute, .. } if attribute == "declaredType"), "{e:?}");
    let e = read(&BALL.replace("instantiationToken=", "guid="));
    assert!(matches!(&e, ReadError::MissingAttribute { attribute, .. } if attribute == "instantiationToken"), "{e:?}");
    let e = read(&BALL.replace(r#"<Float64 name="g" valueReference="5""#, r#"<Float64 name="g""#));
    assert!(
        matches!(&e, ReadError::MissingAttribute { element, attribute, .. } if element == "Float64 \"g\"" && attribute == "valueReference"),
        "{e:?}"
    );
    let e = read(&BALL.replace("</ModelStructure>", "</ModelStructure><ModelStructure/>"));
    assert!(matches!(&e, ReadError::DuplicateElement { element, .. } if element == "ModelStructure"), "{e:?}");
    let e = read(
        &BALL.replace("causality=\"parameter\" variability=\"fixed\"", "causality=\"param\" variability=\"fixed\""),
    );
    assert!(matches!(&e, ReadError::UnknownEnumValue { value, .. } if value == "param"), "{e:?}");
}

#[test]
fn malformed_xml_is_refused_with_its_position() {
    let bad = BALL.replacen("<Output valueReference=\"1\"/>", "<Output valueReference=\"1\">", 1);
    assert!(matches!(read(&bad), ReadError::Xml { .. }));
    let bad = BALL.replacen("valueReference=\"5\"", "valueReference=\"5\" valueReference=\"6\"", 1);
    let e = read(&bad);
    let g = bad.find("<Float64 name=\"g\"").unwrap();
    assert!(
        matches!(&e, ReadError::Xml { position, .. } if position.byte == g),
        "duplicate attribute at its tag: {e:?}"
    );
    let cut = &BALL[..BALL.find("</ModelVariables>").unwrap()];
    assert!(matches!(read(cut), ReadError::UnexpectedEof { element, .. } if element == "ModelVariables"));
    assert!(matches!(read(""), ReadError::NotAModelDescription { found: None, .. }));
    // Every prefix is refused or read, never a panic.
    for end in (0..BALL.len()).filter(|&i| BALL.is_char_boundary(i)).step_by(7) {
        let _ = ModelDescription::from_xml(&BALL[..end]);
    }
}

#[test]
fn deep_nesting_does_not_overflow() {
    let depth = 200_000;
    let xml = BALL.replace(
        "<ModelVariables>",
        &format!("<ModelVariables><Annotations>{}{}</Annotations>", "<a>".repeat(depth), "</a>".repeat(depth)),
    );
    assert_eq!(ModelDescription::from_xml(&xml).unwrap().model_variables.len(), 9);
}

#[test]
fn validation_finds_what_importers_refuse() {
    let base = ModelDescription::from_xml(TYPES).unwrap();
    let mut md = base.clone();
    md.model_variables[2].value_reference = 1; // u8 takes f32's value reference (other type)
    assert_eq!(rules(&md), vec![Rule::DuplicateValueReference]);
    let problem = &md.validate()[0];
    assert_eq!(
        problem.to_string(),
        "[duplicate-value-reference] variable \"i8\": valueReference 1 is also used by \"f32\""
    );

    let mut md = base.clone();
    md.model_variables[0].causality = Causality::Local;
    assert_eq!(rules(&md), vec![Rule::Independent], "no independent variable");
    let mut md = base.clone();
    let mut second = md.model_variables[0].clone();
    second.name = "t2".into();
    second.value_reference = 101;
    md.model_variables.push(second);
    assert_eq!(rules(&md), vec![Rule::Independent], "two");

    let mut md = base.clone();
    md.model_structure.outputs[0].value_reference = 99;
    assert_eq!(rules(&md), vec![Rule::UnknownValueReference, Rule::Outputs]);
    let mut md = base.clone();
    md.model_structure.outputs[0].dependencies = Some(vec![22, 77]);
    assert_eq!(rules(&md), vec![Rule::UnknownValueReference]);

    // Dimension naming a Float parameter, or nothing.
    let mut md = base.clone();
    md.model_variables.iter_mut().find(|v| v.name == "y").unwrap().dimensions = vec![Dimension::Variable(22)];
    assert_eq!(rules(&md), vec![Rule::Dimension]);
    let mut md = base.clone();
    md.model_variables.iter_mut().find(|v| v.name == "y").unwrap().dimensions = vec![Dimension::Variable(55)];
    assert_eq!(rules(&md), vec![Rule::Dimension]);

    // 6 start values for 2 x 4 elements once n = 4.
    let mut md = base.clone();
    md.model_variables.iter_mut().find(|v| v.name == "n").unwrap().start = Some(Values::Int(vec![4]));
    assert_eq!(rules(&md), vec![Rule::StartCount]);
    let mut md = base.clone();
    md.model_variables[1].start = Some(Values::Float(vec![1.0, 2.0]));
    assert_eq!(rules(&md), vec![Rule::StartCount], "two start values for a scalar");

    let mut md = base.clone();
    md.model_variables[4].declared_type = Some("Nope".into());
    assert_eq!(rules(&md), vec![Rule::DeclaredType]);
    let mut md = base.clone();
    md.model_variables[4].declared_type = Some("Mode".into());
    assert_eq!(rules(&md), vec![Rule::DeclaredType], "an Int16 declaring an EnumerationType");
    let mut md = base.clone();
    md.model_variables.iter_mut().find(|v| v.name == "mode").unwrap().start = Some(Values::Int(vec![0]));
    assert_eq!(rules(&md), vec![Rule::DeclaredType], "start is no item");

    let mut md = base.clone();
    md.model_variables[3].start = None;
    assert_eq!(rules(&md), vec![Rule::StartRequired], "an input needs a start value");
    let mut md = base.clone();
    md.model_variables[3].variability = Variability::Continuous;
    assert_eq!(rules(&md), vec![Rule::ContinuousNonFloat]);
    let mut md = base.clone();
    md.co_simulation = None;
    assert_eq!(rules(&md), vec![Rule::NoInterface]);
    let mut md = base;
    md.co_simulation.as_mut().unwrap().common.model_identifier = "1x".into();
    assert_eq!(rules(&md), vec![Rule::ModelIdentifier]);
}

#[test]
fn validation_of_the_ball_structure() {
    let base = ModelDescription::from_xml(BALL).unwrap();
    let mut md = base.clone();
    md.model_variables[2].derivative = Some(42);
    assert_eq!(rules(&md), vec![Rule::Derivative]);
    let mut md = base.clone();
    md.model_variables[2].derivative = Some(5); // g: a fixed parameter, not a state
    assert_eq!(rules(&md), vec![Rule::Derivative]);
    let mut md = base.clone();
    md.model_structure.continuous_state_derivatives[0].value_reference = 8;
    // h_indicator is no derivative; der(h), no longer listed as one, need not be an initial unknown.
    assert_eq!(rules(&md), vec![Rule::ContinuousStateDerivatives, Rule::InitialUnknowns]);
    let mut md = base.clone();
    md.model_structure.initial_unknowns.pop();
    assert_eq!(rules(&md), vec![Rule::InitialUnknowns], "der(v) (initial calculated) missing");
    let mut md = base.clone();
    md.model_structure.initial_unknowns.push(md.model_structure.initial_unknowns[0].clone());
    assert_eq!(rules(&md), vec![Rule::InitialUnknowns], "listed twice");
    let mut md = base.clone();
    md.model_structure.event_indicators[0].value_reference = 5;
    assert_eq!(rules(&md), vec![Rule::EventIndicators]);
    let mut md = base.clone();
    md.model_structure.outputs.reverse();
    assert_eq!(rules(&md), vec![Rule::Outputs]);
    let mut md = base.clone();
    md.model_variables[6].start = Some(Values::Float(vec![1.5]));
    assert_eq!(rules(&md), vec![Rule::Bounds]);
    let mut md = base.clone();
    md.model_variables[0].start = Some(Values::Float(vec![0.0]));
    assert_eq!(rules(&md), vec![Rule::StartForbidden]);
    let mut md = base.clone();
    md.model_variables[5].unit = Some("N".into());
    assert_eq!(rules(&md), vec![Rule::UndeclaredUnit]);
    let mut md = base;
    md.model_variables[5].name = "e".into();
    assert_eq!(rules(&md), vec![Rule::DuplicateName]);
}

#[test]
fn round_trip_through_the_writer() {
    for xml in [BALL, TYPES] {
        let md = ModelDescription::from_xml(xml).unwrap();
        let written = md.to_xml();
        assert_eq!(ModelDescription::from_xml(&written).unwrap(), md, "{written}");
    }
}

//! Writer tests: round trip, determinism, element order, number formatting, escaping.

mod common;

use common::*;
use model_description::*;

#[test]
fn rich_description_round_trips() {
    let md = rich();
    let xml = md.to_xml();
    let back = ModelDescription::from_xml(&xml).unwrap_or_else(|e| panic!("{e}\n{xml}"));
    assert_eq!(back, md);
    // And writing the read-back copy gives the same bytes.
    assert_eq!(back.to_xml(), xml);
}

fn with_enumeration() -> ModelDescription {
    let mut md = minimal();
    md.type_definitions.push(EnumerationType {
        name: "Gear".into(),
        description: Some("gear box position".into()),
        items: vec![
            EnumerationItem { name: "reverse".into(), value: -1, description: None },
            EnumerationItem { name: "neutral".into(), value: 0, description: Some("no drive".into()) },
            EnumerationItem { name: "first".into(), value: 1, description: None },
        ],
    });
    md.model_variables.push(ScalarVariable {
        name: "gear".into(),
        value_reference: 77,
        description: None,
        causality: Causality::Parameter,
        variability: Variability::Fixed,
        initial: Some(Initial::Exact),
        variable_type: VariableType::Enumeration { declared_type: "Gear".into(), start: Some(0), min: None, max: None },
    });
    md
}

#[test]
fn enumeration_types_and_variables_round_trip_and_validate() {
    let md = with_enumeration();
    assert!(md.validate().is_empty(), "{:?}", md.validate());
    let xml = md.to_xml();
    assert!(xml.contains("<TypeDefinitions>"), "{xml}");
    assert!(xml.contains(r#"<Item name="reverse" value="-1"/>"#), "{xml}");
    assert!(xml.contains(r#"<Enumeration declaredType="Gear" start="0"/>"#), "{xml}");
    // TypeDefinitions sit between UnitDefinitions and LogCategories (schema order).
    let pos = |s: &str| xml.find(s).unwrap_or(usize::MAX);
    assert!(pos("<TypeDefinitions>") < pos("<ModelVariables>"));
    assert_eq!(ModelDescription::from_xml(&xml).unwrap(), md);

    let mut bad = with_enumeration();
    if let VariableType::Enumeration { start, .. } = &mut bad.model_variables.last_mut().unwrap().variable_type {
        *start = Some(5);
    }
    let problems = bad.validate();
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert_eq!(problems[0].rule, Rule::DeclaredType);
    assert!(problems[0].to_string().contains("start=5"), "{}", problems[0]);
    let mut bad = with_enumeration();
    bad.type_definitions[0].items[2].value = 0;
    assert!(bad.validate().iter().any(|p| p.rule == Rule::DeclaredType && p.to_string().contains("not unique")));
    let mut bad = with_enumeration();
    bad.type_definitions[0].name = "Other".into();
    assert!(bad.validate().iter().any(|p| p.to_string().contains("declaredType \"Gear\"")));
}

#[test]
fn minimal_description_round_trips() {
    let md = minimal();
    let xml = md.to_xml();
    assert_eq!(ModelDescription::from_xml(&xml).unwrap(), md);
}

#[test]
fn empty_model_variables_and_structure_round_trip() {
    let mut md = minimal();
    md.model_variables.clear();
    let xml = md.to_xml();
    assert!(xml.contains("<ModelVariables/>"), "{xml}");
    assert!(xml.contains("<ModelStructure/>"), "{xml}");
    assert_eq!(ModelDescription::from_xml(&xml).unwrap(), md);
}

#[test]
fn writes_are_byte_identical() {
    let a = rich().to_xml();
    let b = rich().to_xml();
    assert_eq!(a.as_bytes(), b.as_bytes());
    assert_eq!(rich().clone().to_xml(), a);
}

#[test]
fn header_and_declaration() {
    let xml = rich().to_xml();
    assert!(xml.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiModelDescription "), "{xml}");
    assert!(xml.ends_with("</fmiModelDescription>\n"));
}

fn positions(xml: &str, needles: &[&str]) -> Vec<usize> {
    needles.iter().map(|n| xml.find(n).unwrap_or_else(|| panic!("{n} missing in\n{xml}"))).collect()
}

#[test]
fn element_order_follows_the_xsd() {
    let xml = rich().to_xml();
    let order = [
        "<fmiModelDescription",
        "<ModelExchange",
        "<CoSimulation",
        "<UnitDefinitions>",
        "<LogCategories>",
        "<DefaultExperiment",
        "<ModelVariables>",
        "<ModelStructure>",
        "<Outputs>",
        "<Derivatives>",
        "<InitialUnknowns>",
    ];
    let pos = positions(&xml, &order);
    assert!(pos.windows(2).all(|w| w[0] < w[1]), "{pos:?}\n{xml}");
    assert!(!xml.contains("TypeDefinitions") && !xml.contains("VendorAnnotations"));
}

#[test]
fn root_attribute_order() {
    let xml = rich().to_xml();
    let root = &xml[xml.find("<fmiModelDescription").unwrap()..];
    let root = &root[..root.find('>').unwrap()];
    let order = [
        "fmiVersion=",
        "modelName=",
        "guid=",
        "description=",
        "author=",
        "version=",
        "copyright=",
        "license=",
        "generationTool=",
        "generationDateAndTime=",
        "variableNamingConvention=",
        "numberOfEventIndicators=",
    ];
    let pos = positions(root, &order);
    assert!(pos.windows(2).all(|w| w[0] < w[1]), "{root}");
}

#[test]
fn scalar_variable_and_real_attribute_order() {
    let xml = rich().to_xml();
    let sv = xml.lines().find(|l| l.contains("name=\"k\"")).unwrap();
    assert_eq!(
        sv.trim(),
        "<ScalarVariable name=\"k\" valueReference=\"7\" causality=\"parameter\" variability=\"tunable\" initial=\"exact\">"
    );
    let real = xml.lines().find(|l| l.contains("<Real unit=\"m\"")).unwrap();
    assert_eq!(real.trim(), "<Real unit=\"m\" min=\"-INF\" max=\"INF\" nominal=\"1.5\" start=\"0.5\"/>");
    let der = xml.lines().find(|l| l.contains("derivative=")).unwrap();
    assert_eq!(der.trim(), "<Real unit=\"m/s\" derivative=\"2\"/>");
    // initial omitted when None
    let u = xml.lines().find(|l| l.contains("name=\"u\"")).unwrap();
    assert!(!u.contains("initial="), "{u}");
}

#[test]
fn empty_lists_are_omitted_but_variables_and_structure_are_not() {
    let md = minimal();
    let xml = md.to_xml();
    for absent in [
        "UnitDefinitions",
        "LogCategories",
        "DefaultExperiment",
        "ModelExchange",
        "Outputs",
        "Derivatives",
        "InitialUnknowns",
    ] {
        assert!(!xml.contains(absent), "{absent} in\n{xml}");
    }
    assert!(xml.contains("<ModelVariables>"));
    assert!(xml.contains("<ModelStructure/>"));
    // Only non-empty ModelStructure children.
    let mut md2 = minimal();
    md2.model_structure.initial_unknowns.push(common::unknown(1, None, None));
    let xml2 = md2.to_xml();
    assert!(xml2.contains("<InitialUnknowns>") && !xml2.contains("<Outputs") && !xml2.contains("<Derivatives"));
}

#[test]
fn capability_flags_only_when_true() {
    let xml = rich().to_xml();
    let me = xml.lines().find(|l| l.contains("<ModelExchange")).unwrap().trim().to_string();
    assert_eq!(
        me,
        "<ModelExchange modelIdentifier=\"rich_model\" completedIntegratorStepNotNeeded=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"true\"/>"
    );
    let cs = xml.lines().find(|l| l.contains("<CoSimulation")).unwrap().trim().to_string();
    assert_eq!(
        cs,
        "<CoSimulation modelIdentifier=\"rich_model\" canHandleVariableCommunicationStepSize=\"true\" maxOutputDerivativeOrder=\"1\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\"/>"
    );
    assert!(!xml.contains("=\"false\""));
}

#[test]
fn units_write_nonzero_exponents_and_nondefault_factor_offset() {
    let xml = rich().to_xml();
    assert!(xml.contains("<Unit name=\"m\">\n      <BaseUnit m=\"1\"/>\n    </Unit>"), "{xml}");
    assert!(xml.contains("<BaseUnit kg=\"1\" m=\"1\" s=\"-2\"/>"));
    assert!(xml.contains("<BaseUnit K=\"1\" offset=\"273.15\"/>"));
    assert!(xml.contains("<BaseUnit m=\"1\" s=\"-1\" factor=\"0.2777777777777778\"/>"));
    assert!(xml.contains(
        "<BaseUnit kg=\"-3\" m=\"2\" s=\"1\" A=\"-1\" K=\"4\" mol=\"-2\" cd=\"7\" rad=\"-5\" factor=\"1e-300\" offset=\"-1e300\"/>"
    ));
    assert!(xml.contains("<Unit name=\"1\"/>"));
}

#[test]
fn dependencies_absent_empty_and_listed() {
    let xml = rich().to_xml();
    assert!(xml.contains("<Unknown index=\"2\" dependencies=\"\"/>"), "{xml}");
    assert!(xml.contains("<Unknown index=\"11\"/>"));
    assert!(
        xml.contains("<Unknown index=\"16\" dependencies=\"2 4 6\" dependenciesKind=\"dependent constant fixed\"/>")
    );
    let back = ModelDescription::from_xml(&xml).unwrap();
    assert_eq!(back.model_structure.outputs[0].dependencies, Some(vec![]));
    assert_eq!(back.model_structure.outputs[1].dependencies, None);
}

#[test]
fn text_is_escaped_and_survives() {
    let md = rich();
    let xml = md.to_xml();
    assert!(xml.contains("modelName=\"Rich &amp; &lt;odd&gt; &quot;model&quot;\""), "{xml}");
    assert!(xml.contains("multi&#10;line&#9;description"));
    let back = ModelDescription::from_xml(&xml).unwrap();
    assert_eq!(back.model_name, md.model_name);
    assert_eq!(back.model_variables[6].description, md.model_variables[6].description);
    assert_eq!(back.model_variables[13].variable_type, md.model_variables[13].variable_type);
}

#[test]
fn reals_round_trip_bit_exactly() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let mut values = vec![
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.1,
        1.0 / 3.0,
        1e-5,
        9.99999e-6,
        1e16,
        9_999_999_999_999_998.0,
        f64::MIN_POSITIVE,
        f64::MIN_POSITIVE / 3.0, // subnormal
        5e-324,
        f64::MAX,
        f64::MIN,
        f64::EPSILON,
        123_456_789.123_456_79,
    ];
    for _ in 0..2000 {
        let x = f64::from_bits(rng.next_u64());
        if x.is_finite() {
            values.push(x);
        }
    }
    for &x in &values {
        let s = format_f64(x);
        let y = parse_xs_double(&s).unwrap();
        assert_eq!(x.to_bits(), y.to_bits(), "{x:?} -> {s} -> {y:?}");
    }
    // ... and through a whole document.
    let mut md = minimal();
    md.model_variables.clear();
    for (i, &x) in values.iter().enumerate() {
        md.model_variables.push(real(
            &format!("p{i}"),
            i as u32,
            Causality::Parameter,
            Variability::Fixed,
            None,
            Some(x),
            None,
        ));
    }
    let back = ModelDescription::from_xml(&md.to_xml()).unwrap();
    for (a, b) in md.model_variables.iter().zip(&back.model_variables) {
        let (VariableType::Real { start: Some(x), .. }, VariableType::Real { start: Some(y), .. }) =
            (&a.variable_type, &b.variable_type)
        else {
            panic!()
        };
        assert_eq!(x.to_bits(), y.to_bits());
    }
}

#[test]
fn special_reals_are_xs_double() {
    assert_eq!(format_f64(f64::INFINITY), "INF");
    assert_eq!(format_f64(f64::NEG_INFINITY), "-INF");
    assert_eq!(format_f64(f64::NAN), "NaN");
    assert_eq!(format_f64(1.0), "1");
    assert_eq!(format_f64(0.001), "0.001");
    assert_eq!(format_f64(1e-7), "1e-7");
    assert_eq!(format_f64(1e20), "1e20");
    assert!(parse_xs_double("NaN").unwrap().is_nan());
    assert_eq!(parse_xs_double(" -INF "), Some(f64::NEG_INFINITY));
    assert_eq!(parse_xs_double("+INF"), Some(f64::INFINITY));
    assert_eq!(parse_xs_double("1.5E3"), Some(1500.0));
    assert_eq!(parse_xs_double("abc"), None);
}

//! The reader never panics, and its errors say what is wrong and where.

mod common;

use common::*;
use model_description::*;

fn read(xml: &str) -> ReadError {
    match ModelDescription::from_xml(xml) {
        Ok(md) => panic!("expected an error, got {md:?}"),
        Err(e) => e,
    }
}

#[test]
fn every_prefix_of_valid_documents_is_handled() {
    for doc in [rich().to_xml(), fixture("BouncingBall.xml"), fixture("Feedthrough.xml")] {
        let full_ok = ModelDescription::from_xml(&doc).is_ok();
        assert!(full_ok);
        let mut ok_prefixes = 0;
        for end in (0..doc.len()).filter(|&i| doc.is_char_boundary(i)) {
            match ModelDescription::from_xml(&doc[..end]) {
                Ok(_) => ok_prefixes += 1,
                Err(e) => {
                    // Display works and mentions a position.
                    let msg = e.to_string();
                    assert!(msg.contains("line "), "{msg}");
                }
            }
        }
        // Only prefixes that end after the root's end tag can succeed.
        let root_end = doc.find("</fmiModelDescription>").unwrap() + "</fmiModelDescription>".len();
        assert_eq!(ok_prefixes, doc.len() - root_end, "prefixes accepted");
    }
}

#[test]
fn random_bytes_do_not_panic() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let alphabet = b"<>/=\"' abcdefghijklmnopqrstuvwxyz?!-&;#0123456789\n\t:.";
    for round in 0..3000 {
        let len = rng.below(300);
        let bytes: Vec<u8> = if round % 2 == 0 {
            (0..len).map(|_| rng.next_u64() as u8).collect()
        } else {
            (0..len).map(|_| alphabet[rng.below(alphabet.len())]).collect()
        };
        let s = String::from_utf8_lossy(&bytes);
        let _ = ModelDescription::from_xml(&s);
    }
}

#[test]
fn mutated_documents_do_not_panic() {
    let base = rich().to_xml().into_bytes();
    let pieces: [&[u8]; 12] = [
        b"<",
        b">",
        b"\"",
        b"/",
        b"&",
        b"&#0;",
        b"<ScalarVariable>",
        b"</ModelVariables>",
        b"=",
        b"-",
        b"9999999999999",
        b"\xff",
    ];
    let mut rng = Rng(42);
    let mut accepted = 0;
    for _ in 0..3000 {
        let mut doc = base.clone();
        for _ in 0..1 + rng.below(4) {
            let at = rng.below(doc.len());
            match rng.below(3) {
                0 => {
                    doc.remove(at);
                }
                1 => {
                    let p = pieces[rng.below(pieces.len())];
                    doc.splice(at..at, p.iter().copied());
                }
                _ => doc[at] = rng.next_u64() as u8,
            }
        }
        let s = String::from_utf8_lossy(&doc);
        if let Ok(md) = ModelDescription::from_xml(&s) {
            accepted += 1;
            // Whatever is accepted can be written, validated and fingerprinted.
            let _ = md.validate();
            let _ = md.content_guid();
            let _ = md.states();
            let _ = md.expected_model_structure();
        }
    }
    assert!(accepted > 0);
}

#[test]
fn deep_nesting_does_not_overflow() {
    let depth = 200_000;
    let mut s = String::from(r#"<fmiModelDescription fmiVersion="2.0" modelName="m" guid="g"><VendorAnnotations>"#);
    s.push_str(&"<a>".repeat(depth));
    s.push_str(&"</a>".repeat(depth));
    s.push_str("</VendorAnnotations></fmiModelDescription>");
    let md = ModelDescription::from_xml(&s).unwrap();
    assert!(md.model_variables.is_empty());
    // Unclosed, too.
    let opened = s.find("</a>").unwrap();
    let e = read(&s[..opened]);
    let ReadError::UnexpectedEof { element, position } = &e else { panic!("{e}") };
    assert_eq!(element, "a");
    assert_eq!(position.byte, opened - 3, "the innermost open element");
}

const HEAD: &str = r#"<fmiModelDescription fmiVersion="2.0" modelName="m" guid="g">"#;

fn doc(body: &str) -> String {
    format!("{HEAD}\n{body}\n</fmiModelDescription>")
}

#[test]
fn malformed_xml_names_the_position() {
    let e = read("<fmiModelDescription fmiVersion=\"2.0\" modelName=\"m\" guid=\"g\">\n  <ModelVariables>\n  </ModelVariablez>\n</fmiModelDescription>");
    assert!(matches!(e, ReadError::Xml { .. }), "{e:?}");
    assert_eq!(e.position().line, 3, "{e}");
    let msg = e.to_string();
    assert!(msg.contains("malformed XML") && msg.contains("line 3"), "{msg}");

    let e = read(&doc(
        r#"<ModelVariables><ScalarVariable name="a&b" valueReference="0"><Real/></ScalarVariable></ModelVariables>"#,
    ));
    assert!(matches!(e, ReadError::Xml { .. }), "{e:?}");
    assert!(e.to_string().contains("line 2"), "{e}");

    let e = read(r#"<fmiModelDescription fmiVersion="2.0" fmiVersion="2.0" modelName="m" guid="g"/>"#);
    assert!(matches!(e, ReadError::Xml { .. }), "duplicate attribute: {e:?}");

    let e = read(&format!("{HEAD}</fmiModelDescription><fmiModelDescription/>"));
    assert!(e.to_string().contains("second root"), "{e}");
}

#[test]
fn unexpected_eof_names_the_open_element() {
    let e = read(&format!("{HEAD}\n  <ModelVariables>\n    <ScalarVariable name=\"x\" valueReference=\"1\">"));
    let ReadError::UnexpectedEof { element, position } = &e else { panic!("{e:?}") };
    assert_eq!((element.as_str(), position.line), ("ScalarVariable", 3));
    assert!(e.to_string().contains("<ScalarVariable>"), "{e}");
}

#[test]
fn not_a_model_description() {
    assert!(matches!(read(""), ReadError::NotAModelDescription { found: None, .. }));
    assert!(matches!(read("   <!-- nothing -->  "), ReadError::NotAModelDescription { found: None, .. }));
    let e = read("<fmiModelDescriptions/>");
    assert!(e.to_string().contains("<fmiModelDescriptions>"), "{e}");
}

#[test]
fn missing_required_attributes() {
    let cases: [(&str, &str, &str); 7] = [
        (r#"<fmiModelDescription modelName="m" guid="g"/>"#, "fmiModelDescription", "fmiVersion"),
        (r#"<fmiModelDescription fmiVersion="2.0" guid="g"/>"#, "fmiModelDescription", "modelName"),
        (r#"<fmiModelDescription fmiVersion="2.0" modelName="m"/>"#, "fmiModelDescription", "guid"),
        (&doc(r#"<CoSimulation/>"#), "CoSimulation", "modelIdentifier"),
        (&doc(r#"<ModelExchange canGetAndSetFMUstate="true"/>"#), "ModelExchange", "modelIdentifier"),
        (
            &doc(r#"<ModelVariables><ScalarVariable valueReference="1"><Real/></ScalarVariable></ModelVariables>"#),
            "ScalarVariable",
            "name",
        ),
        (
            &doc(r#"<ModelVariables><ScalarVariable name="speed"><Real/></ScalarVariable></ModelVariables>"#),
            "ScalarVariable \"speed\"",
            "valueReference",
        ),
    ];
    for (xml, elem, attr) in cases {
        let e = read(xml);
        match &e {
            ReadError::MissingAttribute { element, attribute, .. } => {
                assert_eq!((element.as_str(), attribute.as_str()), (elem, attr), "{xml}");
            }
            other => panic!("{xml}: {other:?}"),
        }
        let msg = e.to_string();
        assert!(msg.contains(attr) && msg.contains(elem) && msg.contains("missing required attribute"), "{msg}");
    }
    let e = read(&doc(r#"<ModelStructure><Outputs><Unknown dependencies="1"/></Outputs></ModelStructure>"#));
    assert!(e.to_string().contains("Unknown of Outputs") && e.to_string().contains("index"), "{e}");
    let e = read(&doc(r#"<UnitDefinitions><Unit/></UnitDefinitions>"#));
    assert!(matches!(e, ReadError::MissingAttribute { .. }), "{e}");
}

#[test]
fn bad_numbers() {
    let cases = [
        (
            doc(
                r#"<ModelVariables><ScalarVariable name="x" valueReference="-1"><Real/></ScalarVariable></ModelVariables>"#,
            ),
            "valueReference",
            "-1",
        ),
        (
            doc(
                r#"<ModelVariables><ScalarVariable name="x" valueReference="1"><Real start="1,5"/></ScalarVariable></ModelVariables>"#,
            ),
            "start",
            "1,5",
        ),
        (
            doc(
                r#"<ModelVariables><ScalarVariable name="n" valueReference="1" variability="discrete"><Integer max="1.5"/></ScalarVariable></ModelVariables>"#,
            ),
            "max",
            "1.5",
        ),
        (
            doc(r#"<ModelStructure><Outputs><Unknown index="1" dependencies="1 two 3"/></Outputs></ModelStructure>"#),
            "dependencies",
            "two",
        ),
        (doc(r#"<DefaultExperiment stopTime="ten"/>"#), "stopTime", "ten"),
        (doc(r#"<UnitDefinitions><Unit name="u"><BaseUnit m="1.0"/></Unit></UnitDefinitions>"#), "m", "1.0"),
        (
            r#"<fmiModelDescription fmiVersion="2.0" modelName="m" guid="g" numberOfEventIndicators="x"/>"#.to_string(),
            "numberOfEventIndicators",
            "x",
        ),
    ];
    for (xml, attr, val) in cases {
        let e = read(&xml);
        let ReadError::BadNumber { attribute, value, .. } = &e else { panic!("{xml}: {e:?}") };
        assert_eq!((attribute.as_str(), value.as_str()), (attr, val));
        let msg = e.to_string();
        assert!(msg.contains(attr) && msg.contains(val) && msg.contains("not a valid number"), "{msg}");
    }
    let e = read(&doc(
        r#"<ModelVariables><ScalarVariable name="x" valueReference="1"><Real start="1,5"/></ScalarVariable></ModelVariables>"#,
    ));
    assert!(e.to_string().contains("Real of ScalarVariable \"x\""), "{e}");
}

#[test]
fn unknown_enum_values() {
    let cases = [
        ("causality", r#"causality="outptu""#, "outptu"),
        ("variability", r#"variability="Continuous""#, "Continuous"),
        ("initial", r#"initial="guess""#, "guess"),
    ];
    for (attr, text, val) in cases {
        let xml = doc(&format!(
            r#"<ModelVariables><ScalarVariable name="x" valueReference="1" {text}><Real/></ScalarVariable></ModelVariables>"#
        ));
        let e = read(&xml);
        let ReadError::UnknownEnumValue { attribute, value, element, .. } = &e else { panic!("{e:?}") };
        assert_eq!((attribute.as_str(), value.as_str(), element.as_str()), (attr, val, "ScalarVariable \"x\""));
        assert!(e.to_string().contains("unknown value"), "{e}");
    }
    let e = read(&doc(
        r#"<ModelStructure><Derivatives><Unknown index="1" dependencies="1" dependenciesKind="linear"/></Derivatives></ModelStructure>"#,
    ));
    assert!(matches!(&e, ReadError::UnknownEnumValue { value, .. } if value == "linear"), "{e:?}");
    let e = read(&doc(r#"<CoSimulation modelIdentifier="m" canInterpolateInputs="yes"/>"#));
    assert!(
        matches!(&e, ReadError::UnknownEnumValue { attribute, .. } if attribute == "canInterpolateInputs"),
        "{e:?}"
    );
}

#[test]
fn fmi_version_must_be_2_0() {
    for v in ["1.0", "3.0", "2.0.1", ""] {
        let e = read(&format!(r#"<fmiModelDescription fmiVersion="{v}" modelName="m" guid="g"/>"#));
        let ReadError::UnsupportedFmiVersion { found, .. } = &e else { panic!("{e:?}") };
        assert_eq!(found, v);
        assert!(e.to_string().contains("fmiVersion"), "{e}");
        // FMI 1.0 is refused naming the versions that are read
        if v == "1.0" {
            assert!(e.to_string().contains("FMI 2.0 and FMI 3.0 are"), "{e}");
        }
    }
}

#[test]
fn scalar_variable_needs_a_type_child() {
    let e = read(&doc(r#"<ModelVariables>
  <ScalarVariable name="ok" valueReference="0"><Real/></ScalarVariable>
  <ScalarVariable name="untyped" valueReference="1"><Annotations/></ScalarVariable>
</ModelVariables>"#));
    let ReadError::MissingTypeChild { variable, position } = &e else { panic!("{e:?}") };
    assert_eq!(variable, "untyped");
    assert_eq!(position.line, 4);
    assert!(e.to_string().contains("\"untyped\""), "{e}");
}

#[test]
fn duplicate_singletons() {
    let e = read(&doc(r#"<CoSimulation modelIdentifier="a"/><CoSimulation modelIdentifier="b"/>"#));
    assert!(matches!(&e, ReadError::DuplicateElement { element, .. } if element == "CoSimulation"), "{e:?}");
    let e = read(&doc(r#"<ModelStructure><Outputs/><Outputs/></ModelStructure>"#));
    assert!(matches!(&e, ReadError::DuplicateElement { element, .. } if element == "Outputs"), "{e:?}");
}

#[test]
fn read_error_is_a_std_error() {
    let e: Box<dyn std::error::Error> = Box::new(read(""));
    assert!(!e.to_string().is_empty());
}

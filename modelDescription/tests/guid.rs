//! The content GUID: format, stability, sensitivity.

mod common;

use common::*;
use model_description::*;
use sha2::{Digest, Sha256};

fn assert_guid_format(g: &str) {
    assert_eq!(g.len(), 38, "{g}");
    let b = g.as_bytes();
    assert_eq!((b[0], b[37]), (b'{', b'}'), "{g}");
    for (i, &c) in b[1..37].iter().enumerate() {
        if [8, 13, 18, 23].contains(&i) {
            assert_eq!(c, b'-', "{g}");
        } else {
            assert!(c.is_ascii_digit() || (b'a'..=b'f').contains(&c), "{g}");
        }
    }
}

#[test]
fn format_and_definition() {
    let md = rich();
    let g = md.content_guid();
    assert_guid_format(&g);
    let mut copy = md.clone();
    copy.guid = String::new();
    let digest = Sha256::digest(copy.to_xml().as_bytes());
    let hex: String = digest[..16].iter().map(|b| format!("{b:02x}")).collect();
    assert_eq!(g.replace(['{', '}', '-'], ""), hex);
}

#[test]
fn stable_and_independent_of_the_current_guid() {
    let a = rich().content_guid();
    assert_eq!(rich().content_guid(), a);
    let mut md = rich();
    md.guid = "{something-else}".into();
    assert_eq!(md.content_guid(), a);
    let with = rich().with_content_guid();
    assert_eq!(with.guid, a);
    assert_eq!(with.content_guid(), a, "idempotent");
    assert!(with.to_xml().contains(&format!("guid=\"{a}\"")));
    // Survives a write/read cycle.
    assert_eq!(ModelDescription::from_xml(&with.to_xml()).unwrap().content_guid(), a);
}

#[test]
fn changes_when_any_variable_changes() {
    let base = rich();
    let g0 = base.content_guid();
    let mut seen = std::collections::HashSet::new();
    seen.insert(g0.clone());
    for i in 0..base.model_variables.len() {
        let edits: [fn(&mut ScalarVariable); 4] = [
            |v| v.name.push('_'),
            |v| v.value_reference += 1000,
            |v| v.description = Some(format!("{:?}", v.description)),
            |v| {
                v.variable_type = match v.variable_type.clone() {
                    VariableType::Real { start, unit, derivative, min, max, nominal } => VariableType::Real {
                        start: Some(start.unwrap_or(0.0) + 1e-12),
                        unit,
                        derivative,
                        min,
                        max,
                        nominal,
                    },
                    VariableType::Integer { start, min, max } => {
                        VariableType::Integer { start: Some(start.unwrap_or(0) + 1), min, max }
                    }
                    VariableType::Enumeration { declared_type, start, min, max } => {
                        VariableType::Enumeration { declared_type, start: Some(start.unwrap_or(0) + 1), min, max }
                    }
                    VariableType::Boolean { start } => VariableType::Boolean { start: Some(!start.unwrap_or(false)) },
                    VariableType::String { start } => {
                        VariableType::String { start: Some(start.unwrap_or_default() + "!") }
                    }
                }
            },
        ];
        for edit in edits {
            let mut md = base.clone();
            edit(&mut md.model_variables[i]);
            let g = md.content_guid();
            assert_guid_format(&g);
            assert!(seen.insert(g), "variable {i}: GUID unchanged or repeated");
        }
    }
}

#[test]
fn changes_when_anything_else_changes() {
    let g0 = rich().content_guid();
    let edits: Vec<fn(&mut ModelDescription)> = vec![
        |m| m.model_name.push('x'),
        |m| m.number_of_event_indicators += 1,
        |m| m.co_simulation.as_mut().unwrap().can_interpolate_inputs = true,
        |m| m.unit_definitions[1].base_unit.as_mut().unwrap().factor = 1000.0,
        |m| m.model_structure.outputs[0].dependencies = None,
        |m| m.default_experiment = None,
        |m| m.log_categories.pop().map(|_| ()).unwrap_or(()),
        |m| m.model_variables.swap(6, 7),
    ];
    for (i, edit) in edits.into_iter().enumerate() {
        let mut md = rich();
        edit(&mut md);
        assert_ne!(md.content_guid(), g0, "edit {i}");
    }
}

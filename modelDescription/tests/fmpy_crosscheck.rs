//! Cross-check with an independent importer: fmpy validates what we write against the
//! FMI 2.0 XSD and its own rules, and reads back the same variables. Runs when
//! `$FMPY_PYTHON` (default `python3`) can import fmpy. When `$FMPY_PYTHON` is set (the
//! README's test command sets it to its venv), fmpy missing is a failure, not a skip.

mod common;

use common::*;
use model_description::*;
/// Run after [`common::FMPY_PRELUDE`] (`md` is fmpy's reading of the document).
const SCRIPT: &str = r#"
for v in md.modelVariables:
    print("VAR", v.name, v.valueReference, v.type, v.causality, v.variability, v.initial, repr(v.start))
for u in md.outputs:
    print("OUT", md.modelVariables.index(u.variable) + 1)
for u in md.initialUnknowns:
    print("INIT", md.modelVariables.index(u.variable) + 1)
"#;

#[test]
fn fmpy_accepts_and_reads_what_we_write() {
    let Some(base) = fmpy_scratch("md-fmpy") else { return };
    for (name, md) in [
        ("rich", rich()),
        ("minimal", minimal()),
        ("BouncingBall", ModelDescription::from_xml(&fixture("BouncingBall.xml")).unwrap()),
        ("VanDerPol", ModelDescription::from_xml(&fixture("VanDerPol.xml")).unwrap()),
    ] {
        let md = md.with_content_guid();
        let stdout = fmpy_output(name, &base.join(name), &md.to_xml(), SCRIPT);

        let vars: Vec<Vec<&str>> =
            stdout.lines().filter_map(|l| l.strip_prefix("VAR ")).map(|l| l.split(' ').collect()).collect();
        assert_eq!(vars.len(), md.model_variables.len(), "{name}");
        for (f, v) in vars.iter().zip(&md.model_variables) {
            // Names with spaces do not occur in these samples.
            assert_eq!(f[0], v.name, "{name}");
            assert_eq!(f[1], v.value_reference.to_string(), "{name} {}", v.name);
            assert_eq!(f[2], v.variable_type.type_name(), "{name} {}", v.name);
            assert_eq!(f[3], v.causality.as_str(), "{name} {}", v.name);
            assert_eq!(f[4], v.variability.as_str(), "{name} {}", v.name);
            // fmpy reports the effective initial, and (FMI 3.0 style) "exact" for inputs,
            // where FMI 2.0 allows no initial attribute.
            let init = match v.causality {
                Causality::Input => "exact",
                _ => v.effective_initial().map_or("None", |i| i.as_str()),
            };
            assert_eq!(f[5], init, "{name} {}", v.name);
            if let VariableType::Real { start: Some(s), .. } = v.variable_type {
                // fmpy keeps the start as the attribute string: it must parse to our value.
                let text = f[6].trim_matches('\'');
                assert_eq!(parse_xs_double(text).map(f64::to_bits), Some(s.to_bits()), "{name} {}", v.name);
            }
        }
        let outs: Vec<u32> =
            stdout.lines().filter_map(|l| l.strip_prefix("OUT ")).map(|s| s.parse().unwrap()).collect();
        assert_eq!(outs, md.model_structure.outputs.iter().map(|u| u.index).collect::<Vec<_>>(), "{name}");
        let inits: Vec<u32> =
            stdout.lines().filter_map(|l| l.strip_prefix("INIT ")).map(|s| s.parse().unwrap()).collect();
        assert_eq!(inits, md.model_structure.initial_unknowns.iter().map(|u| u.index).collect::<Vec<_>>(), "{name}");
    }
    let _ = std::fs::remove_dir_all(&base);
}

//! Cross-check of the FMI 3.0 reader with an independent importer: fmpy validates the
//! FMI 3.0 test documents (its XSD check and its rules) and reads the same variables,
//! types, start values and dimensions. Runs when `$FMPY_PYTHON` (default `python3`) can
//! import fmpy; when `$FMPY_PYTHON` is set, fmpy missing is a failure, not a skip.

mod common;

use common::{fmpy_output, fmpy_scratch};
use model_description::fmi3::*;

/// Run after [`common::FMPY_PRELUDE`] (`md` is fmpy's reading of the document).
const SCRIPT: &str = r#"
for v in md.modelVariables:
    dims = ",".join(str(x.start) if x.start is not None else "vr" + str(x.valueReference) for x in v.dimensions)
    print("VAR", v.name, v.valueReference, v.type, v.causality, v.variability, dims or "-", sep="\t")
"#;

#[test]
fn fmpy_accepts_and_reads_the_fmi3_documents() {
    let Some(base) = fmpy_scratch("md3-fmpy") else { return };
    for (name, xml) in
        [("ball", include_str!("fixtures/fmi3_ball.xml")), ("types", include_str!("fixtures/fmi3_types.xml"))]
    {
        let md = ModelDescription::from_xml(xml).unwrap();
        assert_eq!(md.validate(), vec![], "{name}");
        let stdout = fmpy_output(name, &base.join(name), xml, SCRIPT);
        let vars: Vec<Vec<&str>> =
            stdout.lines().filter_map(|l| l.strip_prefix("VAR\t")).map(|l| l.split('\t').collect()).collect();
        assert_eq!(vars.len(), md.model_variables.len(), "{name}");
        for (f, v) in vars.iter().zip(&md.model_variables) {
            let dims: Vec<String> = v
                .dimensions
                .iter()
                .map(|d| match d {
                    Dimension::Fixed(n) => n.to_string(),
                    Dimension::Variable(vr) => format!("vr{vr}"),
                })
                .collect();
            let dims = if dims.is_empty() { "-".to_string() } else { dims.join(",") };
            let ours = [
                v.name.clone(),
                v.value_reference.to_string(),
                v.value_type.element().to_string(),
                v.causality.as_str().to_string(),
                v.variability.as_str().to_string(),
                dims,
            ];
            assert_eq!(f, &ours.iter().map(String::as_str).collect::<Vec<_>>(), "{name}");
        }
    }
    let _ = std::fs::remove_dir_all(&base);
}

//! Packaging of FMUs: the archive layout importers expect, generated from the models'
//! declarations, written deterministically (fixed order, timestamps and permissions).

use std::fmt::Write as _;
use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};
use std::process::Command;

use fmi2_export::model_description::{ModelDescription, VariableType};
use fmi2_export::{Declaration, Model};
use zip::write::SimpleFileOptions;

/// One FMU this workspace ships. Everything but the package name comes from the model's
/// declaration (identifier, interfaces, variables, documentation).
pub struct FmuTarget {
    /// Cargo package that builds the shared library (its `[lib] name` must be the model
    /// identifier; a test checks it).
    pub package: &'static str,
    /// `modelIdentifier`: the library is `lib<id>.so` in cargo's output, `<id>.so` in the archive.
    pub model_identifier: String,
    /// The generated description (the same declaration the binary dispatches on).
    pub description: &'static ModelDescription,
    /// Generated `documentation/index.html`.
    pub documentation: String,
}

impl FmuTarget {
    /// The target of model `M`, built by cargo package `package`; `equations` is the
    /// HTML the documentation shows after the variable table.
    pub fn of<M: Model>(package: &'static str, equations: &str) -> FmuTarget {
        let declaration = M::declaration();
        FmuTarget {
            package,
            model_identifier: declaration.spec.model_identifier.to_string(),
            description: declaration.model_description(),
            documentation: documentation(declaration, equations),
        }
    }

    /// The interfaces the description declares, as fmpy names them.
    pub fn interfaces(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        if self.description.co_simulation.is_some() {
            v.push("CoSimulation");
        }
        if self.description.model_exchange.is_some() {
            v.push("ModelExchange");
        }
        v
    }
}

/// Everything `build-fmu` builds: a new FMU is one entry here.
pub fn targets() -> Vec<FmuTarget> {
    vec![
        FmuTarget::of::<nigel_plant::Plant>("fmu-plant", nigel_plant::DOCUMENTATION),
        FmuTarget::of::<nigel_controller::Controller>("fmu-controller", nigel_controller::DOCUMENTATION),
        FmuTarget::of::<nigel_maneuver::TestBench>("fmu-maneuver", nigel_maneuver::DOCUMENTATION),
    ]
}

/// `manifest.json` written next to the archives (and printed by `build-fmu --list`): one
/// object per FMU with its model identifier, package, archive file name and interfaces,
/// so that tests iterate over exactly what was built.
pub fn manifest(targets: &[FmuTarget]) -> String {
    let entries: Vec<String> = targets
        .iter()
        .map(|t| {
            let interfaces: Vec<String> = t.interfaces().iter().map(|i| format!("\"{i}\"")).collect();
            format!(
                "  {{\"model_identifier\": \"{id}\", \"package\": \"{package}\", \"fmu\": \"{id}.fmu\", \
                 \"guid\": \"{guid}\", \"interfaces\": [{interfaces}]}}",
                id = t.model_identifier,
                package = t.package,
                guid = t.description.guid,
                interfaces = interfaces.join(", "),
            )
        })
        .collect();
    format!("[\n{}\n]\n", entries.join(",\n"))
}

/// The closed loop of the three FMUs, drawn into every FMU's documentation.
const CLOSED_LOOP_SVG: &str = include_str!("../../docs/closed-loop.svg");

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// `documentation/index.html`: every variable with unit, start value and meaning, then the equations.
pub fn documentation<B>(declaration: &Declaration<B>, equations: &str) -> String {
    let md = declaration.model_description();
    let mut html = String::new();
    let _ = write!(
        html,
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{name}</title>\
         <style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}table{{border-collapse:collapse}}\
         td,th{{border:1px solid #ccc;padding:2px 6px;text-align:left}}</style></head><body>\n\
         <h1>{name}</h1>\n<p>{desc}</p>\n<p>FMI 2.0, {interfaces}. GUID <code>{guid}</code>. \
         All quantities SI, angles in rad.</p>\n<h2>Variables</h2>\n<table>\n\
         <tr><th>name</th><th>vr</th><th>causality</th><th>variability</th><th>unit</th><th>range</th><th>start</th><th>description</th></tr>\n",
        name = escape(&md.model_name),
        desc = escape(md.description.as_deref().unwrap_or("")),
        guid = escape(&md.guid),
        interfaces = match (md.co_simulation.is_some(), md.model_exchange.is_some()) {
            (true, true) => "Co-Simulation and Model Exchange",
            (true, false) => "Co-Simulation",
            _ => "Model Exchange",
        },
    );
    for v in &md.model_variables {
        // the unit column holds units only; the declared range (and an Integer switch's
        // values, listed in its description) goes to the range column
        let range_of = |min: Option<String>, max: Option<String>| match (min, max) {
            (Some(lo), Some(hi)) => format!("{lo} .. {hi}"),
            (Some(lo), None) => format!(">= {lo}"),
            (None, Some(hi)) => format!("<= {hi}"),
            (None, None) => String::new(),
        };
        let (unit, range, start) = match &v.variable_type {
            VariableType::Real { unit, start, min, max, .. } => {
                let finite = |v: &Option<f64>| v.filter(|x| x.is_finite()).map(|x| x.to_string());
                (unit.clone().unwrap_or_default(), range_of(finite(min), finite(max)), start.map(|s| s.to_string()).unwrap_or_default())
            }
            VariableType::Integer { start, min, max } => (
                String::new(),
                range_of(min.map(|m| m.to_string()), max.map(|m| m.to_string())),
                start.map(|s| s.to_string()).unwrap_or_default(),
            ),
            VariableType::Enumeration { declared_type, start, .. } => {
                let items = md
                    .type_definitions
                    .iter()
                    .find(|t| &t.name == declared_type)
                    .map(|t| t.items.iter().map(|i| format!("{} = {}", i.name, i.value)).collect::<Vec<_>>().join(", "))
                    .unwrap_or_default();
                (String::new(), format!("{declared_type}: {items}"), start.map(|s| s.to_string()).unwrap_or_default())
            }
            VariableType::Boolean { start } => {
                (String::new(), String::new(), start.map(|s| s.to_string()).unwrap_or_default())
            }
            VariableType::String { start } => (String::new(), String::new(), start.clone().unwrap_or_default()),
        };
        let start = match (start.is_empty(), v.initial) {
            (true, Some(fmi2_export::model_description::Initial::Calculated)) => "(calculated)".to_string(),
            _ => start,
        };
        let _ = writeln!(
            html,
            "<tr><td><code>{}</code></td><td>{}</td><td>{:?}</td><td>{:?}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&v.name),
            v.value_reference,
            v.causality,
            v.variability,
            escape(&unit),
            escape(&range),
            escape(&start),
            escape(v.description.as_deref().unwrap_or("")),
        );
    }
    let _ = write!(
        html,
        "</table>\n{equations}\n<h2>The closed loop</h2>\n<p>How the three FMUs of nigel-fmi (plant, controller, \
         test bench) are connected in the benchmark.</p>\n{CLOSED_LOOP_SVG}\n</body></html>\n"
    );
    html
}

/// Errors of packaging.
#[derive(Debug)]
pub enum BuildError {
    Cargo(String),
    Io(PathBuf, std::io::Error),
    Zip(String),
}

impl std::fmt::Display for BuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BuildError::Cargo(m) => write!(f, "cargo build failed: {m}"),
            BuildError::Io(p, e) => write!(f, "{}: {e}", p.display()),
            BuildError::Zip(m) => write!(f, "zip: {m}"),
        }
    }
}

impl std::error::Error for BuildError {}

/// The archive bytes: `modelDescription.xml`, `binaries/linux64/<id>.so`,
/// `documentation/index.html`, in that order, with fixed timestamps and modes.
pub fn archive(xml: &str, library: &[u8], model_identifier: &str, documentation: &str) -> Result<Vec<u8>, BuildError> {
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default())
        .unix_permissions(0o644);
    let err = |e: zip::result::ZipError| BuildError::Zip(e.to_string());
    let entries: [(String, &[u8], u32); 3] = [
        ("modelDescription.xml".into(), xml.as_bytes(), 0o644),
        (format!("binaries/linux64/{model_identifier}.so"), library, 0o755),
        ("documentation/index.html".into(), documentation.as_bytes(), 0o644),
    ];
    for (name, bytes, mode) in entries {
        zip.start_file(name, options.unix_permissions(mode)).map_err(err)?;
        zip.write_all(bytes).map_err(|e| BuildError::Zip(e.to_string()))?;
    }
    Ok(zip.finish().map_err(err)?.into_inner())
}

/// The workspace's target directory (honours `CARGO_TARGET_DIR`).
pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap_or(Path::new(".")).join("target"))
}

/// Builds the shared library of `target` (release, with the fmi2 symbols exported)
/// and returns its path.
pub fn build_library(target: &FmuTarget) -> Result<PathBuf, BuildError> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("Cargo.toml");
    let status = Command::new(cargo)
        .args([
            "build",
            "--release",
            "--quiet",
            "--package",
            target.package,
            "--features",
            "fmi-export",
            "--manifest-path",
        ])
        .arg(&manifest)
        .status()
        .map_err(|e| BuildError::Cargo(e.to_string()))?;
    if !status.success() {
        return Err(BuildError::Cargo(format!("{} exited with {status}", target.package)));
    }
    Ok(target_dir().join("release").join(format!("lib{}.so", target.model_identifier)))
}

/// Builds and writes `<out_dir>/<id>.fmu`; returns its path and size.
pub fn build(target: &FmuTarget, out_dir: &Path) -> Result<(PathBuf, usize), BuildError> {
    let library_path = build_library(target)?;
    let library = std::fs::read(&library_path).map_err(|e| BuildError::Io(library_path.clone(), e))?;
    let bytes = archive(&target.description.to_xml(), &library, &target.model_identifier, &target.documentation)?;
    std::fs::create_dir_all(out_dir).map_err(|e| BuildError::Io(out_dir.to_path_buf(), e))?;
    let path = out_dir.join(format!("{}.fmu", target.model_identifier));
    std::fs::write(&path, &bytes).map_err(|e| BuildError::Io(path.clone(), e))?;
    Ok((path, bytes.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn archive_is_byte_identical_and_has_the_layout_importers_expect() {
        let t = &targets()[0];
        let xml = t.description.to_xml();
        let doc = &t.documentation;
        let a = archive(&xml, b"\x7fELF fake", &t.model_identifier, doc).unwrap();
        let b = archive(&xml, b"\x7fELF fake", &t.model_identifier, doc).unwrap();
        assert_eq!(a, b);
        let mut z = zip::ZipArchive::new(Cursor::new(a)).unwrap();
        let names: Vec<String> = (0..z.len()).map(|i| z.by_index(i).unwrap().name().to_string()).collect();
        assert_eq!(names, ["modelDescription.xml", "binaries/linux64/nigel_plant.so", "documentation/index.html"]);
        let mut text = String::new();
        std::io::Read::read_to_string(&mut z.by_name("modelDescription.xml").unwrap(), &mut text).unwrap();
        assert_eq!(text, xml);
    }

    #[test]
    fn documentation_lists_every_variable_with_its_unit() {
        let t = &targets()[0];
        let doc = &t.documentation;
        for v in &t.description.model_variables {
            assert!(doc.contains(&format!("<code>{}</code>", escape(&v.name))), "{} missing", v.name);
        }
        assert!(doc.contains("<td>N.m</td>") && doc.contains("<td>rad</td>"));
    }

    #[test]
    fn documentation_shows_calculated_states_and_the_switches_ranges() {
        let all = targets();
        let plant = &all.iter().find(|t| t.model_identifier == "nigel_plant").unwrap().documentation;
        // v_x: calculated from v_x_start, which is a parameter starting at 0
        assert!(plant.contains("<tr><td><code>v_x</code></td><td>3</td><td>Output</td><td>Continuous</td><td>m/s</td><td></td><td>(calculated)</td>"), "{plant}");
        assert!(plant.contains(
            "<tr><td><code>v_x_start</code></td><td>63</td><td>Parameter</td><td>Fixed</td><td>m/s</td><td></td><td>0</td>"
        ));
        assert!(plant.contains("<h2>Initial state</h2>"));
        let controller = &all.iter().find(|t| t.model_identifier == "nigel_controller").unwrap().documentation;
        assert!(controller.contains("<td><code>controller</code></td><td>0</td><td>Parameter</td><td>Fixed</td><td></td><td>1 .. 5</td><td>3</td><td>which steering feedback: 1 open_loop"), "{controller}");
        let bench = &all.iter().find(|t| t.model_identifier == "nigel_maneuver").unwrap().documentation;
        assert!(bench.contains("<td><code>maneuver</code></td><td>0</td><td>Parameter</td><td>Fixed</td><td></td><td>1 .. 6</td><td>1</td><td>the maneuver: 1 straight"));
        assert!(bench.contains(
            "<td><code>fidelity</code></td><td>1</td><td>Parameter</td><td>Fixed</td><td></td><td>1 .. 2</td><td>1</td>"
        ));
    }

    /// `[lib] name` of the package in the workspace, read from its Cargo.toml.
    fn library_name(package: &str) -> Option<String> {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent()?;
        for entry in std::fs::read_dir(root).ok()?.flatten() {
            let Ok(text) = std::fs::read_to_string(entry.path().join("Cargo.toml")) else { continue };
            let mut section = String::new();
            let (mut name, mut lib) = (None, None);
            for line in text.lines().map(str::trim) {
                if line.starts_with('[') {
                    section = line.to_string();
                } else if let Some(v) = line.strip_prefix("name").map(str::trim).and_then(|r| r.strip_prefix('=')) {
                    let v = v.trim().trim_matches('"').to_string();
                    match section.as_str() {
                        "[package]" => name = Some(v),
                        "[lib]" => lib = Some(v),
                        _ => {}
                    }
                }
            }
            if name.as_deref() == Some(package) {
                return lib;
            }
        }
        None
    }

    #[test]
    fn every_target_library_is_named_after_its_model_identifier() {
        for t in targets() {
            let lib = library_name(t.package);
            assert_eq!(
                lib.as_deref(),
                Some(t.model_identifier.as_str()),
                "{}: [lib] name must be the model identifier",
                t.package
            );
            let md = t.description;
            for id in [
                md.co_simulation.as_ref().map(|c| &c.model_identifier),
                md.model_exchange.as_ref().map(|m| &m.model_identifier),
            ]
            .into_iter()
            .flatten()
            {
                assert_eq!(id, &t.model_identifier);
            }
        }
        // the check itself finds a mismatch
        assert_eq!(library_name("fmu-plant").as_deref(), Some("nigel_plant"));
        assert_eq!(library_name("no-such-package"), None);
    }

    #[test]
    fn manifest_lists_every_target_with_its_interfaces() {
        let ts = targets();
        let m = manifest(&ts);
        for t in &ts {
            assert!(m.contains(&format!("\"fmu\": \"{}.fmu\"", t.model_identifier)), "{m}");
        }
        assert!(m.contains(r#""interfaces": ["CoSimulation", "ModelExchange"]"#), "{m}");
    }
}

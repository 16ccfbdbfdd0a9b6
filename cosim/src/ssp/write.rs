//! Export of a [`System`] built in Rust as an SSP 1.0 archive that fmpy, ecos and libcosim
//! can run.

use crate::error::{Error, Result};
use crate::system::{BaseType, System, Value};
use std::io::Write;
use std::path::{Path, PathBuf};

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn num(v: f64) -> String {
    let mut s = String::new();
    crate::simulate::push_number(&mut s, v);
    s
}

/// The name of the ParameterSet that holds the start values in an SSP written by [`write_ssp`].
pub const SSP_PARAMETER_SET: &str = "initialValues";

/// Writes `system` as an SSP 1.0 archive: `SystemStructure.ssd` plus each FMU archive
/// under `resources/` (one copy per distinct FMU), start values as inline parameter
/// bindings, connections with their linear transformations.
///
/// Every component's bindings are one ParameterSet named [`SSP_PARAMETER_SET`]: libcosim
/// applies each component's first set by default, ecos applies the sets of the one name
/// given to its `init` (and none without a name), so one name serves both.
pub fn write_ssp(system: &System, name: &str, stop_time: Option<f64>, path: &Path) -> Result<()> {
    let io = |source| Error::Import(crate::ImportError::Io { path: path.to_path_buf(), source });
    // FMU files, one per distinct source
    let mut files: Vec<(PathBuf, String)> = Vec::new();
    for spec in &system.instances {
        let src = spec.fmu.source().to_path_buf();
        if !files.iter().any(|(p, _)| *p == src) {
            let stem = src.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "fmu".into());
            let mut file = format!("resources/{stem}.fmu");
            let mut k = 1;
            while files.iter().any(|(_, f)| *f == file) {
                file = format!("resources/{stem}_{k}.fmu");
                k += 1;
            }
            files.push((src, file));
        }
    }
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.push_str("<ssd:SystemStructureDescription xmlns:ssc=\"http://ssp-standard.org/SSP1/SystemStructureCommon\" xmlns:ssd=\"http://ssp-standard.org/SSP1/SystemStructureDescription\" xmlns:ssv=\"http://ssp-standard.org/SSP1/SystemStructureParameterValues\" version=\"1.0\"");
    x.push_str(&format!(" name=\"{}\" generationTool=\"nigel-cosim\">\n", esc(name)));
    x.push_str(&format!("  <ssd:System name=\"{}\">\n    <ssd:Elements>\n", esc(name)));
    for (i, spec) in system.instances.iter().enumerate() {
        let md = spec.fmu.description();
        let file = &files.iter().find(|(p, _)| p == spec.fmu.source()).map(|(_, f)| f.clone()).unwrap_or_default();
        x.push_str(&format!(
            "      <ssd:Component name=\"{}\" type=\"application/x-fmu-sharedlibrary\" source=\"{}\">\n",
            esc(&spec.name),
            esc(file)
        ));
        // connectors: every output, and the inputs that are connected (an unconnected
        // input connector would be driven with 0 by fmpy's simulate_ssp, not left at its start)
        let vars: Vec<_> = md
            .model_variables
            .iter()
            .enumerate()
            .filter(|(index, v)| match v.causality {
                model_description::Causality::Output => true,
                model_description::Causality::Input => {
                    system.connections.iter().any(|c| c.to.instance == i && c.to.index == *index)
                }
                _ => false,
            })
            .map(|(_, v)| v)
            .collect();
        if !vars.is_empty() {
            x.push_str("        <ssd:Connectors>\n");
            for v in vars {
                x.push_str(&format!(
                    "          <ssd:Connector name=\"{}\" kind=\"{}\"><ssc:{}/></ssd:Connector>\n",
                    esc(&v.name),
                    v.causality.as_str(),
                    BaseType::of(v).as_str()
                ));
            }
            x.push_str("        </ssd:Connectors>\n");
        }
        if !spec.start_values.is_empty() {
            x.push_str("        <ssd:ParameterBindings>\n          <ssd:ParameterBinding>\n            <ssd:ParameterValues>\n");
            x.push_str(&format!(
                "              <ssv:ParameterSet version=\"1.0\" name=\"{}\">\n                <ssv:Parameters>\n",
                SSP_PARAMETER_SET
            ));
            for (index, value) in &spec.start_values {
                let vname = &md.model_variables[*index].name;
                let v = match value {
                    Value::Real(r) => format!("<ssv:Real value=\"{}\"/>", num(*r)),
                    Value::Integer(k) => format!("<ssv:Integer value=\"{k}\"/>"),
                    Value::Boolean(b) => format!("<ssv:Boolean value=\"{b}\"/>"),
                    Value::String(s) => format!("<ssv:String value=\"{}\"/>", esc(s)),
                };
                x.push_str(&format!("                  <ssv:Parameter name=\"{}\">{v}</ssv:Parameter>\n", esc(vname)));
            }
            x.push_str("                </ssv:Parameters>\n              </ssv:ParameterSet>\n            </ssd:ParameterValues>\n          </ssd:ParameterBinding>\n        </ssd:ParameterBindings>\n");
        }
        x.push_str("      </ssd:Component>\n");
    }
    x.push_str("    </ssd:Elements>\n");
    if !system.connections.is_empty() {
        x.push_str("    <ssd:Connections>\n");
        for c in &system.connections {
            let (fi, ti) = (&system.instances[c.from.instance].name, &system.instances[c.to.instance].name);
            let (fv, tv) = (&system.variable(&c.from).name, &system.variable(&c.to).name);
            x.push_str(&format!(
                "      <ssd:Connection startElement=\"{}\" startConnector=\"{}\" endElement=\"{}\" endConnector=\"{}\"",
                esc(fi),
                esc(fv),
                esc(ti),
                esc(tv)
            ));
            match c.linear_transformation {
                Some((f, o)) => x.push_str(&format!(
                    "><ssc:LinearTransformation factor=\"{}\" offset=\"{}\"/></ssd:Connection>\n",
                    num(f),
                    num(o)
                )),
                None => x.push_str("/>\n"),
            }
        }
        x.push_str("    </ssd:Connections>\n");
    }
    x.push_str("  </ssd:System>\n");
    if let Some(stop) = stop_time {
        x.push_str(&format!("  <ssd:DefaultExperiment startTime=\"0\" stopTime=\"{}\"/>\n", num(stop)));
    }
    x.push_str("</ssd:SystemStructureDescription>\n");

    let file = std::fs::File::create(path).map_err(io)?;
    let mut zip = zip::ZipWriter::new(file);
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    let zerr = |e: zip::result::ZipError| {
        Error::Import(crate::ImportError::Archive { path: path.to_path_buf(), reason: e.to_string() })
    };
    zip.start_file("SystemStructure.ssd", options).map_err(zerr)?;
    zip.write_all(x.as_bytes()).map_err(io)?;
    // the FMUs stored, not deflated: they are compressed archives already (deflate gains
    // under 1 %), and a stored FMU is read in place by importers that seek (see `unpack`)
    let stored = options.compression_method(zip::CompressionMethod::Stored);
    for (src, file) in &files {
        let fmu = system.instances.iter().find(|i| i.fmu.source() == src.as_path()).map(|i| &i.fmu);
        let bytes = match fmu {
            Some(fmu) => fmu.archive_bytes()?,
            None => std::fs::read(src)
                .map_err(|source| Error::Import(crate::ImportError::Io { path: src.clone(), source }))?,
        };
        zip.start_file(file.as_str(), stored).map_err(zerr)?;
        zip.write_all(&bytes).map_err(io)?;
    }
    zip.finish().map_err(zerr)?;
    Ok(())
}

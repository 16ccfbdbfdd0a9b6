//! Packaging of FMUs: the archive layout importers expect, generated from the models'
//! declarations, written deterministically (fixed order, timestamps and permissions), with
//! one library per [`Platform`] in each archive. Every FMU is packed twice from the one
//! declaration and the same library files: an FMI 2.0 archive (`<out>/<id>.fmu`) and an
//! FMI 3.0 archive (`<out>/fmi3/<id>.fmu`, [`FmiVersion`]).

pub mod platform;

use std::fmt::Write as _;
use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};
use std::process::Command;

use fmi_export::model_description::fmi3::ModelDescription as ModelDescription3;
use fmi_export::model_description::{ModelDescription, VariableType};
use fmi_export::{Declaration, Model};
use zip::write::SimpleFileOptions;

pub use platform::Platform;

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
    /// The generated FMI 3.0 description of the same declaration.
    pub description3: &'static ModelDescription3,
    /// Generated `documentation/index.html` of the FMI 2.0 archive.
    pub documentation: String,
    /// Generated `documentation/index.html` of the FMI 3.0 archive.
    pub documentation3: String,
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
            description3: declaration.model_description3(),
            documentation: documentation(declaration, equations, FmiVersion::Fmi2),
            documentation3: documentation(declaration, equations, FmiVersion::Fmi3),
        }
    }

    /// The archive's `modelDescription.xml` of `version`.
    pub fn xml(&self, version: FmiVersion) -> String {
        match version {
            FmiVersion::Fmi2 => self.description.to_xml(),
            FmiVersion::Fmi3 => self.description3.to_xml(),
        }
    }

    /// The archive's `documentation/index.html` of `version` (without the platform table).
    pub fn documentation_of(&self, version: FmiVersion) -> &str {
        match version {
            FmiVersion::Fmi2 => &self.documentation,
            FmiVersion::Fmi3 => &self.documentation3,
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

/// The generation of an archive. Both carry the same library files; they differ in
/// `modelDescription.xml`, in the archive's place and in the names of the platform folders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum FmiVersion {
    /// FMI 2.0: `<out>/<id>.fmu`, folders `linux64`, `win64`, `aarch64-linux`, `darwin64`.
    Fmi2,
    /// FMI 3.0: `<out>/fmi3/<id>.fmu`, folders `x86_64-linux`, `x86_64-windows`,
    /// `aarch64-linux`, `x86_64-darwin` and `aarch64-darwin`.
    Fmi3,
}

impl FmiVersion {
    /// Both generations, in the manifest's order.
    pub const ALL: [FmiVersion; 2] = [FmiVersion::Fmi2, FmiVersion::Fmi3];

    /// The `fmiVersion` attribute's value.
    pub fn as_str(self) -> &'static str {
        match self {
            FmiVersion::Fmi2 => "2.0",
            FmiVersion::Fmi3 => "3.0",
        }
    }

    /// The archive's path relative to the output folder.
    pub fn archive_path(self, model_identifier: &str) -> String {
        match self {
            FmiVersion::Fmi2 => format!("{model_identifier}.fmu"),
            FmiVersion::Fmi3 => format!("fmi3/{model_identifier}.fmu"),
        }
    }

    /// The platform folders under `binaries/` that carry `platform`'s library.
    pub fn folders(self, platform: Platform) -> Vec<&'static str> {
        match self {
            FmiVersion::Fmi2 => vec![platform.folder()],
            FmiVersion::Fmi3 => platform.fmi3_folders().to_vec(),
        }
    }
}

/// `manifest.json` written next to the archives (and printed by `build-fmu --list`): one
/// object per FMU with its model identifier, package, archive file name, interfaces and the
/// platforms its archive carries (each with its library, minimum OS, C library and how it is
/// tested), so that tests iterate over exactly what was built.
pub fn manifest(targets: &[FmuTarget], platforms: &[PlatformBuild]) -> String {
    let mut entries: Vec<serde_json::Value> = Vec::new();
    for version in FmiVersion::ALL {
        for t in targets {
            let platform_entries: Vec<serde_json::Value> = platforms
                .iter()
                .flat_map(|p| {
                    version.folders(p.platform).into_iter().map(move |folder| {
                        serde_json::json!({
                            "folder": folder,
                            "library": format!("binaries/{folder}/{}", p.platform.library_file(&t.model_identifier)),
                            "minimum_os": p.minimum_os,
                            "c_library": p.c_library,
                            "tested": p.tested_in(version),
                        })
                    })
                })
                .collect();
            let mut entry = serde_json::json!({
                "model_identifier": t.model_identifier,
                "package": t.package,
                "fmu": version.archive_path(&t.model_identifier),
                "fmi_version": version.as_str(),
            });
            match version {
                FmiVersion::Fmi2 => entry["guid"] = t.description.guid.clone().into(),
                FmiVersion::Fmi3 => entry["instantiation_token"] = t.description3.instantiation_token.clone().into(),
            }
            entry["interfaces"] = serde_json::json!(t.interfaces());
            entry["platforms"] = serde_json::Value::Array(platform_entries);
            entry["not_built"] = serde_json::json!(platforms_not_built(platforms, version));
            entries.push(entry);
        }
    }
    let mut text = serde_json::to_string_pretty(&entries).unwrap_or_default();
    text.push('\n');
    text
}

/// What one platform of an archive needs and how it was built: the [`Platform`]'s own text,
/// except on linux64 without the cross tools, where the library is the build machine's and
/// its glibc requirement is read from the library itself.
#[derive(Clone, Debug, PartialEq)]
pub struct PlatformBuild {
    /// The platform.
    pub platform: Platform,
    /// What the library needs on the user's machine.
    pub minimum_os: String,
    /// The C library it links against.
    pub c_library: String,
    /// How libraries built this way are tested ([`Platform::tested`] for the release
    /// recipe; "not tested" for a build the test command does not make).
    pub tested: String,
}

impl PlatformBuild {
    /// The platform as [`Platform::build`] builds it with its cross toolchain.
    pub fn of(platform: Platform) -> PlatformBuild {
        PlatformBuild {
            platform,
            minimum_os: platform.minimum_os().to_string(),
            c_library: platform.c_library().to_string(),
            tested: platform.tested().to_string(),
        }
    }

    /// How the library is tested through the `version` archive: [`Platform::tested_fmi3`]
    /// for the release recipe's library in the FMI 3.0 archive, else [`PlatformBuild::tested`].
    pub fn tested_in(&self, version: FmiVersion) -> String {
        match version {
            FmiVersion::Fmi3 if self.tested == self.platform.tested() => self.platform.tested_fmi3().to_string(),
            _ => self.tested.clone(),
        }
    }
}

/// The release platform folders a `version` archive of `platforms` lacks, each with why;
/// empty for a release build (all of [`Platform::ALL`]).
pub fn platforms_not_built(platforms: &[PlatformBuild], version: FmiVersion) -> Vec<String> {
    let all: Vec<&str> = Platform::ALL.iter().flat_map(|p| version.folders(*p)).collect();
    Platform::ALL
        .iter()
        .filter(|p| !platforms.iter().any(|b| b.platform == **p))
        .flat_map(|p| version.folders(*p))
        .map(|folder| {
            format!(
                "{folder}: not built (this build asked for fewer platforms; the release archives carry all of {})",
                all.join(", ")
            )
        })
        .collect()
}

/// The highest `GLIBC_2.N` symbol version an ELF library names (its version-needed
/// strings), as `(2, N)`; `None` when it names none.
pub fn glibc_requirement(library: &[u8]) -> Option<(u32, u32)> {
    let needle = b"GLIBC_2.";
    let mut best = None;
    let mut i = 0;
    while let Some(pos) = library[i..].windows(needle.len()).position(|w| w == needle) {
        let start = i + pos + needle.len();
        let digits: String = library[start..].iter().take_while(|b| b.is_ascii_digit()).map(|&b| b as char).collect();
        if let Ok(minor) = digits.parse::<u32>() {
            best = best.max(Some((2, minor)));
        }
        i = start;
    }
    best
}

/// The platforms' part of `documentation/index.html`: a table of the platform folders the
/// `version` archive carries, inserted before the end of the body.
pub fn with_platform_table(
    documentation: &str,
    model_identifier: &str,
    platforms: &[PlatformBuild],
    version: FmiVersion,
) -> String {
    let mut table = String::from(
        "<h2>Platforms</h2>\n<table>\n<tr><th>folder</th><th>library</th><th>needs</th><th>C library</th><th>tested</th></tr>\n",
    );
    for p in platforms {
        for folder in version.folders(p.platform) {
            let _ = writeln!(
                table,
                "<tr><td><code>{}</code></td><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td></tr>",
                folder,
                escape(&p.platform.library_file(model_identifier)),
                escape(&p.minimum_os),
                escape(&p.c_library),
                escape(&p.tested_in(version)),
            );
        }
    }
    table.push_str("</table>\n");
    let missing = platforms_not_built(platforms, version);
    if !missing.is_empty() {
        table.push_str("<p>This archive is not a release build. It lacks:</p>\n<ul>\n");
        for m in &missing {
            let _ = writeln!(table, "<li>{}</li>", escape(m));
        }
        table.push_str("</ul>\n");
    }
    match documentation.rfind("</body>") {
        Some(i) => format!("{}{table}{}", &documentation[..i], &documentation[i..]),
        None => format!("{documentation}{table}"),
    }
}

/// The closed loop of the three FMUs, drawn into every FMU's documentation.
const CLOSED_LOOP_SVG: &str = include_str!("../../docs/closed-loop.svg");

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// `documentation/index.html` of the `version` archive: every variable with its value
/// reference in that archive, unit, start value and meaning, then the equations.
pub fn documentation<B>(declaration: &Declaration<B>, equations: &str, version: FmiVersion) -> String {
    let md = declaration.model_description();
    let (generation, token) = match version {
        FmiVersion::Fmi2 => ("FMI 2.0".to_string(), format!("GUID <code>{}</code>", escape(&md.guid))),
        FmiVersion::Fmi3 => (
            format!(
                "The FMI 3.0 archive (the FMI 2.0 archive of the same model, with the same library files, is \
                 <code>{id}.fmu</code> in the folder above <code>fmi3/</code>): FMI 3.0",
                id = escape(declaration.spec.model_identifier)
            ),
            format!(
                "instantiationToken <code>{}</code> (the FMI 2.0 archive's GUID); the independent variable \
                 <code>time</code> has value reference 0",
                escape(&declaration.model_description3().instantiation_token)
            ),
        ),
    };
    let mut html = String::new();
    let _ = write!(
        html,
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{name}</title>\
         <style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}table{{border-collapse:collapse}}\
         td,th{{border:1px solid #ccc;padding:2px 6px;text-align:left}}</style></head><body>\n\
         <h1>{name}</h1>\n<p>{desc}</p>\n<p>{generation}, {interfaces}. {token}. \
         All quantities SI, angles in rad.</p>\n<h2>Variables</h2>\n<table>\n\
         <tr><th>name</th><th>vr</th><th>causality</th><th>variability</th><th>unit</th><th>range</th><th>start</th><th>description</th></tr>\n",
        name = escape(&md.model_name),
        desc = escape(md.description.as_deref().unwrap_or("")),
        interfaces = match (md.co_simulation.is_some(), md.model_exchange.is_some()) {
            (true, true) => "Co-Simulation and Model Exchange",
            (true, false) => "Co-Simulation",
            _ => "Model Exchange",
        },
    );
    for (row, v) in md.model_variables.iter().enumerate() {
        let value_reference = match version {
            FmiVersion::Fmi2 => v.value_reference,
            FmiVersion::Fmi3 => Declaration::<B>::value_reference3(row),
        };
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
                (
                    unit.clone().unwrap_or_default(),
                    range_of(finite(min), finite(max)),
                    start.map(|s| s.to_string()).unwrap_or_default(),
                )
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
            (true, Some(fmi_export::model_description::Initial::Calculated)) => "(calculated)".to_string(),
            _ => start,
        };
        let _ = writeln!(
            html,
            "<tr><td><code>{}</code></td><td>{}</td><td>{:?}</td><td>{:?}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&v.name),
            value_reference,
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

/// The `version` archive's bytes: `modelDescription.xml`, `binaries/<folder>/<id>.<ext>` for
/// each library (in the order given; in FMI 3.0 the darwin64 universal library's x86-64
/// slice goes to `x86_64-darwin`, its arm64 slice to `aarch64-darwin`),
/// `documentation/index.html`, with fixed timestamps and modes.
pub fn archive(
    version: FmiVersion,
    xml: &str,
    libraries: &[(Platform, &[u8])],
    model_identifier: &str,
    documentation: &str,
) -> Result<Vec<u8>, BuildError> {
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default())
        .unix_permissions(0o644);
    let err = |e: zip::result::ZipError| BuildError::Zip(e.to_string());
    let mut entries: Vec<(String, &[u8], u32)> = vec![("modelDescription.xml".into(), xml.as_bytes(), 0o644)];
    for (platform, bytes) in libraries {
        for folder in version.folders(*platform) {
            let bytes = match version {
                FmiVersion::Fmi2 => bytes,
                FmiVersion::Fmi3 => {
                    platform.fmi3_library(folder, bytes).map_err(|e| BuildError::Zip(format!("{folder}: {e}")))?
                }
            };
            entries.push((format!("binaries/{folder}/{}", platform.library_file(model_identifier)), bytes, 0o755));
        }
    }
    entries.push(("documentation/index.html".into(), documentation.as_bytes(), 0o644));
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

/// Builds the libraries of every target for linux64 with the workspace's own cargo (no
/// cross tools: the glibc baseline is the build machine's) and returns their paths.
pub fn build_host_linux64(targets: &[FmuTarget]) -> Result<Vec<PathBuf>, BuildError> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("Cargo.toml");
    let mut c = Command::new(cargo);
    c.args(["build", "--release", "--quiet"]);
    for t in targets {
        c.args(["--package", t.package]);
    }
    let packages: Vec<&str> = targets.iter().map(|t| t.package).collect();
    let features = library_features(&packages);
    c.args(["--features", &features.join(","), "--manifest-path"]).arg(&manifest);
    let status = c.status().map_err(|e| BuildError::Cargo(e.to_string()))?;
    if !status.success() {
        return Err(BuildError::Cargo(format!("linux64 (host toolchain): cargo exited with {status}")));
    }
    Ok(targets.iter().map(|t| target_dir().join("release").join(format!("lib{}.so", t.model_identifier))).collect())
}

/// Writes the closed loop `job` of the benchmark (`column/maneuver/controller`, e.g.
/// `sim/lane_change/robust`, noise seed `seed`) as an SSP 1.0 archive at `ssp_path`: the
/// instances, parameters and connections of [`nigel_benchmark::fmu_system::closed_loop`]
/// over the archives in `fmu_dir`, written by `nigel_cosim::write_ssp` (default experiment
/// 0 .. 30 s).
pub fn write_closed_loop_ssp(fmu_dir: &Path, job: &str, seed: u64, ssp_path: &Path) -> Result<(), String> {
    use nigel_benchmark::fmu_system::{closed_loop, StartValue};
    use nigel_benchmark::{Controller, Fidelity, Maneuver};
    let bad = || format!("{job:?} is not column/maneuver/controller (e.g. sim/lane_change/robust)");
    let parts: Vec<&str> = job.split('/').collect();
    let [column, maneuver, controller] = parts[..] else { return Err(bad()) };
    let fidelity = Fidelity::ALL.into_iter().find(|f| f.column() == column).ok_or_else(bad)?;
    let maneuver = Maneuver::from_name(maneuver).ok_or_else(bad)?;
    let controller = Controller::WITH_TRACKING.into_iter().find(|c| c.name() == controller).ok_or_else(bad)?;
    let description = closed_loop(fidelity, maneuver, controller, seed, true)?;
    let mut b = nigel_cosim::SystemBuilder::new();
    for (instance, model_identifier) in &description.instances {
        let path = fmu_dir.join(format!("{model_identifier}.fmu"));
        let fmu = nigel_cosim::Fmu::load(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        b.add_instance(instance, fmu).map_err(|e| e.to_string())?;
    }
    for (name, value) in &description.parameters {
        let value = match *value {
            StartValue::Real(x) => nigel_cosim::Value::Real(x),
            StartValue::Integer(n) => nigel_cosim::Value::Integer(n),
            StartValue::Boolean(v) => nigel_cosim::Value::Boolean(v),
        };
        b.set(name, value).map_err(|e| e.to_string())?;
    }
    for (from, to) in &description.connections {
        b.connect(from, to).map_err(|e| e.to_string())?;
    }
    if let Some(dir) = ssp_path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    nigel_cosim::write_ssp(&b.build(), "nigel_closed_loop", Some(description.stop_time), ssp_path)
        .map_err(|e| format!("{}: {e}", ssp_path.display()))
}

/// The closed loop of the FMI 3.0 archives: the SSP `fmi2_ssp` (as [`write_closed_loop_ssp`]
/// wrote it over the FMI 2.0 archives of `fmu_dir`) with each `resources/<id>.fmu` replaced by
/// `fmu_dir/fmi3/<id>.fmu`, written to `ssp_path`. The system structure is kept as it is:
/// both generations have the same variable names, causalities and types (SSP's `Real`,
/// `Integer`, `Boolean` connectors and parameters are FMI 3.0's `Float64`, `Int32` and
/// `Boolean`), so the parameter bindings and connections are the same.
pub fn write_closed_loop_ssp_fmi3(fmi2_ssp: &Path, fmu_dir: &Path, ssp_path: &Path) -> Result<(), String> {
    use std::io::Read as _;
    let read = |p: &Path| std::fs::read(p).map_err(|e| format!("{}: {e}", p.display()));
    let mut input =
        zip::ZipArchive::new(Cursor::new(read(fmi2_ssp)?)).map_err(|e| format!("{}: {e}", fmi2_ssp.display()))?;
    let mut out = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    let zerr = |e: zip::result::ZipError| format!("{}: {e}", ssp_path.display());
    for i in 0..input.len() {
        let mut entry = input.by_index(i).map_err(|e| format!("{}: {e}", fmi2_ssp.display()))?;
        let name = entry.name().to_string();
        let (bytes, entry_options) = match name.strip_prefix("resources/").and_then(|f| f.strip_suffix(".fmu")) {
            Some(id) => {
                // stored, not deflated, as write_ssp stores the FMI 2.0 ones
                (
                    read(&fmu_dir.join(FmiVersion::Fmi3.archive_path(id)))?,
                    options.compression_method(zip::CompressionMethod::Stored),
                )
            }
            None => {
                let mut bytes = Vec::new();
                entry.read_to_end(&mut bytes).map_err(|e| format!("{}: {name}: {e}", fmi2_ssp.display()))?;
                (bytes, options)
            }
        };
        out.start_file(name, entry_options).map_err(zerr)?;
        out.write_all(&bytes).map_err(|e| format!("{}: {e}", ssp_path.display()))?;
    }
    let bytes = out.finish().map_err(zerr)?.into_inner();
    if let Some(dir) = ssp_path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    std::fs::write(ssp_path, bytes).map_err(|e| format!("{}: {e}", ssp_path.display()))
}

/// `built` with the C library and minimum OS the Linux `libraries` really need: when one
/// names a glibc symbol version above the 2.17 baseline (a build with the host toolchain),
/// that version.
fn with_glibc_of(mut built: PlatformBuild, libraries: &[Vec<u8>]) -> PlatformBuild {
    let needed = libraries.iter().filter_map(|b| glibc_requirement(b)).max();
    if let Some((major, minor)) = needed.filter(|&(_, minor)| minor > 17) {
        built.c_library =
            format!("glibc {major}.{minor} (the build machine's; symbol versions up to GLIBC_{major}.{minor})");
        built.minimum_os = format!("Linux with glibc {major}.{minor} or later");
        built.tested = format!(
            "not tested: built with this machine's toolchain (glibc {major}.{minor}), not with the release recipe \
             (glibc 2.17 baseline through cargo-zigbuild) whose libraries the test command runs"
        );
    }
    built
}

/// The cargo features of the FMU libraries of `packages`: each one's `fmi-export`.
pub fn library_features(packages: &[&str]) -> Vec<String> {
    packages.iter().map(|p| format!("{p}/fmi-export")).collect()
}

/// Builds one FMU for linux64 with the workspace's own cargo (no cross toolchain needed;
/// the library needs the build machine's glibc, which its documentation then states) and
/// writes `<out_dir>/<id>.fmu` and `<out_dir>/fmi3/<id>.fmu`; returns each archive's path
/// and size, FMI 2.0 first. For an FMU of one's own whose crate depends on this one: the
/// cross builds of [`build_all`] would build this crate's own dependencies (the master)
/// for every platform too.
pub fn build_for_this_machine(target: &FmuTarget, out_dir: &Path) -> Result<Vec<(PathBuf, usize)>, BuildError> {
    let paths = build_host_linux64(std::slice::from_ref(target))?;
    let library = std::fs::read(&paths[0]).map_err(|e| BuildError::Io(paths[0].clone(), e))?;
    let built = with_glibc_of(PlatformBuild::of(Platform::Linux64), std::slice::from_ref(&library));
    let libraries = [(Platform::Linux64, library.as_slice())];
    FmiVersion::ALL
        .into_iter()
        .map(|version| write_archive(target, version, &libraries, std::slice::from_ref(&built), out_dir))
        .collect()
}

/// Writes `target`'s `version` archive of `libraries` (built as `builds` say) under
/// `out_dir`; returns its path and size.
fn write_archive(
    target: &FmuTarget,
    version: FmiVersion,
    libraries: &[(Platform, &[u8])],
    builds: &[PlatformBuild],
    out_dir: &Path,
) -> Result<(PathBuf, usize), BuildError> {
    let documentation =
        with_platform_table(target.documentation_of(version), &target.model_identifier, builds, version);
    let bytes = archive(version, &target.xml(version), libraries, &target.model_identifier, &documentation)?;
    let path = out_dir.join(version.archive_path(&target.model_identifier));
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| BuildError::Io(dir.to_path_buf(), e))?;
    }
    std::fs::write(&path, &bytes).map_err(|e| BuildError::Io(path.clone(), e))?;
    Ok((path, bytes.len()))
}

/// What [`build_all`] wrote.
#[derive(Debug)]
pub struct Built {
    /// Each FMI 2.0 archive's path and size in bytes, in the order of the targets.
    pub archives: Vec<(PathBuf, usize)>,
    /// Each FMI 3.0 archive's path and size in bytes, in the order of the targets.
    pub archives3: Vec<(PathBuf, usize)>,
    /// How each platform was built (toolchain, C library baseline).
    pub platforms: Vec<PlatformBuild>,
}

/// Builds every target for every platform of `platforms` and writes `<out_dir>/<id>.fmu`
/// and `<out_dir>/fmi3/<id>.fmu` for each, carrying all those platforms; returns each
/// archive's path and size.
///
/// linux64 is built with cargo-zigbuild (glibc 2.17 baseline) when it is installed, else
/// with the workspace's cargo (the build machine's glibc, read from the libraries and
/// reported in the returned [`PlatformBuild`]).
pub fn build_all(
    targets: &[FmuTarget],
    platforms: &[Platform],
    out_dir: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<Built, BuildError> {
    let packages: Vec<&str> = targets.iter().map(|t| t.package).collect();
    let ids: Vec<&str> = targets.iter().map(|t| t.model_identifier.as_str()).collect();
    let mut libraries: Vec<(PlatformBuild, Vec<Vec<u8>>)> = Vec::new();
    for &platform in platforms {
        let started = std::time::Instant::now();
        let mut built = PlatformBuild::of(platform);
        let paths = if platform == Platform::Linux64 && platform.missing_toolchain().is_some() {
            build_host_linux64(targets)?
        } else {
            platform.build(&packages, &ids, &target_dir())?
        };
        let mut bytes = Vec::new();
        for path in &paths {
            bytes.push(std::fs::read(path).map_err(|e| BuildError::Io(path.clone(), e))?);
        }
        if platform == Platform::Linux64 || platform == Platform::Aarch64Linux {
            built = with_glibc_of(built, &bytes);
        }
        progress(&format!("{}: built in {:.1} s", platform.folder(), started.elapsed().as_secs_f64()));
        libraries.push((built, bytes));
    }
    let builds: Vec<PlatformBuild> = libraries.iter().map(|(b, _)| b.clone()).collect();
    std::fs::create_dir_all(out_dir).map_err(|e| BuildError::Io(out_dir.to_path_buf(), e))?;
    let (mut archives, mut archives3) = (Vec::new(), Vec::new());
    for (i, target) in targets.iter().enumerate() {
        let libs: Vec<(Platform, &[u8])> = libraries.iter().map(|(b, l)| (b.platform, l[i].as_slice())).collect();
        archives.push(write_archive(target, FmiVersion::Fmi2, &libs, &builds, out_dir)?);
        archives3.push(write_archive(target, FmiVersion::Fmi3, &libs, &builds, out_dir)?);
    }
    Ok(Built { archives, archives3, platforms: builds })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The archive `bytes` opened, with the names of its entries in archive order.
    fn opened(bytes: Vec<u8>) -> (zip::ZipArchive<Cursor<Vec<u8>>>, Vec<String>) {
        let mut z = zip::ZipArchive::new(Cursor::new(bytes)).unwrap();
        let names = (0..z.len()).map(|i| z.by_index(i).unwrap().name().to_string()).collect();
        (z, names)
    }

    #[test]
    fn archive_is_byte_identical_and_has_the_layout_importers_expect() {
        let t = &targets()[0];
        let xml = t.description.to_xml();
        let doc = &t.documentation;
        let libs: [(Platform, &[u8]); 2] = [(Platform::Linux64, b"\x7fELF fake"), (Platform::Win64, b"MZ fake")];
        let a = archive(FmiVersion::Fmi2, &xml, &libs, &t.model_identifier, doc).unwrap();
        let b = archive(FmiVersion::Fmi2, &xml, &libs, &t.model_identifier, doc).unwrap();
        assert_eq!(a, b);
        let (mut z, names) = opened(a);
        assert_eq!(
            names,
            [
                "modelDescription.xml",
                "binaries/linux64/nigel_plant.so",
                "binaries/win64/nigel_plant.dll",
                "documentation/index.html"
            ]
        );
        let mut text = String::new();
        std::io::Read::read_to_string(&mut z.by_name("modelDescription.xml").unwrap(), &mut text).unwrap();
        assert_eq!(text, xml);
    }

    #[test]
    fn fmi3_archive_has_the_fmi3_platform_folders_and_description() {
        let t = &targets()[0];
        let xml = t.xml(FmiVersion::Fmi3);
        assert!(xml.contains("fmiVersion=\"3.0\"") && xml.contains(&t.description.guid), "{xml}");
        // a universal library of two 4-byte slices: the fat header of <mach-o/fat.h>
        // (magic, 2 architectures), two fat_arch entries (cputype, cpusubtype, offset,
        // size, align), the slices at bytes 48 and 52
        let mut universal: Vec<u8> = [0xcafe_babe_u32, 2].iter().flat_map(|w| w.to_be_bytes()).collect();
        for (cpu, offset) in [(0x0100_0007_u32, 48_u32), (0x0100_000c, 52)] {
            universal.extend([cpu, 3, offset, 4, 2].iter().flat_map(|w| w.to_be_bytes()));
        }
        universal.extend(b"x64!arm!");
        let libs: [(Platform, &[u8]); 4] = [
            (Platform::Linux64, b"\x7fELF x86-64"),
            (Platform::Win64, b"MZ"),
            (Platform::Aarch64Linux, b"\x7fELF arm64"),
            (Platform::Darwin64, &universal),
        ];
        let a = archive(FmiVersion::Fmi3, &xml, &libs, &t.model_identifier, &t.documentation3).unwrap();
        assert_eq!(a, archive(FmiVersion::Fmi3, &xml, &libs, &t.model_identifier, &t.documentation3).unwrap());
        let (mut z, names) = opened(a);
        assert_eq!(
            names,
            [
                "modelDescription.xml",
                "binaries/x86_64-linux/nigel_plant.so",
                "binaries/x86_64-windows/nigel_plant.dll",
                "binaries/aarch64-linux/nigel_plant.so",
                "binaries/x86_64-darwin/nigel_plant.dylib",
                "binaries/aarch64-darwin/nigel_plant.dylib",
                "documentation/index.html"
            ]
        );
        // each Mac folder the slice of its architecture
        for (folder, slice) in [("x86_64-darwin", b"x64!"), ("aarch64-darwin", b"arm!")] {
            let mut bytes = Vec::new();
            std::io::Read::read_to_end(
                &mut z.by_name(&format!("binaries/{folder}/nigel_plant.dylib")).unwrap(),
                &mut bytes,
            )
            .unwrap();
            assert_eq!(&bytes, slice);
        }
        let mut doc = String::new();
        std::io::Read::read_to_string(&mut z.by_name("documentation/index.html").unwrap(), &mut doc).unwrap();
        assert!(doc.contains("The FMI 3.0 archive") && doc.contains("<code>nigel_plant.fmu</code>"), "{doc}");
    }

    /// A darwin64 library that is no universal one, or lacks an architecture, is refused
    /// for the FMI 3.0 archive (whose Mac folders take one slice each) and kept whole for
    /// the FMI 2.0 one (whose darwin64 is the universal library).
    #[test]
    fn fmi3_mac_folders_need_both_slices_of_a_universal_library() {
        let t = &targets()[0];
        let thin: &[u8] = b"\xcf\xfa\xed\xfe thin x86-64";
        let only_x86: Vec<u8> = [0xcafe_babe_u32, 1, 0x0100_0007, 3, 28, 4, 2]
            .iter()
            .flat_map(|w| w.to_be_bytes())
            .chain(*b"x64!")
            .collect();
        for (library, reason) in
            [(thin, "not a universal Mach-O library"), (&only_x86[..], "no slice of CPU type 0x100000c")]
        {
            let e = archive(FmiVersion::Fmi3, "<x/>", &[(Platform::Darwin64, library)], &t.model_identifier, "")
                .unwrap_err()
                .to_string();
            assert!(e.contains(reason), "{e}");
            let a =
                archive(FmiVersion::Fmi2, "<x/>", &[(Platform::Darwin64, library)], &t.model_identifier, "").unwrap();
            let mut z = zip::ZipArchive::new(Cursor::new(a)).unwrap();
            let mut bytes = Vec::new();
            std::io::Read::read_to_end(&mut z.by_name("binaries/darwin64/nigel_plant.dylib").unwrap(), &mut bytes)
                .unwrap();
            assert_eq!(bytes, library);
        }
    }

    #[test]
    fn fmi3_documentation_shows_the_fmi3_value_references() {
        let t = targets().into_iter().find(|t| t.model_identifier == "nigel_plant").unwrap();
        // row r of the declaration (the FMI 2.0 order) has FMI 3.0 value reference r + 1
        for (row, v) in t.description.model_variables.iter().enumerate() {
            let v3 = t.description3.variable_by_name(&v.name).unwrap();
            assert_eq!(v3.value_reference, row as u32 + 1, "{}", v.name);
            assert!(
                t.documentation3.contains(&format!(
                    "<tr><td><code>{}</code></td><td>{}</td>",
                    escape(&v.name),
                    row + 1
                )),
                "{}",
                v.name
            );
            assert!(t.documentation.contains(&format!(
                "<tr><td><code>{}</code></td><td>{}</td>",
                escape(&v.name),
                v.value_reference
            )));
        }
        assert!(t.documentation3.contains(&t.description3.instantiation_token));
        assert!(!t.documentation.contains("FMI 3.0"));
    }

    #[test]
    fn fmi3_closed_loop_ssp_is_the_fmi2_one_with_the_fmi3_archives() {
        use std::io::Read as _;
        let dir = std::env::temp_dir().join(format!("build-fmu-ssp3-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("fmi3")).unwrap();
        let ssd = "<ssd:SystemStructureDescription><ssd:Component source=\"resources/nigel_plant.fmu\"/></ssd:SystemStructureDescription>";
        let mut z = zip::ZipWriter::new(Cursor::new(Vec::new()));
        z.start_file("SystemStructure.ssd", SimpleFileOptions::default()).unwrap();
        z.write_all(ssd.as_bytes()).unwrap();
        z.start_file("resources/nigel_plant.fmu", SimpleFileOptions::default()).unwrap();
        z.write_all(b"fmi2 archive").unwrap();
        std::fs::write(dir.join("closed_loop.ssp"), z.finish().unwrap().into_inner()).unwrap();
        std::fs::write(dir.join("fmi3").join("nigel_plant.fmu"), b"fmi3 archive").unwrap();
        let out = dir.join("ssp").join("closed_loop_fmi3.ssp");
        write_closed_loop_ssp_fmi3(&dir.join("closed_loop.ssp"), &dir, &out).unwrap();
        let first = std::fs::read(&out).unwrap();
        let mut z = zip::ZipArchive::new(Cursor::new(first.clone())).unwrap();
        let mut text = String::new();
        z.by_name("SystemStructure.ssd").unwrap().read_to_string(&mut text).unwrap();
        assert_eq!(text, ssd);
        let mut fmu = Vec::new();
        z.by_name("resources/nigel_plant.fmu").unwrap().read_to_end(&mut fmu).unwrap();
        assert_eq!(fmu, b"fmi3 archive");
        // byte-identical when written again; a missing FMI 3.0 archive is an error naming it
        write_closed_loop_ssp_fmi3(&dir.join("closed_loop.ssp"), &dir, &out).unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), first);
        std::fs::remove_file(dir.join("fmi3").join("nigel_plant.fmu")).unwrap();
        let e = write_closed_loop_ssp_fmi3(&dir.join("closed_loop.ssp"), &dir, &out).unwrap_err();
        assert!(e.contains("fmi3/nigel_plant.fmu"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
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
        let plant_target = all.iter().find(|t| t.model_identifier == "nigel_plant").unwrap();
        let (plant, vr) =
            (&plant_target.documentation, |n: &str| plant_target.description.variable(n).unwrap().value_reference);
        // v_x: calculated from v_x_start, which is a parameter starting at 0
        assert!(plant.contains(&format!("<tr><td><code>v_x</code></td><td>{}</td><td>Output</td><td>Continuous</td><td>m/s</td><td></td><td>(calculated)</td>", vr("v_x"))), "{plant}");
        assert!(plant.contains(&format!(
            "<tr><td><code>v_x_start</code></td><td>{}</td><td>Parameter</td><td>Fixed</td><td>m/s</td><td></td><td>0</td>",
            vr("v_x_start")
        )));
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
    fn manifest_lists_every_target_with_its_interfaces_and_platforms() {
        let ts = targets();
        let builds: Vec<PlatformBuild> = Platform::ALL.into_iter().map(PlatformBuild::of).collect();
        let m = manifest(&ts, &builds);
        let parsed: serde_json::Value = serde_json::from_str(&m).unwrap();
        let entries = parsed.as_array().unwrap();
        // the FMI 2.0 archives first, then the FMI 3.0 ones
        assert_eq!(entries.len(), 2 * ts.len());
        let (entries, entries3) = entries.split_at(ts.len());
        for (t, e) in ts.iter().zip(entries3) {
            assert_eq!(e["fmi_version"], "3.0");
            assert_eq!(e["fmu"], format!("fmi3/{}.fmu", t.model_identifier));
            assert_eq!(e["instantiation_token"], t.description.guid);
            assert_eq!(e["interfaces"], serde_json::json!(t.interfaces()));
            let folders: Vec<&str> =
                e["platforms"].as_array().unwrap().iter().map(|p| p["folder"].as_str().unwrap()).collect();
            assert_eq!(folders, ["x86_64-linux", "x86_64-windows", "aarch64-linux", "x86_64-darwin", "aarch64-darwin"]);
            assert_eq!(e["platforms"][1]["library"], format!("binaries/x86_64-windows/{}.dll", t.model_identifier));
            assert_eq!(e["platforms"][4]["library"], format!("binaries/aarch64-darwin/{}.dylib", t.model_identifier));
            assert!(e["platforms"][1]["tested"].as_str().unwrap().contains("fmi3_closed_loop.c"), "{e}");
            assert_eq!(e["platforms"][1]["minimum_os"], Platform::Win64.minimum_os());
            assert_eq!(e["not_built"], serde_json::json!([]));
        }
        for (t, e) in ts.iter().zip(entries) {
            assert_eq!(e["fmi_version"], "2.0");
            assert_eq!(e["guid"], t.description.guid);
            assert!(e["platforms"][1]["tested"].as_str().unwrap().contains("fmi2_closed_loop.c"), "{e}");
            assert_eq!(e["fmu"], format!("{}.fmu", t.model_identifier));
            let folders: Vec<&str> =
                e["platforms"].as_array().unwrap().iter().map(|p| p["folder"].as_str().unwrap()).collect();
            assert_eq!(folders, ["linux64", "win64", "aarch64-linux", "darwin64"]);
            assert_eq!(e["platforms"][1]["library"], format!("binaries/win64/{}.dll", t.model_identifier));
            assert_eq!(e["platforms"][3]["library"], format!("binaries/darwin64/{}.dylib", t.model_identifier));
        }
        assert_eq!(entries[0]["interfaces"], serde_json::json!(["CoSimulation", "ModelExchange"]));
        // test.sh reads the identifiers with grep
        assert!(m.contains(r#""model_identifier": "nigel_plant""#), "{m}");
    }

    #[test]
    fn glibc_requirement_is_the_highest_version_named() {
        let lib = b"\x7fELF..libm.so.6\0GLIBC_2.2.5\0hypot\0GLIBC_2.35\0GLIBC_2.17\0GLIBC_PRIVATE\0";
        assert_eq!(glibc_requirement(lib), Some((2, 35)));
        assert_eq!(glibc_requirement(b"GLIBC_2.3.4\0GLIBC_2.14"), Some((2, 14)));
        assert_eq!(glibc_requirement(b"no versions"), None);
    }

    #[test]
    fn a_build_with_fewer_platforms_or_this_machines_glibc_says_so() {
        let targets = targets();
        let all: Vec<PlatformBuild> = Platform::ALL.into_iter().map(PlatformBuild::of).collect();
        let release: serde_json::Value = serde_json::from_str(&manifest(&targets, &all)).unwrap();
        assert_eq!(release[0]["not_built"], serde_json::json!([]));
        assert!(release[0]["platforms"][0]["tested"].as_str().unwrap().starts_with("by the test command"));

        // linux64 alone, against a glibc 2.35 library: three platforms missing, not tested
        let host = with_glibc_of(PlatformBuild::of(Platform::Linux64), &[b"GLIBC_2.35\0".to_vec()]);
        let one: serde_json::Value = serde_json::from_str(&manifest(&targets, std::slice::from_ref(&host))).unwrap();
        let missing: Vec<&str> = one[0]["not_built"].as_array().unwrap().iter().map(|m| m.as_str().unwrap()).collect();
        assert_eq!(missing.len(), 3);
        for (m, folder) in missing.iter().zip(["win64", "aarch64-linux", "darwin64"]) {
            assert!(m.starts_with(&format!("{folder}: not built")), "{m}");
        }
        // the FMI 3.0 archive of the same build lacks the same libraries, in its folders
        let fmi3 = &one[targets.len()];
        assert_eq!(fmi3["fmi_version"], "3.0");
        let missing3: Vec<&str> = fmi3["not_built"].as_array().unwrap().iter().map(|m| m.as_str().unwrap()).collect();
        assert_eq!(missing3.len(), 4);
        for (m, folder) in missing3.iter().zip(["x86_64-windows", "aarch64-linux", "x86_64-darwin", "aarch64-darwin"]) {
            assert!(m.starts_with(&format!("{folder}: not built")), "{m}");
        }
        for p in [&one[0]["platforms"][0], &fmi3["platforms"][0]] {
            assert!(p["tested"].as_str().unwrap().starts_with("not tested"), "{p}");
            assert_eq!(p["minimum_os"], "Linux with glibc 2.35 or later");
        }
        assert_eq!(fmi3["platforms"][0]["folder"], "x86_64-linux");
        let [doc, doc3] = [FmiVersion::Fmi2, FmiVersion::Fmi3].map(|version| {
            with_platform_table("<html><body></body></html>", "nigel_plant", std::slice::from_ref(&host), version)
        });
        assert!(doc.contains("not a release build") && doc.contains("<li>darwin64: not built"), "{doc}");
        assert!(doc3.contains("<li>aarch64-darwin: not built") && doc3.contains("<code>x86_64-linux</code>"), "{doc3}");
        for version in FmiVersion::ALL {
            assert!(!with_platform_table("<body></body>", "nigel_plant", &all, version).contains("not a release build"));
        }
    }

    #[test]
    fn documentation_gets_one_platform_row_per_platform_before_the_end() {
        let t = &targets()[1];
        let builds: Vec<PlatformBuild> = Platform::ALL.into_iter().map(PlatformBuild::of).collect();
        let doc = with_platform_table(&t.documentation, &t.model_identifier, &builds, FmiVersion::Fmi2);
        assert!(doc.ends_with("</table>\n</body></html>\n"), "{doc}");
        let doc3 = with_platform_table(&t.documentation3, &t.model_identifier, &builds, FmiVersion::Fmi3);
        assert_eq!(doc3.matches("<tr><td><code>").count(), t.description.model_variables.len() + 5);
        assert!(doc3.contains(
            "<tr><td><code>aarch64-darwin</code></td><td><code>nigel_controller.dylib</code></td><td>macOS 11 or later"
        ));
        assert_eq!(doc.matches("<tr><td><code>").count(), t.description.model_variables.len() + 4);
        assert!(doc.contains(
            "<tr><td><code>win64</code></td><td><code>nigel_controller.dll</code></td><td>64-bit Windows 10 or later"
        ));
        assert!(doc.contains(
            "<td><code>darwin64</code></td><td><code>nigel_controller.dylib</code></td><td>macOS 11 or later"
        ));
        assert!(doc.contains("not executed (no macOS there)"));
    }

    #[test]
    fn platform_folders_round_trip() {
        for p in Platform::ALL {
            assert_eq!(Platform::from_folder(p.folder()), Some(p));
        }
        assert_eq!(Platform::from_folder("win32"), None);
    }
}

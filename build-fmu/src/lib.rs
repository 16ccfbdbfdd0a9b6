//! Packaging of FMUs: the archive layout importers expect, generated from the models'
//! declarations, written deterministically (fixed order, timestamps and permissions), with
//! one library per [`Platform`] in each archive.

pub mod platform;

use std::fmt::Write as _;
use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};
use std::process::Command;

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
/// object per FMU with its model identifier, package, archive file name, interfaces and the
/// platforms its archive carries (each with its library, minimum OS, C library and how it is
/// tested), so that tests iterate over exactly what was built.
pub fn manifest(targets: &[FmuTarget], platforms: &[PlatformBuild]) -> String {
    let entries: Vec<serde_json::Value> = targets
        .iter()
        .map(|t| {
            serde_json::json!({
                "model_identifier": t.model_identifier,
                "package": t.package,
                "fmu": format!("{}.fmu", t.model_identifier),
                "guid": t.description.guid,
                "interfaces": t.interfaces(),
                "platforms": platforms.iter().map(|p| serde_json::json!({
                    "folder": p.platform.folder(),
                    "library": format!("binaries/{}/{}", p.platform.folder(), p.platform.library_file(&t.model_identifier)),
                    "minimum_os": p.minimum_os,
                    "c_library": p.c_library,
                    "tested": p.tested,
                })).collect::<Vec<_>>(),
                "not_built": platforms_not_built(platforms),
            })
        })
        .collect();
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
}

/// The release platforms an archive of `platforms` lacks, each with why; empty for a
/// release build (all of [`Platform::ALL`]).
pub fn platforms_not_built(platforms: &[PlatformBuild]) -> Vec<String> {
    Platform::ALL
        .iter()
        .filter(|p| !platforms.iter().any(|b| b.platform == **p))
        .map(|p| {
            format!(
                "{}: not built (this build asked for fewer platforms; the release archives carry all of {})",
                p.folder(),
                Platform::ALL.map(|p| p.folder()).join(", ")
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

/// The platforms' part of `documentation/index.html`: a table of the platforms the archive
/// carries, inserted before the end of the body.
pub fn with_platform_table(documentation: &str, model_identifier: &str, platforms: &[PlatformBuild]) -> String {
    let mut table = String::from(
        "<h2>Platforms</h2>\n<table>\n<tr><th>folder</th><th>library</th><th>needs</th><th>C library</th><th>tested</th></tr>\n",
    );
    for p in platforms {
        let _ = writeln!(
            table,
            "<tr><td><code>{}</code></td><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td></tr>",
            p.platform.folder(),
            escape(&p.platform.library_file(model_identifier)),
            escape(&p.minimum_os),
            escape(&p.c_library),
            escape(&p.tested),
        );
    }
    table.push_str("</table>\n");
    let missing = platforms_not_built(platforms);
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

/// The archive bytes: `modelDescription.xml`, `binaries/<platform>/<id>.<ext>` for each
/// library (in the order given), `documentation/index.html`, with fixed timestamps and modes.
pub fn archive(
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
        entries.push((
            format!("binaries/{}/{}", platform.folder(), platform.library_file(model_identifier)),
            bytes,
            0o755,
        ));
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
    let features: Vec<String> = targets.iter().map(|t| format!("{}/fmi-export", t.package)).collect();
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

/// Builds one FMU for linux64 with the workspace's own cargo (no cross toolchain needed;
/// the library needs the build machine's glibc, which its documentation then states) and
/// writes `<out_dir>/<id>.fmu`; returns its path and size. For an FMU of one's own whose
/// crate depends on this one: the cross builds of [`build_all`] would build this crate's
/// own dependencies (the master) for every platform too.
pub fn build_for_this_machine(target: &FmuTarget, out_dir: &Path) -> Result<(PathBuf, usize), BuildError> {
    let paths = build_host_linux64(std::slice::from_ref(target))?;
    let library = std::fs::read(&paths[0]).map_err(|e| BuildError::Io(paths[0].clone(), e))?;
    let built = with_glibc_of(PlatformBuild::of(Platform::Linux64), std::slice::from_ref(&library));
    let documentation = with_platform_table(&target.documentation, &target.model_identifier, &[built]);
    let libraries = [(Platform::Linux64, library.as_slice())];
    let bytes = archive(&target.description.to_xml(), &libraries, &target.model_identifier, &documentation)?;
    std::fs::create_dir_all(out_dir).map_err(|e| BuildError::Io(out_dir.to_path_buf(), e))?;
    let path = out_dir.join(format!("{}.fmu", target.model_identifier));
    std::fs::write(&path, &bytes).map_err(|e| BuildError::Io(path.clone(), e))?;
    Ok((path, bytes.len()))
}

/// What [`build_all`] wrote.
#[derive(Debug)]
pub struct Built {
    /// Each archive's path and size in bytes, in the order of the targets.
    pub archives: Vec<(PathBuf, usize)>,
    /// How each platform was built (toolchain, C library baseline).
    pub platforms: Vec<PlatformBuild>,
}

/// Builds every target for every platform of `platforms` and writes `<out_dir>/<id>.fmu`
/// for each, carrying all those platforms; returns each archive's path and size.
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
    let mut written = Vec::new();
    for (i, target) in targets.iter().enumerate() {
        let libs: Vec<(Platform, &[u8])> = libraries.iter().map(|(b, l)| (b.platform, l[i].as_slice())).collect();
        let documentation = with_platform_table(&target.documentation, &target.model_identifier, &builds);
        let bytes = archive(&target.description.to_xml(), &libs, &target.model_identifier, &documentation)?;
        let path = out_dir.join(format!("{}.fmu", target.model_identifier));
        std::fs::write(&path, &bytes).map_err(|e| BuildError::Io(path.clone(), e))?;
        written.push((path, bytes.len()));
    }
    Ok(Built { archives: written, platforms: builds })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn archive_is_byte_identical_and_has_the_layout_importers_expect() {
        let t = &targets()[0];
        let xml = t.description.to_xml();
        let doc = &t.documentation;
        let libs: [(Platform, &[u8]); 2] = [(Platform::Linux64, b"\x7fELF fake"), (Platform::Win64, b"MZ fake")];
        let a = archive(&xml, &libs, &t.model_identifier, doc).unwrap();
        let b = archive(&xml, &libs, &t.model_identifier, doc).unwrap();
        assert_eq!(a, b);
        let mut z = zip::ZipArchive::new(Cursor::new(a)).unwrap();
        let names: Vec<String> = (0..z.len()).map(|i| z.by_index(i).unwrap().name().to_string()).collect();
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
        assert_eq!(entries.len(), ts.len());
        for (t, e) in ts.iter().zip(entries) {
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
        let p = &one[0]["platforms"][0];
        assert!(p["tested"].as_str().unwrap().starts_with("not tested"), "{p}");
        assert_eq!(p["minimum_os"], "Linux with glibc 2.35 or later");
        let doc = with_platform_table("<html><body></body></html>", "nigel_plant", std::slice::from_ref(&host));
        assert!(doc.contains("not a release build") && doc.contains("<li>darwin64: not built"), "{doc}");
        assert!(!with_platform_table("<body></body>", "nigel_plant", &all).contains("not a release build"));
    }

    #[test]
    fn documentation_gets_one_platform_row_per_platform_before_the_end() {
        let t = &targets()[1];
        let builds: Vec<PlatformBuild> = Platform::ALL.into_iter().map(PlatformBuild::of).collect();
        let doc = with_platform_table(&t.documentation, &t.model_identifier, &builds);
        assert!(doc.ends_with("</table>\n</body></html>\n"), "{doc}");
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

//! Importing an FMU: one pipeline for both generations. Unpack, read the model description
//! and its view, choose the interface, find `binaries/<platform>/<modelIdentifier>.so`,
//! resolve the function table (or, imported isolated, only check the library's symbols),
//! check the functions the interface needs. What differs between FMI 2.0 and FMI 3.0 is a
//! [`Generation`]: the platform folder, the core symbols, the table, the functions each
//! interface needs, and what instantiation needs besides the table.

use std::ffi::CString;
use std::path::Path;
use std::sync::Arc;

use fmi_sys::FunctionTable;
use model_description::ModelDescription;

use crate::c_types::{Fmi3Functions, Functions};
use crate::error::{Error, Result};
use crate::fmu::{Abi, Fmu, ImportOptions, Interface};
use crate::library::load_library;
use crate::unpack::{ArchiveSource, UnpackLimits};

/// What instantiation needs besides the table (see [`Generation::finish`]).
type Loaded = (Abi, CString, Vec<(String, crate::fmi3::LeftOut)>);

/// What loading an FMU differs in between the generations.
trait Generation {
    /// The library's function table.
    type Table: fmi_sys::FunctionTable;
    /// The model description as read, beyond the view every FMU has.
    type Described;
    /// The platform folder under `binaries/` (the standard's name for 64-bit Linux).
    const PLATFORM: &'static str;
    /// The description of `xml` (of the archive `path`), checked: its view (FMI 2.0-shaped)
    /// and the rest.
    fn describe(xml: &str, path: &Path) -> Result<(ModelDescription, Self::Described)>;
    /// The first of the core functions (which resolving the table requires) `present`
    /// lacks.
    fn missing_core(present: &dyn Fn(&str) -> bool) -> Option<&'static str>;
    /// Resolves the table of `library`.
    ///
    /// # Safety
    /// `library` must be a library of this generation whose symbols have its C signatures.
    unsafe fn resolve(library: &libloading::Library, shown: &Path) -> Result<Self::Table>;
    /// The table of an FMU imported isolated: every call goes to the instance's host.
    fn proxy(present: &dyn Fn(&str) -> bool) -> Self::Table;
    /// The functions `interface` needs beyond the core ones.
    fn needs(interface: Interface) -> &'static [&'static str];
    /// The model identifier of Scheduled Execution (FMI 3.0 only).
    fn scheduled_identifier(_described: &Self::Described) -> Option<String> {
        None
    }
    /// What the master cannot run of the FMU with `interface`, named; `None`: nothing.
    fn unsupported(_described: &Self::Described, _interface: Interface) -> Option<String> {
        None
    }
    /// Whether the functions the interface needs are checked on the proxy table too (an
    /// FMI 3.0 proxy has no instantiate functions: its host instantiates).
    const NEEDS_CHECKED_ISOLATED: bool;
    /// The table and what instantiation needs besides (FMI 2.0: the resources URI; FMI
    /// 3.0: the instantiation token and the resource path), and the variables the view
    /// leaves out.
    fn finish(table: Self::Table, described: Self::Described, dir: &Path, path: &Path) -> Result<Loaded>;
}

/// FMI 2.0.
struct Fmi2;

/// FMI 3.0.
struct Fmi3;

/// The error for a temporary folder whose path C cannot take.
fn nul_in_folder(dir: &Path) -> Error {
    Error::LoadLibrary { path: dir.to_path_buf(), reason: "the temporary folder's path contains NUL".into() }
}

impl Generation for Fmi2 {
    type Table = Functions;
    type Described = ();
    const PLATFORM: &'static str = crate::platform::FMI2_FOLDER;
    const NEEDS_CHECKED_ISOLATED: bool = true;

    fn describe(xml: &str, path: &Path) -> Result<(ModelDescription, ())> {
        let description = ModelDescription::from_xml(xml)
            .map_err(|e| Error::ModelDescription { path: path.to_path_buf(), reason: e.to_string() })?;
        let mut names = std::collections::HashMap::with_capacity(description.model_variables.len());
        for (k, v) in description.model_variables.iter().enumerate() {
            if let Some(first) = names.insert(v.name.as_str(), k + 1) {
                return Err(Error::ModelDescription {
                    path: path.to_path_buf(),
                    reason: format!(
                        "variables {first} and {} are both called {:?} (variable names must be unique)",
                        k + 1,
                        v.name
                    ),
                });
            }
        }
        Ok((description, ()))
    }

    fn missing_core(present: &dyn Fn(&str) -> bool) -> Option<&'static str> {
        // the 15 core functions, which `Fmi2Functions::load` requires, lead SYMBOLS
        fmi_sys::fmi2::SYMBOLS.iter().take(15).map(|(s, _)| *s).find(|s| !present(s))
    }

    unsafe fn resolve(library: &libloading::Library, shown: &Path) -> Result<Functions> {
        // SAFETY: the caller's.
        unsafe { crate::library::load_functions(library, shown) }
    }

    fn proxy(present: &dyn Fn(&str) -> bool) -> Functions {
        crate::isolate::proxy::table(present)
    }

    fn needs(interface: Interface) -> &'static [&'static str] {
        match interface {
            Interface::CoSimulation => &["fmi2DoStep"],
            Interface::ModelExchange => &[
                "fmi2EnterEventMode",
                "fmi2NewDiscreteStates",
                "fmi2EnterContinuousTimeMode",
                "fmi2CompletedIntegratorStep",
                "fmi2SetTime",
                "fmi2SetContinuousStates",
                "fmi2GetDerivatives",
                "fmi2GetEventIndicators",
                "fmi2GetContinuousStates",
            ],
            // FMI 2.0 has no Scheduled Execution: refused before (no model identifier)
            Interface::ScheduledExecution => &[],
        }
    }

    fn finish(table: Functions, _: (), dir: &Path, _: &Path) -> Result<Loaded> {
        let resource_uri = CString::new(file_uri(&dir.join("resources"))).map_err(|_| nul_in_folder(dir))?;
        Ok((Abi::Fmi2(Arc::new(table)), resource_uri, Vec::new()))
    }
}

/// What FMI 3.0 reads beyond the view: its own description, how the view reaches the
/// variables that are not plain scalars, and what it leaves out.
type Fmi3Described = (
    model_description::fmi3::ModelDescription,
    std::collections::HashMap<u32, crate::fmi3::Access>,
    Vec<(String, crate::fmi3::LeftOut)>,
);

impl Generation for Fmi3 {
    type Table = Fmi3Functions;
    type Described = Fmi3Described;
    const PLATFORM: &'static str = crate::platform::FMI3_FOLDER;
    const NEEDS_CHECKED_ISOLATED: bool = false;

    fn unsupported((md, _, _): &Fmi3Described, interface: Interface) -> Option<String> {
        crate::fmi3::unsupported_feature(md, interface == Interface::ScheduledExecution)
    }

    fn scheduled_identifier((md, _, _): &Fmi3Described) -> Option<String> {
        md.scheduled_execution.as_ref().map(|se| se.common.model_identifier.clone())
    }

    fn describe(xml: &str, path: &Path) -> Result<(ModelDescription, Fmi3Described)> {
        let md = checked_fmi3(xml, path)?;
        let (view, special, not_in_view) = crate::fmi3::fmi2_view(&md);
        Ok((view, (md, special, not_in_view)))
    }

    fn missing_core(present: &dyn Fn(&str) -> bool) -> Option<&'static str> {
        // the 7 core functions, which `Fmi3Functions::load` requires, lead SYMBOLS
        fmi_sys::fmi3::functions::SYMBOLS.iter().take(7).map(|(s, _)| *s).find(|s| !present(s))
    }

    unsafe fn resolve(library: &libloading::Library, shown: &Path) -> Result<Fmi3Functions> {
        // SAFETY: the caller's.
        unsafe { Fmi3Functions::load(library) }
            .map_err(|missing| Error::MissingSymbol { path: shown.to_path_buf(), symbol: missing.0 })
    }

    fn proxy(present: &dyn Fn(&str) -> bool) -> Fmi3Functions {
        crate::isolate::proxy3::table(present)
    }

    fn needs(interface: Interface) -> &'static [&'static str] {
        match interface {
            Interface::CoSimulation => &["fmi3InstantiateCoSimulation", "fmi3DoStep"],
            Interface::ModelExchange => &[
                "fmi3InstantiateModelExchange",
                "fmi3EnterEventMode",
                "fmi3UpdateDiscreteStates",
                "fmi3EnterContinuousTimeMode",
                "fmi3CompletedIntegratorStep",
                "fmi3SetTime",
                "fmi3SetContinuousStates",
                "fmi3GetContinuousStateDerivatives",
                "fmi3GetEventIndicators",
                "fmi3GetContinuousStates",
            ],
            Interface::ScheduledExecution => {
                &["fmi3InstantiateScheduledExecution", "fmi3ActivateModelPartition", "fmi3GetIntervalDecimal"]
            }
        }
    }

    fn finish(
        functions: Fmi3Functions,
        (md, special, not_in_view): Fmi3Described,
        dir: &Path,
        path: &Path,
    ) -> Result<Loaded> {
        let token = CString::new(md.instantiation_token.as_str()).map_err(|_| Error::ModelDescription {
            path: path.to_path_buf(),
            reason: "NUL in instantiationToken".into(),
        })?;
        let resource_path = crate::fmi3::resource_path(dir).ok_or_else(|| nul_in_folder(dir))?;
        let abi = crate::fmi3::Fmi3Abi {
            functions,
            description: md,
            special,
            token,
            resource_path,
            configuration: Vec::new(),
            initial_sizes: Vec::new(),
        };
        Ok((Abi::Fmi3(Arc::new(abi)), CString::default(), not_in_view))
    }
}

/// The text of `modelDescription.xml` of an unpacked FMU (at most `limits.max_xml_bytes`).
fn read_xml(dir: &Path, source: &Path, limits: &UnpackLimits) -> Result<String> {
    let path = dir.join("modelDescription.xml");
    crate::unpack::read_text_file(&path, "modelDescription.xml", limits.max_xml_bytes).map_err(|e| match e {
        Error::Io { source: e, .. } => {
            Error::ModelDescription { path: source.to_path_buf(), reason: format!("cannot read it: {e}") }
        }
        other => other,
    })
}

/// Whether `xml` is an FMI 3.0 description.
fn is_fmi3(xml: &str) -> bool {
    model_description::fmi3::fmi_version_of(xml).is_some_and(|v| v.starts_with("3."))
}

/// Reads the FMI 2.0 `modelDescription.xml` of an unpacked FMU (at most
/// `limits.max_xml_bytes`).
pub fn read_model_description(dir: &Path, source: &Path, limits: &UnpackLimits) -> Result<ModelDescription> {
    ModelDescription::from_xml(&read_xml(dir, source, limits)?)
        .map_err(|e| Error::ModelDescription { path: source.to_path_buf(), reason: e.to_string() })
}

/// The FMI 3.0 description of the FMU archive `path`, read and checked as
/// [`Fmu::load`] does (but for what the master runs: an FMU with clocks is read), without
/// loading its library; `None` for an FMI 2.0 FMU.
pub fn read_fmi3_description(
    path: &Path,
    limits: &UnpackLimits,
) -> Result<Option<model_description::fmi3::ModelDescription>> {
    let unpacked = crate::unpack::unpack_fmu(&ArchiveSource::File(path.to_path_buf()), limits)?;
    let xml = read_xml(unpacked.dir.path(), path, limits)?;
    if !is_fmi3(&xml) {
        return Ok(None);
    }
    checked_fmi3(&xml, path).map(Some)
}

/// Reads an FMI 3.0 description and refuses what [`FMI3_REFUSED`] lists (what the master
/// does not run with the interface chosen is refused by [`load`]).
fn checked_fmi3(xml: &str, path: &Path) -> Result<model_description::fmi3::ModelDescription> {
    let refuse = |reason: String| Error::ModelDescription { path: path.to_path_buf(), reason };
    let md = model_description::fmi3::ModelDescription::from_xml(xml).map_err(|e| refuse(e.to_string()))?;
    let problems: Vec<String> =
        md.validate().into_iter().filter(|p| FMI3_REFUSED.contains(&p.rule)).map(|p| p.to_string()).collect();
    if !problems.is_empty() {
        return Err(refuse(problems.join("; ")));
    }
    Ok(md)
}

/// The problems of an FMI 3.0 description that make its import wrong, refused at load.
const FMI3_REFUSED: &[model_description::fmi3::Rule] = {
    use model_description::fmi3::Rule as R;
    &[
        R::DuplicateName,
        R::DuplicateValueReference,
        R::Independent,
        R::UnknownValueReference,
        R::Dimension,
        R::StartCount,
        R::Derivative,
    ]
};

fn file_uri(path: &Path) -> String {
    let mut uri = String::from("file://");
    for b in path.to_string_lossy().bytes() {
        if b.is_ascii_alphanumeric() || b"/-._~".contains(&b) {
            uri.push(b as char);
        } else {
            uri.push_str(&format!("%{b:02X}"));
        }
    }
    uri
}

impl Fmu {
    /// Imports `path` with default limits, Co-Simulation preferred.
    pub fn load(path: &Path) -> Result<Arc<Fmu>> {
        Fmu::load_with(path, &ImportOptions::default())
    }

    /// Imports `path`: unpack, read the XML, find and load `binaries/linux64/<id>.so`
    /// (FMI 3.0: `binaries/x86_64-linux/`), resolve the functions of the interface.
    pub fn load_with(path: &Path, options: &ImportOptions) -> Result<Arc<Fmu>> {
        Fmu::load_from(&ArchiveSource::File(path.to_path_buf()), options)
    }

    /// Imports the FMU `origin` (a file, or an entry of an `.ssp` read from it in place):
    /// only `modelDescription.xml`, `binaries/<platform>/` and `resources/` are unpacked.
    pub fn load_from(origin: &ArchiveSource, options: &ImportOptions) -> Result<Arc<Fmu>> {
        let unpacked = crate::unpack::unpack_fmu(origin, &options.limits)?;
        let xml = read_xml(unpacked.dir.path(), &origin.shown(), &options.limits)?;
        if is_fmi3(&xml) {
            load::<Fmi3>(origin, options, unpacked, &xml)
        } else {
            load::<Fmi2>(origin, options, unpacked, &xml)
        }
    }
}

/// The pipeline of [`Fmu::load_from`] for the generation `G` of `xml`.
fn load<G: Generation>(
    origin: &ArchiveSource,
    options: &ImportOptions,
    unpacked: crate::unpack::UnpackedFmu,
    xml: &str,
) -> Result<Arc<Fmu>> {
    let shown_path = origin.shown();
    let path = shown_path.as_path();
    let dir = unpacked.dir;
    let (description, described) = G::describe(xml, path)?;
    let interface = match options.interface {
        Some(i) => i,
        None if description.co_simulation.is_some() => Interface::CoSimulation,
        None if description.model_exchange.is_none() && G::scheduled_identifier(&described).is_some() => {
            Interface::ScheduledExecution
        }
        None => Interface::ModelExchange,
    };
    let identifier = match interface {
        Interface::CoSimulation => description.co_simulation.as_ref().map(|c| c.model_identifier.clone()),
        Interface::ModelExchange => description.model_exchange.as_ref().map(|m| m.model_identifier.clone()),
        Interface::ScheduledExecution => G::scheduled_identifier(&described),
    }
    .ok_or(Error::NoInterface { path: path.to_path_buf(), interface: interface.as_str() })?;
    // an interface the FMU does not offer is named first (the Clocks of the Reference FMUs
    // asked for in Co-Simulation: it has none), then what the master does not run in it
    if let Some(feature) = G::unsupported(&described, interface) {
        return Err(Error::Unsupported { path: path.to_path_buf(), feature });
    }
    if !model_description::is_c_identifier(&identifier) {
        return Err(Error::ModelDescription {
            path: path.to_path_buf(),
            reason: format!("modelIdentifier {identifier:?} is not a C identifier"),
        });
    }
    let relative = format!("binaries/{}/{identifier}.{}", G::PLATFORM, crate::platform::LIBRARY_EXTENSION);
    let so = dir.path().join(&relative);
    if !so.is_file() {
        return Err(Error::MissingBinary { expected: relative, platforms: unpacked.platforms });
    }
    // errors name the library inside the archive, not the temporary copy
    let shown = path.join(&relative);
    let (library, table) = if options.isolated {
        // read and checked only: nothing of the library runs in this process
        let bytes = std::fs::read(&so).map_err(|source| Error::Io { path: shown.clone(), source })?;
        crate::platform::check_library(&bytes).map_err(|reason| Error::LoadLibrary { path: shown.clone(), reason })?;
        // without section headers every function is taken as present: a missing one
        // is then the host's error when called
        let exported = crate::platform::exported_symbols(&bytes);
        let present = |symbol: &str| exported.as_ref().is_none_or(|e| e.contains(symbol));
        if let Some(symbol) = G::missing_core(&present) {
            return Err(Error::MissingSymbol { path: shown, symbol });
        }
        (None, G::proxy(&present))
    } else {
        let library = load_library(&so, &shown, &relative)?;
        // SAFETY: the symbols are declared with the C signatures of the generation's headers.
        let table = unsafe { G::resolve(&library, &shown)? };
        (Some(library), table)
    };
    let checked = library.is_some() || G::NEEDS_CHECKED_ISOLATED;
    if let Some(symbol) = G::needs(interface).iter().find(|s| checked && !table.has(s)) {
        return Err(Error::MissingSymbol { path: shown, symbol });
    }
    let (abi, resource_uri, not_in_view) = G::finish(table, described, dir.path(), path)?;
    let mut fmu = Fmu {
        abi,
        allow_non_finite: options.allow_non_finite,
        _library: library,
        description,
        interface,
        source: path.to_path_buf(),
        origin: origin.clone(),
        resource_uri,
        dir: Some(dir),
        isolated_from: None,
        library_path: so,
        not_in_view,
        configured_from: None,
        event_mode: None,
    };
    if let Some(feature) = clocks_not_run(&fmu) {
        return Err(Error::Unsupported { path: path.to_path_buf(), feature });
    }
    fmu.event_mode = event_mode_of(&fmu, options.event_mode)
        .map_err(|reason| Error::EventMode { path: path.to_path_buf(), reason })?;
    Ok(Arc::new(fmu))
}

/// FMI 3.0 Co-Simulation: `eventModeUsed` of `fmu`'s instances under `choice`
/// ([`crate::event_mode::decide`]); `None` for the other generation and interfaces.
fn event_mode_of(fmu: &Fmu, choice: crate::EventModeChoice) -> std::result::Result<Option<crate::EventMode>, String> {
    match fmu.fmi3_description() {
        Some(md) if fmu.interface == Interface::CoSimulation => {
            crate::event_mode::decide(md, &fmu.clocks(), choice).map(Some)
        }
        _ => Ok(None),
    }
}

/// Clocks where the master does not run them: in Co-Simulation without Event Mode.
fn clocks_not_run(fmu: &Fmu) -> Option<String> {
    let clocks = fmu.clocks();
    let first = clocks.first()?;
    let has_event_mode = fmu.fmi3_description()?.co_simulation.as_ref().is_some_and(|cs| cs.has_event_mode);
    let why = match fmu.interface {
        // Scheduled Execution runs the clocks itself (its model partitions)
        Interface::ScheduledExecution => return None,
        Interface::CoSimulation if !has_event_mode => "in Co-Simulation without Event Mode (hasEventMode)",
        _ => return None,
    };
    Some(format!("clocks {why} (Clock variable {:?})", first.name))
}

//! Import of one FMU, FMI 2.0 or FMI 3.0: unpack, read the model description, load the
//! library, resolve the functions of the chosen interface; and [`Instance`], whose every
//! call returns a typed [`Result`], the same calls for both generations (an FMI 3.0 FMU's
//! scalars as the FMI 2.0-shaped view of [`crate::fmi3`]). An instance terminates and
//! frees itself on drop.

use crate::c_types::{CallbackFunctions, Component, Functions, RawStatus};
use crate::error::{Error, Result, Status};
use crate::library::{load_functions, load_library};
use crate::log::{callbacks_for, LogRecord, LogSink};
use crate::unpack::{ArchiveSource, UnpackLimits};
use model_description::ModelDescription;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use crate::c_types::EventInfo;

/// The FMI interface an instance uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interface {
    /// Co-Simulation: the FMU steps itself (`fmi2DoStep`).
    CoSimulation,
    /// Model Exchange: the master integrates the FMU's derivatives.
    ModelExchange,
}

impl Interface {
    /// The XML element name.
    pub fn as_str(self) -> &'static str {
        match self {
            Interface::CoSimulation => "CoSimulation",
            Interface::ModelExchange => "ModelExchange",
        }
    }
    fn fmi_type(self) -> c_int {
        match self {
            Interface::ModelExchange => 0,
            Interface::CoSimulation => 1,
        }
    }
}

/// The functions of an FMU: FMI 2.0's table, or FMI 3.0's with the FMU's own description.
pub(crate) enum Abi {
    /// FMI 2.0 (in process, or the isolation proxy).
    Fmi2(Functions),
    /// FMI 3.0.
    Fmi3(Box<crate::fmi3::Fmi3Abi>),
}

/// The functions each interface needs beyond the common ones (checked at load).
const CS_NEEDS: &[&str] = &["fmi2DoStep"];
const ME_NEEDS: &[&str] = &[
    "fmi2EnterEventMode",
    "fmi2NewDiscreteStates",
    "fmi2EnterContinuousTimeMode",
    "fmi2CompletedIntegratorStep",
    "fmi2SetTime",
    "fmi2SetContinuousStates",
    "fmi2GetDerivatives",
    "fmi2GetEventIndicators",
    "fmi2GetContinuousStates",
];

/// How to import: unpack limits and the interface to load.
#[derive(Clone, Debug, Default)]
pub struct ImportOptions {
    /// Archive limits.
    pub limits: UnpackLimits,
    /// The interface; `None`: Co-Simulation if the FMU has it, else Model Exchange.
    pub interface: Option<Interface>,
    /// Pass on NaN and infinite Reals an FMU returns with fmi2OK (default: refused at
    /// the source, [`Error::NonFinite`] naming the FMU and the variable).
    pub allow_non_finite: bool,
    /// Do not load the library into this process: its functions are known from its ELF
    /// symbol table, and its instances can only run in host processes
    /// ([`Instance::new_isolated`], `Experiment::isolation`), so that not even its
    /// load-time initializers run here.
    pub isolated: bool,
}

/// An imported FMU: its unpacked folder (removed on drop), model description and library.
/// Share it between instances with `Arc`; it outlives them.
pub struct Fmu {
    pub(crate) abi: Abi,
    allow_non_finite: bool,
    /// The library loaded in this process (`None`: imported isolated, never loaded here).
    _library: Option<Arc<libloading::Library>>,
    description: ModelDescription,
    interface: Interface,
    source: PathBuf,
    /// Where the archive is (a file, or an entry of an `.ssp`).
    origin: ArchiveSource,
    resource_uri: CString,
    /// The unpacked folder: owned, or that of the FMU this is the isolated view of.
    dir: Option<tempfile::TempDir>,
    /// Isolated view: the FMU whose library runs in host processes.
    isolated_from: Option<Arc<Fmu>>,
    /// The library inside the unpacked folder.
    library_path: PathBuf,
    /// FMI 3.0: the variables not in the view and why (see [`crate::fmi3`]).
    not_in_view: Vec<(String, crate::fmi3::LeftOut)>,
}

impl std::fmt::Debug for Fmu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fmu").field("source", &self.source).field("interface", &self.interface).finish()
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

/// Reads the FMI 2.0 `modelDescription.xml` of an unpacked FMU (at most
/// `limits.max_xml_bytes`).
pub fn read_model_description(dir: &Path, source: &Path, limits: &UnpackLimits) -> Result<ModelDescription> {
    ModelDescription::from_xml(&read_xml(dir, source, limits)?)
        .map_err(|e| Error::ModelDescription { path: source.to_path_buf(), reason: e.to_string() })
}

/// The FMI 3.0 description of the FMU archive `path`, read and checked as
/// [`Fmu::load`] does, without loading its library; `None` for an FMI 2.0 FMU.
pub fn read_fmi3_description(
    path: &Path,
    limits: &UnpackLimits,
) -> Result<Option<model_description::fmi3::ModelDescription>> {
    let unpacked = crate::unpack::unpack_fmu(&ArchiveSource::File(path.to_path_buf()), limits)?;
    let xml = read_xml(unpacked.dir.path(), path, limits)?;
    if !model_description::fmi3::fmi_version_of(&xml).is_some_and(|v| v.starts_with("3.")) {
        return Ok(None);
    }
    checked_fmi3(&xml, path).map(Some)
}

/// Reads an FMI 3.0 description and refuses what [`FMI3_REFUSED`] lists and what the
/// master does not run.
fn checked_fmi3(xml: &str, path: &Path) -> Result<model_description::fmi3::ModelDescription> {
    let refuse = |reason: String| Error::ModelDescription { path: path.to_path_buf(), reason };
    let md = model_description::fmi3::ModelDescription::from_xml(xml).map_err(|e| refuse(e.to_string()))?;
    let problems: Vec<String> =
        md.validate().into_iter().filter(|p| FMI3_REFUSED.contains(&p.rule)).map(|p| p.to_string()).collect();
    if !problems.is_empty() {
        return Err(refuse(problems.join("; ")));
    }
    if let Some(feature) = crate::fmi3::unsupported_feature(&md) {
        return Err(Error::Unsupported { path: path.to_path_buf(), feature });
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

    /// Imports `path`: unpack, read the XML, find and load `binaries/linux64/<id>.so`,
    /// resolve the functions of the interface.
    pub fn load_with(path: &Path, options: &ImportOptions) -> Result<Arc<Fmu>> {
        Fmu::load_from(&ArchiveSource::File(path.to_path_buf()), options)
    }

    /// Imports the FMU `origin` (a file, or an entry of an `.ssp` read from it in place):
    /// only `modelDescription.xml`, `binaries/linux64/` and `resources/` are unpacked.
    pub fn load_from(origin: &ArchiveSource, options: &ImportOptions) -> Result<Arc<Fmu>> {
        let shown_path = origin.shown();
        let path = shown_path.as_path();
        let unpacked = crate::unpack::unpack_fmu(origin, &options.limits)?;
        let dir = unpacked.dir;
        let xml = read_xml(dir.path(), path, &options.limits)?;
        if model_description::fmi3::fmi_version_of(&xml).is_some_and(|v| v.starts_with("3.")) {
            return Fmu::load_fmi3(origin, options, dir, unpacked.platforms, &xml);
        }
        let description = ModelDescription::from_xml(&xml)
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
        let interface = match options.interface {
            Some(i) => i,
            None if description.co_simulation.is_some() => Interface::CoSimulation,
            None => Interface::ModelExchange,
        };
        let identifier = match interface {
            Interface::CoSimulation => description.co_simulation.as_ref().map(|c| c.model_identifier.clone()),
            Interface::ModelExchange => description.model_exchange.as_ref().map(|m| m.model_identifier.clone()),
        }
        .ok_or(Error::NoInterface { path: path.to_path_buf(), interface: interface.as_str() })?;
        if !model_description::is_c_identifier(&identifier) {
            return Err(Error::ModelDescription {
                path: path.to_path_buf(),
                reason: format!("modelIdentifier {identifier:?} is not a C identifier"),
            });
        }
        let relative = format!("binaries/linux64/{identifier}.so");
        let so = dir.path().join(&relative);
        if !so.is_file() {
            return Err(Error::MissingBinary { expected: relative, platforms: unpacked.platforms });
        }
        // errors name the library inside the archive, not the temporary copy
        let shown = path.join(&relative);
        let (library, functions) = if options.isolated {
            // read and checked only: nothing of the library runs in this process
            let bytes = std::fs::read(&so).map_err(|source| Error::Io { path: shown.clone(), source })?;
            crate::elf::check_shared_library(&bytes)
                .map_err(|reason| Error::LoadLibrary { path: shown.clone(), reason })?;
            // without section headers every function is taken as present: a missing one
            // is then the host's error when called
            let exported = crate::elf::exported_symbols(&bytes);
            let present = |symbol: &str| exported.as_ref().is_none_or(|e| e.contains(symbol));
            // the 15 core functions, which `Fmi2Functions::load` requires, lead SYMBOLS
            if let Some(symbol) = fmi_sys::fmi2::SYMBOLS.iter().take(15).map(|(s, _)| *s).find(|s| !present(s)) {
                return Err(Error::MissingSymbol { path: shown, symbol });
            }
            (None, crate::isolate::proxy::table(&present))
        } else {
            let library = load_library(&so, &shown, &relative)?;
            // SAFETY: the symbols are declared with the C signatures of the FMI 2.0 headers.
            (Some(library.clone()), unsafe { load_functions(&library, &shown)? })
        };
        let needs = match interface {
            Interface::CoSimulation => CS_NEEDS,
            Interface::ModelExchange => ME_NEEDS,
        };
        if let Some(missing) = needs.iter().find(|s| !functions.has(s)) {
            let symbol = [CS_NEEDS, ME_NEEDS].concat().into_iter().find(|s| s == missing).unwrap_or("fmi2?");
            return Err(Error::MissingSymbol { path: shown, symbol });
        }
        let resource_uri = CString::new(file_uri(&dir.path().join("resources"))).map_err(|_| Error::LoadLibrary {
            path: dir.path().to_path_buf(),
            reason: "the temporary folder's path contains NUL".into(),
        })?;
        Ok(Arc::new(Fmu {
            abi: Abi::Fmi2(functions),
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
            not_in_view: Vec::new(),
        }))
    }

    /// The FMI 3.0 part of [`Fmu::load_from`]: `xml` is the archive's description.
    fn load_fmi3(
        origin: &ArchiveSource,
        options: &ImportOptions,
        dir: tempfile::TempDir,
        platforms: Vec<String>,
        xml: &str,
    ) -> Result<Arc<Fmu>> {
        let shown_path = origin.shown();
        let path = shown_path.as_path();
        let refuse = |reason: String| Error::ModelDescription { path: path.to_path_buf(), reason };
        let md = checked_fmi3(xml, path)?;
        let (description, special, not_in_view) = crate::fmi3::fmi2_view(&md);
        let interface = match options.interface {
            Some(i) => i,
            None if md.co_simulation.is_some() => Interface::CoSimulation,
            None => Interface::ModelExchange,
        };
        let identifier = match interface {
            Interface::CoSimulation => md.co_simulation.as_ref().map(|c| c.common.model_identifier.clone()),
            Interface::ModelExchange => md.model_exchange.as_ref().map(|m| m.common.model_identifier.clone()),
        }
        .ok_or(Error::NoInterface { path: path.to_path_buf(), interface: interface.as_str() })?;
        if !model_description::is_c_identifier(&identifier) {
            return Err(refuse(format!("modelIdentifier {identifier:?} is not a C identifier")));
        }
        let relative = format!("binaries/x86_64-linux/{identifier}.so");
        let so = dir.path().join(&relative);
        if !so.is_file() {
            return Err(Error::MissingBinary { expected: relative, platforms });
        }
        let shown = path.join(&relative);
        let (library, functions) = if options.isolated {
            // read and checked only: nothing of the library runs in this process
            let bytes = std::fs::read(&so).map_err(|source| Error::Io { path: shown.clone(), source })?;
            crate::elf::check_shared_library(&bytes)
                .map_err(|reason| Error::LoadLibrary { path: shown.clone(), reason })?;
            // as for FMI 2.0: without section headers every function is taken as present
            let exported = crate::elf::exported_symbols(&bytes);
            let present = |symbol: &str| exported.as_ref().is_none_or(|e| e.contains(symbol));
            // the 7 core functions, which `Fmi3Functions::load` requires, lead SYMBOLS
            let core = fmi_sys::fmi3::functions::SYMBOLS.iter().take(7).map(|(s, _)| *s);
            if let Some(symbol) = core.into_iter().find(|s| !present(s)) {
                return Err(Error::MissingSymbol { path: shown, symbol });
            }
            (None, crate::isolate::proxy3::table(&present))
        } else {
            let library = load_library(&so, &shown, &relative)?;
            // SAFETY: the symbols are declared with the C signatures of the FMI 3.0 headers.
            let functions = unsafe { fmi_sys::fmi3::Fmi3Functions::load(&library) }
                .map_err(|missing| Error::MissingSymbol { path: shown.clone(), symbol: missing.0 })?;
            (Some(library), functions)
        };
        let needs: &[&str] = match interface {
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
        };
        if let Some(symbol) = needs.iter().find(|s| library.is_some() && !functions.has(s)) {
            return Err(Error::MissingSymbol { path: shown, symbol });
        }
        let token =
            CString::new(md.instantiation_token.as_str()).map_err(|_| refuse("NUL in instantiationToken".into()))?;
        let resource_path = crate::fmi3::resource_path(dir.path()).ok_or_else(|| Error::LoadLibrary {
            path: dir.path().to_path_buf(),
            reason: "the temporary folder's path contains NUL".into(),
        })?;
        Ok(Arc::new(Fmu {
            abi: Abi::Fmi3(Box::new(crate::fmi3::Fmi3Abi {
                functions,
                description: md,
                special,
                token,
                resource_path,
            })),
            allow_non_finite: options.allow_non_finite,
            _library: library,
            description,
            interface,
            source: path.to_path_buf(),
            origin: origin.clone(),
            resource_uri: CString::default(),
            dir: Some(dir),
            isolated_from: None,
            library_path: so,
            not_in_view,
        }))
    }

    /// The FMI 3.0 model description (`None` for an FMI 2.0 FMU, whose description is
    /// [`Fmu::description`]). For an FMI 3.0 FMU, [`Fmu::description`] is the view of it
    /// the master works with (see [`crate::fmi3`]).
    pub fn fmi3_description(&self) -> Option<&model_description::fmi3::ModelDescription> {
        match &self.abi {
            Abi::Fmi2(_) => None,
            Abi::Fmi3(a) => Some(&a.description),
        }
    }

    /// FMI 3.0: the variables the view leaves out (String and Binary arrays, arrays of
    /// more than 100,000 elements or of sizes it cannot resolve), neither recorded, set nor
    /// connected, each with the reason; empty for FMI 2.0.
    pub fn not_in_view(&self) -> &[(String, crate::fmi3::LeftOut)] {
        &self.not_in_view
    }

    /// The same FMU with its instances in host processes: a function table that carries
    /// every call to the instance's host (see `isolate`).
    pub fn isolated(self: &Arc<Fmu>) -> Arc<Fmu> {
        if self.is_isolated() {
            return self.clone();
        }
        let abi = match &self.abi {
            Abi::Fmi2(functions) => Abi::Fmi2(crate::isolate::proxy::table(&|symbol| functions.has(symbol))),
            Abi::Fmi3(a) => Abi::Fmi3(Box::new(crate::fmi3::Fmi3Abi {
                functions: crate::isolate::proxy3::table(&|symbol| a.functions.has(symbol)),
                description: a.description.clone(),
                special: a.special.clone(),
                token: a.token.clone(),
                resource_path: a.resource_path.clone(),
            })),
        };
        Arc::new(Fmu {
            abi,
            allow_non_finite: self.allow_non_finite,
            _library: self._library.clone(),
            description: self.description.clone(),
            interface: self.interface,
            source: self.source.clone(),
            origin: self.origin.clone(),
            resource_uri: self.resource_uri.clone(),
            dir: None,
            isolated_from: Some(self.clone()),
            library_path: self.library_path.clone(),
            not_in_view: self.not_in_view.clone(),
        })
    }

    /// Whether instances of this FMU run in host processes (an isolated view, or an FMU
    /// imported with [`ImportOptions::isolated`]).
    pub fn is_isolated(&self) -> bool {
        self.isolated_from.is_some() || self._library.is_none()
    }

    /// The model description.
    pub fn description(&self) -> &ModelDescription {
        &self.description
    }

    /// The loaded interface.
    pub fn interface(&self) -> Interface {
        self.interface
    }

    /// The archive it came from: its file, or `<ssp>/<entry>` for an FMU of an `.ssp`.
    pub fn source(&self) -> &Path {
        &self.source
    }

    /// Where the archive is: a file or an entry of an `.ssp`.
    pub fn origin(&self) -> &ArchiveSource {
        &self.origin
    }

    /// The bytes of the archive it came from (read again from the file or the `.ssp`).
    pub fn archive_bytes(&self) -> Result<Vec<u8>> {
        self.origin.read_bytes(&UnpackLimits { max_entry_bytes: u64::MAX, ..UnpackLimits::default() })
    }

    /// The private folder it is unpacked in (removed when the last `Arc` is dropped).
    pub fn unpacked_dir(&self) -> &Path {
        match (&self.dir, &self.isolated_from) {
            (Some(d), _) => d.path(),
            (None, Some(f)) => f.unpacked_dir(),
            (None, None) => Path::new(""),
        }
    }

    /// `canHandleVariableCommunicationStepSize` (false for Model Exchange).
    pub fn can_handle_variable_step(&self) -> bool {
        self.interface == Interface::CoSimulation
            && self.description.co_simulation.as_ref().is_some_and(|c| c.can_handle_variable_communication_step_size)
    }

    /// `canGetAndSetFMUstate` of the loaded interface, and the functions present.
    pub fn can_get_and_set_state(&self) -> bool {
        let flag = match self.interface {
            Interface::CoSimulation => {
                self.description.co_simulation.as_ref().is_some_and(|c| c.can_get_and_set_fmu_state)
            }
            Interface::ModelExchange => {
                self.description.model_exchange.as_ref().is_some_and(|c| c.can_get_and_set_fmu_state)
            }
        };
        flag && match &self.abi {
            Abi::Fmi2(f) => f.get_fmu_state.is_some() && f.set_fmu_state.is_some() && f.free_fmu_state.is_some(),
            Abi::Fmi3(a) => {
                let f = &a.functions;
                f.get_fmu_state.is_some() && f.set_fmu_state.is_some() && f.free_fmu_state.is_some()
            }
        }
    }
}

/// Life-cycle state of an instance (what the standard allows next).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InstanceState {
    /// After `fmi2Instantiate`.
    Instantiated,
    /// After `fmi2EnterInitializationMode`.
    Initialization,
    /// After `fmi2ExitInitializationMode` (step complete / event or continuous-time mode).
    Running,
    /// After `fmi2Terminate`.
    Terminated,
    /// After an `fmi2Error`: only free is called.
    Errored,
    /// After an `fmi2Fatal`: nothing is called any more, not even free.
    Fatal,
}

impl InstanceState {
    fn as_str(self) -> &'static str {
        match self {
            InstanceState::Instantiated => "instantiated",
            InstanceState::Initialization => "initialization mode",
            InstanceState::Running => "running",
            InstanceState::Terminated => "terminated",
            InstanceState::Errored => "errored",
            InstanceState::Fatal => "fatal",
        }
    }
}

/// A saved FMU state (`fmi2FMUstate`), freed by [`Instance::free_state`] or with the instance.
#[derive(Debug)]
pub struct FmuState(*mut c_void);

// SAFETY: a saved state is only passed back to the instance it came from, which is
// itself never called concurrently (see `Instance`); it moves between threads with it.
unsafe impl Send for FmuState {}

/// One instance of an FMU. Every call returns `Ok` for fmi2OK and fmi2Warning (the
/// warning stays in the log), else a typed [`Error::Fmi`] with the FMU's last messages.
/// Dropping it terminates it (unless it errored or is not initialized) and frees it
/// (unless it had a fatal error).
pub struct Instance {
    component: Component,
    state: InstanceState,
    name: String,
    _name_c: CString,
    log: Box<LogSink>,
    _callbacks: Box<CallbackFunctions>,
    saved: Vec<*mut c_void>,
    fmu: Arc<Fmu>,
    /// The time the FMU's values are at (the last setup, step end or `fmi2SetTime`), for
    /// [`Error::NonFinite`].
    time: f64,
    /// Isolated: the host process the calls go to (the component is its address).
    host: Option<Box<crate::isolate::channel::Channel>>,
    /// FMI 3.0: what `setup_experiment` was given (tolerance, start, stop), passed on by
    /// `fmi3EnterInitializationMode`.
    experiment: (Option<f64>, f64, Option<f64>),
    /// FMI 3.0: the time `fmi3DoStep` reported `terminateSimulation` at.
    terminate_requested: Option<f64>,
    /// FMI 3.0: Booleans as the bytes the ABI has (reused).
    bytes: Vec<u8>,
    /// FMI 3.0: the values of arrays set element by element, by value reference.
    arrays: std::collections::HashMap<u32, Vec<f64>>,
}

/// A function of the FMI 3.0 table, or the error naming it.
macro_rules! f3 {
    ($self:ident, $abi:ident, $field:ident, $name:literal) => {
        $abi.functions.$field.ok_or_else(|| Error::MissingSymbol { path: $self.fmu.source.clone(), symbol: $name })?
    };
}

// SAFETY: an FMI 2.0 instance may be used from any thread as long as calls to it are not
// concurrent (the standard's rule); `&mut self` on every call guarantees that.
unsafe impl Send for Instance {}

impl std::fmt::Debug for Instance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Instance").field("name", &self.name).field("state", &self.state).finish()
    }
}

macro_rules! call {
    ($self:ident, $name:literal, $time:expr, $f:expr) => {{
        $self.check_callable($name)?;
        let mark = crate::call_site::enter(&$self.name, &$self.fmu.source, $name, $time.unwrap_or($self.time));
        // SAFETY: the component is live (not freed), the arguments are valid for the call.
        let raw = unsafe { $f };
        drop(mark);
        $self.status($name, raw, $time)
    }};
}

/// A function both generations have with the same arguments after the instance: FMI 2.0's
/// `$f2` (named `$n2`), FMI 3.0's `$f3` (named `$n3`), each absent from its table an error
/// naming it; called as [`call!`] calls, with the arguments `$arg`.
macro_rules! either {
    // a function every library of its generation has (the table's field is no Option)
    (required $self:ident, $time:expr, $f2:ident $n2:literal, $f3:ident $n3:literal, ($($arg:expr),*)) => {{
        let c = $self.component;
        match &$self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = t.$f2;
                call!($self, $n2, $time, f(c, $($arg),*))
            }
            Abi::Fmi3(a) => {
                let f = a.functions.$f3;
                call!($self, $n3, $time, f(c, $($arg),*))
            }
        }
    }};
    ($self:ident, $time:expr, $f2:ident $n2:literal, $f3:ident $n3:literal, ($($arg:expr),*)) => {{
        let c = $self.component;
        match &$self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = $self.optional(t.$f2, $n2)?;
                call!($self, $n2, $time, f(c, $($arg),*))
            }
            Abi::Fmi3(a) => {
                let f = f3!($self, a, $f3, $n3);
                call!($self, $n3, $time, f(c, $($arg),*))
            }
        }
    }};
}

impl Instance {
    /// `fmi2Instantiate` with the FMU's interface, logging off (warnings and errors are
    /// still logged by the FMU and kept).
    pub fn new(fmu: &Arc<Fmu>, name: &str) -> Result<Instance> {
        if fmu.is_isolated() {
            return Err(Error::Instance {
                name: name.into(),
                reason: "its FMU was imported isolated (its library is not loaded in this process): instantiate it in a host process (Instance::new_isolated, Experiment::isolation)",
            });
        }
        let name_c = CString::new(name).map_err(|_| Error::Instance { name: name.into(), reason: "NUL in name" })?;
        let log = Box::<LogSink>::default();
        let callbacks = callbacks_for(&log);
        let functions = match &fmu.abi {
            Abi::Fmi2(functions) => functions,
            Abi::Fmi3(abi) => return Instance::new_fmi3(fmu, abi, name, name_c, log, callbacks),
        };
        let guid = CString::new(fmu.description.guid.as_str())
            .map_err(|_| Error::ModelDescription { path: fmu.source.clone(), reason: "NUL in guid".into() })?;
        let mark = crate::call_site::enter(name, &fmu.source, "fmi2Instantiate", 0.0);
        // SAFETY: every pointer is valid for the call; callbacks and log live as long as the instance.
        let component = unsafe {
            (functions.instantiate)(
                name_c.as_ptr(),
                fmu.interface.fmi_type(),
                guid.as_ptr(),
                fmu.resource_uri.as_ptr(),
                &*callbacks,
                0,
                0,
            )
        };
        drop(mark);
        if component.is_null() {
            return Err(Error::Instantiate {
                instance: name.into(),
                function: "fmi2Instantiate",
                log: log.recent_problems(),
            });
        }
        Ok(Instance::with(component, name, name_c, log, callbacks, fmu.clone(), None))
    }

    fn with(
        component: Component,
        name: &str,
        name_c: CString,
        log: Box<LogSink>,
        callbacks: Box<CallbackFunctions>,
        fmu: Arc<Fmu>,
        host: Option<Box<crate::isolate::channel::Channel>>,
    ) -> Instance {
        Instance {
            component,
            state: InstanceState::Instantiated,
            name: name.into(),
            _name_c: name_c,
            log,
            _callbacks: callbacks,
            saved: Vec::new(),
            fmu,
            time: 0.0,
            host,
            experiment: (None, 0.0, None),
            terminate_requested: None,
            bytes: Vec::new(),
            arrays: Default::default(),
        }
    }

    /// `fmi3InstantiateCoSimulation` (early return allowed, event mode used when the FMU
    /// has it, no intermediate update) or `fmi3InstantiateModelExchange`, logging off, the
    /// messages to the instance's log.
    fn new_fmi3(
        fmu: &Arc<Fmu>,
        abi: &crate::fmi3::Fmi3Abi,
        name: &str,
        name_c: CString,
        log: Box<LogSink>,
        callbacks: Box<CallbackFunctions>,
    ) -> Result<Instance> {
        let environment = &*log as *const LogSink as *mut c_void;
        let logger: Option<fmi_sys::fmi3::Fmi3LogMessageCallback> = Some(crate::log::log_message);
        let missing = |symbol| Error::MissingSymbol { path: fmu.source.clone(), symbol };
        let (function, component) = match fmu.interface {
            Interface::CoSimulation => {
                let f = abi.functions.instantiate_co_simulation.ok_or(missing("fmi3InstantiateCoSimulation"))?;
                let event_mode = abi.description.co_simulation.as_ref().is_some_and(|cs| cs.has_event_mode) as u8;
                let _mark = crate::call_site::enter(name, &fmu.source, "fmi3InstantiateCoSimulation", 0.0);
                // SAFETY: every pointer is valid for the call; the log outlives the instance.
                let c = unsafe {
                    f(
                        name_c.as_ptr(),
                        abi.token.as_ptr(),
                        abi.resource_path.as_ptr(),
                        0,
                        0,
                        event_mode,
                        1,
                        std::ptr::null(),
                        0,
                        environment,
                        logger,
                        None,
                    )
                };
                ("fmi3InstantiateCoSimulation", c)
            }
            Interface::ModelExchange => {
                let f = abi.functions.instantiate_model_exchange.ok_or(missing("fmi3InstantiateModelExchange"))?;
                let _mark = crate::call_site::enter(name, &fmu.source, "fmi3InstantiateModelExchange", 0.0);
                // SAFETY: as above.
                let c = unsafe {
                    f(name_c.as_ptr(), abi.token.as_ptr(), abi.resource_path.as_ptr(), 0, 0, environment, logger)
                };
                ("fmi3InstantiateModelExchange", c)
            }
        };
        if component.is_null() {
            return Err(Error::Instantiate { instance: name.into(), function, log: log.recent_problems() });
        }
        Ok(Instance::with(component, name, name_c, log, callbacks, fmu.clone(), None))
    }

    /// `fmi2Instantiate` / `fmi3InstantiateCoSimulation` in a host process of its own
    /// (`isolation` names the host binary and the per-call time limit; `run_deadline`: the
    /// run's deadline and its limit); FMI 3.0 Model Exchange by `fmi3InstantiateModelExchange`.
    pub fn new_isolated(
        fmu: &Arc<Fmu>,
        name: &str,
        isolation: &crate::isolate::Isolation,
        run_deadline: Option<(std::time::Instant, std::time::Duration)>,
    ) -> Result<Instance> {
        use crate::error::HostEnd;
        let fmi3 = matches!(fmu.abi, Abi::Fmi3(_));
        let fmu = fmu.isolated();
        let name_c = CString::new(name).map_err(|_| Error::Instance { name: name.into(), reason: "NUL in name" })?;
        let instantiate = match (fmi3, fmu.interface) {
            (false, _) => "fmi2Instantiate",
            (true, Interface::CoSimulation) => "fmi3InstantiateCoSimulation",
            (true, Interface::ModelExchange) => "fmi3InstantiateModelExchange",
        };
        let failed = |m: String| Error::Host {
            instance: name.into(),
            function: instantiate,
            time: 0.0,
            cause: HostEnd::Failed(m),
        };
        let host = crate::isolate::channel::find_host(isolation.host.as_deref()).map_err(failed)?;
        let variables = fmu.description.model_variables.len();
        let mut channel = Box::new(
            crate::isolate::channel::Channel::start(
                &host,
                &fmu.library_path,
                fmi3,
                variables,
                isolation.call_timeout,
                run_deadline,
                crate::isolate::protocol::Spin::of_run(),
            )
            .map_err(|cause| Error::Host {
                instance: name.into(),
                function: match instantiate {
                    "fmi2Instantiate" => "fmi2Instantiate (loading the library)",
                    "fmi3InstantiateCoSimulation" => "fmi3InstantiateCoSimulation (loading the library)",
                    _ => "fmi3InstantiateModelExchange (loading the library)",
                },
                time: 0.0,
                cause,
            })?,
        );
        let log = Box::<LogSink>::default();
        channel.log = &*log as *const LogSink;
        let status = match &fmu.abi {
            Abi::Fmi2(_) => {
                let guid = CString::new(fmu.description.guid.as_str())
                    .map_err(|_| Error::ModelDescription { path: fmu.source.clone(), reason: "NUL in guid".into() })?;
                crate::isolate::proxy::instantiate_in(
                    &mut channel,
                    &name_c,
                    fmu.interface.fmi_type(),
                    &guid,
                    &fmu.resource_uri,
                )
            }
            Abi::Fmi3(a) => {
                let event_mode = match fmu.interface {
                    Interface::CoSimulation => {
                        Some(a.description.co_simulation.as_ref().is_some_and(|cs| cs.has_event_mode))
                    }
                    Interface::ModelExchange => None,
                };
                crate::isolate::proxy3::instantiate_in(&mut channel, &name_c, &a.token, &a.resource_path, event_mode)
            }
        };
        if status != 0 {
            if let Some(cause) = channel.failure.clone() {
                return Err(Error::Host { instance: name.into(), function: instantiate, time: 0.0, cause });
            }
            return Err(Error::Instantiate {
                instance: name.into(),
                function: instantiate,
                log: log.recent_problems(),
            });
        }
        let callbacks = callbacks_for(&log);
        let component = &mut *channel as *mut crate::isolate::channel::Channel as *mut c_void;
        Ok(Instance::with(component, name, name_c, log, callbacks, fmu, Some(channel)))
    }

    /// The instance name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The FMU.
    pub fn fmu(&self) -> &Arc<Fmu> {
        &self.fmu
    }

    /// The life-cycle state.
    pub fn state(&self) -> InstanceState {
        self.state
    }

    /// Takes the messages the FMU logged (the last [`LogSink::CAPACITY`]).
    pub fn take_log(&self) -> Vec<LogRecord> {
        self.log.take()
    }

    fn check_callable(&self, function: &'static str) -> Result<()> {
        match self.state {
            InstanceState::Errored | InstanceState::Fatal | InstanceState::Terminated => {
                Err(Error::IllegalCall { instance: self.name.clone(), function, state: self.state.as_str() })
            }
            _ => Ok(()),
        }
    }

    fn status(&mut self, function: &'static str, raw: RawStatus, time: Option<f64>) -> Result<()> {
        let status = Status::from_raw(raw);
        match status {
            Status::Ok | Status::Warning => return Ok(()),
            Status::Discard => {}
            Status::Error | Status::Pending | Status::Invalid(_) => self.state = InstanceState::Errored,
            Status::Fatal => self.state = InstanceState::Fatal,
        }
        if let Some(cause) = self.host.as_ref().and_then(|h| h.failure.clone()) {
            let time = time.unwrap_or(self.host.as_ref().map_or(0.0, |h| h.last_time));
            return Err(Error::Host { instance: self.name.clone(), function, time, cause });
        }
        Err(Error::Fmi { instance: self.name.clone(), function, status, time, log: self.log.recent_problems() })
    }

    fn optional<T>(&self, f: Option<T>, function: &'static str) -> Result<T> {
        f.ok_or_else(|| Error::MissingSymbol { path: self.fmu.source.clone(), symbol: function })
    }

    /// `fmi2SetupExperiment`; FMI 3.0: kept for `fmi3EnterInitializationMode`.
    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start_time: f64, stop_time: Option<f64>) -> Result<()> {
        let function = if self.is_fmi3() { "fmi3EnterInitializationMode" } else { "fmi2SetupExperiment" };
        if self.state != InstanceState::Instantiated {
            return Err(Error::IllegalCall { instance: self.name.clone(), function, state: self.state.as_str() });
        }
        self.time = start_time;
        let c = self.component;
        let f = match &self.fmu.abi {
            Abi::Fmi2(t) => t.setup_experiment,
            Abi::Fmi3(_) => {
                self.experiment = (tolerance, start_time, stop_time);
                return Ok(());
            }
        };
        call!(
            self,
            "fmi2SetupExperiment",
            Some(start_time),
            f(
                c,
                tolerance.is_some() as c_int,
                tolerance.unwrap_or(0.0),
                start_time,
                stop_time.is_some() as c_int,
                stop_time.unwrap_or(0.0)
            )
        )
    }

    /// Whether the FMU is an FMI 3.0 one.
    pub fn is_fmi3(&self) -> bool {
        matches!(self.fmu.abi, Abi::Fmi3(_))
    }

    /// `fmi2EnterInitializationMode`; FMI 3.0: `fmi3EnterInitializationMode` with the
    /// experiment of [`Instance::setup_experiment`].
    pub fn enter_initialization_mode(&mut self) -> Result<()> {
        let c = self.component;
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = t.enter_initialization_mode;
                call!(self, "fmi2EnterInitializationMode", None, f(c))?
            }
            Abi::Fmi3(a) => {
                let f = a.functions.enter_initialization_mode;
                let (tolerance, start, stop) = self.experiment;
                call!(
                    self,
                    "fmi3EnterInitializationMode",
                    Some(start),
                    f(
                        c,
                        tolerance.is_some() as u8,
                        tolerance.unwrap_or(0.0),
                        start,
                        stop.is_some() as u8,
                        stop.unwrap_or(0.0)
                    )
                )?
            }
        }
        self.state = InstanceState::Initialization;
        Ok(())
    }

    /// `fmi2ExitInitializationMode` / `fmi3ExitInitializationMode`.
    pub fn exit_initialization_mode(&mut self) -> Result<()> {
        either!(required self, None, exit_initialization_mode "fmi2ExitInitializationMode", exit_initialization_mode "fmi3ExitInitializationMode", ())?;
        self.state = InstanceState::Running;
        Ok(())
    }

    /// `fmi2Terminate` / `fmi3Terminate` (only from initialization or running; otherwise
    /// nothing to do).
    pub fn terminate(&mut self) -> Result<()> {
        if !matches!(self.state, InstanceState::Running | InstanceState::Initialization) {
            return Ok(());
        }
        either!(required self, None, terminate "fmi2Terminate", terminate "fmi3Terminate", ())?;
        self.state = InstanceState::Terminated;
        Ok(())
    }

    /// `fmi2Reset` / `fmi3Reset`: back to instantiated (also after an error).
    pub fn reset(&mut self) -> Result<()> {
        let function = if self.is_fmi3() { "fmi3Reset" } else { "fmi2Reset" };
        if self.state == InstanceState::Fatal {
            return Err(Error::IllegalCall { instance: self.name.clone(), function, state: "fatal" });
        }
        let f = match &self.fmu.abi {
            Abi::Fmi2(t) => self.optional(t.reset, "fmi2Reset")?,
            Abi::Fmi3(a) => self.optional(a.functions.reset, "fmi3Reset")?,
        };
        let mark = crate::call_site::enter(&self.name, &self.fmu.source, function, self.time);
        // SAFETY: live component; both generations' reset take the instance only.
        let raw = unsafe { f(self.component) };
        drop(mark);
        self.state = InstanceState::Instantiated;
        self.terminate_requested = None;
        self.status(function, raw, None)
    }

    /// The access of the view's variable `vr` when it is not a plain scalar (FMI 3.0).
    #[inline]
    fn special(&self, vr: u32) -> Option<crate::fmi3::Access> {
        match &self.fmu.abi {
            Abi::Fmi3(a) if !a.special.is_empty() => a.special.get(&vr).copied(),
            _ => None,
        }
    }

    /// Whether some of `vrs` are not plain scalars (FMI 3.0): they go one by one.
    #[inline]
    fn any_special(&self, vrs: &[u32]) -> bool {
        match &self.fmu.abi {
            Abi::Fmi3(a) => !a.special.is_empty() && vrs.iter().any(|vr| a.special.contains_key(vr)),
            Abi::Fmi2(_) => false,
        }
    }

    /// `fmi2GetReal` / `fmi3GetFloat64` of `vrs` into `values` (same length). A NaN or
    /// infinite value is [`Error::NonFinite`] unless the FMU was imported with
    /// `allow_non_finite`. FMI 3.0: Float32, UInt32, Int64, UInt64 (exact up to 2^53),
    /// Binary (its size) and array elements by their own getters.
    #[inline]
    pub fn get_real(&mut self, vrs: &[u32], values: &mut [f64]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "get_real: one value per value reference");
        let c = self.component;
        let special = self.any_special(vrs);
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = t.get_real;
                call!(self, "fmi2GetReal", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()))?
            }
            Abi::Fmi3(a) if !special => {
                let f = a.functions.get_float64;
                call!(self, "fmi3GetFloat64", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len()))?
            }
            Abi::Fmi3(a) => {
                let f = a.functions.get_float64;
                for (vr, value) in vrs.iter().zip(values.iter_mut()) {
                    match self.special(*vr) {
                        Some(access) => *value = self.get_element(access)?,
                        None => call!(self, "fmi3GetFloat64", None, f(c, vr, 1, value, 1))?,
                    }
                }
            }
        }
        // all exponent bits set: Inf or NaN. An OR of integer compares over the values
        // just read, without a branch per value (the compiler vectorizes it).
        const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
        let any = values.iter().fold(false, |any, v| any | (v.to_bits() & EXPONENT == EXPONENT));
        if any && !self.fmu.allow_non_finite {
            return Err(self.non_finite(vrs, values));
        }
        Ok(())
    }

    /// All values of the FMI 3.0 variable of `access`, as f64 (integers exact up to 2^53,
    /// Booleans 0 or 1, a Binary its size in bytes).
    fn get_all(&mut self, access: crate::fmi3::Access) -> Result<Vec<f64>> {
        use model_description::fmi3::ValueType as T;
        let c = self.component;
        let Abi::Fmi3(a) = &self.fmu.abi else { unreachable!("an FMI 3.0 instance") };
        let (vr, n) = (access.vr, access.count);
        macro_rules! get {
            ($field:ident, $name:literal, $t:ty) => {{
                let f = f3!(self, a, $field, $name);
                let mut buf: Vec<$t> = vec![<$t>::default(); n];
                call!(self, $name, None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
                buf
            }};
        }
        macro_rules! exact {
            ($buf:expr, $name:literal) => {{
                let mut out = Vec::with_capacity(n);
                for x in $buf {
                    let wide = x as i128;
                    if wide.abs() > 1 << 53 {
                        return Err(self.not_exact($name, vr, wide));
                    }
                    out.push(wide as f64);
                }
                out
            }};
        }
        Ok(match access.value_type {
            T::Float64 => {
                let f = a.functions.get_float64;
                let mut buf = vec![0.0; n];
                call!(self, "fmi3GetFloat64", None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
                buf
            }
            T::Float32 => get!(get_float32, "fmi3GetFloat32", f32).into_iter().map(f64::from).collect(),
            T::Int8 => get!(get_int8, "fmi3GetInt8", i8).into_iter().map(f64::from).collect(),
            T::UInt8 => get!(get_uint8, "fmi3GetUInt8", u8).into_iter().map(f64::from).collect(),
            T::Int16 => get!(get_int16, "fmi3GetInt16", i16).into_iter().map(f64::from).collect(),
            T::UInt16 => get!(get_uint16, "fmi3GetUInt16", u16).into_iter().map(f64::from).collect(),
            T::Int32 => get!(get_int32, "fmi3GetInt32", i32).into_iter().map(f64::from).collect(),
            T::UInt32 => get!(get_uint32, "fmi3GetUInt32", u32).into_iter().map(f64::from).collect(),
            T::Int64 | T::Enumeration => exact!(get!(get_int64, "fmi3GetInt64", i64), "fmi3GetInt64"),
            T::UInt64 => exact!(get!(get_uint64, "fmi3GetUInt64", u64), "fmi3GetUInt64"),
            T::Boolean => get!(get_boolean, "fmi3GetBoolean", u8).into_iter().map(|b| (b != 0) as i32 as f64).collect(),
            T::Binary => {
                let f = f3!(self, a, get_binary, "fmi3GetBinary");
                let mut sizes = vec![0usize; n];
                let mut data: Vec<*const u8> = vec![std::ptr::null(); n];
                call!(self, "fmi3GetBinary", None, f(c, &vr, 1, sizes.as_mut_ptr(), data.as_mut_ptr(), n))?;
                sizes.into_iter().map(|s| s as f64).collect()
            }
            T::String | T::Clock => unreachable!("not in the view as a number"),
        })
    }

    #[cold]
    fn not_exact(&self, function: &'static str, vr: u32, value: i128) -> Error {
        Error::Fmi {
            instance: self.name.clone(),
            function,
            status: Status::Error,
            time: Some(self.time),
            log: format!(
                "value {value} of value reference {vr} is beyond 2^53, where f64 results cannot hold it exactly"
            ),
        }
    }

    fn get_element(&mut self, access: crate::fmi3::Access) -> Result<f64> {
        let all = self.get_all(access)?;
        Ok(all.get(access.element).copied().unwrap_or(f64::NAN))
    }

    /// Sets all values of the FMI 3.0 variable of `access` from f64 (integers must be
    /// whole and in their type's range).
    fn set_all(&mut self, access: crate::fmi3::Access, values: &[f64]) -> Result<()> {
        use model_description::fmi3::ValueType as T;
        let c = self.component;
        let name = self
            .fmu
            .description
            .model_variables
            .iter()
            .find(|v| v.value_reference == access.vr)
            .map(|v| v.name.clone());
        let Abi::Fmi3(a) = &self.fmu.abi else { unreachable!("an FMI 3.0 instance") };
        let (vr, n) = (access.vr, values.len());
        let variable = || format!("{}.{}", self.name, name.clone().unwrap_or_else(|| format!("<vr {vr}>")));
        macro_rules! set_int {
            ($field:ident, $name:literal, $t:ty) => {{
                let f = f3!(self, a, $field, $name);
                let mut buf: Vec<$t> = Vec::with_capacity(n);
                for x in values {
                    let wide = *x as i128;
                    let fits = wide as f64 == *x && wide >= <$t>::MIN as i128 && wide <= <$t>::MAX as i128;
                    if !fits {
                        return Err(Error::InvalidValue {
                            variable: variable(),
                            value: x.to_string(),
                            reason: format!("not a whole number of {}", stringify!($t)),
                        });
                    }
                    buf.push(wide as $t);
                }
                call!(self, $name, None, f(c, &vr, 1, buf.as_ptr(), n))
            }};
        }
        match access.value_type {
            T::Float64 => {
                let f = a.functions.set_float64;
                call!(self, "fmi3SetFloat64", None, f(c, &vr, 1, values.as_ptr(), n))
            }
            T::Float32 => {
                let f = f3!(self, a, set_float32, "fmi3SetFloat32");
                let buf: Vec<f32> = values.iter().map(|x| *x as f32).collect();
                call!(self, "fmi3SetFloat32", None, f(c, &vr, 1, buf.as_ptr(), n))
            }
            T::Int8 => set_int!(set_int8, "fmi3SetInt8", i8),
            T::UInt8 => set_int!(set_uint8, "fmi3SetUInt8", u8),
            T::Int16 => set_int!(set_int16, "fmi3SetInt16", i16),
            T::UInt16 => set_int!(set_uint16, "fmi3SetUInt16", u16),
            T::Int32 => set_int!(set_int32, "fmi3SetInt32", i32),
            T::UInt32 => set_int!(set_uint32, "fmi3SetUInt32", u32),
            T::Int64 | T::Enumeration => set_int!(set_int64, "fmi3SetInt64", i64),
            T::UInt64 => set_int!(set_uint64, "fmi3SetUInt64", u64),
            T::Boolean => {
                let f = f3!(self, a, set_boolean, "fmi3SetBoolean");
                let buf: Vec<u8> = values.iter().map(|x| (*x != 0.0) as u8).collect();
                call!(self, "fmi3SetBoolean", None, f(c, &vr, 1, buf.as_ptr(), n))
            }
            T::Binary | T::String | T::Clock => Err(Error::InvalidValue {
                variable: variable(),
                value: values.first().map(|x| x.to_string()).unwrap_or_default(),
                reason: "a Binary is recorded as its size and cannot be set".into(),
            }),
        }
    }

    /// Sets element `access.element` of its variable: the other elements keep the values
    /// set or read before (the start values at first).
    fn set_element(&mut self, access: crate::fmi3::Access, value: f64) -> Result<()> {
        if access.count == 1 {
            return self.set_all(access, &[value]);
        }
        let mut values = match self.arrays.remove(&access.vr) {
            Some(v) => v,
            None => self.array_start(access)?,
        };
        values[access.element] = value;
        let result = self.set_all(access, &values);
        self.arrays.insert(access.vr, values);
        result
    }

    /// The values an array starts from for element-wise sets: its start values, else what
    /// the FMU holds.
    fn array_start(&mut self, access: crate::fmi3::Access) -> Result<Vec<f64>> {
        use model_description::fmi3::Values;
        let Abi::Fmi3(a) = &self.fmu.abi else { unreachable!("an FMI 3.0 instance") };
        let start = a.description.variable(access.vr).and_then(|v| v.start.clone());
        let n = access.count;
        let spread = |v: Vec<f64>| if v.len() == 1 { vec![v[0]; n] } else { v };
        match start {
            Some(Values::Float(v)) if v.len() == n || v.len() == 1 => Ok(spread(v)),
            Some(Values::Int(v)) if v.len() == n || v.len() == 1 => {
                Ok(spread(v.into_iter().map(|x| x as f64).collect()))
            }
            Some(Values::Boolean(v)) if v.len() == n || v.len() == 1 => {
                Ok(spread(v.into_iter().map(|x| x as i32 as f64).collect()))
            }
            _ => self.get_all(access),
        }
    }

    /// `fmi2SetReal` / `fmi3SetFloat64` (the other FMI 3.0 types as for [`Instance::get_real`]).
    #[inline]
    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "set_real: one value per value reference");
        let c = self.component;
        let special = self.any_special(vrs);
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = t.set_real;
                call!(self, "fmi2SetReal", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr()))
            }
            Abi::Fmi3(a) if !special => {
                let f = a.functions.set_float64;
                call!(self, "fmi3SetFloat64", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len()))
            }
            Abi::Fmi3(a) => {
                let f = a.functions.set_float64;
                for (vr, value) in vrs.iter().zip(values) {
                    match self.special(*vr) {
                        Some(access) => self.set_element(access, *value)?,
                        None => call!(self, "fmi3SetFloat64", None, f(c, vr, 1, value, 1))?,
                    }
                }
                Ok(())
            }
        }
    }

    /// `fmi2GetInteger`; FMI 3.0: `fmi3GetInt32`, Enumerations by `fmi3GetInt64`, Int8 ..
    /// UInt16 and array elements by their own getters.
    #[inline]
    pub fn get_integer(&mut self, vrs: &[u32], values: &mut [i32]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "get_integer: one value per value reference");
        let c = self.component;
        let special = self.any_special(vrs);
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = t.get_integer;
                call!(self, "fmi2GetInteger", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()))
            }
            Abi::Fmi3(a) if !special => {
                let f = f3!(self, a, get_int32, "fmi3GetInt32");
                call!(self, "fmi3GetInt32", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len()))
            }
            Abi::Fmi3(a) => {
                let get32 = a.functions.get_int32;
                for (vr, value) in vrs.iter().zip(values.iter_mut()) {
                    match self.special(*vr) {
                        Some(access) => {
                            let x = self.get_element(access)?;
                            // the view's Integers are Int8 .. Int32 and Enumerations of i32 items
                            *value = i32::try_from(x as i64).map_err(|_| Error::Fmi {
                                instance: self.name.clone(),
                                function: "fmi3GetInt64",
                                status: Status::Error,
                                time: Some(self.time),
                                log: format!("value {x} of value reference {} is outside the Integer range", access.vr),
                            })?;
                        }
                        None => {
                            let f = self.optional(get32, "fmi3GetInt32")?;
                            call!(self, "fmi3GetInt32", None, f(c, vr, 1, value, 1))?
                        }
                    }
                }
                Ok(())
            }
        }
    }

    /// `fmi2SetInteger`; FMI 3.0: `fmi3SetInt32`, the other types as for
    /// [`Instance::get_integer`].
    #[inline]
    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "set_integer: one value per value reference");
        let c = self.component;
        let special = self.any_special(vrs);
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = t.set_integer;
                call!(self, "fmi2SetInteger", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr()))
            }
            Abi::Fmi3(a) if !special => {
                let f = f3!(self, a, set_int32, "fmi3SetInt32");
                call!(self, "fmi3SetInt32", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len()))
            }
            Abi::Fmi3(a) => {
                let set32 = a.functions.set_int32;
                for (vr, value) in vrs.iter().zip(values) {
                    match self.special(*vr) {
                        Some(access) => self.set_element(access, *value as f64)?,
                        None => {
                            let f = self.optional(set32, "fmi3SetInt32")?;
                            call!(self, "fmi3SetInt32", None, f(c, vr, 1, value, 1))?
                        }
                    }
                }
                Ok(())
            }
        }
    }

    /// `fmi2GetBoolean` (fmi2Boolean is a C int: 0 false, else true); FMI 3.0:
    /// `fmi3GetBoolean` (a C `bool`, read as a byte: nonzero is true), as 0 or 1.
    #[inline]
    pub fn get_boolean(&mut self, vrs: &[u32], values: &mut [i32]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "get_boolean: one value per value reference");
        let c = self.component;
        let special = self.any_special(vrs);
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = t.get_boolean;
                call!(self, "fmi2GetBoolean", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()))
            }
            Abi::Fmi3(_) if special => {
                for (vr, value) in vrs.iter().zip(values.iter_mut()) {
                    *value = match self.special(*vr) {
                        Some(access) => self.get_element(access)? as i32,
                        None => {
                            let mut one = [0];
                            self.get_boolean(&[*vr], &mut one)?;
                            one[0]
                        }
                    };
                }
                Ok(())
            }
            Abi::Fmi3(a) => {
                let f = f3!(self, a, get_boolean, "fmi3GetBoolean");
                let mut bytes = std::mem::take(&mut self.bytes);
                bytes.clear();
                bytes.resize(vrs.len(), 0);
                let r =
                    call!(self, "fmi3GetBoolean", None, f(c, vrs.as_ptr(), vrs.len(), bytes.as_mut_ptr(), bytes.len()));
                for (v, b) in values.iter_mut().zip(&bytes) {
                    *v = (*b != 0) as i32;
                }
                self.bytes = bytes;
                r
            }
        }
    }

    /// `fmi2SetBoolean` / `fmi3SetBoolean` (nonzero is true).
    #[inline]
    pub fn set_boolean(&mut self, vrs: &[u32], values: &[i32]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "set_boolean: one value per value reference");
        let c = self.component;
        let special = self.any_special(vrs);
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = t.set_boolean;
                call!(self, "fmi2SetBoolean", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr()))
            }
            Abi::Fmi3(_) if special => {
                for (vr, value) in vrs.iter().zip(values) {
                    match self.special(*vr) {
                        Some(access) => self.set_element(access, (*value != 0) as i32 as f64)?,
                        None => self.set_boolean(&[*vr], &[*value])?,
                    }
                }
                Ok(())
            }
            Abi::Fmi3(a) => {
                let f = f3!(self, a, set_boolean, "fmi3SetBoolean");
                let mut bytes = std::mem::take(&mut self.bytes);
                bytes.clear();
                bytes.extend(values.iter().map(|v| (*v != 0) as u8));
                let r = call!(self, "fmi3SetBoolean", None, f(c, vrs.as_ptr(), vrs.len(), bytes.as_ptr(), bytes.len()));
                self.bytes = bytes;
                r
            }
        }
    }

    #[cold]
    fn non_finite(&self, vrs: &[u32], values: &[f64]) -> Error {
        let k = values.iter().position(|v| !v.is_finite()).unwrap_or(0);
        let variable = self
            .fmu
            .description
            .model_variables
            .iter()
            .find(|v| v.is_real() && v.value_reference == vrs[k])
            .map_or_else(|| format!("<Real value reference {}>", vrs[k]), |v| v.name.clone());
        Error::NonFinite {
            instance: self.name.clone(),
            fmu: self.fmu.source.clone(),
            variable,
            value: values[k],
            time: self.time,
        }
    }

    /// `fmi2GetString` / `fmi3GetString` of one variable (copied).
    pub fn get_string(&mut self, vr: u32) -> Result<String> {
        let mut p: *const c_char = std::ptr::null();
        let c = self.component;
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = t.get_string;
                call!(self, "fmi2GetString", None, f(c, &vr, 1, &mut p))?
            }
            Abi::Fmi3(a) => {
                let f = f3!(self, a, get_string, "fmi3GetString");
                call!(self, "fmi3GetString", None, f(c, &vr, 1, &mut p, 1))?
            }
        }
        if p.is_null() {
            return Ok(String::new());
        }
        // SAFETY: the FMU returns a NUL-terminated string valid until the next call.
        Ok(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
    }

    /// `fmi2SetString` / `fmi3SetString` of one variable.
    pub fn set_string(&mut self, vr: u32, value: &str) -> Result<()> {
        let s = CString::new(value).map_err(|_| Error::InvalidValue {
            variable: format!("{}.<vr {vr}>", self.name),
            value: value.into(),
            reason: "NUL in string".into(),
        })?;
        let p = s.as_ptr();
        let c = self.component;
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = t.set_string;
                call!(self, "fmi2SetString", None, f(c, &vr, 1, &p))
            }
            Abi::Fmi3(a) => {
                let f = f3!(self, a, set_string, "fmi3SetString");
                call!(self, "fmi3SetString", None, f(c, &vr, 1, &p, 1))
            }
        }
    }

    /// `fmi2DoStep` / `fmi3DoStep` from `time` over `step` (Co-Simulation).
    ///
    /// FMI 3.0: an early return (`earlyReturn` with `lastSuccessfulTime` before the step's
    /// end) is continued from the time reached until the step's end, so that the caller
    /// sees the step it asked for; a return that makes no progress is an error naming the
    /// time. `terminateSimulation` is reported as FMI 2.0 reports it, a Discard with
    /// [`Instance::terminated_status`] true and [`Instance::last_successful_time`] the time
    /// reached, which ends the run there.
    #[inline]
    pub fn do_step(&mut self, time: f64, step: f64) -> Result<()> {
        let c = self.component;
        let f = match &self.fmu.abi {
            Abi::Fmi2(t) => self.optional(t.do_step, "fmi2DoStep")?,
            Abi::Fmi3(a) => {
                let f = f3!(self, a, do_step, "fmi3DoStep");
                return self.do_step_fmi3(f, time, step);
            }
        };
        call!(self, "fmi2DoStep", Some(time), f(c, time, step, 1))?;
        self.time = time + step;
        Ok(())
    }

    fn do_step_fmi3(&mut self, f: fmi_sys::fmi3::functions::types::fmi3DoStepTYPE, time: f64, step: f64) -> Result<()> {
        let c = self.component;
        let end = time + step;
        let mut at = time;
        // each early return must make progress; a bound on the returns per step besides,
        // so that an FMU creeping forward by ulps cannot hold the run forever
        for _ in 0..1000 {
            let (mut event, mut terminate, mut early, mut reached) = (0u8, 0u8, 0u8, at);
            call!(
                self,
                "fmi3DoStep",
                Some(at),
                f(c, at, end - at, 1, &mut event, &mut terminate, &mut early, &mut reached)
            )?;
            if terminate != 0 {
                let reached = if early != 0 && reached.is_finite() { reached } else { end };
                return Err(self.terminated_at("fmi3DoStep", at, reached));
            }
            if event != 0 && self.uses_event_mode() {
                let reached = if early != 0 { reached } else { end };
                self.time = reached;
                if let Some(t) = self.cs_event(reached)? {
                    return Err(self.terminated_at("fmi3UpdateDiscreteStates", t, t));
                }
            }
            if early == 0 {
                self.time = end;
                return Ok(());
            }
            if !(reached > at && reached <= end) {
                self.state = InstanceState::Errored;
                return Err(Error::Fmi {
                    instance: self.name.clone(),
                    function: "fmi3DoStep",
                    status: Status::Error,
                    time: Some(at),
                    log: format!(
                        "returned early at lastSuccessfulTime = {reached} s, no progress from {at} s toward the step's end {end} s"
                    ),
                });
            }
            if reached == end {
                self.time = end;
                return Ok(());
            }
            at = reached;
        }
        self.state = InstanceState::Errored;
        Err(Error::Fmi {
            instance: self.name.clone(),
            function: "fmi3DoStep",
            status: Status::Error,
            time: Some(at),
            log: format!("returned early 1000 times in the step from {time} s to {end} s"),
        })
    }

    /// FMI 3.0 `terminateSimulation` from `function` (called at `at`) at the time `reached`,
    /// reported as FMI 2.0 reports it: a Discard, with [`Instance::terminated_status`] true
    /// and [`Instance::last_successful_time`] `reached`.
    fn terminated_at(&mut self, function: &'static str, at: f64, reached: f64) -> Error {
        self.time = reached;
        self.terminate_requested = Some(reached);
        Error::Fmi {
            instance: self.name.clone(),
            function,
            status: Status::Discard,
            time: Some(at),
            log: format!("terminateSimulation at t = {reached} s"),
        }
    }

    /// Whether the instance was instantiated with `eventModeUsed` (Co-Simulation of an FMU
    /// with `hasEventMode`).
    fn uses_event_mode(&self) -> bool {
        match &self.fmu.abi {
            Abi::Fmi3(a) => {
                self.fmu.interface == Interface::CoSimulation
                    && a.description.co_simulation.as_ref().is_some_and(|cs| cs.has_event_mode)
            }
            Abi::Fmi2(_) => false,
        }
    }

    /// The event a Co-Simulation `fmi3DoStep` asked for (`eventHandlingNeeded`) at `time`:
    /// Event Mode, `fmi3UpdateDiscreteStates` until no new discrete states are needed (at
    /// most 1000 times), back to Step Mode. `Some(time)` when the FMU asked to terminate.
    fn cs_event(&mut self, time: f64) -> Result<Option<f64>> {
        self.enter_event_mode()?;
        for _ in 0..1000 {
            let info = self.new_discrete_states()?;
            if info.terminate_simulation != 0 {
                return Ok(Some(time));
            }
            if info.new_discrete_states_needed == 0 {
                let Abi::Fmi3(a) = &self.fmu.abi else { unreachable!("an FMI 3.0 instance") };
                let f = f3!(self, a, enter_step_mode, "fmi3EnterStepMode");
                let c = self.component;
                call!(self, "fmi3EnterStepMode", Some(time), f(c))?;
                return Ok(None);
            }
        }
        self.state = InstanceState::Errored;
        Err(Error::Fmi {
            instance: self.name.clone(),
            function: "fmi3UpdateDiscreteStates",
            status: Status::Error,
            time: Some(time),
            log: "asked for new discrete states 1000 times in one event".into(),
        })
    }

    /// Isolated: hands `fmi2DoStep(time, step)` (or `fmi3DoStep`) to the host without waiting for it, so
    /// that the hosts of several instances step at the same time; the next
    /// [`Instance::do_step`] with the same arguments takes its answer. False (nothing done)
    /// in process, and when the instance cannot step in its state (`do_step` then says why).
    pub fn post_step(&mut self, time: f64, step: f64) -> bool {
        // FMI 3.0: the arguments of the first fmi3DoStep of `do_step_fmi3`
        let (op, step) = match &self.fmu.abi {
            Abi::Fmi2(t) if t.do_step.is_some() => (crate::isolate::protocol::Op::DoStep, step),
            Abi::Fmi3(a) if a.functions.do_step.is_some() => {
                (crate::isolate::protocol::Op::DoStep3, (time + step) - time)
            }
            _ => return false,
        };
        let Some(host) = self.host.as_deref_mut() else { return false };
        if self.state != InstanceState::Running {
            return false;
        }
        crate::isolate::proxy::post_step(host, op, time, step);
        true
    }

    /// `fmi2GetFMUstate` / `fmi3GetFMUState`: saves the current state.
    pub fn get_state(&mut self) -> Result<FmuState> {
        let mut s: *mut c_void = std::ptr::null_mut();
        either!(self, None, get_fmu_state "fmi2GetFMUstate", get_fmu_state "fmi3GetFMUState", (&mut s))?;
        self.saved.push(s);
        Ok(FmuState(s))
    }

    /// `fmi2GetFMUstate` / `fmi3GetFMUState` into an existing state (overwritten).
    pub fn update_state(&mut self, state: &mut FmuState) -> Result<()> {
        let mut s = state.0;
        either!(self, None, get_fmu_state "fmi2GetFMUstate", get_fmu_state "fmi3GetFMUState", (&mut s))?;
        if s != state.0 {
            self.saved.retain(|p| *p != state.0);
            self.saved.push(s);
            state.0 = s;
        }
        Ok(())
    }

    /// `fmi2SetFMUstate` / `fmi3SetFMUState`: restores a saved state.
    pub fn set_state(&mut self, state: &FmuState) -> Result<()> {
        either!(self, None, set_fmu_state "fmi2SetFMUstate", set_fmu_state "fmi3SetFMUState", (state.0))
    }

    /// `fmi2FreeFMUstate` / `fmi3FreeFMUState`.
    pub fn free_state(&mut self, state: FmuState) -> Result<()> {
        self.saved.retain(|p| *p != state.0);
        let mut s = state.0;
        either!(self, None, free_fmu_state "fmi2FreeFMUstate", free_fmu_state "fmi3FreeFMUState", (&mut s))
    }

    /// `fmi2SetTime` / `fmi3SetTime` (Model Exchange).
    #[inline]
    pub fn set_time(&mut self, time: f64) -> Result<()> {
        self.time = time;
        either!(self, Some(time), set_time "fmi2SetTime", set_time "fmi3SetTime", (time))
    }

    /// `fmi2SetContinuousStates` / `fmi3SetContinuousStates`.
    #[inline]
    pub fn set_continuous_states(&mut self, x: &[f64]) -> Result<()> {
        either!(self, None, set_continuous_states "fmi2SetContinuousStates", set_continuous_states "fmi3SetContinuousStates", (x.as_ptr(), x.len()))
    }

    /// `fmi2GetContinuousStates` / `fmi3GetContinuousStates`.
    pub fn get_continuous_states(&mut self, x: &mut [f64]) -> Result<()> {
        either!(self, None, get_continuous_states "fmi2GetContinuousStates", get_continuous_states "fmi3GetContinuousStates", (x.as_mut_ptr(), x.len()))
    }

    /// `fmi2GetDerivatives` / `fmi3GetContinuousStateDerivatives`.
    #[inline]
    pub fn get_derivatives(&mut self, dx: &mut [f64]) -> Result<()> {
        either!(self, None, get_derivatives "fmi2GetDerivatives", get_continuous_state_derivatives "fmi3GetContinuousStateDerivatives", (dx.as_mut_ptr(), dx.len()))
    }

    /// `fmi2GetEventIndicators` / `fmi3GetEventIndicators`.
    #[inline]
    pub fn get_event_indicators(&mut self, z: &mut [f64]) -> Result<()> {
        either!(self, None, get_event_indicators "fmi2GetEventIndicators", get_event_indicators "fmi3GetEventIndicators", (z.as_mut_ptr(), z.len()))
    }

    /// Whether the FMU's library has `fmi2GetDirectionalDerivative` /
    /// `fmi3GetDirectionalDerivative` (an isolated instance's host does not forward it).
    pub fn has_directional_derivative(&self) -> bool {
        match &self.fmu.abi {
            Abi::Fmi2(t) => t.get_directional_derivative.is_some(),
            Abi::Fmi3(a) => a.functions.get_directional_derivative.is_some(),
        }
    }

    /// The directional derivative at the instance's current point: `dv_unknown` =
    /// d(unknowns)/d(knowns) `dv_known` (FMI 2.0 section 2.1.9, FMI 3.0 section 2.2.11).
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<()> {
        assert_eq!(knowns.len(), dv_known.len(), "get_directional_derivative: one seed per known");
        assert_eq!(unknowns.len(), dv_unknown.len(), "get_directional_derivative: one value per unknown");
        let c = self.component;
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = self.optional(t.get_directional_derivative, "fmi2GetDirectionalDerivative")?;
                call!(
                    self,
                    "fmi2GetDirectionalDerivative",
                    None,
                    f(
                        c,
                        unknowns.as_ptr(),
                        unknowns.len(),
                        knowns.as_ptr(),
                        knowns.len(),
                        dv_known.as_ptr(),
                        dv_unknown.as_mut_ptr()
                    )
                )
            }
            Abi::Fmi3(a) => {
                let f = f3!(self, a, get_directional_derivative, "fmi3GetDirectionalDerivative");
                call!(
                    self,
                    "fmi3GetDirectionalDerivative",
                    None,
                    f(
                        c,
                        unknowns.as_ptr(),
                        unknowns.len(),
                        knowns.as_ptr(),
                        knowns.len(),
                        dv_known.as_ptr(),
                        dv_known.len(),
                        dv_unknown.as_mut_ptr(),
                        dv_unknown.len()
                    )
                )
            }
        }
    }

    /// `fmi2EnterEventMode` / `fmi3EnterEventMode`.
    pub fn enter_event_mode(&mut self) -> Result<()> {
        either!(self, None, enter_event_mode "fmi2EnterEventMode", enter_event_mode "fmi3EnterEventMode", ())
    }

    /// `fmi2NewDiscreteStates`; FMI 3.0: `fmi3UpdateDiscreteStates`, its outputs as the
    /// FMI 2.0 event info (`discreteStatesNeedUpdate` is `newDiscreteStatesNeeded`).
    pub fn new_discrete_states(&mut self) -> Result<EventInfo> {
        let c = self.component;
        let mut info = EventInfo::default();
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = self.optional(t.new_discrete_states, "fmi2NewDiscreteStates")?;
                call!(self, "fmi2NewDiscreteStates", None, f(c, &mut info))?
            }
            Abi::Fmi3(a) => {
                let f = f3!(self, a, update_discrete_states, "fmi3UpdateDiscreteStates");
                let (mut update, mut terminate, mut nominals, mut values, mut defined) = (0u8, 0u8, 0u8, 0u8, 0u8);
                let mut next = 0.0;
                call!(
                    self,
                    "fmi3UpdateDiscreteStates",
                    None,
                    f(c, &mut update, &mut terminate, &mut nominals, &mut values, &mut defined, &mut next)
                )?;
                info.new_discrete_states_needed = (update != 0) as c_int;
                info.terminate_simulation = (terminate != 0) as c_int;
                info.nominals_of_continuous_states_changed = (nominals != 0) as c_int;
                info.values_of_continuous_states_changed = (values != 0) as c_int;
                info.next_event_time_defined = (defined != 0) as c_int;
                info.next_event_time = next;
            }
        }
        Ok(info)
    }

    /// `fmi2EnterContinuousTimeMode` / `fmi3EnterContinuousTimeMode`.
    pub fn enter_continuous_time_mode(&mut self) -> Result<()> {
        either!(self, None, enter_continuous_time_mode "fmi2EnterContinuousTimeMode", enter_continuous_time_mode "fmi3EnterContinuousTimeMode", ())
    }

    /// `fmi2CompletedIntegratorStep` / `fmi3CompletedIntegratorStep`: (enter event mode,
    /// terminate simulation).
    pub fn completed_integrator_step(&mut self) -> Result<(bool, bool)> {
        let c = self.component;
        match &self.fmu.abi {
            Abi::Fmi2(t) => {
                let f = self.optional(t.completed_integrator_step, "fmi2CompletedIntegratorStep")?;
                let (mut event, mut terminate) = (0, 0);
                call!(self, "fmi2CompletedIntegratorStep", None, f(c, 1, &mut event, &mut terminate))?;
                Ok((event != 0, terminate != 0))
            }
            Abi::Fmi3(a) => {
                let f = f3!(self, a, completed_integrator_step, "fmi3CompletedIntegratorStep");
                let (mut event, mut terminate) = (0u8, 0u8);
                call!(self, "fmi3CompletedIntegratorStep", None, f(c, 1, &mut event, &mut terminate))?;
                Ok((event != 0, terminate != 0))
            }
        }
    }

    /// `fmi2GetBooleanStatus(fmi2Terminated)` after a Discard: whether the FMU wants to
    /// stop; FMI 3.0: whether the last `fmi3DoStep` said `terminateSimulation`.
    pub fn terminated_status(&mut self) -> Option<bool> {
        let f = match &self.fmu.abi {
            Abi::Fmi2(t) => t.get_boolean_status?,
            Abi::Fmi3(_) => return Some(self.terminate_requested.is_some()),
        };
        let mut v: c_int = 0;
        // SAFETY: live component, valid out pointer; 3 = fmi2Terminated.
        let raw = unsafe { f(self.component, 3, &mut v) };
        (raw == 0).then_some(v != 0)
    }

    /// `fmi2GetRealStatus(fmi2LastSuccessfulTime)`; FMI 3.0: the `lastSuccessfulTime` of
    /// the `fmi3DoStep` that said `terminateSimulation`.
    pub fn last_successful_time(&mut self) -> Option<f64> {
        let f = match &self.fmu.abi {
            Abi::Fmi2(t) => t.get_real_status?,
            Abi::Fmi3(_) => return self.terminate_requested,
        };
        let mut v = 0.0;
        // SAFETY: live component, valid out pointer; 2 = fmi2LastSuccessfulTime.
        let raw = unsafe { f(self.component, 2, &mut v) };
        (raw == 0).then_some(v)
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        if self.state == InstanceState::Fatal {
            return; // the standard: nothing may be called after a fatal error
        }
        let _ = self.terminate();
        let (free_state, free_instance, function) = match &self.fmu.abi {
            Abi::Fmi2(t) => (t.free_fmu_state, t.free_instance, "fmi2FreeInstance"),
            Abi::Fmi3(a) => (a.functions.free_fmu_state, a.functions.free_instance, "fmi3FreeInstance"),
        };
        if let Some(free_state) = free_state {
            for mut s in std::mem::take(&mut self.saved) {
                // SAFETY: states we obtained from this instance and did not free; both
                // generations' functions take (instance, *mut state).
                unsafe { free_state(self.component, &mut s) };
            }
        }
        let _mark = crate::call_site::enter(&self.name, &self.fmu.source, function, self.time);
        // SAFETY: the component came from the instantiate call and is freed once.
        unsafe { free_instance(self.component) };
    }
}

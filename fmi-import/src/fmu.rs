//! Import of one FMI 2.0 FMU: unpack, read the model description, load the library,
//! resolve the functions of the chosen interface; and [`Instance`], whose every fmi2 call
//! returns a typed [`Result`]. An instance terminates and frees itself on drop.

use crate::error::{Error, Result, Status};
use crate::unpack::{ArchiveSource, UnpackLimits};
use model_description::ModelDescription;
use std::collections::VecDeque;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use fmi_sys::fmi2::logger::{LogEnvironment, LogMessage, LogReceiver};

type Component = fmi_sys::fmi2::fmi2Component;
type RawStatus = fmi_sys::fmi2::fmi2Status;

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

/// `fmi2CallbackFunctions`.
pub(crate) type CallbackFunctions = fmi_sys::fmi2::Fmi2CallbackFunctions;

/// `fmi2EventInfo`.
pub use fmi_sys::fmi2::Fmi2EventInfo as EventInfo;

/// The fmi2 functions of a library: the ones every interface needs, the rest optional
/// (absent when the library lacks them; calling one is then an error naming it).
pub(crate) use fmi_sys::fmi2::Fmi2Functions as Functions;

/// The callbacks of an instance whose messages go to `log` (the logger shim of fmi-sys
/// formats them).
pub(crate) fn callbacks_for(log: &LogSink) -> Box<CallbackFunctions> {
    Box::new(log.environment.callbacks())
}

/// One message an FMU logged.
#[derive(Clone, Debug, PartialEq)]
pub struct LogRecord {
    /// The status the FMU gave it.
    pub status: Status,
    /// The category.
    pub category: String,
    /// The formatted message.
    pub message: String,
}

/// The last messages of one instance (at most [`LogSink::CAPACITY`]). Its address is
/// stable (boxed) while the instance logs to it.
#[derive(Debug, Default)]
pub struct LogSink {
    environment: LogEnvironment<Records>,
}

#[derive(Debug, Default)]
struct Records(Mutex<VecDeque<LogRecord>>);

impl LogReceiver for Records {
    fn receive(&self, m: &LogMessage<'_>) {
        self.push(LogRecord {
            status: Status::from_raw(m.status),
            category: m.category.to_owned(),
            message: m.message.to_owned(),
        });
    }
}

impl Records {
    fn push(&self, record: LogRecord) {
        if let Ok(mut r) = self.0.lock() {
            if r.len() == LogSink::CAPACITY {
                r.pop_front();
            }
            r.push_back(record);
        }
    }
}

impl LogSink {
    /// Messages kept per instance.
    pub const CAPACITY: usize = 64;

    /// Takes the kept messages.
    pub fn take(&self) -> Vec<LogRecord> {
        self.environment.0.lock().map(|mut r| r.drain(..).collect()).unwrap_or_default()
    }

    /// Keeps `record` (the oldest dropped beyond the capacity).
    pub(crate) fn push(&self, record: LogRecord) {
        self.environment.push(record)
    }

    /// The last messages at Warning or worse, joined, for an error message.
    fn recent_problems(&self) -> String {
        let Ok(records) = self.environment.0.lock() else { return String::new() };
        let v: Vec<&str> =
            records.iter().rev().filter(|r| r.status != Status::Ok).take(3).map(|r| r.message.as_str()).collect();
        v.into_iter().rev().collect::<Vec<_>>().join("; ")
    }
}

/// Resolves the fmi2 functions of `lib`; a missing required one is an error naming it and
/// `path`.
///
/// # Safety
/// `lib` must be an FMI 2.0 library whose symbols have these C signatures.
pub(crate) unsafe fn load_functions(lib: &libloading::Library, path: &Path) -> Result<Functions> {
    Functions::load(lib).map_err(|missing| Error::MissingSymbol { path: path.to_path_buf(), symbol: missing.0 })
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
    pub(crate) functions: Functions,
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
}

impl std::fmt::Debug for Fmu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fmu").field("source", &self.source).field("interface", &self.interface).finish()
    }
}

/// Libraries loaded so far, by the SHA-256 of their bytes. A binary loaded once stays
/// loaded for the life of the process and later imports of the same binary share it:
/// the dynamic loader cannot unload libraries that registered thread-local destructors
/// (every Rust cdylib using std's thread locals), so loading a fresh copy from each new
/// temporary folder would map it again and again (about 90 KiB of resident memory per
/// import of our plant). The cost is bounded by the number of distinct binaries.
static LIBRARIES: std::sync::OnceLock<Mutex<std::collections::HashMap<[u8; 32], Arc<libloading::Library>>>> =
    std::sync::OnceLock::new();

pub(crate) fn load_library(so: &Path, shown: &Path, relative: &str) -> Result<Arc<libloading::Library>> {
    use sha2::Digest;
    let bytes = std::fs::read(so).map_err(|source| Error::Io { path: shown.to_path_buf(), source })?;
    let key: [u8; 32] = sha2::Sha256::digest(&bytes).into();
    let cache = LIBRARIES.get_or_init(Default::default);
    let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(lib) = cache.get(&key) {
        return Ok(lib.clone());
    }
    crate::elf::check_shared_library(&bytes)
        .map_err(|reason| Error::LoadLibrary { path: shown.to_path_buf(), reason })?;
    // SAFETY: loading runs the library's initializers; that is what importing an FMU means.
    let library = unsafe { libloading::Library::new(so) }.map_err(|e| Error::LoadLibrary {
        path: shown.to_path_buf(),
        reason: e.to_string().replace(&so.display().to_string(), relative),
    })?;
    let library = Arc::new(library);
    cache.insert(key, library.clone());
    Ok(library)
}

/// Reads `modelDescription.xml` of an unpacked FMU (at most `limits.max_xml_bytes`).
pub fn read_model_description(dir: &Path, source: &Path, limits: &UnpackLimits) -> Result<ModelDescription> {
    let path = dir.join("modelDescription.xml");
    let xml =
        crate::unpack::read_text_file(&path, "modelDescription.xml", limits.max_xml_bytes).map_err(|e| match e {
            Error::Io { source: e, .. } => {
                Error::ModelDescription { path: source.to_path_buf(), reason: format!("cannot read it: {e}") }
            }
            other => other,
        })?;
    ModelDescription::from_xml(&xml)
        .map_err(|e| Error::ModelDescription { path: source.to_path_buf(), reason: e.to_string() })
}

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
        let description = read_model_description(dir.path(), path, &options.limits)?;
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
        let resource_uri = CString::new(file_uri(&dir.path().join("resources")))
            .map_err(|_| Error::Experiment("temporary folder path contains NUL".into()))?;
        Ok(Arc::new(Fmu {
            functions,
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
        }))
    }

    /// The same FMU with its instances in host processes: a function table that carries
    /// every call to the instance's host (see `isolate`).
    pub fn isolated(self: &Arc<Fmu>) -> Arc<Fmu> {
        if self.is_isolated() {
            return self.clone();
        }
        Arc::new(Fmu {
            functions: crate::isolate::proxy::table(&|symbol| self.functions.has(symbol)),
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
        flag && self.functions.get_fmu_state.is_some()
            && self.functions.set_fmu_state.is_some()
            && self.functions.free_fmu_state.is_some()
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
        let mark = crate::call_site::enter(&$self.name, &$self.fmu, $name, $time.unwrap_or($self.time));
        // SAFETY: the component is live (not freed), the arguments are valid for the call.
        let raw = unsafe { $f };
        drop(mark);
        $self.status($name, raw, $time)
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
        let guid = CString::new(fmu.description.guid.as_str())
            .map_err(|_| Error::ModelDescription { path: fmu.source.clone(), reason: "NUL in guid".into() })?;
        let log = Box::<LogSink>::default();
        let callbacks = callbacks_for(&log);
        let mark = crate::call_site::enter(name, fmu, "fmi2Instantiate", 0.0);
        // SAFETY: every pointer is valid for the call; callbacks and log live as long as the instance.
        let component = unsafe {
            (fmu.functions.instantiate)(
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
            return Err(Error::Instantiate { instance: name.into(), log: log.recent_problems() });
        }
        Ok(Instance {
            component,
            state: InstanceState::Instantiated,
            name: name.into(),
            _name_c: name_c,
            log,
            _callbacks: callbacks,
            saved: Vec::new(),
            fmu: fmu.clone(),
            time: 0.0,
            host: None,
        })
    }

    /// `fmi2Instantiate` in a host process of its own (`isolation` names the host binary
    /// and the per-call time limit; `run_deadline`: the run's deadline and its limit).
    pub fn new_isolated(
        fmu: &Arc<Fmu>,
        name: &str,
        isolation: &crate::isolate::Isolation,
        run_deadline: Option<(std::time::Instant, std::time::Duration)>,
    ) -> Result<Instance> {
        use crate::error::HostEnd;
        let fmu = fmu.isolated();
        let name_c = CString::new(name).map_err(|_| Error::Instance { name: name.into(), reason: "NUL in name" })?;
        let guid = CString::new(fmu.description.guid.as_str())
            .map_err(|_| Error::ModelDescription { path: fmu.source.clone(), reason: "NUL in guid".into() })?;
        let failed = |m: String| Error::Host {
            instance: name.into(),
            function: "fmi2Instantiate",
            time: 0.0,
            cause: HostEnd::Failed(m),
        };
        let host = crate::isolate::channel::find_host(isolation.host.as_deref()).map_err(failed)?;
        let variables = fmu.description.model_variables.len();
        let mut channel = Box::new(
            crate::isolate::channel::Channel::start(
                &host,
                &fmu.library_path,
                variables,
                isolation.call_timeout,
                run_deadline,
                crate::isolate::Spin::of_run(),
            )
            .map_err(|cause| Error::Host {
                instance: name.into(),
                function: "fmi2Instantiate (loading the library)",
                time: 0.0,
                cause,
            })?,
        );
        let log = Box::<LogSink>::default();
        channel.log = &*log as *const LogSink;
        let status = crate::isolate::proxy::instantiate_in(
            &mut channel,
            &name_c,
            fmu.interface.fmi_type(),
            &guid,
            &fmu.resource_uri,
        );
        if status != 0 {
            if let Some(cause) = channel.failure.clone() {
                return Err(Error::Host { instance: name.into(), function: "fmi2Instantiate", time: 0.0, cause });
            }
            return Err(Error::Instantiate { instance: name.into(), log: log.recent_problems() });
        }
        let callbacks = callbacks_for(&log);
        let component = &mut *channel as *mut crate::isolate::channel::Channel as *mut c_void;
        Ok(Instance {
            component,
            state: InstanceState::Instantiated,
            name: name.into(),
            _name_c: name_c,
            log,
            _callbacks: callbacks,
            saved: Vec::new(),
            fmu,
            host: Some(channel),
            time: 0.0,
        })
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

    /// `fmi2SetupExperiment`.
    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start_time: f64, stop_time: Option<f64>) -> Result<()> {
        if self.state != InstanceState::Instantiated {
            return Err(Error::IllegalCall {
                instance: self.name.clone(),
                function: "fmi2SetupExperiment",
                state: self.state.as_str(),
            });
        }
        let f = self.fmu.functions.setup_experiment;
        let c = self.component;
        self.time = start_time;
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

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization_mode(&mut self) -> Result<()> {
        let (f, c) = (self.fmu.functions.enter_initialization_mode, self.component);
        call!(self, "fmi2EnterInitializationMode", None, f(c))?;
        self.state = InstanceState::Initialization;
        Ok(())
    }

    /// `fmi2ExitInitializationMode`.
    pub fn exit_initialization_mode(&mut self) -> Result<()> {
        let (f, c) = (self.fmu.functions.exit_initialization_mode, self.component);
        call!(self, "fmi2ExitInitializationMode", None, f(c))?;
        self.state = InstanceState::Running;
        Ok(())
    }

    /// `fmi2Terminate` (only from initialization or running; otherwise nothing to do).
    pub fn terminate(&mut self) -> Result<()> {
        if !matches!(self.state, InstanceState::Running | InstanceState::Initialization) {
            return Ok(());
        }
        let (f, c) = (self.fmu.functions.terminate, self.component);
        call!(self, "fmi2Terminate", None, f(c))?;
        self.state = InstanceState::Terminated;
        Ok(())
    }

    /// `fmi2Reset`: back to instantiated (also after an fmi2Error).
    pub fn reset(&mut self) -> Result<()> {
        if self.state == InstanceState::Fatal {
            return Err(Error::IllegalCall { instance: self.name.clone(), function: "fmi2Reset", state: "fatal" });
        }
        let f = self.optional(self.fmu.functions.reset, "fmi2Reset")?;
        let mark = crate::call_site::enter(&self.name, &self.fmu, "fmi2Reset", self.time);
        // SAFETY: live component.
        let raw = unsafe { f(self.component) };
        drop(mark);
        self.state = InstanceState::Instantiated;
        self.status("fmi2Reset", raw, None)
    }

    /// `fmi2GetReal` of `vrs` into `values` (same length). A NaN or infinite value is
    /// [`Error::NonFinite`] unless the FMU was imported with `allow_non_finite`.
    #[inline]
    pub fn get_real(&mut self, vrs: &[u32], values: &mut [f64]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "get_real: one value per value reference");
        let (f, c) = (self.fmu.functions.get_real, self.component);
        call!(self, "fmi2GetReal", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()))?;
        // all exponent bits set: Inf or NaN. An OR of integer compares over the values
        // just read, without a branch per value (the compiler vectorizes it).
        const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
        let any = values.iter().fold(false, |any, v| any | (v.to_bits() & EXPONENT == EXPONENT));
        if any && !self.fmu.allow_non_finite {
            return Err(self.non_finite(vrs, values));
        }
        Ok(())
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

    /// `fmi2SetReal`.
    #[inline]
    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "set_real: one value per value reference");
        let (f, c) = (self.fmu.functions.set_real, self.component);
        call!(self, "fmi2SetReal", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr()))
    }

    /// `fmi2GetInteger`.
    #[inline]
    pub fn get_integer(&mut self, vrs: &[u32], values: &mut [i32]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "get_integer: one value per value reference");
        let (f, c) = (self.fmu.functions.get_integer, self.component);
        call!(self, "fmi2GetInteger", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()))
    }

    /// `fmi2SetInteger`.
    #[inline]
    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "set_integer: one value per value reference");
        let (f, c) = (self.fmu.functions.set_integer, self.component);
        call!(self, "fmi2SetInteger", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr()))
    }

    /// `fmi2GetBoolean` (fmi2Boolean is a C int: 0 false, else true).
    #[inline]
    pub fn get_boolean(&mut self, vrs: &[u32], values: &mut [i32]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "get_boolean: one value per value reference");
        let (f, c) = (self.fmu.functions.get_boolean, self.component);
        call!(self, "fmi2GetBoolean", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()))
    }

    /// `fmi2SetBoolean`.
    #[inline]
    pub fn set_boolean(&mut self, vrs: &[u32], values: &[i32]) -> Result<()> {
        assert_eq!(vrs.len(), values.len(), "set_boolean: one value per value reference");
        let (f, c) = (self.fmu.functions.set_boolean, self.component);
        call!(self, "fmi2SetBoolean", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr()))
    }

    /// `fmi2GetString` of one variable (copied).
    pub fn get_string(&mut self, vr: u32) -> Result<String> {
        let mut p: *const c_char = std::ptr::null();
        let (f, c) = (self.fmu.functions.get_string, self.component);
        call!(self, "fmi2GetString", None, f(c, &vr, 1, &mut p))?;
        if p.is_null() {
            return Ok(String::new());
        }
        // SAFETY: the FMU returns a NUL-terminated string valid until the next call.
        Ok(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
    }

    /// `fmi2SetString` of one variable.
    pub fn set_string(&mut self, vr: u32, value: &str) -> Result<()> {
        let s = CString::new(value).map_err(|_| Error::InvalidValue {
            variable: format!("{}.<vr {vr}>", self.name),
            value: value.into(),
            reason: "NUL in string".into(),
        })?;
        let p = s.as_ptr();
        let (f, c) = (self.fmu.functions.set_string, self.component);
        call!(self, "fmi2SetString", None, f(c, &vr, 1, &p))
    }

    /// `fmi2DoStep` from `time` over `step` (Co-Simulation).
    #[inline]
    pub fn do_step(&mut self, time: f64, step: f64) -> Result<()> {
        let f = self.optional(self.fmu.functions.do_step, "fmi2DoStep")?;
        let c = self.component;
        call!(self, "fmi2DoStep", Some(time), f(c, time, step, 1))?;
        self.time = time + step;
        Ok(())
    }

    /// Isolated: hands `fmi2DoStep(time, step)` to the host without waiting for it, so
    /// that the hosts of several instances step at the same time; the next
    /// [`Instance::do_step`] with the same arguments takes its answer. False (nothing done)
    /// in process, and when the instance cannot step in its state (`do_step` then says why).
    pub fn post_step(&mut self, time: f64, step: f64) -> bool {
        let Some(host) = self.host.as_deref_mut() else { return false };
        if self.state != InstanceState::Running || self.fmu.functions.do_step.is_none() {
            return false;
        }
        crate::isolate::proxy::post_step(host, time, step);
        true
    }

    /// `fmi2GetFMUstate`: saves the current state.
    pub fn get_state(&mut self) -> Result<FmuState> {
        let f = self.optional(self.fmu.functions.get_fmu_state, "fmi2GetFMUstate")?;
        let mut s: *mut c_void = std::ptr::null_mut();
        let c = self.component;
        call!(self, "fmi2GetFMUstate", None, f(c, &mut s))?;
        self.saved.push(s);
        Ok(FmuState(s))
    }

    /// `fmi2GetFMUstate` into an existing state (overwritten).
    pub fn update_state(&mut self, state: &mut FmuState) -> Result<()> {
        let f = self.optional(self.fmu.functions.get_fmu_state, "fmi2GetFMUstate")?;
        let c = self.component;
        let mut s = state.0;
        call!(self, "fmi2GetFMUstate", None, f(c, &mut s))?;
        if s != state.0 {
            self.saved.retain(|p| *p != state.0);
            self.saved.push(s);
            state.0 = s;
        }
        Ok(())
    }

    /// `fmi2SetFMUstate`: restores a saved state.
    pub fn set_state(&mut self, state: &FmuState) -> Result<()> {
        let f = self.optional(self.fmu.functions.set_fmu_state, "fmi2SetFMUstate")?;
        let c = self.component;
        call!(self, "fmi2SetFMUstate", None, f(c, state.0))
    }

    /// `fmi2FreeFMUstate`.
    pub fn free_state(&mut self, state: FmuState) -> Result<()> {
        let f = self.optional(self.fmu.functions.free_fmu_state, "fmi2FreeFMUstate")?;
        self.saved.retain(|p| *p != state.0);
        let mut s = state.0;
        let c = self.component;
        call!(self, "fmi2FreeFMUstate", None, f(c, &mut s))
    }

    /// `fmi2SetTime` (Model Exchange).
    #[inline]
    pub fn set_time(&mut self, time: f64) -> Result<()> {
        let f = self.optional(self.fmu.functions.set_time, "fmi2SetTime")?;
        let c = self.component;
        self.time = time;
        call!(self, "fmi2SetTime", Some(time), f(c, time))
    }

    /// `fmi2SetContinuousStates`.
    #[inline]
    pub fn set_continuous_states(&mut self, x: &[f64]) -> Result<()> {
        let f = self.optional(self.fmu.functions.set_continuous_states, "fmi2SetContinuousStates")?;
        let c = self.component;
        call!(self, "fmi2SetContinuousStates", None, f(c, x.as_ptr(), x.len()))
    }

    /// `fmi2GetContinuousStates`.
    pub fn get_continuous_states(&mut self, x: &mut [f64]) -> Result<()> {
        let f = self.optional(self.fmu.functions.get_continuous_states, "fmi2GetContinuousStates")?;
        let c = self.component;
        call!(self, "fmi2GetContinuousStates", None, f(c, x.as_mut_ptr(), x.len()))
    }

    /// `fmi2GetDerivatives`.
    #[inline]
    pub fn get_derivatives(&mut self, dx: &mut [f64]) -> Result<()> {
        let f = self.optional(self.fmu.functions.get_derivatives, "fmi2GetDerivatives")?;
        let c = self.component;
        call!(self, "fmi2GetDerivatives", None, f(c, dx.as_mut_ptr(), dx.len()))
    }

    /// `fmi2GetEventIndicators`.
    #[inline]
    pub fn get_event_indicators(&mut self, z: &mut [f64]) -> Result<()> {
        let f = self.optional(self.fmu.functions.get_event_indicators, "fmi2GetEventIndicators")?;
        let c = self.component;
        call!(self, "fmi2GetEventIndicators", None, f(c, z.as_mut_ptr(), z.len()))
    }

    /// `fmi2EnterEventMode`.
    pub fn enter_event_mode(&mut self) -> Result<()> {
        let f = self.optional(self.fmu.functions.enter_event_mode, "fmi2EnterEventMode")?;
        let c = self.component;
        call!(self, "fmi2EnterEventMode", None, f(c))
    }

    /// `fmi2NewDiscreteStates`.
    pub fn new_discrete_states(&mut self) -> Result<EventInfo> {
        let f = self.optional(self.fmu.functions.new_discrete_states, "fmi2NewDiscreteStates")?;
        let c = self.component;
        let mut info = EventInfo::default();
        call!(self, "fmi2NewDiscreteStates", None, f(c, &mut info))?;
        Ok(info)
    }

    /// `fmi2EnterContinuousTimeMode`.
    pub fn enter_continuous_time_mode(&mut self) -> Result<()> {
        let f = self.optional(self.fmu.functions.enter_continuous_time_mode, "fmi2EnterContinuousTimeMode")?;
        let c = self.component;
        call!(self, "fmi2EnterContinuousTimeMode", None, f(c))
    }

    /// `fmi2CompletedIntegratorStep`: (enter event mode, terminate simulation).
    pub fn completed_integrator_step(&mut self) -> Result<(bool, bool)> {
        let f = self.optional(self.fmu.functions.completed_integrator_step, "fmi2CompletedIntegratorStep")?;
        let c = self.component;
        let (mut event, mut terminate) = (0, 0);
        call!(self, "fmi2CompletedIntegratorStep", None, f(c, 1, &mut event, &mut terminate))?;
        Ok((event != 0, terminate != 0))
    }

    /// `fmi2GetBooleanStatus(fmi2Terminated)` after a Discard: whether the FMU wants to stop.
    pub fn terminated_status(&mut self) -> Option<bool> {
        let f = self.fmu.functions.get_boolean_status?;
        let mut v: c_int = 0;
        // SAFETY: live component, valid out pointer; 3 = fmi2Terminated.
        let raw = unsafe { f(self.component, 3, &mut v) };
        (raw == 0).then_some(v != 0)
    }

    /// `fmi2GetRealStatus(fmi2LastSuccessfulTime)`.
    pub fn last_successful_time(&mut self) -> Option<f64> {
        let f = self.fmu.functions.get_real_status?;
        let mut v = 0.0;
        // SAFETY: live component, valid out pointer; 2 = fmi2LastSuccessfulTime.
        let raw = unsafe { f(self.component, 2, &mut v) };
        (raw == 0).then_some(v)
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        if self.state == InstanceState::Fatal {
            return; // the standard: nothing may be called after fmi2Fatal
        }
        let _ = self.terminate();
        if let Some(free_state) = self.fmu.functions.free_fmu_state {
            for mut s in std::mem::take(&mut self.saved) {
                // SAFETY: states we obtained from this instance and did not free.
                unsafe { free_state(self.component, &mut s) };
            }
        }
        let _mark = crate::call_site::enter(&self.name, &self.fmu, "fmi2FreeInstance", self.time);
        // SAFETY: the component came from fmi2Instantiate and is freed once.
        unsafe { (self.fmu.functions.free_instance)(self.component) };
    }
}

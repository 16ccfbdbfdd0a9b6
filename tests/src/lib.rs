//! A minimal FMI 2.0 importer for tests: unpacks a `.fmu`, resolves all 44 `fmi2*`
//! symbols into the function table of `fmi-sys` (a missing one is an error, as in
//! fmpy), and wraps an instance so tests can call the C ABI, including in the wrong order
//! on purpose. The log goes through the logger shim of `fmi-sys`, as in the master.
//!
//! The same library exports the 75 `fmi3*` functions: [`Fmu::functions3`] is their table
//! (all required), [`Fmu::instantiate3`] an FMI 3.0 instance with a capturing logger.

use std::ffi::{c_int, CString};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use fmi_sys::fmi2::logger::{LogEnvironment, LogMessage, LogReceiver};

/// The log of an instance: its callbacks' environment, a [`LogSink`] behind it.
pub type Log = LogEnvironment<LogSink>;
pub use fmi_sys::fmi2::{
    fmi2Component as Component, fmi2Status as Status, Fmi2EventInfo as EventInfo, Fmi2Functions as Functions,
};
pub use model_description::ModelDescription;

pub const OK: Status = 0;
pub const WARNING: Status = 1;
pub const DISCARD: Status = 2;
pub const ERROR: Status = 3;

/// The 44 symbol names.
pub const SYMBOLS: [&str; 44] = {
    let mut names = [""; 44];
    let mut k = 0;
    while k < 44 {
        names[k] = fmi_sys::fmi2::SYMBOLS[k].0;
        k += 1;
    }
    names
};

/// One logged message.
#[derive(Clone, Debug, PartialEq)]
pub struct LogRecord {
    pub status: c_int,
    pub category: String,
    pub message: String,
}

/// Where an instance's log goes.
#[derive(Default, Debug)]
pub struct LogSink {
    pub records: Mutex<Vec<LogRecord>>,
}

impl LogReceiver for LogSink {
    fn receive(&self, m: &LogMessage<'_>) {
        if let Ok(mut r) = self.records.lock() {
            r.push(LogRecord { status: m.status, category: m.category.to_owned(), message: m.message.to_owned() });
        }
    }
}

impl LogSink {
    pub fn take(&self) -> Vec<LogRecord> {
        std::mem::take(&mut *self.records.lock().unwrap_or_else(|e| e.into_inner()))
    }
    /// The last message logged with status Discard or worse.
    pub fn last_error(&self) -> Option<String> {
        self.records.lock().ok()?.iter().rev().find(|r| r.status >= DISCARD).map(|r| r.message.clone())
    }
}

/// An unpacked FMU with its library loaded.
pub struct Fmu {
    pub dir: PathBuf,
    pub description: ModelDescription,
    pub functions: Functions,
    /// The `fmi3*` functions of the same library.
    pub functions3: fmi_sys::fmi3::Fmi3Functions,
    library: std::mem::ManuallyDrop<libloading::Library>,
    /// A library of [`LIBRARIES_VARIABLE`] stays loaded after the drop: the tables it
    /// builds on first use live in its data segment, which `dlclose` would unmap, and
    /// LeakSanitizer would then report them as leaks.
    keep_loaded: bool,
}

impl Drop for Fmu {
    fn drop(&mut self) {
        if !self.keep_loaded {
            // SAFETY: dropped once, here; the function tables are not used after this
            unsafe { std::mem::ManuallyDrop::drop(&mut self.library) }
        }
        // the unpacked archive (some 9 MB with its five platforms' libraries): a run of the
        // suite unpacks dozens; a mapped library stays valid after its file is removed
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The workspace's `target/` (honours `CARGO_TARGET_DIR`).
pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap_or(Path::new(".")).join("target"))
}

/// The environment variable naming a folder of cargo-built libraries (`lib<id>.so`) that
/// replace the archives' linux64 ones, e.g. the AddressSanitizer build of scripts/test.sh.
pub const LIBRARIES_VARIABLE: &str = "NIGEL_FMU_LIBRARIES";

/// `lib<id>.so` in `folder` (cargo's name of the cdylib an archive's `<id>.so` is a copy of).
fn instrumented_library(folder: &Path, id: &str) -> Result<PathBuf, String> {
    let so = folder.join(format!("lib{id}.so"));
    if so.is_file() {
        Ok(so)
    } else {
        Err(format!("{LIBRARIES_VARIABLE} = {}: {} not found", folder.display(), so.display()))
    }
}

/// Path of a built FMU (`target/fmu/<id>.fmu`), or a message saying how to build it.
pub fn built_fmu(model_identifier: &str) -> Result<PathBuf, String> {
    let path = target_dir().join("fmu").join(format!("{model_identifier}.fmu"));
    if path.is_file() {
        Ok(path)
    } else {
        Err(format!(
            "{} not found: run `cargo run --release -p build-fmu` first (the README's test command does)",
            path.display()
        ))
    }
}

impl Fmu {
    /// Unpacks `fmu` into a fresh folder under `target/test-unpacked/` and loads its library.
    pub fn load(fmu: &Path) -> Result<Fmu, String> {
        let file = std::fs::File::open(fmu).map_err(|e| format!("{}: {e}", fmu.display()))?;
        let mut archive = zip::ZipArchive::new(file).map_err(|e| e.to_string())?;
        static COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir = target_dir().join("test-unpacked").join(format!("{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        archive.extract(&dir).map_err(|e| e.to_string())?;
        let mut xml = String::new();
        std::fs::File::open(dir.join("modelDescription.xml"))
            .and_then(|mut f| f.read_to_string(&mut xml))
            .map_err(|e| e.to_string())?;
        let description = ModelDescription::from_xml(&xml).map_err(|e| e.to_string())?;
        let id = description
            .co_simulation
            .as_ref()
            .map(|c| c.model_identifier.clone())
            .or_else(|| description.model_exchange.as_ref().map(|m| m.model_identifier.clone()))
            .ok_or("no interface")?;
        let keep_loaded = std::env::var_os(LIBRARIES_VARIABLE).is_some();
        let so = match std::env::var_os(LIBRARIES_VARIABLE) {
            Some(folder) => instrumented_library(Path::new(&folder), &id)?,
            None => dir.join("binaries").join("linux64").join(format!("{id}.so")),
        };
        let library = unsafe { libloading::Library::new(&so) }.map_err(|e| format!("{}: {e}", so.display()))?;
        // SAFETY: an FMI 2.0 library; the table lives no longer than `library`.
        let functions = unsafe { Functions::load(&library) }.map_err(|e| e.0.to_string())?;
        if let Some(missing) = SYMBOLS.iter().find(|s| !functions.has(s)) {
            return Err(format!("{}: the library does not export {missing}", so.display()));
        }
        // SAFETY: the library exports the FMI 3.0 functions with the header's signatures.
        let functions3 = unsafe { fmi_sys::fmi3::Fmi3Functions::load(&library) }.map_err(|e| e.0.to_string())?;
        if let Some(missing) = functions3.missing().first() {
            return Err(format!("{}: the library does not export {missing}", so.display()));
        }
        Ok(Fmu { dir, description, functions, functions3, library: std::mem::ManuallyDrop::new(library), keep_loaded })
    }

    pub fn guid(&self) -> &str {
        &self.description.guid
    }

    /// Value reference of a Real by name (panics in tests if absent).
    pub fn vr(&self, name: &str) -> u32 {
        self.description.variable(name).unwrap_or_else(|| panic!("no variable {name}")).value_reference
    }

    pub fn resource_uri(&self) -> String {
        format!("file://{}/resources", self.dir.display())
    }

    /// Instantiates with a capturing logger; `None` when the FMU returned NULL.
    pub fn instantiate(&self, name: &str, kind: c_int, guid: &str) -> (Option<Instance<'_>>, Box<Log>) {
        let sink = Box::<Log>::default();
        let callbacks = Box::new(sink.callbacks());
        let name_c = CString::new(name).unwrap();
        let guid_c = CString::new(guid).unwrap();
        let uri = CString::new(self.resource_uri()).unwrap();
        let c = unsafe {
            (self.functions.instantiate)(name_c.as_ptr(), kind, guid_c.as_ptr(), uri.as_ptr(), &*callbacks, 0, 0)
        };
        if c.is_null() {
            (None, sink)
        } else {
            (Some(Instance { fmu: self, c, _callbacks: callbacks }), sink)
        }
    }
}

/// The log of an FMI 3.0 instance (its `instanceEnvironment`).
#[derive(Default, Debug)]
pub struct Log3(pub LogSink);

/// The `fmi3LogMessageCallback` of [`Fmu::instantiate3`]: the environment is a [`Log3`].
unsafe extern "C" fn log_message3(
    environment: *mut std::ffi::c_void,
    status: c_int,
    category: *const std::ffi::c_char,
    message: *const std::ffi::c_char,
) {
    let text = |p: *const std::ffi::c_char| {
        if p.is_null() {
            String::new()
        } else {
            std::ffi::CStr::from_ptr(p).to_string_lossy().into_owned()
        }
    };
    if let Some(log) = (environment as *const Log3).as_ref() {
        if let Ok(mut r) = log.0.records.lock() {
            r.push(LogRecord { status, category: text(category), message: text(message) });
        }
    }
}

impl Fmu {
    /// An FMI 3.0 instance (`fmi3InstantiateCoSimulation` when `co_simulation`, else Model
    /// Exchange) with `token`, the resources folder as a native path and a capturing log;
    /// `None` when the FMU returned NULL.
    pub fn instantiate3(&self, name: &str, co_simulation: bool, token: &str) -> (Option<Instance3<'_>>, Box<Log3>) {
        let log = Box::<Log3>::default();
        let name_c = CString::new(name).unwrap();
        let token_c = CString::new(token).unwrap();
        let resources = CString::new(format!("{}/resources/", self.dir.display())).unwrap();
        let env = &*log as *const Log3 as *mut std::ffi::c_void;
        let f = &self.functions3;
        let c = unsafe {
            if co_simulation {
                (f.instantiate_co_simulation.unwrap())(
                    name_c.as_ptr(),
                    token_c.as_ptr(),
                    resources.as_ptr(),
                    0,
                    0,
                    0,
                    0,
                    std::ptr::null(),
                    0,
                    env,
                    Some(log_message3),
                    None,
                )
            } else {
                (f.instantiate_model_exchange.unwrap())(
                    name_c.as_ptr(),
                    token_c.as_ptr(),
                    resources.as_ptr(),
                    0,
                    0,
                    env,
                    Some(log_message3),
                )
            }
        };
        if c.is_null() {
            (None, log)
        } else {
            (Some(Instance3 { fmu: self, c }), log)
        }
    }
}

/// A live FMI 3.0 instance; freed on drop.
pub struct Instance3<'a> {
    pub fmu: &'a Fmu,
    pub c: fmi_sys::fmi3::fmi3Instance,
}

impl Instance3<'_> {
    pub fn f(&self) -> &fmi_sys::fmi3::Fmi3Functions {
        &self.fmu.functions3
    }
}

impl Drop for Instance3<'_> {
    fn drop(&mut self) {
        unsafe { (self.fmu.functions3.free_instance)(self.c) }
    }
}

/// A live instance; freed on drop.
pub struct Instance<'a> {
    pub fmu: &'a Fmu,
    pub c: Component,
    _callbacks: Box<fmi_sys::fmi2::Fmi2CallbackFunctions>,
}

pub const MODEL_EXCHANGE: c_int = 0;
pub const CO_SIMULATION: c_int = 1;

impl Instance<'_> {
    pub fn f(&self) -> &Functions {
        &self.fmu.functions
    }
    pub fn setup(&self, start: f64) -> Status {
        unsafe { (self.f().setup_experiment)(self.c, 0, 0.0, start, 0, 0.0) }
    }
    pub fn enter_init(&self) -> Status {
        unsafe { (self.f().enter_initialization_mode)(self.c) }
    }
    pub fn exit_init(&self) -> Status {
        unsafe { (self.f().exit_initialization_mode)(self.c) }
    }
    /// setup + enter + exit; asserts each returned OK.
    pub fn initialize(&self) {
        assert_eq!(self.setup(0.0), OK);
        assert_eq!(self.enter_init(), OK);
        assert_eq!(self.exit_init(), OK);
    }
    pub fn set_real(&self, vrs: &[u32], values: &[f64]) -> Status {
        assert_eq!(vrs.len(), values.len());
        unsafe { (self.f().set_real)(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
    }
    pub fn get_real(&self, vrs: &[u32]) -> Result<Vec<f64>, Status> {
        let mut out = vec![f64::NAN; vrs.len()];
        let s = unsafe { (self.f().get_real)(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        if s == OK {
            Ok(out)
        } else {
            Err(s)
        }
    }
    /// fmi2GetDirectionalDerivative of `unknowns` for a unit seed of the one `known`: the
    /// status and the derivatives (zeros where the call wrote none).
    pub fn directional_derivative(&self, unknowns: &[u32], known: u32) -> (Status, Vec<f64>) {
        let mut out = vec![0.0; unknowns.len()];
        let s = unsafe {
            (self.f().get_directional_derivative.unwrap())(
                self.c,
                unknowns.as_ptr(),
                unknowns.len(),
                &known,
                1,
                &1.0,
                out.as_mut_ptr(),
            )
        };
        (s, out)
    }
    pub fn set_boolean(&self, vrs: &[u32], values: &[bool]) -> Status {
        let v: Vec<c_int> = values.iter().map(|&b| b as c_int).collect();
        unsafe { (self.f().set_boolean)(self.c, vrs.as_ptr(), vrs.len(), v.as_ptr()) }
    }
    pub fn do_step(&self, t: f64, h: f64) -> Status {
        unsafe { (self.f().do_step.unwrap())(self.c, t, h, 1) }
    }
    pub fn terminate(&self) -> Status {
        unsafe { (self.f().terminate)(self.c) }
    }
    pub fn reset(&self) -> Status {
        unsafe { (self.f().reset.unwrap())(self.c) }
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        unsafe { (self.fmu.functions.free_instance)(self.c) }
    }
}

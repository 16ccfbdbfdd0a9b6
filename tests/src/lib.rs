//! A minimal FMI 2.0 importer for tests: unpacks a `.fmu`, resolves all 44 `fmi2*`
//! symbols with `libloading` (a missing one is an error, as in fmpy), and wraps an
//! instance so tests can call the C ABI, including in the wrong order on purpose.

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

pub use model_description::ModelDescription;

pub type Component = *mut c_void;
pub type Status = c_int;
pub const OK: Status = 0;
pub const WARNING: Status = 1;
pub const DISCARD: Status = 2;
pub const ERROR: Status = 3;

#[repr(C)]
pub struct CallbackFunctions {
    pub logger: Option<unsafe extern "C" fn()>,
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    pub step_finished: Option<unsafe extern "C" fn(*mut c_void, c_int)>,
    pub component_environment: *mut c_void,
}

#[repr(C)]
#[derive(Default, Debug)]
pub struct EventInfo {
    pub new_discrete_states_needed: c_int,
    pub terminate_simulation: c_int,
    pub nominals_of_continuous_states_changed: c_int,
    pub values_of_continuous_states_changed: c_int,
    pub next_event_time_defined: c_int,
    pub next_event_time: f64,
}

extern "C" {
    fn nigel_test_logger();
}

/// One logged message.
#[derive(Clone, Debug, PartialEq)]
pub struct LogRecord {
    pub status: c_int,
    pub category: String,
    pub message: String,
}

/// Where an instance's log goes (its address is the component environment).
#[derive(Default, Debug)]
pub struct LogSink {
    pub records: Mutex<Vec<LogRecord>>,
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

#[no_mangle]
unsafe extern "C" fn nigel_test_record_log(
    env: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    if env.is_null() {
        return;
    }
    let sink = &*(env as *const LogSink);
    let text =
        |p: *const c_char| if p.is_null() { String::new() } else { CStr::from_ptr(p).to_string_lossy().into_owned() };
    if let Ok(mut r) = sink.records.lock() {
        r.push(LogRecord { status, category: text(category), message: text(message) });
    }
}

macro_rules! fmi2_functions {
    ($($field:ident : $symbol:literal => fn($($arg:ty),*) $(-> $ret:ty)?;)*) => {
        /// Every fmi2 function of the library.
        #[allow(non_snake_case)]
        pub struct Functions { $(pub $field: unsafe extern "C" fn($($arg),*) $(-> $ret)?,)* }
        impl Functions {
            /// Resolves all symbols; the first missing one is the error.
            ///
            /// # Safety
            /// `lib` must be an FMI 2.0 library whose symbols have these C signatures.
            pub unsafe fn load(lib: &libloading::Library) -> Result<Functions, String> {
                Ok(Functions { $($field: *lib.get::<unsafe extern "C" fn($($arg),*) $(-> $ret)?>(concat!($symbol, "\0").as_bytes()).map_err(|e| format!("{}: {e}", $symbol))?,)* })
            }
        }
        /// The 44 symbol names.
        pub const SYMBOLS: &[&str] = &[$($symbol),*];
    };
}

fmi2_functions! {
    get_types_platform: "fmi2GetTypesPlatform" => fn() -> *const c_char;
    get_version: "fmi2GetVersion" => fn() -> *const c_char;
    set_debug_logging: "fmi2SetDebugLogging" => fn(Component, c_int, usize, *const *const c_char) -> Status;
    instantiate: "fmi2Instantiate" => fn(*const c_char, c_int, *const c_char, *const c_char, *const CallbackFunctions, c_int, c_int) -> Component;
    free_instance: "fmi2FreeInstance" => fn(Component);
    setup_experiment: "fmi2SetupExperiment" => fn(Component, c_int, f64, f64, c_int, f64) -> Status;
    enter_initialization_mode: "fmi2EnterInitializationMode" => fn(Component) -> Status;
    exit_initialization_mode: "fmi2ExitInitializationMode" => fn(Component) -> Status;
    terminate: "fmi2Terminate" => fn(Component) -> Status;
    reset: "fmi2Reset" => fn(Component) -> Status;
    get_real: "fmi2GetReal" => fn(Component, *const u32, usize, *mut f64) -> Status;
    get_integer: "fmi2GetInteger" => fn(Component, *const u32, usize, *mut c_int) -> Status;
    get_boolean: "fmi2GetBoolean" => fn(Component, *const u32, usize, *mut c_int) -> Status;
    get_string: "fmi2GetString" => fn(Component, *const u32, usize, *mut *const c_char) -> Status;
    set_real: "fmi2SetReal" => fn(Component, *const u32, usize, *const f64) -> Status;
    set_integer: "fmi2SetInteger" => fn(Component, *const u32, usize, *const c_int) -> Status;
    set_boolean: "fmi2SetBoolean" => fn(Component, *const u32, usize, *const c_int) -> Status;
    set_string: "fmi2SetString" => fn(Component, *const u32, usize, *const *const c_char) -> Status;
    get_fmu_state: "fmi2GetFMUstate" => fn(Component, *mut *mut c_void) -> Status;
    set_fmu_state: "fmi2SetFMUstate" => fn(Component, *mut c_void) -> Status;
    free_fmu_state: "fmi2FreeFMUstate" => fn(Component, *mut *mut c_void) -> Status;
    serialized_fmu_state_size: "fmi2SerializedFMUstateSize" => fn(Component, *mut c_void, *mut usize) -> Status;
    serialize_fmu_state: "fmi2SerializeFMUstate" => fn(Component, *mut c_void, *mut c_char, usize) -> Status;
    deserialize_fmu_state: "fmi2DeSerializeFMUstate" => fn(Component, *const c_char, usize, *mut *mut c_void) -> Status;
    get_directional_derivative: "fmi2GetDirectionalDerivative" => fn(Component, *const u32, usize, *const u32, usize, *const f64, *mut f64) -> Status;
    set_real_input_derivatives: "fmi2SetRealInputDerivatives" => fn(Component, *const u32, usize, *const c_int, *const f64) -> Status;
    get_real_output_derivatives: "fmi2GetRealOutputDerivatives" => fn(Component, *const u32, usize, *const c_int, *mut f64) -> Status;
    do_step: "fmi2DoStep" => fn(Component, f64, f64, c_int) -> Status;
    cancel_step: "fmi2CancelStep" => fn(Component) -> Status;
    get_status: "fmi2GetStatus" => fn(Component, c_int, *mut c_int) -> Status;
    get_real_status: "fmi2GetRealStatus" => fn(Component, c_int, *mut f64) -> Status;
    get_integer_status: "fmi2GetIntegerStatus" => fn(Component, c_int, *mut c_int) -> Status;
    get_boolean_status: "fmi2GetBooleanStatus" => fn(Component, c_int, *mut c_int) -> Status;
    get_string_status: "fmi2GetStringStatus" => fn(Component, c_int, *mut *const c_char) -> Status;
    enter_event_mode: "fmi2EnterEventMode" => fn(Component) -> Status;
    new_discrete_states: "fmi2NewDiscreteStates" => fn(Component, *mut EventInfo) -> Status;
    enter_continuous_time_mode: "fmi2EnterContinuousTimeMode" => fn(Component) -> Status;
    completed_integrator_step: "fmi2CompletedIntegratorStep" => fn(Component, c_int, *mut c_int, *mut c_int) -> Status;
    set_time: "fmi2SetTime" => fn(Component, f64) -> Status;
    set_continuous_states: "fmi2SetContinuousStates" => fn(Component, *const f64, usize) -> Status;
    get_derivatives: "fmi2GetDerivatives" => fn(Component, *mut f64, usize) -> Status;
    get_event_indicators: "fmi2GetEventIndicators" => fn(Component, *mut f64, usize) -> Status;
    get_continuous_states: "fmi2GetContinuousStates" => fn(Component, *mut f64, usize) -> Status;
    get_nominals_of_continuous_states: "fmi2GetNominalsOfContinuousStates" => fn(Component, *mut f64, usize) -> Status;
}

/// An unpacked FMU with its library loaded.
pub struct Fmu {
    pub dir: PathBuf,
    pub description: ModelDescription,
    pub functions: Functions,
    _library: libloading::Library,
}

/// The workspace's `target/` (honours `CARGO_TARGET_DIR`).
pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap_or(Path::new(".")).join("target"))
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
        let so = dir.join("binaries").join("linux64").join(format!("{id}.so"));
        let library = unsafe { libloading::Library::new(&so) }.map_err(|e| format!("{}: {e}", so.display()))?;
        let functions = unsafe { Functions::load(&library)? };
        Ok(Fmu { dir, description, functions, _library: library })
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
    pub fn instantiate(&self, name: &str, kind: c_int, guid: &str) -> (Option<Instance<'_>>, Box<LogSink>) {
        let sink = Box::<LogSink>::default();
        let callbacks = Box::new(CallbackFunctions {
            logger: Some(nigel_test_logger),
            allocate_memory: Some(calloc_shim),
            free_memory: Some(free_shim),
            step_finished: None,
            component_environment: &*sink as *const LogSink as *mut c_void,
        });
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

unsafe extern "C" fn calloc_shim(n: usize, size: usize) -> *mut c_void {
    libc_calloc(n, size)
}
unsafe extern "C" fn free_shim(p: *mut c_void) {
    libc_free(p)
}
extern "C" {
    #[link_name = "calloc"]
    fn libc_calloc(n: usize, size: usize) -> *mut c_void;
    #[link_name = "free"]
    fn libc_free(p: *mut c_void);
}

/// A live instance; freed on drop.
pub struct Instance<'a> {
    pub fmu: &'a Fmu,
    pub c: Component,
    _callbacks: Box<CallbackFunctions>,
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
    pub fn set_boolean(&self, vrs: &[u32], values: &[bool]) -> Status {
        let v: Vec<c_int> = values.iter().map(|&b| b as c_int).collect();
        unsafe { (self.f().set_boolean)(self.c, vrs.as_ptr(), vrs.len(), v.as_ptr()) }
    }
    pub fn do_step(&self, t: f64, h: f64) -> Status {
        unsafe { (self.f().do_step)(self.c, t, h, 1) }
    }
    pub fn terminate(&self) -> Status {
        unsafe { (self.f().terminate)(self.c) }
    }
    pub fn reset(&self) -> Status {
        unsafe { (self.f().reset)(self.c) }
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        unsafe { (self.fmu.functions.free_instance)(self.c) }
    }
}

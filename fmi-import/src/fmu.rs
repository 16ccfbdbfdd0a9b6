//! An imported FMU ([`Fmu`]): its unpacked folder, model description (for FMI 3.0 the
//! view of [`crate::fmi3`] and its own), the chosen interface and its library's function
//! table ([`Abi`]). How it is read and loaded is [`crate::load`]; its instances are
//! [`crate::Instance`]s.

use crate::c_types::Functions;
use crate::error::Result;
use crate::unpack::{ArchiveSource, UnpackLimits};
use model_description::ModelDescription;
use std::ffi::{c_int, CString};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The FMI interface an instance uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interface {
    /// Co-Simulation: the FMU steps itself (`fmi2DoStep`).
    CoSimulation,
    /// Model Exchange: the master integrates the FMU's derivatives.
    ModelExchange,
    /// FMI 3.0 Scheduled Execution: the master activates the FMU's model partitions at
    /// their clocks' ticks (`fmi3ActivateModelPartition`; see `instance/scheduled.rs`).
    ScheduledExecution,
}

impl Interface {
    /// The XML element name.
    pub fn as_str(self) -> &'static str {
        match self {
            Interface::CoSimulation => "CoSimulation",
            Interface::ModelExchange => "ModelExchange",
            Interface::ScheduledExecution => "ScheduledExecution",
        }
    }
    /// The interface whose XML element name is `name` (the inverse of [`Interface::as_str`]).
    pub fn from_element_name(name: &str) -> Option<Interface> {
        [Interface::CoSimulation, Interface::ModelExchange, Interface::ScheduledExecution]
            .into_iter()
            .find(|i| i.as_str() == name)
    }
    pub(crate) fn fmi_type(self) -> c_int {
        match self {
            Interface::ModelExchange => 0,
            // FMI 2.0's fmi2Type: an FMU has no Scheduled Execution there (refused at load)
            Interface::CoSimulation | Interface::ScheduledExecution => 1,
        }
    }
}

/// `cs`, `me` or `se` (as `cosim run --interface` takes them).
impl std::str::FromStr for Interface {
    type Err = String;
    fn from_str(name: &str) -> std::result::Result<Interface, String> {
        let short =
            [("cs", Interface::CoSimulation), ("me", Interface::ModelExchange), ("se", Interface::ScheduledExecution)];
        let found = short.into_iter().find(|(short_name, _)| *short_name == name);
        found.map(|(_, interface)| interface).ok_or_else(|| format!("unknown interface {name:?} (cs, me, se)"))
    }
}

/// The functions of an FMU: FMI 2.0's table, or FMI 3.0's with the FMU's own description.
pub(crate) enum Abi {
    /// FMI 2.0 (in process, or the isolation proxy).
    Fmi2(Arc<Functions>),
    /// FMI 3.0.
    Fmi3(Arc<crate::fmi3::Fmi3Abi>),
}

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
    /// FMI 3.0 Co-Simulation: whether instances use Event Mode (`eventModeUsed`); by
    /// default where the FMU needs it (its clocks). See [`crate::event_mode`].
    pub event_mode: crate::EventModeChoice,
}

/// An imported FMU: its unpacked folder (removed on drop), model description and library.
/// Share it between instances with `Arc`; it outlives them.
pub struct Fmu {
    pub(crate) abi: Abi,
    pub(crate) allow_non_finite: bool,
    /// The library loaded in this process (`None`: imported isolated, never loaded here).
    pub(crate) _library: Option<Arc<libloading::Library>>,
    pub(crate) description: ModelDescription,
    pub(crate) interface: Interface,
    pub(crate) source: PathBuf,
    /// Where the archive is (a file, or an entry of an `.ssp`).
    pub(crate) origin: ArchiveSource,
    pub(crate) resource_uri: CString,
    /// The unpacked folder: owned, or that of the FMU this is the isolated view of.
    pub(crate) dir: Option<tempfile::TempDir>,
    /// Isolated view: the FMU whose library runs in host processes.
    pub(crate) isolated_from: Option<Arc<Fmu>>,
    /// The library inside the unpacked folder.
    pub(crate) library_path: PathBuf,
    /// FMI 3.0: the variables not in the view and why (see [`crate::fmi3`]).
    pub(crate) not_in_view: Vec<(String, crate::fmi3::LeftOut)>,
    /// FMI 3.0 with structural parameters set ([`Fmu::configured`]): the FMU as loaded,
    /// which holds the unpacked folder.
    pub(crate) configured_from: Option<Arc<Fmu>>,
    /// FMI 3.0 Co-Simulation: `eventModeUsed` of its instances and why (`None` for FMI 2.0,
    /// Model Exchange and Scheduled Execution, which have no such choice).
    pub(crate) event_mode: Option<crate::EventMode>,
}

impl std::fmt::Debug for Fmu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fmu").field("source", &self.source).field("interface", &self.interface).finish()
    }
}

impl Fmu {
    /// The FMI 3.0 model description (`None` for an FMI 2.0 FMU, whose description is
    /// [`Fmu::description`]). For an FMI 3.0 FMU, [`Fmu::description`] is the view of it
    /// the master works with (see [`crate::fmi3`]).
    pub fn fmi3_description(&self) -> Option<&model_description::fmi3::ModelDescription> {
        match &self.abi {
            Abi::Fmi2(_) => None,
            Abi::Fmi3(a) => Some(&a.description),
        }
    }

    /// FMI 3.0: whether the view's variable `vr` holds values an f64 does not (Int64,
    /// UInt64, Binary), and which; `None` for every other variable and for FMI 2.0.
    pub fn exact_kind(&self, vr: u32) -> Option<crate::fmi3::ExactKind> {
        match &self.abi {
            Abi::Fmi2(_) => None,
            Abi::Fmi3(a) => a.special.get(&vr).and_then(|access| crate::fmi3::ExactKind::of(access.value_type)),
        }
    }

    /// The integer type of the view's variable `vr` as the FMU declares it (FMI 2.0
    /// Integer and Enumeration: Int32); `None` for a float, Boolean, String or Binary.
    pub fn integer_type(&self, vr: u32) -> Option<crate::fmi3::IntegerType> {
        use model_description::VariableType;
        if let Abi::Fmi3(a) = &self.abi {
            if let Some(access) = a.special.get(&vr) {
                return crate::fmi3::IntegerType::of(access.value_type);
            }
        }
        let v = self.description.model_variables.iter().find(|v| v.value_reference == vr)?;
        match v.variable_type {
            VariableType::Integer { .. } | VariableType::Enumeration { .. } => Some(crate::fmi3::IntegerType::INT32),
            _ => None,
        }
    }

    /// FMI 3.0: the variables the view leaves out (String and Binary arrays, arrays of
    /// more than 100,000 elements or of sizes it cannot resolve), neither recorded, set nor
    /// connected, each with the reason; empty for FMI 2.0.
    pub fn not_in_view(&self) -> &[(String, crate::fmi3::LeftOut)] {
        &self.not_in_view
    }

    /// The FMU's clocks (FMI 3.0; none for FMI 2.0), as its description declares them.
    pub fn clocks(&self) -> Vec<crate::clocks::Clock> {
        self.fmi3_description().map(crate::clocks::clocks_of).unwrap_or_default()
    }

    /// FMI 3.0 Co-Simulation: whether its instances are instantiated with `eventModeUsed`,
    /// and why (`None` where there is no such choice: FMI 2.0, Model Exchange, Scheduled
    /// Execution). An instance of an FMU that refuses `eventModeUsed = true` although it
    /// declares `hasEventMode` runs without it (a second try, logged as a warning).
    pub fn event_mode(&self) -> Option<&crate::EventMode> {
        self.event_mode.as_ref()
    }

    /// The same FMU with its instances in host processes: a function table that carries
    /// every call to the instance's host (see `isolate`).
    pub fn isolated(self: &Arc<Fmu>) -> Arc<Fmu> {
        if self.is_isolated() {
            return self.clone();
        }
        let abi = match &self.abi {
            Abi::Fmi2(functions) => Abi::Fmi2(Arc::new(crate::isolate::proxy::table(&|symbol| functions.has(symbol)))),
            Abi::Fmi3(a) => Abi::Fmi3(Arc::new(crate::fmi3::Fmi3Abi {
                functions: crate::isolate::proxy3::table(&|symbol| a.functions.has(symbol)),
                description: a.description.clone(),
                special: a.special.clone(),
                token: a.token.clone(),
                resource_path: a.resource_path.clone(),
                configuration: a.configuration.clone(),
                initial_sizes: a.initial_sizes.clone(),
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
            configured_from: None,
            event_mode: self.event_mode.clone(),
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
        match (&self.dir, self.isolated_from.as_ref().or(self.configured_from.as_ref())) {
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
            Interface::ScheduledExecution => false,
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

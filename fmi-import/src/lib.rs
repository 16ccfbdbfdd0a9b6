//! `fmi_import`: the importing side of FMI, the mirror of `fmi-export`.
//!
//! - [`unpack`]: FMU and SSP archives unpacked safely (no path escapes, no links, limits
//!   against archive bombs); [`elf`]: shared libraries checked before they are loaded.
//! - [`Fmu::load`] ([`load`]) reads the archive's model description (FMI 2.0 or FMI 3.0)
//!   and resolves the functions of its interface, one pipeline for both generations;
//!   [`Instance`] wraps every call in a typed [`Result`] and keeps the state machine, the
//!   same calls for both generations ([`fmi3`]: how an FMI 3.0 FMU's variables appear to
//!   the master).
//! - [`isolate`]: an instance in a host process of its own (`cosim-host`), a crash or hang
//!   of the FMU being [`Error::Host`].
//! - [`call_site`]: the marker of the FMU call in progress, read after an `exit()` or a
//!   crash inside it.
//!
//! The master (`nigel_cosim`) builds systems, algorithms and observers on these; its own
//! errors are its own type, which wraps this crate's [`Error`].
//!
//! # Modules and what each uses
//!
//! Each file uses only files above it in this list (checked by
//! `scripts/import-cycles.py`, a stage of the test command: no import circle):
//!
//! ```text
//! status, c_types, elf, suggest, call_site, clocks   leaves
//! event_mode   -> clocks                           eventModeUsed: the user's choice, the decision
//! platform     -> elf                              this build's binaries folders
//! fmi3         -> clocks, c_types                  the FMI 3.0 view (clocks: of every generation)
//! error        -> status
//! log          -> status, c_types                  what FMUs log, both loggers
//! unpack       -> error, platform
//! library      -> error, platform, c_types         loading a shared library once
//! isolate/os   -> error                            shared memory, host process, futex (Linux)
//! isolate/protocol -> os                           the host protocol's region and calls
//! isolate/channel -> os, protocol, error, log, status  the master's end of a host
//! isolate/proxy, proxy3 -> channel, protocol, c_types   tables that call a host
//! isolate/host -> os, protocol, channel, proxy3, c_types, library, log, error
//! fmu          -> c_types, fmi3, event_mode, isolate/proxy*, unpack, error    Fmu and its table
//! load         -> fmu, fmi3, event_mode, library, platform, unpack, isolate/proxy*  the one pipeline
//! structural   -> fmu, fmi3, error                  structural parameters, Fmu::configured
//! partitions                                       model partitions (Scheduled Execution)
//! instance/core -> fmu, log, c_types, error, status, call_site, isolate/channel
//! instance/callbacks -> log                       Scheduled Execution's callbacks
//! instance/fmi2, instance/fmi3 -> instance/core, instance/callbacks, fmu, fmi3, log, isolate/proxy*
//! instance/configuration -> instance/core, instance/fmi3   Configuration Mode
//! instance/scheduled -> instance/core, instance/fmi3, instance/callbacks, instance, fmu, log
//! instance     -> instance/core, instance/fmi2, instance/fmi3, fmu, log, isolate
//! ```
//!
//! A new FMI function goes into the generation's module of `instance` (and
//! [`instance`]'s `Calls` when both generations have it); a new generation-dependent
//! step of loading into `load`'s `Generation`.

#![warn(missing_docs)]

pub mod c_types;
pub mod call_site;
pub mod clocks;
pub mod elf;
pub mod error;
pub mod event_mode;
pub mod fmi3;
pub mod fmu;
pub mod instance;
pub mod isolate;
mod janitor;
pub(crate) mod library;
pub mod load;
pub mod log;
pub mod partitions;
pub mod platform;
pub mod status;
pub mod structural;
#[doc(hidden)]
pub mod suggest;
pub mod unpack;

pub use c_types::EventInfo;
pub use call_site::ExitInsideCall;
pub use error::{Error, HostEnd, Result};
pub use event_mode::{EventMode, EventModeChoice};
pub use fmu::{Fmu, ImportOptions, Interface};
pub use instance::{FmuState, Instance, InstanceState, Interval, OutputTick};
pub use isolate::Isolation;
pub use load::{read_fmi3_description, read_model_description};
pub use log::{LogRecord, LogSink};
pub use status::Status;
pub use unpack::UnpackLimits;

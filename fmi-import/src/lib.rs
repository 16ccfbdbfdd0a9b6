//! `fmi_import`: the importing side of FMI, the mirror of `fmi-export`.
//!
//! - [`unpack`]: FMU and SSP archives unpacked safely (no path escapes, no links, limits
//!   against archive bombs); [`elf`]: shared libraries checked before they are loaded.
//! - [`Fmu::load`] reads the archive's model description (FMI 2.0 or FMI 3.0) and resolves
//!   the functions of its interface; [`Instance`] wraps every call in a typed [`Result`]
//!   and keeps the state machine, the same calls for both generations ([`fmi3`]: how an
//!   FMI 3.0 FMU's variables appear to the master).
//! - [`isolate`]: an instance in a host process of its own (`cosim-host`), a crash or hang
//!   of the FMU being [`Error::Host`].
//! - [`call_site`]: the marker of the FMU call in progress, read after an `exit()` or a
//!   crash inside it.
//!
//! The master (`nigel_cosim`) builds systems, algorithms and observers on these.

#![warn(missing_docs)]

pub mod c_types;
pub mod call_site;
pub mod elf;
pub mod error;
pub mod fmi3;
pub mod fmu;
pub mod isolate;
pub(crate) mod library;
pub mod log;
pub mod status;
#[doc(hidden)]
pub mod suggest;
pub mod unpack;

pub use c_types::EventInfo;
pub use call_site::ExitInsideCall;
pub use error::{Error, HostEnd, Result};
pub use fmu::{Fmu, ImportOptions, Instance, InstanceState, Interface};
pub use isolate::Isolation;
pub use log::{LogRecord, LogSink};
pub use status::Status;
pub use unpack::UnpackLimits;

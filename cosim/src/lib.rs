//! `nigel_cosim`: an FMI 2.0 and FMI 3.0 co-simulation master (FMUs and SSP systems).
//!
//! - [`Fmu::load`] imports any FMI 2.0 or FMI 3.0 `.fmu` safely ([`unpack`]: no path escapes, no
//!   links, limits against archive bombs) and resolves the functions of its interface;
//!   [`Instance`] wraps every FMI call in a typed [`Result`].
//! - [`SystemBuilder`] makes a [`System`] of instances, start values and connections
//!   checked for type, causality and unit.
//! - [`simulate()`] runs it with fixed-step Co-Simulation, [`Algorithm::Jacobi`] or
//!   [`Algorithm::Ordered`], time `t0 + n h`, into [`Results`] (CSV as fmpy writes it);
//!   `jacobi` optionally with the instances in several threads ([`Experiment::threads`],
//!   bit-identical results); Model Exchange instances integrated by the master ([`me`]),
//!   those connected to each other advancing together with one event iteration across
//!   them ([`Error::EventIteration`] when it has no fixed point).
//! - [`simulate::Execution`]: a run advanced by its caller (`initialize`, `step`,
//!   `simulate_until`, `get`/`set` between steps, [`simulate::Observer`]s); [`simulate()`]
//!   and its variants are loops over it.
//! - [`InputTable`]: input signals over time (fmpy's `input=`), [`Experiment::input`];
//!   [`Results::write_mat`] writes MAT v4 as Dymola does ([`mat`]).
//! - [`isolate`]: instances in host processes of their own ([`Experiment::isolation`]),
//!   a crash or hang of an FMU being [`Error::Host`] with the rows so far
//!   ([`simulate::simulate_recorded`]); in process, an FMU that calls `exit()` inside a
//!   call ends the process with status 1, reported with the rows so far ([`exit_guard`]).
//! - CI: [`check`]s of a run in the [`metric`] language, [`compare`]d with a baseline in
//!   tolerance tubes, reported as JUnit XML and Markdown ([`junit`]); [`verify`] joins them
//!   for `cosim run`.
//!
//! ```no_run
//! use nigel_cosim::{Fmu, System, Experiment, simulate};
//! let fmu = Fmu::load("target/fmu/nigel_plant.fmu".as_ref())?;
//! let system = System::single("plant", fmu)?;
//! let (results, summary) = simulate(&system, &Experiment::new(1.0, 1e-3))?;
//! results.write_csv(std::fs::File::create("out.csv").unwrap()).unwrap();
//! # Ok::<(), nigel_cosim::Error>(())
//! ```

#![warn(missing_docs)]

pub mod bdf;
pub mod check;
pub mod compare;
pub(crate) use fmi_import::suggest;
pub use fmi_import::{clocks, event_mode, fmi3, instance, load, partitions, structural, unpack};
/// An imported FMU and its instances (`fmi_import`'s [`fmi_import::fmu`], [`instance`] and
/// [`load`] in one place, as the master uses them).
pub mod fmu {
    pub use fmi_import::fmu::*;
    pub use fmi_import::instance::{FmuState, Instance, InstanceState, Interval, OutputTick};
    pub use fmi_import::load::{read_fmi3_description, read_model_description};
    pub use fmi_import::EventInfo;
}
pub mod defaults;
pub mod error;
pub mod exit_guard;
pub mod info;
pub mod integrator;
pub mod junit;
pub mod loops;
pub mod mat;
pub mod me;
pub mod metric;
pub mod options;
pub mod run_setup;
pub mod sample_period;
pub mod simulate;
pub mod ssp;
pub mod system;
pub mod verify;
pub mod watchdog;

/// Isolation: instances in host processes of their own ([`fmi_import::isolate`]), and the
/// whole run in one host process ([`isolate::whole`]).
pub mod isolate {
    pub use fmi_import::isolate::*;
    #[cfg(target_os = "linux")]
    pub mod whole;
    #[cfg(not(target_os = "linux"))]
    #[path = "whole_unsupported.rs"]
    pub mod whole;
}

pub use error::{Error, HostEnd, ImportError, Result, Status};
pub use exit_guard::{on_exit_inside_call, ExitInsideCall};
pub use fmi_import::{EventMode, EventModeChoice};
pub use fmu::{Fmu, ImportOptions, Instance, InstanceState, Interface};
pub use isolate::Isolation;
pub use me::{Event, Solver};
pub use simulate::{
    simulate, simulate_with, Algorithm, Experiment, InputTable, InstancePool, Results, RowSink, SetQueue, Summary,
};
pub use ssp::{read_ssp, write_ssp, SspSystem};
pub use system::{BaseType, Connection, System, SystemBuilder, Value, VariableRef};
pub use unpack::UnpackLimits;

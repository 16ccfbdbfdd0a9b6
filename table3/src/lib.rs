//! Table III and Fig. 7 of the paper (Section V) from the three FMUs, as pinned down in
//! `docs/benchmark.md`.
//!
//! * [`engine`]: what runs one closed loop. [`Engine`] has two implementations:
//!   [`FmuEngine`] co-simulates the archives `nigel_plant.fmu`, `nigel_controller.fmu`
//!   and `nigel_maneuver.fmu` with the `nigel_cosim` master (`ordered`, 1 ms, 30 s,
//!   through the C ABI), and [`InProcess`] runs `nigel_benchmark`'s loop, the independent
//!   implementation the FMU run must reproduce.
//! * [`metric`]: the metric of docs/benchmark.md, computed here from the recorded pose and the
//!   test bench's reference outputs (not taken from either engine).
//! * [`table`]: the 48 runs of one seed (2 columns, 6 maneuvers, 4 controllers) in parallel, [`Table`]; [`paper`] holds the
//!   paper's Table III for comparison.
//! * [`report`]: the markdown table and the JSON of the contract; [`csv`] and [`plot`]
//!   (the Fig. 7 PNGs) write the recorded runs.
//! * [`study`]: several seeds, `robust_tracking` against `robust` cell by cell.
//!
//! Beyond the paper's three controllers, every table has a fourth column,
//! `robust_tracking`: the robust path-tracking gain with pose feedback and the
//! along-track speed correction (`nigel_benchmark::control`).
//!
//! ```no_run
//! use nigel_table3::{FmuEngine, Options, run_table};
//! let engine = FmuEngine::load_dir("target/fmu".as_ref())?;
//! let out = run_table(&engine, &Options::new(0))?;
//! println!("{}", nigel_table3::report::markdown(&out.table));
//! # Ok::<(), nigel_table3::Error>(())
//! ```

#![warn(missing_docs)]

pub mod csv;
pub mod engine;
pub mod error;
pub mod metric;
pub mod paper;
pub mod plot;
pub mod report;
pub mod study;
pub mod table;

pub use engine::{Engine, FmuEngine, InProcess, Job, Run};
pub use error::Error;
pub use metric::Metric;
pub use study::Study;
pub use table::{run_table, run_table_with, Cell, Options, Table, TableRun};

pub use nigel_benchmark::{Controller, Fidelity, Maneuver};

/// The controllers of our Table III in its column order: the paper's three and, beyond
/// the paper, `robust_tracking`.
pub const CONTROLLERS: [Controller; 4] = Controller::WITH_TRACKING;

/// `open_loop`, `pole_placement`, `robust`, `robust_tracking` (the JSON and FMU names).
pub fn controller_name(c: Controller) -> &'static str {
    c.name()
}

/// A job from `column/maneuver/controller` (`sim/lane_change/robust`), seed and disturbances
/// as given.
pub fn parse_job(text: &str, seed: u64) -> Result<Job, Error> {
    let bad = || Error::Usage(format!("{text:?} is not column/maneuver/controller (e.g. sim/lane_change/robust)"));
    let parts: Vec<&str> = text.split('/').collect();
    let [column, maneuver, controller] = parts[..] else { return Err(bad()) };
    let fidelity = Fidelity::ALL.into_iter().find(|f| f.column() == column).ok_or_else(bad)?;
    let maneuver = parse_maneuver(maneuver)?;
    let controller = CONTROLLERS.into_iter().find(|c| c.name() == controller).ok_or_else(bad)?;
    Ok(Job::new(seed, fidelity, maneuver, controller))
}

/// The inverse of [`Maneuver::name`], as a clear error.
pub fn parse_maneuver(name: &str) -> Result<Maneuver, Error> {
    Maneuver::from_name(name).ok_or_else(|| Error::UnknownManeuver(name.to_string()))
}

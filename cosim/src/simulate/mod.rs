//! Fixed-step Co-Simulation of a [`System`](crate::System): initialization per the
//! standard, `jacobi` and `ordered` communication, results at output points. Time is
//! `t0 + n h`.
//!
//! Before the loop everything is resolved to value references and buffer slots: the
//! loop does not allocate and looks nothing up by name.
//!
//! The modules, each using only those above it (`scripts/import-cycles.py` holds this):
//! - `input_table`: input signals over time ([`InputTable`]), the table and its values;
//! - `types`: the public types ([`Experiment`], [`Algorithm`], [`Results`], [`Summary`]);
//! - `clock`: the time base, communication point `n` at `t0 + n h`;
//! - `integers`: connections between integers carried exactly (64-bit ones too);
//! - `profiler`: the time spent in each instance's calls;
//! - `plan`: the value slots and the batched fmi2Get/fmi2Set calls;
//! - `ticks`: the ticks of an instance's FMI 3.0 input clocks and every clock's count;
//! - `me_group`: the Model Exchange integrator of a group of ME instances (a group of
//!   one for an ME instance on its own);
//! - `lane`: one instance with its calls and integrator;
//! - `observer`: what is told after every step (the recorder and its [`RowSink`], the
//!   time limit, the cancel flag, the progress);
//! - `algorithm`: `jacobi`, `ordered` and `jacobi` in threads, each one file behind one
//!   trait;
//! - `between`, `init_loop`: what happens between steps (manipulators, queued sets) and
//!   the initialization's fixed-point loop, both around an algorithm;
//! - `input`: the input table applied around the algorithm;
//! - `execution`: [`Execution`], a run advanced step by step by its caller;
//! - `driver`: [`simulate()`] and its variants, loops over an [`Execution`];
//! - `scheduled`: FMI 3.0 Scheduled Execution of one FMU ([`simulate_scheduled`]), its
//!   own loop over the model partitions' ticks.

mod algorithm;
mod between;
mod clock;
mod driver;
mod execution;
mod init_loop;
mod input;
mod input_table;
mod integers;
mod lane;
mod me_group;
mod observer;
mod plan;
mod profiler;
mod scheduled;
mod ticks;
mod types;

pub use between::{Manipulator, SetQueue, StepInstances};
pub use clock::Point;
pub use driver::{run_to_end, run_to_end_with, simulate, simulate_recorded, simulate_with, TimedSet};
pub use execution::{Execution, InstancePool, Phase};
pub use input_table::InputTable;
pub use lane::apply_start_values;
pub use observer::{Cancel, Observer, Progress, RowSink};
pub use plan::default_record;
pub use scheduled::{is_scheduled, simulate_scheduled, NOT_ISOLATED as SCHEDULED_NOT_ISOLATED};
pub use types::{number_text, push_number, Algorithm, ExactColumn, Experiment, Results, Summary, DEFAULT_MAX_STEPS};

pub use me_group::MAX_EVENT_ROUNDS;

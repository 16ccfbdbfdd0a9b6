//! The benchmark of the paper's Section V (Table III), exactly as pinned down in
//! `docs/benchmark.md`, as a plain Rust library (no solver, no FFI): the controller
//! and test-bench FMUs are thin bindings over it, and it is the in-process cross-check
//! that a co-simulation of those FMUs with the plant FMU must reproduce.
//!
//! * [`noise`]: counter-based SplitMix64 `u(seed, stream, k)` and Box-Muller `g(seed, stream, k)`.
//! * [`scenario`]: [`Maneuver`], [`Fidelity`] (the "sim" / "real" columns), the steering
//!   [`Program`] per sample, [`Disturbances`] per sample (friction, wind, measurement noise; their numbers [`DisturbanceSettings`]),
//!   and [`DisturbanceSequence`]: the same numbers from a table computed once per seed and
//!   process (Table III runs 36 closed loops on one seed).
//! * [`control`]: the sampled law `delta = delta_ff + K (x - x_ref)` with the speed-hold PI,
//!   [`SampledController`]; beyond the paper, the robust tracking law on the pose errors with
//!   the along-track speed correction ([`Controller::RobustTracking`]); the baked gains in [`gains`].
//! * [`fmu_system`]: the closed loop as the three FMUs' instances, parameters and connections
//!   (what build-fmu writes as SSP and nigel-table3 co-simulates).
//! * [`run`]: the figure-8 switching table, the reference (kept per process:
//!   [`Benchmark::shared_reference`]), closed-loop runs and the metric; [`BenchSampler`], the
//!   test bench's outputs sample by sample (what the test-bench FMU runs).
//!
//! ```no_run
//! use nigel_benchmark::{Benchmark, Controller, Fidelity, Maneuver, Scenario};
//! let bench = Benchmark::prepare(Scenario::new(Maneuver::Skidpad, Fidelity::Paper)).unwrap();
//! let run = bench.run(Controller::Robust).unwrap();
//! println!("epsilon = {}", run.metric.epsilon);
//! ```
//!
//! # Decisions where docs/benchmark.md leaves room
//! * Sample boundaries of the programs are integer sample indices (`k in 14_800..15_000`),
//!   so `t = 14.8 s` is never subject to rounding; the fishhook ramp is `a (t_k - 2.5) / 22.5`,
//!   the slalom `a cos(30 pi (t_k - 2.5) / 25)` with `t_k - 2.5 = (k - 2500) * 1 ms`.
//! * Plant per column: "sim" is [`nigel_vehicle::VehicleParams::table2`] (paper fidelity),
//!   "real" is [`nigel_vehicle::VehicleParams::real_fidelity`]. The synthesis geometry
//!   (`l_r = 0.07924`) is the design model only, never the simulated car.
//! * The integration is `nigel_vehicle::integrate` over 1 ms with sub-steps of at most
//!   0.5 ms, exactly what the plant FMU's `fmi2DoStep` does with its default `cs_substep_max`.
//! * Start: origin, heading +X, `v_x = speed_ref` (0.35 m/s), servo angles 0, `I = 0`.
//! * The figure-8 decision at sample `k >= 1` uses the state at `t_k` and `t_(k-1)` of the
//!   nominal paper run, before the steering of sample `k` is applied; `psi_last` starts at 0.
//! * Measurement noise exists only in the real fidelity (`Scenario::measurement_noise` is a
//!   switch that can turn it off there); the speed loop and the metric use the true state.
//! * The metric runs over the states at `t_1 .. t_n` (the state after each sample), the
//!   heading unwrapped by construction (the plant integrates it).

// `!(x > 0.0)`-style checks are deliberate: they refuse NaN together with the bad values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![allow(clippy::needless_range_loop)]
#![warn(missing_docs)]

pub mod control;
pub mod fmu_system;
pub mod gain_file;
pub mod gains;
pub mod noise;
pub mod run;
pub mod scenario;

pub use control::{Controller, ControllerInputs, ControllerOutputs, ControllerSettings, SampledController};
/// The wheels (the suffixes of every per-wheel name), in the order of every per-wheel array.
pub use nigel_vehicle::WHEELS;
pub use run::{
    figure8_switches, table3, BenchSample, BenchSampler, Benchmark, ClosedLoopRun, Metric, Reference, TableCell,
    Trajectory,
};
pub use scenario::{
    DisturbanceSequence, DisturbanceSettings, Disturbances, Fidelity, Maneuver, Program, Scenario, SettingError,
    DEFAULT_SPEED, DEFAULT_STEER_AMPLITUDE, MAX_WIND_AMPLITUDE, MU_MAX, N_SAMPLES, SAMPLE_PERIOD,
};

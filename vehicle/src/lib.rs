//! Nigel: nonlinear 4WD4WS yaw-plane vehicle dynamics (paper Section III), as plain Rust.
//!
//! The same parameter type and right-hand side serve the plant FMU, the synthesis crate
//! (through [`linear_model`]) and the master's in-process reference runs.

pub mod dynamics;
pub mod linear;
pub mod params;
pub mod scalar;

pub use dynamics::{derivatives_of, evaluate, steering, Steering, integrate, rk4_step, straight_running, Evaluation, Inputs, State, N_STATES};
pub use linear::{linear_model, DisturbanceColumn, LinearModel};
pub use params::{ParamError, VehicleParams, WHEELS};
pub use scalar::{Dual, Scalar};

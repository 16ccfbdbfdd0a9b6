//! Nigel: nonlinear 4WD4WS yaw-plane vehicle dynamics (paper Section III), as plain Rust.
//!
//! The same parameter type and right-hand side serve the plant FMU, the synthesis crate
//! (through [`linear_model`]) and the master's in-process reference runs.

// `!(x > 0.0)` is deliberate throughout: it refuses NaN together with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Wheel loops index several per-wheel arrays at once; an index reads clearer than zips.
#![allow(clippy::needless_range_loop)]

pub mod dynamics;
pub mod fastmath;
pub mod linear;
pub mod params;
pub mod scalar;
#[cfg(test)]
mod test_rng;
pub mod tracking;

pub use dynamics::{
    derivatives_of, evaluate, integrate, rk4_step, steering, straight_running, Evaluation, Inputs, ParamScalars,
    ParamsOf, State, Steering, N_STATES,
};
pub use linear::{linear_model, DisturbanceColumn, LinearModel};
pub use params::{ParamError, VehicleParams, WHEELS};
pub use scalar::{Dual, Scalar};
pub use tracking::{
    tracking_error_rates, tracking_errors, tracking_model, TrackingErrors, TrackingModel, N_TRACKING_STATES,
    TRACKING_STATE_NAMES,
};

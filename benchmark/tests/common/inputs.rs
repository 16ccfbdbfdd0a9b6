//! The controller inputs the law's tests start from, shared by the unit tests of
//! `src/control.rs` (included there with `#[path]`) and the integration tests. The parent
//! module brings `ControllerInputs` into scope (`crate::` in the library, `nigel_benchmark::`
//! in a test crate).

use super::ControllerInputs;

/// Off the reference in every signal: `beta - beta_ref = 0.01`, `yaw_rate - yaw_rate_ref =
/// -0.15`, speed error `0.35 - 0.3 = 0.05`, the program `[0.1, 0.1, -0.1, -0.1]`, and the
/// car on its reference pose at the origin (only the tracking law reads the pose).
pub fn off_reference() -> ControllerInputs {
    ControllerInputs {
        beta: 0.02,
        yaw_rate: -0.1,
        speed: 0.3,
        beta_ref: 0.01,
        yaw_rate_ref: 0.05,
        speed_ref: 0.35,
        delta_ff: [0.1, 0.1, -0.1, -0.1],
        x: 0.0,
        y: 0.0,
        psi: 0.0,
        x_ref: 0.0,
        y_ref: 0.0,
        psi_ref: 0.0,
    }
}

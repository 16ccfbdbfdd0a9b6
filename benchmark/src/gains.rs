//! Controller gains baked from the robust synthesis. GENERATED, do not edit: regenerate with
//! `cargo run --release -p nigel-synthesis --bin bake-gains`
//! (`synthesis/tests/baked_gains.rs` fails when this file and a fresh synthesis differ by more
//! than 1e-9).
//!
//! Convention: `delta = delta_ff + K (x - x_ref)`, `x = [beta, yaw_rate]`, rows FL, FR, RL, RR.

/// Robust mixed H2/H-inf gain: paper variant (printed `d2`, `l_r = 0.07924`), 4WD4WS, the Pareto
/// point nearest the origin: k = 9, H-inf bound g = 0.20743902698621247,
/// H2 bound nu = 0.55127099382591 (gamma* = 0.11743902698621246).
pub const ROBUST: [[f64; 2]; 4] = [
    [-0.16065807504986623, -0.3104160521420235], // FL
    [-0.1606580750230906, -0.3104160522174845],  // FR
    [-0.14797726013293167, 0.4092745873151182],  // RL
    [-0.14797866319162523, 0.4092793222431792],  // RR
];

/// Non-robust baseline: pole placement `Re(s) < -2.0` on the nominal model `mu_i = 0.4` (same
/// plant as `ROBUST`); stabilises all 16 friction vertices: true
/// (largest closed-loop real part over them -3.293955174205458).
pub const POLE_PLACEMENT: [[f64; 2]; 4] = [
    [0.44495522866916887, 0.04138846825366576], // FL
    [0.44495522866916887, 0.04138846825366576], // FR
    [0.5549146485747638, -0.07206728388483528], // RL
    [0.5549146485747638, -0.07206728388483528], // RR
];

/// Robust tracking gain `K_track`: mixed H2/H-inf with D-stability on the tracking
/// error model (Table II, physical disturbance column, v = 0.35 m/s, mu in [0.1, 1.0]),
/// weights z = [50 e_y; 10 e_psi; 10 u], region Re(s) < -0.5 and the 135-degree sector;
/// Pareto point k = 12, H-inf bound g = 2.227808682400355, H2 bound nu = 3.3432342322959183
/// (gamma* = 1.3923804265002218); verified (poles, H-inf, H2).
/// Convention: `delta = delta_ff + K_track e`, `e = [e_y, e_psi, beta - beta_ref, yaw_rate - yaw_rate_ref]`
/// (`nigel_vehicle::tracking`), rows FL, FR, RL, RR.
pub const ROBUST_TRACKING: [[f64; 4]; 4] = [
    [-5.272318971900195, -1.6297760804449077, -0.2845464824151373, -0.11299016866604743], // FL
    [-5.272318971929137, -1.6297760804565058, -0.2845464824212304, -0.11299016866717677], // FR
    [0.7266360234755993, 0.7945185938075542, 0.013772622880761934, 0.06320836417032108],  // RL
    [0.7266360234731885, 0.7945185938206956, 0.013772622881474718, 0.06320836417026512],  // RR
];

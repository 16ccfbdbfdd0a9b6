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

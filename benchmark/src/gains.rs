//! Controller gains baked from the robust synthesis. GENERATED, do not edit: regenerate with
//! `cargo run --release -p nigel-synthesis --bin bake-gains`
//! (`synthesis/tests/baked_gains.rs` and `synthesis/tests/tracking.rs` fail when this file and
//! a fresh synthesis differ by more than the solver reproduces them: 1e-8 for the robust gain,
//! 1e-9 for the pole placement, 2e-5 for `K_track`).
//!
//! Convention: `delta = delta_ff + K (x - x_ref)`, `x = [beta, yaw_rate]`, rows FL, FR, RL, RR.

/// Robust mixed H2/H-inf gain: paper variant (printed `d2`, `l_r = 0.07924`), 4WD4WS, the Pareto
/// point nearest the origin: k = 9, H-inf bound g = 0.20743901453571106,
/// H2 bound nu = 0.5512709988325352 (gamma* = 0.11743901453571105).
pub const ROBUST: [[f64; 2]; 4] = [
    [-0.16066941979152105, -0.31042453961559296], // FL
    [-0.16066941979152105, -0.31042453961559296], // FR
    [-0.14797401091215961, 0.4092828088245956], // RL
    [-0.14797401091215961, 0.4092828088245956], // RR
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
/// Pareto point k = 12, H-inf bound g = 2.227808578571624, H2 bound nu = 3.343235155985476
/// (gamma* = 1.392380361607265); verified (poles, H-inf, H2).
/// Convention: `delta = delta_ff + K_track e`, `e = [e_y, e_psi, beta - beta_ref, yaw_rate - yaw_rate_ref]`
/// (`nigel_vehicle::tracking`), rows FL, FR, RL, RR.
pub const ROBUST_TRACKING: [[f64; 4]; 4] = [
    [-5.272365548259472, -1.6297703880292294, -0.28454279532302285, -0.11299076352073209], // FL
    [-5.272365548259472, -1.6297703880292294, -0.28454279532302285, -0.11299076352073209], // FR
    [0.7264180081239429, 0.7944614006439832, 0.013759942543742958, 0.06320472878061711], // RL
    [0.7264180081239429, 0.7944614006439832, 0.013759942543742958, 0.06320472878061711], // RR
];

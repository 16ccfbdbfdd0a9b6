//! `bake-gains`: runs the robust synthesis and writes the gains the controller FMU and the
//! benchmark use into `benchmark/src/gains.rs` (generated Rust source, committed).
//!
//! ```sh
//! cargo run --release -p nigel-synthesis --bin bake-gains            # rewrite benchmark/src/gains.rs
//! cargo run --release -p nigel-synthesis --bin bake-gains -- OUT.rs  # write elsewhere
//! ```
//! Baked: the robust gain (paper variant, 4WD4WS, the Pareto point nearest the origin),
//! the pole-placement baseline (`Re(s) < -2` at `mu_i = 0.4`, same polytope) and the robust
//! tracking gain `K_track` ([`nigel_synthesis::tracking::design_tracking`] with the
//! default design and region). The tests `synthesis/tests/baked_gains.rs` (the paper's two)
//! and `synthesis/tests/tracking.rs` (`K_track`, reusing the design that file verifies)
//! re-run the synthesis and fail if the committed file differs from it by more than the
//! solver reproduces it across OpenBLAS kernels (1e-8 robust, 1e-9 pole placement, 2e-5
//! `K_track`; the reasons are next to each tolerance), so the file cannot drift from the
//! synthesis.
//!
//! Exit codes: 0 written, 1 synthesis failed, 2 bad command line or I/O error.

use std::path::PathBuf;
use std::process::ExitCode;

use nalgebra::DMatrix;
use nigel_synthesis::tracking::{design_tracking, tracking_region};
use nigel_synthesis::{
    pareto_sweep, pole_placement_baseline, Architecture, PlantSpec, PoleRegion, SweepOptions, SynthesisOptions,
    TrackingSpec, VerifyOptions,
};

fn rows(k: &DMatrix<f64>) -> Result<[[f64; 2]; 4], String> {
    if k.shape() != (4, 2) {
        return Err(format!("gain has shape {:?}, expected 4x2", k.shape()));
    }
    Ok([[k[(0, 0)], k[(0, 1)]], [k[(1, 0)], k[(1, 1)]], [k[(2, 0)], k[(2, 1)]], [k[(3, 0)], k[(3, 1)]]])
}

fn matrix_literal(k: &[[f64; 2]; 4]) -> String {
    // `{:?}` prints the shortest decimal that reads back to the same f64 (round trip exact)
    let wheel = ["FL", "FR", "RL", "RR"];
    let mut s = String::from("[\n");
    for (row, name) in k.iter().zip(wheel) {
        s.push_str(&format!("    [{:?}, {:?}], // {name}\n", row[0], row[1]));
    }
    s.push(']');
    s
}

fn tracking_literal(k: &[[f64; 4]; 4]) -> String {
    let wheel = ["FL", "FR", "RL", "RR"];
    let mut s = String::from("[\n");
    for (row, name) in k.iter().zip(wheel) {
        s.push_str(&format!("    [{:?}, {:?}, {:?}, {:?}], // {name}\n", row[0], row[1], row[2], row[3]));
    }
    s.push(']');
    s
}

fn generate() -> Result<String, String> {
    let spec = PlantSpec::paper(Architecture::FourWheelSteering);
    let poly = spec.polytope().map_err(|e| e.to_string())?;
    let opts = SynthesisOptions::default();
    let sweep = pareto_sweep(&poly, &PoleRegion::paper(), &SweepOptions::default(), &opts, None)
        .map_err(|e| format!("Pareto sweep: {e}"))?;
    let chosen = sweep.chosen_point();
    let design = sweep.chosen_design().ok_or("the chosen Pareto point has no design")?;
    let robust = rows(&design.gain)?;
    let baseline = pole_placement_baseline(&poly, 0.4, -2.0, &opts).map_err(|e| format!("baseline: {e}"))?;
    let pole = rows(&baseline.design.gain)?;
    let nu = chosen.nu().unwrap_or(f64::NAN);
    let tracking =
        design_tracking(&TrackingSpec::default_design(), &tracking_region(), &opts, &VerifyOptions::default(), 0, None)
            .map_err(|e| format!("tracking design: {e}"))?;
    if !tracking.verification.passed() {
        return Err("the tracking design failed its verification".into());
    }
    let tracking_point = tracking.sweep.chosen_point();
    Ok(format!(
        "//! Controller gains baked from the robust synthesis. GENERATED, do not edit: regenerate with\n\
         //! `cargo run --release -p nigel-synthesis --bin bake-gains`\n\
         //! (`synthesis/tests/baked_gains.rs` and `synthesis/tests/tracking.rs` fail when this file and\n\
         //! a fresh synthesis differ by more than the solver reproduces them: 1e-8 for the robust gain,\n\
         //! 1e-9 for the pole placement, 2e-5 for `K_track`).\n\
         //!\n\
         //! Convention: `delta = delta_ff + K (x - x_ref)`, `x = [beta, yaw_rate]`, rows FL, FR, RL, RR.\n\n\
         /// Robust mixed H2/H-inf gain: paper variant (printed `d2`, `l_r = 0.07924`), 4WD4WS, the Pareto\n\
         /// point nearest the origin: k = {k}, H-inf bound g = {g:?},\n\
         /// H2 bound nu = {nu:?} (gamma* = {gs:?}).\n\
         pub const ROBUST: [[f64; 2]; 4] = {robust};\n\n\
         /// Non-robust baseline: pole placement `Re(s) < {alpha:?}` on the nominal model `mu_i = {mu:?}` (same\n\
         /// plant as `ROBUST`); stabilises all 16 friction vertices: {stab}\n\
         /// (largest closed-loop real part over them {re:?}).\n\
         pub const POLE_PLACEMENT: [[f64; 2]; 4] = {pole};\n\n\
         /// Robust tracking gain `K_track`: mixed H2/H-inf with D-stability on the tracking\n\
         /// error model (Table II, physical disturbance column, v = 0.35 m/s, mu in [0.1, 1.0]),\n\
         /// weights z = [50 e_y; 10 e_psi; 10 u], region Re(s) < -0.5 and the 135-degree sector;\n\
         /// Pareto point k = {tk}, H-inf bound g = {tg:?}, H2 bound nu = {tnu:?}\n\
         /// (gamma* = {tgs:?}); verified (poles, H-inf, H2).\n\
         /// Convention: `delta = delta_ff + K_track e`, `e = [e_y, e_psi, beta - beta_ref, yaw_rate - yaw_rate_ref]`\n\
         /// (`nigel_vehicle::tracking`), rows FL, FR, RL, RR.\n\
         pub const ROBUST_TRACKING: [[f64; 4]; 4] = {track};\n",
        k = chosen.k,
        g = chosen.g,
        gs = sweep.gamma_star(),
        robust = matrix_literal(&robust),
        alpha = baseline.alpha,
        mu = baseline.mu_nominal,
        stab = baseline.stabilises_all_vertices,
        re = baseline.max_real_part_over_vertices,
        pole = matrix_literal(&pole),
        tk = tracking_point.k,
        tg = tracking.gamma,
        tnu = tracking.nu,
        tgs = tracking.sweep.gamma_star(),
        track = tracking_literal(&tracking.k_track),
    ))
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "-h" || a == "--help") || args.len() > 1 {
        eprintln!("usage: bake-gains [OUT.rs]   (default: benchmark/src/gains.rs of this workspace)");
        return ExitCode::from(if args.len() > 1 { 2 } else { 0 });
    }
    let out = match args.first() {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../benchmark/src/gains.rs"),
    };
    let text = match generate() {
        Ok(t) => t,
        Err(e) => {
            eprintln!("bake-gains: {e}");
            return ExitCode::from(1);
        }
    };
    if let Err(e) = std::fs::write(&out, text) {
        eprintln!("bake-gains: cannot write {}: {e}", out.display());
        return ExitCode::from(2);
    }
    eprintln!("bake-gains: wrote {}", out.display());
    ExitCode::SUCCESS
}

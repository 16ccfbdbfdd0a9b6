//! `nigel-cosim` as a Rust library: read the closed loop's SSP, run it with two controllers
//! (the parameter `controller.controller` changed between runs), and score each run with the
//! benchmark's metric (docs/benchmark.md) from the recorded columns.
//!
//! ```sh
//! cargo run --release -p build-fmu                                  # target/fmu, target/ssp
//! cargo run --release -p nigel-cosim --example closed_loop [SSP]    # default target/ssp/nigel_closed_loop.ssp
//! ```
//!
//! Prints (the SSP `build-fmu` writes: sim column, lane change, seed 0):
//!
//! ```text
//! open_loop epsilon 5.931892230e-2
//! robust    epsilon 4.204754401e-2
//! ```
//!
//! the open-loop and robust cells of `table3`'s sim lane-change row (the test,
//! `examples/test_examples.py`, compares them with `table3 --json` to 1e-9 relative).

use std::path::PathBuf;

use nigel_cosim::{read_ssp, simulate, Algorithm, Experiment, ImportOptions, SystemBuilder, Value};

/// RMSE of X, Y and psi against the reference over t = 1 ms .. end, and their 2-norm.
fn epsilon(results: &nigel_cosim::Results) -> Result<f64, String> {
    let col = |n: &str| results.column(n).ok_or_else(|| format!("no column {n}"));
    let mut sum = 0.0;
    for q in ["x", "y", "psi"] {
        let (car, reference) = (col(&format!("plant.{q}"))?, col(&format!("maneuver.{q}_ref"))?);
        let n = car.len() - 1;
        let mse = car.iter().zip(&reference).skip(1).map(|(a, b)| (a - b) * (a - b)).sum::<f64>() / n as f64;
        sum += mse;
    }
    Ok(sum.sqrt())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/ssp/nigel_closed_loop.ssp"));
    let ssp = read_ssp(&path, &ImportOptions::default())?;
    let mut experiment = Experiment::new(30.0, 1e-3);
    // the controller sees the plant at t_k: outputs flow along the direct feedthrough
    experiment.algorithm = Algorithm::Ordered;
    experiment.record = Some(
        ["plant.x", "plant.y", "plant.psi", "maneuver.x_ref", "maneuver.y_ref", "maneuver.psi_ref"]
            .map(String::from)
            .to_vec(),
    );
    // the controller FMU's switch: 1 open_loop, 3 robust (listed in its description)
    for (name, value) in [("open_loop", 1), ("robust   ", 3)] {
        let mut builder = SystemBuilder::from_system(ssp.system.clone());
        builder.set("controller.controller", Value::Integer(value))?;
        let (results, _summary) = simulate(&builder.build(), &experiment)?;
        println!("{name} epsilon {:.9e}", epsilon(&results)?);
    }
    Ok(())
}

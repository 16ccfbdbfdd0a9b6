//! Speed of the plant's Co-Simulation step without the FMI layer: `integrate` over 1 ms
//! with 0.5 ms RK4 sub-steps (what `fmi2DoStep` of the plant FMU does), paper and real
//! fidelity, along a slalom whose inputs change at every step as a controller's would.
//!
//! `cargo bench -p nigel-vehicle --bench integrate [-- --steps N --fidelity paper|real]` prints the time per step;
//! run the binary under `valgrind --tool=callgrind` for instruction counts per step.

use std::hint::black_box;
use std::time::Instant;

use nigel_vehicle::{integrate, straight_running, Inputs, VehicleParams};

fn run(p: &VehicleParams, steps: usize) -> f64 {
    let mut s = straight_running(0.35);
    let mut u = Inputs::coasting(0.4);
    for k in 0..steps {
        let t = k as f64 * 1e-3;
        let steer = 0.3 * (2.0 * t).sin();
        u.delta = [steer, steer, -0.5 * steer, -0.5 * steer];
        u.tau = [0.004 * (0.35 - s[3]); 4];
        s = integrate(black_box(p), &s, &u, 1e-3, 5e-4);
    }
    black_box(s)[0]
}

fn main() {
    let mut steps = 30_000;
    let mut only: Option<String> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--steps" {
            steps = args.next().and_then(|v| v.parse().ok()).expect("--steps N");
        } else if a == "--fidelity" {
            only = Some(args.next().expect("--fidelity paper|real"));
        }
    }
    for (name, p) in [("paper", VehicleParams::table2()), ("real", VehicleParams::real_fidelity())] {
        if only.as_ref().is_some_and(|o| o != name) {
            continue;
        }
        let start = Instant::now();
        let x = run(&p, steps);
        let per_step = start.elapsed().as_secs_f64() / steps as f64;
        println!(
            "integrate 1 ms (2 RK4 sub-steps), {name} fidelity: {:.1} ns/step over {steps} steps (x = {x:.6} m)",
            per_step * 1e9
        );
    }
}

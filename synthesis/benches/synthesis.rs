//! Timing of one SDP solve and of the whole 4WD4WS Pareto sweep (plain harness:
//! `cargo bench -p nigel-synthesis`, prints min and median over repetitions).

use std::time::Instant;

use nigel_synthesis::{
    min_h2, min_hinf, pareto_sweep, verify_design, Architecture, PlantSpec, PoleRegion, SweepOptions, SynthesisOptions,
    VerifyOptions,
};

fn time<F: FnMut()>(name: &str, reps: usize, mut f: F) {
    f(); // warm-up
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    println!("{name:<52} min {:>9.2} ms   median {:>9.2} ms   ({reps} runs)", t[0] * 1e3, t[reps / 2] * 1e3);
}

fn main() {
    // `cargo bench` passes --bench; `cargo test --benches` passes nothing special: run once
    let quick = !std::env::args().any(|a| a == "--bench");
    let reps = if quick { 1 } else { 10 };
    let poly = PlantSpec::paper(Architecture::FourWheelSteering).polytope().unwrap();
    let region = PoleRegion::paper();
    let opts = SynthesisOptions::default();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    time("one SDP: gamma* (min H-inf, 16 vertices)", reps * 5, || {
        min_hinf(&poly, &region, &opts).unwrap();
    });
    time("one SDP: min H2 at g = 0.2 (mixed, 16 vertices)", reps * 5, || {
        min_h2(&poly, &region, Some(0.2), &opts).unwrap();
    });
    time("whole 4WD4WS sweep, 1 thread (40 SDPs)", reps, || {
        pareto_sweep(&poly, &region, &SweepOptions { threads: 1, ..SweepOptions::default() }, &opts, None).unwrap();
    });
    time(&format!("whole 4WD4WS sweep, {threads} threads (40 SDPs)"), reps, || {
        pareto_sweep(&poly, &region, &SweepOptions::default(), &opts, None).unwrap();
    });
    let d = min_h2(&poly, &region, Some(0.2), &opts).unwrap();
    time("verification (16 vertices + 64 interior points)", reps, || {
        verify_design(&poly, &region, &d.gain, d.gamma, d.nu, &VerifyOptions::default());
    });
}

//! Speed of the in-process benchmark (a bench binary, medians of repeated runs):
//! `cargo bench -p nigel-benchmark --bench closed_loop`.

use std::time::Instant;

use nigel_benchmark::{table3, BenchSampler, Benchmark, Controller, Fidelity, Maneuver, Scenario, N_SAMPLES};

fn median_seconds(repeats: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..repeats)
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[repeats / 2]
}

fn main() {
    for fidelity in Fidelity::ALL {
        let scenario = Scenario::new(Maneuver::Slalom, fidelity);
        let prepare = median_seconds(9, || {
            std::hint::black_box(Benchmark::prepare(scenario).unwrap());
        });
        let bench = Benchmark::prepare(scenario).unwrap();
        let run = median_seconds(9, || {
            std::hint::black_box(bench.run(Controller::Robust).unwrap());
        });
        println!(
            "{:>4} slalom: reference {:.1} ms, closed-loop run {:.1} ms (30,000 samples: {:.2} us a sample)",
            fidelity.column(),
            prepare * 1e3,
            run * 1e3,
            run / 30_000.0 * 1e6
        );
    }
    // the test bench's per-sample outputs: the formulas at every sample (Benchmark::sample)
    // against the per-seed disturbance table (BenchSampler::sample, what the FMU runs)
    let scenario = Scenario::new(Maneuver::Slalom, Fidelity::Real);
    let bench = Benchmark::prepare(scenario).unwrap();
    let sampler = BenchSampler::prepare(scenario).unwrap();
    let sweep = |f: &dyn Fn(usize) -> f64| {
        median_seconds(9, || {
            let mut acc = 0.0;
            for k in 0..=N_SAMPLES {
                acc += f(k);
            }
            std::hint::black_box(acc);
        })
    };
    let formulas = sweep(&|k| bench.sample(k, 0.01, 0.1).map_or(0.0, |s| s.mu[0] + s.beta_meas));
    let table = sweep(&|k| sampler.sample(k, 0.01, 0.1).map_or(0.0, |s| s.mu[0] + s.beta_meas));
    println!(
        "test-bench samples (real slalom, 30,001): formulas {:.1} ns a sample, disturbance table {:.1} ns a sample",
        formulas / (N_SAMPLES + 1) as f64 * 1e9,
        table / (N_SAMPLES + 1) as f64 * 1e9
    );
    let one = median_seconds(3, || {
        std::hint::black_box(table3(0, &Controller::TABLE, 1).unwrap());
    });
    let all = median_seconds(3, || {
        std::hint::black_box(table3(0, &Controller::TABLE, 0).unwrap());
    });
    println!("Table III (36 cells, 12 references, figure-8 table): {one:.2} s on 1 thread, {all:.2} s on all cores");
}

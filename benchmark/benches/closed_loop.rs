//! Speed of the in-process benchmark (a bench binary, medians of repeated runs):
//! `cargo bench -p nigel-benchmark --bench closed_loop`.

use std::time::Instant;

use nigel_benchmark::{table3, Benchmark, Controller, Fidelity, Maneuver, Scenario};

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
    let one = median_seconds(3, || {
        std::hint::black_box(table3(0, &Controller::TABLE, 1).unwrap());
    });
    let all = median_seconds(3, || {
        std::hint::black_box(table3(0, &Controller::TABLE, 0).unwrap());
    });
    println!("Table III (36 cells, 12 references, figure-8 table): {one:.2} s on 1 thread, {all:.2} s on all cores");
}

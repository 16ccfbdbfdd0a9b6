//! Per-run cost of the campaign against the bare co-simulation, side by side: the 30 s
//! closed loop (`target/ssp/nigel_closed_loop.ssp`, 30,000 steps of 1 ms, `ordered`) as
//! 1. `simulate` recording nothing but the first variable (the master alone: instantiate,
//!    initialize, 30,000 steps, terminate, free);
//! 2. a campaign worker's run of the example's description (its start values set,
//!    instances reset with fmi2Reset instead of instantiated, three metrics streamed);
//! 3. the same worker made again before each run (the `.ssp` unpacked and instantiated).
//!
//! Rounds alternate the three; the table gives each one's best and median per run and the
//! spread (max / min) over the rounds. Run: `cargo bench -p nigel-campaign`.

use std::path::Path;
use std::time::Instant;

use nigel_campaign::run::Worker;
use nigel_campaign::spec::Spec;
use nigel_cosim::{simulate, Experiment};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    std::env::set_current_dir(&root).unwrap();
    let spec = Spec::load("campaigns/example.toml".as_ref()).unwrap();
    let base = nigel_campaign::spec::load_system(&spec.system).unwrap();
    let mut e = Experiment::new(spec.stop_time, spec.step);
    e.algorithm = spec.algorithm;
    e.record = Some(vec!["plant.x".into()]);
    let mut worker = Worker::new(&spec).unwrap();
    let runs_per_round = 8u64;
    let rounds = 7;
    let mut times: [Vec<f64>; 3] = Default::default();
    for round in 0..rounds {
        for (k, t) in times.iter_mut().enumerate() {
            let start = Instant::now();
            for j in 0..runs_per_round {
                let i = (round * runs_per_round + j) % spec.runs();
                match k {
                    0 => {
                        let system = spec.system_of(&base, &spec.values(i)).unwrap();
                        simulate(&system, &e).unwrap();
                    }
                    1 => assert_eq!(worker.run(i).status, 0),
                    _ => {
                        worker = Worker::new(&spec).unwrap_or_else(|e| panic!("{e}"));
                        assert_eq!(worker.run(i).status, 0);
                    }
                }
            }
            t.push(start.elapsed().as_secs_f64() * 1e3 / runs_per_round as f64);
        }
    }
    println!("| per run (ms) | best | median | spread max/min |\n|---|---|---|---|");
    for (name, t) in [
        "simulate, nothing but plant.x recorded",
        "campaign worker (reset, metrics)",
        "campaign worker, fresh load + instantiation",
    ]
    .iter()
    .zip(times.iter_mut())
    {
        t.sort_by(f64::total_cmp);
        println!("| {name} | {:.2} | {:.2} | {:.2} |", t[0], t[t.len() / 2], t[t.len() - 1] / t[0]);
    }
}

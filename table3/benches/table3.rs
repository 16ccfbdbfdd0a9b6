//! Wall time of the whole Table III (36 runs of 30 s at 1 ms, references included) on this
//! machine, per engine: `cargo bench -p nigel-table3 --bench table3`. For comparison: an
//! independent numba implementation takes about 52 ms a run (1.9 s for 36).

use nigel_table3::{run_table, Engine, FmuEngine, InProcess, Options};

fn median_wall(engine: &dyn Engine, threads: usize, repeats: usize) -> f64 {
    let mut options = Options::new(0);
    options.threads = threads;
    let mut t: Vec<f64> =
        (0..repeats).map(|_| run_table(engine, &options).expect("the table runs").table.wall_s).collect();
    t.sort_by(f64::total_cmp);
    t[repeats / 2]
}

fn main() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut engines: Vec<Box<dyn Engine>> = Vec::new();
    match FmuEngine::load_default() {
        Ok(e) => engines.push(Box::new(e)),
        Err(e) => println!("FMU engine skipped: {e}"),
    }
    engines.push(Box::new(InProcess::new()));
    for engine in &engines {
        for threads in [1, cores] {
            let wall = median_wall(engine.as_ref(), threads, 3);
            println!(
                "{}: 36 runs in {:.3} s wall on {threads} thread(s) (median of 3), {:.1} ms a run; numba: 1.9 s, 52 ms a run",
                engine.name(),
                wall,
                wall / 36.0 * 1e3
            );
        }
    }
}

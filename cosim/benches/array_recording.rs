//! `FMPY_PYTHON=target/venv/bin/python cargo bench -p nigel-cosim --bench array_recording` (the
//! FMI 3.0 headers from fmpy's package): the time of `cosim run` recording
//! the outputs of an FMI 3.0 FMU with one array output of n elements (tests/cfmu/fmi3_counter.c
//! built with `-DBIG=n`: `big` Float64, `bigi` Int32 or `bigb` Boolean; its 30 scalar outputs
//! besides), 11 rows (0 .. 10 ms in steps of
//! 1 ms), best of 3, for n = 10,000, 30,000 and 100,000; a run past 60 s is stopped and
//! shown as such. Linear recording: the time per element and row stays flat as n grows.
//! The table goes to standard output (docs/third-party-fmus.md shows it).

#[path = "../tests/common/mod.rs"]
mod common;
use common::{build_counter_with, counter_xml_with_large_arrays, work_dir};
use std::time::{Duration, Instant};

const LIMIT: Duration = Duration::from_secs(60);

/// The wall time of one `cosim run` recording `variable`, or `None` past [`LIMIT`].
fn run(cosim: &std::path::Path, fmu: &std::path::Path, csv: &std::path::Path) -> Option<Duration> {
    let start = Instant::now();
    let mut child = std::process::Command::new(cosim)
        .arg("run")
        .arg(fmu)
        .args(["--stop-time", "0.01", "--step", "0.001", "--output"])
        .arg(csv)
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("run cosim");
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            assert!(status.success(), "cosim run {} failed", fmu.display());
            return Some(start.elapsed());
        }
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn main() {
    let cosim = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/release/cosim");
    assert!(cosim.exists(), "{} (cargo build --release -p nigel-cosim)", cosim.display());
    let dir = work_dir("bench-array-recording");
    println!("| elements n | type | cosim run, 11 rows (best of 3) | per element and row |");
    println!("|---:|---|---:|---:|");
    for n in [10_000usize, 30_000, 100_000] {
        let big = format!("BIG={n}");
        for (variable, ty) in [("big", "Float64"), ("bigi", "Int32"), ("bigb", "Boolean")] {
            let xml = counter_xml_with_large_arrays(n, &[variable]);
            let Some(fmu) = build_counter_with(&dir, &format!("{variable}{n}"), &xml, &[&big]) else {
                eprintln!("no fmpy headers (FMPY_PYTHON=target/venv/bin/python): nothing measured");
                return;
            };
            let csv = dir.join("out.csv");
            let mut best: Option<Duration> = None;
            for _ in 0..3 {
                match run(&cosim, &fmu, &csv) {
                    Some(t) => best = Some(best.map_or(t, |b| b.min(t))),
                    None => {
                        best = None;
                        break;
                    }
                }
            }
            match best {
                Some(t) => println!(
                    "| {n} | {ty} | {:.3} s | {:.0} ns |",
                    t.as_secs_f64(),
                    t.as_secs_f64() * 1e9 / (n as f64 * 11.0)
                ),
                None => println!("| {n} | {ty} | stopped after {} s | - |", LIMIT.as_secs()),
            }
        }
    }
}

//! Our closed loop with the controller's FMI 3.0 sample clock (`build-fmu --features
//! controller-sample-clock`, into target/fmu-clocked: `sample_clock`, a periodic input clock
//! of 1 ms, ticking at every communication point) with its instances in host processes
//! (`--isolate`, `--isolate=run`) and stepped in threads (`--threads 2`): the clock calls
//! (`fmi3SetClock`, the intervals, `fmi3UpdateDiscreteStates`, `fmi3EnterStepMode`) cross
//! the process boundary in the order they are made in process, and the thread pool opens
//! and closes the clock events in each instance's steps as one thread does, so the results
//! are the in-process single-thread run's bit for bit (which tests/tests/fmi3_closed_loop.rs
//! holds to the FMI 2.0 closed loop's bits).

mod common;
use nigel_cosim::{read_ssp, simulate, Algorithm, Experiment, Results};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The clocked closed loop's SSP, built by the test command.
fn clocked_ssp() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("target"));
    let p = target.join("fmu-clocked").join("ssp").join("nigel_closed_loop_fmi3.ssp");
    assert!(
        p.is_file(),
        "{} missing: run `cargo run --release -p build-fmu --features controller-sample-clock -- --platforms linux64 \
         --this-glibc target/fmu-clocked/fmu`",
        p.display()
    );
    p
}

/// `b` equals `a` in every bit: the same columns and rows, no value that differs.
fn assert_same_bits(a: &Results, b: &Results, what: &str) {
    assert_eq!((a.rows(), &a.names), (b.rows(), &b.names), "{what}");
    let width = a.width();
    let first = a.values.iter().zip(&b.values).position(|(x, y)| x.to_bits() != y.to_bits());
    let name = |i: usize| if i.is_multiple_of(width) { "time".to_string() } else { a.names[i % width - 1].clone() };
    assert_eq!(first.map(|i| (name(i), i / width)), None, "{what}: (column, row) of the first value that differs");
}

/// 1 s of the loop under jacobi and ordered, every instance in a host process of its own:
/// the in-process run's values and ticks (1001: every point of the 1 s, the stop included).
#[test]
fn the_isolated_clocked_loop_is_the_in_process_one_bit_for_bit() {
    let system = read_ssp(&clocked_ssp(), &Default::default()).unwrap().system;
    for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
        let mut e = Experiment::new(1.0, 1e-3);
        e.algorithm = algorithm;
        let (local, local_summary) = simulate(&system, &e).unwrap();
        e.isolation = Some(common::isolate_all());
        let (isolated, summary) = simulate(&system, &e).unwrap();
        assert_eq!(local_summary.clock_ticks, vec![("controller.sample_clock".to_string(), 1001)], "{algorithm:?}");
        assert_eq!(summary.clock_ticks, local_summary.clock_ticks, "{algorithm:?}");
        assert_same_bits(&local, &isolated, &format!("{algorithm:?} isolated"));
    }
}

/// 2 s of the loop under jacobi in two threads: the first 200 steps calibrate in one thread,
/// then the pool runs at least 1000 (it goes on only while it is faster than one thread):
/// the single-thread run's values and ticks.
#[test]
fn the_clocked_loop_in_two_threads_is_the_single_thread_one_bit_for_bit() {
    let system = read_ssp(&clocked_ssp(), &Default::default()).unwrap().system;
    let mut e = Experiment::new(2.0, 1e-3);
    e.algorithm = Algorithm::Jacobi;
    let (serial, serial_summary) = simulate(&system, &e).unwrap();
    e.threads = 2;
    let (parallel, summary) = simulate(&system, &e).unwrap();
    assert!(summary.parallel_steps >= 1000, "{} steps in the pool", summary.parallel_steps);
    assert_eq!(serial_summary.clock_ticks, vec![("controller.sample_clock".to_string(), 2001)]);
    assert_eq!(summary.clock_ticks, serial_summary.clock_ticks);
    assert_same_bits(&serial, &parallel, "two threads");
}

/// `cosim run` of the loop in process, with `--isolate` (a host per FMU), `--isolate=run`
/// (the whole run in one host) and `--threads 2`: the same CSV, byte for byte, and the same
/// tick count in the summary.
#[test]
fn cosim_run_writes_the_same_clocked_loop_isolated_and_in_threads() {
    let dir = common::work_dir("clocked-loop-cli");
    let run = |name: &str, extra: &[&str]| -> (String, String) {
        let (csv, summary) = (dir.join(format!("{name}.csv")), dir.join(format!("{name}.json")));
        let out = Command::new(env!("CARGO_BIN_EXE_cosim"))
            .arg("run")
            .arg(clocked_ssp())
            .args(["--stop-time", "0.5", "--step", "1e-3", "--algorithm", "jacobi"])
            .args(extra)
            .arg("-o")
            .arg(&csv)
            .arg("--summary")
            .arg(&summary)
            .env("NIGEL_COSIM_HOST", env!("CARGO_BIN_EXE_cosim-host"))
            .output()
            .unwrap();
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
        (std::fs::read_to_string(&csv).unwrap(), summary["clock_ticks"].to_string())
    };
    let (plain, ticks) = run("plain", &[]);
    assert_eq!(plain.lines().count(), 502, "the header and the 501 points of 0.5 s");
    assert!(ticks.contains("501"), "{ticks}");
    for (name, extra) in [("fmu", &["--isolate"][..]), ("run", &["--isolate=run"]), ("threads", &["--threads", "2"])] {
        let (csv, t) = run(name, extra);
        assert!(csv == plain, "{name}: the CSV differs from the in-process run's");
        assert_eq!(t, ticks, "{name}");
    }
}

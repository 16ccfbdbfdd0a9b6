//! Isolation: FMUs in host processes of their own (`--isolate`, `Experiment::isolation`).
//! A C FMU (tests/cfmu/crash.c) misbehaves in `fmi2DoStep` at t = 0.5 s (steps of 0.1 s):
//! a segfault, abort, stack overflow, `exit(0)`, a step that never returns. Under
//! `--isolate` each is a typed error naming the instance, the function, the time and the
//! signal or exit code; the CSV holds the rows up to the last completed step (0 .. 0.5 s,
//! y = t); the exit code is non-zero; TMPDIR (a fresh folder per run) is empty after.

mod common;
use common::{build_crash, build_ctor_crash, builder_with, plant_fmu, work_dir};
use nigel_cosim::{
    read_ssp, simulate, simulate::simulate_recorded, Algorithm, Error, Experiment, Fmu, HostEnd, ImportOptions,
    Instance, Isolation, SystemBuilder, Value,
};
use std::path::{Path, PathBuf};
use std::process::Command;

fn cosim() -> &'static str {
    env!("CARGO_BIN_EXE_cosim")
}

fn isolation() -> Isolation {
    Isolation { instances: None, call_timeout: None, host: Some(PathBuf::from(env!("CARGO_BIN_EXE_cosim-host"))) }
}

fn fresh_tmp(dir: &Path, name: &str) -> PathBuf {
    let t = dir.join(name);
    let _ = std::fs::remove_dir_all(&t);
    std::fs::create_dir_all(&t).unwrap();
    t
}

/// Runs `cosim run crash.fmu --set mode=M --isolate ...` with its own TMPDIR; returns
/// (exit code, stderr, CSV rows) and checks that TMPDIR is empty after.
fn run_crash(test: &str, mode: u32, extra: &[&str]) -> (Option<i32>, String, Vec<(f64, f64)>) {
    let dir = work_dir(&format!("{test}-{mode}-{}", extra.len()));
    let fmu = build_crash(&dir);
    let tmp = fresh_tmp(&dir, &format!("tmp-{mode}-{}", extra.len()));
    let out = dir.join(format!("out-{mode}-{}.csv", extra.len()));
    let _ = std::fs::remove_file(&out);
    let done = Command::new(cosim())
        .args(["run", fmu.to_str().unwrap(), "--set", &format!("mode={mode}"), "--output", out.to_str().unwrap()])
        .args(extra)
        .env("TMPDIR", &tmp)
        .env("NIGEL_COSIM_HOST", env!("CARGO_BIN_EXE_cosim-host"))
        .output()
        .unwrap();
    let left: Vec<_> = std::fs::read_dir(&tmp).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(left.is_empty(), "mode {mode}: left in TMPDIR: {left:?}");
    let text = std::fs::read_to_string(&out).unwrap_or_default();
    let rows = text
        .lines()
        .skip(1)
        .map(|l| {
            let mut it = l.split(',').map(|x| x.parse::<f64>().unwrap());
            (it.next().unwrap(), it.next().unwrap())
        })
        .collect();
    (done.status.code(), String::from_utf8_lossy(&done.stderr).into_owned(), rows)
}

/// The rows of a run that stopped in the step from 0.5 s: 0, 0.1, ..., 0.5 with y = t.
fn assert_rows_to_half(rows: &[(f64, f64)], what: &str) {
    assert_eq!(rows.len(), 6, "{what}: {rows:?}");
    for (n, (t, y)) in rows.iter().enumerate() {
        assert_eq!(*t, n as f64 * 0.1, "{what}: row {n}");
        // y is the FMU's own t + h, the same sum as the master's t0 + n h to one ulp
        assert!((y - t).abs() <= 1e-15, "{what}: row {n}: y {y} at t {t}");
    }
}

#[test]
fn crashes_under_isolate_are_typed_errors_with_the_rows_so_far() {
    for (mode, cause) in [
        (1, vec!["signal 11 (SIGSEGV)"]),
        (2, vec!["signal 6 (SIGABRT)"]),
        // a C stack overflow hits the guard page: SIGSEGV (or SIGABRT from a handler)
        (3, vec!["signal 11 (SIGSEGV)", "signal 6 (SIGABRT)"]),
        (4, vec!["exited with code 0"]),
    ] {
        let (code, stderr, rows) = run_crash("isolation-crash", mode, &["--isolate"]);
        assert_eq!(code, Some(1), "mode {mode}: {stderr}");
        assert!(
            stderr.contains("model: the FMU's host process") && stderr.contains("during fmi2DoStep at t = 0.5 s"),
            "mode {mode}: {stderr}"
        );
        assert!(cause.iter().any(|c| stderr.contains(c)), "mode {mode}: {stderr}");
        assert_rows_to_half(&rows, &format!("mode {mode}"));
    }
}

#[test]
fn a_step_that_never_returns_is_killed_by_the_call_or_the_run_limit() {
    for (limit, message, what) in [
        (["--timeout-call", "0.5"], "the call took longer than 0.5 s (--timeout-call)", "call limit"),
        (["--timeout", "1"], "the run's time limit of 1 s passed (--timeout)", "run limit"),
    ] {
        let (code, stderr, rows) = run_crash("isolation-hang", 5, &["--isolate", limit[0], limit[1]]);
        assert_eq!(code, Some(1), "{stderr}");
        assert!(stderr.contains(&format!("{message} during fmi2DoStep at t = 0.5 s")), "{stderr}");
        assert_rows_to_half(&rows, what);
    }
}

#[test]
fn a_step_that_never_returns_in_process_ends_the_process_past_the_run_limit() {
    // the thread cannot be stopped: 1 s (watchdog::GRACE) past the limit the process
    // ends, naming the call, with the rows so far written and TMPDIR emptied
    let (code, stderr, rows) = run_crash("inprocess-hang", 5, &["--timeout", "1"]);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains(
            "the run's time limit of 1 s (--timeout) passed 1 s ago during fmi2DoStep of model at t = 0.5 s, which has not returned"
        ),
        "{stderr}"
    );
    assert_rows_to_half(&rows, "in process");
}

#[test]
fn a_crash_in_process_leaves_no_unpacked_fmu_behind() {
    let dir = work_dir("inprocess-crash");
    let fmu = build_crash(&dir);
    for (mode, signal) in [(1, libc_signal::SEGV), (2, libc_signal::ABRT)] {
        let tmp = fresh_tmp(&dir, &format!("tmp-{mode}"));
        let done = Command::new(cosim())
            .args(["run", fmu.to_str().unwrap(), "--set", &format!("mode={mode}")])
            .env("TMPDIR", &tmp)
            .output()
            .unwrap();
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(done.status.signal(), Some(signal), "mode {mode}");
        // the janitor process removes the folder once the crashed process is gone: it
        // runs after it, so wait for it (a few milliseconds; 10 s at most)
        let start = std::time::Instant::now();
        while std::fs::read_dir(&tmp).unwrap().next().is_some() && start.elapsed().as_secs() < 10 {
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let left: Vec<_> = std::fs::read_dir(&tmp).unwrap().map(|e| e.unwrap().path()).collect();
        assert!(left.is_empty(), "mode {mode}: left in TMPDIR: {left:?}");
    }
}

/// The signals' numbers on Linux.
mod libc_signal {
    pub const ABRT: i32 = 6;
    pub const SEGV: i32 = 11;
}

#[test]
fn timeout_call_needs_isolate_and_in_process_nothing_changes() {
    let (code, stderr, _) = run_crash("isolation-local", 0, &["--timeout-call", "1"]);
    assert_eq!(code, Some(1));
    assert!(stderr.contains("--timeout-call needs --isolate"), "{stderr}");
    // a well-behaved run, isolated or not: the same 11 rows
    let (code, _, isolated) = run_crash("isolation-local", 0, &["--isolate"]);
    assert_eq!(code, Some(0));
    let (code, _, local) = run_crash("isolation-local", 0, &[]);
    assert_eq!(code, Some(0));
    assert_eq!(isolated.len(), 11);
    assert_eq!(isolated, local);
}

#[test]
fn per_instance_isolation_in_the_library_gives_the_typed_error_and_the_rows() {
    let dir = work_dir("isolation-api");
    let mut b = builder_with(&Fmu::load(&build_crash(&dir)).unwrap(), &["bad", "good"]);
    b.set("bad.mode", Value::Real(1.0)).unwrap();
    let system = b.build();
    let mut e = Experiment::new(1.0, 0.1);
    e.isolation = Some(Isolation { instances: Some(vec!["bad".into()]), ..isolation() });
    let (results, outcome) = simulate_recorded(&system, &e);
    match outcome {
        Err(Error::Import(nigel_cosim::ImportError::Host { instance, function, time, cause })) => {
            assert_eq!((instance.as_str(), function, time), ("bad", "fmi2DoStep", 0.5));
            assert_eq!(cause, HostEnd::Signal(11));
        }
        other => panic!("expected the host's end, got {other:?}"),
    }
    assert_eq!(results.rows(), 6);
    assert_eq!(results.column("good.y").unwrap(), results.column("time").unwrap());
}

#[test]
fn the_isolated_closed_loop_is_bit_identical_to_in_process() {
    let ssp = common::built_ssp("nigel_closed_loop.ssp");
    let system = read_ssp(&ssp, &Default::default()).unwrap().system;
    // every output recorded every step; and two recorded every 6th step, so that the
    // Reals read after a step alternate between two patterns (the host's prefetch
    // relearned or not, its batches answered out of turn must not be)
    let few = Some(vec!["plant.y".to_string(), "controller.delta_fl".to_string()]);
    for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
        for (record, interval, rows) in [(None, None, 301), (few.clone(), Some(6e-3), 51)] {
            let mut e = Experiment::new(0.3, 1e-3);
            e.algorithm = algorithm;
            e.record = record;
            e.output_interval = interval;
            let (local, _) = simulate(&system, &e).unwrap();
            e.isolation = Some(isolation());
            let (isolated, _) = simulate(&system, &e).unwrap();
            assert_eq!(local.names, isolated.names);
            assert_eq!(local.rows(), rows);
            let same = local.values.iter().zip(&isolated.values).all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "{algorithm:?}, {} columns: isolated values differ from in-process", local.width());
        }
    }
}

/// A library that crashes while it is loaded (a load-time initializer writing through a
/// null pointer, tests/cfmu/ctor.c). Under `--isolate` the master never loads it (the
/// model description comes from the XML, the functions from the ELF symbol table): the
/// host that loads it dies, and the run ends with the typed error naming the instance,
/// `fmi2Instantiate (loading the library)` and SIGSEGV, exit code 1, TMPDIR empty. `cosim
/// info` reads it without loading it. In process the master itself dies of the signal
/// in `dlopen`, before any message: what `--isolate` is for.
#[test]
fn a_library_that_crashes_while_loading_kills_only_its_host() {
    use std::os::unix::process::ExitStatusExt;
    let dir = work_dir("isolation-ctor");
    let fmu = build_ctor_crash(&dir);
    let run = |tmp: &Path, args: &[&str]| {
        Command::new(cosim())
            .args(args)
            .arg(fmu.to_str().unwrap())
            .env("TMPDIR", tmp)
            .env("NIGEL_COSIM_HOST", env!("CARGO_BIN_EXE_cosim-host"))
            .output()
            .unwrap()
    };
    let left = |tmp: &Path| std::fs::read_dir(tmp).unwrap().count();

    let tmp = fresh_tmp(&dir, "tmp-isolate");
    let out = dir.join("ctor.csv");
    let done = run(&tmp, &["run", "--isolate", "--output", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&done.stderr);
    assert_eq!(done.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("model: the FMU's host process was killed by signal 11 (SIGSEGV) during fmi2Instantiate (loading the library) at t = 0 s"),
        "{stderr}"
    );
    assert_eq!(left(&tmp), 0);

    let tmp = fresh_tmp(&dir, "tmp-info");
    let done = run(&tmp, &["info"]);
    let stdout = String::from_utf8_lossy(&done.stdout);
    assert!(done.status.success(), "{}", String::from_utf8_lossy(&done.stderr));
    assert!(stdout.contains("model ctor (FMI 2.0)") && stdout.contains("t_crash"), "{stdout}");
    assert_eq!(left(&tmp), 0);

    let tmp = fresh_tmp(&dir, "tmp-in-process");
    let done = run(&tmp, &["run"]);
    assert_eq!(done.status.signal(), Some(libc::SIGSEGV), "in process: {:?}", done.status);
    assert!(done.stderr.is_empty() && done.stdout.is_empty());
    // the master died, and its janitor (fmi-import's janitor.rs, a process of its own that
    // outlives it) removes the unpacked copy of the FMU once the master's end closes its pipe:
    // asynchronously, so the test waits for it (5 s is far past a `rm -rf` of one folder)
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(5);
    while left(&tmp) != 0 && std::time::Instant::now() < deadline {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert_eq!(left(&tmp), 0, "the janitor left the unpacked FMU after the crash");

    // the library: imported isolated, it cannot be instantiated in process; in a host it
    // gives the typed error
    let imported = Fmu::load_with(&fmu, &ImportOptions { isolated: true, ..Default::default() }).unwrap();
    assert!(imported.is_isolated());
    match Instance::new(&imported, "ctor") {
        Err(nigel_cosim::ImportError::Instance { name, reason }) => {
            assert_eq!(name, "ctor");
            assert!(reason.contains("imported isolated"), "{reason}");
        }
        other => panic!("in process: {other:?}"),
    }
    match Instance::new_isolated(&imported, "ctor", &isolation(), None) {
        Err(nigel_cosim::ImportError::Host { instance, function, time, cause }) => {
            assert_eq!((instance.as_str(), function, time), ("ctor", "fmi2Instantiate (loading the library)", 0.0));
            assert_eq!(cause, HostEnd::Signal(11));
        }
        other => panic!("isolated: {other:?}"),
    }
}

/// Imported isolated, the functions the master believes an FMU has come from the ELF
/// symbol table of its library: those of our plant are those the library loaded in
/// process has, and the isolated import runs the closed-loop's plant as the in-process
/// one does.
#[test]
fn an_isolated_import_knows_the_library_from_its_symbol_table() {
    let loaded = Fmu::load(&plant_fmu()).unwrap();
    let isolated = Fmu::load_with(&plant_fmu(), &ImportOptions { isolated: true, ..Default::default() }).unwrap();
    assert!(!loaded.is_isolated() && isolated.is_isolated());
    assert_eq!(loaded.can_get_and_set_state(), isolated.can_get_and_set_state());
    assert_eq!(loaded.can_handle_variable_step(), isolated.can_handle_variable_step());
    let run = |fmu: std::sync::Arc<Fmu>, isolate: bool| {
        let mut b = SystemBuilder::new();
        b.add_instance("plant", fmu).unwrap();
        let mut e = Experiment::new(0.05, 1e-3);
        if isolate {
            e.isolation = Some(isolation());
        }
        simulate(&b.build(), &e).unwrap().0
    };
    let (a, b) = (run(loaded, false), run(isolated, true));
    assert_eq!(a.names, b.names);
    assert_eq!(a.rows(), 51);
    assert!(a.values.iter().zip(&b.values).all(|(x, y)| x.to_bits() == y.to_bits()));
}

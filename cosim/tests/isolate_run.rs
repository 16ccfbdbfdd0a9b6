//! `cosim run --isolate=run`: the whole run in one host process, the FMUs called in it
//! directly. tests/cfmu/crash.c misbehaves in `fmi2DoStep` at t = 0.5 s (steps of 0.1 s):
//! segfault, abort, `exit(0)`, a step that never returns (killed by `--timeout`). Each is
//! exit code 1 with the instance, the call, the time and the signal or exit code, the CSV
//! holding the rows up to the last completed step (0 .. 0.5 s, y = t), TMPDIR empty after.
//! A good run's CSV and summary equal the in-process run's, byte for byte.

mod common;
use common::{build_crash, time_and_y, work_dir};
use std::path::Path;
use std::process::Command;

fn cosim() -> &'static str {
    env!("CARGO_BIN_EXE_cosim")
}

/// `cosim run MODEL ARGS` with TMPDIR `tmp`: exit code, stderr, the CSV text.
fn run(model: &Path, args: &[&str], out: &Path, tmp: &Path) -> (Option<i32>, String, String) {
    let _ = std::fs::remove_file(out);
    std::fs::create_dir_all(tmp).unwrap();
    let o = Command::new(cosim())
        .arg("run")
        .arg(model)
        .args(args)
        .arg("--output")
        .arg(out)
        .env("TMPDIR", tmp)
        .output()
        .unwrap();
    let left: Vec<_> = std::fs::read_dir(tmp).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(left.is_empty(), "{args:?}: left in TMPDIR: {left:?}");
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned(), std::fs::read_to_string(out).unwrap_or_default())
}

#[test]
fn a_crash_exit_or_hang_ends_only_the_host_and_names_the_call() {
    let dir = work_dir("isolate-run");
    let fmu = build_crash(&dir);
    let out = dir.join("out.csv");
    let tmp = dir.join("tmp");
    for (mode, extra, cause) in [
        (1, None, "was killed by signal 11 (SIGSEGV)"),
        (2, None, "was killed by signal 6 (SIGABRT)"),
        // exit(0) inside a call: the host's atexit handler (exit_guard) ends it with status 1
        (4, None, "exited with code 1"),
        (5, Some("--timeout=1"), "was killed: the run's time limit of 1 s passed (--timeout)"),
    ] {
        let set = format!("mode={mode}");
        let mut args = vec!["--set", &set, "--isolate=run"];
        args.extend(extra);
        let (code, stderr, csv) = run(&fmu, &args, &out, &tmp);
        assert_eq!(code, Some(1), "mode {mode}: {stderr}");
        let want = format!("cosim: model: the FMU's host process {cause} during fmi2DoStep at t = 0.5 s");
        assert!(stderr.lines().any(|l| l == want), "mode {mode}: {stderr}");
        assert!(stderr.contains("6 rows up to the last completed step written"), "mode {mode}: {stderr}");
        // the rows 0, 0.1, .. 0.5 with y = t (t = n h as the master computes it, and y the
        // time the FMU's last step reached: the same f64 operations)
        let rows = time_and_y(&csv);
        assert_eq!(rows.len(), 6, "mode {mode}: {csv}");
        for (n, (t, y)) in rows.iter().enumerate() {
            assert_eq!(*t, n as f64 * 0.1, "mode {mode}");
            let reached = if n == 0 { 0.0 } else { (n - 1) as f64 * 0.1 + 0.1 };
            assert_eq!(*y, reached, "mode {mode} row {n}");
        }
    }
}

#[test]
fn a_good_run_in_its_host_writes_what_the_run_in_process_writes() {
    let dir = work_dir("isolate-run-good");
    let fmu = build_crash(&dir);
    let tmp = dir.join("tmp");
    let (a, b) = (dir.join("a.csv"), dir.join("b.csv"));
    let (sa, sb) = (dir.join("a.json"), dir.join("b.json"));
    let (code, stderr, in_process) = run(&fmu, &["--summary", sa.to_str().unwrap()], &a, &tmp);
    assert_eq!(code, Some(0), "{stderr}");
    let (code, stderr, hosted) = run(&fmu, &["--isolate=run", "--summary", sb.to_str().unwrap()], &b, &tmp);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(hosted, in_process);
    assert_eq!(in_process.lines().count(), 12, "the header and t = 0 .. 1 s");
    let json = |p: &Path| -> serde_json::Value { serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap() };
    let (ja, jb) = (json(&sa), json(&sb));
    assert_eq!(ja["steps"], 10);
    assert_eq!(jb["steps"], ja["steps"]);
    assert_eq!(jb["warnings"], ja["warnings"]);
    // the closed loop (three Rust FMUs, ordered), 1 s at 1 ms, every output: bit for bit
    let ssp = common::built_ssp("nigel_closed_loop.ssp");
    let args = ["--stop-time", "1", "--step", "1e-3", "--algorithm", "ordered"];
    let (code, stderr, in_process) = run(&ssp, &args, &a, &tmp);
    assert_eq!(code, Some(0), "{stderr}");
    let (code, stderr, hosted) = run(&ssp, &[&args[..], &["--isolate=run"]].concat(), &b, &tmp);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(in_process.lines().count(), 1002);
    assert!(hosted == in_process, "the closed loop's CSV differs under --isolate=run");
    // --timeout-call belongs to the host per FMU
    let (code, stderr, _) = run(&fmu, &["--isolate=run", "--timeout-call", "1"], &b, &tmp);
    assert_eq!(code, Some(1));
    assert!(stderr.contains("--timeout-call needs --isolate (=fmu"), "{stderr}");
}

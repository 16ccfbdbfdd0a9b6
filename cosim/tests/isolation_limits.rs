//! Data an FMU hands over, isolated or not: an instantiation token of 1 MB and 100,000
//! event indicators cross the region shared with a host process (it is sized from the
//! FMU); a log message of 10 MB is cut to the same bound in process and in a host (FMI
//! 3.0 messages, whose length is known, by `fmi_import::log`'s unit test); a
//! crash of the host after the run (a double free in `fmi2FreeInstance`) fails the run
//! with its rows kept. The C FMUs: tests/cfmu/crash.c, tests/cfmu/ball.c.

mod common;
use common::{build_ball_with_indicators, build_crash, build_crash_with_guid, work_dir};
use std::path::Path;
use std::process::Command;

/// `cosim run FMU ARGS --output CSV` with the host of this build: (exit code, stderr, CSV).
fn run(fmu: &Path, args: &[&str], csv: &Path) -> (Option<i32>, String, String) {
    let _ = std::fs::remove_file(csv);
    let out = Command::new(env!("CARGO_BIN_EXE_cosim"))
        .arg("run")
        .arg(fmu)
        .args(args)
        .arg("--output")
        .arg(csv)
        .env("NIGEL_COSIM_HOST", env!("CARGO_BIN_EXE_cosim-host"))
        .output()
        .unwrap();
    let text = std::fs::read_to_string(csv).unwrap_or_default();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned(), text)
}

#[test]
fn a_one_megabyte_guid_and_100000_event_indicators_cross_to_the_host() {
    let dir = work_dir("isolation-large");
    let csv = dir.join("out.csv");
    let fmu = build_crash_with_guid(&dir, 1 << 20);
    let (code, stderr, isolated) = run(&fmu, &["--isolate"], &csv);
    assert_eq!(code, Some(0), "{stderr}");
    let (code, _, local) = run(&fmu, &[], &csv);
    assert_eq!(code, Some(0));
    // 0 .. 1 s in steps of 0.1 s (crash.xml's DefaultExperiment): 11 rows, as in process
    assert_eq!(isolated.lines().count(), 12);
    assert_eq!(isolated, local);

    let fmu = build_ball_with_indicators(&dir, 100_000);
    let args = ["--stop-time", "1", "--step", "0.01"];
    let (code, stderr, isolated) = run(&fmu, &[&args[..], &["--isolate"]].concat(), &csv);
    assert_eq!(code, Some(0), "{stderr}");
    let (code, stderr, local) = run(&fmu, &args, &csv);
    assert_eq!(code, Some(0), "{stderr}");
    // the ball bounces at t = sqrt(2 / 9.81) = 0.4515 s, found through all 100,000
    // indicators; the same rows to the last bit as in process (the same calls, the same
    // values: the region only carries them)
    assert_eq!(isolated.lines().count(), 102);
    assert_eq!(isolated, local);
}

#[test]
fn a_ten_megabyte_log_message_is_cut_to_the_same_bound_isolated_or_not() {
    let dir = work_dir("isolation-log");
    let fmu = build_crash(&dir);
    let csv = dir.join("out.csv");
    let mut rows = Vec::new();
    for isolate in [false, true] {
        let args: &[&str] = if isolate { &["--set", "mode=6", "--isolate"] } else { &["--set", "mode=6"] };
        let (code, stderr, text) = run(&fmu, args, &csv);
        assert_eq!(code, Some(0), "isolate {isolate}: {}", &stderr[..stderr.len().min(2000)]);
        // the message: 4095 of its 10,000,000 bytes and a note (fmi-sys's FMI 2.0 logger
        // reads an FMU's string safely, up to 4095 bytes, so it cannot give the length)
        assert!(
            stderr
                .contains(&format!("{} [... cut by cosim at 4095 bytes: the message may be longer]", "x".repeat(4095))),
            "isolate {isolate}: {}",
            &stderr[..stderr.len().min(2000)]
        );
        assert!(stderr.len() < 10_000, "isolate {isolate}: {} bytes of stderr", stderr.len());
        rows.push(text);
    }
    assert_eq!(rows[0].lines().count(), 12);
    assert_eq!(rows[0], rows[1]);
}

#[test]
fn a_host_that_crashes_in_free_instance_fails_the_run_and_keeps_the_rows() {
    let dir = work_dir("isolation-free");
    let fmu = build_crash(&dir);
    let csv = dir.join("out.csv");
    let (code, stderr, text) = run(&fmu, &["--set", "mode=7", "--isolate"], &csv);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("fmi2FreeInstance"), "{stderr}");
    assert!(stderr.contains("signal 6 (SIGABRT)"), "{stderr}");
    // every row of the run, 0 .. 1 s (the crash came after the last step)
    assert_eq!(text.lines().count(), 12, "{text}");
}

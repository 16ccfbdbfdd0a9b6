//! SIGINT and SIGTERM (and SIGHUP) during a run: the unpacked FMUs are removed from
//! TMPDIR and `cosim` exits with 128 + the signal's number, as a shell reports it; with
//! `--isolate` the host processes end with it.

mod common;
use common::{plant_fmu, work_dir};
use std::process::Command;
use std::time::{Duration, Instant};

fn interrupt(signal: i32, extra: &[&str]) {
    let dir = work_dir(&format!("signals-{signal}-{}", extra.len()));
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    // a run of hours (1e5 s at 1 ms): it is interrupted long before its end
    let child = Command::new(env!("CARGO_BIN_EXE_cosim"))
        .args(["run", plant_fmu().to_str().unwrap(), "--stop-time", "100000", "--step", "1e-3", "--record", "x"])
        .args(extra)
        .env("TMPDIR", &tmp)
        .env("NIGEL_COSIM_HOST", env!("CARGO_BIN_EXE_cosim-host"))
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // wait until the FMU is unpacked, then a little into the run
    let start = Instant::now();
    while std::fs::read_dir(&tmp).unwrap().next().is_none() {
        assert!(start.elapsed() < Duration::from_secs(60), "the FMU was never unpacked");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(300));
    // SAFETY: our own child's pid.
    unsafe { libc::kill(child.id() as libc::pid_t, signal) };
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(128 + signal), "{stderr}");
    assert!(stderr.contains("temporary folders removed"), "{stderr}");
    let left: Vec<_> = std::fs::read_dir(&tmp).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(left.is_empty(), "left in TMPDIR: {left:?}");
}

#[test]
fn sigterm_and_sigint_remove_the_unpacked_fmus() {
    interrupt(libc::SIGTERM, &[]);
    interrupt(libc::SIGINT, &[]);
    interrupt(libc::SIGTERM, &["--isolate"]);
}

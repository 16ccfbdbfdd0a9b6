//! SIGINT and SIGTERM (and SIGHUP) during a run: the unpacked FMUs are removed from
//! TMPDIR and `cosim` exits with 128 + the signal's number, as a shell reports it; with
//! `--isolate` the host processes end with it.

mod common;
use common::{plant_fmu, work_dir};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// Starts `run` (a long `cosim run`) with TMPDIR `tmp`, waits until the FMU is unpacked
/// there, then a little into the run, sends it `signal` and gives its output.
fn signal_during_the_run(run: &mut Command, tmp: &Path, signal: i32) -> std::process::Output {
    let child = run.env("TMPDIR", tmp).stderr(std::process::Stdio::piped()).spawn().unwrap();
    let start = Instant::now();
    while std::fs::read_dir(tmp).unwrap().next().is_none() {
        assert!(start.elapsed() < Duration::from_secs(60), "the FMU was never unpacked");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(300));
    // SAFETY: our own child's pid.
    unsafe { libc::kill(child.id() as libc::pid_t, signal) };
    child.wait_with_output().unwrap()
}

fn interrupt(signal: i32, extra: &[&str]) {
    let dir = work_dir(&format!("signals-{signal}-{}", extra.len()));
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    // a run of hours (1e5 s at 1 ms): it is interrupted long before its end
    let out = signal_during_the_run(
        Command::new(env!("CARGO_BIN_EXE_cosim"))
            .args(["run", plant_fmu().to_str().unwrap(), "--stop-time", "100000", "--step", "1e-3", "--record", "x"])
            .args(extra)
            .env("NIGEL_COSIM_HOST", env!("CARGO_BIN_EXE_cosim-host")),
        &tmp,
        signal,
    );
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

/// Ctrl-C during `cosim run --output`: the run stops at its next step and the rows it
/// computed are written (as after a failed run), then the exit is the signal's.
#[test]
fn sigint_writes_the_rows_computed_so_far() {
    let dir = work_dir("signals-partial-csv");
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    let csv = dir.join("out.csv");
    let _ = std::fs::remove_file(&csv);
    let out = signal_during_the_run(
        Command::new(env!("CARGO_BIN_EXE_cosim"))
            .args(["run", plant_fmu().to_str().unwrap(), "--stop-time", "100000", "--step", "1e-3", "--record", "x"])
            .args(["--set", "v_x_start=0.35", "--output", csv.to_str().unwrap()]),
        &tmp,
        libc::SIGINT,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(128 + libc::SIGINT), "{stderr}");
    assert!(stderr.contains("written to"), "{stderr}");
    let text = std::fs::read_to_string(&csv).expect("the rows so far");
    let rows: Vec<(f64, f64)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let (t, x) = l.split_once(',').unwrap();
            (t.parse().unwrap(), x.parse().unwrap())
        })
        .collect();
    // some steps were computed, far from the stop time, on the 1 ms grid, every row whole
    assert!(rows.len() > 10, "{} rows", rows.len());
    let (t_last, x_last) = *rows.last().unwrap();
    assert!(t_last < 1000.0, "{t_last}");
    assert!((t_last * 1e3 - (rows.len() - 1) as f64).abs() < 1e-6 * rows.len() as f64);
    // coasting straight at 0.35 m/s from the origin, no steering, drive or wind: no force acts,
    // so x = 0.35 t; 1e-9 relative covers the rounding of some 1e5 RK4 sums (measured 1e-13)
    assert!((x_last - 0.35 * t_last).abs() <= 1e-9 * x_last, "x {x_last} at {t_last}");
    let left: Vec<_> = std::fs::read_dir(&tmp).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(left.is_empty(), "left in TMPDIR: {left:?}");
}

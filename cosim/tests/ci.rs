//! `cosim run --check / --baseline / --junit / --summary-md` and `cosim compare` on our own
//! closed loop (the 30 s lane change of target/ssp/nigel_closed_loop.ssp, ordered, 1 ms
//! steps), against the committed baseline tests/data/closed_loop_30s.csv: the same run
//! recording plant.x, plant.y, plant.psi, plant.speed and plant.yaw_rate every 0.05 s
//! (601 rows, 66 kB).
//!
//! The tolerances, rtol 1e-9 and atol 1e-12: a change of the initial speed by one ulp
//! (0.35 -> 0.35000000000000003) moves these signals by at most 1.7e-21 .. 5.6e-17 (measured
//! with `cosim compare --rtol 0 --atol 0`: the loop is stable, rounding does not grow), so
//! the rounding differences between builds and platforms stay six orders of magnitude inside
//! the tube; a car 3.7e-8 heavier (plant.m 2.68 -> 2.6800001) moves plant.yaw_rate by up to
//! 2.7e-9 beyond it, and fails (the second test).

mod common;
use common::read_csv;
use std::path::{Path, PathBuf};
use std::process::Command;

fn cosim() -> &'static str {
    env!("CARGO_BIN_EXE_cosim")
}

fn closed_loop() -> PathBuf {
    common::built_ssp("nigel_closed_loop.ssp")
}

fn baseline() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/closed_loop_30s.csv")
}

fn work(name: &str) -> PathBuf {
    let d = common::target_dir().join("test-ci").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `cosim ARGS`: exit code, stdout, stderr.
fn cosim_with(args: &[&str]) -> (Option<i32>, String, String) {
    let o = Command::new(cosim()).args(args).output().unwrap();
    (o.status.code(), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

const LOOP: [&str; 7] = ["--stop-time", "30", "--step", "1e-3", "--algorithm", "ordered", "--output-interval"];

/// `cosim run` of the closed loop (LOOP, output every 0.05 s into `out`) with `first` and
/// `checks`, compared with the committed baseline (rtol 1e-9, atol 1e-12), then `reports`.
fn run_closed_loop_against_the_baseline(
    out: &Path,
    first: &[&str],
    checks: &[&str],
    reports: &[&str],
) -> (Option<i32>, String, String) {
    let (ssp, base) = (closed_loop(), baseline());
    cosim_with(
        &[
            &["run", ssp.to_str().unwrap()][..],
            &LOOP,
            &["0.05", "--output", out.to_str().unwrap()],
            first,
            checks,
            &["--baseline", base.to_str().unwrap(), "--baseline-rtol", "1e-9", "--baseline-atol", "1e-12"],
            reports,
        ]
        .concat(),
    )
}

/// Asserts that the text file `path` (a report) contains each of `parts`.
fn assert_file_says(path: &Path, parts: &[&str]) {
    let text = std::fs::read_to_string(path).unwrap();
    for part in parts {
        assert!(text.contains(part), "{part} not in {text}");
    }
}

fn column(csv: &(Vec<String>, Vec<Vec<f64>>), name: &str) -> Vec<f64> {
    let j = csv.0.iter().position(|n| n == name).unwrap_or_else(|| panic!("{name} not in {:?}", csv.0));
    csv.1.iter().map(|r| r[j]).collect()
}

fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "{}", path.display());
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

/// The output lines of docs/ci.md's block marked `<!-- tested: NAME -->` (the lines after
/// the command: a `$` line and its continuations, indented).
fn doc_block(name: &str) -> String {
    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/ci.md")).unwrap();
    let start = doc.find(&format!("<!-- tested: {name} -->")).unwrap_or_else(|| panic!("no block {name}"));
    let body = doc[start..].split("```text\n").nth(1).unwrap().split("```").next().unwrap();
    let mut out = String::new();
    let mut command = true;
    for line in body.lines() {
        if command && (line.starts_with("$ ") || line.starts_with("    ")) {
            continue;
        }
        command = false;
        out.push_str(line);
        out.push('\n');
    }
    out
}

#[test]
fn the_docs_worked_example_of_the_tube_prints_what_it_says() {
    // docs/ci.md: a step from 0 to 1 at 2 s on points every 0.25 s, and the same 0.5 s late
    let dir = work("step");
    let step = |at: f64| -> String {
        let mut s = String::from("\"time\",\"y\"\n");
        for k in 0..=16 {
            let t = k as f64 * 0.25;
            s += &format!("{t},{}\n", if t >= at { 1 } else { 0 });
        }
        s
    };
    std::fs::write(dir.join("step.csv"), step(2.0)).unwrap();
    std::fs::write(dir.join("step_late.csv"), step(2.5)).unwrap();
    std::fs::write(dir.join("step_early.csv"), step(2.25)).unwrap();
    let compare = |result: &str, time_tol: &str| {
        let o = Command::new(cosim())
            .args(["compare", result, "step.csv", "--rtol", "0", "--atol", "1e-3", "--time-tol", time_tol])
            .current_dir(&dir)
            .output()
            .unwrap();
        (o.status.code(), String::from_utf8_lossy(&o.stdout).into_owned())
    };
    let (code, stdout) = compare("step_late.csv", "0.25");
    assert_eq!(code, Some(3));
    assert_eq!(stdout, doc_block("step"));
    // --time-tol 0.3: the tube at 2.25 s is [0.799, 1.001] (within rounding of 2.25 - 0.3)
    let (code, stdout) = compare("step_late.csv", "0.3");
    assert_eq!(code, Some(3));
    assert!(stdout.contains("y  FAIL  1 of 17 points outside the tube; largest violation 0.79"), "{stdout}");
    // 0.25 s late passes with --time-tol 0.3
    assert_eq!(compare("step_early.csv", "0.3"), (Some(0), "compare step_early.csv with the baseline step.csv\ntolerances: rtol 0, atol 0.001, time-tol 0.3 s\ny  pass  17 points inside the tube\n1 signal compared: 1 passed, 0 failed\n".to_string()));
}

#[test]
fn the_closed_loop_holds_its_checks_and_stays_in_the_committed_baseline() {
    let dir = work("pass");
    let (base, out, junit, md) = (baseline(), dir.join("out.csv"), dir.join("junit.xml"), dir.join("summary.md"));
    let (code, stdout, stderr) = run_closed_loop_against_the_baseline(
        &out,
        &["--check", "max(abs(plant.y)) < 0.6", "--check", "final(plant.x) > 1"],
        &["--check", "rms_diff(plant.y, maneuver.y_ref) <= 0.05"],
        &["--junit", junit.to_str().unwrap(), "--summary-md", md.to_str().unwrap()],
    );
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    // the checks' values, derived from the written results (every output, every row t_0 .. t_N)
    let csv = read_csv(&out);
    let (y, x, y_ref) = (column(&csv, "plant.y"), column(&csv, "plant.x"), column(&csv, "maneuver.y_ref"));
    assert_eq!(y.len(), 601);
    let max_abs_y = y.iter().fold(f64::NEG_INFINITY, |m, v| m.max(v.abs()));
    let rms = (y.iter().zip(&y_ref).map(|(a, b)| (a - b) * (a - b)).sum::<f64>() / y.len() as f64).sqrt();
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines[0], format!("check max(abs(plant.y)) < 0.6: {max_abs_y} < 0.6 holds"));
    assert_eq!(lines[1], format!("check final(plant.x) > 1: {} > 1 holds", x[600]));
    assert_eq!(lines[2], format!("check rms_diff(plant.y, maneuver.y_ref) <= 0.05: {rms} <= 0.05 holds"));
    // a lane change of 0.12 m over 30 s at 0.35 m/s
    assert!((0.1..0.6).contains(&max_abs_y) && (10.0..11.0).contains(&x[600]) && rms < 0.05);
    assert_eq!(lines[3], "baseline: tolerances: rtol 1e-9, atol 1e-12, time-tol 0 s");
    for (line, name) in lines[4..9].iter().zip(["plant.x", "plant.y", "plant.psi", "plant.speed", "plant.yaw_rate"]) {
        assert_eq!(*line, format!("baseline: {name:<14}  pass  601 points inside the tube"));
    }
    assert!(lines[9].starts_with("baseline: note: not in the baseline, not compared: plant.v_x, plant.v_y,"));
    assert_eq!(lines[10], "baseline: 5 signals compared: 5 passed, 0 failed");
    // the run's values at the baseline's points are the baseline's, bit for bit (same build)
    let b = read_csv(&base);
    for name in &b.0[1..] {
        assert_eq!(column(&csv, name), column(&b, name), "{name}");
    }
    // docs/ci.md shows this run's lines
    assert_eq!(doc_block("run"), stdout);
    assert_file_says(&junit, &["tests=\"9\" failures=\"0\" errors=\"0\""]);
    let md = std::fs::read_to_string(&md).unwrap();
    assert!(md.contains("passed (9 tests, 0 failed, 0 errors)"), "{md}");
    assert!(md.contains(
        "| cosim.baseline plant.yaw_rate | pass | 601 points inside the tube (rtol 1e-9, atol 1e-12, time-tol 0 s) |"
    ));
}

#[test]
fn a_heavier_car_leaves_the_tube_exits_3_and_keeps_its_results() {
    let dir = work("fail");
    let (out, junit, plots) = (dir.join("out.csv"), dir.join("junit.xml"), dir.join("plots"));
    let (code, stdout, stderr) = run_closed_loop_against_the_baseline(
        &out,
        &["--set", "plant.m=2.6800001"],
        &["--check", "final(plant.x) > 11"],
        &["--plot", plots.to_str().unwrap(), "--junit", junit.to_str().unwrap()],
    );
    assert_eq!(code, Some(3), "{stdout}\n{stderr}");
    let csv = read_csv(&out);
    assert_eq!(csv.1.len(), 601, "the results are written all the same");
    let x = column(&csv, "plant.x");
    assert!(stdout.contains(&format!("check final(plant.x) > 11: {} > 11 FAILS", x[600])), "{stdout}");
    assert!(stdout.contains("baseline: plant.x         pass  601 points inside the tube"), "{stdout}");
    // the largest violation of plant.yaw_rate, derived from the two files: at each point the
    // tube is b +- (1e-12 + 1e-9 |b|) (same grid, no time tolerance)
    let (r, b) = (column(&csv, "plant.yaw_rate"), column(&read_csv(&baseline()), "plant.yaw_rate"));
    let excess: Vec<f64> = r.iter().zip(&b).map(|(r, b)| (r - b).abs() - (1e-12 + 1e-9 * b.abs())).collect();
    let outside = excess.iter().filter(|e| **e > 0.0).count();
    let k = (0..601).max_by(|i, j| excess[*i].total_cmp(&excess[*j])).unwrap();
    let line = stdout.lines().find(|l| l.starts_with("baseline: plant.yaw_rate")).unwrap();
    let want = format!("baseline: plant.yaw_rate  FAIL  {outside} of 601 points outside the tube; largest violation ");
    assert!(line.starts_with(&want), "{line}\n{want}");
    let t = column(&csv, "time")[k];
    assert!(line.contains(&format!(" at t = {t} s (value {}, tube ", r[k])), "{line}");
    // the excess printed is the distance to the nearer edge, within rounding of b +- w
    let printed: f64 = line.split("largest violation ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!((printed - excess[k]).abs() < 1e-15, "{printed} {}", excess[k]);
    assert!(stdout.contains("baseline: 5 signals compared: 1 passed, 4 failed"), "{stdout}");
    for name in ["plant.y", "plant.psi", "plant.speed", "plant.yaw_rate"] {
        let png = plots.join(format!("{name}.png"));
        assert_eq!(png_size(&png), (1000, 800), "{}", png.display());
        assert!(stderr.contains(&format!("cosim: figure {}", png.display())), "{stderr}");
    }
    assert!(!plots.join("plant.x.png").exists(), "a passing signal has no figure");
    assert_file_says(
        &junit,
        &["tests=\"7\" failures=\"5\" errors=\"0\"", "<testcase classname=\"cosim.baseline\" name=\"plant.x\">"],
    );
}

#[test]
fn checks_record_what_they_read_and_leave_it_out_of_the_output() {
    let dir = work("record");
    let (ssp, out, all) = (closed_loop(), dir.join("out.csv"), dir.join("all.csv"));
    let (code, stdout, stderr) = cosim_with(
        &[
            &["run", ssp.to_str().unwrap()][..],
            &LOOP,
            &["0.05", "--output", out.to_str().unwrap(), "--record", "plant.x"],
            &["--check", "max(abs(plant.y)) < 0.6", "--check", "min(plant.v_x - 0.25) > 0"],
        ]
        .concat(),
    );
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    let csv = read_csv(&out);
    assert_eq!(csv.0, ["time", "plant.x"], "only what --record asked");
    let (code, _, stderr) = cosim_with(
        &[&["run", ssp.to_str().unwrap()][..], &LOOP, &["0.05", "--output", all.to_str().unwrap()]].concat(),
    );
    assert_eq!(code, Some(0), "{stderr}");
    let every = read_csv(&all);
    assert_eq!(column(&csv, "plant.x"), column(&every, "plant.x"), "recording more changes nothing");
    let max_abs_y = column(&every, "plant.y").iter().fold(f64::NEG_INFINITY, |m, v| m.max(v.abs()));
    let min_v = column(&every, "plant.v_x").iter().map(|v| v - 0.25).fold(f64::INFINITY, f64::min);
    assert_eq!(
        stdout,
        format!("check max(abs(plant.y)) < 0.6: {max_abs_y} < 0.6 holds\ncheck min(plant.v_x - 0.25) > 0: {min_v} > 0 holds\n")
    );
}

#[test]
fn a_run_that_cannot_be_done_exits_1_and_says_why() {
    let dir = work("error");
    let (ssp, junit) = (closed_loop(), dir.join("junit.xml"));
    let ssp = ssp.to_str().unwrap();
    let (code, _, stderr) = cosim_with(&["run", ssp, "--check", "max(abs(plant.y) < 0.6"]);
    assert_eq!(code, Some(1));
    assert!(stderr.contains("cosim: --check \"max(abs(plant.y) < 0.6\": malformed expression"), "{stderr}");
    let (code, _, stderr) = cosim_with(&["run", ssp, "--check", "max(plant.yy) < 0.6"]);
    assert_eq!(code, Some(1));
    assert!(stderr.starts_with("cosim: --check \"max(plant.yy) < 0.6\": "), "{stderr}");
    assert!(stderr.contains("plant.yy"), "{stderr}");
    let (code, _, stderr) = cosim_with(&["run", ssp, "--baseline", "/nonexistent/base.csv"]);
    assert_eq!(code, Some(1));
    assert!(stderr.starts_with("cosim: /nonexistent/base.csv: "), "{stderr}");
    // a run that fails: the test bench refuses a stop time past its maneuver: the JUnit file
    // holds the run's error and the checks not judged
    let (code, _, stderr) = cosim_with(&[
        "run",
        ssp,
        "--stop-time",
        "1000",
        "--step",
        "0.01",
        "--check",
        "final(plant.x) > 1",
        "--junit",
        junit.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(1), "{stderr}");
    assert_file_says(
        &junit,
        &["tests=\"2\" failures=\"0\" errors=\"2\"", "<error message=\"not judged: the run failed\""],
    );
}

#[test]
fn cosim_compare_handles_other_grids_and_missing_signals() {
    let dir = work("compare");
    let (ssp, base, coarse) = (closed_loop(), baseline(), dir.join("coarse.csv"));
    let (code, _, stderr) = cosim_with(
        &[
            &["run", ssp.to_str().unwrap()][..],
            &LOOP,
            &["0.1", "--output", coarse.to_str().unwrap(), "--record", "plant.x", "--record", "plant.y"],
        ]
        .concat(),
    );
    assert_eq!(code, Some(0), "{stderr}");
    // the coarse run's points are points of the baseline: inside at any tolerance
    let (code, stdout, _) =
        cosim_with(&["compare", coarse.to_str().unwrap(), base.to_str().unwrap(), "--rtol", "0", "--atol", "0"]);
    assert_eq!(code, Some(3), "{stdout}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines[1], "tolerances: rtol 0, atol 0, time-tol 0 s");
    assert_eq!(lines[2], "plant.x         pass  301 points inside the tube");
    assert_eq!(lines[3], "plant.y         pass  301 points inside the tube");
    for (line, name) in lines[4..7].iter().zip(["plant.psi", "plant.speed", "plant.yaw_rate"]) {
        assert_eq!(*line, format!("{name:<14}  FAIL  missing in the result"));
    }
    assert_eq!(
        lines[7],
        "note: the time grids differ (result: 301 points from 0 to 30 s, baseline: 601 points from 0 to 30 s): \
         the baseline is interpolated linearly between its points"
    );
    assert_eq!(lines[8], "5 signals compared: 2 passed, 3 failed");
    let (code, stdout, _) =
        cosim_with(&["compare", coarse.to_str().unwrap(), base.to_str().unwrap(), "--signals", "plant.x", "plant.y"]);
    assert_eq!(code, Some(0), "{stdout}");
    assert!(stdout.ends_with("2 signals compared: 2 passed, 0 failed\n"), "{stdout}");
    let (code, _, stderr) = cosim_with(&["compare", "/nonexistent.csv", base.to_str().unwrap()]);
    assert_eq!(code, Some(1));
    assert!(stderr.starts_with("cosim: /nonexistent.csv: "), "{stderr}");
}

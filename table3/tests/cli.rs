//! The `table3` binary: clear errors for bad input, the JSON contract, CSV and PNG output.

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

fn table3(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_table3")).args(args).output().expect("the binary starts")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The stderr of `table3 args`, asserted to fail without a panic.
fn refused(args: &[&str]) -> String {
    let o = table3(args);
    let e = stderr(&o);
    assert!(!o.status.success(), "{args:?}: {e}");
    assert!(!e.contains("panicked"), "{e}");
    e
}

#[test]
fn unknown_maneuver_is_a_clear_error() {
    let e = refused(&["--engine", "in-process", "--maneuver", "drift"]);
    assert!(e.contains("unknown maneuver \"drift\"") && e.contains("figure_8"), "{e}");
}

#[test]
fn controllers_can_be_chosen_and_unknown_ones_are_a_clear_error() {
    let e = refused(&["--engine", "in-process", "--controller", "lqr"]);
    assert!(e.contains("unknown controller \"lqr\"") && e.contains("robust_tracking"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("t.json");
    let args = ["--engine", "in-process", "--maneuver", "straight", "--controller", "robust_tracking"];
    let o = table3(&[&args[..], &["--controller", "open_loop", "--json", json.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let row = v["results"]["real"]["straight"].as_object().unwrap();
    assert_eq!(row.keys().collect::<Vec<_>>(), ["open_loop", "robust_tracking"]);
}

#[test]
fn unparsable_seed_is_a_clear_error() {
    for seed in ["abc", "-1", "1.5", "99999999999999999999999"] {
        let e = refused(&["--engine", "in-process", "--seed", seed]);
        assert!(e.contains("--seed") && e.contains(seed), "{seed}: {e}");
    }
}

#[test]
fn missing_fmus_are_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    assert_fmu_dir_fails_saying(dir.path(), &["nigel_plant.fmu not found", "build-fmu"]);
}

#[test]
fn corrupt_fmus_are_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    for name in nigel_table3::engine::FMU_FILES {
        std::fs::write(dir.path().join(name), b"PK\x03\x04 this is not a zip archive").unwrap();
    }
    assert_fmu_dir_fails_saying(dir.path(), &["loading", "nigel_plant.fmu"]);
}

/// `table3 --fmu-dir dir` exits 1 with a message (no panic) that says each of `words`.
fn assert_fmu_dir_fails_saying(dir: &std::path::Path, words: &[&str]) {
    let o = table3(&["--fmu-dir", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(words.iter().all(|w| e.contains(w)), "{e}");
    assert!(!e.contains("panicked"), "{e}");
}

#[test]
fn json_has_the_contract_shape_and_the_printed_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("t.json");
    let csv = dir.path().join("csv");
    let o = table3(&[
        "--engine",
        "in-process",
        "--seed",
        "5",
        "--maneuver",
        "lane_change",
        "--json",
        json.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
        "--threads",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(|k| k.as_str()).collect();
    assert_eq!(keys, ["gains", "results", "seed", "wall_s"]);
    assert_eq!(v["seed"], 5);
    assert!(v["wall_s"].as_f64().unwrap() > 0.0);
    assert_eq!(v["gains"]["robust"][2][1].as_f64().unwrap(), nigel_benchmark::gains::ROBUST[2][1]);
    assert_eq!(v["gains"]["pole_placement"][0][0].as_f64().unwrap(), nigel_benchmark::gains::POLE_PLACEMENT[0][0]);
    for (k, columns) in [("robust", 2), ("pole_placement", 2), ("robust_tracking", 4)] {
        let rows = v["gains"][k].as_array().unwrap();
        assert_eq!(rows.len(), 4);
        assert!(rows.iter().all(|r| r.as_array().unwrap().len() == columns), "{k}");
    }
    assert_eq!(v["gains"]["robust_tracking"][0][0].as_f64().unwrap(), nigel_benchmark::gains::ROBUST_TRACKING[0][0]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    for column in ["sim", "real"] {
        let row = &v["results"][column]["lane_change"];
        assert_eq!(row.as_object().unwrap().len(), 4);
        for c in ["open_loop", "pole_placement", "robust", "robust_tracking"] {
            let cell = &row[c];
            let eps = cell["eps"].as_f64().unwrap();
            let rmse: Vec<f64> = cell["rmse"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            assert_eq!(rmse.len(), 3);
            assert!((eps - rmse.iter().map(|x| x * x).sum::<f64>().sqrt()).abs() <= 1e-15 * eps);
            assert!(cell["eps_state"].as_f64().unwrap() > 0.0);
            let max_delta = cell["max_delta"].as_f64().unwrap();
            assert!(max_delta > 0.0 && max_delta < std::f64::consts::FRAC_PI_2, "{c}: {max_delta}");
            if c == "open_loop" {
                assert_eq!(max_delta, std::f64::consts::PI / 6.0, "the program's amplitude");
            }
            // the markdown prints the same number
            assert!(stdout.contains(&format!("{eps:.3e}")), "{eps:.3e} not in\n{stdout}");
        }
        // one CSV per run in fmpy's format: a quoted header with "time" first, 30,001 rows,
        // 19 numbers in every row (the last one too)
        let text = std::fs::read_to_string(csv.join(format!("{column}_lane_change_robust.csv"))).unwrap();
        assert_eq!(text.lines().count(), 30_002);
        assert!(text.starts_with("\"time\",\"x\",\"y\",\"psi\",\"x_ref\""), "{}", &text[..80]);
        for line in text.lines().skip(1) {
            let fields: Vec<&str> = line.split(',').collect();
            assert_eq!(fields.len(), 19, "{line}");
            assert!(fields.iter().all(|f| f.parse::<f64>().is_ok_and(f64::is_finite)), "{line}");
        }
    }
    assert!(v["results"]["sim"].get("skidpad").is_none());
}

#[test]
fn seeds_study_prints_the_ratio_of_every_cell_and_seed() {
    let o = table3(&["--engine", "in-process", "--maneuver", "straight", "--seeds", "2..3", "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("eps(robust_tracking) / eps(robust) per cell, seeds 2, 3"), "{out}");
    assert!(out.contains("| sim | straight |") && out.contains("| real | straight |"), "{out}");
    assert!(out.contains("in all 2 rows of all 2 seeds"), "{out}");
    assert!(out.contains("Largest steering command") && out.contains("robust_tracking 0."), "{out}");
    // the ratio printed is the one of the two tables run separately
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("t.json");
    let args = ["--engine", "in-process", "--maneuver", "straight", "--seed", "3", "--json"];
    let o = table3(&[&args[..], &[json.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let cell = |c: &str| v["results"]["sim"]["straight"][c]["eps"].as_f64().unwrap();
    let ratio = format!(" {:.3} |", cell("robust_tracking") / cell("robust"));
    let row = out.lines().find(|l| l.starts_with("| sim | straight |")).unwrap();
    assert_eq!(row.split('|').nth(4).map(|x| format!("{x}|")), Some(ratio), "{row}");
    for bad in ["9..2", "a..b", "5", "0..5000"] {
        let o = table3(&["--engine", "in-process", "--seeds", bad]);
        assert!(!o.status.success(), "{bad}");
        assert!(stderr(&o).contains("--seeds"), "{bad}: {}", stderr(&o));
    }
}

#[test]
fn png_figures_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let o = table3(&["--engine", "in-process", "--maneuver", "straight", "--png", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    for name in ["fig7_sim.png", "fig7_real.png", "time_sim_straight.png", "time_real_straight.png"] {
        let bytes = std::fs::read(dir.path().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{name}");
        let (w, h) = png_size(&bytes);
        assert!(w >= 1500 && h >= 600, "{name}: {w} x {h}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 4);
    assert!(!Path::new(&dir.path().join("time_sim_skidpad.png")).exists());
}

fn png_size(bytes: &[u8]) -> (u32, u32) {
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    (be(16), be(20))
}

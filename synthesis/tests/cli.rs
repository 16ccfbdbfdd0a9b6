//! The `synthesize` binary: JSON fields and numbers, the plot, exit codes.

use std::path::PathBuf;
use std::process::Command;

use serde_json::Value;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_synthesize"))
}

fn tmp(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("synthesize-{}-{name}", std::process::id()))
}

fn num(v: &Value, path: &str) -> f64 {
    let mut cur = v;
    for key in path.split('.') {
        cur = match key.parse::<usize>() {
            Ok(i) => &cur[i],
            Err(_) => &cur[key],
        };
    }
    cur.as_f64().unwrap_or_else(|| panic!("{path} is not a number: {cur}"))
}

#[test]
fn paper_pareto_json_and_plot() {
    let json = tmp("paper.json");
    let svg = tmp("paper.svg");
    let out = bin()
        .args(["--arch", "4ws", "--d2", "paper", "--objective", "pareto", "--json"])
        .arg(&json)
        .arg("--plot")
        .arg(&svg)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "exit {:?}\n{stdout}\n{stderr}", out.status);
    // readable table and progress lines
    assert!(
        stdout.contains("gamma* = 0.1174") && stdout.contains("<- chosen") && stdout.contains("PASSED"),
        "{stdout}"
    );
    assert!(stderr.contains("[39/39]"), "progress: {stderr}");

    let r: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let gs = num(&r, "gamma_star");
    // the spec's 5-digit figure (rounding up to 4.3e-5); the solver's gamma* is good to 1e-7
    assert!((gs - 0.11744).abs() / 0.11744 < 1e-4, "gamma_star {gs}");
    let pareto = r["pareto"].as_array().unwrap();
    assert_eq!(pareto.len(), 39);
    for (k, p) in pareto.iter().enumerate() {
        assert_eq!(p["k"].as_u64(), Some(k as u64));
        assert!(p["g"].is_f64() && p["nu"].is_f64());
    }
    let k = r["chosen"]["k"].as_u64().unwrap() as usize;
    assert!([8, 9, 10].contains(&k));
    let (g, nu) = (num(&r, "chosen.g"), num(&r, "chosen.nu"));
    assert_eq!(g, num(&pareto[k], "g"));
    assert_eq!(nu, num(&pareto[k], "nu"));
    assert!((g - 0.2075).abs() < 0.011 && (nu - 0.5513).abs() / 0.5513 < 5e-3, "chosen ({g}, {nu})");
    // K: rows FL, FR, RL, RR x (beta, r)
    assert_eq!(r["K_rows"], serde_json::json!(["FL", "FR", "RL", "RR"]));
    let kk = r["K"].as_array().unwrap();
    assert_eq!(kk.len(), 4);
    assert!(kk.iter().all(|row| row.as_array().unwrap().len() == 2));
    assert!((num(&r, "K.0.1") - -0.3104).abs() < 2e-3 && (num(&r, "K.2.1") - 0.4093).abs() < 2e-3, "K {}", r["K"]);
    // per-vertex closed-loop poles
    let vertices = r["vertices"].as_array().unwrap();
    assert_eq!(vertices.len(), 16);
    for v in vertices {
        let poles = v["poles"].as_array().unwrap();
        assert_eq!(poles.len(), 2);
        for p in poles {
            assert!(num(p, "0") < -0.1);
        }
        assert_eq!(v["mu"].as_array().unwrap().len(), 4);
    }
    // actual worst-case norms below the certified bounds
    assert_eq!(num(&r, "actual.hinf_bound"), g);
    assert_eq!(num(&r, "actual.h2_bound"), nu);
    assert!(num(&r, "actual.hinf_worst") <= g && num(&r, "actual.h2_worst") <= nu);
    assert!(num(&r, "actual.hinf_methods_rel_diff") < 1e-6 && num(&r, "actual.h2_methods_rel_diff") < 1e-6);
    assert_eq!(r["verification"]["passed"], Value::Bool(true));
    // solver statistics and timings
    assert_eq!(r["solver"]["n_solves"].as_u64(), Some(40));
    assert!(r["solver"]["total_iterations"].as_u64().unwrap() > 40);
    assert_eq!(r["solver"]["design"]["status"], "Solved");
    assert!(num(&r, "solver.design.r_prim") < 1e-6);
    assert_eq!(r["solver"]["strict_lmis_hold"], Value::Bool(true));
    assert!(num(&r, "timings.total_s") > 0.0 && num(&r, "timings.design_s") > 0.0);
    assert_eq!(num(&r, "margin"), 1e-7);
    assert_eq!(r["plant"]["d2"], "paper");
    assert_eq!(r["region"].as_array().unwrap().len(), 2);

    let png = std::fs::read(svg.with_extension("png")).unwrap();
    let svg = std::fs::read_to_string(&svg).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("<polyline") && svg.contains("chosen k = ") && svg.contains("<polygon"));
    // the zoom shows the half-plane boundary; the axes carry units
    assert!(svg.contains("Re(s) = -0.1 1/s") && svg.contains("Re(s) [1/s]") && svg.contains("Im(s) [rad/s]"));
    // the PNG next to it: 2 pixels per SVG unit (the IHDR chunk's width and height)
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let (w, h) =
        (u32::from_be_bytes(png[16..20].try_into().unwrap()), u32::from_be_bytes(png[20..24].try_into().unwrap()));
    assert_eq!((w, h), (3120, 1080));
    let _ = std::fs::remove_file(json);
}

#[test]
fn ackermann_hinf_has_zero_rear_rows_and_extra_region() {
    let json = tmp("ack.json");
    let out = bin()
        .args(["--arch", "ackermann", "--d2", "physical", "--objective", "hinf", "--half-plane", "-5", "--quiet"])
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(r["plant"]["architecture"], "Ackermann");
    assert_eq!(r["plant"]["steered_wheels"], serde_json::json!(["FL", "FR"]));
    assert_eq!(r["K"][2], serde_json::json!([0.0, 0.0]));
    assert_eq!(r["K"][3], serde_json::json!([0.0, 0.0]));
    assert_eq!(r["region"].as_array().unwrap().len(), 3);
    assert!(num(&r, "verification.max_real_part") < -5.0);
    assert!(r["pareto"].as_array().unwrap().is_empty());
    assert_eq!(num(&r, "chosen.g"), num(&r, "gamma_star"));
    let _ = std::fs::remove_file(json);
}

#[test]
fn bad_options_give_a_clear_error_and_exit_2() {
    for (args, needle) in [
        (vec!["--arch", "3ws"], "--arch"),
        (vec!["--d2", "wrong"], "--d2"),
        (vec!["--speed", "fast"], "--speed"),
        (vec!["--speed", "NaN"], "--speed"),
        (vec!["--objective", "best"], "--objective"),
        (vec!["--frobnicate"], "unknown option"),
        (vec!["--json"], "needs a value"),
        (vec!["--plot", "x.png"], "SVG"),
    ] {
        let out = bin().args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: '{stderr}' should mention {needle}");
    }
    let out = bin().arg("--help").output().unwrap();
    assert!(out.status.success() && String::from_utf8_lossy(&out.stdout).contains("--no-default-region"));
}

#[test]
fn refused_parameters_and_infeasible_regions_exit_1_without_a_gain() {
    let json = tmp("never.json");
    let out = bin().args(["--speed", "-1", "--objective", "hinf", "--json"]).arg(&json).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("speed = -1"), "{stderr}");
    let out = bin()
        .args(["--objective", "hinf", "--half-plane", "-10", "--disk", "5", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("infeasible"), "{stderr}");
    assert!(!json.exists(), "no report (and so no K) is written on failure");
}

//! What third-party FMUs need of the master (issue 35), each shown by a small C FMU of our
//! own (tests/cfmu/): the tolerance told to Co-Simulation FMUs as fmpy tells it.

mod common;
use common::{build_tolerance, work_dir};
use nigel_cosim::{simulate, Experiment, Fmu, SystemBuilder};

fn told_tolerance(fmu: std::sync::Arc<Fmu>, given: Option<f64>) -> f64 {
    let mut b = SystemBuilder::new();
    b.add_instance("m", fmu).unwrap();
    let mut e = Experiment::new(0.1, 0.05);
    e.co_simulation_tolerance = given;
    let (r, _) = simulate(&b.build(), &e).unwrap();
    let told = r.column("told_tolerance").unwrap();
    assert_eq!(told.len(), 3);
    told[2]
}

/// A Co-Simulation FMU is told the caller's relative tolerance, else its DefaultExperiment
/// tolerance, else none (fmpy's `simulate_fmu`, which passes `relative_tolerance` or the
/// DefaultExperiment's to fmi2SetupExperiment in Co-Simulation). The FMU reports the value
/// it received (-1: toleranceDefined false), exactly.
#[test]
fn co_simulation_fmus_are_told_the_tolerance_as_fmpy_tells_them() {
    let dir = work_dir("tp-tolerance");
    let declared = Fmu::load(&build_tolerance(&dir, Some("1e-7"))).unwrap();
    assert_eq!(told_tolerance(declared.clone(), None), 1e-7);
    assert_eq!(told_tolerance(declared, Some(1e-4)), 1e-4);
    let dir = work_dir("tp-tolerance-none");
    let undeclared = Fmu::load(&build_tolerance(&dir, None)).unwrap();
    assert_eq!(told_tolerance(undeclared.clone(), None), -1.0);
    assert_eq!(told_tolerance(undeclared, Some(1e-3)), 1e-3);
    // a declared tolerance that is none (0) is not passed on
    let dir = work_dir("tp-tolerance-zero");
    let zero = Fmu::load(&build_tolerance(&dir, Some("0"))).unwrap();
    assert_eq!(told_tolerance(zero, None), -1.0);
}

/// `cosim run --rtol` is the tolerance Co-Simulation FMUs are told too.
#[test]
fn the_cli_rtol_reaches_co_simulation_fmus() {
    let dir = work_dir("tp-tolerance-cli");
    let fmu = build_tolerance(&dir, Some("1e-7"));
    let csv = dir.join("out.csv");
    let run = |extra: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_cosim"))
            .args(["run", fmu.to_str().unwrap(), "--output", csv.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = std::fs::read_to_string(&csv).unwrap();
        let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        let col = header.iter().position(|h| h.trim_matches('"') == "told_tolerance").unwrap();
        text.lines().last().unwrap().split(',').nth(col).unwrap().parse::<f64>().unwrap()
    };
    assert_eq!(run(&[]), 1e-7);
    assert_eq!(run(&["--rtol", "1e-3"]), 1e-3);
}

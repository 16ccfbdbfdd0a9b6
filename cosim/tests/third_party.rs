//! What third-party FMUs need of the master (issue 35), each shown by a small C FMU of our
//! own (tests/cfmu/): the tolerance told to Co-Simulation FMUs as fmpy tells it; the
//! continuous states of the ModelStructure's `<Derivatives>`, not of every `derivative`
//! attribute; an FMU Jacobian checked against finite differences at its first use.

mod common;
use common::{
    build_tolerance, build_vdp, build_vdp_with_a_derivative_of_no_state, build_vdp_with_a_wrong_jacobian,
    build_vdp_without_directional_derivatives, run_vdp_under_bdf, work_dir,
};
use nigel_cosim::{simulate, Experiment, Fmu, Solver, System, SystemBuilder};

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

/// Van der Pol with a description that declares a derivative of a variable that is no
/// state (as Dymola's CoupledClutches does: 18 `derivative` attributes, 8 states): the
/// states are those of `<Derivatives>` (2; the library refuses any other nx), the Jacobian
/// of the bdf method asks the state derivatives with respect to the states only (the
/// library refuses anything else), and every solver's result is the plain description's
/// bit for bit (the same library, the same calls).
#[test]
fn the_states_are_those_of_the_derivatives_list() {
    let plain = Fmu::load(&build_vdp(&work_dir("tp-vdp-plain"))).unwrap();
    let dymola_like = Fmu::load(&build_vdp_with_a_derivative_of_no_state(&work_dir("tp-vdp-dymola"))).unwrap();
    assert_eq!(dymola_like.description().states(), vec![1, 3]);
    assert_eq!(dymola_like.description().state_derivatives(), vec![2, 4]);
    for solver in [
        Solver::Rk4 { max_step: None },
        Solver::Dopri5 { rtol: 1e-6, atol: 1e-8 },
        Solver::Bdf { rtol: 1e-6, atol: 1e-8 },
    ] {
        let mut e = Experiment::new(2.0, 0.01);
        e.solver = solver;
        e.record = Some(vec!["model.x0".into(), "model.x1".into()]);
        let (want, _) = simulate(&System::single("model", plain.clone()).unwrap(), &e).unwrap();
        let (got, _) = simulate(&System::single("model", dymola_like.clone()).unwrap(), &e)
            .unwrap_or_else(|err| panic!("{solver:?}: {err}"));
        assert_eq!(want.rows(), 201);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&got.values), bits(&want.values), "{solver:?}");
    }
    // cosim info counts the states of <Derivatives>
    let dir = work_dir("tp-vdp-info");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cosim"))
        .args(["info", build_vdp_with_a_derivative_of_no_state(&dir).to_str().unwrap()])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("continuous states: 2,"), "{text}");
}

/// An FMU whose directional derivatives are wrong (vdp.c built to double each partial
/// derivative) does not steer bdf: at its first use the Jacobian is compared with forward
/// differences, found to disagree, and bdf uses differences from then on, with a note
/// naming the FMU, the entry and both values. The run is then the run of the same FMU
/// declaring no directional derivatives, bit for bit (the same differences at the same
/// points). The correct Jacobian passes the check: no note, and the FMU's Jacobian used.
#[test]
fn a_wrong_fmu_jacobian_is_found_at_first_use_and_replaced_by_differences() {
    let run = |path: std::path::PathBuf| run_vdp_under_bdf(&path);
    let (wrong, wrong_summary) = run(build_vdp_with_a_wrong_jacobian(&work_dir("tp-vdp-wrong")));
    let (differences, _) = run(build_vdp_without_directional_derivatives(&work_dir("tp-vdp-fd")));
    assert_eq!(wrong_summary.notes.len(), 1, "{:?}", wrong_summary.notes);
    let note = &wrong_summary.notes[0];
    assert!(note.starts_with("model: fmi2GetDirectionalDerivative") && note.contains("finite differences"), "{note}");
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&wrong.values), bits(&differences.values));
    let (_, right_summary) = run(build_vdp(&work_dir("tp-vdp-right")));
    assert!(right_summary.notes.is_empty(), "{:?}", right_summary.notes);
    assert!(right_summary.stiff.jacobians > 0 && right_summary.stiff.jacobian_rhs == 0, "{:?}", right_summary.stiff);
}

//! The FMU engine: the three archives built by build-fmu, through the C ABI, co-simulated
//! by nigel_cosim (`ordered`, 1 ms, 30 s). Needs `cargo run --release -p build-fmu` first
//! (scripts/test.sh does it); a missing archive fails the test with that instruction.

mod common;
#[path = "common/replica.rs"]
mod replica;

use std::path::Path;
use std::sync::OnceLock;

use nigel_table3::report::json_without_wall;
use nigel_table3::{
    run_table, Controller, Engine, Fidelity, FmuEngine, InProcess, Job, Maneuver, Metric, Options, Run, Table,
};

fn engine() -> &'static FmuEngine {
    static E: OnceLock<FmuEngine> = OnceLock::new();
    E.get_or_init(|| FmuEngine::load_default().unwrap_or_else(|e| panic!("{e}")))
}

fn table_seed0() -> &'static Table {
    static T: OnceLock<Table> = OnceLock::new();
    T.get_or_init(|| run_table(engine(), &Options::new(0)).expect("the FMU table runs").table)
}

/// Largest absolute difference of every recorded series of two runs.
fn max_difference(a: &Run, b: &Run) -> f64 {
    let mut d: f64 = 0.0;
    let pairs = [
        (&a.x, &b.x),
        (&a.y, &b.y),
        (&a.psi, &b.psi),
        (&a.beta, &b.beta),
        (&a.yaw_rate, &b.yaw_rate),
        (&a.x_ref, &b.x_ref),
        (&a.y_ref, &b.y_ref),
        (&a.psi_ref, &b.psi_ref),
        (&a.beta_ref, &b.beta_ref),
        (&a.yaw_rate_ref, &b.yaw_rate_ref),
    ];
    for (u, v) in pairs {
        assert_eq!(u.len(), v.len());
        d = u.iter().zip(v).fold(d, |d, (p, q)| d.max((p - q).abs()));
    }
    for (u, v) in [(&a.delta, &b.delta), (&a.mu, &b.mu)] {
        assert_eq!(u.len(), v.len());
        d = u.iter().zip(v).fold(d, |d, (p, q)| (0..4).fold(d, |d, i| d.max((p[i] - q[i]).abs())));
    }
    d
}

common::self_check_tests!(
    table_seed0,
    self_check_24_cells_through_the_fmus,
    robust_tracking_is_lowest_in_all_12_rows_through_the_fmus
);

#[test]
fn fmu_table_equals_the_in_process_table() {
    let fmu = table_seed0();
    let inp = run_table(&InProcess::new(), &Options::new(0)).unwrap().table;
    assert_eq!(fmu.gains, inp.gains, "the controller FMU's gains are the baked ones");
    let mut worst: f64 = 0.0;
    for (a, b) in fmu.cells.iter().zip(&inp.cells) {
        assert_eq!((a.fidelity, a.maneuver, a.controller), (b.fidelity, b.maneuver, b.controller));
        let rel = (a.metric.eps - b.metric.eps).abs() / b.metric.eps;
        worst = worst.max(rel);
        // the master's time grid (see the bit-for-bit test below) makes 1e-13-level
        // differences; 1e-11 leaves room over the 1e-12 seen
        assert!(rel <= 1e-11, "{:?} {} {}: {} vs {}", a.fidelity, a.maneuver, a.controller, a.metric.eps, b.metric.eps);
    }
    eprintln!("FMU vs in-process: worst relative epsilon difference {worst:.2e} over {} cells", fmu.cells.len());
}

#[test]
fn fmu_runs_follow_the_in_process_runs_sample_by_sample() {
    let inp = InProcess::new();
    for (f, m, c) in [
        (Fidelity::Paper, Maneuver::Figure8, Controller::Robust),
        (Fidelity::Real, Maneuver::Slalom, Controller::PolePlacement),
        (Fidelity::Real, Maneuver::LaneChange, Controller::OpenLoop),
        (Fidelity::Real, Maneuver::Skidpad, Controller::RobustTracking),
    ] {
        let job = Job::new(11, f, m, c);
        let (a, b) = (engine().run(&job).unwrap(), inp.run(&job).unwrap());
        let d = max_difference(&a, &b);
        eprintln!("{}: largest difference of any recorded series {d:.2e}", job.label());
        assert!(d <= 1e-11, "{}: {d}", job.label());
        assert_eq!(a.gain, c.feedback_gain());
    }
}

#[test]
fn fmu_runs_equal_a_loop_on_the_masters_time_grid_bit_for_bit() {
    // the master steps over t_(k+1) - t_k (t_k = k * 1 ms), not exactly 1 ms: that, and
    // nothing else, is the difference from nigel_benchmark's loop
    for (f, m, c) in [
        (Fidelity::Paper, Maneuver::Figure8, Controller::Robust),
        (Fidelity::Real, Maneuver::Slalom, Controller::PolePlacement),
        (Fidelity::Paper, Maneuver::Figure8, Controller::RobustTracking),
    ] {
        let job = Job::new(11, f, m, c);
        let (a, b) = (engine().run(&job).unwrap(), replica::run_on_master_grid(&job));
        assert_eq!(max_difference(&a, &b), 0.0, "{}", job.label());
        assert_eq!(a, b, "{}", job.label());
    }
}

#[test]
fn undisturbed_straight_stays_on_the_reference_through_the_fmus() {
    // mu = 0.4, no wind, no noise: the run is the reference run. Lateral, heading, beta and
    // r are exactly the reference's; X differs only by the master's time grid (the
    // reference is computed inside the test bench on exact 1 ms steps): 1e-12 relative to
    // the 10.5 m driven.
    for f in Fidelity::ALL {
        for c in Controller::WITH_TRACKING {
            let job = Job { disturbed: false, ..Job::new(0, f, Maneuver::Straight, c) };
            let run = engine().run(&job).unwrap();
            let m = Metric::of(&run);
            assert_eq!((m.rmse[1], m.rmse[2], m.eps_state), (0.0, 0.0, 0.0), "{}: {m:?}", job.label());
            let dx = run.x.iter().zip(&run.x_ref).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(dx <= 1e-12 * run.x_ref[30_000], "{}: |x - x_ref| up to {dx}", job.label());
            assert!(m.eps <= 1e-11, "{}: {m:?}", job.label());
            assert!((run.x[30_000] - 0.35 * 30.0).abs() < 1e-9, "{}", run.x[30_000]);
            assert!(run.mu.iter().all(|mu| *mu == [0.4; 4]));
        }
    }
}

#[test]
fn same_seed_twice_and_one_or_two_threads_give_identical_results() {
    let mut options = Options::new(0);
    options.maneuvers = vec![Maneuver::LaneChange, Maneuver::Figure8];
    options.threads = 1;
    let one = run_table(engine(), &options).unwrap().table;
    options.threads = 2;
    let two = run_table(engine(), &options).unwrap().table;
    let text = |t: &Table| serde_json::to_string(&json_without_wall(t)).unwrap();
    assert_eq!(text(&one), text(&two));
    // the same cells of the whole table, run separately, are the same bits
    for c in &two.cells {
        assert_eq!(Some(c), table_seed0().get(c.fidelity, c.maneuver, c.controller));
    }
}

#[test]
fn seeds_beyond_the_fmu_integer_are_refused() {
    let job = Job::new(1 << 31, Fidelity::Paper, Maneuver::Straight, Controller::OpenLoop);
    let e = engine().run(&job).unwrap_err().to_string();
    assert!(e.contains("seed 2147483648") && e.contains("Integer"), "{e}");
}

#[test]
fn the_exported_ssp_runs_in_our_master_exactly_like_the_system_it_came_from() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nigel_closed_loop.ssp");
    let job = Job::new(0, Fidelity::Real, Maneuver::LaneChange, Controller::Robust);
    engine().write_ssp(&job, &path).unwrap();
    let ssp = nigel_cosim::read_ssp(&path, &nigel_cosim::ImportOptions::default()).unwrap();
    assert_eq!(ssp.default_start_stop, (Some(0.0), Some(30.0)));
    assert_eq!(ssp.system.instances.len(), 3);
    // 26 of the paper's loop and the 6 pose inputs of the controller
    assert_eq!(ssp.system.connections.len(), 32);
    let jacobi = FmuEngine::load_default().unwrap().with_algorithm(nigel_cosim::Algorithm::Jacobi);
    let from_ssp = jacobi.run_system(&ssp.system, &job).unwrap();
    let direct = jacobi.run(&job).unwrap();
    assert_eq!(from_ssp, direct);
    // jacobi delays every connection by a step: 3 ms around the loop, 5 % here
    let (e_j, e_o) = (Metric::of(&direct).eps, Metric::of(&engine().run(&job).unwrap()).eps);
    assert!(e_j != e_o && (e_j - e_o).abs() < 0.06 * e_o, "jacobi {e_j}, ordered {e_o}");
}

/// The time figures docs/table3.md shows (`table3/figures/time_sim_skidpad.png`,
/// `time_real_figure_8.png`) are what `table3 --seed 0 --png DIR` draws today, byte for byte
/// (the runs are bit-identical on this platform and the drawing is deterministic: the font is
/// bundled). On a change of the figures, regenerate them with that command and copy the two.
#[test]
fn the_committed_time_figures_are_what_table3_draws() {
    let dir = tempfile::tempdir().unwrap();
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("figures");
    for (fidelity, maneuver) in [(Fidelity::Paper, Maneuver::Skidpad), (Fidelity::Real, Maneuver::Figure8)] {
        let mut o = Options::new(0);
        o.fidelities = vec![fidelity];
        o.maneuvers = vec![maneuver];
        o.keep_runs = true;
        let runs = run_table(engine(), &o).unwrap().runs;
        let name = format!("time_{}_{}.png", fidelity.column(), maneuver.name());
        nigel_table3::plot::time_figure(&runs, fidelity, maneuver, &dir.path().join(&name)).unwrap();
        let drawn = std::fs::read(dir.path().join(&name)).unwrap();
        assert!(drawn == std::fs::read(committed.join(&name)).unwrap(), "{name} differs from table3 --seed 0 --png's");
    }
}

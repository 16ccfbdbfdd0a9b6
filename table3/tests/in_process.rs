//! The library on the in-process engine (nigel_benchmark's loop): the self-check table,
//! the metric against nigel_benchmark's own, the undisturbed straight run, determinism.

mod common;

use std::sync::OnceLock;

use nigel_benchmark::{Benchmark, Scenario};
use nigel_table3::report::json_without_wall;
use nigel_table3::{run_table, Controller, Engine, Fidelity, InProcess, Job, Maneuver, Metric, Options, Table};

fn table_seed0() -> &'static Table {
    static T: OnceLock<Table> = OnceLock::new();
    T.get_or_init(|| run_table(&InProcess::new(), &Options::new(0)).expect("the in-process table runs").table)
}

common::self_check_tests!(table_seed0, self_check_24_cells, robust_tracking_is_lowest_in_all_12_rows);

#[test]
fn the_table_has_every_cell_and_the_baked_gains() {
    let t = table_seed0();
    assert_eq!(t.cells.len(), 48);
    assert_eq!(t.seed, 0);
    let paper = |k: [[f64; 2]; 4]| k.map(|row| [0.0, 0.0, row[0], row[1]]);
    assert_eq!(
        t.gains,
        vec![
            (Controller::PolePlacement, paper(nigel_benchmark::gains::POLE_PLACEMENT)),
            (Controller::Robust, paper(nigel_benchmark::gains::ROBUST)),
            (Controller::RobustTracking, nigel_benchmark::gains::ROBUST_TRACKING),
        ]
    );
    for c in &t.cells {
        assert!(c.metric.eps.is_finite() && c.metric.eps > 0.0, "{c:?}");
        let norm = c.metric.rmse.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert_eq!(c.metric.eps, norm);
    }
}

#[test]
fn metric_equals_nigel_benchmarks_own() {
    // the metric here is computed from the recorded series; nigel_benchmark computes its
    // own inside the loop: both must be the same numbers
    for (f, m, c) in [
        (Fidelity::Paper, Maneuver::Slalom, Controller::Robust),
        (Fidelity::Real, Maneuver::Figure8, Controller::PolePlacement),
        (Fidelity::Real, Maneuver::Fishhook, Controller::RobustTracking),
    ] {
        let run = InProcess::new().run(&Job::new(3, f, m, c)).unwrap();
        let ours = Metric::of(&run);
        let bench = Benchmark::prepare(Scenario { seed: 3, ..Scenario::new(m, f) }).unwrap();
        let theirs = bench.run(c).unwrap().metric;
        let pairs = [
            (ours.rmse[0], theirs.rmse_x),
            (ours.rmse[1], theirs.rmse_y),
            (ours.rmse[2], theirs.rmse_psi),
            (ours.eps, theirs.epsilon),
            (ours.rmse_state[0], theirs.rmse_beta),
            (ours.rmse_state[1], theirs.rmse_yaw_rate),
            (ours.eps_state, theirs.epsilon_state),
        ];
        for (a, b) in pairs {
            assert!((a - b).abs() <= 1e-14 * b.abs(), "{f:?} {m} {c}: {a} vs {b}");
        }
    }
}

#[test]
fn undisturbed_straight_stays_on_the_reference() {
    let engine = InProcess::new();
    for f in Fidelity::ALL {
        for c in Controller::WITH_TRACKING {
            let job = Job { disturbed: false, ..Job::new(0, f, Maneuver::Straight, c) };
            let run = engine.run(&job).unwrap();
            let m = Metric::of(&run);
            assert!(m.eps <= 1e-12 && m.eps_state <= 1e-12, "{}: {m:?}", job.label());
            // and the reference itself goes straight along +X at 0.35 m/s
            assert!(run.y_ref.iter().chain(&run.psi_ref).all(|v| v.abs() <= 1e-12));
            assert!((run.x_ref[30_000] - 0.35 * 30.0).abs() < 1e-9, "{}", run.x_ref[30_000]);
        }
    }
}

#[test]
fn one_and_two_threads_and_two_runs_are_bit_identical() {
    let engine = InProcess::new();
    let mut options = Options::new(7);
    options.maneuvers = vec![Maneuver::LaneChange, Maneuver::Figure8];
    options.threads = 1;
    let one = run_table(&engine, &options).unwrap().table;
    options.threads = 2;
    let two = run_table(&engine, &options).unwrap().table;
    let again = run_table(&engine, &options).unwrap().table;
    let text = |t: &Table| serde_json::to_string(&json_without_wall(t)).unwrap();
    assert_eq!(text(&one), text(&two));
    assert_eq!(text(&two), text(&again));
    assert_eq!(one.cells, two.cells);
    // and a different seed gives different numbers
    options.seed = 8;
    let other = run_table(&engine, &options).unwrap().table;
    assert_ne!(text(&other), text(&two));
}

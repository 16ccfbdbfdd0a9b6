//! `simulate_with`: instances reused through `fmi2Reset` give the results of fresh
//! instances bit for bit (the previous run's parameters do not leak into the next), and
//! the rows handed to a sink are the rows `simulate` keeps.

mod common;

use nigel_cosim::{
    read_ssp, simulate, simulate_with, Algorithm, Experiment, ImportOptions, InstancePool, SystemBuilder, Value,
};

#[test]
fn reset_instances_and_streamed_rows_equal_fresh_runs() {
    let ssp = common::built_ssp("nigel_closed_loop.ssp");
    let base = read_ssp(&ssp, &ImportOptions::default()).unwrap().system;
    let with = |sets: &[(&str, Value)]| {
        let mut b = SystemBuilder::from_system(base.clone());
        for (n, v) in sets {
            b.set(n, v.clone()).unwrap();
        }
        b.build()
    };
    // a run that changes parameters of all three instances, then runs that set none or others
    let a = with(&[
        ("plant.m", Value::Real(2.9)),
        ("plant.friction_circle", Value::Boolean(true)),
        ("controller.controller", Value::Integer(1)),
        ("maneuver.seed", Value::Integer(5)),
    ]);
    let b = with(&[]);
    let c = with(&[("maneuver.maneuver", Value::Integer(3))]);
    let mut e = Experiment::new(2.0, 1e-3);
    e.algorithm = Algorithm::Ordered;
    e.record =
        Some(["plant.x", "plant.y", "plant.psi", "controller.delta_fl", "maneuver.mu_rr"].map(String::from).to_vec());
    let mut pool = InstancePool::new();
    for system in [&a, &b, &c, &a, &b] {
        let fresh = simulate(system, &e).unwrap().0;
        let reused = simulate_with(system, &e, Some(&mut pool), None).unwrap().0;
        assert_eq!(pool.len(), 3, "the three instances go back into the pool");
        assert_eq!(reused.values, fresh.values);
        assert_eq!(reused.names, fresh.names);
        // streamed: the same rows, none kept
        let mut rows: Vec<f64> = Vec::new();
        let mut sink = |t: f64, v: &[f64], _: &[(usize, String)]| {
            rows.push(t);
            rows.extend_from_slice(v);
        };
        let streamed = simulate_with(system, &e, Some(&mut pool), Some(&mut sink)).unwrap().0;
        assert!(streamed.values.is_empty());
        assert_eq!(streamed.names, fresh.names);
        assert_eq!(rows, fresh.values);
    }
    // a run that fails leaves nothing in the pool; the next one instantiates again
    let bad = with(&[("plant.v_fade", Value::Real(-1.0))]);
    assert!(simulate_with(&bad, &e, Some(&mut pool), None).is_err());
    assert!(pool.len() < 3);
    let fresh = simulate(&b, &e).unwrap().0;
    assert_eq!(simulate_with(&b, &e, Some(&mut pool), None).unwrap().0.values, fresh.values);
}

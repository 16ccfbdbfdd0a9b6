//! Event iteration across coupled Model Exchange FMUs: the bouncing ball's velocity feeds
//! a discrete counter that has no event of its own. At each bounce both enter event mode,
//! the ball's new velocity is carried to the counter within the event, and the counter
//! counts the bounce at the bounce's own time; a loop without a fixed point is named.

mod common;
use common::{assert_counted_at_bounces, build_ball, build_latch, builder_with, work_dir};
use nigel_cosim::{simulate, Algorithm, Error, Experiment, Fmu, Solver, SystemBuilder, Value};

const G: f64 = 9.81;

/// Bounce times of the ball dropped from 1 m with restitution 0.7: t1 = sqrt(2/g), and
/// each flight after a bounce lasts 2 v / g with v = 0.7^k g t1.
fn bounces() -> [f64; 3] {
    let t1 = (2.0 / G).sqrt();
    let t2 = t1 + 2.0 * 0.7 * t1;
    let t3 = t2 + 2.0 * 0.49 * t1;
    [t1, t2, t3]
}

fn ball_and_counter(
    dir: &std::path::Path,
    algorithm: Algorithm,
    solver: Solver,
) -> (nigel_cosim::Results, nigel_cosim::Summary) {
    let mut b = SystemBuilder::new();
    b.add_instance("ball", Fmu::load(&build_ball(dir)).unwrap()).unwrap();
    b.add_instance("counter", Fmu::load(&build_latch(dir)).unwrap()).unwrap();
    b.connect("ball.v", "counter.u").unwrap();
    let mut e = Experiment::new(1.5, 0.01);
    e.algorithm = algorithm;
    e.solver = solver;
    simulate(&b.build(), &e).unwrap()
}

#[test]
fn a_bounce_is_an_event_of_the_coupled_counter_at_the_bounce_time() {
    let dir = work_dir("coupled-counter");
    let [t1, t2, t3] = bounces();
    assert!(t3 > 1.5 && t2 < 1.5);
    for algorithm in [Algorithm::Ordered, Algorithm::Jacobi] {
        for solver in [Solver::Rk4 { max_step: None }, Solver::Dopri5 { rtol: 1e-10, atol: 1e-12 }] {
            let (r, s) = ball_and_counter(&dir, algorithm, solver);
            let what = format!("{algorithm:?} {solver:?}");
            // the ball's state events, located to 1e-10 s of the exact times
            let state: Vec<f64> = s.events.iter().filter(|e| e.kind == "state").map(|e| e.time).collect();
            assert_eq!(state.len(), 2, "{what}: {:?}", s.events);
            assert!((state[0] - t1).abs() < 1e-10 && (state[1] - t2).abs() < 1e-10, "{what}: {state:?}");
            assert!(s.events.iter().all(|e| e.instance == "ball"), "{what}: only the ball has events of its own");
            assert_counted_at_bounces(&r, &state, &what);
            assert_eq!(r.column("counter.count").unwrap().last(), Some(&2.0));
        }
    }
}

#[test]
fn the_ball_integrates_as_it_does_alone() {
    // lockstep with a member that has no states changes nothing in the ball's numbers
    let dir = work_dir("coupled-alone");
    let (coupled, _) = ball_and_counter(&dir, Algorithm::Ordered, Solver::Rk4 { max_step: Some(2e-3) });
    let mut b = SystemBuilder::new();
    b.add_instance("ball", Fmu::load(&build_ball(&dir)).unwrap()).unwrap();
    let mut e = Experiment::new(1.5, 0.01);
    e.algorithm = Algorithm::Ordered;
    e.solver = Solver::Rk4 { max_step: Some(2e-3) };
    let (alone, _) = simulate(&b.build(), &e).unwrap();
    for v in ["h", "v"] {
        let (a, c) = (alone.column(v).unwrap(), coupled.column(&format!("ball.{v}")).unwrap());
        assert_eq!(a, c, "ball.{v}");
    }
}

#[test]
fn an_event_iteration_without_a_fixed_point_names_the_fmus() {
    // a follower (follows its input from its time event at 0.25 s on) and an inverter in
    // a loop: settled before 0.25 s, no fixed point after
    let dir = work_dir("coupled-loop");
    let mut b = builder_with(&Fmu::load(&build_latch(&dir)).unwrap(), &["follower", "inverter"]);
    b.set("follower.mode", Value::Real(1.0)).unwrap();
    b.set("follower.t_event", Value::Real(0.25)).unwrap();
    b.set("inverter.mode", Value::Real(2.0)).unwrap();
    b.connect("follower.y", "inverter.u").unwrap();
    b.connect("inverter.y", "follower.u").unwrap();
    let system = b.build();
    // up to 0.2 s: the initial iteration settles (follower holds 0, inverter gives 1)
    let (r, _) = simulate(&system, &Experiment::new(0.2, 0.1)).unwrap();
    assert_eq!(r.column("inverter.y").unwrap(), vec![1.0; 3]);
    assert_eq!(r.column("follower.y").unwrap(), vec![0.0; 3]);
    match simulate(&system, &Experiment::new(1.0, 0.1)) {
        Err(Error::EventIteration { time, rounds, instances }) => {
            assert_eq!((time, rounds), (0.25, 100));
            assert_eq!(instances, ["follower", "inverter"]);
        }
        other => panic!("expected a non-converging event iteration, got {other:?}"),
    }
}

/// A Model Exchange FMU on its own is a group of one of the same integrator: its event
/// iteration has the same limit and the same error as a coupled group's.
#[test]
fn single_me_instance_event_iteration_has_the_group_limit_and_error() {
    let dir = work_dir("restless");
    let latch = Fmu::load(&build_latch(&dir)).unwrap();
    let mut b = SystemBuilder::new();
    b.add_instance("restless", latch).unwrap();
    b.set("restless.mode", Value::Real(3.0)).unwrap();
    b.set("restless.t_event", Value::Real(0.25)).unwrap();
    let system = b.build();
    match simulate(&system, &Experiment::new(1.0, 0.1)) {
        Err(Error::EventIteration { time, rounds, instances }) => {
            assert_eq!((time, rounds), (0.25, nigel_cosim::simulate::MAX_EVENT_ROUNDS));
            assert_eq!(rounds, 100);
            assert_eq!(instances, ["restless"]);
        }
        other => panic!("expected a non-converging event iteration, got {other:?}"),
    }
}

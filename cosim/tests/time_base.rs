//! The time base: communication point n at t0 + n h from the integer step count, the
//! number of steps from (stop - start) / h rounded with a tolerance relative to the step
//! (not to |t|), so that large start times count the steps as a start at 0 does; and the
//! settings that cannot progress refused, with a cap on the steps of a run.

mod common;
use common::{build_ball, plant_fmu, work_dir};
use nigel_cosim::{simulate, Error, Experiment, Fmu, ImportOptions, Interface, Solver, System};

fn plant(interface: Interface) -> System {
    let options = ImportOptions { interface: Some(interface), ..ImportOptions::default() };
    let mut system = System::single("model", Fmu::load_with(&plant_fmu(), &options).unwrap()).unwrap();
    system.instances[0].start_values.clear();
    system
}

fn from(start: f64, stop: f64, step: f64) -> Experiment {
    let mut e = Experiment::new(stop, step);
    e.start_time = start;
    e
}

#[test]
fn large_start_times_count_the_steps_as_zero_does() {
    let system = plant(Interface::CoSimulation);
    for start in [0.0, 1e3, 1e6, 1e9, 1e12] {
        // the stop time as a user types it: start + 0.003
        let stop = start + 0.003;
        let (r, summary) = simulate(&system, &from(start, stop, 1e-3)).unwrap();
        assert_eq!(summary.steps, 3, "start {start}");
        let time = r.column("time").unwrap();
        assert_eq!(time.len(), 4, "start {start}");
        assert_eq!(time[0], start);
        assert_eq!(time[3], stop, "start {start}: the last point is the stop time");
        // every point is t0 + n h as f64 computes it (no accumulated time)
        for (n, t) in time.iter().enumerate() {
            assert_eq!(*t, start + n as f64 * 1e-3, "start {start}, point {n}");
        }
    }
}

#[test]
fn the_remainder_of_the_interval_is_judged_relative_to_the_step() {
    let system = plant(Interface::CoSimulation);
    // 1e-10 s over 1000 steps of 1 ms is a ten-millionth of a step: no step of its own
    let (_, s) = simulate(&system, &from(0.0, 1.0 + 1e-10, 1e-3)).unwrap();
    assert_eq!(s.steps, 1000);
    // at 1e6 s, a remainder of a tenth of a step (1e-4 s, far above the 1.2e-10 s spacing of
    // the times there) is a step of its own, as at 0
    for start in [0.0, 1e6] {
        match simulate(&system, &from(start, start + 0.0031, 1e-3)) {
            Ok((r, s)) => {
                assert_eq!(s.steps, 4, "start {start}");
                assert_eq!(*r.column("time").unwrap().last().unwrap(), start + 0.0031);
            }
            Err(Error::Experiment(m)) => assert!(m.contains("canHandleVariableCommunicationStepSize"), "{m}"),
            Err(e) => panic!("{e}"),
        }
    }
}

#[test]
fn a_step_below_the_resolution_of_the_times_is_refused() {
    let system = plant(Interface::CoSimulation);
    // near 1e12 s the f64 times are 1.2e-4 s apart: 1e-5 s steps cannot be told apart
    match simulate(&system, &from(1e12, 1e12 + 1.0, 1e-5)) {
        Err(Error::Experiment(m)) => assert!(m.contains("resolution"), "{m}"),
        other => panic!("expected the step refused, got {:?}", other.map(|(_, s)| s.steps)),
    }
}

#[test]
fn integrator_settings_that_cannot_progress_are_refused() {
    let system = plant(Interface::ModelExchange);
    let mut e = Experiment::new(1.0, 1e-3);
    e.solver = Solver::Rk4 { max_step: Some(1e-300) };
    let err = simulate(&system, &e).unwrap_err().to_string();
    assert!(err.contains("largest RK4 step 1e-300"), "{err}");
    // 1e-12 s sub-steps over 1 s: 1e12 internal steps, over the cap of 1e9
    e.solver = Solver::Rk4 { max_step: Some(1e-12) };
    let err = simulate(&system, &e).unwrap_err().to_string();
    assert!(err.contains("over the cap"), "{err}");
    e.solver = Solver::Dopri5 { rtol: 1e-300, atol: 1e-302 };
    let err = simulate(&system, &e).unwrap_err().to_string();
    assert!(err.contains("relative tolerance 1e-300"), "{err}");
}

#[test]
fn the_cap_on_the_steps_of_a_run_stops_it_with_an_error() {
    let system = plant(Interface::CoSimulation);
    let mut e = Experiment::new(1.0, 1e-3);
    e.max_steps = 999;
    let err = simulate(&system, &e).unwrap_err().to_string();
    assert!(err.contains("1000 communication steps exceed the cap of 999"), "{err}");
    e.max_steps = 1000;
    assert_eq!(simulate(&system, &e).unwrap().1.steps, 1000);
    // the integrator's internal steps count too: the bouncing ball with dopri5 over 2 s in
    // 20 communication steps takes more internal steps than that (it bounces twice)
    let dir = work_dir("time-base-cap");
    let ball = System::single("ball", Fmu::load(&build_ball(&dir)).unwrap()).unwrap();
    let mut e = Experiment::new(2.0, 0.1);
    e.solver = Solver::Dopri5 { rtol: 1e-8, atol: 1e-10 };
    let (_, free) = simulate(&ball, &e).unwrap();
    assert!(free.integrator_steps.0 > 20, "{:?}", free.integrator_steps);
    e.max_steps = 20;
    match simulate(&ball, &e) {
        Err(Error::Experiment(m)) => assert!(m.contains("ball tried more than 20 internal steps"), "{m}"),
        other => panic!("expected the cap, got {:?}", other.map(|(_, s)| s.integrator_steps)),
    }
}

//! Ending a run the FMI 2 way, with a C FMU after the Reference FMU `Stair` (a counter
//! 1 .. 10, one more each whole second, that ends the simulation when it reaches 10 at
//! t = 9 s), run as fmpy and fmusim run it:
//! - Co-Simulation: `fmi2DoStep` over (8.8, 9.0] returns fmi2Discard with fmi2Terminated
//!   true and fmi2LastSuccessfulTime 9: the run ends there, with the row at 9 (counter 10);
//! - Model Exchange: `terminateSimulation` at the time event at 9: the run ends at the
//!   event, with the row at 9 after its event iteration (counter 10), as in Co-Simulation.

mod common;
use common::{build_stair, work_dir};
use nigel_cosim::{simulate, Experiment, Fmu, ImportOptions, Interface, System};

fn stair(interface: Interface) -> System {
    stair_in(interface, &format!("stair-{}", interface.as_str()))
}

/// As [`stair`], built in a scratch folder of the test's own (tests run in parallel).
fn stair_in(interface: Interface, folder: &str) -> System {
    let dir = work_dir(folder);
    let options = ImportOptions { interface: Some(interface), ..ImportOptions::default() };
    System::single("model", Fmu::load_with(&build_stair(&dir), &options).unwrap()).unwrap()
}

/// Counter at time t: 1 plus the whole seconds up to t (the FMU's definition).
fn counter_at(t: f64) -> f64 {
    1.0 + (t + 1e-9).floor()
}

/// The stair through `interface` to 10 s in steps of 0.2 s: its columns time and counter
/// (asserted 46 rows) and the run's summary.
fn stair_to_10s_in_46_rows(interface: Interface) -> (Vec<f64>, Vec<f64>, nigel_cosim::Summary) {
    let (r, summary) = simulate(&stair(interface), &Experiment::new(10.0, 0.2)).unwrap();
    assert_eq!(r.rows(), 46);
    (r.column("time").unwrap(), r.column("counter").unwrap(), summary)
}

#[test]
fn co_simulation_ends_at_the_last_successful_time_with_that_row() {
    // rows 0, 0.2, ..., 8.8 (45 communication points), then the row at 9
    let (time, counter, summary) = stair_to_10s_in_46_rows(Interface::CoSimulation);
    assert_eq!(*time.last().unwrap(), 9.0);
    assert_eq!(*counter.last().unwrap(), 10.0);
    for (t, c) in time.iter().zip(&counter).take(45) {
        assert_eq!(*c, counter_at(*t), "t = {t}");
    }
    let (instance, t_end, reason) = summary.ended_by.clone().unwrap();
    assert_eq!((instance.as_str(), t_end), ("model", 9.0));
    assert!(reason.contains("fmi2Terminated"), "{reason}");
    assert_eq!(summary.steps, 44, "the step over (8.8, 9.0] did not complete");
}

#[test]
fn model_exchange_ends_at_the_event_with_the_row_at_the_event() {
    // rows 0, 0.2, ..., 8.8 (45 communication points), then the row at the event at 9
    let (time, counter, summary) = stair_to_10s_in_46_rows(Interface::ModelExchange);
    assert!((time[44] - 8.8).abs() < 1e-12, "{}", time[44]); // 44 * 0.2 in f64
    assert_eq!(*time.last().unwrap(), 9.0);
    assert_eq!(*counter.last().unwrap(), 10.0);
    for (t, c) in time.iter().zip(&counter) {
        assert_eq!(*c, counter_at(*t), "t = {t}");
    }
    let (instance, t_end, reason) = summary.ended_by.clone().unwrap();
    assert_eq!((instance.as_str(), t_end, reason), ("model", 9.0, "terminateSimulation"));
}

#[test]
fn model_exchange_with_bdf_ends_at_the_event_with_the_row_at_the_event() {
    // no states (the bdf method has nothing to integrate), time events each second
    let system = stair_in(Interface::ModelExchange, "stair-me-bdf");
    let mut e = Experiment::new(10.0, 0.2);
    e.solver = nigel_cosim::Solver::Bdf { rtol: 1e-6, atol: 1e-8 };
    let (r, summary) = simulate(&system, &e).unwrap();
    let time = r.column("time").unwrap();
    let counter = r.column("counter").unwrap();
    assert_eq!(r.rows(), 46);
    assert_eq!((*time.last().unwrap(), *counter.last().unwrap()), (9.0, 10.0));
    for (t, c) in time.iter().zip(&counter) {
        assert_eq!(*c, counter_at(*t), "t = {t}");
    }
    let times: Vec<f64> = summary.events.iter().map(|e| e.time).collect();
    assert_eq!(times, (1..=9).map(f64::from).collect::<Vec<_>>());
    let (instance, t_end, reason) = summary.ended_by.clone().unwrap();
    assert_eq!((instance.as_str(), t_end, reason), ("model", 9.0, "terminateSimulation"));
}

/// An FMU that asks to end the simulation at the stop time has not ended it early: with
/// the stop time 9 s, the Co-Simulation Discard with fmi2Terminated at
/// lastSuccessfulTime 9 s and the Model Exchange terminateSimulation at the event at 9 s
/// complete the last step: every step counted, the last row at 9 s (counter 10), no
/// `ended_by`.
#[test]
fn an_end_at_the_stop_time_is_no_early_end() {
    for (interface, folder) in [(Interface::CoSimulation, "stair-cs-stop"), (Interface::ModelExchange, "stair-me-stop")]
    {
        let system = stair_in(interface, folder);
        let (r, summary) = simulate(&system, &Experiment::new(9.0, 0.2)).unwrap();
        assert_eq!(summary.ended_by, None, "{interface:?}");
        assert_eq!(summary.steps, 45, "{interface:?}");
        let time = r.column("time").unwrap();
        let counter = r.column("counter").unwrap();
        assert_eq!(r.rows(), 46, "{interface:?}");
        assert_eq!((*time.last().unwrap(), *counter.last().unwrap()), (9.0, 10.0), "{interface:?}");
    }
}

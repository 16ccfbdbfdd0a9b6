//! Model Exchange FMUs that return non-numbers with OK (issue 35, defect 6): a NaN state
//! derivative (rk4, dopri5, bdf), an infinite one (dopri5's error estimate then NaN: the
//! step is not taken), a NaN next event time. Each is an error naming the FMU, the call and
//! the time, with the rows before it kept. The FMU is tests/cfmu/nanme.c: x' = -x, x(0) = 1,
//! misbehaving from t >= t_bad = 0.5 s on (parameter `mode`: 1 NaN derivative, 2 +Inf
//! derivative, 3 NaN next event time at every event iteration).

mod common;
use common::{build_nanme, work_dir};
use nigel_cosim::simulate::simulate_recorded;
use nigel_cosim::{Experiment, Fmu, Solver, System, SystemBuilder, Value};

fn system(test: &str, mode: f64) -> System {
    let fmu = Fmu::load(&build_nanme(&work_dir(test))).unwrap();
    let mut b = SystemBuilder::new();
    b.add_instance("decay", fmu).unwrap();
    b.set("decay.mode", Value::Real(mode)).unwrap();
    b.build()
}

/// The time `t = ... s` an error message names.
fn time_in(message: &str) -> f64 {
    let at = message.rfind("t = ").expect("a time") + 4;
    message[at..].split(' ').next().unwrap().parse().unwrap()
}

#[test]
fn a_nan_derivative_is_an_error_naming_the_fmu_the_call_and_the_time_with_every_solver() {
    let system = system("nan-derivative", 1.0);
    let solvers = [
        Solver::Rk4 { max_step: None },
        Solver::Dopri5 { rtol: 1e-6, atol: 1e-9 },
        Solver::Bdf { rtol: 1e-6, atol: 1e-9 },
    ];
    for solver in solvers {
        let mut e = Experiment::new(1.0, 0.1);
        e.solver = solver;
        let (results, outcome) = simulate_recorded(&system, &e);
        let message = outcome.expect_err("a NaN derivative must stop the run").to_string();
        assert!(message.contains("decay (nanme.fmu)"), "{solver:?}: {message}");
        assert!(message.contains("fmi2GetDerivatives returned der(x) = NaN with fmi2OK"), "{solver:?}: {message}");
        // the first derivative asked at t >= t_bad = 0.5 s, inside the step from 0.4 to 0.5 s
        // or the next one (a stage or a step at most one communication step of 0.1 s on)
        let t = time_in(&message);
        assert!((0.5..0.6).contains(&t), "{solver:?}: {t}");
        // the rows before the failed step are kept: 0 to 0.4 s at least (bdf may step past
        // a communication point and come back to it by its dense output)
        let rows = results.rows();
        assert!((5..=6).contains(&rows), "{solver:?}: {rows} rows");
        let x = results.column("x").unwrap();
        // x = exp(-t) before t_bad, to the solvers' accuracy (rk4 at h = 0.1: 1e-6)
        assert!((x[4] - (-0.4f64).exp()).abs() < 1e-5, "{solver:?}: {}", x[4]);
    }
}

#[test]
fn dopri5_takes_no_step_whose_error_estimate_is_nan() {
    // +Inf derivatives from t = 0.5 s: the stages after an infinite one are infinite and
    // the error estimate sums +Inf and -Inf (NaN), which f64::max would drop
    let system = system("nan-error-estimate", 2.0);
    let mut e = Experiment::new(1.0, 0.1);
    e.solver = Solver::Dopri5 { rtol: 1e-6, atol: 1e-9 };
    let (results, outcome) = simulate_recorded(&system, &e);
    let message = outcome.expect_err("a NaN error estimate must stop the run").to_string();
    assert!(message.contains("decay (nanme.fmu)"), "{message}");
    assert!(message.contains("dopri5 error estimate"), "{message}");
    assert!(message.contains("is NaN"), "{message}");
    let t = message.split("from t = ").nth(1).unwrap().split(' ').next().unwrap().parse::<f64>().unwrap();
    assert!((0.4..0.6).contains(&t), "{t}");
    // no NaN and no infinity reached the results
    assert!(results.values.iter().all(|v| v.is_finite()), "{:?}", results.values);
}

#[test]
fn a_nan_next_event_time_is_an_error_naming_the_fmu_the_call_and_the_time() {
    let system = system("nan-event-time", 3.0);
    for solver in [Solver::Rk4 { max_step: None }, Solver::Bdf { rtol: 1e-6, atol: 1e-9 }] {
        let mut e = Experiment::new(1.0, 0.1);
        e.solver = solver;
        let (_, outcome) = simulate_recorded(&system, &e);
        let message = outcome.expect_err("a NaN next event time must stop the run").to_string();
        assert!(message.contains("decay (nanme.fmu)"), "{solver:?}: {message}");
        assert!(
            message.contains(
                "fmi2NewDiscreteStates returned a next event time of NaN (nextEventTimeDefined true) with fmi2OK"
            ),
            "{solver:?}: {message}"
        );
        // the initial event iteration, at the start time
        assert_eq!(time_in(&message), 0.0, "{message}");
    }
}

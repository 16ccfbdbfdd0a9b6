//! A run driven from outside through its `Execution`: `simulate_until`, `set` and `get`
//! between steps, values queued from a row sink (`SetQueue`), the cancel flag, on the C
//! integrator FMU (tests/cfmu/models.c: x += u h per step, exact for an input constant over
//! the step).

mod common;
use common::{build_fmu, work_dir, Model};
use nigel_cosim::simulate::{Execution, Phase};
use nigel_cosim::{simulate, Error, Experiment, Fmu, InputTable, SetQueue, SystemBuilder, Value};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

fn integrator_system(test: &str) -> nigel_cosim::System {
    let dir = work_dir(test);
    let fmu = Fmu::load(&build_fmu(Model::Integrator, &dir, &[])).unwrap();
    let mut b = SystemBuilder::new();
    b.add_instance("integrator", fmu).unwrap();
    b.build()
}

/// The run of `integrator_system` with u = 1 from t = 0.5 s as an input signal (the
/// reference the stepped runs must equal bit for bit).
fn with_input_jump(system: &nigel_cosim::System) -> nigel_cosim::Results {
    let mut e = Experiment::new(1.0, 0.1);
    e.input = Some(Arc::new(
        InputTable::new(vec!["u".into()], vec![0.0, 0.5, 0.5, 1.0], vec![vec![0.0, 0.0, 1.0, 1.0]]).unwrap(),
    ));
    simulate(system, &e).unwrap().0
}

#[test]
fn an_execution_set_between_steps_acts_from_the_next_step_as_an_input_jump_there() {
    let system = integrator_system("stepping-execution");
    let reference = with_input_jump(&system);
    let x_ref = reference.column("x").unwrap();
    let mut run = Execution::new(&system, &Experiment::new(1.0, 0.1)).unwrap();
    assert_eq!(run.phase(), Phase::Created);
    run.initialize().unwrap();
    assert_eq!((run.step_number(), run.time()), (0, 0.0));
    // 0.45 s is between points: the run stops at the first point after it, 0.5 s (step 5)
    assert_eq!(run.simulate_until(0.45).unwrap(), 0.5);
    assert_eq!(run.step_number(), 5);
    // a time already reached takes no step
    assert_eq!(run.simulate_until(0.2).unwrap(), 0.5);
    assert_eq!(run.step_number(), 5);
    run.set("integrator.u", "1").unwrap();
    // the value is applied before the next step, not at once: x is still 0
    assert_eq!(run.get("integrator.x").unwrap(), Value::Real(0.0));
    assert!(run.step().unwrap());
    // x(0.6) as the input signal's run has it: one step of about 0.1 s at u = 1 (x += u h)
    assert_eq!(run.get("integrator.x").unwrap(), Value::Real(x_ref[6]));
    assert!((x_ref[6] - 0.1).abs() < 1e-15, "{}", x_ref[6]);
    run.simulate_until(10.0).unwrap();
    assert_eq!(run.phase(), Phase::AtEnd);
    assert!(!run.step().unwrap(), "no step past the stop time");
    let summary = run.finish().unwrap();
    assert_eq!(summary.steps, 10);
    let stepped = run.take_results();
    assert_eq!(stepped.names, reference.names);
    assert_eq!(stepped.values, reference.values);
    // what cannot be set during a run is refused by name
    let mut run = Execution::new(&system, &Experiment::new(1.0, 0.1)).unwrap();
    run.initialize().unwrap();
    let e = run.set("integrator.x", "1").unwrap_err();
    assert!(matches!(e, Error::Import(nigel_cosim::ImportError::InvalidValue { .. })), "{e}");
    assert!(e.to_string().contains("integrator.x"), "{e}");
    // stopped before its end: no finish, the rows kept
    run.simulate_until(0.3).unwrap();
    run.stop();
    assert_eq!(run.phase(), Phase::Stopped);
    assert!(run.step().is_err());
    assert!(run.finish().is_err());
    assert_eq!(run.results().rows(), 4);
}

#[test]
fn a_value_queued_at_a_row_applies_from_the_next_step_as_an_input_jump_there() {
    let system = integrator_system("stepping-queue");
    // u = 1 from t = 0.5 s, queued by the row sink when the row at 0.5 s is written
    let queue = Arc::new(SetQueue::new());
    let e = Experiment::new(1.0, 0.1);
    let sink = |t: f64, _row: &[f64]| {
        if (t - 0.5).abs() < 1e-12 {
            queue.push_text(&system, "integrator.u", "1").unwrap();
        }
    };
    let mut rows = Vec::new();
    let mut record = |t: f64, row: &[f64], _: &[(usize, String)]| {
        sink(t, row);
        rows.push((t, row.to_vec()));
    };
    let mut run = Execution::new(&system, &e).unwrap().with_set_queue(queue.clone()).with_sink(&mut record);
    nigel_cosim::simulate::run_to_end(&mut run).unwrap();
    drop(run);
    // the same with an input signal jumping at 0.5 s
    let r = with_input_jump(&system);
    assert_eq!(rows.len(), r.rows());
    for (k, (t, row)) in rows.iter().enumerate() {
        assert_eq!(r.row(k)[0], *t);
        assert_eq!(&r.row(k)[1..], &row[..], "row {k}");
    }
    // x(1) = 0.5: the queued value acted (five steps of 0.1 at u = 1)
    let x = r.column("x").unwrap();
    assert!((x[10] - 0.5).abs() < 1e-15, "{}", x[10]);
    // what cannot be set during a run is refused when queued, by name
    let e = queue.push_text(&system, "integrator.x", "1").unwrap_err();
    assert!(matches!(e, Error::Import(nigel_cosim::ImportError::InvalidValue { .. })), "{e}");
    assert!(e.to_string().contains("integrator.x"), "{e}");
}

#[test]
fn the_cancel_flag_stops_the_run_between_steps_with_the_rows_so_far() {
    let system = integrator_system("stepping-cancel");
    let cancel = Arc::new(AtomicBool::new(false));
    let e = Experiment::new(1.0, 0.1);
    let mut times = Vec::new();
    let mut sink = |t: f64, _row: &[f64], _: &[(usize, String)]| {
        times.push(t);
        if times.len() == 4 {
            cancel.store(true, Ordering::Relaxed);
        }
    };
    let mut run = Execution::new(&system, &e).unwrap().with_sink(&mut sink);
    run.cancel_on(cancel.clone());
    let err = nigel_cosim::simulate::run_to_end(&mut run).unwrap_err();
    drop(run);
    match err {
        // the flag set at the row of t = 0.3 s: the step to 0.3 s was the last
        Error::Cancelled { time } => assert!((time - 0.3).abs() < 1e-12, "{time}"),
        other => panic!("{other}"),
    }
    assert_eq!(times.len(), 4);
}

/// A caller's own manipulator: u = 1 from the step that starts at 0.5 s (step 5).
struct JumpAt5 {
    u: nigel_cosim::VariableRef,
}

impl nigel_cosim::simulate::Manipulator for JumpAt5 {
    fn before_step(
        &mut self,
        point: &nigel_cosim::simulate::Point,
        instances: &mut nigel_cosim::simulate::StepInstances<'_>,
    ) -> nigel_cosim::Result<()> {
        if point.n == 5 {
            instances.set(&self.u, Value::Real(1.0))?;
        }
        Ok(())
    }
}

#[test]
fn a_manipulator_of_the_callers_own_acts_before_the_step_as_an_input_jump_there() {
    let system = integrator_system("stepping-manipulator");
    let u = system.resolve("integrator.u").unwrap();
    let mut seen = Vec::new();
    let mut run = Execution::new(&system, &Experiment::new(1.0, 0.1)).unwrap();
    run.add_manipulator(Box::new(JumpAt5 { u }));
    struct Steps<'a>(&'a mut Vec<(u64, f64)>);
    impl nigel_cosim::simulate::Observer for Steps<'_> {
        fn step_complete(&mut self, point: &nigel_cosim::simulate::Point) -> nigel_cosim::Result<()> {
            self.0.push((point.n, point.t_next));
            Ok(())
        }
    }
    run.add_observer(Box::new(Steps(&mut seen)));
    nigel_cosim::simulate::run_to_end(&mut run).unwrap();
    let stepped = run.take_results();
    drop(run);
    assert_eq!(stepped.values, with_input_jump(&system).values);
    // the observer was told of every step, with the points t0 + (n + 1) h
    assert_eq!(seen.len(), 10);
    for (k, (n, t)) in seen.iter().enumerate() {
        assert_eq!((*n, *t), (k as u64, (k + 1) as f64 * 0.1));
    }
}

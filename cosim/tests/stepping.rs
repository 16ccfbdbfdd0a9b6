//! A run driven from outside: values queued while it is in progress
//! (`Experiment::between_steps`) and the cancel flag (`Experiment::cancel`), on the C
//! integrator FMU (tests/cfmu/models.c: x += u h per step, exact for an input constant over
//! the step).

mod common;
use common::{build_fmu, work_dir, Model};
use nigel_cosim::{simulate, simulate::simulate_with, Error, Experiment, Fmu, InputTable, SetQueue, SystemBuilder};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

fn integrator_system(test: &str) -> nigel_cosim::System {
    let dir = work_dir(test);
    let fmu = Fmu::load(&build_fmu(Model::Integrator, &dir, &[])).unwrap();
    let mut b = SystemBuilder::new();
    b.add_instance("integrator", fmu).unwrap();
    b.build()
}

#[test]
fn a_value_queued_at_a_row_applies_from_the_next_step_as_an_input_jump_there() {
    let system = integrator_system("stepping-queue");
    // u = 1 from t = 0.5 s, queued by the row sink when the row at 0.5 s is written
    let queue = Arc::new(SetQueue::new());
    let mut e = Experiment::new(1.0, 0.1);
    e.between_steps = Some(queue.clone());
    let sink = |t: f64, _row: &[f64]| {
        if (t - 0.5).abs() < 1e-12 {
            queue.push_text(&system, "integrator.u", "1").unwrap();
        }
    };
    let mut rows = Vec::new();
    let mut record = |t: f64, row: &[f64]| {
        sink(t, row);
        rows.push((t, row.to_vec()));
    };
    simulate_with(&system, &e, None, Some(&mut record)).unwrap();
    // the same with an input signal jumping at 0.5 s
    let mut e2 = Experiment::new(1.0, 0.1);
    e2.input = Some(Arc::new(
        InputTable::new(vec!["u".into()], vec![0.0, 0.5, 0.5, 1.0], vec![vec![0.0, 0.0, 1.0, 1.0]]).unwrap(),
    ));
    let (r, _) = simulate(&system, &e2).unwrap();
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
    let mut e = Experiment::new(1.0, 0.1);
    e.cancel = Some(cancel.clone());
    let mut times = Vec::new();
    let mut sink = |t: f64, _row: &[f64]| {
        times.push(t);
        if times.len() == 4 {
            cancel.store(true, Ordering::Relaxed);
        }
    };
    let err = simulate_with(&system, &e, None, Some(&mut sink)).unwrap_err();
    match err {
        // the flag set at the row of t = 0.3 s: the step to 0.3 s was the last
        Error::Cancelled { time } => assert!((time - 0.3).abs() < 1e-12, "{time}"),
        other => panic!("{other}"),
    }
    assert_eq!(times.len(), 4);
}

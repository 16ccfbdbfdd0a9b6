//! Input events between communication points (`--input`, `Experiment::input`): a jump of
//! the input of the C integrator FMU (tests/cfmu/models.c, x += u h per step, exact for
//! an input constant over the step) at t = 0.25 s with steps of 0.1 s. Split at the jump,
//! as fmpy makes it a communication point, x(t) = max(0, t - 0.25) at every point; applied
//! at the next point instead, x(0.3) would be 0. An FMU that cannot vary its step cannot
//! stop there: the jump takes effect at the next point, as in fmpy, with a note. (Rows count the lines of the CSV file, its header 1.)

mod common;
use common::{build_fmu, build_fmu_with, work_dir, Model};
use nigel_cosim::{simulate, Experiment, Fmu, InputTable, System, SystemBuilder};
use std::sync::Arc;

fn jump_at_quarter() -> Arc<InputTable> {
    // u = 0 until 0.25 s, then 1: two rows at 0.25 s
    Arc::new(InputTable::new(vec!["u".into()], vec![0.0, 0.25, 0.25, 2.0], vec![vec![0.0, 0.0, 1.0, 1.0]]).unwrap())
}

#[test]
fn a_jump_between_points_splits_the_step_there() {
    let dir = work_dir("input-split");
    let system = System::single("integrator", Fmu::load(&build_fmu(Model::Integrator, &dir, &[])).unwrap()).unwrap();
    for algorithm in [nigel_cosim::Algorithm::Jacobi, nigel_cosim::Algorithm::Ordered] {
        let mut e = Experiment::new(1.0, 0.1);
        e.algorithm = algorithm;
        e.input = Some(jump_at_quarter());
        let (r, _) = simulate(&system, &e).unwrap();
        let (t, x) = (r.column("time").unwrap(), r.column("x").unwrap());
        assert_eq!(t.len(), 11, "{algorithm:?}: one row per communication point, none at the jump");
        for (t, x) in t.iter().zip(&x) {
            // sums of a few steps of 0.1 and 0.05: a few ulps of 1
            assert!((x - (t - 0.25).max(0.0)).abs() < 1e-15, "{algorithm:?}: x({t}) = {x}");
        }
    }
}

/// An FMU that cannot vary its step cannot stop at a jump between points: as fmpy applies
/// the table at each step's start, the jump takes effect at the next point (0.3 s), and
/// the summary's note says so, naming the jump, the points and the FMU. The integrator
/// then gives x(t) = max(0, t - 0.3) (fmpy's result for this table and step).
#[test]
fn a_jump_between_points_of_a_fixed_step_fmu_takes_effect_at_the_next_point_with_a_note() {
    let dir = work_dir("input-fixed");
    let xml = Model::Integrator.model_description().replace(
        r#"canHandleVariableCommunicationStepSize="true""#,
        r#"canHandleVariableCommunicationStepSize="false""#,
    );
    let fmu = Fmu::load(&build_fmu_with(Model::Integrator, &dir, "fixed", &xml)).unwrap();
    let mut b = SystemBuilder::new();
    b.add_instance("integrator", fmu).unwrap();
    let system = b.build();
    let mut e = Experiment::new(1.0, 0.1);
    e.input = Some(jump_at_quarter());
    let (r, summary) = simulate(&system, &e).unwrap();
    assert_eq!(summary.notes.len(), 1, "{:?}", summary.notes);
    let note = &summary.notes[0];
    assert!(
        note.contains("the jump (rows 3 and 4 both at t = 0.25 s) falls between the communication points 0.2 and 0.30000000000000004 s")
            && note.contains("integrator cannot vary its communication step")
            && note.contains("takes effect at 0.30000000000000004 s"),
        "{note}"
    );
    let (t, x) = (r.column("time").unwrap(), r.column("x").unwrap());
    assert_eq!(t.len(), 11);
    for (t, x) in t.iter().zip(&x) {
        // sums of a few steps of 0.1: a few ulps of 1
        assert!((x - (t - 0.3).max(0.0)).abs() < 1e-15, "x({t}) = {x}");
    }
    // on a communication point it is applied there: x(t) = max(0, t - 0.2)
    e.input = Some(Arc::new(
        InputTable::new(vec!["u".into()], vec![0.0, 0.2, 0.2, 2.0], vec![vec![0.0, 0.0, 1.0, 1.0]]).unwrap(),
    ));
    let (r, summary) = simulate(&system, &e).unwrap();
    assert!(summary.notes.is_empty(), "{:?}", summary.notes);
    for (t, x) in r.column("time").unwrap().iter().zip(&r.column("x").unwrap()) {
        assert!((x - (t - 0.2).max(0.0)).abs() < 1e-15, "x({t}) = {x}");
    }
}

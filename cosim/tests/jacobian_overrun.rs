//! An FMU whose directional derivatives write past memory (issue 35, MapleSim 2023's
//! ControlledTemperature: 16 bytes past a 48-byte block of its own, which glibc found later
//! and aborted the master on in `fmi2FreeInstance`) neither crashes nor misleads bdf: the
//! importing layer keeps a red zone after every block an FMI 2.0 FMU allocates through
//! `allocateMemory` and after `dvUnknown`, the write lands there, and bdf takes finite
//! differences for that FMU from then on, with a note. The guard counts the overruns of each
//! instance's own blocks (those allocated in its calls), so one instance's write is never
//! blamed on another's call, in threads too.

mod common;
use common::{
    build_vdp, build_vdp_with_an_overrun, build_vdp_without_directional_derivatives, run_vdp_under_bdf, work_dir,
};
use nigel_cosim::{simulate, Experiment, Fmu, Solver, System};

/// vdp.c writing 16 bytes past a block of two doubles it allocated (kept alive), and vdp.c
/// writing two values past dvUnknown: each run completes, the note names the call and the
/// write, and the rows are those of the same FMU declaring no directional derivatives, bit
/// for bit (from the first Jacobian on, the same differences at the same points).
#[test]
fn a_directional_derivative_that_writes_past_memory_is_caught_and_replaced_by_differences() {
    let run = |path: std::path::PathBuf| run_vdp_under_bdf(&path);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let (differences, d) = run(build_vdp_without_directional_derivatives(&work_dir("overrun-fd")));
    assert!(d.notes.is_empty() && d.stiff.jacobians > 0, "{:?} {:?}", d.notes, d.stiff);
    for (flag, what) in [
        ("-DOVERRUN_OWN_BLOCK", "wrote 16 bytes past the end of a block of 16 bytes that the FMU allocated"),
        ("-DOVERRUN_DV_UNKNOWN", "wrote 16 bytes past the 16 bytes of dvUnknown (nUnknown = 2)"),
    ] {
        let (got, s) = run(build_vdp_with_an_overrun(&work_dir(&format!("overrun{flag}")), flag));
        assert_eq!(s.notes.len(), 1, "{flag}: {:?}", s.notes);
        let note = &s.notes[0];
        assert!(note.starts_with("model: fmi2GetDirectionalDerivative ") && note.contains(what), "{flag}: {note}");
        assert!(note.ends_with("bdf uses finite differences for its Jacobian"), "{note}");
        assert_eq!(s.stiff.jacobians, d.stiff.jacobians, "{flag}");
        assert_eq!(bits(&got.values), bits(&differences.values), "{flag}");
    }
}

/// The FMI 3.0 van der Pol (`tests/cfmu/fmi3_vdp.c`) built with -DOVERRUN_SENSITIVITY writes
/// two values past the `nSensitivity` values of `fmi3GetDirectionalDerivative`'s
/// `sensitivity`: the red zone after the master's buffer takes them, the note names the call
/// and the buffer in FMI 3.0 terms, and bdf differences the Jacobian from the first call on:
/// the rows equal those of the same FMU declaring `providesDirectionalDerivatives="false"`
/// bit for bit (the same differences at the same points).
#[test]
fn an_fmi3_directional_derivative_that_writes_past_sensitivity_is_caught_and_replaced_by_differences() {
    let xml = include_str!("cfmu/fmi3_vdp.xml");
    let without = xml.replace(r#"providesDirectionalDerivatives="true""#, r#"providesDirectionalDerivatives="false""#);
    let Some(plain) = common::fmi3_c::build(&work_dir("overrun3-fd"), "fmi3_vdp", &without) else { return };
    let overrun = common::fmi3_c::build_with(&work_dir("overrun3"), "fmi3_vdp", xml, &["OVERRUN_SENSITIVITY"]).unwrap();
    let run = run_vdp_under_bdf;
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let (differences, d) = run(&plain);
    assert!(d.notes.is_empty() && d.stiff.jacobians > 0, "{:?} {:?}", d.notes, d.stiff);
    let (got, s) = run(&overrun);
    assert_eq!(s.notes.len(), 1, "{:?}", s.notes);
    let note = &s.notes[0];
    assert!(
        note.starts_with("model: fmi3GetDirectionalDerivative ")
            && note.contains("wrote 16 bytes past the 16 bytes of sensitivity (nSensitivity = 2)"),
        "{note}"
    );
    assert!(note.ends_with("bdf uses finite differences for its Jacobian"), "{note}");
    assert_eq!(s.stiff.jacobians, d.stiff.jacobians);
    assert_eq!(bits(&got.values), bits(&differences.values));
}

/// Two van der Pol instances stepped in two threads, `bad` built with -DOVERRUN_OWN_BLOCK
/// (16 bytes past a block of its own at every directional derivative) and `good` without:
/// only `bad` is blamed (one note, naming it), and `good` keeps its own Jacobian: its rows
/// equal those of `good` run alone bit for bit (a Jacobian differenced instead would give
/// other rows), and bad's equal those of the FMU without directional derivatives.
#[test]
fn an_overrun_is_blamed_on_its_own_instance_only() {
    let bad = build_vdp_with_an_overrun(&work_dir("overrun-two-bad"), "-DOVERRUN_OWN_BLOCK");
    let good = build_vdp(&work_dir("overrun-two-good"));
    let plain = build_vdp_without_directional_derivatives(&work_dir("overrun-two-fd"));
    let experiment = |record: &[&str], threads: usize| {
        let mut e = Experiment::new(2.0, 0.01);
        e.solver = Solver::Bdf { rtol: 1e-6, atol: 1e-8 };
        e.record = Some(record.iter().map(|r| r.to_string()).collect());
        e.threads = threads;
        e
    };
    let mut b = nigel_cosim::SystemBuilder::new();
    b.add_instance("bad", Fmu::load(&bad).unwrap()).unwrap();
    b.add_instance("good", Fmu::load(&good).unwrap()).unwrap();
    let both = ["bad.x0", "bad.x1", "good.x0", "good.x1"];
    let (r, s) = simulate(&b.build(), &experiment(&both, 2)).unwrap();
    assert_eq!(s.notes.len(), 1, "{:?}", s.notes);
    assert!(
        s.notes[0].starts_with("bad: fmi2GetDirectionalDerivative wrote 16 bytes past the end of a block"),
        "{:?}",
        s.notes
    );
    let alone = |path: &std::path::Path| {
        let e = experiment(&["model.x0", "model.x1"], 1);
        simulate(&System::single("model", Fmu::load(path).unwrap()).unwrap(), &e).unwrap().0
    };
    let bits = |v: Vec<f64>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let (good_alone, bad_differenced) = (alone(&good), alone(&plain));
    for (column, (reference, name)) in
        [(&bad_differenced, "x0"), (&bad_differenced, "x1"), (&good_alone, "x0"), (&good_alone, "x1")]
            .into_iter()
            .enumerate()
    {
        assert_eq!(bits(r.column(both[column]).unwrap()), bits(reference.column(name).unwrap()), "{}", both[column]);
    }
}

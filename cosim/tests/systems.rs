//! Systems of C test FMUs: ordering, delays, connection checks, errors mid-run.

mod common;
use common::{build_fmu, build_fmu_with, work_dir, Model};
use nigel_cosim::{simulate, Algorithm, Error, Experiment, Fmu, Status, SystemBuilder, Value};

fn chain(dir: &std::path::Path) -> SystemBuilder {
    let mut b = SystemBuilder::new();
    b.add_instance("src", Fmu::load(&build_fmu(Model::Source, dir, &[])).unwrap()).unwrap();
    b.add_instance("amp", Fmu::load(&build_fmu(Model::Gain, dir, &[])).unwrap()).unwrap();
    b.add_instance("int", Fmu::load(&build_fmu(Model::Integrator, dir, &[])).unwrap()).unwrap();
    b.connect("src.y", "amp.u").unwrap();
    b.connect("amp.y", "int.u").unwrap();
    b
}

fn run(b: SystemBuilder, algorithm: Algorithm) -> nigel_cosim::Results {
    let system = b.build();
    let mut e = Experiment::new(1.0, 0.1);
    e.algorithm = algorithm;
    simulate(&system, &e).unwrap().0
}

#[test]
fn ordered_sees_sources_at_the_same_point_jacobi_one_step_later() {
    let dir = work_dir("ordered");
    let ordered = run(chain(&dir), Algorithm::Ordered);
    let jacobi = run(chain(&dir), Algorithm::Jacobi);
    assert_eq!(ordered.names, ["src.y", "amp.y", "int.x"]);
    assert_eq!(ordered.rows(), 11);
    let t = ordered.column("time").unwrap();
    // time is t0 + n h, not accumulated
    for (n, tn) in t.iter().enumerate() {
        assert_eq!(*tn, n as f64 * 0.1);
    }
    let (go, gj) = (ordered.column("amp.y").unwrap(), jacobi.column("amp.y").unwrap());
    let (xo, xj) = (ordered.column("int.x").unwrap(), jacobi.column("int.x").unwrap());
    // independent derivation: y = 2 t; x_n = sum_{k<n} 2 t_k (t_{k+1} - t_k) (the step the
    // master passes is the difference of the two communication points, as in fmpy)
    let (mut x, mut x_delayed) = (0.0, 0.0);
    for n in 0..t.len() {
        assert_eq!(go[n], 2.0 * t[n], "ordered: no delay at n = {n}");
        assert_eq!(xo[n], x, "ordered integral at n = {n}");
        if n + 1 < t.len() {
            x += 2.0 * t[n] * (t[n + 1] - t[n]);
        }
        if n >= 1 {
            assert_eq!(gj[n], 2.0 * t[n - 1], "jacobi: one step of delay at n = {n}");
            assert!((xj[n] - xo[n - 1]).abs() < 1e-15, "jacobi integral lags one step at n = {n}");
        }
        assert_eq!(xj[n], x_delayed, "jacobi integral at n = {n}");
        if n >= 1 && n + 1 < t.len() {
            x_delayed += 2.0 * t[n - 1] * (t[n + 1] - t[n]);
        }
    }
    assert_eq!(gj[0], 0.0);
    assert!((xo[10] - 0.9).abs() < 1e-12); // sum 2 * 0.1k * 0.1, k = 0..9 = 0.9
}

#[test]
fn algebraic_loop_is_named() {
    let dir = work_dir("loop");
    let gain = Fmu::load(&build_fmu(Model::Gain, &dir, &[])).unwrap();
    let mut b = SystemBuilder::new();
    b.add_instance("a", gain.clone()).unwrap();
    b.add_instance("b", gain).unwrap();
    b.connect("a.y", "b.u").unwrap();
    b.connect("b.y", "a.u").unwrap();
    let system = b.build();
    let mut e = Experiment::new(1.0, 0.5);
    e.algorithm = Algorithm::Ordered;
    match simulate(&system, &e) {
        Err(Error::AlgebraicLoop { variables }) => {
            for v in ["a.y", "b.u", "b.y", "a.u"] {
                assert!(variables.iter().any(|x| x == v), "{v} not in {variables:?}");
            }
            assert_eq!(variables.first(), variables.last(), "a closed loop: {variables:?}");
        }
        other => panic!("expected an algebraic loop, got {other:?}"),
    }
    // jacobi breaks the loop with its delay: a = 2 b(prev), all zero from zero
    e.algorithm = Algorithm::Jacobi;
    let (r, _) = simulate(&system, &e).unwrap();
    assert_eq!(r.column("a.y").unwrap(), vec![0.0, 0.0, 0.0]);
}

#[test]
fn connections_are_checked_for_causality_type_and_unit() {
    let dir = work_dir("checks");
    let mut b = chain(&dir);
    let err = |r: Result<&mut SystemBuilder, Error>| r.err().map(|e| e.to_string()).unwrap_or_default();
    assert!(err(b.connect("src.y", "amp.y")).contains("not an input"));
    assert!(err(b.connect("amp.u", "int.u")).contains("not an output"));
    assert!(err(b.connect("src.y", "int.u")).contains("already connected"));
    assert!(err(b.connect("src.nope", "int.u")).contains("no variable \"nope\""));
    assert!(err(b.connect("zz.y", "int.u")).contains("no instance \"zz\""));
    // units: metres into millimetres is a factor 1000; metres into m/s is refused
    let xml_mm =
        Model::Gain.model_description().replace(r#"<Real start="0" unit="m"/>"#, r#"<Real start="0" unit="mm"/>"#);
    let xml_ms =
        Model::Gain.model_description().replace(r#"<Real start="0" unit="m"/>"#, r#"<Real start="0" unit="m/s"/>"#);
    b.add_instance("g_mm", Fmu::load(&build_fmu_with(Model::Gain, &dir, "gain_mm", &xml_mm)).unwrap()).unwrap();
    b.add_instance("g_ms", Fmu::load(&build_fmu_with(Model::Gain, &dir, "gain_ms", &xml_ms)).unwrap()).unwrap();
    assert!(err(b.connect("src.y", "g_ms.u")).contains("different dimensions"));
    b.connect("src.y", "g_mm.u").unwrap();
    // start values: type and causality
    assert!(matches!(
        b.set("amp.k", Value::Boolean(true)),
        Err(Error::Import(nigel_cosim::ImportError::InvalidValue { .. }))
    ));
    assert!(matches!(b.set_text("amp.k", "abc"), Err(Error::Import(nigel_cosim::ImportError::InvalidValue { .. }))));
    assert!(matches!(b.set_text("amp.y", "1"), Err(Error::Import(nigel_cosim::ImportError::InvalidValue { .. }))));
    b.set_text("amp.k", "3").unwrap();
    let mut e = Experiment::new(0.5, 0.25);
    e.algorithm = Algorithm::Ordered;
    e.record = Some(vec!["g_mm.u".into(), "amp.y".into()]);
    let (r, _) = simulate(&b.build(), &e).unwrap();
    assert_eq!(r.column("g_mm.u").unwrap(), vec![0.0, 250.0, 500.0]);
    assert_eq!(r.column("amp.y").unwrap(), vec![0.0, 0.75, 1.5]);
}

#[test]
fn experiment_is_checked() {
    let dir = work_dir("experiment");
    let system = chain(&dir).build();
    for (stop, step, interval) in [(1.0, 0.0, None), (f64::NAN, 0.1, None), (1.0, 0.1, Some(0.15))] {
        let mut e = Experiment::new(stop, step);
        e.output_interval = interval;
        assert!(matches!(simulate(&system, &e), Err(Error::Experiment(_))), "{stop} {step} {interval:?}");
    }
    let mut e = Experiment::new(1.0, 0.1);
    e.output_interval = Some(0.5);
    let (r, _) = simulate(&system, &e).unwrap();
    assert_eq!(r.column("time").unwrap(), vec![0.0, 0.5, 1.0]);
    // not a whole number of steps: these FMUs can take a shorter last step, which ends
    // exactly at the stop time
    let (r, _) = simulate(&system, &Experiment::new(1.0, 0.3)).unwrap();
    assert_eq!(r.column("time").unwrap(), vec![0.0, 0.3, 0.6, 0.3 * 3.0, 1.0]);
    assert_eq!(r.column("src.y").unwrap().last(), Some(&1.0));
    // an FMU that cannot is named
    let fixed = Model::Gain.model_description().replace(
        r#"canHandleVariableCommunicationStepSize="true""#,
        r#"canHandleVariableCommunicationStepSize="false""#,
    );
    let mut b = SystemBuilder::new();
    b.add_instance("rigid", Fmu::load(&build_fmu_with(Model::Gain, &dir, "rigid", &fixed)).unwrap()).unwrap();
    match simulate(&b.build(), &Experiment::new(1.0, 0.3)) {
        Err(Error::Experiment(m)) => assert!(m.contains("rigid") && m.contains("canHandleVariable"), "{m}"),
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn an_fmu_failing_mid_run_gives_a_typed_error_naming_it() {
    let dir = work_dir("faulty");
    let fmu = Fmu::load(&build_fmu(Model::Faulty, &dir, &[])).unwrap();
    for (mode, status) in [(3.0, Status::Error), (2.0, Status::Discard)] {
        let mut b = SystemBuilder::new();
        b.add_instance("bad", fmu.clone()).unwrap();
        b.set("bad.mode", Value::Real(mode)).unwrap();
        match simulate(&b.build(), &Experiment::new(1.0, 0.25)) {
            Err(Error::Import(nigel_cosim::ImportError::Fmi { instance, function, status: s, time, log })) => {
                assert_eq!((instance.as_str(), function, s, time), ("bad", "fmi2DoStep", status, Some(0.5)));
                assert!(log.contains("failing on purpose at t = 0.5"), "{log}");
            }
            other => panic!("expected an fmi2DoStep error, got {other:?}"),
        }
    }
}

#[test]
fn a_library_without_do_step_is_refused_by_name() {
    let dir = work_dir("nodostep");
    let fmu = build_fmu(Model::Gain, &dir, &["-DOMIT_DOSTEP"]);
    match Fmu::load(&fmu) {
        Err(nigel_cosim::ImportError::MissingSymbol { symbol, .. }) => assert_eq!(symbol, "fmi2DoStep"),
        other => panic!("expected a missing symbol, got {other:?}"),
    }
}

#[test]
fn a_discarded_step_is_restored_and_retried_in_halves() {
    let dir = work_dir("discard");
    let fmu = Fmu::load(&build_fmu(Model::Faulty, &dir, &[])).unwrap();
    let mut b = SystemBuilder::new();
    b.add_instance("f", fmu).unwrap();
    b.set("f.mode", Value::Real(2.0)).unwrap();
    b.set("f.fail_time", Value::Real(10.0)).unwrap(); // never fails on time
    b.set("f.max_ok_step", Value::Real(0.03)).unwrap(); // 0.1 s steps are discarded
    let system = b.build();
    let mut e = Experiment::new(0.5, 0.1);
    // without retries: a clear error naming the Discard
    match simulate(&system, &e) {
        Err(Error::Import(nigel_cosim::ImportError::Fmi {
            status: Status::Discard,
            function: "fmi2DoStep",
            log,
            ..
        })) => {
            assert!(log.contains("discarded"), "{log}")
        }
        other => panic!("expected a Discard, got {other:?}"),
    }
    e.retry_discard = true;
    let (r, s) = simulate(&system, &e).unwrap();
    // each 0.1 s step: halves 0.05 (discarded again), quarters 0.025 (accepted): 1 + 2 retries
    assert_eq!(s.discard_retries, 5 * 3);
    // y = t, the FMU's own clock, reached every communication point
    let (t, y) = (r.column("time").unwrap(), r.column("y").unwrap());
    for (a, b) in t.iter().zip(&y) {
        assert!((a - b).abs() < 1e-15, "{a} vs {b}");
    }
}

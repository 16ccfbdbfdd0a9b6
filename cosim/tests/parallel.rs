//! `jacobi` with the instances stepped in several threads: the same numbers as in one
//! thread (bit for bit), errors typed as in one thread, and what FMI forbids refused.

mod common;
use common::{build_fmu, build_fmu_with, work_dir, Model};
use nigel_cosim::{simulate, Algorithm, Error, Experiment, Fmu, Results, Status, SystemBuilder, Value};

/// Ten chains src -> amp -> int side by side (30 instances), each source with its own slope.
fn wide(dir: &std::path::Path, chains: usize) -> nigel_cosim::System {
    let src = Fmu::load(&build_fmu(Model::Source, dir, &[])).unwrap();
    let amp = Fmu::load(&build_fmu(Model::Gain, dir, &[])).unwrap();
    let int = Fmu::load(&build_fmu(Model::Integrator, dir, &[])).unwrap();
    let mut b = SystemBuilder::new();
    for c in 0..chains {
        b.add_instance(&format!("src{c}"), src.clone()).unwrap();
        b.add_instance(&format!("amp{c}"), amp.clone()).unwrap();
        b.add_instance(&format!("int{c}"), int.clone()).unwrap();
        b.set(&format!("src{c}.slope"), Value::Real(1.0 + c as f64)).unwrap();
        b.connect(&format!("src{c}.y"), &format!("amp{c}.u")).unwrap();
        b.connect(&format!("amp{c}.y"), &format!("int{c}.u")).unwrap();
    }
    b.build()
}

/// The results and the number of steps the thread pool ran.
fn run_threads(system: &nigel_cosim::System, threads: usize, stop: f64, step: f64) -> (Results, u64) {
    let mut e = Experiment::new(stop, step);
    e.algorithm = Algorithm::Jacobi;
    e.threads = threads;
    let (r, s) = simulate(system, &e).unwrap();
    (r, s.parallel_steps)
}

#[test]
fn threads_give_the_serial_numbers_bit_for_bit_and_the_derived_values() {
    let dir = work_dir("parallel-wide");
    let system = wide(&dir, 10);
    // 2000 steps: the first 200 calibrate in one thread, then the pool runs at least
    // 1000 (it goes on only if it is faster than one thread)
    let (serial, pooled) = run_threads(&system, 1, 2.0, 1e-3);
    assert_eq!((serial.rows(), pooled), (2001, 0));
    for threads in [2, 3, 7, 64] {
        let (parallel, pooled) = run_threads(&system, threads, 2.0, 1e-3);
        assert!((1000..=1800).contains(&pooled), "threads {threads}: {pooled} steps in the pool");
        assert_eq!(parallel.names, serial.names);
        assert_eq!(parallel.values.len(), serial.values.len());
        for (k, (a, b)) in serial.values.iter().zip(&parallel.values).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "threads {threads}: value {k} differs");
        }
    }
    // and the values are the jacobi ones derived by hand: amp.y_n = 2 s t_(n-1),
    // int.x_n = sum_(1 <= k < n) 2 s t_(k-1) (t_(k+1) - t_k)
    let t = serial.column("time").unwrap();
    for c in [0usize, 9] {
        let s = 1.0 + c as f64;
        let g = serial.column(&format!("amp{c}.y")).unwrap();
        let x = serial.column(&format!("int{c}.x")).unwrap();
        let mut integral = 0.0;
        for n in 0..t.len() {
            let expected_gain = if n == 0 { 0.0 } else { 2.0 * s * t[n - 1] };
            assert_eq!(g[n], expected_gain, "chain {c}, n = {n}");
            assert_eq!(x[n], integral, "chain {c}, n = {n}");
            if n >= 1 && n + 1 < t.len() {
                integral += 2.0 * s * t[n - 1] * (t[n + 1] - t[n]);
            }
        }
    }
}

#[test]
fn the_closed_loop_in_two_threads_equals_one_thread() {
    let ssp = common::built_ssp("nigel_closed_loop.ssp");
    assert!(ssp.is_file(), "{} missing: run `cargo run --release -p build-fmu` first", ssp.display());
    let system = nigel_cosim::read_ssp(&ssp, &Default::default()).unwrap().system;
    let (serial, _) = run_threads(&system, 1, 1.0, 1e-3);
    let (parallel, pooled) = run_threads(&system, 2, 1.0, 1e-3);
    assert_eq!((serial.rows(), pooled), (1001, 800)); // 200 calibration steps, then the pool
    assert_eq!(serial.names, parallel.names);
    let moved = serial.column("plant.x").unwrap();
    assert!(moved[1000] > 0.1, "the car moves: x(1 s) = {}", moved[1000]);
    for (k, (a, b)) in serial.values.iter().zip(&parallel.values).enumerate() {
        assert_eq!(a.to_bits(), b.to_bits(), "value {k} ({}) differs", serial.names[k % serial.width()]);
    }
}

#[test]
fn an_error_in_a_worker_thread_is_typed_as_in_one_thread() {
    let dir = work_dir("parallel-faulty");
    let faulty = Fmu::load(&build_fmu(Model::Faulty, &dir, &[])).unwrap();
    let src = Fmu::load(&build_fmu(Model::Source, &dir, &[])).unwrap();
    for threads in [1, 2, 3] {
        let mut b = SystemBuilder::new();
        b.add_instance("a", src.clone()).unwrap();
        b.add_instance("b", src.clone()).unwrap();
        b.add_instance("bad", faulty.clone()).unwrap();
        b.set("bad.fail_time", Value::Real(0.5)).unwrap(); // step 500: in the pool
        let mut e = Experiment::new(1.0, 1e-3);
        e.threads = threads;
        match simulate(&b.build(), &e) {
            Err(Error::Import(nigel_cosim::ImportError::Fmi { instance, function, status, time, log })) => {
                assert_eq!((instance.as_str(), function, status), ("bad", "fmi2DoStep", Status::Error));
                // t_500 = 500 h: the first communication point at or after 0.5
                assert_eq!(time, Some(500.0 * 1e-3), "threads {threads}");
                assert!(log.contains("failing on purpose"), "{log}");
            }
            other => panic!("threads {threads}: expected fmi2DoStep Error, got {other:?}"),
        }
    }
    let mut e = Experiment::new(1.0, 0.1);
    e.threads = 0;
    let mut b = SystemBuilder::new();
    b.add_instance("a", src).unwrap();
    assert!(matches!(simulate(&b.build(), &e), Err(Error::Experiment(m)) if m.contains("threads")));
}

#[test]
fn an_fmu_instantiable_once_per_process_is_refused_twice() {
    let dir = work_dir("once");
    let xml = Model::Source.model_description().replace(
        "canHandleVariableCommunicationStepSize",
        "canBeInstantiatedOnlyOncePerProcess=\"true\" canHandleVariableCommunicationStepSize",
    );
    let fmu = Fmu::load(&build_fmu_with(Model::Source, &dir, "once", &xml)).unwrap();
    let mut b = SystemBuilder::new();
    b.add_instance("first", fmu.clone()).unwrap();
    let one = b.build();
    assert!(simulate(&one, &Experiment::new(0.1, 0.1)).is_ok(), "one instance is fine");
    let mut b = SystemBuilder::from_system(one);
    b.add_instance("second", fmu).unwrap();
    match simulate(&b.build(), &Experiment::new(0.1, 0.1)) {
        Err(Error::Experiment(m)) => {
            assert!(m.contains("first") && m.contains("second"), "{m}");
            assert!(m.contains("canBeInstantiatedOnlyOncePerProcess"), "{m}");
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
}

//! Clocked variables exchanged only at their clock's ticks (FMI 3.0: a clocked variable may
//! be read and set only while its clock is active), with a C test FMU that refuses any
//! other access (`tests/cfmu/fmi3_clocked_exchange.c`): the held values at every row
//! derived by hand below.
//!
//! The headers come from fmpy's package (`fmpy/c-code`), found with `$FMPY_PYTHON`
//! (default `python3`); without fmpy the tests are skipped, unless `$FMPY_PYTHON` is set.

mod common;
use common::work_dir;
use nigel_cosim::{simulate, Experiment, Fmu, ImportOptions, InputTable, Interface, System};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The test FMU built in `dir` with the description declaring `interface` (`None`: no
/// fmpy, skipped).
fn exchange_fmu(dir: &Path, interface: Interface) -> Option<PathBuf> {
    let xml = include_str!("cfmu/fmi3_clocked_exchange.xml");
    let cs = r#"<CoSimulation modelIdentifier="fmi3_clocked_exchange" hasEventMode="true" canHandleVariableCommunicationStepSize="true"/>"#;
    assert!(xml.contains(cs), "the description's CoSimulation element");
    let xml = match interface {
        Interface::CoSimulation => xml.to_string(),
        Interface::ModelExchange => xml.replace(cs, r#"<ModelExchange modelIdentifier="fmi3_clocked_exchange"/>"#),
        // a partition needs a priority
        Interface::ScheduledExecution => xml
            .replace(cs, r#"<ScheduledExecution modelIdentifier="fmi3_clocked_exchange"/>"#)
            .replace(r#"intervalDecimal="0.25"/>"#, r#"intervalDecimal="0.25" priority="0"/>"#),
    };
    common::fmi3_c::build(dir, "fmi3_clocked_exchange", &xml)
}

/// The system of the FMU loaded for `interface`, `u` from the input file of the tests
/// (`isolated`: the instance in a host process, `--isolate`).
fn run_exchange(path: &Path, interface: Interface, isolated: bool) -> nigel_cosim::Results {
    let options = ImportOptions { interface: Some(interface), ..ImportOptions::default() };
    let system = System::single("c", Fmu::load_with(path, &options).unwrap()).unwrap();
    let mut experiment = Experiment::new(1.0, 0.1);
    experiment.isolation = isolated.then(common::isolate_all);
    experiment.input = Some(Arc::new(
        InputTable::new(vec!["u".into()], vec![0.0, 0.2, 0.4, 0.7], vec![vec![0.0, 2.0, 4.0, 7.0]]).unwrap(),
    ));
    if interface == Interface::ScheduledExecution {
        let (results, outcome) = nigel_cosim::simulate::simulate_scheduled(&system, &experiment);
        outcome.unwrap();
        return results;
    }
    simulate(&system, &experiment).unwrap().0
}

/// The test FMU built in `work_dir(test)` for `interface`, run (in a host process when
/// `isolated`), its rows' held values checked ([`check_held`] with `open`); nothing without
/// fmpy.
fn assert_held_in(test: &str, interface: Interface, isolated: bool, open: bool) {
    let Some(path) = exchange_fmu(&work_dir(test), interface) else { return };
    check_held(&run_exchange(&path, interface, isolated), open);
}

/// The held values of the test below at each row. `open`: the row at a tick (the start
/// time's too) is recorded with the tick's event open (Co-Simulation, docs/clocks.md), where this
/// FMU answers the tick's y (it computes y in fmi3SetClock and again on a set of u while
/// active), the tick at the stop time (k = 5, y = 10·7 + 5 = 75) opened for the last row;
/// else (Model Exchange) a row holds the values before the ticks at its time: y of the last
/// tick before it, except at the start time, whose tick is activated in the Event Mode that
/// ends initialization (docs/clocks.md): the row at 0 s holds y_1 = 1.
fn check_held(results: &nigel_cosim::Results, open: bool) {
    let time = results.column("time").unwrap();
    let y = results.column("y").unwrap();
    let t_now = results.column("t_now").unwrap();
    let ticks = [(0.0, 1.0), (0.25, 22.0), (0.5, 43.0), (0.75, 74.0), (1.0, 75.0)];
    // rows at the points 0, 0.1, ..., 1 s and at the ticks between points, 0.25 and 0.75 s
    assert_eq!(time.len(), 13, "{time:?}");
    for ((t, y), t_now) in time.iter().zip(&y).zip(&t_now) {
        // ticks and points differ by ulps at most: 1e-9 s apart
        let before = |tick: f64| if open || tick == 0.0 { tick < t + 1e-9 } else { tick < t - 1e-9 };
        let expected = ticks.iter().rev().find(|(tick, _)| before(*tick)).map_or(-1.0, |(_, y)| *y);
        assert_eq!(*y, expected, "y at t = {t} s");
        // the variable that is not clocked is read at every row: the FMU's time, the sum of
        // the master's step starts and sizes, within ulps of the row's t0 + n h
        assert!((t_now - t).abs() < 1e-12, "t_now {t_now} at t = {t} s");
    }
}

/// A run from 0 to 1 s with steps of 0.1 s, `u` from an input file: a discrete input, held
/// from each row (0 from 0 s, 2 from 0.2 s, 4 from 0.4 s, 7 from 0.7 s).
///
/// `tick` ticks at 0, 0.25, 0.5, 0.75 s (interval 0.25 s, shift 0; the tick at the stop
/// time 1 s is opened for the last row only). At the k-th tick τ_k the master applies the
/// last set of `u` (the input file's value at τ_k: 0, 2, 4, 7) and reads y = 10 u + k, held
/// until the next tick: y_1 = 10·0 + 1 = 1, y_2 = 10·2 + 2 = 22, y_3 = 10·4 + 3 = 43, y_4 =
/// 10·7 + 4 = 74 (y_5 = 75 at the stop). The sets of `u` between ticks are queued (the FMU
/// refuses them). A row at a tick, the one at 0 s included, is recorded with its event open,
/// where the FMU answers the tick's y (y_1 = 1 at 0 s); a row between ticks the y of the
/// last tick before it (`check_held`).
#[test]
fn clocked_variables_are_held_between_ticks_and_set_at_them() {
    assert_held_in("clocked-exchange", Interface::CoSimulation, false, true);
}

/// The same with the instance in a host process (`--isolate`): `fmi3SetClock`, the
/// intervals, `fmi3UpdateDiscreteStates` and the clocked sets and gets cross the process
/// boundary in the order they are made in process (a set queued for the next call goes
/// with it, so the clocked input set after `fmi3SetClock` reaches the FMU while its clock
/// is active, and the FMU refuses it otherwise): the same held values, in Co-Simulation and
/// Model Exchange.
#[test]
fn isolated_instances_exchange_clocked_variables_at_their_ticks_only() {
    for (interface, open) in [(Interface::CoSimulation, true), (Interface::ModelExchange, false)] {
        assert_held_in(&format!("clocked-exchange-isolated-{interface:?}"), interface, true, open);
    }
}

/// The same in Model Exchange (the instance integrated on its own, no states): the ticks
/// run in events between fmi3EnterEventMode and fmi3EnterContinuousTimeMode, the same rows
/// and held values as derived above.
#[test]
fn model_exchange_exchanges_clocked_variables_at_their_ticks_only() {
    assert_held_in("clocked-exchange-me", Interface::ModelExchange, false, false);
}

/// The same in Scheduled Execution: `u` set once before each fmi3ActivateModelPartition of
/// tick (the input file's value at the tick: 0, 2, 4, 7), y read right after it. The rows
/// are at the ticks 0, 0.25, 0.5, 0.75 s and the stop time 1 s and hold the values after
/// the activations: y = 1, 22, 43, 74, then 74 held (derived above). t_now is the
/// activation's time.
#[test]
fn scheduled_execution_exchanges_clocked_variables_at_their_activations_only() {
    let dir = work_dir("clocked-exchange-se");
    let Some(path) = exchange_fmu(&dir, Interface::ScheduledExecution) else { return };
    let results = run_exchange(&path, Interface::ScheduledExecution, false);
    assert_eq!(results.column("time").unwrap(), [0.0, 0.25, 0.5, 0.75, 1.0]);
    assert_eq!(results.column("y").unwrap(), [1.0, 22.0, 43.0, 74.0, 74.0]);
    assert_eq!(results.column("t_now").unwrap(), [0.0, 0.25, 0.5, 0.75, 0.75]);
    assert_eq!(results.column("tick").unwrap(), [1.0, 1.0, 1.0, 1.0, 0.0]);
}

/// Scheduled Execution with isolation is refused, saying why (the FMU calls the scheduler
/// back from inside `fmi3ActivateModelPartition`, which a host process cannot carry): in the
/// library, and by `cosim run --isolate` and `--isolate=run`, exit code 1 before any call.
#[test]
fn scheduled_execution_with_isolation_is_refused_saying_why() {
    let dir = work_dir("clocked-exchange-se-isolated");
    let Some(path) = exchange_fmu(&dir, Interface::ScheduledExecution) else { return };
    let options = ImportOptions { interface: Some(Interface::ScheduledExecution), ..ImportOptions::default() };
    let system = System::single("c", Fmu::load_with(&path, &options).unwrap()).unwrap();
    let mut experiment = Experiment::new(1.0, 0.1);
    experiment.isolation = Some(common::isolate_all());
    let e = nigel_cosim::simulate::simulate_scheduled(&system, &experiment).1.unwrap_err().to_string();
    assert!(e.contains("clockUpdate") && e.contains("leave out --isolate"), "{e}");
    for flag in ["--isolate", "--isolate=run"] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_cosim"))
            .arg("run")
            .arg(&path)
            .args(["--interface", "se", "--stop-time", "1", flag])
            .env("NIGEL_COSIM_HOST", env!("CARGO_BIN_EXE_cosim-host"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{flag}: {stderr}");
        assert!(stderr.contains("Scheduled Execution is run in process only"), "{flag}: {stderr}");
    }
}

/// A tick of a periodic clock that resets a continuous state (`tests/cfmu/fmi3_sawtooth.c`:
/// x' = 1, each tick of `sample` sets x = 0 and says valuesOfContinuousStatesChanged), run
/// in Model Exchange from 0 to 1 s with steps of 0.1 s under every solver: the integrator
/// starts again from the state the FMU gives after each tick. The ticks are at 0, 0.25, 0.5,
/// 0.75 s (and 1 s, the stop time), so x at a row between ticks is the time since the last
/// tick: 0.1, 0.2 at 0.1, 0.2 s; 0.05, 0.15 at 0.3, 0.4 s; 0.1, 0.2 at 0.6, 0.7 s; 0.05,
/// 0.15 at 0.8, 0.9 s; a row at a tick holds the value before it (0.25; docs/clocks.md),
/// the row at 0 s the start value 0. Integrated on from its own state instead, x would be
/// the time itself (0.3 at 0.3 s). `resets` counts the ticks before the row (the start
/// tick's at 0 s included). x' is constant, so every method is exact up to the rounding of
/// the sums of step sizes: 1e-12.
#[test]
fn a_tick_that_resets_a_state_restarts_the_integrator_from_it() {
    let dir = work_dir("clocked-sawtooth");
    let Some(path) = common::fmi3_c::build(&dir, "fmi3_sawtooth", include_str!("cfmu/fmi3_sawtooth.xml")) else {
        return;
    };
    let solvers = [
        nigel_cosim::Solver::Rk4 { max_step: None },
        nigel_cosim::Solver::Dopri5 { rtol: 1e-6, atol: 1e-8 },
        nigel_cosim::Solver::Bdf { rtol: 1e-6, atol: 1e-8 },
    ];
    for solver in solvers {
        let system = System::single("s", Fmu::load(&path).unwrap()).unwrap();
        let mut experiment = Experiment::new(1.0, 0.1);
        experiment.solver = solver;
        let results = simulate(&system, &experiment).unwrap().0;
        let time = results.column("time").unwrap();
        let x = results.column("x").unwrap();
        let resets = results.column("resets").unwrap();
        // the points 0, 0.1, ..., 1 s and the ticks between points, 0.25 and 0.75 s
        assert_eq!(time.len(), 13, "{solver:?}: {time:?}");
        let ticks = [0.0, 0.25, 0.5, 0.75, 1.0];
        for ((t, x), n) in time.iter().zip(&x).zip(&resets) {
            // the last tick before the row (the start tick at the row at 0 s); ticks and
            // points differ by ulps at most
            let before: Vec<f64> = ticks.iter().copied().filter(|tick| *tick == 0.0 || *tick < t - 1e-9).collect();
            let last = *before.last().unwrap();
            let expected = if *t < 1e-9 { 0.0 } else { t - last };
            assert!((x - expected).abs() < 1e-12, "{solver:?}: x = {x} at t = {t} s, expected {expected}");
            assert_eq!(*n, before.len() as f64, "{solver:?}: resets at t = {t} s");
        }
    }
}

//! Our FMI 3.0 closed loop (target/ssp, built by build-fmu), whose controller declares its
//! sample clock (`sample_clock`, a periodic input clock of 1 ms, ticking at every
//! communication point), with its instances in host processes
//! (`--isolate`, `--isolate=run`) and stepped in threads (`--threads 2`): the clock calls
//! (`fmi3SetClock`, the intervals, `fmi3UpdateDiscreteStates`, `fmi3EnterStepMode`) cross
//! the process boundary in the order they are made in process, and the thread pool opens
//! and closes the clock events in each instance's steps as one thread does, so the results
//! are the in-process single-thread run's bit for bit (which tests/tests/fmi3_closed_loop.rs
//! holds to the FMI 2.0 closed loop's bits).

mod common;
use nigel_cosim::{read_ssp, simulate, Algorithm, Experiment, Results};
use std::path::PathBuf;
use std::process::Command;

/// The clocked closed loop's SSP, built by the test command.
fn clocked_ssp() -> PathBuf {
    common::built_ssp("nigel_closed_loop_fmi3.ssp")
}

/// `b` equals `a` in every bit: the same columns and rows, no value that differs.
fn assert_same_bits(a: &Results, b: &Results, what: &str) {
    assert_eq!((a.rows(), &a.names), (b.rows(), &b.names), "{what}");
    let width = a.width();
    let first = a.values.iter().zip(&b.values).position(|(x, y)| x.to_bits() != y.to_bits());
    let name = |i: usize| if i.is_multiple_of(width) { "time".to_string() } else { a.names[i % width - 1].clone() };
    assert_eq!(first.map(|i| (name(i), i / width)), None, "{what}: (column, row) of the first value that differs");
}

/// 1 s of the loop under jacobi and ordered, every instance in a host process of its own:
/// the in-process run's values and ticks (1001: every point of the 1 s, the stop included).
#[test]
fn the_isolated_clocked_loop_is_the_in_process_one_bit_for_bit() {
    let system = read_ssp(&clocked_ssp(), &Default::default()).unwrap().system;
    for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
        let mut e = Experiment::new(1.0, 1e-3);
        e.algorithm = algorithm;
        let (local, local_summary) = simulate(&system, &e).unwrap();
        e.isolation = Some(common::isolate_all());
        let (isolated, summary) = simulate(&system, &e).unwrap();
        assert_eq!(local_summary.clock_ticks, vec![("controller.sample_clock".to_string(), 1001)], "{algorithm:?}");
        assert_eq!(summary.clock_ticks, local_summary.clock_ticks, "{algorithm:?}");
        assert_same_bits(&local, &isolated, &format!("{algorithm:?} isolated"));
    }
}

/// 2 s of the loop under jacobi in two threads: the first 200 steps calibrate in one thread,
/// then the pool runs at least 1000 (it goes on only while it is faster than one thread):
/// the single-thread run's values and ticks.
#[test]
fn the_clocked_loop_in_two_threads_is_the_single_thread_one_bit_for_bit() {
    let system = read_ssp(&clocked_ssp(), &Default::default()).unwrap().system;
    let mut e = Experiment::new(2.0, 1e-3);
    e.algorithm = Algorithm::Jacobi;
    let (serial, serial_summary) = simulate(&system, &e).unwrap();
    e.threads = 2;
    let (parallel, summary) = simulate(&system, &e).unwrap();
    assert!(summary.parallel_steps >= 1000, "{} steps in the pool", summary.parallel_steps);
    assert_eq!(serial_summary.clock_ticks, vec![("controller.sample_clock".to_string(), 2001)]);
    assert_eq!(summary.clock_ticks, serial_summary.clock_ticks);
    assert_same_bits(&serial, &parallel, "two threads");
}

/// `cosim run` of the loop in process, with `--isolate` (a host per FMU), `--isolate=run`
/// (the whole run in one host) and `--threads 2`: the same CSV, byte for byte, and the same
/// tick count in the summary.
#[test]
fn cosim_run_writes_the_same_clocked_loop_isolated_and_in_threads() {
    let dir = common::work_dir("clocked-loop-cli");
    let run = |name: &str, extra: &[&str]| -> (String, String) {
        let (csv, summary) = (dir.join(format!("{name}.csv")), dir.join(format!("{name}.json")));
        let out = Command::new(env!("CARGO_BIN_EXE_cosim"))
            .arg("run")
            .arg(clocked_ssp())
            .args(["--stop-time", "0.5", "--step", "1e-3", "--algorithm", "jacobi"])
            .args(extra)
            .arg("-o")
            .arg(&csv)
            .arg("--summary")
            .arg(&summary)
            .env("NIGEL_COSIM_HOST", env!("CARGO_BIN_EXE_cosim-host"))
            .output()
            .unwrap();
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
        (std::fs::read_to_string(&csv).unwrap(), summary["clock_ticks"].to_string())
    };
    let (plain, ticks) = run("plain", &[]);
    assert_eq!(plain.lines().count(), 502, "the header and the 501 points of 0.5 s");
    assert!(ticks.contains("501"), "{ticks}");
    for (name, extra) in [("fmu", &["--isolate"][..]), ("run", &["--isolate=run"]), ("threads", &["--threads", "2"])] {
        let (csv, t) = run(name, extra);
        assert!(csv == plain, "{name}: the CSV differs from the in-process run's");
        assert_eq!(t, ticks, "{name}");
    }
}

/// The controller alone in Model Exchange (`--interface me`, steps of 0.5 ms, so its 1 ms
/// ticks fall on every other communication point), inputs from a file: the FMI 3.0 archive
/// publishes each next activation as `nextEventTime`, which cosim takes as that tick's event
/// (one sample per tick: 20 ticks, at 0, 1, ..., 19 ms; the one at the stop time would run
/// at the start of a step after it, which the run does not take), and the tick at the start
/// time is activated in the event that ends initialization (else the FMU would sample by
/// time events from there and refuse the later fmi3SetClock, failing the run). Each tick
/// samples with the inputs of its time, as the same archive in Co-Simulation does (whose
/// clocked loop is the FMI 2.0 one's to the bit: tests/tests/fmi3_closed_loop.rs): cosim
/// runs a Model Exchange tick at the start of the step from it, a Co-Simulation tick at the
/// end of the step reaching it (docs/clocks.md), so the rows agree at the start and between
/// ticks (t_k + 0.5 ms), where both hold sample k.
#[test]
fn the_clocked_controller_in_model_exchange_samples_once_per_tick_as_in_co_simulation() {
    let dir = common::work_dir("clocked-controller-me");
    let input = dir.join("input.csv");
    let mut text = String::from("time,beta,yaw_rate,speed,yaw_rate_ref\n");
    for i in 0..=40 {
        let t = i as f64 * 5e-4;
        let s = (70.0 * t).sin();
        text += &format!("{t:?},{:?},{:?},{:?},{:?}\n", 0.02 * s, 0.3 * (30.0 * t).cos(), 0.2 + 5.0 * t, 0.1 * s);
    }
    std::fs::write(&input, text).unwrap();
    let fmu = common::target_dir().join("fmu").join("fmi3").join("nigel_controller.fmu");
    let run = |interface: &str| -> (Vec<Vec<f64>>, String) {
        let (csv, summary) = (dir.join(format!("{interface}.csv")), dir.join(format!("{interface}.json")));
        let args = ["--interface", interface, "--stop-time", "0.02", "--step", "5e-4"];
        let out = common::cosim_run_with_input(&fmu, &args, &input, &csv, &summary);
        assert!(out.status.success(), "{interface}: {}", String::from_utf8_lossy(&out.stderr));
        let rows = std::fs::read_to_string(&csv)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect())
            .collect();
        let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
        (rows, summary["clock_ticks"].to_string())
    };
    let (me, me_ticks) = run("me");
    let (cs, cs_ticks) = run("cs");
    assert_eq!(me_ticks, r#"[{"clock":"sample_clock","ticks":20}]"#);
    assert_eq!(cs_ticks, r#"[{"clock":"sample_clock","ticks":21}]"#, "Co-Simulation: the stop time's tick too");
    assert_eq!((me.len(), cs.len()), (41, 41));
    let bits = |row: &Vec<f64>| row.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for r in (0..41).filter(|r| *r == 0 || r % 2 == 1) {
        assert_eq!(bits(&me[r]), bits(&cs[r]), "row {r} (t = {} s)", cs[r][0]);
    }
    // the law did something: the steering moved from sample to sample
    assert!(me.iter().any(|row| (row[1] - me[0][1]).abs() > 1e-3));
}

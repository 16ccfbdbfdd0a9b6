//! FMI 3.0 Scheduled Execution (`cosim run --interface se`): the C FMU
//! `tests/cfmu/fmi3_partitions.c` (two periodic partitions of different priority, a
//! countdown clock the slower one sets, a triggered clock from an input file, an output
//! clock) against tick times derived by hand, and the Reference FMUs' `Clocks` of the
//! corpus running the scenario its `model.c` documents, when the corpus is there.

mod common;
use common::fmi3_c::corpus;
use common::work_dir;
use nigel_cosim::simulate::{simulate_scheduled, InputTable};
use nigel_cosim::{Experiment, Fmu, ImportOptions, Interface, SystemBuilder};
use std::path::Path;
use std::process::Command;
use std::sync::Arc;

/// The description of tests/cfmu/fmi3_partitions.c.
const XML: &str = include_str!("cfmu/fmi3_partitions.xml");

/// The run to 2 s with `kick` at 0.25 and 1 s and u = 2 from 1 s (an input file).
fn run(fmu: &Path) -> nigel_cosim::Results {
    let options = ImportOptions { interface: Some(Interface::ScheduledExecution), ..ImportOptions::default() };
    let mut b = SystemBuilder::new();
    b.add_instance("p", Fmu::load_with(fmu, &options).unwrap()).unwrap();
    let system = b.build();
    let mut experiment = Experiment::new(2.0, 0.25);
    let table = InputTable::new(
        vec!["kick".into(), "u".into()],
        vec![0.0, 0.25, 0.5, 1.0],
        vec![vec![0.0, 1.0, 0.0, 1.0], vec![1.0, 1.0, 1.0, 2.0]],
    )
    .unwrap();
    experiment.input = Some(Arc::new(table));
    let (results, outcome) = simulate_scheduled(&system, &experiment);
    let summary = outcome.unwrap();
    assert_eq!(
        summary.notes,
        [
            "Scheduled Execution: partitions activated: fast 8, slow 2, later 2, kick 2",
            "Scheduled Execution: output clocks ticked: out 2"
        ]
    );
    results
}

/// The ticks, derived by hand: fast every 0.25 s from 0 (0, 0.25, ..., 1.75: 8 in [0, 2)),
/// slow at 0.5 and 1.5, later 0.125 s after each slow (0.625, 1.625: the countdown slow
/// sets), kick at 0.25 and 1 (the file's nonzero rows), out at fast's 4th and 8th
/// activations (0.75, 1.75). At 0.5 and 1.5 slow (priority 0) runs before fast (priority
/// 1): `first` is slow's value reference 2 there. x adds u * 0.25 per fast tick, u = 1
/// before 1 s and 2 from it (set before the activations at 1 s): 0.25 k for the first four,
/// then 1 + 0.5 (k - 4); exact in binary. One row per tick time and one at the stop time.
#[test]
fn partitions_tick_in_priority_order_with_countdown_triggered_and_output_clocks() {
    let dir = work_dir("fmi3-scheduled");
    let Some(fmu) = common::fmi3_c::build(&dir, "fmi3_partitions", XML) else { return };
    let r = run(&fmu);
    let col = |n: &str| r.column(n).unwrap_or_else(|| panic!("column {n}"));
    assert_eq!(col("time"), [0.0, 0.25, 0.5, 0.625, 0.75, 1.0, 1.25, 1.5, 1.625, 1.75, 2.0]);
    assert_eq!(col("n_fast"), [1.0, 2.0, 3.0, 3.0, 4.0, 5.0, 6.0, 7.0, 7.0, 8.0, 8.0]);
    assert_eq!(col("n_slow"), [0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0]);
    assert_eq!(col("n_later"), [0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0]);
    assert_eq!(col("n_kick"), [0.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0]);
    assert_eq!(col("first"), [1.0, 1.0, 2.0, 3.0, 1.0, 1.0, 1.0, 2.0, 3.0, 1.0, 1.0]);
    assert_eq!(col("t_later"), [0.0, 0.0, 0.0, 0.625, 0.625, 0.625, 0.625, 0.625, 1.625, 1.625, 1.625]);
    assert_eq!(col("x"), [0.25, 0.5, 0.75, 0.75, 1.0, 1.5, 2.0, 2.5, 2.5, 3.0, 3.0]);
    // the clock columns: 1 at the rows where the clock ticked
    assert_eq!(col("fast"), [1.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 1.0, 0.0]);
    assert_eq!(col("later"), [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
    assert_eq!(col("out"), [0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    // deterministic: a second run is the same, bit for bit
    assert_eq!(run(&fmu).values, r.values);
    let info = Command::new(env!("CARGO_BIN_EXE_cosim")).args(["info", fmu.to_str().unwrap()]).output().unwrap();
    let info = String::from_utf8_lossy(&info.stdout);
    let partitions: Vec<&str> = info.lines().filter(|l| l.starts_with("model partition ")).collect();
    assert_eq!(
        partitions,
        [
            "model partition fast (clock, priority 1): ticks every 0.25 s from 0 s; run with --interface se",
            "model partition slow (clock, priority 0): ticks every 1 s from 0.5 s; run with --interface se",
            "model partition later (clock, priority 2): ticks countdown (set by the FMU); run with --interface se",
            "model partition kick (clock, priority 3): ticks triggered (an input file's clock column); run with --interface se",
        ]
    );
}

/// The Reference FMUs' `Clocks` (Scheduled Execution only) through `cosim run --interface
/// se` with inClock2 from an input file at 0, 1, 8 and 9 s, the scenario its model.c
/// documents: inClock1 every second (10 ticks in [0, 10)), inClock3 counted down from
/// inClock1's partition at 4 s; at 9 s (and the stop row, 10 s) inClock1Ticks 10,
/// inClock2Ticks 4, inClock3Ticks 1, totalInClockTicks 15. Skipped without the corpus.
#[test]
fn the_reference_clocks_fmu_runs_the_scenario_its_model_documents() {
    let fmu = corpus().join("fmi3/cs/ReferenceFMUs-0.0.41-src/Clocks/Clocks.fmu");
    if !fmu.is_file() {
        eprintln!("{} not there: skipped", fmu.display());
        return;
    }
    let dir = work_dir("fmi3-scheduled-clocks");
    let input = dir.join("in.csv");
    std::fs::write(&input, "time,inClock2\n0,1\n1,1\n2,0\n8,1\n9,1\n").unwrap();
    let csv = dir.join("out.csv");
    let (header, rows) = common::run_to_csv(
        Command::new(env!("CARGO_BIN_EXE_cosim"))
            .args(["run", fmu.to_str().unwrap(), "--interface", "se", "--stop-time", "10", "--input"])
            .arg(&input)
            .arg("-o")
            .arg(&csv),
        &csv,
    );
    let at = |t: f64, name: &str| {
        let j = header.iter().position(|h| h == name).unwrap();
        rows.iter().find(|r| r[0] == t).unwrap()[j]
    };
    let times: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(times, (0..=10).map(f64::from).collect::<Vec<_>>());
    for t in [9.0, 10.0] {
        let counts = ["inClock1Ticks", "inClock2Ticks", "inClock3Ticks", "totalInClockTicks"].map(|n| at(t, n));
        assert_eq!(counts, [10.0, 4.0, 1.0, 15.0], "t = {t}");
    }
    // inClock3 ticked at 4 s only (counted down, 0 s, from inClock1's partition at 4 s)
    assert_eq!(rows.iter().filter(|r| at(r[0], "inClock3") == 1.0).map(|r| r[0]).collect::<Vec<_>>(), [4.0]);
}

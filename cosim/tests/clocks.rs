//! FMI 3.0 clocks in Co-Simulation with Event Mode, with a C test FMU that counts the ticks
//! of one input clock of every kind and of an output clock (`tests/cfmu/fmi3_clocks.c`; its
//! comment says when each clock ticks): the tick times derived by hand below, against the
//! counts the FMU reports at every communication point and the run's summary.
//!
//! The headers come from fmpy's package (`fmpy/c-code`), found with `$FMPY_PYTHON`
//! (default `python3`); without fmpy the tests are skipped, unless `$FMPY_PYTHON` is set.

mod common;
use common::{work_dir, zip_entries};
use nigel_cosim::{simulate, Experiment, Fmu, InputTable, System, SystemBuilder};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

/// `fmi3_clocks.fmu` built in `dir` (`None`: no fmpy, skipped).
fn clocks_fmu(dir: &Path) -> Option<PathBuf> {
    common::fmi3_c::build(dir, "fmi3_clocks", include_str!("cfmu/fmi3_clocks.xml"))
}

/// The tick times of each clock in a run from 0 to 1.5 s with steps of 0.1 s and `trig`
/// ticked by an input file at 0.45 and 1.2 s, derived by hand from the FMU's comment. A
/// tick at the stop time is opened for the last row (docs/clocks.md).
///
/// - periodic: shift 0.1 + k 0.25 = 0.1, 0.35, 0.6, 0.85, 1.1, 1.35;
/// - fixed: 0 + k 0.4 (the FMU's interval, not the description's 0.5) = 0, 0.4, 0.8, 1.2;
/// - changing: intervals 0.1, 0.2, 0.3, 0.4, 0.5 from 0 = 0.1, 0.3, 0.6, 1.0, 1.5 (the stop);
/// - countdown: started at periodic's second tick (0.35) with 0.5 = 0.85;
/// - trig: 0.45, 1.2 (the input file);
/// - out_clock: in the events of periodic's 2nd, 4th, 6th ticks = 0.35, 0.85, 1.35.
const TICKS: [(&str, &[f64]); 6] = [
    ("n_periodic", &[0.1, 0.35, 0.6, 0.85, 1.1, 1.35]),
    ("n_fixed", &[0.0, 0.4, 0.8, 1.2]),
    ("n_changing", &[0.1, 0.3, 0.6, 1.0, 1.5]),
    ("n_countdown", &[0.85]),
    ("n_trig", &[0.45, 1.2]),
    ("n_out_clock", &[0.35, 0.85, 1.35]),
];

#[test]
fn every_kind_of_clock_ticks_at_its_times() {
    let dir = work_dir("clocks-kinds");
    let Some(path) = clocks_fmu(&dir) else { return };
    every_kind_ticks_at_its_times(&path, None);
}

/// The same with the instance in a host process (`--isolate`): every clock call
/// (`fmi3SetClock`, `fmi3GetClock`, `fmi3GetIntervalDecimal`, `fmi3GetShiftDecimal`, the
/// event's calls) crosses the process boundary, the same counts at every row.
#[test]
fn every_kind_of_clock_ticks_at_its_times_in_a_host_process() {
    let dir = work_dir("clocks-kinds-isolated");
    let Some(path) = clocks_fmu(&dir) else { return };
    every_kind_ticks_at_its_times(&path, Some(common::isolate_all()));
}

/// The same FMU built with `FMI3_FRACTION_ONLY`: it gives its intervals only as fractions
/// (`fmi3GetIntervalFraction`: periodic 1/4, fixed 400/1000, changing k/10, countdown 1/2)
/// and exports no `fmi3GetIntervalDecimal` (nor `fmi3GetShiftDecimal`), so the master takes
/// each interval as counter / resolution: the same hand-derived ticks (the counts are of
/// ticks within 1e-9 s of a row, so 3/10 for 0.1 * 3, an ulp apart, changes no count), in
/// process and in a host process.
#[test]
fn every_kind_of_clock_ticks_at_its_times_from_fractional_intervals() {
    let dir = work_dir("clocks-kinds-fraction");
    let xml = include_str!("cfmu/fmi3_clocks.xml");
    let Some(path) = common::fmi3_c::build_with(&dir, "fmi3_clocks", xml, &["FMI3_FRACTION_ONLY"]) else { return };
    // the library names no fmi3GetIntervalDecimal (its symbol table holds every name it
    // exports), but fmi3GetIntervalFraction
    let so = std::fs::read(dir.join("fmi3_clocks.so")).unwrap();
    let names = |name: &str| so.windows(name.len()).any(|w| w == name.as_bytes());
    assert!(!names("fmi3GetIntervalDecimal") && names("fmi3GetIntervalFraction"));
    every_kind_ticks_at_its_times(&path, None);
    every_kind_ticks_at_its_times(&path, Some(common::isolate_all()));
}

/// The FMU at `path` alone from 0 to 1.5 s in steps of 0.1 s with `trig` ticked by an input
/// table at 0.45 and 1.2 s (the clock column: 1 at the times trig ticks, 0 elsewhere), with
/// `isolation`.
fn run_with_trig(
    path: &Path,
    isolation: Option<nigel_cosim::Isolation>,
) -> (nigel_cosim::Results, nigel_cosim::Summary) {
    let system = System::single("c", Fmu::load(path).unwrap()).unwrap();
    let mut experiment = Experiment::new(1.5, 0.1);
    experiment.isolation = isolation;
    experiment.input = Some(Arc::new(
        InputTable::new(vec!["trig".into()], vec![0.0, 0.45, 0.5, 1.2, 1.3], vec![vec![0.0, 1.0, 0.0, 1.0, 0.0]])
            .unwrap(),
    ));
    simulate(&system, &experiment).unwrap()
}

fn every_kind_ticks_at_its_times(path: &Path, isolation: Option<nigel_cosim::Isolation>) {
    let (results, summary) = run_with_trig(path, isolation);
    let time = results.column("time").unwrap();
    // rows at the points 0, 0.1, ..., 1.5 s and at the ticks between points: 0.35, 0.85,
    // 1.35 (periodic) and 0.45 (trig)
    assert_eq!(time.len(), 20, "{time:?}");
    for tick in [0.35, 0.45, 0.85, 1.35] {
        assert!(time.contains(&tick), "a row at the tick {tick} s: {time:?}");
    }
    for (name, ticks) in TICKS {
        let counts = results.column(name).unwrap();
        for (t, n) in time.iter().zip(&counts) {
            // the row at a point is recorded with the event of the ticks at it open (the
            // start time's too): this FMU counts a tick in fmi3SetClock, so the row counts the
            // ticks up to it (times differ from the points' t0 + n h by ulps at most: 1e-9 s
            // apart)
            let expected = ticks.iter().filter(|tick| **tick < t + 1e-9).count() as f64;
            assert_eq!(*n, expected, "{name} at t = {t} s: ticks {ticks:?}");
        }
    }
    let last_tick = results.column("last_tick").unwrap();
    assert_eq!(
        *last_tick.last().unwrap(),
        1.5,
        "changing's last tick, at the stop time: 0.1 + 0.2 + 0.3 + 0.4 + 0.5 s"
    );
    let counted: Vec<(String, u64)> = summary.clock_ticks.clone();
    assert_eq!(
        counted,
        [("periodic", 6), ("fixed", 4), ("changing", 5), ("countdown", 1), ("trig", 2), ("out_clock", 3)]
            .map(|(n, k)| (n.to_string(), k))
    );
}

#[test]
fn cosim_info_lists_the_clocks() {
    let dir = work_dir("clocks-info");
    let Some(path) = clocks_fmu(&dir) else { return };
    let out = Command::new(env!("CARGO_BIN_EXE_cosim")).arg("info").arg(&path).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let clocks: Vec<&str> = text.lines().skip_while(|l| *l != "clocks:").skip(1).take(6).collect();
    assert_eq!(
        clocks[0].split_whitespace().collect::<Vec<_>>().join(" "),
        "periodic input constant interval 0.25 s, shift 0.1 s; governs n_periodic"
    );
    assert!(clocks[1].contains("fixed") && clocks[1].contains("interval 0.5 s"), "{}", clocks[1]);
    assert!(clocks[2].contains("changing") && clocks[2].contains("interval from the FMU"), "{}", clocks[2]);
    assert!(
        clocks[5].contains("out_clock") && clocks[5].contains("output") && clocks[5].contains("no interval"),
        "{}",
        clocks[5]
    );
}

#[test]
fn a_clock_column_for_a_periodic_clock_is_refused() {
    let dir = work_dir("clocks-bad-input");
    let Some(path) = clocks_fmu(&dir) else { return };
    let system = System::single("c", Fmu::load(&path).unwrap()).unwrap();
    let mut experiment = Experiment::new(1.0, 0.1);
    experiment.input = Some(Arc::new(InputTable::new(vec!["periodic".into()], vec![0.0], vec![vec![1.0]]).unwrap()));
    let e = simulate(&system, &experiment).unwrap_err().to_string();
    assert!(e.contains("\"periodic\"") && e.contains("only triggered input clocks"), "{e}");
}

/// Instances `a` and `b` of the FMU at `path`, not connected.
fn two_instances(path: &Path) -> SystemBuilder {
    common::builder_with(&Fmu::load(path).unwrap(), &["a", "b"])
}

#[test]
fn an_output_clock_ticks_a_connected_triggered_clock_at_the_next_point() {
    let dir = work_dir("clocks-connected");
    let Some(path) = clocks_fmu(&dir) else { return };
    let mut b = two_instances(&path);
    // a clock connects to a triggered input clock only
    let e = b.connect("a.n_out_clock", "b.trig").unwrap_err().to_string();
    assert!(e.contains("the destination is a clock"), "{e}");
    let e = b.connect("a.periodic", "b.trig").unwrap_err().to_string();
    assert!(e.contains("not an output clock"), "{e}");
    let e = b.connect("a.out_clock", "b.periodic").unwrap_err().to_string();
    assert!(e.contains("only a triggered input clock"), "{e}");
    b.connect("a.out_clock", "b.trig").unwrap();
    let e = b.connect("a.out_clock", "b.trig").unwrap_err().to_string();
    assert!(e.contains("already connected"), "{e}");
    let (results, summary) = simulate(&b.build(), &Experiment::new(1.5, 0.1)).unwrap();
    // a.out_clock ticks at 0.35, 0.85, 1.35 (TICKS); each tick is carried to b.trig at the
    // end of its step, the next point: 0.4, 0.9, 1.4 s, where b's step starts with it
    let carried = [0.4, 0.9, 1.4];
    let time = results.column("time").unwrap();
    for (t, n) in time.iter().zip(results.column("b.n_trig").unwrap()) {
        assert_eq!(n, carried.iter().filter(|tick| **tick < t - 1e-9).count() as f64, "b.n_trig at t = {t} s");
    }
    let ticks = |name: &str| summary.clock_ticks.iter().find(|(n, _)| n == name).map(|(_, k)| *k);
    assert_eq!((ticks("a.out_clock"), ticks("b.trig"), ticks("a.trig")), (Some(3), Some(3), Some(0)));
}

/// Two instances connected clock to clock (`a.out_clock -> b.trig`) stepped in two threads
/// (`--threads 2`), in steps of 30 ms so that the periodic clock's ticks (0.1 + k 0.25 s)
/// fall inside steps and split them: after the 200 calibration steps each instance is in a
/// thread of its own, the pool splits every step at the ticks and carries `a`'s output
/// clock ticks to `b` across the threads as one thread does; 60 s, the single-thread run's
/// rows and ticks bit for bit.
#[test]
fn connected_clocks_in_two_threads_give_the_single_thread_run() {
    let dir = work_dir("clocks-threads");
    let Some(path) = clocks_fmu(&dir) else { return };
    let mut b = two_instances(&path);
    b.connect("a.out_clock", "b.trig").unwrap();
    let system = b.build();
    let mut e = Experiment::new(60.0, 0.03);
    let (serial, serial_summary) = simulate(&system, &e).unwrap();
    e.threads = 2;
    let (parallel, summary) = simulate(&system, &e).unwrap();
    assert!(summary.parallel_steps >= 1000, "{} steps in the pool", summary.parallel_steps);
    // rows at the 2001 points and at the periodic ticks between them (0.35 s the first)
    assert!(serial.rows() > 2001 && serial.column("time").unwrap().contains(&0.35), "{}", serial.rows());
    assert_eq!((parallel.rows(), &parallel.names), (serial.rows(), &serial.names));
    let differing = serial.values.iter().zip(&parallel.values).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
    assert_eq!(differing, 0, "values of the two-thread run differ from the single-thread one's");
    assert_eq!(summary.clock_ticks, serial_summary.clock_ticks);
    let ticks = |name: &str| summary.clock_ticks.iter().find(|(n, _)| n == name).map(|(_, k)| *k);
    // a.out_clock ticks at every second periodic tick, each carried to b.trig
    assert!(ticks("a.out_clock").is_some_and(|k| k > 100) && ticks("a.out_clock") == ticks("b.trig"));
}

/// An SSP (SSP 2.0 draft: ssc:Clock connectors) of two instances of the clock FMU with
/// `connection` (start element.connector, end element.connector) between them.
fn clock_ssp(dir: &Path, fmu: &Path, connection: (&str, &str, &str, &str), declared: &str) -> PathBuf {
    let connectors =
        |kind: &str, name: &str| format!(r#"<ssd:Connector name="{name}" kind="{kind}">{declared}</ssd:Connector>"#);
    let component = |name: &str, connector: String| {
        format!(
            r#"<ssd:Component name="{name}" source="resources/fmi3_clocks.fmu"><ssd:Connectors>{connector}</ssd:Connectors></ssd:Component>"#
        )
    };
    let (a, out, b, input) = connection;
    let ssd = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="2.0" name="clocks">
  <ssd:System name="root">
    <ssd:Elements>{}{}</ssd:Elements>
    <ssd:Connections><ssd:Connection startElement="{a}" startConnector="{out}" endElement="{b}" endConnector="{input}"/></ssd:Connections>
  </ssd:System>
</ssd:SystemStructureDescription>"#,
        component(a, connectors("output", out)),
        component(b, connectors("input", input)),
    );
    let ssp = dir.join("clocks.ssp");
    zip_entries(
        &ssp,
        &[("SystemStructure.ssd", ssd.into_bytes()), ("resources/fmi3_clocks.fmu", std::fs::read(fmu).unwrap())],
    );
    ssp
}

#[test]
fn an_ssp_connects_clocks_as_the_ssp_2_draft_writes_them() {
    let dir = work_dir("clocks-ssp");
    let Some(path) = clocks_fmu(&dir) else { return };
    let clock = r#"<ssc:Clock intervalVariability="triggered"/>"#;
    let ssp = clock_ssp(&dir, &path, ("a", "out_clock", "b", "trig"), clock);
    let system = nigel_cosim::ssp::read_ssp(&ssp, &Default::default()).unwrap().system;
    assert_eq!(system.clock_connections.len(), 1);
    let (_, summary) = simulate(&system, &Experiment::new(1.5, 0.1)).unwrap();
    // a.out_clock's three ticks (TICKS) carried to b.trig
    assert!(summary.clock_ticks.contains(&("b.trig".to_string(), 3)), "{:?}", summary.clock_ticks);
    // checked like any connection: a clock to a clock only, and the declared type
    let ssp = clock_ssp(&dir, &path, ("a", "n_out_clock", "b", "trig"), "");
    let e = nigel_cosim::ssp::read_ssp(&ssp, &Default::default()).err().expect("refused").to_string();
    assert!(e.contains("the destination is a clock"), "{e}");
    let ssp = clock_ssp(&dir, &path, ("a", "out_clock", "b", "trig"), r#"<ssc:Real/>"#);
    let e = nigel_cosim::ssp::read_ssp(&ssp, &Default::default()).err().expect("refused").to_string();
    assert!(e.contains("is declared Real but the variable is a clock"), "{e}");
}

/// The README's clock figure: `cosim run` of the test FMU with an input file ticking `trig`,
/// drawn by scripts/clock_figure.py (with fmpy's Python, which has matplotlib); the ticks it
/// draws are TICKS, and the counts the README's caption prints are the run's summary.
#[test]
fn the_readme_figure_of_the_ticks_is_drawn_from_a_run() {
    let dir = work_dir("clocks-figure");
    let Some(path) = clocks_fmu(&dir) else { return };
    let input = dir.join("clocks_in.csv");
    std::fs::write(&input, "time,trig\n0,0\n0.45,1\n0.5,0\n1.2,1\n1.3,0\n").unwrap();
    let (csv, summary) = (dir.join("clocks.csv"), dir.join("summary.json"));
    let run = common::cosim_run_with_input(&path, &["--stop-time", "1.5", "--step", "0.1"], &input, &csv, &summary);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let png = if std::env::var_os("NIGEL_WRITE_DOC_FIGURES").is_some() {
        repo.join("docs/figures/clock_ticks.png")
    } else {
        dir.join("clock_ticks.png")
    };
    let python = std::env::var("FMPY_PYTHON").unwrap_or_else(|_| "python3".into());
    let drawn = Command::new(python)
        .arg(repo.join("scripts/clock_figure.py"))
        .arg(&csv)
        .arg(&summary)
        .arg(&png)
        .output()
        .unwrap();
    assert!(drawn.status.success(), "{}", String::from_utf8_lossy(&drawn.stderr));
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000, "a drawn PNG");
    // each line: clock, count, tick times
    let printed = String::from_utf8_lossy(&drawn.stdout).to_string();
    let mut counts = Vec::new();
    for (line, (name, ticks)) in printed.lines().zip(TICKS) {
        let words: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(words[0], &name[2..], "{printed}");
        let times: Vec<f64> = words[2..].iter().map(|w| w.parse().unwrap()).collect();
        assert_eq!(times.len(), ticks.len(), "{name}: {printed}");
        for (a, b) in times.iter().zip(ticks) {
            assert!((a - b).abs() < 1e-9, "{name}: drawn {times:?}, derived {ticks:?}");
        }
        counts.push(format!("{} {}", words[0], words[1]));
    }
    let caption = format!("({})", counts.join(", "));
    let readme = std::fs::read_to_string(repo.join("README.md")).unwrap();
    assert!(readme.contains(&caption), "README.md's clock figure caption should say {caption}");
}

/// fmpy's FMI 3.0 calls (fmpy.fmi3.FMU3Slave) drive the FMU through the ticks derived by
/// hand (TICKS, not cosim's schedule): to each of cosim's row times, the clock event of the
/// clocks ticking there opened (Event Mode, fmi3SetClock), the outputs read, the event closed
/// (fmi3UpdateDiscreteStates, fmi3EnterStepMode; not after the last row). Prints one line per
/// row: time and the outputs.
const FMPY_DRIVER: &str = r#"
import sys, json
from fmpy import extract
from fmpy.fmi3 import FMU3Slave
fmu, rows, ticks = sys.argv[1], json.loads(sys.argv[2]), json.loads(sys.argv[3])
s = FMU3Slave(guid='{fmi3-clocks}', unzipDirectory=extract(fmu), modelIdentifier='fmi3_clocks', instanceName='c')
s.instantiate(eventModeUsed=True)
s.enterInitializationMode(startTime=0.0, stopTime=rows[-1])
s.exitInitializationMode()
while s.updateDiscreteStates()[0]:
    pass
s.enterStepMode()
t = 0.0
for row in rows:
    if row > t:
        s.doStep(t, row - t)
        t = row
    due = [vr for vr, times in ticks if any(abs(x - row) < 1e-9 for x in times)]
    if due:
        s.enterEventMode()
        s.setClock(due, [True] * len(due))
    print(row, *s.getInt32(list(range(10, 16))), *s.getFloat64([16]))
    if due and row < rows[-1]:
        while s.updateDiscreteStates()[0]:
            pass
        s.enterStepMode()
s.terminate()
s.freeInstance()
"#;

#[test]
fn fmpy_driving_the_fmu_through_the_hand_derived_ticks_gives_cosims_rows() {
    let dir = work_dir("clocks-fmpy");
    let Some(path) = clocks_fmu(&dir) else { return };
    let (results, _) = run_with_trig(&path, None);
    let time = results.column("time").unwrap();
    // the input clocks' value references (1 periodic .. 5 trig) and their hand-derived ticks
    let ticks: Vec<String> = TICKS[..5].iter().enumerate().map(|(k, (_, t))| format!("[{}, {t:?}]", k + 1)).collect();
    let (times, ticks) = (format!("{time:?}"), format!("[{}]", ticks.join(", ")));
    let lines = common::fmi3_c::fmpy_lines(FMPY_DRIVER, &[path.as_os_str(), times.as_ref(), ticks.as_ref()]);
    let columns = ["n_periodic", "n_fixed", "n_changing", "n_countdown", "n_trig", "n_out_clock", "last_tick"];
    assert_eq!(lines.len(), time.len());
    for (name, k) in columns.iter().zip(1..) {
        let ours = results.column(name).unwrap();
        let theirs: Vec<f64> = lines.iter().map(|l| l[k]).collect();
        // counts and times the FMU stores: equal, not close
        assert_eq!(ours, theirs, "{name}: cosim vs fmpy's calls, rows at {time:?}");
    }
}

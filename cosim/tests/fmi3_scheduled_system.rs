//! FMI 3.0 Scheduled Execution of a system of several FMUs: two instances, A and B, of the C
//! FMU `tests/cfmu/fmi3_se_node.c` (built twice, from two descriptions that differ in the
//! priority of the partition `sample`), connected both ways (A.y -> B.u, a clocked input;
//! A.y -> B.v and B.y -> A.v, unclocked) and clock to clock (A.done -> B.trigger). The
//! partitions of both are activated at their ticks in priority order across the instances,
//! the clocked values exchanged at the ticks; the fixed clock's interval is the FMU's after
//! initialization, the tunable clock's new interval is taken when the FMU says. Every value
//! derived by hand next to the test.

mod common;
use common::work_dir;
use nigel_cosim::simulate::simulate_scheduled;
use nigel_cosim::system::Value;
use nigel_cosim::{Experiment, Fmu, ImportOptions, Interface, SystemBuilder};
use std::path::{Path, PathBuf};

/// The description (tests/cfmu/fmi3_se_node.xml), `sample` at priority `sample_priority`
/// (the file's is 1). The description's interval of the fixed clock `sample` is 1 s; the FMU
/// gives its parameter `period` instead.
fn xml(sample_priority: u32) -> String {
    let at = |priority: u32| format!(r#"intervalDecimal="1" priority="{priority}""#);
    include_str!("cfmu/fmi3_se_node.xml").replace(&at(1), &at(sample_priority))
}

/// The two FMUs: A's `sample` at priority 1, B's at priority 0; `None` (skip) without fmpy's
/// headers.
fn build(dir: &Path) -> Option<(PathBuf, PathBuf)> {
    let (a, b) = (dir.join("a"), dir.join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    Some((common::fmi3_c::build(&a, "fmi3_se_node", &xml(1))?, common::fmi3_c::build(&b, "fmi3_se_node", &xml(0))?))
}

fn system(a: &Path, b: &Path) -> nigel_cosim::System {
    let options = ImportOptions { interface: Some(Interface::ScheduledExecution), ..ImportOptions::default() };
    let mut s = SystemBuilder::new();
    s.add_instance("A", Fmu::load_with(a, &options).unwrap()).unwrap();
    s.add_instance("B", Fmu::load_with(b, &options).unwrap()).unwrap();
    s.set("B.period", Value::Real(0.25)).unwrap();
    s.connect("A.y", "B.u").unwrap();
    s.connect("A.y", "B.v").unwrap();
    s.connect("B.y", "A.v").unwrap();
    s.connect("A.done", "B.trigger").unwrap();
    s.build()
}

/// The ticks, derived by hand (stop 2 s, ticks in [0, 2)):
/// - A.sample every 0.5 s (A's period, not the description's 1 s): 0, 0.5, 1, 1.5;
///   B.sample every 0.25 s (B.period = 0.25): 0, 0.25, ..., 1.75. y = the partition's count.
/// - B.trigger at A.done's ticks, which A.sample ticks: 0, 0.5, 1, 1.5 (priority 2: after
///   both samples at the same time).
/// - rate (tunable, 0.5 s) of both: 0 and 0.5; at its 2nd activation (0.5) the FMU makes
///   the interval 0.75 s: next 0.5 + 0.75 = 1.25, then 2 (not < 2). Three activations each.
///
/// Where A.sample and B.sample tick together (0, 0.5, 1, 1.5) B's (priority 0) runs first:
/// - B.w = B.v = A.y before A's activation at that time = A's activations before t:
///   0, 1, 1, 2, 2, 3, 3, 4 at 0, 0.25, ..., 1.75 (and 4 at the stop row).
/// - A.w = A.v = B.y after B's activation at t = B's count at t: 1, 3, 5, 7 at 0, 0.5, 1, 1.5.
/// - B.z = B.u at B.trigger = A.y after A's activation at t: 1, 2, 3, 4.
///
/// Rows at every tick time and at the stop time, holding the values after the activations.
#[test]
fn partitions_of_two_fmus_tick_in_priority_order_across_them_and_exchange_at_their_ticks() {
    let dir = work_dir("fmi3-scheduled-system");
    let Some((a, b)) = build(&dir) else { return };
    let system = system(&a, &b);
    let experiment = Experiment::new(2.0, 0.25);
    let (r, outcome) = simulate_scheduled(&system, &experiment);
    let summary = outcome.unwrap();
    assert_eq!(
        summary.notes,
        [
            "Scheduled Execution: partitions activated: A.sample 4, A.trigger 0, A.rate 3, B.sample 8, B.trigger 4, B.rate 3",
            "Scheduled Execution: output clocks ticked: A.done 4, B.done 8",
        ]
    );
    let col = |n: &str| r.column(n).unwrap_or_else(|| panic!("column {n}"));
    assert_eq!(col("time"), [0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0]);
    assert_eq!(col("A.n_sample"), [1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 4.0]);
    assert_eq!(col("B.n_sample"), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 8.0]);
    assert_eq!(col("A.y"), col("A.n_sample"));
    assert_eq!(col("B.w"), [0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0]);
    assert_eq!(col("A.w"), [1.0, 1.0, 3.0, 3.0, 5.0, 5.0, 7.0, 7.0, 7.0]);
    assert_eq!(col("B.z"), [1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 4.0]);
    assert_eq!(col("B.n_trigger"), col("B.z"));
    assert_eq!(col("A.n_trigger"), [0.0; 9]);
    for name in ["A.n_rate", "B.n_rate"] {
        assert_eq!(col(name), [1.0, 1.0, 2.0, 2.0, 2.0, 3.0, 3.0, 3.0, 3.0], "{name}");
    }
    // the clock columns: 1 at the rows where the clock ticked
    let a_sample = [1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0];
    assert_eq!(col("A.sample"), a_sample);
    assert_eq!(col("A.done"), a_sample);
    assert_eq!(col("B.trigger"), a_sample);
    assert_eq!(col("B.sample"), [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.0]);
    assert_eq!(col("B.rate"), [1.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
    // deterministic: a second run is the same, bit for bit
    let (again, _) = simulate_scheduled(&system, &experiment);
    assert_eq!(again.values, r.values);
}

/// The same system as an SSP (SSP 2.0 draft clock connectors), run with `cosim run
/// --interface se` and B.period from `--set`: the CSV holds the values derived above.
#[test]
fn an_ssp_of_scheduled_fmus_runs_from_the_command_line() {
    let dir = work_dir("fmi3-scheduled-ssp");
    let Some((a, b)) = build(&dir) else { return };
    let connector = |name: &str, kind: &str, declared: &str| {
        format!(r#"<ssd:Connector name="{name}" kind="{kind}">{declared}</ssd:Connector>"#)
    };
    let (real, clock) = ("<ssc:Real/>", r#"<ssc:Clock intervalVariability="triggered"/>"#);
    let component = |name: &str| {
        let connectors = [
            connector("y", "output", real),
            connector("u", "input", real),
            connector("v", "input", real),
            connector("done", "output", clock),
            connector("trigger", "input", clock),
        ]
        .concat();
        format!(
            r#"<ssd:Component name="{name}" source="resources/{name}.fmu"><ssd:Connectors>{connectors}</ssd:Connectors></ssd:Component>"#
        )
    };
    let connection = |a: &str, x: &str, b: &str, y: &str| {
        format!(r#"<ssd:Connection startElement="{a}" startConnector="{x}" endElement="{b}" endConnector="{y}"/>"#)
    };
    let connections = [
        connection("A", "y", "B", "u"),
        connection("A", "y", "B", "v"),
        connection("B", "y", "A", "v"),
        connection("A", "done", "B", "trigger"),
    ]
    .concat();
    let ssd = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="2.0" name="scheduled">
  <ssd:System name="root">
    <ssd:Elements>{}{}</ssd:Elements>
    <ssd:Connections>{connections}</ssd:Connections>
  </ssd:System>
</ssd:SystemStructureDescription>"#,
        component("A"),
        component("B")
    );
    let ssp = dir.join("scheduled.ssp");
    common::zip_entries(
        &ssp,
        &[
            ("SystemStructure.ssd", ssd.into_bytes()),
            ("resources/A.fmu", std::fs::read(&a).unwrap()),
            ("resources/B.fmu", std::fs::read(&b).unwrap()),
        ],
    );
    let csv = dir.join("out.csv");
    let (header, rows) = common::run_to_csv(
        std::process::Command::new(env!("CARGO_BIN_EXE_cosim"))
            .args([
                "run",
                ssp.to_str().unwrap(),
                "--interface",
                "se",
                "--stop-time",
                "2",
                "--set",
                "B.period=0.25",
                "-o",
            ])
            .arg(&csv),
        &csv,
    );
    let col = |name: &str| {
        let j = header.iter().position(|h| h == name).unwrap_or_else(|| panic!("column {name} in {header:?}"));
        rows.iter().map(|r| r[j]).collect::<Vec<f64>>()
    };
    assert_eq!(col("time"), [0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0]);
    assert_eq!(col("B.w"), [0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0]);
    assert_eq!(col("A.w"), [1.0, 1.0, 3.0, 3.0, 5.0, 5.0, 7.0, 7.0, 7.0]);
    assert_eq!(col("B.z"), [1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 4.0]);
}

/// fmpy's FMI 3.0 calls (`fmpy.fmi3.FMU3ScheduledExecution`) drive the two FMUs through the
/// activations derived by hand above (ACTIVATIONS, not cosim's schedule), setting each
/// instance's connected inputs from their sources right before each of its activations;
/// after each tick time's activations (and at the stop time) the outputs are printed: one
/// line per row, the time then A's and B's y, z, w, n_sample, n_trigger, n_rate.
const FMPY_DRIVER: &str = r#"
import sys, json
from fmpy import extract
from fmpy.fmi3 import FMU3ScheduledExecution
a, b, activations, stop = sys.argv[1], sys.argv[2], json.loads(sys.argv[3]), float(sys.argv[4])
fmus = {}
for name, path in (("A", a), ("B", b)):
    f = FMU3ScheduledExecution(guid='{fmi3-se-node}', unzipDirectory=extract(path), modelIdentifier='fmi3_se_node', instanceName=name)
    f.instantiate()
    fmus[name] = f
fmus["B"].setFloat64([10], [0.25])
for f in fmus.values():
    f.enterInitializationMode(startTime=0.0, stopTime=stop)
    f.exitInitializationMode()
# the connections into each instance: (input, source instance, source output)
into = {"A": [(12, "B", 13)], "B": [(11, "A", 13), (12, "A", 13)]}
def row(t):
    values = [t]
    for f in (fmus["A"], fmus["B"]):
        values += f.getFloat64([13, 14, 15]) + f.getInt32([20, 21, 22])
    print(*values)
last = None
for t, name, clock in activations:
    if last is not None and t != last:
        row(last)
    last = t
    for vr, source, output in into[name]:
        fmus[name].setFloat64([vr], fmus[source].getFloat64([output]))
    fmus[name].activateModelPartition(clock, t)
row(last)
row(stop)
for f in fmus.values():
    f.terminate()
    f.freeInstance()
"#;

/// The activations of the run to 2 s, derived by hand above: (time, instance, clock) in
/// the order of the priorities B.sample 0, A.sample 1, trigger 2, rate 3 (A before B).
const ACTIVATIONS: &str = r#"[
  [0, "B", 1], [0, "A", 1], [0, "B", 2], [0, "A", 4], [0, "B", 4],
  [0.25, "B", 1],
  [0.5, "B", 1], [0.5, "A", 1], [0.5, "B", 2], [0.5, "A", 4], [0.5, "B", 4],
  [0.75, "B", 1],
  [1.0, "B", 1], [1.0, "A", 1], [1.0, "B", 2],
  [1.25, "B", 1], [1.25, "A", 4], [1.25, "B", 4],
  [1.5, "B", 1], [1.5, "A", 1], [1.5, "B", 2],
  [1.75, "B", 1]
]"#;

#[test]
fn fmpy_driving_the_fmus_through_the_hand_derived_activations_gives_cosims_rows() {
    let dir = work_dir("fmi3-scheduled-fmpy");
    let Some((a, b)) = build(&dir) else { return };
    let (r, outcome) = simulate_scheduled(&system(&a, &b), &Experiment::new(2.0, 0.25));
    outcome.unwrap();
    let lines =
        common::fmi3_c::fmpy_lines(FMPY_DRIVER, &[a.as_os_str(), b.as_os_str(), ACTIVATIONS.as_ref(), "2".as_ref()]);
    assert_eq!(lines.iter().map(|l| l[0]).collect::<Vec<_>>(), r.column("time").unwrap());
    let names = ["y", "z", "w", "n_sample", "n_trigger", "n_rate"];
    let columns = ["A", "B"].iter().flat_map(|i| names.iter().map(move |n| format!("{i}.{n}")));
    for (name, k) in columns.zip(1..) {
        let theirs: Vec<f64> = lines.iter().map(|l| l[k]).collect();
        // values the FMUs store and counts: equal, not close
        assert_eq!(r.column(&name).unwrap(), theirs, "{name}: cosim vs fmpy's calls");
    }
}

//! FMI 3.0 Scheduled Execution of a `changing` (aperiodic) clock's model partition, with the
//! C FMU `tests/cfmu/fmi3_changing.c`: the master asks the first interval with
//! `fmi3GetIntervalDecimal` in Initialization Mode and each next one right after each
//! activation (FMI 3.0, the changing aperiodic clock: t_0 = t_start + T_0, t_i = t_(i-1) +
//! T_i, T_i known once the clock was activated), against tick times derived by hand; the FMU
//! refuses an activation at any other time. fmpy's FMI 3.0 calls
//! (`fmpy.fmi3.FMU3ScheduledExecution`) drive the same FMU through the hand-derived
//! activations: the intervals the FMU gives them are the ones derived, and the rows cosim's.

mod common;
use common::work_dir;
use nigel_cosim::simulate::simulate_scheduled;
use nigel_cosim::{Experiment, Fmu, ImportOptions, Interface, Results, SystemBuilder, Value};
use std::path::{Path, PathBuf};

const XML: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="changing" instantiationToken="{fmi3-changing}">
  <ScheduledExecution modelIdentifier="fmi3_changing"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    <Clock name="steps" valueReference="1" causality="input" intervalVariability="changing" priority="0"/>
    <Clock name="fast" valueReference="2" causality="input" intervalVariability="constant" intervalDecimal="0.5" priority="1"/>
    <Float64 name="first_delay" valueReference="10" causality="parameter" variability="fixed" start="0.25"/>
    <Float64 name="t_steps" valueReference="11" causality="output" variability="discrete" clocks="1"/>
    <Int32 name="n_steps" valueReference="20" causality="output" clocks="1"/>
    <Int32 name="n_fast" valueReference="21" causality="output" clocks="2"/>
    <Int32 name="first" valueReference="22" causality="output"/>
  </ModelVariables>
  <ModelStructure>
    <Output valueReference="11"/>
    <Output valueReference="20"/>
    <Output valueReference="21"/>
    <Output valueReference="22"/>
  </ModelStructure>
</fmiModelDescription>
"#;

fn build(dir: &Path) -> Option<PathBuf> {
    common::fmi3_c::build(dir, "fmi3_changing", XML)
}

/// The run to 3 s with `first_delay` = `delay`.
fn run(fmu: &Path, delay: f64) -> Results {
    let options = ImportOptions { interface: Some(Interface::ScheduledExecution), ..ImportOptions::default() };
    let mut b = SystemBuilder::new();
    b.add_instance("c", Fmu::load_with(fmu, &options).unwrap()).unwrap();
    b.set("c.first_delay", Value::Real(delay)).unwrap();
    let (results, outcome) = simulate_scheduled(&b.build(), &Experiment::new(3.0, 0.5));
    outcome.unwrap();
    results
}

/// The ticks, derived by hand from the FMU's comment. `steps`: t_0 = 0 + first_delay, then
/// T_k = 0.25 (k + 1) after the k-th activation; `fast` every 0.5 s from 0, in [0, 3).
///
/// - first_delay 0.25: steps at 0.25, 0.25 + 0.5 = 0.75, 0.75 + 0.75 = 1.5, 1.5 + 1 = 2.5
///   (then 2.5 + 1.25 = 3.75, past the stop); fast at 0, 0.5, 1, 1.5, 2, 2.5. At 1.5 and 2.5
///   both tick and steps (priority 0) goes first.
/// - first_delay 0 (a first tick at the start): steps at 0, 0.5, 0.5 + 0.75 = 1.25, 1.25 + 1
///   = 2.25 (then 3.5); with fast at 0 and 0.5 steps goes first.
///
/// A row at each tick time (after its activations) and at the stop time; exact in binary.
#[test]
fn a_changing_clock_partition_ticks_at_the_intervals_the_fmu_gives() {
    let dir = work_dir("fmi3-scheduled-changing");
    let Some(fmu) = build(&dir) else { return };
    let r = run(&fmu, 0.25);
    let col = |r: &Results, n: &str| r.column(n).unwrap_or_else(|| panic!("column {n}"));
    assert_eq!(col(&r, "time"), [0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0]);
    assert_eq!(col(&r, "n_steps"), [0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0]);
    assert_eq!(col(&r, "t_steps"), [0.0, 0.25, 0.25, 0.75, 0.75, 1.5, 1.5, 2.5, 2.5]);
    assert_eq!(col(&r, "n_fast"), [1.0, 1.0, 2.0, 2.0, 3.0, 4.0, 5.0, 6.0, 6.0]);
    assert_eq!(col(&r, "first"), [2.0, 1.0, 2.0, 1.0, 2.0, 1.0, 2.0, 1.0, 1.0]);
    assert_eq!(col(&r, "steps"), [0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0]);
    let r = run(&fmu, 0.0);
    assert_eq!(col(&r, "time"), [0.0, 0.5, 1.0, 1.25, 1.5, 2.0, 2.25, 2.5, 3.0]);
    assert_eq!(col(&r, "n_steps"), [1.0, 2.0, 2.0, 3.0, 3.0, 3.0, 4.0, 4.0, 4.0]);
    assert_eq!(col(&r, "n_fast"), [1.0, 2.0, 3.0, 3.0, 4.0, 5.0, 5.0, 6.0, 6.0]);
    assert_eq!(col(&r, "first"), [1.0, 1.0, 2.0, 1.0, 2.0, 2.0, 1.0, 2.0, 2.0]);
    let info = std::process::Command::new(env!("CARGO_BIN_EXE_cosim")).arg("info").arg(&fmu).output().unwrap();
    let info = String::from_utf8_lossy(&info.stdout);
    assert!(
        info.lines().any(|l| l
            == "model partition steps (clock, priority 0): ticks changing (each interval from the FMU after an \
                activation); run with --interface se"),
        "{info}"
    );
}

/// fmpy's calls: the FMU instantiated for Scheduled Execution, `first_delay` set,
/// `fmi3GetIntervalDecimal` of steps in Initialization Mode and right after each of its
/// activations (printed: the first line, the intervals and their qualifiers), the
/// activations of `ACTIVATIONS` (time, clock) in order, a row after each time's activations
/// and at the stop time: the time, t_steps, n_steps, n_fast, first.
const FMPY_DRIVER: &str = r#"
import sys, json, ctypes
from fmpy import extract
from fmpy.fmi3 import FMU3ScheduledExecution
path, delay, activations, stop = sys.argv[1], float(sys.argv[2]), json.loads(sys.argv[3]), float(sys.argv[4])
f = FMU3ScheduledExecution(guid='{fmi3-changing}', unzipDirectory=extract(path), modelIdentifier='fmi3_changing', instanceName='c')
f.instantiate()
f.setFloat64([10], [delay])
given = []
def interval():
    vr, value, qualifier = (ctypes.c_uint32 * 1)(1), (ctypes.c_double * 1)(), (ctypes.c_int * 1)()
    f.getIntervalDecimal(vr, value, qualifier)
    given.extend([value[0], qualifier[0]])
f.enterInitializationMode(startTime=0.0, stopTime=stop)
interval()
f.exitInitializationMode()
rows = []
def row(t):
    rows.append([t] + f.getFloat64([11]) + f.getInt32([20, 21, 22]))
last = None
for t, clock in activations:
    if last is not None and t != last:
        row(last)
    last = t
    f.activateModelPartition(clock, t)
    if clock == 1:
        interval()
row(last)
row(stop)
print(*given)
for r in rows:
    print(*r)
f.terminate()
f.freeInstance()
"#;

/// The activations of the run to 3 s with first_delay 0.25, derived by hand above: (time,
/// clock), steps (1, priority 0) before fast (2) at the same time.
const ACTIVATIONS: &str =
    "[[0, 2], [0.25, 1], [0.5, 2], [0.75, 1], [1.0, 2], [1.5, 1], [1.5, 2], [2.0, 2], [2.5, 1], [2.5, 2]]";

#[test]
fn fmpy_driving_the_changing_partition_through_the_hand_derived_ticks_gives_cosims_rows() {
    let dir = work_dir("fmi3-scheduled-changing-fmpy");
    let Some(fmu) = build(&dir) else { return };
    let r = run(&fmu, 0.25);
    let lines = common::fmi3_c::fmpy_lines(
        FMPY_DRIVER,
        &[fmu.as_os_str(), "0.25".as_ref(), ACTIVATIONS.as_ref(), "3".as_ref()],
    );
    // the intervals the FMU gave fmpy: 0.25 in Initialization Mode, then 0.5, 0.75, 1, 1.25
    // after steps' activations, each fmi3IntervalChanged (2): the ones derived above
    assert_eq!(lines[0], [0.25, 2.0, 0.5, 2.0, 0.75, 2.0, 1.0, 2.0, 1.25, 2.0]);
    let rows = &lines[1..];
    assert_eq!(rows.iter().map(|l| l[0]).collect::<Vec<_>>(), r.column("time").unwrap());
    for (name, k) in ["t_steps", "n_steps", "n_fast", "first"].into_iter().zip(1..) {
        let theirs: Vec<f64> = rows.iter().map(|l| l[k]).collect();
        // values the FMU stores and counts: equal, not close
        assert_eq!(r.column(name).unwrap(), theirs, "{name}: cosim vs fmpy's calls");
    }
}

/// A first interval that is no time (first_delay -1 s, which the FMU gives as it is) ends the
/// run before any activation with an error naming the call, the clock and the value.
#[test]
fn a_changing_clock_interval_that_is_no_time_is_an_error_naming_it() {
    let dir = work_dir("fmi3-scheduled-changing-bad");
    let Some(fmu) = build(&dir) else { return };
    let options = ImportOptions { interface: Some(Interface::ScheduledExecution), ..ImportOptions::default() };
    let mut b = SystemBuilder::new();
    b.add_instance("c", Fmu::load_with(&fmu, &options).unwrap()).unwrap();
    b.set("c.first_delay", Value::Real(-1.0)).unwrap();
    let (results, outcome) = simulate_scheduled(&b.build(), &Experiment::new(3.0, 0.5));
    let e = outcome.unwrap_err().to_string();
    // the FMU returned fmi3OK with the interval: the standard, not the FMU's status, refuses it
    assert!(
        e.contains("c: fmi3GetIntervalDecimal returned fmi3OK at t = 0 s, but the interval -1 s of clock 1 is no time"),
        "{e}"
    );
    assert_eq!(results.rows(), 0, "no row: no activation ran");
}

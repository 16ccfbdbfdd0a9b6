//! The Event Mode policy of FMI 3.0 Co-Simulation (`cosim run --event-mode auto|on|off`,
//! `ImportOptions::event_mode`): by default `eventModeUsed` only for an FMU with clocks, which
//! needs it; an FMU without clocks handles its events inside `fmi3DoStep`, as fmpy's
//! `simulate_fmu` runs it by default. The test FMU (tests/cfmu/fmi3_event_mode.c) says how
//! it was instantiated (`event_mode_used`) and integrates x with a rate of 1 that becomes 2
//! at x = 0.55: inside the step at the crossing without Event Mode, at the step's end in
//! Event Mode with it, so the two runs differ where the event is.

mod common;

use common::{fmi3_c, read_csv, run_to_csv, work_dir};
use nigel_cosim::{simulate, EventModeChoice, Experiment, Fmu, ImportOptions, SystemBuilder};
use std::path::{Path, PathBuf};
use std::process::Command;

const XML: &str = include_str!("cfmu/fmi3_event_mode.xml");

fn event_model(test: &str, xml: &str) -> Option<(PathBuf, PathBuf)> {
    let dir = work_dir(test);
    let fmu = fmi3_c::build(&dir, "fmi3_event_mode", xml)?;
    Some((dir, fmu))
}

fn cosim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_cosim"))
}

/// `cosim run FMU --stop-time 1 --step 0.1 ARGS -o CSV`: the rows (time, x, event_mode_used,
/// events).
fn run(dir: &Path, fmu: &Path, args: &[&str]) -> Vec<Vec<f64>> {
    let csv = dir.join(format!("run{}.csv", args.join("")));
    let mut command = cosim();
    command.arg("run").arg(fmu).args(["--stop-time", "1", "--step", "0.1"]).args(args).arg("-o").arg(&csv);
    let (header, rows) = run_to_csv(&mut command, &csv);
    assert_eq!(header, ["time", "x", "event_mode_used", "events"]);
    rows
}

/// x at the rows t = 0, 0.1, ..., 1 s: rate 1 up to the event, 2 after it. Without Event Mode
/// the FMU changes the rate at the crossing itself, x = 0.55 at t = 0.55 s: x(t) = 0.55 +
/// 2 (t - 0.55) from t = 0.6 s (0.65, ..., 1.45 at 1 s). In Event Mode the step to 0.6 s ends
/// at x = 0.6 with eventHandlingNeeded and the rate changes there: x(t) = 0.6 + 2 (t - 0.6)
/// (1.4 at 1 s). The FMU sums its steps (and the master's times are k h), so each value is
/// within a few rounding errors of these: 1e-12 is far above them (ten sums of numbers
/// below 2, each rounding by at most 2.2e-16) and far below the 0.05 the two runs differ by.
fn expected_x(event_mode: bool) -> Vec<f64> {
    let t_event = if event_mode { 0.6 } else { 0.55 };
    (0..=10).map(|k| k as f64 / 10.0).map(|t| if t < 0.55 { t } else { t_event + 2.0 * (t - t_event) }).collect()
}

fn assert_rows(rows: &[Vec<f64>], event_mode: bool) {
    let x = expected_x(event_mode);
    assert_eq!(rows.len(), 11);
    for (k, row) in rows.iter().enumerate() {
        assert!((row[0] - k as f64 / 10.0).abs() < 1e-12, "time {row:?}");
        assert!((row[1] - x[k]).abs() < 1e-12, "x at t = {}: {} expected {}", row[0], row[1], x[k]);
        assert_eq!(row[2], if event_mode { 1.0 } else { 0.0 }, "event_mode_used at t = {}", row[0]);
        // the event in the step to 0.6 s, counted from that row on
        assert_eq!(row[3], if k >= 6 { 1.0 } else { 0.0 }, "events at t = {}", row[0]);
    }
}

/// By default an FMU with Event Mode but no clocks is instantiated without it and handles its
/// event itself: x = 1.45 at 1 s; the same rows as fmpy 0.3.32's `simulate_fmu` with its
/// default (`use_event_mode=False`, and no early return, so the FMU's early return at 0 s
/// with eventHandlingNeeded, which the master takes as the FMU's own event there and steps
/// on from, is not made in fmpy's run). `--event-mode off` is the same run.
#[test]
fn by_default_an_fmu_without_clocks_runs_without_event_mode_as_fmpy_does() {
    let Some((dir, fmu)) = event_model("event-mode-auto", XML) else { return };
    let rows = run(&dir, &fmu, &[]);
    assert_rows(&rows, false);
    assert_eq!(run(&dir, &fmu, &["--event-mode", "off"]), rows);
    let script = "import sys\nfrom fmpy import simulate_fmu\n\
                  r = simulate_fmu(sys.argv[1], stop_time=1.0, output_interval=0.1)\n\
                  for row in r:\n    print(' '.join(repr(float(row[c])) for c in ['time', 'x', 'event_mode_used', 'events']))\n";
    let theirs = fmi3_c::fmpy_lines(script, &[&fmu]);
    assert_eq!(theirs.len(), rows.len());
    for (ours, theirs) in rows.iter().zip(&theirs) {
        // the same sums in the same order: the same doubles
        assert_eq!(ours, theirs);
    }
}

/// `--event-mode on` drives Event Mode as before this policy: the step to 0.6 s says
/// eventHandlingNeeded, Event Mode changes the rate there (x = 1.4 at 1 s), the row at 0.6 s
/// is recorded once, after the event.
#[test]
fn event_mode_on_drives_event_mode() {
    let Some((dir, fmu)) = event_model("event-mode-on", XML) else { return };
    assert_rows(&run(&dir, &fmu, &["--event-mode", "on"]), true);
}

/// `--event-mode on` for an FMU that declares no hasEventMode is refused (FMI 3.0 forbids
/// eventModeUsed = true there), and so is `use_event_mode` in the library; auto runs it.
#[test]
fn event_mode_on_without_has_event_mode_is_refused() {
    let xml = XML.replace(r#" hasEventMode="true""#, "");
    assert_ne!(xml, XML);
    let Some((dir, fmu)) = event_model("event-mode-on-refused", &xml) else { return };
    let out = cosim().arg("run").arg(&fmu).args(["--event-mode", "on"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("the FMU declares no hasEventMode for Co-Simulation"), "{stderr}");
    assert_rows(&run(&dir, &fmu, &[]), false);
}

/// `--event-mode off` for an FMU with clocks is refused, naming the clocks and why; by
/// default it keeps Event Mode (the library's decision says why).
#[test]
fn event_mode_off_on_a_clocked_fmu_is_refused_naming_its_clocks() {
    let dir = work_dir("event-mode-off-clocked");
    let Some(fmu) = fmi3_c::build(&dir, "fmi3_clocks", include_str!("cfmu/fmi3_clocks.xml")) else { return };
    let out = cosim().arg("run").arg(&fmu).args(["--event-mode", "off", "--stop-time", "1"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(r#"declares the clocks "periodic", "fixed", "changing", "countdown", "trig", "out_clock""#)
            && stderr.contains("FMI 3.0 requires eventModeUsed = true of an FMU with clocks"),
        "{stderr}"
    );
    let loaded = Fmu::load(&fmu).unwrap();
    let decision = loaded.event_mode().expect("an FMI 3.0 Co-Simulation FMU");
    assert!(decision.used && decision.why.starts_with("needed (auto): the FMU declares the clocks"), "{decision:?}");
}

/// `cosim info` says which Event Mode a run uses and why, and what on and off would do.
#[test]
fn info_says_which_event_mode_and_why() {
    let Some((_, fmu)) = event_model("event-mode-info", XML) else { return };
    let out = cosim().arg("info").arg(&fmu).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        text.contains(
            "Co-Simulation Event Mode (eventModeUsed): not used: not needed (auto): the FMU has Event Mode but no clocks"
        ),
        "{text}"
    );
    assert!(text.contains("  with --event-mode on: used: asked for (event mode on)"), "{text}");
}

/// An FMU that declares hasEventMode but refuses eventModeUsed = true (as the Reference FMUs'
/// Roberts does; this one for an instance named "...refuses...") is, under `on`, instantiated
/// again without it, with a warning in its log: the run is the one without Event Mode.
#[test]
fn under_on_an_fmu_that_refuses_event_mode_is_instantiated_again_without_it() {
    let Some((_, path)) = event_model("event-mode-refused-by-fmu", XML) else { return };
    let options = ImportOptions { event_mode: EventModeChoice::On, ..ImportOptions::default() };
    let fmu = Fmu::load_with(&path, &options).unwrap();
    let mut b = SystemBuilder::new();
    b.add_instance("refuses", fmu).unwrap();
    let (r, summary) = simulate(&b.build(), &Experiment::new(1.0, 0.1)).unwrap();
    let x = r.column("x").or_else(|| r.column("refuses.x")).expect("x");
    assert!((x[10] - 1.45).abs() < 1e-12, "x(1) = {} (1.45 without Event Mode, expected_x)", x[10]);
    let warnings = format!("{:?}", summary.warnings);
    assert!(warnings.contains("instantiated again without Event Mode"), "{warnings}");
}

/// `cosim run --event-mode on` of a model without FMI 3.0 Co-Simulation FMUs (the FMI 2.0
/// plant) runs, noting that the choice does not apply.
#[test]
fn an_event_mode_choice_that_applies_to_no_fmu_is_noted() {
    let csv = work_dir("event-mode-not-applied").join("plant.csv");
    let mut command = cosim();
    command.arg("run").arg(common::plant_fmu()).args(["--event-mode", "on", "--stop-time", "0.01", "-o"]).arg(&csv);
    let out = command.output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("cosim: note: event mode on does not apply"), "{stderr}");
    assert_eq!(read_csv(&csv).1.len(), 11, "the rows at 0, 1 ms, ..., 10 ms");
}

/// An SSD in `dir` of the one component `name`, the test FMU (built there).
fn one_component_ssd(dir: &Path, name: &str) -> PathBuf {
    let ssd = dir.join("one.ssd");
    let text = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" version="1.0" name="one">
<ssd:System name="root"><ssd:Elements><ssd:Component name="{name}" source="fmi3_event_mode.fmu"/></ssd:Elements></ssd:System>
</ssd:SystemStructureDescription>"#
    );
    std::fs::write(&ssd, text).unwrap();
    ssd
}

/// In an SSP the choice applies to each FMU: `cosim run SYSTEM.ssd --event-mode on` drives the
/// component's Event Mode (x = 1.4 at 1 s), the default does not (1.45), and `cosim info`
/// says which per instance.
#[test]
fn in_an_ssp_the_choice_applies_to_each_fmu() {
    let Some((dir, _)) = event_model("event-mode-ssp", XML) else { return };
    let ssd = one_component_ssd(&dir, "e");
    for (args, event_mode) in [(&[][..], false), (&["--event-mode", "on"][..], true)] {
        let csv = dir.join(format!("ssp{}.csv", args.len()));
        let mut command = cosim();
        command.arg("run").arg(&ssd).args(["--stop-time", "1", "--step", "0.1"]).args(args).arg("-o").arg(&csv);
        let (header, rows) = run_to_csv(&mut command, &csv);
        // one instance: its columns by the variables' names, as for a single FMU
        assert_eq!(header, ["time", "x", "event_mode_used", "events"]);
        assert_rows(&rows, event_mode);
    }
    let out = cosim().arg("info").arg(&ssd).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("(CoSimulation, no Event Mode)"), "{text}");
}

/// The second try of an FMU that refuses eventModeUsed = true (`on`) is made in its host
/// process too (`--isolate`): the run is the one without Event Mode (x = 1.45 at 1 s), the
/// warning printed.
#[test]
fn under_on_the_second_try_is_made_in_the_host_too() {
    let Some((dir, _)) = event_model("event-mode-refused-isolated", XML) else { return };
    let ssd = one_component_ssd(&dir, "refuses");
    let csv = dir.join("isolated.csv");
    let mut command = cosim();
    command.arg("run").arg(&ssd).args(["--stop-time", "1", "--step", "0.1", "--event-mode", "on", "--isolate"]);
    command.env("NIGEL_COSIM_HOST", env!("CARGO_BIN_EXE_cosim-host")).arg("-o").arg(&csv);
    let out = command.output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("instantiated again without Event Mode"));
    assert_rows(&read_csv(&csv).1, false);
}

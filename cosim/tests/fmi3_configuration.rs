//! FMI 3.0 Configuration Mode: a structural parameter set with `--set` (or
//! [`SystemBuilder::set`]) goes through `fmi3EnterConfigurationMode` / the setter /
//! `fmi3ExitConfigurationMode` right after instantiation, and the arrays it sizes have the
//! new size in the master's view and the results. The C FMU `tests/cfmu/fmi3_sized.c`
//! (y[i] = k[i] u t after each step, k and y of size n, n set in Configuration Mode only,
//! every array get and set checked for exactly n values) against values derived by hand,
//! fmpy 0.3.32's low-level calls, and the PMSF `DynamicArrayTest` of the corpus when
//! the corpus is there (`common::corpus`).

mod common;
use common::fmi3_c::python;
use common::work_dir;
use nigel_cosim::{simulate, Experiment, Fmu, SystemBuilder, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The description of `cfmu/fmi3_sized.c` (the campaign's structural sweep builds it too).
const XML: &str = include_str!("cfmu/fmi3_sized.xml");

fn sized(test: &str) -> Option<(PathBuf, PathBuf)> {
    let dir = work_dir(test);
    let fmu = common::fmi3_c::build(&dir, "fmi3_sized", XML)?;
    Some((dir, fmu))
}

/// The names of the first instance's variables that start with `prefix` (an array's
/// elements, as the view has them after configuration).
fn element_names(system: &nigel_cosim::System, prefix: &str) -> Vec<String> {
    system
        .description(0)
        .model_variables
        .iter()
        .filter(|v| v.name.starts_with(prefix))
        .map(|v| v.name.clone())
        .collect()
}

/// The values of the columns `names` at each row of a run of `fmu` with the settings
/// `sets` (`name`, text) to 1 s in steps of 0.5 s.
fn run(fmu: &Path, sets: &[(&str, &str)]) -> nigel_cosim::Result<Vec<Vec<f64>>> {
    let mut b = SystemBuilder::new();
    b.add_instance("c", Fmu::load(fmu).unwrap()).unwrap();
    for (name, text) in sets {
        b.set_text(&format!("c.{name}"), text)?;
    }
    let system = b.build();
    let (result, _) = simulate(&system, &Experiment::new(1.0, 0.5))?;
    let names = element_names(&system, "y[");
    Ok((0..result.rows()).map(|r| names.iter().map(|n| result.column(n).unwrap()[r]).collect()).collect())
}

/// n = 4, k = [1 2 3 4], u = 2: y[i] = k[i] u t is [1 2 3 4] at 0.5 s and [2 4 6 8] at 1 s
/// (exact: small integers times 0.5 and 1); before the first step y is all 0 (the FMU's
/// arrays start at 0), four columns, not the two of n's start value.
#[test]
fn a_structural_parameter_sizes_its_arrays_through_configuration_mode() {
    let Some((_dir, fmu)) = sized("fmi3-configuration") else { return };
    let rows = run(&fmu, &[("n", "4"), ("k", "[1, 2, 3, 4]"), ("u", "2")]).unwrap();
    assert_eq!(rows, vec![vec![0.0; 4], vec![1.0, 2.0, 3.0, 4.0], vec![2.0, 4.0, 6.0, 8.0]]);
    // without it: n = 2, k = [1 1], u = 1: y = [t t]
    let rows = run(&fmu, &[]).unwrap();
    assert_eq!(rows, vec![vec![0.0; 2], vec![0.5, 0.5], vec![1.0, 1.0]]);
}

/// Values set before the structural parameter stay set, found again by name in the new
/// view: k = [3 5] then n = 3 gives k = [3 5 1] (the FMU's 1 for the new element), so y at
/// 1 s (u = 1) is [3 5 1]. An element the new size no longer has is refused naming it;
/// a size that is no whole number of the type, or beyond `max`, is refused too.
#[test]
fn values_set_before_are_kept_and_a_lost_element_or_a_bad_size_is_refused() {
    let Some((_dir, fmu)) = sized("fmi3-configuration-order") else { return };
    let rows = run(&fmu, &[("k", "[3, 5]"), ("n", "3")]).unwrap();
    assert_eq!(rows[2], vec![3.0, 5.0, 1.0]);
    let e = run(&fmu, &[("k", "[3, 5]"), ("n", "1")]).unwrap_err().to_string();
    assert!(e.contains("k[2] is set or connected, and the arrays n sizes no longer have it"), "{e}");
    let e = run(&fmu, &[("n", "2.5")]).unwrap_err().to_string();
    assert!(e.contains("not a whole number of UInt64"), "{e}");
    let e = run(&fmu, &[("n", "101")]).unwrap_err().to_string();
    assert!(e.contains("outside its range [1, 100]"), "{e}");
}

/// y (its three elements) at 1 s from fmpy 0.3.32's low-level calls on the FMU at `fmu`:
/// instantiate, `calls` (Python lines on the FMU3Slave `s`, ending in Step Mode at 0.5 s),
/// the step from 0.5 to 1 s.
fn fmpy_y_at_1s(fmu: &Path, calls: &str) -> Vec<f64> {
    let script = format!(
        r#"
import sys, zipfile, tempfile
from fmpy.fmi3 import FMU3Slave
d = tempfile.mkdtemp()
zipfile.ZipFile(sys.argv[1]).extractall(d)
s = FMU3Slave(guid='{{fmi3-sized}}', unzipDirectory=d, modelIdentifier='fmi3_sized', instanceName='c')
s.instantiate()
{calls}
s.doStep(0.5, 0.5)
print(' '.join(repr(x) for x in s.getFloat64([4], nValues=3)))
s.terminate()
s.freeInstance()
"#
    );
    let out = Command::new(python()).args(["-c", &script]).arg(fmu).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).split_whitespace().map(|x| x.parse().unwrap()).collect()
}

/// fmpy 0.3.32 driving the same FMU through its low-level calls (Configuration Mode, n = 3,
/// k = [2 3 4], u = 0.5, two steps of 0.5 s) reads the same y at 1 s as `cosim run` writes,
/// bit for bit; `cosim info` names the parameter and the arrays it sizes.
#[test]
fn cosim_run_equals_fmpy_low_level_calls_and_info_lists_the_parameter() {
    let Some((dir, fmu)) = sized("fmi3-configuration-fmpy") else { return };
    let theirs = fmpy_y_at_1s(
        &fmu,
        "s.enterConfigurationMode()
s.setUInt64([1], [3])
s.exitConfigurationMode()
s.setFloat64([2], [2.0, 3.0, 4.0])
s.setFloat64([3], [0.5])
s.enterInitializationMode(startTime=0.0)
s.exitInitializationMode()
s.doStep(0.0, 0.5)",
    );
    // k[i] u t at 1 s
    assert_eq!(theirs, [1.0, 1.5, 2.0]);
    let csv = dir.join("out.csv");
    let cosim = env!("CARGO_BIN_EXE_cosim");
    let fmu_arg = fmu.to_str().unwrap();
    let args = ["run", fmu_arg, "--stop-time", "1", "--step", "0.5", "--set", "n=3", "--set", "k=[2,3,4]"];
    let out = Command::new(cosim).args(args).args(["--set", "u=0.5", "-o", csv.to_str().unwrap()]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.contains(r#""y[1]","y[2]","y[3]""#) && !header.contains("y[4]"), "{header}");
    let last: Vec<f64> = lines.last().unwrap().split(',').map(|x| x.parse().unwrap()).collect();
    let columns: Vec<&str> = header.split(',').map(|h| h.trim_matches('"')).collect();
    let ours: Vec<f64> =
        ["y[1]", "y[2]", "y[3]"].iter().map(|n| last[columns.iter().position(|c| c == n).unwrap()]).collect();
    assert_eq!(ours, theirs);
    let info = Command::new(cosim).args(["info", fmu_arg]).output().unwrap();
    let info = String::from_utf8_lossy(&info.stdout);
    assert!(
        info.lines().any(|l| l
            == "structural parameter n (fixed, start 2, sizes k, y): set with --set n=VALUE, in Configuration Mode"),
        "{info}"
    );
}

/// The PMSF `DynamicArrayTest` (output = input * parameter, element by element, at each
/// step; arrays XSize x YSize, 4 x 3 by default) with XSize = 6, the parameter 0 .. 17 and
/// the input 2: 18 elements, the output 2 k for element k (0-based, row-major) after the
/// first step. Skipped without the corpus.
#[test]
fn the_corpus_dynamic_array_test_records_18_elements_with_xsize_6() {
    let fmu = common::fmi3_c::corpus().join("fmi3/cs/PMSF-FMI30TestFMUs/DynamicArrayTest/DynamicArrayTest.fmu");
    if !fmu.is_file() {
        eprintln!("{} not there: skipped", fmu.display());
        return;
    }
    let parameter: Vec<String> = (0..18).map(|k| k.to_string()).collect();
    // the FMU leaves the elements its resize adds (13 .. 18) uninitialized until its first
    // step: the row at 0 s holds whatever its memory held, now and then a NaN, which the
    // master would refuse as a non-finite output (seen: 7e160, 5e-324, NaN); the values
    // checked are those after the first step
    let options = nigel_cosim::ImportOptions { allow_non_finite: true, ..Default::default() };
    let mut b = SystemBuilder::new();
    b.add_instance("m", Fmu::load_with(&fmu, &options).unwrap()).unwrap();
    b.set("m.XSize", Value::Real(6.0)).unwrap();
    b.set_text("m.Float64Parameter", &format!("[{}]", parameter.join(","))).unwrap();
    b.set_text("m.Float64Input", &format!("[{}]", vec!["2"; 18].join(","))).unwrap();
    let system = b.build();
    let (result, _) = simulate(&system, &Experiment::new(0.04, 0.02)).unwrap();
    let outputs = element_names(&system, "Float64Output[");
    assert_eq!(outputs.len(), 18);
    assert_eq!((outputs[0].as_str(), outputs[17].as_str()), ("Float64Output[1,1]", "Float64Output[6,3]"));
    let after_first_step: Vec<f64> = outputs.iter().map(|n| result.column(n).unwrap()[1]).collect();
    assert_eq!(after_first_step, (0..18).map(|k| 2.0 * k as f64).collect::<Vec<_>>());
}

/// `fmi3Reset` puts the FMU back to n = 2 (this FMU's reset); the instance of a configured
/// FMU goes through Configuration Mode again, so that the view's four elements of k are
/// what the FMU holds after the reset too (a set of four values to an FMU with n = 2 is
/// its fmi3Error). y[4] = k[4] u t = 4 * 1 * 0.5 after one step.
#[test]
fn a_reset_configures_the_structural_parameters_again() {
    let Some((_dir, path)) = sized("fmi3-configuration-reset") else { return };
    let fmu = Fmu::load(&path).unwrap().configured("c", &[("n", 4.0)]).unwrap();
    assert_eq!(fmu.configuration(), [("n".to_string(), 4.0)]);
    let md = fmu.description();
    let vr = |name: &str| md.variable(name).unwrap().value_reference;
    let k: Vec<u32> = (1..=4).map(|i| vr(&format!("k[{i}]"))).collect();
    let mut instance = nigel_cosim::Instance::new(&fmu, "c").unwrap();
    instance.reset().unwrap();
    instance.set_real(&k, &[1.0, 2.0, 3.0, 4.0]).unwrap();
    instance.setup_experiment(None, 0.0, None).unwrap();
    instance.enter_initialization_mode().unwrap();
    instance.exit_initialization_mode().unwrap();
    instance.do_step(0.0, 0.5).unwrap();
    let mut y = [0.0];
    instance.get_real(&[vr("y[4]")], &mut y).unwrap();
    assert_eq!(y, [2.0]);
}

/// The description with n tunable: Reconfiguration Mode may change it between steps.
fn tunable_xml() -> String {
    let fixed = r#"causality="structuralParameter" variability="fixed""#;
    assert!(XML.contains(fixed));
    XML.replace(fixed, r#"causality="structuralParameter" variability="tunable""#)
}

/// `cosim run` of `fmu` to 1 s in steps of 0.5 s with `args`: the CSV's header and rows
/// (cells as text), or the error.
fn run_cli(fmu: &Path, dir: &Path, args: &[&str]) -> Result<(Vec<String>, Vec<Vec<String>>), String> {
    let csv = dir.join("out.csv");
    let out = Command::new(env!("CARGO_BIN_EXE_cosim"))
        .args(["run", fmu.to_str().unwrap(), "--stop-time", "1", "--step", "0.5", "-o", csv.to_str().unwrap()])
        .args(args)
        .output()
        .unwrap();
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).into_owned());
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(|h| h.trim_matches('"').to_string()).collect();
    Ok((header, lines.map(|l| l.split(',').map(str::to_string).collect()).collect()))
}

/// Reconfiguration Mode: `--set-at 0.5 n=3` with n tunable (start 2). The results have a
/// column for each element y can have (y[1] .. y[3]); the row at 0.5 s holds the values
/// before the change (as a row at a clock tick does), y[3] NaN there: n was 2. The FMU
/// resizes its arrays when it leaves (Re)Configuration Mode, k all 1 again, so at 1 s y[i] =
/// k[i] u t = 1 * 1 * 1 for the three elements. Shrinking (`--set n=3`, then `--set-at 0.5
/// n=1`) leaves y[2] and y[3] NaN after the change: y[1] = 1 at 1 s.
#[test]
fn a_tunable_structural_parameter_changes_between_steps_in_reconfiguration_mode() {
    let dir = work_dir("fmi3-reconfiguration");
    let Some(fmu) = common::fmi3_c::build(&dir, "fmi3_sized", &tunable_xml()) else { return };
    let (header, rows) = run_cli(&fmu, &dir, &["--set-at", "0.5", "n=3"]).unwrap();
    assert_eq!(header, ["time", "y[1]", "y[2]", "y[3]"]);
    let cells: Vec<Vec<&str>> = rows.iter().map(|r| r.iter().map(String::as_str).collect()).collect();
    assert_eq!(cells, [vec!["0", "0", "0", "NaN"], vec!["0.5", "0.5", "0.5", "NaN"], vec!["1", "1", "1", "1"]]);
    let (header, rows) = run_cli(&fmu, &dir, &["--set", "n=3", "--set-at", "0.5", "n=1"]).unwrap();
    assert_eq!(header, ["time", "y[1]", "y[2]", "y[3]"]);
    let cells: Vec<Vec<&str>> = rows.iter().map(|r| r.iter().map(String::as_str).collect()).collect();
    assert_eq!(cells, [vec!["0", "0", "0", "0"], vec!["0.5", "0.5", "0.5", "0.5"], vec!["1", "1", "NaN", "NaN"]]);
    // an input set the same way is a plain set: u = 2 from 0.5 s, y = k u t = 2 at 1 s
    let (header, rows) = run_cli(&fmu, &dir, &["--set-at", "0.5", "u=2"]).unwrap();
    assert_eq!(header, ["time", "y[1]", "y[2]"]);
    assert_eq!(rows[2], ["1", "2", "2"]);
    // fmpy's low-level calls through the same change: Reconfiguration Mode from Step Mode
    // after the first step, y read with its three elements after the second
    let theirs: Vec<String> = fmpy_y_at_1s(
        &fmu,
        "s.enterInitializationMode(startTime=0.0)
s.exitInitializationMode()
s.doStep(0.0, 0.5)
s.enterConfigurationMode()
s.setUInt64([1], [3])
s.exitConfigurationMode()",
    )
    .iter()
    .map(f64::to_string)
    .collect();
    let (_, rows) = run_cli(&fmu, &dir, &["--set-at", "0.5", "n=3"]).unwrap();
    assert_eq!(rows[2][1..], theirs);
    // Model Exchange: the change in an event at 0.5 s (Event Mode), the same rows (y = k u t
    // at the time set)
    let me = work_dir("fmi3-reconfiguration-me");
    let me_xml = tunable_xml().replace(
        r#"<CoSimulation modelIdentifier="fmi3_sized" canHandleVariableCommunicationStepSize="true"/>"#,
        r#"<ModelExchange modelIdentifier="fmi3_sized"/>"#,
    );
    let Some(me_fmu) = common::fmi3_c::build(&me, "fmi3_sized", &me_xml) else { return };
    let (header, rows) = run_cli(&me_fmu, &me, &["--set-at", "0.5", "n=3"]).unwrap();
    assert_eq!(header, ["time", "y[1]", "y[2]", "y[3]"]);
    let cells: Vec<Vec<&str>> = rows.iter().map(|r| r.iter().map(String::as_str).collect()).collect();
    assert_eq!(cells, [vec!["0", "0", "0", "NaN"], vec!["0.5", "0.5", "0.5", "NaN"], vec!["1", "1", "1", "1"]]);
    // an array n sizes as an event indicator: the integrator's count cannot change
    let indicators = work_dir("fmi3-reconfiguration-me-indicators");
    let xml = me_xml.replace(
        r#"<InitialUnknown valueReference="4"/>"#,
        r#"<InitialUnknown valueReference="4"/>
    <EventIndicator valueReference="4"/>"#,
    );
    let Some(fmu) = common::fmi3_c::build(&indicators, "fmi3_sized", &xml) else { return };
    let e = run_cli(&fmu, &indicators, &["--set-at", "0.5", "n=3"]).unwrap_err();
    assert!(e.contains("it sizes y, a continuous state, derivative or event indicator of a Model Exchange FMU"), "{e}");
    // a fixed structural parameter is not changed during a run
    let fixed = work_dir("fmi3-reconfiguration-fixed");
    let Some(fmu) = common::fmi3_c::build(&fixed, "fmi3_sized", XML) else { return };
    let e = run_cli(&fmu, &fixed, &["--set-at", "0.5", "n=3"]).unwrap_err();
    assert!(e.contains("a fixed structural parameter is set before initialization only"), "{e}");
}

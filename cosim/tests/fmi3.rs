//! FMI 3.0 Co-Simulation with a C test FMU written against the standard's headers
//! (`tests/cfmu/fmi3_counter.c`: y grows by mode * u * h per step; early return and
//! termination when asked): load, the view the master works with, runs, parameters of
//! every type the view has, early return, termination, FMU state, `cosim info` and
//! `cosim run`, refusals; and the results against fmpy 0.3.32's.
//!
//! The headers come from fmpy's package (`fmpy/c-code`), found with `$FMPY_PYTHON`
//! (default `python3`); without fmpy the tests are skipped, unless `$FMPY_PYTHON` is set.

mod common;
use common::{build_counter, work_dir};
use nigel_cosim::{simulate, Experiment, Fmu, Instance, System, SystemBuilder, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

use common::fmi3_c::python;

const XML: &str = include_str!("cfmu/fmi3_counter.xml");

fn counter(test: &str) -> Option<(PathBuf, PathBuf)> {
    let dir = work_dir(test);
    let fmu = build_counter(&dir, "fmi3_counter", XML)?;
    Some((dir, fmu))
}

fn with_starts(fmu: &Path, starts: &[(&str, Value)]) -> System {
    let mut b = SystemBuilder::new();
    b.add_instance("c", Fmu::load(fmu).unwrap()).unwrap();
    for (name, value) in starts {
        b.set(&format!("c.{name}"), value.clone()).unwrap();
    }
    b.build()
}

/// y after the steps `steps`, summed as the FMU sums them (u = 1).
fn summed(steps: &[f64], scale: f64) -> f64 {
    steps.iter().fold(0.0, |y, h| y + scale * 1.0 * h)
}

/// The steps the master took: the differences of its time grid t0 + k h.
fn steps_of(time: &[f64]) -> Vec<f64> {
    time.windows(2).map(|w| w[1] - w[0]).collect()
}

#[test]
fn the_view_has_the_scalars_and_the_description_every_variable() {
    let Some((_dir, path)) = counter("fmi3-view") else { return };
    let fmu = Fmu::load(&path).unwrap();
    let md3 = fmu.fmi3_description().expect("an FMI 3.0 FMU");
    assert_eq!(md3.instantiation_token, "{fmi3-counter}");
    assert_eq!(md3.model_variables.len(), 36);
    let view = fmu.description();
    assert_eq!(view.fmi_version, "3.0");
    // the three arrays as their 3 + 2 + 2 elements
    assert_eq!(view.model_variables.len(), 40);
    let names: Vec<&str> = view.model_variables.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names[24..29], ["arr[1]", "arr[2]", "arr[3]", "gains[1]", "gains[2]"]);
    assert_eq!(view.states(), vec![3], "y, variable 3 of the view, is the state of der(y)");
    assert_eq!(view.number_of_event_indicators, 1);
    assert!(fmu.not_in_view().is_empty());
    assert_eq!(view.variable("y").unwrap().variable_type.type_name(), "Real");
    let mode = &view.variable("mode").unwrap().variable_type;
    assert!(
        matches!(mode, model_description::VariableType::Enumeration { declared_type, .. } if declared_type == "Mode"),
        "{mode:?}"
    );
    assert_eq!(view.variable("n").unwrap().variable_type.type_name(), "Integer");
    assert_eq!(view.model_structure.outputs.len(), 5 + 10 + 3 + 2 + 1 + 2);
    assert!(fmu.can_get_and_set_state());
}

#[test]
fn a_run_steps_the_fmu_and_records_every_type() {
    let Some((_dir, path)) = counter("fmi3-run") else { return };
    let system = with_starts(&path, &[("k", Value::Integer(21)), ("b", Value::Boolean(true))]);
    let (r, summary) = simulate(&system, &Experiment::new(1.0, 0.1)).unwrap();
    assert_eq!(r.rows(), 11);
    assert_eq!(summary.steps, 10);
    let y = r.column("y").unwrap();
    let n = r.column("n").unwrap();
    let odd = r.column("odd").unwrap();
    let steps = steps_of(&r.column("time").unwrap());
    for k in 0..11 {
        assert_eq!(y[k], summed(&steps[..k], 1.0), "row {k}");
        assert_eq!(n[k], k as f64);
        assert_eq!(odd[k], (k % 2) as f64);
    }
    assert_eq!(r.column("m").unwrap(), vec![42.0; 11], "Int32 input 21 set before initialization, output 2 k");
    assert_eq!(r.column("nb").unwrap(), vec![0.0; 11], "Boolean input true, output its negation");
}

#[test]
fn an_enumeration_parameter_is_set_through_int64() {
    let Some((_dir, path)) = counter("fmi3-enum") else { return };
    let system = with_starts(&path, &[("mode", Value::Integer(2))]);
    let (r, _) = simulate(&system, &Experiment::new(0.5, 0.1)).unwrap();
    let steps = steps_of(&r.column("time").unwrap());
    assert_eq!(*r.column("y").unwrap().last().unwrap(), summed(&steps, 2.0));
    // the FMU refuses mode 3 (fmi3SetInt64 returns fmi3Error): an error naming the call
    let system = with_starts(&path, &[("mode", Value::Integer(3))]);
    let e = simulate(&system, &Experiment::new(0.5, 0.1)).unwrap_err();
    assert!(e.to_string().contains("fmi3SetInt64"), "{e}");
    assert!(e.to_string().contains("mode must be 1 or 2"), "the FMU's message: {e}");
}

#[test]
fn an_early_return_is_continued_to_the_end_of_the_step() {
    let Some((_dir, path)) = counter("fmi3-early") else { return };
    let system = with_starts(&path, &[("early_at", Value::Real(0.35))]);
    let (r, summary) = simulate(&system, &Experiment::new(1.0, 0.1)).unwrap();
    assert_eq!(summary.steps, 10);
    let y = r.column("y").unwrap();
    let steps = steps_of(&r.column("time").unwrap());
    assert_eq!(y[3], summed(&steps[..3], 1.0), "before the step that returned early");
    // the step (0.3, 0.4] was taken as (0.3, 0.35] and (0.35, 0.4]: its y is 0.4 up to
    // the roundings of the two parts (each below 0.5 ulp of 0.4)
    assert!((y[4] - 0.4).abs() <= 2.0 * f64::EPSILON * 0.4, "{}", y[4]);
    assert_eq!(r.column("n").unwrap()[4], 4.0, "the returned part is no step of its own");
    assert!((y[10] - 1.0).abs() < 16.0 * f64::EPSILON, "{}: 11 roundings of values below 1", y[10]);
}

#[test]
fn terminate_simulation_ends_the_run_there() {
    let Some((_dir, path)) = counter("fmi3-terminate") else { return };
    let system = with_starts(&path, &[("stop_at", Value::Real(0.45))]);
    let (r, summary) = simulate(&system, &Experiment::new(1.0, 0.1)).unwrap();
    let time = r.column("time").unwrap();
    // the step (0.4, 0.5] said terminateSimulation: its row is the last
    assert_eq!(*time.last().unwrap(), 5.0 * 0.1);
    assert_eq!(*r.column("n").unwrap().last().unwrap(), 5.0);
    let (instance, t_end, reason) = summary.ended_by.clone().unwrap();
    assert_eq!((instance.as_str(), t_end), ("c", 0.5));
    assert_eq!(reason, "fmi3DoStep returned terminateSimulation");
}

#[test]
fn fmu_state_and_strings_round_trip() {
    let Some((_dir, path)) = counter("fmi3-state") else { return };
    let fmu = Fmu::load(&path).unwrap();
    let mut inst = Instance::new(&fmu, "c").unwrap();
    inst.setup_experiment(None, 0.0, Some(1.0)).unwrap();
    inst.set_string(6, "hello").unwrap();
    inst.enter_initialization_mode().unwrap();
    inst.exit_initialization_mode().unwrap();
    assert_eq!(inst.get_string(6).unwrap(), "hello");
    inst.do_step(0.0, 0.25).unwrap();
    let saved = inst.get_state().unwrap();
    let mut y = [0.0];
    inst.get_real(&[2], &mut y).unwrap();
    assert_eq!(y[0], 0.25);
    inst.do_step(0.25, 0.5).unwrap();
    inst.get_real(&[2], &mut y).unwrap();
    assert_eq!(y[0], 0.75);
    inst.set_state(&saved).unwrap();
    inst.get_real(&[2], &mut y).unwrap();
    assert_eq!(y[0], 0.25, "restored");
    inst.free_state(saved).unwrap();
    let mut flags = [7, 7];
    inst.set_boolean(&[11], &[5]).unwrap(); // nonzero is true
    inst.get_boolean(&[11, 12], &mut flags).unwrap();
    assert_eq!(flags, [1, 0], "read back as 0 or 1");
    let e = inst.get_real(&[99], &mut y).unwrap_err();
    assert!(e.to_string().contains("fmi3GetFloat64") && e.to_string().contains("no such Float64"), "{e}");
}

#[test]
fn bad_fmi3_input_is_refused() {
    let dir = work_dir("fmi3-refused");
    let cases = [
        ("token", XML.replace("instantiationToken=\"{fmi3-counter}\"", "instantiationToken=\"{other}\""), "wrong instantiationToken"),
        ("dupvr", XML.replace("name=\"k\" valueReference=\"9\"", "name=\"k\" valueReference=\"1\""), "duplicate-value-reference"),
        ("unknown", XML.replace("<Int32 name=\"k\"", "<Int128 name=\"k\"").replace("start=\"0\"/>\n    <Int32 name=\"m\"", "start=\"0\"/>\n    <Int32 name=\"m\""), "unknown element <Int128>"),
        ("malformed", XML.replace("</ModelVariables>", ""), "malformed XML"),
        (
            "clock",
            XML.replace("</ModelVariables>", "<Clock name=\"tick\" valueReference=\"40\" causality=\"input\" intervalVariability=\"triggered\"/></ModelVariables>"),
            // the counter has no Event Mode, where the master would run its clocks
            "clocks in Co-Simulation without Event Mode (hasEventMode) (Clock variable \"tick\")",
        ),
        ("noindependent", XML.replace("causality=\"independent\" ", ""), "independent"),
    ];
    for (stem, xml, expected) in cases {
        let Some(path) = build_counter(&dir, stem, &xml) else { return };
        let e = match Fmu::load(&path) {
            Ok(fmu) => Instance::new(&fmu, "c").map(|_| ()).unwrap_err(),
            Err(e) => e,
        };
        assert!(e.to_string().contains(expected), "{stem}: {e}");
        if stem == "token" {
            assert!(
                matches!(&e, nigel_cosim::ImportError::Instantiate { function: "fmi3InstantiateCoSimulation", .. }),
                "{e:?}"
            );
        }
    }
}

fn cosim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cosim")).args(args).output().unwrap()
}

/// `cosim run FMU --stop-time STOP --step 0.1 --output OUT EXTRA...` (OUT removed first).
fn run_to_csv(fmu: &Path, stop: &str, out: &Path, extra: &[&str]) -> std::process::Output {
    let _ = std::fs::remove_file(out);
    let mut args =
        vec!["run", fmu.to_str().unwrap(), "--stop-time", stop, "--step", "0.1", "--output", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    cosim(&args)
}

#[test]
fn cosim_info_and_run() {
    let Some((dir, path)) = counter("fmi3-cli") else { return };
    let out = cosim(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.starts_with("model fmi3_counter (FMI 3.0), instantiationToken {fmi3-counter}"), "{text}");
    assert!(text.contains("interfaces: CoSimulation (fmi3_counter; variable step, early return, FMU state)"), "{text}");
    let mode = text.lines().find(|l| l.starts_with("mode ")).unwrap();
    assert!(mode.contains("Enumeration") && mode.contains("parameter"), "{mode}");
    let label = text.lines().find(|l| l.starts_with("label ")).unwrap();
    assert!(label.contains("String") && label.contains("\"abc\""), "{label}");

    let csv = dir.join("out.csv");
    let out = run_to_csv(&path, "1", &csv, &["--set", "u=2", "--set", "gains=[3, 4]"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "\"y\"").unwrap();
    let last: Vec<&str> = text.lines().last().unwrap().split(',').collect();
    let y: f64 = last[col].parse().unwrap();
    assert!((y - 2.0).abs() < 1e-14, "{y}");
    // the array set whole: gy = 3 y + 4; its elements are columns of their own
    let gy = header.iter().position(|h| *h == "\"gy\"").unwrap();
    assert_eq!(last[gy].parse::<f64>().unwrap(), 3.0 * y + 4.0);
    assert!(header.contains(&"\"arr[3]\""), "{header:?}");
    let out = cosim(&["run", path.to_str().unwrap(), "--stop-time", "1", "--set", "gains=[1 2 3]"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("3 values for the 2 elements of the array"), "{err}");
}

/// fmpy 0.3.32 runs the same FMU with the same step and start values of every type the
/// view has: the same outputs, bit for bit.
#[test]
fn results_equal_fmpys() {
    let Some((dir, path)) = counter("fmi3-fmpy") else { return };
    let csv = dir.join("fmpy.csv");
    let script = r#"
import sys
from fmpy import simulate_fmu
COLUMNS = ['y', 'n', 'odd', 'm', 'nb', 'f32', 'i8', 'u8', 'i16', 'u16', 'u32', 'i64', 'u64', 'f32out']
r = simulate_fmu(sys.argv[1], fmi_type='CoSimulation', stop_time=1.0, output_interval=0.1,
                 start_values={'u': 0.3, 'mode': 2, 'k': 5, 'b': True, 'label': 'xyz', 'f32in': 0.1},
                 output=COLUMNS)
with open(sys.argv[2], 'w') as f:
    for row in r:
        f.write(' '.join(repr(float(row[c])) for c in ['time'] + COLUMNS) + '\n')
"#;
    let out = Command::new(python()).args(["-c", script]).arg(&path).arg(&csv).output().unwrap();
    assert!(out.status.success(), "fmpy: {}", String::from_utf8_lossy(&out.stderr));
    let theirs: Vec<Vec<f64>> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
        .collect();
    let system = with_starts(
        &path,
        &[
            ("u", Value::Real(0.3)),
            ("mode", Value::Integer(2)),
            ("k", Value::Integer(5)),
            ("b", Value::Boolean(true)),
            ("label", Value::String("xyz".into())),
            ("f32in", Value::Real(0.1)),
        ],
    );
    let (r, _) = simulate(&system, &Experiment::new(1.0, 0.1)).unwrap();
    let ours: Vec<Vec<f64>> = (0..r.rows())
        .map(|k| {
            ["time", "y", "n", "odd", "m", "nb", "f32", "i8", "u8", "i16", "u16", "u32", "i64", "u64", "f32out"]
                .iter()
                .map(|c| r.column(c).unwrap()[k])
                .collect()
        })
        .collect();
    assert_eq!(ours.len(), theirs.len(), "rows: ours {ours:?}\nfmpy {theirs:?}");
    for (a, b) in ours.iter().zip(&theirs) {
        assert_eq!(a, b, "ours vs fmpy");
    }
}

/// fmpy 0.3.32's `simulate_fmu(fmu, stop_time=1.0, output_interval=0.1, ARGUMENTS)` rows of
/// time, y and n (written to `csv` and read back).
fn fmpy_rows(fmu: &Path, csv: &Path, arguments: &str) -> Vec<Vec<f64>> {
    let script = format!(
        "import sys\nfrom fmpy import simulate_fmu\n\
         r = simulate_fmu(sys.argv[1], stop_time=1.0, output_interval=0.1, output=['y', 'n'], {arguments})\n\
         with open(sys.argv[2], 'w') as f:\n    \
         for row in r:\n        \
         f.write(' '.join(repr(float(row[c])) for c in ['time', 'y', 'n']) + '\\n')\n"
    );
    let out = Command::new(python()).args(["-c", &script]).arg(fmu).arg(csv).output().unwrap();
    assert!(out.status.success(), "fmpy: {}", String::from_utf8_lossy(&out.stderr));
    std::fs::read_to_string(csv).unwrap().lines().map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect()).collect()
}

fn model_exchange(fmu: &Path, starts: &[(&str, Value)]) -> System {
    let options = nigel_cosim::ImportOptions {
        interface: Some(nigel_cosim::Interface::ModelExchange),
        ..nigel_cosim::ImportOptions::default()
    };
    let mut b = SystemBuilder::new();
    b.add_instance("c", Fmu::load_with(fmu, &options).unwrap()).unwrap();
    for (name, value) in starts {
        b.set(&format!("c.{name}"), value.clone()).unwrap();
    }
    b.build()
}

/// Model Exchange: the master integrates y' = mode u (RK4, exact for a constant slope up to
/// rounding) and finds the crossing of z = y - 0.55 (counted in n by the FMU's
/// fmi3UpdateDiscreteStates) between the rows at 0.5 and 0.6.
#[test]
fn model_exchange_integrates_and_finds_the_state_event() {
    let Some((_dir, path)) = counter("fmi3-me") else { return };
    let system = model_exchange(&path, &[("mode", Value::Integer(2))]);
    let (r, _) = simulate(&system, &Experiment::new(1.0, 0.1)).unwrap();
    let (time, y, n) = (r.column("time").unwrap(), r.column("y").unwrap(), r.column("n").unwrap());
    assert_eq!(r.rows(), 11);
    for k in 0..11 {
        // a few roundings of values up to 2 per step
        assert!((y[k] - 2.0 * time[k]).abs() < 64.0 * f64::EPSILON, "t = {}: y = {}", time[k], y[k]);
        // 2 t crosses 0.55 at t = 0.275 (+1), the time event at 0.75 (+10)
        let expected = if time[k] > 0.275 { 1.0 } else { 0.0 } + if time[k] >= 0.75 { 10.0 } else { 0.0 };
        assert_eq!(n[k], expected, "t = {}", time[k]);
    }
}

/// Model Exchange: terminateSimulation from fmi3UpdateDiscreteStates at the time event at
/// stop_at ends the run there, with the row at that event (as in Co-Simulation and as the
/// FMI 2.0 path writes it).
#[test]
fn model_exchange_terminates_at_the_time_event() {
    let Some((_dir, path)) = counter("fmi3-me-end") else { return };
    let system = model_exchange(&path, &[("stop_at", Value::Real(0.62))]);
    let (r, summary) = simulate(&system, &Experiment::new(1.0, 0.1)).unwrap();
    let (instance, t_end, reason) = summary.ended_by.clone().unwrap();
    assert_eq!((instance.as_str(), t_end, reason), ("c", 0.62, "terminateSimulation"));
    assert_eq!(r.rows(), 8, "rows 0 .. 0.6, then 0.62");
    assert_eq!(r.row(7)[0], 0.62);
}

/// fmpy 0.3.32 integrates the same FMU in Model Exchange (CVode): the same event count, and
/// y within its tolerance.
#[test]
fn model_exchange_agrees_with_fmpy() {
    let Some((dir, path)) = counter("fmi3-me-fmpy") else { return };
    let theirs = fmpy_rows(&path, &dir.join("fmpy.csv"), "fmi_type='ModelExchange', start_values={'u': 1.0}");
    let (r, _) = simulate(&model_exchange(&path, &[("u", Value::Real(1.0))]), &Experiment::new(1.0, 0.1)).unwrap();
    assert_eq!(*r.column("n").unwrap().last().unwrap(), 11.0, "y = t crossed 0.55 (+1), the time event at 0.75 (+10)");
    // fmpy records rows before and after the event at t = 0.55 besides: the grid's only
    let at_grid: Vec<&Vec<f64>> =
        theirs.iter().filter(|row| (row[0] * 10.0 - (row[0] * 10.0).round()).abs() < 1e-9).collect();
    assert_eq!(at_grid.len(), r.rows(), "{theirs:?}");
    for (k, row) in at_grid.iter().enumerate() {
        assert_eq!(row[0], r.column("time").unwrap()[k]);
        // CVode at fmpy's default relative tolerance 1e-4 on a linear solution
        assert!(
            (row[1] - r.column("y").unwrap()[k]).abs() < 1e-4,
            "t = {}: {} vs {}",
            row[0],
            row[1],
            r.column("y").unwrap()[k]
        );
        assert_eq!(row[2], r.column("n").unwrap()[k]);
    }
}

/// FMI 2.0 and FMI 3.0 instances in one system, connected by names (Real <-> Float64): an
/// FMI 2.0 source (y = t) feeds the FMI 3.0 counter's u, whose y feeds an FMI 2.0 gain
/// (y = 2 u). The counter (no direct feedthrough) adds the source's value at the step's
/// start times h under both algorithms; the gain (direct feedthrough) doubles the counter's
/// y of the same communication point under `ordered` (the inputs set in topological order)
/// and of the point before under `jacobi`. Both as built and as written to an SSP and read
/// back.
#[test]
fn fmi2_and_fmi3_instances_in_one_system() {
    use nigel_cosim::{read_ssp, Algorithm, ImportOptions};
    let Some((dir, counter_fmu)) = counter("fmi3-mixed") else { return };
    let (system, ssp) = mixed_system(&dir, &counter_fmu);
    let from_ssp = read_ssp(&ssp, &ImportOptions::default()).unwrap().system;
    let out = cosim(&["info", ssp.to_str().unwrap()]);
    assert!(out.status.success(), "cosim info of the mixed SSP: {}", String::from_utf8_lossy(&out.stderr));
    for algorithm in [Algorithm::Ordered, Algorithm::Jacobi] {
        let experiment = Experiment { algorithm, ..Experiment::new(1.0, 0.1) };
        let (r, _) = simulate(&system, &experiment).unwrap();
        let (rs, _) = simulate(&from_ssp, &experiment).unwrap();
        assert_eq!((&r.names, &r.values), (&rs.names, &rs.values), "{algorithm:?}: the SSP's run is the system's");
        let time = r.column("time").unwrap();
        let ys = r.column("source.y").unwrap();
        let yc = r.column("counter.y").unwrap();
        let yg = r.column("gain.y").unwrap();
        assert_eq!(ys, time, "the FMI 2.0 source: y = t");
        for k in 1..r.rows() {
            let h = time[k] - time[k - 1];
            let g = match algorithm {
                Algorithm::Ordered => yc[k],
                _ => yc[k - 1],
            };
            assert_eq!(yc[k], yc[k - 1] + 1.0 * ys[k - 1] * h, "{algorithm:?}: counter at t = {}", time[k]);
            assert_eq!(yg[k], 2.0 * g, "{algorithm:?}: gain at t = {}", time[k]);
        }
    }
}

/// The FMI 2.0 source, the FMI 3.0 counter (`counter_fmu`) and the FMI 2.0 gain of
/// `fmi2_and_fmi3_instances_in_one_system`, and the same system written to `dir/mixed.ssp`.
fn mixed_system(dir: &Path, counter_fmu: &Path) -> (System, PathBuf) {
    use common::{build_fmu, Model};
    let source = build_fmu(Model::Source, dir, &[]);
    let gain = build_fmu(Model::Gain, dir, &[]);
    let mut b = SystemBuilder::new();
    b.add_instance("source", Fmu::load(&source).unwrap()).unwrap();
    b.add_instance("counter", Fmu::load(counter_fmu).unwrap()).unwrap();
    b.add_instance("gain", Fmu::load(&gain).unwrap()).unwrap();
    b.connect_unconverted("source.y", "counter.u", None).unwrap();
    b.connect("counter.y", "gain.u").unwrap();
    let system = b.build();
    let ssp = dir.join("mixed.ssp");
    nigel_cosim::write_ssp(&system, "mixed", Some(1.0), &ssp).unwrap();
    (system, ssp)
}

/// Every FMI 3.0 type recorded: each output of the counter against its definition in
/// fmi3_counter.c, an array element set alone (`gains[2]`), a Float32 input.
#[test]
fn every_type_and_array_elements_are_recorded() {
    let Some((_dir, path)) = counter("fmi3-types") else { return };
    let system = with_starts(&path, &[("gains[2]", Value::Real(5.0)), ("f32in", Value::Real(0.1))]);
    let (r, _) = simulate(&system, &Experiment::new(1.0, 0.1)).unwrap();
    let col = |name: &str| r.column(name).unwrap_or_else(|| panic!("no column {name}: {:?}", r.names));
    let (y, n) = (col("y"), col("n"));
    for k in 0..r.rows() {
        let (y, n) = (y[k], n[k]);
        assert_eq!(col("f32")[k], y as f32 as f64, "Float32: the f32 of y, widened exactly");
        assert_eq!(col("i8")[k], n - 5.0);
        assert_eq!(col("u8")[k], 20.0 * n);
        assert_eq!(col("i16")[k], -1000.0 * n);
        assert_eq!(col("u16")[k], 6000.0 * n);
        assert_eq!(col("u32")[k], 4e8 * n);
        assert_eq!(col("i64")[k], -(2f64.powi(40)) * n);
        assert_eq!(col("u64")[k], 2f64.powi(48) * n);
        assert_eq!(col("bin")[k], n, "a Binary recorded as its size");
        assert_eq!([col("arr[1]")[k], col("arr[2]")[k], col("arr[3]")[k]], [y, 2.0 * y, 3.0 * y]);
        assert_eq!(col("gy")[k], 1.0 * y + 5.0, "gains[1] kept its start value 1, gains[2] set to 5");
        assert_eq!([col("flags[1]")[k], col("flags[2]")[k]], [n % 2.0, 1.0 - n % 2.0]);
        assert_eq!(col("f32out")[k], 2.0 * (0.1f32 as f64), "2 f32in, f32in the f32 nearest 0.1");
    }
    // a value that is not one of the type's is refused, naming the variable
    let fmu = Fmu::load(&path).unwrap();
    let mut inst = Instance::new(&fmu, "c").unwrap();
    let n_vr = fmu.description().variable("gains[1]").unwrap().value_reference;
    inst.set_real(&[n_vr], &[3.0]).unwrap();
    let e = inst.set_real(&[fmu.description().variable("bin").unwrap().value_reference], &[1.0]).unwrap_err();
    assert!(e.to_string().contains("c.bin") && e.to_string().contains("cannot be set"), "{e}");
}

/// `--isolate=run` (the whole run in one host) and `--isolate=fmu` / `--isolate` (a host
/// per FMU, the FMI 3.0 calls carried through the shared region to the host, which calls
/// the FMU's functions with the master's arguments) write the CSV of the run in process,
/// byte for byte, under `jacobi` and `ordered`: plain steps (every type of the view read
/// through the typed getters), an early return (`early_at`: `earlyReturn` and
/// `lastSuccessfulTime` through the host), `terminateSimulation` (`stop_at`), Event Mode
/// (`hasEventMode`, `--event-mode on`: `fmi3UpdateDiscreteStates`, `fmi3EnterStepMode`), and Model Exchange
/// (the master's solver through the host: states, derivatives, event indicators; with
/// `mode=2` the state event near 0.275 s and the time event at 0.75 s, with `stop_at` the
/// termination at the time event). A set the FMU refuses (`mode=3`), queued in the host
/// for the next call, is the error of that call naming the set and the FMU's message.
#[test]
fn isolation_of_fmi3_fmus() {
    let Some((dir, path)) = counter("fmi3-isolate") else { return };
    let xml = XML.replace(
        "mightReturnEarlyFromDoStep=\"true\"/>",
        "mightReturnEarlyFromDoStep=\"true\" hasEventMode=\"true\"/>",
    );
    let Some(event_mode) = build_counter(&dir, "event_mode", &xml) else { return };
    let cases: [(&Path, &[&str]); 6] = [
        (&path, &[]),
        (&path, &["--set", "early_at=0.35"]),
        (&path, &["--set", "stop_at=0.45"]),
        // without clocks Event Mode is used when asked for (tests/event_mode.rs)
        (&event_mode, &["--event-mode", "on"]),
        (&path, &["--interface", "me", "--set", "mode=2"]),
        (&path, &["--interface", "me", "--set", "stop_at=0.62"]),
    ];
    for (case, (fmu, sets)) in cases.iter().enumerate() {
        for algorithm in ["jacobi", "ordered"] {
            let run = |isolate: &[&str], out: &Path| {
                run_to_csv(fmu, "1", out, &[&["--algorithm", algorithm][..], sets, isolate].concat())
            };
            let plain = dir.join(format!("plain-{case}-{algorithm}.csv"));
            let out = run(&[], &plain);
            assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
            let expected = std::fs::read_to_string(&plain).unwrap();
            assert!(expected.lines().count() > 5, "{case}: {expected}");
            for isolate in ["--isolate=run", "--isolate=fmu", "--isolate"] {
                let hosted = dir.join(format!("hosted-{case}-{algorithm}{isolate}.csv"));
                let out = run(&[isolate], &hosted);
                assert!(out.status.success(), "{case} {algorithm} {isolate}: {}", String::from_utf8_lossy(&out.stderr));
                let got = std::fs::read_to_string(&hosted).unwrap();
                assert_eq!(got, expected, "{case} {algorithm} {isolate}");
            }
        }
    }
    let out = run_to_csv(&path, "1", &dir.join("refused.csv"), &["--set", "mode=3", "--isolate=fmu"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cosim: model: fmi3EnterInitializationMode returned"), "{err}");
    assert!(err.contains("fmi3SetInt64 (sent with fmi3EnterInitializationMode) returned"), "{err}");
    assert!(err.contains("mode must be 1 or 2"), "{err}");
}

/// Systems with FMI 3.0 FMUs under `--isolate=fmu`: the closed loop of FMI 3.0 FMUs
/// (target/ssp/nigel_closed_loop_fmi3.ssp) and the FMI 2.0 source, FMI 3.0 counter and FMI
/// 2.0 gain of `fmi2_and_fmi3_instances_in_one_system` as an SSP give the CSV of the run in
/// process byte for byte, under `jacobi` and `ordered` (the hosts' steps overlapped).
#[test]
fn isolated_systems_with_fmi3_fmus_equal_in_process() {
    let Some((dir, counter_fmu)) = counter("fmi3-isolate-systems") else { return };
    let (_, mixed) = mixed_system(&dir, &counter_fmu);
    let closed_loop = common::plant_fmu().parent().unwrap().parent().unwrap().join("ssp/nigel_closed_loop_fmi3.ssp");
    assert!(closed_loop.is_file(), "{} missing: run `cargo run --release -p build-fmu` first", closed_loop.display());
    for (name, ssp, stop, step) in [("mixed", &mixed, "1", "0.1"), ("closed-loop", &closed_loop, "0.3", "0.001")] {
        for algorithm in ["jacobi", "ordered"] {
            let run = |isolate: &[&str], out: &Path| {
                let _ = std::fs::remove_file(out);
                let mut args = vec!["run", ssp.to_str().unwrap(), "--stop-time", stop, "--step", step];
                args.extend_from_slice(&["--algorithm", algorithm, "--output", out.to_str().unwrap()]);
                args.extend_from_slice(isolate);
                cosim(&args)
            };
            let plain = dir.join(format!("{name}-{algorithm}.csv"));
            let out = run(&[], &plain);
            assert!(out.status.success(), "{name} {algorithm}: {}", String::from_utf8_lossy(&out.stderr));
            let hosted = dir.join(format!("{name}-{algorithm}-isolated.csv"));
            let out = run(&["--isolate=fmu"], &hosted);
            assert!(out.status.success(), "{name} {algorithm}: {}", String::from_utf8_lossy(&out.stderr));
            let expected = std::fs::read_to_string(&plain).unwrap();
            assert!(expected.lines().count() > 10, "{name}: {expected}");
            assert_eq!(std::fs::read_to_string(&hosted).unwrap(), expected, "{name} {algorithm}");
        }
    }
}

/// A misbehaving FMI 3.0 FMU under `--isolate=run` and `--isolate=fmu`, as crash.c is for
/// FMI 2.0: a write through NULL, abort() or exit(0) inside fmi3DoStep (Co-Simulation, the
/// step from 0.5 s, crash_at = 0.45) or inside the fmi3UpdateDiscreteStates of the time
/// event the FMU asks for at crash_at (Model Exchange) ends only the host: exit code 1, an error naming the instance, the call, the
/// time and the signal or exit code (under `--isolate=run` the host's exit guard reports
/// the exit(); under `--isolate=fmu` the master sees the FMU's host exit with code 0),
/// and the CSV with the rows before (Co-Simulation 0 .. 0.5 s; Model Exchange 0 .. 0.4 s,
/// the grid points before the event), each equal to the same rows of a run without the
/// crash.
#[test]
fn a_crashing_fmi3_fmu_under_isolation_is_a_typed_error_with_the_rows_so_far() {
    let Some((dir, path)) = counter("fmi3-crash") else { return };
    let run = |extra: &[&str], out: &Path| run_to_csv(&path, "1", out, extra);
    let rows = |p: &Path| -> Vec<String> {
        std::fs::read_to_string(p).unwrap_or_default().lines().skip(1).map(String::from).collect()
    };
    for (interface, isolate, function, time, kept) in [
        ("cs", "--isolate=run", "fmi3DoStep", "0.5", 6),
        ("cs", "--isolate=fmu", "fmi3DoStep", "0.5", 6),
        ("me", "--isolate=run", "fmi3UpdateDiscreteStates", "0.45", 5),
        ("me", "--isolate=fmu", "fmi3UpdateDiscreteStates", "0.45", 5),
    ] {
        let whole = dir.join(format!("whole-{interface}{isolate}.csv"));
        let out = run(&["--interface", interface, isolate], &whole);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        for how in 1..=3 {
            let crashed = dir.join(format!("crashed-{interface}{isolate}-{how}.csv"));
            let how_arg = format!("crash_how={how}");
            let out = run(&["--interface", interface, isolate, "--set", "crash_at=0.45", "--set", &how_arg], &crashed);
            assert_eq!(out.status.code(), Some(1), "{interface} {isolate} {how}");
            let err = String::from_utf8_lossy(&out.stderr);
            let want = match (how, isolate) {
                (1, _) => format!("cosim: model: the FMU's host process was killed by signal 11 (SIGSEGV) during {function} at t = {time} s"),
                (2, _) => format!("cosim: model: the FMU's host process was killed by signal 6 (SIGABRT) during {function} at t = {time} s"),
                // the host of the run's exit guard names the call the exit() came from, then ends with code 1
                (_, "--isolate=run") => format!("model (fmi3_counter.fmu) called exit() inside {function} at t = {time} s, ending the process in the middle of the run"),
                // the FMU's own host ends with the FMU's code
                _ => format!("cosim: model: the FMU's host process exited with code 0 during {function} at t = {time} s"),
            };
            assert!(err.lines().any(|l| l == want), "{interface} {isolate} {how}: {err}");
            assert_eq!(
                rows(&crashed),
                rows(&whole)[..kept],
                "{interface} {isolate} {how}: the rows before the crash: {err}"
            );
        }
    }
}

/// The counter's description with `variables` (XML elements) before its `crash_at`.
fn counter_xml_with(variables: &[&str]) -> String {
    let anchor = r#"<Float64 name="crash_at" valueReference="30"#;
    let inserted: String = variables.iter().map(|v| format!("{v}\n    ")).collect();
    let xml = XML.replace(anchor, &format!("{inserted}{anchor}"));
    assert_ne!(xml, XML);
    xml
}

/// Runs `path` to 0.5 s into `dir`/out.csv and asserts that it succeeded and wrote the same
/// CSV as the plain counter (built in the work folder `plain_test`); the run's output.
fn run_as_the_plain_counter(path: &Path, dir: &Path, plain_test: &str) -> std::process::Output {
    let csv = dir.join("out.csv");
    let out = run_to_csv(path, "0.5", &csv, &[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (plain_dir, plain) = counter(plain_test).unwrap();
    let plain_csv = plain_dir.join("plain.csv");
    assert!(run_to_csv(&plain, "0.5", &plain_csv, &[]).status.success());
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), std::fs::read_to_string(&plain_csv).unwrap());
    out
}

/// The counter declaring `hasEventMode`, built in `work_dir(test)` (with the folder).
fn counter_with_event_mode(test: &str) -> Option<(PathBuf, PathBuf)> {
    let dir = work_dir(test);
    let xml = XML.replace(
        "mightReturnEarlyFromDoStep=\"true\"/>",
        "mightReturnEarlyFromDoStep=\"true\" hasEventMode=\"true\"/>",
    );
    assert_ne!(xml, XML);
    let path = build_counter(&dir, "event_mode", &xml)?;
    Some((dir, path))
}

/// Value references up to 4294967295 are the FMU's to use (Dymola uses 4294967294): a
/// parameter there leaves the rest of the view whole (before, the array elements' view
/// references were counted above the largest one, overflowed u32, and every variable was
/// left out with a false "more than 100,000 elements"), and an array whose dimensions
/// multiply past u64 (3 x 6148914691236517206) is left out as too large instead of wrapping
/// around to 2 elements. The run records the same columns and values as the plain counter.
#[test]
fn value_references_near_2_pow_32_and_overflowing_dimensions() {
    let dir = work_dir("fmi3-far-vr");
    let xml = counter_xml_with(&[
        r#"<Float64 name="far" valueReference="4294967295" causality="parameter" variability="fixed" start="1"/>"#,
        r#"<Float64 name="huge" valueReference="42" causality="local" variability="continuous"><Dimension start="3"/><Dimension start="6148914691236517206"/></Float64>"#,
    ]);
    let Some(path) = build_counter(&dir, "far_vr", &xml) else { return };
    let fmu = Fmu::load(&path).unwrap();
    let left: Vec<(&str, &str)> = fmu.not_in_view().iter().map(|(n, why)| (n.as_str(), why.as_str())).collect();
    assert_eq!(left, [("huge", "an array of more than 100,000 elements")]);
    assert_eq!(fmu.description().variable("far").map(|v| v.value_reference), Some(4294967295));
    run_as_the_plain_counter(&path, &dir, "fmi3-far-vr-plain");
}

/// What the master's view leaves out (String and Binary arrays) is said, not dropped
/// silently: listed by `Fmu::not_in_view` and `cosim info` with the reason, a note of
/// `cosim run` on stderr, and a `--set` of it an error naming the variable and the reason;
/// the rest of the FMU runs as without them.
#[test]
fn string_and_binary_arrays_are_left_out_and_said_so() {
    let dir = work_dir("fmi3-left-out");
    let xml = counter_xml_with(&[
        r#"<String name="names" valueReference="40" causality="parameter" variability="fixed"><Dimension start="2"/><Start value="a"/><Start value="b"/></String>"#,
        r#"<Binary name="blobs" valueReference="41" causality="output" variability="discrete"><Dimension start="3"/></Binary>"#,
    ]);
    let Some(path) = build_counter(&dir, "left_out", &xml) else { return };
    let fmu = Fmu::load(&path).unwrap();
    let left: Vec<(&str, &str)> = fmu.not_in_view().iter().map(|(n, why)| (n.as_str(), why.as_str())).collect();
    assert_eq!(left, [("names", "a String array"), ("blobs", "a Binary array")]);
    assert!(fmu.description().variable("names").is_none() && fmu.description().variable("blobs[1]").is_none());
    let out = cosim(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.lines().any(|l| {
            l
            == "not run by cosim (neither recorded, set nor connected): names (a String array), blobs (a Binary array)"
        }),
        "{text}"
    );
    // the same columns and values as the FMU without the two arrays
    let out = run_as_the_plain_counter(&path, &dir, "fmi3-left-out-plain");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cosim: note: model.names is a String array: not recorded"), "{err}");
    assert!(err.contains("cosim: note: model.blobs is a Binary array: not recorded"), "{err}");
    let out = cosim(&["run", path.to_str().unwrap(), "--stop-time", "0.5", "--set", "names=x"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "variable \"names\" of instance \"model\" is a String array, which cosim does not record, set nor connect"
        ),
        "{err}"
    );
}

/// An array whose `<Dimension>` names a structural parameter has the size of the parameter's
/// start value: recorded as its elements as a fixed-size array is. Setting the structural
/// parameter gives the array its new size in the view; this FMU answers
/// `fmi3EnterConfigurationMode` with fmi3Error, and the run says so (Configuration Mode
/// itself: `fmi3_configuration.rs`).
#[test]
fn an_array_sized_by_a_structural_parameter_has_its_start_size_unless_set() {
    let dir = work_dir("fmi3-structural");
    let sized = XML
        .replace(
            r#"<Float64 name="arr" valueReference="24" causality="output"><Dimension start="3"/></Float64>"#,
            r#"<Float64 name="arr" valueReference="24" causality="output"><Dimension valueReference="40"/></Float64>"#,
        )
        .replace(
            r#"<Float64 name="crash_at""#,
            "<UInt64 name=\"size\" valueReference=\"40\" causality=\"structuralParameter\" variability=\"fixed\" start=\"3\"/>\n    <Float64 name=\"crash_at\"",
        );
    assert_ne!(sized, XML);
    let Some(path) = build_counter(&dir, "structural", &sized) else { return };
    let fmu = Fmu::load(&path).unwrap();
    let names: Vec<&str> = fmu.description().model_variables.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names[24..27], ["arr[1]", "arr[2]", "arr[3]"]);
    let run = |p: &Path| {
        let system = with_starts(p, &[]);
        simulate(&system, &Experiment::new(0.5, 0.1)).unwrap().0
    };
    let (_, plain) = counter("fmi3-structural-plain").unwrap();
    let (a, b) = (run(&path), run(&plain));
    for name in ["arr[1]", "arr[2]", "arr[3]", "y"] {
        assert_eq!(a.column(name), b.column(name), "{name}");
    }
    let mut builder = SystemBuilder::new();
    builder.add_instance("c", fmu).unwrap();
    builder.set("c.size", Value::Real(4.0)).unwrap();
    let system = builder.build();
    let names: Vec<&str> = system.description(0).model_variables.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names[24..28], ["arr[1]", "arr[2]", "arr[3]", "arr[4]"]);
    let e = simulate(&system, &Experiment::new(0.5, 0.1)).unwrap_err();
    assert!(e.to_string().contains("fmi3EnterConfigurationMode"), "{e}");
}

/// Co-Simulation event mode: an FMU with `hasEventMode` asked to use it (`--event-mode on`;
/// without clocks the default is no Event Mode, tests/event_mode.rs) is instantiated with
/// `eventModeUsed`; the step in which the counter's y reaches 0.55 (u = 1: the step to 0.6 s) says
/// `eventHandlingNeeded`, the master runs Event Mode (`fmi3UpdateDiscreteStates` adds 1 to
/// n) and returns to Step Mode. fmpy 0.3.32 with `use_event_mode=True` does the same; it
/// records the event's instant twice (before and after), the master once, after: the
/// same rows as fmpy's last row at each time. Without `hasEventMode` no event is handled
/// (n counts the steps only, `every_type_and_array_elements_are_recorded`).
#[test]
fn cs_event_mode_where_the_fmu_has_it_as_fmpy_runs_it() {
    let Some((dir, path)) = counter_with_event_mode("fmi3-event-mode") else { return };
    let r = run_with_event_mode(&path, "c");
    let (time, n) = (r.column("time").unwrap(), r.column("n").unwrap());
    for k in 0..r.rows() {
        // the step count, and 1 from the event at the end of the step to 0.6 s
        assert_eq!(n[k], k as f64 + if k >= 6 { 1.0 } else { 0.0 }, "t = {}", time[k]);
    }
    let mut theirs: Vec<Vec<f64>> = Vec::new();
    for row in fmpy_rows(&path, &dir.join("fmpy.csv"), "fmi_type='CoSimulation', use_event_mode=True") {
        match theirs.last_mut() {
            Some(last) if last[0] == row[0] => *last = row,
            _ => theirs.push(row),
        }
    }
    let ours: Vec<Vec<f64>> = (0..r.rows()).map(|k| vec![time[k], r.column("y").unwrap()[k], n[k]]).collect();
    assert_eq!(ours, theirs, "ours vs fmpy's last row at each time");
}

/// The counter at `path` loaded with Event Mode asked for (`cosim run --event-mode on`) as
/// the one instance `name`, run 1 s at 0.1 s.
fn run_with_event_mode(path: &Path, name: &str) -> nigel_cosim::Results {
    let options = nigel_cosim::ImportOptions { event_mode: nigel_cosim::EventModeChoice::On, ..Default::default() };
    let mut b = SystemBuilder::new();
    b.add_instance(name, Fmu::load_with(path, &options).unwrap()).unwrap();
    simulate(&b.build(), &Experiment::new(1.0, 0.1)).unwrap().0
}

/// An FMU that declares `hasEventMode` but refuses to be instantiated with `eventModeUsed`
/// (as the Reference FMUs' Roberts does; the counter refuses it for an instance named
/// "...no-event-mode...") gets, when Event Mode is asked for, a second try without it and
/// runs as an FMU without Event Mode: no event is handled, n counts the steps only (the
/// same run as the counter's description without `hasEventMode`).
#[test]
fn an_fmu_that_refuses_event_mode_is_instantiated_again_without_it() {
    let Some((_, path)) = counter_with_event_mode("fmi3-refuses-event-mode") else { return };
    let r = run_with_event_mode(&path, "c-no-event-mode");
    let n = r.column("c-no-event-mode.n").or_else(|| r.column("n")).expect("the column n");
    assert_eq!(n, (0..11).map(|k| k as f64).collect::<Vec<_>>());
}

/// An FMI 3.0 Int64 output declared `ssc:Integer` in an SSP (as OMSimulator writes it;
/// SSP 1.0 has no Int64), connected (written sink first) to another counter's Float64
/// input: read, and its values beyond 32 bits carried exactly (the view holds an Int64 as
/// a Real). A Boolean declaration of the same variable is refused.
#[test]
fn an_int64_connector_declared_integer_in_an_ssp_carries_its_values_exactly() {
    use nigel_cosim::{read_ssp, Algorithm, ImportOptions};
    let Some((dir, _)) = counter("fmi3-ssp-int64") else { return };
    let ssd = |ty: &str| {
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" version="1.0" name="t">
<ssd:System name="root"><ssd:Elements>
  <ssd:Component name="c1" source="fmi3_counter.fmu"><ssd:Connectors><ssd:Connector name="i64" kind="output"><ssc:{ty}/></ssd:Connector></ssd:Connectors></ssd:Component>
  <ssd:Component name="c2" source="fmi3_counter.fmu"/>
</ssd:Elements><ssd:Connections><ssd:Connection startElement="c2" startConnector="u" endElement="c1" endConnector="i64"/></ssd:Connections>
</ssd:System></ssd:SystemStructureDescription>"#
        )
    };
    let path = dir.join("int64.ssd");
    std::fs::write(&path, ssd("Boolean")).unwrap();
    let e = read_ssp(&path, &ImportOptions::default()).err().expect("a Boolean Int64 refused").to_string();
    assert!(e.contains("connector \"i64\" is declared Boolean"), "{e}");
    std::fs::write(&path, ssd("Integer")).unwrap();
    let s = read_ssp(&path, &ImportOptions::default()).unwrap();
    assert_eq!(s.system.name_of(&s.system.connections[0].from), "c1.i64");
    let mut e = Experiment::new(0.5, 0.1);
    e.algorithm = Algorithm::Ordered;
    e.record = Some(vec!["c1.n".into(), "c2.u".into()]);
    let (r, _) = simulate(&s.system, &e).unwrap();
    let (n, u) = (r.column("c1.n").unwrap(), r.column("c2.u").unwrap());
    // i64 = -2^40 n (fmi3_counter.c), n the steps done: -5.5e12 after 5 steps, past i32
    assert_eq!(n, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
    for k in 0..n.len() {
        assert_eq!(u[k], -(2f64.powi(40)) * n[k], "c2.u at step {k}");
    }
}

/// A run whose result would lack every output it was asked to record (by default: all
/// outputs) does not end with status 0: the counter described with one output, an array
/// of 200,000 elements that the master leaves out of its view, is refused naming it,
/// instead of writing a CSV of the time column alone.
#[test]
fn a_run_that_can_record_none_of_the_outputs_fails() {
    let dir = work_dir("fmi3-no-output");
    // shared with the Python package's test of the same refusal
    let xml = include_str!("cfmu/fmi3_counter_no_output.xml");
    let Some(fmu) = build_counter(&dir, "no_output", xml) else { return };
    let csv = dir.join("out.csv");
    let out =
        cosim(&["run", fmu.to_str().unwrap(), "--stop-time", "0.1", "--step", "0.05", "-o", csv.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("no output of the system can be recorded") && err.contains("model.big"), "{err}");
}

/// An early return whose lastSuccessfulTime lies past the step (the counter with
/// crash_how = 4: terminateSimulation "at" t + 1000 s from the step at 0.05 s) is no time
/// of the run: an error naming the FMU, the call and the times, no row past the stop time,
/// and no status 0.
#[test]
fn an_early_return_past_the_step_is_an_error_not_a_row() {
    let Some((dir, fmu)) = counter("fmi3-early-past") else { return };
    let csv = dir.join("out.csv");
    let out = cosim(&[
        "run",
        fmu.to_str().unwrap(),
        "--stop-time",
        "0.1",
        "--step",
        "0.01",
        "--set",
        "crash_at=0.05",
        "--set",
        "crash_how=4",
        "-o",
        csv.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("fmi3DoStep ended the simulation at lastSuccessfulTime = 1000.05")
            && err.contains("outside the step"),
        "{err}"
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let last: f64 = text.lines().last().unwrap().split(',').next().unwrap().parse().unwrap();
    assert!(last <= 0.1, "a row at {last} s");
}

/// An early return that makes no progress (the counter with crash_how = 5: lastSuccessfulTime
/// = t from the step at 0.05 s) and one that creeps (crash_how = 6: a 4000th of what is left
/// of the step a return, so 1000 returns do not reach its end) end the run, each with fmi3OK named as
/// what the FMU returned: the first breaks the standard's early return, the second only
/// cosim's bound of 1000 early returns a step, and neither is an fmi3Error of the FMU.
#[test]
fn early_returns_without_progress_or_past_the_bound_say_what_the_fmu_returned() {
    let Some((dir, fmu)) = counter("fmi3-early-stuck") else { return };
    let run = |how: &str| {
        let csv = dir.join(format!("out{how}.csv"));
        let how = format!("crash_how={how}");
        let args = ["run", fmu.to_str().unwrap(), "--stop-time", "0.1", "--step", "0.01", "--set", "crash_at=0.05"];
        let out = cosim(&[&args[..], &["--set", &how, "-o", csv.to_str().unwrap()]].concat());
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let stuck = run("5");
    assert!(
        stuck.contains(
            "fmi3DoStep returned fmi3OK at t = 0.05 s, but earlyReturn = true with lastSuccessfulTime = 0.05 s made \
             no progress from 0.05 s toward the step's end 0.06 s"
        ) && !stuck.contains("fmi3Error"),
        "{stuck}"
    );
    let creeping = run("6");
    // each return goes a 4000th of what is left of the step: the 1000th reaches
    // 0.06 - 0.01 (3999/4000)^1000 s = 0.06 - 0.01 * 0.778778 s = 0.0522122 s (6 digits)
    assert!(
        creeping.contains("fmi3DoStep returned fmi3OK at t = 0.052212")
            && creeping.contains(
                "but it returned early (earlyReturn = true) for the 1000th time in the step from 0.05 s to 0.06 s: 1000 early \
                 returns in one step is cosim's bound"
            )
            && !creeping.contains("fmi3Error"),
        "{creeping}"
    );
}

/// A non-finite FMI 3.0 value names the FMI 3.0 getter and status: the counter with u = 1e38
/// in steps of 1 s has y = 1e38 k at t = k s (exact enough: 1e38 k < f64's max), and its
/// f32 = (float)y overflows f32's largest 3.4028e38 to inf first at t = 4 s (3e38 still fits).
#[test]
fn a_non_finite_fmi3_value_names_the_fmi3_getter() {
    let Some((_dir, fmu)) = counter("fmi3-non-finite") else { return };
    let system = with_starts(&fmu, &[("u", Value::Real(1e38))]);
    let e = simulate(&system, &Experiment::new(6.0, 1.0)).unwrap_err().to_string();
    assert!(e.contains("c (fmi3_counter.fmu): f32 = inf at t = 4 s, returned with fmi3OK by fmi3GetFloat32"), "{e}");
}

/// A description of a later FMI 3 minor version ("3.1") runs as FMI 3.0, with a note saying
/// so; a revision of 3.0 ("3.0.2") needs none.
#[test]
fn a_later_minor_version_runs_with_a_note() {
    let dir = work_dir("fmi3-version");
    for (version, noted) in [("3.1", true), ("3.0.2", false)] {
        let xml = XML.replace(r#"fmiVersion="3.0""#, &format!(r#"fmiVersion="{version}""#));
        let Some(fmu) = build_counter(&dir, &format!("v{}", version.replace('.', "_")), &xml) else { return };
        let out = cosim(&["run", fmu.to_str().unwrap(), "--stop-time", "0.1", "--step", "0.05"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{version}: {err}");
        let note = format!(r#"declares fmiVersion "{version}": run as FMI 3.0"#);
        assert_eq!(err.contains(&note), noted, "{version}: {err}");
    }
}

/// Model Exchange: discrete inputs change in Event Mode only (FMI 3.0 section 3.2.1; the
/// counter, as the Reference FMUs, refuses `fmi3SetInt32` / `fmi3SetBoolean` of k and b in
/// Continuous-Time Mode). An input table changes k from 1 to 4 and b to true at 0.3 s (a
/// communication point) and k to -2 at 0.45 s (between points: the step is split there);
/// each change is an input event, and a value that stays is not set again.
///
/// By hand (m = 2 k, nb = !b, read back from the FMU): the rows at 0 .. 0.3 s hold k = 1
/// (m = 2, nb = 1; a row is recorded before the inputs of the next step are applied), the
/// row at 0.4 s k = 4 (m = 8, nb = 0), and from 0.5 s on k = -2 (m = -4). fmpy 0.3.32 (the
/// same table as its `input=`) gives the same values at every grid time but 0.3 s, where
/// it records the row after the event. The counter is described without its event
/// indicator here: fmpy's CVode root function sets every input, the discrete ones too, in
/// Continuous-Time Mode, which the counter refuses (the Reference FMUs' Feedthrough has no
/// event indicator, so fmpy never does so there).
#[test]
fn model_exchange_sets_discrete_inputs_in_event_mode() {
    let dir = work_dir("fmi3-me-discrete-input");
    let xml = XML.replace(r#"<EventIndicator valueReference="14" dependencies="2"/>"#, "");
    let Some(path) = build_counter(&dir, "fmi3_counter", &xml) else { return };
    let table = nigel_cosim::InputTable::new(
        vec!["k".into(), "b".into()],
        vec![0.0, 0.3, 0.45, 1.0],
        vec![vec![1.0, 4.0, -2.0, -2.0], vec![0.0, 1.0, 1.0, 1.0]],
    )
    .unwrap();
    let mut e = Experiment::new(1.0, 0.1);
    e.input = Some(std::sync::Arc::new(table));
    let (r, summary) = simulate(&model_exchange(&path, &[]), &e).unwrap();
    let (time, m, nb) = (r.column("time").unwrap(), r.column("m").unwrap(), r.column("nb").unwrap());
    assert_eq!(r.rows(), 11);
    for k in 0..11 {
        let (m_hand, nb_hand) = match k {
            0..=3 => (2.0, 1.0),
            4 => (8.0, 0.0),
            _ => (-4.0, 0.0),
        };
        assert_eq!((m[k], nb[k]), (m_hand, nb_hand), "t = {}", time[k]);
    }
    let inputs: Vec<f64> = summary.events.iter().filter(|e| e.kind == "input").map(|e| e.time).collect();
    assert_eq!(inputs, vec![0.30000000000000004, 0.45], "one input event per change (0.1 + 0.1 + 0.1 is the point)");
    // fmpy with the same table, at the grid times but 0.3 s
    let script = "import sys, numpy as np\nfrom fmpy import simulate_fmu\n\
         sig = np.array([(0.0, 1, False), (0.3, 4, True), (0.45, -2, True), (1.0, -2, True)], dtype=[('time', np.double), ('k', np.int32), ('b', np.bool_)])\n\
         r = simulate_fmu(sys.argv[1], fmi_type='ModelExchange', stop_time=1.0, output_interval=0.1, input=sig, output=['m', 'nb'])\n\
         print('\\n'.join('%r %r %r' % (float(t), float(m), float(nb)) for t, m, nb in r))\n";
    let out = Command::new(python()).args(["-c", script]).arg(&path).output().unwrap();
    assert!(out.status.success(), "fmpy: {}", String::from_utf8_lossy(&out.stderr));
    let theirs: Vec<Vec<f64>> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| !l.starts_with("Warning")) // fmpy's "missing input for variable u"
        .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
        .collect();
    for k in (0..11).filter(|k| *k != 3) {
        let row = theirs.iter().rev().find(|row| (row[0] - time[k]).abs() < 1e-9).expect("fmpy's row");
        assert_eq!((row[1], row[2]), (m[k], nb[k]), "t = {}", time[k]);
    }
}

/// 64-bit integers, Binaries and Strings recorded as the FMU holds them (issue 35, defects
/// 4 and 5): an input file drives the counter's Int64 and UInt64 inputs with values an f64
/// does not hold, read exactly; the outputs i64out = i64in ^ 1 and u64out = u64in ^ 1 (the
/// lowest bit flipped, so that a rounding shows) are written in decimal, the Binary `bin`
/// (n zero bytes after n steps) in hex, the String parameter `label` as its text.
///
/// By hand: at t = 0 (initialization takes the first row) i64in = -2^63, so i64out =
/// -2^63 + 1 = -9223372036854775807; u64in = 2^64 - 1, so u64out = 18446744073709551614.
/// The row at 0.25 s still holds them (a row is recorded before the next step's inputs),
/// the row at 0.5 s the second row's 2^53 + 2 = 9007199254740994: out 9007199254740995,
/// which is no f64 (the nearest are ...994 and ...996). fmpy 0.3.32, given the same
/// values as int64 / uint64 columns, records the same integers.
#[test]
fn sixty_four_bit_integers_binaries_and_strings_are_recorded_exactly() {
    let Some((dir, fmu)) = counter("fmi3-exact") else { return };
    let input = dir.join("in.csv");
    std::fs::write(
        &input,
        "time,i64in,u64in\n0,-9223372036854775808,18446744073709551615\n0.25,9007199254740994,9007199254740994\n1,9007199254740994,9007199254740994\n",
    )
    .unwrap();
    let csv = dir.join("out.csv");
    let fmu_arg = fmu.to_str().unwrap();
    let columns = |path: &Path| -> Vec<Vec<String>> {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').map(|h| h.trim_matches('"')).collect();
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        ["i64out", "u64out", "bin", "label"]
            .iter()
            .map(|name| {
                let j = header.iter().position(|h| h == name).unwrap_or_else(|| panic!("{name} in {header:?}"));
                rows.iter().map(|r| r[j].to_string()).collect()
            })
            .collect()
    };
    let by_hand = vec![
        vec!["-9223372036854775807", "-9223372036854775807", "9007199254740995"],
        vec!["18446744073709551614", "18446744073709551614", "9007199254740995"],
        vec!["", "00", "0000"],
        vec!["abc", "abc", "abc"],
    ];
    for isolate in ["", "--isolate=run", "--isolate=fmu"] {
        let mut args = vec!["run", fmu_arg, "--stop-time", "0.5", "--step", "0.25", "--input", input.to_str().unwrap()];
        args.extend(["--record", "i64out", "--record", "u64out", "--record", "bin", "--record", "label"]);
        args.extend(["-o", csv.to_str().unwrap()]);
        if !isolate.is_empty() {
            args.push(isolate);
        }
        let out = cosim(&args);
        assert!(out.status.success(), "{isolate}: {}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(columns(&csv), by_hand, "{isolate}");
    }
    // fmpy with the same values as exact integer columns
    let script = "import sys, numpy as np\nfrom fmpy import simulate_fmu\n\
         sig = np.array([(0.0, -2**63, 2**64 - 1), (0.25, 2**53 + 2, 2**53 + 2), (1.0, 2**53 + 2, 2**53 + 2)], dtype=[('time', np.double), ('i64in', np.int64), ('u64in', np.uint64)])\n\
         r = simulate_fmu(sys.argv[1], stop_time=0.5, output_interval=0.25, input=sig, output=['i64out', 'u64out'])\n\
         print('\\n'.join('%d %d' % (i, u) for i, u in zip(r['i64out'], r['u64out'])))\n";
    let out = Command::new(python()).args(["-c", script]).arg(&fmu).output().unwrap();
    assert!(out.status.success(), "fmpy: {}", String::from_utf8_lossy(&out.stderr));
    let theirs: Vec<Vec<String>> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| !l.starts_with("Warning"))
        .map(|l| l.split(' ').map(str::to_string).collect())
        .collect();
    let ours = columns(&csv);
    assert_eq!(theirs.len(), 3, "{theirs:?}");
    for (k, row) in theirs.iter().enumerate() {
        assert_eq!((&row[0], &row[1]), (&ours[0][k], &ours[1][k]), "row {k}");
    }
}

/// An `<Alias>` (FMI 3.0 section 2.4.7.5) is another name of its variable: `cosim info`
/// lists it, a run records it under its own name (by default, as an output like its
/// variable), its value that of the variable in every row; fmpy 0.3.32 records it too,
/// with the same values.
#[test]
fn an_alias_is_listed_and_recorded_under_its_name() {
    let dir = work_dir("fmi3-alias");
    let xml = XML.replace(
        r#"<Float64 name="y" valueReference="2" causality="output" unit="m" initial="exact" start="0"/>"#,
        r#"<Float64 name="y" valueReference="2" causality="output" unit="m" initial="exact" start="0"><Alias name="y_ft" description="y in feet"/></Float64>"#,
    );
    assert_ne!(xml, XML, "the alias is in the description");
    let Some(fmu) = build_counter(&dir, "alias", &xml) else { return };
    let out = cosim(&["info", fmu.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().find(|l| l.starts_with("y_ft ")).unwrap_or_else(|| panic!("{text}"));
    assert!(line.contains("output") && line.contains("alias of y") && line.contains("y in feet"), "{line}");
    let csv = dir.join("out.csv");
    let out =
        cosim(&["run", fmu.to_str().unwrap(), "--stop-time", "0.3", "--step", "0.1", "-o", csv.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').map(|h| h.trim_matches('"')).collect();
    let (jy, jft) = (header.iter().position(|h| *h == "y").unwrap(), header.iter().position(|h| *h == "y_ft").unwrap());
    let rows: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split(',').collect()).collect();
    // y = t (u = 1, mode 1): 0, 0.1, 0.2, 0.30000000000000004, the alias the same text
    let y: Vec<&str> = rows.iter().map(|r| r[jy]).collect();
    assert_eq!(y, ["0", "0.1", "0.2", "0.30000000000000004"]);
    assert_eq!(rows.iter().map(|r| r[jft]).collect::<Vec<_>>(), y);
    let script = "import sys\nfrom fmpy import simulate_fmu\n\
         r = simulate_fmu(sys.argv[1], stop_time=0.3, output_interval=0.1)\n\
         print(' '.join(repr(float(v)) for v in r['y_ft']))\n";
    let out = Command::new(python()).args(["-c", script]).arg(&fmu).output().unwrap();
    assert!(out.status.success(), "fmpy: {}", String::from_utf8_lossy(&out.stderr));
    let theirs: Vec<f64> =
        String::from_utf8_lossy(&out.stdout).split_whitespace().map(|v| v.parse().unwrap()).collect();
    assert_eq!(theirs, y.iter().map(|v| v.parse::<f64>().unwrap()).collect::<Vec<_>>());
}

/// Runs `system` 0.2 s in steps of 0.1 s under `algorithm` with `input`, recording
/// `record`: every one of its three rows holds `by_hand`'s exact value in each column
/// (`what` names the run in a failure).
fn assert_exact_rows(
    system: &System,
    input: nigel_cosim::InputTable,
    algorithm: nigel_cosim::Algorithm,
    record: &[&str],
    by_hand: &[&str],
    what: &str,
) {
    let mut e = Experiment::new(0.2, 0.1);
    e.algorithm = algorithm;
    e.record = Some(record.iter().map(|n| n.to_string()).collect());
    e.input = Some(std::sync::Arc::new(input));
    let (r, _) = simulate(system, &e).unwrap_or_else(|err| panic!("{what}: {err}"));
    for (column, value) in by_hand.iter().enumerate() {
        assert_eq!(r.exact_column(column).unwrap(), [*value; 3], "{what} {}", record[column]);
    }
}

/// Two counters, c1 feeding c2 (`i64out -> i64in`, `u64out -> u64in`); c1's inputs from
/// `inputs` (an input table of exact integers, held), each instance loaded for `interface`.
fn counters_connected(
    path: &Path,
    interface: nigel_cosim::Interface,
    connections: &[(&str, &str)],
    inputs: &[(&str, i128)],
) -> (System, nigel_cosim::InputTable) {
    let options = nigel_cosim::ImportOptions { interface: Some(interface), ..nigel_cosim::ImportOptions::default() };
    let mut b = SystemBuilder::new();
    for name in ["c1", "c2"] {
        b.add_instance(name, Fmu::load_with(path, &options).unwrap()).unwrap();
    }
    for (from, to) in connections {
        b.connect(from, to).unwrap();
    }
    let names = inputs.iter().map(|(n, _)| n.to_string()).collect();
    let columns = inputs.iter().map(|(_, v)| vec![*v as f64; 2]).collect();
    let mut table = nigel_cosim::InputTable::new(names, vec![0.0, 1.0], columns).unwrap();
    table.integers = inputs.iter().map(|(_, v)| Some(vec![*v; 2])).collect();
    (b.build(), table)
}

/// Connections carry 64-bit integers exactly, in Co-Simulation and Model Exchange, under
/// `jacobi` and `ordered` (issue 35 defect 4, issue 36 defect 6). The counter's outputs
/// are its inputs with the lowest bit flipped (i64out = i64in ^ 1, u64out = u64in ^ 1),
/// so that a rounding anywhere shows. By hand: c1.i64in = 2^62 gives c1.i64out = 2^62 + 1
/// = 4611686018427387905, which no f64 holds (the f64s there are 2^10 apart); it arrives
/// in c2.i64in as it is, and c2.i64out = 2^62 = 4611686018427387904. c1.u64in = 2^64 - 1
/// (u64::MAX, above i64::MAX) gives c1.u64out = 18446744073709551614 = c2.u64in, and
/// c2.u64out = 18446744073709551615. Every row the same (the inputs are held, and the
/// connections carried at initialization already).
#[test]
fn sixty_four_bit_connections_carry_their_values_to_the_bit() {
    use nigel_cosim::{Algorithm, Interface};
    let Some((_dir, path)) = counter("fmi3-wide-connection") else { return };
    let record = ["c1.i64out", "c2.i64in", "c2.i64out", "c1.u64out", "c2.u64in", "c2.u64out"];
    let by_hand = [
        "4611686018427387905",
        "4611686018427387905",
        "4611686018427387904",
        "18446744073709551614",
        "18446744073709551614",
        "18446744073709551615",
    ];
    for interface in [Interface::CoSimulation, Interface::ModelExchange] {
        for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
            let (system, input) = counters_connected(
                &path,
                interface,
                &[("c1.i64out", "c2.i64in"), ("c1.u64out", "c2.u64in")],
                &[("c1.i64in", 1 << 62), ("c1.u64in", i128::from(u64::MAX))],
            );
            assert_exact_rows(&system, input, algorithm, &record, &by_hand, &format!("{interface:?} {algorithm:?}"));
        }
    }
}

/// The counter's description with its 64-bit array inputs and outputs (`tests/cfmu/fmi3_counter.c`:
/// i64aout[k] = i64ain[k] ^ 1, u64aout[k] = u64ain[k] ^ 1, two elements each).
fn counter_with_wide_arrays(test: &str) -> Option<(PathBuf, PathBuf)> {
    let last = r#"<UInt64 name="u64out" valueReference="35" causality="output"/>"#;
    assert!(XML.contains(last));
    let arrays = format!(
        r#"{last}
    <Int64 name="i64ain" valueReference="36" causality="input" start="0"><Dimension start="2"/></Int64>
    <Int64 name="i64aout" valueReference="37" causality="output"><Dimension start="2"/></Int64>
    <UInt64 name="u64ain" valueReference="38" causality="input" start="0"><Dimension start="2"/></UInt64>
    <UInt64 name="u64aout" valueReference="39" causality="output"><Dimension start="2"/></UInt64>"#
    );
    let dir = work_dir(test);
    let fmu = build_counter(&dir, "fmi3_counter", &XML.replace(last, &arrays))?;
    Some((dir, fmu))
}

/// The elements of 64-bit arrays are carried exactly as the scalars are: from an input
/// file, across connections element to element, into the results, in Co-Simulation and
/// Model Exchange under both algorithms. By hand (the outputs flip the lowest bit of their
/// inputs): c1.i64ain = (2^62, -2^62 - 3) gives c1.i64aout = (2^62 + 1, -2^62 - 4), in
/// c2.i64ain as they are (connected crosswise: element 1 to 2, 2 to 1), so c2.i64ain =
/// (-2^62 - 4, 2^62 + 1) and c2.i64aout = (-2^62 - 3, 2^62); c1.u64ain = (2^64 - 1, 2^53 + 2)
/// gives c1.u64aout = (2^64 - 2, 2^53 + 3) = c2.u64ain, c2.u64aout = (2^64 - 1, 2^53 + 2).
/// None of 2^62 + 1, -2^62 - 3, 2^64 - 2, 2^53 + 3 is an f64 (before: refused beyond 2^53).
#[test]
fn sixty_four_bit_array_elements_carry_their_values_to_the_bit() {
    use nigel_cosim::{Algorithm, Interface};
    let Some((_dir, path)) = counter_with_wide_arrays("fmi3-wide-arrays") else { return };
    let record = [
        "c1.i64aout[1]",
        "c1.i64aout[2]",
        "c2.i64ain[1]",
        "c2.i64ain[2]",
        "c2.i64aout[1]",
        "c2.i64aout[2]",
        "c2.u64ain[1]",
        "c2.u64ain[2]",
        "c2.u64aout[1]",
        "c2.u64aout[2]",
    ];
    let p62 = 1i128 << 62;
    let by_hand = [p62 + 1, -p62 - 4, -p62 - 4, p62 + 1, -p62 - 3, p62]
        .into_iter()
        .chain([(1i128 << 64) - 2, (1i128 << 53) + 3, (1i128 << 64) - 1, (1i128 << 53) + 2])
        .map(|v| v.to_string())
        .collect::<Vec<_>>();
    for interface in [Interface::CoSimulation, Interface::ModelExchange] {
        for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
            let (system, input) = counters_connected(
                &path,
                interface,
                &[
                    ("c1.i64aout[1]", "c2.i64ain[2]"),
                    ("c1.i64aout[2]", "c2.i64ain[1]"),
                    ("c1.u64aout[1]", "c2.u64ain[1]"),
                    ("c1.u64aout[2]", "c2.u64ain[2]"),
                ],
                &[
                    ("c1.i64ain[1]", p62),
                    ("c1.i64ain[2]", -p62 - 3),
                    ("c1.u64ain[1]", i128::from(u64::MAX)),
                    ("c1.u64ain[2]", (1 << 53) + 2),
                ],
            );
            let by_hand: Vec<&str> = by_hand.iter().map(String::as_str).collect();
            assert_exact_rows(&system, input, algorithm, &record, &by_hand, &format!("{interface:?} {algorithm:?}"));
        }
    }
}

/// An element beyond its type's range is refused naming the variable and the value
/// (2^63 into an Int64 array element), never wrapped.
#[test]
fn a_sixty_four_bit_array_element_out_of_range_is_refused() {
    let Some((_dir, path)) = counter_with_wide_arrays("fmi3-wide-array-range") else { return };
    let (system, input) =
        counters_connected(&path, nigel_cosim::Interface::CoSimulation, &[], &[("c1.i64ain[2]", 1i128 << 63)]);
    let mut e = Experiment::new(0.2, 0.1);
    e.input = Some(std::sync::Arc::new(input));
    let err = simulate(&system, &e).unwrap_err().to_string();
    assert!(err.contains("i64ain") && err.contains("9223372036854775808") && err.contains("Int64"), "{err}");
}

/// The same through the command line on an SSP system (`tests/data/int64_chain.ssd`: the
/// counters' 64-bit connectors declared `ssc:Integer`, one connection written sink first),
/// c1's inputs from an input file of exact integers: the CSV holds the values to the bit,
/// under both algorithms, in Co-Simulation and Model Exchange, in process and with every
/// FMU in a host process of its own. By hand as above: c1.i64in = 2^62 gives 2^62 + 1 at
/// c1.i64out and c2.i64in, and 2^62 at c2.i64out; c1.u64in = 2^64 - 1 gives 2^64 - 2 at
/// c1.u64out and c2.u64in, and 2^64 - 1 at c2.u64out.
#[test]
fn an_ssp_of_int64_connectors_carries_them_exactly_from_the_command_line() {
    let Some((dir, _fmu)) = counter("fmi3-int64-ssp") else { return };
    let ssd = dir.join("int64_chain.ssd");
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/int64_chain.ssd"), &ssd).unwrap();
    let input = dir.join("in.csv");
    std::fs::write(&input, "time,c1.i64in,c1.u64in\n0,4611686018427387904,18446744073709551615\n1,4611686018427387904,18446744073709551615\n").unwrap();
    let record = ["c1.i64out", "c2.i64in", "c2.i64out", "c1.u64out", "c2.u64in", "c2.u64out"];
    let by_hand = "4611686018427387905,4611686018427387905,4611686018427387904,18446744073709551614,18446744073709551614,18446744073709551615";
    let csv = dir.join("out.csv");
    for (algorithm, interface, isolate) in [
        ("jacobi", "cs", ""),
        ("ordered", "cs", ""),
        ("jacobi", "me", ""),
        ("ordered", "me", ""),
        ("jacobi", "cs", "--isolate=fmu"),
    ] {
        let mut args = vec!["run", ssd.to_str().unwrap(), "--step", "0.1", "--input", input.to_str().unwrap()];
        args.extend(["--algorithm", algorithm, "--interface", interface, "-o", csv.to_str().unwrap()]);
        for r in &record {
            args.extend(["--record", r]);
        }
        if !isolate.is_empty() {
            args.push(isolate);
        }
        let out = cosim(&args);
        let what = format!("{algorithm} {interface} {isolate}");
        assert!(out.status.success(), "{what}: {}", String::from_utf8_lossy(&out.stderr));
        let text = std::fs::read_to_string(&csv).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "\"time\",\"c1.i64out\",\"c2.i64in\",\"c2.i64out\",\"c1.u64out\",\"c2.u64in\",\"c2.u64out\""
        );
        assert_eq!(lines[1..], [format!("0,{by_hand}"), format!("0.1,{by_hand}"), format!("0.2,{by_hand}")], "{what}");
    }
}

/// At initialization the connections are carried until no value changes, and an integer
/// settles only when it no longer changes at all: a change of 1 at 2^62 (a relative 2e-19,
/// far below the Reals' tolerance of 1e-10) is no convergence. A chain c1 -> c2 -> .. -> c5
/// of the counter (i64out = i64in ^ 1, depending on i64in at initialization) under
/// `jacobi`, c2.i64in .. c4.i64in starting at 2^62, each one off or on its settled value.
/// By hand: c1.i64in = 2^62 gives c1.i64out = 2^62 + 1 = c2.i64in, c2.i64out = 2^62 =
/// c3.i64in, then 2^62 + 1 = c4.i64in and 2^62 = c5.i64in: the row at the start time
/// holds them. Sweeps that stopped at the first small change (then one more carry before
/// the first row) would leave c5.i64in at 2^62 + 1.
#[test]
fn an_integer_chain_settles_exactly_at_initialization() {
    use nigel_cosim::Algorithm;
    let Some((_dir, path)) = counter("fmi3-integer-chain") else { return };
    let mut b = SystemBuilder::new();
    let names = ["c1", "c2", "c3", "c4", "c5"];
    for name in names {
        b.add_instance(name, Fmu::load(&path).unwrap()).unwrap();
    }
    for name in &names[..4] {
        b.set(&format!("{name}.i64in"), Value::Real(2f64.powi(62))).unwrap();
    }
    for pair in names.windows(2) {
        b.connect(&format!("{}.i64out", pair[0]), &format!("{}.i64in", pair[1])).unwrap();
    }
    let mut e = Experiment::new(0.1, 0.1);
    e.algorithm = Algorithm::Jacobi;
    e.record = Some(names[1..].iter().map(|n| format!("{n}.i64in")).collect());
    let (r, _) = simulate(&b.build(), &e).unwrap();
    let first_row: Vec<&str> = (0..4).map(|k| r.exact_column(k).unwrap()[0].as_str()).collect();
    assert_eq!(first_row, ["4611686018427387905", "4611686018427387904", "4611686018427387905", "4611686018427387904"]);
}

/// An integer connection checks the value against the input's type at every set: a
/// negative Int64 into a UInt64, a UInt64 above i64::MAX into an Int64, an Int64 beyond
/// 32 bits into an Int32 are errors naming both ends, the value and the time, never
/// wrapped or clamped. A value in range crosses to the narrower type: c1.i64out = 6 ^ 1 = 7
/// into the Int32 c2.k gives c2.m = 2 k = 14 (fmi3_counter.c).
#[test]
fn an_integer_connection_refuses_a_value_its_input_cannot_hold() {
    use nigel_cosim::Interface;
    let Some((_dir, path)) = counter("fmi3-integer-range") else { return };
    let run = |connection: (&str, &str), input: (&str, i128)| {
        let (system, table) = counters_connected(&path, Interface::CoSimulation, &[connection], &[input]);
        let mut e = Experiment::new(0.2, 0.1);
        e.record = Some(vec!["c2.m".into()]);
        e.input = Some(std::sync::Arc::new(table));
        simulate(&system, &e).map(|(r, _)| r.column("c2.m").unwrap())
    };
    for (connection, input, message) in [
        (
            ("c1.i64out", "c2.u64in"),
            ("c1.i64in", -4),
            "connection c1.i64out -> c2.u64in: c1.i64out = -3 at t = 0 s is outside the range of c2.u64in (UInt64, 0 to 18446744073709551615)",
        ),
        (
            ("c1.u64out", "c2.i64in"),
            ("c1.u64in", i128::from(u64::MAX)),
            "connection c1.u64out -> c2.i64in: c1.u64out = 18446744073709551614 at t = 0 s is outside the range of c2.i64in (Int64, -9223372036854775808 to 9223372036854775807)",
        ),
        (
            ("c1.i64out", "c2.k"),
            ("c1.i64in", 1 << 40),
            "connection c1.i64out -> c2.k: c1.i64out = 1099511627777 at t = 0 s is outside the range of c2.k (Int32, -2147483648 to 2147483647)",
        ),
    ] {
        let err = run(connection, input).expect_err(message).to_string();
        assert!(err.contains(message), "{err}");
    }
    assert_eq!(run(("c1.i64out", "c2.k"), ("c1.i64in", 6)).unwrap(), [14.0; 3]);
}

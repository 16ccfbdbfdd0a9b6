//! A third-party cross-check with `fmi-rs` (crates.io, CATIA-Systems, by fmpy's
//! authors), over the three built archives in `target/fmu/`:
//!
//! 1. fmi-rs parses each modelDescription.xml and its FMI 2.0 validation (its port of
//!    fmpy's: causality / variability / initial combinations, start values, structured
//!    names, ModelStructure outputs, derivatives and initial unknowns) finds no problem;
//!    a broken copy of the same document shows that the validation is live.
//! 2. fmi-rs unpacks, loads and runs each FMU as Co-Simulation with its own driver
//!    (`fmi_rs::sim::fmi2::cs::simulate`), with non-default start values, and every output
//!    at every communication point equals, bit for bit, what our master `nigel_cosim`
//!    records running the same archive with the same settings.
//! 3. The plant through fmi-rs's Model Exchange driver with its forward Euler equals, bit for
//!    bit, forward Euler written here over `nigel_cosim`'s Model Exchange instance.
//!
//! Tolerance: none (f64 bit patterns compared). Both importers call the same
//! deterministic binary with the same arguments: t_n = t0 + n h and step = t_{n+1} - t_n
//! are the same f64 expressions in fmi-rs (`next_regular_point`) and in our master; start
//! values are parsed from the same decimal literals by Rust's correctly rounded `f64`
//! parser; Euler is `x += dx * h` in both (Rust does not contract to FMA). Any
//! difference is a difference in the calls made or state shared between instances, which
//! is what this test exists to catch.

// fmi-rs's drivers take an `Arc<Recorder>`, and `Recorder` (a RefCell) is not Sync: one thread only here
#![allow(clippy::arc_with_non_send_sync)]

use std::path::PathBuf;
use std::sync::Arc;

use fmi_rs::model_description::fmi2::{Causality, ModelDescription as RsModelDescription, VariableType};
use fmi_rs::sim::fmi2::recorder::Recorder;
use fmi_rs::sim::fmi2::{SimulationSettings, Trajectories, VariableValue};
use fmi_rs::sim::solver::ForwardEulerFactory;
use nigel_cosim::{simulate, Experiment, Fmu, ImportOptions, Instance, Interface, SystemBuilder};
use nigel_integration_tests::built_fmu;

const STEP: f64 = 1e-3;

/// Model identifier, start values (name, literal), stop time.
type Case = (&'static str, Vec<(&'static str, &'static str)>, f64);

/// The three FMUs with non-default start values (inputs, states, parameters of every
/// type the FMU has: Real, Boolean, Integer, Enumeration) and the run length.
fn cases() -> Vec<Case> {
    vec![
        (
            "nigel_plant",
            vec![
                ("v_x_start", "0.35"),
                ("delta_fl", "0.2"),
                ("delta_fr", "0.25"),
                ("delta_rl", "-0.1"),
                ("delta_rr", "-0.05"),
                ("tau_rl", "0.02"),
                ("tau_rr", "0.015"),
                ("mu_fl", "0.3"),
                ("mu_rr", "0.5"),
                ("wind_side", "0.4"),
                ("steering_servo", "true"),
            ],
            2.0,
        ),
        (
            "nigel_controller",
            vec![
                ("beta", "0.01"),
                ("yaw_rate", "0.2"),
                ("speed", "0.3"),
                ("speed_ref", "0.4"),
                ("yaw_rate_ref", "0.3"),
                ("delta_ff_fl", "0.1"),
                ("delta_ff_rr", "-0.05"),
                ("controller", "4"),
                ("k_beta_fl", "-0.2"),
                ("k_yaw_rate_rl", "0.5"),
            ],
            2.0,
        ),
        (
            "nigel_maneuver",
            vec![
                ("maneuver", "5"),
                ("fidelity", "2"),
                ("seed", "7"),
                ("duration", "4"),
                ("steer_amplitude", "0.4"),
                ("beta", "0.01"),
                ("yaw_rate", "0.1"),
            ],
            4.0,
        ),
    ]
}

fn archive(id: &str) -> PathBuf {
    built_fmu(id).unwrap_or_else(|e| panic!("{e}"))
}

/// An unpacked copy, by fmi-rs's own unzip (`FMU2Builder`), and its parsed description.
fn fmi_rs_load(id: &str) -> fmi_rs::fmi2::builder::FMU2Builder {
    fmi_rs::fmi2::builder::FMU2Builder::new(&archive(id)).unwrap_or_else(|e| panic!("{id}: fmi-rs: {e}"))
}

/// The archive's modelDescription as fmi-rs's simulators take it, and a recorder of every
/// output (fmi-rs's own `Trajectories`).
fn description_and_recorder(builder: &fmi_rs::fmi2::builder::FMU2Builder) -> (Arc<RsModelDescription>, Arc<Recorder>) {
    let md = Arc::new(
        fmi_rs::model_description::fmi2::ModelDescription::from_path(
            &builder.unzipdir.path().join("modelDescription.xml"),
        )
        .unwrap(),
    );
    let recorder = Arc::new(Recorder::new(Trajectories::new(md.clone(), output_indices(&md))));
    (md, recorder)
}

fn problems(md: &RsModelDescription) -> Vec<String> {
    md.validate().into_iter().map(|p| p.message).collect()
}

#[test]
fn fmi_rs_parses_and_validates_every_model_description_without_a_problem() {
    for (id, _, _) in cases() {
        let builder = fmi_rs_load(id);
        let md = &builder.model_description;
        let found = problems(md);
        assert!(found.is_empty(), "{id}: fmi-rs validation: {found:#?}");

        // fmi-rs read the same document we wrote: variables, references, structure
        let ours = nigel_integration_tests::Fmu::load(&archive(id)).unwrap().description.clone();
        assert_eq!(md.guid, ours.guid, "{id}");
        let theirs: Vec<(&str, u32)> = md.modelVariables.iter().map(|v| (v.name.as_str(), v.valueReference)).collect();
        let mine: Vec<(&str, u32)> =
            ours.model_variables.iter().map(|v| (v.name.as_str(), v.value_reference)).collect();
        assert_eq!(theirs, mine, "{id}: variables");
        let s = &ours.model_structure;
        assert_eq!(md.outputs.len(), s.outputs.len(), "{id}");
        assert_eq!(md.derivatives.len(), s.derivatives.len(), "{id}");
        assert_eq!(md.initialUnknowns.len(), s.initial_unknowns.len(), "{id}");
        assert!(md.coSimulation.is_some() && md.modelExchange.is_some(), "{id}: both interfaces");

        // the platform binary, loaded by fmi-rs: the FMI version and types platform it reports
        let instance = builder.instantiate_cs("probe").unwrap_or_else(|e| panic!("{id}: {e}"));
        assert_eq!(instance.getVersion(), "2.0", "{id}");
        assert_eq!(instance.getTypesPlatform(), "default", "{id}");
    }
}

#[test]
fn fmi_rs_validation_is_live_on_our_documents() {
    // the same XML with one defect each: the validation that passed above must now fail
    // (the unpacked archive lives as long as its Fmu)
    let fmu = nigel_integration_tests::Fmu::load(&archive("nigel_plant")).unwrap();
    let dir = fmu.dir.clone();
    let xml = std::fs::read_to_string(dir.join("modelDescription.xml")).unwrap();
    assert!(problems(&RsModelDescription::from_string(&xml).unwrap()).is_empty());
    // 1. an output dropped from <Outputs> (the first <Unknown> there)
    let outputs = xml.find("<Outputs>").unwrap();
    let first = outputs + xml[outputs..].find("<Unknown").unwrap();
    let end = first + xml[first..].find("/>").unwrap() + 2;
    let dropped = format!("{}{}", &xml[..first], &xml[end..]);
    let found = problems(&RsModelDescription::from_string(&dropped).unwrap());
    assert!(found.iter().any(|m| m.contains("outputs do not match")), "{found:#?}");
    // 2. an input without its start value
    let input = xml.find("name=\"delta_fl\"").unwrap();
    let start = input + xml[input..].find(" start=\"0\"").unwrap();
    let no_start = format!("{}{}", &xml[..start], &xml[start + " start=\"0\"".len()..]);
    let found = problems(&RsModelDescription::from_string(&no_start).unwrap());
    assert_eq!(found, vec!["Variable 'delta_fl' has no start value.".to_string()]);
    // 3. a name the structured naming convention forbids
    let bad_name = xml.replacen("name=\"der(x)\"", "name=\"der x\"", 1);
    let found = problems(&RsModelDescription::from_string(&bad_name).unwrap());
    assert!(found.iter().any(|m| m.contains("'der x'") && m.contains("structured")), "{found:#?}");
}

/// Indices (0-based) of the recorded variables: every non-String output, in
/// ModelVariables order (as `nigel_cosim` records by default).
fn output_indices(md: &RsModelDescription) -> Vec<usize> {
    md.modelVariables
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output && !matches!(v.variableType, VariableType::String { .. }))
        .map(|(i, _)| i)
        .collect()
}

fn settings(
    builder: &fmi_rs::fmi2::builder::FMU2Builder,
    md: Arc<RsModelDescription>,
    starts: &[(&str, &str)],
    stop: f64,
) -> SimulationSettings {
    SimulationSettings {
        unzipdir: builder.unzipdir.path().to_path_buf(),
        model_description: md,
        start_time: 0.0,
        stop_time: stop,
        logging_on: false,
        set_stop_time: true, // as our master: fmi2SetupExperiment(stopTimeDefined = true)
        output_interval: STEP,
        log_time_scale: false,
        tolerance: 1e-9, // fmi-rs's relative tolerance on time points, not sent to the FMU
        set_tolerance: false,
        start_values: starts.iter().map(|(n, v)| (n.to_string(), v.to_string())).collect(),
        log_fmi_calls: false,
        input_file: None,
        early_return_allowed: false,
        event_mode_used: false,
        log_file: None,
        initial_fmu_state_file: None,
        final_fmu_state_file: None,
    }
}

fn as_f64(v: &VariableValue) -> f64 {
    v.to_f64().expect("not a String")
}

/// Asserts fmi-rs's trajectories equal `nigel_cosim`'s results bit for bit; returns the
/// number of values compared.
fn assert_bit_identical(id: &str, t: &Trajectories, names: &[String], rows: &[Vec<f64>]) -> usize {
    let theirs: Vec<String> = t.variables().map(|v| v.name.clone()).collect();
    assert_eq!(theirs, names, "{id}: recorded variables");
    assert_eq!(t.time.len(), rows.len(), "{id}: communication points");
    let mut compared = 0;
    for (k, (row, time)) in t.rows.iter().zip(&t.time).enumerate() {
        assert_eq!(time.to_bits(), rows[k][0].to_bits(), "{id}: time of point {k}");
        for (j, v) in row.iter().enumerate() {
            let (a, b) = (as_f64(v), rows[k][j + 1]);
            assert_eq!(a.to_bits(), b.to_bits(), "{id}: {} at t = {time}: fmi-rs {a:e}, nigel_cosim {b:e}", names[j]);
            compared += 1;
        }
    }
    compared
}

#[test]
fn co_simulation_through_fmi_rs_equals_nigel_cosim_bit_for_bit() {
    for (id, starts, stop) in cases() {
        // fmi-rs: its unzip, its driver, its recorder
        let builder = fmi_rs_load(id);
        let (md, recorder) = description_and_recorder(&builder);
        fmi_rs::sim::fmi2::cs::simulate(&settings(&builder, md.clone(), &starts, stop), None, recorder.clone())
            .unwrap_or_else(|e| panic!("{id}: fmi-rs simulate: {e}"));
        let trajectories = Arc::into_inner(recorder).unwrap().into_trajectories();

        // nigel_cosim: the same archive, start values and grid
        let mut b = SystemBuilder::new();
        b.add_instance(id, Fmu::load(&archive(id)).unwrap()).unwrap();
        for (name, value) in &starts {
            b.set_text(&format!("{id}.{name}"), value).unwrap();
        }
        let (results, _) = simulate(&b.build(), &Experiment::new(stop, STEP)).unwrap();
        let rows: Vec<Vec<f64>> = (0..results.rows()).map(|k| results.row(k).to_vec()).collect();

        let n = assert_bit_identical(id, &trajectories, &results.names, &rows);
        let points = (stop / STEP).round() as usize + 1;
        assert_eq!(n, points * results.names.len(), "{id}");
        eprintln!("{id}: {n} values ({points} points x {} outputs) bit-identical", results.names.len());

        // the run is not trivial: some output moved away from its initial value
        let moved = (1..rows[0].len()).any(|j| rows.iter().any(|r| r[j].to_bits() != rows[0][j].to_bits()));
        assert!(moved, "{id}: every output constant, the comparison would be weak");
    }
}

#[test]
fn model_exchange_through_fmi_rs_euler_equals_euler_over_nigel_cosim() {
    let (id, starts, stop) = cases().swap_remove(0);
    assert_eq!(id, "nigel_plant");

    // fmi-rs: Model Exchange driver, forward Euler with h = STEP
    let builder = fmi_rs_load(id);
    let (md, recorder) = description_and_recorder(&builder);
    fmi_rs::sim::fmi2::me::simulate(
        &settings(&builder, md.clone(), &starts, stop),
        &ForwardEulerFactory { fixed_step_size: STEP },
        None,
        recorder.clone(),
    )
    .unwrap_or_else(|e| panic!("fmi-rs ME simulate: {e}"));
    let trajectories = Arc::into_inner(recorder).unwrap().into_trajectories();

    // forward Euler here, over nigel_cosim's Model Exchange instance (FMI 2.0 section 3.2.3)
    let fmu = Fmu::load_with(
        &archive(id),
        &ImportOptions { interface: Some(Interface::ModelExchange), ..ImportOptions::default() },
    )
    .unwrap();
    let ours = fmu.description();
    let outputs: Vec<(String, u32)> = ours
        .model_variables
        .iter()
        .filter(|v| v.causality == model_description::Causality::Output)
        .map(|v| (v.name.clone(), v.value_reference))
        .collect();
    let vrs: Vec<u32> = outputs.iter().map(|o| o.1).collect();
    let names: Vec<String> = outputs.iter().map(|o| o.0.clone()).collect();
    let nx = ours.model_structure.derivatives.len();
    assert_eq!(nx, 10, "6 rigid-body + 4 servo states");

    let mut inst = Instance::new(&fmu, "euler").unwrap();
    inst.setup_experiment(None, 0.0, Some(stop)).unwrap();
    for (name, value) in &starts {
        let v = ours.variable(name).unwrap();
        match value.parse::<f64>() {
            Ok(x) => inst.set_real(&[v.value_reference], &[x]).unwrap(),
            Err(_) => inst.set_boolean(&[v.value_reference], &[(*value == "true") as i32]).unwrap(),
        }
    }
    inst.enter_initialization_mode().unwrap();
    inst.exit_initialization_mode().unwrap();
    assert_eq!(inst.new_discrete_states().unwrap().new_discrete_states_needed, 0);
    inst.enter_continuous_time_mode().unwrap();
    let (mut x, mut dx) = (vec![0.0; nx], vec![0.0; nx]);
    inst.get_continuous_states(&mut x).unwrap();
    let steps = (stop / STEP).round() as usize;
    let mut rows = Vec::with_capacity(steps + 1);
    let mut record = |inst: &mut Instance, t: f64| {
        let mut row = vec![t; vrs.len() + 1];
        inst.get_real(&vrs, &mut row[1..]).unwrap();
        rows.push(row);
    };
    record(&mut inst, 0.0);
    for n in 0..steps {
        inst.set_time(n as f64 * STEP).unwrap();
        inst.set_continuous_states(&x).unwrap();
        inst.get_derivatives(&mut dx).unwrap();
        for (xi, di) in x.iter_mut().zip(&dx) {
            *xi += di * STEP;
        }
        let t = (n + 1) as f64 * STEP;
        inst.set_time(t).unwrap();
        inst.set_continuous_states(&x).unwrap();
        record(&mut inst, t);
    }
    inst.terminate().unwrap();

    let n = assert_bit_identical(id, &trajectories, &names, &rows);
    eprintln!("{id} ME: {n} values of forward Euler bit-identical");
    let psi = names.iter().position(|n| n == "psi").unwrap() + 1;
    assert!(rows[steps][psi].abs() > 1e-2, "the car turned: psi = {}", rows[steps][psi]);
}

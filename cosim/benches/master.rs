//! `cargo bench -p nigel-cosim`: the master's speed.
//!
//! 1. the plant alone, 30 s at 1 ms, through the master (CS, jacobi), recording nothing
//!    and recording all 25 outputs every step; the plant's own `fmi2DoStep` called
//!    directly in a bare loop for the floor;
//! 2. the master's overhead per FMU per step with a trivial FMU (C `gain`, 10 instances in
//!    a chain, 30,000 steps), ordered and jacobi;
//! 3. if `COSIM_BENCH_PYTHON` names a Python with fmpy (and optionally ecospy /
//!    libcosimpy), the same plant run by those tools (`cosim/benches/external.py`).
//!
//! Prints one line per measurement (best of 5 runs).

use nigel_cosim::{simulate, Algorithm, Experiment, Fmu, Instance, System, SystemBuilder};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn target() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("target"))
}

fn best_of<F: FnMut() -> Duration>(n: usize, mut f: F) -> Duration {
    (0..n).map(|_| f()).min().unwrap_or_default()
}

fn trivial_fmu(dir: &Path) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cfmu/models.c");
    let so = dir.join("gain.so");
    let ok = Command::new("cc")
        .args(["-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-DMODEL=2"])
        .arg(&src)
        .arg("-o")
        .arg(&so)
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    assert!(ok, "cc failed");
    let xml = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="gain" guid="{test-gain}" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="gain" canHandleVariableCommunicationStepSize="true"/>
  <ModelVariables>
    <ScalarVariable name="u" valueReference="0" causality="input"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output"><Real/></ScalarVariable>
    <ScalarVariable name="k" valueReference="2" causality="parameter" variability="fixed"><Real start="2"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="2" dependencies="1"/></Outputs></ModelStructure>
</fmiModelDescription>"#;
    let fmu = dir.join("gain.fmu");
    let mut zip = zip::ZipWriter::new(std::fs::File::create(&fmu).unwrap());
    let o = zip::write::SimpleFileOptions::default();
    use std::io::Write;
    zip.start_file("modelDescription.xml", o).unwrap();
    zip.write_all(xml.as_bytes()).unwrap();
    zip.start_file("binaries/linux64/gain.so", o).unwrap();
    zip.write_all(&std::fs::read(&so).unwrap()).unwrap();
    zip.finish().unwrap();
    fmu
}

fn main() {
    let plant = target().join("fmu").join("nigel_plant.fmu");
    if !plant.is_file() {
        eprintln!("{} missing: run `cargo run --release -p build-fmu` first", plant.display());
        std::process::exit(1);
    }
    let fmu = Fmu::load(&plant).unwrap();
    let steps = 30_000.0;
    let mut system = SystemBuilder::new();
    system.add_instance("plant", fmu.clone()).unwrap();
    system.set_text("plant.v_x_start", "0.35").unwrap();
    system.set_text("plant.delta_fl", "0.2").unwrap();
    let system: System = system.build();
    let run = |record: Option<Vec<String>>| {
        best_of(5, || {
            let mut e = Experiment::new(30.0, 1e-3);
            e.record = record.clone();
            let t = Instant::now();
            simulate(&system, &e).unwrap();
            t.elapsed()
        })
    };
    let none = run(Some(vec![]));
    let all = run(None);
    // the floor: the same fmi2DoStep calls in a bare loop
    let bare = best_of(5, || {
        let mut inst = Instance::new(&fmu, "bare").unwrap();
        let vx = fmu.description().real_value_reference("v_x_start").unwrap();
        let d = fmu.description().real_value_reference("delta_fl").unwrap();
        inst.setup_experiment(None, 0.0, Some(30.0)).unwrap();
        inst.set_real(&[vx, d], &[0.35, 0.2]).unwrap();
        inst.enter_initialization_mode().unwrap();
        inst.exit_initialization_mode().unwrap();
        let t = Instant::now();
        for n in 0..30_000u32 {
            let t0 = f64::from(n) * 1e-3;
            inst.do_step(t0, f64::from(n + 1) * 1e-3 - t0).unwrap();
        }
        t.elapsed()
    });
    // the floor with the 25 outputs read after every step (one fmi2GetReal)
    let outputs: Vec<u32> = fmu
        .description()
        .model_variables
        .iter()
        .filter(|v| v.causality == model_description::Causality::Output)
        .map(|v| v.value_reference)
        .collect();
    let bare_get = best_of(5, || {
        let mut inst = Instance::new(&fmu, "bare").unwrap();
        let vx = fmu.description().real_value_reference("v_x_start").unwrap();
        let d = fmu.description().real_value_reference("delta_fl").unwrap();
        inst.setup_experiment(None, 0.0, Some(30.0)).unwrap();
        inst.set_real(&[vx, d], &[0.35, 0.2]).unwrap();
        inst.enter_initialization_mode().unwrap();
        inst.exit_initialization_mode().unwrap();
        let mut values = vec![0.0; outputs.len()];
        let t = Instant::now();
        for n in 0..30_000u32 {
            let t0 = f64::from(n) * 1e-3;
            inst.do_step(t0, f64::from(n + 1) * 1e-3 - t0).unwrap();
            inst.get_real(&outputs, &mut values).unwrap();
        }
        t.elapsed()
    });
    let us = |d: Duration| d.as_secs_f64() * 1e6 / steps;
    println!(
        "plant 30 s at 1 ms, bare fmi2DoStep loop       : {:8.1} ms  ({:.3} us/step)",
        bare.as_secs_f64() * 1e3,
        us(bare)
    );
    println!(
        "plant 30 s at 1 ms, bare loop + 1 fmi2GetReal of the {} outputs: {:8.1} ms  ({:.3} us/step)",
        outputs.len(),
        bare_get.as_secs_f64() * 1e3,
        us(bare_get)
    );
    println!(
        "plant 30 s at 1 ms, master, recording nothing   : {:8.1} ms  ({:.3} us/step)",
        none.as_secs_f64() * 1e3,
        us(none)
    );
    println!(
        "plant 30 s at 1 ms, master, 25 outputs recorded : {:8.1} ms  ({:.3} us/step)",
        all.as_secs_f64() * 1e3,
        us(all)
    );

    // overhead per FMU per step: a chain of trivial FMUs
    let dir = target().join("cosim-bench");
    std::fs::create_dir_all(&dir).unwrap();
    let gain = Fmu::load(&trivial_fmu(&dir)).unwrap();
    let n = 10;
    let mut b = SystemBuilder::new();
    for i in 0..n {
        b.add_instance(&format!("g{i}"), gain.clone()).unwrap();
        if i > 0 {
            b.connect(&format!("g{}.y", i - 1), &format!("g{i}.u")).unwrap();
        }
    }
    let chain = b.build();
    for algorithm in [Algorithm::Ordered, Algorithm::Jacobi] {
        let d = best_of(5, || {
            let mut e = Experiment::new(30.0, 1e-3);
            e.algorithm = algorithm;
            e.record = Some(vec![]);
            let t = Instant::now();
            simulate(&chain, &e).unwrap();
            t.elapsed()
        });
        println!(
            "trivial FMU x {n} in a chain, 30,000 steps, {algorithm:?}: {:8.1} ms  ({:.1} ns per FMU per step, incl. 1 get + 1 set per connection)",
            d.as_secs_f64() * 1e3,
            d.as_secs_f64() * 1e9 / (steps * n as f64)
        );
    }

    if let Some(python) = std::env::var_os("COSIM_BENCH_PYTHON") {
        // relative to the workspace root (cargo runs benches in the package folder)
        let python = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(python);
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/external.py");
        let ssp = dir.join("plant.ssp");
        nigel_cosim::write_ssp(&system, "plant", Some(30.0), &ssp).unwrap();
        let status = Command::new(python).arg(script).arg(&plant).arg(&ssp).status();
        if !status.map(|s| s.success()).unwrap_or(false) {
            eprintln!("external tools: the Python script failed");
        }
    } else {
        println!("(set COSIM_BENCH_PYTHON=target/venv/bin/python for fmpy / ecos / libcosim on the same FMU)");
    }
}

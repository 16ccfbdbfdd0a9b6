//! `cargo bench -p nigel-cosim`: the master's speed (best of 5 runs each).
//!
//! 1. The three-FMU closed loop `target/ssp/nigel_closed_loop.ssp`, 30 s at 1 ms (30,000
//!    steps): the floor (the plant's own `fmi2DoStep` in a bare loop, then all three FMUs'
//!    in a bare loop with no data exchanged); the master in `ordered` and `jacobi`,
//!    recording nothing and recording all 52 outputs every step, `jacobi` in 1 and 2
//!    threads, `ordered` with the per-FMU profile; each with its epsilon (the paper's
//!    tracking metric over the 30,000 samples) and final pose, so that readers see every
//!    tool ran the same thing.
//! 2. With `COSIM_BENCH_PYTHON` naming the Python of `scripts/python-env.sh`: the same
//!    `.ssp` run by ecos (ecospy), libcosim (libcosimpy) and fmpy `simulate_ssp`
//!    (`cosim/benches/external.py`), in the same run.
//! 3. The master's overhead per FMU per step: 10 trivial C FMUs in a chain.
//! 4. Threads: 10 C FMUs side by side, trivial and heavier (`-DWORK`), `jacobi` in 1 and
//!    2 threads.
//! 5. The FMI layer per value: `fmi2GetReal` of all Real outputs and `fmi2SetReal` of all
//!    Real inputs of each of our three FMUs, one call per batch, in ns per value and per
//!    call (the master's buffers, `nigel_cosim::Instance`, the C ABI, the layer's checks
//!    and the model's getter/setter); and the master's own cost per step: `ordered`
//!    recording nothing minus the bare loop of the three `fmi2DoStep`s.
//! 6. Isolation: the closed loop in process against `--isolate`, alternated (alone with
//!    `COSIM_BENCH_ONLY=isolation`; `COSIM_BENCH_SPINS` adds fixed ways of waiting); and
//!    with `COSIM_BENCH_ONLY=round-trips` the floor, null round trips master <-> host.
//!
//! `COSIM_BENCH_ONLY=isolation` runs the isolation cost alone, `COSIM_BENCH_ONLY=per_value`
//! section 5 alone.

use nigel_cosim::{simulate, Algorithm, Experiment, Fmu, Instance, Results, System, SystemBuilder};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

const STEPS: f64 = 30_000.0;
const POSE: [&str; 6] = ["plant.x", "plant.y", "plant.psi", "maneuver.x_ref", "maneuver.y_ref", "maneuver.psi_ref"];

fn target() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("target"))
}

/// `n` instances `g0 .. g(n-1)` of `fmu`, each output `y` feeding the next one's input `u`.
fn chain_of(fmu: &std::sync::Arc<Fmu>, n: usize) -> System {
    let mut b = SystemBuilder::new();
    for i in 0..n {
        b.add_instance(&format!("g{i}"), fmu.clone()).unwrap();
        if i > 0 {
            b.connect(&format!("g{}.y", i - 1), &format!("g{i}.u")).unwrap();
        }
    }
    b.build()
}

fn best_of<F: FnMut() -> Duration>(n: usize, mut f: F) -> Duration {
    (0..n).map(|_| f()).min().unwrap_or_default()
}

fn line(what: &str, d: Duration, note: &str) {
    println!("{what:<58}: {:8.1} ms  ({:6.2} us/step) {note}", d.as_secs_f64() * 1e3, d.as_secs_f64() * 1e6 / STEPS);
}

/// The paper's epsilon: the norm of the RMS errors of x, y, psi against the reference
/// over samples 1..=30000 (as `table3` computes it).
fn epsilon(r: &Results) -> f64 {
    let col = |n: &str| r.column(n).unwrap_or_else(|| panic!("{n} not recorded"));
    let c: Vec<Vec<f64>> = POSE.iter().map(|n| col(n)[1..].to_vec()).collect();
    let rms =
        |a: &[f64], b: &[f64]| (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / a.len() as f64).sqrt();
    let e = [rms(&c[0], &c[3]), rms(&c[1], &c[4]), rms(&c[2], &c[5])];
    (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt()
}

fn pose(r: &Results) -> String {
    let last = |n: &str| *r.column(n).unwrap().last().unwrap();
    format!("x {:.9} y {:.9} psi {:.9}", last("plant.x"), last("plant.y"), last("plant.psi"))
}

/// The C test model (tests/cfmu/models.c) `gain`, compiled with `flags`, as an FMU.
fn c_gain(dir: &Path, name: &str, flags: &[&str]) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cfmu/models.c");
    let so = dir.join(format!("{name}.so"));
    let ok = Command::new("cc")
        .args(["-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-DMODEL=2"])
        .args(flags)
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
    let fmu = dir.join(format!("{name}.fmu"));
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

/// The instances of `system` initialized with its start values, inputs left at them.
fn bare_instances(system: &System, only: Option<&str>) -> Vec<Instance> {
    let mut out = Vec::new();
    for spec in system.instances.iter().filter(|s| only.is_none_or(|o| s.name == o)) {
        let mut inst = Instance::new(&spec.fmu, &spec.name).unwrap();
        inst.setup_experiment(None, 0.0, Some(30.0)).unwrap();
        nigel_cosim::simulate::apply_start_values(&mut inst, spec).unwrap();
        inst.enter_initialization_mode().unwrap();
        inst.exit_initialization_mode().unwrap();
        out.push(inst);
    }
    out
}

fn bare_loop(system: &System, only: Option<&str>) -> Duration {
    best_of(5, || {
        let mut instances = bare_instances(system, only);
        let t = Instant::now();
        for n in 0..30_000u32 {
            let t0 = f64::from(n) * 1e-3;
            for inst in instances.iter_mut() {
                inst.do_step(t0, f64::from(n + 1) * 1e-3 - t0).unwrap();
            }
        }
        t.elapsed()
    })
}

fn run_master(
    system: &System,
    algorithm: Algorithm,
    threads: usize,
    record: Option<Vec<String>>,
    profile: bool,
) -> Duration {
    best_of(5, || {
        let mut e = Experiment::new(30.0, 1e-3);
        e.algorithm = algorithm;
        e.threads = threads;
        e.record = record.clone();
        e.profile = profile;
        let t = Instant::now();
        simulate(system, &e).unwrap();
        t.elapsed()
    })
}

/// The closed loop in process and with every FMU in its own host process (`--isolate`),
/// `jacobi` and `ordered` recording nothing, alternated 5 times (best and spread of each);
/// the isolation cost per FMU per step is the difference over 3 FMUs x 30,000 steps.
/// `COSIM_BENCH_SPINS` (`;`-separated `NIGEL_COSIM_SPIN` values, an empty one the
/// default) runs the isolated side once per way of waiting, all alternated.
fn isolation(system: &System) {
    let host = target().join("release").join("cosim-host");
    if !host.is_file() {
        println!("isolation: {} missing (cargo build --release -p nigel-cosim)", host.display());
        return;
    }
    let spins: Vec<String> = std::env::var("COSIM_BENCH_SPINS")
        .map(|v| v.split(';').map(|s| s.trim().to_string()).collect())
        .unwrap_or_else(|_| vec![String::new()]);
    let set_spin = |spin: &str| {
        if spin.is_empty() {
            std::env::remove_var("NIGEL_COSIM_SPIN");
        } else {
            std::env::set_var("NIGEL_COSIM_SPIN", spin);
        }
    };
    for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
        let mut times = vec![Vec::new(); 1 + spins.len()];
        for _ in 0..5 {
            for (k, times) in times.iter_mut().enumerate() {
                let mut e = Experiment::new(30.0, 1e-3);
                e.algorithm = algorithm;
                e.record = Some(vec![]);
                if k > 0 {
                    set_spin(&spins[k - 1]);
                    e.isolation = Some(nigel_cosim::Isolation { host: Some(host.clone()), ..Default::default() });
                }
                let t = Instant::now();
                simulate(system, &e).unwrap();
                times.push(t.elapsed());
            }
        }
        set_spin("");
        let best = |v: &[Duration]| v.iter().min().copied().unwrap_or_default();
        let worst = |v: &[Duration]| v.iter().max().copied().unwrap_or_default();
        let a = best(&times[0]);
        let name = format!("{algorithm:?}").to_lowercase();
        line(
            &format!("master {name}, recording nothing, in process"),
            a,
            &format!(
                "(5 runs alternated with --isolate: {:.1} .. {:.1} ms)",
                a.as_secs_f64() * 1e3,
                worst(&times[0]).as_secs_f64() * 1e3
            ),
        );
        for (k, spin) in spins.iter().enumerate() {
            let b = best(&times[k + 1]);
            let policy = if spin.is_empty() { String::new() } else { format!(" (spin {spin})") };
            line(
                &format!("master {name}, recording nothing, --isolate{policy}"),
                b,
                &format!(
                    "({:.1} .. {:.1} ms; isolation cost {:.2} us per FMU per step)",
                    b.as_secs_f64() * 1e3,
                    worst(&times[k + 1]).as_secs_f64() * 1e3,
                    (b.saturating_sub(a)).as_secs_f64() * 1e6 / (STEPS * system.instances.len() as f64)
                ),
            );
        }
    }
}

/// The floor under an isolated step: null round trips (a call the host answers at once)
/// master <-> host, 10,000 per host, with each way of waiting (`NIGEL_COSIM_SPIN`: master
/// spin, host spin in us, yield every n spin rounds), to one host, and to three hosts in
/// turn and overlapped (posted to all, then collected); the policies alternated 3 times,
/// best and range, in us per round trip. Spinning only is measured with one host alone:
/// three hosts and the master spinning on two cores wait for the scheduler's time slices
/// (milliseconds per round trip).
fn round_trips(system: &System, host: &Path) {
    let dir = system.instances[0].fmu.unpacked_dir().join("binaries").join("linux64");
    let Some(library) = std::fs::read_dir(&dir).ok().and_then(|mut d| d.find_map(|e| e.ok().map(|e| e.path()))) else {
        println!("round trips: no library in {}", dir.display());
        return;
    };
    let policies = [("spin only", "1000000,1000000,0"), ("futex only", "0,0,0"), ("default", "")];
    let cases = [(1usize, false), (3, false), (3, true)];
    let n = 10_000u32;
    let mut times = vec![vec![Vec::new(); cases.len()]; policies.len()];
    for _ in 0..3 {
        for (k, (_, policy)) in policies.iter().enumerate() {
            if policy.is_empty() {
                std::env::remove_var("NIGEL_COSIM_SPIN");
            } else {
                std::env::set_var("NIGEL_COSIM_SPIN", policy);
            }
            for (j, &(hosts, overlapped)) in cases.iter().enumerate() {
                if policy.starts_with("1000000") && hosts > 1 {
                    continue;
                }
                let d = nigel_cosim::isolate::null_round_trips(host, &library, hosts, n, overlapped).unwrap();
                times[k][j].push(d.as_secs_f64() * 1e6 / f64::from(n) / hosts as f64);
            }
        }
    }
    std::env::remove_var("NIGEL_COSIM_SPIN");
    for (k, (name, _)) in policies.iter().enumerate() {
        for (j, &(hosts, overlapped)) in cases.iter().enumerate() {
            let v = &times[k][j];
            if v.is_empty() {
                continue;
            }
            let best = v.iter().copied().fold(f64::INFINITY, f64::min);
            let worst = v.iter().copied().fold(0.0, f64::max);
            println!(
                "null round trip, {name:<10}, {hosts} host(s){:<12}: {best:7.2} us per host ({best:.2} .. {worst:.2})",
                if overlapped { ", overlapped" } else { "" }
            );
        }
    }
}

fn main() {
    let ssp = target().join("ssp").join("nigel_closed_loop.ssp");
    if !ssp.is_file() {
        eprintln!("{} missing: run `cargo run --release -p build-fmu` first", ssp.display());
        std::process::exit(1);
    }
    let closed = nigel_cosim::read_ssp(&ssp, &Default::default()).unwrap();
    let system = &closed.system;
    if std::env::var_os("COSIM_BENCH_ONLY").is_some_and(|v| v == "round-trips") {
        round_trips(system, &target().join("release").join("cosim-host"));
        return;
    }
    if std::env::var_os("COSIM_BENCH_ONLY").is_some_and(|v| v == "isolation") {
        isolation(system);
        return;
    }
    if std::env::var_os("COSIM_BENCH_ONLY").is_some_and(|v| v == "per_value") {
        per_value(system);
        return;
    }
    println!(
        "closed loop {} ({} instances, {} connections), 30 s at 1 ms:",
        ssp.display(),
        system.instances.len(),
        system.connections.len()
    );
    line("floor: the plant's own fmi2DoStep, bare loop", bare_loop(system, Some("plant")), "");
    let floor_three = bare_loop(system, None);
    line("floor: the three FMUs' fmi2DoStep, bare loop, no exchange", floor_three, "");
    let pose_names: Vec<String> = POSE.iter().map(|s| s.to_string()).collect();
    for algorithm in [Algorithm::Ordered, Algorithm::Jacobi] {
        let mut e = Experiment::new(30.0, 1e-3);
        e.algorithm = algorithm;
        e.record = Some(pose_names.clone());
        let (r, _) = simulate(system, &e).unwrap();
        let note = format!("epsilon {:.12} | {}", epsilon(&r), pose(&r));
        let name = format!("{algorithm:?}").to_lowercase();
        let nothing = run_master(system, algorithm, 1, Some(vec![]), false);
        line(&format!("master {name}, recording nothing"), nothing, &note);
        if algorithm == Algorithm::Ordered {
            line(
                "  exchange cost: ordered (recording nothing) - bare loop",
                nothing.saturating_sub(floor_three),
                "(the gets, sets and the master's own work per step)",
            );
        }
        line(
            &format!("master {name}, all 52 outputs recorded every step"),
            run_master(system, algorithm, 1, None, false),
            "",
        );
        if algorithm == Algorithm::Ordered {
            line(
                "master ordered, all recorded, per-FMU profile (--summary)",
                run_master(system, algorithm, 1, None, true),
                "",
            );
        } else {
            line(
                "master jacobi, 2 threads, recording nothing",
                run_master(system, algorithm, 2, Some(vec![]), false),
                "",
            );
            line("master jacobi, 2 threads, all recorded", run_master(system, algorithm, 2, None, false), "");
        }
    }

    if let Some(python) = std::env::var_os("COSIM_BENCH_PYTHON") {
        // relative to the workspace root (cargo runs benches in the package folder)
        let python = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(python);
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/external.py");
        let status = Command::new(python).arg(script).arg(&ssp).status();
        if !status.map(|s| s.success()).unwrap_or(false) {
            eprintln!("external tools: the Python script failed");
        }
    } else {
        println!("(set COSIM_BENCH_PYTHON=target/venv/bin/python for ecos, libcosim and fmpy on the same .ssp)");
    }

    isolation(system);

    per_value(system);

    // overhead per FMU per step: a chain of trivial FMUs
    let dir = target().join("cosim-bench");
    std::fs::create_dir_all(&dir).unwrap();
    let gain = Fmu::load(&c_gain(&dir, "gain", &[])).unwrap();
    let heavy = Fmu::load(&c_gain(&dir, "gain_work", &["-DWORK=400"])).unwrap();
    let n = 10;
    let chain = chain_of(&gain, n);
    for algorithm in [Algorithm::Ordered, Algorithm::Jacobi] {
        let d = run_master(&chain, algorithm, 1, Some(vec![]), false);
        println!(
            "trivial FMU x {n} in a chain, 30,000 steps, {algorithm:?}: {:8.1} ms  ({:.1} ns per FMU per step, incl. 1 get + 1 set per connection)",
            d.as_secs_f64() * 1e3,
            d.as_secs_f64() * 1e9 / (STEPS * n as f64)
        );
    }
    // threads: the same chains, trivial and heavier
    for (what, fmu) in [("trivial", &gain), ("heavier (WORK=400)", &heavy)] {
        let chain = chain_of(fmu, n);
        let one = run_master(&chain, Algorithm::Jacobi, 1, Some(vec![]), false);
        let two = run_master(&chain, Algorithm::Jacobi, 2, Some(vec![]), false);
        println!(
            "{what} FMU x {n}, jacobi, 30,000 steps: 1 thread {:8.1} ms, 2 threads {:8.1} ms ({:.2}x)",
            one.as_secs_f64() * 1e3,
            two.as_secs_f64() * 1e3,
            one.as_secs_f64() / two.as_secs_f64()
        );
    }
}

/// Section 5 (alone: `COSIM_BENCH_ONLY=per_value`): `fmi2GetReal` of every Real output and
/// `fmi2SetReal` of every Real input of each instance (the inputs set to the values read
/// back, which every FMU accepts), best of 5 rounds of 20,000 calls.
fn per_value(system: &System) {
    use model_description::Causality;
    const CALLS: u32 = 20_000;
    for spec in &system.instances {
        let mut inst = bare_instances(system, Some(&spec.name)).pop().unwrap();
        let md = spec.fmu.description();
        let vrs = |c: Causality| -> Vec<u32> {
            md.model_variables.iter().filter(|v| v.causality == c && v.is_real()).map(|v| v.value_reference).collect()
        };
        let (outputs, inputs) = (vrs(Causality::Output), vrs(Causality::Input));
        let mut out = vec![0.0; outputs.len()];
        let mut input_values = vec![0.0; inputs.len()];
        inst.get_real(&inputs, &mut input_values).unwrap();
        inst.get_real(&outputs, &mut out).unwrap(); // the initial event, once
        let get = best_of(5, || {
            let t = Instant::now();
            for _ in 0..CALLS {
                inst.get_real(&outputs, &mut out).unwrap();
            }
            t.elapsed()
        });
        let set = best_of(5, || {
            let t = Instant::now();
            for _ in 0..CALLS {
                inst.set_real(&inputs, &input_values).unwrap();
            }
            t.elapsed()
        });
        let ns = |d: Duration, n: usize| {
            (d.as_secs_f64() * 1e9 / f64::from(CALLS), d.as_secs_f64() * 1e9 / (f64::from(CALLS) * n.max(1) as f64))
        };
        let (g_call, g_value) = ns(get, outputs.len());
        let (s_call, s_value) = ns(set, inputs.len());
        println!(
            "{:<10} fmi2GetReal of {:2} outputs: {:7.1} ns/call {:5.1} ns/value | fmi2SetReal of {:2} inputs: {:7.1} ns/call {:5.1} ns/value",
            spec.name, outputs.len(), g_call, g_value, inputs.len(), s_call, s_value
        );
    }
}

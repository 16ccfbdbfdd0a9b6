//! Hostile and mistaken input found by a fuzzer and by users, each refused by name (or
//! handled) where the master used to crash, hang, write gigabytes or go on silently:
//! lying and bomb archives, truncated libraries, non-regular files, oversized and
//! repetitive XML, duplicate names, hostile log formats, undeclared SSD connectors,
//! wrong `.ssv` roots, long connector chains.

mod common;
use common::{build_fmu, build_fmu_with, build_hostile, plant_fmu, work_dir, zip_entries, Model};
use nigel_cosim::{read_ssp, Error, Fmu, ImportOptions, Instance, UnpackLimits};
use std::io::{Read, Write};
use std::path::Path;

/// The gain FMU's entries plus `extra`.
fn gain_with(dir: &Path, extra: &[(&str, Vec<u8>)]) -> Vec<(String, Vec<u8>)> {
    build_fmu(Model::Gain, dir, &[]);
    let mut v = vec![
        ("modelDescription.xml".to_string(), Model::Gain.model_description().into_bytes()),
        ("binaries/linux64/gain.so".to_string(), std::fs::read(dir.join("gain.so")).unwrap()),
    ];
    v.extend(extra.iter().map(|(n, b)| (n.to_string(), b.clone())));
    v
}

fn zip_owned(path: &Path, entries: &[(String, Vec<u8>)]) {
    let e: Vec<(&str, Vec<u8>)> = entries.iter().map(|(n, b)| (n.as_str(), b.clone())).collect();
    zip_entries(path, &e);
}

fn load(path: &Path, limits: UnpackLimits) -> Result<std::sync::Arc<Fmu>, Error> {
    Ok(Fmu::load_with(path, &ImportOptions { limits, ..ImportOptions::default() })?)
}

#[test]
fn an_entry_larger_than_its_header_is_refused_at_once() {
    let dir = work_dir("lying-header");
    let fmu = dir.join("lying.fmu");
    zip_owned(&fmu, &gain_with(&dir, &[("resources/zeros.bin", vec![0u8; 1 << 20])]));
    // patch the entry's uncompressed size (1 MiB) to 1 KiB in its local header (offset
    // 22) and its central directory record (offset 24); no zip64 fields at this size
    let mut bytes = std::fs::read(&fmu).unwrap();
    let (real, lie) = ((1u32 << 20).to_le_bytes(), 1024u32.to_le_bytes());
    let mut patched = 0;
    for k in 0..bytes.len() - 30 {
        let at = match &bytes[k..k + 4] {
            b"PK\x03\x04" => k + 22,
            b"PK\x01\x02" => k + 24,
            _ => continue,
        };
        if bytes[at..at + 4] == real {
            bytes[at..at + 4].copy_from_slice(&lie);
            patched += 1;
        }
    }
    assert_eq!(patched, 2, "local and central size fields");
    std::fs::write(&fmu, bytes).unwrap();
    match load(&fmu, UnpackLimits::default()) {
        Err(Error::Import(nigel_cosim::ImportError::ArchiveLimit { entry, size, limit, limit_name })) => {
            assert_eq!(
                (entry.as_str(), limit, limit_name),
                ("resources/zeros.bin", 1024, "the size its header declares")
            );
            // refused within the first buffer past the declared size (64 KiB reads)
            assert!(size > 1024 && size <= 1024 + 65536, "{size}");
        }
        other => panic!("accepted or wrong error: {other:?}"),
    }
}

#[test]
fn a_zip_bomb_within_the_size_limits_is_refused_by_its_ratio_before_writing() {
    let dir = work_dir("ratio-bomb");
    let zeros = vec![0u8; 8 << 20];
    let entries: Vec<(String, Vec<u8>)> =
        gain_with(&dir, &[("resources/a.bin", zeros.clone()), ("resources/b.bin", zeros.clone())]);
    let fmu = dir.join("bomb.fmu");
    zip_owned(&fmu, &entries);
    let compressed = std::fs::metadata(&fmu).unwrap().len();
    assert!(compressed < 100_000, "{compressed}"); // deflate packs zeros about 1000:1
    match load(&fmu, UnpackLimits::default()) {
        Err(e @ Error::Import(nigel_cosim::ImportError::ArchiveLimit { limit_name: "max_ratio", .. })) => {
            let Error::Import(nigel_cosim::ImportError::ArchiveLimit { entry, size, limit, .. }) = &e else {
                unreachable!()
            };
            assert_eq!((entry.as_str(), *limit), ("resources/a.bin", 100));
            assert!(*size > 500, "ratio {size}");
            assert!(e.to_string().contains("--max-ratio"), "{e}");
        }
        other => panic!("accepted or wrong error: {other:?}"),
    }
    // a user who trusts the archive raises the limit
    let fmu = load(&fmu, UnpackLimits { max_ratio: 10_000, ..UnpackLimits::default() }).unwrap();
    assert_eq!(std::fs::metadata(fmu.unpacked_dir().join("resources/b.bin")).unwrap().len(), 8 << 20);
    // the total limit is checked on the declared sizes too
    drop(fmu);
    let small = UnpackLimits { max_ratio: 10_000, max_total_bytes: 10 << 20, ..UnpackLimits::default() };
    assert!(matches!(
        load(&dir.join("bomb.fmu"), small),
        Err(Error::Import(nigel_cosim::ImportError::ArchiveLimit { limit_name: "max_total_bytes", .. }))
    ));
}

#[test]
fn a_truncated_library_is_refused_before_dlopen() {
    let dir = work_dir("truncated-so");
    let mut plant = zip::ZipArchive::new(std::fs::File::open(plant_fmu()).unwrap()).unwrap();
    let mut read = |name: &str| {
        let mut v = Vec::new();
        plant.by_name(name).unwrap().read_to_end(&mut v).unwrap();
        v
    };
    let (xml, so) = (read("modelDescription.xml"), read("binaries/linux64/nigel_plant.so"));
    for (what, cut) in [("half", so.len() / 2), ("all but the last byte", so.len() - 1), ("4 KiB", 4096)] {
        let fmu = dir.join("truncated.fmu");
        zip_entries(
            &fmu,
            &[("modelDescription.xml", xml.clone()), ("binaries/linux64/nigel_plant.so", so[..cut].to_vec())],
        );
        match Fmu::load(&fmu) {
            Err(nigel_cosim::ImportError::LoadLibrary { path, reason }) => {
                assert!(reason.contains("past the end of the file"), "{what}: {reason}");
                assert!(path.ends_with("binaries/linux64/nigel_plant.so"), "{}", path.display());
            }
            other => panic!("{what}: {other:?}"),
        }
    }
}

#[test]
fn only_regular_files_are_opened() {
    let dir = work_dir("fifo");
    let fifo = dir.join("model.fmu");
    assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    // should the master open the FIFO and wait for a writer, this thread writes junk into
    // it, so that the test fails with a wrong error instead of hanging
    let rescuer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_secs(5));
            use std::os::unix::fs::OpenOptionsExt;
            if let Ok(mut f) = std::fs::OpenOptions::new().write(true).custom_flags(0o4000).open(&fifo) {
                let _ = f.write_all(b"junk");
            }
        })
    };
    match Fmu::load(&fifo) {
        Err(e @ nigel_cosim::ImportError::NotRegularFile { .. }) => assert!(e.to_string().contains("FIFO"), "{e}"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        read_ssp(&dir.join("model.fmu").with_extension("ssp"), &ImportOptions::default()),
        Err(Error::Import(nigel_cosim::ImportError::Io { .. }))
    ));
    std::fs::rename(&fifo, dir.join("system.ssd")).unwrap();
    assert!(matches!(
        read_ssp(&dir.join("system.ssd"), &ImportOptions::default()),
        Err(Error::Import(nigel_cosim::ImportError::NotRegularFile { .. }))
    ));
    assert!(matches!(Fmu::load(&dir), Err(nigel_cosim::ImportError::NotRegularFile { .. })));
    drop(rescuer); // detached: it finds no reader and does nothing
}

#[test]
fn xml_size_limit_duplicate_names_and_many_attributes() {
    let dir = work_dir("xml-limits");
    let xml = Model::Gain.model_description();
    let small = UnpackLimits { max_xml_bytes: 500, ..UnpackLimits::default() };
    match load(&build_fmu(Model::Gain, &dir, &[]), small) {
        Err(e @ Error::Import(nigel_cosim::ImportError::ArchiveLimit { limit_name: "max_xml_bytes", .. })) => {
            assert!(e.to_string().contains("modelDescription.xml"), "{e}")
        }
        other => panic!("{other:?}"),
    }
    // two variables called u
    let twice = xml.replace(r#"name="k""#, r#"name="u""#);
    match Fmu::load(&build_fmu_with(Model::Gain, &dir, "twice", &twice)) {
        Err(nigel_cosim::ImportError::ModelDescription { reason, .. }) => {
            assert_eq!(reason, "variables 1 and 3 are both called \"u\" (variable names must be unique)")
        }
        other => panic!("{other:?}"),
    }
    // 160,000 attributes on the root element: read (unknown attributes are skipped) ...
    let many: String = (0..160_000).map(|k| format!(" a{k}=\"{k}\"")).collect();
    let wide = xml.replacen("<fmiModelDescription ", &format!("<fmiModelDescription{many} "), 1);
    assert_eq!(Fmu::load(&build_fmu_with(Model::Gain, &dir, "wide", &wide)).unwrap().description().model_name, "gain");
    // ... and a repeated one among them is still found and named
    let repeated = xml.replacen("<fmiModelDescription ", &format!("<fmiModelDescription{many} a7=\"x\" "), 1);
    match Fmu::load(&build_fmu_with(Model::Gain, &dir, "repeated", &repeated)) {
        Err(nigel_cosim::ImportError::ModelDescription { reason, .. }) => {
            assert!(reason.contains("attribute a7 repeated in <fmiModelDescription>"), "{reason}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn hostile_log_formats_neither_crash_nor_show_the_masters_memory() {
    let dir = work_dir("log-formats");
    let fmu = Fmu::load(&build_hostile(&dir)).unwrap();
    let inst = Instance::new(&fmu, "h").unwrap();
    let log: Vec<String> = inst.take_log().into_iter().map(|r| r.message).collect();
    assert_eq!(log.len(), 5, "{log:?}");
    assert_eq!(log[0], "[log message not formatted: its format contains %n, which writes to memory] %s%n%n%s");
    assert_eq!(log[1], "<string in the importer's memory>");
    assert_eq!(log[2], "<unreadable string>");
    assert_eq!(log[3], "[log message not formatted: its format contains a * width or precision] %*d");
    // what C's printf makes of the same format and arguments
    assert_eq!(log[4], "x = 1.5, n = 42, s = ok,  3.14%, Z-7");
}

const SSD_HEAD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="t">"#;

/// src.y -> s0.in -> s0.out -> s1.in -> ... -> s{n-1}.out -> amp.u through `n` nested
/// systems, each adding 1 with a LinearTransformation; `inner(k)` is system k's own
/// connection (in -> out). `extra` goes into the root system.
fn chain_ssd(n: usize, inner: &dyn Fn(usize) -> String, extra: &str) -> String {
    let mut x = format!(
        "{SSD_HEAD}<ssd:System name=\"root\">{extra}<ssd:Elements>\n<ssd:Component name=\"src\" source=\"source.fmu\"/>\n<ssd:Component name=\"amp\" source=\"gain.fmu\"/>\n"
    );
    for k in 0..n {
        x.push_str(&format!(
            "<ssd:System name=\"s{k}\"><ssd:Connectors><ssd:Connector name=\"in\" kind=\"input\"/><ssd:Connector name=\"out\" kind=\"output\"/></ssd:Connectors><ssd:Connections>{}</ssd:Connections></ssd:System>\n",
            inner(k)
        ));
    }
    x.push_str("</ssd:Elements><ssd:Connections>\n");
    x.push_str("<ssd:Connection startElement=\"src\" startConnector=\"y\" endElement=\"s0\" endConnector=\"in\"/>\n");
    for k in 1..n {
        x.push_str(&format!(
            "<ssd:Connection startElement=\"s{}\" startConnector=\"out\" endElement=\"s{k}\" endConnector=\"in\"/>\n",
            k - 1
        ));
    }
    x.push_str(&format!(
        "<ssd:Connection startElement=\"s{}\" startConnector=\"out\" endElement=\"amp\" endConnector=\"u\"/>\n",
        n - 1
    ));
    x.push_str("</ssd:Connections></ssd:System></ssd:SystemStructureDescription>\n");
    x
}

fn plus_one(_: usize) -> String {
    r#"<ssd:Connection startConnector="in" endConnector="out"><ssc:LinearTransformation offset="1"/></ssd:Connection>"#
        .into()
}

#[test]
fn a_16000_hop_connector_chain_is_followed_and_a_typo_in_it_named() {
    let dir = work_dir("ssp-chain");
    build_fmu(Model::Source, &dir, &[]);
    build_fmu(Model::Gain, &dir, &[]);
    let n = 8000; // 2 n + 1 = 16001 hops from src.y to amp.u
    let path = dir.join("chain.ssd");
    std::fs::write(&path, chain_ssd(n, &plus_one, "")).unwrap();
    let ssp = read_ssp(&path, &ImportOptions::default()).unwrap();
    let c = &ssp.system.connections;
    assert_eq!(c.len(), 1);
    assert_eq!((ssp.system.name_of(&c[0].from).as_str(), ssp.system.name_of(&c[0].to).as_str()), ("src.y", "amp.u"));
    assert_eq!((c[0].gain, c[0].offset), (1.0, n as f64)); // sums of integers: exact
                                                           // one connector misspelt in the middle of the chain: named, with the declared ones
    let typo = |k: usize| if k == n / 2 { plus_one(k).replace("\"out\"", "\"outt\"") } else { plus_one(k) };
    std::fs::write(&path, chain_ssd(n, &typo, "")).unwrap();
    match read_ssp(&path, &ImportOptions::default()) {
        Err(Error::Ssp { reason, .. }) => assert_eq!(
            reason,
            "connection in -> outt of system \"s4000\": system \"s4000\" declares no connector \"outt\"; did you mean \"out\"?"
        ),
        other => panic!("accepted or wrong error: {:?}", other.map(|s| s.system.connections.len())),
    }
    // the same at the root: a connection to an undeclared connector of a nested system
    let root_typo = chain_ssd(3, &plus_one, "").replace(
        r#"startElement="s0" startConnector="out" endElement="s1""#,
        r#"startElement="s0" startConnector="ot" endElement="s1""#,
    );
    std::fs::write(&path, root_typo).unwrap();
    match read_ssp(&path, &ImportOptions::default()) {
        Err(Error::Ssp { reason, .. }) => {
            assert!(reason.contains("system \"s0\" declares no connector \"ot\"; did you mean \"out\""), "{reason}")
        }
        other => panic!("accepted: {:?}", other.is_ok()),
    }
}

#[test]
fn a_parameter_file_whose_root_is_not_a_parameter_set_is_refused() {
    let dir = work_dir("ssv-root");
    build_fmu(Model::Source, &dir, &[]);
    build_fmu(Model::Gain, &dir, &[]);
    std::fs::write(dir.join("values.ssv"), "<html><body>Parameters</body></html>").unwrap();
    let binding = r#"<ssd:ParameterBindings><ssd:ParameterBinding source="values.ssv"/></ssd:ParameterBindings>"#;
    let path = dir.join("ssv.ssd");
    std::fs::write(&path, chain_ssd(1, &plus_one, binding)).unwrap();
    match read_ssp(&path, &ImportOptions::default()) {
        Err(Error::Ssp { reason, .. }) => assert_eq!(
            reason,
            "root system \"root\": parameter file \"values.ssv\" has the root element <html>, not <ParameterSet>"
        ),
        other => panic!("accepted: {:?}", other.is_ok()),
    }
}

#[test]
fn the_algebraic_loop_error_names_only_the_loop() {
    // a.y feeds c (a tail: c -> d depends on the loop but is not on it) and the loop a <-> b
    let dir = work_dir("loop-members");
    let gain = Fmu::load(&build_fmu(Model::Gain, &dir, &[])).unwrap();
    let mut b = nigel_cosim::SystemBuilder::new();
    for name in ["a", "b", "c", "d"] {
        b.add_instance(name, gain.clone()).unwrap();
    }
    b.connect("a.y", "c.u").unwrap();
    b.connect("c.y", "d.u").unwrap();
    b.connect("a.y", "b.u").unwrap();
    b.connect("b.y", "a.u").unwrap();
    let mut e = nigel_cosim::Experiment::new(1.0, 0.5);
    e.algorithm = nigel_cosim::Algorithm::Ordered;
    match nigel_cosim::simulate(&b.build(), &e) {
        Err(Error::AlgebraicLoop { variables }) => {
            let mut members = variables.clone();
            assert_eq!(members.first(), members.last(), "closed: {variables:?}");
            members.pop();
            members.sort();
            assert_eq!(members, ["a.u", "a.y", "b.u", "b.y"], "{variables:?}");
        }
        other => panic!("{:?}", other.map(|_| ())),
    }
}

fn cosim(args: &[&str]) -> (bool, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cosim")).args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn an_exact_variable_name_wins_over_the_instance_prefix() {
    let dir = work_dir("exact-name");
    // the source's slope is called "model.slope": `--set model.slope=3` is that variable
    let xml = Model::Source.model_description().replace(r#"name="slope""#, r#"name="model.slope""#);
    let fmu = build_fmu_with(Model::Source, &dir, "dotted", &xml);
    let csv = dir.join("out.csv");
    let (ok, _, err) = cosim(&[
        "run",
        fmu.to_str().unwrap(),
        "--set",
        "model.slope=3",
        "--stop-time",
        "1",
        "--step",
        "0.5",
        "--output",
        csv.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "\"time\",\"y\"\n0,0\n0.5,1.5\n1,3\n");
}

#[test]
fn messages_say_what_is_wrong_in_plain_words_with_suggestions() {
    let plant = plant_fmu();
    let p = plant.to_str().unwrap();
    let run = |set: &str| {
        let (ok, _, err) = cosim(&["run", p, "--stop-time", "0.01", "--set", set]);
        assert!(!ok, "{set} accepted");
        err.trim().to_string()
    };
    assert_eq!(
        run("v_x_strat=0.35"),
        "cosim: instance \"model\" has no variable \"v_x_strat\"; did you mean \"v_x_start\" or \"v_y_start\" or \"v_x\"? (`cosim info` lists the variables)"
    );
    assert_eq!(
        run("v_x=0.35"),
        "cosim: model.v_x = \"0.35\": a continuous output variable without a start value is calculated by the FMU and cannot be set; its initial value is set by the parameter \"v_x_start\""
    );
    assert_eq!(run("friction_circle=yes"), "cosim: model.friction_circle = \"yes\": not a Boolean (true, false, 1, 0)");
    // written by `cargo run --release -p build-fmu` with the FMUs
    let ssp = plant.parent().unwrap().parent().unwrap().join("ssp/nigel_closed_loop.ssp");
    assert!(ssp.is_file(), "{} missing: run `cargo run --release -p build-fmu` first", ssp.display());
    {
        let s = ssp.to_str().unwrap();
        let run = |set: &str| cosim(&["run", s, "--stop-time", "0.01", "--set", set]).2.trim().to_string();
        assert_eq!(
            run("v_x_start=1"),
            "cosim: \"v_x_start\" names no instance: in a system, variables are named instance.variable; did you mean \"plant.v_x_start\"?"
        );
        assert_eq!(
            run("plnt.v_x_start=1"),
            "cosim: the system has no instance \"plnt\"; did you mean \"plant\"? (its instances: plant, controller, maneuver)"
        );
        let (ok, out, err) = cosim(&["info", s]);
        assert!(ok, "{err}");
        assert!(
            out.contains(&format!("instance plant                resources/nigel_plant.fmu in {s} (CoSimulation)")),
            "{out}"
        );
        assert!(out.contains("  start v_x_start = 0.35 m/s\n"), "{out}");
        assert!(!out.contains("nigel-cosim-") && !out.contains("Real(") && !out.contains("Boolean("), "{out}");
    }
    let (ok, out, err) = cosim(&["info", p]);
    assert!(ok, "{err}");
    assert!(out.contains("default experiment: start 0 s, stop 10 s, step 0.001 s, tolerance 1e-8\n"), "{out}");
    let mu = out.lines().find(|l| l.starts_with("mu_fl ")).unwrap();
    let words: Vec<&str> = mu.split_whitespace().collect();
    assert_eq!(words[..9], ["mu_fl", "input", "continuous", "Real", "-", "0.4", "0", "..", "3"], "{mu}");
    assert!(mu.ends_with("road-tire friction coefficient, 0 .. 3"), "{mu}");
    assert!(!out.contains("Some(") && !out.contains("None"), "{out}");
}

#[test]
fn non_finite_outputs_are_refused_at_their_source() {
    let dir = work_dir("non-finite");
    let hostile = build_hostile(&dir);
    let gain = Fmu::load(&build_fmu(Model::Gain, &dir, &[])).unwrap();
    for (bad, shown) in [("0", "NaN"), ("1", "inf"), ("2", "-inf")] {
        let mut b = nigel_cosim::SystemBuilder::new();
        b.add_instance("h", Fmu::load(&hostile).unwrap()).unwrap();
        b.add_instance("g", gain.clone()).unwrap();
        b.connect("h.y", "g.u").unwrap();
        b.set_text("h.bad", bad).unwrap();
        let system = b.build();
        for algorithm in [nigel_cosim::Algorithm::Ordered, nigel_cosim::Algorithm::Jacobi] {
            let mut e = nigel_cosim::Experiment::new(1.0, 0.125);
            e.algorithm = algorithm;
            match nigel_cosim::simulate(&system, &e) {
                Err(err @ Error::Import(nigel_cosim::ImportError::NonFinite { .. })) => {
                    let Error::Import(nigel_cosim::ImportError::NonFinite { instance, variable, value, time, .. }) =
                        &err
                    else {
                        unreachable!()
                    };
                    // y turns bad at t_bad = 0.5 s, a communication point (4 steps of 1/8 s: exact)
                    assert_eq!((instance.as_str(), variable.as_str(), *time), ("h", "y", 0.5), "{algorithm:?}");
                    assert_eq!(value.to_string(), shown);
                    let text = err.to_string();
                    assert!(text.starts_with(&format!("h (hostile.fmu): y = {shown} at t = 0.5 s")), "{text}");
                }
                other => panic!("{algorithm:?} {bad}: {:?}", other.map(|(r, _)| r.column("g.y"))),
            }
        }
    }
    // allowed: passed on and recorded
    let options = ImportOptions { allow_non_finite: true, ..ImportOptions::default() };
    let mut b = nigel_cosim::SystemBuilder::new();
    b.add_instance("h", Fmu::load_with(&hostile, &options).unwrap()).unwrap();
    let (r, _) = nigel_cosim::simulate(&b.build(), &nigel_cosim::Experiment::new(1.0, 0.125)).unwrap();
    let y = r.column("y").unwrap();
    assert_eq!(y[..4], [0.0, 0.125, 0.25, 0.375]);
    assert!(y[4..].iter().all(|v| v.is_nan()), "{y:?}");
}

#[test]
fn the_cli_refuses_runs_it_cannot_mean_and_warns_of_long_steps() {
    let plant = plant_fmu();
    let p = plant.to_str().unwrap();
    let dir = work_dir("cli-checks");
    for (args, needle) in [
        (vec!["--stop-time", "0"], "the stop time 0 s must be after the start time 0 s"),
        (vec!["--step", "2", "--stop-time", "1"], "the step 2 s is longer than the run (1 s from 0 to 1 s)"),
        (vec!["--output", "out.txt"], "--output out.txt: the file name must end in .csv"),
    ] {
        let mut all = vec!["run", p];
        all.extend(args.iter().copied());
        let (ok, _, err) = cosim(&all);
        assert!(!ok && err.contains(needle), "{args:?}: {err}");
    }
    let (ok, _, err) = cosim(&["run", p, "--stop-time", "0.01"]);
    assert!(ok && err.contains("note: no --output or --summary given"), "{err}");
    let ssp = plant.parent().unwrap().parent().unwrap().join("ssp/nigel_closed_loop.ssp");
    let s = ssp.to_str().unwrap();
    let summary = dir.join("s.json");
    let (ok, _, err) =
        cosim(&["run", s, "--step", "0.1", "--stop-time", "0.2", "--summary", summary.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        err.contains("warning: controller (nigel_controller.fmu) runs every 0.001 s (its DefaultExperiment stepSize), but the communication step is 0.1 s"),
        "{err}"
    );
    let (_, _, err) = cosim(&["run", s, "--stop-time", "0.2", "--summary", summary.to_str().unwrap()]);
    assert!(!err.contains("warning"), "{err}");
    // --interface applies to the FMUs of a system: Model Exchange is integrated by the master
    let (ok, _, err) =
        cosim(&["run", s, "--interface", "me", "--stop-time", "0.01", "--summary", summary.to_str().unwrap()]);
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    // RK4 at the communication step: one accepted integrator step per FMU and step
    let steps = json["integrator_steps"]["accepted"].as_u64().unwrap_or(0);
    assert!(steps >= 10, "{json}");
}

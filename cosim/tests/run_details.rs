//! `cosim run` details: an SSP's missing or unreadable FMU named by its component and the
//! .ssp; negative times; the step warning only for FMUs that sample; an FMU that calls
//! exit(0) inside fmi2DoStep in process; and a run unpacks of an FMU only what it uses
//! (modelDescription.xml, binaries/linux64/, resources/), straight from the .ssp.

mod common;
use common::{build_crash, build_fmu, plant_fmu, time_and_y, work_dir, zip_entries, Model};
use nigel_cosim::{read_ssp, Error, Fmu, ImportOptions, SystemBuilder};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

fn cosim(args: &[&str], tmp: Option<&Path>) -> (Option<i32>, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cosim"));
    c.args(args);
    if let Some(t) = tmp {
        c.env("TMPDIR", t);
    }
    let out = c.output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Every file under `dir`, relative, sorted.
fn files_under(dir: &Path) -> Vec<String> {
    fn walk(base: &Path, d: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.push(p.strip_prefix(base).unwrap().to_string_lossy().into_owned());
            }
        }
    }
    let mut v = Vec::new();
    walk(dir, dir, &mut v);
    v.sort();
    v
}

/// The entries of a zip archive: (name, bytes, stored uncompressed).
fn entries_of(path: &Path) -> Vec<(String, Vec<u8>, bool)> {
    let mut zip = zip::ZipArchive::new(std::fs::File::open(path).unwrap()).unwrap();
    (0..zip.len())
        .map(|i| {
            let mut e = zip.by_index(i).unwrap();
            let mut b = Vec::new();
            e.read_to_end(&mut b).unwrap();
            (e.name().to_string(), b, e.compression() == zip::CompressionMethod::Stored)
        })
        .collect()
}

/// The gain FMU with the parts a run does not use: other platforms, documentation, sources.
fn gain_of_four_platforms(dir: &Path) -> PathBuf {
    build_fmu(Model::Gain, dir, &[]);
    let fmu = dir.join("gain4.fmu");
    zip_entries(
        &fmu,
        &[
            ("modelDescription.xml", Model::Gain.model_description().into_bytes()),
            ("binaries/linux64/gain.so", std::fs::read(dir.join("gain.so")).unwrap()),
            ("binaries/win64/gain.dll", vec![b'M'; 4096]),
            ("binaries/aarch64-linux/gain.so", vec![0x7f; 4096]),
            ("binaries/darwin64/gain.dylib", vec![0xcf; 4096]),
            ("documentation/index.html", b"<html></html>".to_vec()),
            ("sources/gain.c", b"/* */".to_vec()),
            ("resources/table.txt", b"1 2 3\n".to_vec()),
        ],
    );
    fmu
}

fn ssp_of(fmu: &Path, path: &Path) {
    let mut b = SystemBuilder::new();
    b.add_instance("amp", Fmu::load(fmu).unwrap()).unwrap();
    nigel_cosim::write_ssp(&b.build(), "t", Some(1.0), path).unwrap();
}

#[test]
fn a_run_unpacks_only_what_it_uses_straight_from_the_ssp() {
    let dir = work_dir("lazy-unpack");
    let fmu = gain_of_four_platforms(&dir);
    let used = ["binaries/linux64/gain.so", "modelDescription.xml", "resources/table.txt"];
    let loaded = Fmu::load(&fmu).unwrap();
    assert_eq!(files_under(loaded.unpacked_dir()), used);
    // the SSP stores its FMUs (read in place); a run of it unpacks the same three files
    // and writes no .fmu anywhere
    let ssp = dir.join("t.ssp");
    ssp_of(&fmu, &ssp);
    let entries = entries_of(&ssp);
    let (_, inner, stored) = entries.iter().find(|(n, ..)| n == "resources/gain4.fmu").unwrap();
    assert!(*stored, "the FMU is stored in the SSP");
    assert_eq!(inner, &std::fs::read(&fmu).unwrap());
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    std::env::set_var("TMPDIR", &tmp);
    let system = read_ssp(&ssp, &ImportOptions::default()).unwrap();
    let f = &system.system.instances[0].fmu;
    assert_eq!(files_under(f.unpacked_dir()), used);
    assert_eq!(f.source(), ssp.join("resources/gain4.fmu"));
    assert_eq!(system.path_in_archive(f.source()), Some(Path::new("resources/gain4.fmu")));
    assert!(files_under(&tmp).iter().all(|p| !p.ends_with(".fmu")), "{:?}", files_under(&tmp));
    // writing the system again copies the FMU's bytes out of the SSP
    let again = dir.join("again.ssp");
    nigel_cosim::write_ssp(&system.system, "t", Some(1.0), &again).unwrap();
    assert_eq!(entries_of(&again).iter().find(|(n, ..)| n == "resources/gain4.fmu").unwrap().1, *inner);
    drop(system);
    // an SSP of another tool that deflates its FMUs: inflated in memory, same result
    let deflated = dir.join("deflated.ssp");
    let owned: Vec<(&str, Vec<u8>)> = entries.iter().map(|(n, b, _)| (n.as_str(), b.clone())).collect();
    zip_entries(&deflated, &owned);
    assert!(!entries_of(&deflated).iter().any(|(_, _, s)| *s));
    let system = read_ssp(&deflated, &ImportOptions::default()).unwrap();
    assert_eq!(files_under(system.system.instances[0].fmu.unpacked_dir()), used);
    let (results, _) = nigel_cosim::simulate(&system.system, &nigel_cosim::Experiment::new(1.0, 0.5)).unwrap();
    assert_eq!(results.rows(), 3);
    drop(system);
    // a hostile FMU inside an SSP is refused as it is on its own: an entry that escapes
    // the folder in a part a run does not unpack (documentation/)
    let slip = dir.join("slip.fmu");
    zip_entries(
        &slip,
        &[
            ("modelDescription.xml", Model::Gain.model_description().into_bytes()),
            ("binaries/linux64/gain.so", std::fs::read(dir.join("gain.so")).unwrap()),
            ("documentation/../../escaped.txt", b"x".to_vec()),
        ],
    );
    let mut nested = owned.clone();
    nested.retain(|(n, _)| *n != "resources/gain4.fmu");
    nested.push(("resources/gain4.fmu", std::fs::read(&slip).unwrap()));
    let hostile = dir.join("hostile.ssp");
    zip_entries(&hostile, &nested);
    match read_ssp(&hostile, &ImportOptions::default()) {
        Err(Error::Import(nigel_cosim::ImportError::UnsafeEntry { entry, .. })) => {
            assert_eq!(entry, "documentation/../../escaped.txt")
        }
        other => panic!("accepted or wrong error: {:?}", other.map(|_| ())),
    }
    assert!(!dir.join("escaped.txt").exists());
    // the refused FMU's folder is removed (this binary's other tests unpack nothing in
    // process; the C compiler they run leaves its own temporary files here for a moment)
    let ours: Vec<String> = files_under(&tmp).into_iter().filter(|p| p.starts_with("nigel-cosim-")).collect();
    assert!(ours.is_empty(), "left {ours:?}");
}

#[test]
fn a_missing_or_unreadable_fmu_is_named_by_its_component_and_the_ssp() {
    let dir = work_dir("missing-fmu");
    // written by hand: this test loads nothing in process (the one above watches TMPDIR)
    let ssd_text = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" version="1.0" name="t">
  <ssd:System name="t"><ssd:Elements>
    <ssd:Component name="amp" type="application/x-fmu-sharedlibrary" source="resources/gain.fmu"/>
  </ssd:Elements></ssd:System>
</ssd:SystemStructureDescription>
"#;
    let ssd: Vec<(&str, Vec<u8>)> = vec![("SystemStructure.ssd", ssd_text.as_bytes().to_vec())];
    let missing = dir.join("missing.ssp");
    zip_entries(&missing, &ssd);
    let mut junk = ssd.clone();
    junk.push(("resources/gain.fmu", b"not a zip archive".to_vec()));
    let unreadable = dir.join("unreadable.ssp");
    zip_entries(&unreadable, &junk);
    for (ssp, what) in [(&missing, "is not in the archive"), (&unreadable, "not a readable zip archive")] {
        let csv = dir.join("out.csv");
        let (code, _, err) = cosim(&["run", ssp.to_str().unwrap(), "--output", csv.to_str().unwrap()], None);
        assert_eq!(code, Some(1), "{err}");
        assert!(err.contains(&ssp.display().to_string()), "{err}");
        assert!(err.contains("component \"amp\""), "{err}");
        assert!(err.contains("resources/gain.fmu") && err.contains(what), "{err}");
        assert!(!err.contains("nigel-cosim-"), "names a temporary path: {err}");
    }
}

#[test]
fn negative_times_are_accepted() {
    let dir = work_dir("negative-times");
    let fmu = build_crash(&dir);
    let csv = dir.join("out.csv");
    let (code, _, err) = cosim(
        &[
            "run",
            fmu.to_str().unwrap(),
            "--start-time",
            "-1",
            "--stop-time",
            "-0.5",
            "--step",
            "0.25",
            "--output",
            csv.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(code, Some(0), "{err}");
    // y is the time the FMU reached: its fmi2SetupExperiment start, then t + h (exact in binary)
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "\"time\",\"y\"\n-1,-1\n-0.75,-0.75\n-0.5,-0.5\n");
}

#[test]
fn the_step_warning_is_only_for_fmus_that_sample() {
    let plant = plant_fmu();
    let fmu_dir = plant.parent().unwrap();
    let csv = work_dir("step-warning").join("out.csv");
    let run = |fmu: &Path, extra: &[&str]| {
        let mut args = vec!["run", fmu.to_str().unwrap(), "--stop-time", "0.004", "--step", "2e-3"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--output", csv.to_str().unwrap()]);
        let (code, _, err) = cosim(&args, None);
        assert_eq!(code, Some(0), "{err}");
        err
    };
    // the continuous plant (DefaultExperiment stepSize 1e-3), in ME and CS: no warning
    for interface in ["me", "cs"] {
        let err = run(&plant, &["--interface", interface]);
        assert!(!err.contains("warning"), "{interface}: {err}");
    }
    // the maneuver samples (discrete outputs) every 1e-3 s, its DefaultExperiment stepSize
    let err = run(&fmu_dir.join("nigel_maneuver.fmu"), &[]);
    assert!(
        err.contains("runs every 0.001 s (its DefaultExperiment stepSize), but the communication step is 0.002 s"),
        "{err}"
    );
    // the controller: discrete outputs, DefaultExperiment stepSize 1e-3 s (not its parameter sample_period)
    let err = run(&fmu_dir.join("nigel_controller.fmu"), &[]);
    assert!(err.contains("runs every 0.001 s (its DefaultExperiment stepSize)"), "{err}");
    // a Model Exchange FMU with a discrete local (stepSize 0.01 s) is continuous: no
    // warning at a step of 0.1 s; the same FMU with that variable an output samples it
    for (causality, warns) in [("local", false), ("output", true)] {
        let dir = work_dir(&format!("step-warning-{causality}"));
        let fmu = common::build_ramp(&dir, &common::ramp_xml(causality));
        let csv = dir.join("out.csv");
        let (code, _, err) =
            cosim(&["run", fmu.to_str().unwrap(), "--step", "0.1", "--output", csv.to_str().unwrap()], None);
        assert_eq!(code, Some(0), "{err}");
        let expected = "runs every 0.01 s (its DefaultExperiment stepSize), but the communication step is 0.1 s";
        assert_eq!(err.contains(expected), warns, "{causality}: {err}");
        assert_eq!(err.contains("warning"), warns, "{causality}: {err}");
    }
}

#[test]
fn an_fmu_that_calls_exit_inside_a_step_fails_the_run_with_the_rows_so_far() {
    let dir = work_dir("exit-in-process");
    let fmu = build_crash(&dir);
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    let csv = dir.join("out.csv");
    // mode 4: exit(0) in fmi2DoStep from t = 0.5 s, steps of 0.1 s (its DefaultExperiment)
    let (code, _, err) =
        cosim(&["run", fmu.to_str().unwrap(), "--set", "mode=4", "--output", csv.to_str().unwrap()], Some(&tmp));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("cosim: model (crash.fmu) called exit() inside fmi2DoStep at t = 0.5 s"), "{err}");
    assert!(err.contains(&format!("6 rows up to the last completed step written to {}", csv.display())), "{err}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows = time_and_y(&text);
    assert_eq!(rows.len(), 6, "{text}");
    for (n, (t, y)) in rows.iter().enumerate() {
        assert_eq!(*t, n as f64 * 0.1, "row {n}");
        // y is the FMU's own t + h, the same sum as the master's t0 + n h to one ulp
        assert!((y - t).abs() <= 1e-15, "row {n}: y {y} at t {t}");
    }
    assert!(files_under(&tmp).is_empty(), "left {:?}", files_under(&tmp));
    // a run that ends normally still ends with status 0 (the handler does nothing then)
    let (code, _, err) = cosim(&["run", fmu.to_str().unwrap(), "--output", csv.to_str().unwrap()], Some(&tmp));
    assert_eq!(code, Some(0), "{err}");
}

//! Our FMUs in FMI 3.0 through the master's FMI 3.0 import:
//! - each FMU's FMI 3.0 description (`model_description3` of its declaration) passes the
//!   FMI 3.0 validation and reads back from its XML as it was written;
//! - the closed loop with the plant in FMI 3.0 (the built plant library, which exports both
//!   generations, in an FMI 3.0 archive) and the controller and test bench in FMI 2.0, and
//!   the closed loop of the three in FMI 3.0, give the FMI 2.0 closed loop's results bit for
//!   bit, under jacobi and ordered.
//!
//! Their speed against the FMI 2.0 closed loop is a benchmark, `cosim/benches/fmi3.py`.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use fmi_export::Model;
use model_description::fmi3;
use nigel_cosim::{read_ssp, simulate, Algorithm, Experiment};
use nigel_integration_tests::target_dir;

fn descriptions() -> Vec<(&'static str, &'static fmi3::ModelDescription, &'static str)> {
    let plant = nigel_plant::Plant::declaration();
    let controller = nigel_controller::Controller::declaration();
    let maneuver = nigel_maneuver::TestBench::declaration();
    vec![
        ("nigel_plant", plant.model_description3(), plant.xml3()),
        ("nigel_controller", controller.model_description3(), controller.xml3()),
        ("nigel_maneuver", maneuver.model_description3(), maneuver.xml3()),
    ]
}

#[test]
fn our_fmi3_descriptions_validate_and_read_back() {
    for (id, md, xml) in descriptions() {
        assert_eq!(md.validate(), vec![], "{id}");
        let read = fmi3::ModelDescription::from_xml(xml).unwrap_or_else(|e| panic!("{id}: {e}"));
        assert_eq!(&read, md, "{id}: the XML reads back as the description it was written from");
    }
}

fn entries(bytes: &[u8]) -> Vec<(String, Vec<u8>)> {
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
    (0..zip.len())
        .map(|i| {
            let mut e = zip.by_index(i).unwrap();
            let mut data = Vec::new();
            e.read_to_end(&mut data).unwrap();
            (e.name().to_string(), data)
        })
        .filter(|(name, _)| !name.ends_with('/'))
        .collect()
}

fn zipped(entries: &[(String, Vec<u8>)]) -> Vec<u8> {
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    for (name, data) in entries {
        out.start_file(name.as_str(), options).unwrap();
        out.write_all(data).unwrap();
    }
    out.finish().unwrap().into_inner()
}

/// The FMI 3.0 archive of one of our FMUs from its FMI 2.0 one: the same library under
/// `binaries/x86_64-linux/`, the same resources, the FMI 3.0 description `xml3`.
fn fmi3_archive(fmi2: &[u8], xml3: &str) -> Vec<u8> {
    let mut out = vec![("modelDescription.xml".to_string(), xml3.as_bytes().to_vec())];
    for (name, data) in entries(fmi2) {
        if let Some(rest) = name.strip_prefix("binaries/linux64/") {
            out.push((format!("binaries/x86_64-linux/{rest}"), data));
        } else if name.starts_with("resources/") {
            out.push((name, data));
        }
    }
    assert!(out.iter().any(|(n, _)| n.starts_with("binaries/x86_64-linux/")), "the archive has a linux64 library");
    zipped(&out)
}

/// The closed loop's `.ssp` with the FMUs `which` (model identifiers) in FMI 3.0.
fn ssp_with_fmi3(fmi2_ssp: &Path, dir: &Path, which: &[&str], file: &str) -> PathBuf {
    let bytes = std::fs::read(fmi2_ssp).unwrap();
    let xml3 = descriptions();
    let replaced: Vec<(String, Vec<u8>)> = entries(&bytes)
        .into_iter()
        .map(|(name, data)| {
            let fmi3 = xml3.iter().find(|(id, _, _)| which.contains(id) && name.ends_with(&format!("{id}.fmu")));
            match fmi3 {
                Some((_, _, xml)) => (name, fmi3_archive(&data, xml)),
                None => (name, data),
            }
        })
        .collect();
    let path = dir.join(file);
    std::fs::write(&path, zipped(&replaced)).unwrap();
    path
}

/// The FMI 2.0 closed loop, the one with the plant in FMI 3.0, the one of three FMI 3.0 FMUs
/// (their `.ssp` files written once per test process, into a folder of its own).
fn closed_loops() -> (nigel_cosim::System, nigel_cosim::System, nigel_cosim::System) {
    static SSPS: std::sync::OnceLock<[PathBuf; 3]> = std::sync::OnceLock::new();
    let [fmi2_ssp, mixed, fmi3] = SSPS.get_or_init(|| {
        let fmi2_ssp = target_dir().join("ssp").join("nigel_closed_loop.ssp");
        assert!(fmi2_ssp.is_file(), "{} missing: run `cargo run --release -p build-fmu`", fmi2_ssp.display());
        let dir = target_dir().join(format!("fmi3-closed-loop-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let all = ["nigel_plant", "nigel_controller", "nigel_maneuver"];
        let mixed = ssp_with_fmi3(&fmi2_ssp, &dir, &all[..1], "nigel_closed_loop_mixed.ssp");
        let fmi3 = ssp_with_fmi3(&fmi2_ssp, &dir, &all, "nigel_closed_loop_fmi3.ssp");
        [fmi2_ssp, mixed, fmi3]
    });
    let read = |p: &PathBuf| read_ssp(p, &Default::default()).unwrap().system;
    (read(fmi2_ssp), read(mixed), read(fmi3))
}

#[test]
fn the_closed_loops_with_fmi3_fmus_are_the_fmi2_one_bit_for_bit() {
    let (fmi2, mixed, fmi3) = closed_loops();
    let generations = |s: &nigel_cosim::System| -> Vec<bool> {
        s.instances.iter().map(|i| i.fmu.fmi3_description().is_some()).collect()
    };
    let plant = mixed.instance_index("plant").expect("an instance called plant");
    let mut expected = vec![false; 3];
    expected[plant] = true;
    assert_eq!(generations(&mixed), expected, "only the plant in FMI 3.0");
    assert_eq!(generations(&fmi3), vec![true; 3]);
    // the whole 30 s of the benchmark: the test bench asks to end the simulation at its
    // duration, the stop time, which is no early end (every instance takes the last step)
    for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
        let mut e = Experiment::new(30.0, 1e-3);
        e.algorithm = algorithm;
        let (a, summary) = simulate(&fmi2, &e).unwrap();
        assert_eq!(a.rows(), 30001);
        assert_eq!(summary.ended_by, None, "{algorithm:?}");
        for (name, system) in [("mixed", &mixed), ("FMI 3.0", &fmi3)] {
            let (b, summary) = simulate(system, &e).unwrap();
            assert_eq!(summary.ended_by, None, "{algorithm:?} {name}: the end at the stop time is no early end");
            assert_eq!(a.rows(), b.rows(), "{algorithm:?} {name}");
            assert_eq!(a.names, b.names, "{algorithm:?} {name}");
            let differing = a.values.iter().zip(&b.values).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
            assert_eq!(differing, 0, "{algorithm:?}: values of the {name} closed loop differ from the FMI 2.0 one's");
        }
    }
}

/// The shipped closed loop of the FMI 3.0 archives (target/ssp, built by build-fmu), whose
/// controller declares its sample clock (`sample_clock`, a fixed periodic input clock of
/// 1 ms governing the held outputs), gives the FMI 2.0 closed loop's results bit for bit, under jacobi and ordered:
/// the master opens the clock event of each tick at the end of the step that reaches it
/// and exchanges the values of that communication point in it, so the controller samples
/// with the inputs it holds there and the exchange reads that sample, as the FMI 2.0
/// controller samples lazily at the first read (docs/clocks.md). Every communication point
/// of the 30 s is a tick, the one at the stop time included: 30001 ticks.
#[test]
fn the_clocked_fmi3_closed_loop_is_the_fmi2_one_bit_for_bit() {
    let clocked_ssp = target_dir().join("ssp").join("nigel_closed_loop_fmi3.ssp");
    assert!(clocked_ssp.is_file(), "{} missing: run `cargo run --release -p build-fmu`", clocked_ssp.display());
    let clocked = read_ssp(&clocked_ssp, &Default::default()).unwrap().system;
    let controller = clocked.instance_index("controller").expect("an instance called controller");
    let md = clocked.instances[controller].fmu.fmi3_description().expect("the controller in FMI 3.0");
    let clocks: Vec<&str> =
        md.model_variables.iter().filter(|v| v.value_type == fmi3::ValueType::Clock).map(|v| v.name.as_str()).collect();
    assert_eq!(clocks, ["sample_clock"], "the controller declares its sample clock");
    let fmi2 = closed_loops().0;
    for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
        let mut e = Experiment::new(30.0, 1e-3);
        e.algorithm = algorithm;
        let (a, _) = simulate(&fmi2, &e).unwrap();
        let (b, summary) = simulate(&clocked, &e).unwrap();
        assert_eq!(summary.ended_by, None, "{algorithm:?}");
        assert_eq!(summary.clock_ticks, vec![("controller.sample_clock".to_string(), 30001)], "{algorithm:?}");
        assert_eq!((a.rows(), &a.names), (b.rows(), &b.names), "{algorithm:?}");
        // (variable, row) of the first value that differs in its bits, if one does
        let width = a.width();
        let first = a.values.iter().zip(&b.values).position(|(x, y)| x.to_bits() != y.to_bits());
        let name = |i: usize| if i % width == 0 { "time".to_string() } else { a.names[i % width - 1].clone() };
        assert_eq!(first.map(|i| (name(i), i / width)), None, "{algorithm:?}: the clocked loop differs");
        // the controller did something: its drive force moved
        let force = 1 + a.names.iter().position(|n| n == "controller.drive_force").expect("drive_force recorded");
        assert!((0..b.rows()).any(|r| b.values[r * width + force].abs() > 1e-3), "{algorithm:?}");
    }
}

//! Our FMUs in FMI 3.0 through the master's FMI 3.0 import:
//! - each FMU's FMI 3.0 description (`model_description3` of its declaration) passes the
//!   FMI 3.0 validation and reads back from its XML as it was written;
//! - the closed loop with the plant in FMI 3.0 (the built plant library, which exports both
//!   generations, in an FMI 3.0 archive) and the controller and test bench in FMI 2.0 gives
//!   the FMI 2.0 closed loop's results bit for bit, under jacobi and ordered.

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

/// The FMI 3.0 archive of the plant from its FMI 2.0 one: the same library under
/// `binaries/x86_64-linux/`, the same resources, the FMI 3.0 description.
fn fmi3_plant(fmi2: &[u8]) -> Vec<u8> {
    let xml3 = nigel_plant::Plant::declaration().xml3();
    let mut out = vec![("modelDescription.xml".to_string(), xml3.as_bytes().to_vec())];
    for (name, data) in entries(fmi2) {
        if let Some(rest) = name.strip_prefix("binaries/linux64/") {
            out.push((format!("binaries/x86_64-linux/{rest}"), data));
        } else if name.starts_with("resources/") {
            out.push((name, data));
        }
    }
    out.iter()
        .any(|(n, _)| n == "binaries/x86_64-linux/nigel_plant.so")
        .then(|| zipped(&out))
        .expect("the plant archive has a linux64 library")
}

/// The closed loop's `.ssp` with the plant in FMI 3.0.
fn mixed_ssp(fmi2_ssp: &Path, dir: &Path) -> PathBuf {
    let bytes = std::fs::read(fmi2_ssp).unwrap();
    let replaced: Vec<(String, Vec<u8>)> = entries(&bytes)
        .into_iter()
        .map(|(name, data)| if name.ends_with("nigel_plant.fmu") { (name, fmi3_plant(&data)) } else { (name, data) })
        .collect();
    let path = dir.join("nigel_closed_loop_mixed.ssp");
    std::fs::write(&path, zipped(&replaced)).unwrap();
    path
}

#[test]
fn the_closed_loop_with_the_fmi3_plant_is_the_fmi2_one_bit_for_bit() {
    let fmi2_ssp = target_dir().join("ssp").join("nigel_closed_loop.ssp");
    assert!(fmi2_ssp.is_file(), "{} missing: run `cargo run --release -p build-fmu`", fmi2_ssp.display());
    let dir = target_dir().join("fmi3-closed-loop");
    std::fs::create_dir_all(&dir).unwrap();
    let fmi2 = read_ssp(&fmi2_ssp, &Default::default()).unwrap().system;
    let mixed = read_ssp(&mixed_ssp(&fmi2_ssp, &dir), &Default::default()).unwrap().system;
    let plant = mixed.instance_index("plant").expect("an instance called plant");
    assert!(mixed.instances[plant].fmu.fmi3_description().is_some(), "the plant runs as FMI 3.0");
    assert_eq!(mixed.instances.iter().filter(|i| i.fmu.fmi3_description().is_none()).count(), 2);
    for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
        let mut e = Experiment::new(2.0, 1e-3);
        e.algorithm = algorithm;
        let (a, _) = simulate(&fmi2, &e).unwrap();
        let (b, _) = simulate(&mixed, &e).unwrap();
        assert_eq!(a.names, b.names, "{algorithm:?}");
        assert_eq!(a.rows(), 2001);
        let differing = a.values.iter().zip(&b.values).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
        assert_eq!(differing, 0, "{algorithm:?}: values of the FMI 3.0 plant's loop differ from the FMI 2.0 one's");
    }
}

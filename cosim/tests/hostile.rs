//! Hostile archives and libraries: each refused with a typed error naming the cause,
//! nothing written outside the private temporary folder, and that folder removed.
//! One test function, so that the temporary folder (TMPDIR) is this test's alone.

mod common;
use common::{build_fmu, compile, work_dir, zip_entries, Model};
use nigel_cosim::{Fmu, ImportError as Error, ImportOptions, UnpackLimits};
use std::io::Write;
use std::path::Path;

fn entries_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

/// A zip whose one entry declares `declared` uncompressed bytes (zip64) but holds 5.
fn lying_zip(path: &Path, declared: u64) {
    let file = std::fs::File::create(path).unwrap();
    let mut zip = zip::ZipWriter::new(file);
    let options =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored).large_file(true);
    zip.start_file("modelDescription.xml", options).unwrap();
    zip.write_all(b"12345").unwrap();
    zip.finish().unwrap();
    let mut bytes = std::fs::read(path).unwrap();
    // patch the uncompressed size wherever it is stored (32-bit fields and zip64 extra fields)
    let mut patched = 0;
    for k in 0..bytes.len().saturating_sub(8) {
        if bytes[k..k + 8] == 5u64.to_le_bytes() && k >= 8 && bytes[k - 8..k] == 5u64.to_le_bytes() {
            bytes[k - 8..k].copy_from_slice(&declared.to_le_bytes()); // uncompressed precedes compressed
            patched += 1;
        }
    }
    assert!(patched >= 1, "no zip64 size field found to patch");
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn hostile_inputs_are_refused_by_name_and_leave_nothing_behind() {
    let dir = work_dir("hostile");
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    std::env::set_var("TMPDIR", &tmp); // the master's temporary folders go here
    let good = build_fmu(Model::Gain, &dir, &[]);
    let xml = Model::Gain.model_description().into_bytes();
    let so = std::fs::read(dir.join("gain.so")).unwrap();

    let case = |name: &str, entries: &[(&str, Vec<u8>)]| {
        let p = dir.join(format!("{name}.fmu"));
        zip_entries(&p, entries);
        p
    };
    let expect = |path: &Path, limits: UnpackLimits, check: &dyn Fn(&Error) -> bool, what: &str| {
        let options = ImportOptions { limits, ..ImportOptions::default() };
        match Fmu::load_with(path, &options) {
            Err(e) => {
                assert!(check(&e), "{what}: unexpected error {e:?}");
                let text = e.to_string();
                assert!(!text.is_empty());
                eprintln!("{what}: {text}");
            }
            Ok(_) => panic!("{what}: loaded"),
        }
        assert!(entries_in(&tmp).is_empty(), "{what}: left {:?} in the temporary folder", entries_in(&tmp));
    };
    let d = UnpackLimits::default();

    // zip slip, absolute paths
    let slip = case("slip", &[("modelDescription.xml", xml.clone()), ("../../escaped.txt", b"x".to_vec())]);
    expect(&slip, d, &|e| matches!(e, Error::UnsafeEntry { entry, .. } if entry == "../../escaped.txt"), "zip slip");
    assert!(!dir.join("escaped.txt").exists() && !tmp.join("escaped.txt").exists());
    // an absolute entry naming a file of this test's own folder (not a shared path such as /tmp,
    // which another run or user may hold)
    let escaped = std::fs::canonicalize(&dir).unwrap().join("abs-escaped.txt");
    let _ = std::fs::remove_file(&escaped);
    let escaped_name = escaped.to_string_lossy().into_owned();
    assert!(escaped.is_absolute(), "{escaped_name}");
    let abs = case("abs", &[(escaped_name.as_str(), b"x".to_vec())]);
    expect(&abs, d, &|e| matches!(e, Error::UnsafeEntry { reason, .. } if reason.contains("absolute")), "absolute");
    assert!(!escaped.exists());

    // a symbolic link entry
    let link = dir.join("link.fmu");
    {
        let mut zip = zip::ZipWriter::new(std::fs::File::create(&link).unwrap());
        let o = zip::write::SimpleFileOptions::default();
        zip.start_file("modelDescription.xml", o).unwrap();
        zip.write_all(&xml).unwrap();
        zip.add_symlink("binaries/linux64/gain.so", "/etc/passwd", o).unwrap();
        zip.finish().unwrap();
    }
    expect(&link, d, &|e| matches!(e, Error::UnsafeEntry { reason: "symbolic link", .. }), "symlink");

    // a 10 GB declared entry, and limits a user can lower or raise
    let bomb = dir.join("bomb.fmu");
    lying_zip(&bomb, 10_000_000_000);
    expect(&bomb, d, &|e| matches!(e, Error::ArchiveLimit { size: 10_000_000_000, .. }), "10 GB entry");
    let few = UnpackLimits { max_entries: 1, ..d };
    expect(&good, few, &|e| matches!(e, Error::ArchiveLimit { size: 2, limit: 1, .. }), "too many entries");
    let small = UnpackLimits { max_entry_bytes: 100, ..d };
    expect(&good, small, &|e| matches!(e, Error::ArchiveLimit { limit: 100, .. }), "entry over a lowered limit");

    // not a zip; no modelDescription.xml; malformed XML
    let junk = dir.join("junk.fmu");
    std::fs::write(&junk, b"this is not a zip archive").unwrap();
    expect(&junk, d, &|e| matches!(e, Error::Archive { .. }), "not a zip");
    let no_md = case("nomd", &[("binaries/linux64/gain.so", so.clone())]);
    expect(
        &no_md,
        d,
        &|e| matches!(e, Error::ModelDescription { reason, .. } if reason.contains("cannot read")),
        "no XML",
    );
    let bad_xml =
        case("badxml", &[("modelDescription.xml", b"<fmiModelDescription fmiVersion=\"2.0\"><Model".to_vec())]);
    expect(&bad_xml, d, &|e| matches!(e, Error::ModelDescription { .. }), "malformed XML");

    // missing binary: the error lists the platforms the FMU has
    let win = case("win", &[("modelDescription.xml", xml.clone()), ("binaries/win64/gain.dll", b"MZ".to_vec())]);
    expect(
        &win,
        d,
        &|e| matches!(e, Error::MissingBinary { expected, platforms } if expected == "binaries/linux64/gain.so" && platforms == &["win64".to_string()]),
        "missing .so",
    );
    // a .so that is not a library; one without fmi2DoStep
    let fake =
        case("fake", &[("modelDescription.xml", xml.clone()), ("binaries/linux64/gain.so", b"not ELF".to_vec())]);
    expect(&fake, d, &|e| matches!(e, Error::LoadLibrary { .. }), "not a library");
    compile(Model::Gain, &dir.join("nostep.so"), &["-DOMIT_DOSTEP"]);
    let nostep = case(
        "nostep",
        &[
            ("modelDescription.xml", xml.clone()),
            ("binaries/linux64/gain.so", std::fs::read(dir.join("nostep.so")).unwrap()),
        ],
    );
    expect(&nostep, d, &|e| matches!(e, Error::MissingSymbol { symbol: "fmi2DoStep", .. }), "missing symbol");
    // wrong GUID: the FMU refuses to instantiate, the master says so
    let guid = case(
        "guid",
        &[
            ("modelDescription.xml", Model::Gain.model_description().replace("{test-gain}", "{other}").into_bytes()),
            ("binaries/linux64/gain.so", so.clone()),
        ],
    );
    {
        let fmu = Fmu::load(&guid).unwrap();
        let unpacked = fmu.unpacked_dir().to_path_buf();
        assert!(unpacked.starts_with(&tmp));
        match nigel_cosim::Instance::new(&fmu, "g") {
            Err(Error::Instantiate { log, .. }) => assert!(log.contains("wrong GUID"), "{log}"),
            other => panic!("expected an instantiate error, got {other:?}"),
        }
        drop(fmu);
        assert!(!unpacked.exists(), "unpacked folder not removed");
    }
    assert!(entries_in(&tmp).is_empty());
    // and a good one still loads from the same place
    let fmu = Fmu::load(&good).unwrap();
    assert_eq!(fmu.description().model_name, "gain");
    drop(fmu);
    assert!(entries_in(&tmp).is_empty());
}

//! FMI 3.0 test FMUs written in C against the standard's headers (from fmpy's package,
//! `fmpy/c-code`, found with `$FMPY_PYTHON`, default `python3`), zipped as FMI 3.0 archives:
//! modelDescription.xml + binaries/x86_64-linux/<id>.so.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The Python with fmpy (`$FMPY_PYTHON`, default `python3`).
pub fn python() -> String {
    std::env::var("FMPY_PYTHON").unwrap_or_else(|_| "python3".to_string())
}

/// The folder of the FMI 3.0 headers in fmpy's package, `None` (skip) without fmpy.
pub fn headers() -> Option<PathBuf> {
    let out = Command::new(python())
        .args(["-c", "import fmpy, os; print(os.path.join(os.path.dirname(fmpy.__file__), 'c-code'))"])
        .output()
        .ok()
        .filter(|o| o.status.success());
    match out {
        Some(o) => Some(PathBuf::from(String::from_utf8_lossy(&o.stdout).trim())),
        None => {
            assert!(std::env::var_os("FMPY_PYTHON").is_none(), "FMPY_PYTHON={} cannot import fmpy", python());
            eprintln!("fmpy not importable with {}: FMI 3.0 tests skipped", python());
            None
        }
    }
}

/// Compiles `tests/cfmu/<id>.c` (warnings are errors) with `fmi3_rest.c` (every other FMI
/// 3.0 function, answering fmi3Error) and packs it with `xml` as `<dir>/<id>.fmu`; `None`
/// (skip) without fmpy's headers.
pub fn build(dir: &Path, id: &str, xml: &str) -> Option<PathBuf> {
    let headers = headers()?;
    let cfmu = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cfmu");
    let src = cfmu.join(format!("{id}.c"));
    let so = dir.join(format!("{id}.so"));
    let status = Command::new("cc")
        .args(["-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-Wall", "-Wno-unused-parameter", "-Werror"])
        .arg("-I")
        .arg(&headers)
        .arg(&src)
        .arg(cfmu.join("fmi3_rest.c"))
        .arg("-o")
        .arg(&so)
        .status()
        .expect("run cc");
    assert!(status.success(), "cc failed for {}", src.display());
    let fmu = dir.join(format!("{id}.fmu"));
    super::zip_entries(
        &fmu,
        &[
            ("modelDescription.xml", xml.as_bytes().to_vec()),
            (&format!("binaries/x86_64-linux/{id}.so"), std::fs::read(&so).unwrap()),
        ],
    );
    Some(fmu)
}

/// The third-party corpus: `$NIGEL_CORPUS`, else `../shared/corpus` beside the project (read
/// only, by the tests that skip without it).
pub fn corpus() -> PathBuf {
    std::env::var_os("NIGEL_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus"))
}

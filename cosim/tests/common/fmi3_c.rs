//! FMI 3.0 test FMUs written in C against the standard's headers (from fmpy's package,
//! `fmpy/c-code`, found with `$FMPY_PYTHON`, default `python3`), zipped as FMI 3.0 archives:
//! modelDescription.xml + binaries/x86_64-linux/<id>.so.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The Python with fmpy (`$FMPY_PYTHON`, default `python3`).
pub fn python() -> String {
    std::env::var("FMPY_PYTHON").unwrap_or_else(|_| "python3".to_string())
}

/// The lines the fmpy script `script` prints (`python -c script args...`, asserted to
/// succeed), each as its whitespace-separated numbers.
pub fn fmpy_lines<S: AsRef<std::ffi::OsStr>>(script: &str, args: &[S]) -> Vec<Vec<f64>> {
    let out = Command::new(python()).args(["-c", script]).args(args).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| l.split_whitespace().map(|w| w.parse().unwrap()).collect())
        .collect()
}

/// The `cc` flags of an FMI 3.0 test FMU: warnings are errors, the standard's headers from
/// the folder `headers`.
pub fn flags(headers: &Path) -> Vec<OsString> {
    ["-Wall", "-Werror", "-Wno-unused-parameter", "-I"]
        .into_iter()
        .map(OsString::from)
        .chain([headers.as_os_str().to_owned()])
        .collect()
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
    build_with(dir, id, xml, &[])
}

/// The same, compiled with the preprocessor `defines` (`-D` each, in both files).
pub fn build_with(dir: &Path, id: &str, xml: &str, defines: &[&str]) -> Option<PathBuf> {
    build_named(dir, id, id, xml, defines)
}

/// [`build_with`], the archive named `<dir>/<stem>.fmu` (several builds of one FMU in `dir`).
pub fn build_named(dir: &Path, id: &str, stem: &str, xml: &str, defines: &[&str]) -> Option<PathBuf> {
    let headers = headers()?;
    // from cosim's manifest folder or a sibling's (the campaign's tests include this module)
    let cfmu = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cosim/tests/cfmu");
    let so = dir.join(format!("{id}.so"));
    let mut flags = flags(&headers);
    flags.extend(defines.iter().map(|d| OsString::from(format!("-D{d}"))));
    super::cc(&flags, &[cfmu.join(format!("{id}.c")), cfmu.join("fmi3_rest.c")], &so);
    let fmu = dir.join(format!("{stem}.fmu"));
    super::pack_library(&fmu, xml, &format!("binaries/x86_64-linux/{id}.so"), &so);
    Some(fmu)
}

/// The third-party corpus: `$NIGEL_CORPUS`, else `../shared/corpus` beside the project (read
/// only, by the tests that skip without it).
pub fn corpus() -> PathBuf {
    std::env::var_os("NIGEL_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus"))
}

//! The archives' libraries on each platform they carry (`target/fmu/*.fmu`, as build-fmu
//! wrote them; `target/ssp/nigel_closed_loop.ssp` gives the closed loop's wiring):
//!
//! - linux64: no symbol version above GLIBC_2.17 (`objdump -T`), 44 fmi2 exports; the C
//!   importer `tests/c/fmi2_closed_loop.c`, built with gcc, runs the closed loop of plant,
//!   controller and test bench 30 s at 1 ms (Jacobi), and its CSV equals nigel_cosim's
//!   Jacobi run of the same SSP bit for bit (two importers, one answer);
//! - win64: the same C importer built with mingw-w64 runs the DLLs under wine; exports and
//!   imported DLLs checked;
//! - aarch64-linux: the same C importer built with aarch64-linux-gnu-gcc runs under
//!   qemu-user; glibc versions checked;
//! - darwin64: structural only (no macOS here): both architectures, the 44 `_fmi2*`
//!   exports, `minos` 11.0, only `/usr/lib/` libraries imported (Mach-O parsed below).
//!
//! The FMI 3.0 archives (`target/fmu/fmi3/*.fmu`) carry the same library files (checked
//! byte for byte) in the FMI 3.0 folders; the C FMI 3.0 importer `tests/c/fmi3_closed_loop.c`
//! (built against fmpy's FMI 3.0 headers) runs the same closed loop through the fmi3
//! functions: on x86_64-linux natively, on x86_64-windows under wine and on aarch64-linux
//! under qemu-user, each compared with the linux64 FMI 2.0 run as the FMI 2.0 runs are, and
//! equal bit for bit to the FMI 2.0 run of the same platform (the same library, the same
//! grid, the same order of calls); x86_64-darwin and aarch64-darwin: the fmi3 exports of
//! the universal library.
//!
//! Each foreign run is compared with the linux64 run column by column (see
//! [`compare_with_linux64`] for what must be bit-identical and why the rest is not).
//!
//! A platform the manifest does not list is reported and skipped, unless
//! `NIGEL_REQUIRE_PLATFORMS` (`all` or a comma list; scripts/test.sh sets `all`) names it:
//! then its absence fails the test.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use nigel_cosim::{read_ssp, simulate, Algorithm, Experiment, ImportOptions, System, Value};

const STOP_TIME: f64 = 30.0;
const STEP: f64 = 1e-3;

fn target_dir() -> PathBuf {
    let dir = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("target"));
    // absolute and without `..`: the paths go to wine as Z:\... and to qemu
    dir.canonicalize().unwrap_or(dir)
}

/// A scratch folder of one test alone (`target/platform-tests/<test>`): the tests of this
/// file run in parallel threads, and a library one test has mapped must not be rewritten
/// by another (that was a SIGBUS, or a half-written CSV read, depending on timing). It is
/// emptied first, so no file of an earlier run is read.
fn work_dir(test: &str) -> PathBuf {
    let d = target_dir().join("platform-tests").join(test);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The manifest's path and its entries of the archives of `fmi_version` ("2.0", "3.0").
fn manifest_entries(fmi_version: &str) -> (PathBuf, Vec<serde_json::Value>) {
    let path = target_dir().join("fmu").join("manifest.json");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (run `cargo run --release -p build-fmu` first)", path.display()));
    let m: serde_json::Value = serde_json::from_str(&text).unwrap();
    let entries = m.as_array().unwrap().iter().filter(|e| e["fmi_version"] == fmi_version).cloned().collect();
    (path, entries)
}

/// The platform folders of one manifest entry, in its order.
fn entry_folders(entry: &serde_json::Value) -> Vec<String> {
    entry["platforms"].as_array().unwrap().iter().map(|p| p["folder"].as_str().unwrap().to_string()).collect()
}

/// The platform folders of the manifest (the same for every FMU: build-fmu packs each
/// platform into every archive).
fn manifest_platforms() -> Vec<String> {
    // the FMI 2.0 archives' entries; the FMI 3.0 ones name the same libraries by other folders
    let (path, entries) = manifest_entries("2.0");
    assert!(!entries.is_empty(), "{}: no FMI 2.0 archive", path.display());
    let first = entry_folders(&entries[0]);
    for e in &entries {
        assert_eq!(entry_folders(e), first, "{}: platforms differ between archives", e["fmu"]);
    }
    first
}

/// The FMI 3.0 archives' platform folders of the manifest, checked to be the FMI 3.0
/// names of the FMI 2.0 archives' platforms (the same in every archive).
fn manifest_platforms3() -> Vec<String> {
    let (path, entries) = manifest_entries("3.0");
    assert_eq!(entries.len(), FMUS.len(), "{}: one FMI 3.0 archive per FMU", path.display());
    let want: Vec<String> = manifest_platforms().iter().flat_map(|f| fmi3_folders(f)).map(|f| f.to_string()).collect();
    for e in &entries {
        assert_eq!(entry_folders(e), want, "{}: FMI 3.0 folders", e["fmu"]);
    }
    want
}

/// The FMI 3.0 folders of an FMI 2.0 platform folder (FMI 3.0 section 2.5.1.1: `<arch>-<os>`).
fn fmi3_folders(folder: &str) -> &'static [&'static str] {
    match folder {
        "linux64" => &["x86_64-linux"],
        "win64" => &["x86_64-windows"],
        "aarch64-linux" => &["aarch64-linux"],
        "darwin64" => &["x86_64-darwin", "aarch64-darwin"],
        other => panic!("unknown platform folder {other}"),
    }
}

/// True when `folder` is in the archives; false (with a note) when it is not and not required.
fn built(folder: &str) -> bool {
    if manifest_platforms().iter().any(|p| p == folder) {
        return true;
    }
    let required = std::env::var("NIGEL_REQUIRE_PLATFORMS").unwrap_or_default();
    if required == "all" || required.split(',').any(|p| p.trim() == folder) {
        panic!(
            "{folder} is required (NIGEL_REQUIRE_PLATFORMS={required}) but target/fmu/manifest.json does not list it"
        );
    }
    eprintln!("{folder} not in the archives: not tested (bash scripts/setup-cross.sh, then build-fmu)");
    false
}

const FMUS: [&str; 3] = ["nigel_plant", "nigel_controller", "nigel_maneuver"];

fn extension(folder: &str) -> &'static str {
    match folder {
        "win64" => "dll",
        "darwin64" => "dylib",
        _ => "so",
    }
}

/// The bytes of the file `name` in the zip archive at `archive`.
fn archive_entry(archive: &Path, name: &str) -> Vec<u8> {
    let mut z = zip::ZipArchive::new(std::fs::File::open(archive).unwrap()).unwrap();
    let mut entry = z.by_name(name).unwrap_or_else(|e| panic!("{}: {name}: {e}", archive.display()));
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(&mut entry, &mut bytes).unwrap();
    bytes
}

/// Unpacks `binaries/<folder>/<id>.<ext>` of every archive into `dir`.
fn libraries(folder: &str, dir: &Path) -> Vec<PathBuf> {
    FMUS.iter()
        .map(|id| {
            let archive = target_dir().join("fmu").join(format!("{id}.fmu"));
            let bytes = archive_entry(&archive, &format!("binaries/{folder}/{id}.{}", extension(folder)));
            let path = dir.join(format!("{id}.{}", extension(folder)));
            std::fs::write(&path, bytes).unwrap();
            path
        })
        .collect()
}

/// The libraries of `folder` unpacked into the work folder `test` (and that folder), `None`
/// when `folder` is not in the archives ([`built`]).
fn built_libraries(folder: &str, test: &str) -> Option<(PathBuf, Vec<PathBuf>)> {
    if !built(folder) {
        return None;
    }
    let dir = work_dir(test);
    let libs = libraries(folder, &dir);
    Some((dir, libs))
}

/// `llvm-lipo` (Debian's llvm-22 names it `llvm-lipo-22`).
fn llvm_lipo() -> PathBuf {
    ["llvm-lipo", "llvm-lipo-22"]
        .iter()
        .find(|name| Command::new(name).arg("-version").output().is_ok_and(|o| o.status.success()))
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/lib/llvm-22/bin/llvm-lipo"))
}

/// What the FMI 3.0 folder `folder3` must carry of the FMI 2.0 archive's library `fmi2`:
/// the same file, except in a Mac folder the slice of its architecture, as `llvm-lipo
/// -thin` extracts it from the universal library.
fn expected_fmi3_library(folder3: &str, fmi2: Vec<u8>, dir: &Path, id: &str) -> Vec<u8> {
    let arch = match folder3 {
        "x86_64-darwin" => "x86_64",
        "aarch64-darwin" => "arm64",
        _ => return fmi2,
    };
    let (universal, thin) = (dir.join(format!("{id}.universal")), dir.join(format!("{id}.{arch}")));
    std::fs::write(&universal, fmi2).unwrap();
    let status = Command::new(llvm_lipo()).arg("-thin").arg(arch).arg(&universal).arg("-output").arg(&thin).status();
    assert!(status.is_ok_and(|s| s.success()), "llvm-lipo -thin {arch} {}", universal.display());
    let bytes = std::fs::read(&thin).unwrap();
    std::fs::remove_file(&universal).unwrap();
    std::fs::remove_file(&thin).unwrap();
    bytes
}

/// Unpacks `binaries/<folder3>/<id>.<ext>` of every FMI 3.0 archive into `dir`, each
/// checked to be the file the FMI 2.0 archive carries in `folder` (for a Mac folder, the
/// slice of its architecture: [`expected_fmi3_library`]).
fn libraries3(folder: &str, folder3: &str, dir: &Path) -> Vec<PathBuf> {
    assert!(fmi3_folders(folder).contains(&folder3));
    assert!(manifest_platforms3().iter().any(|f| f == folder3), "{folder3}: not in the FMI 3.0 archives");
    let read = archive_entry;
    FMUS.iter()
        .map(|id| {
            let ext = extension(folder);
            let bytes = read(
                &target_dir().join("fmu").join("fmi3").join(format!("{id}.fmu")),
                &format!("binaries/{folder3}/{id}.{ext}"),
            );
            let fmi2 =
                read(&target_dir().join("fmu").join(format!("{id}.fmu")), &format!("binaries/{folder}/{id}.{ext}"));
            assert!(
                bytes == expected_fmi3_library(folder3, fmi2, dir, id),
                "{id}: binaries/{folder3} of the FMI 3.0 archive is not (its part of) binaries/{folder} of the FMI 2.0 one"
            );
            let path = dir.join(format!("{id}.{ext}"));
            std::fs::write(&path, bytes).unwrap();
            path
        })
        .collect()
}

/// The folder of fmpy's C headers (`fmpy/c-code`, with fmi3FunctionTypes.h), of the Python
/// the test command set up (`FMPY_PYTHON`, else `target/venv`).
fn fmi3_headers() -> PathBuf {
    let python = std::env::var_os("FMPY_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| target_dir().join("venv").join("bin").join("python"));
    let out = Command::new(&python)
        .args(["-c", "import fmpy, os; print(os.path.join(os.path.dirname(fmpy.__file__), 'c-code'))"])
        .output()
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (bash scripts/python-env.sh sets up fmpy, whose headers the FMI 3.0 importer needs)",
                python.display()
            )
        });
    assert!(out.status.success(), "{}: no fmpy: {}", python.display(), String::from_utf8_lossy(&out.stderr));
    let dir = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    assert!(dir.join("fmi3FunctionTypes.h").is_file(), "{}: no fmi3FunctionTypes.h", dir.display());
    dir
}

fn run(c: &mut Command) -> String {
    let out = c.output().unwrap_or_else(|e| panic!("{c:?}: {e}"));
    assert!(out.status.success(), "{c:?}: {}\n{}", out.status, String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn closed_loop_system() -> (System, nigel_cosim::SspSystem) {
    let ssp = target_dir().join("ssp").join("nigel_closed_loop.ssp");
    let imported = read_ssp(&ssp, &ImportOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", ssp.display()));
    (imported.system.clone(), imported)
}

/// The job file of `tests/c/fmi2_closed_loop.c`, or with `fmi3` of `fmi3_closed_loop.c`,
/// for `system`, with `library(i)` the path of instance i's library as the importer must
/// open it. It records every Real output of every instance as `instance.name`. FMI 3.0 has
/// its own value references (declaration row r, the index into the FMI 2.0 variables, has
/// value reference r + 1), the instantiationToken (the FMI 2.0 GUID), and each Integer start
/// value set as Int32 or, for an enumeration, as Int64.
fn job_file(system: &System, library: &dyn Fn(usize) -> String, fmi3: bool) -> String {
    let vr_of = |var: &model_description::ScalarVariable, index: usize| {
        if fmi3 {
            index as u32 + 1
        } else {
            var.value_reference
        }
    };
    let mut job = format!("experiment {STOP_TIME:?} {STEP:?}\n");
    for (i, inst) in system.instances.iter().enumerate() {
        job += &format!("fmu {} {} {}\n", inst.name, inst.fmu.description().guid, library(i));
    }
    for inst in &system.instances {
        let vars = &inst.fmu.description().model_variables;
        for (index, value) in &inst.start_values {
            let vr = vr_of(&vars[*index], *index);
            let enumeration = matches!(vars[*index].variable_type, model_description::VariableType::Enumeration { .. });
            job += &match value {
                Value::Real(x) => format!("real {} {vr} {x:?}\n", inst.name),
                Value::Integer(n) if enumeration && fmi3 => format!("enumeration {} {vr} {n}\n", inst.name),
                Value::Integer(n) => format!("integer {} {vr} {n}\n", inst.name),
                Value::Boolean(b) => format!("boolean {} {vr} {}\n", inst.name, u8::from(*b)),
                Value::String(s) => panic!("{}: String start value {s:?}: the C importer sets none", inst.name),
            };
        }
    }
    for c in &system.connections {
        let (from, to) = (&system.instances[c.from.instance], &system.instances[c.to.instance]);
        let from_vr = vr_of(&from.fmu.description().model_variables[c.from.index], c.from.index);
        let to_vr = vr_of(&to.fmu.description().model_variables[c.to.index], c.to.index);
        job += &format!("connect {} {from_vr} {} {to_vr} {:?} {:?}\n", from.name, to.name, c.gain, c.offset);
    }
    for inst in &system.instances {
        for (index, var) in inst.fmu.description().model_variables.iter().enumerate() {
            let real = matches!(var.variable_type, model_description::VariableType::Real { .. });
            if real && var.causality == model_description::Causality::Output {
                job += &format!("record {} {} {}.{}\n", inst.name, vr_of(var, index), inst.name, var.name);
            }
        }
    }
    job
}

/// A CSV as the C importer writes it: header, then rows.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(|s| s.trim_matches('"').to_string()).collect();
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect()).collect();
    (header, rows)
}

const IMPORTER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/c/fmi2_closed_loop.c");
const IMPORTER3: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/c/fmi3_closed_loop.c");

/// Which C API the closed loop goes through.
#[derive(Clone, Copy, PartialEq)]
enum Abi {
    /// `fmi2_closed_loop.c` on the FMI 2.0 archives' libraries of the folder.
    Fmi2,
    /// `fmi3_closed_loop.c` on the FMI 3.0 archives' libraries of this FMI 3.0 folder.
    Fmi3(&'static str),
    /// `fmi2_closed_loop.c` (FMI 2.0) or `fmi3_closed_loop.c` (FMI 3.0) on the cargo-built
    /// `lib<id>.so` in [`instrumented_libraries`].
    Instrumented { fmi3: bool },
}

/// The folder of AddressSanitizer-instrumented `lib<id>.so` that scripts/test.sh builds
/// into target/asan and names in `NIGEL_FMU_LIBRARIES` (the variable of the tests crate's
/// loader too); `None` when it is not set.
fn instrumented_libraries() -> Option<PathBuf> {
    std::env::var_os("NIGEL_FMU_LIBRARIES").map(PathBuf::from)
}

/// Runs the C importer of the C API `abi` built by `compiler` on the libraries of `folder`;
/// `runner` prefixes the command (wine, qemu); `path_of` turns a host path into the one the
/// program opens.
fn closed_loop_through(
    abi: Abi,
    folder: &str,
    dir: &Path,
    compiler: &[&str],
    exe_name: &str,
    runner: &mut dyn FnMut(&Path) -> Command,
    path_of: &dyn Fn(&Path) -> String,
) -> (Vec<String>, Vec<Vec<f64>>) {
    let libs = match abi {
        Abi::Fmi2 => libraries(folder, dir),
        Abi::Fmi3(folder3) => libraries3(folder, folder3, dir),
        Abi::Instrumented { .. } => {
            let from = instrumented_libraries().expect("NIGEL_FMU_LIBRARIES");
            FMUS.iter().map(|id| from.join(format!("lib{id}.so"))).collect()
        }
    };
    let fmi3 = matches!(abi, Abi::Fmi3(_) | Abi::Instrumented { fmi3: true });
    let (system, _keep) = closed_loop_system();
    let index: BTreeMap<String, usize> = FMUS.iter().enumerate().map(|(k, id)| (id.to_string(), k)).collect();
    let library = |i: usize| {
        let id = &system.instances[i].fmu.description().co_simulation.as_ref().unwrap().model_identifier;
        path_of(&libs[index[id.as_str()]])
    };
    let job = job_file(&system, &library, fmi3);
    let job_path = dir.join("closed_loop.job");
    std::fs::write(&job_path, job).unwrap();
    let exe = dir.join(exe_name);
    let mut compile = Command::new(compiler[0]);
    compile.args(&compiler[1..]).args(["-std=c99", "-O2", "-Wall", "-Werror", "-o"]).arg(&exe);
    if fmi3 {
        compile.arg("-I").arg(fmi3_headers()).arg(IMPORTER3);
    } else {
        compile.arg(IMPORTER);
    }
    run(&mut compile);
    let csv = dir.join("closed_loop.csv");
    let _ = std::fs::remove_file(&csv);
    run(runner(&exe).arg(path_of(&job_path)).arg(path_of(&csv)));
    let (header, rows) = read_csv(&csv);
    assert_eq!(rows.len(), 30_001, "{folder}: 0 .. 30 s at 1 ms");
    (header, rows)
}

type Table = (Vec<String>, Vec<Vec<f64>>);

/// Columns computed with our own arithmetic only (+ - * / and sqrt on doubles, correctly
/// rounded by IEEE 754 on every platform; Rust contracts no a * b + c into a fused
/// multiply-add; the tyres' `sin_cos` and `atan2` are the plant's own polynomials,
/// `nigel_vehicle::fastmath`) and fed by no C library function: bit for bit on every
/// platform. They are the test bench's open-loop outputs: the steering program (lane
/// change: +-a on integer sample ranges), the speed reference and the wind (a constant gust
/// plus scaled SplitMix64 integer noise).
///
/// Every other column depends, through the closed loop, on a C library function whose last
/// bit may differ between glibc on x86-64, mingw-w64 (msvcrt and libmingwex) and glibc's
/// aarch64 build: the plant's heading rotation `psi.sin_cos()` (`sin`, `cos`), its outputs
/// `beta = atan2(v_y, v_x)` and `speed = hypot(v_x, v_y)`, and the test bench's friction
/// `mu = 0.35 sin(...) + ...` (`sin`); in the real column also the friction circle (`hypot`)
/// and the Box-Muller measurement noise (`ln`, `cos`), which this job (sim) does not run.
const OWN_ARITHMETIC: [&str; 7] = [
    "maneuver.delta_ff_fl",
    "maneuver.delta_ff_fr",
    "maneuver.delta_ff_rl",
    "maneuver.delta_ff_rr",
    "maneuver.speed_ref",
    "maneuver.wind_x",
    "maneuver.wind_y",
];

/// Every column of `other` equals linux64's bit for bit when it is in [`OWN_ARITHMETIC`]
/// or when the platforms' C libraries agreed, else is within `1e-12` of linux64's relative
/// to the column's largest magnitude. Returns the columns that differed.
fn compare_with_linux64(
    folder: &str,
    linux: &(Vec<String>, Vec<Vec<f64>>),
    other: &(Vec<String>, Vec<Vec<f64>>),
) -> Vec<String> {
    assert_eq!(linux.0, other.0, "{folder}: columns");
    let mut differed = Vec::new();
    for j in 0..linux.0.len() {
        let scale = linux.1.iter().map(|r| r[j].abs()).fold(0.0, f64::max);
        let mut worst: f64 = 0.0;
        let mut identical = true;
        for (a, b) in linux.1.iter().zip(&other.1) {
            if a[j].to_bits() != b[j].to_bits() {
                identical = false;
                worst = worst.max((a[j] - b[j]).abs());
            }
        }
        let name = &linux.0[j];
        if OWN_ARITHMETIC.contains(&name.as_str()) || name == "time" {
            assert!(identical, "{folder}: {name} must equal linux64 bit for bit, differs by up to {worst:e}");
        }
        // 1e-12 relative: the C libraries' functions differ by an ulp or so (about 1e-16
        // relative); the closed loop is stable, so 30 000 steps grow that by orders of
        // magnitude less than the 1e4 this leaves
        assert!(worst <= 1e-12 * scale, "{folder}: {name} differs from linux64 by {worst:e}, scale {scale:e}");
        if !identical {
            differed.push(format!("{name} (max {:.1e} relative)", worst / scale));
        }
    }
    eprintln!(
        "{folder}: {} of {} columns bit-identical to linux64; within 1e-12: {}",
        linux.0.len() - differed.len(),
        linux.0.len(),
        differed.join(", ")
    );
    differed
}

/// objdump -T's GLIBC_2.N versions of `lib`, the highest.
fn highest_glibc(objdump: &str, lib: &Path) -> (u32, u32) {
    let text = run(Command::new(objdump).arg("-T").arg(lib));
    let mut best = (0, 0);
    for word in text.split_whitespace() {
        let Some(v) = word.trim_matches(|c| c == '(' || c == ')').strip_prefix("GLIBC_") else { continue };
        let parts: Vec<u32> = v.split('.').filter_map(|x| x.parse().ok()).collect();
        if parts.len() >= 2 {
            best = best.max((parts[0], parts[1]));
        }
    }
    best
}

#[test]
fn linux64_needs_glibc_2_17_and_two_importers_agree_bit_for_bit() {
    let Some((_, libs)) = built_libraries("linux64", "linux64-exports") else { return };
    for lib in libs {
        let v = highest_glibc("objdump", &lib);
        assert!(((2, 2)..=(2, 17)).contains(&v), "{}: needs GLIBC_{}.{}", lib.display(), v.0, v.1);
        assert_eq!(exports(&LINUX64, &lib, "fmi2").len(), 44, "{}: fmi2 exports", lib.display());
    }
    let c_run = fmi2_run(&LINUX64);
    // the same SSP through nigel_cosim's Jacobi master: another importer, the same numbers
    let (system, _keep) = closed_loop_system();
    let record = Some(c_run.0[1..].to_vec());
    let experiment = Experiment { algorithm: Algorithm::Jacobi, record, ..Experiment::new(STOP_TIME, STEP) };
    let (results, _) = simulate(&system, &experiment).unwrap();
    // the results as a table: time, then the recorded columns
    let master: Table = (
        std::iter::once("time".to_owned()).chain(results.names.iter().cloned()).collect(),
        (0..results.rows()).map(|k| results.row(k).to_vec()).collect(),
    );
    assert_master_equals_c_importer("linux64 nigel_cosim in process", c_run, &master);
}

fn wine_path(p: &Path) -> String {
    format!("Z:{}", p.display().to_string().replace('/', "\\"))
}

/// The command that runs a Windows program under wine in the test's folder `dir`, with
/// the shim of ProcessPrng next to it.
fn wine_runner(dir: &Path) -> impl FnMut(&Path) -> Command {
    // Rust's standard library (1.78 and later) imports ProcessPrng from
    // bcryptprimitives.dll, which Windows 10 has and wine 8 lacks: a shim next to the
    // importer forwards it to BCryptGenRandom (test only; nothing of it is in the archive)
    let shim = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/c/process_prng_shim.c");
    run(Command::new("x86_64-w64-mingw32-gcc")
        .args(["-shared", "-O2", "-o"])
        .arg(dir.join("bcryptprimitives.dll"))
        .arg(&shim)
        .arg("-lbcrypt"));
    let prefix = target_dir().join("wine-prefix");
    move |exe: &Path| {
        let mut c = Command::new("wine");
        c.arg(exe)
            .env("WINEPREFIX", &prefix)
            .env("WINEDEBUG", "-all")
            .env("WINEDLLOVERRIDES", "mscoree,mshtml=;bcryptprimitives=n")
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY");
        c
    }
}

#[test]
fn win64_closed_loop_under_wine_matches_linux64() {
    let Some((_, libs)) = built_libraries("win64", "win64") else { return };
    for lib in &libs {
        assert_eq!(exports(&WIN64, lib, "fmi2").len(), 44, "{}: fmi2 exports", lib.display());
        let text = run(Command::new("x86_64-w64-mingw32-objdump").arg("-p").arg(lib));
        let dlls: Vec<String> =
            text.lines().filter_map(|l| l.trim().strip_prefix("DLL Name: ")).map(|s| s.to_lowercase()).collect();
        let system = [
            "kernel32.dll",
            "msvcrt.dll",
            "ntdll.dll",
            "bcryptprimitives.dll",
            "ws2_32.dll",
            "userenv.dll",
            "advapi32.dll",
        ];
        for d in &dlls {
            assert!(
                system.contains(&d.as_str()) || d.starts_with("api-ms-win-"),
                "{}: imports {d}, not a system DLL",
                lib.display()
            );
        }
    }
    compare_with_linux64("win64", fmi2_run(&LINUX64), fmi2_run(&WIN64));
}

/// A platform whose libraries run here: its FMI 2.0 and FMI 3.0 folders, its C compiler,
/// and how its programs start.
struct Platform {
    folder: &'static str,
    folder3: &'static str,
    compiler: &'static str,
    /// The executables' file-name ending (`.exe` on Windows).
    exe: &'static str,
    starts: Start,
    /// Its FMI 2.0 closed loop's place in [`fmi2_run`]'s cache.
    index: usize,
}

/// How a platform's programs start here.
#[derive(Clone, Copy)]
enum Start {
    Natively,
    UnderWine,
    UnderQemu,
}

const LINUX64: Platform = Platform {
    folder: "linux64",
    folder3: "x86_64-linux",
    compiler: "gcc",
    exe: "",
    starts: Start::Natively,
    index: 0,
};
const WIN64: Platform = Platform {
    folder: "win64",
    folder3: "x86_64-windows",
    compiler: "x86_64-w64-mingw32-gcc",
    exe: ".exe",
    starts: Start::UnderWine,
    index: 1,
};
const AARCH64_LINUX: Platform = Platform {
    folder: "aarch64-linux",
    folder3: "aarch64-linux",
    compiler: "aarch64-linux-gnu-gcc",
    exe: "",
    starts: Start::UnderQemu,
    index: 2,
};

type Runner = Box<dyn FnMut(&Path) -> Command>;

impl Platform {
    /// How the platform's programs in `dir` start (wine's shim goes there), and how a host
    /// path is spelled to them.
    fn runner(&self, dir: &Path) -> (Runner, fn(&Path) -> String) {
        match self.starts {
            Start::Natively => (Box::new(|exe: &Path| Command::new(exe)), host_path),
            Start::UnderWine => (Box::new(wine_runner(dir)), wine_path),
            Start::UnderQemu => (Box::new(qemu), host_path),
        }
    }

    /// [`closed_loop_through`] the C API `abi` on this platform, `stem` the importer's name.
    fn closed_loop(&self, abi: Abi, dir: &Path, stem: &str) -> Table {
        let (mut runner, path_of) = self.runner(dir);
        let exe = format!("{stem}{}", self.exe);
        closed_loop_through(abi, self.folder, dir, &[self.compiler], &exe, &mut *runner, &path_of)
    }

    /// [`model_exchange_through_both_apis`] on this platform.
    fn model_exchange(&self, dir: &Path) -> (Table, Table) {
        let (mut runner, path_of) = self.runner(dir);
        let exe = format!("me_fixed_step{}", self.exe);
        model_exchange_through_both_apis(self.folder, self.folder3, dir, &[self.compiler], &exe, &mut *runner, &path_of)
    }
}

fn host_path(p: &Path) -> String {
    p.display().to_string()
}

/// The FMI 2.0 closed loop of `p`, run once per test binary in its own folder, whichever
/// test asks first (the others wait for it): linux64's is the reference of every other
/// platform; each platform's FMI 3.0 run is compared with its own.
fn fmi2_run(p: &Platform) -> &'static Table {
    static RUNS: [std::sync::OnceLock<Table>; 3] =
        [std::sync::OnceLock::new(), std::sync::OnceLock::new(), std::sync::OnceLock::new()];
    RUNS[p.index].get_or_init(|| {
        let dir = work_dir(&format!("{}-run", p.folder));
        p.closed_loop(Abi::Fmi2, &dir, "fmi2_closed_loop")
    })
}

/// The FMI 3.0 closed loop on `p` in `dir`: equal bit for bit to `p`'s FMI 2.0 run (the
/// same library), and, off linux64, compared with linux64's as the FMI 2.0 run is.
fn fmi3_closed_loop_matches(p: &Platform, dir: &Path) {
    let fmi3 = p.closed_loop(Abi::Fmi3(p.folder3), dir, "fmi3_closed_loop");
    if p.index != LINUX64.index {
        compare_with_linux64(&format!("{} (FMI 3.0)", p.folder3), fmi2_run(&LINUX64), &fmi3);
    }
    assert_same_bits(p.folder3, fmi2_run(p), &fmi3);
}

/// The arm64 glibc the programs run with under qemu-user: the loader and every library from
/// one build of it, Debian's cross package (libc6-arm64-cross, what aarch64-linux-gnu-gcc
/// links against). `-L` alone gives its loader, which searches `/lib/aarch64-linux-gnu`,
/// where multiarch's libc6:arm64 (another build of glibc 2.36, pulled in by the arm64 Rust
/// standard library) lives: the two disagree on the loader's private data, and the first
/// `pthread_create` then loops in the loader for ever (a program without threads, as the C
/// importers, happens to run). QEMU_LD_PREFIX and QEMU_SET_ENV (not `-L`, `-E`) so that a
/// program started under qemu by the program (the isolation's host, through a wrapper)
/// inherits them.
const QEMU_ENV: [(&str, &str); 2] =
    [("QEMU_LD_PREFIX", "/usr/aarch64-linux-gnu"), ("QEMU_SET_ENV", "LD_LIBRARY_PATH=/usr/aarch64-linux-gnu/lib")];

fn qemu(exe: &Path) -> Command {
    let mut c = Command::new("qemu-aarch64");
    c.envs(QEMU_ENV).arg(exe);
    c
}

/// `fmi3` equals `fmi2` in every column and row to the bit: the same library file on the same
/// platform, stepped on the same grid with the same calls in the same order, only through the
/// other C API (whose functions reach the same model code).
fn assert_same_bits(what: &str, fmi2: &Table, fmi3: &Table) {
    assert_eq!(fmi3.0, fmi2.0, "{what}: columns");
    assert_eq!(fmi3.1.len(), fmi2.1.len(), "{what}: rows");
    for (k, (a, b)) in fmi2.1.iter().zip(&fmi3.1).enumerate() {
        for j in 0..a.len() {
            assert_eq!(
                a[j].to_bits(),
                b[j].to_bits(),
                "{what}: row {k}, {}: FMI 2.0 {} FMI 3.0 {}",
                fmi2.0[j],
                a[j],
                b[j]
            );
        }
    }
}

#[test]
fn aarch64_closed_loop_under_qemu_matches_linux64() {
    let Some((_, libs)) = built_libraries("aarch64-linux", "aarch64-linux") else { return };
    for lib in libs {
        let v = highest_glibc("aarch64-linux-gnu-objdump", &lib);
        assert!(v <= (2, 17), "{}: needs GLIBC_{}.{}", lib.display(), v.0, v.1);
    }
    compare_with_linux64("aarch64-linux", fmi2_run(&LINUX64), fmi2_run(&AARCH64_LINUX));
}

/// The names of the FMI 3.0 functions every library exports (all of them: the FMU answers
/// those of a feature it lacks with fmi3Error).
fn fmi3_symbols() -> Vec<&'static str> {
    fmi_sys::fmi3::SYMBOLS.iter().map(|(name, _)| *name).collect()
}

/// The C importers built with gcc's AddressSanitizer and UndefinedBehaviorSanitizer
/// (`-fsanitize=address,undefined`, any report fatal) run the closed loop through both C
/// APIs on the instrumented libraries of `NIGEL_FMU_LIBRARIES` (the ASan step of
/// scripts/test.sh sets it; without it the test has nothing to run and says so). The
/// Rust code of the libraries is instrumented by ASan (UBSan is a C/C++ tool; Rust checks
/// its own arithmetic and bounds); the C importers by both, so a bad pointer, size or
/// lifetime on either side of the C boundary stops the run. The results are those of the
/// release libraries bit for bit: the same source, with no floating-point contraction or
/// reassociation in any profile, and the same C library.
#[test]
fn linux64_c_importers_under_asan_and_ubsan_on_the_instrumented_libraries() {
    if instrumented_libraries().is_none() {
        eprintln!("NIGEL_FMU_LIBRARIES not set: nothing to run (scripts/test.sh's ASan step sets it)");
        return;
    }
    let compiler = ["gcc", "-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-g"];
    let sanitized = |exe: &Path| {
        let mut c = Command::new(exe);
        // leaks count too: the importers free what they instantiate, the FMU what it allocates
        c.env("ASAN_OPTIONS", "detect_leaks=1:abort_on_error=0").env("UBSAN_OPTIONS", "print_stacktrace=1");
        c
    };
    for (fmi3, exe) in [(false, "fmi2_closed_loop"), (true, "fmi3_closed_loop")] {
        let dir = work_dir(&format!("sanitized-{exe}"));
        let table = closed_loop_through(
            Abi::Instrumented { fmi3 },
            "linux64",
            &dir,
            &compiler,
            exe,
            &mut |e| sanitized(e),
            &|p| p.display().to_string(),
        );
        assert_same_bits(&format!("{exe} under ASan+UBSan"), fmi2_run(&LINUX64), &table);
    }
    // Model Exchange through both C APIs, against the release library's FMI 2.0 run
    let dir = work_dir("sanitized-me");
    let (fmi2, fmi3) = model_exchange_through_both_apis(
        "linux64",
        "instrumented",
        &dir,
        &compiler,
        "me_fixed_step",
        &mut |e| sanitized(e),
        &|p| p.display().to_string(),
    );
    let release = dir.join("release");
    std::fs::create_dir_all(&release).unwrap();
    let (reference, _) = LINUX64.model_exchange(&release);
    assert_same_bits("me_fixed_step FMI 2.0 under ASan+UBSan", &reference, &fmi2);
    assert_same_bits("me_fixed_step FMI 3.0 under ASan+UBSan", &reference, &fmi3);
}

/// The names of the functions the library `lib` of `p` exports that begin with `prefix`,
/// sorted (`nm -D` of an ELF library, `objdump -p`'s export table of a DLL).
fn exports(p: &Platform, lib: &Path, prefix: &str) -> Vec<String> {
    let mut names: Vec<String> = match p.starts {
        Start::UnderWine => run(Command::new("x86_64-w64-mingw32-objdump").arg("-p").arg(lib))
            .lines()
            .filter(|l| l.trim_start().starts_with('['))
            .filter_map(|l| l.split_whitespace().last().map(str::to_string))
            .collect(),
        Start::Natively | Start::UnderQemu => {
            let nm = if matches!(p.starts, Start::UnderQemu) { "aarch64-linux-gnu-nm" } else { "nm" };
            run(Command::new(nm).args(["-D", "--defined-only"]).arg(lib))
                .lines()
                .filter_map(|l| l.split_whitespace().nth(2).map(str::to_string))
                .collect()
        }
    };
    names.retain(|n| n.starts_with(prefix));
    names.sort();
    names
}

/// The FMI 3.0 archives' libraries of `p` export every fmi3 function, and the FMI 3.0 closed
/// loop through them matches ([`fmi3_closed_loop_matches`]).
fn fmi3_closed_loop_test(p: &Platform) {
    if !built(p.folder) {
        return;
    }
    let dir = work_dir(&format!("{}-fmi3", p.folder3));
    let mut want = fmi3_symbols();
    want.sort();
    for lib in libraries3(p.folder, p.folder3, &dir) {
        assert_eq!(exports(p, &lib, "fmi3"), want, "{}: fmi3 exports", lib.display());
    }
    fmi3_closed_loop_matches(p, &dir);
}

#[test]
fn x86_64_linux_fmi3_closed_loop_equals_the_fmi2_one_bit_for_bit() {
    fmi3_closed_loop_test(&LINUX64);
}

#[test]
fn x86_64_windows_fmi3_closed_loop_under_wine_matches_linux64() {
    fmi3_closed_loop_test(&WIN64);
}

#[test]
fn aarch64_linux_fmi3_closed_loop_under_qemu_matches_linux64() {
    fmi3_closed_loop_test(&AARCH64_LINUX);
}

// ---- Mach-O, the little of it the darwin64 checks read --------------------------------

const FAT_MAGIC: u32 = 0xcafe_babe;
const MH_MAGIC_64: u32 = 0xfeed_facf;
const CPU_TYPE_X86_64: u32 = 0x0100_0007;
const CPU_TYPE_ARM64: u32 = 0x0100_000c;
const LC_SYMTAB: u32 = 0x2;
const LC_LOAD_DYLIB: u32 = 0xc;
const LC_ID_DYLIB: u32 = 0xd;
const LC_BUILD_VERSION: u32 = 0x32;
const PLATFORM_MACOS: u32 = 1;

struct Slice {
    cpu: u32,
    minos: Option<(u32, u32)>,
    dylibs: Vec<String>,
    fmi_exports: Vec<String>,
    /// The library's own name (`LC_ID_DYLIB`), what a program linked against it records.
    install_name: Option<String>,
}

fn u32_le(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

fn u32_be(b: &[u8], at: usize) -> u32 {
    u32::from_be_bytes(b[at..at + 4].try_into().unwrap())
}

fn c_string(b: &[u8], at: usize) -> String {
    let end = b[at..].iter().position(|&c| c == 0).map_or(b.len(), |e| at + e);
    String::from_utf8_lossy(&b[at..end]).into_owned()
}

/// One thin 64-bit little-endian Mach-O image.
fn parse_slice(b: &[u8]) -> Slice {
    assert_eq!(u32_le(b, 0), MH_MAGIC_64, "not a 64-bit Mach-O");
    let cpu = u32_le(b, 4);
    let ncmds = u32_le(b, 16) as usize;
    let mut at = 32; // sizeof(mach_header_64)
    let mut slice = Slice { cpu, minos: None, dylibs: Vec::new(), fmi_exports: Vec::new(), install_name: None };
    for _ in 0..ncmds {
        let (cmd, size) = (u32_le(b, at), u32_le(b, at + 4) as usize);
        match cmd {
            LC_BUILD_VERSION => {
                assert_eq!(u32_le(b, at + 8), PLATFORM_MACOS, "build version platform");
                let v = u32_le(b, at + 12); // xxxx.yy.zz nibbles
                slice.minos = Some((v >> 16, (v >> 8) & 0xff));
            }
            LC_LOAD_DYLIB => slice.dylibs.push(c_string(b, at + u32_le(b, at + 8) as usize)),
            LC_ID_DYLIB => slice.install_name = Some(c_string(b, at + u32_le(b, at + 8) as usize)),
            LC_SYMTAB => {
                let (symoff, nsyms, stroff) =
                    (u32_le(b, at + 8) as usize, u32_le(b, at + 12) as usize, u32_le(b, at + 16) as usize);
                for k in 0..nsyms {
                    let e = symoff + 16 * k; // sizeof(nlist_64)
                    let n_type = b[e + 4];
                    // N_EXT, and N_TYPE == N_SECT: an exported definition
                    if n_type & 0x01 != 0 && n_type & 0x0e == 0x0e {
                        let name = c_string(b, stroff + u32_le(b, e) as usize);
                        if name.starts_with("_fmi2") || name.starts_with("_fmi3") {
                            slice.fmi_exports.push(name);
                        }
                    }
                }
            }
            _ => {}
        }
        at += size;
    }
    slice
}

/// The checks of one thin Mach-O image of `lib` (CPU type `cpu`): macOS 11, the 44 fmi2
/// and the 75 fmi3 exports, system libraries only, the install name `@rpath/lib<id>.dylib`
/// (not the folder it was built in: the same bytes from any checkout).
fn check_darwin_slice(lib: &Path, cpu: u32, slice: &Slice) {
    assert_eq!(slice.cpu, cpu, "{}: CPU type", lib.display());
    let id = lib.file_stem().unwrap().to_string_lossy();
    assert_eq!(
        slice.install_name,
        Some(format!("@rpath/lib{id}.dylib")),
        "{} cpu {cpu:#x}: install name",
        lib.display()
    );
    assert_eq!(slice.minos, Some((11, 0)), "{} cpu {cpu:#x}: minimum macOS", lib.display());
    let mut exports = slice.fmi_exports.clone();
    exports.sort();
    exports.dedup();
    let mut fmi3: Vec<String> = exports
        .iter()
        .filter_map(|e| e.strip_prefix('_'))
        .filter(|e| e.starts_with("fmi3"))
        .map(str::to_string)
        .collect();
    exports.retain(|e| e.starts_with("_fmi2"));
    assert_eq!(exports.len(), 44, "{} cpu {cpu:#x}: fmi2 exports {exports:?}", lib.display());
    fmi3.sort();
    let mut want3: Vec<String> = fmi3_symbols().iter().map(|s| s.to_string()).collect();
    want3.sort();
    assert_eq!(fmi3, want3, "{} cpu {cpu:#x}: fmi3 exports", lib.display());
    assert!(
        exports.contains(&"_fmi2DoStep".to_string()) && exports.contains(&"_fmi2GetDirectionalDerivative".to_string())
    );
    assert!(!slice.dylibs.is_empty());
    for d in &slice.dylibs {
        assert!(d.starts_with("/usr/lib/") || d.starts_with("/System/Library/"), "{}: imports {d}", lib.display());
    }
}

#[test]
fn darwin64_is_universal_macos_11_with_the_fmi2_and_fmi3_exports_and_system_libraries_only() {
    let Some((dir, libs)) = built_libraries("darwin64", "darwin64") else { return };
    // the FMI 2.0 archives' darwin64: one universal library of both architectures
    for lib in libs {
        let b = std::fs::read(&lib).unwrap();
        assert_eq!(u32_be(&b, 0), FAT_MAGIC, "{}: not a universal binary", lib.display());
        let n = u32_be(&b, 4) as usize;
        let mut cpus = Vec::new();
        for k in 0..n {
            let e = 8 + 20 * k; // sizeof(fat_arch), big-endian
            let (cpu, offset, size) = (u32_be(&b, e), u32_be(&b, e + 8) as usize, u32_be(&b, e + 12) as usize);
            check_darwin_slice(&lib, cpu, &parse_slice(&b[offset..offset + size]));
            cpus.push(cpu);
        }
        cpus.sort();
        assert_eq!(cpus, [CPU_TYPE_X86_64, CPU_TYPE_ARM64], "{}: architectures", lib.display());
    }
    // the FMI 3.0 archives' x86_64-darwin and aarch64-darwin: each the thin slice of its
    // architecture (libraries3 compares it with llvm-lipo's extraction)
    for (folder3, cpu) in [("x86_64-darwin", CPU_TYPE_X86_64), ("aarch64-darwin", CPU_TYPE_ARM64)] {
        let sub = dir.join(folder3);
        std::fs::create_dir_all(&sub).unwrap();
        for lib in libraries3("darwin64", folder3, &sub) {
            let b = std::fs::read(&lib).unwrap();
            assert_eq!(u32_le(&b, 0), MH_MAGIC_64, "{}: not a thin 64-bit Mach-O", lib.display());
            check_darwin_slice(&lib, cpu, &parse_slice(&b));
        }
    }
}

// ---- Model Exchange through both C APIs ------------------------------------------------

const ME_IMPORTER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/c/me_fixed_step.c");
/// The Model Exchange run: 2 s of the plant at a fixed 1 ms RK4 step.
const ME_STOP_TIME: f64 = 2.0;

/// The job file of `tests/c/me_fixed_step.c` for the plant in `library`: a turn from 0.35
/// m/s (front wheels at 0.05 rad), every Real output recorded, with the FMI 2.0 and the FMI
/// 3.0 value reference of each variable (declaration row r has FMI 3.0 value reference r + 1).
fn me_job(library: &str) -> String {
    let d = build_fmu::targets().into_iter().find(|t| t.model_identifier == "nigel_plant").unwrap().description;
    let vars = &d.model_variables;
    let row = |name: &str| vars.iter().position(|v| v.name == name).unwrap_or_else(|| panic!("no variable {name}"));
    let mut job = format!("experiment {ME_STOP_TIME:?} {STEP:?}\nfmu {} {library}\n", d.guid);
    job += &format!("states {}\n", d.model_structure.derivatives.len());
    for (name, value) in [("v_x_start", 0.35), ("delta_fl", 0.05), ("delta_fr", 0.05)] {
        let r = row(name);
        job += &format!("real {} {} {value:?}\n", vars[r].value_reference, r + 1);
    }
    for (r, v) in vars.iter().enumerate() {
        let real = matches!(v.variable_type, model_description::VariableType::Real { .. });
        if real && v.causality == model_description::Causality::Output {
            job += &format!("record {} {} {}\n", v.value_reference, r + 1, v.name);
        }
    }
    job
}

/// The plant's library of `folder` (FMI 2.0 archive) and of `folder3` (FMI 3.0 archive: the
/// same file; `"instrumented"`: the one of [`instrumented_libraries`]) through Model Exchange, `me_fixed_step.c` built by `compiler` and run by
/// `runner` through the FMI 2.0 and then the FMI 3.0 C API; both tables.
fn model_exchange_through_both_apis(
    folder: &str,
    folder3: &'static str,
    dir: &Path,
    compiler: &[&str],
    exe_name: &str,
    runner: &mut dyn FnMut(&Path) -> Command,
    path_of: &dyn Fn(&Path) -> String,
) -> (Table, Table) {
    let plant = FMUS.iter().position(|id| *id == "nigel_plant").unwrap();
    let (lib2, lib3) = if folder3 == "instrumented" {
        let lib = instrumented_libraries().expect("NIGEL_FMU_LIBRARIES").join("libnigel_plant.so");
        (lib.clone(), lib)
    } else {
        let sub = dir.join("fmi3");
        std::fs::create_dir_all(&sub).unwrap();
        (libraries(folder, dir)[plant].clone(), libraries3(folder, folder3, &sub)[plant].clone())
    };
    let exe = dir.join(exe_name);
    let mut compile = Command::new(compiler[0]);
    compile.args(&compiler[1..]).args(["-std=c99", "-O2", "-Wall", "-Werror", "-o"]).arg(&exe);
    compile.arg("-I").arg(fmi3_headers()).arg(ME_IMPORTER);
    run(&mut compile);
    let mut tables = Vec::new();
    for (api, lib) in [("2", &lib2), ("3", &lib3)] {
        let job = dir.join(format!("me{api}.job"));
        std::fs::write(&job, me_job(&path_of(lib))).unwrap();
        let csv = dir.join(format!("me{api}.csv"));
        run(runner(&exe).arg(api).arg(path_of(&job)).arg(path_of(&csv)));
        let table = read_csv(&csv);
        assert_eq!(table.1.len(), 2001, "{folder3} FMI {api}.0: 0 .. 2 s at 1 ms");
        tables.push(table);
    }
    let fmi3 = tables.pop().unwrap();
    let fmi2 = tables.pop().unwrap();
    // the run integrated something: the car moved forward and turned (x and psi grew)
    let last = fmi2.1.last().unwrap();
    let column = |name: &str| fmi2.0.iter().position(|c| c == name).unwrap();
    assert!(last[column("speed")] > 0.1 && last[column("speed")] < 0.35, "{folder3}: speed {}", last[column("speed")]);
    assert_ne!(fmi2.1[0][1..], last[1..], "{folder3}: the states did not change");
    (fmi2, fmi3)
}

/// The FMI 3.0 Model Exchange run of the plant equals the FMI 2.0 one bit for bit on each
/// platform that runs here: the same library, the same RK4 arithmetic in the same C
/// program, only the calls of the other API (whose functions reach the same model code).
fn fmi3_model_exchange_equals_the_fmi2_one(p: &Platform) {
    if !built(p.folder) {
        return;
    }
    let (fmi2, fmi3) = p.model_exchange(&work_dir(&format!("me-{}", p.folder3)));
    assert_same_bits(&format!("{} Model Exchange", p.folder3), &fmi2, &fmi3);
}

#[test]
fn x86_64_linux_fmi3_model_exchange_equals_the_fmi2_one_bit_for_bit() {
    fmi3_model_exchange_equals_the_fmi2_one(&LINUX64);
}

#[test]
fn x86_64_windows_fmi3_model_exchange_under_wine_equals_the_fmi2_one_bit_for_bit() {
    fmi3_model_exchange_equals_the_fmi2_one(&WIN64);
}

#[test]
fn aarch64_linux_fmi3_model_exchange_under_qemu_equals_the_fmi2_one_bit_for_bit() {
    fmi3_model_exchange_equals_the_fmi2_one(&AARCH64_LINUX);
}

/// The folder of the unpacked release archive of the master for `triple`
/// (`$NIGEL_DIST_DIR/cosim-<version>-<triple>`): scripts/test-dist.sh unpacks them and sets
/// `NIGEL_DIST_DIR`.
fn dist_folder(triple: &str) -> PathBuf {
    let dist = std::env::var_os("NIGEL_DIST_DIR")
        .expect("NIGEL_DIST_DIR: the unpacked release archives (scripts/test-dist.sh runs this test)");
    Path::new(&dist).join(format!("cosim-{}-{triple}", env!("CARGO_PKG_VERSION")))
}

/// The master's `cosim run` of the closed-loop SSP (Jacobi, 30 s at 1 ms, every output at
/// every step: the C importer's job) with the options `extra`, started by `runner`, its CSV
/// read; `path_of` turns a host path into the one the program opens.
fn master_run(
    dir: &Path,
    cosim: &Path,
    extra: &[&str],
    runner: &mut dyn FnMut(&Path) -> Command,
    path_of: &dyn Fn(&Path) -> String,
) -> Table {
    let ssp = target_dir().join("ssp").join("nigel_closed_loop.ssp");
    let csv = dir.join("master.csv");
    // in `dir`: there the Windows program finds the test's bcryptprimitives.dll shim
    run(runner(cosim)
        .current_dir(dir)
        .args(["run", &path_of(&ssp), "--algorithm", "jacobi"])
        .args(["--stop-time", &format!("{STOP_TIME:?}"), "--step", &format!("{STEP:?}")])
        .args(["--output", &path_of(&csv)])
        .args(extra));
    read_csv(&csv)
}

/// Every column of the C importer's run `c_run` equals the master's column of the same name
/// bit for bit (the master's CSV holds the outputs in shortest round-trip form, so parsing
/// gives the computed doubles back).
fn assert_master_equals_c_importer(what: &str, c_run: &Table, master: &Table) {
    assert_eq!(master.1.len(), c_run.1.len(), "{what}: rows");
    for (j, name) in c_run.0.iter().enumerate() {
        let m = master.0.iter().position(|n| n == name).unwrap_or_else(|| panic!("{what}: no column {name}"));
        for (k, (a, b)) in c_run.1.iter().zip(&master.1).enumerate() {
            assert_eq!(a[j].to_bits(), b[m].to_bits(), "{what}: row {k}, {name}: C importer {} master {}", a[j], b[m]);
        }
    }
    eprintln!("{what}: {} columns x {} rows equal to the C importer's bit for bit", c_run.0.len(), c_run.1.len());
}

/// The master's Windows build under wine loads the FMUs' win64 DLLs and gives what the plain
/// C importer (fmi2_closed_loop.c, mingw-w64, under wine) gives with the same DLLs, to the
/// bit: so where the Windows master differs from x86-64 Linux (scripts/test-dist.sh), the
/// difference is the DLLs' C library's, not the master's (as on Linux, where
/// `linux64_needs_glibc_2_17_and_two_importers_agree_bit_for_bit` holds the master to the C
/// importer).
#[test]
#[ignore = "run by scripts/test-dist.sh on the unpacked release archives (NIGEL_DIST_DIR)"]
fn windows_master_under_wine_equals_the_c_importer_on_the_same_dlls_bit_for_bit() {
    let cosim = dist_folder("x86_64-pc-windows-gnu").join("cosim.exe");
    let dir = work_dir("windows-master");
    let mut wine = wine_runner(&dir);
    let master = master_run(&dir, &cosim, &[], &mut wine, &wine_path);
    assert_master_equals_c_importer("x86-64 Windows master (wine)", fmi2_run(&WIN64), &master);
}

/// The master's aarch64 Linux build under qemu-user loads the FMUs' aarch64-linux libraries
/// and gives what the plain C importer (fmi2_closed_loop.c, aarch64-linux-gnu-gcc, under
/// qemu) gives with the same libraries and the same glibc, to the bit, as the Windows master
/// does above; in process and with each FMU in a host process of its own (`--isolate`: the
/// aarch64 `cosim-host`, started under qemu through a two-line wrapper named by
/// `NIGEL_COSIM_HOST`, since qemu-user cannot exec a foreign program without binfmt_misc).
#[test]
#[ignore = "run by scripts/test-dist.sh on the unpacked release archives (NIGEL_DIST_DIR)"]
fn aarch64_master_under_qemu_equals_the_c_importer_on_the_same_libraries_bit_for_bit() {
    let folder = dist_folder("aarch64-unknown-linux-gnu");
    let dir = work_dir("aarch64-master");
    let master = master_run(&dir, &folder.join("cosim"), &[], &mut qemu, &host_path);
    assert_master_equals_c_importer("aarch64 Linux master (qemu)", fmi2_run(&AARCH64_LINUX), &master);
    let wrapper = dir.join("cosim-host-under-qemu");
    let host = folder.join("cosim-host");
    std::fs::write(&wrapper, format!("#!/bin/sh\nexec qemu-aarch64 '{}' \"$@\"\n", host.display())).unwrap();
    std::fs::set_permissions(&wrapper, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let mut isolated = |exe: &Path| {
        let mut c = qemu(exe);
        c.env("NIGEL_COSIM_HOST", &wrapper);
        c
    };
    let master = master_run(&dir, &folder.join("cosim"), &["--isolate"], &mut isolated, &host_path);
    assert_master_equals_c_importer("aarch64 Linux master --isolate (qemu)", fmi2_run(&AARCH64_LINUX), &master);
}

//! Test FMUs written in C (tests/cfmu/models.c), compiled with the system `cc` and zipped
//! as proper FMI 2.0 archives: modelDescription.xml + binaries/linux64/<id>.so.
#![allow(dead_code)]

pub mod fmi3_c;

use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model {
    Source,
    Gain,
    Integrator,
    Faulty,
}

impl Model {
    fn number(self) -> u32 {
        match self {
            Model::Source => 1,
            Model::Gain => 2,
            Model::Integrator => 3,
            Model::Faulty => 4,
        }
    }
    pub fn id(self) -> &'static str {
        match self {
            Model::Source => "source",
            Model::Gain => "gain",
            Model::Integrator => "integrator",
            Model::Faulty => "faulty",
        }
    }
    pub fn variables(self) -> &'static str {
        match self {
            Model::Source => {
                r#"<ScalarVariable name="y" valueReference="0" causality="output"><Real unit="m"/></ScalarVariable>
    <ScalarVariable name="slope" valueReference="1" causality="parameter" variability="fixed"><Real start="1" unit="m/s"/></ScalarVariable>"#
            }
            Model::Gain => {
                r#"<ScalarVariable name="u" valueReference="0" causality="input"><Real start="0" unit="m"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output"><Real unit="m"/></ScalarVariable>
    <ScalarVariable name="k" valueReference="2" causality="parameter" variability="fixed"><Real start="2"/></ScalarVariable>"#
            }
            Model::Integrator => {
                r#"<ScalarVariable name="u" valueReference="0" causality="input"><Real start="0" unit="m"/></ScalarVariable>
    <ScalarVariable name="x" valueReference="1" causality="output" initial="exact"><Real start="0" unit="m"/></ScalarVariable>"#
            }
            Model::Faulty => {
                r#"<ScalarVariable name="y" valueReference="0" causality="output"><Real/></ScalarVariable>
    <ScalarVariable name="fail_time" valueReference="1" causality="parameter" variability="fixed"><Real start="0.5"/></ScalarVariable>
    <ScalarVariable name="mode" valueReference="2" causality="parameter" variability="fixed"><Real start="3"/></ScalarVariable>
    <ScalarVariable name="max_ok_step" valueReference="3" causality="parameter" variability="fixed"><Real start="0"/></ScalarVariable>"#
            }
        }
    }
    fn structure(self) -> &'static str {
        match self {
            Model::Source => r#"<Outputs><Unknown index="1" dependencies=""/></Outputs>"#,
            Model::Gain => r#"<Outputs><Unknown index="2" dependencies="1"/></Outputs>"#,
            Model::Integrator => r#"<Outputs><Unknown index="2" dependencies=""/></Outputs>"#,
            Model::Faulty => r#"<Outputs><Unknown index="1" dependencies=""/></Outputs>"#,
        }
    }
    pub fn model_description(self) -> String {
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="{id}" guid="{{test-{id}}}" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="{id}" canHandleVariableCommunicationStepSize="true" canGetAndSetFMUstate="{state}"/>
  <UnitDefinitions>
    <Unit name="m"><BaseUnit m="1"/></Unit>
    <Unit name="mm"><BaseUnit m="1" factor="0.001"/></Unit>
    <Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit>
  </UnitDefinitions>
  <ModelVariables>
    {vars}
  </ModelVariables>
  <ModelStructure>{structure}</ModelStructure>
</fmiModelDescription>
"#,
            id = self.id(),
            state = self == Model::Faulty,
            vars = self.variables(),
            structure = self.structure()
        )
    }
}

/// The target folder: the build's, with the FMUs and SSPs the test command builds
/// (target/fmu, target/ssp).
pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("target"))
}

/// `target/ssp/<file>`, one of our SSPs built by `cargo run --release -p build-fmu`.
pub fn built_ssp(file: &str) -> PathBuf {
    let p = target_dir().join("ssp").join(file);
    assert!(
        p.is_file(),
        "{} missing: run `cargo run --release -p build-fmu -- --platforms linux64 --this-glibc` first",
        p.display()
    );
    p
}

/// A fresh folder for one test's files, under target/cosim-tests/.
pub fn work_dir(test: &str) -> PathBuf {
    let dir = target_dir().join("cosim-tests").join(format!("{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("work dir");
    dir
}

/// Compiles models.c for `model` into `out` (with extra `cc` flags).
pub fn compile(model: Model, out: &Path, extra: &[&str]) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cosim/tests/cfmu/models.c");
    let mut flags = vec![OsString::from(format!("-DMODEL={}", model.number()))];
    flags.extend(extra.iter().map(OsString::from));
    cc(&flags, &[src], out);
}

/// Runs `cc -shared -fPIC -O2 -fvisibility=hidden -Wno-unused-parameter <flags> <sources> -o
/// <so>`: the shared library of a C test FMU.
pub fn cc(flags: &[OsString], sources: &[PathBuf], so: &Path) {
    let status = Command::new("cc")
        .args(["-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-Wno-unused-parameter"])
        .args(flags)
        .args(sources)
        .arg("-o")
        .arg(so)
        .status()
        .expect("run cc");
    assert!(status.success(), "cc failed for {sources:?}");
}

/// Packs `xml` as modelDescription.xml and the library `so` as `binary` (its path in the
/// archive) into the FMU `fmu`.
pub fn pack_library(fmu: &Path, xml: &str, binary: &str, so: &Path) {
    zip_entries(
        fmu,
        &[("modelDescription.xml", xml.as_bytes().to_vec()), (binary, std::fs::read(so).expect("read so"))],
    );
}

/// Zips `entries` (name, bytes) into `path`.
pub fn zip_entries(path: &Path, entries: &[(&str, Vec<u8>)]) {
    let file = std::fs::File::create(path).expect("create zip");
    let mut zip = zip::ZipWriter::new(file);
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    for (name, bytes) in entries {
        zip.start_file(*name, options).expect("zip entry");
        zip.write_all(bytes).expect("zip write");
    }
    zip.finish().expect("zip finish");
}

/// Builds `<dir>/<id>.fmu` for `model`; `extra` cc flags (e.g. -DOMIT_DOSTEP).
pub fn build_fmu(model: Model, dir: &Path, extra: &[&str]) -> PathBuf {
    let so = dir.join(format!("{}.so", model.id()));
    compile(model, &so, extra);
    let fmu = dir.join(format!("{}.fmu", model.id()));
    pack_library(&fmu, &model.model_description(), &format!("binaries/linux64/{}.so", model.id()), &so);
    fmu
}

/// Entries of the folder where the master unpacks (`nigel-cosim-*` in the temp dir).
pub fn unpack_dirs() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(std::env::temp_dir())
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("nigel-cosim-")))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// The plant FMU built by `cargo run --release -p build-fmu`.
pub fn plant_fmu() -> PathBuf {
    let p = target_dir().join("fmu").join("nigel_plant.fmu");
    assert!(p.is_file(), "{} missing: run `cargo run --release -p build-fmu` first", p.display());
    p
}

/// The plant's FMI 3.0 archive built by `cargo run --release -p build-fmu`.
pub fn plant_fmu3() -> PathBuf {
    let p = plant_fmu().with_file_name("fmi3").join("nigel_plant.fmu");
    assert!(p.is_file(), "{} missing: run `cargo run --release -p build-fmu` first", p.display());
    p
}

/// Builds `<dir>/<file_stem>.fmu` for `model` with a modified modelDescription.xml.
pub fn build_fmu_with(model: Model, dir: &Path, file_stem: &str, xml: &str) -> PathBuf {
    let so = dir.join(format!("{file_stem}.so"));
    compile(model, &so, &[]);
    let fmu = dir.join(format!("{file_stem}.fmu"));
    pack_library(&fmu, xml, &format!("binaries/linux64/{}.so", model.id()), &so);
    fmu
}

/// Compiles `tests/cfmu/<id>.c` and packs it with `xml` as `<dir>/<id>.fmu`.
fn build_single_c_fmu(dir: &Path, id: &str, xml: &str) -> PathBuf {
    build_single_c_fmu_with_flags(dir, id, xml, &[])
}

/// [`build_single_c_fmu`] with extra `cc` flags (e.g. `-DWRONG_JACOBIAN`).
fn build_single_c_fmu_with_flags(dir: &Path, id: &str, xml: &str, flags: &[&str]) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../cosim/tests/cfmu/{id}.c"));
    let so = dir.join(format!("{id}.so"));
    cc(&flags.iter().map(OsString::from).collect::<Vec<_>>(), &[src], &so);
    let fmu = dir.join(format!("{id}.fmu"));
    pack_library(&fmu, xml, &format!("binaries/linux64/{id}.so"), &so);
    fmu
}

/// The FMU of crash.c whose library segfaults in its load-time initializer
/// (tests/cfmu/ctor.c), as `<dir>/ctor.fmu`.
pub fn build_ctor_crash(dir: &Path) -> PathBuf {
    let xml = include_str!("../cfmu/crash.xml")
        .replace(r#"modelName="crash""#, r#"modelName="ctor""#)
        .replace(r#"modelIdentifier="crash""#, r#"modelIdentifier="ctor""#);
    build_single_c_fmu(dir, "ctor", &xml)
}

/// The misbehaving FMU (tests/cfmu/hostile.c): hostile log formats at instantiation,
/// output `y` NaN / Inf with fmi2OK from `t_bad` on; as `<dir>/hostile.fmu`.
pub fn build_hostile(dir: &Path) -> PathBuf {
    let xml = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="hostile" guid="{hostile}" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="hostile" canHandleVariableCommunicationStepSize="true"/>
  <ModelVariables>
    <ScalarVariable name="y" valueReference="0" causality="output"><Real/></ScalarVariable>
    <ScalarVariable name="t_bad" valueReference="1" causality="parameter" variability="fixed"><Real start="0.5"/></ScalarVariable>
    <ScalarVariable name="bad" valueReference="2" causality="parameter" variability="fixed"><Real start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="1" dependencies=""/></Outputs></ModelStructure>
</fmiModelDescription>
"#;
    build_single_c_fmu(dir, "hostile", xml)
}

/// `pub fn $name(dir: &Path) -> PathBuf` for each `$name => "$id"`: the C test FMU
/// tests/cfmu/$id.c with its description tests/cfmu/$id.xml, as `<dir>/$id.fmu`.
macro_rules! c_fmu_builders {
    ($($(#[$doc:meta])* $name:ident => $id:literal;)*) => {
        $(
            $(#[$doc])*
            pub fn $name(dir: &Path) -> PathBuf {
                build_single_c_fmu(dir, $id, include_str!(concat!("../cfmu/", $id, ".xml")))
            }
        )*
    };
}

c_fmu_builders! {
    /// Exponential decay that returns NaN or infinite derivatives, or a NaN next event time,
    /// with fmi2OK (tests/cfmu/nanme.c), Model Exchange only, as `<dir>/nanme.fmu`.
    build_nanme => "nanme";
    /// The bouncing ball (tests/cfmu/ball.c), Model Exchange only, as `<dir>/ball.fmu`.
    build_ball => "ball";
    /// The self-ending counter (tests/cfmu/stair.c, after the Reference FMU Stair), Model
    /// Exchange and Co-Simulation, as `<dir>/stair.fmu`.
    build_stair => "stair";
    /// The misbehaving Co-Simulation FMU (tests/cfmu/crash.c: segfault, abort, stack overflow,
    /// exit(0), a never-returning step at t_crash, a 10 MB log message, a double free), as
    /// `<dir>/crash.fmu`.
    build_crash => "crash";
    /// Van der Pol with directional derivatives (tests/cfmu/vdp.c), Model Exchange only, as
    /// `<dir>/vdp.fmu`.
    build_vdp => "vdp";
}
/// The bouncing ball with `n` event indicators (all z = h), as `<dir>/ball.fmu`.
pub fn build_ball_with_indicators(dir: &Path, n: usize) -> PathBuf {
    let xml = include_str!("../cfmu/ball.xml")
        .replace(r#"numberOfEventIndicators="1""#, &format!(r#"numberOfEventIndicators="{n}""#));
    build_single_c_fmu_with_flags(dir, "ball", &xml, &[&format!("-DINDICATORS={n}")])
}

/// The discrete latch (tests/cfmu/latch.c), Model Exchange only, as `<dir>/latch.fmu`.
pub fn build_latch(dir: &Path) -> PathBuf {
    let xml = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="latch" guid="{latch}" numberOfEventIndicators="0">
  <ModelExchange modelIdentifier="latch"/>
  <ModelVariables>
    <ScalarVariable name="u" valueReference="0" causality="input"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output" variability="discrete" initial="exact"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="count" valueReference="2" causality="output" variability="discrete" initial="exact"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="t_last" valueReference="3" causality="output" variability="discrete" initial="exact"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="mode" valueReference="4" causality="parameter" variability="fixed"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="t_event" valueReference="5" causality="parameter" variability="fixed"><Real start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs><Unknown index="2" dependencies=""/><Unknown index="3" dependencies=""/><Unknown index="4" dependencies=""/></Outputs>
  </ModelStructure>
</fmiModelDescription>
"#;
    build_single_c_fmu(dir, "latch", xml)
}

/// [`build_crash`] with a GUID of `bytes` bytes (`{crash}` then hexadecimal digits of a
/// pseudo-random sequence up to that length: the archive compresses it no more than its
/// zip-bomb limit allows).
pub fn build_crash_with_guid(dir: &Path, bytes: usize) -> PathBuf {
    let mut x = 0x9e3779b97f4a7c15u64;
    let digits: String = (0..bytes.saturating_sub(7))
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            char::from_digit((x % 16) as u32, 16).unwrap()
        })
        .collect();
    let guid = format!("{{crash}}{digits}");
    let xml = include_str!("../cfmu/crash.xml").replace(r#"guid="{crash}""#, &format!(r#"guid="{guid}""#));
    build_single_c_fmu(dir, "crash", &xml)
}

/// The rows `time,y` of a two-column CSV written by `cosim run` (header skipped).
#[allow(dead_code)] // not every test binary reads such a CSV
pub fn time_and_y(csv: &str) -> Vec<(f64, f64)> {
    csv.lines()
        .skip(1)
        .map(|l| {
            let (t, y) = l.split_once(',').unwrap();
            (t.parse().unwrap(), y.parse().unwrap())
        })
        .collect()
}

/// The vdp FMU at `path` alone ("model") to 2 s in steps of 0.01 s under bdf (rtol 1e-6,
/// atol 1e-8), its states recorded: the tests that compare its Jacobians with differences.
pub fn run_vdp_under_bdf(path: &Path) -> (nigel_cosim::Results, nigel_cosim::Summary) {
    let mut e = nigel_cosim::Experiment::new(2.0, 0.01);
    e.solver = nigel_cosim::Solver::Bdf { rtol: 1e-6, atol: 1e-8 };
    e.record = Some(vec!["model.x0".into(), "model.x1".into()]);
    let fmu = nigel_cosim::Fmu::load(path).unwrap();
    nigel_cosim::simulate(&nigel_cosim::System::single("model", fmu).unwrap(), &e).unwrap()
}

/// The folder `work_dir(test)` with the FMUs source.fmu and gain.fmu built in it (the
/// parts of the SSP tests' systems).
pub fn work_dir_with_source_and_gain(test: &str) -> PathBuf {
    let dir = work_dir(test);
    build_fmu(Model::Source, &dir, &[]);
    build_fmu(Model::Gain, &dir, &[]);
    dir
}

/// Packs the SSP `ssp`: `ssd` as SystemStructure.ssd and the files `files` of `dir` under
/// their names.
pub fn pack_ssp(ssp: &Path, ssd: String, dir: &Path, files: &[&str]) {
    let mut entries = vec![("SystemStructure.ssd", ssd.into_bytes())];
    entries.extend(files.iter().map(|name| (*name, std::fs::read(dir.join(name)).unwrap())));
    zip_entries(ssp, &entries);
}

/// A system builder with an instance of `fmu` under each of `names`.
pub fn builder_with(fmu: &std::sync::Arc<nigel_cosim::Fmu>, names: &[&str]) -> nigel_cosim::SystemBuilder {
    let mut b = nigel_cosim::SystemBuilder::new();
    for name in names {
        b.add_instance(name, fmu.clone()).unwrap();
    }
    b
}

/// Runs `command` (a run that writes the CSV `csv`), asserts that it succeeded (showing its
/// stderr otherwise) and reads the CSV: the header's names (quotes removed) and the rows.
pub fn run_to_csv(command: &mut Command, csv: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let out = command.output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    read_csv(csv)
}

/// `cosim run MODEL ARGS... --input INPUT -o CSV --summary SUMMARY`, its output (the
/// program of this package's build; a package without it, such as the campaign's tests
/// that include this module, has no use for this).
pub fn cosim_run_with_input(
    model: &Path,
    args: &[&str],
    input: &Path,
    csv: &Path,
    summary: &Path,
) -> std::process::Output {
    // known when this package's tests are compiled, absent in the campaign's (which do not call this)
    let Some(cosim) = option_env!("CARGO_BIN_EXE_cosim") else { panic!("the cosim program of this package") };
    Command::new(cosim)
        .arg("run")
        .arg(model)
        .args(args)
        .arg("--input")
        .arg(input)
        .arg("-o")
        .arg(csv)
        .arg("--summary")
        .arg(summary)
        .output()
        .unwrap()
}

/// The CSV `cosim run` writes: the header's names (quotes removed) and the rows.
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(|h| h.trim_matches('"').to_string()).collect();
    let rows = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    (header, rows)
}

/// The model description of the FMU with no states (tests/cfmu/ramp.c); `offset_causality`
/// of its discrete variable `offset` ("local" as the FMU has it, "output" to test the
/// sample-period warning).
pub fn ramp_xml(offset_causality: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="ramp" guid="{{ramp}}" numberOfEventIndicators="0">
  <ModelExchange modelIdentifier="ramp"/>
  <DefaultExperiment startTime="0" stopTime="1" stepSize="0.01"/>
  <ModelVariables>
    <ScalarVariable name="y" valueReference="0" causality="output"><Real/></ScalarVariable>
    <ScalarVariable name="slope" valueReference="1" causality="parameter" variability="fixed"><Real start="2"/></ScalarVariable>
    <ScalarVariable name="t_step" valueReference="2" causality="parameter" variability="fixed"><Real start="0.55"/></ScalarVariable>
    <ScalarVariable name="offset" valueReference="3" causality="{offset_causality}" variability="discrete"><Real/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="1" dependencies=""/></Outputs></ModelStructure>
</fmiModelDescription>
"#
    )
}

/// The FMU with no continuous states and no event indicators (tests/cfmu/ramp.c), Model
/// Exchange only, with the model description `xml` ([`ramp_xml`]), as `<dir>/ramp.fmu`.
pub fn build_ramp(dir: &Path, xml: &str) -> PathBuf {
    build_single_c_fmu(dir, "ramp", xml)
}

/// The stiff linear system with a closed-form solution (tests/cfmu/linear.c), Model
/// Exchange only, as `<dir>/linear.fmu`.
pub fn build_linear(dir: &Path) -> PathBuf {
    let xml = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="linear" guid="{linear}" numberOfEventIndicators="0">
  <ModelExchange modelIdentifier="linear"/>
  <ModelVariables>
    <ScalarVariable name="x1" valueReference="0" causality="output" initial="exact"><Real start="1"/></ScalarVariable>
    <ScalarVariable name="der(x1)" valueReference="1"><Real derivative="1"/></ScalarVariable>
    <ScalarVariable name="x2" valueReference="2" causality="output" initial="exact"><Real start="1"/></ScalarVariable>
    <ScalarVariable name="der(x2)" valueReference="3"><Real derivative="3"/></ScalarVariable>
    <ScalarVariable name="lambda" valueReference="4" causality="parameter" variability="fixed"><Real start="10000"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs><Unknown index="1" dependencies=""/><Unknown index="3" dependencies=""/></Outputs>
    <Derivatives><Unknown index="2" dependencies="1 3"/><Unknown index="4" dependencies="3"/></Derivatives>
  </ModelStructure>
</fmiModelDescription>
"#;
    build_single_c_fmu(dir, "linear", xml)
}

/// [`build_vdp`] with `providesDirectionalDerivative="false"` (the master differences the
/// right-hand side), as `<dir>/vdp.fmu`.
pub fn build_vdp_without_directional_derivatives(dir: &Path) -> PathBuf {
    let xml = include_str!("../cfmu/vdp.xml")
        .replace(r#"providesDirectionalDerivative="true""#, r#"providesDirectionalDerivative="false""#);
    build_single_c_fmu(dir, "vdp", &xml)
}

/// [`build_vdp`] whose description declares, as Dymola's do, a `derivative` attribute on a
/// variable that is no state derivative: `derivative_calls` (a local) is declared the
/// derivative of `directional_calls` (both made continuous), while `<Derivatives>` lists
/// the two state derivatives only. The library is vdp.c's: it refuses nx other than 2
/// and a directional derivative of anything but a state derivative with respect to a
/// state. As `<dir>/vdp.fmu`.
pub fn build_vdp_with_a_derivative_of_no_state(dir: &Path) -> PathBuf {
    let xml = include_str!("../cfmu/vdp.xml")
        .replace(
            r#"<ScalarVariable name="directional_calls" valueReference="5"><Real/></ScalarVariable>"#,
            r#"<ScalarVariable name="directional_calls" valueReference="5" variability="continuous"><Real/></ScalarVariable>"#,
        )
        .replace(
            r#"<ScalarVariable name="derivative_calls" valueReference="6"><Real/></ScalarVariable>"#,
            r#"<ScalarVariable name="derivative_calls" valueReference="6" variability="continuous"><Real derivative="6"/></ScalarVariable>"#,
        );
    assert!(xml.contains(r#"derivative="6""#));
    build_single_c_fmu(dir, "vdp", &xml)
}

/// [`build_vdp`] built with `-DWRONG_JACOBIAN`: its fmi2GetDirectionalDerivative gives
/// twice every partial derivative (a wrong Jacobian that is otherwise well-behaved), as
/// `<dir>/vdp.fmu`.
pub fn build_vdp_with_a_wrong_jacobian(dir: &Path) -> PathBuf {
    build_single_c_fmu_with_flags(dir, "vdp", include_str!("../cfmu/vdp.xml"), &["-DWRONG_JACOBIAN"])
}

/// [`build_vdp`] built with `flag`, `-DOVERRUN_OWN_BLOCK` (its fmi2GetDirectionalDerivative
/// writes 16 bytes past a block of 16 it allocated through allocateMemory) or
/// `-DOVERRUN_DV_UNKNOWN` (it writes two values past dvUnknown), as `<dir>/vdp.fmu`.
pub fn build_vdp_with_an_overrun(dir: &Path, flag: &str) -> PathBuf {
    build_single_c_fmu_with_flags(dir, "vdp", include_str!("../cfmu/vdp.xml"), &[flag])
}

/// The Co-Simulation FMU that reports the tolerance of fmi2SetupExperiment
/// (tests/cfmu/tolerance.c) as `<dir>/tolerance.fmu`; `default_tolerance` is its
/// DefaultExperiment's tolerance attribute (`None`: no attribute).
pub fn build_tolerance(dir: &Path, default_tolerance: Option<&str>) -> PathBuf {
    let tolerance = default_tolerance.map(|t| format!(r#" tolerance="{t}""#)).unwrap_or_default();
    let xml = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="tolerance" guid="{{tolerance}}" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="tolerance"/>
  <DefaultExperiment startTime="0" stopTime="0.1" stepSize="0.05"{tolerance}/>
  <ModelVariables>
    <ScalarVariable name="told_tolerance" valueReference="0" causality="output" variability="discrete"><Real/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output"><Real/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="1" dependencies=""/><Unknown index="2" dependencies=""/></Outputs></ModelStructure>
</fmiModelDescription>
"#
    );
    build_single_c_fmu(dir, "tolerance", &xml)
}

/// Builds `<dir>/<stem>.fmu` from the FMI 3.0 test FMU tests/cfmu/fmi3_counter.c with `xml` as its description.
pub fn build_counter(dir: &Path, stem: &str, xml: &str) -> Option<PathBuf> {
    build_counter_with(dir, stem, xml, &[])
}

/// [`build_counter`] with the preprocessor `defines` (`BIG=N`: the size of the large arrays).
pub fn build_counter_with(dir: &Path, stem: &str, xml: &str, defines: &[&str]) -> Option<PathBuf> {
    fmi3_c::build_named(dir, "fmi3_counter", stem, xml, defines)
}

/// The FMI 3.0 test FMU's description (tests/cfmu/fmi3_counter.xml) with the large array
/// outputs `arrays` (of `big` Float64, `bigi` Int32, `bigb` Boolean, `bigw` Int64 with its
/// read counter `bigw_reads`) of `n` elements each (fmi3_counter.c built with `-DBIG=n`).
pub fn counter_xml_with_large_arrays(n: usize, arrays: &[&str]) -> String {
    let xml = include_str!("../cfmu/fmi3_counter.xml");
    let arr = r#"<Float64 name="arr" valueReference="24" causality="output"><Dimension start="3"/></Float64>"#;
    assert!(xml.contains(arr));
    let mut declared = arr.to_string();
    for (name, ty, vr) in
        [("big", "Float64", 40), ("bigi", "Int32", 41), ("bigb", "Boolean", 42), ("bigw", "Int64", 43)]
    {
        if arrays.contains(&name) {
            declared.push_str(&format!(
                r#"
    <{ty} name="{name}" valueReference="{vr}" causality="output"><Dimension start="{n}"/></{ty}>"#
            ));
        }
    }
    if arrays.contains(&"bigw") {
        declared.push_str(
            r#"
    <Int32 name="bigw_reads" valueReference="44" causality="output" variability="discrete"/>"#,
        );
    }
    xml.replace(arr, &declared)
}

/// Asserts that the latch `counter` (tests/cfmu/latch.c) of the result `r`, coupled to the
/// ball, has counted each of the ball's bounces at the `bounces` times (`[first, second]`)
/// themselves: count and t_last change within the event, at the bounce time.
pub fn assert_counted_at_bounces(r: &nigel_cosim::Results, bounces: &[f64], what: &str) {
    let (t, count, t_last) =
        (r.column("time").unwrap(), r.column("counter.count").unwrap(), r.column("counter.t_last").unwrap());
    for k in 0..t.len() {
        let (n, last) = if t[k] >= bounces[1] {
            (2.0, bounces[1])
        } else if t[k] >= bounces[0] {
            (1.0, bounces[0])
        } else {
            (0.0, 0.0)
        };
        assert_eq!((count[k], t_last[k]), (n, last), "{what}: at t = {}", t[k]);
    }
}

/// Every instance in a host process of its own (`--isolate`), the host the one this
/// package builds (`option_env!`: the campaign's tests include this module and build no host).
pub fn isolate_all() -> nigel_cosim::Isolation {
    nigel_cosim::Isolation {
        instances: None,
        call_timeout: None,
        host: option_env!("CARGO_BIN_EXE_cosim-host").map(PathBuf::from),
    }
}

//! `build-fmu`: builds every FMU of the workspace into `target/fmu/`, two archives per FMU
//! with a library for each platform built (FMI 2.0 `target/fmu/<id>.fmu` and FMI 3.0
//! `target/fmu/fmi3/<id>.fmu`, the same library files), and a `manifest.json` listing them.
//!
//! Usage: `cargo run --release -p build-fmu -- [--platforms LIST|all] [--this-glibc] [OUT_DIR]`, `--list`
//! to print the manifest without building, `--help` for the options.
//!
//! After the archives it writes the closed loop of the paper's Table III as an SSP 1.0
//! archive, `OUT_DIR/../ssp/nigel_closed_loop.ssp` (`target/ssp/` by default): plant,
//! controller and test bench with every connection, parameters for the sim column,
//! lane change, robust controller, seed 0 (`table3 --ssp PATH --ssp-job COLUMN/MANEUVER/CONTROLLER`
//! writes any other job), and the same closed loop of the FMI 3.0 archives,
//! `nigel_closed_loop_fmi3.ssp`.

use std::path::PathBuf;
use std::process::ExitCode;

use build_fmu::{Platform, PlatformBuild};
use clap::Parser;

/// The job the closed-loop SSP is parameterized for.
const CLOSED_LOOP_JOB: &str = "sim/lane_change/robust";

/// Builds the nigel FMUs (plant, controller, maneuver test bench): an FMI 2.0 and an FMI 3.0
/// .fmu per model (target/fmu/ID.fmu, target/fmu/fmi3/ID.fmu) with a library for each
/// platform, byte-identical on rebuild, plus target/fmu/manifest.json and the closed loop as
/// target/ssp/nigel_closed_loop.ssp and target/ssp/nigel_closed_loop_fmi3.ssp.
#[derive(Parser)]
#[command(name = "build-fmu")]
struct Args {
    /// Platforms to build, comma-separated: linux64, win64, aarch64-linux, darwin64, or
    /// `all` (the default: the release archives). A missing cross toolchain is an error
    /// naming it (`bash scripts/setup-cross.sh` installs them all); an archive with fewer
    /// platforms says so in the manifest and its documentation.
    #[arg(long, value_name = "LIST", default_value = "all")]
    platforms: String,
    /// Build linux64 with this machine's own toolchain when cargo-zigbuild is missing: the
    /// library then needs this machine's glibc or later rather than 2.17, is not the
    /// release recipe the test command tests, and the manifest says so.
    #[arg(long)]
    this_glibc: bool,
    /// Print the manifest (model identifiers, packages, interfaces, platforms) without building.
    #[arg(long)]
    list: bool,
    /// Output folder of the archives [default: target/fmu].
    out_dir: Option<PathBuf>,
}

/// The platforms to build from `--platforms` (`all` or a list), and the notes to print.
fn choose(list: &str, this_glibc: bool) -> Result<(Vec<Platform>, Vec<String>), String> {
    let chosen: Vec<Platform> = if list == "all" {
        Platform::ALL.to_vec()
    } else {
        let mut v = Vec::new();
        for name in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let p = Platform::from_folder(name).ok_or_else(|| {
                let known: Vec<&str> = Platform::ALL.iter().map(|p| p.folder()).collect();
                format!("--platforms: unknown platform {name:?} (known: {}, or all)", known.join(", "))
            })?;
            if !v.contains(&p) {
                v.push(p);
            }
        }
        v.sort();
        v
    };
    if chosen.is_empty() {
        return Err("--platforms: no platform given".into());
    }
    let mut notes = Vec::new();
    let mut missing = Vec::new();
    for p in &chosen {
        match p.missing_toolchain() {
            Some(_) if *p == Platform::Linux64 && this_glibc => notes.push(
                "linux64 is built with this machine's toolchain (--this-glibc): it needs this machine's glibc or later"
                    .to_string(),
            ),
            Some(m) => missing.push(format!("{} needs {m}", p.folder())),
            None => {}
        }
    }
    if !missing.is_empty() {
        return Err(format!(
            "--platforms {list}: {}; `bash scripts/setup-cross.sh` installs every cross toolchain, \
             or name fewer platforms (e.g. --platforms linux64)",
            missing.join("; ")
        ));
    }
    if chosen.len() < Platform::ALL.len() {
        let left: Vec<&str> = Platform::ALL.iter().filter(|p| !chosen.contains(p)).map(|p| p.folder()).collect();
        notes.push(format!("not a release build: the archives lack {} (the manifest says so)", left.join(", ")));
    }
    Ok((chosen, notes))
}

/// The end of an archive's `built ...` line: its interfaces and its platform folders.
fn interfaces_and_platforms(target: &build_fmu::FmuTarget, platforms: &str) -> String {
    format!("interfaces: {}, platforms: {platforms}", target.interfaces().join(" "))
}

fn main() -> ExitCode {
    let args = Args::parse();
    let targets = build_fmu::targets();
    let (platforms, skipped) = match choose(&args.platforms, args.this_glibc) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("build-fmu: {e}");
            return ExitCode::FAILURE;
        }
    };
    if args.list {
        let builds: Vec<PlatformBuild> = platforms.iter().copied().map(PlatformBuild::of).collect();
        print!("{}", build_fmu::manifest(&targets, &builds));
        return ExitCode::SUCCESS;
    }
    for note in &skipped {
        eprintln!("build-fmu: {note}");
    }
    let out_dir = args.out_dir.unwrap_or_else(|| build_fmu::target_dir().join("fmu"));
    let names: Vec<&str> = platforms.iter().map(|p| p.folder()).collect();
    eprintln!("build-fmu: building {} for {}", targets.len(), names.join(", "));
    let build_fmu::Built { archives: written, archives3, platforms: builds } =
        match build_fmu::build_all(&targets, &platforms, &out_dir, &mut |m| eprintln!("build-fmu: {m}")) {
            Ok(w) => w,
            Err(e) => {
                eprintln!("build-fmu: {e}");
                return ExitCode::FAILURE;
            }
        };
    let fmi3_folders = platforms.iter().flat_map(|p| p.fmi3_folders()).copied().collect::<Vec<_>>().join(" ");
    for (target, (path, size)) in targets.iter().zip(&written) {
        let md = target.description;
        let what = format!("{} variables, GUID {}", md.model_variables.len(), md.guid);
        println!(
            "built {} ({size} bytes): {what}, {}",
            path.display(),
            interfaces_and_platforms(target, &names.join(" "))
        );
    }
    for (target, (path, size)) in targets.iter().zip(&archives3) {
        let md = target.description3;
        let what =
            format!("FMI 3.0, {} variables, instantiationToken {}", md.model_variables.len(), md.instantiation_token);
        println!(
            "built {} ({size} bytes): {what}, {}",
            path.display(),
            interfaces_and_platforms(target, &fmi3_folders)
        );
    }
    let manifest_path = out_dir.join("manifest.json");
    if let Err(e) = std::fs::write(&manifest_path, build_fmu::manifest(&targets, &builds)) {
        eprintln!("build-fmu: {}: {e}", manifest_path.display());
        return ExitCode::FAILURE;
    }
    println!("wrote {}", manifest_path.display());
    if !platforms.contains(&Platform::Linux64) {
        println!("no closed-loop SSP: writing it loads the linux64 libraries, which were not built");
        return ExitCode::SUCCESS;
    }
    let ssp_path = out_dir.parent().unwrap_or(&out_dir).join("ssp").join("nigel_closed_loop.ssp");
    match build_fmu::write_closed_loop_ssp(&out_dir, CLOSED_LOOP_JOB, 0, &ssp_path) {
        Ok(()) => println!("wrote {} ({CLOSED_LOOP_JOB}, seed 0)", ssp_path.display()),
        Err(e) => {
            eprintln!("build-fmu: {e}");
            return ExitCode::FAILURE;
        }
    }
    let ssp3_path = ssp_path.with_file_name("nigel_closed_loop_fmi3.ssp");
    match build_fmu::write_closed_loop_ssp_fmi3(&ssp_path, &out_dir, &ssp3_path) {
        Ok(()) => println!("wrote {} (the same closed loop of the FMI 3.0 archives)", ssp3_path.display()),
        Err(e) => {
            eprintln!("build-fmu: {e}");
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}

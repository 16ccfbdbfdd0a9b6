//! `build-fmu`: builds every FMU of the workspace into `target/fmu/`, one archive per FMU
//! with a library for each platform built, and a `manifest.json` listing them.
//!
//! Usage: `cargo run --release -p build-fmu -- [--platforms LIST|all] [OUT_DIR]`, `--list`
//! to print the manifest without building, `--help` for the options.
//!
//! After the archives it writes the closed loop of the paper's Table III as an SSP 1.0
//! archive, `OUT_DIR/../ssp/nigel_closed_loop.ssp` (`target/ssp/` by default): plant,
//! controller and test bench with every connection, parameters for the sim column,
//! lane change, robust controller, seed 0 (`table3 --ssp PATH --ssp-job COLUMN/MANEUVER/CONTROLLER`
//! writes any other job).

use std::path::PathBuf;
use std::process::ExitCode;

use build_fmu::{Platform, PlatformBuild};
use clap::Parser;

/// The job the closed-loop SSP is parameterized for.
const CLOSED_LOOP_JOB: &str = "sim/lane_change/robust";

/// Builds the nigel FMUs (plant, controller, maneuver test bench): one .fmu per model with
/// a library for each platform, byte-identical on rebuild, plus target/fmu/manifest.json and
/// the closed loop as target/ssp/nigel_closed_loop.ssp.
#[derive(Parser)]
#[command(name = "build-fmu")]
struct Args {
    /// Platforms to build, comma-separated: linux64, win64, aarch64-linux, darwin64, or
    /// `all` (an error when a toolchain is missing). Default: every platform whose
    /// toolchain is installed (linux64 always, with the build machine's glibc when
    /// cargo-zigbuild is missing); the others are skipped with a note saying how to install
    /// them (`bash scripts/setup-cross.sh`).
    #[arg(long, value_name = "LIST")]
    platforms: Option<String>,
    /// Print the manifest (model identifiers, packages, interfaces, platforms) without building.
    #[arg(long)]
    list: bool,
    /// Output folder of the archives [default: target/fmu].
    out_dir: Option<PathBuf>,
}

/// The platforms to build, and what was skipped (with why), from `--platforms`.
fn choose(list: Option<&str>) -> Result<(Vec<Platform>, Vec<String>), String> {
    let Some(list) = list else {
        let mut chosen = vec![Platform::Linux64];
        let mut skipped = Vec::new();
        if let Some(missing) = Platform::Linux64.missing_toolchain() {
            skipped.push(format!(
                "linux64 is built with this machine's toolchain, so it needs this machine's glibc or later (missing for the glibc 2.17 baseline: {missing})"
            ));
        }
        for p in &Platform::ALL[1..] {
            match p.missing_toolchain() {
                None => chosen.push(*p),
                Some(missing) => skipped.push(format!("{} skipped: missing {missing}", p.folder())),
            }
        }
        return Ok((chosen, skipped));
    };
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
    for p in &chosen {
        if let Some(missing) = p.missing_toolchain() {
            return Err(format!("--platforms: {} needs {missing}", p.folder()));
        }
    }
    Ok((chosen, Vec::new()))
}

fn main() -> ExitCode {
    let args = Args::parse();
    let targets = build_fmu::targets();
    let (platforms, skipped) = match choose(args.platforms.as_deref()) {
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
    let build_fmu::Built { archives: written, platforms: builds } =
        match build_fmu::build_all(&targets, &platforms, &out_dir, &mut |m| eprintln!("build-fmu: {m}")) {
            Ok(w) => w,
            Err(e) => {
                eprintln!("build-fmu: {e}");
                return ExitCode::FAILURE;
            }
        };
    for (target, (path, size)) in targets.iter().zip(&written) {
        let md = target.description;
        println!(
            "built {} ({} bytes): {} variables, GUID {}, interfaces: {}, platforms: {}",
            path.display(),
            size,
            md.model_variables.len(),
            md.guid,
            target.interfaces().join(" "),
            names.join(" "),
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
    ExitCode::SUCCESS
}

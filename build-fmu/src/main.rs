//! `build-fmu`: builds every FMU of the workspace into `target/fmu/`, with a
//! `manifest.json` listing them.
//!
//! Usage: `cargo run --release -p build-fmu [-- OUT_DIR]`, or `-- --list` to print the
//! manifest (model identifiers, packages, interfaces) without building.
//!
//! After the archives it writes the closed loop of the paper's Table III as an SSP 1.0
//! archive, `OUT_DIR/../ssp/nigel_closed_loop.ssp` (`target/ssp/` by default): plant,
//! controller and test bench with every connection, parameters for the sim column,
//! lane change, robust controller, seed 0 (`table3 --ssp PATH --ssp-job COLUMN/MANEUVER/CONTROLLER`
//! writes any other job).

use std::process::ExitCode;

/// The job the closed-loop SSP is parameterized for.
const CLOSED_LOOP_JOB: &str = "sim/lane_change/robust";

fn main() -> ExitCode {
    let targets = build_fmu::targets();
    let arg = std::env::args_os().nth(1);
    if arg.as_deref() == Some(std::ffi::OsStr::new("--list")) {
        print!("{}", build_fmu::manifest(&targets));
        return ExitCode::SUCCESS;
    }
    let out_dir = arg.map(std::path::PathBuf::from).unwrap_or_else(|| build_fmu::target_dir().join("fmu"));
    for target in &targets {
        match build_fmu::build(target, &out_dir) {
            Ok((path, size)) => {
                let md = target.description;
                println!(
                    "built {} ({} bytes): {} variables, GUID {}, interfaces: {}",
                    path.display(),
                    size,
                    md.model_variables.len(),
                    md.guid,
                    target.interfaces().join(" "),
                );
            }
            Err(e) => {
                eprintln!("build-fmu: {}: {e}", target.model_identifier);
                return ExitCode::FAILURE;
            }
        }
    }
    let manifest_path = out_dir.join("manifest.json");
    if let Err(e) = std::fs::write(&manifest_path, build_fmu::manifest(&targets)) {
        eprintln!("build-fmu: {}: {e}", manifest_path.display());
        return ExitCode::FAILURE;
    }
    println!("wrote {}", manifest_path.display());
    let ssp_path = out_dir.parent().unwrap_or(&out_dir).join("ssp").join("nigel_closed_loop.ssp");
    let written = nigel_table3::parse_job(CLOSED_LOOP_JOB, 0)
        .and_then(|job| nigel_table3::FmuEngine::load_dir(&out_dir)?.write_ssp(&job, &ssp_path));
    match written {
        Ok(()) => println!("wrote {} ({CLOSED_LOOP_JOB}, seed 0)", ssp_path.display()),
        Err(e) => {
            eprintln!("build-fmu: {}: {e}", ssp_path.display());
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}

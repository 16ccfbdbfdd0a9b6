//! `build-fmu`: builds every FMU of the workspace into `target/fmu/`, with a
//! `manifest.json` listing them.
//!
//! Usage: `cargo run --release -p build-fmu [-- OUT_DIR]`, or `-- --list` to print the
//! manifest (model identifiers, packages, interfaces) without building.

use std::process::ExitCode;

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
    ExitCode::SUCCESS
}

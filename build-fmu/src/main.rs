//! `build-fmu`: builds every FMU of the workspace into `target/fmu/`.
//!
//! Usage: `cargo run --release -p build-fmu [-- OUT_DIR]`

use std::process::ExitCode;

fn main() -> ExitCode {
    let out_dir =
        std::env::args_os().nth(1).map(std::path::PathBuf::from).unwrap_or_else(|| build_fmu::target_dir().join("fmu"));
    for target in build_fmu::targets() {
        match build_fmu::build(&target, &out_dir) {
            Ok((path, size)) => {
                let md = (target.description)();
                println!(
                    "built {} ({} bytes): {} variables, GUID {}, interfaces:{}{}",
                    path.display(),
                    size,
                    md.model_variables.len(),
                    md.guid,
                    if md.co_simulation.is_some() { " CoSimulation" } else { "" },
                    if md.model_exchange.is_some() { " ModelExchange" } else { "" },
                );
            }
            Err(e) => {
                eprintln!("build-fmu: {}: {e}", target.model_identifier);
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}

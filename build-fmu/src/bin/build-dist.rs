//! `build-dist`: builds the master's programs (`cosim`, `cosim-host`, `campaign`) for every
//! release platform with the FMUs' recipes ([`build_fmu::Platform::build_programs`]: the same
//! toolchains and target directories) and lays each platform's out in
//! `OUT/cosim-<version>-<triple>/` with the licenses; `scripts/dist.sh` archives them.
//!
//! Usage: `cargo run --release -p build-fmu --bin build-dist -- [--platforms LIST|all] [OUT]`
//! (OUT: `target/dist/stage` by default). Prints each folder it wrote, one a line.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use build_fmu::Platform;
use clap::Parser;

/// The packages and programs of the master.
const PACKAGES: [&str; 2] = ["nigel-cosim", "nigel-campaign"];
const PROGRAMS: [&str; 3] = ["cosim", "cosim-host", "campaign"];

/// Builds cosim, cosim-host and campaign for the release platforms into one folder each.
#[derive(Parser)]
#[command(name = "build-dist")]
struct Args {
    /// Platforms, comma-separated (linux64, win64, aarch64-linux, darwin64: x86_64 and
    /// aarch64 macOS), or `all`.
    #[arg(long, value_name = "LIST", default_value = "all")]
    platforms: String,
    /// Where the folders go [default: target/dist/stage].
    out: Option<PathBuf>,
}

fn copy(from: &Path, to: &Path) -> Result<(), String> {
    std::fs::copy(from, to).map(|_| ()).map_err(|e| format!("copying {} to {}: {e}", from.display(), to.display()))
}

fn main() -> ExitCode {
    let args = Args::parse();
    let platforms: Vec<Platform> = if args.platforms == "all" {
        Platform::ALL.to_vec()
    } else {
        let mut v = Vec::new();
        for name in args.platforms.split(',') {
            match Platform::from_folder(name.trim()) {
                Some(p) => v.push(p),
                None => {
                    eprintln!("build-dist: --platforms: unknown platform {name:?}");
                    return ExitCode::from(2);
                }
            }
        }
        v
    };
    let target = build_fmu::target_dir();
    let out = args.out.unwrap_or_else(|| target.join("dist").join("stage"));
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let version = env!("CARGO_PKG_VERSION");
    for platform in platforms {
        if let Some(missing) = platform.missing_toolchain() {
            eprintln!("build-dist: {}: {missing}", platform.folder());
            return ExitCode::FAILURE;
        }
        eprintln!("build-dist: building {} for {}", PROGRAMS.join(", "), platform.folder());
        let built = match platform.build_programs(&PACKAGES, &PROGRAMS, &target) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("build-dist: {e}");
                return ExitCode::FAILURE;
            }
        };
        for (triple, programs) in built {
            let folder = out.join(format!("cosim-{version}-{triple}"));
            let _ = std::fs::remove_dir_all(&folder);
            let result = std::fs::create_dir_all(&folder)
                .map_err(|e| format!("{}: {e}", folder.display()))
                .and_then(|()| {
                    programs.iter().try_for_each(|p| copy(p, &folder.join(p.file_name().unwrap_or_default())))
                })
                .and_then(|()| {
                    ["LICENSE-MIT", "LICENSE-APACHE"].iter().try_for_each(|l| copy(&repo.join(l), &folder.join(l)))
                });
            if let Err(e) = result {
                eprintln!("build-dist: {e}");
                return ExitCode::FAILURE;
            }
            println!("{}", folder.display());
        }
    }
    ExitCode::SUCCESS
}

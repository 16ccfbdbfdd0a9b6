//! What the campaign test binaries share: where the repository and its target folder are,
//! the `campaign run` command and writing a spec.
#![allow(dead_code)] // not every test binary uses every helper

use std::path::{Path, PathBuf};

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").canonicalize().unwrap()
}

/// The workspace's target folder (`CARGO_TARGET_DIR`, relative to the root when relative).
pub fn target_dir() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(t) if Path::new(&t).is_absolute() => PathBuf::from(t),
        Some(t) => root().join(t),
        None => root().join("target"),
    }
}

/// The command `campaign run SPEC --out OUT`, to which a test adds its other arguments.
pub fn campaign_run(spec: &Path, out: &Path) -> std::process::Command {
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_campaign"));
    command.arg("run").arg(spec).arg("--out").arg(out);
    command
}

/// Writes the campaign spec `path`: `system = "<system>"`, then `rest` (TOML).
pub fn write_spec(path: &Path, system: &Path, rest: &str) {
    std::fs::write(path, format!("system = {:?}\n{rest}", system.display().to_string())).unwrap();
}

//! This build's platform as FMU archives name it: the folder under `binaries/` whose library
//! a run in this process loads (FMI 2.0 section 2.4: `linux64`, `win64`, `darwin64`; FMI 3.0
//! section 2.5.1.1: `<arch>-<os>`), and the library's file extension. FMI 2.0 names no ARM
//! platform: on 64-bit ARM Linux the FMI 3.0 name `aarch64-linux` is used for both
//! generations (as our archives and other exporters' do); a macOS build of either
//! architecture loads FMI 2.0's `darwin64`, a universal library or one of its own
//! architecture.

/// (FMI 2.0 folder, FMI 3.0 folder) of this build.
#[cfg(all(target_os = "linux", target_arch = "x86_64"))]
const NAMES: (&str, &str) = ("linux64", "x86_64-linux");
#[cfg(all(target_os = "linux", target_arch = "aarch64"))]
const NAMES: (&str, &str) = ("aarch64-linux", "aarch64-linux");
#[cfg(all(target_os = "windows", target_arch = "x86_64"))]
const NAMES: (&str, &str) = ("win64", "x86_64-windows");
#[cfg(all(target_os = "macos", target_arch = "x86_64"))]
const NAMES: (&str, &str) = ("darwin64", "x86_64-darwin");
#[cfg(all(target_os = "macos", target_arch = "aarch64"))]
const NAMES: (&str, &str) = ("darwin64", "aarch64-darwin");

/// The FMI 2.0 platform folder of this build (`binaries/<folder>/`).
pub const FMI2_FOLDER: &str = NAMES.0;
/// The FMI 3.0 platform folder of this build.
pub const FMI3_FOLDER: &str = NAMES.1;
/// The extension of an FMU's library here: `so`, `dll` or `dylib`.
pub const LIBRARY_EXTENSION: &str = std::env::consts::DLL_EXTENSION;

/// Checks the library's structure before it is loaded where a malformed file can crash the
/// loader (ELF: [`crate::elf::check_shared_library`]); Windows' and macOS' loaders refuse a
/// malformed PE or Mach-O file with an error, which the load reports.
pub fn check_library(bytes: &[u8]) -> Result<(), String> {
    if cfg!(target_os = "linux") {
        crate::elf::check_shared_library(bytes)
    } else {
        Ok(())
    }
}

/// The names the library exports, where they can be read without loading it (ELF); `None`
/// elsewhere (every function is then taken as present).
pub fn exported_symbols(bytes: &[u8]) -> Option<std::collections::HashSet<String>> {
    if cfg!(target_os = "linux") {
        crate::elf::exported_symbols(bytes)
    } else {
        None
    }
}

//! The platforms an archive carries: how each is built, what it needs on the user's machine
//! and how it is tested.
//!
//! | folder          | built with                                                         |
//! |-----------------|--------------------------------------------------------------------|
//! | `linux64`       | `cargo zigbuild --target x86_64-unknown-linux-gnu.2.17` (glibc 2.17 symbol versions) |
//! | `win64`         | Debian's `rustc-web`, `-Zbuild-std`, `x86_64-pc-windows-gnu`, linker `x86_64-w64-mingw32-gcc`, `llvm-strip` |
//! | `aarch64-linux` | `rustc-web` with `libstd-rust-web-dev:arm64`, `cargo zigbuild --target aarch64-unknown-linux-gnu.2.17` |
//! | `darwin64`      | `rustc-web`, `-Zbuild-std`, `cargo zigbuild` for x86_64 and arm64 (macOS 11), `llvm-lipo` |
//!
//! The platforms other than the host's own need Rust's standard library for their target.
//! `rustup target add` is not relied on: Debian ships the standard library's source
//! (`rust-web-src`), which cargo builds for any target with `-Zbuild-std`
//! (`RUSTC_BOOTSTRAP=1` allows that unstable flag on the stable compiler), and the
//! prebuilt arm64 library (`libstd-rust-web-dev:arm64`). `scripts/setup-cross.sh`
//! installs all of it.
//!
//! Each platform builds all FMU packages in one cargo invocation into a target directory
//! cargo keeps incremental: a rebuild with nothing changed compiles nothing.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::BuildError;

/// A platform folder of the archive (`binaries/<folder>/`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Platform {
    /// x86-64 Linux, glibc 2.17 or later.
    Linux64,
    /// x86-64 Windows.
    Win64,
    /// 64-bit ARM Linux (FMI 3's name; FMI 2 names no ARM platform, and importers that do
    /// not know the folder ignore it).
    Aarch64Linux,
    /// macOS, one universal library for x86-64 and arm64.
    Darwin64,
}

/// Deployment target of the darwin64 libraries (the `minos` of their `LC_BUILD_VERSION`).
pub const MACOS_MINIMUM: &str = "11.0";

/// The sysroot of Debian's rustc-web (`/usr/bin/rustc`, `/usr/bin/cargo`): its `lib/rustlib`
/// holds the standard library's sources (rust-web-src) and the arm64 standard library.
const RUST_WEB: &str = "/usr";

/// The rustc-web target triples as cargo names them, with the zigbuild suffix where the
/// glibc baseline is chosen through the triple.
const LINUX64_TRIPLE: &str = "x86_64-unknown-linux-gnu";
const WIN64_TRIPLE: &str = "x86_64-pc-windows-gnu";
const AARCH64_TRIPLE: &str = "aarch64-unknown-linux-gnu";
const DARWIN_TRIPLES: [&str; 2] = ["x86_64-apple-darwin", "aarch64-apple-darwin"];
const GLIBC_BASELINE: &str = "2.17";

impl Platform {
    /// Every platform, in the archive's order.
    pub const ALL: [Platform; 4] = [Platform::Linux64, Platform::Win64, Platform::Aarch64Linux, Platform::Darwin64];

    /// The folder name under `binaries/`.
    pub fn folder(self) -> &'static str {
        match self {
            Platform::Linux64 => "linux64",
            Platform::Win64 => "win64",
            Platform::Aarch64Linux => "aarch64-linux",
            Platform::Darwin64 => "darwin64",
        }
    }

    /// The FMI 3.0 platform folders (`<arch>-<os>`, FMI 3.0 section 2.5.1.1) of this
    /// platform's library: the darwin64 universal library's two slices go to the two Mac
    /// folders ([`Platform::fmi3_library`]).
    pub fn fmi3_folders(self) -> &'static [&'static str] {
        match self {
            Platform::Linux64 => &["x86_64-linux"],
            Platform::Win64 => &["x86_64-windows"],
            Platform::Aarch64Linux => &["aarch64-linux"],
            Platform::Darwin64 => &["x86_64-darwin", "aarch64-darwin"],
        }
    }

    /// What the FMI 3.0 platform folder `folder` carries of this platform's `library`: the
    /// thin slice of the folder's architecture for the darwin64 universal library (FMI 3.0
    /// names one architecture per folder), the library itself for the others.
    pub fn fmi3_library<'a>(self, folder: &str, library: &'a [u8]) -> Result<&'a [u8], String> {
        match (self, folder) {
            (Platform::Darwin64, "x86_64-darwin") => thin_slice(library, CPU_TYPE_X86_64),
            (Platform::Darwin64, "aarch64-darwin") => thin_slice(library, CPU_TYPE_ARM64),
            _ => Ok(library),
        }
    }

    /// The platform of a folder name.
    pub fn from_folder(name: &str) -> Option<Platform> {
        Platform::ALL.into_iter().find(|p| p.folder() == name)
    }

    /// The library's file name in the archive, `<modelIdentifier>.<so|dll|dylib>`.
    pub fn library_file(self, model_identifier: &str) -> String {
        format!("{model_identifier}.{}", self.extension())
    }

    fn extension(self) -> &'static str {
        match self {
            Platform::Linux64 | Platform::Aarch64Linux => "so",
            Platform::Win64 => "dll",
            Platform::Darwin64 => "dylib",
        }
    }

    /// What the library needs on the user's machine.
    pub fn minimum_os(self) -> &'static str {
        match self {
            Platform::Linux64 => {
                "x86-64 Linux with glibc 2.17 or later (RHEL/CentOS 7 and later, Ubuntu 14.04 and later, Debian 8 and later)"
            }
            Platform::Win64 => {
                "64-bit Windows 10 or later (the Rust standard library calls ProcessPrng of bcryptprimitives.dll); no runtime to install"
            }
            Platform::Aarch64Linux => "64-bit ARM Linux with glibc 2.17 or later",
            Platform::Darwin64 => {
                "macOS 11 or later, Intel or Apple silicon (darwin64: one universal library; FMI 3.0: \
                 each folder the slice of its architecture)"
            }
        }
    }

    /// The C library the binary links against.
    pub fn c_library(self) -> &'static str {
        match self {
            Platform::Linux64 | Platform::Aarch64Linux => "glibc 2.17 (no symbol version above GLIBC_2.17)",
            Platform::Win64 => "msvcrt.dll (the C runtime of every Windows); system DLLs only",
            Platform::Darwin64 => "libSystem.B.dylib (system library only)",
        }
    }

    /// How the project's test command (`bash scripts/test.sh`) tests the platform's library
    /// as this recipe builds it (byte-identical on every build from the same sources).
    pub fn tested(self) -> &'static str {
        match self {
            Platform::Linux64 => {
                "by the test command, on this recipe's library: executed: every test of the workspace, fmpy (validate_fmu, simulations) and the co-simulation \
                 cross-checks load this library; objdump -T checks the glibc symbol versions; the C FMI \
                 importer build-fmu/tests/c/fmi2_closed_loop.c runs the closed loop (plant, controller, test bench) 30 s at 1 ms as the reference"
            }
            Platform::Win64 => {
                "by the test command, on this recipe's library: executed under wine 8: the C FMI importer build-fmu/tests/c/fmi2_closed_loop.c, built with mingw-w64, runs the closed loop \
                 30 s at 1 ms and every output is compared with the linux64 run; exports and imported DLLs checked"
            }
            Platform::Aarch64Linux => {
                "by the test command, on this recipe's library: executed under qemu-user: the C FMI importer build-fmu/tests/c/fmi2_closed_loop.c, built with aarch64-linux-gnu-gcc, runs \
                 the closed loop 30 s at 1 ms and every output is compared with the linux64 run"
            }
            Platform::Darwin64 => {
                "by the test command, on this recipe's library: not executed (no macOS there): structural checks only, both architectures present, the 44 fmi2 \
                 exports, the minimum macOS version and only system libraries imported"
            }
        }
    }

    /// How the test command tests this platform's library through the FMI 3.0 archive (the
    /// same file as in the FMI 2.0 archive, [`Platform::tested`], called through its fmi3
    /// functions).
    pub fn tested_fmi3(self) -> &'static str {
        match self {
            Platform::Linux64 => {
                "by the test command, on this recipe's library: executed: fmpy (validate_fmu, Co-Simulation and Model \
                 Exchange against the FMI 2.0 archive) and the C FMI 3.0 importer build-fmu/tests/c/fmi3_closed_loop.c, \
                 which runs the closed loop (plant, controller, test bench) 30 s at 1 ms equal to the FMI 2.0 run bit for bit, \
                 and build-fmu/tests/c/me_fixed_step.c, the plant through Model Exchange (fixed-step RK4) equal to its \
                 FMI 2.0 Model Exchange run bit for bit"
            }
            Platform::Win64 => {
                "by the test command, on this recipe's library: executed under wine 8: the C FMI 3.0 importer \
                 build-fmu/tests/c/fmi3_closed_loop.c, built with mingw-w64, runs the closed loop 30 s at 1 ms, every \
                 output compared with the linux64 FMI 2.0 run and equal to the FMI 2.0 run of the same DLL bit for bit; \
                 build-fmu/tests/c/me_fixed_step.c runs the plant through Model Exchange equal to its FMI 2.0 run bit for bit"
            }
            Platform::Aarch64Linux => {
                "by the test command, on this recipe's library: executed under qemu-user: the C FMI 3.0 importer \
                 build-fmu/tests/c/fmi3_closed_loop.c, built with aarch64-linux-gnu-gcc, runs the closed loop 30 s at 1 ms, \
                 every output compared with the linux64 FMI 2.0 run and equal to the FMI 2.0 run of the same library bit for \
                 bit; build-fmu/tests/c/me_fixed_step.c runs the plant through Model Exchange equal to its FMI 2.0 run bit for bit"
            }
            Platform::Darwin64 => {
                "by the test command, on this recipe's library: not executed (no macOS there): structural checks only, \
                 each folder the thin slice of its architecture (the one llvm-lipo -thin extracts from the FMI 2.0 archive's \
                 universal library), the fmi3 exports, the minimum macOS version and only system libraries imported"
            }
        }
    }

    /// What is missing to build this platform here, with how to install it; `None` when
    /// everything is present.
    pub fn missing_toolchain(self) -> Option<String> {
        let zig = || find_tool("cargo-zigbuild").is_some() && zig_available();
        const ZIG: &str = "cargo-zigbuild and zig (PyPI: cargo-zigbuild, ziglang)";
        const RUST_WEB_SRC: &str = "rustc-web, cargo-web and rust-web-src (Debian)";
        // (present, what to install), in the order the message lists them
        let needs: Vec<(bool, &str)> = match self {
            Platform::Linux64 => vec![(zig(), ZIG)],
            Platform::Win64 => vec![
                (rust_web_src(), RUST_WEB_SRC),
                (
                    find_tool("x86_64-w64-mingw32-gcc").is_some(),
                    "x86_64-w64-mingw32-gcc (Debian: gcc-mingw-w64-x86-64)",
                ),
                (llvm_tool("llvm-strip").is_some(), "llvm-strip (Debian: llvm-22)"),
            ],
            Platform::Aarch64Linux => vec![
                (
                    Path::new(RUST_WEB).join("lib/rustlib").join(AARCH64_TRIPLE).is_dir() && rust_web_recent(),
                    "rustc-web, cargo-web and libstd-rust-web-dev:arm64 (Debian, arm64 added to dpkg)",
                ),
                (zig(), ZIG),
            ],
            Platform::Darwin64 => vec![
                (rust_web_src(), RUST_WEB_SRC),
                (zig(), ZIG),
                (llvm_tool("llvm-lipo").is_some(), "llvm-lipo (Debian: llvm-22)"),
                // rustc strips macOS libraries with this name for llvm-objcopy
                (
                    find_tool("rust-objcopy").is_some(),
                    "rust-objcopy (llvm-objcopy of llvm-22 under that name in target/cross-venv/bin)",
                ),
            ],
        };
        let missing: Vec<&str> = needs.into_iter().filter(|(present, _)| !present).map(|(_, what)| what).collect();
        if missing.is_empty() {
            None
        } else {
            Some(format!("{}; `bash scripts/setup-cross.sh` installs them", missing.join(", ")))
        }
    }

    /// The target triples of this platform's builds (darwin64: two, joined afterwards).
    pub fn triples(self) -> &'static [&'static str] {
        match self {
            Platform::Linux64 => &[LINUX64_TRIPLE],
            Platform::Win64 => &[WIN64_TRIPLE],
            Platform::Aarch64Linux => &[AARCH64_TRIPLE],
            Platform::Darwin64 => &DARWIN_TRIPLES,
        }
    }

    /// The one recipe of this platform: runs cargo (build, release profile) with `args`
    /// (packages, features, what to build) for its triples into its target directory under
    /// `target_dir`, and returns each triple's release folder. The FMUs' libraries
    /// ([`Platform::build`]) and the master's programs ([`Platform::build_programs`]) both
    /// come from here, into the same target directories, so that what they share compiles once.
    pub fn cargo_build(self, args: &[String], target_dir: &Path) -> Result<Vec<(&'static str, PathBuf)>, BuildError> {
        let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("Cargo.toml");
        let mut c = match self {
            Platform::Linux64 => zigbuild(&host_cargo()),
            Platform::Win64 => {
                let mut c = rust_web_cargo();
                c.arg("build").args(build_std());
                // no time stamp in the PE header: the binary is byte-identical on rebuild
                c.env("CARGO_TARGET_X86_64_PC_WINDOWS_GNU_LINKER", "x86_64-w64-mingw32-gcc")
                    .env("CARGO_TARGET_X86_64_PC_WINDOWS_GNU_RUSTFLAGS", "-C link-arg=-Wl,--no-insert-timestamp");
                c
            }
            Platform::Aarch64Linux => {
                let mut c = zigbuild(&rust_web_bin("cargo"));
                c.env("RUSTC", rust_web_bin("rustc"));
                c
            }
            Platform::Darwin64 => {
                let mut c = zigbuild(&rust_web_bin("cargo"));
                c.env("RUSTC", rust_web_bin("rustc")).env("MACOSX_DEPLOYMENT_TARGET", MACOS_MINIMUM).args(build_std());
                // a library's install name @rpath/lib<name>.dylib, not the path it was built at
                // (ld64's default): the same bytes from any folder, and no build path shipped
                for t in DARWIN_TRIPLES {
                    let var = format!("CARGO_TARGET_{}_RUSTFLAGS", t.to_uppercase().replace('-', "_"));
                    c.env(var, "-Zosx-rpath-install-name");
                }
                c
            }
        };
        c.args(["--release", "--quiet"]).args(args).arg("--manifest-path").arg(&manifest);
        for t in self.triples() {
            // the glibc baseline of the Linux platforms is chosen through zigbuild's triple
            let glibc = matches!(self, Platform::Linux64 | Platform::Aarch64Linux);
            let t = if glibc { format!("{t}.{GLIBC_BASELINE}") } else { t.to_string() };
            c.args(["--target", &t]);
        }
        // linux64 with the workspace's own toolchain into target/; the others with
        // rustc-web into target/rust-web (another compiler: artifacts kept apart)
        let dir = match self {
            Platform::Linux64 => target_dir.to_path_buf(),
            _ => target_dir.join("rust-web"),
        };
        c.arg("--target-dir").arg(&dir);
        run(c, self)?;
        Ok(self.triples().iter().map(|t| (*t, dir.join(t).join("release"))).collect())
    }

    /// Builds the programs (`[[bin]]`s) of `packages` for this platform ([`Platform::cargo_build`])
    /// and returns, per triple, the path of each program named in `programs`.
    pub fn build_programs(
        self,
        packages: &[&str],
        programs: &[&str],
        target_dir: &Path,
    ) -> Result<Vec<(&'static str, Vec<PathBuf>)>, BuildError> {
        let mut args: Vec<String> = vec!["--bins".into()];
        for p in packages {
            args.extend(["--package".into(), p.to_string()]);
        }
        let exe = if self == Platform::Win64 { ".exe" } else { "" };
        Ok(self
            .cargo_build(&args, target_dir)?
            .into_iter()
            .map(|(t, dir)| (t, programs.iter().map(|p| dir.join(format!("{p}{exe}"))).collect()))
            .collect())
    }

    /// Builds the libraries of `packages` (cargo packages; their `[lib] name`s are
    /// `model_identifiers`, in the same order) for this platform with their `fmi-export`
    /// feature, all in one cargo invocation, and returns each library's path.
    pub fn build(
        self,
        packages: &[&str],
        model_identifiers: &[&str],
        target_dir: &Path,
    ) -> Result<Vec<PathBuf>, BuildError> {
        let features = crate::library_features(packages);
        let mut args: Vec<String> = Vec::new();
        for p in packages {
            args.extend(["--package".into(), p.to_string()]);
        }
        args.extend(["--features".into(), features.join(",")]);
        let dirs = self.cargo_build(&args, target_dir)?;
        let lib = |dir: &Path, prefix: &str, id: &str| dir.join(format!("{prefix}{id}.{}", self.extension()));
        match self {
            Platform::Linux64 | Platform::Aarch64Linux => {
                Ok(model_identifiers.iter().map(|id| lib(&dirs[0].1, "lib", id)).collect())
            }
            Platform::Win64 => {
                // the symbol table out (2.4 MB -> 1.6 MB; the exports stay): llvm-strip
                // writes no time stamp, so the copy is byte-identical on rebuild
                let stripped_dir = target_dir.join("win64-stripped");
                std::fs::create_dir_all(&stripped_dir).map_err(|e| BuildError::Io(stripped_dir.clone(), e))?;
                let strip = llvm_tool("llvm-strip").ok_or_else(|| BuildError::Cargo("llvm-strip not found".into()))?;
                let mut out = Vec::new();
                for id in model_identifiers {
                    let (built, stripped) = (lib(&dirs[0].1, "", id), lib(&stripped_dir, "", id));
                    if !up_to_date(&stripped, std::slice::from_ref(&built)) {
                        let mut c = Command::new(&strip);
                        c.arg("--strip-all").arg("-o").arg(&stripped).arg(&built);
                        run(c, self)?;
                    }
                    out.push(stripped);
                }
                Ok(out)
            }
            Platform::Darwin64 => {
                let universal_dir = target_dir.join("darwin64-universal");
                std::fs::create_dir_all(&universal_dir).map_err(|e| BuildError::Io(universal_dir.clone(), e))?;
                let lipo = llvm_tool("llvm-lipo").ok_or_else(|| BuildError::Cargo("llvm-lipo not found".into()))?;
                let mut out = Vec::new();
                for id in model_identifiers {
                    let parts: Vec<PathBuf> = dirs.iter().map(|(_, dir)| lib(dir, "lib", id)).collect();
                    let universal = lib(&universal_dir, "lib", id);
                    if !up_to_date(&universal, &parts) {
                        let status = Command::new(&lipo)
                            .arg("-create")
                            .args(&parts)
                            .arg("-output")
                            .arg(&universal)
                            .status()
                            .map_err(|e| BuildError::Cargo(format!("llvm-lipo: {e}")))?;
                        if !status.success() {
                            return Err(BuildError::Cargo(format!("llvm-lipo exited with {status}")));
                        }
                    }
                    out.push(universal);
                }
                Ok(out)
            }
        }
    }
}

/// The Mach-O CPU types (`<mach/machine.h>`) of the two darwin64 architectures.
pub const CPU_TYPE_X86_64: u32 = 0x0100_0007;
pub const CPU_TYPE_ARM64: u32 = 0x0100_000c;
/// The magic of a universal ("fat") Mach-O file with 32-bit offsets, big-endian, as
/// `llvm-lipo -create` writes it (`<mach-o/fat.h>`).
const FAT_MAGIC: u32 = 0xcafe_babe;

/// The thin slice of CPU type `cpu` in the universal Mach-O file `universal`: its header
/// (magic, number of architectures), then one `fat_arch` per architecture (cputype,
/// cpusubtype, offset, size, align; 32-bit big-endian), the slices at their offsets.
pub fn thin_slice(universal: &[u8], cpu: u32) -> Result<&[u8], String> {
    let word = |at: usize| -> Result<u32, String> {
        universal
            .get(at..at + 4)
            .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| format!("universal library truncated at byte {at}"))
    };
    if word(0)? != FAT_MAGIC {
        return Err(format!("not a universal Mach-O library (magic {:#010x})", word(0)?));
    }
    let count = word(4)? as usize;
    for k in 0..count {
        let entry = 8 + 20 * k;
        if word(entry)? == cpu {
            let (offset, size) = (word(entry + 8)? as usize, word(entry + 12)? as usize);
            return universal
                .get(offset..offset + size)
                .ok_or_else(|| format!("the slice of CPU type {cpu:#x} ({size} bytes at {offset}) is past the end"));
        }
    }
    Err(format!("the universal library has no slice of CPU type {cpu:#x}"))
}

/// `-Zbuild-std` with the standard library's source from rust-web-src.
fn build_std() -> [&'static str; 1] {
    ["-Zbuild-std=std,panic_unwind"]
}

/// True when `output` exists and is newer than every input.
fn up_to_date(output: &Path, inputs: &[PathBuf]) -> bool {
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    match modified(output) {
        Some(out) => inputs.iter().all(|i| modified(i).is_some_and(|t| t <= out)),
        None => false,
    }
}

fn run(mut c: Command, platform: Platform) -> Result<(), BuildError> {
    let status = c.status().map_err(|e| BuildError::Cargo(format!("{}: {e}", platform.folder())))?;
    if status.success() {
        Ok(())
    } else {
        Err(BuildError::Cargo(format!("{}: cargo exited with {status}", platform.folder())))
    }
}

/// The cargo that runs build-fmu (the workspace's own toolchain).
fn host_cargo() -> PathBuf {
    std::env::var_os("CARGO").map(PathBuf::from).unwrap_or_else(|| "cargo".into())
}

fn rust_web_bin(name: &str) -> PathBuf {
    Path::new(RUST_WEB).join("bin").join(name)
}

/// Debian's cargo-web, allowed the unstable `-Zbuild-std`.
fn rust_web_cargo() -> Command {
    let mut c = Command::new(rust_web_bin("cargo"));
    c.env("RUSTC", rust_web_bin("rustc")).env("RUSTC_BOOTSTRAP", "1").env_remove("RUSTFLAGS");
    c
}

/// `cargo zigbuild` run through `cargo` (the cargo-zigbuild wrapper calls the cargo named
/// by `CARGO`), with the cross tools' folder first on `PATH` so that it finds zig.
fn zigbuild(cargo: &Path) -> Command {
    let zigbuild = find_tool("cargo-zigbuild").unwrap_or_else(|| "cargo-zigbuild".into());
    let mut c = Command::new(zigbuild);
    c.arg("zigbuild").env("CARGO", cargo).env("RUSTC_BOOTSTRAP", "1").env("PATH", search_path());
    c
}

fn rust_web_src() -> bool {
    Path::new(RUST_WEB).join("lib/rustlib/src/rust/library/std").is_dir() && rust_web_recent()
}

/// True when `/usr/bin/rustc` is rustc-web, recent enough for the workspace (Debian's plain
/// `rustc` package, 1.63 on Debian 12, installs at the same place and cannot build it).
fn rust_web_recent() -> bool {
    let Ok(out) = Command::new(rust_web_bin("rustc")).arg("--version").output() else { return false };
    let text = String::from_utf8_lossy(&out.stdout);
    let version: Vec<u32> =
        text.split_whitespace().nth(1).unwrap_or("").split('.').filter_map(|x| x.parse().ok()).collect();
    rust_web_bin("cargo").is_file() && version.len() >= 2 && (version[0], version[1]) >= (1, 80)
}

/// The folders searched for tools: `target/cross-venv/bin` (where setup-cross.sh installs
/// the PyPI tools), then `PATH`.
fn search_path() -> std::ffi::OsString {
    let mut dirs = vec![crate::target_dir().join("cross-venv").join("bin")];
    dirs.extend(std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()));
    std::env::join_paths(dirs).unwrap_or_default()
}

/// The first executable called `name` in `target/cross-venv/bin` (where setup-cross.sh installs
/// the PyPI tools), then on `PATH`.
pub fn find_tool(name: &str) -> Option<PathBuf> {
    std::env::split_paths(&search_path()).map(|d| d.join(name)).find(|p| p.is_file())
}

fn zig_available() -> bool {
    find_tool("zig").is_some()
        || find_tool("python3").is_some_and(|py| {
            Command::new(py).args(["-c", "import ziglang"]).output().is_ok_and(|o| o.status.success())
        })
}

/// An LLVM tool (`llvm-lipo`, `llvm-strip`): on `PATH`, as `NAME-22`, or in llvm-22's folder.
fn llvm_tool(name: &str) -> Option<PathBuf> {
    find_tool(name).or_else(|| find_tool(&format!("{name}-22"))).or_else(|| {
        let p = Path::new("/usr/lib/llvm-22/bin").join(name);
        p.is_file().then_some(p)
    })
}

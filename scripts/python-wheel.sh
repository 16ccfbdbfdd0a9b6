#!/usr/bin/env bash
# Builds the Python package nigel_cosim (python/) into target/wheels/ for one platform, one
# abi3 wheel (every CPython >= 3.10), and prints the wheel's path.
# Usage: bash scripts/python-wheel.sh [PLATFORM]   (PLATFORM: linux-x86_64, the default, or one
# of the others below; scripts/wheel-check.py checks a wheel's tags and native module)
#   linux-x86_64     ...-cp310-abi3-manylinux2014_x86_64.manylinux_2_17_x86_64.whl
#   linux-aarch64    ...-cp310-abi3-manylinux2014_aarch64.manylinux_2_17_aarch64.whl
#   windows-x86_64   ...-cp310-abi3-win_amd64.whl (mingw-w64; python3.dll through raw-dylib)
#   macos-universal2 ...-cp310-abi3-macosx_11_0_arm64.macosx_11_0_universal2.macosx_11_0_x86_64.whl
#                    (one module with x86-64 and arm64 slices, macOS 11)
# (manylinux2014 is manylinux_2_17: the two names of one platform tag.) The Linux wheels are
# linked by zig against glibc 2.17, as the FMUs' libraries are; the others use the toolchains
# of the FMUs' and the master's recipes (build-fmu/src/platform.rs, Platform::cargo_build:
# Debian's rustc-web, -Zbuild-std for Windows and macOS, zig as macOS linker) into the same
# target folder (target/rust-web), so that what they share compiles once. maturin and zig
# come from scripts/setup-cross.sh's venv.
set -euo pipefail
. "$(dirname "$0")/target-dir.sh"
platform="${1:-linux-x86_64}"
bash "$repo/scripts/setup-cross.sh"
venv="$target/cross-venv"
version="$(sed -n 's/^version = "\(.*\)"/\1/p' "$repo/Cargo.toml" | head -1)"
common=(build --quiet --release --manifest-path "$repo/python/Cargo.toml" -o "$target/wheels")
if [ "$platform" != linux-x86_64 ]; then
    # maturin runs `cargo`: rustc-web's (it has the arm64 standard library and the sources
    # -Zbuild-std builds), ahead of rustup's on PATH
    tools="$venv/rust-web-bin"
    mkdir -p "$tools"
    ln -sf /usr/bin/cargo "$tools/cargo"
    export PATH="$tools:$PATH" RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1
    unset RUSTFLAGS
    common+=(--target-dir "$target/rust-web")
fi
case "$platform" in
    linux-x86_64)
        tag=manylinux2014_x86_64.manylinux_2_17_x86_64
        args=(--zig --compatibility manylinux_2_17 --target x86_64-unknown-linux-gnu) ;;
    linux-aarch64)
        tag=manylinux2014_aarch64.manylinux_2_17_aarch64
        args=(--zig --compatibility manylinux_2_17 --target aarch64-unknown-linux-gnu) ;;
    windows-x86_64)
        tag=win_amd64
        export CARGO_TARGET_X86_64_PC_WINDOWS_GNU_LINKER=x86_64-w64-mingw32-gcc
        export CARGO_TARGET_X86_64_PC_WINDOWS_GNU_RUSTFLAGS="-C link-arg=-Wl,--no-insert-timestamp"
        # --strip: without the COFF symbol table (4 of the module's 12.7 MB), as the FMUs' DLLs
        args=(--strip --target x86_64-pc-windows-gnu -Zbuild-std=std,panic_unwind) ;;
    macos-universal2)
        # (maturin names a universal2 wheel with its two slices' tags too: a pip that does not
        # know universal2 installs it)
        tag=macosx_11_0_arm64.macosx_11_0_universal2.macosx_11_0_x86_64
        export MACOSX_DEPLOYMENT_TARGET=11.0
        # the flags of the macOS FMUs' recipe (Platform::cargo_build); maturin adds
        # -undefined dynamic_lookup to every crate's and names the module
        # @rpath/nigel_cosim._native.abi3.so itself, so no crate of the FMUs' build is reused
        export CARGO_TARGET_X86_64_APPLE_DARWIN_RUSTFLAGS=-Zosx-rpath-install-name
        export CARGO_TARGET_AARCH64_APPLE_DARWIN_RUSTFLAGS=-Zosx-rpath-install-name
        args=(--zig --target universal2-apple-darwin -Zbuild-std=std,panic_unwind) ;;
    *) echo "python-wheel: unknown platform $platform (linux-x86_64, linux-aarch64, windows-x86_64, macos-universal2)" >&2; exit 2 ;;
esac
wheel="$target/wheels/nigel_cosim-$version-cp310-abi3-$tag.whl"
rm -f "$wheel"
PATH="$venv/bin:$PATH" maturin "${common[@]}" "${args[@]}" >&2
[ -f "$wheel" ] || { echo "python-wheel: maturin did not write $wheel" >&2; ls "$target/wheels" >&2; exit 1; }
echo "$wheel"

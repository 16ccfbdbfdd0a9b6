#!/usr/bin/env bash
# The Python package nigel_cosim's wheels for the platforms other than x86-64 Linux (that one:
# scripts/python-wheel.sh), into target/wheels/, one abi3 wheel each (every CPython >= 3.10):
#   aarch64 Linux   ...-cp310-abi3-manylinux2014_aarch64.manylinux_2_17_aarch64.whl (zig, glibc 2.17)
#   x86-64 Windows  ...-cp310-abi3-win_amd64.whl (mingw-w64; python3.dll through raw-dylib, no import library)
#   macOS           ...-cp310-abi3-macosx_11_0_universal2.whl (x86-64 and arm64 in one module, macOS 11)
# with the toolchains of the FMUs' and the master's recipes (build-fmu/src/platform.rs,
# Platform::cargo_build: Debian's rustc-web, -Zbuild-std for Windows and macOS, zig as linker
# for Linux and macOS) into the same target folder (target/rust-web), so that what they share
# compiles once. Usage: python-wheels-cross.sh [aarch64-linux,win64,macos]. Prints each wheel's path.
# NOT YET RUN TO THE END (issue 39 item 6): the win64 build got past pyo3's configuration (abi3,
# python3.dll through raw-dylib); no wheel written yet, so neither command runs it. Check each
# wheel with scripts/wheel-check.py.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in
    /*) ;;
    *) target="$repo/$target" ;;
esac
bash "$repo/scripts/setup-cross.sh"
venv="$target/cross-venv"
version="$(sed -n 's/^version = "\(.*\)"/\1/p' "$repo/Cargo.toml" | head -1)"
platforms="${1:-aarch64-linux,win64,macos}"
# maturin runs `cargo`: rustc-web's (it has the arm64 standard library and the sources
# -Zbuild-std builds), ahead of rustup's on PATH
tools="$target/cross-venv/rust-web-bin"
mkdir -p "$tools"
ln -sf /usr/bin/cargo "$tools/cargo"
export PATH="$tools:$venv/bin:$PATH" RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1
unset RUSTFLAGS
common=(build --quiet --release --manifest-path "$repo/python/Cargo.toml" -o "$target/wheels" --target-dir "$target/rust-web")
for platform in ${platforms//,/ }; do
    case "$platform" in
        aarch64-linux)
            wheel="nigel_cosim-$version-cp310-abi3-manylinux2014_aarch64.manylinux_2_17_aarch64.whl"
            args=(--zig --compatibility manylinux_2_17 --target aarch64-unknown-linux-gnu) ;;
        win64)
            wheel="nigel_cosim-$version-cp310-abi3-win_amd64.whl"
            export CARGO_TARGET_X86_64_PC_WINDOWS_GNU_LINKER=x86_64-w64-mingw32-gcc
            export CARGO_TARGET_X86_64_PC_WINDOWS_GNU_RUSTFLAGS="-C link-arg=-Wl,--no-insert-timestamp"
            args=(--target x86_64-pc-windows-gnu -Zbuild-std=std,panic_unwind) ;;
        macos)
            wheel="nigel_cosim-$version-cp310-abi3-macosx_11_0_universal2.whl"
            export MACOSX_DEPLOYMENT_TARGET=11.0
            args=(--zig --target universal2-apple-darwin -Zbuild-std=std,panic_unwind) ;;
        *) echo "python-wheels-cross: unknown platform $platform (aarch64-linux, win64, macos)" >&2; exit 2 ;;
    esac
    rm -f "$target/wheels/$wheel"
    maturin "${common[@]}" "${args[@]}" >&2
    [ -f "$target/wheels/$wheel" ] || { echo "python-wheels-cross: maturin did not write $wheel" >&2; ls "$target/wheels" >&2; exit 1; }
    echo "$target/wheels/$wheel"
done

#!/usr/bin/env bash
# Installs the cross toolchains build-fmu uses for the platforms other than the host's own,
# and the runners the platform tests use. Idempotent: a second run checks and returns.
#
# Everything comes from Debian (bookworm + bookworm-security), PyPI and nothing else:
# - linux64 with a glibc 2.17 baseline: cargo-zigbuild and zig (PyPI wheels `cargo-zigbuild`,
#   `ziglang`) link against the glibc version named in the target triple;
# - win64 (x86_64-pc-windows-gnu): Debian's rustc-web/cargo-web 1.96 with rust-web-src
#   (standard library built from source with -Zbuild-std), linker x86_64-w64-mingw32-gcc;
#   llvm-strip (llvm-22) strips the DLLs; wine runs them in the tests;
# - aarch64-linux: libstd-rust-web-dev:arm64 (the standard library of rustc-web for arm64),
#   linked by cargo-zigbuild against glibc 2.17; gcc-aarch64-linux-gnu and
#   libc6-dev-arm64-cross build the tests' C importer, qemu-user runs it;
# - darwin64: cargo-zigbuild with -Zbuild-std (rust-web-src) for x86_64 and arm64,
#   llvm-lipo (llvm-22) joins them into one universal dylib.
# - the Python wheel (scripts/python-wheel.sh): maturin (PyPI) with the same zig, for
#   manylinux2014 (glibc 2.17) as the FMUs' linux64 libraries.
# The PyPI tools go into "$TARGET/cross-venv" (TARGET is $CARGO_TARGET_DIR or <repo>/target).
# Measured on Debian 12: 87 Debian packages, 2.2 GiB installed, plus 0.44 GiB for the venv;
# about 3 minutes. A run with everything present takes about a second.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in
    /*) ;;
    *) target="$repo/$target" ;;
esac

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "setup-cross: need root (or sudo) for apt-get" >&2; exit 1; }
    sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive

if ! dpkg --print-foreign-architectures | grep -qx arm64; then
    echo "setup-cross: adding the arm64 architecture to dpkg" >&2
    "${sudo_cmd[@]}" dpkg --add-architecture arm64
    apt_updated=""
fi
packages=(
    rustc-web cargo-web rust-web-src libstd-rust-web-dev:arm64
    gcc-mingw-w64-x86-64 wine wine64
    gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user
    llvm-22
)
needed=()
for pkg in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || needed+=("$pkg")
done
if [ ${#needed[@]} -ne 0 ]; then
    echo "setup-cross: installing ${needed[*]}" >&2
    "${sudo_cmd[@]}" apt-get update -qq
    "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${needed[@]}" >/dev/null
fi

# The PyPI tools, pinned; a marker holding the pins skips pip when they match.
venv="$target/cross-venv"
pins="cargo-zigbuild==0.24.0 ziglang==0.17.0 maturin==1.16.0"
if [ "$(cat "$venv/.pins" 2>/dev/null)" != "$pins" ]; then
    echo "setup-cross: installing $pins into $venv" >&2
    python3 -m venv "$venv"
    # shellcheck disable=SC2086
    "$venv/bin/pip" install -q --disable-pip-version-check $pins
    echo "$pins" >"$venv/.pins"
fi
# rustc strips the debug information of macOS libraries with `rust-objcopy` (llvm-objcopy
# under the name rustup ships it as), found on PATH; build-fmu puts this folder first on it
if [ "$(readlink "$venv/bin/rust-objcopy" 2>/dev/null)" != /usr/lib/llvm-22/bin/llvm-objcopy ]; then
    ln -sf /usr/lib/llvm-22/bin/llvm-objcopy "$venv/bin/rust-objcopy"
fi

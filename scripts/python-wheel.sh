#!/usr/bin/env bash
# Builds the Python package nigel_cosim (python/) into target/wheels/:
# nigel_cosim-<version>-cp310-abi3-manylinux2014_x86_64.manylinux_2_17_x86_64.whl (the two
# names of one platform tag: manylinux2014 is manylinux_2_17), one wheel for every CPython
# >= 3.10 (abi3), linked by zig against glibc 2.17 as the FMUs' linux64 libraries are. maturin and zig come from scripts/setup-cross.sh's venv. Prints the
# wheel's path.
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
wheel="$target/wheels/nigel_cosim-$version-cp310-abi3-manylinux2014_x86_64.manylinux_2_17_x86_64.whl"
rm -f "$wheel"
PATH="$venv/bin:$PATH" maturin build --quiet --release --zig --compatibility manylinux_2_17 \
    --target x86_64-unknown-linux-gnu --manifest-path "$repo/python/Cargo.toml" -o "$target/wheels" >&2
[ -f "$wheel" ] || { echo "python-wheel: maturin did not write $wheel" >&2; ls "$target/wheels" >&2; exit 1; }
echo "$wheel"

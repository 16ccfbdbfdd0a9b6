#!/usr/bin/env bash
# Runs every test of the workspace from a fresh clone: system packages and cross
# toolchains, the FMUs for every platform, the Rust tests (release profile, the same build
# the FMUs use; build-fmu/tests/platforms.rs runs each platform's libraries natively, under
# wine and under qemu-user, and checks the darwin64 ones structurally) and the fmpy
# cross-checks, which load the archives' linux64 libraries.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-system.sh
bash scripts/setup-cross.sh
target_dir="${CARGO_TARGET_DIR:-target}"
echo "== building the FMUs (linux64, win64, aarch64-linux, darwin64)"
cargo run --release --quiet -p build-fmu -- --platforms all
echo "== rebuilding from touched sources must give byte-identical archives"
touch fmu-plant/src/lib.rs fmi-export/src/abi.rs
cargo run --release --quiet -p build-fmu -- --platforms all "$target_dir/fmu-rebuild" >/dev/null
# the FMUs of build-fmu's list (target/fmu may also hold FMUs the examples wrote)
ids=$(grep -o '"model_identifier": "[^"]*"' "$target_dir/fmu/manifest.json" | cut -d'"' -f4)
[ -n "$ids" ] || { echo "no FMU in $target_dir/fmu/manifest.json" >&2; exit 1; }
for id in $ids; do
    cmp "$target_dir/fmu/$id.fmu" "$target_dir/fmu-rebuild/$id.fmu" || { echo "rebuilt $id.fmu differs" >&2; exit 1; }
    echo "identical: $id.fmu"
done
# the platform tests fail, rather than skip, when an archive lacks a platform
export NIGEL_REQUIRE_PLATFORMS=all
echo "== Python venv with fmpy"
bash scripts/python-env.sh >/dev/null
export FMPY_PYTHON="$PWD/$target_dir/venv/bin/python"
[ -x "$FMPY_PYTHON" ] || FMPY_PYTHON="$target_dir/venv/bin/python"
echo "== Rust tests"
cargo test --release --workspace --no-fail-fast
echo "== the layer's C ABIs (FMI 2.0 and 3.0) in process under AddressSanitizer"
# the toy through both ABIs, the plant's FMI 3.0 runs and derivatives: an out-of-bounds
# read or write, a use after free or a double free in the layer stops the test
rustup toolchain install nightly --profile minimal >/dev/null 2>&1 || true
asan_test() {
    RUSTFLAGS="-Zsanitizer=address" cargo +nightly test --target x86_64-unknown-linux-gnu \
        --target-dir "$target_dir/asan" -p "$1" --test "$2"
}
asan_test fmi-export toy
asan_test fmu-plant fmi3
echo "== synthesis tests under two more OpenBLAS kernels"
bash scripts/test-blas-kernels.sh
echo "== fmpy cross-checks"
"$target_dir/venv/bin/python" -m pytest tests/python -q
echo "== co-simulation master cross-checks"
"$target_dir/venv/bin/python" -m pytest cosim/tests/python -q
echo "== Table III closed loop as SSP in fmpy"
"$target_dir/venv/bin/python" -m pytest table3/tests/python -q
echo "== examples (each prints what its header says; checked against table3)"
"$target_dir/venv/bin/python" -m pytest examples -q
echo "== campaign results in fmpy and pandas"
"$target_dir/venv/bin/python" -m pytest campaign/tests/python -q
echo "== campaign on a local Slurm cluster"
bash scripts/test-campaign-slurm.sh

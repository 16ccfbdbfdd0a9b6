#!/usr/bin/env bash
# Runs every test of the workspace from a fresh clone: system packages, the FMUs, the
# Rust tests (release profile, the same build the FMUs use) and the fmpy cross-checks.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-system.sh
target_dir="${CARGO_TARGET_DIR:-target}"
echo "== building the FMUs"
cargo run --release --quiet -p build-fmu
echo "== rebuilding from touched sources must give byte-identical archives"
touch fmu-plant/src/lib.rs fmi2-export/src/abi.rs
cargo run --release --quiet -p build-fmu -- "$target_dir/fmu-rebuild" >/dev/null
for f in "$target_dir"/fmu/*.fmu; do
    cmp "$f" "$target_dir/fmu-rebuild/$(basename "$f")" && echo "identical: $(basename "$f")"
done
echo "== exported symbols (every FMU of build-fmu's list, from target/fmu/manifest.json)"
ids=$(grep -o '"model_identifier": "[^"]*"' "$target_dir/fmu/manifest.json" | cut -d'"' -f4)
[ -n "$ids" ] || { echo "no FMU in $target_dir/fmu/manifest.json" >&2; exit 1; }
for id in $ids; do
    so="$target_dir/release/lib$id.so"
    n=$(nm -D --defined-only "$so" | grep -c ' T fmi2')
    [ "$n" -eq 44 ] || { echo "$so exports $n fmi2 symbols, expected 44" >&2; exit 1; }
    echo "$(basename "$so"): 44 fmi2 symbols"
done
echo "== Python venv with fmpy"
bash scripts/python-env.sh >/dev/null
export FMPY_PYTHON="$PWD/$target_dir/venv/bin/python"
[ -x "$FMPY_PYTHON" ] || FMPY_PYTHON="$target_dir/venv/bin/python"
echo "== Rust tests"
cargo test --release --workspace
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

#!/usr/bin/env bash
# The main job: installs the system packages and cross toolchains (as the test command does),
# builds every binary of the workspace into target/release/ (cosim, cosim-host, campaign,
# table3, synthesize, build-fmu, ...), the Python package's wheels into target/wheels/ (x86-64
# and aarch64 Linux, Windows, macOS), the master's release archives for five platforms
# into target/dist/ (scripts/dist.sh), the venv
# of the README's quick start (target/venv: fmpy, pandas, matplotlib and nigel_cosim), the three FMUs for all four platforms (the release
# archives: linux64 with the glibc 2.17 baseline, win64, aarch64-linux, darwin64) into
# target/fmu/ and the closed loop as SSP into target/ssp/, co-simulates that closed loop with our master (30 s at 1 ms, ordered), runs
# the paper's Table III and Fig. 7 through the FMUs, and synthesizes the robust controller
# (Pareto sweep of the paper). Everything it writes lands in target/results/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-system.sh
bash scripts/setup-cross.sh
target_dir="${CARGO_TARGET_DIR:-target}"
results="$target_dir/results"
mkdir -p "$results"

echo "== building every binary of the workspace (target/release)"
cargo build --release --quiet --workspace --bins

echo "== the Python package's wheel (target/wheels: pip install it into any CPython >= 3.10)"
wheel="$(bash scripts/python-wheel.sh)"
python3 scripts/wheel-check.py "$wheel" linux-x86_64
echo "== its wheels for aarch64 Linux (manylinux2014), Windows (win_amd64), macOS 11 (universal2), each checked"
for platform in linux-aarch64 windows-x86_64 macos-universal2; do
    other="$(bash scripts/python-wheel.sh "$platform")"
    python3 scripts/wheel-check.py "$other" "$platform"
done
echo "== the venv of the README's quick start: target/venv with fmpy, pandas, matplotlib and nigel_cosim"
bash scripts/python-venv-wheel.sh "$wheel"

echo "== building the FMUs (all four platforms) and the closed-loop SSP"
cargo run --release --quiet -p build-fmu -- --platforms all

echo "== the master for every platform: target/dist/cosim-VERSION-TRIPLE.{tar.gz,zip} and SHA256SUMS"
bash scripts/dist.sh

echo "== co-simulation: plant + controller + test bench (lane change, robust), 30 s at 1 ms"
cargo run --release --quiet -p nigel-cosim --bin cosim -- run "$target_dir/ssp/nigel_closed_loop.ssp" \
    --stop-time 30 --step 1e-3 --algorithm ordered \
    --output "$results/closed_loop.csv" --output-interval 0.01 --summary "$results/closed_loop_summary.json"
echo "wrote $results/closed_loop.csv and $results/closed_loop_summary.json"

echo "== Table III and Fig. 7 through the FMUs (seed 0)"
cargo run --release --quiet -p nigel-table3 --bin table3 -- --seed 0 \
    --json "$results/table3.json" --png "$results/figures" --quiet

echo "== robust synthesis (paper variant, 4WD4WS, Pareto sweep)"
cargo run --release --quiet -p nigel-synthesis --bin synthesize -- \
    --arch 4ws --d2 paper --objective pareto \
    --json "$results/synthesis.json" --plot "$results/synthesis.svg"

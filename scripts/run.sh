#!/usr/bin/env bash
# The main job: builds the FMUs into target/fmu/ and synthesizes the robust controller
# (Pareto sweep of the paper), writing target/results/synthesis.{json,svg}.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-system.sh
cargo run --release --quiet -p build-fmu
target_dir="${CARGO_TARGET_DIR:-target}"
mkdir -p "$target_dir/results"
cargo run --release --quiet -p nigel-synthesis --bin synthesize -- \
    --arch 4ws --d2 paper --objective pareto \
    --json "$target_dir/results/synthesis.json" --plot "$target_dir/results/synthesis.svg"

#!/usr/bin/env bash
# Runs every test of the workspace from a fresh clone: system packages, the FMUs, the
# Rust tests (release profile, the same build the FMUs use) and the fmpy cross-checks.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-system.sh
echo "== building the FMUs"
cargo run --release --quiet -p build-fmu
echo "== Rust tests"
cargo test --release --workspace
echo "== fmpy cross-checks"
bash scripts/python-env.sh >/dev/null
target_dir="${CARGO_TARGET_DIR:-target}"
"$target_dir/venv/bin/python" -m pytest tests/python -q

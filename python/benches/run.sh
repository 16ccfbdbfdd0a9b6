#!/usr/bin/env bash
# The Python benchmark (python/benches/bench_python.py): builds the wheel, unpacks it into
# target/bench-site (no venv of its own: the test venv target/venv has fmpy, ecospy and
# libcosimpy) and runs it. Needs target/fmu and target/ssp (bash scripts/run.sh or the test
# command builds them). Arguments: the number of rounds (default 5).
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in
    /*) ;;
    *) target="$repo/$target" ;;
esac
wheel="$(bash "$repo/scripts/python-wheel.sh")"
bash "$repo/scripts/python-env.sh" >/dev/null
rm -rf "$target/bench-site"
"$target/venv/bin/python" -m pip install --quiet --no-deps --target "$target/bench-site" "$wheel"
PYTHONPATH="$target/bench-site" "$target/venv/bin/python" "$repo/python/benches/bench_python.py" "$target" "${1:-5}"

#!/usr/bin/env bash
# The venv of the README's quick start: target/venv (scripts/python-env.sh: fmpy, numpy,
# pandas, matplotlib, pytest, every package pinned) with the Python package nigel_cosim
# installed into it from the wheel given as $1 (default: the one scripts/python-wheel.sh
# writes), replacing any earlier build of it. The main command and the test command run it,
# so `target/venv/bin/python` imports both fmpy and nigel_cosim after either. Prints the venv.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in
    /*) ;;
    *) target="$repo/$target" ;;
esac
version="$(sed -n 's/^version = "\(.*\)"/\1/p' "$repo/Cargo.toml" | head -1)"
wheel="${1:-$target/wheels/nigel_cosim-$version-cp310-abi3-manylinux2014_x86_64.manylinux_2_17_x86_64.whl}"
[ -f "$wheel" ] || { echo "python-venv-wheel: no wheel at $wheel (bash scripts/python-wheel.sh builds it)" >&2; exit 1; }
venv="$(bash "$repo/scripts/python-env.sh")"
# --no-deps: its dependencies (numpy, and pandas of the extra) are pinned in the venv already
PIP_DISABLE_PIP_VERSION_CHECK=1 "$venv/bin/python" -m pip install --no-input --quiet --no-deps --force-reinstall "$wheel" >&2
"$venv/bin/python" -c 'import nigel_cosim, fmpy, pandas' >&2
echo "$venv"

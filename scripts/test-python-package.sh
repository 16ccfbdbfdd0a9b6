#!/usr/bin/env bash
# Tests the Python package as a user gets it: builds the wheel (scripts/python-wheel.sh),
# installs it into a new venv (target/wheel-venv, made afresh each time) with only the
# tests' own dependencies (fmpy, pandas, matplotlib, pytest, at the pins of
# scripts/python-env.sh), and
# runs python/tests there. Needs target/release/{cosim,campaign} and target/fmu, target/ssp
# (the test command builds them first).
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in
    /*) ;;
    *) target="$repo/$target" ;;
esac
wheel="$(bash "$repo/scripts/python-wheel.sh")"
venv="$target/wheel-venv"
rm -rf "$venv"
"${PYTHON:-python3}" -m venv "$venv"
# the pins of the test venv (scripts/python-env.sh), but not the other masters
requirements="$(mktemp)"
trap 'rm -f "$requirements"' EXIT
sed -n '/^requirements=/,/^EOF$/p' "$repo/scripts/python-env.sh" | grep '==' | grep -v -e '^ecospy==' -e '^libcosimpy==' >"$requirements"
PIP_DISABLE_PIP_VERSION_CHECK=1 "$venv/bin/python" -m pip install --no-input --quiet "$wheel" -r "$requirements" >&2
cd "$repo"
"$venv/bin/python" -m pytest python/tests -q "$@"

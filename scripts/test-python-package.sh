#!/usr/bin/env bash
# Tests the Python package as a user gets it: builds the wheel (scripts/python-wheel.sh), runs
# README.md's block that installs it into a venv of one's own, as printed (readme-install:
# `python3 -m venv .venv && .venv/bin/pip install "...whl[pandas]" matplotlib`, then the example
# examples/python_cosim.py), from a fresh folder holding links to target/ and examples/; adds
# the tests' own dependencies (fmpy, pytest, at the pins of scripts/python-env.sh) to that venv
# and runs python/tests there, after mypy's stubtest on the installed package and mypy on
# python/nigel_cosim (mypy pinned here; either failing fails the script). Needs
# target/release/{cosim,campaign} and target/fmu, target/ssp (the test command builds them first).
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in
    /*) ;;
    *) target="$repo/$target" ;;
esac
wheel="$(bash "$repo/scripts/python-wheel.sh")"
work="$target/wheel-user"
rm -rf "$work" "$target/wheel-venv"
mkdir -p "$work"
ln -s "$target" "$work/target"
ln -s "$repo/examples" "$work/examples"
# readme-install: the README's ```sh block with `pip install`, run as printed
install_block="$(python3 - "$repo/README.md" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
blocks = [b for b in re.findall(r"^```sh\n(.*?)^```", text, re.S | re.M) if "pip install" in b]
assert len(blocks) == 1, f"README.md: {len(blocks)} blocks with pip install, expected 1"
print(blocks[0])
PY
)"
echo "$install_block" >&2
(cd "$work" && PIP_DISABLE_PIP_VERSION_CHECK=1 bash -euo pipefail -c "$install_block")
[ -f "$work/target/python_cosim.png" ] || { echo "README.md's install block did not draw target/python_cosim.png" >&2; exit 1; }
venv="$work/.venv"
# the pins of the test venv (scripts/python-env.sh), but not the other masters
requirements="$(mktemp)"
trap 'rm -f "$requirements"' EXIT
sed -n '/^requirements=/,/^EOF$/p' "$repo/scripts/python-env.sh" | grep '==' | grep -v -e '^ecospy==' -e '^libcosimpy==' >"$requirements"
# mypy and its dependencies, pinned: the typing check of the package below
cat >>"$requirements" <<'EOF'
mypy==2.4.1
mypy_extensions==1.2.0
pathspec==1.1.1
librt==0.17.0
ast-serialize==0.13.1
tomli==2.2.1; python_version < "3.11"
EOF
PIP_DISABLE_PIP_VERSION_CHECK=1 "$venv/bin/python" -m pip install --no-input --quiet "$wheel" -r "$requirements" >&2
cd "$repo"
# typing: the stubs of the installed extension (_native.pyi) match what the module defines
# (names, arguments, defaults: stubtest), and the Python half type-checks against them
"$venv/bin/python" -m mypy.stubtest --mypy-config-file python/pyproject.toml nigel_cosim
"$venv/bin/python" -m mypy --config-file python/pyproject.toml python/nigel_cosim
"$venv/bin/python" -m pytest python/tests -q "$@"
# the user's folder (its venv some 700 MB) is kept only when a step above failed
rm -rf "$work"

#!/usr/bin/env bash
# Creates the Python environment of the fmpy cross-checks (tests/python) at
# "$TARGET/venv", where TARGET is $CARGO_TARGET_DIR or <repo>/target, and prints its path.
#
# Needs only python3 (>= 3.9; 3.11 here) with the venv module, and PyPI. Every package is
# pinned, transitive ones included, so two machines get the same environment. A marker file
# in the venv holds the hash of the pins and of the interpreter: when it matches, pip is not
# run at all (the script returns in well under a second).
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in
    /*) ;;
    *) target="$repo/$target" ;; # relative to the repo root, as scripts/test.sh (run from there) uses it
esac
venv="$target/venv"
python="${PYTHON:-python3}"

# fmpy 0.3.32 is the newest 0.3 release. Its own requirements (attrs, cmake, jinja2, lark, lxml,
# msgpack, nbformat, numpy) are pinned with their dependencies; lxml is what fmpy's
# validate_fmu and its SSP reader (XML schema validation) use, cmake is only for fmpy's
# source-code FMU builds (a wheel from PyPI, nothing is downloaded at run time).
# ecospy (ecos, needs Debian's libtbb12) and libcosimpy (libcosim) are the co-simulation
# masters the master's cross-checks (cosim/tests/python) compare with; no dependencies.
# fmu-manipulation-toolbox (fmucontainer: a container FMU with its own C runtime around our
# FMUs) needs colorama, elementpath and xmlschema. matplotlib (with contourpy, cycler, fonttools,
# kiwisolver, pillow, pyparsing, python-dateutil, tzdata) draws the examples' PNG figures
# (Agg backend, no display needed). plotly (with narwhals) is fmpy's own plotting backend:
# fmpy.util.plot_result and `fmpy simulate --show-plot` (a PNG from plotly would need kaleido
# and a Chrome; HTML and the figure object need neither).
# pandas (with the python-dateutil and tzdata above) reads the campaign's results.csv in its tests.
# pythonfmu3 (no dependencies; its FMI 3.0 C++ wrapper ships prebuilt in the wheel) builds the
# third-party FMI 3.0 FMU of cosim/tests/python/test_cosim_pythonfmu3.py.
# scipy 1.17.1 (the newest for Python 3.11; no dependencies beyond numpy) gives the stiff benchmark and tests (cosim/benches/stiff.py,
# cosim/tests/python/test_stiff_reference.py) their reference solutions: solve_ivp's Radau
# (an implicit Runge-Kutta method, independent of the master's BDF and of CVode).
requirements="$(cat <<'EOF'
fmpy==0.3.32
ecospy==0.7.2
libcosimpy==0.0.6
fmu-manipulation-toolbox==2.0
colorama==0.4.6
elementpath==5.1.4
xmlschema==4.3.2
matplotlib==3.11.2
contourpy==1.3.3
cycler==0.12.1
fonttools==4.68.0
kiwisolver==1.5.1
pillow==13.0.0
pyparsing==3.3.3
python-dateutil==4.0.0
tzdata==2026.6
plotly==7.1.0
narwhals==2.29.0
numpy==2.4.6
pytest==9.2.0
lxml==6.1.3
attrs==26.1.0
cmake==4.4.4
fastjsonschema==2.22.3
iniconfig==2.3.1
Jinja2==3.1.6
jsonschema==4.26.0
jsonschema-specifications==2025.9.1
jupyter_core==5.9.1
lark==1.3.1
MarkupSafe==3.0.4
msgpack==1.2.4
nbformat==5.11.1
packaging==26.3
platformdirs==4.14.7
pluggy==1.7.0
Pygments==2.21.0
referencing==0.37.0
rpds-py==2026.9.1
traitlets==5.16.1
typing_extensions==4.16.0
pandas==3.1.1
pythonfmu3==0.3.4
scipy==1.17.1
EOF
)"

command -v "$python" >/dev/null || { echo "python-env: $python not found" >&2; exit 1; }
py_id="$("$python" -c 'import sys, platform; print(sys.version.split()[0], platform.machine())')"
hash="$(printf '%s\n%s\n' "$requirements" "$py_id" | sha256sum | cut -d' ' -f1)"
marker="$venv/.nigel-requirements.sha256"

if [ -x "$venv/bin/python" ] && [ -f "$marker" ] && [ "$(cat "$marker")" = "$hash" ]; then
    echo "$venv"
    exit 0
fi

echo "python-env: setting up $venv ($py_id)" >&2
mkdir -p "$target"
if [ ! -x "$venv/bin/python" ]; then
    if ! "$python" -m venv "$venv" >&2; then
        rm -rf "$venv"
        echo "python-env: '$python -m venv' failed (on Debian: apt-get install python3-venv)" >&2
        exit 1
    fi
fi
rm -f "$marker"
req_file="$(mktemp)"
trap 'rm -f "$req_file"' EXIT
printf '%s\n' "$requirements" >"$req_file"
PIP_DISABLE_PIP_VERSION_CHECK=1 "$venv/bin/python" -m pip install --no-input --quiet -r "$req_file" >&2
# a smoke check of the pieces the tests use, before the marker says "done"
"$venv/bin/python" -c 'import fmpy, fmpy.validation, fmpy.ssp.simulation, fmpy.sundials, lxml, numpy, pytest, ecospy, libcosimpy, matplotlib, plotly, scipy.integrate' >&2
printf '%s\n' "$hash" >"$marker"
echo "$venv"

#!/usr/bin/env bash
# The aarch64 wheel of nigel_cosim run under qemu-user by an aarch64 CPython: Debian's arm64
# python3.11 and numpy (apt-get download, unpacked with dpkg -x into target/arm64-python; no
# package is installed), the same glibc build as the aarch64 master's runs (QEMU_LD_PREFIX,
# see QEMU_ENV in build-fmu/tests/platforms.rs). Its simulate_ssp of the closed loop (5 s,
# 1 ms, ordered) must equal the aarch64 cosim's CSV bit for bit, as
# python/tests/test_package.py holds the x86-64 wheel to the x86-64 cosim (that test file
# needs fmpy and pandas, which have no arm64 build here).
# Usage: test-wheel-aarch64.sh WHEEL COSIM (COSIM: the aarch64 program, e.g. test-dist.sh's).
set -euo pipefail
. "$(dirname "$0")/target-dir.sh"
wheel="$1" cosim="$2"
root="$target/arm64-python"
packages=(python3.11-minimal libpython3.11-minimal libpython3.11-stdlib python3-numpy libexpat1 zlib1g
    libffi8 libblas3 liblapack3 libgfortran5 libgcc-s1 libstdc++6)
if [ "$(cat "$root/.packages" 2>/dev/null)" != "${packages[*]}" ]; then
    rm -rf "$root" && mkdir -p "$root/debs"
    (cd "$root/debs" && apt-get download -q "${packages[@]/%/:arm64}" >/dev/null 2>&1)
    for deb in "$root"/debs/*.deb; do dpkg -x "$deb" "$root"; done
    rm -rf "$root/debs"
    echo "${packages[*]}" >"$root/.packages"
fi
work="$target/wheel-aarch64"
rm -rf "$work" && mkdir -p "$work/site"
(cd "$work/site" && unzip -q "$wheel")
lib="$root/usr/lib/aarch64-linux-gnu"
export QEMU_LD_PREFIX=/usr/aarch64-linux-gnu
export QEMU_SET_ENV="LD_LIBRARY_PATH=$root/lib/aarch64-linux-gnu:$lib:$lib/blas:$lib/lapack:/usr/aarch64-linux-gnu/lib,PYTHONHOME=$root/usr,PYTHONPATH=$work/site:$root/usr/lib/python3/dist-packages"
ssp="$target/ssp/nigel_closed_loop.ssp"
qemu-aarch64 "$cosim" run "$ssp" --stop-time 5 --step 1e-3 --algorithm ordered --output "$work/cli.csv"
qemu-aarch64 "$root/usr/bin/python3.11" - "$ssp" "$work/cli.csv" <<'EOF'
import platform
import sys

import numpy as np

import nigel_cosim

ssp, csv = sys.argv[1:3]
assert platform.machine() == "aarch64", platform.machine()
cli = np.genfromtxt(csv, delimiter=",", names=True, deletechars="", dtype=np.float64)
ours = nigel_cosim.simulate_ssp(ssp, stop_time=5.0, step_size=1e-3, algorithm="ordered")
assert ours.dtype.names == cli.dtype.names, (ours.dtype.names, cli.dtype.names)
assert "plant.x" in ours.dtype.names and len(ours) == 5001, len(ours)
differing = [f for f in cli.dtype.names if not np.array_equal(ours[f].astype(np.float64), cli[f])]
assert not differing, f"the aarch64 wheel differs from the aarch64 cosim in {differing}"
print(f"aarch64 wheel under qemu (CPython {platform.python_version()}): simulate_ssp equals the aarch64 cosim bit for bit, "
      f"{len(cli.dtype.names)} columns x {len(ours)} rows")
EOF

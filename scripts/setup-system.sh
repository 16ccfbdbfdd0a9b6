#!/usr/bin/env bash
# Installs the Debian packages the workspace links against (clarabel's SDP cones need
# BLAS/LAPACK): libopenblas-dev and libgfortran-12-dev; and libtbb12, which ecos (the
# co-simulation master the cross-checks compare with) needs at run time. Does nothing when present.
set -euo pipefail
needed=()
for pkg in libopenblas-dev libgfortran-12-dev libtbb12; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || needed+=("$pkg")
done
if [ ${#needed[@]} -eq 0 ]; then
    exit 0
fi
echo "setup: installing ${needed[*]}" >&2
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "setup: need root (or sudo) to install ${needed[*]}" >&2; exit 1; }
    sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq "${needed[@]}" >/dev/null

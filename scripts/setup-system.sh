#!/usr/bin/env bash
# Installs the Debian packages the workspace links against (clarabel's SDP cones need
# BLAS/LAPACK): libopenblas-dev and libgfortran-12-dev; and libtbb12, which ecos (the
# co-simulation master the cross-checks compare with) needs at run time. Does nothing when present.
set -euo pipefail
. "$(dirname "$0")/apt-install.sh"
apt_install_missing setup libopenblas-dev libgfortran-12-dev libtbb12

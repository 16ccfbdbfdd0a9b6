#!/usr/bin/env bash
# Sourced by the scripts that need Debian packages:
#   apt_install_missing NAME PACKAGE...
# installs those of the PACKAGEs that are not installed yet (apt-get, with sudo when not
# root), saying so on standard error as NAME; does nothing when all are present; exits 1
# when it would need root and there is no sudo.
apt_install_missing() {
    local name="$1"
    shift
    local needed=()
    for pkg in "$@"; do
        dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || needed+=("$pkg")
    done
    [ ${#needed[@]} -eq 0 ] && return 0
    echo "$name: installing ${needed[*]}" >&2
    local sudo_cmd=()
    if [ "$(id -u)" -ne 0 ]; then
        command -v sudo >/dev/null || { echo "$name: need root (or sudo) to install ${needed[*]}" >&2; exit 1; }
        sudo_cmd=(sudo)
    fi
    export DEBIAN_FRONTEND=noninteractive
    "${sudo_cmd[@]}" apt-get update -qq
    "${sudo_cmd[@]}" apt-get install -y -qq "${needed[@]}" >/dev/null
}

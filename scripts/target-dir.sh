#!/usr/bin/env bash
# Sourced by the scripts and examples that use the build's output: sets `repo` (the checkout
# holding this folder) and `target` (cargo's target folder: $CARGO_TARGET_DIR, relative to
# the checkout when relative, else target/ of the checkout).
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in /*) ;; *) target="$repo/$target" ;; esac

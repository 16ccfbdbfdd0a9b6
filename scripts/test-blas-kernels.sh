#!/usr/bin/env bash
# Runs the synthesis tests (the tests that compare solver output) under OpenBLAS kernels
# other than the machine's own, so that one CI machine sees the rounding another machine's
# kernel gives: the same LMIs solved with Haswell, Sandybridge or SkylakeX kernels differ in
# the last digits, and a tolerance the solver cannot keep shows up here.
#
# The machine's own kernel (or the one OPENBLAS_CORETYPE already names) is the run of
# `cargo test --release --workspace` in scripts/test.sh; this adds two others. A kernel needs
# its instructions: Haswell AVX2 and FMA, Sandybridge AVX; Nehalem (SSE only) fills in on
# older CPUs. OpenBLAS must be a DYNAMIC_ARCH build (Debian's is) for OPENBLAS_CORETYPE to
# take effect; each run checks that OpenBLAS reports the kernel asked for.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(uname -m)" != x86_64 ]; then
    echo "OpenBLAS kernel runs: x86-64 kernels only, skipped on $(uname -m)"
    exit 0
fi
flags=" $(grep -m1 '^flags' /proc/cpuinfo | cut -d: -f2) "
has() { [[ "$flags" == *" $1 "* ]]; }
own="${OPENBLAS_CORETYPE:-}"
candidates=()
if has avx2 && has fma; then candidates+=(Haswell); fi
if has avx; then candidates+=(Sandybridge); fi
candidates+=(Nehalem Core2)
kernels=()
for k in "${candidates[@]}"; do
    [ "${k,,}" = "${own,,}" ] && continue
    [ ${#kernels[@]} -lt 2 ] && kernels+=("$k")
done
log="$PWD/${CARGO_TARGET_DIR:-target}/blas-kernels.log"
case "${CARGO_TARGET_DIR:-}" in /*) log="$CARGO_TARGET_DIR/blas-kernels.log" ;; esac
# the synthesis crate's test executables of the workspace's build (the one scripts/test.sh
# has made: `-p nigel-synthesis` alone would unify other features and rebuild dependencies)
# (NIGEL_TEST_EXECUTABLES: cargo's JSON messages of that build, when the caller has them)
artifacts() {
    if [ -n "${NIGEL_TEST_EXECUTABLES:-}" ]; then cat "$NIGEL_TEST_EXECUTABLES"
    else cargo test --release --workspace --no-run --message-format=json 2>/dev/null; fi
}
exes=$(artifacts | python3 scripts/test-executables.py - synthesis)
run_synthesis_tests() {
    local exe
    # as cargo test runs them: from the crate's folder
    for exe in $exes; do (cd synthesis && "$exe" --quiet) || return 1; done
}
for k in "${kernels[@]}"; do
    echo "== synthesis tests with OPENBLAS_CORETYPE=$k"
    if ! OPENBLAS_CORETYPE="$k" OPENBLAS_VERBOSE=2 run_synthesis_tests >"$log" 2>&1; then
        grep -v '^Core: ' "$log" || true
        echo "synthesis tests failed with OPENBLAS_CORETYPE=$k" >&2
        exit 1
    fi
    grep -v '^Core: ' "$log" | grep -E '^test result|passed|failed' || true
    grep -q "^Core: $k\$" "$log" || { echo "OpenBLAS did not use the $k kernel (not a DYNAMIC_ARCH build?)" >&2; exit 1; }
done

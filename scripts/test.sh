#!/usr/bin/env bash
# Runs every test of the workspace from a fresh clone: system packages and cross
# toolchains, the FMUs for every platform, the Rust tests (release profile, the same build
# the FMUs use; build-fmu/tests/platforms.rs runs each platform's libraries natively, under
# wine and under qemu-user, and checks the darwin64 ones structurally) and the fmpy
# cross-checks, which load the archives' linux64 libraries.
set -euo pipefail
cd "$(dirname "$0")/.."
# the repository (some steps below run from a crate's folder)
repo_dir="$PWD"
# the target folder as an absolute path (CARGO_TARGET_DIR may be relative to the repository)
target_dir="${CARGO_TARGET_DIR:-target}"
case "$target_dir" in /*) ;; *) target_dir="$PWD/$target_dir" ;; esac
# Each stage prints its wall time and the CPU time of its processes (user + system, from the
# shell's children in /proc), and the run ends with the table: on a shared machine the wall
# time varies, the CPU time hardly.
ticks=$(getconf CLK_TCK)
children_cpu() { awk -v t="$ticks" '{ sub(/^.*\) /, ""); print ($14 + $15) / t }' /proc/$$/stat; }
stage_table=""
stage_name=""
stage() {
    local cpu now
    cpu=$(children_cpu)
    now=$SECONDS
    if [ -n "$stage_name" ]; then
        stage_table+=$(printf '%6d s %7.0f s  %s' $((now - stage_wall)) "$(awk -v a="$cpu" -v b="$stage_cpu" 'BEGIN { print a - b }')" "$stage_name")$'\n'
    fi
    stage_name="$1"
    stage_wall=$now
    stage_cpu=$cpu
    [ -n "$1" ] && echo "== $1"
    return 0
}
# Steps that need few cores run beside others (their output to target/background-NAME.log):
# `background NAME CMD...` starts one, `wait_for NAME` waits for it and fails the run with its
# log when it failed. Their CPU time counts in the stage that waits for them.
declare -A background_pids
# a failing stage ends the run: its background steps end with it
trap 'kill $(jobs -p) 2>/dev/null || true' EXIT
background() {
    local name="$1"
    shift
    "$@" >"$target_dir/background-$name.log" 2>&1 &
    background_pids[$name]=$!
}
wait_for() {
    local name="$1"
    if ! wait "${background_pids[$name]}"; then
        cat "$target_dir/background-$name.log" >&2
        echo "the background step '$name' failed (its log above: $target_dir/background-$name.log)" >&2
        exit 1
    fi
}
stage_summary() {
    stage ""
    echo "== time per stage (wall, CPU)"
    printf '%s' "$stage_table"
    printf '%6d s %7.0f s  all\n' "$SECONDS" "$(children_cpu)"
}
# A fresh run writes some 8 GB under target/ and 3 GB of toolchains under ~/.rustup and
# ~/.cargo: with less room it would fail hours later at a random step, so it stops here.
free_mib=$(df -Pm "$repo_dir" | awk 'NR == 2 { print $4 }')
echo "free disk space beside the repository: $free_mib MiB"
if [ "$free_mib" -lt 4096 ]; then
    echo "scripts/test.sh: only $free_mib MiB free on the disk of $repo_dir; a run needs up to 11 GB (8 GB of it under target/ when fresh)" >&2
    exit 1
elif [ "$free_mib" -lt 12288 ]; then
    echo "warning: $free_mib MiB free; a fresh run needs up to 11 GB (less when target/ is already built)" >&2
fi
# A test that hangs must not hold CI for its whole 90 minutes: after 70 (the run takes some
# 21 on CI) the run is stopped with a message, and the last "== stage" line above says where.
watchdog_minutes="${NIGEL_TEST_WATCHDOG_MINUTES:-70}"
kill_tree() {
    local child
    for child in $(ps -o pid= --ppid "$1"); do kill_tree "$child"; done
    kill -TERM "$1" 2>/dev/null || true
}
(
    # (the sleep is this subshell's child, ended with it when the run ends first: no process
    # of the run outlives it)
    sleeper=""
    trap 'kill "$sleeper" 2>/dev/null; exit 0' TERM
    sleep $((watchdog_minutes * 60)) </dev/null >/dev/null 2>&1 &
    sleeper=$!
    wait "$sleeper"
    echo "scripts/test.sh: still running after $watchdog_minutes minutes: stopped (a test hangs?)" >&2
    for child in $(ps -o pid= --ppid $$); do
        [ "$child" != "$BASHPID" ] && kill_tree "$child"
    done
    kill -TERM $$
) &
stage "import circles between the files of each crate (scripts/import-cycles.py)"
python3 scripts/import-cycles.py --self-test
python3 scripts/import-cycles.py
stage "system packages and cross toolchains"
bash scripts/setup-system.sh
bash scripts/setup-cross.sh
mkdir -p "$target_dir"
# the Python venv (pip, mostly waiting on downloads and unpacking) beside the FMUs' build
background venv bash scripts/python-env.sh
stage "building the FMUs (linux64, win64, aarch64-linux, darwin64)"
cargo run --release --quiet -p build-fmu -- --platforms all
stage "rebuilding from touched sources must give byte-identical archives"
# (the rebuild writes its closed-loop SSPs over target/ssp/: the first ones are kept aside)
rm -rf "$target_dir/ssp-first" && cp -r "$target_dir/ssp" "$target_dir/ssp-first"
touch fmu-plant/src/lib.rs fmi-export/src/abi/fmi2.rs fmi-export/src/abi/fmi3.rs
cargo run --release --quiet -p build-fmu -- --platforms all "$target_dir/fmu-rebuild" >/dev/null
# the archives of build-fmu's list, FMI 2.0 (ID.fmu) and FMI 3.0 (fmi3/ID.fmu) (target/fmu
# may also hold FMUs the examples wrote)
archives=$(grep -o '"fmu": "[^"]*"' "$target_dir/fmu/manifest.json" | cut -d'"' -f4)
[ -n "$archives" ] || { echo "no FMU in $target_dir/fmu/manifest.json" >&2; exit 1; }
for a in $archives; do
    cmp "$target_dir/fmu/$a" "$target_dir/fmu-rebuild/$a" || { echo "rebuilt $a differs" >&2; exit 1; }
    echo "identical: $a"
done
for ssp in nigel_closed_loop.ssp nigel_closed_loop_fmi3.ssp; do
    cmp "$target_dir/ssp-first/$ssp" "$target_dir/ssp/$ssp" || { echo "rebuilt $ssp differs" >&2; exit 1; }
    echo "identical: $ssp"
done
# the platform tests fail, rather than skip, when an archive lacks a platform
export NIGEL_REQUIRE_PLATFORMS=all
stage "Python venv with fmpy (built beside the FMUs)"
wait_for venv
export FMPY_PYTHON="$target_dir/venv/bin/python"
stage "Rust tests"
cargo test --release --workspace --no-fail-fast --no-run
# the instrumented builds of the two ASan steps below (nightly, their own target dir) beside
# the tests' runs, many of which use one core (wine, qemu, single long tests)
rustup toolchain install nightly --profile minimal >/dev/null 2>&1 || true
asan() {
    RUSTFLAGS="-Zsanitizer=address" cargo +nightly "$1" --target x86_64-unknown-linux-gnu \
        --target-dir "$target_dir/asan" "${@:2}"
}
asan_builds() {
    asan test --no-run -p fmi-export --test toy
    asan test --no-run -p fmu-plant --test fmi3
    # the three cdylibs instrumented (the debug profile of target/asan)
    asan build --lib -p fmu-plant -p fmu-controller -p fmu-maneuver \
        --features fmu-plant/fmi-export,fmu-controller/fmi-export,fmu-maneuver/fmi-export
}
background asan-builds asan_builds
# the third-party corpus (../shared/corpus: FMUs and SSPs nobody here wrote) through the corpus's
# own runners, one case at a time, beside the tests' runs; its table is printed below
if [ -d ../shared/corpus ]; then
    background conformance bash scripts/conformance.sh "$target_dir/release/cosim" ../shared/corpus
else
    echo "no ../shared/corpus beside the project: the third-party conformance cases are not run"
fi
cargo test --release --workspace --no-fail-fast
wait_for asan-builds
# the test executables of this build, for the steps below that run some again: a `cargo test
# -p PACKAGE` would unify other features and rebuild dependencies
export NIGEL_TEST_EXECUTABLES="$target_dir/test-executables.json"
cargo test --release --workspace --no-run --message-format=json >"$NIGEL_TEST_EXECUTABLES"
# test_executable CRATE_FOLDER TEST: the executable of the integration test TEST of the crate
test_executable() { python3 "$repo_dir/scripts/test-executables.py" "$NIGEL_TEST_EXECUTABLES" "$1" "$2"; }
# the master and the Python package on the other platforms, beside the stages below (their
# cross builds take one core most of the time; docs/platforms.md has what each costs): the
# master's release archives for x86-64 and aarch64 Linux and Windows built and run under wine
# and qemu on the closed loop, compared with x86-64 Linux (scripts/test-dist.sh), and the
# aarch64 Linux wheel built, its tags and native module checked (scripts/wheel-check.py) and
# run under qemu by an aarch64 CPython (scripts/test-wheel-aarch64.sh), and the Windows wheel
# built into the Windows master's target folder and checked (no Windows CPython to run it).
# The macOS archives and wheel are left out: their two -Zbuild-std targets cost too much CPU
# for CI's budget (docs/platforms.md)
other_platforms() {
    NIGEL_DIST_PLATFORMS=linux64,win64,aarch64-linux bash scripts/test-dist.sh
    local wheel version
    wheel="$(bash scripts/python-wheel.sh linux-aarch64)"
    python3 scripts/wheel-check.py "$wheel" linux-aarch64
    # its run under qemu by Debian's arm64 CPython, against test-dist.sh's aarch64 cosim
    version="$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
    bash scripts/test-wheel-aarch64.sh "$wheel" "$target_dir/dist-test/cosim-$version-aarch64-unknown-linux-gnu/cosim"
    wheel="$(bash scripts/python-wheel.sh windows-x86_64)"
    python3 scripts/wheel-check.py "$wheel" windows-x86_64
}
background other-platforms other_platforms
stage "the layer's C ABIs (FMI 2.0 and 3.0) in process under AddressSanitizer"
# the toy through both ABIs, the plant's FMI 3.0 runs and derivatives: an out-of-bounds
# read or write, a use after free or a double free in the layer stops the test
asan test -p fmi-export --test toy
asan test -p fmu-plant --test fmi3
stage "the FMU libraries under AddressSanitizer: random call sequences, dlopen abuse, the C importers under ASan+UBSan"
# the three cdylibs instrumented (built beside the Rust tests: the debug profile of
# target/asan), loaded in place of the archives' linux64 libraries through
# NIGEL_FMU_LIBRARIES: by the release test binaries of the tests crate (uninstrumented
# Rust, with gcc's ASan runtime preloaded: it serves the instrumented library's checks and
# takes over malloc and free) and by the C importers built with -fsanitize=address,undefined
export NIGEL_FMU_LIBRARIES="$target_dir/asan/x86_64-unknown-linux-gnu/debug"
asan_runtime=$(gcc -print-file-name=libasan.so)
for t in random_calls c_abi c_abi3; do
    exe=$(test_executable tests "$t")
    # the first 3,000 and 1,500 of the uninstrumented run's seeded sequences of FMI 2.0 and
    # 3.0 (150,000 and 20,000): the instrumented debug build is some ten times slower
    NIGEL_RANDOM_SEQUENCES=3000 NIGEL_RANDOM_SEQUENCES3=1500 LD_PRELOAD="$asan_runtime" \
        ASAN_OPTIONS=detect_leaks=1 "$exe" --quiet
done
(cd build-fmu && "$(test_executable build-fmu platforms)" --quiet linux64_c_importers_under_asan_and_ubsan)
unset NIGEL_FMU_LIBRARIES
stage "synthesis tests under two more OpenBLAS kernels"
bash scripts/test-blas-kernels.sh
stage "the Python package: its wheel in a fresh venv (README.md's install line), against fmpy and the command lines"
bash scripts/test-python-package.sh
# the wheel also into target/venv, as the main command does: the README's quick start (run
# by tests/python/test_doc_figures.py) imports nigel_cosim and fmpy from one venv
bash scripts/python-venv-wheel.sh >/dev/null
stage "fmpy cross-checks"
# (tests/python/test_fmi3_archives.py: the FMI 3.0 archives against the FMI 2.0 ones, and the
# own-controller example's two archives, which it builds with `cargo run -p own-controller`)
"$target_dir/venv/bin/python" -m pytest tests/python -q
stage "co-simulation master cross-checks"
"$target_dir/venv/bin/python" -m pytest cosim/tests/python -q
stage "Table III closed loop as SSP in fmpy"
"$target_dir/venv/bin/python" -m pytest table3/tests/python -q
stage "examples (each prints what its header says; checked against table3)"
"$target_dir/venv/bin/python" -m pytest examples -q
stage "campaign results in fmpy and pandas"
"$target_dir/venv/bin/python" -m pytest campaign/tests/python -q
stage "campaign on a local Slurm cluster"
bash scripts/test-campaign-slurm.sh
if [ -d ../shared/corpus ]; then
    stage "third-party conformance (run beside the Rust tests): the table"
    wait_for conformance
    cat "$target_dir/background-conformance.log"
fi
stage "the master and the Python package on every platform (run beside the stages above): the log"
wait_for other-platforms
cat "$target_dir/background-other-platforms.log"
stage_summary

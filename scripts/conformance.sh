#!/usr/bin/env bash
# The third-party conformance run: the corpus's FMI 2.0 FMUs (under cosim's default solver, auto,
# then the Model Exchange ones again under dopri5 and under bdf), its FMI 3.0 FMUs and its SSP systems, each case
# in child processes with the corpus's own runners, then one table (scripts/conformance_table.py),
# whose referee decides, where cosim and fmpy differ, which one is right.
# usage: bash scripts/conformance.sh [COSIM] [CORPUS]     (defaults: target/release/cosim, ../shared/corpus)
# Exit status: 0 when every case fmpy completes cosim completes with results equal to fmpy's
# or right by the referee (the shipped reference, the input file, fmpy at a tight tolerance),
# or is listed in scripts/conformance-known.txt with its reason;
# 1 otherwise (a crash, a hang or a wrong value always counts).
set -euo pipefail
cd "$(dirname "$0")/.."
target_dir="${CARGO_TARGET_DIR:-target}"
cosim="$(realpath "${1:-$target_dir/release/cosim}")"
corpus="${2:-../shared/corpus}"
python="${FMPY_PYTHON:-$target_dir/venv/bin/python}"
if [ ! -d "$corpus" ]; then
    echo "conformance: no corpus at $corpus: the third-party cases were not run"
    exit 0
fi
[ -x "$cosim" ] || { echo "conformance: no cosim at $cosim (build it: cargo build --release -p nigel-cosim)" >&2; exit 1; }
work="${NIGEL_CONFORMANCE_WORK:-$target_dir/conformance}"
rm -rf "$work" && mkdir -p "$work"
# absolute: the runners run each case from a folder of its own
work="$(cd "$work" && pwd)"
# each case's TMPDIR under the work folder: an FMU that leaves its unpacked files shows there
export TMPDIR="$work/tmp" && mkdir -p "$TMPDIR"
run_part() {
    local name="$1"
    shift
    echo "== conformance: $name"
    "$python" "$@" >"$work/$name.log" 2>&1 || true
    tail -n 3 "$work/$name.log"
}
run_part fmi3 "$corpus/fmi3.py" --suite "$corpus/fmi3" --cosim "$cosim" --work "$work/fmi3" --json "$work/fmi3.json"
# the referee of the FMI 3.0 cases where cosim and fmpy differ (a tight-tolerance fmpy run each,
# 1 to 80 s) beside the other parts
# the tight runs' results are kept between runs (they depend on the FMU, its input and fmpy only:
# MapleSim SlidingCrank's takes 50 to 140 s)
export NIGEL_CONFORMANCE_REFEREE_CACHE="$(realpath -m "$target_dir/conformance-referee")"
"$python" scripts/conformance_table.py --referee-only "$work" "$corpus" fmi3 >"$work/fmi3-referee.log" 2>&1 &
referee_pid=$!
# every FMI 2.0 case (CS and ME) with cosim's default solver, auto (rk4, continuing with bdf
# from the first step it finds stiff): what a user who names no solver gets, against fmpy's
# default (CVode); the runner always names a solver, so auto is named here
run_part fmi2 "$corpus/fmi2.py" --fmus "$corpus/fmi2" --cosim "$cosim" --work "$work/fmi2" --solver auto --json "$work/fmi2.json"
# the Model Exchange cases again with cosim's two other solvers: dopri5 (explicit; on the stiff
# MapleSim Rectifier slower than fmpy's CVode, as an explicit solver on a stiff model is) and bdf
run_part fmi2-dopri5 "$corpus/fmi2.py" --fmus "$corpus/fmi2" --cosim "$cosim" --work "$work/fmi2-dopri5" --only me/ --solver dopri5 --json "$work/fmi2-dopri5.json"
run_part fmi2-bdf "$corpus/fmi2.py" --fmus "$corpus/fmi2" --cosim "$cosim" --work "$work/fmi2-bdf" --only me/ --solver bdf --json "$work/fmi2-bdf.json"
run_part ssp "$corpus/ssp.py" "$cosim" "$corpus/ssp" --work "$work/ssp" --json "$work/ssp.json"
wait "$referee_pid" || tail -n 3 "$work/fmi3-referee.log"
# cosim unpacks into nigel-cosim-* folders and removes them, also after a failed run (fmpy
# leaves its own tmp* folders behind: not ours to judge)
leftover=$(find "$TMPDIR" -mindepth 1 -maxdepth 1 -name "nigel-cosim-*" | head -5)
exec "$python" scripts/conformance_table.py "$work" scripts/conformance-known.txt "$corpus" ${leftover:+--leftover "$leftover"}

#!/usr/bin/env bash
# One's own gain through the benchmark: design a state feedback with the synthesis, then run
# it in Table III (table3 --gain) and in the closed-loop SSP (cosim run --gains). Both read the
# JSON that `synthesize --json` writes: its "K", rows FL, FR, RL, RR, columns beta, r.
#
#   cargo run --release -p build-fmu            # target/fmu/*.fmu and target/ssp/nigel_closed_loop.ssp
#   bash examples/own_gain.sh [OUT_DIR]         # default target/examples/own_gain
#
# The design here is the paper's problem on the physical disturbance column (--d2 physical,
# Table II geometry) instead of the printed one. Prints, after the synthesis' own report:
#   - table3's sim and real lane-change rows with the robust controller and "custom" (the
#     gain of k.json): sim custom 6.126e-2, real custom 3.549e-2;
#   - "cosim custom epsilon 6.126091740e-02": the same sim lane-change job run by the master
#     from the SSP with the gain set by --gains, scored here from its CSV.
# The test (examples/test_examples.py) checks that the two epsilons agree to 1e-9 relative
# and that both use the gain in k.json.
set -euo pipefail
. "$(dirname "$0")/../scripts/target-dir.sh"
out="${1:-$target/examples/own_gain}"
mkdir -p "$out"
cd "$repo"
cargo build --release --quiet -p nigel-synthesis --bin synthesize -p nigel-table3 --bin table3 -p nigel-cosim --bin cosim
bin="$target/release"

# 1. the design: gamma*, the Pareto sweep, the chosen K, its verification -> k.json
"$bin/synthesize" --arch 4ws --d2 physical --json "$out/k.json" --quiet

# 2. Table III with it: the robust controller and the custom gain, lane change, both columns
"$bin/table3" --quiet --gain "$out/k.json" --controller robust --maneuver lane_change --json "$out/table3.json"

# 3. the closed-loop SSP in the master with it (sim, lane change, seed 0), pose and reference recorded
"$bin/cosim" run "$target/ssp/nigel_closed_loop.ssp" --algorithm ordered --stop-time 30 --step 1e-3 \
    --gains "$out/k.json" --output "$out/cosim.csv" \
    --record plant.x --record plant.y --record plant.psi \
    --record maneuver.x_ref --record maneuver.y_ref --record maneuver.psi_ref \
    --record controller.gain_beta_fl --record controller.gain_yaw_rate_rr
# epsilon = ||(RMSE_X, RMSE_Y, RMSE_psi)|| over t = 1 ms .. 30 s (docs/benchmark.md)
awk -F, 'NR > 2 { for (i = 0; i < 3; i++) { d = $(2 + i) - $(5 + i); s[i] += d * d }; n++ }
         END { printf "cosim custom epsilon %.9e\n", sqrt((s[0] + s[1] + s[2]) / n) }' "$out/cosim.csv"

#!/usr/bin/env bash
# One's own controller FMU in the loop in place of ours: the crate examples/own-controller
# (a sampled 1 ms P law on the yaw rate and the speed, ~200 lines on fmi-export) is packaged
# as target/fmu/own_controller.fmu (and as the FMI 3.0 archive target/fmu/fmi3/own_controller.fmu)
# and put into the closed-loop SSP in place of
# nigel_controller (target/ssp/own_controller_closed_loop.ssp, same connections); the master
# runs the sim lane change (seed 0, 30 s, 1 ms) from it.
#
#   cargo run --release -p build-fmu               # target/fmu/*.fmu and target/ssp/nigel_closed_loop.ssp
#   bash examples/own_controller.sh [OUT_DIR]      # default target/examples/own_controller
#
# Prints the paths of the two FMUs and the SSP, then
#   "own controller epsilon 1.158163341e-01"
# the lane change's epsilon = ||(RMSE_X, RMSE_Y, RMSE_psi)|| over t = 1 ms .. 30 s
# (docs/benchmark.md), scored from the master's CSV (OUT_DIR/cosim.csv). Our robust controller
# scores 4.204754401e-02 on the same job. The test (examples/test_examples.py) recomputes
# epsilon from the CSV, checks the recorded commands against the P law, and that the result
# differs from the robust and the open-loop ones of table3.
set -euo pipefail
. "$(dirname "$0")/../scripts/target-dir.sh"
out="${1:-$target/examples/own_controller}"
mkdir -p "$out"
cd "$repo"
cargo build --release --quiet -p own-controller -p nigel-cosim --bin own-controller --bin cosim
bin="$target/release"

# 1. the FMU and the SSP with it
"$bin/own-controller"

# 2. the closed loop in the master: pose and reference (for epsilon), the law's inputs and outputs
c=controller
"$bin/cosim" run "$target/ssp/own_controller_closed_loop.ssp" --algorithm ordered --stop-time 30 --step 1e-3 \
    --output "$out/cosim.csv" \
    --record plant.x --record plant.y --record plant.psi \
    --record maneuver.x_ref --record maneuver.y_ref --record maneuver.psi_ref \
    --record $c.yaw_rate --record $c.yaw_rate_ref --record $c.speed --record $c.speed_ref \
    --record $c.delta_ff_fl --record $c.delta_ff_rl --record $c.delta_fl --record $c.delta_rl --record $c.drive_force
# epsilon = ||(RMSE_X, RMSE_Y, RMSE_psi)|| over t = 1 ms .. 30 s (docs/benchmark.md)
awk -F, 'NR > 2 { for (i = 0; i < 3; i++) { d = $(2 + i) - $(5 + i); s[i] += d * d }; n++ }
         END { printf "own controller epsilon %.9e\n", sqrt((s[0] + s[1] + s[2]) / n) }' "$out/cosim.csv"

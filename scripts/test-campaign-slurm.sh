#!/usr/bin/env bash
# The campaign on a real Slurm cluster (scripts/slurm-local.sh, one node on 127.0.0.1):
# 40 runs of the example's system as 4 array tasks, merged and compared byte for byte with
# a local run; then again with one task cancelled on purpose while it runs, the merge
# refused naming the missing shard, the shard completed with --resume, merged and compared;
# the cluster stopped by PID and no daemon left.
set -euo pipefail
cd "$(dirname "$0")/.."
target_dir="${CARGO_TARGET_DIR:-target}"
campaign="$(realpath "$target_dir/release/campaign")"
[ -x "$campaign" ] || cargo build --release --quiet -p nigel-campaign
work="$(mktemp -d)"
chmod 755 "$work"  # munged (user munge) must reach its folders
export SLURM_LOCAL_DIR="$work/cluster"
stopped=0
cleanup() {
    [ "$stopped" = 1 ] || bash scripts/slurm-local.sh stop >/dev/null || true
    rm -rf "$work"
}
trap cleanup EXIT
SECONDS=0
bash scripts/slurm-local.sh start
export SLURM_CONF="$SLURM_LOCAL_DIR/slurm/slurm.conf"
pids=$(cat "$SLURM_LOCAL_DIR"/munge/munged.pid "$SLURM_LOCAL_DIR"/slurm/slurmctld.pid "$SLURM_LOCAL_DIR"/slurm/slurmd.pid)

# the example with a 4 s horizon and 10 draws: 2 x 2 x 10 = 40 runs
ssp="$(realpath "$target_dir/ssp/nigel_closed_loop.ssp")"
sed -e "s|^system = .*|system = \"$ssp\"|" -e 's/^stop_time = 30.0/stop_time = 4.0/' -e 's/^samples = 20 /samples = 10 /' \
    campaigns/example.toml > "$work/small.toml"
"$campaign" run "$work/small.toml" --out "$work/local" 2>/dev/null
"$campaign" slurm "$work/small.toml" --out "$work/slurm" --tasks 4 --submit
cmp "$work/local/results.csv" "$work/slurm/results.csv"
echo "slurm: 40 runs as 4 array tasks, merged: byte-identical to the local run"

# one task cancelled while it runs: 30 s runs, 4 tasks of 10
sed -e 's/^stop_time = 4.0/stop_time = 30.0/' "$work/small.toml" > "$work/long.toml"
"$campaign" slurm "$work/long.toml" --out "$work/killed" --tasks 4 >/dev/null
job=$(sbatch --parsable "$work/killed/campaign.sbatch")
shard="$work/killed/shards/2-of-4.csv"
for _ in $(seq 600); do
    [ -f "$shard" ] && [ "$(($(wc -l < "$shard") - 1))" -ge 2 ] && break
    sleep 0.05
done
scancel "${job}_2"
while [ -n "$(squeue -h -r -j "$job" -o %i)" ]; do sleep 0.2; done
rows=$(($(wc -l < "$shard") - 1))
[ "$rows" -lt 10 ] || { echo "task 2 finished its 10 runs before it was cancelled" >&2; exit 1; }
echo "slurm: task 2 cancelled after $rows of its 10 runs"
if msg=$("$campaign" merge "$work/killed" 2>&1); then
    echo "merge accepted a campaign with a cancelled task" >&2
    exit 1
fi
echo "$msg"
grep -q "shard 2/4" <<<"$msg"
# the missing runs again, as an array task of its own
again=$(sbatch --parsable --array=2 "$work/killed/campaign.sbatch")
while [ -n "$(squeue -h -r -j "$again" -o %i)" ]; do sleep 0.2; done
"$campaign" merge "$work/killed"
"$campaign" run "$work/long.toml" --out "$work/local-long" 2>/dev/null
cmp "$work/local-long/results.csv" "$work/killed/results.csv"
echo "slurm: resumed task merged: byte-identical to the local run"

bash scripts/slurm-local.sh stop
stopped=1
for pid in $pids; do
    if kill -0 "$pid" 2>/dev/null; then
        echo "daemon $pid still running" >&2
        exit 1
    fi
done
echo "slurm: cluster stopped, no daemon left ($SECONDS s in all)"

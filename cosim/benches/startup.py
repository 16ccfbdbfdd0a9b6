"""The whole `cosim run` process against ecos in process, on the closed loop, alternated.

Usage: target/venv/bin/python cosim/benches/startup.py COSIM SSP [SSP_ONE_PLATFORM] [ROUNDS]

Each round runs, one after the other:
- `cosim run SSP --stop-time 30 --step 1e-3 --record plant.x --output X.csv`, timed from
  the start of the process to its end (start-up, unpacking and loading the three FMUs, the
  30,000 steps, the CSV);
- the same with every output recorded (`--output X.csv` alone);
- ecos (ecospy) in this Python process on the same SSP: `EcosSimulation(...)` (its unpacking
  and loading), `init`, `step(30000)`, `terminate`, timed around those calls only (not
  Python's start nor the import of ecospy);
- `cosim run ... --stop-time 0.001` on SSP and on SSP_ONE_PLATFORM (start-up: one step).
With COSIM_BASELINE=/path/to/an/older/cosim, that binary's start-up and `--record plant.x`
run on SSP are timed in the same rounds. Prints, per run, the median and the range (min .. max) over the rounds, and the ratios of
the medians. The machine is shared: read the ranges, not only the medians.
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time

cosim, ssp = sys.argv[1], sys.argv[2]
one = sys.argv[3] if len(sys.argv) > 3 and sys.argv[3] != "-" else None
rounds = int(sys.argv[4]) if len(sys.argv) > 4 else 7
N = 30000
out = tempfile.NamedTemporaryFile(suffix=".csv", delete=False).name


baseline = os.environ.get("COSIM_BASELINE")


def whole(args, binary=None):
    t = time.perf_counter()
    subprocess.run([binary or cosim, "run", *args, "--output", out], check=True, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t


def ecos():
    from ecospy import EcosSimulation

    t = time.perf_counter()
    sim = EcosSimulation(ssp_path=ssp, step_size=1e-3)
    sim.init(parameter_set="initialValues")  # ecos applies a binding only when named
    sim.step(N)
    sim.terminate()
    return time.perf_counter() - t


runs = {
    "cosim run, --record plant.x (whole process)": lambda: whole(
        [ssp, "--stop-time", "30", "--step", "1e-3", "--record", "plant.x"]),
    "cosim run, all outputs to CSV (whole process)": lambda: whole([ssp, "--stop-time", "30", "--step", "1e-3"]),
    "ecos in process (load, init, step(30000))": ecos,
    "cosim start-up (one step), this SSP": lambda: whole([ssp, "--stop-time", "0.001", "--step", "1e-3"]),
}
if one:
    runs["cosim start-up (one step), one-platform SSP"] = lambda: whole(
        [one, "--stop-time", "0.001", "--step", "1e-3"])
if baseline:
    runs["baseline cosim run, --record plant.x"] = lambda: whole(
        [ssp, "--stop-time", "30", "--step", "1e-3", "--record", "plant.x"], baseline)
    runs["baseline cosim start-up (one step), this SSP"] = lambda: whole(
        [ssp, "--stop-time", "0.001", "--step", "1e-3"], baseline)
times = {k: [] for k in runs}
ecos()  # warm the file cache and ecospy's import once, untimed
whole([ssp, "--stop-time", "0.001", "--step", "1e-3"])
for _ in range(rounds):
    for k, f in runs.items():
        times[k].append(f())
med = {k: statistics.median(v) for k, v in times.items()}
print(f"{rounds} rounds, alternated; SSP {ssp}")
for k, v in times.items():
    print(f"{k:<50} median {med[k] * 1e3:7.1f} ms  range {min(v) * 1e3:7.1f} .. {max(v) * 1e3:7.1f} ms")
e = med["ecos in process (load, init, step(30000))"]
for k in list(runs)[:2]:
    print(f"ecos / {k}: {e / med[k]:.2f}x (ratio of medians)")
if one:
    a, b = med["cosim start-up (one step), this SSP"], med["cosim start-up (one step), one-platform SSP"]
    print(f"start-up, this SSP / one-platform SSP: {a / b:.2f}")
if baseline:
    a, b = med["baseline cosim start-up (one step), this SSP"], med["cosim start-up (one step), this SSP"]
    print(f"start-up, baseline / this cosim: {a / b:.2f}x")
    print(f"ecos / baseline cosim run, --record plant.x: {e / med['baseline cosim run, --record plant.x']:.2f}x")

"""nigel_cosim from Python against the Python masters users pick instead, side by side in one
run, alternated round by round, medians and spreads (min-max) printed:

- the closed loop (target/ssp/nigel_closed_loop.ssp), 30 s at 1 ms: ``nigel_cosim.simulate_ssp``
  (results in hand: every output, 30,001 rows, as a structured array) against ecos (ecospy,
  ``step(30000)`` with the SSP's parameter set, nothing recorded) and libcosim (libcosimpy,
  ``simulate_until(30 s)``, nothing recorded);
- the plant FMU alone, 30 s at 1 ms in Co-Simulation: ``nigel_cosim.simulate_fmu`` against
  ``fmpy.simulate_fmu`` with the same keywords (both return the same array, checked).

Each timing is the whole call as a user makes it (loading and unpacking included for
simulate_ssp / simulate_fmu / fmpy; ecos and libcosim load in their constructors, which are
timed too). Run: ``bash python/benches/run.sh`` (builds the wheel, uses the test venv's
fmpy, ecospy and libcosimpy)."""

import statistics
import sys
import time
from pathlib import Path

import fmpy
import numpy as np

import nigel_cosim

TARGET = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2] / "target"
SSP = str(TARGET / "ssp" / "nigel_closed_loop.ssp")
PLANT = str(TARGET / "fmu" / "nigel_plant.fmu")
ROUNDS = int(sys.argv[2]) if len(sys.argv) > 2 else 5
N = 30000


def timed(f):
    t = time.perf_counter()
    f()
    return time.perf_counter() - t


def ours_closed_loop():
    r = nigel_cosim.simulate_ssp(SSP, stop_time=30.0, step_size=1e-3)
    assert len(r) == N + 1


def ecos_closed_loop():
    from ecospy import EcosSimulation

    sim = EcosSimulation(ssp_path=SSP, step_size=1e-3)
    sim.init(parameter_set="initialValues")  # ecos applies a binding only when named
    sim.step(N)
    sim.terminate()


def libcosim_closed_loop():
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_ssp_file(SSP, step_size=1_000_000)  # ns
    ex.simulate_until(30_000_000_000)


PLANT_ARGS = dict(stop_time=30.0, output_interval=1e-3)


def ours_plant():
    nigel_cosim.simulate_fmu(PLANT, **PLANT_ARGS)


def fmpy_plant():
    fmpy.simulate_fmu(PLANT, **PLANT_ARGS)


def compare(name, ours, theirs):
    times = {"ours": [], "theirs": []}
    for k in range(ROUNDS):
        # alternate which side goes first, so a slow phase of the machine hits both
        order = [("ours", ours), ("theirs", theirs)] if k % 2 == 0 else [("theirs", theirs), ("ours", ours)]
        for side, f in order:
            times[side].append(timed(f))
    mo, mt = statistics.median(times["ours"]), statistics.median(times["theirs"])
    ratios = sorted(t / o for o, t in zip(times["ours"], times["theirs"]))
    print(
        f"{name:<44} ours {mo * 1e3:8.1f} ms [{min(times['ours']) * 1e3:.1f}-{max(times['ours']) * 1e3:.1f}]"
        f"  theirs {mt * 1e3:9.1f} ms [{min(times['theirs']) * 1e3:.1f}-{max(times['theirs']) * 1e3:.1f}]"
        f"  ratio of medians {mt / mo:6.1f}x (per round {ratios[0]:.1f}-{ratios[-1]:.1f}x)",
        flush=True,
    )


# the two plant runs give the same numbers (so the ratio compares equal work)
a = nigel_cosim.simulate_fmu(PLANT, **PLANT_ARGS)
b = fmpy.simulate_fmu(PLANT, **PLANT_ARGS)
assert a.dtype.names == b.dtype.names and all(np.array_equal(a[n], b[n]) for n in b.dtype.names)

print(f"{ROUNDS} rounds, alternated; medians [min-max]")
compare("closed loop 30 s @ 1 ms vs ecospy 0.7.2", ours_closed_loop, ecos_closed_loop)
compare("closed loop 30 s @ 1 ms vs libcosimpy 0.0.6", ours_closed_loop, libcosim_closed_loop)
compare("plant alone 30 s @ 1 ms vs fmpy 0.3.32", ours_plant, fmpy_plant)

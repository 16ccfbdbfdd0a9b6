"""nigel_cosim from Python: the benchmark's closed loop (target/ssp/nigel_closed_loop.ssp:
plant, robust controller and lane-change test bench, 30 s at 1 ms, ordered), its metric
(docs/benchmark.md's epsilon), a sweep of the vehicle's mass from one load of the system, a
small Monte Carlo campaign as a pandas DataFrame, and a figure.

    bash scripts/run.sh                                  # target/ssp, target/wheels
    python3 -m venv .venv && .venv/bin/pip install "target/wheels/nigel_cosim-0.1.0-cp310-abi3-manylinux2014_x86_64.manylinux_2_17_x86_64.whl[pandas]" matplotlib
    .venv/bin/python examples/python_cosim.py [OUT.png]      # or target/venv/bin/python, made by run.sh

Prints (the sim lane change with the robust controller, seed 0, `ordered`, as `table3` computes it):

    epsilon 4.204754401e-02 (RMSE X 0.0007 m, Y 0.0419 m, psi 0.00383 rad)
    mass 2.4 kg: epsilon ...
    campaign: 8 runs, epsilon median ...
    wrote python_cosim.png
"""
import sys
from pathlib import Path

import numpy as np

import nigel_cosim

REPO = Path(__file__).resolve().parents[1]
SSP = REPO / "target" / "ssp" / "nigel_closed_loop.ssp"
POSE = ["plant.x", "plant.y", "plant.psi", "maneuver.x_ref", "maneuver.y_ref", "maneuver.psi_ref"]


def epsilon(result):
    """docs/benchmark.md: the norm of the RMSEs of x, y and psi over t_1 .. t_N."""
    after = result["time"] > 0
    rmse = [np.sqrt(np.mean((result[f"plant.{q}"][after] - result[f"maneuver.{q}_ref"][after]) ** 2)) for q in ("x", "y", "psi")]
    return float(np.linalg.norm(rmse)), rmse


# 1. one call, as fmpy's simulate_ssp (the SSP's parameter bindings applied)
result = nigel_cosim.simulate_ssp(SSP, stop_time=30.0, step_size=1e-3, algorithm="ordered", output=POSE)
eps, (rx, ry, rpsi) = epsilon(result)
print(f"epsilon {eps:.9e} (RMSE X {rx:.4f} m, Y {ry:.4f} m, psi {rpsi:.5f} rad)")

# 2. load once, run many times: the FMUs are unpacked and instantiated once
sweep = {}
with nigel_cosim.System(SSP) as system:
    for m in (2.4, 2.7, 3.0):
        r = system.simulate(stop_time=30.0, step_size=1e-3, algorithm="ordered", start_values={"plant.m": m}, output=POSE)
        sweep[m] = r
        print(f"mass {m} kg: epsilon {epsilon(r)[0]:.6e}")

# 3. a campaign: 2 maneuvers x 4 random masses, threads of this process, as a DataFrame
frame = nigel_cosim.run_campaign(
    {
        "system": str(SSP),
        "stop_time": 10.0,
        "step": 1e-3,
        "algorithm": "ordered",
        "seed": 1,
        "samples": 4,
        "grid": {"maneuver.maneuver": [2, 3]},
        "random": {"plant.m": {"uniform": [2.4, 3.0]}},
        "metrics": {
            "epsilon": "norm(rms_diff(plant.x, maneuver.x_ref), rms_diff(plant.y, maneuver.y_ref), rms_diff(plant.psi, maneuver.psi_ref))"
        },
    }
)
print(f"campaign: {len(frame)} runs, epsilon median {frame['epsilon'].median():.6e}")

# 4. a figure of the sweep
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

png = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("python_cosim.png")
fig, ax = plt.subplots(figsize=(7, 4))
ax.plot(result["time"], result["maneuver.y_ref"], "k--", label="reference")
for m, r in sweep.items():
    ax.plot(r["time"], r["plant.y"], label=f"m = {m} kg")
ax.set_xlabel("time [s]")
ax.set_ylabel("lateral position y [m]")
ax.set_title("Lane change, robust controller: the mass sweep of nigel_cosim.System")
ax.legend()
fig.tight_layout()
fig.savefig(png, dpi=120)
print(f"wrote {png}")

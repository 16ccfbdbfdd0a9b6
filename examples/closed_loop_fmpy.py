"""The benchmark's closed loop in fmpy, from Python: the plant, the controller and the test
bench FMUs connected as in docs/closed-loop.svg, stepped at 1 ms for 30 s, the metric of
docs/benchmark.md computed from the run, and a figure written to PNG.

    cargo run --release -p build-fmu                       # target/fmu/*.fmu
    target/venv/bin/python examples/closed_loop_fmpy.py [OUT.png]

Prints (sim column, lane change, robust controller, seed 0):

    epsilon 4.204754401e-02 (RMSE X 0.0007 m, Y 0.0419 m, psi 0.00383 rad)
    wrote closed_loop_fmpy.png

The same job in `table3 --maneuver lane_change --controller robust --json t.json` gives
eps 0.0420475440138...; the test (examples/test_examples.py) holds the two to 1e-9
relative (the same FMUs, the same step sizes and order: only the last bits of 30,000 RMSE
terms may differ). The loop is "ordered": at
each sample the plant's outputs go to the test bench, the test bench's to the controller,
and the controller's to the plant before any FMU steps, so the controller sees the plant at
t_k, as `cosim run --algorithm ordered` does.
"""
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no display needed

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
FMU_DIR = REPO / "target" / "fmu"
WHEELS = ("fl", "fr", "rl", "rr")
STEP = 1e-3  # s, the benchmark's sample period
SAMPLES = 30_000  # 30 s


class Instance:
    """One Co-Simulation instance of an FMU, with its variables by name."""

    def __init__(self, name):
        path = str(FMU_DIR / f"nigel_{name}.fmu")
        md = read_model_description(path)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path),
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)

    def get(self, names):
        return self.fmu.getReal([self.vr[n] for n in names])

    def set(self, names, values):
        self.fmu.setReal([self.vr[n] for n in names], list(values))


plant, controller, bench = Instance("plant"), Instance("controller"), Instance("maneuver")
# the job: sim column (fidelity 1 = paper), lane change (maneuver 2), robust (controller 3);
# the switches are Integer parameters, their values listed in each variable's description
bench.fmu.setInteger([bench.vr["maneuver"], bench.vr["fidelity"], bench.vr["seed"]], [2, 1, 0])
controller.fmu.setInteger([controller.vr["controller"]], [3])
plant.set(["v_x_start"], [0.35])  # the benchmark's initial speed [m/s]
for i in (plant, controller, bench):
    i.fmu.enterInitializationMode()
    i.fmu.exitInitializationMode()

# connections (outputs -> inputs), grouped by the FMU that reads them
TO_BENCH = (["beta", "yaw_rate"], ["beta", "yaw_rate"])
TO_CONTROLLER_FROM_BENCH = (
    ["beta_meas", "yaw_rate_meas", "beta_ref", "yaw_rate_ref", "speed_ref", "x_ref", "y_ref", "psi_ref"]
    + [f"delta_ff_{w}" for w in WHEELS],
    ["beta", "yaw_rate", "beta_ref", "yaw_rate_ref", "speed_ref", "x_ref", "y_ref", "psi_ref"]
    + [f"delta_ff_{w}" for w in WHEELS],
)
TO_CONTROLLER_FROM_PLANT = (["speed", "x", "y", "psi"], ["speed", "x", "y", "psi"])
TO_PLANT_FROM_BENCH = ([f"mu_{w}" for w in WHEELS] + ["wind_x", "wind_y"],) * 2
TO_PLANT_FROM_CONTROLLER = ([f"delta_{w}" for w in WHEELS] + [f"tau_{w}" for w in WHEELS],) * 2

pose, reference, steer = [], [], []
for k in range(SAMPLES + 1):
    p = plant.get(TO_BENCH[0] + TO_CONTROLLER_FROM_PLANT[0])
    bench.set(TO_BENCH[1], p[:2])
    b = bench.get(TO_CONTROLLER_FROM_BENCH[0] + TO_PLANT_FROM_BENCH[0])
    n = len(TO_CONTROLLER_FROM_BENCH[0])
    controller.set(TO_CONTROLLER_FROM_BENCH[1] + TO_CONTROLLER_FROM_PLANT[1], b[:n] + p[2:])
    c = controller.get(TO_PLANT_FROM_CONTROLLER[0])
    plant.set(TO_PLANT_FROM_BENCH[1] + TO_PLANT_FROM_CONTROLLER[1], b[n:] + c)
    pose.append(p[3:6])
    reference.append(b[5:8])
    steer.append(c[0])
    if k == SAMPLES:
        break
    # t_k = k * 1 ms and steps of t_(k+1) - t_k, as fmpy's own loop and our master take them
    t, h = k * STEP, (k + 1) * STEP - k * STEP
    for i in (plant, bench, controller):
        i.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
for i in (plant, controller, bench):
    i.fmu.terminate()
    i.fmu.freeInstance()

pose, reference = np.array(pose), np.array(reference)
# the metric: RMSE of X, Y and the heading over t = 1 ms .. 30 s, epsilon their 2-norm
rmse = np.sqrt(np.mean((pose[1:] - reference[1:]) ** 2, axis=0))
eps = float(np.linalg.norm(rmse))
print(f"epsilon {eps:.9e} (RMSE X {rmse[0]:.4f} m, Y {rmse[1]:.4f} m, psi {rmse[2]:.5f} rad)")

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("closed_loop_fmpy.png")
t = np.arange(SAMPLES + 1) * STEP
fig, (xy, st) = plt.subplots(1, 2, figsize=(12, 4.5), constrained_layout=True)
xy.plot(reference[:, 0], reference[:, 1], color="0.8", lw=6, label="reference (undisturbed open-loop run)")
xy.plot(pose[:, 0], pose[:, 1], color="tab:green", lw=1.5, label="robust controller")
xy.plot([0], [0], "ko", mfc="white", label="start")
xy.set(xlabel="X [m]", ylabel="Y [m]", title=f"sim lane change, seed 0: path (epsilon {eps:.4f})")
xy.legend(loc="lower left")
st.plot(t, np.degrees(steer), color="tab:green", lw=0.8)
st.set(xlabel="t [s]", ylabel="delta_FL [deg]", title="front-left steering command", xlim=(0, 30))
st.set_xticks(np.arange(0, 31, 5))
fig.savefig(out, dpi=110)
print(f"wrote {out}")

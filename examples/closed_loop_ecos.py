"""The closed-loop SSP (test bench, controller, plant; target/ssp/nigel_closed_loop.ssp) run by
ecos (ecospy) with the SSP's parameter set applied, 30 s at 1 ms, and the epsilon metric of
docs/benchmark.md computed from the run.

    cargo run --release -p build-fmu                     # target/fmu/*.fmu, target/ssp/*.ssp
    target/venv/bin/python examples/closed_loop_ecos.py [SSP]

Prints (the SSP of build-fmu: sim column, lane change, robust controller, seed 0):

    ecos v0.7.2, parameter set initialValues: maneuver 2, controller 3, v_x_start 0.35 m/s
    final y -0.12344203896611659 m (t = 30 s)
    epsilon 0.041356478829581121 (RMSE X 0.0008 m, Y 0.0412 m, psi 0.00366 rad)

ecos, like libcosim and fmpy, delays every connection by one step (a Jacobi master): the
same loop as `cosim run SSP --algorithm jacobi --step 1e-3`, which examples/test_examples.py
checks it against (final y and epsilon to 1e-12 relative;
measured 8e-14: the master steps over t_(k+1) - t_k with t_k = k h, which differs from h
by an ulp at some steps).
"""
import sys
import zipfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
from ecospy import EcosLib, EcosSimulation

REPO = Path(__file__).resolve().parents[1]
SSP = Path(sys.argv[1]) if len(sys.argv) > 1 else REPO / "target" / "ssp" / "nigel_closed_loop.ssp"
STEP = 1e-3  # s, the benchmark's sample period
SAMPLES = 30_000  # 30 s
# the pose and the test bench's reference pose; ecos names a variable `instance::variable`
POSE = ["plant::x", "plant::y", "plant::psi"]
REFERENCE = ["maneuver::x_ref", "maneuver::y_ref", "maneuver::psi_ref"]


def parameter_set_name(ssp):
    """The one name of the SSD's ParameterSets (ecos applies only the sets of the name given
    to init(), none without a name; our SSP export names every component's set alike)."""
    ns = "{http://ssp-standard.org/SSP1/SystemStructureParameterValues}"
    with zipfile.ZipFile(ssp) as z:
        ssd = ET.fromstring(z.read("SystemStructure.ssd"))
    names = {s.get("name") for s in ssd.iter(f"{ns}ParameterSet")}
    if len(names) != 1:
        sys.exit(f"{ssp}: expected one ParameterSet name, found {sorted(names)}")
    return names.pop()


EcosLib.set_log_level("warn")  # ecos's per-step info lines off
parameter_set = parameter_set_name(SSP)
sim = EcosSimulation(ssp_path=str(SSP), step_size=STEP)
sim.init(parameter_set=parameter_set)
print(f"ecos {EcosLib.version()}, parameter set {parameter_set}: maneuver {sim.get_integer('maneuver::maneuver')}, "
      f"controller {sim.get_integer('controller::controller')}, v_x_start {sim.get_real('plant::v_x_start')} m/s")

pose, reference = [], []
for _ in range(SAMPLES):
    sim.step(1)  # t_k -> t_(k+1); the values read after it are those at t_(k+1)
    pose.append([sim.get_real(n) for n in POSE])
    reference.append([sim.get_real(n) for n in REFERENCE])
sim.terminate()

pose, reference = np.array(pose), np.array(reference)
# the metric: RMSE of X, Y and the heading over t = 1 ms .. 30 s, epsilon their 2-norm
rmse = np.sqrt(np.mean((pose - reference) ** 2, axis=0))
eps = float(np.linalg.norm(rmse))
print(f"final y {pose[-1, 1]:.17g} m (t = {SAMPLES * STEP:g} s)")
print(f"epsilon {eps:.17g} (RMSE X {rmse[0]:.4f} m, Y {rmse[1]:.4f} m, psi {rmse[2]:.5f} rad)")

"""The closed-loop SSP (test bench, controller, plant; target/ssp/nigel_closed_loop.ssp) run by
libcosim (libcosimpy) with the SSP's parameter set applied, 30 s at 1 ms, and the epsilon
metric of docs/benchmark.md computed from the run. libcosim's log is quiet (errors only).

    cargo run --release -p build-fmu                     # target/fmu/*.fmu, target/ssp/*.ssp
    target/venv/bin/python examples/closed_loop_libcosim.py [SSP]

Prints (the SSP of build-fmu: sim column, lane change, robust controller, seed 0):

    libcosim, parameter set applied: maneuver 2, controller 3, v_x_start 0.35 m/s
    final y -0.12344203896612321 m (t = 30 s)
    epsilon 0.041356478829578755 (RMSE X 0.0008 m, Y 0.0412 m, psi 0.00366 rad)

libcosim applies each component's first ParameterSet of the SSD by itself (ours has one per
component); the values printed are read back from the FMUs after initialization. libcosim,
like ecos and fmpy, delays every connection by one step (a Jacobi master): the same loop as
`cosim run SSP --algorithm jacobi --step 1e-3`, which examples/test_examples.py checks it
against (final y and epsilon to 1e-12 relative;
measured 8e-14: the master steps over t_(k+1) - t_k with t_k = k h, which differs from h
by an ulp at some steps).
"""
import sys
from pathlib import Path

import numpy as np
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver

REPO = Path(__file__).resolve().parents[1]
SSP = Path(sys.argv[1]) if len(sys.argv) > 1 else REPO / "target" / "ssp" / "nigel_closed_loop.ssp"
STEP_NS = 1_000_000  # libcosim counts time in nanoseconds: 1 ms, the benchmark's sample period
SAMPLES = 30_000  # 30 s
POSE = ["plant.x", "plant.y", "plant.psi"]
REFERENCE = ["maneuver.x_ref", "maneuver.y_ref", "maneuver.psi_ref"]

log_output_level(CosimLogLevel.ERROR)  # libcosim's info and warning lines off
execution = CosimExecution.from_ssp_file(str(SSP), step_size=STEP_NS)
observer = CosimObserver.create_last_value()
execution.add_observer(observer)


def slot(name):
    """(slave index, value reference) of `instance.variable`."""
    instance, variable = name.split(".")
    i = execution.slave_index_from_instance_name(instance)
    refs = {v.name.decode(): v.reference for v in execution.slave_variables(i)}
    return i, refs[variable]


def read_real(name):
    i, r = slot(name)
    return observer.last_real_values(i, [r])[0]


def read_integer(name):
    i, r = slot(name)
    return observer.last_integer_values(i, [r])[0]


pose_slots, reference_slots = [slot(n) for n in POSE], [slot(n) for n in REFERENCE]
pose, reference = [], []
for k in range(SAMPLES):
    execution.step(1)  # t_k -> t_(k+1); the observer holds the values at t_(k+1)
    if k == 0:  # the observer has values once a step ran
        print(f"libcosim, parameter set applied: maneuver {read_integer('maneuver.maneuver')}, "
              f"controller {read_integer('controller.controller')}, v_x_start {read_real('plant.v_x_start')} m/s")
    pose.append([observer.last_real_values(i, [r])[0] for i, r in pose_slots])
    reference.append([observer.last_real_values(i, [r])[0] for i, r in reference_slots])

pose, reference = np.array(pose), np.array(reference)
# the metric: RMSE of X, Y and the heading over t = 1 ms .. 30 s, epsilon their 2-norm
rmse = np.sqrt(np.mean((pose - reference) ** 2, axis=0))
eps = float(np.linalg.norm(rmse))
print(f"final y {pose[-1, 1]:.17g} m (t = {SAMPLES * STEP_NS * 1e-9:g} s)")
print(f"epsilon {eps:.17g} (RMSE X {rmse[0]:.4f} m, Y {rmse[1]:.4f} m, psi {rmse[2]:.5f} rad)")

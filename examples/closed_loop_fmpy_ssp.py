"""The closed-loop SSP (test bench, controller, plant; target/ssp/nigel_closed_loop.ssp) run by
fmpy's `simulate_ssp` with the SSD's parameter bindings applied, 30 s at 1 ms, and the
epsilon metric of docs/benchmark.md computed from the run.

    cargo run --release -p build-fmu                     # target/fmu/*.fmu, target/ssp/*.ssp
    target/venv/bin/python examples/closed_loop_fmpy_ssp.py [SSP]

Prints (the SSP of build-fmu: sim column, lane change, robust controller, seed 0, about 10 s):

    fmpy 0.3.32, 8 bindings applied: maneuver 2, controller 3, v_x_start 0.35 m/s
    final y -0.12344296027504906 m (t = 30 s)
    epsilon 0.041355935843594413 (RMSE X 0.0008 m, Y 0.0412 m, psi 0.00366 rad)

fmpy's `simulate_ssp` applies none of the SSD's own ParameterBindings: they are read here and
passed as its `parameter_set`, with typed values (fmpy's `set_value` would set a Boolean given
as the text "false" to true). Like ecos and libcosim it delays every connection by one step
(Jacobi), but it starts every connection at 0.0 instead of the FMUs' initial outputs, so the
first millisecond runs with friction 0 and no wind: epsilon differs from `cosim run SSP
--algorithm jacobi` by about 1.3e-5 relative (examples/test_examples.py holds it to 1e-4 and
checks that the difference is there; table3/tests/python/test_ssp_fmpy.py proves the cause).
"""
import sys
from pathlib import Path

import fmpy
import numpy as np
from fmpy.ssp.simulation import find_components, simulate_ssp
from fmpy.ssp.ssd import Parameter, ParameterSet, read_ssd

REPO = Path(__file__).resolve().parents[1]
SSP = Path(sys.argv[1]) if len(sys.argv) > 1 else REPO / "target" / "ssp" / "nigel_closed_loop.ssp"


def bound_parameters(ssp):
    """The SSD's inline parameter bindings as one fmpy ParameterSet, `component.variable`."""
    parameters = []
    for c in find_components(read_ssd(str(ssp)).system):
        for binding in c.parameterBindings:
            for values in binding.parameterValues:
                for p in values.parameters:
                    if p.type == "Boolean":
                        value = str(p.value).strip().lower() in ("true", "1")
                    elif p.type in ("Integer", "Enumeration"):
                        value = int(p.value)
                    else:
                        value = float(p.value)
                    parameters.append(Parameter(name=f"{c.name}.{p.name}", type=p.type, value=value))
    return ParameterSet(name="bindings", parameters=parameters)


bindings = bound_parameters(SSP)
bound = {p.name: p.value for p in bindings.parameters}
print(f"fmpy {fmpy.__version__}, {len(bound)} bindings applied: maneuver {bound['maneuver.maneuver']}, "
      f"controller {bound['controller.controller']}, v_x_start {bound['plant.v_x_start']} m/s")
# row n holds the values at t_(n+1) (fmpy labels a row with the start of its step)
r = simulate_ssp(str(SSP), stop_time=30.0, step_size=1e-3, parameter_set=bindings)

pose = np.column_stack([r["plant.x"], r["plant.y"], r["plant.psi"]])
reference = np.column_stack([r["maneuver.x_ref"], r["maneuver.y_ref"], r["maneuver.psi_ref"]])
# the metric: RMSE of X, Y and the heading over t = 1 ms .. 30 s, epsilon their 2-norm
rmse = np.sqrt(np.mean((pose - reference) ** 2, axis=0))
eps = float(np.linalg.norm(rmse))
print(f"final y {pose[-1, 1]:.17g} m (t = {len(r) * 1e-3:g} s)")
print(f"epsilon {eps:.17g} (RMSE X {rmse[0]:.4f} m, Y {rmse[1]:.4f} m, psi {rmse[2]:.5f} rad)")

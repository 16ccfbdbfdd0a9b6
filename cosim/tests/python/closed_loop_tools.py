"""Helpers shared by the Python cross-checks (cosim/tests/python, table3/tests/python) and
the external-tools bench (cosim/benches/external.py): where the build puts things, the
paper's epsilon of a run, and the loops that drive libcosim (libcosimpy) and ecos (ecospy)
one step at a time and read variables after each step. No pytest here: the bench imports
it as a plain module (the fixtures are in fixtures.py)."""
import os
import pathlib
import subprocess

import numpy as np

REPO = pathlib.Path(__file__).resolve().parents[3]

# the pose of the closed loop and the reference pose, as `instance.variable`
POSE = ["plant.x", "plant.y", "plant.psi", "maneuver.x_ref", "maneuver.y_ref", "maneuver.psi_ref"]


def target_dir():
    """$CARGO_TARGET_DIR (relative to the repository root) or <repo>/target."""
    t = os.environ.get("CARGO_TARGET_DIR")
    if t:
        p = pathlib.Path(t)
        return p if p.is_absolute() else REPO / p
    return REPO / "target"


def release_binary(name, package):
    """Path of the release binary `name` of cargo package `package`, built if missing."""
    exe = target_dir() / "release" / name
    if not exe.exists():
        subprocess.run(["cargo", "build", "--release", "-q", "-p", package], cwd=REPO, check=True)
    return exe


def epsilon(series):
    """||(RMSE_X, RMSE_Y, RMSE_psi)||_2 of the series of POSE (name -> values)."""
    x, y, psi, x_ref, y_ref, psi_ref = (np.asarray(series[n]) for n in POSE)
    rmse = [np.sqrt(np.mean((a - b) ** 2)) for a, b in ((x, x_ref), (y, y_ref), (psi, psi_ref))]
    return float(np.linalg.norm(rmse))


def libcosim_series(ssp, step_ns, steps, names):
    """libcosim runs `ssp` for `steps` steps of `step_ns` nanoseconds; its last-value
    observer reads `names` (`instance.variable`, Reals) after each step (as our master
    records them). Returns name -> list of `steps` values."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_ssp_file(str(ssp), step_size=step_ns)
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    slots = []
    for name in names:
        inst, var = name.split(".")
        i = ex.slave_index_from_instance_name(inst)
        refs = {v.name.decode(): v.reference for v in ex.slave_variables(i)}
        slots.append((i, refs[var]))
    series = {n: [] for n in names}
    for _ in range(steps):
        ex.step(1)
        for name, (i, r) in zip(names, slots):
            series[name].append(obs.last_real_values(i, [r])[0])
    return series


def ecos_series(ssp, step_size, steps, names, parameter_set=None):
    """ecos runs `ssp` for `steps` steps of `step_size` seconds and reads `names` after each
    step (after the connections were applied: a direct-feedthrough output shows the new
    input). ecos applies the SSD's bindings of the one ParameterSet named `parameter_set`,
    none without a name. Returns name -> list of `steps` values."""
    from ecospy import EcosSimulation

    sim = EcosSimulation(ssp_path=str(ssp), step_size=step_size)
    if parameter_set is None:
        sim.init()
    else:
        sim.init(parameter_set=parameter_set)
    series = {n: [] for n in names}
    for _ in range(steps):
        sim.step(1)
        for name in names:
            series[name].append(sim.get_real(name.replace(".", "::")))
    sim.terminate()
    return series


def bound_parameters(path):
    """The SSD's inline parameter bindings as one typed fmpy ParameterSet (`component.variable`):
    fmpy's `simulate_ssp` applies no SSD bindings itself."""
    from fmpy.ssp.simulation import find_components
    from fmpy.ssp.ssd import Parameter, ParameterSet, read_ssd

    params = []
    for c in find_components(read_ssd(str(path)).system):
        for binding in c.parameterBindings:
            for values in binding.parameterValues:
                for p in values.parameters:
                    if p.type == "Boolean":
                        v = str(p.value).strip().lower() in ("true", "1")
                    elif p.type in ("Integer", "Enumeration"):
                        v = int(p.value)
                    else:
                        v = float(p.value)
                    params.append(Parameter(name=f"{c.name}.{p.name}", type=p.type, value=v))
    return ParameterSet(name="bindings", parameters=params)

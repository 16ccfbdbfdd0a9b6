"""The closed loop (target/ssp/nigel_closed_loop.ssp), 30 s at 1 ms, run by ecos (ecospy),
libcosim (libcosimpy) and fmpy's simulate_ssp: each timed around its run call only (ecos
and libcosim best of 3, fmpy once: it takes about a minute), then what it computed: the
final pose and the paper's epsilon over the 30,000 samples (read in a second, untimed run
for ecos and libcosim, which record nothing in the timed one). Called by
`cargo bench -p nigel-cosim` with COSIM_BENCH_PYTHON set; argument: the .ssp."""
import sys
import time

import numpy as np

ssp = sys.argv[1]
N = 30000
POSE = ["plant.x", "plant.y", "plant.psi", "maneuver.x_ref", "maneuver.y_ref", "maneuver.psi_ref"]


def best(f, n=3):
    return min(f() for _ in range(n))


def epsilon(series):
    x, y, psi, x_ref, y_ref, psi_ref = (np.asarray(series[n]) for n in POSE)
    rms = [np.sqrt(np.mean((a - b) ** 2)) for a, b in ((x, x_ref), (y, y_ref), (psi, psi_ref))]
    return float(np.linalg.norm(rms))


def report(tool, seconds, series, note=""):
    final = f"x {series['plant.x'][-1]:.9f} y {series['plant.y'][-1]:.9f} psi {series['plant.psi'][-1]:.9f}"
    print(f"{tool:<58}: {seconds * 1e3:8.1f} ms  ({seconds * 1e6 / N:6.2f} us/step) "
          f"epsilon {epsilon(series):.12f} | {final} {note}", flush=True)


try:
    from ecospy import EcosSimulation

    def ecos_timed():
        sim = EcosSimulation(ssp_path=ssp, step_size=1e-3)
        sim.init(parameter_set="initialValues")  # ecos applies a binding only when named
        t = time.perf_counter()
        sim.step(N)
        dt = time.perf_counter() - t
        sim.terminate()
        return dt

    def ecos_series():
        sim = EcosSimulation(ssp_path=ssp, step_size=1e-3)
        sim.init(parameter_set="initialValues")
        series = {n: [] for n in POSE}
        for _ in range(N):
            sim.step(1)
            for name in POSE:
                series[name].append(sim.get_real(name.replace(".", "::")))
        sim.terminate()
        return series
    report("ecos (ecospy 0.7.2), step(30000)", best(ecos_timed), ecos_series())
except Exception as e:  # a missing tool is reported, not fatal
    print("ecos:", repr(e))

try:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import log_output_level, CosimLogLevel
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)

    def libcosim_timed():
        ex = CosimExecution.from_ssp_file(ssp, step_size=1_000_000)  # ns
        t = time.perf_counter()
        ex.simulate_until(30_000_000_000)
        return time.perf_counter() - t

    def libcosim_series():
        ex = CosimExecution.from_ssp_file(ssp, step_size=1_000_000)
        obs = CosimObserver.create_last_value()
        ex.add_observer(obs)
        slots = []
        for name in POSE:
            inst, var = name.split(".")
            i = ex.slave_index_from_instance_name(inst)
            refs = {v.name.decode(): v.reference for v in ex.slave_variables(i)}
            slots.append((i, refs[var]))
        series = {n: [] for n in POSE}
        for _ in range(N):
            ex.step(1)
            for name, (i, r) in zip(POSE, slots):
                series[name].append(obs.last_real_values(i, [r])[0])
        return series
    report("libcosim (libcosimpy 0.0.6), simulate_until(30 s)", best(libcosim_timed), libcosim_series())
except Exception as e:
    print("libcosim:", repr(e))

try:
    from fmpy.ssp.simulation import find_components, simulate_ssp
    from fmpy.ssp.ssd import Parameter, ParameterSet, read_ssd

    # fmpy applies no SSD bindings itself: they are passed as a typed parameter set
    params = []
    for c in find_components(read_ssd(ssp).system):
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
    ps = ParameterSet(name="bindings", parameters=params)
    t = time.perf_counter()
    r = simulate_ssp(ssp, stop_time=30.0, step_size=1e-3, parameter_set=ps)
    dt = time.perf_counter() - t
    report("fmpy 0.3.32 simulate_ssp (records all every step)", dt, {n: r[n] for n in POSE})
except Exception as e:
    print("fmpy:", repr(e))

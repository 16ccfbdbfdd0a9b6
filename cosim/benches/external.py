"""The closed loop (target/ssp/nigel_closed_loop.ssp), 30 s at 1 ms, run by ecos (ecospy),
libcosim (libcosimpy) and fmpy's simulate_ssp: each timed around its run call only (ecos
and libcosim best of 3, fmpy once: it takes about a minute), then what it computed: the
final pose and the paper's epsilon over the 30,000 samples (read in a second, untimed run
for ecos and libcosim, which record nothing in the timed one). Called by
`cargo bench -p nigel-cosim` with COSIM_BENCH_PYTHON set; argument: the .ssp."""
import pathlib
import sys
import time

# the drivers and epsilon are shared with the cross-checks (cosim/tests/python)
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests" / "python"))
from closed_loop_tools import POSE, bound_parameters, ecos_series, epsilon, libcosim_series  # noqa: E402

ssp = sys.argv[1]
N = 30000


def best(f, n=3):
    return min(f() for _ in range(n))


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

    report("ecos (ecospy 0.7.2), step(30000)", best(ecos_timed),
           ecos_series(ssp, 1e-3, N, POSE, parameter_set="initialValues"))
except Exception as e:  # a missing tool is reported, not fatal
    print("ecos:", repr(e))

try:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import log_output_level, CosimLogLevel

    log_output_level(CosimLogLevel.ERROR)

    def libcosim_timed():
        ex = CosimExecution.from_ssp_file(ssp, step_size=1_000_000)  # ns
        t = time.perf_counter()
        ex.simulate_until(30_000_000_000)
        return time.perf_counter() - t

    report("libcosim (libcosimpy 0.0.6), simulate_until(30 s)", best(libcosim_timed),
           libcosim_series(ssp, 1_000_000, N, POSE))
except Exception as e:
    print("libcosim:", repr(e))

try:
    from fmpy.ssp.simulation import simulate_ssp

    ps = bound_parameters(ssp)
    t = time.perf_counter()
    r = simulate_ssp(ssp, stop_time=30.0, step_size=1e-3, parameter_set=ps)
    dt = time.perf_counter() - t
    report("fmpy 0.3.32 simulate_ssp (records all every step)", dt, {n: r[n] for n in POSE})
except Exception as e:
    print("fmpy:", repr(e))

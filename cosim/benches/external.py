"""The plant FMU, 30 s at 1 ms, run by fmpy, ecos (ecospy) and libcosim (libcosimpy),
each timed around its run call only (best of 3). Called by `cargo bench -p nigel-cosim`
with COSIM_BENCH_PYTHON set; arguments: the plant .fmu and the one-plant .ssp the bench
wrote (start values v_x_start = 0.35, delta_fl = 0.2 as inline parameter bindings)."""
import sys
import time

fmu, ssp = sys.argv[1], sys.argv[2]
START = {"v_x_start": 0.35, "delta_fl": 0.2}
STEPS = 30000


def best(f, n=3):
    times = []
    for _ in range(n):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def report(tool, seconds, note=""):
    print(f"{tool:<44}: {seconds * 1e3:8.1f} ms  ({seconds * 1e6 / STEPS:.3f} us/step) {note}", flush=True)


try:
    from fmpy import simulate_fmu, read_model_description, extract
    from fmpy.ssp.simulation import simulate_ssp
    report("fmpy 0.3.32 simulate_fmu (CS, 1 ms output)",
           best(lambda: simulate_fmu(fmu, fmi_type="CoSimulation", stop_time=30.0, output_interval=1e-3,
                                     start_values=START), 1))
    report("fmpy 0.3.32 simulate_ssp (same .ssp)", best(lambda: simulate_ssp(ssp, stop_time=30.0, step_size=1e-3), 1),
           "(fmpy ignores the bindings: car at rest)")
except Exception as e:  # a missing tool is reported, not fatal
    print("fmpy:", e)

try:
    from ecospy import EcosSimulation

    def ecos_run():
        sim = EcosSimulation(ssp_path=ssp, step_size=1e-3)
        sim.init(parameter_set="plant")  # ecos applies a binding only when named
        t = time.perf_counter()
        sim.step(STEPS)
        dt = time.perf_counter() - t
        assert abs(sim.get_real("plant::x") - 0.8952045191552) < 1e-9, sim.get_real("plant::x")
        sim.terminate()
        return dt
    report("ecos (ecospy 0.7.2), same .ssp, step(30000)", min(ecos_run() for _ in range(3)))
except Exception as e:
    print("ecos:", repr(e))

try:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimSlave import CosimLocalSlave
    from libcosimpy.CosimLogging import log_output_level, CosimLogLevel

    log_output_level(CosimLogLevel.ERROR)

    def libcosim_run():
        ex = CosimExecution.from_step_size(1_000_000)  # ns
        i = ex.add_local_slave(CosimLocalSlave(fmu_path=fmu, instance_name="plant"))
        refs = {v.name.decode(): v.reference for v in ex.slave_variables(i)}
        for k, v in START.items():
            ex.real_initial_value(i, refs[k], v)
        t = time.perf_counter()
        ex.simulate_until(30_000_000_000)
        return time.perf_counter() - t
    report("libcosim (libcosimpy 0.0.6), same FMU", min(libcosim_run() for _ in range(3)))

    def libcosim_ssp_run():
        ex = CosimExecution.from_ssp_file(ssp, step_size=1_000_000)
        t = time.perf_counter()
        ex.simulate_until(30_000_000_000)
        return time.perf_counter() - t
    report("libcosim (libcosimpy 0.0.6), same .ssp", min(libcosim_ssp_run() for _ in range(3)),
           "(libcosim ignores inline bindings: car at rest)")
except Exception as e:
    print("libcosim:", e)

"""Reference solutions of the stiff Model Exchange tests and benchmark, independent of the
master's integrators (cosim's bdf and dopri5) and of CVode:

- van der Pol (cosim/tests/cfmu/vdp.c): its equations written here, x0' = x1,
  x1' = mu (1 - x0^2) x1 - x0, x0(0) = 2, x1(0) = 0, integrated by SciPy's Radau (an implicit
  Runge-Kutta method of order 5, Hairer and Wanner's RADAU5) with its exact Jacobian;
- the bouncing ball (cosim/tests/cfmu/ball.c): the closed form, a parabola between bounces;
- an FMU's own right-hand side (the plant): fmpy's FMU2Model gives f(t, x) =
  fmi2GetDerivatives after fmi2SetTime and fmi2SetContinuousStates; Radau integrates it
  (the Jacobian by Radau's own finite differences).

Also: compiling a C test FMU of cosim/tests/cfmu into an archive, and the error measure of a
run against a reference.
"""
import functools
import math
import subprocess
import zipfile
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

CFMU = Path(__file__).resolve().parent.parent / "cfmu"

# The reference runs' tolerances: rtol 1e-10 with atol 1e-12 (x0 and x1 of van der Pol are
# O(1) and O(1/mu) on the slow branch, > 1e-6 for mu <= 1e5 except at their zeros): Radau of
# order 5 at rtol 1e-10 is 1e5 times tighter than the loosest bound the tests put on a bdf
# run (1e-3 .. 1e-1); rtol 1e-12 would take Radau (steps in Python) half a minute per mu.
REFERENCE_RTOL = 1e-10
REFERENCE_ATOL = 1e-12


def build_cfmu(name, folder):
    """cosim/tests/cfmu/NAME.c compiled with the system cc into FOLDER/NAME.fmu (with
    NAME.xml as its model description); its path."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    so = folder / f"{name}.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-I", str(CFMU), str(CFMU / f"{name}.c"),
                    "-o", str(so)], check=True)
    fmu = folder / f"{name}.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        z.write(CFMU / f"{name}.xml", "modelDescription.xml")
        z.write(so, f"binaries/linux64/{name}.so")
    return fmu


def vdp_reference(mu, times, rtol=REFERENCE_RTOL, atol=REFERENCE_ATOL):
    """van der Pol at `mu` at the given times (from t = 0): an array of rows (x0, x1)."""

    def f(t, x):
        return [x[1], mu * (1.0 - x[0] * x[0]) * x[1] - x[0]]

    def jac(t, x):
        return [[0.0, 1.0], [-2.0 * mu * x[0] * x[1] - 1.0, mu * (1.0 - x[0] * x[0])]]

    times = np.asarray(times, dtype=float)
    sol = solve_ivp(f, (0.0, times[-1]), [2.0, 0.0], method="Radau", jac=jac, t_eval=times, rtol=rtol, atol=atol)
    assert sol.success, sol.message
    return sol.y.T


# The phase of van der Pol: the time of its first fast transition (x0 through 0, going down;
# (3/2 - ln 2) mu + O(mu^(-1/3)), near 0.807 mu). On the slow branch before it an error of x0
# is neither damped nor amplified, so a run's errors add up into a shift of the transition,
# which is what a run's error at the rows after it measures. Measured on rows 1/20,000 of mu
# apart (linear interpolation between the rows around the crossing): a resolution of
# 1 / (0.807 * 20,000) = 6.2e-5 of the transition time at most.
TRANSITION_ROWS = 20000
TRANSITION_RESOLUTION = 1.0 / (0.807 * TRANSITION_ROWS)


@functools.lru_cache(maxsize=None)
def vdp_transition_reference(mu, rtol=REFERENCE_RTOL, atol=REFERENCE_ATOL):
    """The time of van der Pol's first transition at `mu` by Radau on the equations
    (rtol 1e-10), located by Radau's event search on x0 (a root of its dense output)."""

    def f(t, x):
        return [x[1], mu * (1.0 - x[0] * x[0]) * x[1] - x[0]]

    def jac(t, x):
        return [[0.0, 1.0], [-2.0 * mu * x[0] * x[1] - 1.0, mu * (1.0 - x[0] * x[0])]]

    def crossing(t, x):
        return x[0]

    crossing.terminal = True
    crossing.direction = -1.0
    sol = solve_ivp(f, (0.0, mu), [2.0, 0.0], method="Radau", jac=jac, events=crossing, rtol=rtol, atol=atol)
    assert sol.success and len(sol.t_events[0]) == 1, sol.message
    return float(sol.t_events[0][0])


def transition_time(t, x0):
    """Where x0 first goes through 0 (downwards) in a run's rows: linear between the rows
    around it; None when it does not."""
    t, x0 = np.asarray(t), np.asarray(x0)
    below = np.flatnonzero((x0[1:] < 0.0) & (x0[:-1] >= 0.0))
    if len(below) == 0:
        return None
    k = below[0]
    return float(t[k] + (t[k + 1] - t[k]) * x0[k] / (x0[k] - x0[k + 1]))


def transition_case(mu):
    """The case of a transition run (as CASES'): 0 to mu s, TRANSITION_ROWS rows, x0."""
    return (f"van der Pol mu = {mu:.0e}, transition", "vdp", mu, mu / TRANSITION_ROWS, {"mu": mu}, ["x0"])


def transition_shift(t, x, mu):
    """A run's transition time relative to the reference's, minus one: (t* - t*_ref) / t*_ref
    (inf when the run failed or did not cross)."""
    if x is None:
        return math.inf
    found = transition_time(t, x[:, 0])
    if found is None:
        return math.inf
    ref = vdp_transition_reference(mu)
    return (found - ref) / ref


def transition_errors(cosim, fmu, mu, rtol, folder, with_cvode=True, cvode_first=False):
    """The relative shift of the first transition in `cosim run --solver bdf` and (with_cvode)
    fmpy's CVode at `rtol`, each with the wall time of its run: ((shift, seconds),
    (shift, seconds) or None); cvode_first runs CVode first (the benchmark alternates)."""
    case = transition_case(mu)
    step = case[3]

    def bdf():
        elapsed, x, _ = run_cosim(cosim, fmu, case, rtol, Path(folder) / "transition.csv")
        return transition_shift(None if x is None else np.arange(len(x)) * step, x, mu), elapsed

    def cvode():
        elapsed, y, _ = run_cvode(fmu, case, rtol)
        return transition_shift(None if y is None else np.arange(len(y)) * step, y, mu), elapsed

    if not with_cvode:
        return bdf(), None
    if cvode_first:
        c = cvode()
        return bdf(), c
    b = bdf()
    return b, cvode()


def ball_bounces(stop, g=9.81, e=0.7, h0=1.0):
    """The bounce times of the ball (dropped from h0 at rest) up to `stop`, and the speed
    after each: t_1 = sqrt(2 h0 / g), v_1 = e g t_1, t_(k+1) = t_k + 2 v_k / g, v_(k+1) = e v_k."""
    t, v = math.sqrt(2.0 * h0 / g), e * math.sqrt(2.0 * g * h0)
    bounces = []
    # past the accumulation point (ball_accumulation_time) the bounces are infinitely many:
    # the list ends where the speed is 1e-12 of the first (a flight of 1e-12 s and less)
    v_end = 1e-12 * v
    while t <= stop and v > v_end:
        bounces.append((t, v))
        t, v = t + 2.0 * v / g, e * v
    return bounces


def ball_accumulation_time(g=9.81, e=0.7, h0=1.0):
    """Where the bounce times accumulate: t_1 (1 + 2 e / (1 - e)), s."""
    return math.sqrt(2.0 * h0 / g) * (1.0 + 2.0 * e / (1.0 - e))


def ball_reference(times, g=9.81, e=0.7, h0=1.0):
    """The ball's (h, v) at the given times (before the accumulation point)."""
    times = np.asarray(times, dtype=float)
    bounces = ball_bounces(times[-1], g, e, h0)
    rows = []
    for t in times:
        # the last bounce at or before t (before the first: the fall from h0)
        k = next((i for i in range(len(bounces) - 1, -1, -1) if bounces[i][0] <= t), None)
        if k is None:
            rows.append((h0 - 0.5 * g * t * t, -g * t))
        else:
            tk, vk = bounces[k]
            s = t - tk
            rows.append((vk * s - 0.5 * g * s * s, vk - g * s))
    return np.array(rows)


def fmu_reference(fmu, times, start_values, names, rtol=1e-10, atol=1e-12):
    """An ME FMU without events from t = 0 with the given start values (inputs held at them),
    integrated by Radau over the FMU's right-hand side as fmpy's FMU2Model gives it: the
    values of `names` at `times`, an array of rows."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Model
    from fmpy.simulation import apply_start_values
    import ctypes

    real_p = ctypes.POINTER(ctypes.c_double)

    md = read_model_description(str(fmu))
    assert md.numberOfEventIndicators == 0, f"{fmu}: the reference handles no events"
    unzipdir = extract(str(fmu))
    model = FMU2Model(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.modelExchange.modelIdentifier,
                      instanceName="reference")
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    nx = len(md.derivatives)
    try:
        model.instantiate()
        model.setupExperiment(startTime=0.0)
        apply_start_values(model, md, dict(start_values))
        model.enterInitializationMode()
        model.exitInitializationMode()
        # fmpy's newDiscreteStates: (newDiscreteStatesNeeded, terminateSimulation,
        # nominalsChanged, valuesChanged, nextEventTimeDefined, nextEventTime)
        info = model.newDiscreteStates()
        while info[0]:
            info = model.newDiscreteStates()
        assert not info[4], f"{fmu}: the reference handles no time events"
        model.enterContinuousTimeMode()
        x0 = np.zeros(nx)
        model.getContinuousStates(x0.ctypes.data_as(real_p), nx)

        dx = np.zeros(nx)
        x_buf = np.zeros(nx)

        def f(t, x):
            x_buf[:] = x
            model.setTime(t)
            model.setContinuousStates(x_buf.ctypes.data_as(real_p), nx)
            model.getDerivatives(dx.ctypes.data_as(real_p), nx)
            return dx.copy()

        times = np.asarray(times, dtype=float)
        sol = solve_ivp(f, (0.0, times[-1]), x0, method="Radau", rtol=rtol, atol=atol, dense_output=True)
        assert sol.success, sol.message
        out = np.zeros((len(times), len(names)))
        for r, t in enumerate(times):
            x = sol.sol(t)
            x_buf[:] = x
            model.setTime(t)
            model.setContinuousStates(x_buf.ctypes.data_as(real_p), nx)
            out[r] = model.getReal([vrs[n] for n in names])
        return out
    finally:
        model.terminate()
        model.freeInstance()


def relative_error(x, ref):
    """The largest over rows and columns of |x - x_ref| / max(1, |x_ref|); inf for a run
    that failed (None) or ended early."""
    if x is None or len(x) < len(ref):
        return math.inf
    x = np.asarray(x)[: len(ref)]
    return float(np.max(np.abs(x - ref) / np.maximum(1.0, np.abs(ref))))


# The work-precision cases of cosim/benches/stiff.py and of the README's table (checked in
# tests/python/test_doc_figures.py): (label, FMU key, stop time, output interval, start
# values, recorded names). The FMU keys: "vdp" and "ball" (cosim/tests/cfmu), "plant"
# (target/fmu/nigel_plant.fmu, a steer and drive input held at their start values).
PLANT_START = {"v_x_start": 0.35, "delta_fl": 0.2, "delta_fr": 0.2, "tau_rl": 0.02, "mu_rr": 0.3}
PLANT_NAMES = ["x", "y", "psi", "v_x", "v_y", "yaw_rate"]
CASES = [(f"van der Pol mu = {mu:.0e}", "vdp", mu, mu / 500, {"mu": mu}, ["x0", "x1"]) for mu in (1e3, 1e4, 1e5)] + [
    ("plant (ME)", "plant", 10.0, 0.01, PLANT_START, PLANT_NAMES),
    ("bouncing ball", "ball", 2.4, 0.01, {}, ["h", "v"]),
]


def case_fmus(folder, plant):
    """The FMU of each key: the C test FMUs compiled into `folder`, the plant's archive."""
    return {"vdp": build_cfmu("vdp", folder), "ball": build_cfmu("ball", folder), "plant": Path(plant)}


def case_reference(case, fmus):
    """The reference rows of a case: Radau on the equations (van der Pol), Radau over the
    FMU's right-hand side (the plant), the closed form (the ball)."""
    _, key, stop, step, start, names = case
    times = np.arange(round(stop / step) + 1) * step
    if key == "vdp":
        return vdp_reference(start["mu"], times)
    if key == "ball":
        return ball_reference(times)
    return fmu_reference(fmus[key], times, start, names)


def run_cosim(cosim, fmu, case, rtol, out):
    """`cosim run FMU --interface me --solver bdf --rtol RTOL` on a case: (wall time of the
    process, rows or None, the last line of stderr when it failed)."""
    import time

    _, _, stop, step, start, names = case
    args = [str(cosim), "run", str(fmu), "--interface", "me", "--solver", "bdf", "--rtol", repr(rtol),
            "--stop-time", repr(stop), "--step", repr(step), "--output", str(out)]
    for k, v in start.items():
        args += ["--set", f"{k}={v!r}"]
    for n in names:
        args += ["--record", n]
    t = time.perf_counter()
    done = subprocess.run(args, capture_output=True, text=True)
    elapsed = time.perf_counter() - t
    if done.returncode != 0:
        return elapsed, None, (done.stderr.strip().splitlines() or ["(no message)"])[-1]
    r = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    return elapsed, np.column_stack([r[n] for n in names]), None


def run_cvode(fmu, case, rtol):
    """fmpy's simulate_fmu with CVode at `rtol` on a case: (time of the call, rows or None,
    CVode's message when it failed)."""
    import time

    from fmpy import simulate_fmu

    _, _, stop, step, start, names = case
    t = time.perf_counter()
    try:
        r = simulate_fmu(str(fmu), fmi_type="ModelExchange", solver="CVode", relative_tolerance=rtol, stop_time=stop,
                         output_interval=step, start_values=start, output=names, record_events=False)
    except Exception as e:  # CVode's failures (mxstep, error test) end the run
        return time.perf_counter() - t, None, str(e).splitlines()[0]
    elapsed = time.perf_counter() - t
    return elapsed, np.column_stack([r[n] for n in names]), None

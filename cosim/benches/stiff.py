"""Work-precision of `cosim run --interface me --solver bdf` against fmpy's CVode (BDF,
SUNDIALS) on the same FMUs, in one run, alternated.

Usage: target/venv/bin/python cosim/benches/stiff.py COSIM PLANT_FMU [ROUNDS]

The FMUs: van der Pol (cosim/tests/cfmu/vdp.c, with directional derivatives) at mu = 1e3,
1e4, 1e5 from t = 0 to mu (its first fast transition near 0.81 mu), 500 output rows; the plant (PLANT_FMU, ME) over 10 s with a
steer and drive input held; the bouncing ball (cosim/tests/cfmu/ball.c) over 2.4 s (eight
bounces, before the accumulation point at 2.56 s). Each is compiled here with the system cc.

Error of a run: the largest over the output rows and states of |x - x_ref| / max(1, |x_ref|)
against a reference: for the plant and van der Pol at mu = 1e3 `cosim --solver dopri5 --rtol
1e-12` (an explicit method, unrelated to either BDF), for van der Pol at mu = 1e4 and 1e5
(where dopri5's stability bound makes 1e8 and more steps) CVode at the tightest of rtol
1e-12 .. 1e-9 it finishes with, its outputs 100 times as often (fmpy's CVode takes at most
500 steps between outputs), and where it finishes none, cosim bdf at rtol 1e-12 (then not
independent of the bdf runs; its difference to dopri5 at mu = 1e3 is printed); the difference of that CVode run and of cosim bdf at rtol
1e-12 to the reference is printed; for the ball
the closed form (a parabola between bounces at t_k = t1 (1 + 2 e (1 - e^(k-1)) / (1 - e)),
v after a bounce e v).

Time of a run: cosim the whole process (start, unpack, load, run, CSV), fmpy the
`simulate_fmu` call in this process (its unpacking and loading included, not Python's start
nor the import of fmpy). Each round runs every (FMU, tolerance) once with each tool, one after
the other; printed: per case, the median time over the rounds, the range, and the error.
"""
import math
import statistics
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu

cosim, plant = sys.argv[1], sys.argv[2]
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 5
CFMU = Path(__file__).resolve().parent.parent / "tests" / "cfmu"
work = Path(tempfile.mkdtemp(prefix="stiff-bench-"))


def build(name):
    so = work / f"{name}.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-O2", "-fvisibility=hidden", str(CFMU / f"{name}.c"), "-o", str(so)],
                   check=True)
    fmu = work / f"{name}.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        z.write(CFMU / f"{name}.xml", "modelDescription.xml")
        z.write(so, f"binaries/linux64/{name}.so")
    return fmu


vdp, ball = build("vdp"), build("ball")
PLANT_SET = {"v_x_start": 0.35, "delta_fl": 0.2, "delta_fr": 0.2, "tau_rl": 0.02, "mu_rr": 0.3}


def run_cosim(fmu, stop, step, solver, rtol, start, names):
    out = work / "out.csv"
    args = [cosim, "run", str(fmu), "--interface", "me", "--solver", solver, "--rtol", repr(rtol),
            "--stop-time", repr(stop), "--step", repr(step), "--output", str(out)]
    for k, v in start.items():
        args += ["--set", f"{k}={v}"]
    for n in names:
        args += ["--record", n]
    t = time.perf_counter()
    done = subprocess.run(args, capture_output=True, text=True)
    elapsed = time.perf_counter() - t
    if done.returncode != 0:
        return elapsed, None, done.stderr.strip().splitlines()[-1]
    r = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    return elapsed, np.column_stack([r[n] for n in names]), None


def run_fmpy(fmu, stop, step, rtol, start, names):
    t = time.perf_counter()
    try:
        r = simulate_fmu(str(fmu), fmi_type="ModelExchange", solver="CVode", relative_tolerance=rtol, stop_time=stop,
                         output_interval=step, start_values=start, output=names, record_events=False)
    except Exception as e:  # CVode's failures (mxstep, error test) end the run
        return time.perf_counter() - t, None, str(e).splitlines()[0]
    elapsed = time.perf_counter() - t
    return elapsed, np.column_stack([r[n] for n in names]), None


def error(x, ref):
    if x is None:
        return math.inf
    n = min(len(x), len(ref))
    if n < len(ref):
        return math.inf
    return float(np.max(np.abs(x[:n] - ref[:n]) / np.maximum(1.0, np.abs(ref[:n]))))


def ball_exact(stop, step, g=9.81, e=0.7):
    t1 = math.sqrt(2.0 / g)
    times = np.arange(0, round(stop / step) + 1) * step
    h, v = [], []
    for t in times:
        if t < t1:
            h.append(1.0 - 0.5 * g * t * t)
            v.append(-g * t)
            continue
        k, tk, vk = 1, t1, e * g * t1
        while t >= tk + 2 * vk / g:
            tk += 2 * vk / g
            vk *= e
            k += 1
        s = t - tk
        h.append(vk * s - 0.5 * g * s * s)
        v.append(vk - g * s)
    return np.column_stack([h, v])


cases = []  # (label, fmu, stop, step, start, names, rtols)
for mu in (1e3, 1e4, 1e5):
    # to t = mu: the slow branch from x0 = 2 and the first fast transition (near 0.81 mu)
    cases.append((f"van der Pol mu = {mu:.0e}", vdp, mu, mu / 500, {"mu": mu}, ["x0", "x1"], (1e-4, 1e-6, 1e-8)))
cases.append(("plant (ME)", Path(plant), 10.0, 1e-3, PLANT_SET, ["x", "y", "psi", "v_x", "v_y", "yaw_rate"], (1e-4, 1e-6, 1e-8)))
cases.append(("bouncing ball", ball, 2.4, 0.01, {}, ["h", "v"], (1e-4, 1e-6, 1e-8)))

references = {}
for label, fmu, stop, step, start, names, _ in cases:
    if fmu == ball:
        references[label] = ball_exact(stop, step)
        continue
    # CVode at the tightest of these tolerances it finishes with, with outputs 100 times
    # as often as the runs (fmpy's CVode takes at most 500 steps between two outputs:
    # a fast transition within one interval ends it with "mxstep steps taken")
    for cv_rtol in (1e-12, 1e-11, 1e-10, 1e-9):
        _, cv, cerr = run_fmpy(fmu, stop, step / 100, cv_rtol, start, names)
        if cv is not None:
            cv = cv[::100]
            break
    _, ours, oerr = run_cosim(fmu, stop, step, "bdf", 1e-12, start, names)
    assert oerr is None, oerr
    if stop * start.get("mu", 1.0) <= 1e6:
        # dopri5's steps are bounded by stability, ~3.3 / (3 mu): feasible to mu t = 1e6
        _, ref, err = run_cosim(fmu, stop, step, "dopri5", 1e-12, start, names)
        assert err is None, err
        how = "dopri5 rtol 1e-12"
    elif cv is not None:
        ref, how = cv, f"CVode rtol {cv_rtol:.0e}"
    else:
        # CVode ends in every one: our bdf at rtol 1e-12 (checked against dopri5 at mu = 1e3)
        ref, how = ours, "cosim bdf rtol 1e-12 (CVode finishes no reference run)"
    references[label] = ref
    print(f"reference {label}: {how}; CVode rtol {cv_rtol:.0e} vs it: "
          f"{'failed: ' + cerr[-60:] if cv is None else f'{error(cv, ref):.1e}'}, "
          f"cosim bdf rtol 1e-12 vs it: {error(ours, ref):.1e}")

times = {}
errors = {}
failures = {}
for _ in range(rounds):
    for label, fmu, stop, step, start, names, rtols in cases:
        for rtol in rtols:
            for tool in ("cosim bdf", "fmpy CVode"):
                if tool == "cosim bdf":
                    t, x, err = run_cosim(fmu, stop, step, "bdf", rtol, start, names)
                else:
                    t, x, err = run_fmpy(fmu, stop, step, rtol, start, names)
                key = (label, rtol, tool)
                times.setdefault(key, []).append(t)
                errors[key] = error(x, references[label])
                if err:
                    failures[key] = err

print(f"{rounds} rounds; time: median (min .. max) s; error: largest |x - x_ref| / max(1, |x_ref|)")
print("| case | rtol | cosim bdf: time | error | fmpy CVode: time | error |")
print("|---|---|---|---|---|---|")
for label, _, _, _, _, _, rtols in cases:
    for rtol in rtols:
        row = [label, f"{rtol:.0e}"]
        for tool in ("cosim bdf", "fmpy CVode"):
            key = (label, rtol, tool)
            ts = times[key]
            cell = f"{statistics.median(ts):.3f} ({min(ts):.3f} .. {max(ts):.3f})"
            e = errors[key]
            row += [cell, "failed: " + failures[key][:60] if key in failures else f"{e:.1e}"]
        print("| " + " | ".join(row) + " |")

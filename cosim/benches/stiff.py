"""Work-precision of `cosim run --interface me --solver bdf` against fmpy's CVode (BDF,
SUNDIALS) on the same FMUs, in one run, alternated.

Usage: target/venv/bin/python cosim/benches/stiff.py COSIM PLANT_FMU [ROUNDS] [PNG]

The cases (cosim/tests/python/stiff_reference.py, CASES): van der Pol (cosim/tests/cfmu/vdp.c,
with directional derivatives) at mu = 1e3, 1e4, 1e5 from t = 0 to mu (the slow branch from
x0 = 2 and the first fast transition, near 0.81 mu), 500 output rows; the plant (PLANT_FMU, ME)
over 10 s with a steer and drive input held, 1000 rows; the bouncing ball
(cosim/tests/cfmu/ball.c, state events) over 2.4 s (eight bounces, before the accumulation
point at 2.56 s), 240 rows. The C FMUs are compiled here with the system cc. Each at rtol
1e-3 .. 1e-10 with each tool.

Error of a run: the largest over the output rows and the recorded variables of
|x - x_ref| / max(1, |x_ref|), against references independent of both tools: van der Pol by
SciPy's Radau on its equations (rtol 1e-10), the plant by Radau over the FMU's own right-hand
side through fmpy's FMU2Model (rtol 1e-10), the ball in closed form.

Time of a run: cosim the whole process (start, unpack, load, run, CSV), fmpy the
`simulate_fmu` call in this process (its unpacking and loading included, not Python's start
nor the import of fmpy). Each round runs every (case, tolerance) once with each tool, the
tool first in the pair alternating from round to round; printed: per case and tolerance the
median time over the rounds, the range (min .. max), and the error (deterministic). With PNG,
error against median time, log-log, one panel per case (cosim/benches/stiff_figure.py, which
also redraws it from the table docs/performance.md records).

Then the phase of van der Pol at rtol 1e-3 .. 1e-5 (mu = 1e3, 1e4, 1e5): the time of the first
fast transition in each tool's run (rows 1/20,000 of mu apart) against Radau's, as a relative
shift and in units of rtol, with the times of those runs (the same rounds, alternated). The
tables and the rows of both go to results.json in a temporary folder.
"""
import json
import math
import statistics
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "python"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from stiff_reference import (CASES, TRANSITION_RESOLUTION, case_fmus, case_reference, relative_error,  # noqa: E402
                             run_cosim, run_cvode, transition_errors, vdp_transition_reference)

cosim, plant = sys.argv[1], sys.argv[2]
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 5
png = sys.argv[4] if len(sys.argv) > 4 else None
RTOLS = [10.0 ** -k for k in range(3, 11)]
TOOLS = ("cosim bdf", "fmpy CVode")
work = Path(tempfile.mkdtemp(prefix="stiff-bench-"))
fmus = case_fmus(work, plant)
references = {case[0]: case_reference(case, fmus) for case in CASES}

times, errors, failures = {}, {}, {}
for r in range(rounds):
    for case in CASES:
        label, key = case[0], case[1]
        for rtol in RTOLS:
            for tool in (TOOLS if r % 2 == 0 else TOOLS[::-1]):
                if tool == "cosim bdf":
                    t, x, err = run_cosim(cosim, fmus[key], case, rtol, work / "out.csv")
                else:
                    t, x, err = run_cvode(fmus[key], case, rtol)
                k = (label, rtol, tool)
                times.setdefault(k, []).append(t)
                errors[k] = relative_error(x, references[label])
                if err:
                    # fmpy's message for CV_TOO_MUCH_WORK (code -1): mxstep steps taken before an output
                    failures[k] = "mxstep" if "code -1)" in err else err

print(f"{rounds} rounds; time: median (min .. max) s; error: largest |x - x_ref| / max(1, |x_ref|)")
print("| case | rtol | cosim bdf: time | error | fmpy CVode: time | error |")
print("|---|---|---|---|---|---|")
rows = []
for case in CASES:
    label = case[0]
    for rtol in RTOLS:
        row = [label, f"{rtol:.0e}"]
        for tool in TOOLS:
            k = (label, rtol, tool)
            ts = times[k]
            row += [f"{statistics.median(ts):.3f} ({min(ts):.3f} .. {max(ts):.3f})",
                    "failed: " + failures[k][:60] if k in failures else f"{errors[k]:.1e}"]
            rows.append({"case": label, "rtol": rtol, "tool": tool, "times": ts, "error": errors[k],
                         "failure": failures.get(k)})
        print("| " + " | ".join(row) + " |")
# The phase of van der Pol at loose tolerances: the first transition's time against Radau's,
# on rows 1/20,000 of mu apart (stiff_reference.transition_errors), the same rounds alternated
TRANSITION_MUS = [1e3, 1e4, 1e5]
TRANSITION_RTOLS = [1e-3, 1e-4, 1e-5]
shifts, shift_times = {}, {}
for r in range(rounds):
    for mu in TRANSITION_MUS:
        for rtol in TRANSITION_RTOLS:
            # the pair's order alternates: bdf first in even rounds, CVode first in odd ones
            bdf, cvode = transition_errors(cosim, fmus["vdp"], mu, rtol, work, cvode_first=r % 2 == 1)
            for tool, (shift, seconds) in (("cosim bdf", bdf), ("fmpy CVode", cvode)):
                shifts[(mu, rtol, tool)] = shift
                shift_times.setdefault((mu, rtol, tool), []).append(seconds)
print()
print(f"the first transition of van der Pol: (t* - t*_ref) / t*_ref, and in units of rtol "
      f"(resolution {TRANSITION_RESOLUTION:.1e}); time: median (min .. max) s")
print("| mu | Radau t*_ref, s | rtol | cosim bdf: shift | rtol units | time | fmpy CVode: shift | rtol units | time |")
print("|---|---|---|---|---|---|---|---|---|")
transitions = []
for mu in TRANSITION_MUS:
    for rtol in TRANSITION_RTOLS:
        row = [f"{mu:.0e}", f"{vdp_transition_reference(mu):.3f}", f"{rtol:.0e}"]
        for tool in TOOLS:
            k = (mu, rtol, tool)
            ts = shift_times[k]
            row += [f"{shifts[k]:+.1e}", f"{abs(shifts[k]) / rtol:.1f}",
                    f"{statistics.median(ts):.3f} ({min(ts):.3f} .. {max(ts):.3f})"]
            transitions.append({"mu": mu, "rtol": rtol, "tool": tool, "shift": shifts[k], "times": ts})
        print("| " + " | ".join(row) + " |")
(work / "results.json").write_text(json.dumps({"work_precision": rows, "transitions": transitions}, indent=1))
print(f"raw results: {work / 'results.json'}")

if png:
    from stiff_figure import draw

    finished = {k: (statistics.median(times[k]), errors[k]) for k in times
                if k not in failures and math.isfinite(errors[k])}
    draw([case[0] for case in CASES], RTOLS, finished, set(failures), rounds, png)
    print(f"wrote {png}")

"""The referee of the conformance table (scripts/conformance_table.py): where cosim and fmpy
differ on a corpus case, an independent judge decides which of the two is right, column by
column, in this order:

1. the shipped reference (`_ref.csv`) where it holds the column: cosim is right when it lies
   inside the reference's tube by fmpy's cross-check rule (`fmpy.util.validate_signal`, fewer
   than 10 % of the reference's points outside, as the FMI 2.0 runner judges);
2. an exact derivation from the input file where the FMU is known to copy its inputs to its
   outputs (the Reference FMUs' Feedthrough: `<T>_output = <T>_input`): cosim's integer
   output equals the input file's integer at every row, compared as integers (no float64 on
   the way, so 2^63 - 1 and 2^64 - 1 stay exact);
3. a tight-tolerance fmpy run of the same case (Model Exchange: fmpy's CVode at rtol 1e-10;
   Co-Simulation: the FMU's own solver told rtol 1e-10): cosim is right when it is within the
   runners' default comparison of that run (1e-3 of the signal's range on common time
   points); fmpy's default run then is the one that is wrong when it is not.

Run only for the cases where cosim differs from fmpy, so it costs one fmpy run at most each,
and none where an earlier run's result is kept (NIGEL_CONFORMANCE_REFEREE_CACHE).
`python conformance_referee.py --fmpy-tight ...` is the child process of the tight run.
"""
import csv
import gzip
import hashlib
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np

# the runners' default comparison: deviation at most 1e-3 of the signal's range
TOL = 1e-3
# fmpy's cross-check rule (fmpy.util.validate_result): right below 10 % of points outside the tube
TUBE_MAX = 0.1
# the tight run's relative tolerance: MapleSim 2024 SlidingCrank ME needs 1e-10 (fmpy's CVode
# at 1e-8 and 1e-9 ends 1.5e-2 and 1.8e-3 of CrankRotation[2] off itself at 1e-10, which ends
# 5e-5 from cosim); Dymola CoupledClutches ME at 1e-10 is 8e-9 of range from cosim
TIGHT_RTOL = 1e-10
# SlidingCrank's tight run writes 100,000 output points: 45 to 65 s on a loaded machine
TIGHT_TIMEOUT_S = 180
# models whose outputs are their inputs (Reference FMUs' Feedthrough, src/Feedthrough/model.c:
# every <T>_output is set from <T>_input)
COPIES_INPUTS = {("ReferenceFMUs", "Feedthrough")}


# ----------------------------------------------------------------------------- results
def _value(text):
    """a CSV cell: int when it is one (exact, 64-bit and beyond), float, else the text."""
    s = text.strip()
    if s in ("true", "True"):
        return 1
    if s in ("false", "False"):
        return 0
    try:
        return int(s)
    except ValueError:
        pass
    try:
        return float(s)
    except ValueError:
        return s


def read_result(path):
    """-> (times, {column: list of values}); Altair's name(i) becomes name[i] as in cosim's CSV."""
    with (gzip.open(path, "rt", newline="") if path.endswith(".gz") else open(path, newline="")) as f:
        rows = [r for r in csv.reader(f) if r and any(c.strip() for c in r)]
    header = [h.strip().strip('"') for h in rows[0]]
    header = [h.replace("(", "[").replace(")", "]") if h.endswith(")") else h for h in header]
    cols = {name: [_value(r[j]) if j < len(r) else "" for r in rows[1:]] for j, name in enumerate(header)}
    times = [float(t) for t in cols.pop(header[0])]
    return times, cols


def last_of_each_time(times):
    """indices of the last row of each time (the values after an event)"""
    return [i for i in range(len(times)) if i + 1 == len(times) or times[i + 1] != times[i]]


def numeric(column):
    return all(isinstance(v, (int, float)) for v in column)


def scale_of(values):
    """the range of a signal, or max(1, |value|) for a constant (the runners' scale)"""
    finite = [v for v in values if not (isinstance(v, float) and not np.isfinite(v))]
    if not finite:
        return 1.0
    spread = float(max(finite) - min(finite))
    return spread if spread > 0 else max(1.0, float(max(abs(v) for v in finite)))


def deviations(cand, base):
    """per common numeric column, max |cand - base| / scale(base) on the common time points
    (last row of each time on both sides); differences taken exactly for integers."""
    (tc, C), (tb, B) = cand, base
    ic, ib = last_of_each_time(tc), last_of_each_time(tb)
    tb_u = np.array([tb[i] for i in ib])
    within = 1e-9 * max([1.0] + [abs(t) for t in tb_u])
    pairs = []
    for i in ic:
        k = int(np.searchsorted(tb_u, tc[i]))
        near = [q for q in (k - 1, k) if 0 <= q < len(tb_u) and abs(tb_u[q] - tc[i]) <= within]
        if near:
            pairs.append((i, ib[near[0]]))
    devs = {}
    for name in sorted(set(C) & set(B)):
        a, b = C[name], B[name]
        if not (numeric(a) and numeric(b)):
            devs[name] = 0.0 if all(str(a[i]) == str(b[j]) for i, j in pairs) else float("inf")
            continue
        worst = 0.0
        for i, j in pairs:
            if isinstance(a[i], float) and isinstance(b[j], float) and np.isnan(a[i]) and np.isnan(b[j]):
                continue
            d = abs(a[i] - b[j])
            worst = max(worst, float("inf") if d != d else float(d))
        devs[name] = worst / scale_of([b[j] for _, j in pairs]) if pairs else float("inf")
    return devs, len(pairs)


# ----------------------------------------------------------------------------- referees
def tube_outside(result, reference, name):
    """fraction of the reference's points where the result leaves the reference's tube
    (fmpy.util.validate_signal, fmpy's FMI cross-check rule)"""
    from fmpy.util import validate_signal
    (t, R), (tr, REF) = result, reference
    _, _, _, out = validate_signal(t=np.array(t, float), y=np.array(R[name], float),
                                   t_ref=np.array(tr, float), y_ref=np.array(REF[name], float))
    return float(np.sum(out)) / float(len(out))


def input_derivation(case, result, names):
    """{column: (right, detail)} for the outputs a copying FMU derives from its input file"""
    if (case["tool_family"], case["model"]) not in COPIES_INPUTS or not case.get("input"):
        return {}
    ti, I = read_result(case["input"])
    tc, C = result
    judged = {}
    for name in names:
        source = name[: -len("_output")] + "_input" if name.endswith("_output") else None
        if source not in I or name not in C or not all(isinstance(v, int) for v in I[source]):
            continue
        # a discrete input holds the last row at or before t (the later row of a jump); at the
        # time of an input row a single result row may hold the value before it or after it
        # (fmpy writes both rows, cosim the one before: the input event is the next step's start)
        def held(t, at_or_before):
            rows = [k for k in range(len(ti)) if (ti[k] <= t + 1e-12 if at_or_before else ti[k] < t - 1e-12)]
            return I[source][rows[-1]] if rows else None
        wrong = [tc[i] for i in last_of_each_time(tc) if C[name][i] not in (held(tc[i], True), held(tc[i], False))]
        judged[name] = (not wrong, "equals %s of the input file at every row" % source if not wrong
                        else "differs from %s of the input file at t = %s s (%s)" % (source, wrong[0], C[name][tc.index(wrong[0])]))
    return judged


def tight_run_key(case):
    """what the tight run's result depends on: the FMU, the input file, the experiment, fmpy"""
    from importlib.metadata import version
    h = hashlib.sha256()
    for path in (case["fmu"], case.get("input")):
        if path:
            with open(path, "rb") as f:
                h.update(hashlib.sha256(f.read()).digest())
    h.update(json.dumps([case["interface"], case["start"], case["stop"], case["step"], TIGHT_RTOL,
                         version("fmpy")]).encode())
    return h.hexdigest()[:32]


def tight_run(case, out):
    """fmpy on the same case at rtol TIGHT_RTOL, in a child process; -> (result or None, message).
    With NIGEL_CONFORMANCE_REFEREE_CACHE set, a result kept there (gzip) under the run's key is
    read instead: fmpy's run of one FMU at one experiment gives one result."""
    cache = os.environ.get("NIGEL_CONFORMANCE_REFEREE_CACHE")
    kept = os.path.join(cache, tight_run_key(case) + ".csv.gz") if cache else None
    if kept and os.path.exists(kept):
        return read_result(kept), "kept from an earlier run"
    cmd = [sys.executable, os.path.abspath(__file__), "--fmpy-tight", json.dumps(dict(case, out=out))]
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=TIGHT_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return None, "fmpy at rtol %g did not finish in %d s" % (TIGHT_RTOL, TIGHT_TIMEOUT_S)
    if p.returncode != 0 or not os.path.exists(out):
        return None, "fmpy at rtol %g failed: %s" % (TIGHT_RTOL, (p.stderr.strip().splitlines() or ["?"])[-1][:160])
    if kept:
        os.makedirs(cache, exist_ok=True)
        with open(out, "rb") as src, gzip.open(kept + ".part", "wb") as dst:
            shutil.copyfileobj(src, dst)
        os.replace(kept + ".part", kept)
    return read_result(out), "%.1f s" % (time.perf_counter() - t0)


def judge(case):
    """case: dict with fmu, interface ("cs"|"me"), start, stop, step, input, ref (paths or None),
    cosim_csv, fmpy_csv, tight_csv, tool_family, model. -> dict(right, referees, fmpy_wrong, lines)"""
    cosim, fmpy_result = read_result(case["cosim_csv"]), read_result(case["fmpy_csv"])
    devs, _ = deviations(cosim, fmpy_result)
    # the columns off by the runners' default comparison; all of them where the runner's own
    # rule (the FMI 2.0 runner's tube against fmpy) failed a case within it
    disputed = [n for n, d in devs.items() if not d <= TOL] or sorted(devs)
    lines, referees, right, fmpy_wrong = [], set(), True, False
    reference = read_result(case["ref"]) if case.get("ref") else None
    rest = []
    for name in disputed:
        if reference and name in reference[1] and numeric(reference[1][name]) and numeric(cosim[1][name]):
            c_out = tube_outside(cosim, reference, name)
            f_out = tube_outside(fmpy_result, reference, name) if numeric(fmpy_result[1][name]) else float("nan")
            ok = c_out < TUBE_MAX
            right &= ok
            fmpy_wrong |= ok and not f_out < TUBE_MAX
            referees.add("reference")
            lines.append("%s: %.0f %% of the reference's points outside cosim's tube, %.0f %% outside fmpy's (right below %.0f %%)"
                         % (name, 100 * c_out, 100 * f_out, 100 * TUBE_MAX))
        else:
            rest.append(name)
    derived = input_derivation(case, cosim, rest)
    fmpy_derived = input_derivation(case, fmpy_result, rest)
    for name, (ok, detail) in derived.items():
        f_ok, f_detail = fmpy_derived.get(name, (False, "lacks the column"))
        right &= ok
        fmpy_wrong |= ok and not f_ok
        referees.add("input file")
        lines.append("%s: cosim %s; fmpy %s" % (name, detail, f_detail))
    rest = [n for n in rest if n not in derived]
    if rest:
        referees.add("fmpy rtol %g" % TIGHT_RTOL)
        tight, message = tight_run(case, case["tight_csv"])
        if tight is None:
            right = False
            lines.append(message)
        else:
            c_dev, n = deviations(cosim, tight)
            f_dev, _ = deviations(fmpy_result, tight)
            worst = max(rest, key=lambda k: c_dev.get(k, float("inf")))
            worst_f = max(rest, key=lambda k: f_dev.get(k, float("inf")))
            ok = n > 0 and all(c_dev.get(k, float("inf")) <= TOL for k in rest)
            right &= ok
            fmpy_wrong |= ok and not all(f_dev.get(k, float("inf")) <= TOL for k in rest)
            lines.append("fmpy at rtol %g (%s): cosim %.2g of range off it (%s), fmpy's default run %.2g (%s) on %d common times"
                         % (TIGHT_RTOL, message, c_dev.get(worst, float("inf")), worst,
                            f_dev.get(worst_f, float("inf")), worst_f, n))
    return dict(right=right and bool(disputed), referees=sorted(referees), fmpy_wrong=fmpy_wrong, lines=lines,
                disputed=disputed)


# ----------------------------------------------------------------------------- child
def flat_names(name, shape):
    if not shape:
        return [name]
    return ["%s[%s]" % (name, ",".join(str(i + 1) for i in ix)) for ix in np.ndindex(*shape)]


def cell(x):
    if isinstance(x, (float, np.floating)):
        return repr(float(x))
    if isinstance(x, (bool, int, np.bool_, np.integer)):
        return str(int(x))
    return bytes(x).hex() if isinstance(x, (bytes, np.bytes_)) else str(x)


def fmpy_tight(case):
    import fmpy
    from fmpy.util import read_csv
    inp = read_csv(case["input"]) if case.get("input") else None
    kw = dict(validate=False, start_time=case["start"], stop_time=case["stop"], output_interval=case["step"],
              input=inp, relative_tolerance=TIGHT_RTOL)
    if case["interface"] == "me":
        kw.update(fmi_type="ModelExchange", solver="CVode")
    else:
        kw.update(fmi_type="CoSimulation", step_size=case["step"])
    res = fmpy.simulate_fmu(case["fmu"], **kw)
    names = [(n, res.dtype[n].shape) for n in res.dtype.names]
    with open(case["out"], "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(sum((flat_names(n, s) for n, s in names), []))
        for row in res:
            w.writerow(sum(([cell(x) for x in np.asarray(row[n]).reshape(-1)] for n, s in names), []))


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--fmpy-tight":
        fmpy_tight(json.loads(sys.argv[2]))
    else:
        sys.exit(__doc__)

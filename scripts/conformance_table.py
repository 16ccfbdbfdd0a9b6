"""One table of the third-party conformance run (scripts/conformance.sh): per part the cases,
how many fmpy and cosim complete, and how many cosim gets right where fmpy completes; then
every case that misses that goal, marked "known" when scripts/conformance-known.txt lists it
(with its reason) and "NEW" otherwise.

Right means equal to fmpy's result by the runner's comparison, or, where the two differ, right
by the referee (scripts/conformance_referee.py: the shipped reference's tube, an exact
derivation from the input file, or fmpy at a tight tolerance), which the table names per case.
Speed: per part cosim's and fmpy's wall-clock times (each a child process, as the runners
measure them) summed over the cases both complete, and every case where cosim is slower.

usage: python conformance_table.py WORK KNOWN_FILE CORPUS [--leftover TEXT]
       python conformance_table.py --referee-only WORK CORPUS PART   (the referee of one part alone)
Exit status 1 when a case misses the goal and is not listed, or crashed, hung or gave a wrong
value (unless listed with a reason that starts "CRASH:" or "HANG:"); 0 otherwise.
"""
import json
import os
import sys

import conformance_referee

GOOD_FMI3 = {"bitwise", "pass", "ref-ok"}
GOOD_SSP = {"pass", "refused-as-expected", "ran (no values)", "no-fmu"}


def load(work, name):
    path = os.path.join(work, name + ".json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def last_error(text):
    lines = (text or "").strip().splitlines()
    return lines[-1][:160] if lines else ""


def fmi2_rows(results, work, corpus):
    """(case, fmpy completes, cosim completes, cosim right by the runner, note, crash or hang,
    the referee's case or None) of the FMI 2.0 runner."""
    for r in results:
        fmpy_ok = r["fmpy_status"] == "ok"
        cosim_ok = r["cosim_status"] == "ok"
        right = cosim_ok and bool(r.get("cosim_pass"))
        note = r["cosim_status"] if not cosim_ok else ("" if right else "off %s: %s %s" % (
            "the reference" if r.get("has_ref") else "fmpy", r.get("cosim_rel_out"), r.get("cosim_worst")))
        if not cosim_ok and last_error(r.get("cosim_err")):
            note += ": " + last_error(r.get("cosim_err"))
        here = os.path.join(corpus, "fmi2", r["case"])
        run = os.path.join(work, r["case"])
        # with a reference the runner judged cosim by it already; without, against fmpy
        referee = None if r.get("has_ref") else dict(
            fmu=os.path.join(here, r["model"] + ".fmu"), interface=r["it"], start=r["start"], stop=r["stop"],
            step=r["step"], input=os.path.join(here, r["model"] + "_in.csv") if r.get("has_input") else None,
            ref=None, tool_family=r["tool"], model=r["model"])
        yield r["case"], fmpy_ok, cosim_ok, right, note, r["cosim_status"].startswith(("CRASH", "HANG")), referee, run


def fmi3_rows(results, work, corpus):
    for r in results:
        fmpy_ok = r["fmpy_status"] == "ok"
        cosim_ok = r["cosim_status"] == "ok"
        right = cosim_ok and r["verdict"] in GOOD_FMI3
        note = r["verdict"] + (": " + last_error(r.get("cosim_err")) if last_error(r.get("cosim_err")) and not cosim_ok else "")
        bad = r["cosim_status"].startswith(("CRASH", "HANG", "crash", "hang", "signal", "timeout"))
        here = os.path.join(corpus, "fmi3", r["it"], r["tool"], r["model"])
        referee = dict(fmu=os.path.join(here, r["model"] + ".fmu"), interface=r["it"], start=r["start"], stop=r["stop"],
                       step=r["step"], input=os.path.join(here, r["input"]) if r.get("input") else None,
                       ref=os.path.join(here, r["ref"]) if r.get("ref") else None,
                       tool_family=r["tool"].split("-")[0], model=r["model"])
        yield r["case"], fmpy_ok, cosim_ok, right, note, bad, referee, os.path.join(work, r["case"])


def ssp_rows(results, work, corpus):
    for r in results:
        right = r["verdict"] in GOOD_SSP
        note = r["verdict"] + (": " + r["message"].splitlines()[-1][:160] if r.get("message") and not right else "")
        # fmpy is no yardstick for SSP (it ignores parameter bindings): every case counts
        yield (r["source"] + "/" + r["case"], True, r["verdict"] not in ("refused", "crash", "hang", "failed", "missing"),
               right, note, r["verdict"] in ("crash", "hang", "WRONG"), None, None)


def referee_says(referee, run):
    """the referee's verdict where cosim and fmpy both completed and differ; kept in the case's
    folder (referee.json), so that scripts/conformance.sh can judge the FMI 3.0 part while the
    other parts run"""
    kept = os.path.join(run, "referee.json")
    if os.path.exists(kept):
        with open(kept) as f:
            return json.load(f)
    case = dict(referee, cosim_csv=os.path.join(run, "cosim.csv"), fmpy_csv=os.path.join(run, "fmpy.csv"),
                tight_csv=os.path.join(run, "fmpy-tight.csv"))
    try:
        verdict = conformance_referee.judge(case)
    except Exception as e:  # a result the referee cannot read decides nothing
        verdict = dict(right=False, referees=["none"], fmpy_wrong=False, lines=["referee failed: %s: %s" % (type(e).__name__, e)])
    with open(kept, "w") as f:
        json.dump(verdict, f)
    return verdict


def referee_part(work, corpus, name):
    """judge the part's cases where cosim and fmpy differ, print nothing (the table reads them)"""
    rows = dict(PARTS)[name](load(work, name) or [], os.path.join(work, name), corpus)
    for case, fmpy_ok, cosim_ok, right, note, bad, referee, run in rows:
        if fmpy_ok and cosim_ok and not right and referee:
            referee_says(referee, run)


# the main FMI 2.0 part runs cosim's default solver (auto); fmi2-dopri5 and fmi2-bdf its Model
# Exchange cases with the other two solvers
PARTS = [("fmi2", fmi2_rows), ("fmi2-dopri5", fmi2_rows), ("fmi2-bdf", fmi2_rows), ("fmi3", fmi3_rows), ("ssp", ssp_rows)]


def main():
    if len(sys.argv) == 5 and sys.argv[1] == "--referee-only":
        return referee_part(sys.argv[2], sys.argv[3], sys.argv[4])
    work, known_file, corpus = sys.argv[1], sys.argv[2], sys.argv[3]
    leftover = sys.argv[5] if len(sys.argv) > 5 and sys.argv[4] == "--leftover" else None
    known = {}
    if os.path.exists(known_file):
        for line in open(known_file):
            line = line.strip()
            if line and not line.startswith("#"):
                key, _, why = line.partition("  ")
                known[key.strip()] = why.strip()
    table, misses, failed, fixed, judged, speeds = [], [], False, [], [], []
    for name, rows in PARTS:
        results = load(work, name)
        if results is None:
            table.append("%-11s  no results (the runner failed: %s)" % (name, os.path.join(work, name + ".log")))
            failed = True
            continue
        rows = list(rows(results, os.path.join(work, name), corpus))
        n_fmpy = sum(1 for r in rows if r[1])
        n_cosim = sum(1 for r in rows if r[2])
        n_right = n_refereed = n_known = 0
        for case, fmpy_ok, cosim_ok, right, note, bad, referee, run in rows:
            key = name + ":" + case
            if fmpy_ok and cosim_ok and not right and referee:
                verdict = referee_says(referee, run)
                right = verdict["right"]
                n_refereed += right
                judged.append((key, verdict))
                note += "; referee (%s): %s" % (", ".join(verdict["referees"]), "cosim right" if right else "cosim not right")
            n_right += fmpy_ok and right
            if bad or (fmpy_ok and not right):
                # a crash or hang counts as known only where the list says "CRASH:" or "HANG:"
                # (the FMU's own fault, shown and explained there)
                if key in known and (not bad or known[key].startswith(("CRASH:", "HANG:"))):
                    n_known += 1
                    misses.append(("known", key, note, known[key]))
                else:
                    misses.append(("NEW", key, note, ""))
                    failed = True
            elif key in known:
                fixed.append(key)
        table.append("%-11s %6d %10d %11d %11d of %2d %10d %6d" % (name, len(rows), n_fmpy, n_cosim, n_right, n_fmpy,
                                                                 n_refereed, n_known))
        both = [r for r in results if r.get("cosim_status") == "ok" and r.get("fmpy_status") == "ok" and "cosim_wall" in r]
        if both:
            slower = ["%s %.2f s against %.2f s" % (r["case"], r["cosim_wall"], r["fmpy_wall"])
                      for r in both if r["cosim_wall"] > r["fmpy_wall"]]
            speeds.append("%-11s cosim %6.1f s, fmpy %6.1f s over the %d cases both complete; cosim slower on %s"
                          % (name, sum(r["cosim_wall"] for r in both), sum(r["fmpy_wall"] for r in both), len(both),
                             "; ".join(slower) if slower else "none"))
    print("== conformance table (cases where fmpy completes: cosim must complete and be right)")
    print("%-11s %6s %10s %11s %16s %10s %6s" % ("part", "cases", "fmpy done", "cosim done", "cosim right*", "refereed*", "known"))
    print("\n".join(table))
    print("* of the cases fmpy completes (SSP: of all cases; fmpy is no yardstick there); right: equal to fmpy's")
    print("  result (or by the FMI 3.0 runner within 1e-3 of the reference where fmpy is not: ref-ok), or, where")
    print("  they differ, right by the referee (refereed: how many of those)")
    print("== referee (cases where cosim and fmpy both complete and differ)")
    for key, verdict in judged:
        print("%s  %s by %s%s" % (key, "cosim right" if verdict["right"] else "cosim NOT right", ", ".join(verdict["referees"]),
                                  "; fmpy's default run is the wrong one" if verdict["right"] and verdict["fmpy_wrong"] else ""))
        for line in verdict["lines"]:
            print("    " + line)
    print("== speed (wall clock of each run's child process)")
    print("\n".join(speeds))
    print("== misses")
    for kind, key, note, why in misses:
        print("%-5s %s  %s%s" % (kind, key, note, ("  [known: " + why + "]") if why else ""))
    for key in fixed:
        print("fixed %s: now right, remove it from scripts/conformance-known.txt" % key)
    known_bad = sum(1 for kind, _, _, why in misses if kind == "known" and why.startswith(("CRASH:", "HANG:")))
    if leftover:
        # a process killed by a signal (a crash inside an FMU's call, a hang ended by the
        # runner's timeout) cannot remove its unpacked FMU: only left-behind folders without
        # such a case fail the run
        print("cosim's folders left in the cases' TMPDIR: %s" % leftover.replace("\n", ", "))
        if known_bad:
            print("(left by the %d known crash or hang above, whose process was killed)" % known_bad)
        else:
            failed = True
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()

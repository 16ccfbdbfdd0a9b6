"""One table of the third-party conformance run (scripts/conformance.sh): per part the cases,
how many fmpy and cosim complete, and how many cosim gets right where fmpy completes; then
every case that misses that goal, marked "known" when scripts/conformance-known.txt lists it
(with its reason) and "NEW" otherwise.

usage: python conformance_table.py WORK KNOWN_FILE [--leftover TEXT]
Exit status 1 when a case misses the goal and is not listed, or crashed, hung or gave a wrong
value (unless listed with a reason that starts "CRASH:" or "HANG:"); 0 otherwise.
"""
import json
import os
import sys

GOOD_FMI3 = {"bitwise", "pass", "ref-ok"}
GOOD_SSP = {"pass", "refused-as-expected", "ran (no values)", "no-fmu"}


def load(work, name):
    path = os.path.join(work, name + ".json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def fmi2_rows(results):
    """(case, fmpy completes, cosim completes, cosim right, note) of the FMI 2.0 runner."""
    for r in results:
        fmpy_ok = r["fmpy_status"] == "ok"
        cosim_ok = r["cosim_status"] == "ok"
        right = cosim_ok and bool(r.get("cosim_pass"))
        note = r["cosim_status"] if not cosim_ok else ("" if right else "off the reference: %s %s" % (r.get("cosim_rel_out"), r.get("cosim_worst")))
        if not cosim_ok:
            note += ": " + (r.get("cosim_err") or "").strip().splitlines()[-1:][0][:160] if (r.get("cosim_err") or "").strip() else ""
        yield r["case"], fmpy_ok, cosim_ok, right, note, r["cosim_status"].startswith(("CRASH", "HANG"))


def fmi3_rows(results):
    for r in results:
        fmpy_ok = r["fmpy_status"] == "ok"
        cosim_ok = r["cosim_status"] == "ok"
        right = cosim_ok and r["verdict"] in GOOD_FMI3
        err = (r.get("cosim_err") or "").strip().splitlines()
        note = r["verdict"] + (": " + err[-1][:160] if err and not cosim_ok else "")
        bad = r["cosim_status"].startswith(("CRASH", "HANG", "crash", "hang", "signal", "timeout"))
        yield r["case"], fmpy_ok, cosim_ok, right, note, bad


def ssp_rows(results):
    for r in results:
        right = r["verdict"] in GOOD_SSP
        note = r["verdict"] + (": " + r["message"].splitlines()[-1][:160] if r.get("message") and not right else "")
        # fmpy is no yardstick for SSP (it ignores parameter bindings): every case counts
        yield r["source"] + "/" + r["case"], True, r["verdict"] not in ("refused", "crash", "hang", "failed", "missing"), right, note, r["verdict"] in ("crash", "hang", "WRONG")


def main():
    work, known_file = sys.argv[1], sys.argv[2]
    leftover = sys.argv[4] if len(sys.argv) > 4 and sys.argv[3] == "--leftover" else None
    known = {}
    if os.path.exists(known_file):
        for line in open(known_file):
            line = line.strip()
            if line and not line.startswith("#"):
                key, _, why = line.partition("  ")
                known[key.strip()] = why.strip()
    parts = [("fmi2", fmi2_rows), ("fmi2-auto", fmi2_rows), ("fmi2-bdf", fmi2_rows), ("fmi3", fmi3_rows), ("ssp", ssp_rows)]
    print("== conformance table (cases where fmpy completes: cosim must complete and be right)")
    print("%-9s %6s %12s %13s %16s %7s" % ("part", "cases", "fmpy done", "cosim done", "cosim right*", "known"))
    misses, failed, fixed = [], False, []
    for name, rows in parts:
        results = load(work, name)
        if results is None:
            print("%-9s  no results (the runner failed: %s)" % (name, os.path.join(work, name + ".log")))
            failed = True
            continue
        rows = list(rows(results))
        n_fmpy = sum(1 for r in rows if r[1])
        n_cosim = sum(1 for r in rows if r[2])
        n_right = sum(1 for r in rows if r[1] and r[3])
        n_known = 0
        for case, fmpy_ok, _, right, note, bad in rows:
            key = name + ":" + case
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
        print("%-9s %6d %12d %13d %11d of %2d %7d" % (name, len(rows), n_fmpy, n_cosim, n_right, n_fmpy, n_known))
    print("* of the cases fmpy completes (SSP: of all cases; fmpy is no yardstick there)")
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

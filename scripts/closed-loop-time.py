"""CPU time of the 30 s closed loop under two builds of `cosim` (docs/architecture.md, "The
closed loop's time before and after the seams"): alternating runs of
`COSIM run SSP --stop-time 30 --step 1e-3 --algorithm ALGORITHM -o OUT.csv`, which build goes
first alternating from pair to pair, each run's user + system time from getrusage (load on the
machine disturbs CPU time less than wall time).

    python3 scripts/closed-loop-time.py BEFORE_COSIM AFTER_COSIM PAIRS ALGORITHM [SSP] [--but-the-last-row]

SSP defaults to target/ssp/nigel_closed_loop.ssp (the FMI 2.0 closed loop); both builds run
the same SSP and FMUs, so the time compared is the master's and the importing layer's. The
two builds' CSVs must be the same bytes (the refactoring keeps every result bit for bit):
the script stops with a message if they differ; with `--but-the-last-row`, all rows but the
last (the row of the stop time, where an FMU that ends the run there was handled otherwise
before main's 9978186: under `ordered` the FMI 3.0 maneuver's terminateSimulation at 30 s
kept the instances after it from taking the last step).
Prints the median CPU time of each and the median, smallest and largest ratio after / before
of the pairs. `alternate` is also scripts/clocked-loop-time.py's loop.
"""
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

TARGET = Path(__file__).resolve().parents[1] / os.environ.get("CARGO_TARGET_DIR", "target")


def cpu_time(cosim, ssp, algorithm, out):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([str(cosim), "run", str(ssp), "--stop-time", "30", "--step", "1e-3", "--algorithm", algorithm,
                    "-o", str(out)], check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def csv_rows(path, but_the_last_row):
    rows = path.read_bytes().splitlines()
    return rows[:-1] if but_the_last_row else rows


def alternate(pairs, algorithm, first, second, same_csv, but_the_last_row=False):
    """`pairs` alternating runs of the two sides, each `(label, cosim, ssp)`, the first side
    first in even pairs; with `same_csv` their CSVs must be the same bytes (all rows but the
    last with `but_the_last_row`). Prints and returns the medians and the per-pair ratios
    second / first."""
    times = {first[0]: [], second[0]: []}
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(pairs):
            for label, cosim, ssp in (first, second) if i % 2 == 0 else (second, first):
                times[label].append(cpu_time(cosim, ssp, algorithm, Path(tmp) / f"{label}.csv"))
            csvs = [csv_rows(Path(tmp) / f"{side[0]}.csv", but_the_last_row) for side in (first, second)]
            if same_csv and csvs[0] != csvs[1]:
                sys.exit(f"{algorithm}: the CSVs of {first[0]} and {second[0]} differ")
    ratios = sorted(b / a for a, b in zip(times[first[0]], times[second[0]]))
    print(f"{algorithm}: {first[0]} {statistics.median(times[first[0]]):.3f} s, {second[0]} "
          f"{statistics.median(times[second[0]]):.3f} s (medians); {second[0]} / {first[0]} per pair: median "
          f"{statistics.median(ratios):.3f}, {ratios[0]:.3f} to {ratios[-1]:.3f} ({pairs} pairs"
          f"{(', CSVs equal but the last row' if but_the_last_row else ', CSVs equal') if same_csv else ''})")
    return times, ratios


def main():
    but_the_last_row = "--but-the-last-row" in sys.argv
    args = [a for a in sys.argv[1:] if a != "--but-the-last-row"]
    if len(args) not in (4, 5):
        sys.exit(__doc__)
    pairs, algorithm = int(args[2]), args[3]
    ssp = Path(args[4]) if len(args) > 4 else TARGET / "ssp" / "nigel_closed_loop.ssp"
    alternate(pairs, algorithm, ("before", Path(args[0]), ssp), ("after", Path(args[1]), ssp), True, but_the_last_row)


if __name__ == "__main__":
    main()

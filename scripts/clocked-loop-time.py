"""CPU time of the clocked FMI 3.0 closed loop against another closed loop (docs/fmus.md, "Its
time"): alternating runs of `cosim run SSP --stop-time 30 --step 1e-3 --algorithm ALGORITHM`,
which goes first alternating from pair to pair, each run's user + system time from getrusage.

    python3 scripts/clocked-loop-time.py PAIRS ALGORITHM [UNCLOCKED_SSP CLOCKED_SSP]

The SSPs default to target/ssp's nigel_closed_loop.ssp (FMI 2.0, no clock: the "unclocked"
runs) and nigel_closed_loop_fmi3.ssp (the FMI 3.0 archives, the controller with its sample
clock), built alike by `cargo run --release -p build-fmu -- --platforms linux64 --this-glibc`.
(An unclocked FMI 3.0 loop is built from a commit before the clock became the default, when
it was the option `controller-sample-clock`.)
Prints the median CPU time of each and the median, smallest and largest ratio of the pairs.
"""
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

TARGET = Path(__file__).resolve().parents[1] / os.environ.get("CARGO_TARGET_DIR", "target")


def cpu_time(ssp, algorithm, out):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([str(TARGET / "release" / "cosim"), "run", str(ssp), "--stop-time", "30", "--step", "1e-3",
                    "--algorithm", algorithm, "-o", str(out)], check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def main():
    pairs, algorithm = int(sys.argv[1]), sys.argv[2]
    unclocked, clocked = (sys.argv[3:5] if len(sys.argv) > 4
                          else (TARGET / "ssp" / "nigel_closed_loop.ssp", TARGET / "ssp" / "nigel_closed_loop_fmi3.ssp"))
    times = {"unclocked": [], "clocked": []}
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(pairs):
            order = [("unclocked", unclocked), ("clocked", clocked)]
            for label, ssp in order if i % 2 == 0 else order[::-1]:
                times[label].append(cpu_time(ssp, algorithm, Path(tmp) / f"{label}.csv"))
    ratios = sorted(c / u for u, c in zip(times["unclocked"], times["clocked"]))
    print(f"{algorithm}: unclocked {statistics.median(times['unclocked']):.3f} s, clocked "
          f"{statistics.median(times['clocked']):.3f} s (medians); clocked / unclocked per pair: median "
          f"{statistics.median(ratios):.3f}, {ratios[0]:.3f} to {ratios[-1]:.3f} ({pairs} pairs)")


if __name__ == "__main__":
    main()

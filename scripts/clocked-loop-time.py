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
import importlib.util
import os
import sys
from pathlib import Path

TARGET = Path(__file__).resolve().parents[1] / os.environ.get("CARGO_TARGET_DIR", "target")
# the alternating loop of closed-loop-time.py (a file name with hyphens: loaded by path)
_spec = importlib.util.spec_from_file_location("closed_loop_time", Path(__file__).with_name("closed-loop-time.py"))
closed_loop_time = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(closed_loop_time)


def main():
    pairs, algorithm = int(sys.argv[1]), sys.argv[2]
    unclocked, clocked = (sys.argv[3:5] if len(sys.argv) > 4
                          else (TARGET / "ssp" / "nigel_closed_loop.ssp", TARGET / "ssp" / "nigel_closed_loop_fmi3.ssp"))
    cosim = TARGET / "release" / "cosim"
    closed_loop_time.alternate(pairs, algorithm, ("unclocked", cosim, unclocked), ("clocked", cosim, clocked), False)


if __name__ == "__main__":
    main()

"""Compares a closed-loop CSV of another platform's master with the x86-64 Linux one.
Byte for byte first; where they differ, the difference must be that of the FMUs' own C
library: same header, same rows, the time column identical, and every value within 1e-12 of
its column's largest magnitude. That bound is build-fmu/tests/platforms.rs's for the same
FMU libraries run by a plain C importer (no master of ours): the plant's heading rotation
(sin, cos), beta (atan2), speed (hypot) and the friction's sine come from each platform's C
library (msvcrt under wine, glibc on aarch64), which may round the last bit otherwise. The
columns no C library function feeds (the test bench's steering program, speed reference and
wind: OWN_ARITHMETIC of build-fmu/tests/platforms.rs) must be identical, as there.
Usage: compare-platform-csv.py REFERENCE.csv OTHER.csv NAME"""
import csv
import sys

# the test bench's open-loop outputs, computed with + - * / and sqrt only (correctly rounded
# everywhere): bit for bit on every platform (build-fmu/tests/platforms.rs's OWN_ARITHMETIC)
OWN_ARITHMETIC = [f"maneuver.{n}" for n in ("delta_ff_fl", "delta_ff_fr", "delta_ff_rl", "delta_ff_rr", "speed_ref", "wind_x", "wind_y")]

reference, other, name = sys.argv[1:4]
if open(reference, "rb").read() == open(other, "rb").read():
    print(f"identical to x86-64 Linux byte for byte: {name}")
    sys.exit(0)
a = list(csv.reader(open(reference)))
b = list(csv.reader(open(other)))
if a[0] != b[0] or len(a) != len(b):
    sys.exit(f"{name}: other columns or rows than x86-64 Linux ({len(b)} rows, {len(a)} there)")
header, rows_a, rows_b = a[0], a[1:], b[1:]
if [r[0] for r in rows_a] != [r[0] for r in rows_b]:
    sys.exit(f"{name}: the time column differs from x86-64 Linux")
differing, first, worst = 0, None, (0.0, "")
for j, column in enumerate(header[1:], start=1):
    ref = [float(r[j]) for r in rows_a]
    bound = 1e-12 * max(abs(v) for v in ref)
    for k, (x, y) in enumerate(zip(ref, (float(r[j]) for r in rows_b))):
        if x != y and column in OWN_ARITHMETIC:
            sys.exit(f"{name}: {column} at t = {rows_a[k][0]} s: {y!r} against {x!r}; no C library function feeds it, so it must be identical")
        if x != y:
            differing += 1
            first = min(first or (k, column), (k, column))
            if abs(x - y) > bound:
                sys.exit(f"{name}: {column} at t = {rows_a[k][0]} s: {y!r} against {x!r}, beyond 1e-12 of the column's largest magnitude")
            if abs(x - y) > worst[0]:
                worst = (abs(x - y), column)
total = len(rows_a) * (len(header) - 1)
print(
    f"{name}: {differing} of {total} values differ from x86-64 Linux in the last bits (first {first[1]} at t = {rows_a[first[0]][0]} s, "
    f"largest {worst[0]:.3g} in {worst[1]}), each within 1e-12 of its column's largest magnitude: the FMUs' C library"
)

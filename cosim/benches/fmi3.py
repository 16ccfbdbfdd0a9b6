"""The FMI 3.0 closed loop against the FMI 2.0 one in `cosim run`, in one run, alternated.

Usage: target/venv/bin/python cosim/benches/fmi3.py COSIM SSP_DIR [ROUNDS]

The systems (SSP_DIR is build-fmu's target/ssp):
- FMI 2.0: SSP_DIR/nigel_closed_loop.ssp (the three FMUs' FMI 2.0 archives);
- mixed: that SSP with the plant's FMI 2.0 archive replaced by its FMI 3.0 archive, taken
  from SSP_DIR/nigel_closed_loop_fmi3.ssp (written here into a temporary folder);
- FMI 3.0: SSP_DIR/nigel_closed_loop_fmi3.ssp (the three FMUs' FMI 3.0 archives).
The FMI 3.0 archives hold the same libraries as the FMI 2.0 ones (each exports both
generations), so what differs is the master's FMI 3.0 import path and the FMUs' FMI 3.0 ABI.

Each is run as `cosim run SSP --stop-time 30 --step 1e-3 --algorithm ordered ...`, timed from
the start of the process to its end (start-up, unpacking and loading the FMUs, the 30,000
steps, the CSV), three times per round: recording one variable (`--record plant.x`), all
outputs to the CSV, and `--record plant.x --summary FILE`, of which the time is the summary's
`wall_time_s` (initialization and the 30,000 steps only, with the clock reads of the summary's
per-FMU times). Each round runs every case once, in an order rotated by one case per round, so
that no system always runs first or after the same neighbour. One untimed run of each warms
the file cache. Printed per case: the median over the rounds and the range (min .. max), and
the ratios of the medians to the FMI 2.0 system's. The machine is shared: read the ranges,
not only the medians.
"""
import json
import statistics
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

cosim, ssp_dir = sys.argv[1], Path(sys.argv[2])
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 9
work = Path(tempfile.mkdtemp(prefix="fmi3-bench-"))
out = work / "out.csv"

fmi2_ssp = ssp_dir / "nigel_closed_loop.ssp"
fmi3_ssp = ssp_dir / "nigel_closed_loop_fmi3.ssp"


def mixed_ssp():
    """The FMI 2.0 SSP with the plant's entry taken from the FMI 3.0 SSP (same entry name)."""
    with zipfile.ZipFile(fmi3_ssp) as z3:
        plant3 = [n for n in z3.namelist() if n.endswith("nigel_plant.fmu")]
        assert len(plant3) == 1, z3.namelist()
        plant3_bytes = z3.read(plant3[0])
    path = work / "nigel_closed_loop_mixed.ssp"
    with zipfile.ZipFile(fmi2_ssp) as z2, zipfile.ZipFile(path, "w") as z:
        names = z2.namelist()
        assert plant3[0] in names, (plant3[0], names)
        for info in z2.infolist():
            data = plant3_bytes if info.filename == plant3[0] else z2.read(info)
            # stored, as write_ssp writes them: the master reads the FMUs in place
            z.writestr(info.filename, data, compress_type=zipfile.ZIP_STORED)
    return path


systems = {"FMI 2.0": fmi2_ssp, "mixed (plant FMI 3.0)": mixed_ssp(), "FMI 3.0": fmi3_ssp}
summary = work / "summary.json"
recordings = {
    "--record plant.x": ["--record", "plant.x"],
    "all outputs": [],
    "loop (wall_time_s)": ["--record", "plant.x", "--summary", str(summary)],
}


def whole(ssp, extra):
    args = [cosim, "run", str(ssp), "--stop-time", "30", "--step", "1e-3", "--algorithm", "ordered",
            "--output", str(out), *extra]
    t = time.perf_counter()
    subprocess.run(args, check=True, stderr=subprocess.DEVNULL)
    elapsed = time.perf_counter() - t
    if "--summary" in extra:
        return json.loads(summary.read_text())["wall_time_s"]
    return elapsed


cases = [(s, r) for r in recordings for s in systems]
times = {c: [] for c in cases}
for s, r in cases:
    whole(systems[s], recordings[r])
for k in range(rounds):
    for s, r in cases[k % len(cases):] + cases[:k % len(cases)]:
        times[(s, r)].append(whole(systems[s], recordings[r]))
med = {c: statistics.median(v) for c, v in times.items()}
print(f"{rounds} rounds, alternated; cosim run --stop-time 30 --step 1e-3 --algorithm ordered")
for (s, r), v in times.items():
    print(f"{s:<22} {r:<19} median {med[(s, r)] * 1e3:7.1f} ms  range {min(v) * 1e3:7.1f} .. {max(v) * 1e3:7.1f} ms")
for r in recordings:
    base = med[("FMI 2.0", r)]
    for s in list(systems)[1:]:
        print(f"{s} / FMI 2.0, {r}: {med[(s, r)] / base:.3f}x (ratio of medians)")

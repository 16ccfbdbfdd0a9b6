"""The campaign's results.csv as users load it: fmpy's read_csv and pandas give the same
numbers as the file's rows, a failed run included (status 1, NaN metrics, its message in
messages.csv)."""

import math
import os
import subprocess
from pathlib import Path

import pandas
from fmpy.util import read_csv

ROOT = Path(__file__).resolve().parents[3]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
if not TARGET.is_absolute():
    TARGET = ROOT / TARGET
CAMPAIGN = TARGET / "release" / "campaign"
SSP = TARGET / "ssp" / "nigel_closed_loop.ssp"


def test_fmpy_and_pandas_read_results(tmp_path):
    spec = tmp_path / "c.toml"
    spec.write_text(
        f'system = "{SSP}"\nstop_time = 0.2\nstep = 1e-3\nsamples = 2\n'
        '[grid]\n"maneuver.duration" = [30.0, 0.1]\n'
        '[cases.column]\nsim = { "maneuver.fidelity" = 1, "plant.friction_circle" = false }\n'
        'real = { "maneuver.fidelity" = 2, "plant.friction_circle" = true }\n'
        '[random]\n"plant.m" = { uniform = [2.4, 3.0] }\n'
        '[metrics]\ny_final = "final(plant.y)"\nspeed_mean = "mean(plant.speed)"\n'
    )
    out = tmp_path / "out"
    done = subprocess.run([str(CAMPAIGN), "run", str(spec), "--out", str(out)], capture_output=True, text=True)
    # exit status 3: the campaign completed and runs failed (the four refused below), said in one line
    assert done.returncode == 3, done.stderr
    assert "campaign: 8 runs, 4 failed (4 failed): run 4 failed (" in done.stderr, done.stderr
    lines = (out / "results.csv").read_text().splitlines()
    rows = [[float(x) for x in line.split(",")] for line in lines[1:]]
    assert len(rows) == 2 * 2 * 2

    traj = read_csv(out / "results.csv")
    assert list(traj.dtype.names) == ["run", "status", "message", "maneuver.duration", "column", "plant.m", "y_final", "speed_mean"]
    frame = pandas.read_csv(out / "results.csv")
    assert list(frame.columns) == list(traj.dtype.names)
    for k, row in enumerate(rows):
        for j, name in enumerate(traj.dtype.names):
            for got in (traj[name][k], frame[name][k]):
                assert (math.isnan(got) and math.isnan(row[j])) or got == row[j], (k, name)
    failed = frame[frame.status == 1]
    # duration 0.1 s < stop time 0.2 s is refused by the test bench: runs 4 .. 7 (the grid's second value)
    assert list(failed.run) == [4, 5, 6, 7]
    assert failed.y_final.isna().all() and (failed.message == 1).all()
    messages = pandas.read_csv(out / "messages.csv")
    assert list(messages.run) == [4, 5, 6, 7]
    assert all("duration" in m for m in messages.message)
    # the case column holds the case's index: sim, real alternate fastest within a duration
    assert list(frame.column[:4]) == [0, 0, 1, 1]

"""Every example runs and prints what its header says. The numbers each prints are checked
against `table3 --json` of the same job, an independent path through the same FMUs (the
master's Rust loop, or nigel-benchmark's in-process loop), not against a copy of the output.

Run by scripts/test.sh: `target/venv/bin/python -m pytest examples -q` (after build-fmu)."""
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "cosim" / "tests" / "python"))

from closed_loop_tools import release_binary, target_dir  # noqa: E402

# Same FMUs, same step sizes and order of calls: the runs agree to the rounding of the 30,000
# squared errors summed in a different order (numpy's pairwise sum, awk's running sum), far
# below 1e-9 relative on any x86-64 machine.
REL = 1e-9


@pytest.fixture(scope="module")
def table3_sim_lane_change(tmp_path_factory):
    """The sim lane-change cells of Table III from the FMU engine (the default)."""
    d = tmp_path_factory.mktemp("table3")
    subprocess.run([str(release_binary("table3", "nigel-table3")), "--quiet", "--maneuver", "lane_change",
                    "--controller", "open_loop", "--controller", "robust", "--json", str(d / "t.json")],
                   check=True, capture_output=True)
    return json.loads((d / "t.json").read_text())["results"]["sim"]["lane_change"]


def number(pattern, text):
    m = re.search(pattern, text)
    assert m, f"{pattern!r} not in\n{text}"
    return float(m.group(1))


def test_a_closed_loop_in_fmpy(table3_sim_lane_change, tmp_path):
    png = tmp_path / "closed_loop.png"
    r = subprocess.run([sys.executable, str(REPO / "examples" / "closed_loop_fmpy.py"), str(png)],
                       capture_output=True, text=True, check=True)
    eps = number(r"epsilon (\S+) \(RMSE", r.stdout)
    want = table3_sim_lane_change["robust"]["eps"]
    assert abs(eps - want) <= REL * want, (eps, want)
    assert f"wrote {png}" in r.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_b_own_gain_in_table3_and_cosim(tmp_path):
    r = subprocess.run(["bash", str(REPO / "examples" / "own_gain.sh"), str(tmp_path)],
                       capture_output=True, text=True, check=True)
    k = json.loads((tmp_path / "k.json").read_text())["K"]
    table = json.loads((tmp_path / "table3.json").read_text())
    custom = table["results"]["sim"]["lane_change"]["custom"]["eps"]
    # table3 ran the file's gain (its JSON lists the gains as rows of [k_beta, k_yaw_rate])
    assert table["gains"]["custom"] == k
    # the master, given the same file through --gains, ran the same closed loop
    eps = number(r"cosim custom epsilon (\S+)", r.stdout)
    assert abs(eps - custom) <= REL * custom, (eps, custom)
    # and the controller FMU used that gain: its gain_* outputs, recorded in the CSV
    header = (tmp_path / "cosim.csv").read_text().splitlines()[:2]
    names = [n.strip('"') for n in header[0].split(",")]
    row = dict(zip(names, map(float, header[1].split(","))))
    assert row["controller.gain_beta_fl"] == k[0][0] and row["controller.gain_yaw_rate_rr"] == k[3][1]
    # a different gain than the paper's robust one, and a different result
    assert custom != table["results"]["sim"]["lane_change"]["robust"]["eps"]


def test_d_cosim_as_a_library(table3_sim_lane_change):
    r = subprocess.run(["cargo", "run", "--release", "--quiet", "-p", "nigel-cosim", "--example", "closed_loop",
                        "--", str(target_dir() / "ssp" / "nigel_closed_loop.ssp")],
                       cwd=REPO, capture_output=True, text=True, check=True)
    for name in ("open_loop", "robust"):
        eps = number(rf"{name}\s+epsilon (\S+)", r.stdout)
        want = table3_sim_lane_change[name]["eps"]
        assert abs(eps - want) <= REL * want, (name, eps, want)

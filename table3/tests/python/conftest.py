# The fixtures and helpers are shared with the master's cross-checks: cosim/tests/python
# (fixtures.py, closed_loop_tools.py), put on the import path here, and the check of the
# figures the docs print (tests/python/doc_figures.py). Below: the fixtures of the SSP
# cross-checks (test_ssp_*.py).
import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]
sys.path.insert(0, str(REPO / "cosim" / "tests" / "python"))
sys.path.insert(0, str(REPO / "tests" / "python"))

from fixtures import cosim, plant_fmu, table3  # noqa: E402, F401
from closed_loop_tools import target_dir  # noqa: E402

# the one job of Table III the SSP cross-checks run
JOB = "sim/lane_change/robust"


@pytest.fixture(scope="module")
def ssp(table3):
    p = target_dir() / "ssp" / "nigel_closed_loop.ssp"
    subprocess.run([str(table3), "--ssp", str(p), "--ssp-job", JOB], check=True, capture_output=True)
    return p


@pytest.fixture(scope="module")
def ours(table3, tmp_path_factory):
    d = tmp_path_factory.mktemp("ours")
    out = {}
    for alg in ("ordered", "jacobi"):
        subprocess.run([str(table3), "--quiet", "--algorithm", alg, "--maneuver", "lane_change",
                        "--json", str(d / f"{alg}.json"), "--csv", str(d / alg)],
                       check=True, capture_output=True)
        cells = json.loads((d / f"{alg}.json").read_text())["results"]["sim"]["lane_change"]
        rows = np.genfromtxt(d / alg / "sim_lane_change_robust.csv", delimiter=",", names=True)
        out[alg] = (cells["robust"]["eps"], rows)
    return out

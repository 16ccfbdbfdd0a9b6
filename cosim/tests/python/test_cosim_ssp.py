"""An SSP exported by the master (cosim/tests/ssp.rs) run by fmpy's simulate_ssp and by
`cosim run --algorithm jacobi`: the same values, fmpy's rows shifted by one.

fmpy 0.3.32's simulate_ssp starts every connection at 0.0 (no initial propagation),
labels a row with the time at the *start* of the step whose results it holds, and
accumulates time (t += h). The exported system has all outputs zero at t = 0, so
our row n + 1 (time t0 + (n+1) h) must equal fmpy's row n; rounding of fmpy's
accumulated time reaches the FMUs, hence the 1e-12 tolerance instead of bit equality."""
import subprocess

import numpy as np
import pytest
from fmpy.ssp.simulation import simulate_ssp
from lxml import etree
import zipfile
import os
import fmpy.ssp

from closed_loop_tools import REPO, target_dir


@pytest.fixture(scope="module")
def exported_ssp():
    p = target_dir() / "cosim-tests" / "export" / "chain_with_plant.ssp"
    if not p.exists():
        subprocess.run(["cargo", "test", "--release", "-q", "-p", "nigel-cosim", "--test", "ssp",
                        "writes_the_system_for_the_fmpy_cross_check"], cwd=REPO, check=True)
    return p


def test_export_validates_against_the_ssp_schema(exported_ssp):
    schema_dir = os.path.join(os.path.dirname(fmpy.ssp.__file__), "schema")
    schema = etree.XMLSchema(file=os.path.join(schema_dir, "SystemStructureDescription.xsd"))
    with zipfile.ZipFile(exported_ssp) as z:
        root = etree.fromstring(z.read("SystemStructure.ssd"))
    assert schema.validate(root), schema.error_log


def test_jacobi_equals_fmpy_simulate_ssp(cosim, exported_ssp, tmp_path):
    stop, h = 1.0, 0.01
    out = tmp_path / "ours.csv"
    subprocess.run([str(cosim), "run", str(exported_ssp), "--stop-time", str(stop), "--step", str(h),
                    "--algorithm", "jacobi", "--output", str(out)], check=True, capture_output=True)
    ours = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    ref = simulate_ssp(str(exported_ssp), stop_time=stop, step_size=h)
    names = ["src.y", "amp.y", "int.x", "plant.x", "plant.v_x", "plant.force_lat_fl"]
    n = len(ref)
    assert n == 100 and len(ours) == 101
    for name in names:
        assert name in ref.dtype.names and name in ours.dtype.names
        diff = np.max(np.abs(ours[name][1:n + 1] - ref[name]))
        assert diff <= 1e-12, f"{name}: {diff}"
    # the chain really moved: y = 2 t, x = integral of the delayed 2 t
    assert abs(ours["amp.y"][-1] - 2 * 0.99) < 1e-12  # one step of jacobi delay
    assert ours["int.x"][-1] > 0.9


def test_cosim_info_lists_the_ssp(cosim, exported_ssp):
    r = subprocess.run([str(cosim), "info", str(exported_ssp)], capture_output=True, text=True, check=True)
    assert "4 instances, 3 connections" in r.stdout
    assert "amp.y [m] -> plant.mu_fl [-]" in r.stdout


def test_threads_option_gives_the_same_csv_and_says_how_many_steps_ran_in_the_pool(cosim, exported_ssp, tmp_path):
    import json
    outs = []
    for threads in (1, 2):
        out, summary = tmp_path / f"t{threads}.csv", tmp_path / f"t{threads}.json"
        subprocess.run([str(cosim), "run", str(exported_ssp), "--stop-time", "1.5", "--step", "1e-3",
                        "--algorithm", "jacobi", "--threads", str(threads), "--output", str(out),
                        "--summary", str(summary)], check=True, capture_output=True)
        outs.append(out.read_bytes())
        pooled = json.loads(summary.read_text())["parallel_steps"]
        # 200 calibration steps in one thread, then at least the pool's 1000 probe steps
        assert pooled == 0 if threads == 1 else 1000 <= pooled <= 1300, (threads, pooled)
    assert outs[0] == outs[1]
    r = subprocess.run([str(cosim), "run", str(exported_ssp), "--stop-time", "0.1", "--threads", "0"],
                       capture_output=True, text=True)
    assert r.returncode != 0 and "--threads must be at least 1" in r.stderr

"""A third-party binary: `fmucontainer` (fmu-manipulation-toolbox 2.0) wraps the FMUs of the
SSP the master exported (cosim/tests/ssp.rs) into one container FMU with its own C runtime,
which imports our FMUs itself. The master loads that container like any FMU; the
container's schedule (parallel: every internal connection one step late) must give our
own `jacobi` run of the same SSP at every point."""
import os
import shutil
import subprocess
import sys

import numpy as np

from test_cosim_ssp import exported_ssp  # noqa: F401  (the fixture)


def test_container_fmu_loads_and_matches_jacobi(cosim, exported_ssp, tmp_path):  # noqa: F811
    shutil.copy(exported_ssp, tmp_path / "chain.ssp")
    tool = os.path.join(os.path.dirname(sys.executable), "fmucontainer")
    subprocess.run([tool, "-container", "chain.ssp:0.01", "-fmu-directory", str(tmp_path)], cwd=tmp_path,
                   check=True, capture_output=True)
    container = tmp_path / "chain.fmu"
    assert container.exists()
    info = subprocess.run([str(cosim), "info", str(container)], capture_output=True, text=True, check=True)
    assert "source.y" in info.stdout and "gain.y" in info.stdout
    subprocess.run([str(cosim), "run", str(container), "--stop-time", "1", "--step", "0.01",
                    "--record", "source.y", "--record", "gain.y", "--output", str(tmp_path / "c.csv")],
                   check=True, capture_output=True)
    subprocess.run([str(cosim), "run", str(exported_ssp), "--stop-time", "1", "--step", "0.01",
                    "--algorithm", "jacobi", "--record", "src.y", "--record", "amp.y",
                    "--output", str(tmp_path / "ours.csv")], check=True, capture_output=True)
    c = np.genfromtxt(tmp_path / "c.csv", delimiter=",", names=True, deletechars="")
    ours = np.genfromtxt(tmp_path / "ours.csv", delimiter=",", names=True, deletechars="")
    assert len(c) == len(ours) == 101
    assert np.max(np.abs(c["source.y"] - ours["src.y"])) <= 1e-12
    assert np.max(np.abs(c["gain.y"] - ours["amp.y"])) <= 1e-12
    assert ours["amp.y"][-1] == 1.98  # 2 * src.y(0.99): one step of delay

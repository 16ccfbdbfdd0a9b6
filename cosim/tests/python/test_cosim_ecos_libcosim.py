"""The SSP exported by the master (cosim/tests/ssp.rs), run by ecos (ecospy 0.7.2) and
libcosim (libcosimpy 0.0.6), against `cosim run --algorithm jacobi` on the same file.

All three delay every connection by one step. Reading conventions differ: we and
libcosim's observer read outputs right after the step (before the new inputs are set);
ecos reads after the connections were applied, so for a direct-feedthrough output (the
gain's y = k u) ecos shows the value with the new input. States and outputs without
feedthrough (src.y, int.x) are compared; libcosim on every recorded variable."""
import subprocess

import numpy as np
import pytest

from closed_loop_tools import ecos_series, libcosim_series
from test_cosim_ssp import exported_ssp  # noqa: F401  (the fixture)

STOP, H, N = 1.0, 0.01, 100
RECORDED = ["src.y", "amp.y", "int.x", "plant.mu_fl", "plant.x", "plant.beta"]


@pytest.fixture(scope="module")
def ours(cosim, exported_ssp, tmp_path_factory):  # noqa: F811
    out = tmp_path_factory.mktemp("ours") / "ours.csv"
    subprocess.run([str(cosim), "run", str(exported_ssp), "--stop-time", str(STOP), "--step", str(H),
                    "--algorithm", "jacobi", "--output", str(out)]
                   + [a for v in RECORDED for a in ("--record", v)], check=True, capture_output=True)
    return np.genfromtxt(out, delimiter=",", names=True, deletechars="")


def test_libcosim_agrees_at_every_step(ours, exported_ssp):  # noqa: F811
    theirs = libcosim_series(exported_ssp, int(H * 1e9), N, RECORDED)  # time in ns
    worst = max(abs(theirs[name][n - 1] - ours[name][n]) for name in RECORDED for n in range(1, N + 1))
    assert worst <= 1e-12, worst
    assert ours["int.x"][N] > 0.9


def test_ecos_agrees_on_states_and_outputs_without_feedthrough(ours, exported_ssp):  # noqa: F811
    theirs = ecos_series(exported_ssp, H, N, ["src.y", "int.x", "plant.x", "amp.y"])
    worst = max(abs(theirs[name][n - 1] - ours[name][n])
                for name in ["src.y", "int.x", "plant.x"] for n in range(1, N + 1))
    assert worst <= 1e-12, worst
    for n in range(1, N + 1):
        # feedthrough output read after the new input: 2 src.y(t_n), our ordered value
        assert abs(theirs["amp.y"][n - 1] - 2 * ours["src.y"][n]) <= 1e-12

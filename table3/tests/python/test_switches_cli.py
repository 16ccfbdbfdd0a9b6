"""The closed loop's switches and initial speed from the command line (`cosim run SSP --set`):
the switches are plain Integers (1-based, listed in each variable's description); an item
name where the Integer is due gets an error that names the value to use, an unknown name one
that lists the values; the initial speed is the plant parameter `v_x_start`."""
import subprocess

import numpy as np


def run(cosim, ssp, *sets, out=None):
    args = [str(cosim), "run", str(ssp), "--stop-time", "0.01", "--step", "1e-3"]
    for s in sets:
        args += ["--set", s]
    if out is not None:
        args += ["--output", str(out), "--record", "plant.x", "--record", "plant.v_x"]
    return subprocess.run(args, capture_output=True, text=True)


def test_an_item_name_is_refused_naming_its_value(cosim, ssp):
    r = run(cosim, ssp, "controller.controller=robust")
    assert r.returncode != 0
    assert 'controller.controller = "robust"' in r.stderr and "set controller.controller=3" in r.stderr, r.stderr
    r = run(cosim, ssp, "maneuver.fidelity=real")
    assert r.returncode != 0 and "set maneuver.fidelity=2" in r.stderr, r.stderr


def test_an_unknown_name_or_value_is_refused_listing_the_values(cosim, ssp):
    r = run(cosim, ssp, "maneuver.maneuver=zigzag")
    assert r.returncode != 0
    assert "1 straight" in r.stderr and "6 figure_8" in r.stderr, r.stderr
    r = run(cosim, ssp, "maneuver.maneuver=7")
    assert r.returncode != 0 and "maneuver" in r.stderr and "7" in r.stderr, r.stderr


def test_integer_values_and_the_initial_speed_are_applied(cosim, ssp, tmp_path):
    out = tmp_path / "o.csv"
    r = run(cosim, ssp, "controller.controller=1", "maneuver.maneuver=3", "plant.v_x_start=0.5", out=out)
    assert r.returncode == 0, r.stderr
    a = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    assert a["plant.v_x"][0] == 0.5
    # 1 ms at about 0.5 m/s (the speed PI pulls it toward 0.35: slightly less)
    assert 0.49e-3 < a["plant.x"][1] < 0.5e-3

"""An FMU that ends its own run (tests/cfmu/stair.c, after the Reference FMU Stair: a counter
1 .. 10 that ends the simulation at t = 9 s) run by the master and by fmpy 0.3.32's
`simulate_fmu` in both interfaces: the same rows, the same values (Model Exchange: and the
row at the event that ended the run, which fmpy does not write)."""
import subprocess

import numpy as np
import pytest
from fmpy import simulate_fmu

from stiff_reference import build_cfmu


@pytest.fixture(scope="module")
def stair_fmu(tmp_path_factory):
    return build_cfmu("stair", tmp_path_factory.mktemp("stair"))


@pytest.mark.parametrize("interface,fmi_type", [("cs", "CoSimulation"), ("me", "ModelExchange")])
def test_self_ending_fmu_runs_as_fmpy_runs_it(cosim, stair_fmu, tmp_path, interface, fmi_type):
    out = tmp_path / "ours.csv"
    done = subprocess.run([str(cosim), "run", str(stair_fmu), "--interface", interface, "--output", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "model ended the simulation at t = 9 s" in done.stderr, done.stderr
    ours = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    # the master records communication points only, not the instants before and after events
    extra = {"record_events": False} if interface == "me" else {}
    ref = simulate_fmu(str(stair_fmu), fmi_type=fmi_type, output_interval=0.2, **extra)
    # CS: 0 .. 8.8 then the row at fmi2LastSuccessfulTime 9 (fmpy too); ME: 0 .. 8.8 as fmpy
    # without record_events, then ours at the event at 9 that set terminateSimulation, read
    # after its event iteration as in Co-Simulation (fmpy records no row after the event)
    assert len(ref) == (46 if interface == "cs" else 45)
    assert len(ours) == 46, ours["time"][-3:]
    n = len(ref)
    # both compute the points as start + n * 0.2 (fmpy) or t0 + n h (ours): equal to 1 ulp of 10 s
    assert np.max(np.abs(ours["time"][:n] - ref["time"])) <= 2e-15
    assert np.array_equal(ours["counter"][:n], ref["counter"])
    assert (ours["time"][-1], ours["counter"][-1]) == (9.0, 10.0)

"""An FMI 3.0 FMU that nobody on the project wrote: pythonfmu3 0.3.4 (PyPI), an FMI 3.0
exporter with its own C++ FMI 3.0 wrapper and model description writer, builds the model
of its own test suite `pythonfmu3/tests/slaves/pythonslaveMXCS.py` (Dahlquist's test
problem x' = -k x, x(0) = 1, Model Exchange and Co-Simulation; its Co-Simulation step is
explicit Euler, x += -k x h). The master runs that FMU in both interfaces and fmpy 0.3.32
runs it: the same rows.

The FMU's library calls the Python C API without linking libpython: pythonfmu3 expects it to
be loaded into a process that has a Python interpreter (fmpy's). `cosim` is run with this
interpreter's libpython preloaded (`LD_PRELOAD`) and its prefix as `PYTHONHOME`, which is how
a user runs a pythonfmu3 FMU in a tool without Python of its own."""
import os
import subprocess
import sys
import sysconfig
from pathlib import Path

import numpy as np
import pytest
import pythonfmu3  # pinned in scripts/python-env.sh
from fmpy import simulate_fmu


@pytest.fixture(scope="module")
def dahlquist_fmu(tmp_path_factory):
    d = tmp_path_factory.mktemp("pythonfmu3")
    slave = Path(pythonfmu3.__file__).parent / "tests" / "slaves" / "pythonslaveMXCS.py"
    subprocess.run([sys.executable, "-m", "pythonfmu3", "build", "-f", str(slave), "-d", str(d)], check=True,
                   capture_output=True)
    fmu = d / "Dahlquist.fmu"
    assert fmu.is_file(), list(d.iterdir())
    return fmu


def with_python():
    """The environment that gives `cosim` this interpreter (see the module)."""
    libdir = Path(sysconfig.get_config_var("LIBDIR"))
    # the development link, else the runtime library itself (Debian's without python3-dev)
    names = [sysconfig.get_config_var("LDLIBRARY"), sysconfig.get_config_var("INSTSONAME")]
    found = [libdir / n for n in names if n and (libdir / n).is_file() and ".so" in n]
    assert found, f"no shared libpython in {libdir} ({names}): pythonfmu3 FMUs need one"
    lib = found[0]
    env = dict(os.environ, LD_PRELOAD=str(lib), PYTHONHOME=sys.base_prefix)
    env.pop("PYTHONPATH", None)
    return env


@pytest.mark.parametrize("interface,fmi_type", [("cs", "CoSimulation"), ("me", "ModelExchange")])
def test_a_pythonfmu3_fmu_runs_as_fmpy_runs_it(cosim, dahlquist_fmu, tmp_path, interface, fmi_type):
    out = tmp_path / "ours.csv"
    done = subprocess.run([str(cosim), "info", str(dahlquist_fmu)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("model Dahlquist (FMI 3.0)"), done.stdout
    args = [str(cosim), "run", str(dahlquist_fmu), "--interface", interface, "--stop-time", "1", "--step", "0.1",
            "--set", "k=2", "--output", str(out)]
    done = subprocess.run(args, capture_output=True, text=True, env=with_python(), timeout=120)
    assert done.returncode == 0, done.stderr
    ours = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    ref = simulate_fmu(str(dahlquist_fmu), fmi_type=fmi_type, stop_time=1.0, output_interval=0.1,
                       start_values={"k": 2.0}, output=["x"])
    assert len(ours) == len(ref) == 11
    # both compute the grid as start + n h: to 1 ulp of 1 s
    assert np.max(np.abs(ours["time"] - ref["time"])) <= 2.3e-16
    if interface == "cs":
        # the FMU's own Euler steps, from the same inputs: the same doubles
        assert np.array_equal(ours["x"], ref["x"])
        # and Euler's closed form (1 - k h)^n = 0.8^n, to the roundings of n products
        assert np.max(np.abs(ours["x"] - 0.8 ** np.arange(11))) <= 11 * 2.3e-16
    else:
        # against exp(-2 t): our RK4 at steps of at most 0.1 (its factor per step
        # 1 - z + z^2/2 - z^3/6 + z^4/24 at z = 0.2 exceeds exp(-0.2) by 3.1e-6 relative, so
        # after n steps x is off by about n 3.1e-6 exp(-0.2 n), at most 5.6e-6 at n = 5), and
        # fmpy's CVode at its default relative tolerance 1e-4
        exact = np.exp(-2.0 * ours["time"])
        assert np.max(np.abs(ours["x"] - exact)) <= 1e-5
        assert np.max(np.abs(ref["x"] - exact)) <= 1e-3


def test_without_a_python_in_the_process_the_load_error_names_the_missing_symbol(cosim, dahlquist_fmu):
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    done = subprocess.run([str(cosim), "run", str(dahlquist_fmu), "--stop-time", "0.1", "--step", "0.1"],
                          capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 1, done.stderr
    assert "binaries/x86_64-linux/Dahlquist.so: cannot load" in done.stderr, done.stderr
    assert "undefined symbol: _Py" in done.stderr, done.stderr

# The fixtures and helpers are shared with the master's cross-checks: cosim/tests/python
# (fixtures.py, closed_loop_tools.py), put on the import path here.
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[3] / "cosim" / "tests" / "python"))

from fixtures import cosim, plant_fmu, table3  # noqa: E402, F401

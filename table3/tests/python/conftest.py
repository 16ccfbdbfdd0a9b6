# The fixtures and helpers are shared with the master's cross-checks: cosim/tests/python
# (fixtures.py, closed_loop_tools.py), put on the import path here, and the check of the
# figures the docs print (tests/python/doc_figures.py).
import pathlib
import sys

REPO = pathlib.Path(__file__).resolve().parents[3]
sys.path.insert(0, str(REPO / "cosim" / "tests" / "python"))
sys.path.insert(0, str(REPO / "tests" / "python"))

from fixtures import cosim, plant_fmu, table3  # noqa: E402, F401

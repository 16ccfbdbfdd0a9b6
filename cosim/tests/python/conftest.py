# The fixtures are shared with table3/tests/python (see fixtures.py, closed_loop_tools.py).
from fixtures import cosim, plant_fmu, table3  # noqa: F401

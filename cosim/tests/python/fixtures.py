"""The pytest fixtures of both Python test folders (cosim/tests/python and
table3/tests/python): each conftest.py imports them from here."""
import pytest

from closed_loop_tools import release_binary, target_dir


@pytest.fixture(scope="session")
def cosim():
    """Path of the release `cosim` binary (built by `cargo test --release --workspace`)."""
    return release_binary("cosim", "nigel-cosim")


@pytest.fixture(scope="session")
def table3():
    """Path of the release `table3` binary (built by `cargo test --release --workspace`)."""
    return release_binary("table3", "nigel-table3")


@pytest.fixture(scope="session")
def plant_fmu():
    p = target_dir() / "fmu" / "nigel_plant.fmu"
    assert p.exists(), f"{p} missing: run `cargo run --release -p build-fmu`"
    return p

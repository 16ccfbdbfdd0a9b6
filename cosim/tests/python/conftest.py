import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


def target_dir():
    t = os.environ.get("CARGO_TARGET_DIR")
    if t:
        p = pathlib.Path(t)
        return p if p.is_absolute() else REPO / p
    return REPO / "target"


@pytest.fixture(scope="session")
def cosim():
    """Path of the release `cosim` binary (built by `cargo test --release --workspace`)."""
    exe = target_dir() / "release" / "cosim"
    if not exe.exists():
        subprocess.run(["cargo", "build", "--release", "-q", "-p", "nigel-cosim"], cwd=REPO, check=True)
    return exe


@pytest.fixture(scope="session")
def plant_fmu():
    p = target_dir() / "fmu" / "nigel_plant.fmu"
    assert p.exists(), f"{p} missing: run `cargo run --release -p build-fmu`"
    return p

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
def table3():
    """Path of the release `table3` binary (built by `cargo test --release --workspace`)."""
    exe = target_dir() / "release" / "table3"
    if not exe.exists():
        subprocess.run(["cargo", "build", "--release", "-q", "-p", "nigel-table3"], cwd=REPO, check=True)
    return exe

"""scripts/import-cycles.py finds a real circle in a made-up crate and passes the workspace."""

import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "import-cycles.py"


def test_self_test_finds_a_made_up_circle():
    r = subprocess.run([sys.executable, str(SCRIPT), "--self-test"], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "import circle between k/src/a.rs, k/src/n/b.rs, k/src/n/c.rs" in r.stdout


def test_a_circle_fails_the_check(tmp_path):
    src = tmp_path / "c" / "src"
    src.mkdir(parents=True)
    (tmp_path / "Cargo.toml").write_text('[workspace]\nmembers = ["c"]\n')
    (src / "lib.rs").write_text("mod x;\nmod y;\n")
    (src / "x.rs").write_text("use crate::y::Y;\npub struct X;\n")
    (src / "y.rs").write_text("pub struct Y;\nfn f(_: super::x::X) {}\n")
    r = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 1 and "c (lib.rs): import circle between c/src/x.rs, c/src/y.rs" in r.stdout, r.stdout
    (src / "y.rs").write_text("pub struct Y;\n")
    r = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout

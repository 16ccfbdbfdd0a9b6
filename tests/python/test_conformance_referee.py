"""The conformance table's referee (scripts/conformance_referee.py) and the table's verdict
(scripts/conformance_table.py) on small hand-written results: 64-bit integers compared exactly,
the input-file derivation with its event row, the reference's tube, and a miss that no referee
judges right failing the table unless listed in the known file. No FMU runs (the tight fmpy run
is exercised by scripts/conformance.sh on the corpus)."""
import json
import os
import subprocess
import sys

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import conformance_referee as referee  # noqa: E402

pytest.importorskip("fmpy")


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    return str(path)


def test_64_bit_integers_read_and_compared_exactly(tmp_path):
    cosim = write(tmp_path / "c.csv", '"time","u"\n0,0\n1,18446744073709551615\n')
    fmpy = write(tmp_path / "f.csv", "time,u\n0.0,0\n1.0,0\n")
    c, f = referee.read_result(cosim), referee.read_result(fmpy)
    # 2^64 - 1 survives as the integer (a float64 would round it to 2^64)
    assert c[1]["u"][1] == 2**64 - 1
    devs, n = referee.deviations(c, f)
    # fmpy's column is the constant 0: scale max(1, |0|) = 1, so the deviation is the difference
    assert n == 2 and devs["u"] == float(2**64 - 1)
    devs, _ = referee.deviations(c, c)
    assert devs["u"] == 0.0


def feedthrough_case(tmp_path, rows):
    inp = write(tmp_path / "in.csv", "time,Int64_input\n0.0,-9223372036854775808\n1.0,9223372036854775807\n")
    res = write(tmp_path / "r.csv", "time,Int64_output\n" + "".join("%s,%s\n" % r for r in rows))
    case = dict(tool_family="ReferenceFMUs", model="Feedthrough", input=inp)
    return referee.input_derivation(case, referee.read_result(res), ["Int64_output"])["Int64_output"]


def test_input_derivation_of_a_copying_fmu(tmp_path):
    lo, hi = -(2**63), 2**63 - 1
    # the row at the input's time 1 s may hold the value before the event (cosim) or after it
    assert feedthrough_case(tmp_path, [(0, lo), (0.5, lo), (1, lo), (1.5, hi)])[0]
    assert feedthrough_case(tmp_path, [(0, lo), (0.5, lo), (1, hi), (1.5, hi)])[0]
    # fmpy 0.3.32's cast: 2^63 - 1 read as float64 becomes INT64_MIN after the event
    ok, detail = feedthrough_case(tmp_path, [(0, lo), (1, lo), (1, lo), (1.5, lo)])
    assert not ok and "t = 1.5 s" in detail
    # only for a model known to copy its inputs
    case = dict(tool_family="Dymola", model="Feedthrough", input=str(tmp_path / "in.csv"))
    assert referee.input_derivation(case, referee.read_result(str(tmp_path / "r.csv")), ["Int64_output"]) == {}


RAMP = "".join("%g,%g\n" % (k / 10, k / 10) for k in range(11))


def test_reference_tube_judges_the_column_where_cosim_and_fmpy_differ(tmp_path):
    # the reference and cosim: y = t on [0, 1]; fmpy: y = t + 0.5 (half the range off)
    ref = write(tmp_path / "ref.csv", "time,y\n" + RAMP)
    cosim = write(tmp_path / "cosim.csv", "time,y\n" + RAMP)
    fmpy = write(tmp_path / "fmpy.csv", "time,y\n" + "".join("%g,%g\n" % (k / 10, k / 10 + 0.5) for k in range(11)))
    verdict = referee.judge(dict(cosim_csv=cosim, fmpy_csv=fmpy, ref=ref, input=None, tool_family="T", model="M"))
    assert verdict["right"] and verdict["fmpy_wrong"] and verdict["referees"] == ["reference"]
    assert verdict["disputed"] == ["y"]
    # cosim equal to the reference lies inside its tube at every point; fmpy, half the range off,
    # outside at most (far beyond the 10 % that fails the cross-check)
    assert referee.tube_outside(referee.read_result(cosim), referee.read_result(ref), "y") == 0.0
    assert referee.tube_outside(referee.read_result(fmpy), referee.read_result(ref), "y") > 0.5


def table(tmp_path, cosim_rows, known=""):
    """the table over one FMI 3.0 case with a reference (cosim's result given), empty other parts"""
    work, corpus = tmp_path / "work", tmp_path / "corpus"
    for part in ("fmi2", "fmi2-dopri5", "fmi2-bdf", "ssp"):
        write(work / (part + ".json"), "[]")
    write(corpus / "fmi3/me/T/M/M_ref.csv", "time,y\n" + RAMP)
    write(work / "fmi3/me/T/M/cosim.csv", "time,y\n" + cosim_rows)
    write(work / "fmi3/me/T/M/fmpy.csv", "time,y\n" + "".join("%g,%g\n" % (k / 10, 1 - k / 10) for k in range(11)))
    case = dict(case="me/T/M", it="me", tool="T", model="M", start=0, stop=1, step=0.1, input=None, ref="M_ref.csv",
                fmpy_status="ok", cosim_status="ok", verdict="DIFF", cosim_err="", cosim_wall=0.1, fmpy_wall=1.0)
    write(work / "fmi3.json", json.dumps([case]))
    known_file = write(tmp_path / "known.txt", known)
    return subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "conformance_table.py"), str(work), known_file,
                           str(corpus)], capture_output=True, text=True)


def test_table_counts_a_refereed_case_right_and_fails_on_an_unlisted_miss(tmp_path):
    right = table(tmp_path, RAMP)
    assert right.returncode == 0, right.stdout + right.stderr
    assert "fmi3:me/T/M  cosim right by reference; fmpy's default run is the wrong one" in right.stdout
    assert "fmi3             1          1           1           1 of  1          1      0" in right.stdout
    wrong_rows = "".join("%g,%g\n" % (k / 10, 0.5 + k / 20) for k in range(11))
    miss = table(tmp_path / "miss", wrong_rows)
    assert miss.returncode == 1 and "NEW   fmi3:me/T/M" in miss.stdout
    listed = table(tmp_path / "listed", wrong_rows, known="fmi3:me/T/M  the reason\n")
    assert listed.returncode == 0 and "known fmi3:me/T/M" in listed.stdout


def test_tight_run_kept_between_runs_is_read_not_rerun(tmp_path, monkeypatch):
    # no FMU at all: fmpy could not run this case, so a result can only come from the cache
    fmu = write(tmp_path / "M.fmu", "not an FMU")
    case = dict(fmu=fmu, interface="me", start=0.0, stop=1.0, step=0.5, input=None)
    cache = tmp_path / "cache"
    monkeypatch.setenv("NIGEL_CONFORMANCE_REFEREE_CACHE", str(cache))
    result, message = referee.tight_run(case, str(tmp_path / "tight.csv"))
    assert result is None and "failed" in message
    cache.mkdir()
    import gzip
    with gzip.open(cache / (referee.tight_run_key(case) + ".csv.gz"), "wt") as f:
        f.write("time,y\n0.0,1\n0.5,2\n1.0,3\n")
    result, message = referee.tight_run(case, str(tmp_path / "tight.csv"))
    assert message == "kept from an earlier run" and result == ([0.0, 0.5, 1.0], {"y": [1, 2, 3]})
    # another experiment (another step) is another key: not read
    assert referee.tight_run_key(dict(case, step=0.25)) != referee.tight_run_key(case)

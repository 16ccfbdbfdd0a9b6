"""The JUnit files of `cosim run --junit`, `cosim compare --junit` and `campaign run --junit`,
parsed with xml.etree and held to what the JUnit readers of the CI services read: the
Surefire / Ant schemas (`junit-10.xsd` as pytest tests its own `--junitxml` against, Jenkins'
`junit-4.xsd`): `testsuites` of `testsuite`s with the required `name`, `tests`, `failures`,
`errors`, counts that match their cases, `time` in the schema's pattern, `testcase`s with
`name` and `classname` holding only `failure`, `error`, `skipped`, `system-out`,
`system-err`, a `failure` / `error` with its `message` and `type`."""
import re
import subprocess
import xml.etree.ElementTree as ET

from closed_loop_tools import REPO, release_binary, target_dir

# junit-10.xsd's SUREFIRE_TIME
TIME = re.compile(r"^(([0-9]{0,3},)*[0-9]{3}|[0-9]{0,3})*(\.[0-9]{0,3})?$")
CASE_CHILDREN = {"failure", "error", "skipped", "system-out", "system-err"}


def check_junit(path):
    """Parses `path` and checks it against the schemas' rules; returns its cases as
    (classname, name, outcome, message)."""
    root = ET.parse(path).getroot()
    assert root.tag == "testsuites"
    cases = []
    totals = [0, 0, 0]
    for suite in root:
        assert suite.tag == "testsuite"
        for attr in ("name", "tests", "failures", "errors"):
            assert attr in suite.attrib, attr
        assert TIME.match(suite.get("time")), suite.get("time")
        counts = [0, 0, 0]
        for case in suite:
            assert case.tag == "testcase", case.tag
            assert case.get("name") and case.get("classname") is not None
            if "time" in case.attrib:
                assert TIME.match(case.get("time"))
            outcome, message = "passed", None
            for child in case:
                assert child.tag in CASE_CHILDREN, child.tag
                if child.tag in ("failure", "error"):
                    assert child.get("message") and child.get("type") == child.tag
                    assert outcome == "passed", "one failure or error per case"
                    outcome, message = child.tag, child.get("message")
            counts[0] += 1
            counts[1] += outcome == "failure"
            counts[2] += outcome == "error"
            cases.append((case.get("classname"), case.get("name"), outcome, message))
        assert [int(suite.get(a)) for a in ("tests", "failures", "errors")] == counts
        totals = [a + b for a, b in zip(totals, counts)]
    assert [int(root.get(a)) for a in ("tests", "failures", "errors")] == totals
    assert TIME.match(root.get("time"))
    return cases


def closed_loop():
    return target_dir() / "ssp" / "nigel_closed_loop.ssp"


BASELINE = REPO / "cosim" / "tests" / "data" / "closed_loop_30s.csv"
LOOP = ["--stop-time", "30", "--step", "1e-3", "--algorithm", "ordered", "--output-interval", "0.05"]


def test_cosim_run_junit_has_a_case_per_check_and_signal(cosim, tmp_path):
    junit = tmp_path / "junit.xml"
    p = subprocess.run(
        [cosim, "run", closed_loop(), *LOOP, "--set", "plant.m=2.6800001", "--output", tmp_path / "out.csv"]
        + ["--check", "max(abs(plant.y)) < 0.6", "--check", "final(plant.x) > 11"]
        + ["--baseline", BASELINE, "--baseline-rtol", "1e-9", "--baseline-atol", "1e-12", "--junit", junit],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 3, p.stderr
    cases = check_junit(junit)
    assert [(c, n, o) for c, n, o, _ in cases] == [
        ("cosim.run", f"cosim run {closed_loop()}", "passed"),
        ("cosim.check", "max(abs(plant.y)) < 0.6", "passed"),
        ("cosim.check", "final(plant.x) > 11", "failure"),
        ("cosim.baseline", "plant.x", "passed"),
        ("cosim.baseline", "plant.y", "failure"),
        ("cosim.baseline", "plant.psi", "failure"),
        ("cosim.baseline", "plant.speed", "failure"),
        ("cosim.baseline", "plant.yaw_rate", "failure"),
    ]
    # the messages are the lines cosim printed
    assert f"check {cases[2][3].replace(' fails:', ':').replace(' is false', ' FAILS')}" in p.stdout
    for _, name, _, message in cases[4:]:
        assert re.match(r"\d+ of 601 points outside the tube; largest violation [0-9.e-]+ at t = ", message)
        assert f"baseline: {name:<14}  FAIL  {message}" in p.stdout


def test_a_failed_run_is_an_error_case(cosim, tmp_path):
    junit = tmp_path / "junit.xml"
    p = subprocess.run(
        [cosim, "run", closed_loop(), "--stop-time", "1000", "--step", "0.01", "--check", "final(plant.x) > 1"]
        + ["--junit", junit],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 1
    cases = check_junit(junit)
    assert [o for _, _, o, _ in cases] == ["error", "error"]
    # the run's error is what cosim printed
    assert f"cosim: {cases[0][3]}" in p.stderr
    assert cases[1][3] == "not judged: the run failed"


def test_cosim_compare_junit(cosim, tmp_path):
    # a result that lacks a signal and has one off by 1 % at one point
    lines = BASELINE.read_text().splitlines()
    header = lines[0].split(",")
    rows = [[float(v) for v in l.split(",")] for l in lines[1:]]
    b = rows[300][2]
    rows[300][2] *= 1.01
    keep = [0, 1, 2]
    result = tmp_path / "result.csv"
    result.write_text(
        "\n".join([",".join(header[j] for j in keep)] + [",".join(repr(r[j]) for j in keep) for r in rows]) + "\n"
    )
    junit, md = tmp_path / "junit.xml", tmp_path / "summary.md"
    p = subprocess.run(
        [cosim, "compare", result, BASELINE, "--junit", junit, "--summary-md", md], capture_output=True, text=True
    )
    assert p.returncode == 3, p.stderr
    cases = check_junit(junit)
    assert [(n, o) for _, n, o, _ in cases] == [
        ("plant.x", "passed"),
        ("plant.y", "failure"),
        ("plant.psi", "failure"),
        ("plant.speed", "failure"),
        ("plant.yaw_rate", "failure"),
    ]
    t, y = rows[300][0], rows[300][2]
    # the default tolerances: the tube is b +- (1e-6 + 1e-3 |b|) at the same time
    w = 1e-6 + 1e-3 * abs(b)
    assert t == 15.0
    assert cases[1][3].startswith("1 of 601 points outside the tube; largest violation ")
    assert f" at t = 15 s (value {y!r}, tube {b - w!r} .. {b + w!r})" in cases[1][3]
    excess = float(cases[1][3].split("largest violation ")[1].split(" ")[0])
    assert abs(excess - (abs(y - b) - w)) < 1e-15
    assert cases[2][3] == "missing in the result"
    assert "| cosim.baseline plant.psi | **FAIL** | missing in the result |" in md.read_text()


def test_campaign_junit_has_a_case_per_run(tmp_path):
    campaign = release_binary("campaign", "nigel-campaign")
    spec = tmp_path / "c.toml"
    spec.write_text(
        f'system = "{closed_loop()}"\nstop_time = 1.0\nstep = 0.001\n\n'
        '[grid]\n"plant.m" = [2.68, 3.0]\n\n[metrics]\nx_final = "final(plant.x)"\n\n'
        '[checks]\nimpossible = "final(plant.x) > 1000"\n'
    )
    junit = tmp_path / "junit.xml"
    p = subprocess.run(
        [campaign, "run", spec, "--out", tmp_path / "out", "--threads", "1", "--junit", junit],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 3, p.stderr
    cases = check_junit(junit)
    assert [(c, n, o) for c, n, o, _ in cases] == [
        ("campaign.c", "run 0 (plant.m = 2.68)", "failure"),
        ("campaign.c", "run 1 (plant.m = 3)", "failure"),
    ]
    assert all(m.startswith("failed a check: check impossible: final(plant.x) > 1000 fails: ") for *_, m in cases)

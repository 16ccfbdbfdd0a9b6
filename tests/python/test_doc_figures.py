"""Every deterministic figure the docs print is computed here (or in the test that already
computes it, which calls the same `doc_figures.check`) and compared with the doc's text at the
printed precision: a stale figure or a figure whose text was edited away fails, naming the doc.
How a figure is checked and how to update one: "Figures in the docs" in README.md.

The commands are the ones the docs name, on the FMUs and the SSP the test command built
(target/fmu, target/ssp) and the release binaries `cargo test --release --workspace` built:
- the ```python blocks with a `# prints` line are run as they stand and their output compared;
- `cosim run` of the closed-loop SSP, jacobi and ordered (epsilon, final pose);
- `table3 --seed 0` through the FMUs (Table III, the auxiliary metric, gains, steering) and
  `table3 --engine in-process --seed N`, N = 0..9 (the seed study; the in-process engine equals
  the FMU runs to 1e-12 relative, tests/fmu.rs, far below the 3 printed digits);
- `synthesize` (the designs' gamma*, chosen point, norms, gains);
- the committed report of the robustness study (campaign/figures/robustness_report.json: the
  study's 10,080 runs are a recorded run, not repeated here).
"""
import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from doc_figures import REPO, check, check_at_most, python_blocks, require

sys.path.insert(0, str(REPO / "cosim" / "tests" / "python"))
from closed_loop_tools import POSE, epsilon, release_binary, target_dir  # noqa: E402

DOCS = ["README.md", "cosim/README.md", "campaign/README.md", "examples/README.md", "table3/README.md",
        "python/README.md", "docs/vehicle-model.md", "docs/synthesis.md", "docs/benchmark.md", "docs/fmi-notes.md",
        "docs/performance.md", "docs/fmus.md", "docs/platforms.md", "docs/cosim.md", "docs/python.md",
        "docs/table3.md", "docs/reference.md", "docs/testing.md"]

SSP = target_dir() / "ssp" / "nigel_closed_loop.ssp"


# --- python blocks that say what they print -------------------------------------------------

BLOCKS = [(path, line, code, expected) for path in DOCS for line, code, expected in python_blocks(path)]


def test_the_docs_have_python_blocks_that_print():
    # the README's quick start (nigel_cosim, fmpy) and docs/fmus.md's fmpy examples of the three
    # FMUs; a doc edit that drops `# prints` drops a check
    assert sum(1 for b in BLOCKS if b[0] == "README.md") >= 2, BLOCKS
    assert sum(1 for b in BLOCKS if b[0] == "docs/fmus.md") >= 3, BLOCKS


@pytest.mark.parametrize("path,line,code,expected", BLOCKS, ids=[f"{b[0]}:{b[1]}" for b in BLOCKS])
def test_python_block_prints_what_its_comment_says(path, line, code, expected):
    if not (target_dir() / "fmu").is_dir():
        pytest.skip(f"{target_dir() / 'fmu'} is absent: the blocks run on what `bash scripts/run.sh` builds")
    code = code.replace('"target/', f'"{target_dir()}/')
    r = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"{path}:{line}: the block fails:\n{r.stderr}"
    got = " ".join(r.stdout.split())
    assert got == " ".join(expected.split()), \
        f"{path}:{line}: the block prints {got!r}, its comment says {expected!r}"



# --- the README's shell blocks, as printed ----------------------------------------------------

def shell_blocks(path):
    """The fenced ```sh blocks of a doc, as (line number, text)."""
    text = (REPO / path).read_text()
    return [(text[: m.start()].count("\n") + 1, m.group(1))
            for m in re.finditer(r"^```sh\n(.*?)^```", text, re.S | re.M)]


def test_readme_shell_blocks_run_as_printed(tmp_path):
    """Every ```sh block of README.md runs as printed, in order, from a folder that holds what
    the main command made (`target`, linked to this build's) and the repository's `examples`
    and `scripts`: the two commands themselves are what the test command is (not rerun here),
    and the block that installs the wheel into a venv of one's own is what
    scripts/test-python-package.sh runs (it reads it from README.md: a network install)."""
    if not (target_dir() / "fmu").is_dir():
        pytest.skip(f"{target_dir() / 'fmu'} is absent: the blocks run on what `bash scripts/run.sh` builds")
    blocks = shell_blocks("README.md")
    for name in ("target", "examples", "scripts", "campaigns"):
        (tmp_path / name).symlink_to(target_dir() if name == "target" else REPO / name)
    env = dict(os.environ)
    ran = []
    for line, block in blocks:
        if "bash scripts/run.sh" in block:
            assert "bash scripts/test.sh" in block, f"README.md:{line}"
            continue
        if "pip install" in block:
            package_test = (REPO / "scripts" / "test-python-package.sh").read_text()
            assert "readme-install" in package_test, "scripts/test-python-package.sh no longer runs README.md's install block"
            continue
        if block.strip().startswith("export PATH="):
            # `$PWD/target/release`: the main command's programs, from the folder the blocks run in
            env["PATH"] = f"{tmp_path / 'target' / 'release'}:{env['PATH']}"
            ran.append(line)
            continue
        r = subprocess.run(["bash", "-euo", "pipefail", "-c", block], cwd=tmp_path, env=env,
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, f"README.md:{line}: the block fails:\n{block}\n{r.stderr}"
        ran.append(line)
    assert len(ran) >= 2, blocks  # the PATH line and the command-line quick start
    # the quick start's run wrote every output of the 30 s at 1 ms
    rows = np.genfromtxt(tmp_path / "target" / "closed_loop.csv", delimiter=",", names=True)
    assert len(rows) == 30001 and rows["time"][-1] == pytest.approx(30.0)


def test_along_track_pole():
    """The along-track loop's dominant pole (README, controller FMU): the root of
    s^3 + (kp/m) s^2 + (ki/m + k kp/m) s + k ki/m nearest the origin (benchmark/src/control.rs;
    benchmark/tests/along_track.rs checks the simulated decay against it)."""
    from fmpy import read_model_description
    start = lambda fmu: {v.name: v.start for v in read_model_description(str(target_dir() / "fmu" / fmu)).modelVariables}  # noqa: E731
    ctl, plant = start("nigel_controller.fmu"), start("nigel_plant.fmu")
    kp, ki, k = (float(ctl[n]) for n in ("kp_speed", "ki_speed", "k_along_track"))
    m = float(plant["m"])
    for name, value in (("kp_speed", kp), ("ki_speed", ki), ("k_along_track", k)):
        check("docs/fmus.md", f"`{name}` {{}}", value)
    poles = np.roots([1, kp / m, ki / m + k * kp / m, k * ki / m])
    dominant = max(poles, key=lambda p: p.real)
    assert abs(dominant.imag) < 1e-9, poles  # real: no overshoot
    check("docs/fmus.md", "time constant (dominant pole {} /s)", dominant.real)
    check("docs/fmus.md", "follows `-0.1 e^({} t)`", dominant.real)


# --- the closed-loop SSP in the master ------------------------------------------------------

@pytest.fixture(scope="module")
def closed_loop(tmp_path_factory):
    """epsilon and the final pose of `cosim run` of the closed-loop SSP, 30 s at 1 ms."""
    assert SSP.exists(), f"{SSP} missing: run `cargo run --release -p build-fmu`"
    cosim = release_binary("cosim", "nigel-cosim")
    d = tmp_path_factory.mktemp("closed_loop")
    out = {}
    for alg in ("jacobi", "ordered"):
        csv = d / f"{alg}.csv"
        cmd = [str(cosim), "run", str(SSP), "--stop-time", "30", "--step", "1e-3", "--algorithm", alg,
               "--output", str(csv)]
        for name in POSE:
            cmd += ["--record", name]
        subprocess.run(cmd, check=True, capture_output=True)
        rows = np.genfromtxt(csv, delimiter=",", names=True)
        names = {n: n.replace(".", "") for n in POSE} if "plantx" in rows.dtype.names else {n: n for n in POSE}
        series = {n: rows[names[n]][1:] for n in POSE}  # t_1 .. t_N, as Table III's metric
        out[alg] = (epsilon(series), [float(series[n][-1]) for n in POSE[:3]])
    return out


def test_closed_loop_figures(closed_loop):
    eps_j, (x_j, y_j, psi_j) = closed_loop["jacobi"]
    eps_o, (x_o, y_o, psi_o) = closed_loop["ordered"]
    check("docs/cosim.md", "ecos and libcosim compute our `jacobi` run to every printed digit (epsilon {},", eps_j)
    check("cosim/README.md", "| **master `ordered`, recording nothing** |{*}| {} | {}, {}, {} |",
          eps_o, x_o, y_o, psi_o)
    check("cosim/README.md", "| **master `jacobi`, recording nothing** |{*}| {} | {}, {}, {} |",
          eps_j, x_j, y_j, psi_j)
    check("docs/table3.md", "| our `ordered` | {} |", eps_o)
    check("docs/table3.md", "| our `jacobi` | {} | | {} % |", eps_j, 100 * (eps_o - eps_j) / eps_o)
    check("docs/fmi-notes.md", "On the benchmark the difference is about {} % in epsilon", 100 * (eps_o - eps_j) / eps_o)
    # the README's "Which algorithm" (the quick start's Python block prints jacobi's itself)
    check("README.md", "On this loop the two differ by {} % in epsilon: jacobi {}, ordered {}",
          100 * (eps_o - eps_j) / eps_o, eps_j, eps_o)


def run_epsilon(ssp, csv, *sets):
    """epsilon of `cosim run SSP` (ordered, 30 s at 1 ms, as Table III) with `--set`s."""
    cmd = [str(release_binary("cosim", "nigel-cosim")), "run", str(ssp), "--stop-time", "30", "--step", "1e-3",
           "--algorithm", "ordered", "--output", str(csv)]
    for name in POSE:
        cmd += ["--record", name]
    for x in sets:
        cmd += ["--set", x]
    subprocess.run(cmd, check=True, capture_output=True)
    rows = np.genfromtxt(csv, delimiter=",", names=True)
    return epsilon({n: rows[n.replace(".", "")][1:] for n in POSE})


def test_real_straight_without_the_measurement_noise(table3_seed0, tmp_path):
    """README: what is left of the tracking error on real straight is not the noise."""
    _, t = table3_seed0
    table3 = str(release_binary("table3", "nigel-table3"))
    eps = {}
    for c in ("robust_tracking", "robust"):
        ssp = tmp_path / f"{c}.ssp"
        subprocess.run([table3, "--ssp", str(ssp), "--ssp-job", f"real/straight/{c}"], check=True, capture_output=True)
        noisy = run_epsilon(ssp, tmp_path / f"{c}.csv")
        # the exported job is the table's cell (same FMUs, same master, same steps)
        assert noisy == pytest.approx(t["results"]["real"]["straight"][c]["eps"], rel=1e-12)
        eps[c] = (noisy, run_epsilon(ssp, tmp_path / f"{c}_quiet.csv", "maneuver.measurement_noise=false"))
    check("docs/table3.md", "changes the tracking epsilon of real straight from {} to {})", *eps["robust_tracking"])
    check("docs/table3.md", "(real straight {}, {} without the noise)", *eps["robust"])


# --- Table III, seed 0, through the FMUs ----------------------------------------------------

@pytest.fixture(scope="module")
def table3_seed0(tmp_path_factory):
    d = tmp_path_factory.mktemp("table3")
    r = subprocess.run([str(release_binary("table3", "nigel-table3")), "--seed", "0", "--quiet",
                        "--json", str(d / "t.json")], check=True, capture_output=True, text=True)
    return r.stdout, json.loads((d / "t.json").read_text())


def rows_of(markdown, column):
    """The rows of the markdown table whose header starts `| column |`."""
    lines = markdown.splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith(f"| {column} | "))
    return [l for l in lines[start + 2:] if l.startswith("| ")][: 6]


def test_table3_seed0(table3_seed0):
    markdown, t = table3_seed0
    # the two tables, as `table3 --seed 0` prints them (the paper's columns included)
    for column in ("sim", "real"):
        header = next(l for l in markdown.splitlines() if l.startswith(f"| {column} | "))
        require("docs/table3.md", header)
        for row in rows_of(markdown, column):
            require("docs/table3.md", row)
    # the committed JSON is this run's (the wall time aside)
    committed = json.loads((REPO / "table3" / "figures" / "table3_seed0.json").read_text())
    assert committed["gains"] == t["gains"], "table3/figures/table3_seed0.json: gains are stale"
    for f, maneuvers in t["results"].items():
        for m, cells in maneuvers.items():
            for c, cell in cells.items():
                old = committed["results"][f][m][c]
                # same FMUs and binary: bit-identical on one machine; 1e-12 for another libm
                assert old["eps"] == pytest.approx(cell["eps"], rel=1e-12), \
                    f"table3/figures/table3_seed0.json: {f} {m} {c} eps {old['eps']} is stale ({cell['eps']})"

    R = t["results"]
    eps = lambda f, m, c: R[f][m][c]["eps"]  # noqa: E731
    aux = lambda f, m, c: R[f][m][c]["eps_state"]  # noqa: E731
    check("docs/table3.md", "e.g. sim skidpad {} robust, {} robust tracking, {} open-loop, {} non-robust; "
          "sim straight {} / {} / {} / {})",
          *(aux("sim", "skidpad", c) for c in ("robust", "robust_tracking", "open_loop", "pole_placement")),
          *(aux("sim", "straight", c) for c in ("robust", "robust_tracking", "open_loop", "pole_placement")))
    g = t["gains"]
    check("docs/table3.md", "Gains (from the controller FMU; the synthesis' baked values): robust "
          "`[[{}, {}], [{}, {}], [{}, {}], [{}, {}]]`", *np.ravel(g["robust"]))
    check("docs/table3.md", "placement (`Re(s) < -2` at mu = 0.4) `[[{}, {}], [{}, {}], [{}, {}], [{}, {}]]`",
          *np.ravel(g["pole_placement"]))
    check("docs/table3.md", "(columns e_y, e_psi, beta, yaw_rate) `[[{}, {}, {}, {}]` (FL = FR), `[{}, {}, {}, {}]]` (RL = RR)",
          *g["robust_tracking"][0], *g["robust_tracking"][2])
    # the largest steering command of each controller in seed 0
    md = {c: max(R[f][m][c]["max_delta"] for f in R for m in R[f]) for c in R["sim"]["straight"]}
    check("docs/table3.md", "in seed 0 its largest command is {} rad, against {} for robust, {} for non-robust and {} for the program alone",
          md["robust_tracking"], md["robust"], md["pole_placement"], md["open_loop"])
    rows = [(f, m) for f in R for m in R[f]]
    ratios = [aux(f, m, "robust_tracking") / aux(f, m, "robust") for f, m in rows]
    check("docs/table3.md", "its `||(RMSE_beta, RMSE_r)||` is {}-{}x the robust controller's in every row of seed 0",
          min(ratios), max(ratios))
    check("docs/table3.md", "epsilon (sim / real) is {} / {} on straight (robust {} / {}), {} / {} on skidpad ({} / {}), "
          "{} / {} on figure-8 ({} / {})",
          *(v for m in ("straight", "skidpad", "figure_8")
            for v in (eps("sim", m, "robust_tracking"), eps("real", m, "robust_tracking"),
                      eps("sim", m, "robust"), eps("real", m, "robust"))))
    # among the paper's three controllers: open loop lowest on sim straight, robust elsewhere
    three = ("open_loop", "pole_placement", "robust")
    lowest = {(f, m): min(three, key=lambda c: eps(f, m, c)) for f, m in rows}
    assert [k for k, c in lowest.items() if c != "robust"] == [("sim", "straight")], lowest
    assert lowest[("sim", "straight")] == "open_loop"
    check("docs/table3.md", "**Straight, sim column**: open-loop ({}) beats robust ({}, {}x)",
          eps("sim", "straight", "open_loop"), eps("sim", "straight", "robust"),
          eps("sim", "straight", "robust") / eps("sim", "straight", "open_loop"))
    check("docs/table3.md", "seed 0 robust is marginally lower ({} vs {})",
          eps("real", "straight", "robust"), eps("real", "straight", "open_loop"))
    pp = [eps(f, m, "pole_placement") / eps(f, m, "open_loop") for f, m in rows]
    assert min(pp) > 1, "the non-robust baseline is the worst controller in every row"
    check("docs/table3.md", "({}x to {}x the open-loop epsilon)", min(pp), max(pp))
    rings = [eps("sim", m, "open_loop") / eps("sim", m, "robust") for m in ("skidpad", "fishhook", "slalom", "figure_8")]
    check("docs/table3.md", "(epsilon {}-{}x lower than open-loop in sim on skidpad, fishhook, slalom, figure-8)",
          min(rings), max(rings))
    check("docs/table3.md", "it is for slalom ({} against {} open-loop)",
          abs(eps("real", "slalom", "robust") - eps("sim", "slalom", "robust")),
          abs(eps("real", "slalom", "open_loop") - eps("sim", "slalom", "open_loop")))
    rmse = R["real"]["straight"]["robust_tracking"]["rmse"]
    check("docs/table3.md", "RMSE_psi {} rad against RMSE_Y {} mm", rmse[2], 1e3 * rmse[1])
    # the same cells quoted by the fmpy loop's test and the examples
    check("docs/fmus.md", "give Table III's epsilon (sim lane-change {}, real fishhook {}, robust) to 1e-5",
          eps("sim", "lane_change", "robust"), eps("real", "fishhook", "robust"))
    check("examples/README.md", "where ours scores {} (robust) and {} (open loop)",
          eps("sim", "lane_change", "robust"), eps("sim", "lane_change", "open_loop"))
    # the paper's columns, read from the rows above (which equal the CLI's)
    header = next(l for l in markdown.splitlines() if l.startswith("| sim | "))
    assert [c.strip() for c in header.strip("|").split("|")][8] == "paper robust", header
    paper = {}
    for column in ("sim", "real"):
        for row in rows_of(markdown, column):
            cells = [c.strip() for c in row.strip("|").split("|")]
            paper[(column, cells[0])] = float(cells[8])  # paper robust (after ours, 4, and "lowest")
    # docs/benchmark.md's copy of the paper's table equals table3's (table3/src/paper.rs)
    for m in R["sim"]:
        cols = {}
        for column in ("sim", "real"):
            row = next(r for r in rows_of(markdown, column) if r.startswith(f"| {m} | "))
            cols[column] = [c.strip() for c in row.strip("|").split("|")][6:9]
        name = m.replace("_", "-")
        check("docs/benchmark.md", f"| {name} | {{}} / {{}} | {{}} / {{}} | {{}} / {{}} |",
              *(float(cols[c][i]) for i in range(3) for c in ("sim", "real")))
    check("docs/benchmark.md", "slightly lower in sim (robust about {}x)",
          eps("sim", "straight", "robust") / eps("sim", "straight", "open_loop"))
    mag = {k: eps(*k, "robust") / v for k, v in paper.items()}
    others = [v for (f, m), v in mag.items() if m != "straight"]
    sim_ratio = [eps("sim", m, "open_loop") / eps("sim", m, "robust") for m in R["sim"] if m != "straight"]
    check("docs/table3.md", "our robust epsilon is close to the paper's on straight ({}x / {}x) but {}-{}x the paper's on the "
          "other rows, and the robust/open-loop ratio is smaller ({}-{}x in sim",
          mag[("sim", "straight")], mag[("real", "straight")], min(others), max(others), min(sim_ratio), max(sim_ratio))


# --- the seed study, seeds 0..9 -------------------------------------------------------------

@pytest.fixture(scope="module")
def seeds(tmp_path_factory):
    d = tmp_path_factory.mktemp("seeds")
    exe = str(release_binary("table3", "nigel-table3"))
    out = []
    for seed in range(10):
        subprocess.run([exe, "--engine", "in-process", "--seed", str(seed), "--quiet", "--json", str(d / f"{seed}.json")],
                       check=True, capture_output=True)
        out.append(json.loads((d / f"{seed}.json").read_text())["results"])
    return out


def test_seed_study(seeds):
    eps = lambda r, f, m, c: r[f][m][c]["eps"]  # noqa: E731
    maneuvers = list(seeds[0]["sim"])
    controllers = list(seeds[0]["sim"]["straight"])
    for r in seeds:
        for f in r:
            for m in maneuvers:
                assert min(controllers, key=lambda c: eps(r, f, m, c)) == "robust_tracking", (f, m)
    ratio = {(f, m): [eps(r, f, m, "robust_tracking") / eps(r, f, m, "robust") for r in seeds]
             for f in ("sim", "real") for m in maneuvers}
    for m in maneuvers:
        s, q = ratio[("sim", m)], ratio[("real", m)]
        check("docs/table3.md", f"| {m} | {{}} ({{}}) | {{}} ({{}}) |", max(s), np.mean(s), max(q), np.mean(q))
    every = [x for v in ratio.values() for x in v]
    check("docs/synthesis.md", "over seeds 0..9 its epsilon is {} to {} times the paper's robust controller's", min(every), max(every))
    worst = lambda m: max(max(ratio[("sim", m)]), max(ratio[("real", m)]))  # noqa: E731
    check("docs/table3.md", "so at least {}x lower in every cell, {}x on straight, {}x on skidpad and {}x on figure-8",
          1 / max(every), 1 / worst("straight"), 1 / worst("skidpad"), 1 / worst("figure_8"))
    md = {c: max(r[f][m][c]["max_delta"] for r in seeds for f in r for m in maneuvers) for c in controllers}
    check("docs/table3.md", "The largest steering command over all 480 runs is {} rad for robust tracking ({} non-robust, "
          "{} robust, {} open loop), {} % of `delta_max = pi/2`",
          md["robust_tracking"], md["pole_placement"], md["robust"], md["open_loop"],
          100 * md["robust_tracking"] / (np.pi / 2))
    check("docs/table3.md", "over seeds 0..9, below, {} and {})", md["robust_tracking"], md["robust"])
    # straight: open loop against robust over the seeds, per column
    for f, template in (("sim", "open-loop is lowest on straight in all {} seeds in sim (robust {}-{}x)"),
                        ("real", "and in {} of 10 in real (robust {}-{}x)")):
        rr = [eps(r, f, "straight", "robust") / eps(r, f, "straight", "open_loop") for r in seeds]
        lowest = sum(1 for r in seeds
                     if min(("open_loop", "pole_placement", "robust"), key=lambda c: eps(r, f, "straight", c)) == "open_loop")
        check("docs/table3.md", template, lowest, min(rr), max(rr))
    for r in seeds:
        for f in r:
            for m in maneuvers:
                if m != "straight":
                    assert min(("open_loop", "pole_placement", "robust"), key=lambda c: eps(r, f, m, c)) == "robust"


# --- the robustness study: the committed report ---------------------------------------------

def test_robustness_study_tables_are_its_report():
    """The study is a recorded run (campaign/README.md says when and how); its report is
    committed. The tables and the headline numbers must be the report's."""
    rep = json.loads((REPO / "campaign" / "figures" / "robustness_report.json").read_text())
    assert rep["runs"] == 10_080
    check("campaign/README.md", "One run of it, 1 Dec 2026, 2 threads beside a CI run on this 2-core machine: {} runs,",
          rep["runs"])
    eps = {g["group"]["controller"]: g["metrics"]["epsilon"] for g in rep["groups"]}
    for c, e in eps.items():
        check("campaign/README.md", f"| {c} | {{}} | {{}} | {{}} | {{}} | {{}} |",
              e["count"], e["mean"], e["median"], e["p95"], e["worst"])
    pairs = {(p["a"], p["b"]): p for p in rep["pairs"] if p["group"] == "all"}
    for (a, b), p in pairs.items():
        check("campaign/README.md", f"| {a} vs {b} | {{}} | {{}} | {{}} | {{}} |",
              p["pairs"], p["p_less"], p["p_more"], p["median_ratio"])
    ol_r, r_rt, pp_r = pairs[("open_loop", "robust")], pairs[("robust", "robust_tracking")], pairs[("pole_placement", "robust")]
    check("campaign/README.md", "**P(robust < open loop) = {}** over all {} pairs (robust's epsilon at the median {} of "
          "the open loop's); **P(robust_tracking < robust) = {}** (median {}x lower);",
          ol_r["p_more"], ol_r["pairs"], 1 / ol_r["median_ratio"], r_rt["p_more"], r_rt["median_ratio"])
    check("campaign/README.md", "the non-robust pole placement loses to the open loop in {} % of the pairs",
          100 * pairs[("open_loop", "pole_placement")]["p_less"])
    check("docs/reference.md", "noise seed = {} runs, 0 failed): on the same draws P(robust < open loop) = {}, "
          "P(robust tracking < robust) = {}, P(robust < pole placement) = {}; median epsilon open loop {}, "
          "pole placement {}, robust {}, robust tracking {};",
          rep["runs"], ol_r["p_more"], r_rt["p_more"], pp_r["p_more"], eps["open_loop"]["median"],
          eps["pole_placement"]["median"], eps["robust"]["median"], eps["robust_tracking"]["median"])
    worst = {w["run"]: w for w in rep["worst"]}
    pp, rt = worst[3889], worst[4860]  # the worst pole placement and robust tracking runs
    assert pp["metrics"]["epsilon"] == eps["pole_placement"]["worst"]
    assert rt["metrics"]["epsilon"] == eps["robust_tracking"]["worst"]
    v = pp["values"]
    check("campaign/README.md", "(run {}, skidpad `sim`, {} m/s, {} kg, {} N/rad, friction mean {}: epsilon {},",
          pp["run"], v["speed"], v["plant.m"], v["c_tire"], v["maneuver.friction_mean"], pp["metrics"]["epsilon"])
    check("docs/reference.md", "(epsilon {} at {} m/s,", pp["metrics"]["epsilon"], v["speed"])
    v = rt["values"]
    check("campaign/README.md", "Its worst run (run {}, skidpad `real`, {} m/s, friction mean {}) saturates the steering "
          "at 90 deg (`max_delta` {}):", rt["run"], v["speed"], v["maneuver.friction_mean"], rt["metrics"]["max_delta"])
    check("campaign/README.md", "the car leaves the circle (epsilon {})", rt["metrics"]["epsilon"])
    assert pp["values"]["maneuver.maneuver"] == rt["values"]["maneuver.maneuver"] == 3  # skidpad
    assert (pp["values"]["column"], rt["values"]["column"]) == (0, 1)  # sim, real


# --- the robust synthesis -------------------------------------------------------------------

@pytest.fixture(scope="module")
def designs(tmp_path_factory):
    d = tmp_path_factory.mktemp("synthesis")
    exe = str(release_binary("synthesize", "nigel-synthesis"))
    out = {}
    for name, args in {"4ws": ["--arch", "4ws", "--d2", "paper"], "ackermann": ["--arch", "ackermann", "--d2", "paper"],
                       "physical": ["--arch", "4ws", "--d2", "physical"], "tracking": ["--model", "tracking"],
                       "paper_point": ["--objective", "h2", "--hinf-bound", "0.198"]}.items():
        subprocess.run([exe, *args, "--json", str(d / f"{name}.json")], check=True, capture_output=True)
        out[name] = json.loads((d / f"{name}.json").read_text())
    return out


def test_synthesis_figures(designs):
    p, a, ph, t = designs["4ws"], designs["ackermann"], designs["physical"], designs["tracking"]
    nu_paper = designs["paper_point"]["chosen"]["nu"]
    ch = lambda d: (d["chosen"]["k"], d["chosen"]["g"], d["chosen"]["nu"])  # noqa: E731
    norms = lambda d: (d["actual"]["hinf_worst"], d["actual"]["h2_worst"])  # noqa: E731
    check("docs/synthesis.md", "| paper, 4WD4WS | {} (MATLAB 0.1175) | {}, ({}, {}); the paper's (0.198, 0.556): ν(0.198) = {} | {} / {} |",
          p["gamma_star"], *ch(p), nu_paper, *norms(p))
    check("docs/synthesis.md", "| paper, Ackermann | {} | {}, ({}, {}) (paper 0.2606, 0.6449) | {} / {} |",
          a["gamma_star"], *ch(a), *norms(a))
    check("docs/synthesis.md", "| physical, 4WD4WS | {} | {}, ({}, {}) | |", ph["gamma_star"], *ch(ph))
    check("docs/synthesis.md", "rows FL, FR, RL, RR): `[{}, {}], [{}, {}], [{}, {}], [{}, {}]`.", *np.ravel(p["K"]))
    check_at_most("docs/synthesis.md", "the H∞ norm by Hamiltonian bisection and by a frequency sweep (agree to {})",
                  max(d["actual"]["hinf_methods_rel_diff"] for d in (p, a, ph)))
    # rounding-limited on both sides (the Gramian's doubling adds one product's rounding per
    # squaring, scaled by the closed loop's conditioning): 5.3e-13 to 1.4e-12 seen across
    # machines and OpenBLAS kernels, so the README prints a bound with room above them
    check_at_most("docs/synthesis.md", "the H2 norm by a Lyapunov equation and by Gramian integration (agree to {}:",
                  max(d["actual"]["h2_methods_rel_diff"] for d in (p, a, ph)), room=100)
    for name, d in (("`paper`, 4WD4WS | (0.198, 0.556)", p), ("`paper`, Ackermann | (0.261, 0.645)", a),
                    ("`physical`, 4WD4WS | ", ph)):
        check("docs/synthesis.md", f"| {name} | {{}}, k = {{}}, ({{}}, {{}}) |", d["gamma_star"], *ch(d))
    check("docs/synthesis.md", "Our `nu(0.198) = {}`", nu_paper)
    w = t["study"]["wind_step"]
    check("docs/synthesis.md", "| {} | {}, ({}, {}) | {} / {} | {} ({} with the 0.03 s servo) | e_y {} mm, steering rate {} rad/s |",
          t["gamma_star"], *ch(t), *norms(t), t["verification"]["max_real_part"], t["study"]["servo_loop_max_real_part"],
          1e3 * w["lateral_peak"], w["steering_rate_peak"])
    check("docs/synthesis.md", "angles positive to the left): `[{}, {}, {}, {}]` (FL = FR), `[{}, {}, {}, {}]` (RL = RR).",
          *t["K"][0], *t["K"][2])
    assert t["K"][0] == t["K"][1] and t["K"][2] == t["K"][3]


# --- stiff Model Exchange: cosim's bdf and fmpy's CVode against independent references --------

def test_stiff_work_precision_errors(tmp_path):
    """README.md's table of `cosim/benches/stiff.py`: the errors (deterministic) of each run
    against the references of cosim/tests/python/stiff_reference.py (Radau on van der Pol's
    equations and over the plant's right-hand side, the ball's closed form); the times are
    measurements (`{*}`). A CVode run that ends with mxstep prints "mxstep" in place of its
    error."""
    from stiff_reference import CASES, case_fmus, case_reference, relative_error, run_cosim, run_cvode

    fmus = case_fmus(tmp_path, target_dir() / "fmu" / "nigel_plant.fmu")
    cosim = release_binary("cosim", "nigel-cosim")
    names = {"van der Pol mu = 1e+03": "van der Pol, mu = 1e3", "van der Pol mu = 1e+04": "van der Pol, mu = 1e4",
             "van der Pol mu = 1e+05": "van der Pol, mu = 1e5", "plant (ME)": "plant (ME)",
             "bouncing ball": "bouncing ball"}
    for case in CASES:
        ref = case_reference(case, fmus)
        for rtol, printed in ((1e-4, "1e-4"), (1e-6, "1e-6"), (1e-8, "1e-8")):
            _, x, err = run_cosim(cosim, fmus[case[1]], case, rtol, tmp_path / "out.csv")
            assert err is None, err
            _, y, cv_err = run_cvode(fmus[case[1]], case, rtol)
            row = f"| {names[case[0]]} | {printed} | {{}} | {{*}} |"
            if cv_err is None:
                check("docs/cosim.md", row + " {} | {*} |", relative_error(x, ref), relative_error(y, ref))
            else:
                assert "code -1)" in cv_err, cv_err  # CV_TOO_MUCH_WORK: mxstep steps before an output
                check("docs/cosim.md", row + " mxstep | {*} |", relative_error(x, ref))
def test_stiff_transition_shifts(tmp_path):
    """The shifts of van der Pol's first transition (deterministic) in the tables of
    docs/performance.md ("The phase of van der Pol at loose tolerances", printed by
    `cosim/benches/stiff.py`) and README.md, both tools, against Radau's transition time."""
    from stiff_reference import build_cfmu, transition_errors, vdp_transition_reference

    fmu = build_cfmu("vdp", tmp_path)
    cosim = release_binary("cosim", "nigel-cosim")
    for mu, mu_text in ((1e3, "1e3"), (1e4, "1e4"), (1e5, "1e5")):
        ref = vdp_transition_reference(mu)
        for rtol, rtol_text in ((1e-3, "1e-03"), (1e-4, "1e-04"), (1e-5, "1e-05")):
            (bdf, _), (cvode, _) = transition_errors(cosim, fmu, mu, rtol, tmp_path)
            check("docs/performance.md", f"| {mu:.0e} | {{}} | {rtol_text} | {{}} | {{}} | {{*}} | {{}} | {{}} | {{*}} |",
                  ref, bdf, abs(bdf) / rtol, cvode, abs(cvode) / rtol)
            if rtol < 1e-3:
                check("docs/cosim.md", f"| {mu_text} | {rtol:.0e}".replace("e-0", "e-") + " | {} | {} |", bdf, cvode)


# --- the AddressSanitizer step of scripts/test.sh -------------------------------------------

def test_readme_prints_the_random_sequences_the_asan_step_runs():
    """README.md's "first 3,000 and 1,500 sequences" are the NIGEL_RANDOM_SEQUENCES and
    NIGEL_RANDOM_SEQUENCES3 of scripts/test.sh's ASan step."""
    script = (REPO / "scripts" / "test.sh").read_text()
    fmi2 = int(re.search(r"NIGEL_RANDOM_SEQUENCES=(\d+)", script).group(1))
    fmi3 = int(re.search(r"NIGEL_RANDOM_SEQUENCES3=(\d+)", script).group(1))
    check("docs/testing.md", "first {} and {} sequences per FMU and interface", fmi2, fmi3)

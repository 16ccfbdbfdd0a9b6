"""`table3 --csv` files are fmpy result files: `fmpy.util.read_csv` reads them (quoted names,
"time" first, no empty field), fmpy's plotting (plotly) draws them, and matplotlib's Agg
backend writes a PNG of them. The epsilon recomputed here from the CSV's pose columns equals
the JSON's."""
import json
import subprocess

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import plotly.graph_objects  # noqa: E402
from fmpy.util import create_plotly_figure, plot_result, read_csv  # noqa: E402

COLUMNS = ["time", "x", "y", "psi", "x_ref", "y_ref", "psi_ref", "beta", "yaw_rate", "beta_ref", "yaw_rate_ref",
           "delta_fl", "delta_fr", "delta_rl", "delta_rr", "mu_fl", "mu_fr", "mu_rl", "mu_rr"]


@pytest.fixture(scope="module")
def run(table3, tmp_path_factory):
    d = tmp_path_factory.mktemp("csv")
    subprocess.run([str(table3), "--quiet", "--engine", "in-process", "--maneuver", "lane_change",
                    "--controller", "robust", "--json", str(d / "t.json"), "--csv", str(d)],
                   check=True, capture_output=True)
    cell = json.loads((d / "t.json").read_text())["results"]["sim"]["lane_change"]["robust"]
    return d, read_csv(str(d / "sim_lane_change_robust.csv")), cell


def test_read_csv_reads_every_column_and_sample(run):
    _, r, _ = run
    assert list(r.dtype.names) == COLUMNS
    assert len(r) == 30_001
    # time is k * 1 ms (written as the shortest decimal of k * 1e-3)
    assert np.array_equal(r["time"], np.arange(30_001) * 1e-3)
    for name in COLUMNS:
        assert np.all(np.isfinite(r[name])), name
    # the last row carries the command held up to the stop time (that of the row before)
    for name in ("delta_fl", "delta_rr", "mu_fl", "mu_rr"):
        assert r[name][-1] == r[name][-2], name


def test_epsilon_from_the_csv_equals_the_json(run):
    _, r, cell = run
    # the metric over t = 1 ms .. 30 s (docs/benchmark.md), from the CSV's shortest-decimal
    # numbers, which round-trip every double exactly: the same sums as table3's to the last
    # few ulp of 30,000 terms, so 1e-12 relative holds on any machine
    k = slice(1, None)
    rmse = [np.sqrt(np.mean((r[a][k] - r[b][k]) ** 2)) for a, b in (("x", "x_ref"), ("y", "y_ref"), ("psi", "psi_ref"))]
    eps = float(np.linalg.norm(rmse))
    assert abs(eps - cell["eps"]) <= 1e-12 * cell["eps"], (eps, cell["eps"])


def test_fmpy_plot_result_draws_it(run, tmp_path, monkeypatch):
    _, r, _ = run
    # plot_result ends in plotly's Figure.show (a browser); keep the figure it shows instead
    shown = []
    monkeypatch.setattr(plotly.graph_objects.Figure, "show", lambda fig, *a, **k: shown.append(fig))
    plot_result(r, names=["x", "y", "delta_fl", "mu_fl"])
    (fig,) = shown
    traces = {t.name: t for t in fig.data}
    assert set(traces) == {"x", "y", "delta_fl", "mu_fl"}
    assert np.array_equal(np.asarray(traces["y"].y), r["y"])
    # the figure object also writes HTML without kaleido
    html = tmp_path / "lane_change.html"
    create_plotly_figure(r, names=["x", "y"]).write_html(str(html))
    assert html.stat().st_size > 10_000


def test_matplotlib_agg_writes_a_png(run, tmp_path):
    _, r, _ = run
    png = tmp_path / "lane_change.png"
    fig, ax = plt.subplots()
    ax.plot(r["x_ref"], r["y_ref"], lw=0.8)
    ax.plot(r["x"], r["y"])
    fig.savefig(png)
    plt.close(fig)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

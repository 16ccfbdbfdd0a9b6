"""The work-precision figure of cosim/benches/stiff.py: error against median time, log-log,
one panel per case, both tools.

stiff.py draws it after its measurement; this file also redraws it from the measurement's
table as docs/performance.md records it (the same medians and errors), without measuring
again:

    target/venv/bin/python cosim/benches/stiff_figure.py docs/performance.md docs/figures/stiff_work_precision.png

Each curve runs from rtol 1e-3 to 1e-10; only its two ends carry their rtol (labels at every
point overlapped where the points crowd), the order in between being the curve's. A tool's
failed runs (CVode's mxstep) are said under the panel's title, not inside the plot.
"""
import re
import sys

TOOLS = ("cosim bdf", "fmpy CVode")
STYLES = {"cosim bdf": ("o-", "tab:blue"), "fmpy CVode": ("s--", "tab:orange")}
# where a curve's end labels go: right of cosim's points (the left curve), left of CVode's
LABEL_SIDE = {"cosim bdf": ((6, -3), "left"), "fmpy CVode": ((-6, -3), "right")}


def draw(cases, rtols, points, failures, rounds, png):
    """cases: the case labels in panel order; points: (case, rtol, tool) -> (median time [s],
    error) for the runs that finished; failures: the (case, rtol, tool) that did not."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    fig, grid = plt.subplots(2, 3, figsize=(13.0, 8.4))
    axes = list(grid.flat)
    axes[-1].axis("off")
    axes[-1].text(0.0, 0.45, "each curve: rtol from 1e-3 to 1e-10, its ends labelled\n"
                  "each point: the median time over the rounds\n"
                  "cosim bdf: the whole cosim process\nfmpy CVode: the simulate_fmu call\n"
                  "error: largest |x - x_ref| / max(1, |x_ref|) over the rows\n"
                  "references: Radau (SciPy) on the equations / over the\nFMU's right-hand side; the ball's closed form",
                  fontsize=9, va="center")
    ms = FuncFormatter(lambda v, _: f"{v * 1e3:g}")
    for ax, label in zip(axes, cases):
        notes = []
        for tool in TOOLS:
            style, color = STYLES[tool]
            pts = [(points[(label, r, tool)][0], points[(label, r, tool)][1], r) for r in rtols
                   if (label, r, tool) in points]
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, color=color, label=tool, markersize=5)
                # the ends of the curve: the loosest and the tightest rtol that finished
                offset, align = LABEL_SIDE[tool]
                for t, e, r in (pts[0], pts[-1]):
                    ax.annotate(f"rtol {r:.0e}", (t, e), fontsize=7, color=color, xytext=offset,
                                textcoords="offset points", ha=align)
            failed = [r for r in rtols if (label, r, tool) in failures]
            if failed:
                span = f"{failed[0]:.0e}" if len(failed) == 1 else f"{failed[0]:.0e} .. {failed[-1]:.0e}"
                notes.append(f"{tool}: no result at rtol {span} (mxstep)")
        ax.set_title(label + ("\n" + "; ".join(notes) if notes else ""), fontsize=9)
        ax.set_xlabel("time of the run, ms (median)")
        ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(ms)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.margins(x=0.25, y=0.12)
        ax.grid(True, which="major", alpha=0.4)
        ax.grid(True, which="minor", alpha=0.12)
    for ax in (axes[0], axes[3]):
        ax.set_ylabel("error vs the reference")
    # the legend in the free panel, where it covers no point
    handles, labels = axes[0].get_legend_handles_labels()
    axes[-1].legend(handles, labels, fontsize=9, loc="upper left")
    fig.suptitle(f"work-precision, rtol 1e-3 .. 1e-10, {rounds} rounds alternated: cosim process vs fmpy simulate_fmu",
                 fontsize=11)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def from_table(markdown):
    """The cases, rtols, points and failures of stiff.py's work-precision table in
    `markdown` (docs/performance.md), and its number of rounds."""
    rows = re.findall(r"^\| ([^|]+?) \| (1e-\d\d) \| ([\d.]+) \([^)]*\) \| ([^|]+?) \| ([\d.]+) \([^)]*\) \| ([^|]+?) \|$",
                      markdown, re.M)
    rounds = int(re.search(r"median \(min \.\. max\) over (\d+) rounds", markdown).group(1))
    cases, rtols, points, failures = [], [], {}, set()
    for case, rtol, t_bdf, e_bdf, t_cv, e_cv in rows:
        r = float(rtol)
        if case not in cases:
            cases.append(case)
        if r not in rtols:
            rtols.append(r)
        for tool, t, e in (("cosim bdf", t_bdf, e_bdf), ("fmpy CVode", t_cv, e_cv)):
            if e.startswith("failed"):
                failures.add((case, r, tool))
            else:
                points[(case, r, tool)] = (float(t), float(e))
    return cases, rtols, points, failures, rounds


if __name__ == "__main__":
    table, png = sys.argv[1], sys.argv[2]
    cases, rtols, points, failures, rounds = from_table(open(table).read())
    assert len(cases) == 5 and len(rtols) == 8, (cases, rtols)
    draw(cases, rtols, points, failures, rounds, png)
    print(f"wrote {png}")

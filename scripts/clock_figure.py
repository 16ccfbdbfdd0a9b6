#!/usr/bin/env python3
"""Draws the ticks of a clocked run: one row per clock counter of the result CSV (`n_<clock>`),
a mark at every time its count goes up, and the counts of the run's `--summary` in the labels.

usage: python scripts/clock_figure.py RESULT.csv SUMMARY.json OUT.png
(the README's figure: `cargo test --release -p nigel-cosim --test clocks` runs the C test FMU
tests/cfmu/fmi3_clocks.c with `cosim run` and calls this script; it writes docs/figures/clock_ticks.png
when NIGEL_WRITE_DOC_FIGURES=1)."""
import csv
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def ticks_of(path):
    """{clock: [times its counter went up]}: the count at a row counts the ticks before it,
    so a tick lies between the row before the step up and the row of it; drawn at the former
    (the tick's own row holds the values before it)."""
    rows = list(csv.DictReader(open(path)))
    out = {}
    for name in rows[0]:
        if not name.startswith("n_"):
            continue
        times = []
        for before, now in zip(rows, rows[1:]):
            for _ in range(int(float(now[name])) - int(float(before[name]))):
                times.append(float(before["time"]))
        out[name[2:]] = times
    return out


def main(result, summary, png):
    counts = {c["clock"]: c["ticks"] for c in json.load(open(summary)).get("clock_ticks", [])}
    ticks = ticks_of(result)
    times = [float(r["time"]) for r in csv.DictReader(open(result))]
    fig, ax = plt.subplots(figsize=(7, 2.6), dpi=110)
    for k, (clock, times) in enumerate(ticks.items()):
        ax.plot(times, [k] * len(times), "|", markersize=16, markeredgewidth=2)
    ax.set_yticks(range(len(ticks)))
    ax.set_yticklabels([f"{c} ({counts.get(c, len(t))})" for c, t in ticks.items()])
    ax.set_xlabel("time, s")
    ax.set_title("FMI 3.0 clock ticks run by cosim (C test FMU, steps of 0.1 s)", fontsize=10)
    ax.grid(axis="x", alpha=0.3)
    ax.set_ylim(-0.6, len(ticks) - 0.4)
    ax.set_xlim(times[0] - 0.02, times[-1] + 0.02)
    fig.tight_layout()
    fig.savefig(png)
    for clock, times in ticks.items():
        print(clock, counts.get(clock, len(times)), " ".join(f"{t:g}" for t in times))


if __name__ == "__main__":
    main(*sys.argv[1:4])

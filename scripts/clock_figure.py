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
    """{clock: [times its counter went up]}: a row at a tick is recorded with the tick's event
    open, and the test FMU counts a tick as its clock is set, so a tick is at the row where
    the count goes up (docs/clocks.md)."""
    rows = list(csv.DictReader(open(path)))
    out = {}
    for name in rows[0]:
        if not name.startswith("n_"):
            continue
        times = []
        for before, now in zip([{name: "0"}] + rows, rows):
            for _ in range(int(float(now[name])) - int(float(before[name]))):
                times.append(float(now["time"]))
        out[name[2:]] = times
    return out


def main(result, summary, png):
    counts = {c["clock"]: c["ticks"] for c in json.load(open(summary)).get("clock_ticks", [])}
    ticks = ticks_of(result)
    row_times = [float(r["time"]) for r in csv.DictReader(open(result))]
    fig, ax = plt.subplots(figsize=(7, 2.6), dpi=110)
    for k, (clock, tick_times) in enumerate(ticks.items()):
        ax.plot(tick_times, [k] * len(tick_times), "|", markersize=16, markeredgewidth=2)
    ax.set_yticks(range(len(ticks)))
    ax.set_yticklabels([f"{c} ({counts.get(c, len(t))})" for c, t in ticks.items()])
    ax.set_xlabel("time, s")
    ax.set_title("FMI 3.0 clock ticks run by cosim (C test FMU, steps of 0.1 s)", fontsize=10)
    ax.grid(axis="x", alpha=0.3)
    ax.set_ylim(-0.6, len(ticks) - 0.4)
    # the whole run: its first and last rows
    ax.set_xlim(row_times[0] - 0.02, row_times[-1] + 0.02)
    fig.tight_layout()
    fig.savefig(png)
    for clock, times in ticks.items():
        print(clock, counts.get(clock, len(times)), " ".join(f"{t:g}" for t in times))


if __name__ == "__main__":
    main(*sys.argv[1:4])

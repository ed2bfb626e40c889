#!/usr/bin/env python3
"""The per-pair cost distributions of run.py, at issue 12's start and now: one panel per scene,
the pairs that carry load and all overlapping pairs (docs/benchmarks.md, "Each pair timed in the
running stage").

  /usr/bin/python3 benchmarks/contact_pair_timing/plot.py
      [--csv docs/data/contact_pair_timing_histograms.csv] [--png docs/contact_pair_costs.png]
      [--now-label d206238]

Each curve is the share of the class's pairs per bin of cost (80 bins per decade, from 1 ns),
smoothed over 5 bins; the legend gives the class's mean.
"""
import argparse
import collections
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

BINS_PER_DECADE = 80
TITLES = {"tower": "default example, 0.1 s", "dry_wall": "dry-stone wall, 0.2 s",
          "pile": "dense pile, 4 ms", "wall55": "wall55, 0.03 s", "arch": "arch, 0.02 s"}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--csv", default="docs/data/contact_pair_timing_histograms.csv")
    p.add_argument("--png", default="docs/contact_pair_costs.png")
    p.add_argument("--now-label", default="d206238", help="the commit run.py measured as now")
    a = p.parse_args()
    counts = collections.defaultdict(lambda: collections.Counter())  # (case, code, class) -> bins
    for r in csv.DictReader(open(a.csv)):
        counts[(r["case"], r["code"], r["class"])][int(r["bin"])] += float(r["pairs"])
    cases = [c for c in TITLES if any(k[0] == c for k in counts)]
    fig, axes = plt.subplots(2, len(cases), figsize=(3.2 * len(cases), 6.0), sharex=True)
    rows = [("carries load", ["carries_load"]),
            ("all overlapping", ["carries_load", "overlapping_unloaded"])]
    for col, case in enumerate(cases):
        for row, (label, classes) in enumerate(rows):
            ax = axes[row][col]
            for code, color in (("start", "#888888"), ("now", "#1f77b4")):
                bins = collections.Counter()
                for c in classes:
                    bins.update(counts[(case, code, c)])
                total = sum(bins.values())
                if not total:
                    continue
                lo, hi = min(bins), max(bins)
                xs, ys = [], []
                for b in range(lo, hi + 1):
                    window = sum(bins.get(b + d, 0.0) for d in range(-2, 3)) / 5.0
                    xs.append(10 ** ((b + 0.5) / BINS_PER_DECADE))
                    ys.append(window / total)
                mean = sum(10 ** ((b + 0.5) / BINS_PER_DECADE) * n for b, n in bins.items()) / total
                ax.plot(xs, ys, color=color, lw=1.5,
                        label=f"{'start' if code == 'start' else 'now'}: mean {mean:,.0f} ns")
            ax.set_xscale("log")
            ax.set_xlim(30, 2e4)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="upper left")
            if row == 0:
                ax.set_title(TITLES[case], fontsize=9)
            if col == 0:
                ax.set_ylabel(f"{label}: share of pairs per bin", fontsize=8)
            if row == 1:
                ax.set_xlabel("ns per pair (in the running stage)", fontsize=8)
    fig.suptitle("One contact pair's cost, friction and dashpot included: issue 12's start "
                 f"(f37b868) and now ({a.now_label})", fontsize=10)
    fig.tight_layout()
    fig.savefig(a.png, dpi=110)
    print(f"wrote {a.png}")


if __name__ == "__main__":
    main()

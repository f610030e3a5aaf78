#!/usr/bin/python3
"""Plot the convergence tables written by the verification tests (convergence.csv).

    /usr/bin/python3 postproc/plot_convergence.py build/tests/convergence.csv [--out convergence.png]

Each CSV row is: test name, kind (space / time / space+time), ranks, h or dt, error, fitted
order. One log-log panel per kind; each test is a line with markers, and dashed reference
slopes of order 1 and 2 are drawn through the last point of each panel.
"""
import argparse
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    series = defaultdict(list)
    orders = {}
    with open(path, newline="") as f:
        for row in csv.reader(f):
            if len(row) != 6:
                continue
            name, kind, ranks, x, err, order = row
            key = (kind, f"{name} ({ranks} rank{'s' if ranks != '1' else ''})")
            series[key].append((float(x), float(err)))
            orders[key] = float(order)
    return series, orders


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("--out", default="convergence.png")
    args = ap.parse_args(argv)
    try:
        series, orders = read(args.csv)
    except OSError as e:
        sys.exit(f"plot_convergence: error: {args.csv}: {e.strerror}")
    if not series:
        sys.exit(f"plot_convergence: error: {args.csv}: no convergence rows")
    kinds = sorted({k for k, _ in series})
    fig, axes = plt.subplots(1, len(kinds), figsize=(6 * len(kinds), 5), squeeze=False)
    for ax, kind in zip(axes[0], kinds):
        last = None
        for (k, label), pts in sorted(series.items()):
            if k != kind:
                continue
            pts.sort()
            xs, es = zip(*pts)
            ax.loglog(xs, es, "o-", label=f"{label}: {orders[(k, label)]:.2f}")
            last = (xs[0], es[0]) if last is None or xs[0] < last[0] else last
        if last:
            x0, e0 = last
            xs = [x0, x0 * 8]
            for p, style in ((1, "k--"), (2, "k:")):
                ax.loglog(xs, [e0 * (x / x0) ** p for x in xs], style, label=f"slope {p}")
        ax.set_xlabel("h" if kind.startswith("space") else "dt")
        ax.set_ylabel("max-norm error")
        ax.set_title(f"convergence in {kind}")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())

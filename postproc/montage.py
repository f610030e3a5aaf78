#!/usr/bin/python3
"""Assemble the PNG snapshots of a morphogen run into one labelled figure.

    /usr/bin/python3 postproc/montage.py OUTPUT_DIR [--species a] [--out montage_a.png]

Reads OUTPUT_DIR/<species>_<step>.png (written every -png_every steps), orders them by step
and writes a grid of panels titled with the step number (default OUTPUT_DIR/montage_<species>.png).
"""
import argparse
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402


def snapshots(directory, species):
    pat = re.compile(r"^%s_(\d+)\.png$" % re.escape(species))
    found = []
    for name in os.listdir(directory):
        m = pat.match(name)
        if m:
            found.append((int(m.group(1)), os.path.join(directory, name)))
    return sorted(found)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("output_dir")
    ap.add_argument("--species", default=None, help="species name (default: the first found)")
    ap.add_argument("--out", default=None, help="output PNG (default OUTPUT_DIR/montage_<species>.png)")
    ap.add_argument("--columns", type=int, default=4)
    args = ap.parse_args(argv)
    if not os.path.isdir(args.output_dir):
        sys.exit(f"montage: error: {args.output_dir}: no such directory")
    species = args.species
    if species is None:
        names = sorted({re.sub(r"_(\d+|final)\.png$", "", f) for f in os.listdir(args.output_dir)
                        if re.search(r"_\d+\.png$", f)})
        if not names:
            sys.exit(f"montage: error: {args.output_dir}: no <species>_<step>.png snapshots")
        species = names[0]
    snaps = snapshots(args.output_dir, species)
    if not snaps:
        sys.exit(f"montage: error: {args.output_dir}: no {species}_<step>.png snapshots")
    cols = min(args.columns, len(snaps))
    rows = math.ceil(len(snaps) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3 * cols, 3.2 * rows), squeeze=False)
    for ax in axes.flat:
        ax.axis("off")
    for ax, (step, path) in zip(axes.flat, snaps):
        ax.imshow(mpimg.imread(path))
        ax.set_title(f"{species}, step {step}")
    fig.tight_layout()
    out = args.out or os.path.join(args.output_dir, f"montage_{species}.png")
    fig.savefig(out, dpi=100)
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())

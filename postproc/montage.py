#!/usr/bin/python3
"""Assemble a morphogen run's snapshots into one figure with one colour scale and a colour bar.

    /usr/bin/python3 postproc/montage.py OUTPUT_DIR [--species a] [--out montage_a.png]
        [--source auto|snapshots|png] [--cmap viridis] [--range LO,HI] [--columns 4]

snapshots: the VTKHDF series (<name>.vtkhdf.series; step 0 is in it when the run used
-snapshot_every): every panel is drawn with the same colour range (the min/max over all panels,
or --range) and one colour bar, titled with the step and time; 3-D runs show the middle z slice.
png: the <species>_<step>.png images (-png_every; step 0 included), shown as written (their
colours are the run's fixed PNG range; no colour bar, as the images carry no values).
auto (default): snapshots when the series holds at least two, else the PNG images.
Writes OUTPUT_DIR/montage_<species>.png unless --out is given.
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
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import morphogen_h5 as mh  # noqa: E402


def png_snapshots(directory, species):
    """[(step, path)] of <species>_<step>.png, by step."""
    pat = re.compile(r"^%s_(\d+)\.png$" % re.escape(species))
    found = []
    for name in os.listdir(directory):
        m = pat.match(name)
        if m:
            found.append((int(m.group(1)), os.path.join(directory, name)))
    return sorted(found)


def series_frames(directory):
    """[(time, path)] of the run's VTKHDF series, or [] without one."""
    try:
        return mh.read_series(directory)
    except mh.MorphogenH5Error:
        return []


def field_2d(path, species):
    """(step, time, 2-D array (ny, nx), extent (x0, x1, y0, y1)) of a snapshot."""
    snap = mh.read_snapshot(path)
    if species not in snap["fields"]:
        raise mh.MorphogenH5Error(f"{path}: no species {species!r} (has {', '.join(snap['species'])})")
    a = np.asarray(snap["fields"][species], dtype=float)
    if a.ndim == 3:
        a = a[a.shape[0] // 2]
    ny, nx = a.shape
    hx, hy = snap["spacing3"][0], snap["spacing3"][1]
    x0 = snap["origin3"][0] - hx / 2  # cell-centred: the domain starts half a cell earlier
    y0 = snap["origin3"][1] - hy / 2
    return snap["step"], snap["time"], a, (x0, x0 + nx * hx, y0, y0 + ny * hy)


def parse_range(text):
    try:
        lo, hi = (float(v) for v in text.split(","))
    except ValueError:
        sys.exit(f"montage: error: --range {text}: expected LO,HI (two numbers)")
    if not lo < hi:
        sys.exit(f"montage: error: --range {text}: needs LO < HI")
    return lo, hi


def grid(n, columns, w=3.0, h=3.0, extra_w=0.0):
    cols = min(columns, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(w * cols + extra_w, h * rows), squeeze=False)
    for ax in axes.flat:
        ax.axis("off")
    return fig, axes


def montage_snapshots(frames, species, args):
    data = [field_2d(p, species) for _, p in frames]
    if args.range:
        lo, hi = parse_range(args.range)
    else:
        lo = min(float(np.nanmin(d[2])) for d in data)
        hi = max(float(np.nanmax(d[2])) for d in data)
        if not hi > lo:
            hi = lo + 1.0
    fig, axes = grid(len(data), args.columns, extra_w=0.8)
    im = None
    for ax, (step, time, a, ext) in zip(axes.flat, data):
        im = ax.imshow(a, origin="lower", extent=ext, cmap=args.cmap, vmin=lo, vmax=hi,
                       interpolation="nearest")
        ax.set_title(f"{species}, step {step}, t {time:.4g}", fontsize=9)
    fig.tight_layout(rect=(0, 0, 0.92, 1))
    cax = fig.add_axes((0.935, 0.15, 0.015, 0.7))
    fig.colorbar(im, cax=cax, label=species)
    return fig


def montage_pngs(snaps, species, args):
    fig, axes = grid(len(snaps), args.columns, h=3.2)
    for ax, (step, path) in zip(axes.flat, snaps):
        ax.imshow(mpimg.imread(path))
        ax.set_title(f"{species}, step {step}")
    fig.tight_layout()
    return fig


def first_species(directory, frames):
    if frames:
        return mh.read_metadata(frames[0][1])["species"][0]
    names = sorted({re.sub(r"_\d+\.png$", "", f) for f in os.listdir(directory)
                    if re.search(r"_\d+\.png$", f)})
    return names[0] if names else None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("output_dir")
    ap.add_argument("--species", default=None, help="species name (default: the first)")
    ap.add_argument("--out", default=None, help="output PNG (default OUTPUT_DIR/montage_<species>.png)")
    ap.add_argument("--columns", type=int, default=4)
    ap.add_argument("--source", choices=("auto", "snapshots", "png"), default="auto")
    ap.add_argument("--cmap", default="viridis", help="matplotlib colour map (snapshots)")
    ap.add_argument("--range", default=None, help="colour range LO,HI (snapshots; default min/max)")
    args = ap.parse_args(argv)
    if not os.path.isdir(args.output_dir):
        sys.exit(f"montage: error: {args.output_dir}: no such directory")
    if args.columns < 1:
        sys.exit(f"montage: error: --columns {args.columns}: must be >= 1")
    if args.cmap == "grey":
        args.cmap = "gray"
    if args.cmap not in matplotlib.colormaps:
        sys.exit(f"montage: error: --cmap {args.cmap}: unknown, allowed matplotlib's (e.g. viridis, "
                 "magma, grey, coolwarm)")
    frames = series_frames(args.output_dir)
    species = args.species or first_species(args.output_dir, frames)
    if species is None:
        sys.exit(f"montage: error: {args.output_dir}: no snapshots and no <species>_<step>.png images")
    source = args.source
    if source == "auto":
        source = "snapshots" if len(frames) >= 2 else "png"
    try:
        if source == "snapshots":
            if not frames:
                sys.exit(f"montage: error: {args.output_dir}: no .vtkhdf.series (run with -snapshot_every N)")
            fig = montage_snapshots(frames, species, args)
        else:
            snaps = png_snapshots(args.output_dir, species)
            if not snaps:
                sys.exit(f"montage: error: {args.output_dir}: no {species}_<step>.png snapshots")
            fig = montage_pngs(snaps, species, args)
    except mh.MorphogenH5Error as e:
        sys.exit(f"montage: error: {e}")
    out = args.out or os.path.join(args.output_dir, f"montage_{species}.png")
    fig.savefig(out, dpi=100)
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())

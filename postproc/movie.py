#!/usr/bin/python3
"""Make an MP4 or GIF movie of chosen species of a morphogen run (ffmpeg).

    /usr/bin/python3 postproc/movie.py RUN_DIR [--species a,b] [--out RUN_DIR/movie.mp4]
        [--source auto|snapshots|png] [--fps 10] [--scale N] [--cmap viridis] [--range LO,HI]

snapshots: the VTKHDF series (run with -snapshot_every N or -snapshot_every_time T; the initial
state is its first frame). Every frame of a species is coloured with one range (the min/max over
the whole run, or --range), species side by side; 3-D runs show the middle z slice; y points up.
png: the <species>_<step>.png images (-png_every N), as written, species side by side.
auto (default): snapshots when the series holds at least two frames, else the PNG images.
The output format follows the extension: .mp4 (H.264, yuv420p: plays everywhere) or .gif
(a palette made from the movie). --scale N enlarges each cell to N x N pixels (default: the
smallest factor that makes the frames at least 256 pixels high). Needs ffmpeg (Debian package
ffmpeg; .ci/setup installs it).
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    sys.exit(f"movie: error: {msg}")


def series_frames(run_dir):
    import morphogen_h5 as mh
    try:
        return mh.read_series(run_dir)
    except mh.MorphogenH5Error:
        return []


def png_frames(run_dir, species):
    """{step: path} of <species>_<step>.png."""
    pat = re.compile(r"^%s_(\d+)\.png$" % re.escape(species))
    out = {}
    for name in os.listdir(run_dir):
        m = pat.match(name)
        if m:
            out[int(m.group(1))] = os.path.join(run_dir, name)
    return out


def colour(a, lo, hi, cmap):
    """uint8 RGB image (rows top first) of a 2-D field (row 0 = bottom) through cmap."""
    t = (np.asarray(a, dtype=float) - lo) / (hi - lo) if hi > lo else np.full(np.shape(a), 0.5)
    rgb = cmap(np.clip(t, 0.0, 1.0))[..., :3]
    rgb[~np.isfinite(t)] = (1.0, 0.0, 1.0)
    return (np.rint(rgb[::-1] * 255)).astype(np.uint8)


def snapshot_tiles(frames, species, args):
    """[(list of per-species RGB tiles)] per frame, from the VTKHDF series."""
    import matplotlib
    import morphogen_h5 as mh
    cmap = matplotlib.colormaps["gray" if args.cmap == "grey" else args.cmap]
    fields = []
    for _, path in frames:
        snap = mh.read_snapshot(path)
        row = []
        for s in species:
            if s not in snap["fields"]:
                fail(f"{path}: no species {s!r} (has {', '.join(snap['species'])})")
            a = np.asarray(snap["fields"][s], dtype=float)
            row.append(a[a.shape[0] // 2] if a.ndim == 3 else a)
        fields.append(row)
    ranges = []
    for k in range(len(species)):
        if args.range:
            ranges.append(args.range)
        else:
            lo = min(float(np.nanmin(f[k])) for f in fields)
            hi = max(float(np.nanmax(f[k])) for f in fields)
            ranges.append((lo, hi))
    return [[colour(f[k], *ranges[k], cmap) for k in range(len(species))] for f in fields]


def png_tiles(run_dir, species):
    import matplotlib.image as mpimg
    per = [png_frames(run_dir, s) for s in species]
    steps = sorted(set.intersection(*(set(p) for p in per)))
    if not steps:
        fail(f"{run_dir}: no <species>_<step>.png images of {','.join(species)} (run with -png_every N)")
    tiles = []
    for step in steps:
        row = []
        for p in per:
            img = mpimg.imread(p[step])
            if img.dtype != np.uint8:
                img = np.rint(np.clip(img, 0, 1) * 255).astype(np.uint8)
            if img.ndim == 2:
                img = np.repeat(img[..., None], 3, axis=2)
            row.append(img[..., :3])
        tiles.append(row)
    return tiles


def assemble(row, scale, gap=4):
    """One frame: the tiles upscaled, side by side with a white gap."""
    big = [np.repeat(np.repeat(t, scale, axis=0), scale, axis=1) for t in row]
    h = max(t.shape[0] for t in big)
    parts = []
    for i, t in enumerate(big):
        if i:
            parts.append(np.full((h, gap, 3), 255, np.uint8))
        pad = np.full((h - t.shape[0], t.shape[1], 3), 255, np.uint8)
        parts.append(np.concatenate((t, pad), axis=0))
    return np.concatenate(parts, axis=1)


def even(frame):
    """Pads to even width and height (H.264 with yuv420p needs them)."""
    h, w = frame.shape[:2]
    return np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), constant_values=255)


def encode(frames, out, fps, ffmpeg):
    h, w = frames[0].shape[:2]
    cmd = [ffmpeg, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24",
           "-s", f"{w}x{h}", "-r", str(fps), "-i", "-"]
    if out.lower().endswith(".gif"):
        cmd += ["-vf", "split[a][b];[a]palettegen[p];[b][p]paletteuse", out]
    else:
        cmd += ["-c:v", "libx264", "-pix_fmt", "yuv420p", "-movflags", "+faststart", out]
    proc = subprocess.run(cmd, input=b"".join(f.tobytes() for f in frames), capture_output=True)
    if proc.returncode != 0:
        fail(f"ffmpeg failed writing {out}: {proc.stderr.decode(errors='replace').strip()[-400:]}")


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--species", default=None, help="comma-separated species (default: all)")
    ap.add_argument("--out", default=None, help="output .mp4 or .gif (default RUN_DIR/movie.mp4)")
    ap.add_argument("--source", choices=("auto", "snapshots", "png"), default="auto")
    ap.add_argument("--fps", type=float, default=10.0)
    ap.add_argument("--scale", type=int, default=0, help="pixels per cell (0: automatic)")
    ap.add_argument("--cmap", default="viridis", help="matplotlib colour map (snapshots)")
    ap.add_argument("--range", default=None, help="colour range LO,HI of every species (snapshots)")
    args = ap.parse_args(argv)
    if not os.path.isdir(args.run_dir):
        fail(f"{args.run_dir}: no such directory")
    if not (args.fps > 0):
        fail(f"--fps {args.fps}: must be > 0")
    if not 0 <= args.scale <= 64:
        fail(f"--scale {args.scale}: allowed 0 (automatic) to 64")
    args.out = args.out or os.path.join(args.run_dir, "movie.mp4")
    if not args.out.lower().endswith((".mp4", ".gif")):
        fail(f"--out {args.out}: allowed extensions .mp4, .gif")
    if args.range is not None:
        try:
            lo, hi = (float(v) for v in args.range.split(","))
        except ValueError:
            fail(f"--range {args.range}: expected LO,HI (two numbers)")
        if not lo < hi:
            fail(f"--range {args.range}: needs LO < HI")
        args.range = (lo, hi)
    import matplotlib
    if (args.cmap if args.cmap != "grey" else "gray") not in matplotlib.colormaps:
        fail(f"--cmap {args.cmap}: unknown, allowed matplotlib's (e.g. viridis, magma, grey, coolwarm)")
    return args


def main(argv=None):
    args = parse_args(argv)
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        fail("ffmpeg not found (Debian: apt-get install ffmpeg; .ci/setup installs it)")
    frames = series_frames(args.run_dir)
    source = args.source
    if source == "auto":
        source = "snapshots" if len(frames) >= 2 else "png"
    if source == "snapshots":
        if not frames:
            fail(f"{args.run_dir}: no .vtkhdf.series (run with -snapshot_every N)")
        import morphogen_h5 as mh
        known = mh.read_metadata(frames[0][1])["species"]
        species = args.species.split(",") if args.species else known
        tiles = snapshot_tiles(frames, species, args)
    else:
        species = args.species.split(",") if args.species else sorted(
            {re.sub(r"_\d+\.png$", "", f) for f in os.listdir(args.run_dir) if re.search(r"_\d+\.png$", f)})
        if not species:
            fail(f"{args.run_dir}: no <species>_<step>.png images (run with -png_every N)")
        tiles = png_tiles(args.run_dir, species)
    h = tiles[0][0].shape[0]
    scale = args.scale or max(1, -(-256 // h))
    movie = [even(assemble(row, scale)) for row in tiles]
    encode(movie, args.out, args.fps, ffmpeg)
    print(f"{args.out}: {len(movie)} frames of {','.join(species)}, {movie[0].shape[1]}x{movie[0].shape[0]} "
          f"pixels, {args.fps:g} fps")
    return 0


if __name__ == "__main__":
    sys.exit(main())

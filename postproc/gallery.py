#!/usr/bin/python3
"""Run every shipped deck and write one small image per deck: the gallery (docs/gallery/).

    /usr/bin/python3 postproc/gallery.py [--decks turing_spots,brusselator] [--out docs/gallery]
        [--exe build/morphogen] [--ranks 1] [--work DIR] [--size 192]
        [--steps N] [--grid-div D]

Each deck in input/ (or those named by --decks) runs as shipped (full size; a few seconds to a
minute each on one core) with its output in --work (default: a temporary directory), and its
final image becomes OUT/<deck>.png, resized to --size pixels on its longer side. The species
drawn is the deck's first png_species, else the one summary.json classifies as spots, else the
first. Sweep decks (a sweep: section) run with `morphogen sweep` and give the thumbnail mosaic
of postproc/phase_diagram.py. OUT/index.md gets a Markdown table (deck, what it reproduces, image)
from each deck's header comment.

--steps N and --grid-div D give a reduced run for checking the script (every -grid_n, and
-grid_L where the deck sets it, divided by D, so the spacing is kept; N steps).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(HERE)


def fail(msg):
    sys.exit(f"gallery: error: {msg}")


def deck_header(path):
    """(title, source) from the deck's first comment paragraph "# Title: source ..."."""
    lines = []
    with open(path) as fh:
        for line in fh:
            if not line.startswith("#"):
                break
            text = line[1:].strip()
            if not text:
                break
            lines.append(text)
    para = " ".join(lines)
    title, _, source = para.partition(":")
    source = source.strip()
    m = re.search(r"(?<!Fig)(?<!al)(?<!eqs)(?<!eq)(?<!p)\.\s+(?=[A-Z(])", source)
    if m:
        source = source[:m.start() + 1]
    source = source.split(": ")[0].rstrip(",;")
    if len(source) > 100:
        source = source[:97].rsplit(" ", 1)[0] + " ..."
    return title.strip(), source


def deck_keys(path):
    """The deck's top-level keys we need: grid n/L, png_species, sweep (plain YAML)."""
    import yaml
    with open(path) as fh:
        doc = yaml.safe_load(fh) or {}
    grid = doc.get("grid") or {}
    return {"n": grid.get("n"), "L": grid.get("L"), "png_species": doc.get("png_species"),
            "sweep": "sweep" in doc}


def as_list(v):
    if v is None:
        return None
    if isinstance(v, (list, tuple)):
        return [float(x) for x in v]
    return [float(x) for x in str(v).split(",")]


def reduced_options(keys, steps, div):
    opts = []
    if steps:
        opts += ["-steps", str(steps)]
    if div and div > 1:
        n = as_list(keys["n"]) or [256, 256]
        opts += ["-grid_n", ",".join(str(max(8, int(round(v / div)))) for v in n)]
        L = as_list(keys["L"])
        if L:
            opts += ["-grid_L", ",".join(repr(v / div) for v in L)]
    return opts


def run(cmd, cwd, ranks, log):
    if ranks > 1:
        cmd = [shutil.which("mpiexec") or "mpiexec", "--oversubscribe", "-n", str(ranks)] + cmd
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    with open(log, "w") as fh:
        proc = subprocess.run(cmd, cwd=cwd, stdout=fh, stderr=subprocess.STDOUT, env=env)
    if proc.returncode != 0:
        with open(log) as fh:
            tail = fh.read().strip().splitlines()[-3:]
        fail(f"{' '.join(cmd)} failed (exit {proc.returncode}): {' / '.join(tail)}")


def pick_species(keys, run_dir):
    if keys["png_species"]:
        return str(keys["png_species"]).split(",")[0].strip()
    try:
        with open(os.path.join(run_dir, "summary.json")) as fh:
            species = json.load(fh)["species"]
        for name, rec in species.items():
            if rec.get("class") == "spots":
                return name
        return next(iter(species))
    except (OSError, ValueError, KeyError, StopIteration):
        finals = sorted(f[:-len("_final.png")] for f in os.listdir(run_dir) if f.endswith("_final.png"))
        if not finals:
            fail(f"{run_dir}: no <species>_final.png written")
        return finals[0]


def thumbnail(src, dst, size):
    """src resized to `size` pixels on its longer side (box filter down, nearest up)."""
    from PIL import Image
    with Image.open(src) as im:
        im = im.convert("RGB")
        w, h = im.size
        f = size / max(w, h)
        new = (max(1, round(w * f)), max(1, round(h * f)))
        im.resize(new, Image.BOX if f < 1 else Image.NEAREST).save(dst, optimize=True)


def make_one(deck, args, work):
    name = os.path.splitext(os.path.basename(deck))[0]
    keys = deck_keys(deck)
    run_dir = os.path.join(work, name)
    shutil.rmtree(run_dir, ignore_errors=True)
    opts = reduced_options(keys, args.steps, args.grid_div)
    log = os.path.join(work, name + ".log")
    t0 = time.time()
    if keys["sweep"]:
        run([args.exe, "sweep", deck, "-output_dir", run_dir] + opts, work, args.ranks, log)
        run([sys.executable, os.path.join(HERE, "phase_diagram.py"), run_dir], work, 1, log + ".fig")
        src, species = os.path.join(run_dir, "phase_mosaic.png"), "mosaic"
    else:
        run([args.exe, deck, "-output_dir", run_dir, "-png_every", "0", "-snapshot_every", "0",
             "-checkpoint_final", "false"] + opts, work, args.ranks, log)
        species = pick_species(keys, run_dir)
        src = os.path.join(run_dir, f"{species}_final.png")
    dst = os.path.join(args.out, name + ".png")
    thumbnail(src, dst, args.size)
    title, source = deck_header(deck)
    print(f"{name}: {species} -> {dst} ({time.time() - t0:.1f} s)", flush=True)
    return {"deck": name, "title": title, "source": source, "species": species, "image": name + ".png"}


def write_index(rows, out):
    """index.md over every deck made so far: the rows of earlier runs (OUT/index.json) updated
    with these, so a run over some decks keeps the others' rows."""
    path = os.path.join(out, "index.json")
    known = {}
    if os.path.isfile(path):
        with open(path) as fh:
            known = {r["deck"]: r for r in json.load(fh)}
    for r in rows:
        known[r["deck"]] = r
    rows = [known[k] for k in sorted(known) if os.path.isfile(os.path.join(out, known[k]["image"]))]
    with open(path, "w") as fh:
        json.dump(rows, fh, indent=1)
    lines = ["| deck | reproduces | image |", "|---|---|---|"]
    for r in rows:
        what = f"{r['title']}: {r['source']}" if r["source"] else r["title"]
        shown = "phase-diagram mosaic" if r["species"] == "mosaic" else f"species {r['species']}"
        lines.append(f"| `{r['deck']}.yaml` | {what.replace('|', '/')} ({shown}) | "
                     f"<img src=\"{r['image']}\" width=\"160\"> |")
    with open(os.path.join(out, "index.md"), "w") as fh:
        fh.write("# Gallery\n\nGenerated by `postproc/gallery.py`: the final image of each deck in "
                 "`input/`.\n\n" + "\n".join(lines) + "\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--decks", default=None, help="comma-separated deck names (default: all in input/)")
    ap.add_argument("--out", default=os.path.join(SOURCE, "docs", "gallery"))
    ap.add_argument("--exe", default=os.path.join(SOURCE, "build", "morphogen"))
    ap.add_argument("--ranks", type=int, default=1)
    ap.add_argument("--work", default=None, help="run directory (default: temporary, removed)")
    ap.add_argument("--size", type=int, default=192, help="image size, pixels (longer side)")
    ap.add_argument("--steps", type=int, default=0, help="reduced run: steps (0: the deck's)")
    ap.add_argument("--grid-div", type=int, default=1, help="reduced run: divide the grid by D")
    args = ap.parse_args(argv)
    if not (os.path.isfile(args.exe) and os.access(args.exe, os.X_OK)):
        fail(f"--exe {args.exe}: not an executable (build morphogen first)")
    for opt, v, lo in (("--ranks", args.ranks, 1), ("--size", args.size, 16), ("--steps", args.steps, 0),
                       ("--grid-div", args.grid_div, 1)):
        if v < lo:
            fail(f"{opt} {v}: must be >= {lo}")
    input_dir = os.path.join(SOURCE, "input")
    available = sorted(f[:-5] for f in os.listdir(input_dir) if f.endswith(".yaml"))
    names = args.decks.split(",") if args.decks else available
    for n in names:
        if n not in available:
            fail(f"--decks {n}: no input/{n}.yaml; allowed {', '.join(available)}")
    os.makedirs(args.out, exist_ok=True)
    work = args.work or tempfile.mkdtemp(prefix="morphogen_gallery_")
    os.makedirs(work, exist_ok=True)
    try:
        rows = [make_one(os.path.join(input_dir, n + ".yaml"), args, os.path.abspath(work)) for n in names]
    finally:
        if args.work is None:
            shutil.rmtree(work, ignore_errors=True)
    write_index(rows, args.out)
    print(f"gallery: {len(rows)} images and index.md in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

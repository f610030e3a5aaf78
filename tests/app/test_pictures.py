"""PNG quick-look options (-png_scale, -png_colorbar, -png_colormap, -png_bits, -png_range),
their -help entries and validation, and the run record of summary.json."""
import json
import os
import struct
import subprocess
import sys

import numpy as np
import pytest

from conftest import SOURCE, run

sys.path.insert(0, os.path.join(SOURCE, "postproc"))
import morphogen_h5 as mh  # noqa: E402

SMALL = ["-grid_n", "24,16", "-steps", "20", "-progress_every", "1000", "-checkpoint_final", "false"]


def png_header(path):
    """(width, height, bit depth, colour type) from the IHDR chunk."""
    with open(path, "rb") as fh:
        head = fh.read(26)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    w, h = struct.unpack(">II", head[16:24])
    return w, h, head[24], head[25]


def grey16(path):
    """16-bit grey PNG -> float array in [0, 1], row 0 at the top."""
    from PIL import Image
    with Image.open(path) as im:
        return np.asarray(im, dtype=np.float64) / 65535.0


def test_scale_colorbar_colormap(workdir):
    out = workdir / "o"
    r = run(SMALL + ["-png_scale", "4", "-png_colorbar", "true", "-png_colormap", "magma",
                     "-output_dir", str(out)], cwd=workdir)
    assert r.returncode == 0, r.stderr
    w, h, depth, colour = png_header(out / "a_final.png")
    assert (h, depth, colour) == (16 * 4, 8, 2)  # RGB
    assert w > 24 * 4 + 20  # field, gap, bar and labels
    import matplotlib.image as mpimg
    img = (mpimg.imread(str(out / "a_final.png"))[..., :3] * 255).round().astype(int)
    # nearest-neighbour upscale: 4 x 4 blocks of one colour
    field = img[:, : 24 * 4]
    assert (field[::4, ::4] == field[3::4, 3::4]).all()
    # magma, not viridis: its darkest entry (0, 0, 4) at the bar's bottom, (252, 253, 191) on top
    bar = img[:, 24 * 4 + 8]
    assert tuple(bar[-1]) == (0, 0, 4) and tuple(bar[0]) == (252, 253, 191)


def test_help_lists_png_options(workdir):
    r = run(["-help"], cwd=workdir)
    assert r.returncode == 0, r.stderr
    for opt in ("-png_scale", "-png_colorbar", "-png_colormap", "-png_bits", "-png_range"):
        assert opt in r.stdout, opt


def test_16bit_grey_and_range_modes(workdir):
    # a bump that diffuses away: the data range shrinks over the run
    common = SMALL + ["-model", "turing", "-init_a", "4 + 8*disk(Lx/2, Ly/2, 2)", "-init_b", "4",
                      "-D_a", "0.2", "-dt", "1",
                      "-png_every", "5", "-snapshot_every", "5", "-png_bits", "16",
                      "-png_species", "a"]
    finals = {}
    for mode in ("fixed", "each"):
        out = workdir / mode
        r = run(common + ["-png_range", mode, "-output_dir", str(out)], cwd=workdir)
        assert r.returncode == 0, r.stderr
        assert png_header(out / "a_final.png")[2:] == (16, 0)  # 16-bit grey
        steps = [5, 10, 15, 20]
        lo = hi = None
        for s in steps:
            g = grey16(out / f"a_{s:07d}.png")[::-1]  # row 0 = bottom, as the field
            v = mh.read_snapshot(out / f"morphogen_{s:07d}.vtkhdf")["fields"]["a"].astype(float)
            if mode == "each" or lo is None:
                lo, hi = v.min(), v.max()
            else:
                lo, hi = min(lo, v.min()), max(hi, v.max())
            want = (v - lo) / (hi - lo)
            assert np.abs(g - want).max() < 1e-4, (mode, s)  # float32 snapshot vs double image
        finals[mode] = grey16(out / "a_final.png")
    assert finals["each"].max() == 1.0
    assert finals["fixed"].max() < 0.9  # the first image's wider range is kept


@pytest.mark.parametrize("args, words", [
    (["-png_scale", "0"], ["-png_scale", "0"]),
    (["-png_scale", "65"], ["-png_scale", "65"]),
    (["-png_colormap", "jet"], ["-png_colormap", "jet", "viridis", "magma", "grey", "coolwarm"]),
    (["-png_bits", "12"], ["-png_bits", "12", "8", "16"]),
    (["-png_range", "first"], ["-png_range", "first", "fixed", "each"]),
    (["-png_colorbar", "maybe"], ["-png_colorbar", "maybe", "true", "false"]),
    (["-png_bits", "16", "-png_colorbar", "true"], ["-png_colorbar", "-png_bits 16"]),
    (["-png_bits", "16", "-png_colormap", "magma"], ["-png_colormap", "magma", "grey"]),
])
def test_bad_png_options(workdir, args, words):
    out = workdir / "o"
    assert run(SMALL + ["-output_dir", str(out)], cwd=workdir).returncode == 0
    before = {p: (out / p).read_bytes() for p in sorted(os.listdir(out))}
    r = run(SMALL + ["-output_dir", str(out)] + args, cwd=workdir)
    assert r.returncode == 1, r.stdout + r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert {p: (out / p).read_bytes() for p in sorted(os.listdir(out))} == before


@pytest.mark.parametrize("ranks", [1, 2])
def test_summary_run_record(workdir, ranks):
    out = workdir / "o"
    r = run(["-grid_n", "32,24", "-steps", "50", "-progress_every", "1000", "-output_dir", str(out)],
            cwd=workdir, ranks=ranks)
    assert r.returncode == 0, r.stderr
    rec = json.loads((out / "summary.json").read_text())["run"]
    assert rec["ranks"] == ranks
    assert rec["cell_updates"] == 32 * 24 * 50
    assert 0 < rec["loop_time_s"] <= rec["wall_time_s"]
    assert rec["cell_updates_per_s"] == pytest.approx(rec["cell_updates"] / rec["loop_time_s"])
    v = rec["versions"]
    assert v["morphogen"].startswith("0.") and "3.18" in v["petsc"] and v["hdf5"].count(".") == 2
    # the same morphogen version as the checkpoint's
    ck = mh.read_checkpoint(sorted(out.glob("checkpoint_*.vtkhdf"))[-1])
    assert ck["version"] == v["morphogen"]

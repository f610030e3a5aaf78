"""-png_max_size: quick-looks of slices larger than N cells are block means of f x f cells
(f = ceil(max(nx, ny) / N)), the same pixels on 1 and 2 ranks; the option's bad values fail
with one line; the log has one output-time line per writer."""
import os
import sys

import numpy as np
import pytest

from conftest import SOURCE, run

sys.path.insert(0, os.path.join(SOURCE, "postproc"))
import morphogen_h5 as mh  # noqa: E402

RUN = ["-grid_n", "40,28", "-steps", "30", "-progress_every", "1000", "-png_bits", "16",
       "-png_range", "each", "-png_species", "a", "-summary", "false"]


def grey16(path):
    """16-bit grey PNG -> float array in [0, 1], row 0 at the top."""
    from PIL import Image
    with Image.open(path) as im:
        return np.asarray(im, dtype=np.float64) / 65535.0


def block_means(field, f):
    """Block means of a (ny, nx) field, edge blocks over the cells they hold (row 0 = bottom)."""
    ny, nx = field.shape
    h, w = -(-ny // f), -(-nx // f)
    out = np.empty((h, w))
    for J in range(h):
        for I in range(w):
            out[J, I] = field[J * f:(J + 1) * f, I * f:(I + 1) * f].mean()
    return out


@pytest.fixture(scope="module")
def images(tmp_path_factory):
    got = {}
    for ranks in (1, 2):
        d = tmp_path_factory.mktemp(f"np{ranks}")
        r = run(RUN + ["-png_max_size", "16", "-output_dir", str(d / "o")], cwd=d, ranks=ranks)
        assert r.returncode == 0, r.stderr
        got[ranks] = (d / "o", r.stdout)
    return got


def test_reduced_image_is_the_block_mean(images):
    out, _ = images[1]
    img = grey16(out / "a_final.png")[::-1]  # row 0 = bottom, as the field
    assert img.shape == (10, 14)  # f = ceil(40 / 16) = 3: ceil(28/3) x ceil(40/3)
    a = mh.read_checkpoint(sorted(out.glob("checkpoint_*.vtkhdf"))[-1])["fields"]["a"]
    lo, hi = a.min(), a.max()  # the range of the full-resolution field
    want = (block_means(a, 3) - lo) / (hi - lo)
    assert np.abs(img - want).max() <= 0.6 / 65535  # 16-bit rounding only
    # and not decimation: the cell at each block's corner differs by many grey levels somewhere
    assert np.abs(img - (a[::3, ::3] - lo) / (hi - lo)).max() > 50 / 65535


def test_same_pixels_on_1_and_2_ranks(images):
    for name in ("a_final.png", "a_0000030.png"):
        assert np.array_equal(grey16(images[1][0] / name), grey16(images[2][0] / name))


def test_one_output_time_line_per_writer(images):
    for _, stdout in images.values():
        for writer in ("HDF5 snapshots", "PNG images", "checkpoints"):
            lines = [ln for ln in stdout.splitlines() if ln.startswith("output: " + writer)]
            assert len(lines) == 1 and lines[0].endswith(("file)", "files)")), stdout
    assert "output: PNG images" in images[1][1] and "(2 files)" in images[1][1]


def test_fitting_grid_unchanged(workdir):
    """A grid within -png_max_size (default 1024) is drawn cell for cell."""
    r = run(RUN + ["-output_dir", str(workdir / "o")], cwd=workdir)
    assert r.returncode == 0, r.stderr
    img = grey16(workdir / "o" / "a_final.png")[::-1]
    a = mh.read_checkpoint(sorted((workdir / "o").glob("checkpoint_*.vtkhdf"))[-1])["fields"]["a"]
    assert img.shape == a.shape
    assert np.abs(img - (a - a.min()) / (a.max() - a.min())).max() <= 0.6 / 65535


@pytest.mark.parametrize("value, words", [
    ("8", ["-png_max_size 8", "0 (full resolution)", "at least 16"]),
    ("-1", ["-png_max_size", "-1"]),
    ("big", ["-png_max_size", "big"]),
])
def test_bad_png_max_size(workdir, value, words):
    r = run(RUN + ["-output_dir", str(workdir / "o"), "-png_max_size", value], cwd=workdir)
    assert r.returncode == 1, r.stdout + r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert not (workdir / "o").exists()


def test_help_lists_png_max_size(workdir):
    r = run(["-help"], cwd=workdir)
    assert "-png_max_size" in r.stdout

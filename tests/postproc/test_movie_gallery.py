"""postproc/movie.py (MP4/GIF through ffmpeg), montage.py from snapshots (one colour scale and a
colour bar, step 0 included), wavelength.py on VTKHDF snapshots, gallery.py on reduced runs."""
import json
import os
import shutil
import subprocess
import sys

import pytest

from conftest import EXE, SOURCE, run

POST = os.path.join(SOURCE, "postproc")
RUN = ["-grid_n", "32,24", "-steps", "40", "-snapshot_every", "10", "-png_every", "10",
       "-progress_every", "1000"]


def script(name, *args, timeout=300):
    return subprocess.run([sys.executable, os.path.join(POST, name)] + [str(a) for a in args],
                          capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    base = tmp_path_factory.mktemp("movie")
    out = base / "run"
    r = run(RUN + ["-output_dir", str(out)], cwd=base)
    assert r.returncode == 0, r.stderr
    return out


def frames(path):
    probe = shutil.which("ffprobe")
    assert probe, "ffprobe (Debian package ffmpeg) is required; .ci/setup installs it"
    r = subprocess.run([probe, "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                        "stream=nb_read_frames,width,height,codec_name", "-of", "json", str(path)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)["streams"][0]


def test_movie_mp4_from_snapshots(short_run, tmp_path):
    out = tmp_path / "m.mp4"
    r = script("movie.py", short_run, "--species", "a,b", "--out", out, "--fps", "5")
    assert r.returncode == 0, r.stderr
    s = frames(out)
    assert s["codec_name"] == "h264" and int(s["nb_read_frames"]) == 5  # steps 0, 10, ..., 40
    assert s["height"] >= 256 and s["width"] > 2 * s["height"]  # two species side by side


def test_movie_gif_from_pngs(short_run, tmp_path):
    out = tmp_path / "m.gif"
    r = script("movie.py", short_run, "--species", "b", "--source", "png", "--out", out, "--scale", "2")
    assert r.returncode == 0, r.stderr
    s = frames(out)
    assert s["codec_name"] == "gif" and int(s["nb_read_frames"]) == 4  # steps 10, 20, 30, 40
    assert (s["width"], s["height"]) == (64, 48)


@pytest.mark.parametrize("args, words", [
    (["--out", "x.avi"], ["--out", ".mp4, .gif"]),
    (["--fps", "0"], ["--fps"]),
    (["--scale", "99"], ["--scale 99"]),
    (["--range", "3,1"], ["--range 3,1", "LO < HI"]),
    (["--cmap", "nosuch"], ["--cmap nosuch"]),
    (["--species", "zz"], ["no species 'zz'"]),
])
def test_movie_bad_input(short_run, tmp_path, args, words):
    r = script("movie.py", short_run, *args)
    assert r.returncode != 0
    line = r.stderr.strip().splitlines()[-1]
    assert line.startswith("movie: error:"), r.stderr
    for w in words:
        assert w in line, line


def test_montage_from_snapshots(short_run, tmp_path):
    out = tmp_path / "mont.png"
    r = script("montage.py", short_run, "--species", "b", "--out", out, "--columns", "5")
    assert r.returncode == 0, r.stderr
    import matplotlib.image as mpimg
    img = mpimg.imread(str(out))
    assert img.shape[1] > 5 * 250  # five panels (steps 0..40) and a colour bar
    # step 0 is among the panels: the series starts at step 0
    sys.path.insert(0, POST)
    import morphogen_h5 as mh
    assert mh.read_metadata(mh.read_series(short_run)[0][1])["step"] == 0


def test_wavelength_reads_vtkhdf(tmp_path):
    out = tmp_path / "spots"
    r = run(["-grid_n", "64,64", "-steps", "20000", "-progress_every", "100000", "-output_dir", str(out)],
            cwd=tmp_path, ranks=2)
    assert r.returncode == 0, r.stderr
    snap = out / "morphogen_0020000.vtkhdf"
    res = script("wavelength.py", snap, "--species", "b")
    assert res.returncode == 0, res.stderr
    fields = dict(kv.split("=") for kv in res.stdout.split()[1:])
    from_png = script("wavelength.py", out / "b_final.png")
    lam_png = float(from_png.stdout.split("wavelength=")[1].split()[0])
    assert fields["species"] == "b"
    assert 12 < float(fields["wavelength_cells"]) < 24
    assert abs(float(fields["wavelength"]) - lam_png) < 0.05 * lam_png
    bad = script("wavelength.py", snap, "--species", "zz")
    assert bad.returncode != 0 and "no species 'zz'" in bad.stderr


def test_gallery_reduced(tmp_path):
    out = tmp_path / "gallery"
    r = script("gallery.py", "--decks", "turing_spots,gray_scott_garrity_f055_k062", "--out", out,
               "--exe", EXE, "--steps", "300", "--grid-div", "4", "--size", "96", timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    from PIL import Image
    for deck in ("turing_spots", "gray_scott_garrity_f055_k062"):
        with Image.open(out / f"{deck}.png") as im:
            assert max(im.size) == 96
    index = (out / "index.md").read_text()
    assert "`turing_spots.yaml`" in index and "Fig. 1" in index
    bad = script("gallery.py", "--decks", "nosuch", "--out", out, "--exe", EXE)
    assert bad.returncode != 0 and "--decks nosuch" in bad.stderr

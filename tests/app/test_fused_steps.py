"""End-to-end temporal blocking (-explicit_fuse_steps): a 2-rank run of input/turing_spots.yaml
(per-cell Gaussian parameters, periodic, 5-point) with snapshots, checkpoints, PNGs and
progress lines falling inside would-be passes, and a step count that is no multiple of k,
writes the same bytes in every HDF5 dataset and PNG as the same run with k = 1; the summary's
samples come a whole number of passes apart, so they do not shorten passes; an unsupported configuration
(zero-flux boundaries) runs one step per pass with a log line saying why. Parameter fields of
one value give the scalars' bits in every parameter form of the row kernels."""
import glob
import json
import os
import re

import h5py
import numpy as np
import pytest

from conftest import SOURCE, run

DECK = os.path.join(SOURCE, "input", "turing_spots.yaml")
COMMON = ["-grid_n", "64,64", "-steps", "203", "-snapshot_every", "37", "-png_every", "50",
          "-progress_every", "61", "-checkpoint_every", "100", "-summary", "false"]


def datasets(path):
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda n, o: out.__setitem__(n, o[()]) if isinstance(o, h5py.Dataset) else None)
    return out


@pytest.mark.parametrize("k", [4, 7])
def test_fused_run_writes_the_same_files(tmp_path, k):
    for kk in (1, k):
        p = run([DECK] + COMMON + ["-explicit_fuse_steps", str(kk), "-output_dir", f"k{kk}"],
                tmp_path, ranks=2)
        assert p.returncode == 0, p.stderr
        assert "one step per pass" not in p.stdout
    m = re.search(r"fused steps: 203 steps in (\d+) passes \(up to %d steps each\)" % k, p.stdout)
    assert m, p.stdout
    assert -(-203 // k) <= int(m.group(1)) < 203 // 2  # passes were fused, outputs ended them
    ref = sorted(glob.glob(str(tmp_path / "k1" / "*.vtkhdf")))
    assert len(ref) >= 7  # snapshots 0, 37, ..., 185, 203 and checkpoints
    for path in ref:
        a, b = datasets(path), datasets(path.replace(os.sep + "k1" + os.sep, os.sep + f"k{k}" + os.sep))
        assert a.keys() == b.keys()
        for name in a:
            assert np.asarray(a[name]).tobytes() == np.asarray(b[name]).tobytes(), (path, name)
    pngs = sorted(glob.glob(str(tmp_path / "k1" / "*.png")))
    assert pngs
    for path in pngs:
        with open(path, "rb") as f1, open(path.replace(os.sep + "k1" + os.sep, os.sep + f"k{k}" + os.sep), "rb") as f2:
            assert f1.read() == f2.read(), path


def test_summary_samples_keep_whole_passes(tmp_path):
    """A short run samples its summary up to every step; with k = 4 every 4th step, so 203
    steps take ceil(203 / 4) = 51 passes, and the final field's metrics are those of k = 1."""
    quiet = ["-grid_n", "64,64", "-steps", "203", "-png_every", "0", "-progress_every", "1000",
             "-nan_check_every", "1000"]
    summaries = {}
    for kk in (1, 4):
        p = run([DECK] + quiet + ["-explicit_fuse_steps", str(kk), "-output_dir", f"k{kk}"],
                tmp_path, ranks=2)
        assert p.returncode == 0, p.stderr
        with open(tmp_path / f"k{kk}" / "summary.json") as f:
            summaries[kk] = json.load(f)
    assert "fused steps: 203 steps in 51 passes (up to 4 steps each)" in p.stdout, p.stdout
    for s in ("a", "b"):
        assert summaries[1]["species"][s]["metrics"] == summaries[4]["species"][s]["metrics"]


def test_unsupported_falls_back_with_a_log_line(tmp_path):
    p = run([DECK, "-grid_n", "32,32", "-steps", "10", "-grid_bc", "neumann",
             "-explicit_fuse_steps", "4"], tmp_path)
    assert p.returncode == 0, p.stderr
    assert "explicit_fuse_steps 4: fused steps need periodic boundaries on both axes" in p.stdout


def test_default_fuses_large_states_in_place(tmp_path):
    """The default (-explicit_fuse_steps 0, automatic) fuses 8 steps per pass where a rank's
    state averages at least 8 MiB (2048 x 512 cells of 2 species on 2 ranks), in place, and
    writes the same bytes as one step per pass; a small grid runs one step per pass, silently."""
    big = ["-grid_n", "2048,512", "-steps", "21", "-png_every", "0", "-summary", "false",
           "-progress_every", "1000"]
    for name, extra in (("auto", []), ("k1", ["-explicit_fuse_steps", "1"])):
        p = run([DECK] + big + extra + ["-output_dir", name], tmp_path, ranks=2)
        assert p.returncode == 0, p.stderr
        if name == "auto":
            assert "explicit_fuse_steps auto: up to 8 steps per pass" in p.stdout, p.stdout
            assert "fused steps: 21 steps in 3 passes (up to 8 steps each)" in p.stdout, p.stdout
        else:
            assert "fused steps" not in p.stdout
    a = datasets(str(tmp_path / "k1" / "morphogen_0000021.vtkhdf"))
    b = datasets(str(tmp_path / "auto" / "morphogen_0000021.vtkhdf"))
    assert a.keys() == b.keys() and a
    for name in a:
        assert np.asarray(a[name]).tobytes() == np.asarray(b[name]).tobytes(), name
    p = run([DECK, "-grid_n", "64,64", "-steps", "10", "-summary", "false"], tmp_path, ranks=2)
    assert p.returncode == 0, p.stderr
    assert "fuse" not in p.stdout


# Each parameter form of the row kernels (which parameters are per-cell rows, the others
# scalars kept in registers): a field of one value everywhere gives the bits of the scalar, for
# every subset of Turing's three parameters, in one-step passes (64^2) and in fused in-place
# passes that read the fields' rows where they lie (2048x512 on 2 ranks: the default fuses).
CONSTANT_FIELDS = {"alpha": "12 + 0*x", "beta": "16 + 0*y", "s": "1/128 + 0*x"}


def species(path):
    with h5py.File(path, "r") as f:
        return {s: f["VTKHDF/PointData/" + s][()] for s in ("a", "b")}


@pytest.mark.parametrize("grid,ranks", [("64,64", 1), ("2048,512", 2)])
def test_constant_fields_give_the_scalar_bits(tmp_path, grid, ranks):
    args = [DECK, "-grid_n", grid, "-steps", "24", "-summary", "false", "-png_every", "0",
            "-progress_every", "1000", "-params_alpha", "12", "-params_beta", "16",
            "-params_s", "1/128", "-init_a", "4 + 0.1*sin(0.3*x)*cos(0.2*y)"]
    subsets = [(), ("alpha",), ("beta",), ("s",), ("alpha", "beta"), ("beta", "s"),
               ("alpha", "beta", "s")]
    results = []
    for sub in subsets:
        extra = []
        for name in sub:
            extra += ["-params_" + name, CONSTANT_FIELDS[name]]
        out = "p_" + ("_".join(sub) or "scalar")
        p = run(args + extra + ["-output_dir", out], tmp_path, ranks=ranks)
        assert p.returncode == 0, p.stderr
        assert ("explicit_fuse_steps auto" in p.stdout) == (ranks == 2), p.stdout
        results.append(species(str(tmp_path / out / "morphogen_0000024.vtkhdf")))
    for sub, r in zip(subsets[1:], results[1:]):
        for s in ("a", "b"):
            assert r[s].tobytes() == results[0][s].tobytes(), (sub, s)

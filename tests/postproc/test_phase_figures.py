"""postproc/phase_diagram.py (sweep mosaic and class map) and postproc/ingrid_diagram.py (in-grid
parameter map): a tiny real sweep, hand-made sweep.json / run directories, and bad input.

Run by CTest with MORPHOGEN_EXE, MORPHOGEN_MPIEXEC and MORPHOGEN_SOURCE_DIR set; by hand:
    MORPHOGEN_EXE=build/morphogen /usr/bin/python3 -m pytest -q tests/postproc/test_phase_figures.py
"""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import matplotlib

matplotlib.use("Agg")
import matplotlib.colors as mcolors  # noqa: E402
import matplotlib.image as mpimg  # noqa: E402

SOURCE = os.environ.get("MORPHOGEN_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("MORPHOGEN_EXE", os.path.join(SOURCE, "build", "morphogen"))
MPIEXEC = os.environ.get("MORPHOGEN_MPIEXEC", "mpiexec")
POSTPROC = os.path.join(SOURCE, "postproc")
PHASE = os.path.join(POSTPROC, "phase_diagram.py")
INGRID = os.path.join(POSTPROC, "ingrid_diagram.py")

sys.path.insert(0, POSTPROC)
import ingrid_diagram as ig  # noqa: E402
import phase_diagram as pd  # noqa: E402


def script(path, *args):
    return subprocess.run([sys.executable, path] + [str(a) for a in args],
                          capture_output=True, text=True, timeout=300)


def rgb(img, row, col, r=2):
    """Median colour of a small patch (the PNG as floats in 0..1)."""
    patch = img[row - r:row + r + 1, col - r:col + r + 1, :3].reshape(-1, 3)
    return np.median(patch, axis=0)


def not_blank(img):
    """Many distinct colours and real contrast."""
    flat = np.round(img[..., :3].reshape(-1, 3) * 255).astype(int)
    return len({tuple(c) for c in flat[:: max(1, len(flat) // 20000)]}) > 20 and img[..., :3].std() > 0.05


# ----------------------------------------------------------------------------------------------
# A real sweep: 4 x 4 Gray-Scott points on 32^2 grids, 2 ranks
# ----------------------------------------------------------------------------------------------

GS_DECK = """\
model: gray_scott
grid:
  n: 32,32
  L: 0.3125
params:
  F: 0.035
  k: 0.065
D:
  a: 1e-5
  b: 2e-5
init:
  a: 0.25*square(Lx/2, Ly/2, 6*hx) +- 1%
  b: 1 - 0.5*square(Lx/2, Ly/2, 6*hx) +- 1%
dt: 1
steps: 3000
output_dir: sweep
sweep:
  axes: params_F,params_k
  params_F: linspace(0.02, 0.05, 4)
  params_k: linspace(0.05, 0.065, 4)
  species: a
"""


@pytest.fixture(scope="module")
def gs_sweep(tmp_path_factory):
    if not os.path.isfile(EXE):
        pytest.skip(f"{EXE}: not built")
    d = tmp_path_factory.mktemp("gs")
    (d / "gs.yaml").write_text(GS_DECK)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    proc = subprocess.run([MPIEXEC, "--oversubscribe", "-n", "2", EXE, "sweep", "gs.yaml"], cwd=d,
                          capture_output=True, text=True, timeout=240, env=env)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert (d / "sweep" / "sweep.json").is_file()
    return d / "sweep"


def test_sweep_mosaic_and_class_map(gs_sweep):
    res = script(PHASE, gs_sweep, "--thumb-px", 48)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("phase_diagram:") and "16/16 points" in lines[0]
    mosaic = mpimg.imread(str(gs_sweep / "phase_mosaic.png"))
    classes = mpimg.imread(str(gs_sweep / "phase_classes.png"))
    # 4 x 4 thumbnails of 48 px plus margins; the class map has its legend on the right
    assert 4 * 48 <= mosaic.shape[1] <= 4 * 48 + 400 and 4 * 48 <= mosaic.shape[0] <= 4 * 48 + 300, mosaic.shape
    assert 200 <= classes.shape[1] <= 1400 and 150 <= classes.shape[0] <= 1000, classes.shape
    assert classes.shape[1] > classes.shape[0]
    assert not_blank(mosaic) and classes[..., :3].std() > 0.05


def test_sweep_out_prefix_and_species(gs_sweep, tmp_path):
    res = script(PHASE, gs_sweep, "--species", "b", "--out-prefix", tmp_path / "x")
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "x_mosaic.png").is_file() and (tmp_path / "x_classes.png").is_file()
    bad = script(PHASE, gs_sweep, "--species", "nosuch", "--out-prefix", tmp_path / "y")
    assert bad.returncode == 1 and "nosuch" in bad.stderr and len(bad.stderr.strip().splitlines()) == 1


# ----------------------------------------------------------------------------------------------
# Hand-made sweep.json: class colours at known positions, stability contours, axis kinds
# ----------------------------------------------------------------------------------------------

def synthetic_sweep(d, classes, F, k, stability=True):
    """sweep.json with the given {index: class}, no field files."""
    recs = []
    for p, c in classes.items():
        i0, i1 = p % len(F), p // len(F)
        recs.append({"index": p, "params": {"params_F": F[i0], "params_k": k[i1]}, "class": c,
                     "reason": "hand-made", "species": "a", "model": "gray_scott",
                     "file": f"points/point_{p:06d}.vtkhdf"})
    sw = {"axes": [{"option": "params_F", "values": F}, {"option": "params_k", "values": k}],
          "points": len(F) * len(k), "finished": len(recs), "classes": {}, "base_options": "",
          "records": recs}
    if stability:
        rF = [float(v) for v in np.linspace(F[0], F[-1], 4 * (len(F) - 1) + 1)]
        rk = [float(v) for v in np.linspace(k[0], k[-1], 4 * (len(k) - 1) + 1)]
        # first axis fastest; Turing where F > 0.0235 (between the 2nd and 3rd columns),
        # Hopf where k > 0.0465 (between the two rows)
        sw["stability_map"] = {"axes": [rF, rk],
                               "turing": [f > 0.0235 for kk in rk for f in rF],
                               "hopf": [kk > 0.0465 for kk in rk for f in rF],
                               "wavelength": [None] * (len(rF) * len(rk))}
    d.mkdir(parents=True, exist_ok=True)
    (d / "sweep.json").write_text(json.dumps(sw))
    return sw


def test_class_map_colours_at_point_positions(tmp_path):
    F, k = [0.01, 0.02, 0.03], [0.04, 0.05]
    classes = {0: "spots", 1: "stripes", 2: "uniform", 3: "labyrinth", 4: "holes"}  # 5: not run
    d = tmp_path / "syn"
    synthetic_sweep(d, classes, F, k)
    sweep = pd.Sweep(str(d), pd.load_sweep(str(d)))
    out = tmp_path / "classes.png"
    centres, drawn = pd.write_class_map(sweep, str(out))
    assert drawn == {"turing": True, "hopf": True}
    img = mpimg.imread(str(out))
    for p in range(6):
        row, col = centres[p]
        want = mcolors.to_rgb(pd.CLASS_COLOURS[classes[p]] if p in classes else pd.MISSING_COLOUR)
        assert np.allclose(rgb(img, row, col), want, atol=0.02), (p, rgb(img, row, col), want)
    # the Turing boundary: black pixels on the row of point 0 between columns 2 and 3 (F 0.02 | 0.03)
    row = centres[0][0]
    between = img[row, centres[1][1] + 3:centres[2][1] - 3, :3]
    assert (between.max(axis=1) < 0.15).any()
    # the Hopf boundary (dashed, its own colour) crosses the column of point 0 between the rows
    col = centres[0][1]
    hopf = mcolors.to_rgb(pd.HOPF_COLOUR)
    seg = img[centres[3][0] + 3:centres[0][0] - 3, col - 6:col + 7, :3].reshape(-1, 3)
    assert (np.abs(seg - hopf).max(axis=1) < 0.1).any()


def test_class_map_cli_on_unfinished_sweep(tmp_path):
    d = tmp_path / "syn"
    synthetic_sweep(d, {0: "spots", 4: "oscillating"}, [0.01, 0.02, 0.03], [0.04, 0.05])
    res = script(PHASE, d)
    assert res.returncode == 0, res.stderr
    assert "2/6 points" in res.stdout and "boundaries: turing, hopf" in res.stdout
    assert (d / "phase_mosaic.png").is_file() and (d / "phase_classes.png").is_file()


def test_one_and_three_axis_sweeps(tmp_path):
    one = tmp_path / "one"
    one.mkdir()
    s = [0.001, 0.01, 0.1, 1.0]
    (one / "sweep.json").write_text(json.dumps({
        "axes": [{"option": "params_s", "values": s}], "points": 4, "finished": 4,
        "records": [{"index": p, "params": {"params_s": v}, "class": "spots"} for p, v in enumerate(s)],
        "stability_map": {"axes": [[float(v) for v in np.logspace(-3, 0, 13)]], "turing": [i < 6 for i in range(13)],
                          "hopf": [False] * 13}}))
    res = script(PHASE, one)
    assert res.returncode == 0, res.stderr
    assert "s (4, log)" in res.stdout and "boundaries: turing" in res.stdout
    img = mpimg.imread(str(one / "phase_classes.png"))
    assert img.shape[1] > 2 * img.shape[0]  # a strip

    three = tmp_path / "three"
    three.mkdir()
    recs = [{"index": p, "class": ["spots", "stripes", "uniform"][p % 3]} for p in range(12)]
    (three / "sweep.json").write_text(json.dumps({
        "axes": [{"option": "params_F", "values": [0.01, 0.02]}, {"option": "params_k", "values": [0.05, 0.06]},
                 {"option": "D_b", "values": [1e-5, 2e-5, 3e-5]}], "points": 12, "records": recs,
        "stability_map": {}}))
    res = script(PHASE, three)
    assert res.returncode == 0, res.stderr
    assert "no stability map" in res.stdout
    img = mpimg.imread(str(three / "phase_classes.png"))
    assert img.shape[1] > 2.5 * img.shape[0]  # three panels side by side


def test_axis_kinds():
    assert pd.axis_kind(list(np.linspace(0.01, 0.07, 16))) == "linear"
    assert pd.axis_kind(list(np.logspace(-3, -1, 5))) == "log"
    assert pd.axis_kind([1, 2, 5, 10]) == "index"
    assert pd.axis_kind([0.03]) == "index"
    assert pd.Axis("params_F", [0.1, 0.2]).label == "F" and pd.Axis("D_b", [1, 2]).label == "D_b"


# ----------------------------------------------------------------------------------------------
# In-grid diagram
# ----------------------------------------------------------------------------------------------

INGRID_OPTIONS = """\
# Options of this run, resolved (hand-written for the test)
grid_n: "64,48"
grid_L: "64,48"
grid_bc: "neumann"
model: "turing"
params_alpha: "8 + 12*i/(nx-1)"
params_beta: "8 + 12*j/(ny-1) +- 0.1% gauss"
params_s: "1/128"
D_a: "0.0625"
D_b: "0.25"
init_a: "4"
init_b: "4"
output_name: "morphogen"
"""


def write_vtkhdf(path, fields, spacing=(1.0, 1.0), layout="PointData"):
    """A 2-D snapshot as morphogen writes it (PointData on the cell centres), or with layout
    "CellData" as an intermediate development version did (the cell corners, Origin 0)."""
    import h5py

    ny, nx = next(iter(fields.values())).shape
    with h5py.File(path, "w") as f:
        g = f.create_group("VTKHDF")
        g.attrs["Version"] = np.array([1, 0], dtype=np.int32)
        g.attrs.create("Type", np.bytes_("ImageData"), dtype=h5py.string_dtype("ascii", len("ImageData")))
        if layout == "PointData":
            g.attrs["WholeExtent"] = np.array([0, nx - 1, 0, ny - 1, 0, 0], dtype=np.int32)
            g.attrs["Origin"] = np.array([0.5 * spacing[0], 0.5 * spacing[1], 0.0])  # cell centres
        else:
            g.attrs["WholeExtent"] = np.array([0, nx, 0, ny, 0, 0], dtype=np.int32)  # cell corners
            g.attrs["Origin"] = np.zeros(3)
        g.attrs["Spacing"] = np.array([spacing[0], spacing[1], spacing[0]])
        g.attrs["Direction"] = np.eye(3).ravel()
        pdg = g.create_group(layout)
        for name, a in fields.items():
            pdg.create_dataset(name, data=a[None].astype(np.float32))
        f.create_group("morphogen")


def ingrid_run(d, options=INGRID_OPTIONS):
    d.mkdir(parents=True, exist_ok=True)
    (d / "options_used.yaml").write_text(options)
    jj, ii = np.mgrid[0:48, 0:64]
    a = 4 + np.sin(ii / 3.0) * np.cos(jj / 4.0) * (ii / 63.0)
    write_vtkhdf(d / "morphogen_0001000.vtkhdf", {"a": a, "b": 16 / (a + 1)})
    write_vtkhdf(d / "morphogen_0000000.vtkhdf", {"a": np.full((48, 64), 4.0), "b": np.full((48, 64), 4.0)})


def test_read_field_reads_both_layouts(tmp_path):
    pytest.importorskip("h5py")
    jj, ii = np.mgrid[0:6, 0:8]
    a = (ii + 10.0 * jj).astype(np.float32)
    for layout in ("PointData", "CellData"):
        path = tmp_path / f"{layout}.vtkhdf"
        write_vtkhdf(path, {"a": a, "b": -a}, layout=layout)
        arr, species = pd.read_field(str(path), None)
        assert species == "a" and np.array_equal(arr, a), layout
        assert np.array_equal(pd.read_field(str(path), "b")[0], -a), layout


def test_detect_axes():
    opts = ig.read_options_text(INGRID_OPTIONS)
    assert opts["params_beta"] == "8 + 12*j/(ny-1) +- 0.1% gauss" and opts["grid_n"] == "64,48"
    axes = ig.detect_axes(opts)
    assert set(axes) == {"x", "y"}
    assert axes["x"][0] == "alpha" and axes["x"][1:] == pytest.approx((8, 20))
    assert axes["y"][0] == "beta" and axes["y"][1:] == pytest.approx((8, 20))
    # positions (cell centres x = (i + 1/2) h), a y-only ramp, a constant
    axes = ig.detect_axes({"grid_n": "256,256", "grid_L": "256", "params_alpha": "12 +- 0.01% gauss",
                           "params_beta": "15.85 + 0.5*y/Ly"})
    assert set(axes) == {"y"} and axes["y"][0] == "beta"
    assert axes["y"][1:] == pytest.approx((15.85 + 0.5 * 0.5 / 256, 15.85 + 0.5 * 255.5 / 256))
    # not linear, diagonal, or not a plain arithmetic expression: no axis, and nothing executed
    flag = "/tmp/_ingrid_must_not_exist"
    for expr in ("8 + i*i/nx", "8 + i + j", "sin(i)", "8 + 12*i^2", "png(\"a.png\", 1, 2)",
                 f"__import__('os').system('touch {flag}')", "(lambda: 1)()", "i if 1 else j"):
        assert ig.detect_axes({"grid_n": "64,64", "params_alpha": expr}) == {}, expr
    assert not os.path.exists(flag)


def test_turing_closed_form():
    # Turk's alpha = 12, beta = 16 is exactly on the Turing threshold (D_a 1/16, D_b 1/4)
    t, tr, margin = ig.turing_model_stability([12, 12, 12, 12], [15.3, 15.9, 16.0, 16.1], 1 / 16, 1 / 4)
    assert list(t) == [False, True, False, False]
    assert tr[0] > 0 and tr[1] < 0  # 15.3: oscillatory side of the Hopf line (alpha > delta^2)
    assert margin[2] == pytest.approx(0, abs=1e-12)


def test_ingrid_figure_from_run_dir(tmp_path):
    d = tmp_path / "run"
    ingrid_run(d)
    res = script(INGRID, d)
    assert res.returncode == 0, res.stderr
    line = res.stdout.strip()
    assert len(line.splitlines()) == 1
    assert "morphogen_0001000.vtkhdf" in line  # the newest snapshot
    assert "x = alpha 8..20" in line and "y = beta 8..20" in line and "Turing" in line
    img = mpimg.imread(str(d / "ingrid_a.png"))
    assert img.shape[0] > 200 and img.shape[1] > 300 and not_blank(img)
    # explicit flags and a snapshot file, species b, own output
    out = tmp_path / "flags.png"
    res = script(INGRID, d / "morphogen_0001000.vtkhdf", "--species", "b", "--x-param", "alpha",
                 "--x-range", 0, 1, "--y-param", "beta", "--out", out, "--no-stability")
    assert res.returncode == 0, res.stderr
    assert "x = alpha 0..1" in res.stdout and out.is_file()


def test_ingrid_needs_flags_when_nothing_varies(tmp_path):
    d = tmp_path / "flat"
    ingrid_run(d, INGRID_OPTIONS.replace('"8 + 12*i/(nx-1)"', '"12"').replace(
        '"8 + 12*j/(ny-1) +- 0.1% gauss"', '"16 +- 0.1% gauss"'))
    res = script(INGRID, d)
    assert res.returncode == 1 and "--x-param" in res.stderr and len(res.stderr.strip().splitlines()) == 1
    res = script(INGRID, d, "--x-param", "alpha", "--x-range", 8, 20)
    assert res.returncode == 0, res.stderr


# ----------------------------------------------------------------------------------------------
# Bad input
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("path", [PHASE, INGRID])
def test_missing_dir(tmp_path, path):
    res = script(path, tmp_path / "nope")
    assert res.returncode == 1
    assert len(res.stderr.strip().splitlines()) == 1 and "no such" in res.stderr and "Traceback" not in res.stderr


def test_bad_sweep_dirs(tmp_path):
    res = script(PHASE, tmp_path)  # no sweep.json
    assert res.returncode == 1 and "sweep.json" in res.stderr and len(res.stderr.strip().splitlines()) == 1
    (tmp_path / "sweep.json").write_text("{not json")
    res = script(PHASE, tmp_path)
    assert res.returncode == 1 and "cannot read" in res.stderr and len(res.stderr.strip().splitlines()) == 1
    (tmp_path / "sweep.json").write_text(json.dumps({"axes": [{"option": f"params_{c}", "values": [1, 2]}
                                                              for c in "abcd"], "records": []}))
    res = script(PHASE, tmp_path)
    assert res.returncode == 1 and "4 axes" in res.stderr
    empty = tmp_path / "empty"
    empty.mkdir()
    res = script(INGRID, empty)
    assert res.returncode == 1 and "snapshot" in res.stderr and len(res.stderr.strip().splitlines()) == 1

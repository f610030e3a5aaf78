"""postproc/render_surface.py: a 2-D snapshot as a texture on a parametric surface, to a PNG.

The snapshots are synthetic VTKHDF files written here with h5py in the layout of
src/io/vtkhdf_file.cpp (and, when the morphogen executable is built, one real run). The renders
run in pvbatch subprocesses (h5py and ParaView's VTK load different HDF5 libraries: never both in
one process; this process imports only render_surface's pure-Python expression compiler).
The OpenGL backend runs under xvfb-run when there is no $DISPLAY (Debian's ParaView renders only
through X); the matplotlib backend needs no display. Skipped when pvbatch is not installed.
"""
import math
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

from conftest import EXE, SOURCE, run  # tests/postproc/conftest.py

sys.path.insert(0, os.path.join(SOURCE, "postproc"))
import render_surface as rs  # noqa: E402  (pure Python at import: no VTK, no h5py)

h5py = pytest.importorskip("h5py")

PVBATCH = shutil.which("pvbatch")
XVFB_RUN = shutil.which("xvfb-run")
SCRIPT = os.path.join(SOURCE, "postproc", "render_surface.py")

pytestmark = pytest.mark.skipif(PVBATCH is None,
                                reason="pvbatch not installed (Debian: paraview, python3-paraview; "
                                       ".ci/setup installs them)")

TORUS = ["--surface-x", "(3 + cos(2*_pi*v/Ly)) * cos(2*_pi*u/Lx)",
         "--surface-y", "(3 + cos(2*_pi*v/Ly)) * sin(2*_pi*u/Lx)",
         "--surface-z", "sin(2*pi*v/Ly)"]
CYLINDER = ["--surface-x", "cos(2*_pi*u/Lx)", "--surface-y", "sin(2*_pi*u/Lx)",
            "--surface-z", "v/Lx*2*_pi"]


def write_snapshot(path, n, L, time=1.5, step=10, layout="PointData"):
    """A VTKHDF ImageData snapshot as morphogen writes it: species a (float32, a checkerboard of
    sines) and b (float64); 2-D when len(n) == 2 (datasets (1, ny, nx)), else 3-D. layout
    "PointData": points at the cell centres (WholeExtent 0..n-1, Origin h/2); "CellData": the
    layout of an intermediate development version (the cell corners, WholeExtent 0..n, Origin 0)."""
    dim = len(n)
    n3 = list(n) + [1] * (3 - dim)
    h = [L[a] / n[a] for a in range(dim)]
    h3 = h + [h[0]] * (3 - dim)
    o3 = [x / 2 for x in h] + [0.0] * (3 - dim)
    x = [o3[a] + h3[a] * np.arange(n3[a]) for a in range(3)]
    Z, Y, X = np.meshgrid(x[2], x[1], x[0], indexing="ij")
    a = np.sin(2 * np.pi * 4 * X / L[0]) * np.cos(2 * np.pi * 2 * Y / L[1]) + 0.1 * Z
    with h5py.File(path, "w") as f:
        g = f.create_group("VTKHDF")
        g.attrs["Version"] = np.array([1, 0], dtype=np.int32)
        g.attrs.create("Type", np.bytes_("ImageData"), dtype=h5py.string_dtype("ascii", 9))
        if layout == "PointData":
            extent = [0, n3[0] - 1, 0, n3[1] - 1, 0, n3[2] - 1]
            g.attrs["Origin"] = np.array(o3)
        else:  # the cell corners
            extent = [0, n[0], 0, n[1], 0, n[2] if dim == 3 else 0]
            g.attrs["Origin"] = np.zeros(3)
        g.attrs["WholeExtent"] = np.array(extent, dtype=np.int32)
        g.attrs["Spacing"] = np.array(h3)
        g.attrs["Direction"] = np.eye(3).ravel()
        pd = g.create_group(layout)
        pd["a"] = a.astype(np.float32)
        pd["b"] = 1.0 + a ** 2
        m = f.create_group("morphogen")
        m.attrs["time"] = time
        m.attrs["step"] = step
    return path


@pytest.fixture(scope="module")
def snaps(tmp_path_factory):
    d = tmp_path_factory.mktemp("surface")
    return {"2d": write_snapshot(d / "syn_0000010.vtkhdf", [64, 32], [64.0, 32.0]),
            "2d_cells": write_snapshot(d / "cells_0000010.vtkhdf", [64, 32], [64.0, 32.0],
                                       layout="CellData"),
            "3d": write_snapshot(d / "vol_0000010.vtkhdf", [8, 6, 4], [8.0, 6.0, 4.0])}


def render(args, display=False, timeout=240):
    cmd = [PVBATCH, SCRIPT] + [str(a) for a in args]
    env = dict(os.environ)
    if display:
        cmd += ["--backend", "gl"]
        if not os.environ.get("DISPLAY"):
            if XVFB_RUN is None:
                pytest.skip("no X display and no xvfb-run (Debian: xvfb, xauth): the gl backend "
                            "needs X; the image backend is tested without it")
            cmd = [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24 -noreset"] + cmd
    elif "--backend" not in args:
        cmd += ["--backend", "image"]
    try:
        return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)
    except subprocess.TimeoutExpired as e:
        err = e.stderr.decode() if isinstance(e.stderr, bytes) else (e.stderr or "")
        pytest.fail(f"{' '.join(cmd)}: no answer in {timeout} s (ParaView crashed?)\n{err[-3000:]}")


def assert_picture(path, size, min_colours=20):
    """The PNG exists, has the requested size, and is not blank: many distinct colours and a
    good share of pixels that are not the background."""
    import matplotlib.image as mpimg

    assert os.path.exists(path), f"{path}: not written"
    img = mpimg.imread(str(path))
    assert (img.shape[1], img.shape[0]) == tuple(size), f"{path}: {img.shape}"
    rgb = img[..., :3]
    colours = np.unique((rgb.reshape(-1, 3) * 255).round().astype(np.uint8), axis=0)
    not_bg = np.any(np.abs(rgb - rgb[0, 0]) > 0.05, axis=-1).mean()
    assert len(colours) >= min_colours and not_bg > 0.1, \
        f"{path}: {len(colours)} colours, {not_bg:.2f} of the pixels not background"
    return rgb


# ------------------------------------------------------------------------ expression compiler

@pytest.mark.parametrize("text,expected", [
    ("-2^2", lambda u, v: -4.0), ("2^3^2", lambda u, v: 512.0),
    ("log(100)", lambda u, v: math.log(100)),
    ("rint(2.5)", lambda u, v: 3.0), ("min(3, u, 2)", lambda u, v: np.minimum(u, 2)),
    ("avg(1, 2, 3)", lambda u, v: 2.0), ("u > 1 ? u : v", lambda u, v: np.where(u > 1, u, v)),
    ("u < 1 && v > 1", lambda u, v: ((u < 1) & (v > 1)).astype(float)),
    ("(3 + cos(2*_pi*v/Ly)) * cos(2*_pi*u/Lx)",
     lambda u, v: (3 + np.cos(2 * np.pi * v / 5)) * np.cos(2 * np.pi * u / 4)),
    ("2*-u + 1e-3*v^2 - .5", lambda u, v: -2 * u + 1e-3 * v ** 2 - 0.5),
    ("sin(pi*u) + _e", lambda u, v: np.sin(np.pi * u) + np.e),
])
def test_expressions_follow_muparser(text, expected):
    u, v = np.array([0.3, 1.7, 2.5]), np.array([2.0, 0.5, 1.0])
    got = rs.compile_expression(text, constants={"Lx": 4.0, "Ly": 5.0})(u=u, v=v)
    want = np.broadcast_to(expected(u, v), u.shape)
    np.testing.assert_allclose(np.broadcast_to(got, u.shape), want, rtol=1e-14, err_msg=text)


@pytest.mark.parametrize("text,message", [
    ("sin(u", "expected ')'"), ("u*", "unexpected end"), ("w + 1", "unknown name 'w'"),
    ("", "empty"), ("foo(u)", "unknown name 'foo'"), ("u v", "unexpected 'v'"),
    ("sin(u, v)", "takes 1 argument"), ("3 $ 4", "unexpected character '$'"),
    ("__import__('os')", "unexpected character"), ("__import__", "unknown name '__import__'"),
])
def test_bad_expressions(text, message):
    with pytest.raises(rs.ExpressionError, match=re.escape(message)):
        rs.compile_expression(text)(u=np.zeros(1), v=np.zeros(1))


# --------------------------------------------------------------------------------- rendering

def test_torus_image_backend(snaps, tmp_path):
    out = tmp_path / "sub" / "torus.png"
    proc = render([snaps["2d"], "--species", "a", *TORUS, "--output", out, "--size", "320x240",
                   "--view", "30,40"])
    assert proc.returncode == 0, f"{proc.stdout}\n{proc.stderr[-3000:]}"
    assert proc.stdout.strip().splitlines()[-1] == str(out)
    assert_picture(out, (320, 240))


def test_both_file_layouts_render_alike(snaps, tmp_path):
    """A snapshot of the CellData layout (an intermediate development version) maps exactly as
    the same values in the PointData layout morphogen writes."""
    pics = []
    for key in ("2d", "2d_cells"):
        out = tmp_path / f"{key}.png"
        proc = render([snaps[key], "--species", "a", *CYLINDER, "--output", out, "--size",
                       "200x160", "--no-time"])
        assert proc.returncode == 0, f"{proc.stdout}\n{proc.stderr[-3000:]}"
        pics.append(assert_picture(out, (200, 160)))
    assert np.array_equal(pics[0], pics[1])


def test_torus_gl_backend(snaps, tmp_path):
    out = tmp_path / "torus_gl.png"
    proc = render([snaps["2d"], "--species", "b", *TORUS, "--output", out, "--size", "360x270",
                   "--view", "-60,35"], display=True)
    assert proc.returncode == 0, f"{proc.stdout}\n{proc.stderr[-3000:]}"
    rgb = assert_picture(out, (360, 270))
    # the texture, not one flat colour: the torus's pixels cover much of the colour map
    surface = rgb[np.any(np.abs(rgb - rgb[0, 0]) > 0.05, axis=-1)]
    assert np.ptp(surface.mean(axis=-1)) > 0.3


def test_views_differ_and_plane_default(snaps, tmp_path):
    a, b, p = tmp_path / "a.png", tmp_path / "b.png", tmp_path / "plane.png"
    for out, view in ((a, "0,10"), (b, "90,60")):
        proc = render([snaps["2d"], *CYLINDER, "--output", out, "--size", "200x160", "--view", view,
                       "--no-bar", "--no-time"])
        assert proc.returncode == 0, proc.stderr[-3000:]
    assert not np.array_equal(assert_picture(a, (200, 160)), assert_picture(b, (200, 160)))
    proc = render([snaps["2d"], "--output", p, "--size", "200x160", "--view", "0,90"])  # the plane
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert_picture(p, (200, 160))


def test_bad_input(snaps, tmp_path):
    out = str(tmp_path / "x.png")
    cases = [
        (["--surface-y", "sin(v", "--output", out], "--surface-y sin(v"),
        (["--surface-z", "w*u", "--output", out], "unknown name 'w'"),
        (["--surface-z", "sqrt(u - 10)", "--output", out],
         "--surface-z sqrt(u - 10): not finite at (u, v)"),
        (["--species", "zz", "--output", out], "no species zz"),
    ]
    for extra, message in cases:
        proc = render([snaps["2d"], *extra])
        assert proc.returncode == 1, proc.stderr[-2000:]
        err = proc.stderr.strip()
        assert err.startswith("render_surface: error:") and message in err, err
        assert len(err.splitlines()) == 1, err
    proc = render([snaps["3d"], "--output", out])
    assert proc.returncode == 1 and "2-D runs only" in proc.stderr, proc.stderr[-2000:]
    proc = render([tmp_path / "missing.vtkhdf"])
    assert proc.returncode == 1 and "missing.vtkhdf" in proc.stderr, proc.stderr[-2000:]
    proc = render([snaps["2d"], "--view", "10,100"])
    assert proc.returncode == 2 and "--view" in proc.stderr
    assert not os.path.exists(out)


@pytest.mark.skipif(not os.path.exists(EXE), reason="morphogen executable not built")
def test_real_run_on_cylinder(tmp_path):
    d = tmp_path / "run"
    proc = run(["-grid_n", "32,32", "-steps", "20", "-snapshot_every", "10", "-output_dir", str(d)],
               cwd=tmp_path)
    assert proc.returncode == 0, f"{proc.stdout}\n{proc.stderr}"
    for source, frame in ((d, "-1"), (d / "morphogen.xmf", "0")):
        out = tmp_path / f"cyl_{frame}.png"
        proc = render([source, "--frame", frame, "--species", "b", *CYLINDER, "--output", out,
                       "--size", "240x200"])
        assert proc.returncode == 0, f"{proc.stdout}\n{proc.stderr[-3000:]}"
        assert_picture(out, (240, 200), min_colours=10)

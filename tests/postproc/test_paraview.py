"""ParaView (Debian 12's 5.11, the project's VTK) reads morphogen's output; the pvbatch tools work.

Runs 2-D and 3-D morphogen runs on 1 and 2 ranks, then, in pvbatch subprocesses (h5py and
ParaView's VTK load different HDF5 libraries: never both in one process):
- opens each run's .xmf by absolute path and by ./NAME.xmf (cwd = the run directory) with
  OpenDataFile (Xdmf3ReaderS) and, for 3-D runs, the older XDMF (xdmf2) reader (it reads no cell
  data of flat 2-D images), and checks the image of the cell corners (extent 0..n, origin 0,
  bounds exactly the domain 0 .. n h), spacing, cell-data array names, sizes (one value per
  cell) and types, every value against h5py (postproc/morphogen_h5.py) and the times;
- opens .vtkhdf snapshots directly with VTK's vtkHDFReader and ParaView's VTKHDFReader proxy:
  point data on the cell centres (extent 0..n-1, bounds h/2 .. (n - 1/2) h), every array and
  value. 3-D always; 2-D only where VTK is not 9.2 (ParaView 5.11): VTK 9.2's reader overruns a
  heap buffer on any image with a flat axis (vtkHDFReader::Read copies the 6-entry update extent
  into the 4 entries ReduceDimension returns) and aborts, whatever the file holds;
- converts runs with postproc/vtkhdf_to_vti.py and re-reads the .pvd / .vti, also a series
  mixing snapshots of the CellData layout (an intermediate development version) and PointData;
- renders 2-D and 3-D series with postproc/render.py (default backend; the OpenGL backend too
  on $DISPLAY or a private Xvfb when one is installed: Debian's ParaView renders only through X).
Skipped when pvbatch is not installed.
"""
import json
import os
import re
import select
import shutil
import subprocess
import sys

import numpy as np
import pytest

from conftest import SOURCE, launch_runs  # tests/postproc/conftest.py

sys.path.insert(0, os.path.join(SOURCE, "postproc"))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from vtkhdf_layouts import to_celldata_layout  # noqa: E402
import morphogen_h5 as mh  # noqa: E402  (h5py, in this process only)

PVBATCH = shutil.which("pvbatch")
PVPYTHON = shutil.which("pvpython")
XVFB = shutil.which("Xvfb")
CONVERTER = os.path.join(SOURCE, "postproc", "vtkhdf_to_vti.py")
RENDER = os.path.join(SOURCE, "postproc", "render.py")
EPS32 = float(np.finfo(np.float32).eps)

pytestmark = pytest.mark.skipif(PVBATCH is None, reason="pvbatch not installed (Debian: paraview, "
                                                        "python3-paraview; .ci/setup installs them)")

# name: (cells, lengths, extra options, ranks); lengths chosen so hx, hy (and hz) all differ
RUNS = {
    "2d": ([32, 24], [32.0, 12.0], ["-dt", "0.2"], 1),
    "2d_np2": ([32, 24], [32.0, 12.0], ["-dt", "0.2"], 2),
    "3d": ([16, 12, 8], [16.0, 6.0, 2.0], ["-dt", "0.02"], 1),
    "3d_np2": ([16, 12, 8], [16.0, 6.0, 2.0], ["-dt", "0.02", "-snapshot_precision", "float64",
                                                 "-output_name", "vol"], 2),
}
STEPS, EVERY = 20, 10
SPECIES = ["a", "b"]

READ_SCRIPT = r'''
import json, os, sys
from paraview import simple
from vtkmodules.util.numpy_support import vtk_to_numpy

def image_of(obj):
    while obj is not None and obj.IsA("vtkMultiBlockDataSet"):
        obj = obj.GetBlock(0)
    return obj

def describe(d):
    if d is None:
        return None
    out = {"class": d.GetClassName(), "image": bool(d.IsA("vtkImageData")),
           "extent": list(d.GetExtent()), "spacing": list(d.GetSpacing()),
           "origin": list(d.GetOrigin()), "bounds": list(d.GetBounds()),
           "cells": d.GetNumberOfCells(), "points": d.GetNumberOfPoints()}
    for key, fd in (("arrays", d.GetCellData()), ("point_arrays", d.GetPointData())):
        out[key] = {}
        for i in range(fd.GetNumberOfArrays()):
            a = fd.GetArray(i)
            out[key][a.GetName()] = {"type": a.GetDataTypeAsString(),
                                     "values": vtk_to_numpy(a).astype(float).tolist()}
    return out

results = []
for job in json.load(open(sys.argv[1])):
    os.chdir(job["cwd"])
    kind, path = job["reader"], job["path"]
    if kind == "version":
        from vtkmodules.vtkCommonCore import vtkVersion
        results.append({"reader": "version", "version": vtkVersion.GetVTKVersion()})
        continue
    if kind == "vtkHDFReader":  # plain VTK
        from vtkmodules.vtkIOHDF import vtkHDFReader
        r = vtkHDFReader()
        r.SetFileName(path)
        r.Update()
        results.append({"reader": "vtkHDFReader", "times": [], "frames": [describe(r.GetOutput())]})
        continue
    if kind == "open":
        r = simple.OpenDataFile(path)
    elif kind == "xdmf2":
        r = simple.XDMFReader(FileNames=[path])
    elif kind == "VTKHDFReader":  # ParaView's proxy; 5.11 registers it for *.hdf, not *.vtkhdf
        r = simple.VTKHDFReader(FileName=[path])
    elif kind == "pvd":
        r = simple.PVDReader(FileName=path)
    else:
        raise SystemExit("unknown reader " + kind)
    tv = r.TimestepValues
    times = list(tv) if isinstance(tv, (list, tuple)) or hasattr(tv, "__len__") else [tv]
    res = {"reader": r.GetXMLName(), "times": times, "frames": []}
    for t in (times or [None]):
        if t is None:
            r.UpdatePipeline()
        else:
            r.UpdatePipeline(t)
        res["frames"].append(describe(image_of(r.GetClientSideObject().GetOutputDataObject(0))))
    simple.Delete(r)
    results.append(res)
json.dump(results, open(sys.argv[2], "w"))
'''


def brief(text, limit=3000):
    """ParaView's stderr without its stack-trace lines (the message comes before them)."""
    lines = [ln for ln in text.splitlines() if not re.match(r"^\s*(\x1b\[[0-9;]*m)*\s*\d+\s+0x", ln)]
    return "\n".join(lines)[-limit:]


def pv(cmd, cwd=None, timeout=180):
    """Run a ParaView command; a crashed ParaView can hang in its signal handler: killed."""
    try:
        return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired as e:
        err = e.stderr.decode() if isinstance(e.stderr, bytes) else (e.stderr or "")
        pytest.fail(f"{' '.join(map(str, cmd))}: no answer in {timeout} s (ParaView crashed?)\n{brief(err)}")


def pv_read(jobs, tmp):
    """Run READ_SCRIPT in pvbatch over jobs [{reader, path, cwd}] -> results (same order)."""
    script, jobs_file, out = tmp / "pv_read.py", tmp / "jobs.json", tmp / "results.json"
    script.write_text(READ_SCRIPT)
    jobs_file.write_text(json.dumps(jobs))
    proc = pv([PVBATCH, str(script), str(jobs_file), str(out)])
    assert proc.returncode == 0 and out.exists(), \
        f"pvbatch failed:\n{proc.stdout[-3000:]}\n{brief(proc.stderr)}"
    return json.loads(out.read_text())


def pvpython_cmd():
    return [PVPYTHON, "--no-mpi"] if PVPYTHON else [PVBATCH]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = launch_runs(tmp_path_factory.mktemp("pvruns"), RUNS, STEPS, EVERY)
    for r in out.values():
        d, n, h = r["dir"], r["n"], r["h"]
        dim, n3 = len(n), (list(n) + [1])[:3]
        spacing = h + [h[0]] if dim == 2 else h
        series = mh.read_series(str(d))
        r.update(xmf=d / f"{r['name']}.xmf", spacing=spacing, cells=int(np.prod(n)), dim=dim,
                 series=series, vtk_type="double" if "float64" in r["extra"] else "float",
                 snaps=[mh.read_snapshot(p) for _, p in series],
                 # .xmf (and converted .vti): cell data of an image of the cell corners from the
                 # domain's corner (z 0..0 in 2-D): the bounds are the domain
                 cell_geometry=dict(
                     extent=[v for a in range(3) for v in (0, n3[a] if a < dim else 0)],
                     origin=[0.0] * 3,
                     bounds=[v for a in range(3) for v in (0.0, n3[a] * h[a] if a < dim else 0.0)]),
                 # .vtkhdf read directly: point data on the cell centres
                 point_geometry=dict(
                     extent=[v for a in range(3) for v in (0, n3[a] - 1)],
                     origin=[h[a] / 2 if a < dim else 0.0 for a in range(3)],
                     bounds=[v for a in range(3) for v in ((h[a] / 2, (n3[a] - 0.5) * h[a])
                                                           if a < dim else (0.0, 0.0))]))
    return out


def check_image(frame, r, snap, where, vtk_type=None, points=False):
    """One frame read by VTK against the run's geometry and the h5py snapshot: cell data on the
    image of the cell corners (bounds = the domain), or with points=True point data on the cell
    centres (a .vtkhdf file read directly)."""
    assert frame is not None and frame["image"], f"{where}: not image data: {frame and frame['class']}"
    geo = r["point_geometry" if points else "cell_geometry"]
    assert frame["extent"] == geo["extent"], (where, frame["extent"])
    assert frame["points" if points else "cells"] == r["cells"], where
    np.testing.assert_allclose(frame["spacing"], r["spacing"], rtol=1e-12, err_msg=where)
    np.testing.assert_allclose(frame["origin"], geo["origin"], rtol=1e-12, atol=1e-15, err_msg=where)
    np.testing.assert_allclose(frame["bounds"], geo["bounds"], rtol=1e-12, atol=1e-15, err_msg=where)
    arrays, other = (frame["point_arrays"], frame["arrays"]) if points else \
        (frame["arrays"], frame["point_arrays"])
    assert set(SPECIES) <= set(arrays), f"{where}: arrays {sorted(arrays)}"
    assert not set(SPECIES) & set(other), f"{where}: species on both points and cells"
    for s in SPECIES:
        arr = arrays[s]
        if vtk_type:
            assert arr["type"] == vtk_type, f"{where}: {s} is {arr['type']}"
        ref = np.asarray(snap["fields"][s], dtype=float).ravel()  # [k][j][i]: x fastest, as VTK
        got = np.asarray(arr["values"])
        assert got.shape == ref.shape, f"{where}: {s}: {got.shape} values, expected {ref.shape}"
        diff = float(np.max(np.abs(got - ref)))
        assert diff <= EPS32 * float(np.max(np.abs(ref))), f"{where}: {s}: max |diff| {diff}"


# ------------------------------------------------------------------------------ .xmf in ParaView

# the older XDMF reader reads no cell data of flat (2-D) images: XDMF3 only there
XMF_CASES = [(k, how, reader) for k in RUNS for how in ("absolute", "dot") for reader in ("open", "xdmf2")
             if reader == "open" or k.startswith("3d")]


@pytest.fixture(scope="module")
def xmf_reads(runs, tmp_path_factory):
    jobs = []
    for key, how, reader in XMF_CASES:
        r = runs[key]
        if how == "absolute":
            jobs.append({"reader": reader, "path": str(r["xmf"].resolve()), "cwd": "/"})
        else:
            jobs.append({"reader": reader, "path": f"./{r['name']}.xmf", "cwd": str(r["dir"])})
    return dict(zip(XMF_CASES, pv_read(jobs, tmp_path_factory.mktemp("xmf"))))


@pytest.mark.parametrize("key,how,reader", XMF_CASES)
def test_xmf_series_in_paraview(runs, xmf_reads, key, how, reader):
    r, res = runs[key], xmf_reads[(key, how, reader)]
    where = f"{key} {reader} {how}"
    times = [t for t, _ in r["series"]]
    np.testing.assert_allclose(res["times"], times, rtol=1e-12, atol=0, err_msg=where)
    assert len(res["frames"]) == len(times)
    for i, (frame, snap) in enumerate(zip(res["frames"], r["snaps"])):
        check_image(frame, r, snap, f"{where} frame {i}", r["vtk_type"])


def test_xmf_bounds_are_exactly_the_domain(runs, xmf_reads):
    """What the run's final message says to open: each species is cell data, one value per cell,
    and the bounds are exactly the domain (0 .. n h), not the cell centres."""
    for key in RUNS:
        r = runs[key]
        for frame in xmf_reads[(key, "absolute", "open")]["frames"]:
            assert frame["bounds"] == r["cell_geometry"]["bounds"], f"{key}: {frame['bounds']}"
            assert frame["cells"] == r["cells"] and not frame["point_arrays"], key
            for s in SPECIES:
                assert len(frame["arrays"][s]["values"]) == r["cells"], (key, s)
    nx, ny = RUNS["2d"][0]
    hx, hy = runs["2d"]["h"]
    assert runs["2d"]["cell_geometry"]["bounds"] == [0.0, nx * hx, 0.0, ny * hy, 0.0, 0.0]


# ------------------------------------------------------------------- .vtkhdf opened directly

def vtk_version(tmp_path):
    return pv_read([{"reader": "version", "path": "", "cwd": "/"}], tmp_path)[0]["version"]


def check_vtkhdf_reads(runs, tmp_path, keys):
    cases = [(key, reader, -1) for key in keys for reader in ("vtkHDFReader", "VTKHDFReader")]
    cases.append((keys[0], "vtkHDFReader", 0))
    jobs = [{"reader": reader, "path": runs[key]["series"][i][1], "cwd": "/"} for key, reader, i in cases]
    for (key, reader, i), res in zip(cases, pv_read(jobs, tmp_path)):
        r = runs[key]
        assert res["frames"], f"{key} {reader}: nothing read"
        check_image(res["frames"][0], r, r["snaps"][i], f"{key} {reader} snapshot {i}", r["vtk_type"],
                    points=True)


def test_vtkhdf_opens_directly_3d(runs, tmp_path):
    """ParaView 5.11's VTKHDF reader (and plain VTK's) opens a 3-D .vtkhdf file itself: every
    species as point data on the cell centres, bounds h/2 .. (n - 1/2) h."""
    check_vtkhdf_reads(runs, tmp_path, ["3d", "3d_np2"])


def test_vtkhdf_opens_directly_2d(runs, tmp_path):
    version = vtk_version(tmp_path)
    if version.startswith("9.2."):
        pytest.skip(f"VTK {version} (ParaView 5.11): vtkHDFReader aborts on every image with a flat "
                    "axis (a heap overrun in vtkHDFReader::Read, whatever the file holds); 2-D runs "
                    "open through the .xmf")
    check_vtkhdf_reads(runs, tmp_path, ["2d", "2d_np2"])


# ------------------------------------------------------------------------------- converter

def test_converter_writes_vti_and_pvd(runs, tmp_path):
    # (run, converter input, which snapshots it holds): a directory, a .series, one .vtkhdf file
    conversions = [("2d", [str(runs["2d"]["dir"])], slice(None)),
                   ("3d_np2", [str(runs["3d_np2"]["dir"] / "vol.vtkhdf.series")], slice(None)),
                   ("2d_np2", [runs["2d_np2"]["series"][-1][1]], slice(-1, None))]
    jobs = []
    for n, (key, inputs, which) in enumerate(conversions):
        r, out = runs[key], tmp_path / f"vti{n}"
        proc = pv(pvpython_cmd() + [CONVERTER] + inputs + ["--out", str(out)])
        assert proc.returncode == 0, f"{key}: {proc.stdout}\n{brief(proc.stderr)}"
        assert sorted(os.listdir(out)) == sorted([f"{r['name']}.pvd"] + [
            os.path.basename(p).replace(".vtkhdf", ".vti") for _, p in r["series"][which]])
        jobs.append({"reader": "pvd", "path": str(out / f"{r['name']}.pvd"), "cwd": str(tmp_path)})
        last_vti = os.path.basename(r["series"][-1][1]).replace(".vtkhdf", ".vti")
        jobs.append({"reader": "open", "path": str(out / last_vti), "cwd": str(tmp_path)})
    results = pv_read(jobs, tmp_path)
    for n, (key, _, which) in enumerate(conversions):
        r = runs[key]
        pvd_res, vti_res = results[2 * n], results[2 * n + 1]
        series, snaps = r["series"][which], r["snaps"][which]
        if len(series) > 1:
            np.testing.assert_allclose(pvd_res["times"], [t for t, _ in series], rtol=1e-12)
        assert len(pvd_res["frames"]) == len(series)
        for i, (frame, snap) in enumerate(zip(pvd_res["frames"], snaps)):
            check_image(frame, r, snap, f"{key} .pvd frame {i}", r["vtk_type"])
        check_image(vti_res["frames"][0], r, snaps[-1], f"{key} last .vti", r["vtk_type"])



@pytest.mark.parametrize("key", ["2d", "3d"])
def test_converter_reads_celldata_layout(runs, tmp_path, key):
    """A series mixing snapshots of the CellData layout with PointData ones converts alike: cell
    data on the image of the cell corners, bounds = the domain, the same values."""
    r = runs[key]
    mixed = tmp_path / "mixed"
    shutil.copytree(r["dir"], mixed)
    for _, p in r["series"][:-1]:
        to_celldata_layout(mixed / os.path.basename(p))
    assert mh.read_snapshot(str(mixed / os.path.basename(r["series"][0][1])))["layout"] == "CellData"
    assert mh.read_snapshot(str(mixed / os.path.basename(r["series"][-1][1])))["layout"] == "PointData"
    out = tmp_path / "vti"
    series = mixed / f"{r['name']}.vtkhdf.series"
    proc = pv(pvpython_cmd() + [CONVERTER, str(series), "--out", str(out)])
    assert proc.returncode == 0, f"{proc.stdout}\n{brief(proc.stderr)}"
    res = pv_read([{"reader": "pvd", "path": str(out / f"{r['name']}.pvd"), "cwd": str(tmp_path)}],
                  tmp_path)[0]
    np.testing.assert_allclose(res["times"], [t for t, _ in r["series"]], rtol=1e-12)
    assert len(res["frames"]) == len(r["series"])
    for i, (frame, snap) in enumerate(zip(res["frames"], r["snaps"])):
        check_image(frame, r, snap, f"{key} mixed layouts, frame {i}", r["vtk_type"])


def test_converter_bad_input(runs, tmp_path):
    proc = pv(pvpython_cmd() + [CONVERTER, str(tmp_path / "missing.xmf")])
    assert proc.returncode != 0
    assert proc.stderr.strip().startswith("vtkhdf_to_vti: error:") and "missing.xmf" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    # a run whose index lists a truncated snapshot: one line, not a ParaView abort
    broken = tmp_path / "broken"
    shutil.copytree(runs["2d"]["dir"], broken)
    snap = broken / os.path.basename(runs["2d"]["series"][1][1])
    with open(snap, "r+b") as fh:
        fh.truncate(os.path.getsize(snap) // 3)
    proc = pv(pvpython_cmd() + [CONVERTER, str(broken / "morphogen.xmf"), "--out", str(tmp_path / "o")])
    assert proc.returncode == 1 and "truncated" in proc.stderr, brief(proc.stderr)
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr


# ---------------------------------------------------------------------------------- render

def assert_nonblank_png(path, size):
    import matplotlib.image as mpimg

    img = mpimg.imread(str(path))
    assert img.shape[1] == size[0] and img.shape[0] == size[1], f"{path}: {img.shape}"
    rgb = img[..., :3]
    colours = np.unique((rgb.reshape(-1, 3) * 255).round().astype(np.uint8), axis=0)
    not_bg = np.any(np.abs(rgb - rgb[0, 0]) > 0.05, axis=-1).mean()
    assert len(colours) > 50 and not_bg > 0.05, \
        f"{path}: {len(colours)} colours, {not_bg:.2f} of the pixels not background"


def render(args, display=None):
    cmd = [PVBATCH, RENDER] + args
    env = None
    if display:
        cmd += ["--backend", "gl"]
        env = dict(os.environ, DISPLAY=display)
    try:
        return subprocess.run(cmd, capture_output=True, text=True, timeout=240, env=env)
    except subprocess.TimeoutExpired as e:
        err = e.stderr.decode() if isinstance(e.stderr, bytes) else (e.stderr or "")
        pytest.fail(f"{' '.join(cmd)}: no answer in 240 s (ParaView crashed?)\n{brief(err)}")


@pytest.fixture(scope="module")
def x_display():
    """$DISPLAY, or a private Xvfb server for this module: -displayfd picks a free display without
    a race; -noreset, because pvbatch's X display test (connect, disconnect) otherwise makes Xvfb
    reset, and the render window's connection during the reset fails now and then."""
    if os.environ.get("DISPLAY"):
        yield os.environ["DISPLAY"]
        return
    if XVFB is None:
        pytest.skip("no X display and no Xvfb: Debian's ParaView renders with OpenGL only through X "
                    "(apt-get install xvfb); render.py's image backend is tested without one")
    rfd, wfd = os.pipe()
    server = subprocess.Popen([XVFB, "-displayfd", str(wfd), "-screen", "0", "1280x1024x24",
                               "-nolisten", "tcp", "-noreset"], pass_fds=(wfd,),
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(wfd)
    data = b""
    try:  # read the whole line: closing the pipe before Xvfb wrote its newline kills Xvfb
        while b"\n" not in data:
            ready, _, _ = select.select([rfd], [], [], 60)
            chunk = os.read(rfd, 64) if ready else b""
            if not chunk:
                break
            data += chunk
    finally:
        os.close(rfd)
    number = data.decode().strip()
    try:
        if not number.isdigit():
            pytest.fail("Xvfb did not start (no display number within 60 s)")
        yield f":{number}"
    finally:
        server.terminate()
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()


@pytest.mark.parametrize("key", ["2d", "3d_np2"])
def test_render_series(runs, tmp_path, key):
    r = runs[key]
    pattern = tmp_path / "frames" / "frame_%04d.png"
    proc = render([str(r["xmf"]), "--species", "b", "--out", str(pattern), "--size", "320x240"])
    assert proc.returncode == 0, f"{proc.stdout}\n{brief(proc.stderr)}"
    frames = sorted((tmp_path / "frames").glob("*.png"))
    assert [f.name for f in frames] == [f"frame_{i:04d}.png" for i in range(len(r["series"]))]
    for f in frames:
        assert_nonblank_png(f, (320, 240))


@pytest.mark.parametrize("key,mode", [("2d_np2", "slice"), ("3d", "slice"), ("3d", "contour")])
def test_render_gl(runs, tmp_path, x_display, key, mode):
    r = runs[key]
    out = tmp_path / f"{key}_{mode}.png"
    proc = render([str(r["dir"]), "--last", "--mode", mode, "--out", str(out), "--size", "400x300"], x_display)
    assert proc.returncode == 0, f"{proc.stdout}\n{brief(proc.stderr)}"
    assert_nonblank_png(out, (400, 300))


def test_render_bad_input(runs, tmp_path):
    proc = render([str(tmp_path / "nope.xmf")])
    assert proc.returncode == 1 and proc.stderr.strip().startswith("render: error:"), proc.stderr
    proc = render([str(runs["2d"]["xmf"]), "--species", "zz", "--out", str(tmp_path / "x.png")])
    assert proc.returncode == 1 and "no species zz" in proc.stderr, proc.stderr

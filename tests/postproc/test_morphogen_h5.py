"""postproc/morphogen_h5.py (h5py) on real runs, and the HDF5 output's layout (README "Output"):
snapshots, .vtkhdf.series, .xmf and checkpoints of 2-D and 3-D runs on 1 and 2 ranks."""
import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from conftest import SOURCE, launch_runs, option_value  # tests/postproc/conftest.py

sys.path.insert(0, os.path.join(SOURCE, "postproc"))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from vtkhdf_layouts import to_celldata_layout  # noqa: E402
import morphogen_h5 as mh  # noqa: E402

h5py = pytest.importorskip("h5py")

SCRIPT = os.path.join(SOURCE, "postproc", "morphogen_h5.py")
EPS32 = float(np.finfo(np.float32).eps)

# name: (cells, lengths, extra options, ranks); lengths chosen so hx, hy (and hz) all differ
RUNS = {
    "2d": ([32, 24], [32.0, 12.0], ["-dt", "0.2"], 1),
    "2d_np2": ([32, 24], [32.0, 12.0], ["-dt", "0.2", "-snapshot_precision", "float64",
                                         "-output_name", "pat"], 2),
    "3d": ([16, 12, 8], [16.0, 6.0, 2.0], ["-dt", "0.02"], 1),
    "3d_np2": ([16, 12, 8], [16.0, 6.0, 2.0], ["-dt", "0.02"], 2),
}
STEPS, EVERY = 20, 10


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = launch_runs(tmp_path_factory.mktemp("h5runs"), RUNS, STEPS, EVERY, ["-checkpoint_every", str(EVERY)])
    for r in out.values():
        r["dt"] = float(option_value(r["extra"], "-dt"))
        r["precision"] = "float64" if "float64" in r["extra"] else "float32"
    return out


def expected_geometry(r):
    """(WholeExtent, Origin, Spacing, dataset shape) the format prescribes: the cells are
    PointData on the cell centres (n points per axis, z 0..0 in 2-D), Origin h/2."""
    n, h = r["n"], r["h"]
    if len(n) == 2:
        return ([0, n[0] - 1, 0, n[1] - 1, 0, 0], [h[0] / 2, h[1] / 2, 0.0], [h[0], h[1], h[0]],
                (1, n[1], n[0]))
    return ([0, n[0] - 1, 0, n[1] - 1, 0, n[2] - 1], [x / 2 for x in h], list(h), (n[2], n[1], n[0]))


@pytest.mark.parametrize("key", list(RUNS))
def test_file_layout(runs, key):
    r = runs[key]
    d, name = r["dir"], r["name"]
    extent, origin, spacing, shape = expected_geometry(r)
    steps = list(range(0, STEPS + 1, EVERY))
    for step in steps:
        path = d / f"{name}_{step:07d}.vtkhdf"
        assert path.exists(), sorted(os.listdir(d))
        with h5py.File(path, "r") as f:
            g = f["VTKHDF"]
            assert g.attrs["Version"].dtype == np.int32 and list(g.attrs["Version"]) == [1, 0]
            tid = g.attrs.get_id("Type").get_type()
            assert isinstance(tid, h5py.h5t.TypeStringID) and not tid.is_variable_str()
            assert tid.get_cset() == h5py.h5t.CSET_ASCII and g.attrs["Type"] == b"ImageData"
            assert g.attrs["WholeExtent"].dtype == np.int32
            assert list(g.attrs["WholeExtent"]) == extent
            for key_, want in (("Origin", origin), ("Spacing", spacing), ("Direction", np.eye(3).ravel())):
                assert g.attrs[key_].dtype == np.float64, key_
                np.testing.assert_allclose(g.attrs[key_], want, rtol=1e-15, atol=0, err_msg=key_)
            assert "CellData" not in g and sorted(g["PointData"].keys()) == ["a", "b"]
            for s in ("a", "b"):
                ds = g["PointData"][s]
                assert ds.shape == shape and ds.dtype == np.dtype(r["precision"]), (s, ds.shape, ds.dtype)
                assert np.all(np.isfinite(ds[()]))
            m = f["morphogen"]
            assert m.attrs["step"].dtype == np.int64 and int(m.attrs["step"]) == step
            assert m.attrs["time"].dtype == np.float64
            assert float(m.attrs["time"]) == pytest.approx(step * r["dt"], rel=1e-12)
            assert mh._text(m.attrs["model"]) == "turing"
    # .vtkhdf.series
    doc = json.loads((d / f"{name}.vtkhdf.series").read_text())
    assert doc["file-series-version"] == "1.0"
    assert [e["name"] for e in doc["files"]] == [f"{name}_{s:07d}.vtkhdf" for s in steps]
    np.testing.assert_allclose([e["time"] for e in doc["files"]], [s * r["dt"] for s in steps], rtol=1e-12)
    # .xmf: XDMF 3 temporal collection of 3DCoRectMesh grids of the cell corners (origin 0, so
    # the bounds are the domain) whose cell attributes are the snapshots' PointData datasets
    root = ET.parse(d / f"{name}.xmf").getroot()
    assert root.tag == "Xdmf" and root.get("Version") == "3.0"
    coll = root.find("Domain/Grid")
    assert coll.get("GridType") == "Collection" and coll.get("CollectionType") == "Temporal"
    grids = coll.findall("Grid")
    assert len(grids) == len(steps)
    dims = " ".join(str(v) for v in shape)
    mesh = " ".join(str(v + 1 if v > 1 else 1) for v in shape)  # the cell corners
    for g, step in zip(grids, steps):
        assert float(g.find("Time").get("Value")) == pytest.approx(step * r["dt"], rel=1e-12)
        topo = g.find("Topology")
        assert topo.get("TopologyType") == "3DCoRectMesh" and topo.get("Dimensions") == mesh
        geo = g.find("Geometry")
        assert geo.get("GeometryType") == "ORIGIN_DXDYDZ"
        o, h = ([float(v) for v in item.text.split()] for item in geo.findall("DataItem"))
        assert o == [0.0, 0.0, 0.0]  # exactly: the domain's corner
        np.testing.assert_allclose(h, spacing[::-1], rtol=1e-15)
        attrs = g.findall("Attribute")
        assert [a.get("Name") for a in attrs] == ["a", "b"]
        for a in attrs:
            assert a.get("Center") == "Cell" and a.get("AttributeType") == "Scalar"
            item = a.find("DataItem")
            assert item.get("Format") == "HDF" and item.get("Dimensions") == dims
            assert item.get("Precision") == ("8" if r["precision"] == "float64" else "4")
            assert item.text.strip() == f"{name}_{step:07d}.vtkhdf:/VTKHDF/PointData/{a.get('Name')}"


@pytest.mark.parametrize("key", list(RUNS))
def test_read_snapshot_and_series(runs, key):
    r = runs[key]
    dim = len(r["n"])
    series = mh.read_series(str(r["dir"]))
    assert series == mh.read_series(str(r["dir"] / f"{r['name']}.vtkhdf.series"))
    assert [os.path.basename(p) for _, p in series] == \
        [f"{r['name']}_{s:07d}.vtkhdf" for s in range(0, STEPS + 1, EVERY)]
    for time, path in series:
        s = mh.read_snapshot(path)
        assert s["time"] == pytest.approx(time, rel=1e-15) and s["model"] == "turing"
        assert s["step"] == round(time / r["dt"]) and s["dim"] == dim
        np.testing.assert_allclose(s["spacing"], r["h"], rtol=1e-15)
        np.testing.assert_allclose(s["origin"], [x / 2 for x in r["h"]], rtol=1e-15)
        assert s["layout"] == "PointData"
        np.testing.assert_allclose(s["bounds"], [(0, n * h) for n, h in zip(r["n"], r["h"])],
                                   rtol=1e-15, atol=0)
        assert list(s["fields"]) == ["a", "b"]
        for v in s["fields"].values():
            assert v.shape == tuple(reversed(r["n"])) and v.dtype == np.dtype(r["precision"])
    # the last snapshot and the final checkpoint hold the same state
    last = mh.read_snapshot(series[-1][1])
    ck = mh.read_checkpoint(str(r["dir"] / f"checkpoint_{STEPS:07d}.vtkhdf"))
    for sp in ("a", "b"):
        ref = ck["fields"][sp]
        assert ref.dtype == np.float64
        tol = EPS32 * np.max(np.abs(ref)) if r["precision"] == "float32" else 0.0
        assert np.max(np.abs(last["fields"][sp] - ref)) <= tol


def test_same_snapshots_on_1_and_2_ranks(runs):
    """Explicit scheme: bitwise identical on 1 and 2 ranks, hence identical files' values."""
    one = mh.read_snapshot(str(runs["3d"]["dir"] / f"morphogen_{STEPS:07d}.vtkhdf"))
    two = mh.read_snapshot(str(runs["3d_np2"]["dir"] / f"morphogen_{STEPS:07d}.vtkhdf"))
    for sp in ("a", "b"):
        np.testing.assert_array_equal(one["fields"][sp], two["fields"][sp])


def test_read_checkpoint(runs):
    r = runs["2d_np2"]
    ck = mh.read_checkpoint(str(r["dir"] / f"checkpoint_{EVERY:07d}.vtkhdf"))
    for key in ("time", "step", "dt", "seed", "model", "options", "version", "petsc_version",
                "hdf5_version", "nranks", "level", "complete"):
        assert key in ck["attrs"] and key in ck, key
    assert ck["step"] == EVERY and ck["time"] == pytest.approx(EVERY * r["dt"], rel=1e-12)
    assert ck["dt"] == pytest.approx(r["dt"]) and ck["nranks"] == 2 and ck["complete"] == 1
    assert ck["seed"] == 1 and ck["level"] == 0 and ck["model"] == "turing"
    assert "grid_n" in ck["options"] and "32,24" in ck["options"]
    assert ck["fields"]["a"].shape == (24, 32)


def test_read_checkpoint_refuses_broken_files(runs, tmp_path):
    src = runs["2d"]["dir"] / f"checkpoint_{STEPS:07d}.vtkhdf"
    trunc = tmp_path / "checkpoint_truncated.vtkhdf"
    shutil.copy(src, trunc)
    with open(trunc, "r+b") as fh:
        fh.truncate(os.path.getsize(src) // 2)
    with pytest.raises(mh.MorphogenH5Error, match="truncated"):
        mh.read_checkpoint(str(trunc))
    incomplete = tmp_path / "checkpoint_incomplete.vtkhdf"
    shutil.copy(src, incomplete)
    with h5py.File(incomplete, "r+") as f:
        del f["morphogen"].attrs["complete"]
    with pytest.raises(mh.MorphogenH5Error, match="incomplete"):
        mh.read_checkpoint(str(incomplete))
    tmpname = tmp_path / "checkpoint_0000020.vtkhdf.tmp"
    shutil.copy(src, tmpname)
    with pytest.raises(mh.MorphogenH5Error, match="incomplete"):
        mh.read_checkpoint(str(tmpname))
    snap = runs["2d"]["dir"] / f"morphogen_{STEPS:07d}.vtkhdf"
    with pytest.raises(mh.MorphogenH5Error, match="incomplete checkpoint"):
        mh.read_checkpoint(str(snap))  # a snapshot is not a checkpoint
    with pytest.raises(mh.MorphogenH5Error, match="no such file"):
        mh.read_snapshot(str(tmp_path / "nope.vtkhdf"))
    with pytest.raises(mh.MorphogenH5Error, match="series"):
        mh.read_series(str(tmp_path))


def test_command_line(runs, tmp_path):
    r = runs["3d"]
    res = subprocess.run([sys.executable, SCRIPT, str(r["dir"] / f"checkpoint_{STEPS:07d}.vtkhdf"),
                          str(r["dir"])], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert "checkpoint, model turing, step 20" in res.stdout and "16 x 12 x 8 (3-D)" in res.stdout
    assert "series of 3 snapshot(s)" in res.stdout and "nranks = 1" in res.stdout
    res = subprocess.run([sys.executable, SCRIPT, "--json", str(r["dir"])], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    docs = json.loads(res.stdout)
    assert len(docs) == 3 and docs[0]["extent"] == [0, 15, 0, 11, 0, 7]
    assert docs[0]["shape"] == [16, 12, 8] and docs[0]["layout"] == "PointData"
    assert docs[1]["dtypes"] == {"a": "float32", "b": "float32"}
    bad = tmp_path / "bad.vtkhdf"
    bad.write_text("not hdf5")
    res = subprocess.run([sys.executable, SCRIPT, str(bad)], capture_output=True, text=True)
    assert res.returncode == 1 and res.stderr.count("\n") == 1 and "morphogen_h5: error:" in res.stderr


def to_celldata_layout_copy(src, dst):
    """A copy of snapshot src at dst, rewritten in the CellData layout."""
    shutil.copy(src, dst)
    return to_celldata_layout(dst)


@pytest.mark.parametrize("key", ["2d", "3d"])
def test_celldata_layout_is_read(runs, key, tmp_path):
    r = runs[key]
    new = mh.read_snapshot(mh.read_series(str(r["dir"]))[-1][1])
    cells = mh.read_snapshot(str(to_celldata_layout_copy(new["path"], tmp_path / "cells.vtkhdf")))
    assert cells["layout"] == "CellData" and new["layout"] == "PointData"
    for k in ("time", "step", "dim", "shape", "origin", "spacing", "origin3", "spacing3", "bounds",
              "species", "dtypes"):
        assert cells[k] == new[k], k
    for s in new["fields"]:
        assert np.array_equal(cells["fields"][s], new["fields"][s])
    assert cells["extent"] == [v + 1 if i % 2 and v else v for i, v in enumerate(new["extent"])]
    res = subprocess.run([sys.executable, SCRIPT, "--json", str(tmp_path / "cells.vtkhdf")],
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    doc = json.loads(res.stdout)[0]
    assert doc["layout"] == "CellData" and doc["shape"] == list(new["shape"])

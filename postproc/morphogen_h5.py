#!/usr/bin/python3
"""Read morphogen's HDF5 output (VTKHDF snapshots, checkpoints, .vtkhdf.series) into numpy.

    /usr/bin/python3 postproc/morphogen_h5.py FILE_OR_DIR [...] [--json]

As a module (h5py; do not import it in a ParaView/VTK process, see README "Output"):

    import morphogen_h5 as mh
    snap = mh.read_snapshot("run/morphogen_0000500.vtkhdf")
    snap["fields"]["a"]            # (ny, nx) in 2-D, (nz, ny, nx) in 3-D: index [k][j][i]
    snap["time"], snap["step"], snap["model"], snap["spacing"], snap["origin"]
    for time, path in mh.read_series("run"):          # or "run/morphogen.vtkhdf.series"
        ...
    ck = mh.read_checkpoint("run/checkpoint_0001000.vtkhdf")   # + ck["attrs"] (all of /morphogen)

spacing and origin are tuples in x, y[, z] order with one entry per grid dimension (2 or 3);
the cell centre of index i along x is origin[0] + i * spacing[0] (= (i + 0.5) h), whatever the
file's layout; bounds is ((x0, x1), (y0, y1)[, (z0, z1)]), the domain (0 .. n h). Snapshots store
the cells as /VTKHDF/PointData on the cell centres (WholeExtent 0..n-1 per axis, z 0..0 in 2-D,
Origin h/2); files of the CellData layout (an image of the cell corners: WholeExtent 0..n, z
0..0 in 2-D, Origin 0), written by an intermediate development version, are read too; "layout"
says which ("PointData" or "CellData"). "extent" is the file's WholeExtent (6 integers). Any
unreadable, truncated or malformed file raises MorphogenH5Error (a ValueError) naming the file and the reason; read_checkpoint also
refuses a checkpoint without complete = 1 (an interrupted write).

The command line prints a summary of each file (a snapshot or checkpoint: model, step, time,
grid, per-species dtype/min/max/mean; a directory or .vtkhdf.series: its files and times).
--json prints the metadata instead (no field values), one JSON document for all arguments;
postproc/vtkhdf_to_vti.py and postproc/render.py use it to describe single files to ParaView.
"""
import argparse
import glob
import json
import os
import sys

import numpy as np

try:
    import h5py
except ImportError:  # pragma: no cover - reported when used
    h5py = None


class MorphogenH5Error(ValueError):
    """A file that is not a readable morphogen VTKHDF file (the message names file and reason)."""


def _fail(path, reason):
    raise MorphogenH5Error(f"{path}: {reason}")


def _text(value):
    """HDF5 string attribute (bytes, numpy bytes, str) -> str; other values unchanged."""
    if isinstance(value, (bytes, np.bytes_)):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray) and value.dtype.kind in "SO" and value.shape == ():
        return _text(value[()])
    return value


def _scalar(value):
    """Numpy scalar / 0-d or 1-element array -> Python int/float; strings decoded."""
    value = _text(value)
    if isinstance(value, np.ndarray) and value.size == 1:
        value = value.reshape(())[()]
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


def _open(path):
    if h5py is None:
        raise MorphogenH5Error("h5py is not installed (apt-get install python3-h5py)")
    if not os.path.exists(path):
        _fail(path, "no such file")
    if os.path.isdir(path):
        _fail(path, "is a directory, not a .vtkhdf file")
    try:
        return h5py.File(path, "r")
    except OSError as e:
        _fail(path, f"cannot open as HDF5 (truncated, incomplete or not HDF5): {e}")


def _layout(f, path):
    """Validate /VTKHDF and return (extent, cells (nz, ny, nx), origin3 (first cell centre),
    spacing3, group ("PointData", or "CellData" in files of that layout), species list)."""
    if "VTKHDF" not in f:
        _fail(path, "no /VTKHDF group (not a VTKHDF file)")
    g = f["VTKHDF"]
    for key in ("Version", "Type", "WholeExtent", "Origin", "Spacing"):
        if key not in g.attrs:
            _fail(path, f"/VTKHDF has no {key} attribute")
    kind = _text(g.attrs["Type"])
    if kind != "ImageData":
        _fail(path, f"/VTKHDF Type is {kind!r}, expected 'ImageData'")
    version = [int(v) for v in np.atleast_1d(g.attrs["Version"])]
    if not version or version[0] not in (1, 2):
        _fail(path, f"unsupported VTKHDF Version {version}")
    extent = [int(v) for v in np.atleast_1d(g.attrs["WholeExtent"])]
    origin = [float(v) for v in np.atleast_1d(g.attrs["Origin"])]
    spacing = [float(v) for v in np.atleast_1d(g.attrs["Spacing"])]
    if len(extent) != 6 or len(origin) != 3 or len(spacing) != 3:
        _fail(path, f"WholeExtent/Origin/Spacing have {len(extent)}/{len(origin)}/{len(spacing)} "
                    "values, expected 6/3/3")
    group = "PointData" if "PointData" in g or "CellData" not in g else "CellData"
    spans = [extent[2 * a + 1] - extent[2 * a] for a in (2, 1, 0)]
    if min(spans) < 0:
        _fail(path, f"empty WholeExtent {extent}")
    if group == "PointData":  # one point per cell, at its centre
        shape = tuple(s + 1 for s in spans)  # (nz, ny, nx)
    else:  # CellData: points at the cell corners; a flat axis (0..0) holds one layer of cells
        shape = tuple(max(s, 1) for s in spans)
        origin = [o + h / 2 if s > 0 else o for o, h, s in zip(origin, spacing, spans[::-1])]
    if group not in g or not len(g[group]):
        _fail(path, f"no datasets in /VTKHDF/{group}")
    species = list(g[group].keys())
    for name in species:
        ds = g[group][name]
        if not isinstance(ds, h5py.Dataset):
            _fail(path, f"/VTKHDF/{group}/{name} is not a dataset")
        if tuple(ds.shape) != shape:
            _fail(path, f"/VTKHDF/{group}/{name} has shape {tuple(ds.shape)}, WholeExtent "
                        f"{extent} needs (nz, ny, nx) = {shape}")
    return extent, shape, origin, spacing, group, species


def _attrs(f):
    if "morphogen" not in f:
        return {}
    return {k: _scalar(v) for k, v in f["morphogen"].attrs.items()}


def _read(path, with_fields=True):
    with _open(path) as f:
        try:
            extent, cells, origin3, spacing3, group, species = _layout(f, path)
            attrs = _attrs(f)
            dim = 2 if cells[0] == 1 else 3
            fields, dtypes = {}, {}
            for name in species:
                ds = f["VTKHDF"][group][name]
                dtypes[name] = ds.dtype.name
                if with_fields:
                    data = ds[()]
                    fields[name] = data[0] if dim == 2 else data
        except MorphogenH5Error:
            raise
        except (OSError, KeyError, RuntimeError, ValueError) as e:
            _fail(path, f"unreadable (truncated or incomplete?): {e}")
    out = {
        "path": os.path.abspath(path),
        "time": float(attrs["time"]) if "time" in attrs else None,
        "step": int(attrs["step"]) if "step" in attrs else None,
        "model": attrs.get("model"),
        "dim": dim,
        "shape": tuple(cells[::-1][:dim]),  # nx, ny[, nz]
        "extent": extent,
        "layout": group,
        "bounds": tuple((origin3[a] - spacing3[a] / 2, origin3[a] + (cells[2 - a] - 0.5) * spacing3[a])
                        for a in range(dim)),
        "origin": tuple(origin3[:dim]),
        "spacing": tuple(spacing3[:dim]),
        "origin3": tuple(origin3),
        "spacing3": tuple(spacing3),
        "species": species,
        "dtypes": dtypes,
        "attrs": attrs,
    }
    if with_fields:
        out["fields"] = fields
    return out


def read_snapshot(path):
    """A snapshot (or checkpoint) file -> dict(time, step, model, spacing, origin, fields, ...).

    fields maps species -> ndarray of shape (ny, nx) in 2-D, (nz, ny, nx) in 3-D, in the file's
    precision. Also: dim, shape (nx, ny[, nz]), extent (the file's WholeExtent), layout
    ("PointData", or "CellData" for files of that layout), bounds (the domain per axis),
    origin3/spacing3 (three components: the first cell centre, z = 0 in 2-D, and the file's
    Spacing), species (file order), dtypes, attrs (all /morphogen attributes), path."""
    return _read(path)


def read_metadata(path):
    """As read_snapshot without the field values."""
    return _read(path, with_fields=False)


def read_checkpoint(path):
    """A checkpoint -> read_snapshot's dict plus its /morphogen attributes as top-level keys
    (dt, seed, options, version, petsc_version, hdf5_version, nranks, level, complete) and in
    "attrs". Raises MorphogenH5Error for a truncated, temporary or incomplete checkpoint."""
    if str(path).endswith(".tmp"):
        _fail(path, "temporary file of an unfinished checkpoint write (incomplete)")
    out = _read(path)
    attrs = out["attrs"]
    if not attrs:
        _fail(path, "no /morphogen group: not a checkpoint")
    if _scalar(attrs.get("complete", 0)) != 1:
        _fail(path, "incomplete checkpoint (no /morphogen complete = 1)")
    for key in ("time", "step", "dt", "model"):
        if key not in attrs:
            _fail(path, f"checkpoint lacks /morphogen attribute {key!r}")
    for key, value in attrs.items():
        out.setdefault(key, value)
    return out


def _series_path(path):
    if os.path.isdir(path):
        found = sorted(glob.glob(os.path.join(path, "*.vtkhdf.series")))
        if not found:
            _fail(path, "no *.vtkhdf.series file in this directory")
        if len(found) > 1:
            names = ", ".join(os.path.basename(p) for p in found)
            _fail(path, f"several series ({names}): give the .vtkhdf.series file")
        return found[0]
    if not os.path.exists(path):
        _fail(path, "no such file or directory")
    return path


def read_series(path):
    """A run directory (with one *.vtkhdf.series) or a .vtkhdf.series file -> [(time, path)],
    in the series' order, paths absolute (the series holds names relative to its directory)."""
    series = _series_path(path)
    try:
        with open(series) as fh:
            doc = json.load(fh)
        files = doc["files"]
        out = []
        for entry in files:
            out.append((float(entry["time"]),
                        os.path.abspath(os.path.join(os.path.dirname(series), entry["name"]))))
    except (OSError, ValueError, KeyError, TypeError) as e:
        _fail(series, f"not a readable .vtkhdf.series (JSON with files[].name/time): {e}")
    return out


def _summary(path):
    lines = []
    if os.path.isdir(path) or str(path).endswith(".series"):
        entries = read_series(path)
        lines.append(f"{_series_path(path)}: series of {len(entries)} snapshot(s)")
        for time, p in entries:
            flag = "" if os.path.exists(p) else "  (missing)"
            lines.append(f"  t={time:<14.8g} {os.path.basename(p)}{flag}")
        return lines
    d = _read(path)
    attrs = d["attrs"]
    kind = "checkpoint" if "complete" in attrs else "snapshot"
    lines.append(f"{d['path']}: {kind}, model {d['model']}, step {d['step']}, time {d['time']!r}")
    grid = " x ".join(str(n) for n in d["shape"])
    lines.append(f"  grid {grid} ({d['dim']}-D), spacing {d['spacing']}, origin {d['origin']}")
    for name in d["species"]:
        v = d["fields"][name]
        lines.append(f"  {name:<10} {d['dtypes'][name]:<8} min {np.min(v):.6g}  max {np.max(v):.6g}"
                     f"  mean {np.mean(v):.6g}")
    for key in sorted(attrs):
        if key in ("time", "step", "model"):
            continue
        value = attrs[key]
        if isinstance(value, str) and "\n" in value:
            value = f"<{len(value.splitlines())} lines>"
        lines.append(f"  {key} = {value}")
    return lines


def _jsonable(d):
    keep = ("path", "time", "step", "model", "dim", "shape", "extent", "layout", "bounds", "origin",
            "spacing",
            "origin3", "spacing3", "species", "dtypes")
    return {k: (json.loads(json.dumps(d[k])) if isinstance(d[k], tuple) else d[k]) for k in keep}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("paths", nargs="+", metavar="FILE_OR_DIR",
                    help="snapshot/checkpoint .vtkhdf, .vtkhdf.series, or run directory")
    ap.add_argument("--json", action="store_true",
                    help="print the files' metadata (no values) as one JSON list")
    args = ap.parse_args(argv)
    try:
        if args.json:
            docs = []
            for p in args.paths:
                if os.path.isdir(p) or p.endswith(".series"):
                    for time, f in read_series(p):
                        doc = _jsonable(read_metadata(f))
                        doc["series_time"] = time
                        docs.append(doc)
                else:
                    docs.append(_jsonable(read_metadata(p)))
            print(json.dumps(docs))
        else:
            for p in args.paths:
                print("\n".join(_summary(p)))
    except MorphogenH5Error as e:
        sys.exit(f"morphogen_h5: error: {e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

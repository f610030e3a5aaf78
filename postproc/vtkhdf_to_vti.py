#!/usr/bin/env pvbatch
"""Convert a morphogen run (VTKHDF snapshots) to VTK XML image files (.vti) and a .pvd index.

    pvpython --no-mpi postproc/vtkhdf_to_vti.py INPUT [INPUT ...] [--out DIR] [--name NAME]
                                                [--species a,b]
    pvbatch postproc/vtkhdf_to_vti.py RUN_DIR

For tools that read neither VTKHDF nor XDMF (older ParaView/VisIt, VTK readers, meshio...).
INPUT is a run directory (its NAME.xmf), a NAME.xmf, a NAME.vtkhdf.series, or one or more
snapshot/checkpoint .vtkhdf files. Writes DIR/<snapshot name>.vti per output time (binary,
zlib-compressed, the file's precision; field data TimeValue and Step) and DIR/NAME.pvd
listing them with their times (DIR defaults to RUN_DIR/vti). The fields are cell data of an
image of the cell corners, so the bounds are the domain (0 .. n h), as in the run's .xmf; 2-D
runs give flat images (z extent 0..0), 3-D runs full volumes. Snapshots of either layout
(/VTKHDF/PointData on the cell centres, or the CellData layout) convert alike; an .xmf of an
earlier version (Center="Node") converts as point data on the cell centres.

Runs in ParaView's Python (the project's VTK, Debian's python3-paraview); plain `pvpython` needs
--no-mpi. Everything is read through VTK's XDMF3 reader: ParaView 5.11's VTKHDF reader crashes
on 2-D image data. A .series or a list of .vtkhdf files is first described in a temporary XDMF
file (absolute data paths, so 5.11's relative-path mis-join cannot occur), using the metadata that
postproc/morphogen_h5.py --json prints; that runs in a separate /usr/bin/python3 (h5py) process
($MORPHOGEN_PYTHON overrides), because h5py and ParaView's VTK load different HDF5 libraries.
render.py uses resolve_input() from here. Errors: one line on stderr, exit status 1.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON = os.environ.get("MORPHOGEN_PYTHON", "/usr/bin/python3")
PROG = "vtkhdf_to_vti"


class InputError(Exception):
    """Bad input: reported as one line."""


# ---------------------------------------------------------------- input -> XDMF (no VTK, no HDF5)

def xdmf_entries(xmf):
    """The snapshots an XDMF temporal index describes: [{time, file, stem, species}] in file order
    (file: absolute path of the HDF5 file its attributes point at)."""
    try:
        root = ET.parse(xmf).getroot()
    except (OSError, ET.ParseError) as e:
        raise InputError(f"{xmf}: not a readable XDMF file: {e}")
    base = os.path.dirname(os.path.abspath(xmf))
    entries = []
    for grid in root.iter("Grid"):
        if grid.get("GridType", "Uniform") != "Uniform":
            continue
        time_el = grid.find("Time")
        time = float(time_el.get("Value")) if time_el is not None else float(len(entries))
        species, files = [], []
        for attr in grid.findall("Attribute"):
            item = attr.find("DataItem")
            species.append(attr.get("Name"))
            if item is not None and item.get("Format", "XML") == "HDF" and item.text:
                files.append(item.text.strip().rsplit(":", 1)[0])
        if not files:
            raise InputError(f"{xmf}: grid at time {time!r} has no HDF attributes")
        path = files[0] if os.path.isabs(files[0]) else os.path.join(base, files[0])
        entries.append({"time": time, "file": os.path.normpath(path),
                        "stem": re.sub(r"\.vtkhdf$", "", os.path.basename(path)), "species": species})
    if not entries:
        raise InputError(f"{xmf}: no grids (not a morphogen XDMF index?)")
    return entries


def h5_metadata(files):
    """Metadata of VTKHDF files from morphogen_h5.py --json, run by an h5py Python."""
    cmd = [PYTHON, os.path.join(HERE, "morphogen_h5.py"), "--json"] + list(files)
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    except OSError as e:
        raise InputError(f"cannot run {PYTHON} (needs h5py; set MORPHOGEN_PYTHON): {e}")
    if proc.returncode != 0:
        msg = (proc.stderr.strip().splitlines() or ["failed"])[-1]
        raise InputError(re.sub(r"^morphogen_h5: error: ", "", msg))
    return json.loads(proc.stdout)


def check_files(index, files):
    """Refuse an index whose HDF5 files are missing or unreadable: VTK's XDMF reader aborts the
    process on them. The h5py check is skipped when no h5py Python can be run."""
    missing = [f for f in files if not os.path.exists(f)]
    if missing:
        raise InputError(f"{index}: lists {missing[0]}, which does not exist")
    try:
        h5_metadata(sorted(set(files)))
    except InputError as e:
        if not str(e).startswith("cannot run "):
            raise


def write_xdmf(metas, times, path):
    """An XDMF 3 temporal collection over VTKHDF files (absolute paths), as morphogen writes:
    an image of the cell corners (n + 1 points per axis, 1 along a flat z) from the domain's
    corner, the species as its cell data, whichever group of the file holds them."""
    out = ['<?xml version="1.0" ?>', '<Xdmf Version="3.0">', ' <Domain>',
           '  <Grid Name="morphogen" GridType="Collection" CollectionType="Temporal">']
    for m, t in zip(metas, times):
        group = m.get("layout", "PointData")  # "CellData" in files of that layout
        nx, ny, nz = (list(m["shape"]) + [1])[:3]
        dims = f"{nz} {ny} {nx}"
        mesh = f"{nz + 1 if nz > 1 else 1} {ny + 1} {nx + 1}"
        h = m["spacing3"]  # origin3: the first cell centre, whatever the layout
        o = [m["origin3"][a] - h[a] / 2 if a < m["dim"] else m["origin3"][a] for a in range(3)]
        out.append(f'   <Grid Name="{os.path.basename(m["path"])}" GridType="Uniform">')
        out.append(f'    <Time Value="{t!r}"/>')
        out.append(f'    <Topology TopologyType="3DCoRectMesh" Dimensions="{mesh}"/>')
        out.append('    <Geometry GeometryType="ORIGIN_DXDYDZ">')
        out.append('     <DataItem Dimensions="3" NumberType="Float" Precision="8" Format="XML">'
                   f'{o[2]!r} {o[1]!r} {o[0]!r}</DataItem>')
        out.append('     <DataItem Dimensions="3" NumberType="Float" Precision="8" Format="XML">'
                   f'{h[2]!r} {h[1]!r} {h[0]!r}</DataItem>')
        out.append('    </Geometry>')
        for s in m["species"]:
            prec = 8 if m["dtypes"][s] == "float64" else 4
            out.append(f'    <Attribute Name="{s}" AttributeType="Scalar" Center="Cell">')
            out.append(f'     <DataItem Dimensions="{dims}" NumberType="Float" Precision="{prec}" '
                       f'Format="HDF">{m["path"]}:/VTKHDF/{group}/{s}</DataItem>')
            out.append('    </Attribute>')
        out.append('   </Grid>')
    out += ['  </Grid>', ' </Domain>', '</Xdmf>', '']
    with open(path, "w") as fh:
        fh.write("\n".join(out))


def _series_files(series):
    try:
        with open(series) as fh:
            doc = json.load(fh)
        base = os.path.dirname(os.path.abspath(series))
        return [(float(e["time"]), os.path.join(base, e["name"])) for e in doc["files"]]
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise InputError(f"{series}: not a readable .vtkhdf.series: {e}")


def resolve_input(paths, tmpdir, name=None):
    """INPUT arguments -> (xmf path (absolute), entries, run name, run directory).

    A directory gives its NAME.xmf (the only .xmf, or --name's); a .xmf is used as is; a
    .vtkhdf.series or .vtkhdf files are described in tmpdir/NAME.xmf first."""
    paths = [str(p) for p in paths]
    for p in paths:
        if not os.path.exists(p):
            raise InputError(f"{p}: no such file or directory")
    first = paths[0]
    if len(paths) == 1 and os.path.isdir(first):
        if name:
            xmf = os.path.join(first, name + ".xmf")
            if not os.path.exists(xmf):
                raise InputError(f"{first}: no {name}.xmf in this directory")
        else:
            found = sorted(f for f in os.listdir(first) if f.endswith(".xmf"))
            if not found:
                raise InputError(f"{first}: no .xmf index in this directory (not a morphogen run "
                                 "directory with snapshots?)")
            if len(found) > 1:
                raise InputError(f"{first}: several .xmf indexes ({', '.join(found)}): use --name")
            xmf = os.path.join(first, found[0])
        paths, first = [xmf], xmf
    if any(os.path.isdir(p) for p in paths):
        raise InputError("give one run directory, or files")
    if len(paths) == 1 and first.endswith(".xmf"):
        xmf = os.path.abspath(first)
        run_name = name or os.path.basename(xmf)[:-4]
        entries = xdmf_entries(xmf)
        check_files(xmf, [e["file"] for e in entries])
        return xmf, entries, run_name, os.path.dirname(xmf)
    if len(paths) == 1 and first.endswith(".series"):
        pairs = _series_files(first)
        if not pairs:
            raise InputError(f"{first}: empty series")
        missing = [f for _, f in pairs if not os.path.exists(f)]
        if missing:
            raise InputError(f"{first}: lists {os.path.basename(missing[0])}, which does not exist")
        run_name = name or re.sub(r"(\.vtkhdf)?\.series$", "", os.path.basename(first))
        times = [t for t, _ in pairs]
        files = [f for _, f in pairs]
    else:
        bad = [p for p in paths if p.endswith(".xmf") or p.endswith(".series")]
        if bad:
            raise InputError(f"{bad[0]}: give an index (.xmf/.series) alone")
        files = [os.path.abspath(p) for p in paths]
        times = None
        stems = {re.sub(r"_\d+\.vtkhdf$", "", os.path.basename(f)) for f in files}
        run_name = name or (stems.pop() if len(stems) == 1 else "snapshots")
    metas = h5_metadata(files)
    if times is None:
        times = [m["time"] if m["time"] is not None else float(i) for i, m in enumerate(metas)]
        order = sorted(range(len(files)), key=lambda i: times[i])
        metas, times = [metas[i] for i in order], [times[i] for i in order]
    if len(set(times)) != len(times):
        raise InputError("several files have the same time: convert them one at a time")
    xmf = os.path.join(tmpdir, re.sub(r"[^\w.-]", "_", run_name) + ".xmf")
    write_xdmf(metas, times, xmf)
    return xmf, xdmf_entries(xmf), run_name, os.path.dirname(os.path.abspath(files[0]))


# ---------------------------------------------------------------- reading and writing with VTK

def image_cells(image):
    """(attributes, (nx, ny, nz), first cell centre (x, y, z), spacing) of an image read from a
    morphogen file: its cell data (an image of the cell corners, as morphogen's .xmf describes
    either file layout) or, through an .xmf of an earlier version, its point data (one point
    per cell, at the centre). Values are x fastest."""
    dims, o, h = image.GetDimensions(), image.GetOrigin(), image.GetSpacing()
    cd = image.GetCellData()
    if cd.GetNumberOfArrays() > 0:
        n = tuple(d - 1 if d > 1 else 1 for d in dims)
        return cd, n, tuple(o[a] + h[a] / 2 if dims[a] > 1 else o[a] for a in range(3)), h
    return image.GetPointData(), tuple(dims), tuple(o), h


def read_xdmf(xmf, entries, verbose=False):
    """Yield (entry, vtkImageData) per time of an XDMF temporal index (absolute path)."""
    from vtkmodules.vtkCommonCore import vtkObject
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as SDDP
    from vtkmodules.vtkIOXdmf3 import vtkXdmf3Reader

    if not verbose:
        vtkObject.GlobalWarningDisplayOff()
    reader = vtkXdmf3Reader()
    reader.SetFileName(os.path.abspath(xmf))  # never a bare relative name (5.11 mis-joins it)
    reader.UpdateInformation()
    times = reader.GetOutputInformation(0).Get(SDDP.TIME_STEPS())
    times = list(times) if times else [None]
    if len(times) != len(entries):
        raise InputError(f"{xmf}: VTK's XDMF reader sees {len(times)} time(s), the file "
                         f"lists {len(entries)} grids (repeated times?)")
    for entry, t in zip(entries, times):
        if t is None:
            reader.Update()
        else:
            reader.UpdateTimeStep(t)
        out = reader.GetOutputDataObject(0)
        if out is None or not out.IsA("vtkImageData"):
            kind = out.GetClassName() if out is not None else "nothing"
            raise InputError(f"{xmf}: time {entry['time']!r}: read {kind}, expected image data")
        image = vtkImageData()
        image.DeepCopy(out)
        pd, n, _, _ = image_cells(image)
        for s in entry["species"]:
            arr = pd.GetArray(s)
            if arr is None or arr.GetNumberOfTuples() != n[0] * n[1] * n[2]:
                raise InputError(f"{entry['file']}: species {s} could not be read (missing, "
                                 "truncated or unreadable file)")
        yield entry, image


def write_pvd(path, items):
    """items: [(time, file name relative to the .pvd)]."""
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             '  <Collection>']
    for time, fname in items:
        lines.append(f'    <DataSet timestep="{time!r}" group="" part="0" file="{fname}"/>')
    lines += ['  </Collection>', '</VTKFile>', '']
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        fh.write("\n".join(lines))
    os.replace(tmp, path)


def convert(inputs, out_dir=None, name=None, species=None, verbose=False):
    """Convert; returns (pvd path, [vti paths])."""
    from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkLongLongArray
    from vtkmodules.vtkIOXML import vtkXMLImageDataWriter

    with tempfile.TemporaryDirectory(prefix="vtkhdf_to_vti_") as tmp:
        xmf, entries, run_name, run_dir = resolve_input(inputs, tmp, name)
        out_dir = out_dir or os.path.join(run_dir, "vti")
        os.makedirs(out_dir, exist_ok=True)
        written, items = [], []
        for entry, image in read_xdmf(xmf, entries, verbose):
            pd = image_cells(image)[0]
            if species:
                unknown = [s for s in species if pd.GetArray(s) is None]
                if unknown:
                    have = ", ".join(entry["species"])
                    raise InputError(f"no species {unknown[0]} (the files have {have})")
                for s in entry["species"]:
                    if s not in species:
                        pd.RemoveArray(s)
            tv = vtkDoubleArray()
            tv.SetName("TimeValue")
            tv.InsertNextValue(entry["time"])
            image.GetFieldData().AddArray(tv)
            m = re.search(r"_(\d+)$", entry["stem"])
            if m:
                st = vtkLongLongArray()
                st.SetName("Step")
                st.InsertNextValue(int(m.group(1)))
                image.GetFieldData().AddArray(st)
            fname = entry["stem"] + ".vti"
            path = os.path.join(out_dir, fname)
            writer = vtkXMLImageDataWriter()
            writer.SetFileName(path)
            writer.SetInputData(image)
            writer.SetDataModeToAppended()
            writer.EncodeAppendedDataOff()
            writer.SetCompressorTypeToZLib()
            if writer.Write() != 1:
                raise InputError(f"{path}: could not write")
            written.append(path)
            items.append((entry["time"], fname))
        pvd = os.path.join(out_dir, run_name + ".pvd")
        write_pvd(pvd, items)
    return pvd, written


def main(argv=None):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__.splitlines()[0])
    ap.add_argument("inputs", nargs="+", metavar="INPUT",
                    help="run directory, NAME.xmf, NAME.vtkhdf.series, or .vtkhdf files")
    ap.add_argument("--out", default=None, help="output directory (default RUN_DIR/vti)")
    ap.add_argument("--name", default=None,
                    help="run name: which NAME.xmf of a directory, and the .pvd's name")
    ap.add_argument("--species", default=None, help="comma-separated species to keep (default all)")
    ap.add_argument("--verbose", action="store_true", help="show VTK's warnings")
    args = ap.parse_args(argv)
    species = [s for s in args.species.split(",") if s] if args.species else None
    try:
        pvd, written = convert(args.inputs, args.out, args.name, species, args.verbose)
    except InputError as e:
        sys.stderr.write(f"{PROG}: error: {e}\n")
        return 1
    print(f"{pvd} ({len(written)} .vti file{'s' if len(written) != 1 else ''})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

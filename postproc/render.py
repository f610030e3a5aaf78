#!/usr/bin/env pvbatch
"""Render a morphogen snapshot or a whole run to PNG images with ParaView.

    pvbatch postproc/render.py RUN_DIR/NAME.xmf --species u --out frames/frame_%04d.png
    pvbatch postproc/render.py RUN_DIR [--species a] [--size 800x600] [--last] [--every N]
                               [--mode slice|volume|contour] [--range LO,HI|all|frame] ...

INPUT is what postproc/vtkhdf_to_vti.py takes: a run directory, NAME.xmf, NAME.vtkhdf.series,
or .vtkhdf files. One PNG per output time (every --every'th time; only the last with --last),
named by --out with %d-style formatting of the frame number (0, 1, ...; a pattern without a
% gets _%04d added before its extension when there are several frames). Default:
NAME_<species>_%04d.png in the current directory. Each written path is printed.

Views: a 2-D run is the x-y plane seen from +z (parallel projection, y up). A 3-D run is by
default (--mode slice) the z = --slice-at plane (default: the middle cell layer, k = nz/2, as in
the PNG quick-looks) inside the domain's outline, seen obliquely; --mode volume renders the
volume, --mode contour the isosurface --iso (default: the middle of the colour range) coloured
by --iso-color. Colour map: --cmap (a ParaView preset, default "Viridis (matplotlib)"); colour
range: --range all (default: min/max over the rendered frames), frame (each frame's own), or
LO,HI. A colour bar and the time are drawn unless --no-bar / --no-time.

Backends: --backend gl renders with ParaView's render view (OpenGL). Debian 12's ParaView is an
X11 build with no offscreen (EGL/OSMesa) support, so this needs an X display: a desktop, or on a
headless machine  xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" pvbatch postproc/render.py ...
(without -noreset, pvbatch's X display test makes Xvfb reset, and now and then the render window's
connection fails: "bad X server connection", SIGABRT). --backend image needs no
display: it draws the plane (2-D) or the z slice (3-D) cell by cell with matplotlib (viridis, or
--cmap when it names a matplotlib map), with colour bar and time; volume and contour need gl.
--backend auto (default) uses gl when $DISPLAY is set (and a local display's socket exists),
image otherwise.

Data are read through the XDMF3 reader only, as cell data with bounds = the domain (ParaView
5.11's VTKHDF reader crashes on 2-D image data; the older XDMF reader reads no cell data of 2-D
images), by absolute path (5.11 mis-joins data paths for a bare relative .xmf name). Errors:
one line on stderr, exit status 1.
"""
import argparse
import os
import re
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vtkhdf_to_vti import InputError, image_cells, read_xdmf, resolve_input  # noqa: E402

PROG = "render"
MPL_NAMES = {"viridis (matplotlib)": "viridis", "inferno (matplotlib)": "inferno",
             "magma (matplotlib)": "magma", "plasma (matplotlib)": "plasma",
             "cool to warm": "coolwarm", "grayscale": "gray", "gray": "gray"}


def parse_args(argv):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__.splitlines()[0])
    ap.add_argument("inputs", nargs="+", metavar="INPUT",
                    help="NAME.xmf, run directory, NAME.vtkhdf.series or .vtkhdf files")
    ap.add_argument("--species", default=None, help="species to show (default: the first)")
    ap.add_argument("--out", default=None, help="output pattern (default NAME_<species>_%%04d.png)")
    ap.add_argument("--size", default="800x600", help="image size WxH in pixels (default 800x600)")
    ap.add_argument("--cmap", default="Viridis (matplotlib)", help="colour map preset")
    ap.add_argument("--range", default="all", dest="crange",
                    help="colour range: all (over the frames, default), frame, or LO,HI")
    ap.add_argument("--mode", choices=("slice", "volume", "contour"), default="slice",
                    help="3-D view (default slice)")
    ap.add_argument("--slice-at", type=float, default=None,
                    help="z of the 3-D slice (default: the middle cell layer's centre)")
    ap.add_argument("--iso", type=float, default=None, help="contour value (default: mid-range)")
    ap.add_argument("--iso-color", default="0.9,0.6,0.2", help="contour colour R,G,B in [0,1]")
    ap.add_argument("--every", type=int, default=1, help="render every N-th output time")
    ap.add_argument("--last", action="store_true", help="render only the last output time")
    ap.add_argument("--name", default=None, help="which NAME.xmf of a run directory")
    ap.add_argument("--no-bar", action="store_true", help="no colour bar")
    ap.add_argument("--no-time", action="store_true", help="no time label")
    ap.add_argument("--backend", choices=("auto", "gl", "image"), default="auto")
    args = ap.parse_args(argv)
    try:
        w, h = (int(v) for v in args.size.lower().split("x"))
        if w < 16 or h < 16:
            raise ValueError
        args.size = (w, h)
    except ValueError:
        ap.error(f"--size {args.size}: expected WxH, e.g. 800x600")
    if args.crange not in ("all", "frame"):
        try:
            lo, hi = (float(v) for v in args.crange.split(","))
            if not lo < hi:
                raise ValueError
            args.crange = (lo, hi)
        except ValueError:
            ap.error(f"--range {args.crange}: expected all, frame or LO,HI with LO < HI")
    try:
        args.iso_color = [float(v) for v in args.iso_color.split(",")]
        assert len(args.iso_color) == 3
    except (ValueError, AssertionError):
        ap.error(f"--iso-color {args.iso_color}: expected R,G,B")
    if args.every < 1:
        ap.error("--every must be >= 1")
    return args


def display_works():
    """$DISPLAY is set and, for a local display (:N), its socket exists. No test connection: a
    connect/disconnect can make an X server (Xvfb without -noreset) reset under our feet."""
    display = os.environ.get("DISPLAY", "")
    m = re.match(r"^(unix)?:(\d+)(\.\d+)?$", display)
    if m:
        return os.path.exists(f"/tmp/.X11-unix/X{m.group(2)}")
    return bool(display)


def frame_paths(pattern, count):
    if "%" not in pattern and count > 1:
        root, ext = os.path.splitext(pattern)
        pattern = root + "_%04d" + (ext or ".png")
    try:
        paths = [pattern % i if "%" in pattern else pattern for i in range(count)]
    except (TypeError, ValueError) as e:
        raise InputError(f"--out {pattern}: bad %-pattern ({e})")
    for p in paths:
        d = os.path.dirname(p)
        if d:
            os.makedirs(d, exist_ok=True)
    return paths


def time_label(t):
    return f"t = {t:.6g}"


# ------------------------------------------------------------------------------ gl backend

def render_gl(args, xmf, entries, dim, species, paths):
    from paraview import simple

    # XDMF3: the older XDMF reader reads no cell data of 2-D (flat) images.
    reader = simple.Xdmf3ReaderS(FileName=[xmf])
    times = list(reader.TimestepValues) if len(entries) > 1 else [None]
    if len(times) == 1 and times[0] is None and len(entries) > 1:
        raise InputError(f"{xmf}: no time steps")
    chosen = [times[i] if i < len(times) else None for i in args.frames]
    if chosen[0] is None:
        reader.UpdatePipeline()
    else:
        reader.UpdatePipeline(chosen[0])
    # cell data (an image of the cell corners); an .xmf of an earlier version: point data
    cells = species in reader.CellData.keys()

    def data_range(t):
        if t is None:
            reader.UpdatePipeline()
        else:
            reader.UpdatePipeline(t)
        return (reader.CellData if cells else reader.PointData)[species].GetRange()

    if args.crange == "all":
        rs = [data_range(t) for t in chosen]
        crange = (min(r[0] for r in rs), max(r[1] for r in rs))
    elif args.crange != "frame":
        crange = args.crange
    else:
        crange = data_range(chosen[0])

    view = simple.CreateRenderView()
    try:
        _draw_gl(args, simple, reader, cells, view, entries, dim, species, paths, chosen, crange,
                 data_range)
    finally:
        # Without this, Python's exit tears the GL context down first: X error, exit status 1.
        simple.Delete(view)


def _draw_gl(args, simple, reader, cells, view, entries, dim, species, paths, chosen, crange,
             data_range):
    """cells: the species is cell data (an image of the cell corners), else point data."""
    view.ViewSize = list(args.size)
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = [1.0, 1.0, 1.0]
    lut = simple.GetColorTransferFunction(species)
    if not lut.ApplyPreset(args.cmap, True):
        raise InputError(f"--cmap {args.cmap}: no such ParaView colour map preset")
    pwf = simple.GetOpacityTransferFunction(species)

    info = reader.GetDataInformation()
    b = info.GetBounds()
    center = [(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2]
    size = max(b[1] - b[0], b[3] - b[2], b[5] - b[4]) or 1.0
    colored = None
    if dim == 2:
        colored = simple.Show(reader, view)
        colored.SetRepresentationType("Surface")
        view.CameraPosition = [center[0], center[1], center[2] + 4 * size]
        view.CameraFocalPoint = center
        view.CameraViewUp = [0, 1, 0]
        view.CameraParallelProjection = 1
        view.InteractionMode = "2D"
    else:
        outline = simple.Show(simple.Outline(Input=reader), view)
        outline.DiffuseColor = outline.AmbientColor = [0.0, 0.0, 0.0]
        outline.ColorArrayName = ["POINTS", ""]
        if args.mode == "slice":
            ext = info.GetExtent()
            z = args.slice_at
            if z is None:  # the middle layer's centre (cells), the middle point layer (points)
                nz = ext[5] - ext[4] + 1
                hz = (b[5] - b[4]) / (nz - 1) if nz > 1 else 0.0
                z = b[4] + ((nz - 1) // 2 + 0.5) * hz if cells else b[4] + (nz // 2) * hz
            sl = simple.Slice(Input=reader)
            sl.SliceType = "Plane"
            sl.SliceType.Origin = [center[0], center[1], z]
            sl.SliceType.Normal = [0, 0, 1]
            colored = simple.Show(sl, view)
        elif args.mode == "volume":  # point data: 5.11's volume mappers, contours need it
            colored = simple.Show(simple.CellDatatoPointData(Input=reader) if cells else reader, view)
            colored.SetRepresentationType("Volume")
        else:
            iso = args.iso
            if iso is None:
                iso = 0.5 * (crange[0] + crange[1])
            src = simple.CellDatatoPointData(Input=reader) if cells else reader
            ct = simple.Contour(Input=src, ContourBy=["POINTS", species], Isosurfaces=[iso])
            cd = simple.Show(ct, view)
            cd.ColorArrayName = ["POINTS", ""]
            cd.DiffuseColor = cd.AmbientColor = args.iso_color
        view.CameraFocalPoint = center
        view.CameraPosition = [center[0] + 1.6 * size, center[1] - 2.2 * size, center[2] + 1.9 * size]
        view.CameraViewUp = [0, 0, 1]
    if colored is not None:
        point_input = not cells or (args.mode == "volume" and dim == 3)
        simple.ColorBy(colored, ("POINTS" if point_input else "CELLS", species))
        colored.LookupTable = lut
        if args.mode == "volume" and dim == 3:
            colored.ScalarOpacityFunction = pwf
        if not args.no_bar:
            colored.SetScalarBarVisibility(view, True)
            bar = simple.GetScalarBar(lut, view)
            bar.Title = species
            bar.ComponentTitle = ""
            bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
            bar.RangeLabelFormat = "%-#.5g"
            bar.WindowLocation = "Any Location"
            bar.Orientation = "Vertical"
            bar.Position = [0.85, 0.1]
            bar.ScalarBarLength = 0.8
    label = None
    if not args.no_time:
        text = simple.Text(Text="")
        label = simple.Show(text, view)
        label.Color = [0.0, 0.0, 0.0]
        label.WindowLocation = "Upper Left Corner"
        label.FontSize = 14
    view.ResetCamera()
    if dim == 2:
        # fill the height, or 80% of the width (the colour bar sits on the right)
        w, h = args.size
        dx, dy = (b[1] - b[0]) or 1.0, (b[3] - b[2]) or 1.0
        scale = 0.5 * max(1.1 * dy, 1.3 * dx * h / w)
        view.CameraParallelScale = scale
        shift = 0.14 * scale * w / h if not args.no_bar else 0.0
        view.CameraFocalPoint = [center[0] + shift, center[1], center[2]]
        view.CameraPosition = [center[0] + shift, center[1], center[2] + 4 * size]
    else:
        view.CameraFocalPoint = center
    for frame, (i, t, path) in enumerate(zip(args.frames, chosen, paths)):
        if t is not None:
            view.ViewTime = t
        r = crange if args.crange != "frame" else data_range(t)
        if r[1] <= r[0]:
            r = (r[0] - 0.5 * max(abs(r[0]), 1e-12), r[1] + 0.5 * max(abs(r[1]), 1e-12))
        lut.RescaleTransferFunction(r[0], r[1])
        pwf.RescaleTransferFunction(r[0], r[1])
        if label is not None:
            text.Text = f"{species}   {time_label(entries[i]['time'])}"
        simple.SaveScreenshot(path, view, ImageResolution=list(args.size))
        if not os.path.exists(path):
            raise InputError(f"{path}: ParaView wrote no image")
        print(path)


# ---------------------------------------------------------------------------- image backend

def render_image(args, xmf, entries, dim, species, paths):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from vtkmodules.util.numpy_support import vtk_to_numpy

    cmap = MPL_NAMES.get(args.cmap.lower(), args.cmap)
    if cmap not in plt.colormaps():
        raise InputError(f"--cmap {args.cmap}: the image backend knows matplotlib maps only")
    wanted = set(args.frames)

    def planes():
        for i, (entry, image) in enumerate(read_xdmf(xmf, entries)):
            if i not in wanted:
                continue
            pd, (nx, ny, nz), o, h = image_cells(image)  # o: the first cell centre
            values = vtk_to_numpy(pd.GetArray(species)).reshape(nz, ny, nx)
            k = 0
            if dim == 3:
                k = nz // 2 if args.slice_at is None else int(round((args.slice_at - o[2]) / h[2]))
                if not 0 <= k < nz:
                    raise InputError(f"--slice-at {args.slice_at}: outside z "
                                     f"[{o[2]}, {o[2] + (nz - 1) * h[2]}]")
            extent = (o[0] - h[0] / 2, o[0] + (nx - 0.5) * h[0],
                      o[1] - h[1] / 2, o[1] + (ny - 0.5) * h[1])
            yield entry, values[k].copy(), extent, o[2] + k * h[2]

    if args.crange == "all":
        lo, hi = float("inf"), float("-inf")
        for _, plane, _, _ in planes():
            lo, hi = min(lo, float(plane.min())), max(hi, float(plane.max()))
        crange = (lo, hi)
    else:
        crange = args.crange
    w, h = args.size
    for (entry, plane, extent, z), path in zip(planes(), paths):
        r = (float(plane.min()), float(plane.max())) if crange == "frame" else crange
        fig = plt.figure(figsize=(w / 100, h / 100), dpi=100)
        ax = fig.add_axes([0.08, 0.08, 0.74 if not args.no_bar else 0.88, 0.84])
        im = ax.imshow(plane, origin="lower", extent=extent, cmap=cmap, vmin=r[0], vmax=r[1],
                       interpolation="nearest", aspect="equal")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        title = species if args.no_time else f"{species}   {time_label(entry['time'])}"
        if dim == 3:
            title += f"   (z = {z:.6g})"
        ax.set_title(title)
        if not args.no_bar:
            fig.colorbar(im, cax=fig.add_axes([0.86, 0.08, 0.03, 0.84]))
        fig.savefig(path, dpi=100)
        plt.close(fig)
        print(path)


def main(argv=None):
    args = parse_args(argv)
    try:
        with tempfile.TemporaryDirectory(prefix="morphogen_render_") as tmp:
            xmf, entries, run_name, _ = resolve_input(args.inputs, tmp, args.name)
            species_all = entries[0]["species"]
            species = args.species or species_all[0]
            if species not in species_all:
                raise InputError(f"no species {species} (the run has {', '.join(species_all)})")
            # dimension from the XDMF topology (no HDF5 needed): "nz ny nx"
            import xml.etree.ElementTree as ET

            topo = next(ET.parse(xmf).getroot().iter("Topology"))
            nz = int(topo.get("Dimensions").split()[0])
            dim = 2 if nz == 1 else 3
            n = len(entries)
            args.frames = [n - 1] if args.last else list(range(0, n, args.every))
            backend = args.backend
            if backend == "auto":
                backend = "gl" if display_works() else "image"
            if backend == "image" and dim == 3 and args.mode != "slice":
                raise InputError(f"--mode {args.mode} needs an X display (--backend gl; on a "
                                 "headless machine run under xvfb-run, see --help)")
            if backend == "gl" and not os.environ.get("DISPLAY"):
                raise InputError("--backend gl needs an X display (Debian's ParaView has no "
                                 "offscreen rendering): run under xvfb-run (see --help), or use "
                                 "--backend image")
            out = args.out or f"{run_name}_{species}_%04d.png"
            paths = frame_paths(out, len(args.frames))
            (render_gl if backend == "gl" else render_image)(args, xmf, entries, dim, species, paths)
    except InputError as e:
        sys.stderr.write(f"{PROG}: error: {e}\n")
        return 1
    return 0


if __name__ == "__main__":
    status = main()
    if status:  # no sys.exit(0): under pvbatch it can end in an X error at teardown
        sys.exit(status)

#!/usr/bin/env pvbatch
"""Render a 2-D morphogen snapshot as a colour texture on a parametric surface, to a PNG.

    pvbatch postproc/render_surface.py RUN/NAME_0005000.vtkhdf --species a \\
        --surface-x "(3 + cos(2*_pi*v/Ly)) * cos(2*_pi*u/Lx)" \\
        --surface-y "(3 + cos(2*_pi*v/Ly)) * sin(2*_pi*u/Lx)" \\
        --surface-z "sin(2*_pi*v/Ly)" --view -60,35 --output torus.png

INPUT is what postproc/render.py takes: a snapshot or checkpoint .vtkhdf file, a run directory,
NAME.xmf or NAME.vtkhdf.series (then --frame picks the output time: default -1, the last). The
run must be 2-D. The surface is X(u, v) = (--surface-x, --surface-y, --surface-z), the same
muParser-style expressions as morphogen's -surface_x/-surface_y/-surface_z: variables u and v
(the cell-centre coordinates x and y), constants Lx, Ly (domain lengths), pi, _pi, _e; operators
+ - * / ^ (power), comparisons, && ||, c ? a : b; muParser's functions (sin ... atanh, exp, ln,
log (natural), log2, log10, sqrt, abs, sign, rint, min, max, sum, avg). They are evaluated with
numpy at the cell centres (not with eval()). Defaults: the plane x = u, y = v, z = 0. Where the
surface closes on itself (X(u + Lx, v) = X(u, v), likewise for v: a torus, a cylinder) the seam
is closed with the first column/row; --seam open keeps it open.

--view AZ,EL: camera azimuth and elevation in degrees (matplotlib's convention: the camera looks
at the surface's centre from the direction (cos EL cos AZ, cos EL sin AZ, sin EL), z up; default
-60,30). --size WxH (default 800x600), --cmap (a ParaView preset, default
"Viridis (matplotlib)"), --range LO,HI (default: the data's min/max), --no-bar, --no-time.

Data are read with VTK's XDMF reader in this process (through postproc/vtkhdf_to_vti.py's
resolve_input/read_xdmf: ParaView 5.11's VTKHDF reader crashes on 2-D image data; a .vtkhdf file
is first described in a temporary .xmf from the metadata that postproc/morphogen_h5.py --json
prints in a separate /usr/bin/python3, because h5py and ParaView's VTK load different HDF5
libraries). The surface is a vtkStructuredGrid with the species as point data.

Backends: --backend gl renders with ParaView's render view (needs an X display: Debian 12's
ParaView has no offscreen rendering; on a headless machine
    xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" pvbatch postproc/render_surface.py ...
see render.py). --backend image draws the surface with matplotlib's mplot3d (no display needed;
coarser: at most ~200 facets per direction, matplotlib colour maps only). --backend auto
(default): gl when $DISPLAY is set, image otherwise. Errors: one line on stderr, exit status 1.
"""
import argparse
import math
import os
import re
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from render import MPL_NAMES, display_works, time_label  # noqa: E402
from vtkhdf_to_vti import InputError, image_cells, read_xdmf, resolve_input  # noqa: E402

PROG = "render_surface"

# ------------------------------------------------------------- muParser-style expressions -> numpy


def _nonzero(a):
    return np.asarray(a) != 0


_FUNCTIONS = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos,
    "atan": np.arctan, "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh, "asinh": np.arcsinh,
    "acosh": np.arccosh, "atanh": np.arctanh, "log2": np.log2, "log10": np.log10, "log": np.log,
    "ln": np.log, "exp": np.exp, "sqrt": np.sqrt, "sign": np.sign, "abs": np.abs,
    "rint": lambda a: np.floor(np.asarray(a) + 0.5),  # muParser rounds halves up
}
_VARIADIC = {
    "min": lambda *a: np.minimum.reduce(np.broadcast_arrays(*a)),
    "max": lambda *a: np.maximum.reduce(np.broadcast_arrays(*a)),
    "sum": lambda *a: sum(a),
    "avg": lambda *a: sum(a) / len(a),
}
_CONSTANTS = {"pi": math.pi, "_pi": math.pi, "_e": math.e}
_BINARY = {  # operator: (precedence, right-associative, function)
    "||": (1, False, lambda a, b: (_nonzero(a) | _nonzero(b)).astype(float)),
    "&&": (2, False, lambda a, b: (_nonzero(a) & _nonzero(b)).astype(float)),
    "==": (3, False, lambda a, b: np.asarray(a == b, dtype=float)),
    "!=": (3, False, lambda a, b: np.asarray(a != b, dtype=float)),
    "<": (3, False, lambda a, b: np.asarray(a < b, dtype=float)),
    ">": (3, False, lambda a, b: np.asarray(a > b, dtype=float)),
    "<=": (3, False, lambda a, b: np.asarray(a <= b, dtype=float)),
    ">=": (3, False, lambda a, b: np.asarray(a >= b, dtype=float)),
    "+": (4, False, lambda a, b: a + b),
    "-": (4, False, lambda a, b: a - b),
    "*": (5, False, lambda a, b: a * b),
    "/": (5, False, lambda a, b: a / b),
    "^": (7, True, lambda a, b: np.power(a, b)),
}
_UNARY_PRECEDENCE = 6  # -2^2 = -(2^2), as in muParser
_TOKEN = re.compile(r"\s*(?:(\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?)"
                    r"|([A-Za-z_]\w*)|(\|\||&&|==|!=|<=|>=|[-+*/^(),?:<>]))")


class ExpressionError(ValueError):
    pass


def compile_expression(text, variables=("u", "v"), constants=None):
    """A muParser-style expression -> function(**values) -> numpy value. Raises
    ExpressionError(message with the position) on a syntax error or an unknown name."""
    constants = dict(_CONSTANTS, **(constants or {}))
    tokens, pos = [], 0
    while pos < len(text):
        if not text[pos:].strip():
            break
        m = _TOKEN.match(text, pos)
        if not m:
            raise ExpressionError(f"unexpected character {text[pos:].lstrip()[0]!r} at position "
                                  f"{len(text) - len(text[pos:].lstrip())}")
        kind = "num" if m.group(1) else "name" if m.group(2) else "op"
        tokens.append((kind, m.group(m.lastindex), m.start(m.lastindex)))
        pos = m.end()
    if not tokens:
        raise ExpressionError("empty expression")
    tokens.append(("end", "", len(text)))
    i = 0

    def peek():
        return tokens[i]

    def take(value=None):
        nonlocal i
        tok = tokens[i]
        if value is not None and tok[1] != value:
            found = "end of expression" if tok[0] == "end" else repr(tok[1])
            raise ExpressionError(f"expected {value!r} at position {tok[2]}, found {found}")
        i += 1
        return tok

    def primary():
        kind, value, at = take()
        if kind == "num":
            number = float(value)
            return lambda env: number
        if kind == "op" and value in "+-" and value:
            operand = binary(_UNARY_PRECEDENCE)
            return (lambda env: -operand(env)) if value == "-" else operand
        if kind == "op" and value == "(":
            inner = ternary()
            take(")")
            return inner
        if kind == "name":
            if peek()[1] == "(" and (value in _FUNCTIONS or value in _VARIADIC):
                take("(")
                args = [ternary()]
                while peek()[1] == ",":
                    take(",")
                    args.append(ternary())
                take(")")
                if value in _FUNCTIONS:
                    if len(args) != 1:
                        raise ExpressionError(f"{value}() takes 1 argument, got {len(args)} "
                                              f"(position {at})")
                    f, a = _FUNCTIONS[value], args[0]
                    return lambda env: f(a(env))
                g = _VARIADIC[value]
                return lambda env: g(*[a(env) for a in args])
            if value in variables:
                return lambda env: env[value]
            if value in constants:
                c = float(constants[value])
                return lambda env: c
            allowed = ", ".join(list(variables) + sorted(constants))
            raise ExpressionError(f"unknown name {value!r} at position {at} (variables and "
                                  f"constants: {allowed})")
        found = "end of expression" if kind == "end" else repr(value)
        raise ExpressionError(f"unexpected {found} at position {at}")

    def binary(min_prec):
        left = primary()
        while True:
            op = peek()
            if op[0] != "op" or op[1] not in _BINARY:
                return left
            prec, right_assoc, f = _BINARY[op[1]]
            if prec < min_prec:
                return left
            take()
            right = binary(prec if right_assoc else prec + 1)
            left = (lambda f, a, b: lambda env: f(a(env), b(env)))(f, left, right)

    def ternary():
        cond = binary(1)
        if peek()[1] != "?":
            return cond
        take("?")
        a = ternary()
        take(":")
        b = ternary()
        return lambda env: np.where(_nonzero(cond(env)), a(env), b(env))

    tree = ternary()
    if peek()[0] != "end":
        raise ExpressionError(f"unexpected {peek()[1]!r} at position {peek()[2]}")

    def evaluate(**env):
        with np.errstate(all="ignore"):
            return tree(env)

    return evaluate


# -------------------------------------------------------------------------------- arguments


def parse_args(argv):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__.splitlines()[0])
    ap.add_argument("input", metavar="INPUT",
                    help="snapshot .vtkhdf, run directory, NAME.xmf or NAME.vtkhdf.series")
    ap.add_argument("--species", default=None, help="species to show (default: the first)")
    ap.add_argument("--surface-x", default="u", help="x(u, v) (default u)")
    ap.add_argument("--surface-y", default="v", help="y(u, v) (default v)")
    ap.add_argument("--surface-z", default="0", help="z(u, v) (default 0)")
    ap.add_argument("--output", default=None, help="PNG file (default NAME_<species>_surface.png)")
    ap.add_argument("--view", default="-60,30", help="camera AZ,EL in degrees (default -60,30)")
    ap.add_argument("--frame", type=int, default=-1,
                    help="output time of a run/.xmf/.series (index, default -1: the last)")
    ap.add_argument("--name", default=None, help="which NAME.xmf of a run directory")
    ap.add_argument("--size", default="800x600", help="image size WxH in pixels (default 800x600)")
    ap.add_argument("--cmap", default="Viridis (matplotlib)", help="colour map preset")
    ap.add_argument("--range", default=None, dest="crange",
                    help="colour range LO,HI (default: the data's min/max)")
    ap.add_argument("--seam", choices=("auto", "open"), default="auto",
                    help="close the seams of a closed surface (auto, default) or not")
    ap.add_argument("--no-bar", action="store_true", help="no colour bar")
    ap.add_argument("--no-time", action="store_true", help="no species/time label")
    ap.add_argument("--backend", choices=("auto", "gl", "image"), default="auto")
    args = ap.parse_args(argv)
    try:
        w, h = (int(v) for v in args.size.lower().split("x"))
        if w < 16 or h < 16:
            raise ValueError
        args.size = (w, h)
    except ValueError:
        ap.error(f"--size {args.size}: expected WxH, e.g. 800x600")
    try:
        az, el = (float(v) for v in args.view.split(","))
        if not (math.isfinite(az) and -90.0 <= el <= 90.0):
            raise ValueError
        args.view = (az, el)
    except ValueError:
        ap.error(f"--view {args.view}: expected AZ,EL in degrees with -90 <= EL <= 90")
    if args.crange is not None:
        try:
            lo, hi = (float(v) for v in args.crange.split(","))
            if not lo < hi:
                raise ValueError
            args.crange = (lo, hi)
        except ValueError:
            ap.error(f"--range {args.crange}: expected LO,HI with LO < HI")
    return args


# ------------------------------------------------------------------------------ data, surface


def load_plane(args, tmp):
    """INPUT -> dict(species, values (ny, nx), u (nx,), v (ny,), Lx, Ly, time, name)."""
    xmf, entries, run_name, _ = resolve_input([args.input], tmp, args.name)
    if not -len(entries) <= args.frame < len(entries):
        raise InputError(f"--frame {args.frame}: {args.input} has {len(entries)} output time(s)")
    entry = entries[args.frame]
    if len(entries) > 1:  # describe only the chosen file, so that only it is read
        sub = os.path.join(tmp, "frame")
        os.makedirs(sub)
        xmf, entries, _, _ = resolve_input([entry["file"]], sub)
        entries[0]["time"] = entry["time"]
    species = args.species or entries[0]["species"][0]
    if species not in entries[0]["species"]:
        raise InputError(f"no species {species} (the run has {', '.join(entries[0]['species'])})")
    from vtkmodules.util.numpy_support import vtk_to_numpy

    for e, image in read_xdmf(xmf, entries):
        pd, (nx, ny, nz), o, h = image_cells(image)  # o: the first cell centre
        if nz != 1:
            raise InputError(f"{e['file']}: a 3-D snapshot ({nx}x{ny}x{nz}); render_surface maps "
                             "2-D runs only")
        values = vtk_to_numpy(pd.GetArray(species)).reshape(ny, nx).astype(float)
        return dict(species=species, values=values, u=o[0] + h[0] * np.arange(nx),
                    v=o[1] + h[1] * np.arange(ny), Lx=nx * h[0], Ly=ny * h[1],
                    time=entry["time"], name=run_name)
    raise InputError(f"{args.input}: nothing read")


def surface(args, plane):
    """-> (X, Y, Z, values), each (rows, cols); seams closed where the surface closes."""
    consts = {"Lx": plane["Lx"], "Ly": plane["Ly"]}
    funcs = []
    for opt, text in (("--surface-x", args.surface_x), ("--surface-y", args.surface_y),
                      ("--surface-z", args.surface_z)):
        try:
            funcs.append((opt, text, compile_expression(text, constants=consts)))
        except ExpressionError as e:
            raise InputError(f"{opt} {text}: {e}")

    def evaluate(U, V):
        out = []
        for opt, text, f in funcs:
            value = np.broadcast_to(np.asarray(f(u=U, v=V), dtype=float), U.shape).copy()
            bad = ~np.isfinite(value)
            if bad.any():
                j, i = np.argwhere(bad)[0]
                raise InputError(f"{opt} {text}: not finite at (u, v) = ({U[j, i]!r}, {V[j, i]!r})")
            out.append(value)
        return out

    u, v, values = plane["u"], plane["v"], plane["values"]
    U, V = np.meshgrid(u, v)
    X = evaluate(U, V)
    if args.seam == "auto":
        size = max(float(np.ptp(c)) for c in X) or 1.0
        # close along u when X(u0 + Lx, v) = X(u0, v) for every v (likewise along v)
        Xu = evaluate(U[:, :1] + plane["Lx"], V[:, :1])
        if max(float(np.max(np.abs(a - b[:, :1]))) for a, b in zip(Xu, X)) <= 1e-9 * size:
            X = [np.concatenate([c, a], axis=1) for c, a in zip(X, Xu)]
            values = np.concatenate([values, values[:, :1]], axis=1)
            U = np.concatenate([U, U[:, :1] + plane["Lx"]], axis=1)
            V = np.concatenate([V, V[:, :1]], axis=1)
        Xv = evaluate(U[:1, :], V[:1, :] + plane["Ly"])
        if max(float(np.max(np.abs(a - b[:1, :]))) for a, b in zip(Xv, X)) <= 1e-9 * size:
            X = [np.concatenate([c, a], axis=0) for c, a in zip(X, Xv)]
            values = np.concatenate([values, values[:1, :]], axis=0)
    return X[0], X[1], X[2], values


def camera_direction(view):
    az, el = (math.radians(a) for a in view)
    return [math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)]


# ------------------------------------------------------------------------------ gl backend


def structured_grid(X, Y, Z, values, species):
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkStructuredGrid

    rows, cols = values.shape
    pts = np.ascontiguousarray(np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1))
    points = vtkPoints()
    points.SetData(numpy_to_vtk(pts, deep=True))
    grid = vtkStructuredGrid()
    grid.SetDimensions(cols, rows, 1)  # x (u) fastest: matches the row-major (rows, cols) order
    grid.SetPoints(points)
    arr = numpy_to_vtk(np.ascontiguousarray(values.ravel()), deep=True)
    arr.SetName(species)
    grid.GetPointData().AddArray(arr)
    return grid


def render_gl(args, X, Y, Z, values, plane, crange, path, tmp):
    from paraview import simple
    from vtkmodules.vtkIOXML import vtkXMLStructuredGridWriter

    species = plane["species"]
    vts = os.path.join(tmp, "surface.vts")
    writer = vtkXMLStructuredGridWriter()
    writer.SetFileName(vts)
    writer.SetInputData(structured_grid(X, Y, Z, values, species))
    if writer.Write() != 1:
        raise InputError(f"{vts}: could not write")
    reader = simple.XMLStructuredGridReader(FileName=[vts])
    view = simple.CreateRenderView()
    try:
        view.ViewSize = list(args.size)
        view.OrientationAxesVisibility = 0
        view.UseColorPaletteForBackground = 0
        view.Background = [1.0, 1.0, 1.0]
        lut = simple.GetColorTransferFunction(species)
        if not lut.ApplyPreset(args.cmap, True):
            raise InputError(f"--cmap {args.cmap}: no such ParaView colour map preset")
        rep = simple.Show(reader, view)
        rep.SetRepresentationType("Surface")
        simple.ColorBy(rep, ("POINTS", species))
        rep.LookupTable = lut
        rep.Specular = 0.15
        lut.RescaleTransferFunction(crange[0], crange[1])
        if not args.no_bar:
            rep.SetScalarBarVisibility(view, True)
            bar = simple.GetScalarBar(lut, view)
            bar.Title = species
            bar.ComponentTitle = ""
            bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
            bar.RangeLabelFormat = "%-#.5g"
            bar.WindowLocation = "Any Location"
            bar.Orientation = "Vertical"
            bar.Position = [0.8, 0.1]
            bar.ScalarBarLength = 0.8
        if not args.no_time:
            text = simple.Text(Text=f"{species}   {time_label(plane['time'])}")
            label = simple.Show(text, view)
            label.Color = [0.0, 0.0, 0.0]
            label.WindowLocation = "Upper Left Corner"
            label.FontSize = 14
        b = reader.GetDataInformation().GetBounds()
        center = [(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2]
        size = max(b[1] - b[0], b[3] - b[2], b[5] - b[4]) or 1.0
        d = camera_direction(args.view)
        view.CameraFocalPoint = center
        view.CameraPosition = [center[k] + 4 * size * d[k] for k in range(3)]
        view.CameraViewUp = [0, 0, 1] if abs(args.view[1]) < 89.9 else \
            [-math.cos(math.radians(args.view[0])), -math.sin(math.radians(args.view[0])), 0]
        view.CameraParallelProjection = 0
        view.ResetCamera()  # keeps the direction, fits the surface's bounding sphere
        simple.SaveScreenshot(path, view, ImageResolution=list(args.size))
        if not os.path.exists(path):
            raise InputError(f"{path}: ParaView wrote no image")
    finally:
        # Without this, Python's exit tears the GL context down first: X error, exit status 1.
        simple.Delete(view)


# ---------------------------------------------------------------------------- image backend


def render_image(args, X, Y, Z, values, plane, crange, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cmap_name = MPL_NAMES.get(args.cmap.lower(), args.cmap)
    if cmap_name not in plt.colormaps():
        raise InputError(f"--cmap {args.cmap}: the image backend knows matplotlib maps only")
    cmap = plt.get_cmap(cmap_name)
    norm = matplotlib.colors.Normalize(vmin=crange[0], vmax=crange[1])
    # facet (j, i) (between rows j, j+1 and columns i, i+1) takes the colour of its corner (j, i)
    rows, cols = values.shape
    step_r, step_c = max(1, (rows - 1) // 200), max(1, (cols - 1) // 200)
    sl = (slice(None, None, step_r), slice(None, None, step_c))
    Xs, Ys, Zs, Vs = X[sl], Y[sl], Z[sl], values[sl]
    w, h = args.size
    fig = plt.figure(figsize=(w / 100, h / 100), dpi=100)
    ax = fig.add_axes([0.0, 0.0, 0.84 if not args.no_bar else 1.0, 1.0], projection="3d")
    ax.plot_surface(Xs, Ys, Zs, facecolors=cmap(norm(Vs)), rstride=1, cstride=1, linewidth=0,
                    antialiased=False, shade=True)
    lo = [float(c.min()) for c in (X, Y, Z)]
    hi = [float(c.max()) for c in (X, Y, Z)]
    span = max(b - a for a, b in zip(lo, hi)) or 1.0
    ax.set_xlim(lo[0], hi[0] if hi[0] > lo[0] else lo[0] + 1e-3 * span)
    ax.set_ylim(lo[1], hi[1] if hi[1] > lo[1] else lo[1] + 1e-3 * span)
    ax.set_zlim(lo[2], hi[2] if hi[2] > lo[2] else lo[2] + 1e-3 * span)
    ax.set_box_aspect([max(b - a, 1e-3 * span) for a, b in zip(lo, hi)])
    ax.view_init(elev=args.view[1], azim=args.view[0])
    ax.set_axis_off()
    if not args.no_time:
        fig.text(0.02, 0.96, f"{plane['species']}   {time_label(plane['time'])}", va="top")
    if not args.no_bar:
        sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
        fig.colorbar(sm, cax=fig.add_axes([0.87, 0.1, 0.03, 0.8]))
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    # "--view -60,30": argparse would take -60,30 for an option (it is no plain negative number)
    argv = [f"--view={argv[k + 1]}" if a == "--view" and k + 1 < len(argv) else a
            for k, a in enumerate(argv) if not (k > 0 and argv[k - 1] == "--view")]
    args = parse_args(argv)
    try:
        with tempfile.TemporaryDirectory(prefix="morphogen_render_surface_") as tmp:
            plane = load_plane(args, tmp)
            X, Y, Z, values = surface(args, plane)
            crange = args.crange or (float(values.min()), float(values.max()))
            if crange[1] <= crange[0]:
                pad = 0.5 * max(abs(crange[0]), 1e-12)
                crange = (crange[0] - pad, crange[1] + pad)
            path = args.output or f"{plane['name']}_{plane['species']}_surface.png"
            if os.path.dirname(path):
                os.makedirs(os.path.dirname(path), exist_ok=True)
            backend = args.backend
            if backend == "auto":
                backend = "gl" if display_works() else "image"
            if backend == "gl":
                if not os.environ.get("DISPLAY"):
                    raise InputError("--backend gl needs an X display (Debian's ParaView has no "
                                     "offscreen rendering): run under xvfb-run (see --help), or "
                                     "use --backend image")
                render_gl(args, X, Y, Z, values, plane, crange, path, tmp)
            else:
                render_image(args, X, Y, Z, values, plane, crange, path)
            print(path)
    except InputError as e:
        sys.stderr.write(f"{PROG}: error: {e}\n")
        return 1
    return 0


if __name__ == "__main__":
    status = main()
    if status:  # no sys.exit(0): under pvbatch it can end in an X error at teardown
        sys.exit(status)

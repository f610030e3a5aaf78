#!/usr/bin/python3
"""Phase-diagram figures of a `morphogen sweep` output directory.

    /usr/bin/python3 postproc/phase_diagram.py SWEEP_DIR [--species a] [--out-prefix SWEEP_DIR/phase]
                                               [--thumb-px 64] [--swap-axes]

Reads SWEEP_DIR/sweep.json (written by `morphogen sweep DECK.yaml`) and the final fields
SWEEP_DIR/points/point_<i>.vtkhdf, and writes

  <prefix>_mosaic.png   Munafo / Pearson-map style mosaic: every point's final field of the
                        analysed species as a thumbnail (viridis, each thumbnail normalised to
                        its own min..max; a uniform field is drawn in one colour, its value on
                        the range of all points, so the different homogeneous states differ),
                        placed at its parameter position;
  <prefix>_classes.png  the class of every point in a fixed colour per class (legend with the
                        counts), with the Turing-instability boundary of sweep.json's
                        "stability_map" drawn over it as a solid line and the Hopf boundary as
                        a dashed line, where the map has them;

and prints a one-line summary. The default prefix is SWEEP_DIR/phase.

The first sweep axis runs along x, the second along y (--swap-axes exchanges them); the axes
are labelled with the option names without their `params_` prefix and the values are the tick
labels. An axis whose values are geometrically spaced (logspace) is drawn as a log axis;
another irregular list of values is drawn evenly spaced (categorical). Points not in
sweep.json (an unfinished sweep) are blank (light grey) cells; a point whose field file is
missing shows its class only. A 1-axis sweep gives a strip, a 3-axis sweep one panel per
value of the third axis (at most 16 panels). Non-finite values (blow-ups) are drawn black.

A sweep over a list of points (`-sweep_points`, e.g. a screen's Turing-unstable sets) has no
grid: <prefix>_classes.png is then a scatter plot of the points over the first two axes (one
axis: over the point index), coloured by class, and <prefix>_mosaic.png the thumbnails in point
order (at most 400, evenly chosen), each labelled with its axis values.
Bad input: a one-line error on stderr and exit status 1.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.colors as mcolors  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

PROG = "phase_diagram"

# Fixed colour per class (in legend order); "missing" is a point without a record.
CLASS_COLOURS = {
    "uniform": "#cfcfcf",
    "spots": "#1f77b4",
    "holes": "#17becf",
    "stripes": "#ff7f0e",
    "labyrinth": "#d62728",
    "mixed": "#9467bd",
    "oscillating": "#2ca02c",
    "chaotic": "#8c564b",
    "blowup": "#000000",
}
OTHER_COLOUR = "#bcbd22"  # a class name this script does not know
MISSING_COLOUR = "#f2f2f2"
TURING_COLOUR = "#000000"
HOPF_COLOUR = "#e6007e"
NONFINITE_RGBA = (0.0, 0.0, 0.0, 1.0)
MAX_PANELS = 16
PANEL_COLUMNS = 4
DPI = 100


class InputError(Exception):
    """Bad input: reported as one line and exit status 1."""


# ----------------------------------------------------------------------------------------------
# Axes
# ----------------------------------------------------------------------------------------------

def axis_kind(values):
    """'linear' (evenly spaced), 'log' (geometric, positive, not also evenly spaced) or 'index'
    (anything else, including a single value)."""
    v = np.asarray(values, dtype=float)
    if v.size < 2 or not np.all(np.isfinite(v)):
        return "index"
    d = np.diff(v)
    if np.all(d != 0) and np.allclose(d, d[0], rtol=1e-6, atol=0):
        return "linear"
    if v.size > 2 and (np.all(v > 0) or np.all(v < 0)):
        r = v[1:] / v[:-1]
        if np.all(r != 1) and np.allclose(r, r[0], rtol=1e-6, atol=0):
            return "log"
    return "index"


def strip_prefix(option):
    return option[len("params_"):] if option.startswith("params_") else option


def fmt_value(x):
    return "%.4g" % x


class Axis:
    """One sweep axis and its plot coordinate u: the value (linear), log10 |value| (log) or the
    index (irregular). u is evenly spaced in the index in all three cases."""

    def __init__(self, option, values):
        self.option = option
        self.values = [float(x) for x in values]
        self.n = len(self.values)
        self.label = strip_prefix(option) if option else ""
        self.kind = axis_kind(self.values)
        v = np.asarray(self.values)
        if self.kind == "linear":
            self.u = v.copy()
        elif self.kind == "log":
            self.u = np.log10(np.abs(v))
        else:
            self.u = np.arange(self.n, dtype=float)
        self.du = (self.u[-1] - self.u[0]) / (self.n - 1) if self.n > 1 else 1.0

    def edges(self):
        return self.u[0] - 0.5 * self.du, self.u[-1] + 0.5 * self.du

    def u_at_fraction(self, f):
        """Plot coordinate at fractional index f (f = 0 .. n-1; linear in u)."""
        return self.u[0] + np.asarray(f, dtype=float) * self.du

    def title(self):
        if not self.option:
            return ""
        return self.label + (" (log scale)" if self.kind == "log" else "")

    def index_of(self, value):
        """Index of the axis value nearest to `value`."""
        v = np.asarray(self.values)
        return int(np.argmin(np.abs(v - value)))


def dummy_axis():
    return Axis("", [0.0])


# ----------------------------------------------------------------------------------------------
# Input
# ----------------------------------------------------------------------------------------------

def load_sweep(directory):
    """sweep.json of `directory` as a dict, checked; raises InputError."""
    if not os.path.isdir(directory):
        raise InputError(f"{directory}: no such directory")
    path = os.path.join(directory, "sweep.json")
    if not os.path.isfile(path):
        raise InputError(f"{path}: not found (not a `morphogen sweep` output directory?)")
    try:
        with open(path) as f:
            sweep = json.load(f)
    except (OSError, ValueError) as e:
        raise InputError(f"{path}: cannot read: {e}")
    if not isinstance(sweep, dict) or not isinstance(sweep.get("axes"), list) or not sweep["axes"]:
        raise InputError(f"{path}: no \"axes\" list")
    for a in sweep["axes"]:
        if not isinstance(a, dict) or not isinstance(a.get("option"), str) \
                or not isinstance(a.get("values"), list) or not a["values"]:
            raise InputError(f"{path}: an axis without \"option\" and \"values\"")
        try:
            [float(x) for x in a["values"]]
        except (TypeError, ValueError):
            raise InputError(f"{path}: axis {a['option']}: non-numeric values")
    if len(sweep["axes"]) > 3 and "points_file" not in sweep:
        raise InputError(f"{path}: {len(sweep['axes'])} axes; only 1-, 2- and 3-axis sweeps can be drawn")
    recs = sweep.get("records", [])
    if not isinstance(recs, list):
        raise InputError(f"{path}: \"records\" is not a list")
    sweep["records"] = [r for r in recs if isinstance(r, dict)]
    return sweep


def record_index(rec, axes):
    """The point number of a record: its "index", else found from its parameter values."""
    if isinstance(rec.get("index"), int):
        return rec["index"]
    params = rec.get("params", {})
    p, stride = 0, 1
    for a in axes:
        if a.option not in params:
            return None
        p += a.index_of(float(params[a.option])) * stride
        stride *= a.n
    return p


def read_field(path, species):
    """2-D array (ny, nx) of `species` in a VTKHDF file (the middle z slice in 3-D), and the
    species name used. Uses postproc/morphogen_h5.py when present, else h5py."""
    arr = None
    try:
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import morphogen_h5  # noqa: F401  (another engineer's reader; optional)

        snap = morphogen_h5.read_snapshot(path)
        fields = snap["fields"]
        if species is None:
            species = (list(snap.get("species") or []) or sorted(fields))[0]
        arr = np.asarray(fields[species])
    except Exception:  # noqa: BLE001 - missing/unknown reader: read it here
        arr = None
    finally:
        if sys.path and sys.path[0] == os.path.dirname(os.path.abspath(__file__)):
            sys.path.pop(0)
    if arr is None:
        import h5py

        with h5py.File(path, "r") as f:
            g = f["VTKHDF"]
            pd = g["PointData"] if "PointData" in g else g["CellData"]  # either layout
            if species is None:
                species = sorted(pd.keys())[0]
            if species not in pd:
                raise KeyError(f"no species {species!r} (has {', '.join(sorted(pd.keys()))})")
            arr = np.asarray(pd[species][...])
    if arr.ndim == 3:
        arr = arr[arr.shape[0] // 2]
    if arr.ndim != 2:
        raise ValueError(f"field of shape {arr.shape}")
    return arr.astype(float), species


def box_resample(a, ny, nx):
    """Resample a 2-D array to (ny, nx): box average when shrinking, nearest when growing."""
    out = a
    for axis, n in ((0, ny), (1, nx)):
        m = out.shape[axis]
        if m >= n:
            e = (np.arange(n + 1) * m) // n
            s = np.add.reduceat(out, e[:-1], axis=axis)
            cnt = np.diff(e).astype(float)
            out = s / (cnt[:, None] if axis == 0 else cnt[None, :])
        else:
            idx = ((np.arange(n) + 0.5) * m / n).astype(int)
            out = np.take(out, idx, axis=axis)
    return out


# ----------------------------------------------------------------------------------------------
# The data of the figures
# ----------------------------------------------------------------------------------------------

class Sweep:
    def __init__(self, directory, sweep, species=None, swap=False):
        self.dir = directory
        self.raw = sweep
        self.axes = [Axis(a["option"], a["values"]) for a in sweep["axes"]]
        self.naxes = len(self.axes)
        self.points = int(np.prod([a.n for a in self.axes]))
        self.by_index = {}
        for r in sweep["records"]:
            p = record_index(r, self.axes)
            if p is not None and 0 <= p < self.points:
                self.by_index[p] = r
        self.species = species
        if self.species is None:
            for r in self.by_index.values():
                if isinstance(r.get("species"), str):
                    self.species = r["species"]
                    break
        self.model = next((r.get("model") for r in self.by_index.values() if r.get("model")), "")
        # plot axes: x, y (1-axis: a dummy y), and the panel axis (3-axis)
        x, y = (self.axes + [dummy_axis()])[:2]
        self.swap = swap and self.naxes >= 2
        self.xaxis, self.yaxis = (y, x) if self.swap else (x, y)
        self.paxis = self.axes[2] if self.naxes == 3 else None
        if self.paxis is not None and self.paxis.n > MAX_PANELS:
            raise InputError(
                f"3-axis sweep with {self.paxis.n} values of {self.paxis.option}: more than "
                f"{MAX_PANELS} panels; sweep at most {MAX_PANELS} values on the third axis")
        self.stability = self._stability()

    def npanels(self):
        return self.paxis.n if self.paxis is not None else 1

    def point(self, ix, iy, ip=0):
        """Point number of plot cell (ix, iy) of panel ip."""
        i0, i1 = (iy, ix) if self.swap else (ix, iy)
        n0 = self.axes[0].n
        n1 = self.axes[1].n if self.naxes > 1 else 1
        return i0 + n0 * (i1 + n1 * ip)

    def classes(self):
        counts = {}
        for r in self.by_index.values():
            c = str(r.get("class", "?"))
            counts[c] = counts.get(c, 0) + 1
        return counts

    def _stability(self):
        """{"turing": bool array, "hopf": ..., "axes": [refined values...]} reshaped to
        (m_last, ..., m0), or None when the map is missing or inconsistent."""
        sm = self.raw.get("stability_map")
        if not isinstance(sm, dict) or not isinstance(sm.get("axes"), list):
            return None
        axes = sm["axes"]
        if len(axes) != self.naxes:
            return None
        try:
            m = [len(a) for a in axes]
            shape = tuple(reversed(m))
            out = {"m": m}
            for key in ("turing", "hopf", "hopf_region"):
                v = sm.get(key)
                if isinstance(v, list) and len(v) == int(np.prod(m)):
                    out[key] = np.asarray([bool(b) for b in v]).reshape(shape)
            if "turing" not in out and "hopf" not in out:
                return None
            out["axes"] = [np.asarray(a, dtype=float) for a in axes]
            return out
        except (TypeError, ValueError):
            return None

    def stability_slice(self, key, ip):
        """(u_x, u_y, mask[y, x]) of the stability map on panel ip, or None."""
        st = self.stability
        if st is None or key not in st:
            return None
        mask = st[key]
        if self.naxes == 3:
            pvalue = self.paxis.values[ip]
            k = int(np.argmin(np.abs(st["axes"][2] - pvalue)))
            mask = mask[k]
        if self.naxes == 1:
            mask = mask.reshape(1, -1)
        # mask is [i1, i0]; fractional index of refined sample r: r (n - 1) / (m - 1)
        def coords(axis, m):
            if axis.n < 2 or m < 2:
                return np.array([axis.u[0]])
            return axis.u_at_fraction(np.arange(m) * (axis.n - 1) / (m - 1))

        u0 = coords(self.axes[0], mask.shape[1])
        u1 = coords(self.axes[1], mask.shape[0]) if self.naxes > 1 else np.array([0.0])
        # the map spans the first to the last value (cell centres): repeat its edge samples at
        # the cell edges so that a boundary reaches the frame
        if mask.shape[1] >= 2:
            e = self.axes[0].edges()
            u0 = np.concatenate(([e[0]], u0, [e[1]]))
            mask = np.concatenate((mask[:, :1], mask, mask[:, -1:]), axis=1)
        if mask.shape[0] >= 2 and self.naxes > 1:
            e = self.axes[1].edges()
            u1 = np.concatenate(([e[0]], u1, [e[1]]))
            mask = np.concatenate((mask[:1], mask, mask[-1:]), axis=0)
        if self.swap:
            return u1, u0, mask.T
        return u0, u1, mask


# ----------------------------------------------------------------------------------------------
# Layout: panels of fixed pixel size, so a data position maps to a known PNG pixel
# ----------------------------------------------------------------------------------------------

def panel_layout(npanels, pw, ph, right_px, title_px=34):
    """Figure and axes list: panels of pw x ph pixels in a grid of at most 4 columns."""
    ncols = min(npanels, PANEL_COLUMNS)
    nrows = int(math.ceil(npanels / ncols))
    left, bottom, gap_x, gap_y, top = 80, 62, 70, 50, title_px
    pt = 22 if npanels > 1 else 0  # panel title
    W = left + ncols * pw + (ncols - 1) * gap_x + right_px
    H = top + nrows * (ph + pt) + (nrows - 1) * gap_y + bottom
    W, H = max(W, 320), max(H, 160)
    fig = plt.figure(figsize=(W / DPI, H / DPI), dpi=DPI)
    axes = []
    for p in range(npanels):
        r, c = divmod(p, ncols)
        x0 = left + c * (pw + gap_x)
        y0 = H - top - pt - r * (ph + pt + gap_y) - ph
        axes.append(fig.add_axes([x0 / W, y0 / H, pw / W, ph / H]))
    return fig, axes, (W, H)


def label_axes(ax, sweep, pw, ph, ylabel=True):
    for axis, pixels, setter, lab, horizontal in (
            (sweep.xaxis, pw, ax.set_xticks, ax.set_xlabel, True),
            (sweep.yaxis, ph, ax.set_yticks, ax.set_ylabel, False)):
        if not axis.option:
            setter([])
            continue
        labels = [fmt_value(v) for v in axis.values]
        width = max(len(s) for s in labels) * 6.5 + 8 if horizontal else 14
        stride = max(1, int(math.ceil(axis.n * width / max(pixels, 1))))
        idx = list(range(0, axis.n, stride))
        setter([axis.u[i] for i in idx])
        if horizontal:
            ax.set_xticklabels([labels[i] for i in idx], fontsize=8)
        else:
            ax.set_yticklabels([labels[i] for i in idx], fontsize=8)
        if horizontal or ylabel:
            lab(axis.title(), fontsize=10)
    x0, x1 = sweep.xaxis.edges()
    y0, y1 = sweep.yaxis.edges()
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)


def panel_title(ax, sweep, ip):
    if sweep.paxis is not None:
        ax.set_title(f"{sweep.paxis.label} = {fmt_value(sweep.paxis.values[ip])}", fontsize=9)


def extent(sweep):
    x0, x1 = sweep.xaxis.edges()
    y0, y1 = sweep.yaxis.edges()
    return (x0, x1, y0, y1)


# ----------------------------------------------------------------------------------------------
# Mosaic
# ----------------------------------------------------------------------------------------------

def load_thumbnails(sweep, cell):
    """{point: float array (t, t) or None (uniform: then "uniform_value")}, value range of all
    fields, count of unreadable field files."""
    thumbs, lo, hi, unreadable = {}, math.inf, -math.inf, 0
    gap = 1 if cell >= 16 else 0
    t = cell - 2 * gap
    for p, rec in sweep.by_index.items():
        f = rec.get("file")
        if not isinstance(f, str):
            unreadable += 1
            continue
        path = f if os.path.isabs(f) else os.path.join(sweep.dir, f)
        try:
            field, species = read_field(path, sweep.species)
        except Exception:  # noqa: BLE001 - a missing or unreadable file: class only
            unreadable += 1
            continue
        if sweep.species is None:
            sweep.species = species
        finite = np.isfinite(field)
        if finite.any():
            lo, hi = min(lo, float(field[finite].min())), max(hi, float(field[finite].max()))
        ny, nx = field.shape
        s = t / max(ny, nx)
        ty, tx = max(1, int(round(ny * s))), max(1, int(round(nx * s)))
        thumbs[p] = (box_resample(np.where(finite, field, np.nan), ty, tx), gap)
    return thumbs, (lo, hi), unreadable


def mosaic_canvas(sweep, thumbs, vrange, cell, ip):
    cmap = plt.get_cmap("viridis")
    nx, ny = sweep.xaxis.n, sweep.yaxis.n
    canvas = np.ones((ny * cell, nx * cell, 4))
    canvas[...] = mcolors.to_rgba("white")
    lo, hi = vrange
    for iy in range(ny):
        for ix in range(nx):
            p = sweep.point(ix, iy, ip)
            y0, x0 = iy * cell, ix * cell
            if p not in sweep.by_index:
                canvas[y0:y0 + cell, x0:x0 + cell] = mcolors.to_rgba(MISSING_COLOUR)
                continue
            if p not in thumbs:
                continue
            a, gap = thumbs[p]
            fin = np.isfinite(a)
            if fin.any():
                amin, amax = float(a[fin].min()), float(a[fin].max())
                scale = max(abs(amin), abs(amax), 1e-300)
                if amax - amin > 1e-9 * scale:
                    norm = (a - amin) / (amax - amin)
                else:  # uniform: one colour, its value on the range of all points
                    v = 0.5 if not (hi > lo) else (0.5 * (amin + amax) - lo) / (hi - lo)
                    norm = np.full(a.shape, v)
            else:
                norm = np.zeros(a.shape)
            rgba = cmap(np.clip(np.nan_to_num(norm), 0, 1))
            rgba[~fin] = NONFINITE_RGBA
            th, tw = a.shape
            oy = y0 + gap + (cell - 2 * gap - th) // 2
            ox = x0 + gap + (cell - 2 * gap - tw) // 2
            canvas[oy:oy + th, ox:ox + tw] = rgba
    return canvas


def write_mosaic(sweep, path, thumb_px=64):
    nmax = max(sweep.xaxis.n, sweep.yaxis.n)
    cell = max(int(thumb_px), int(math.ceil(240 / nmax)))
    cell = max(4, min(cell, 8000 // nmax))  # keep the figure below ~8000 px a side
    thumbs, vrange, unreadable = load_thumbnails(sweep, cell)
    pw, ph = sweep.xaxis.n * cell, sweep.yaxis.n * cell
    fig, axes, (_, H) = panel_layout(sweep.npanels(), pw, ph, right_px=30, title_px=46)
    for ip, ax in enumerate(axes):
        ax.imshow(mosaic_canvas(sweep, thumbs, vrange, cell, ip), origin="lower",
                  extent=extent(sweep), aspect="auto", interpolation="nearest")
        label_axes(ax, sweep, pw, ph, ylabel=ip % PANEL_COLUMNS == 0)
        panel_title(ax, sweep, ip)
    fig.suptitle(f"{sweep.model or 'sweep'}: final {sweep.species or 'field'}\n"
                 f"{len(sweep.by_index)}/{sweep.points} points, each thumbnail min..max",
                 fontsize=9, y=1 - 6 / H, va="top")
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return len(thumbs), unreadable


# ----------------------------------------------------------------------------------------------
# Class map
# ----------------------------------------------------------------------------------------------

def class_colour(c):
    return CLASS_COLOURS.get(c, OTHER_COLOUR)


def draw_boundary(ax, sweep, key, ip, colour, style):
    """Contour of the stability flag `key` on panel ip; True when a boundary was drawn."""
    s = sweep.stability_slice(key, ip)
    if s is None:
        return False
    ux, uy, mask = s
    m = mask.astype(float)
    if not (mask.any() and not mask.all()):
        return False
    kw = dict(colors=colour, linewidths=2.0, linestyles=style)
    if m.shape[0] >= 2 and m.shape[1] >= 2:
        cs = ax.contour(ux, uy, m, levels=[0.5], **kw)
        for c in cs.collections:  # stay inside the panel
            c.set_clip_path(ax.patch)
        return True
    # a 1-D map: lines where the flag changes, across the strip
    line = m.ravel()
    along_x = m.shape[1] >= 2
    u = ux if along_x else uy
    for r in np.nonzero(line[1:] != line[:-1])[0]:
        c = 0.5 * (u[r] + u[r + 1])
        (ax.axvline if along_x else ax.axhline)(c, color=colour, lw=2.0, ls=style)
    return True


def write_class_map(sweep, path, cell=None):
    """Writes the class map; returns {point: (row, col)}, the pixel centre of every cell in
    the PNG (row 0 at the top)."""
    nmax = max(sweep.xaxis.n, sweep.yaxis.n)
    if cell is None:
        cell = int(min(64, max(10, 640 // nmax)))
    pw, ph = sweep.xaxis.n * cell, sweep.yaxis.n * cell
    fig, axes, (W, H) = panel_layout(sweep.npanels(), pw, ph, right_px=190)
    drawn = {"turing": False, "hopf": False}
    for ip, ax in enumerate(axes):
        img = np.zeros((sweep.yaxis.n, sweep.xaxis.n, 4))
        for iy in range(sweep.yaxis.n):
            for ix in range(sweep.xaxis.n):
                rec = sweep.by_index.get(sweep.point(ix, iy, ip))
                img[iy, ix] = mcolors.to_rgba(MISSING_COLOUR if rec is None
                                              else class_colour(str(rec.get("class", "?"))))
        ax.imshow(img, origin="lower", extent=extent(sweep), aspect="auto",
                  interpolation="nearest")
        drawn["turing"] |= draw_boundary(ax, sweep, "turing", ip, TURING_COLOUR, "solid")
        # the Hopf line (trace J = 0 where det J > 0): the edge of "hopf_region"; sweep.json files
        # written before it existed only have "hopf" (a complex pair with Re > 0), whose edge
        # also follows trace^2 = 4 det, which is not a stability boundary
        hopf_key = "hopf_region" if sweep.stability and "hopf_region" in sweep.stability else "hopf"
        drawn["hopf"] |= draw_boundary(ax, sweep, hopf_key, ip, HOPF_COLOUR, "dashed")
        label_axes(ax, sweep, pw, ph, ylabel=ip % PANEL_COLUMNS == 0)
        panel_title(ax, sweep, ip)
    counts = sweep.classes()
    order = [c for c in CLASS_COLOURS if c in counts] + sorted(c for c in counts if c not in CLASS_COLOURS)
    handles = [Patch(facecolor=class_colour(c), edgecolor="0.5", label=f"{c} ({counts[c]})") for c in order]
    missing = sweep.points - len(sweep.by_index)
    if missing:
        handles.append(Patch(facecolor=MISSING_COLOUR, edgecolor="0.5", label=f"not run ({missing})"))
    if drawn["turing"]:
        handles.append(Line2D([], [], color=TURING_COLOUR, lw=2, label="Turing boundary"))
    if drawn["hopf"]:
        handles.append(Line2D([], [], color=HOPF_COLOUR, lw=2, ls="--", label="Hopf boundary"))
    fig.legend(handles=handles, loc="upper left", fontsize=8, frameon=False,
               bbox_to_anchor=(1 - 180 / W, 1 - 40 / H))
    fig.suptitle(f"{sweep.model or 'sweep'}: pattern classes ({len(sweep.by_index)}/{sweep.points} points)",
                 fontsize=10, y=1 - 8 / H, va="top")
    fig.canvas.draw()
    centres = {}
    for ip, ax in enumerate(axes):
        for iy in range(sweep.yaxis.n):
            for ix in range(sweep.xaxis.n):
                x, y = ax.transData.transform((sweep.xaxis.u[ix], sweep.yaxis.u[iy]))
                centres[sweep.point(ix, iy, ip)] = (int(round(H - y - 0.5)), int(round(x - 0.5)))
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return centres, drawn


# ----------------------------------------------------------------------------------------------

def summary_line(sweep, mosaic, classes, nthumbs, unreadable, drawn):
    axes = " x ".join(f"{a.label} ({a.n}{', log' if a.kind == 'log' else ''})" for a in sweep.axes)
    counts = sweep.classes()
    cls = ", ".join(f"{c} {counts[c]}" for c in sorted(counts, key=lambda c: (-counts[c], c))) or "none"
    if sweep.stability is None:
        bound = "no stability map"
    else:
        parts = [k for k in ("turing", "hopf") if drawn[k]]
        bound = ("boundaries: " + ", ".join(parts)) if parts else "no stability boundary in range"
    extra = f", {unreadable} field files unreadable" if unreadable else ""
    return (f"{PROG}: {sweep.dir}: {len(sweep.by_index)}/{sweep.points} points, axes {axes}; "
            f"classes: {cls}; {bound}; {nthumbs} thumbnails{extra}; wrote {mosaic}, {classes}")


MAX_LISTED_THUMBS = 400


def write_listed(directory, raw, prefix, species, thumb_px):
    """The figures of a listed sweep (see the module text); returns the summary line."""
    recs = sorted((r for r in raw["records"] if isinstance(r.get("index"), int)),
                  key=lambda r: r["index"])
    opts = [a["option"] for a in raw["axes"]]
    labels = [strip_prefix(o) for o in opts]
    fig, ax = plt.subplots(figsize=(7, 5.5))
    counts = {}
    for r in recs:
        counts[r.get("class", "?")] = counts.get(r.get("class", "?"), 0) + 1
    for c in sorted(counts, key=lambda c: (-counts[c], c)):
        sel = [r for r in recs if r.get("class", "?") == c]
        xs = [r["params"].get(opts[0]) if len(opts) > 1 else r["index"] for r in sel]
        ys = [r["params"].get(opts[1 if len(opts) > 1 else 0]) for r in sel]
        ax.scatter(xs, ys, s=18, color=CLASS_COLOURS.get(c, OTHER_COLOUR), label=f"{c} ({counts[c]})",
                   edgecolors="none")
    ax.set_xlabel(labels[0] if len(opts) > 1 else "point")
    ax.set_ylabel(labels[1] if len(opts) > 1 else labels[0])
    ax.legend(fontsize=8, loc="best")
    ax.set_title(f"{len(recs)}/{raw.get('points', len(recs))} points of {raw.get('points_file', '')}")
    fig.savefig(prefix + "_classes.png", dpi=DPI)
    plt.close(fig)
    step = max(1, math.ceil(len(recs) / MAX_LISTED_THUMBS))
    shown = recs[::step]
    cols = max(1, min(10, len(shown)))
    rows = max(1, math.ceil(len(shown) / cols))
    size = max(thumb_px, 48) / DPI
    fig, axes = plt.subplots(rows, cols, figsize=(cols * size * 1.6, rows * size * 1.9), squeeze=False)
    for a in axes.flat:
        a.axis("off")
    for a, r in zip(axes.flat, shown):
        f = r.get("file")
        if isinstance(f, str) and os.path.isfile(os.path.join(directory, f)):
            arr, _ = read_field(os.path.join(directory, f), species or r.get("species"))
            a.imshow(arr, origin="lower", cmap="viridis", interpolation="nearest")
        a.set_title(f"{r['index']}: " + ", ".join(f"{fmt_value(r['params'].get(o, float('nan')))}"
                                                  for o in opts) + f"\n{r.get('class', '?')}",
                    fontsize=6)
    fig.tight_layout()
    fig.savefig(prefix + "_mosaic.png", dpi=DPI)
    plt.close(fig)
    cls = ", ".join(f"{c} {counts[c]}" for c in sorted(counts, key=lambda c: (-counts[c], c))) or "none"
    return (f"{PROG}: {directory}: {len(recs)}/{raw.get('points', len(recs))} listed points "
            f"({', '.join(labels)}); classes: {cls}; {len(shown)} thumbnails; wrote "
            f"{prefix}_mosaic.png, {prefix}_classes.png")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sweep_dir")
    ap.add_argument("--species", default=None, help="species drawn (default: the analysed one)")
    ap.add_argument("--out-prefix", default=None, help="output prefix (default SWEEP_DIR/phase)")
    ap.add_argument("--thumb-px", type=int, default=64, help="thumbnail size in pixels (default 64)")
    ap.add_argument("--swap-axes", action="store_true", help="first sweep axis along y, second along x")
    args = ap.parse_args(argv)
    try:
        if args.thumb_px < 4:
            raise InputError(f"--thumb-px {args.thumb_px}: must be at least 4")
        raw = load_sweep(args.sweep_dir)
        if "points_file" in raw:
            prefix = args.out_prefix or os.path.join(args.sweep_dir, "phase")
            print(write_listed(args.sweep_dir, raw, prefix, args.species, args.thumb_px))
            return 0
        sweep = Sweep(args.sweep_dir, raw, args.species, args.swap_axes)
        prefix = args.out_prefix or os.path.join(args.sweep_dir, "phase")
        outdir = os.path.dirname(prefix)
        if outdir and not os.path.isdir(outdir):
            raise InputError(f"{outdir}: no such directory (for --out-prefix)")
        mosaic, classes = prefix + "_mosaic.png", prefix + "_classes.png"
        if args.species is not None and sweep.by_index:
            # a wrong species name is an error, not a mosaic of blanks
            rec = next(iter(sweep.by_index.values()))
            f = rec.get("file")
            if isinstance(f, str) and os.path.isfile(os.path.join(args.sweep_dir, f)):
                try:
                    read_field(os.path.join(args.sweep_dir, f), args.species)
                except Exception as e:  # noqa: BLE001
                    msg = e.args[0] if isinstance(e, KeyError) and e.args else e
                    raise InputError(f"{os.path.join(args.sweep_dir, f)}: {msg}")
        nthumbs, unreadable = write_mosaic(sweep, mosaic, args.thumb_px)
        _, drawn = write_class_map(sweep, classes)
    except InputError as e:
        sys.exit(f"{PROG}: error: {e}")
    except OSError as e:
        sys.exit(f"{PROG}: error: {e}")
    print(summary_line(sweep, mosaic, classes, nthumbs, unreadable, drawn))
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""Shapes of the spots of a 2-D pattern, the orientation of stripes, and the stretch of a 2-D
or 3-D pattern (numpy only; used by tests/analysis/test_classify_decks.py).

    /usr/bin/python3 postproc/spot_shapes.py RUN_DIR_OR_FILE [--species b] [--theta EXPR]
        [--json] [--thirds]

Reads a checkpoint or snapshot (a run directory: its newest checkpoint, else newest snapshot).
Spots: the cells above the midrange (min + max) / 2, 4-connected, wrapping across periodic
axes (the same phase as the C++ pattern metrics); components of at most 2 cells are ignored.
Per spot: area (cells), centroid, second moments about the centroid (plus 1/12 per axis for
the cells' own extent) with eigenvalues l1 >= l2: elongation sqrt(l1 / l2), major-axis angle
from x in degrees (-90, 90].

With --theta (an expression of x, y, Lx, Ly, r, theta, pi, atan2, sqrt, sin, cos, ...), or
by default the run's own -tensor_theta read from the checkpoint's options (when it parses),
each spot's major axis is compared with the tensor's first principal direction at its
centroid: the orientation error is the angle between the two lines (0..90 degrees). (Not by
default for a surface-corrected run, whose tensor is meant on the surface.)

Printed summary: spots, mean/CV of area, mean/CV of elongation, mean and 90th percentile of
the orientation error, the stripe orientation (structure tensor; see stripe_orientation) and
with --thirds the mean spot area in the left, middle and right thirds of the domain (x).
"""
import argparse
import glob
import json
import math
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import morphogen_h5 as mh  # noqa: E402


def newest_file(path):
    """A run directory -> its newest checkpoint (else snapshot); a file -> itself."""
    if not os.path.isdir(path):
        return path
    for pattern in ("checkpoint_*.vtkhdf", "*_[0-9]*.vtkhdf"):
        files = sorted(glob.glob(os.path.join(path, pattern)))
        if files:
            return files[-1]
    raise SystemExit(f"{path}: no checkpoint or snapshot")


def run_options(snap):
    """The run's options (from the checkpoint's /morphogen options text), {} if none."""
    text = snap.get("attrs", {}).get("options", "")
    out = {}
    for line in str(text).splitlines():
        m = re.match(r'^(\w+):\s*"(.*)"\s*$', line)
        if m:
            out[m.group(1)] = m.group(2)
    return out


def load(path, species=None):
    """(field float64: (ny, nx) in 2-D, (nz, ny, nx) in 3-D; spacing (hx, hy[, hz]); periodic
    per axis (x, y[, z]); the run's options; species)."""
    f = newest_file(path)
    snap = mh.read_snapshot(f)
    species = species or snap["species"][-1]
    opts = run_options(snap)
    bc = [b.strip() for b in opts.get("grid_bc", "periodic").split(",")]
    bc = bc * snap["dim"] if len(bc) == 1 else bc
    periodic = tuple(b == "periodic" for b in bc)
    return (np.asarray(snap["fields"][species], dtype=np.float64), tuple(snap["spacing"]),
            periodic, opts, species)


def label(mask, periodic=(True, True)):
    """4-connected components of a boolean (ny, nx) mask; wrap on periodic axes.
    Returns int labels (-1 outside the mask; each component labelled by its smallest flat
    index)."""
    ny, nx = mask.shape
    idx = np.arange(ny * nx).reshape(ny, nx)
    big = ny * nx
    lab = np.where(mask, idx, big)
    while True:
        old = lab
        best = lab
        for axis, per in ((0, periodic[1]), (1, periodic[0])):
            for shift in (1, -1):
                nb = np.roll(lab, shift, axis=axis)
                if not per:  # no wrap: the rolled-in row/column is not a neighbour
                    sl = [slice(None), slice(None)]
                    sl[axis] = 0 if shift == 1 else -1
                    nb = nb.copy()
                    nb[tuple(sl)] = big
                best = np.minimum(best, np.where(mask, nb, big))
        flat = best.ravel()
        # pointer jumping: follow each label to its own label until it is a fixed point
        for _ in range(8):
            inside = flat < big
            flat = np.where(inside, np.minimum(flat, flat[np.minimum(flat, big - 1)]), big)
        lab = flat.reshape(ny, nx)
        if np.array_equal(lab, old):
            break
    return np.where(mask, lab, -1)


def spot_shapes(u, spacing=(1.0, 1.0), periodic=(True, True), min_cells=3):
    """Components of the high phase (u > midrange) as a list of dicts: area (cells), cx, cy
    (physical, in [0, L) on periodic axes), elongation, angle_deg (major axis from x),
    extent (largest unwrapped extent in cells, large for components wrapping the domain)."""
    ny, nx = u.shape
    hx, hy = spacing
    mask = u > 0.5 * (u.min() + u.max())
    lab = label(mask, periodic)
    jj, ii = np.nonzero(mask)
    ll = lab[jj, ii]
    order = np.argsort(ll, kind="stable")
    ll, ii, jj = ll[order], ii[order], jj[order]
    starts = np.flatnonzero(np.r_[True, ll[1:] != ll[:-1]])
    ends = np.r_[starts[1:], len(ll)]
    out = []
    for s, e in zip(starts, ends):
        n = e - s
        if n < min_cells:
            continue
        i0, j0 = ii[s], jj[s]
        di = ii[s:e] - i0
        dj = jj[s:e] - j0
        if periodic[0]:
            di = (di + nx // 2) % nx - nx // 2
        if periodic[1]:
            dj = (dj + ny // 2) % ny - ny // 2
        mi, mj = di.mean(), dj.mean()
        x = (di - mi) * hx
        y = (dj - mj) * hy
        cxx = np.mean(x * x) + hx * hx / 12
        cyy = np.mean(y * y) + hy * hy / 12
        cxy = np.mean(x * y)
        tr, det = cxx + cyy, cxx * cyy - cxy * cxy
        disc = math.sqrt(max(tr * tr / 4 - det, 0.0))
        l1, l2 = tr / 2 + disc, max(tr / 2 - disc, 1e-300)
        angle = 0.5 * math.degrees(math.atan2(2 * cxy, cxx - cyy))
        cx = ((i0 + mi) % nx + 0.5) * hx if periodic[0] else (i0 + mi + 0.5) * hx
        cy = ((j0 + mj) % ny + 0.5) * hy if periodic[1] else (j0 + mj + 0.5) * hy
        extent = max(di.max() - di.min(), dj.max() - dj.min()) + 1
        out.append(dict(area=int(n), cx=float(cx), cy=float(cy),
                        elongation=float(math.sqrt(l1 / l2)), angle_deg=float(angle),
                        extent=int(extent)))
    return out


def stripe_orientation(u, spacing=(1.0, 1.0)):
    """Direction of stripes (degrees from x in [0, 180)) and the global coherence (0 isotropic,
    1 parallel stripes) from the domain-averaged structure tensor of the gradient (central
    differences, periodic): the stripes run perpendicular to the mean gradient direction."""
    hx, hy = spacing
    gx = (np.roll(u, -1, axis=1) - np.roll(u, 1, axis=1)) / (2 * hx)
    gy = (np.roll(u, -1, axis=0) - np.roll(u, 1, axis=0)) / (2 * hy)
    jxx, jxy, jyy = np.mean(gx * gx), np.mean(gx * gy), np.mean(gy * gy)
    grad_dir = 0.5 * math.degrees(math.atan2(2 * jxy, jxx - jyy))
    coherence = math.hypot(jxx - jyy, 2 * jxy) / (jxx + jyy) if jxx + jyy > 0 else 0.0
    return (grad_dir + 90.0) % 180.0, coherence


def spectral_stretch(u, spacing=None):
    """Power-weighted covariance of the wave vectors of a 2-D or 3-D field (mean removed,
    periodic FFT; axes in x, y[, z] order): (eigenvalues ascending, normalised by the largest;
    eigenvectors as columns). A pattern stretched by a factor f along a unit vector e has its
    wave vectors squeezed along e: the smallest eigenvalue is about 1/f^2 of the others and its
    eigenvector is e (e.g. a diffusion tensor with lambda1 along e: f^2 = lambda1/lambda2)."""
    u = np.asarray(u, dtype=np.float64)
    u = u - u.mean()
    spacing = spacing or (1.0,) * u.ndim
    p = (np.abs(np.fft.fftn(u)) ** 2).ravel()
    # array axes are (z,) y, x: build k in x, y[, z] order
    freqs = [np.fft.fftfreq(n, d=h) for n, h in zip(u.shape[::-1], spacing)]
    grids = np.meshgrid(*freqs[::-1], indexing="ij")[::-1]
    k = np.stack([g.ravel() for g in grids])
    cov = (k * p) @ k.T / p.sum()
    w, v = np.linalg.eigh(cov)
    return w / w[-1], v


def line_angle_diff(a_deg, b_deg):
    """Angle between two undirected lines, degrees in [0, 90]."""
    d = np.abs((np.asarray(a_deg) - np.asarray(b_deg)) % 180.0)
    return np.minimum(d, 180.0 - d)


_FUNCS = {"atan2": np.arctan2, "atan": np.arctan, "sqrt": np.sqrt, "sin": np.sin, "cos": np.cos,
          "tan": np.tan, "exp": np.exp, "abs": np.abs, "min": np.minimum, "max": np.maximum,
          "pi": math.pi, "_pi": math.pi}


def theta_at(expr, x, y, L):
    """Evaluate a (muParser-like, arithmetic only) angle expression at points x, y."""
    Lx, Ly = L
    dx, dy = x - Lx / 2, y - Ly / 2
    env = dict(_FUNCS, x=x, y=y, Lx=Lx, Ly=Ly, r=np.hypot(dx, dy), theta=np.arctan2(dy, dx))
    return np.broadcast_to(eval(expr.replace("^", "**"), {"__builtins__": {}}, env), x.shape)


def summarise(u, spacing, periodic, theta_expr=None, thirds=False):
    ny, nx = u.shape
    L = (nx * spacing[0], ny * spacing[1])
    spots = [s for s in spot_shapes(u, spacing, periodic) if s["extent"] < min(nx, ny) // 2]
    area = np.array([s["area"] for s in spots], dtype=float)
    el = np.array([s["elongation"] for s in spots])
    out = {"spots": len(spots),
           "area_mean": float(area.mean()) if len(area) else 0.0,
           "area_cv": float(area.std() / area.mean()) if len(area) else 0.0,
           "elongation_mean": float(el.mean()) if len(el) else 0.0,
           "elongation_cv": float(el.std() / el.mean()) if len(el) else 0.0}
    ang, coh = stripe_orientation(u, spacing)
    out["stripe_angle_deg"], out["stripe_coherence"] = ang, coh
    if theta_expr and spots:
        cx = np.array([s["cx"] for s in spots])
        cy = np.array([s["cy"] for s in spots])
        want = np.degrees(theta_at(theta_expr, cx, cy, L))
        err = line_angle_diff([s["angle_deg"] for s in spots], want)
        out["orientation_error_mean_deg"] = float(err.mean())
        out["orientation_error_p90_deg"] = float(np.percentile(err, 90))
    if thirds and spots:
        cx = np.array([s["cx"] for s in spots])
        for name, lo, hi in (("left", 0, 1 / 3), ("middle", 1 / 3, 2 / 3), ("right", 2 / 3, 1)):
            sel = (cx >= lo * L[0]) & (cx < hi * L[0])
            out[f"area_{name}"] = float(area[sel].mean()) if sel.any() else 0.0
            out[f"spots_{name}"] = int(sel.sum())
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("path", help="run directory, checkpoint or snapshot .vtkhdf")
    p.add_argument("--species", help="species (default: the last, b for turing)")
    p.add_argument("--theta", help="expected major-axis angle (radians) as an expression; "
                                   "default: the run's tensor_theta")
    p.add_argument("--thirds", action="store_true", help="mean spot area per third of x")
    p.add_argument("--json", action="store_true", help="print JSON")
    a = p.parse_args()
    u, spacing, periodic, opts, species = load(a.path, a.species)
    if u.ndim != 2:
        raise SystemExit(f"{a.path}: a 2-D run is needed")
    theta = a.theta
    tensor_run = "tensor" in opts.get("diffusion", "") or any(
        v == "tensor" for k, v in opts.items() if k.startswith("diffusion_"))
    if theta is None and tensor_run and "surface_x" not in opts and opts.get("tensor_theta"):
        theta = opts["tensor_theta"]
        try:
            theta_at(theta, np.zeros(1), np.zeros(1), (1.0, 1.0))
        except Exception:  # not an arithmetic expression Python can read: skip
            theta = None
    out = summarise(u, spacing, periodic, theta, a.thirds)
    out["species"] = species
    if a.json:
        print(json.dumps(out, indent=1))
    else:
        print(" ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}"
                       for k, v in out.items()))


if __name__ == "__main__":
    main()

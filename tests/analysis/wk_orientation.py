"""Local stripe direction of a final checkpoint against the run's diffusion-tensor map, for the
Witkin-Kass decks grown on orientation maps and the mazes (test_classify_decks.py).

The gradient structure tensor J = <grad u grad u^T> (central differences) is smoothed by a
periodic Gaussian of sigma cells (about a quarter of the patterns' period); the stripes at a
cell run across J's principal direction, and |(J_xx - J_yy, 2 J_xy)| weighs the cell (0 where
the pattern is isotropic). alignment(): the weighted mean of cos 2(direction - angle), 1 when
every stripe runs along the angle, 0 when unrelated (or at 45 degrees), -1 across it."""
import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "app"))
from conftest import SOURCE  # noqa: E402

sys.path.insert(0, os.path.join(SOURCE, "postproc"))
import spot_shapes  # noqa: E402


def orientation(out, species, sigma=4.0):
    """(direction, weight, theta, (x, y)) per cell of the final checkpoint's species: the local
    stripe direction (radians), its weight, the run's -tensor_<species>_theta (else
    -tensor_theta) evaluated at the cell centres, and the centres in cells. Cells within
    2 sigma of a zero-flux wall get weight 0 (the periodic differences wrap there)."""
    pytest.importorskip("h5py")
    u, h, periodic, opts = spot_shapes.load(str(out), species)[:4]
    gx = (np.roll(u, -1, 1) - np.roll(u, 1, 1)) / 2
    gy = (np.roll(u, -1, 0) - np.roll(u, 1, 0)) / 2
    ny, nx = u.shape
    k2 = np.fft.fftfreq(ny)[:, None] ** 2 + np.fft.fftfreq(nx)[None, :] ** 2
    g = np.exp(-2 * (math.pi * sigma) ** 2 * k2)
    jxx, jxy, jyy = (np.real(np.fft.ifft2(np.fft.fft2(f) * g)) for f in (gx * gx, gx * gy, gy * gy))
    direction = 0.5 * np.arctan2(2 * jxy, jxx - jyy) + math.pi / 2
    weight = np.hypot(jxx - jyy, 2 * jxy)
    m = int(2 * sigma)
    if not periodic[0]:
        weight[:, :m] = weight[:, -m:] = 0
    if not periodic[1]:
        weight[:m, :] = weight[-m:, :] = 0
    y, x = np.mgrid[0:ny, 0:nx] + 0.5
    expr = opts.get(f"tensor_{species}_theta", opts.get("tensor_theta", "0"))
    theta = spot_shapes.theta_at(expr, x * h[0], y * h[1], (nx * h[0], ny * h[1]))
    return direction, weight, theta, (x, y)


def alignment(direction, weight, angle):
    """Weighted mean of cos 2(direction - angle) (angle: radians, a number or per cell)."""
    return float(np.sum(weight * np.cos(2 * (direction - angle))) / np.sum(weight))


def axis_fraction(direction, weight, tol_deg=15.0):
    """Fraction of the weight whose direction lies within tol_deg of the x or y axis (1/3 for
    directions spread evenly at tol 15)."""
    d = np.degrees(direction) % 90.0
    return float(np.sum(weight * ((d < tol_deg) | (d > 90.0 - tol_deg))) / np.sum(weight))


def mean_direction_deg(direction, weight):
    """The weighted mean direction (degrees in [0, 180)) on the doubled angle."""
    s, c = np.sum(weight * np.sin(2 * direction)), np.sum(weight * np.cos(2 * direction))
    return (0.5 * math.degrees(math.atan2(s, c))) % 180.0

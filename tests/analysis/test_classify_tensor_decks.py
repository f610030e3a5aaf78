"""The classifier on the anisotropic and inhomogeneous diffusion decks (Sanderson Figs. 6 and 7,
Witkin-Kass oriented stripes, a diffusion map, a dipole field, a torus, a 3-D tensor): every deck
below runs at full length on 2 ranks and its summary.json must give the class its header
describes. Classes of spots refer to
the species: Turing's spots are high in b, so the same run is `holes` in a.

Where a class is not the whole promise, the final checkpoint is measured
(postproc/spot_shapes.py): the stripes' angle, spot sizes across a diffusion map, first- against
second-order tensor schemes, spots following a tensor field, uniform spots on a torus, and the
stretch of a 3-D pattern. Each deck runs once per session (the class and the promise tests share
the run)."""
import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "app"))
from conftest import SOURCE  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from deck_runs import deck_runner, summary  # noqa: E402

sys.path.insert(0, os.path.join(SOURCE, "postproc"))
import spot_shapes  # noqa: E402

EXPECTED = {
    "turing_saddle": {"a": "holes", "b": "spots"},              # Sanderson Fig. 6
    "turing_circles_first_order": {"b": "spots"},               # Fig. 7 left (a: holes at 0.85)
    "turing_circles_second_order": {"a": "holes", "b": "spots"},  # Fig. 7 right
    "witkin_kass_oriented_stripes": {"a": "stripes", "b": "stripes"},  # stripes along 30 deg
    "witkin_kass_zebra": {"cp": "stripes", "cm": "stripes"},  # custom threshold pair (WK Fig. 3)
    "brusselator_double_spots": {"b1": "spots", "b2": "spots"},  # Sanderson Fig. 18
    "turing_diffusion_map": {"a": "holes", "b": "spots"},       # graded spot sizes
    "turing_torus": {"a": "holes", "b": "spots"},               # spots for a torus
}
# turing_dipole (spots among elongated ones near the charges: `mixed` in b) and
# turing_tensor_3d (the mid-z slice cuts elongated blobs: not a robust class) have promise
# tests only.


@pytest.fixture(scope="module")
def deck_run(tmp_path_factory):
    return deck_runner(tmp_path_factory)



def final_field(out, species):
    """(field (ny, nx) or (nz, ny, nx), spacing, periodic, options) of the final checkpoint."""
    pytest.importorskip("h5py")
    return spot_shapes.load(str(out), species)[:4]


@pytest.mark.parametrize("deck", sorted(EXPECTED))
def test_deck_class(deck_run, deck):
    s = summary(deck_run(deck))
    for species, cls in EXPECTED[deck].items():
        got = s["species"][species]
        assert got["class"] == cls, f"{deck} {species}: {got['class']} ({got['reason']})"


def test_oriented_stripes_follow_the_tensor_angle(deck_run):
    """Witkin-Kass stripes with theta = 30 degrees: the stripes of both species run within 10
    degrees of 30 (structure tensor of the final field, and the axis the spectrum is squeezed
    along), they are nearly parallel (coherence > 0.8), and linear theory puts the fastest wave
    vector across them (direction_fastest_deg within 10 degrees of 120)."""
    out = deck_run("witkin_kass_oriented_stripes")
    for species in ("a", "b"):
        u, h, _, _ = final_field(out, species)
        angle, coherence = spot_shapes.stripe_orientation(u, h)
        assert spot_shapes.line_angle_diff(angle, 30.0) <= 10.0, (species, angle)
        assert coherence > 0.8, (species, coherence)
        w, v = spot_shapes.spectral_stretch(u, h)
        stretch = math.degrees(math.atan2(v[1, 0], v[0, 0]))
        assert spot_shapes.line_angle_diff(stretch, 30.0) <= 10.0, (species, stretch, w)
    direction = summary(out)["stability"]["direction_fastest_deg"]
    assert spot_shapes.line_angle_diff(direction, 120.0) <= 10.0, direction


def test_diffusion_map_grades_spot_size(deck_run):
    """D_a, D_b x (0.5 + 1.5 x/Lx): the mean spot area (b) grows from the left third of the
    domain to the middle and the right third (about 37, 72, 92 cells: at least 1.8 times from
    left to right), and the left third holds more spots than the right."""
    u, h, periodic, _ = final_field(deck_run("turing_diffusion_map"), "b")
    s = spot_shapes.summarise(u, h, periodic, thirds=True)
    assert s["area_left"] < s["area_middle"] < s["area_right"], s
    assert s["area_right"] >= 1.8 * s["area_left"], s
    assert s["spots_left"] > s["spots_right"], s


def test_second_order_spots_more_uniform_than_first_order(deck_run):
    """Sanderson Fig. 7: with the same tensor field (circles), the second-order scheme's spots
    (b) are more uniform than the first-order masks': their major axes follow the tensor's
    direction more closely (mean angle between them; measured 4.6 against 6.5 degrees) and
    their areas vary less (coefficient of variation; measured 0.070 against 0.100)."""
    res = {}
    for order in ("first", "second"):
        u, h, periodic, opts = final_field(deck_run(f"turing_circles_{order}_order"), "b")
        res[order] = spot_shapes.summarise(u, h, periodic, opts["tensor_theta"])
        assert res[order]["spots"] > 150, (order, res[order])
    first, second = res["first"], res["second"]
    assert (second["orientation_error_mean_deg"] < first["orientation_error_mean_deg"] - 0.5), \
        (first, second)
    assert second["area_cv"] < first["area_cv"], (first, second)


@pytest.mark.parametrize("deck,limit", [("turing_saddle", 8.0),
                                        ("turing_circles_second_order", 8.0),
                                        ("turing_dipole", 15.0)])
def test_spots_follow_the_tensor_field(deck_run, deck, limit):
    """Spots (b) are elongated along the tensor's first principal direction at their centre:
    the mean angle between a spot's major axis and -tensor_theta there is small (measured
    about 4.5 degrees for Figs. 6 and 7, 9.4 for the dipole, whose spots near the charges sit
    where the field turns fast; spots with random axes would give 45). Their elongation is
    about sqrt(lambda1/lambda2) = 1.7."""
    u, h, periodic, opts = final_field(deck_run(deck), "b")
    s = spot_shapes.summarise(u, h, periodic, opts["tensor_theta"])
    assert s["spots"] > 150, s
    assert s["orientation_error_mean_deg"] < limit, s
    assert 1.5 < s["elongation_mean"] < 2.0, s


def test_dipole_spots_smaller_where_the_field_is_strong(deck_run):
    """Reaction rate from |E|: spots (b) within 30 cells of a charge (s up to 3/128) are
    smaller than those over 100 cells from both (s = 1/128; measured about 16 and 33 cells)."""
    u, h, periodic, _ = final_field(deck_run("turing_dipole"), "b")
    ny, nx = u.shape
    spots = [s for s in spot_shapes.spot_shapes(u, h, periodic) if s["extent"] < nx // 2]
    cx = np.array([s["cx"] for s in spots])
    cy = np.array([s["cy"] for s in spots])
    area = np.array([s["area"] for s in spots], dtype=float)
    d = np.minimum(np.hypot(cx - nx / 3, cy - ny / 2), np.hypot(cx - 2 * nx / 3, cy - ny / 2))
    near, far = area[d < 30], area[d > 100]
    assert len(near) >= 10 and len(far) >= 10, (len(near), len(far))
    assert near.mean() < 0.7 * far.mean(), (near.mean(), far.mean())


def test_torus_spots_uniform_on_the_surface(deck_run):
    """Witkin-Kass surface-metric correction: in the parameter plane the spots (b) on the inner
    equator (v near Ly/2) are much larger than on the outer one (v near 0), but their areas on
    the torus (cells times the area element |X_u| |X_v| = (R + r cos(2 pi v/Ly)) / R) agree
    within 20 % (measured: 90 and 40 cells in the plane, 55 and 57 on the surface; without the
    correction the surface areas are 35 and 79)."""
    u, h, periodic, _ = final_field(deck_run("turing_torus"), "b")
    ny, nx = u.shape
    spots = [s for s in spot_shapes.spot_shapes(u, h, periodic) if s["extent"] < ny // 2]
    cy = np.array([s["cy"] for s in spots])
    area = np.array([s["area"] for s in spots], dtype=float)
    c = np.cos(2 * math.pi * cy / (ny * h[1]))
    surface = area * (2 + c) / 2  # R = 2 r, |X_v| = 1
    inner, outer = c < -0.5, c > 0.5
    assert inner.sum() >= 10 and outer.sum() >= 10, (inner.sum(), outer.sum())
    assert area[inner].mean() > 1.6 * area[outer].mean(), (area[inner].mean(), area[outer].mean())
    ratio = surface[inner].mean() / surface[outer].mean()
    assert 0.8 < ratio < 1.25, (ratio, surface[inner].mean(), surface[outer].mean())


def test_tensor_3d_pattern_stretched_along_the_tensor(deck_run):
    """3-D, lambda1 = 2 along (1, 1, 0)/sqrt 2, lambda2 = lambda3 = 0.5: the power spectrum of
    the final u is squeezed along that axis (the smallest eigenvalue of the wave vectors'
    covariance is below 0.4 of the largest; lambda2/lambda1 = 0.25, measured 0.25) and its axis
    is within 10 degrees of the diagonal."""
    u, h, _, _ = final_field(deck_run("turing_tensor_3d"), "u")
    assert u.ndim == 3
    w, v = spot_shapes.spectral_stretch(u, h)
    axis = v[:, 0]
    angle = math.degrees(math.acos(min(1.0, abs(axis @ np.array([1, 1, 0]) / math.sqrt(2)))))
    assert w[0] < 0.4, w
    assert angle <= 10.0, (angle, axis, w)


def test_double_spots_are_oblong_along_x(deck_run):
    """Sanderson Fig. 18: the coupled layers' spots under the uniform tensor (1.25 along x,
    0.75 along y) are oblong along x in both layers: median elongation of the spots >= 1.2
    (about 1.13 for the isotropic Fig. 10 deck) and median |major-axis angle| <= 15 degrees
    (measured 1.30-1.34 and 3.5-7 degrees)."""
    import numpy as np
    out = deck_run("brusselator_double_spots")
    for species in ("b1", "b2"):
        u, h, periodic, _ = final_field(out, species)
        shapes = spot_shapes.spot_shapes(u, h, periodic)
        assert len(shapes) >= 20, (species, len(shapes))
        elongation = float(np.median([s["elongation"] for s in shapes]))
        angle = float(np.median([abs(s["angle_deg"]) for s in shapes]))
        assert elongation >= 1.2, (species, elongation)
        assert angle <= 15.0, (species, angle)

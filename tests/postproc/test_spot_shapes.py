"""postproc/spot_shapes.py on synthetic fields with known answers: periodic labelling, spot
area, elongation and major axis (also for a spot cut by the periodic boundary), orientation
errors against an angle expression, stripe orientation, spectral stretch in 2-D and 3-D, the
spot areas per third of x; and its command line on a short run."""
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import EXE, SOURCE  # tests/postproc/conftest.py

sys.path.insert(0, os.path.join(SOURCE, "postproc"))
import spot_shapes as ss  # noqa: E402


def ellipse_field(n, centres, a, b, angle_deg):
    """1 inside ellipses (semi-axes a along angle, b across) at the given centres, periodic."""
    x = np.arange(n) + 0.5
    X, Y = np.meshgrid(x, x)
    u = np.zeros((n, n))
    t = math.radians(angle_deg)
    for cx, cy in centres:
        dx = (X - cx + n / 2) % n - n / 2
        dy = (Y - cy + n / 2) % n - n / 2
        p = dx * math.cos(t) + dy * math.sin(t)
        q = -dx * math.sin(t) + dy * math.cos(t)
        u[(p / a) ** 2 + (q / b) ** 2 <= 1] = 1.0
    return u


def test_label_wraps_on_periodic_axes_only():
    m = np.zeros((6, 6), dtype=bool)
    m[2, 0] = m[2, 5] = True  # neighbours across the x boundary
    lab = ss.label(m, (True, True))
    assert lab[2, 0] == lab[2, 5]
    lab = ss.label(m, (False, True))
    assert lab[2, 0] != lab[2, 5]


@pytest.mark.parametrize("angle", [0.0, 30.0, 90.0, -45.0])
def test_spot_area_elongation_and_axis(angle):
    u = ellipse_field(128, [(40, 40), (100, 90), (2, 64)], 8, 4, angle)  # the last one wraps
    spots = ss.spot_shapes(u)
    assert len(spots) == 3
    for s in spots:
        assert abs(s["area"] - math.pi * 32) < 8
        assert 1.8 < s["elongation"] < 2.2
        assert ss.line_angle_diff(s["angle_deg"], angle) < 3
    wrapped = min(spots, key=lambda s: min(s["cx"], 128 - s["cx"]))
    assert min(wrapped["cx"], 128 - wrapped["cx"]) < 3 and abs(wrapped["cy"] - 64) < 1


def test_orientation_error_against_an_expression():
    u = ellipse_field(128, [(32, 32), (96, 96)], 8, 4, 45.0)  # on the diagonal, along it
    s = ss.summarise(u, (1.0, 1.0), (True, True), "pi/4")
    assert s["spots"] == 2 and s["orientation_error_mean_deg"] < 2
    s = ss.summarise(u, (1.0, 1.0), (True, True), "atan2(y - Ly/2, x - Lx/2)")  # radial
    assert s["orientation_error_mean_deg"] < 2
    s = ss.summarise(u, (1.0, 1.0), (True, True), "atan2(y - Ly/2, x - Lx/2) + pi/2")
    assert s["orientation_error_mean_deg"] > 85  # tangential: across the spots


def test_stripes_and_spectral_stretch_2d():
    n = 128
    x = np.arange(n) + 0.5
    X, Y = np.meshgrid(x, x)
    # wave vector (1, 2) cycles per domain (at 63.4 degrees): stripes run across it, at 153.4
    u = np.cos(2 * math.pi * (1 * X + 2 * Y) / n)
    angle, coherence = ss.stripe_orientation(u)
    want = (math.degrees(math.atan2(2, 1)) + 90) % 180
    assert ss.line_angle_diff(angle, want) < 0.5 and coherence > 0.99
    w, v = ss.spectral_stretch(u)
    stretch = math.degrees(math.atan2(v[1, 0], v[0, 0]))
    assert ss.line_angle_diff(stretch, want) < 0.5 and w[0] < 1e-6


def test_spectral_stretch_3d_axis():
    n = 32
    rng = np.random.default_rng(1)
    noise = rng.standard_normal((n, n, n))
    # smooth more along x than along y and z: a pattern stretched along x
    k = np.fft.fftfreq(n)
    KZ, KY, KX = np.meshgrid(k, k, k, indexing="ij")
    u = np.real(np.fft.ifftn(np.fft.fftn(noise) * np.exp(-(16 * KX**2 + KY**2 + KZ**2) * 200)))
    w, v = ss.spectral_stretch(u)
    assert abs(abs(v[0, 0]) - 1) < 0.02 and w[0] < 0.2


def test_thirds():
    left = ellipse_field(120, [(20, 30), (20, 90)], 3, 3, 0)
    right = ellipse_field(120, [(100, 30), (100, 90)], 6, 6, 0)
    u = np.maximum(left, right)
    s = ss.summarise(u, (1.0, 1.0), (True, True), thirds=True)
    assert s["spots_left"] == 2 and s["spots_right"] == 2 and s["spots_middle"] == 0
    assert 3 < s["area_right"] / s["area_left"] < 4.5  # discrete discs of radius 6 and 3


def test_command_line_on_a_run(tmp_path):
    pytest.importorskip("h5py")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    ellipse = ("((x-32)*cos(pi/6) + (y-32)*sin(pi/6))^2/100"
               " + ((y-32)*cos(pi/6) - (x-32)*sin(pi/6))^2/25 < 1 ? 4.5 : 4")
    r = subprocess.run([EXE, "-grid_n", "64,64", "-steps", "1", "-diffusion", "tensor",
                        "-tensor_theta", "pi/6", "-tensor_l1", "1.5", "-tensor_l2", "0.5",
                        "-output_dir", "o", "-init_b", ellipse],
                       cwd=tmp_path, capture_output=True, text=True, timeout=120, env=env)
    assert r.returncode == 0, r.stderr
    r = subprocess.run(["/usr/bin/python3", os.path.join(SOURCE, "postproc", "spot_shapes.py"),
                        str(tmp_path / "o"), "--json", "--thirds"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["species"] == "b" and out["spots"] == 1
    assert "orientation_error_mean_deg" in out  # the run's -tensor_theta was used
    assert out["orientation_error_mean_deg"] < 3 and 1.8 < out["elongation_mean"] < 2.2

"""The classifier on the shipped presets: every deck below runs at full length on 2 ranks and
its summary.json (written at the end of every run: pattern class per species from the final
field and 1,000 samples of the run) must give the class its header describes: Sanderson et al.
Figs. 1 and 3, Garrity's four Gray-Scott presets, Pearson's spots, a Barkley spiral and the
Brusselator's hexagons, its stripes from fixed rows (Fig. 20, pinned cells) and two coupled
Brusselator layers' spots on spots (Fig. 10), and Witkin & Kass's Fig. 3 buttons (the mazes,
sand and the orientation-map buttons also by their local stripe direction against the deck's
map), and the stable-ARD paper's Fig. 1 Barkley column (turbulence in a channel flow past two
balls) (the diffusion-tensor decks: test_classify_tensor_decks.py). Classes of
spots refer to the species: Turing's spots are high in b, so the same run is `holes` in a."""
import json
import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "app"))
from conftest import SOURCE, run  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from deck_runs import deck_runner, summary  # noqa: E402
import wk_orientation as wko  # noqa: E402

EXPECTED = {
    "turing_spots": {"a": "holes", "b": "spots"},               # Sanderson Fig. 1
    "turing_stripes": {"a": "labyrinth"},                       # Sanderson Fig. 3
    "gray_scott_garrity_f055_k062": {"B": "labyrinth"},         # coral labyrinth
    "gray_scott_garrity_f018_k051": {"B": "chaotic"},           # rings and arcs, never still
    "gray_scott_garrity_f026_k053": {"B": "holes", "A": "spots"},  # cellular low-B holes
    "gray_scott_garrity_f055_k063": {"B": "labyrinth"},         # one branching worm
    "gray_scott_pearson_spots": {"a": "spots"},                 # Pearson's self-replicating spots
    "barkley_spiral": {"A": "oscillating"},                     # a rotating spiral
    "brusselator": {"b": "spots"},                              # hexagonal spots
    "cavity_gray_scott_replay": {"a": "labyrinth"},  # stable-ARD Fig. 5, flow from a file: one wound band
    "brusselator_fixed_rows": {"a": "stripes", "b": "stripes"},  # Fig. 20 left: pinned rows
    "brusselator_spot_on_spot": {"b1": "spots", "b2": "spots"},  # Fig. 10: coupled layers
    "brusselator_aligned_spots": {"a2": "stripes", "b2": "stripes"},  # Fig. 21: aligned by mu
    "witkin_kass_weave": {"p1": "mixed"},      # WK Fig. 3-4e: threads of two orientations
    "witkin_kass_triweave": {"p1": "mixed"},   # WK Fig. 3-2b: three-direction mesh
    "witkin_kass_coral": {"p1": "stripes"},    # WK Fig. 3-1c: five-direction branching threads
    "witkin_kass_replication": {"p1": "mixed"},  # WK Fig. 3-2d: triweave on a 64^2 torus
    "witkin_kass_maze": {"m2": "labyrinth"},   # WK Fig. 3-3b: two-direction D-A maze
    "witkin_kass_twisty_maze": {"p3": "labyrinth", "m3": "labyrinth"},  # WK Fig. 3-2c: five-direction D-A
    "witkin_kass_sand": {"p1": "stripes", "m1": "stripes"},  # WK Fig. 3-3a: ripples along y
    "witkin_kass_space_giraffe": {"cp": "holes"},  # WK Fig. 3-4a: giraffe, k falling early
    "witkin_kass_stucco": {"cp": "labyrinth"},  # WK Fig. 3-4c: grainy labyrinth, k = e^(t/4)
    "witkin_kass_radial": {"p1": "mixed", "p2": "mixed"},  # WK Fig. 3-3d: spokes and rings woven
    "witkin_kass_double_spiral": {"p1": "mixed", "p2": "mixed"},  # WK Fig. 3-2a: two spirals woven
    "witkin_kass_zebra_haunch": {"p1": "labyrinth", "m1": "labyrinth"},  # WK Fig. 3-3c: curved stripes
    "witkin_kass_giraffe": {"cp": "holes", "cm": "holes"},  # WK Fig. 3-1b: polygons in a network
    "witkin_kass_reptile": {"cp": "holes", "cm": "holes"},  # WK Fig. 3-1a: finer scales
    "fig1_barkley": {"A": "chaotic"},  # stable-ARD Fig. 1: Barkley turbulence in the channel flow
}


@pytest.fixture(scope="module")
def deck_run(tmp_path_factory):
    return deck_runner(tmp_path_factory)



@pytest.mark.parametrize("deck", sorted(EXPECTED))
def test_deck_class(deck_run, deck):
    s = summary(deck_run(deck))
    for species, cls in EXPECTED[deck].items():
        got = s["species"][species]
        assert got["class"] == cls, f"{deck} {species}: {got['class']} ({got['reason']})"


def test_default_deck_wavelength_matches_linear_theory(tmp_path):
    """Fig. 1's spots are ~18 cells apart; the spectrum's dominant wavelength of the final
    field is within 5 % of the fastest-growing wavelength linear theory predicts."""
    r = run(["-output_dir", "o", "-png_every", "0", "-checkpoint_final", "false"], tmp_path, 2)
    assert r.returncode == 0, r.stderr[-1500:]
    with open(tmp_path / "o/summary.json") as f:
        s = json.load(f)
    predicted = s["stability"]["wavelength_fastest"]
    measured = s["species"]["b"]["metrics"]["wavelength_cells"]
    assert abs(measured - predicted) <= 0.05 * predicted, (measured, predicted)



def test_wk_giraffe_cells_are_coarser_than_reptile_scales(deck_run):
    """Giraffe and reptile (eq. 13 from a jittered diamond mesh): the high phase of cp is one
    connected network around at least 10 (giraffe) / 20 (reptile) dark cells holding 80 % of the
    low phase, and the giraffe's cells are at least 2.5 times the reptile's in mean area."""
    cells = {}
    for deck, least in (("witkin_kass_giraffe", 10), ("witkin_kass_reptile", 20)):
        m = summary(deck_run(deck))["species"]["cp"]["metrics"]
        assert m["high"]["networks"] == 1 and m["high"]["components"] <= 3, (deck, m["high"])
        assert m["low"]["spots"] >= least and m["low"]["spot_area_fraction"] >= 0.8, (deck, m["low"])
        cells[deck] = m["low"]["spot_area_cells"]
    assert cells["witkin_kass_giraffe"] >= 2.5 * cells["witkin_kass_reptile"], cells



def test_wk_space_giraffe_and_stucco_differ_from_constant_k(deck_run, tmp_path):
    """Varying k over time (WK section 6.1): the space giraffe (the giraffe deck with k falling
    to e^-10 by t = 10) ends still, with round dark patches in a bright network that covers over
    half the area where the giraffe's covers under 0.45; the stucco (k = e^(t/4) from noise)
    breaks into at least 3 times as many bright pieces as the same deck with k = 1."""
    g = summary(deck_run("witkin_kass_giraffe"))["species"]["cp"]
    sg = summary(deck_run("witkin_kass_space_giraffe"))["species"]["cp"]
    assert g["metrics"]["high"]["area_fraction"] < 0.45, g["metrics"]["high"]
    assert sg["metrics"]["high"]["area_fraction"] > 0.5, sg["metrics"]["high"]
    assert sg["metrics"]["high"]["networks"] == 1 and sg["metrics"]["low"]["spots"] >= 10
    assert sg["dynamics"]["behaviour"] == "stationary", sg["dynamics"]
    st = summary(deck_run("witkin_kass_stucco"))["species"]["cp"]["metrics"]
    r = run([os.path.join(SOURCE, "input", "witkin_kass_stucco.yaml"), "-params_k", "1",
             "-output_dir", "k1", "-png_every", "0"], tmp_path, 2, timeout=300)
    assert r.returncode == 0, r.stderr[-1500:]
    k1 = summary(tmp_path / "k1")["species"]["cp"]["metrics"]
    assert st["high"]["components"] >= 3 * k1["high"]["components"], (st["high"], k1["high"])

# Witkin-Kass buttons on orientation maps and the mazes: the local stripe direction of the final
# checkpoint (tests/analysis/wk_orientation.py) against the deck's own -tensor_*_theta map.


def test_wk_maze_walls_meet_at_right_angles(deck_run):
    """Two-direction D-A (eq. 15): p1's walls run along x and p2's along y (alignment with their
    pair's theta > 0.6) and 80 % of the structure-tensor weight lies within 15 degrees of the
    axes (1/3 if the directions were spread evenly)."""
    out = deck_run("witkin_kass_maze")
    for species in ("p1", "p2"):
        d, w, theta, _ = wko.orientation(out, species)
        assert wko.alignment(d, w, theta) > 0.6, (species, wko.alignment(d, w, theta))
        assert wko.axis_fraction(d, w) > 0.8, (species, wko.axis_fraction(d, w))


def test_wk_twisty_maze_has_five_directions(deck_run):
    """Five-direction D-A: each p_i's walls lean towards its own theta_i = (i - 1) 36 degrees
    (alignment > 0.25 for all five), and p3's walls are not a right-angled maze (axis fraction
    < 0.6; the two-direction maze: > 0.8)."""
    out = deck_run("witkin_kass_twisty_maze")
    for i in range(1, 6):
        d, w, theta, _ = wko.orientation(out, f"p{i}")
        assert wko.alignment(d, w, theta) > 0.25, (i, wko.alignment(d, w, theta))
    d, w, _, _ = wko.orientation(out, "p3")
    assert wko.axis_fraction(d, w) < 0.6, wko.axis_fraction(d, w)


def test_wk_sand_ripples_run_along_y(deck_run):
    """Sand: the ripples of p1 and m1 run along theta = 90 degrees (alignment > 0.9)."""
    out = deck_run("witkin_kass_sand")
    for species in ("p1", "m1"):
        d, w, theta, _ = wko.orientation(out, species)
        assert wko.alignment(d, w, theta) > 0.9, (species, wko.alignment(d, w, theta))
        assert wko.alignment(d, w, math.pi / 2) > 0.9, species


@pytest.mark.parametrize("deck,turn", [("witkin_kass_radial", 0.0),
                                       ("witkin_kass_double_spiral", 45.0)])
def test_wk_threads_follow_the_radial_or_spiral_map(deck_run, deck, turn):
    """Radial / double spiral: p1's threads follow phi + turn (phi the polar angle about the
    centre; alignment > 0.8) and not the other deck's map, phi + 45 - turn (|alignment| < 0.2);
    p2's follow its own map, 90 degrees from p1's."""
    out = deck_run(deck)
    d, w, theta, (x, y) = wko.orientation(out, "p1")
    phi = np.arctan2(y - x.shape[0] / 2, x - x.shape[1] / 2)
    assert wko.alignment(d, w, phi + math.radians(turn)) > 0.8
    assert abs(wko.alignment(d, w, phi + math.radians(45.0 - turn))) < 0.2
    assert wko.alignment(d, w, theta) > 0.8
    d, w, theta, _ = wko.orientation(out, "p2")
    assert wko.alignment(d, w, theta) > 0.8, wko.alignment(d, w, theta)


def test_wk_zebra_haunch_follows_its_three_fields(deck_run):
    """Zebra haunch: the stripes follow the merged map (alignment > 0.7 in p1 and m1), and near
    each field's centre (within 0.1 L) their mean direction is within 20 degrees of that field's
    angle: 90 (body), 45 (haunch), 0 (leg)."""
    out = deck_run("witkin_kass_zebra_haunch")
    for species in ("p1", "m1"):
        d, w, theta, (x, y) = wko.orientation(out, species)
        assert wko.alignment(d, w, theta) > 0.7, (species, wko.alignment(d, w, theta))
        n = x.shape[1]
        for cx, cy, angle in ((0.25, 0.7, 90.0), (0.8, 0.65, 45.0), (0.45, 0.15, 0.0)):
            near = np.hypot(x - cx * n, y - cy * n) < 0.1 * n
            got = wko.mean_direction_deg(d, w * near)
            assert wko.spot_shapes.line_angle_diff(got, angle) <= 20.0, (species, cx, cy, got)


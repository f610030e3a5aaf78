"""The classifier on the shipped presets: every deck below runs at full length on 2 ranks and
its summary.json (written at the end of every run: pattern class per species from the final
field and 1,000 samples of the run) must give the class its header describes: Sanderson et al.
Figs. 1 and 3, Garrity's four Gray-Scott presets, Pearson's spots, a Barkley spiral and the
Brusselator's hexagons, its stripes from fixed rows (Fig. 20, pinned cells) and two coupled
Brusselator layers' spots on spots (Fig. 10) (the diffusion-tensor decks: test_classify_tensor_decks.py). Classes of
spots refer to the species: Turing's spots are high in b, so the same run is `holes` in a."""
import json
import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "app"))
from conftest import run  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from deck_runs import deck_runner, summary  # noqa: E402

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
    "brusselator_fixed_rows": {"a": "stripes", "b": "stripes"},  # Fig. 20 left: pinned rows
    "brusselator_spot_on_spot": {"b1": "spots", "b2": "spots"},  # Fig. 10: coupled layers
    "brusselator_aligned_spots": {"a2": "stripes", "b2": "stripes"},  # Fig. 21: aligned by mu
    "witkin_kass_weave": {"p1": "mixed"},      # WK Fig. 3-4e: threads of two orientations
    "witkin_kass_triweave": {"p1": "mixed"},   # WK Fig. 3-2b: three-direction mesh
    "witkin_kass_coral": {"p1": "stripes"},    # WK Fig. 3-1c: five-direction branching threads
    "witkin_kass_replication": {"p1": "mixed"},  # WK Fig. 3-2d: triweave on a 64^2 torus
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

"""The explicit fast path's in-place update (-explicit_in_place; integrators/
explicit_integrator.hpp: new rows wait in a ring of row buffers until the rows reading them are
done) gives the same bytes as the sweep into a second state set, on 1, 2 and 4 ranks: 5-point
and 9-point stencils in 2-D, 7-, 19- and 27-point stencils in 3-D (swept in blocks of y rows,
each reading the saved old row above it), periodic, zero-flux and Dirichlet boundaries, per-cell and scalar parameters, sources,
pinned cells, grids whose rank blocks are a single row, and 3-D grids swept in several blocks
of y rows. `auto` chooses in place only
where a rank's state is at least 8 MiB, 64 MiB in 3-D (the run's memory matters; in cache the
row copies cost more than the write-allocate they save)."""
import os

import h5py
import numpy as np
import pytest

from conftest import SOURCE, run

DECK = os.path.join(SOURCE, "input", "turing_spots.yaml")
DECK_3D = os.path.join(SOURCE, "input", "turing_spots_3d.yaml")
GS_DECK = os.path.join(SOURCE, "input", "gray_scott_pearson_spots.yaml")  # scalar parameters

CASES = {
    "periodic_5pt": ["-grid_n", "48,40"],
    "neumann_9pt": ["-grid_n", "40,36", "-grid_bc", "neumann", "-stencil", "9pt"],
    "dirichlet_mixed": ["-grid_n", "32,30", "-grid_bc", "periodic,dirichlet",
                        "-dirichlet_a", "4 + 0.1*x", "-stencil", "9pt"],
    "sources_pins": ["-grid_n", "36,33", "-grid_bc", "neumann", "-source_a", "0.01*sin(x)",
                     "-pin_b", "j < 2"],
    "one_row_blocks": ["-grid_n", "16,4", "-grid_L", "25,6.25"],
    "periodic_3d_7pt": [DECK_3D, "-grid_n", "14,12,10"],
    "neumann_3d_19pt": [DECK_3D, "-grid_n", "10,9,8", "-grid_bc", "neumann", "-stencil", "19pt",
                        "-source_b", "0.01*cos(z)", "-pin_a", "k < 1"],
    "dirichlet_3d_27pt": [DECK_3D, "-grid_n", "9,10,8", "-grid_bc", "periodic,neumann,dirichlet",
                          "-dirichlet_a", "4 + 0.1*x", "-stencil", "27pt"],
    "gray_scott_3d_scalar_params": [GS_DECK, "-grid_n", "8,6,4", "-grid_L", "0.1",
                                    "-stencil", "7pt"],
    # Rows of 600-1000 cells: the 3-D sweep goes in blocks of 4-19 y rows (block_rows(), about
    # 256 KiB of three planes), each block reading the saved old row above it; the last block
    # is partial.
    "blocks_3d_7pt": [DECK_3D, "-grid_n", "1000,26,6"],
    "blocks_3d_27pt_dirichlet": [DECK_3D, "-grid_n", "600,23,5", "-stencil", "27pt",
                                 "-grid_bc", "periodic,dirichlet,neumann",
                                 "-dirichlet_b", "4 - 0.1*y"],
    "blocks_3d_19pt_scalar_params": [GS_DECK, "-grid_n", "800,22,5", "-grid_L", "8,0.22,0.05",
                                     "-stencil", "19pt"],
}


def final_state(out):
    snaps = sorted(p for p in os.listdir(out) if p.startswith("morphogen_") and p.endswith(".vtkhdf"))
    with h5py.File(os.path.join(out, snaps[-1]), "r") as f:
        g = f["VTKHDF/PointData"]
        return {k: g[k][()] for k in g}


@pytest.mark.parametrize("ranks", [1, 2, 4])
@pytest.mark.parametrize("case", sorted(CASES))
def test_in_place_equals_second_state_set(tmp_path, case, ranks):
    states = {}
    for mode in ("yes", "no"):
        out = tmp_path / mode
        args = CASES[case] if CASES[case][0] in (DECK_3D, GS_DECK) else [DECK] + CASES[case]
        p = run(args + ["-steps", "25", "-snapshot_precision", "float64",
                                        "-summary", "false", "-png_every", "0",
                                        "-explicit_in_place", mode, "-output_dir", str(out)],
                tmp_path, ranks=ranks)
        assert p.returncode == 0, p.stderr
        states[mode] = final_state(out)
    assert states["yes"].keys() == states["no"].keys()
    moved = 0.0
    for name, a in states["yes"].items():
        assert a.tobytes() == states["no"][name].tobytes(), name
        moved = max(moved, float(np.ptp(a)))
    assert moved > 0.0  # the run did something


def test_bad_value_is_one_line(tmp_path):
    p = run([DECK, "-grid_n", "16,16", "-steps", "1", "-explicit_in_place", "maybe"], tmp_path)
    assert p.returncode != 0
    assert "-explicit_in_place maybe" in p.stderr and "auto" in p.stderr, p.stderr


def test_other_integrators_refuse_it(tmp_path):
    p = run([DECK, "-grid_n", "16,16", "-steps", "1", "-integrator", "split",
             "-explicit_in_place", "yes"], tmp_path)
    assert p.returncode != 0
    assert "-explicit_in_place: applies to -integrator explicit only" in p.stderr, p.stderr

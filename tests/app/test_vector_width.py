"""The explicit fast path's two compiles of the fused row kernel (-explicit_vector_width;
integrators/kernel_choice.hpp: 256-bit and 512-bit vectors, auto times both in the first passes
of each rank) give the same bytes, on 1, 2 and 4 ranks: 5- and 9-point stencils in 2-D, 7-, 19-
and 27-point in 3-D, per-cell and scalar parameters, a clamp floor, Dirichlet faces, the in-place
sweep and fused passes (-explicit_fuse_steps). The log names the compile that ran. Software
prefetch (-explicit_prefetch) on and off give the same bytes too."""
import os

import pytest

from conftest import SOURCE, run
from test_in_place_sweep import final_state

DECK = os.path.join(SOURCE, "input", "turing_spots.yaml")
DECK_3D = os.path.join(SOURCE, "input", "turing_spots_3d.yaml")
GS_DECK = os.path.join(SOURCE, "input", "gray_scott_pearson_spots.yaml")  # scalar parameters

CASES = {
    "periodic_5pt": [DECK, "-grid_n", "67,40"],
    "neumann_9pt_in_place": [DECK, "-grid_n", "45,36", "-grid_bc", "neumann", "-stencil", "9pt",
                             "-explicit_in_place", "yes"],
    "dirichlet_9pt": [DECK, "-grid_n", "37,30", "-grid_bc", "periodic,dirichlet",
                      "-dirichlet_a", "4 + 0.1*x", "-stencil", "9pt"],
    "gray_scott_scalar_fused": [GS_DECK, "-grid_n", "70,64", "-explicit_fuse_steps", "4"],
    "gray_scott_scalar_clamp": [GS_DECK, "-grid_n", "53,21", "-clamp", "true"],
    "periodic_3d_7pt": [DECK_3D, "-grid_n", "21,12,10"],
    "neumann_3d_19pt": [DECK_3D, "-grid_n", "19,9,8", "-grid_bc", "neumann", "-stencil", "19pt"],
    "dirichlet_3d_27pt_in_place": [DECK_3D, "-grid_n", "17,10,8", "-stencil", "27pt",
                                   "-grid_bc", "periodic,neumann,dirichlet",
                                   "-dirichlet_a", "4 + 0.1*x", "-explicit_in_place", "yes"],
}


def final(tmp_path, case, width, ranks):
    out = tmp_path / width
    p = run(CASES[case] + ["-steps", "24", "-snapshot_precision", "float64", "-summary", "false",
                           "-png_every", "0", "-explicit_vector_width", width,
                           "-output_dir", str(out)], tmp_path, ranks=ranks)
    assert p.returncode == 0, p.stderr
    return final_state(out), p.stdout


@pytest.mark.parametrize("ranks", [1, 2, 4])
@pytest.mark.parametrize("case", sorted(CASES))
def test_widths_give_the_same_bytes(tmp_path, case, ranks):
    ref, log = final(tmp_path, case, "256", ranks)
    wide_cpu = "explicit kernel (rank 0)" in log  # printed where the CPU has AVX-512
    for width in ("512", "auto"):
        state, log = final(tmp_path, case, width, ranks)
        assert state.keys() == ref.keys()
        for name, a in state.items():
            assert a.tobytes() == ref[name].tobytes(), (width, name)
        if wide_cpu and width == "512":
            assert "512-bit" in log and "256-bit" not in log, log


def test_auto_times_both(tmp_path):
    # 2100 steps: more than the 1 warm-up + 2 x 1024 passes after which auto chooses on any CPU.
    p = run([DECK, "-grid_n", "128,128", "-steps", "2100", "-png_every", "0", "-summary", "false",
             "-output_dir", str(tmp_path / "o")], tmp_path)
    assert p.returncode == 0, p.stderr
    line = [ln for ln in p.stdout.splitlines() if ln.startswith("explicit kernel")]
    if not line:
        pytest.skip("the build's CPU has no AVX-512: one compile, nothing to time")
    assert "least pass 256-bit" in line[0] and "still timing" not in line[0], line


@pytest.mark.parametrize("args,message", [
    (["-explicit_vector_width", "128"], "-explicit_vector_width 128"),
    (["-integrator", "split", "-dt", "1", "-explicit_vector_width", "512"],
     "-explicit_vector_width: applies to -integrator explicit only"),
    (["-explicit_prefetch", "always"], "-explicit_prefetch always"),
    (["-integrator", "ts", "-explicit_prefetch", "yes"],
     "-explicit_prefetch: applies to -integrator explicit only"),
])
def test_bad_use_is_one_line(tmp_path, args, message):
    p = run([DECK, "-grid_n", "16,16", "-steps", "1"] + args, tmp_path)
    assert p.returncode != 0
    assert message in p.stderr, p.stderr
    assert len(p.stderr.strip().splitlines()) == 1, p.stderr


# -explicit_prefetch (integrators/explicit_integrator.hpp, core/prefetch.hpp): software prefetch
# of the rows a single-step sweep reads from memory (box stencils: issued by the row kernel
# between its blocks of cells; 5/7-point: the whole row before the kernel); forced on at these
# small grids (auto turns it on from 8 MiB of state per rank), it must not change a bit.
# gray_scott_scalar_clamp also takes the per-row calls that replace the multi-row ones when
# prefetching.
PREFETCH_CASES = ["periodic_5pt", "neumann_9pt_in_place", "gray_scott_scalar_clamp",
                  "periodic_3d_7pt", "neumann_3d_19pt", "dirichlet_3d_27pt_in_place"]


@pytest.mark.parametrize("ranks", [1, 2, 4])
@pytest.mark.parametrize("case", PREFETCH_CASES)
def test_prefetch_gives_the_same_bytes(tmp_path, case, ranks):
    def state(mode):
        out = tmp_path / mode
        p = run(CASES[case] + ["-steps", "12", "-snapshot_precision", "float64", "-summary",
                               "false", "-png_every", "0", "-explicit_prefetch", mode,
                               "-output_dir", str(out)], tmp_path, ranks=ranks)
        assert p.returncode == 0, p.stderr
        return final_state(out)

    ref, got = state("no"), state("yes")
    assert got.keys() == ref.keys()
    for name, a in got.items():
        assert a.tobytes() == ref[name].tobytes(), name


"""-integrator ts with the exact inverse of its implicit diffusion Jacobian
(-ts_diffusion_solver auto|spectral: integrators/ts_exact_pc.hpp, KSP preonly) against the
iterative solve (-ts_diffusion_solver ksp, CG + ICC at -ksp_rtol 1e-13): the same fields to
1e-12 of their size (rounding: a relative error of 1e-7 in the inverse fails it) after 20 steps of 2-D and 3-D grids with periodic, zero-flux and Dirichlet
boundaries (Dirichlet values also following t), 5-, 9- and 19-point stencils, a rotated constant tensor, an adaptive step and a fully implicit (BDF, Newton)
scheme (BDF and CN: Newton), ROSW and a species without diffusion, on 1, 2 and 4 ranks; the rank
counts agree with each other to 1e-12. Where the exact solve does not apply (a diffusion map,
pinned cells, coefficients following t, a linear-solver option, -snes_mf) auto falls back to KSP
and says why; spectral is then a one-line error, as is the option without -integrator ts."""
import glob
import os

import h5py
import numpy as np
import pytest

from conftest import SOURCE, error_lines, run

DECK = os.path.join(SOURCE, "input", "turing_spots.yaml")
DECK_3D = os.path.join(SOURCE, "input", "turing_spots_3d.yaml")
COMMON = ["-integrator", "ts", "-steps", "20", "-dt", "2", "-png_every", "0",
          "-init_a", "4 +- 25%", "-init_b", "4 +- 25%"]  # structure for the diffusion to act on

CASES = {
    "periodic_5pt": [DECK, "-grid_n", "48,40"],
    "neumann_9pt": [DECK, "-grid_n", "40,36", "-grid_bc", "neumann", "-stencil", "9pt"],
    "dirichlet_mixed": [DECK, "-grid_n", "32,30", "-grid_bc", "periodic,dirichlet",
                        "-dirichlet_a", "4 + 0.1*x"],
    "dirichlet_timed": [DECK, "-grid_n", "30,28", "-grid_bc", "dirichlet",
                        "-dirichlet_b", "4 + 0.2*sin(0.1*t) + 0.01*y"],  # b follows t, M does not
    "neumann_3d_19pt": [DECK_3D, "-grid_n", "10,9,8", "-grid_bc", "neumann", "-stencil", "19pt"],
    "tensor_periodic": [DECK, "-grid_n", "36,32", "-diffusion", "tensor", "-tensor_theta", "0.3",
                        "-tensor_l1", "1.5", "-tensor_l2", "0.5"],  # cross terms: complex DFT
    "adaptive": [DECK, "-grid_n", "40,40", "-ts_adapt_type", "basic", "-dt", "4"],
    "bdf_newton": [DECK, "-grid_n", "32,32", "-ts_type", "bdf", "-dt", "1"],
    "rosw": [DECK, "-grid_n", "32,30", "-ts_type", "rosw"],
    "cn_newton": [DECK, "-grid_n", "30,32", "-ts_type", "cn", "-dt", "1"],
    "b_not_diffusing": [DECK, "-grid_n", "32,32", "-D_b", "0"],  # r / shift for that species
}


def final_state(out):
    last = sorted(glob.glob(os.path.join(out, "checkpoint_*.vtkhdf")))[-1]
    with h5py.File(last, "r") as f:
        g = f["VTKHDF/PointData"]
        return {k: g[k][()].astype(np.float64) for k in g if k in ("a", "b")}


def ts_run(tmp_path, tag, args, ranks):
    out = str(tmp_path / tag)
    # The deck, the common options, then the case's (a case's -dt overrides the common one).
    p = run(args[:1] + COMMON + args[1:] + ["-output_dir", out], tmp_path, ranks)
    assert p.returncode == 0, p.stdout + p.stderr
    return p.stdout, final_state(out)


def close(x, y, rel):
    for k in x:
        scale = max(1.0, float(np.abs(x[k]).max()))
        assert float(np.abs(x[k] - y[k]).max()) <= rel * scale, (k, np.abs(x[k] - y[k]).max())


@pytest.mark.parametrize("case", sorted(CASES))
def test_exact_inverse_matches_ksp_on_any_ranks(tmp_path, case):
    args = CASES[case]
    log, ref = ts_run(tmp_path, "ksp", args + ["-ts_diffusion_solver", "ksp",
                                               "-ksp_rtol", "1e-13"], 1)
    assert "TS diffusion solve: ksp (-ts_diffusion_solver ksp)" in log
    first = None
    for ranks in (1, 2, 4):
        log, got = ts_run(tmp_path, "exact%d" % ranks, args, ranks)
        assert "TS diffusion solve of a: " in log and "the exact inverse (preonly)" in log, log
        close(got, ref, 1e-12)
        if first is None:
            first = got
        else:
            close(got, first, 1e-12)


def test_fallbacks_and_errors(tmp_path):
    varying = [DECK, "-grid_n", "32,32", "-D_a", "0.0625*(1 + 0.5*x/Lx)"]
    log, _ = ts_run(tmp_path, "map", varying, 1)
    assert "TS diffusion solve: ksp (species a:" in log, log
    fallbacks = {
        "-pc_type was given": ["-pc_type", "jacobi"],
        "-snes_mf was given": ["-snes_mf"],  # no IJacobian, so no shift for the inverse
        "-ksp_initial_guess_nonzero was given": ["-ksp_initial_guess_nonzero"],
        "coefficients follow t": ["-D_a", "0.0625*(1 + 0.1*sin(t))"],
        "species b:": ["-pin_b", "j < 2"],
    }
    for i, (why, extra) in enumerate(fallbacks.items()):
        log, _ = ts_run(tmp_path, "fallback%d" % i, [DECK, "-grid_n", "32,32"] + extra, 1)
        assert "TS diffusion solve: ksp (" + why in log, log
    bad = [
        ([varying[0]] + COMMON + varying[1:] + ["-ts_diffusion_solver", "spectral"],
         ["-ts_diffusion_solver spectral: species a:", "allowed here: ksp or auto"]),
        ([DECK] + COMMON + ["-grid_n", "32,32", "-ts_diffusion_solver", "spectral", "-pc_type",
                            "jacobi"],
         ["-ts_diffusion_solver spectral: -pc_type was given", "allowed here: ksp or auto"]),
        ([DECK, "-grid_n", "32,32", "-steps", "2", "-ts_diffusion_solver", "spectral"],
         ["-ts_diffusion_solver", "applies to -integrator ts"]),
        ([DECK] + COMMON + ["-grid_n", "32,32", "-ts_diffusion_solver", "fft"],
         ["-ts_diffusion_solver", "fft", "auto, ksp, spectral"]),
    ]
    for args, needles in bad:
        p = run(args + ["-output_dir", str(tmp_path / "bad")], tmp_path)
        assert p.returncode != 0
        lines = error_lines(p)
        assert len(lines) == 1, p.stderr
        for n in needles:
            assert n in lines[0], lines[0]

"""3-D isotropic box stencils (-stencil 19pt, 27pt) through the whole run.

A Fourier mode cos(2 pi x/L) cos(2 pi y/L) cos(4 pi z/L) on a periodic grid is an eigenvector of
every symmetric stencil, with eigenvalue lambda = sum_t w_t cos(k . off_t h) computed here from
the published weights (Patra & Karttunen 2006). With the reaction switched off (Gray-Scott with
s = 0), after N steps the mode's amplitude is
  explicit Euler:      (1 + dt D lambda)^N
  split (CN, Strang):  ((1 + dt D lambda / 2) / (1 - dt D lambda / 2))^N
Checked to 1e-12 (explicit) and 1e-9 (split, KSP rtol 1e-13); explicit results bitwise equal on
1, 2 and 4 ranks (the 4-rank split reads edge and corner ghosts of the box stencil).
"""
import glob
import itertools
import math
import os
import sys

import h5py
import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "app"))
from conftest import run  # noqa: E402

N, L, D, STEPS = 12, 12.0, 0.5, 20
WEIGHTS = {"19pt": ([-24, 2, 1, 0], 6.0), "27pt": ([-128, 14, 3, 1], 30.0), "7pt": ([-6, 1, 0, 0], 1.0)}
K = (2 * math.pi / L, 2 * math.pi / L, 4 * math.pi / L)


def eigenvalue(stencil):
    w, scale = WEIGHTS[stencil]
    lam = 0.0
    for off in itertools.product((-1, 0, 1), repeat=3):
        lam += w[sum(o != 0 for o in off)] / scale * math.cos(sum(k * o for k, o in zip(K, off)))
    return lam  # h = 1


def final_a(d):
    path = sorted(glob.glob(os.path.join(d, "checkpoint_*.vtkhdf")))[-1]
    with h5py.File(path, "r") as f:
        g = f["VTKHDF"]["CellData" if "CellData" in f["VTKHDF"] else "PointData"]
        return g["a"][...].reshape(N, N, N)  # z, y, x


def mode():
    c = (np.arange(N) + 0.5) * (L / N)
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    return np.cos(K[0] * x) * np.cos(K[1] * y) * np.cos(K[2] * z)


def run_mode(tmp_path, stencil, integ, out, ranks=1):
    args = ["-model", "gray_scott", "-params_s", "0", "-grid_n", f"{N},{N},{N}",
            "-grid_L", f"{L},{L},{L}", "-grid_bc", "periodic", "-stencil", stencil,
            "-D_a", str(D), "-D_b", str(D),
            "-init_a", "2 + cos(2*pi*x/Lx)*cos(2*pi*y/Ly)*cos(4*pi*z/Lz)", "-init_b", "1",
            "-steps", str(STEPS), "-checkpoint_every", str(STEPS), "-png_every", "0",
            "-summary", "0", "-output_dir", out] + integ
    r = run(args, tmp_path, ranks=ranks)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return final_a(tmp_path / out)


@pytest.mark.parametrize("stencil", ["19pt", "27pt", "7pt"])
def test_explicit_mode_decay_and_rank_independence(tmp_path, stencil):
    lam = eigenvalue(stencil)
    dt = 0.9 * 2 / (D * 12)  # below every stencil's explicit bound (spectral radius <= 12)
    amp = (1 + dt * D * lam) ** STEPS
    a1 = run_mode(tmp_path, stencil, ["-dt", str(dt)], "r1")
    assert np.max(np.abs(a1 - 2 - amp * mode())) < 1e-12, (stencil, amp)
    if stencil != "7pt":
        for ranks in (2, 4):
            assert np.array_equal(a1, run_mode(tmp_path, stencil, ["-dt", str(dt)], f"r{ranks}",
                                               ranks))


@pytest.mark.parametrize("stencil", ["19pt", "27pt"])
@pytest.mark.parametrize("ranks", [1, 4])
def test_split_crank_nicolson_mode_decay(tmp_path, stencil, ranks):
    lam, dt = eigenvalue(stencil), 2.0  # 5x the explicit bound
    amp = ((1 + 0.5 * dt * D * lam) / (1 - 0.5 * dt * D * lam)) ** STEPS
    a = run_mode(tmp_path, stencil, ["-integrator", "split", "-dt", str(dt),
                                     "-diffusion_ksp_rtol", "1e-13"], "s", ranks)
    assert np.max(np.abs(a - 2 - amp * mode())) < 1e-9, (stencil, amp)


def test_box_stencil_refused_in_2d_and_with_unequal_spacing(tmp_path):
    base = ["-model", "gray_scott", "-steps", "1", "-png_every", "0", "-output_dir", "bad"]
    r = run(base + ["-grid_n", "16,16", "-stencil", "27pt"], tmp_path)
    assert r.returncode != 0 and "-stencil" in r.stderr and "27pt" in r.stderr, r.stderr
    r = run(base + ["-grid_n", "16,16,8", "-grid_L", "1,1,1", "-stencil", "19pt"], tmp_path)
    assert r.returncode != 0 and "19pt" in r.stderr and "equal spacings" in r.stderr, r.stderr
    assert not os.path.exists(tmp_path / "bad" / "summary.json")

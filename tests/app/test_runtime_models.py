"""Models built at run time, end to end (issue 11):
- `-model custom` with the Brusselator's rates as expressions matches the compiled Brusselator
  (explicit, split and TS integrators; 1e-11), and gives the same fields on 1 and 2 ranks
  (explicit: bitwise);
- rates using t and x (parameters whose default is that expression) against closed forms:
  explicit Euler exactly, TS (RK4 at its stage times) to 1e-9;
- `-layers 2` with zero coupling: each layer evolves as the single model (1e-11);
- the coupling alone (s = 0, D = 0): a1 - a2 decays by exactly (1 - 2 mu dt) per explicit step
  and a1 + a2 is conserved (1e-13);
- Gray-Scott as expressions with its Jacobian by expressions (-jac_a_b ..., or the deck's
  `jac:` map) under the split integrator equals the compiled gray_scott split run (1e-11);
- bad custom-model input: one-line errors naming the option, non-zero exit, no output."""
import glob
import os

import h5py
import numpy as np
import pytest

from conftest import run

QUIET = ["-png_every", "0", "-progress_every", "1000000", "-summary", "0"]
GRID = ["-grid_n", "32,24", "-grid_L", "48,36", "-grid_bc", "periodic"]
BRUSS_RATES = ["-rate_a", "s*(alpha - (1 + beta)*a + a^2*b)", "-rate_b", "s*(beta*a - a^2*b)"]
PARAMS = ["-params_alpha", "3", "-params_beta", "9", "-params_s", "1"]
INIT = "3 + 0.05*sin(2*pi*x/Lx)*cos(4*pi*y/Ly)"


def fields(d):
    path = sorted(glob.glob(os.path.join(d, "checkpoint_*.vtkhdf")))[-1]
    with h5py.File(path, "r") as f:
        g = f["VTKHDF"]["CellData" if "CellData" in f["VTKHDF"] else "PointData"]
        return {k: g[k][...] for k in g}


def run_ok(args, cwd, ranks=1):
    r = run(args + QUIET, cwd, ranks=ranks)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r


def error_line(r):
    assert r.returncode != 0
    lines = [l for l in r.stderr.splitlines() if l.startswith("morphogen: error")]
    assert len(lines) == 1, r.stdout[-2000:] + r.stderr[-2000:]
    return lines[0]


COMMON = GRID + ["-D_a", "4", "-D_b", "10", "-init_a", INIT, "-init_b", INIT, "-steps", "200",
                 "-checkpoint_every", "200"]


@pytest.mark.parametrize("integrator", [["-dt", "0.01"],
                                        ["-integrator", "split", "-dt", "0.05"],
                                        ["-integrator", "ts", "-dt", "0.05"]])
def test_custom_matches_compiled_brusselator(tmp_path, integrator):
    run_ok(["-model", "brusselator"] + PARAMS + COMMON + integrator + ["-output_dir", "b"], tmp_path)
    run_ok(["-model", "custom", "-species", "a,b"] + BRUSS_RATES + PARAMS + COMMON + integrator +
           ["-output_dir", "c"], tmp_path)
    fb, fc = fields(tmp_path / "b"), fields(tmp_path / "c")
    assert np.ptp(fb["a"]) > 1e-3  # the state evolved away from uniform
    for s in "ab":
        assert np.max(np.abs(fb[s] - fc[s])) < 1e-11, (s, np.max(np.abs(fb[s] - fc[s])))


def test_custom_same_on_one_two_and_four_ranks(tmp_path):
    """Explicit: bitwise; split: to the solver tolerance (tightened to 1e-12: the Turing-unstable
    dynamics amplify the default 1e-8 to ~1e-5 by t = 10)."""
    base = ["-model", "custom", "-species", "a,b"] + BRUSS_RATES + PARAMS + COMMON
    for name, integ, tol in (("e", ["-dt", "0.01"], 0.0),
                             ("s", ["-integrator", "split", "-dt", "0.05", "-diffusion_ksp_rtol", "1e-12",
                                   "-split_newton_tol", "1e-14"], 1e-8)):
        for ranks in (1, 2, 4):
            run_ok(base + integ + ["-output_dir", f"{name}{ranks}"], tmp_path, ranks=ranks)
        f1 = fields(tmp_path / f"{name}1")
        for ranks in (2, 4):
            fr = fields(tmp_path / f"{name}{ranks}")
            for s in "ab":
                assert np.max(np.abs(f1[s] - fr[s])) <= tol, (name, ranks, s)


def test_uncoupled_layers_evolve_as_the_model(tmp_path):
    run_ok(["-model", "brusselator"] + PARAMS + COMMON + ["-dt", "0.01", "-output_dir", "one"],
           tmp_path)
    layered = ["-model", "brusselator", "-layers", "2", "-dt", "0.01", "-steps", "200",
               "-checkpoint_every", "200", "-output_dir", "two"] + GRID
    for l in "12":
        layered += ["-params_alpha" + l, "3", "-params_beta" + l, "9", "-params_s" + l, "1",
                    "-D_a" + l, "4", "-D_b" + l, "10", "-init_a" + l, INIT, "-init_b" + l, INIT]
    r = run_ok(layered, tmp_path)
    assert "diffusion of b2" in r.stdout
    f1, f2 = fields(tmp_path / "one"), fields(tmp_path / "two")
    assert sorted(f2) == ["a1", "a2", "b1", "b2"]
    for s in "ab":
        for l in "12":
            assert np.max(np.abs(f1[s] - f2[s + l])) < 1e-11


def test_coupling_relaxes_layers_exactly(tmp_path):
    mu, dt, steps = 0.5, 0.01, 100
    args = ["-model", "brusselator", "-layers", "2", "-dt", str(dt), "-steps", str(steps),
            "-checkpoint_every", str(steps), "-output_dir", "c", "-params_couple_a", str(mu),
            "-params_couple_b", "0"] + GRID
    for l, a0 in (("1", "2 + 0.1*i"), ("2", "1 - 0.05*j")):
        args += ["-params_s" + l, "0", "-D_a" + l, "0", "-D_b" + l, "0", "-init_a" + l, a0,
                 "-init_b" + l, "3"]
    run_ok(args, tmp_path)
    f = fields(tmp_path / "c")
    n = f["a1"].shape
    i = np.broadcast_to(np.arange(n[-1]), n)
    j = np.broadcast_to(np.arange(n[-2])[:, None], n)
    a1, a2 = 2 + 0.1 * i, 1 - 0.05 * j
    decay = (1 - 2 * mu * dt) ** steps
    assert np.max(np.abs((f["a1"] - f["a2"]) - (a1 - a2) * decay)) < 1e-13
    assert np.max(np.abs((f["a1"] + f["a2"]) - (a1 + a2))) < 1e-13
    assert np.max(np.abs(f["b1"] - 3)) == 0


@pytest.mark.parametrize("args,expect", [
    (["-model", "custom"], "-model custom: give the species"),
    (["-model", "custom", "-species", "a,b", "-rate_a", "a"], "-rate_b"),
    (["-model", "custom", "-species", "a", "-rate_a", "k*a"], "-params_k"),
    (["-model", "custom", "-species", "a", "-rate_a", "a*(1-"], "-rate_a a*(1-"),
    (["-model", "custom", "-species", "t", "-rate_a", "t"], "-species t"),
    (["-model", "custom", "-species", "a,2b", "-rate_a", "a"], "-species 2b"),
    (["-model", "brusselator", "-layers", "17"], "-layers 17"),
])
def test_bad_custom_input(tmp_path, args, expect):
    r = run(args + ["-output_dir", "bad"] + QUIET, tmp_path)
    assert expect in error_line(r)
    assert not os.path.exists(tmp_path / "bad")


@pytest.mark.parametrize("ranks", [1, 2])
def test_rates_of_time_and_space_closed_forms(tmp_path, ranks):
    """da/dt = -(t + c x) a, c = 0.02, D = 0, a(0) = 1: explicit Euler gives
    prod_n (1 - (t_n + c x) dt) exactly (parameters at t_n); TS RK4 (parameters at its stage
    times) gives exp(-(t^2/2 + c x t)) to 1e-9."""
    dt, steps = 0.01, 100
    base = ["-model", "custom", "-species", "a", "-rate_a", "-(t + 0.02*x)*a", "-D_a", "0",
            "-init_a", "1", "-steps", str(steps), "-checkpoint_every", str(steps)] + GRID
    run_ok(base + ["-dt", str(dt), "-output_dir", "e"], tmp_path, ranks)
    run_ok(base + ["-dt", str(dt), "-integrator", "ts", "-ts_diffusion", "explicit",
                   "-ts_type", "rk", "-ts_rk_type", "4", "-output_dir", "ts"], tmp_path, ranks)
    a = fields(tmp_path / "e")["a"]
    n = a.shape
    x = 0.02 * np.broadcast_to((np.arange(n[-1]) + 0.5) * 48 / 32, n)
    expect = np.ones(n)
    for k in range(steps):
        expect = expect * (1 - (k * dt + x) * dt)
    assert np.max(np.abs(a - expect)) < 1e-13
    T = steps * dt
    exact = np.exp(-(T * T / 2 + x * T))
    assert np.max(np.abs(fields(tmp_path / "ts")["a"] - exact)) < 1e-9


@pytest.mark.parametrize("integrator", [["-dt", "0.1"], ["-integrator", "split", "-dt", "0.5"]])
def test_custom_gray_scott_matches_compiled(tmp_path, integrator):
    """Gray-Scott written as expressions equals the compiled gray_scott after 100 steps
    (explicit: round-off, 1e-13; split: the Newton tolerance, 1e-11)."""
    common = GRID + ["-params_F", "0.04", "-params_k", "0.06", "-params_s", "1", "-D_a", "0.5",
                     "-D_b", "1", "-init_a", "0.25 + 0.05*sin(2*pi*x/Lx)",
                     "-init_b", "0.5 + 0.05*cos(2*pi*y/Ly)", "-steps", "100",
                     "-checkpoint_every", "100"] + integrator
    run_ok(["-model", "gray_scott"] + common + ["-output_dir", "g"], tmp_path)
    run_ok(["-model", "custom", "-species", "a,b", "-rate_a", "s*(a^2*b - (F + k)*a)",
            "-rate_b", "s*(-a^2*b + F*(1 - b))"] + common + ["-output_dir", "c"], tmp_path)
    fg, fc = fields(tmp_path / "g"), fields(tmp_path / "c")
    tol = 1e-13 if integrator[0] == "-dt" else 1e-11
    for s in "ab":
        assert np.max(np.abs(fg[s] - fc[s])) < tol, (s, np.max(np.abs(fg[s] - fc[s])))


GS_JAC = {"a_a": "s*(2*a*b - (F + k))", "a_b": "s*a^2", "b_a": "-2*s*a*b",
          "b_b": "-s*(a^2 + F)"}


def test_custom_jacobian_by_expressions_split_matches_compiled(tmp_path):
    """Split integrator (per-cell Newton with the Jacobian by expressions): Gray-Scott as
    expressions equals the compiled gray_scott to the Newton tolerance (1e-11) after 100 steps;
    the same model given as a deck (`jac: {a: {a: ...}}`) gives the same fields bitwise."""
    common = GRID + ["-params_F", "0.04", "-params_k", "0.06", "-params_s", "1", "-D_a", "0.5",
                     "-D_b", "1", "-init_a", "0.25 + 0.05*sin(2*pi*x/Lx)",
                     "-init_b", "0.5 + 0.05*cos(2*pi*y/Ly)", "-steps", "100",
                     "-checkpoint_every", "100", "-integrator", "split", "-dt", "0.5"]
    rates = ["-rate_a", "s*(a^2*b - (F + k)*a)", "-rate_b", "s*(-a^2*b + F*(1 - b))"]
    # a value starting with '-' would be read as an option name: " -2*s*a*b"
    jac = [x for k, v in GS_JAC.items() for x in ("-jac_" + k, " " + v)]
    run_ok(["-model", "gray_scott"] + common + ["-output_dir", "g"], tmp_path)
    run_ok(["-model", "custom", "-species", "a,b"] + rates + jac + common + ["-output_dir", "c"],
           tmp_path)
    deck = tmp_path / "gs.yaml"
    deck.write_text("model: custom\nspecies: a,b\nrate:\n  a: s*(a^2*b - (F + k)*a)\n"
                    "  b: s*(-a^2*b + F*(1 - b))\njac:\n" +
                    "".join(f"  {s}:\n" + "".join(f"    {q}: {GS_JAC[s + '_' + q]}\n"
                                                 for q in "ab") for s in "ab"))
    run_ok([str(deck)] + common + ["-output_dir", "d"], tmp_path)
    fg, fc, fd = fields(tmp_path / "g"), fields(tmp_path / "c"), fields(tmp_path / "d")
    assert np.ptp(fg["a"]) > 1e-3
    for s in "ab":
        assert np.max(np.abs(fg[s] - fc[s])) < 1e-11, (s, np.max(np.abs(fg[s] - fc[s])))
        assert np.array_equal(fc[s], fd[s])


@pytest.mark.parametrize("args,expect", [
    (["-jac_a_a", "0", "-jac_a_b", "0", "-jac_b_b", "0"], "-jac_b_a: missing"),
    (["-jac_a_a", "0", "-jac_a_b", "a*(", "-jac_b_a", "0", "-jac_b_b", "0"], "-jac_a_b a*("),
])
def test_bad_custom_jacobian(tmp_path, args, expect):
    r = run(["-model", "custom", "-species", "a,b", "-rate_a", "0 - a", "-rate_b", "a"] + args +
            ["-output_dir", "bad"] + QUIET, tmp_path)
    assert expect in error_line(r)
    assert not os.path.exists(tmp_path / "bad")


@pytest.mark.parametrize("ranks", [1, 2, 4])
def test_decoupled_layers_equal_independent_runs_bitwise(tmp_path, ranks):
    """Two layers of a custom model with mu = nu = 0 equal two independent runs of the single
    model (layer 2 with other parameters and D) bitwise: both take the general explicit path."""
    one = ["-model", "custom", "-species", "a,b"] + BRUSS_RATES + GRID + [
        "-dt", "0.01", "-steps", "200", "-checkpoint_every", "200"]
    layers = {"1": (PARAMS, ["-D_a", "4", "-D_b", "10"], INIT),
              "2": (["-params_alpha", "2.5", "-params_beta", "8", "-params_s", "0.8"],
                    ["-D_a", "3", "-D_b", "12"], "2.5 + 0.05*cos(2*pi*x/Lx)")}
    two = ["-model", "custom", "-species", "a,b", "-layers", "2", "-params_couple_a", "0",
           "-params_couple_b", "0"] + BRUSS_RATES + GRID + [
        "-dt", "0.01", "-steps", "200", "-checkpoint_every", "200", "-output_dir", "two"]
    for l, (params, D, init) in layers.items():
        run_ok(one + params + D + ["-init_a", init, "-init_b", INIT, "-output_dir", "one" + l],
               tmp_path, ranks)
        two += [params[i] + l if i % 2 == 0 else params[i] for i in range(len(params))]
        two += [D[0] + l, D[1], D[2] + l, D[3], "-init_a" + l, init, "-init_b" + l, INIT]
    run_ok(two, tmp_path, ranks)
    f2 = fields(tmp_path / "two")
    for l in "12":
        f1 = fields(tmp_path / ("one" + l))
        assert np.ptp(f1["a"]) > 1e-3
        for s in "ab":
            assert np.array_equal(f1[s], f2[s + l]), (l, s, np.max(np.abs(f1[s] - f2[s + l])))

"""`morphogen screen`, end to end: a Brusselator alpha x beta grid screen reports exactly the
analytically Turing-unstable sets, each with the fastest wavelength of a brute-force dispersion
maximum; random and LHS screens give the same table on 1 and 2 ranks; a custom model with the
Brusselator's rates gives the same sets as -model brusselator, and a layered model screens;
bad input is refused with one line naming the option, and nothing is written."""
import csv
import json
import os
import sys

import h5py
import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "app"))
from conftest import run  # noqa: E402

DA, DB = 1.0, 8.0
ALPHA, BETA = (0.5, 3.0), (1.0, 12.0)
NA, NB = 60, 80
BRUSSELATOR = ["-model", "brusselator", "-D_a", str(DA), "-D_b", str(DB), "-params_s", "1",
               "-screen_params", "alpha,beta", "-screen_range_alpha", "%g,%g" % ALPHA,
               "-screen_range_beta", "%g,%g" % BETA]
CUSTOM = ["-model", "custom", "-species", "a,b", "-rate_a", "alpha - (1 + beta)*a + a^2*b",
          "-rate_b", "beta*a - a^2*b", "-D_a", str(DA), "-D_b", str(DB),
          "-screen_params", "alpha,beta", "-screen_range_alpha", "%g,%g" % ALPHA,
          "-screen_range_beta", "%g,%g" % BETA, "-screen_search_b", "0,30"]


def ok(r):
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r


def table(d):
    with open(os.path.join(d, "turing_sets.csv")) as f:
        rows = list(csv.DictReader(f))
    with open(os.path.join(d, "screen.json")) as f:
        return rows, json.load(f)


def linspace(lo, hi, n):  # the screen's grid values, bit for bit
    v = lo + (hi - lo) * np.arange(n) / (n - 1)
    v[-1] = hi
    return v


def grid_sets():
    """alpha, beta of every set (alpha fastest) and the exact classification."""
    a, b = np.meshgrid(linspace(*ALPHA, NA), linspace(*BETA, NB), indexing="xy")
    a, b = a.ravel(), b.ravel()
    hopf = 1 + a ** 2
    onset = (1 + a * np.sqrt(DA / DB)) ** 2
    assert np.min(np.abs(b - hopf) / hopf) > 1e-6 and np.min(np.abs(b - onset) / onset) > 1e-6
    return a, b, b < hopf, (b < hopf) & (b > onset)


def brute_force(alpha, beta):
    """Fastest k and growth: max over k of the largest Re eigenvalue of J - k^2 D."""
    J = np.array([[beta - 1, alpha ** 2], [-beta, -alpha ** 2]])
    D = np.diag([DA, DB])

    def sigma(k):
        A = J[None] - (k ** 2)[:, None, None] * D[None]
        return np.linalg.eigvals(A).real.max(axis=1)

    k = np.linspace(0, 3 * np.sqrt(np.abs(J).sum(axis=1).max() / DA), 4001)
    for _ in range(3):  # zoom in around the maximum
        i = int(np.argmax(sigma(k)))
        lo, hi = k[max(i - 2, 0)], k[min(i + 2, len(k) - 1)]
        k = np.linspace(lo, hi, 4001)
    s = sigma(k)
    return k[int(np.argmax(s))], s.max()


def test_brusselator_grid_screen_matches_the_analytic_turing_region(tmp_path):
    r = ok(run(["screen"] + BRUSSELATOR + ["-screen_points", f"{NA},{NB}", "-screen_output", "s"],
               tmp_path, 2))
    assert f"{NA * NB} sets" in r.stdout
    rows, summary = table(tmp_path / "s")
    a, b, stable, turing = grid_sets()
    assert [int(x["index"]) for x in rows] == list(np.flatnonzero(turing))
    c = summary["counts"]
    assert c == {"total": NA * NB, "no_steady_state": 0, "unstable_k0": int((~stable).sum()),
                 "stable": int((stable & ~turing).sum()), "turing_unstable": int(turing.sum())}
    assert summary["ranks"] == 2 and summary["closed_form"] and summary["sets_per_s"] > 0
    assert 50 < len(rows) < NA * NB  # a real region, not all or nothing
    for x in rows[:: max(1, len(rows) // 60)]:
        i = int(x["index"])
        alpha, beta = float(x["alpha"]), float(x["beta"])
        assert (alpha, beta) == (a[i], b[i])
        assert (float(x["u_a"]), float(x["u_b"])) == pytest.approx((alpha, beta / alpha))
        k, growth = brute_force(alpha, beta)
        assert float(x["wavelength"]) == pytest.approx(2 * np.pi / k, rel=1e-3)
        assert float(x["k"]) == pytest.approx(k, rel=1e-3)
        assert float(x["growth"]) == pytest.approx(growth, rel=1e-6, abs=1e-12)


def test_general_eigensolver_path_finds_the_same_sets(tmp_path):
    args = ["screen"] + BRUSSELATOR + ["-screen_points", "30,40"]
    ok(run(args + ["-screen_output", "fast"], tmp_path))
    ok(run(args + ["-screen_general", "-screen_output", "general"], tmp_path))
    fast, _ = table(tmp_path / "fast")
    general, summary = table(tmp_path / "general")
    assert not summary["closed_form"]
    assert [x["index"] for x in fast] == [x["index"] for x in general] and fast
    for f, g in zip(fast, general):
        assert float(g["wavelength"]) == pytest.approx(float(f["wavelength"]), rel=1e-6)


@pytest.mark.parametrize("sampling", ["random", "lhs"])
def test_same_table_on_1_and_2_ranks(tmp_path, sampling):
    args = ["screen"] + BRUSSELATOR + ["-screen_sampling", sampling, "-screen_points", "20000",
                                       "-screen_seed", "7"]
    ok(run(args + ["-screen_output", "one"], tmp_path, 1))
    ok(run(args + ["-screen_output", "two"], tmp_path, 2))
    one = (tmp_path / "one/turing_sets.csv").read_text()
    assert one == (tmp_path / "two/turing_sets.csv").read_text()
    rows, summary = table(tmp_path / "one")
    assert summary["counts"]["total"] == 20000 and len(rows) == summary["counts"]["turing_unstable"]
    a = np.array([float(x["alpha"]) for x in rows])
    b = np.array([float(x["beta"]) for x in rows])
    assert ALPHA[0] <= a.min() and a.max() < ALPHA[1] and BETA[0] <= b.min() and b.max() < BETA[1]
    hopf, onset = 1 + a ** 2, (1 + a * np.sqrt(DA / DB)) ** 2
    assert np.all((b < hopf) & (b > onset))
    ok(run(args[:-1] + ["8", "-screen_output", "other"], tmp_path, 1))  # another seed
    assert (tmp_path / "other/turing_sets.csv").read_text() != one


@pytest.mark.parametrize("ranks", [1, 2, 3, 4])
def test_hdf5_table_holds_the_csv_rows(tmp_path, ranks):
    """-screen_format both: turing_sets.h5 has one dataset per CSV column with the same numbers
    (many chunks dealt over the ranks: 120,000 sets); hdf5 alone writes no CSV."""
    args = ["screen"] + BRUSSELATOR + ["-screen_points", "300,400"]
    ok(run(args + ["-screen_format", "both", "-screen_output", "b"], tmp_path, ranks))
    with open(tmp_path / "b/turing_sets.csv") as f:
        head = f.readline().strip().split(",")
    data = np.loadtxt(tmp_path / "b/turing_sets.csv", delimiter=",", skiprows=1)
    with h5py.File(tmp_path / "b/turing_sets.h5") as f:
        assert f.attrs["columns"].decode() == ",".join(head)
        assert f["index"].dtype == np.int64 and len(data) > 10000
        for c, name in enumerate(head):
            assert np.array_equal(f[name][...], data[:, c]), name
    assert json.loads((tmp_path / "b/screen.json").read_text())["table_h5"] == "turing_sets.h5"
    ok(run(args + ["-screen_format", "hdf5", "-screen_output", "h"], tmp_path, ranks))
    assert not (tmp_path / "h/turing_sets.csv").exists()
    with h5py.File(tmp_path / "h/turing_sets.h5") as f, \
            h5py.File(tmp_path / "b/turing_sets.h5") as g:
        assert all(np.array_equal(f[n][...], g[n][...]) for n in head)


def test_custom_model_screens_like_the_registered_one(tmp_path):
    points = ["-screen_points", "24,30"]
    ok(run(["screen"] + BRUSSELATOR + points + ["-screen_output", "reg"], tmp_path, 2))
    ok(run(["screen"] + CUSTOM + points + ["-screen_output", "cus"], tmp_path, 2))
    reg, sreg = table(tmp_path / "reg")
    cus, scus = table(tmp_path / "cus")
    assert scus["model"] == "custom" and scus["counts"] == sreg["counts"]
    assert [x["index"] for x in cus] == [x["index"] for x in reg] and reg
    for c, g in zip(cus, reg):  # the custom model's Jacobian is a finite difference
        assert float(c["wavelength"]) == pytest.approx(float(g["wavelength"]), rel=1e-4)


def test_layered_model_screens(tmp_path):
    r = ok(run(["screen", "-model", "brusselator", "-layers", "2", "-params_couple_a", "0.1",
                "-params_couple_b", "0.1", "-D_a1", "1", "-D_b1", "8", "-D_a2", "1", "-D_b2",
                "8", "-params_beta2", "2", "-screen_params", "alpha1,beta1",
                "-screen_range_alpha1", "0.5,3", "-screen_range_beta1", "1,12",
                "-screen_points", "6,8", "-screen_output", "lay"], tmp_path, 2))
    rows, summary = table(tmp_path / "lay")
    assert summary["counts"]["total"] == 48 and not summary["closed_form"]
    assert sum(summary["counts"].values()) == 2 * 48
    with open(tmp_path / "lay/turing_sets.csv") as f:
        header = f.readline().strip().split(",")
    assert header == ["index", "alpha1", "beta1", "wavelength", "k", "growth", "u_a1", "u_b1",
                      "u_a2", "u_b2"]


BAD = [
    (["-screen_params", "gamma"], "-screen_params gamma: not a parameter of model brusselator"),
    (["-screen_range_alpha", "3,1"], "-screen_range_alpha 3,1: lo must be < hi"),
    (["-screen_range_alpha", "1"], "-screen_range_alpha"),
    (["-screen_points", "0"], "-screen_points 0: must be an integer"),
    (["-screen_sampling", "sobol"], "-screen_sampling"),
    (["-screen_format", "xlsx"], "-screen_format"),
    (["-params_s", "1+x"], "-params_s 1+x: a screen needs a number"),
    (["-D_b", "8 +- 10%"], "-D_b 8 +- 10%: a screen needs a number"),
    (["-screen_rang_beta", "1,2"], "-screen_rang_beta 1,2: unknown option"),
    (["-screen_range_alpha", "-1,2"], "-screen_range_alpha -1,2: outside the allowed range"),
]


@pytest.mark.parametrize("extra,message", BAD, ids=[m.split(":")[0] for _, m in BAD])
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, extra, message):
    r = run(["screen"] + BRUSSELATOR + ["-screen_output", "bad"] + extra, tmp_path)
    assert r.returncode == 1, r.stdout + r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("morphogen: error: "), r.stderr
    assert message in lines[0], lines[0]
    assert not (tmp_path / "bad").exists()


def test_missing_params_is_refused(tmp_path):
    r = run(["screen", "-model", "brusselator"], tmp_path)
    assert r.returncode == 1 and "-screen_params: missing" in r.stderr


def test_screen_options_in_a_plain_run_say_how_to_screen(tmp_path):
    r = run(BRUSSELATOR + ["-output_dir", "plain"], tmp_path)
    assert r.returncode == 1
    assert "-screen_params: this is a Turing screen; run it with morphogen screen" in r.stderr
    assert not (tmp_path / "plain").exists()

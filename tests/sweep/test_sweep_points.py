"""`morphogen sweep` over a list of points (-sweep_points FILE), end to end on 1, 2 and 4 ranks: a
screen's Turing-unstable sets are simulated and only those, rows evenly chosen by
-sweep_points_max, each record carrying its index in the file; a listed sweep of given (F, k)
rows writes the same fields, bit for bit, as the product sweep over those values; a screen run
with other fixed values is warned about; a changed file is refused on resume; bad input is
refused with one line and writes nothing."""
import csv
import os
import sys

import h5py
import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "app"))
sys.path.insert(0, os.path.dirname(__file__))
from sweep_helpers import ok, table  # noqa: E402
from conftest import SOURCE, run  # noqa: E402

BRUS = os.path.join(SOURCE, "input", "brusselator.yaml")
GS = os.path.join(SOURCE, "input", "gray_scott_pearson_spots.yaml")
BRUS_SMALL = ["-D_a", "1", "-D_b", "8", "-grid_n", "32,32", "-grid_L", "32,32", "-dt", "0.01",
              "-steps", "300", "-png_every", "0"]
GS_SMALL = ["-grid_n", "32,32", "-grid_L", "0.3125", "-steps", "400", "-png_every", "0"]


def screen(tmp_path):
    ok(run(["screen", "-model", "brusselator", "-D_a", "1", "-D_b", "8", "-screen_params",
            "alpha,beta", "-screen_range_alpha", "1,3", "-screen_range_beta", "2,8",
            "-screen_points", "12,12", "-screen_format", "both", "-screen_output", "scr"],
           tmp_path, 2))
    with open(tmp_path / "scr/turing_sets.csv") as f:
        return list(csv.DictReader(f))


@pytest.mark.parametrize("ranks", [1, 2, 4])
def test_sweep_of_a_screens_unstable_sets(tmp_path, ranks):
    rows = screen(tmp_path)
    m = len(rows)
    assert m > 20
    r = ok(run(["sweep", BRUS, "-sweep_points", "scr/turing_sets.csv", "-sweep_points_max", "5",
                "-output_dir", "s"] + BRUS_SMALL, tmp_path, ranks, timeout=300))
    assert "5 points (rows of scr/turing_sets.csv: params_alpha, params_beta)" in r.stdout
    assert "warning" not in r.stderr
    t = table(tmp_path / "s")
    assert t["points"] == 5 and t["finished"] == 5 and t["points_file"] == "scr/turing_sets.csv"
    for rec in t["records"]:
        row = rows[rec["index"] * m // 5]  # evenly spaced rows floor(i M / N)
        assert rec["source_index"] == int(row["index"])
        assert rec["params"]["params_alpha"] == float(row["alpha"])
        assert rec["params"]["params_beta"] == float(row["beta"])
        assert rec["stability"]["turing_unstable"], rec  # the run's own analysis agrees
    with open(tmp_path / "s/sweep.csv") as f:
        head = f.readline()
    assert head.startswith("index,source_index,params_alpha,params_beta,class,")
    # options_used.yaml reruns as the same listed sweep
    ok(run(["sweep", str(tmp_path / "s/options_used.yaml"), "-output_dir", "again"], tmp_path,
           ranks, timeout=300))
    again = table(tmp_path / "again")
    assert [(r["params"], r["source_index"], r["class"]) for r in again["records"]] == \
        [(r["params"], r["source_index"], r["class"]) for r in t["records"]]


def test_hdf5_table_gives_the_same_points(tmp_path):
    """The screen's turing_sets.h5 as the points file: the same points, records and fields."""
    screen(tmp_path)
    for f in ("csv", "h5"):
        ok(run(["sweep", BRUS, "-sweep_points", f"scr/turing_sets.{f}", "-sweep_points_max", "3",
                "-output_dir", f] + BRUS_SMALL, tmp_path, 2))
    a, b = table(tmp_path / "csv"), table(tmp_path / "h5")
    assert b["points_file"] == "scr/turing_sets.h5" and b["finished"] == 3
    for ra, rb in zip(a["records"], b["records"]):
        assert (ra["params"], ra["source_index"], ra["class"]) == \
            (rb["params"], rb["source_index"], rb["class"])
        assert ra["metrics"] == rb["metrics"]


def test_listed_points_equal_the_product_sweep_bitwise(tmp_path):
    (tmp_path / "pts.csv").write_text("F,k,note\n0.03,0.06,1\n0.05,0.06,2\n0.03,0.065,3\n"
                                      "0.05,0.065,4\n")
    ok(run(["sweep", GS, "-sweep_axes", "params_F,params_k", "-sweep_params_F", "0.03,0.05", "-sweep_params_k", "0.06,0.065",
            "-output_dir", "prod"] + GS_SMALL, tmp_path, 2))
    ok(run(["sweep", GS, "-sweep_points", "pts.csv", "-sweep_axes", "params_F,params_k",
            "-output_dir", "list"] + GS_SMALL, tmp_path, 2))
    a, b = table(tmp_path / "prod"), table(tmp_path / "list")
    assert [r["source_index"] for r in b["records"]] == [0, 1, 2, 3]  # no index column: rows
    for ra, rb in zip(a["records"], b["records"]):
        assert ra["params"] == rb["params"] and ra["class"] == rb["class"]
        with h5py.File(tmp_path / "prod" / ra["file"]) as fa, \
                h5py.File(tmp_path / "list" / rb["file"]) as fb:
            for s in ("a", "b"):
                assert np.array_equal(fa["VTKHDF/PointData"][s][...],
                                      fb["VTKHDF/PointData"][s][...])


def test_deck_keys_relative_to_the_deck_and_screen_mismatch_warning(tmp_path):
    screen(tmp_path)
    deck = tmp_path / "d.yaml"
    deck.write_text(open(BRUS).read().replace("output_dir: brusselator", "output_dir: dk") +
                    "sweep: {points: scr/turing_sets.csv, points_max: 2}\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    small = ["-grid_n", "32,32", "-grid_L", "32,32", "-dt", "0.002", "-steps", "50"]
    r = ok(run(["sweep", str(deck)] + small, elsewhere, 2))  # D_a, D_b: the deck's
    assert "2 points" in r.stdout
    warn = [l for l in r.stderr.splitlines() if l.startswith("morphogen: warning: -sweep_points")]
    assert len(warn) == 2 and "-D_a is 49.4 here, 1 in the screen" in warn[0], r.stderr
    assert table(elsewhere / "dk")["finished"] == 2


def test_changed_points_file_is_refused_on_resume(tmp_path):
    screen(tmp_path)
    base = ["sweep", BRUS, "-sweep_points", "scr/turing_sets.csv", "-output_dir", "s"]
    ok(run(base + ["-sweep_points_max", "3"] + BRUS_SMALL, tmp_path))
    r = run(base + ["-sweep_points_max", "4"] + BRUS_SMALL, tmp_path)
    assert r.returncode == 1 and "the axes changed" in r.stderr, r.stderr


@pytest.mark.parametrize("text,args,needle", [
    (None, [], "-sweep_points missing.csv: cannot open"),
    ("F,k\n", [], "needs a header line and at least one row"),
    ("F,k\n0.03,0.06\n", [], "not a screen's file"),
    ("F,k\n0.03,0.06\n", ["-sweep_axes", "params_F,params_q"], "no column for sweep axis params_q"),
    ("F,k\n0.03,zz\n", ["-sweep_axes", "params_F,params_k"], "line 2: 'zz' is not a finite"),
    ("F,k\n0.03,0.06\n0.04\n", ["-sweep_axes", "params_F,params_k"], "line 3: 1 fields"),
    ("F,k\n0.03,0.06\n", ["-sweep_axes", "params_F", "-sweep_params_F", "0.1"],
     "-sweep_params_F: not used with -sweep_points"),
    ("F,k\n0.03,7\n", ["-sweep_axes", "params_F,params_k"], "-params_k 7: out of range"),
    ("h5:F", ["-sweep_axes", "params_F,params_k"], "no column for sweep axis params_k"),
    ("h5:", ["-sweep_axes", "params_F,params_k"], "no datasets in its root group"),
])
def test_bad_points_input(tmp_path, text, args, needle):
    name = "missing.csv" if text is None else "p.csv"
    if text is not None and text.startswith("h5:"):  # an HDF5 file with these 1-D datasets
        name = "p.h5"
        with h5py.File(tmp_path / name, "w") as f:
            for col in filter(None, text[3:].split(",")):
                f[col] = np.array([0.03, 0.04])
    elif text is not None:
        (tmp_path / name).write_text(text)
    r = run(["sweep", GS, "-sweep_points", name, "-output_dir", "s"] + GS_SMALL + args,
            tmp_path, 2)
    assert r.returncode == 1, r.stdout + r.stderr
    lines = [l for l in r.stderr.splitlines() if l.startswith("morphogen: error:")]
    assert lines and needle in lines[0], r.stderr
    assert not (tmp_path / "s").exists()


def test_points_max_needs_points(tmp_path):
    deck = os.path.join(SOURCE, "input", "gray_scott_sweep.yaml")
    r = run(["sweep", deck, "-sweep_points_max", "3", "-output_dir", "s"] + GS_SMALL, tmp_path)
    assert r.returncode == 1 and "-sweep_points_max 3: needs -sweep_points" in r.stderr
    assert not (tmp_path / "s").exists()

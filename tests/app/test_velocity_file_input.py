"""Advection velocity from HDF5 files (-velocity_file, -velocity_datasets, -velocity_times,
-velocity_time_attribute; fields/velocity_file.hpp).

Bad input never runs: each case exits non-zero with exactly one error line naming the option,
the value and what is allowed, and leaves an existing output directory untouched (1 and 2
ranks): missing file, not HDF5, missing dataset, wrong grid size, non-finite value, series times
not increasing, a malformed .series file, a missing time attribute, a wrong count of
-velocity_times, -velocity_file beside -velocity_x or -fluid, the companions without
-velocity_file, and a later frame whose speed outgrows a given or the widest halo (refused at
the start: the halo is sized from the largest speed over all frames).

Valid runs (2 ranks): a steady velocity written with h5py gives the same final state as the
same velocity as expressions (bitwise, float64 snapshots); a morphogen snapshot of an advected
run read back (its final snapshot, and its .vtkhdf.series) gives the expression run's result;
deck keys velocity: {file, datasets} with a file beside the deck, run from elsewhere (1 rank)."""
import json
import os

import pytest
from conftest import error_lines, run

h5py = pytest.importorskip("h5py")
np = pytest.importorskip("numpy")

N = 32
GRID = ["-model", "custom", "-species", "a", "-rate_a", "0", "-D_a", "0", "-grid_n", f"{N},{N}",
        "-grid_L", str(N), "-grid_bc", "periodic,neumann", "-steps", "6", "-dt", "0.5",
        "-init_a", "exp(-((x-12)^2 + (y-16)^2)/18)", "-summary", "false", "-advect", "a"]
EXPR = ["-velocity_x", "0.25*(y-16)", "-velocity_y", "0.125*(x-16)"]


def centres():
    c = np.arange(N) + 0.5
    return np.meshgrid(c, c, indexing="xy")  # x[j, i], y[j, i]


def write(path, fields, time=None, shape=(1, N, N), group="VTKHDF/PointData"):
    with h5py.File(path, "w") as f:
        for name, v in fields.items():
            f.create_dataset(f"{group}/{name}", data=np.asarray(v, dtype=np.float64).reshape(shape))
        if time is not None:
            f.create_group("morphogen").attrs["time"] = time


def shear(scale=1.0):
    x, y = centres()
    return {"velocity_x": scale * 0.25 * (y - 16), "velocity_y": scale * 0.125 * (x - 16)}


def series(path, entries):
    path.write_text(json.dumps({"file-series-version": "1.0",
                                "files": [{"name": n, "time": t} for n, t in entries]}))


@pytest.fixture
def files(tmp_path):
    d = tmp_path / "in"
    d.mkdir()
    write(d / "ok.h5", shear())
    write(d / "fast.h5", shear(20.0))
    write(d / "faster.h5", shear(800.0))
    write(d / "only_x.h5", {"velocity_x": shear()["velocity_x"]})
    write(d / "small.h5", {k: v[::2, ::2] for k, v in shear().items()}, shape=(16, 16))
    bad = shear()
    bad["velocity_y"][5, 3] = np.nan
    write(d / "nan.h5", bad)
    (d / "text.h5").write_text("not hdf5\n")
    for i, t in ((1, 0.0), (2, 1.5), (3, 4.0)):
        write(d / f"flow_{i:04d}.h5", shear(0.5 * i), time=t)
    series(d / "same_t.series", [("ok.h5", 1.0), ("ok.h5", 1.0)])
    series(d / "outgrow.series", [("ok.h5", 0.0), ("fast.h5", 10.0)])
    series(d / "outgrow_widest.series", [("ok.h5", 0.0), ("faster.h5", 10.0)])
    (d / "broken.series").write_text('{"files": [{"name": "ok.h5", "time": 0}')
    return d


CASES = [
    # (id, args (IN = the input directory), substrings the one-line error must contain)
    ("missing_file", ["-velocity_file", "IN/nope.h5"],
     ["-velocity_file IN/nope.h5", "no such file"]),
    ("not_hdf5", ["-velocity_file", "IN/text.h5"],
     ["-velocity_file IN/text.h5", "not an HDF5 file"]),
    ("missing_dataset", ["-velocity_file", "IN/only_x.h5"],
     ["-velocity_file IN/only_x.h5", "-velocity_datasets velocity_x,velocity_y",
      "no dataset 'velocity_y'", "/VTKHDF/PointData/velocity_y",
      "the file's datasets: /VTKHDF/PointData/velocity_x"]),
    ("missing_named_dataset",
     ["-velocity_file", "IN/ok.h5", "-velocity_datasets", "velocity_x,/w"],
     ["-velocity_datasets velocity_x,/w", "no dataset '/w'"]),
    ("wrong_grid", ["-velocity_file", "IN/small.h5"],
     ["-velocity_file IN/small.h5", "has 16 x 16 values", "grid 32 x 32 (ny x nx)", "flat array"]),
    ("not_finite", ["-velocity_file", "IN/nan.h5"],
     ["-velocity_file IN/nan.h5", "/VTKHDF/PointData/velocity_y", "value nan at cell (3,5,0)",
      "must be finite"]),
    ("times_not_increasing", ["-velocity_file", "IN/same_t.series"],
     ["-velocity_file IN/same_t.series", "times not increasing", "strictly increasing"]),
    ("broken_series", ["-velocity_file", "IN/broken.series"],
     ["-velocity_file IN/broken.series", "not a valid .series JSON file"]),
    ("no_time_attribute", ["-velocity_file", "IN/ok.h5,IN/fast.h5"],
     ["-velocity_file IN/ok.h5,IN/fast.h5", "no attribute 'time' on /morphogen",
      "-velocity_times"]),
    ("times_count", ["-velocity_file", "IN/ok.h5,IN/fast.h5", "-velocity_times", "0"],
     ["-velocity_times", "1 times for 2 files", "one time per file"]),
    ("times_with_one_file", ["-velocity_file", "IN/ok.h5", "-velocity_times", "0"],
     ["-velocity_times", "applies to a comma list"]),
    ("with_expression", ["-velocity_file", "IN/ok.h5", "-velocity_x", "1"],
     ["-velocity_x", "-velocity_file IN/ok.h5", "drop -velocity_x or -velocity_file"]),
    ("with_fluid", ["-velocity_file", "IN/ok.h5", "-fluid", "cavity", "-grid_bc", "neumann"],
     ["-velocity_file IN/ok.h5", "-fluid cavity", "drop -velocity_file or the fluid"]),
    ("pattern_bad_conversion", ["-velocity_file", "IN/flow_%s.h5"],
     ["-velocity_file IN/flow_%s.h5", "one integer conversion (%d, %4d or %04d)"]),
    ("pattern_two_conversions", ["-velocity_file", "IN/flow_%d_%d.h5"],
     ["-velocity_file IN/flow_%d_%d.h5", "one integer conversion"]),
    ("pattern_no_match", ["-velocity_file", "IN/none_%03d.h5"],
     ["-velocity_file IN/none_%03d.h5", "no file matches", "none_000.h5", "none_001.h5"]),
    ("datasets_without_file", EXPR + ["-velocity_datasets", "u,v"],
     ["-velocity_datasets", "applies with -velocity_file only"]),
    # Frame 2 (t = 10, never reached in 6 steps) has max |u_x| = 77.5: Courant 38.75.
    ("later_frame_beyond_given_halo",
     ["-velocity_file", "IN/outgrow.series", "-advection_halo", "8"],
     ["-advection_halo 8", "reaches 40 cells", "Courant number max|u_x| dt/hx = 38.75"]),
    ("later_frame_beyond_widest_halo", ["-velocity_file", "IN/outgrow_widest.series"],
     ["-dt 0.5", "widest advection halo (64 cells)", "smaller -dt"]),
]


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_velocity_file_bad_input(case, ranks, files, tmp_path):
    _, args, needles = case
    args = [a.replace("IN/", str(files) + "/") for a in args]
    out = tmp_path / "out"
    out.mkdir()
    sentinel = out / "a_final.png"
    sentinel.write_text("previous result")
    proc = run(GRID + args + ["-output_dir", str(out)], cwd=tmp_path, ranks=ranks)
    assert proc.returncode != 0, proc.stdout
    lines = error_lines(proc)
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("morphogen: error: "), lines[0]
    for n in needles:
        assert n.replace("IN/", str(files) + "/") in lines[0], lines[0]
    assert sorted(os.listdir(out)) == ["a_final.png"]
    assert sentinel.read_text() == "previous result"


def test_help_lists_velocity_file_options(tmp_path):
    proc = run(["-help"], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    for key in ("-velocity_file FILE|A,B,..|S.series", "-velocity_datasets X,Y[,Z]",
                "-velocity_times T1,T2,..", "-velocity_time_attribute /object/name"):
        assert key in proc.stdout, proc.stdout


def snapshots(out):
    return sorted(p for p in os.listdir(out)
                  if p.startswith("morphogen_") and p.endswith(".vtkhdf"))


def final_a(out):
    snaps = snapshots(out)
    with h5py.File(out / snaps[-1], "r") as f:
        return f["VTKHDF/PointData/a"][()]


def run_ok(args, out, tmp_path, ranks=2):
    proc = run(GRID + args + ["-snapshot_precision", "float64", "-output_dir", str(out)],
               cwd=tmp_path, ranks=ranks)
    assert proc.returncode == 0, proc.stderr
    return proc


def test_h5py_file_equals_expressions(files, tmp_path):
    run_ok(EXPR, tmp_path / "expr", tmp_path)
    expr = final_a(tmp_path / "expr")
    proc = run_ok(["-velocity_file", str(files / "ok.h5")], tmp_path / "file", tmp_path)
    assert "velocity from -velocity_file" in proc.stdout and "steady" in proc.stdout
    a = final_a(tmp_path / "file")
    assert np.ptp(a) > 0.1
    assert np.array_equal(a, expr)


def test_snapshot_read_back(tmp_path):
    first = tmp_path / "first"
    run_ok(EXPR + ["-snapshot_every", "2"], first, tmp_path)
    expr = final_a(first)
    run_ok(["-velocity_file", str(first / snapshots(first)[-1])], tmp_path / "again", tmp_path)
    assert np.array_equal(final_a(tmp_path / "again"), expr)
    # The run's series: four frames (t = 0, 1, 2, 3) of the same steady velocity, interpolated.
    proc = run_ok(["-velocity_file", str(first / "morphogen.vtkhdf.series")],
                  tmp_path / "series", tmp_path)
    assert "4 frames, t in [0, 3]" in proc.stdout and "held outside" in proc.stdout
    assert np.abs(final_a(tmp_path / "series") - expr).max() < 1e-13


def test_deck_keys_and_deck_directory(files, tmp_path):
    """Deck keys velocity: {file, datasets} (nested, as -velocity_file/-velocity_datasets); a
    relative file name is found in the deck's directory when run from elsewhere."""
    run_ok(EXPR, tmp_path / "expr", tmp_path, ranks=1)
    deck = files / "replay.yaml"
    deck.write_text("velocity:\n  file: ok.h5\n  datasets: [velocity_x, velocity_y]\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "deck"
    proc = run([str(deck)] + GRID + ["-snapshot_precision", "float64", "-output_dir", str(out)],
               cwd=elsewhere)
    assert proc.returncode == 0, proc.stderr
    assert np.array_equal(final_a(out), final_a(tmp_path / "expr"))
    used = (out / "options_used.yaml").read_text()
    assert 'velocity_file: "ok.h5"' in used and 'velocity_datasets: "velocity_x,velocity_y"' in used


def test_numbered_pattern_equals_comma_list(files, tmp_path):
    """-velocity_file flow_%04d.h5 reads flow_0001..0003 (0 is missing; 4 ends the sequence),
    exactly as the comma list of the three files (times from their /morphogen/time)."""
    names = ",".join(str(files / f"flow_{i:04d}.h5") for i in (1, 2, 3))
    run_ok(["-velocity_file", names], tmp_path / "list", tmp_path)
    proc = run_ok(["-velocity_file", str(files / "flow_%04d.h5")], tmp_path / "pattern",
                  tmp_path)
    assert "3 frames, t in [0, 4]" in proc.stdout, proc.stdout
    a = final_a(tmp_path / "pattern")
    assert np.ptp(a) > 0.1
    assert np.array_equal(a, final_a(tmp_path / "list"))

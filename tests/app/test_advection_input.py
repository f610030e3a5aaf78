"""Bad advection input (-advect, -advection_*, -velocity_*) never runs: each case exits
non-zero, prints exactly one error line naming the option and what is allowed, and leaves an
existing output directory untouched. Run on 1 and 2 ranks. Covered: an unknown or repeated
species in -advect, an unknown scheme or back-trace, velocity options without -advect, a
non-finite velocity, a dt whose back-trace exceeds the widest halo, a dt too large for a given
-advection_halo, and a velocity using t that outgrows the halo sized at the start (refused at
the step where it does, before any output). A valid advected run writes the velocity into its
snapshots and options_used.yaml reproduces it."""
import os

import pytest
from conftest import error_lines, run


GRID = ["-model", "gray_scott", "-grid_n", "32,32", "-grid_L", "32", "-steps", "5", "-dt", "0.5",
        "-summary", "false"]
ADV = GRID + ["-advect", "a,b", "-velocity_x", "1", "-velocity_y", "0.5"]

CASES = [
    # (id, args, substrings the one-line error must contain)
    ("unknown_species", GRID + ["-advect", "a,c", "-velocity_x", "1"],
     ["-advect a,c", "no species 'c'", "allowed a, b"]),
    ("repeated_species", GRID + ["-advect", "a,a"], ["-advect a,a", "'a' given twice"]),
    ("bad_scheme", ADV + ["-advection_scheme", "quintic"],
     ["-advection_scheme", "quintic", "linear", "cubic"]),
    ("bad_backtrace", ADV + ["-advection_backtrace", "rk4"],
     ["-advection_backtrace", "rk4", "rk2", "euler"]),
    ("velocity_without_advect", GRID + ["-velocity_x", "1"],
     ["-velocity_x", "add -advect SPECIES"]),
    ("scheme_without_advect", GRID + ["-advection_scheme", "cubic"],
     ["-advection_scheme", "add -advect SPECIES"]),
    ("velocity_not_finite", ADV + ["-velocity_y", "sqrt(x-10)"],
     ["-velocity_y sqrt(x-10)", "nan", "at cell (0,0,0)"]),
    ("velocity_infinite", ADV + ["-velocity_x", "1/(x-0.5)"],
     ["-velocity_x 1/(x-0.5)", "inf", "at cell (0,0,0)"]),
    ("velocity_z_in_2d", ADV + ["-velocity_z", "1"], ["-velocity_z", "unknown option"]),
    # |u_x| dt / h = 200 * 0.5 = 100 cells: beyond the widest halo (64).
    ("dt_beyond_widest_halo", GRID + ["-advect", "a", "-velocity_x", "200"],
     ["-dt 0.5", "back-trace reaches 102 cells", "Courant number max|u_x| dt/hx = 100",
      "widest advection halo (64 cells)", "smaller -dt"]),
    ("dt_beyond_given_halo", ADV + ["-velocity_x", "6", "-advection_halo", "4",
                                    "-advection_scheme", "cubic"],
     ["-advection_halo 4", "-dt 0.5", "reaches 6 cells", "Courant number max|u_x| dt/hx = 3",
      "cubic", "-advection_halo >= 6"]),
    ("halo_out_of_range", ADV + ["-advection_halo", "65"], ["-advection_halo", "65", "64"]),
    # u_x = 1 + t: Courant 0.5 at the start (halo 2), 1.5 after step 2 (needs 3).
    ("velocity_outgrows_halo", GRID + ["-advect", "a", "-velocity_x", "1 + t"],
     ["-velocity_x 1 + t", "at t = 1.25", "reaches 3 cells", "advection halo (2 cells, sized from "
      "the velocity at the start)", "-advection_halo 3"]),
]


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_advection_bad_input(case, ranks, tmp_path):
    _, args, needles = case
    out = tmp_path / "out"
    out.mkdir()
    sentinel = out / "a_final.png"
    sentinel.write_text("previous result")
    proc = run(args + ["-output_dir", str(out)], cwd=tmp_path, ranks=ranks)
    assert proc.returncode != 0, proc.stdout
    lines = error_lines(proc)
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("morphogen: error: "), lines[0]
    for n in needles:
        assert n in lines[0], lines[0]
    assert sorted(os.listdir(out)) == ["a_final.png"]
    assert sentinel.read_text() == "previous result"


def test_help_lists_advection_options(tmp_path):
    proc = run(["-help"], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    for key in ("-advect a,b", "-velocity_x EXPR", "-advection_scheme linear|cubic",
                "-advection_halo W"):
        assert key in proc.stdout, proc.stdout
    proc = run(ADV + ["-help"], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "Advection:" in proc.stdout
    for key in ("-advect <a,b>", "-advection_scheme <linear>", "-advection_backtrace <rk2>",
                "-velocity_x <1>", "-velocity_y <0.5>"):
        assert key in proc.stdout, proc.stdout


def test_valid_run_writes_velocity_and_reproduces(tmp_path):
    h5py = pytest.importorskip("h5py")
    out = tmp_path / "out"
    args = ADV + ["-velocity_x", "0.1*(y - 16)", "-advection_scheme", "cubic",
                  "-init_a", "1 - 0.5*disk(16, 16, 5)", "-init_b", "0.25*disk(16, 16, 5)",
                  "-output_dir", str(out)]
    proc = run(args, cwd=tmp_path, ranks=2)
    assert proc.returncode == 0, proc.stderr
    assert "advection of a,b (semi-Lagrangian, cubic, rk2 back-trace" in proc.stdout
    used = (out / "options_used.yaml").read_text()
    for key in ('advect: "a,b"', 'velocity_x: "0.1*(y - 16)"', 'advection_scheme: "cubic"'):
        assert key in used, used
    snaps = sorted(p for p in os.listdir(out) if p.endswith(".vtkhdf") and p.startswith("morphogen_"))
    assert snaps, os.listdir(out)
    with h5py.File(out / snaps[-1], "r") as f:
        pd = f["VTKHDF/PointData"]
        assert set(pd.keys()) >= {"a", "b", "velocity_x", "velocity_y"}
        vx = pd["velocity_x"][()].reshape(32, 32)
        vy = pd["velocity_y"][()].reshape(32, 32)
    j = 20
    assert abs(vx[j, 3] - 0.1 * (j + 0.5 - 16)) < 1e-6
    assert abs(vy).max() == pytest.approx(0.5)
    again = tmp_path / "again"
    proc = run([str(out / "options_used.yaml"), "-output_dir", str(again)], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (again / "a_final.png").read_bytes() == (out / "a_final.png").read_bytes()

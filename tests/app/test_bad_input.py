"""Bad input never crashes, hangs or silently runs: each case exits non-zero within the
timeout, prints exactly one error line that names the option (or deck key) and what is
allowed, and leaves an existing output directory untouched. Run on 1 and 2 ranks."""
import os

import pytest
from conftest import error_lines, run

CASES = [
    # (id, args, substrings the one-line error must contain)
    ("misspelt", ["-stpes", "10"], ["-stpes", "did you mean -steps"]),
    ("unknown", ["-frobnicate", "1"], ["-frobnicate", "unknown option"]),
    ("steps_range", ["-steps", "-5"], ["-steps", "-5", "allowed >= 0"]),
    ("param_range", ["-params_alpha", "-3"], ["-params_alpha", "-3", "allowed [0, 1000000]"]),
    ("param_field_range", ["-params_alpha", "x - 100"], ["-params_alpha", "outside the allowed range [0, 1000000]", "at cell"]),
    ("diffusion_range", ["-D_a", "-1"], ["-D_a", "-1", "allowed >= 0"]),
    ("not_a_number", ["-dt", "fast"], ["-dt", "fast", "not a number"]),
    ("bad_expression", ["-params_alpha", "12 +* x"], ["-params_alpha", "12 +* x", "Unexpected"]),
    ("unknown_variable", ["-init_a", "4 + w"], ["-init_a", "Unexpected token"]),
    ("bad_perturbation", ["-params_alpha", "12 +- lots"], ["-params_alpha", "bad perturbation"]),
    ("missing_png", ["-params_alpha", 'png("nope.png", 10, 14)'], ["-params_alpha", "nope.png"]),
    ("missing_deck", ["no_such_deck.yaml"], ["no_such_deck.yaml", "no such file"]),
    ("unstable_dt", ["-dt", "2"], ["-dt", "stability bound dt <= 1", "-force_dt"]),
    ("unknown_model", ["-model", "turning"], ["-model", "turning", "did you mean turing"]),
    ("unknown_bc", ["-grid_bc", "peridic"], ["-grid_bc", "peridic", "periodic, neumann, dirichlet"]),
    ("grid_one_value", ["-grid_n", "256"], ["-grid_n", "expected 2 to 3"]),
    ("grid_too_small", ["-grid_n", "2,2"], ["-grid_n", "[3,"]),
    ("grid_not_int", ["-grid_n", "64,abc"], ["-grid_n", "abc", "not an integer"]),
    ("stencil_3d", ["-grid_n", "16,16,16", "-stencil", "9pt"], ["-stencil", "9pt", "allowed 7pt"]),
    ("stencil_unequal_h", ["-stencil", "9pt", "-grid_L", "256,128"], ["-stencil", "equal spacing"]),
    ("png_species", ["-png_species", "c"], ["-png_species", "c", "allowed a, b"]),
    ("bool", ["-clamp", "maybe"], ["-clamp", "maybe", "true or false"]),
    ("param_of_other_model", ["-params_F", "0.03"], ["-params_F", "unknown option", "F is a parameter of gray_scott"]),
    ("diverged", ["-clamp", "false", "-params_s", "5", "-steps", "3000", "-png_every", "0"],
     ["became", "by step", "reduce -dt"]),
    ("split_ordering", ["-integrator", "split", "-split_ordering", "lei"], ["-split_ordering", "lei", "did you mean lie"]),
    ("split_reaction", ["-integrator", "split", "-split_reaction", "rk3"], ["-split_reaction", "rk3", "allowed euler"]),
    ("bad_pc_type", ["-integrator", "split", "-diffusion_pc_type", "nonsense"], ["-diffusion_pc_type nonsense: unknown PC type"]),
    ("ksp_diverged", ["-grid_n", "64,64", "-integrator", "split", "-dt", "10", "-diffusion_ksp_max_it", "1", "-steps", "3"],
     ["diffusion solve of species", "DIVERGED_ITS", "after 1 iterations", "at step 1"]),
    ("newton_failed", ["-grid_n", "64,64", "-integrator", "split", "-dt", "1000", "-split_newton_max_it", "1",
                       "-split_newton_tol", "1e-14", "-steps", "3"],
     ["reaction solve failed at cell", "residual", "Newton iterations"]),
    ("explicit_dt_suggests_split", ["-dt", "5"], ["-dt 5", "-integrator split"]),
    ("sequence_not_divisible", ["-sequence_levels", "3", "-sequence_steps", "10,10", "-grid_n", "250,256"],
     ["-grid_n 250", "multiple of 4"]),
    ("sequence_steps_missing", ["-sequence_levels", "2"], ["-sequence_steps", "expected 1"]),
    ("sequence_levels_range", ["-sequence_levels", "9"], ["-sequence_levels", "allowed [1, 8]"]),
    ("sequence_dt_checked_on_finest", ["-sequence_levels", "2", "-sequence_steps", "10", "-dt", "3"],
     ["-dt 3", "stability bound dt <= 1"]),
    ("deck_not_first", ["-steps", "10", "turing_spots.yaml"], ["turing_spots.yaml", "must be the first argument"]),
    ("int_overflow", ["-steps", "4294967296"], ["-steps", "4294967296", "out of range"]),
    ("diffusion_inf", ["-D_a", "inf"], ["-D_a", "inf", "out of range"]),
    ("ts_dt_refused", ["-integrator", "ts", "-ts_dt", "0.1"], ["-ts_dt", "use -dt"]),
]




@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_bad_input(case, ranks, workdir):
    _, args, needles = case
    out = workdir / "out"
    out.mkdir()
    sentinel = out / "a_final.png"
    sentinel.write_text("previous result")
    proc = run(args + ["-output_dir", str(out), "-steps", "10"] if "-steps" not in args else args + ["-output_dir", str(out)],
               cwd=workdir, ranks=ranks, timeout=120)
    assert proc.returncode != 0, proc.stdout
    lines = error_lines(proc)
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("morphogen: error: "), lines[0]
    for n in needles:
        assert n in lines[0], lines[0]
    if case[0] not in ("diverged", "ksp_diverged", "newton_failed"):
        assert sorted(os.listdir(out)) == ["a_final.png"]
    assert sentinel.read_text() == "previous result"


def test_invalid_yaml_deck(workdir):
    deck = workdir / "bad.yaml"
    deck.write_text("model: turing\ngrid: [unclosed\n")
    proc = run([str(deck)], cwd=workdir)
    assert proc.returncode != 0
    lines = error_lines(proc)
    assert len(lines) == 1 and "bad.yaml" in lines[0] and "YAML" in lines[0], proc.stderr


def test_misspelt_deck_key(workdir):
    deck = workdir / "typo.yaml"
    deck.write_text("model: turing\ngrid:\n  n: 32,32\nparams:\n  alpah: 12\nsteps: 10\n")
    proc = run([str(deck), "-output_dir", str(workdir / "o")], cwd=workdir)
    assert proc.returncode != 0
    lines = error_lines(proc)
    assert len(lines) == 1 and "-params_alpah" in lines[0] and "did you mean -params_alpha" in lines[0], proc.stderr
    assert not (workdir / "o").exists()


def test_unwritable_output_dir(workdir):
    blocker = workdir / "file"
    blocker.write_text("x")
    proc = run(["-grid_n", "32,32", "-steps", "2", "-output_dir", str(blocker / "sub")], cwd=workdir)
    assert proc.returncode != 0
    lines = error_lines(proc)
    assert len(lines) == 1 and "-output_dir" in lines[0], proc.stderr


def test_force_dt_runs(workdir):
    proc = run(["-grid_n", "32,32", "-dt", "1.2", "-force_dt", "-steps", "5", "-output_dir", str(workdir / "o")], cwd=workdir)
    assert proc.returncode == 0, proc.stderr


def test_grid_too_small_for_ranks(workdir):
    proc = run(["-grid_n", "3,3", "-steps", "2", "-output_dir", str(workdir / "o")], cwd=workdir, ranks=8)
    assert proc.returncode != 0
    lines = error_lines(proc)
    assert len(lines) == 1 and "-grid_n 3,3: cannot be split over 8 ranks" in lines[0], proc.stderr
    assert not (workdir / "o").exists()


def test_petsc_options_read_later_are_not_unknown(workdir):
    """Options that a PETSc object reads at its first solve (after the unused-option check)
    are accepted, e.g. -diffusion_ksp_converged_reason."""
    proc = run(["-grid_n", "32,32", "-integrator", "split", "-dt", "5", "-steps", "2",
                "-diffusion_ksp_converged_reason", "-output_dir", str(workdir / "o")], cwd=workdir)
    assert proc.returncode == 0, proc.stderr
    assert "Linear diffusion_ solve converged" in proc.stdout

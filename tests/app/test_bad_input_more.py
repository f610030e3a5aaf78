"""More bad input (found by fuzzing the CLI): each case exits non-zero within the timeout, prints
exactly one error line naming the option and what is allowed, and leaves an existing output
directory untouched; on 1 and 2 ranks. Plus solver options that used to stop with a PETSc trace
and now run (-*_ksp_type preonly with a direct PC)."""
import os

import pytest
from conftest import error_lines, run

GRID = ["-grid_n", "16,16", "-steps", "2"]
# A passive dye in a unit box: the advection and fluid cases.
DYE = ["-model", "custom", "-species", "dye", "-rate_dye", "0", "-D_dye", "0", "-grid_L", "1",
       "-grid_bc", "neumann", "-init_dye", "x", "-advect", "dye", "-dt", "0.01"]
CAVITY = DYE + ["-fluid", "cavity"]
CAVITY_PERIODIC = [a if a != "neumann" else "periodic" for a in DYE]
OBSTACLE = CAVITY + ["-fluid_obstacle", "disk(0.5, 0.5, 0.2)"]

CASES = [
    # (id, args, substrings the one-line error must contain)
    ("stray_word", ["-dt", "0.1", "junk"], ["'junk' after -dt 0.1", "not an option name"]),
    ("lone_dash", ["-"], ["'-'", "not an option name"]),
    ("split_value", ["-init_a", "4", "+", "x"], ["'+' after -init_a 4", "quote a value"]),
    ("courant_overflow", DYE + ["-velocity_x", "1e300"],
     ["-dt 0.01", "Courant number max|u_x| dt/hx = 1.6e+299", "widest advection halo (64 cells)"]),
    ("obstacle_uses_t", CAVITY + ["-fluid_obstacle", "t > 1"],
     ["-fluid_obstacle t > 1", "cannot depend on t"]),
    ("obstacle_everywhere", CAVITY + ["-fluid_obstacle", "1"],
     ["-fluid_obstacle 1", "covers every cell"]),
    ("rate_assignment", ["-model", "custom", "-species", "a", "-rate_a", "a = 2"],
     ["-rate_a a = 2", "assignment", "compare with =="]),
    ("rate_list", ["-model", "custom", "-species", "a", "-rate_a", "a, 2"],
     ["-rate_a a, 2", "comma-separated list"]),
    ("jac_assignment", ["-model", "custom", "-species", "a", "-rate_a", "0 - a", "-jac_a_a", "a=1"],
     ["-jac_a_a a=1", "assignment"]),
    ("output_name_long", ["-output_name", "x" * 300], ["-output_name", "300 characters", "at most 200"]),
    ("png_species_twice", ["-png_species", "a,a"], ["-png_species", "a given twice"]),
    ("ksp_rtol_above_1", ["-integrator", "split", "-diffusion_ksp_rtol", "2"],
     ["-diffusion_ksp_rtol 2", "allowed [0, 1)"]),
    ("ksp_rtol_nan", ["-integrator", "split", "-diffusion_ksp_rtol", "nan"],
     ["-diffusion_ksp_rtol nan", "allowed [0, 1)"]),
    ("mg_levels_zero", ["-integrator", "split", "-diffusion_pc_type", "mg", "-diffusion_pc_mg_levels", "0"],
     ["-diffusion_pc_mg_levels 0", "allowed an integer >= 1"]),
    ("mg_without_galerkin", ["-integrator", "split", "-diffusion_pc_type", "mg", "-diffusion_pc_mg_levels", "3"],
     ["-diffusion_ksp_*/-diffusion_pc_* options", "add -diffusion_pc_mg_galerkin both"]),
    ("ts_mg_without_galerkin", ["-integrator", "ts", "-pc_type", "mg", "-pc_mg_levels", "3"],
     ["-ksp_*/-pc_* options", "add -pc_mg_galerkin both"]),
    ("ts_rtol_negative", ["-integrator", "ts", "-ts_rtol", "-1"], ["-ts_rtol -1", "allowed a finite number >= 0"]),
    ("fluid_mg_levels", OBSTACLE + ["-fluid_pc_type", "mg", "-fluid_pc_mg_levels", "3"],
     ["-fluid cavity pressure solve", "-fluid_ksp_*/-fluid_pc_* options"]),
    ("fluid_visc_mg_levels", OBSTACLE + ["-fluid_visc_pc_type", "mg", "-fluid_visc_pc_mg_levels", "3"],
     ["-fluid cavity viscosity solve", "-fluid_visc_ksp_*/-fluid_visc_pc_* options"]),
    ("fluid_ksp_rtol_nan", CAVITY + ["-fluid_ksp_rtol", "nan"], ["-fluid_ksp_rtol nan", "allowed [0, 1)"]),
    ("hex_real", ["-grid_L", "0x10"], ["-grid_L 0x10", "not a number"]),
    ("hex_in_list", ["-png_range_a", "0x10,20"], ["-png_range_a 0x10", "not a number"]),
    ("trailing_comma", ["-grid_n", "16,16,"], ["-grid_n", "not an integer"]),
    ("trailing_comma_bc", ["-grid_bc", "periodic,"], ["-grid_bc"]),
    # An explicit -diffusion_solver spectral that cannot be honoured (used to fall back to KSP).
    ("spectral_timed_D", ["-integrator", "split", "-diffusion_solver", "spectral",
                          "-D_a", "1 + 0.1*t"],
     ["-diffusion_solver spectral: species a", "its coefficients use t (-D_a",
      "allowed here: ksp or auto"]),
    ("spectral_polar", ["-integrator", "split", "-diffusion_solver", "spectral",
                        "-diffusion_a", "polar"],
     ["-diffusion_solver spectral: species a", "follow the state (-diffusion_a polar",
      "allowed here: ksp or auto"]),
    ("spectral_pinned", ["-integrator", "split", "-diffusion_solver", "spectral",
                         "-pin_a", "j < 2"],
     ["-diffusion_solver spectral: species a", "allowed here: ksp or auto"]),
    ("spectral_varying_D", ["-integrator", "split", "-diffusion_solver", "spectral",
                            "-D_b", "1 + x/16"],
     ["-diffusion_solver spectral: species b", "allowed here: ksp or auto"]),
    # Wall-bounded flows on a periodic axis.
    ("cavity_periodic", CAVITY_PERIODIC + ["-fluid", "cavity"],
     ["-fluid cavity with -grid_bc periodic,periodic", "neither axis may be periodic",
      "allowed: -grid_bc neumann or dirichlet on both axes"]),
    ("channel_periodic_y", CAVITY_PERIODIC + ["-grid_bc", "neumann,periodic", "-fluid", "channel"],
     ["-fluid channel with -grid_bc neumann,periodic", "neither axis may be periodic"]),
    # Log files that cannot be written: refused before the run, not in PetscFinalize.
    ("log_view_no_dir", ["-log_view", ":/nonexistent/dir/file.txt"],
     ["-log_view :/nonexistent/dir/file.txt", "directory /nonexistent/dir does not exist",
      "allowed: -log_view [ascii][:FILE[:FORMAT]]"]),
    ("log_view_bad_format", ["-log_view", ":log.txt:bogus"],
     ["-log_view :log.txt:bogus", "format 'bogus'", "ascii_info_detail"]),
    ("log_view_type", ["-log_view", "log.txt"],
     ["-log_view log.txt", "viewer type 'log.txt'", "allowed: -log_view [ascii]"]),
    ("log_trace_no_dir", ["-log_trace", "/nonexistent/dir/trace"],
     ["-log_trace /nonexistent/dir/trace", "does not exist", "allowed: -log_trace [PREFIX]"]),
]


# Every case on 1 rank; on 2 ranks those whose check involves parallel code (reductions over
# the grid, PETSc's parallel solvers, MPI-IO file names), to keep the suite short.
TWO_RANKS = {"courant_overflow", "obstacle_everywhere", "output_name_long", "mg_without_galerkin",
             "ts_mg_without_galerkin", "fluid_mg_levels", "stray_word", "spectral_timed_D",
             "cavity_periodic", "log_view_no_dir", "log_trace_no_dir"}
RUNS = [(c, 1) for c in CASES] + [(c, 2) for c in CASES if c[0] in TWO_RANKS]


@pytest.mark.parametrize("case,ranks", RUNS, ids=[f"{c[0]}-{r}" for c, r in RUNS])
def test_bad_input_more(case, ranks, workdir):
    _, args, needles = case
    out = workdir / "out"
    out.mkdir()
    sentinel = out / "a_final.png"
    sentinel.write_text("previous result")
    proc = run(GRID + args + ["-output_dir", str(out)], cwd=workdir, ranks=ranks, timeout=60)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    lines = error_lines(proc)
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("morphogen: error: "), lines[0]
    assert "PETSC ERROR" not in proc.stderr + proc.stdout
    for n in needles:
        assert n in lines[0], lines[0]
    assert sorted(os.listdir(out)) == ["a_final.png"]
    assert sentinel.read_text() == "previous result"


# A direct solve (-*_ksp_type preonly -*_pc_type lu) used to stop with PETSc's "Running KSP of
# preonly doesn't make sense with nonzero initial guess"; the result must equal the default
# iterative solve to its tolerance.
@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("what", ["diffusion", "fluid"])
def test_preonly_direct_solve_runs(what, ranks, workdir):
    base = (GRID + ["-integrator", "split", "-dt", "5", "-init_a", "4 + sin(2*pi*x/Lx)"]
            if what == "diffusion" else GRID + OBSTACLE)
    extra = (["-diffusion_ksp_type", "preonly", "-diffusion_pc_type", "lu"] if what == "diffusion"
             else ["-fluid_ksp_type", "preonly", "-fluid_pc_type", "lu"])
    h5py = pytest.importorskip("h5py")
    finals = []
    for tag, opts in (("default", []), ("direct", extra)):
        out = workdir / tag
        proc = run(base + opts + ["-output_dir", str(out), "-summary", "false"], cwd=workdir,
                   ranks=ranks, timeout=60)
        assert proc.returncode == 0, proc.stderr
        assert "PETSC ERROR" not in proc.stderr
        with h5py.File(out / "checkpoint_0000002.vtkhdf", "r") as f:
            name = "a" if what == "diffusion" else "velocity_x"
            finals.append(f["VTKHDF/PointData/" + name][()].ravel())
    scale = max(1.0, float(abs(finals[0]).max()))
    assert float(abs(finals[0] - finals[1]).max()) <= 1e-6 * scale


# -diffusion_solver auto with a D using t: KSP for that species, chosen (and said) at setup;
# the other species keeps the spectral solve.
def test_auto_timed_diffusion_uses_ksp(workdir):
    proc = run(GRID + ["-integrator", "split", "-D_a", "1 + 0.1*t", "-output_dir",
                       str(workdir / "out"), "-summary", "false"], cwd=workdir, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "diffusion solve of a: ksp (its coefficients use t" in proc.stdout, proc.stdout
    assert "diffusion solve of b: spectral" in proc.stdout, proc.stdout
    assert "its matrix changed" not in proc.stdout


# A writable -log_view file is written as before.
def test_log_view_file_written(workdir):
    proc = run(GRID + ["-log_view", ":lv.txt:ascii_info_detail", "-output_dir",
                       str(workdir / "out"), "-summary", "false"], cwd=workdir, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert (workdir / "lv.txt").stat().st_size > 1000

"""Diffusion coefficients and Dirichlet values using t from the command line: a run with both
reports them in its term list and finishes; a coefficient that leaves its range at a later t,
or an explicit -dt that the coefficients outgrow, stops the run with one error line naming the
option and t (exit non-zero). What stays unsupported at setup (t with -diffusion polar|shaped,
-stencil 9pt) is covered by tests/operators/test_tensor_bad_input.py. Run on 1 and 2 ranks."""
import pytest
from conftest import error_lines, run

BASE = ["-model", "gray_scott", "-grid_n", "16,16", "-grid_L", "1", "-png_every", "0",
        "-summary", "false", "-checkpoint_final", "false"]


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("integrator", ["explicit", "split", "ts"])
def test_timed_run_finishes(integrator, ranks, workdir):
    proc = run(BASE + ["-integrator", integrator, "-D_b", "1e-3*(1 + 0.5*sin(t))",
                       "-D_a", "5e-4 + 1e-4*x*t", "-grid_bc", "dirichlet,neumann",
                       "-dirichlet_b", "1 - 0.1*sin(t)", "-dt", "0.5", "-steps", "4",
                       "-output_dir", str(workdir / "o")], cwd=workdir, ranks=ranks)
    assert proc.returncode == 0, proc.stderr
    assert "time-dependent" in proc.stdout, proc.stdout


CASES = [
    # (id, args, substrings the one-line error must contain)
    ("map_negative_later", ["-D_b", "1e-3*(1 - t)", "-dt", "0.5"],
     ["-D_b", "1e-3*(1 - t)", "at t = 1.5", "outside the allowed range [0,"]),
    ("tensor_indefinite_later", ["-diffusion_b", "tensor", "-tensor_l1", "1 - t", "-D_b", "1e-3",
                                 "-dt", "0.5"],
     ["-tensor_theta..tensor_l2", "positive definite", "at t = 1", "tensor_l1 = 0"]),
    ("explicit_bound_later", ["-D_b", "1e-3*(1 + 10*t)", "-dt", "0.1"],
     ["-dt 0.1: at t = ", "time-dependent diffusion needs dt <=", "-force_dt"]),
    ("dirichlet_bad_expression_later", ["-grid_bc", "dirichlet", "-dirichlet_b", "sqrt(0.5 - t)",
                                        "-dt", "0.5", "-integrator", "split"],
     ["-dirichlet_b", "sqrt(0.5 - t)"]),
]


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_timed_value_fails_later(case, ranks, workdir):
    _, args, needles = case
    proc = run(BASE + args + ["-steps", "10", "-output_dir", str(workdir / "o")], cwd=workdir,
               ranks=ranks)
    assert proc.returncode != 0, proc.stdout
    lines = error_lines(proc)
    assert len(lines) == 1, proc.stderr
    for n in needles:
        assert n in lines[0], lines[0]

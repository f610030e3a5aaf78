"""Bad diffusion-tensor input (-diffusion tensor, -tensor_*, -D_S maps) never runs: each case
exits non-zero, prints exactly one error line that names the option (and, for values that are
wrong somewhere on the grid, the cell), and leaves the output directory as it was (an existing
one untouched, a missing one not created). Run on 1 and 2 ranks. A species' tensor keys fall back
per key (-tensor_S_NAME, else -tensor_NAME, else the default); mixing components (xx, xy, ...) and
principal values (theta, l1, ...) for one species, own or shared keys alike, is an error that
names both keys. A valid tensor run records its tensor options in options_used.yaml, which
reproduces it."""
import os
import subprocess

import pytest

EXE = os.environ.get("MORPHOGEN_EXE", os.path.join(os.path.dirname(__file__), "../../build/morphogen"))
MPIEXEC = os.environ.get("MORPHOGEN_MPIEXEC", "mpiexec")

GRID = ["-grid_n", "32,32", "-steps", "5"]

CASES = [
    # (id, args, substrings the one-line error must contain)
    ("principal_not_pd", GRID + ["-diffusion", "tensor", "-tensor_l2", "x-5"],
     ["-tensor_theta..tensor_l2", "positive definite", "at cell (0,0)", "tensor_l2 = -4.5"]),
    ("components_det_negative", GRID + ["-diffusion", "tensor", "-tensor_xx", "1", "-tensor_xy", "x/10",
                                        "-tensor_yy", "1"],
     ["-tensor_xx..tensor_yy", "positive definite", "at cell (10,0)", "tensor_xy = 1.05"]),
    ("components_constant_indefinite", GRID + ["-diffusion_b", "tensor", "-tensor_xx", "1", "-tensor_xy", "2",
                                               "-tensor_yy", "1"],
     ["-tensor_xx..tensor_yy", "diffusion tensor of b", "at cell (0,0)"]),
    # theta is not set for a: it falls back to the shared -tensor_theta (default 0), named so.
    ("per_species_not_pd", GRID + ["-diffusion_a", "tensor", "-tensor_a_l1", "3", "-tensor_a_l2", "-1"],
     ["-tensor_theta..tensor_a_l2", "diffusion tensor of a", "at cell (0,0)", "tensor_theta = 0",
      "tensor_a_l2 = -1"]),
    ("tensor_3d_not_pd", ["-grid_n", "8,8,6", "-steps", "5", "-diffusion", "tensor", "-tensor_l3", "z-2"],
     ["-tensor_theta..tensor_l3", "positive definite", "at cell (0,0,0)"]),
    ("tensor_times_negative_D", GRID + ["-diffusion", "tensor", "-D_a", "x-5"],
     ["-D_a", "D_a >= 0", "at cell (0,0)"]),
    ("tensor_nan", GRID + ["-diffusion", "tensor", "-tensor_l1", "sqrt(x-5)"],
     ["-tensor_l1", "nan", "at cell (0,0"]),
    ("stencil_9pt_tensor", GRID + ["-stencil", "9pt", "-diffusion", "tensor"],
     ["-stencil 9pt", "-diffusion_a tensor", "use -stencil 5pt"]),
    ("stencil_9pt_tensor_one_species", GRID + ["-stencil", "9pt", "-diffusion_b", "tensor"],
     ["-stencil 9pt", "-diffusion_b tensor"]),
    ("stencil_9pt_diffusion_map", GRID + ["-stencil", "9pt", "-D_a", "0.0625*(1 + 0.1*x/Lx)"],
     ["-stencil 9pt", "-D_a", "5pt"]),
    ("unknown_scheme", GRID + ["-diffusion", "tensor", "-tensor_scheme", "third_order"],
     ["-tensor_scheme", "third_order", "allowed second_order, first_order"]),
    ("unknown_diffusion_kind", GRID + ["-diffusion", "anisotropic"],
     ["-diffusion", "anisotropic", "iso", "tensor"]),
    ("tensor_option_without_tensor", GRID + ["-tensor_l1", "2"],
     ["-tensor_l1", "unknown option"]),
    ("scheme_without_tensor", GRID + ["-tensor_scheme", "first_order"],
     ["-tensor_scheme", "unknown option"]),
    ("tensor_option_other_species_iso", GRID + ["-diffusion_a", "tensor", "-tensor_b_l1", "2"],
     ["-tensor_b_l1", "unknown option"]),
    ("tensor_option_unknown_species", GRID + ["-diffusion", "tensor", "-tensor_c_l1", "2"],
     ["-tensor_c_l1", "unknown option"]),
    ("tensor_3d_key_in_2d", GRID + ["-diffusion", "tensor", "-tensor_phi", "0.3"],
     ["-tensor_phi", "unknown option"]),
    ("components_and_principal", GRID + ["-diffusion", "tensor", "-tensor_xx", "2", "-tensor_theta", "0.3"],
     ["-tensor_xx and -tensor_theta", "tensor of a", "not both"]),
    ("components_and_principal_per_species", GRID + ["-diffusion_a", "tensor", "-tensor_a_xy", "0.1",
                                                     "-tensor_a_l1", "2"],
     ["-tensor_a_xy and -tensor_a_l1", "tensor of a", "not both"]),
    # Own components with a shared principal key (which every tensor species falls back to) ...
    ("own_components_shared_principal", GRID + ["-diffusion", "tensor", "-tensor_a_xx", "2",
                                                "-tensor_theta", "0.3"],
     ["-tensor_a_xx and -tensor_theta", "tensor of a", "not both"]),
    # ... own principal values with a shared component ...
    ("own_principal_shared_components", GRID + ["-diffusion_a", "tensor", "-tensor_a_l1", "2",
                                                "-tensor_xy", "0.1"],
     ["-tensor_xy and -tensor_a_l1", "tensor of a", "not both"]),
    # ... and for the second species only (a's principal keys are fine).
    ("second_species_mixes", GRID + ["-diffusion", "tensor", "-tensor_theta", "0.3",
                                     "-tensor_b_xx", "2"],
     ["-tensor_b_xx and -tensor_theta", "tensor of b", "not both"]),
    ("dt_above_tensor_bound", GRID + ["-diffusion", "tensor", "-tensor_l1", "4", "-dt", "1"],
     ["-dt 1", "stability bound dt <= 0.25", "lambda_max = 1", "-integrator split"]),
    ("dt_above_map_bound", GRID + ["-D_a", "0.0625 + x/8", "-dt", "0.5"],
     ["-dt 0.5", "stability bound", "lambda_max", "-force_dt"]),
    # Tensors and maps may use t (evaluated per step); what is still refused at setup:
    ("tensor_time_dependent_not_pd_at_start", GRID + ["-diffusion", "tensor", "-tensor_l1",
                                                      "sin(t) - 0.5"],
     ["-tensor_theta..tensor_l2", "positive definite", "at cell (0,0) at t = 0", "tensor_l1 = -0.5"]),
    ("diffusion_time_dependent_polar", GRID + ["-diffusion_a", "polar", "-D_a", "0.06*(1 + t)"],
     ["-D_a", "0.06*(1 + t)", "not supported with -diffusion_a polar", "allowed with iso and tensor"]),
    ("diffusion_time_dependent_9pt", GRID + ["-stencil", "9pt", "-D_a", "0.06*(1 + t)"],
     ["-stencil 9pt", "-D_a", "needs -stencil 5pt"]),
]


def run(args, cwd, ranks=1, timeout=120):
    cmd = [EXE] + list(args)
    if ranks > 1:
        cmd = [MPIEXEC, "--oversubscribe", "-n", str(ranks)] + cmd
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout, env=env)


def error_lines(proc):
    """Non-empty stderr lines of morphogen itself (mpiexec appends its own banner, framed by
    dashed lines, when a rank exits non-zero)."""
    lines = []
    for l in proc.stderr.splitlines():
        if l.startswith("-----"):
            break
        if l.strip():
            lines.append(l)
    return lines


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_tensor_bad_input(case, ranks, tmp_path):
    _, args, needles = case
    # An existing output directory stays untouched ...
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
    assert "step 1/" not in proc.stdout


@pytest.mark.parametrize("case", [c for c in CASES if c[0] in (
    "principal_not_pd", "stencil_9pt_tensor", "unknown_scheme", "tensor_option_without_tensor",
    "dt_above_tensor_bound", "tensor_time_dependent")], ids=lambda c: c[0])
def test_tensor_bad_input_creates_no_output_dir(case, tmp_path):
    # ... and a missing one is not created.
    _, args, needles = case
    out = tmp_path / "new_out"
    proc = run(args + ["-output_dir", str(out)], cwd=tmp_path)
    assert proc.returncode != 0, proc.stdout
    lines = error_lines(proc)
    assert len(lines) == 1 and all(n in lines[0] for n in needles), proc.stderr
    assert not out.exists()


def test_valid_tensor_run_records_options_and_reproduces(tmp_path):
    out = tmp_path / "out"
    args = GRID + ["-diffusion_a", "tensor", "-tensor_theta", "0.6", "-tensor_l1", "3",
                   "-tensor_l2", "0.5 + 0.01*x", "-tensor_scheme", "second_order",
                   "-D_b", "0.25 + 0.01*y", "-init_a", "4 +- 1%", "-dt", "0.1",
                   "-output_dir", str(out)]
    proc = run(args, cwd=tmp_path, ranks=2)
    assert proc.returncode == 0, proc.stderr
    used = (out / "options_used.yaml").read_text()
    for key in ('diffusion_a: "tensor"', 'tensor_theta: "0.6"', 'tensor_l1: "3"',
                'tensor_l2: "0.5 + 0.01*x"', 'tensor_scheme: "second_order"', 'D_b: "0.25 + 0.01*y"'):
        assert key in used, used
    again = tmp_path / "again"
    proc = run([str(out / "options_used.yaml"), "-output_dir", str(again)], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (again / "a_final.png").read_bytes() == (out / "a_final.png").read_bytes()


def test_tensor_keys_fall_back_per_key(tmp_path):
    # b's unset theta falls back to the shared -tensor_theta; a's l1 to the shared -tensor_l1:
    # the same run as with every key given per species, and not the run with b's theta default.
    common = ["-grid_n", "32,32", "-steps", "20", "-diffusion", "tensor", "-init_a", "4 +- 1%",
              "-init_b", "4 +- 1%", "-dt", "0.1"]
    runs = {
        "fallback": ["-tensor_theta", "0.5", "-tensor_l1", "2", "-tensor_b_l1", "3", "-tensor_b_l2", "0.8"],
        "explicit": ["-tensor_a_theta", "0.5", "-tensor_a_l1", "2", "-tensor_b_theta", "0.5",
                     "-tensor_b_l1", "3", "-tensor_b_l2", "0.8"],
        "b_theta_default": ["-tensor_a_theta", "0.5", "-tensor_a_l1", "2", "-tensor_b_l1", "3",
                            "-tensor_b_l2", "0.8"],
    }
    for name, keys in runs.items():
        proc = run(common + keys + ["-output_dir", str(tmp_path / name)], cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
    png = {(name, s): (tmp_path / name / f"{s}_final.png").read_bytes() for name in runs for s in "ab"}
    for s in "ab":
        assert png[("fallback", s)] == png[("explicit", s)], s
    assert png[("fallback", "b")] != png[("b_theta_default", "b")]
    used = (tmp_path / "fallback" / "options_used.yaml").read_text()
    for key in ('tensor_theta: "0.5"', 'tensor_l1: "2"', 'tensor_b_l1: "3"', 'tensor_b_l2: "0.8"'):
        assert key in used, used

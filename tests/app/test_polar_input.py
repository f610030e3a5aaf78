"""Bad input for solution-dependent diffusion (-diffusion_S polar|shaped, -polar_*, -shaped_*)
never runs: each case exits non-zero with exactly one error line naming the option, its value and
what is allowed, and leaves an existing output directory untouched. A valid polar run records its
options in options_used.yaml, which reproduces it bitwise, and -help lists the options."""
import os

import pytest
from conftest import error_lines, run


GRID = ["-grid_n", "32,32", "-steps", "5"]
POLAR = GRID + ["-diffusion", "polar"]
SHAPED = GRID + ["-diffusion", "shaped", "-tensor_l1", "1.5", "-tensor_l2", "0.5"]

CASES = [
    # (id, args, substrings the one-line error must contain)
    ("unknown_form", POLAR + ["-polar_form", "star"],
     ["-polar_form", "star", "allowed cosine, witkin_kass"]),
    ("lobes_zero", POLAR + ["-polar_lobes", "0"], ["-polar_lobes", "0", "[1, 16]"]),
    ("lobes_too_many", POLAR + ["-polar_lobes", "17"], ["-polar_lobes", "17"]),
    ("speeds_count", POLAR + ["-polar_lobes", "3", "-polar_speeds", "1,2"],
     ["-polar_speeds", "2 values", "allowed 1 or 3"]),
    ("speed_negative", POLAR + ["-polar_speeds", "1,-2,1,1"], ["-polar_speeds", "-2", "out of range"]),
    ("speed_not_number", POLAR + ["-polar_speeds", "fast"], ["-polar_speeds", "fast"]),
    ("wk_speeds_count", POLAR + ["-polar_form", "witkin_kass", "-polar_speeds", "1,2,3"],
     ["-polar_speeds", "3 values", "allowed 1 or 2", "(a1,a2)"]),
    ("wk_lobes", POLAR + ["-polar_form", "witkin_kass", "-polar_lobes", "4"],
     ["-polar_lobes", "Witkin-Kass", "four lobes"]),
    ("theta0_time", POLAR + ["-polar_theta0", "0.1*t"], ["-polar_theta0", "0.1*t", "time-dependent"]),
    ("theta0_bad_expr", POLAR + ["-polar_theta0", "x+"], ["-polar_theta0", "x+"]),
    ("polar_3d", ["-grid_n", "8,8,6", "-steps", "2", "-diffusion", "polar"],
     ["-diffusion_a polar", "2-D", "shaped"]),
    ("polar_9pt", POLAR + ["-stencil", "9pt"], ["-stencil 9pt", "5pt"]),
    ("polar_dt_bound", POLAR + ["-polar_speeds", "4", "-dt", "1"],
     ["-dt 1", "stability bound", "-integrator split"]),
    ("polar_key_species_iso", GRID + ["-diffusion_a", "polar", "-polar_b_lobes", "3"],
     ["-polar_b_lobes", "unknown option"]),
    ("polar_key_without_polar", GRID + ["-polar_lobes", "3"], ["-polar_lobes", "unknown option"]),
    ("unknown_kind", GRID + ["-diffusion_a", "polr"], ["-diffusion_a", "polr", "polar", "shaped"]),
    ("shaped_I_too_big", SHAPED + ["-shaped_I", "0.5"],
     ["-shaped_I 0.5", "l1 - I > 0 and l2 - I > 0", "at cell (0,0)", "tensor_l2 = 0.5"]),
    ("shaped_I_negative", SHAPED + ["-shaped_I", "-1"], ["-shaped_I", "-1"]),
    ("shaped_components", GRID + ["-diffusion", "shaped", "-tensor_xx", "1"],
     ["-tensor_xx", "shaped", "principal values"]),
    ("shaped_v_partial", SHAPED + ["-shaped_vx", "1"], ["-shaped_vx/-shaped_vy", "every component"]),
    ("shaped_v_time", SHAPED + ["-shaped_vx", "t", "-shaped_vy", "1"], ["-shaped_vx", "time-dependent"]),
    ("shaped_key_without_shaped", GRID + ["-shaped_I", "0.1"], ["-shaped_I", "unknown option"]),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_polar_bad_input(case, tmp_path):
    _, args, needles = case
    out = tmp_path / "out"
    out.mkdir()
    sentinel = out / "a_final.png"
    sentinel.write_text("previous result")
    proc = run(args + ["-output_dir", str(out)], cwd=tmp_path)
    assert proc.returncode != 0, proc.stdout
    lines = error_lines(proc)
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("morphogen: error: "), lines[0]
    for n in needles:
        assert n in lines[0], lines[0]
    assert sorted(os.listdir(out)) == ["a_final.png"]
    assert sentinel.read_text() == "previous result"


@pytest.mark.parametrize("case", [c for c in CASES if c[0] in ("speeds_count", "shaped_I_too_big")],
                         ids=lambda c: c[0])
def test_polar_bad_input_two_ranks(case, tmp_path):
    _, args, needles = case
    proc = run(args + ["-output_dir", str(tmp_path / "o")], cwd=tmp_path, ranks=2)
    assert proc.returncode != 0
    lines = error_lines(proc)
    assert len(lines) == 1 and all(n in lines[0] for n in needles), proc.stderr


def test_valid_polar_run_records_options_and_reproduces(tmp_path):
    out = tmp_path / "out"
    args = GRID + ["-diffusion_a", "polar", "-polar_lobes", "3", "-polar_speeds", "1,0.5,2",
                   "-polar_theta0", "0.2*x", "-diffusion_b", "shaped", "-tensor_l1", "1.5",
                   "-tensor_l2", "0.5", "-shaped_I", "0.2", "-init_a", "4 +- 1%", "-dt", "0.1",
                   "-output_dir", str(out)]
    proc = run(args, cwd=tmp_path, ranks=2)
    assert proc.returncode == 0, proc.stderr
    assert "polar a(theta), cosine 3 lobes" in proc.stdout
    used = (out / "options_used.yaml").read_text()
    for key in ('diffusion_a: "polar"', 'polar_lobes: "3"', 'polar_speeds: "1,0.5,2"',
                'polar_theta0: "0.2*x"', 'diffusion_b: "shaped"', 'shaped_I: "0.2"'):
        assert key in used, used
    again = tmp_path / "again"
    proc = run([str(out / "options_used.yaml"), "-output_dir", str(again)], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (again / "a_final.png").read_bytes() == (out / "a_final.png").read_bytes()


def test_help_lists_polar_and_shaped(tmp_path):
    proc = run(["-help"], cwd=tmp_path)
    for key in ("-polar_form", "-polar_lobes", "-polar_speeds", "-polar_theta0", "-shaped_I",
                "-shaped_vx", "(iso, tensor, polar, shaped)"):
        assert key in proc.stdout, key

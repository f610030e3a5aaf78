"""FFTW planning of the spectral solves (-fft_planner, -fft_wisdom), end to end on 1 and 2 ranks:
- a run that times its plans (measure) writes them to the wisdom file, and a second run that
  reads them is bitwise identical to it (checkpoint fields), so runs and restarts stay
  reproducible; heuristic plans (estimate) and plans timed without a file agree to 1e-12;
- an unwritable wisdom file is a one-line warning, not a failure;
- an unknown planner is a one-line error naming the option."""
import h5py
import numpy as np
import pytest

from conftest import error_lines, run

BASE = ["-grid_n", "48,40", "-png_every", "0", "-progress_every", "100000", "-integrator",
        "split", "-dt", "2", "-steps", "20", "-summary", "false"]


def fields(path):
    with h5py.File(path, "r") as f:
        g = f["VTKHDF/PointData"]
        return {k: g[k][...] for k in g}


def ok(r):
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r


@pytest.mark.parametrize("np_", [1, 2])
def test_timed_plans_are_kept_and_reused_bitwise(tmp_path, np_):
    wisdom = tmp_path / "cache" / "wisdom"
    opts = BASE + ["-fft_wisdom", str(wisdom)]
    r = ok(run(opts + ["-output_dir", "first"], tmp_path, np_))
    assert "diffusion solve of" in r.stdout and "spectral" in r.stdout
    assert wisdom.exists() and "fftw_wisdom" in wisdom.read_text()
    ok(run(opts + ["-output_dir", "second"], tmp_path, np_))
    ok(run(BASE + ["-fft_planner", "estimate", "-output_dir", "estimate"], tmp_path, np_))
    ok(run(BASE + ["-fft_wisdom", "none", "-output_dir", "nofile"], tmp_path, np_))
    a = fields(tmp_path / "first/checkpoint_0000020.vtkhdf")
    b = fields(tmp_path / "second/checkpoint_0000020.vtkhdf")
    for other in ("estimate", "nofile"):
        c = fields(tmp_path / other / "checkpoint_0000020.vtkhdf")
        for s in a:
            assert np.array_equal(a[s], b[s]), f"{s}: max diff {np.abs(a[s] - b[s]).max()}"
            scale = np.abs(a[s]).max()
            assert np.abs(a[s] - c[s]).max() <= 1e-12 * scale, f"{other} {s}"


def test_unwritable_wisdom_file_is_a_warning(tmp_path):
    r = ok(run(BASE + ["-fft_wisdom", "/proc/no/such/dir/wisdom", "-output_dir", "o"], tmp_path))
    warn = [l for l in r.stderr.splitlines() if l.startswith("morphogen: warning: cannot write")]
    assert len(warn) == 1 and "-fft_wisdom" in warn[0], r.stderr


def test_unknown_planner_is_refused(tmp_path):
    r = run(BASE + ["-fft_planner", "fastest", "-output_dir", "o"], tmp_path)
    assert r.returncode != 0
    lines = error_lines(r)
    assert len(lines) == 1 and "-fft_planner" in lines[0] and "fastest" in lines[0], r.stderr
    assert not (tmp_path / "o").exists()

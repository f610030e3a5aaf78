"""Silent or misleading results, end to end (issue 10):
- every model forms its pattern from its name alone (its embedded default deck), on a reduced
  grid and step count: summary.json classifies every species non-uniform;
- a run that blows up but stays finite stops (exit 1) with species, cell, step and the last
  good checkpoint; the NaN guard before a checkpoint write names the last good checkpoint too;
- a dt beyond the reaction's explicit bound (Jacobian at the initial state) gets one warning;
- NaN survives the clamp (explicit and split integrators) and is caught;
- rejected input found during the run (an expression that fails at a later t) and a directory
  that cannot take new files leave the existing output byte-identical; write failures exit 4."""
import json
import os
import subprocess

import h5py
import numpy as np
import pytest

from conftest import run

QUIET = ["-png_every", "0", "-progress_every", "1000000"]

# model -> options that shrink its default deck (same spacing, fewer cells and steps)
MODELS = {
    "turing": ["-grid_n", "64,64", "-steps", "30000"],
    "gray_scott": ["-grid_n", "64,64", "-grid_L", "0.625", "-steps", "5000"],
    "gray_scott_sims": ["-grid_n", "96,96", "-steps", "3000"],
    "brusselator": ["-grid_n", "64,64", "-grid_L", "96", "-steps", "20000"],
    "gierer_meinhardt": ["-grid_n", "64,64", "-steps", "10000"],
    "meinhardt": ["-grid_n", "64,64", "-steps", "4000"],
    "schnakenberg": ["-grid_n", "64,64", "-steps", "6000"],
    "fitzhugh_nagumo": ["-grid_n", "64,64", "-steps", "1000"],
    "barkley": ["-grid_n", "128,128", "-grid_L", "64", "-steps", "1000"],
    "barkley_turbulent": ["-grid_n", "128,128", "-grid_L", "64", "-steps", "1000"],
    "oregonator": ["-grid_n", "64,64", "-grid_L", "16", "-steps", "5000"],
}


def error_line(r):
    lines = [l for l in r.stderr.splitlines() if l.startswith("morphogen: error")]
    assert len(lines) == 1, r.stdout[-2000:] + r.stderr[-2000:]
    return lines[0]


def snapshot(d):
    """{name: bytes} of every file in directory d (recursively)."""
    out = {}
    for root, _, files in os.walk(d):
        for f in files:
            p = os.path.join(root, f)
            with open(p, "rb") as fh:
                out[os.path.relpath(p, d)] = fh.read()
    return out


def test_every_model_has_a_default_deck():
    from conftest import SOURCE
    text = open(os.path.join(SOURCE, "CMakeLists.txt")).read()
    for model in MODELS:
        assert f" {model}=" in text or f"\n    {model}=" in text, model


@pytest.mark.parametrize("model", sorted(MODELS))
def test_model_forms_its_pattern_from_its_name(model, tmp_path):
    r = run(["-model", model, "-output_dir", "o"] + MODELS[model] + QUIET, tmp_path)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "warning" not in r.stderr, r.stderr
    summary = json.loads((tmp_path / "o/summary.json").read_text())
    assert summary["model"] == model
    classes = {s: c["class"] for s, c in summary["species"].items()}
    assert all(c not in ("uniform", "blowup") for c in classes.values()), classes


def test_finite_blowup_stops_with_the_last_good_checkpoint(tmp_path):
    """Turing at h = 1, dt 0.9 x the diffusion bound and a faster reaction (s = 0.1, still
    within the reaction's own bound 2.5): a checkerboard grows to 5e18 by step 300 and stays
    finite to the end of this run (exit 0 before); the guard stops it at the 1e10 bound."""
    r = run(["-grid_n", "64,64", "-dt", "0.9", "-params_s", "0.1", "-steps", "400",
             "-checkpoint_every", "100",
             "-output_dir", "o"] + QUIET, tmp_path, 2)
    assert r.returncode == 1, r.stdout[-2000:] + r.stderr[-2000:]
    line = error_line(r)
    assert "over the blow-up bound 1e10" in line and "at cell (" in line and "by step" in line
    assert "last good checkpoint: o/checkpoint_" in line
    good = line.split("last good checkpoint: ")[1].strip()
    with h5py.File(tmp_path / good, "r") as f:
        for v in f["VTKHDF/PointData"].values():
            assert np.all(np.abs(v[...]) <= 1e10)


def test_nan_found_at_a_checkpoint_write_names_the_last_good_one(tmp_path):
    """The NaN check runs rarely (every 100000 steps) but every checkpoint write checks first."""
    r = run(["-grid_n", "48,40", "-dt", "4", "-force_dt", "-clamp", "false", "-steps", "2000",
             "-checkpoint_every", "5", "-nan_check_every", "100000", "-output_dir", "o"] + QUIET,
            tmp_path)
    assert r.returncode == 1
    line = error_line(r)
    assert "the run diverged" in line and "last good checkpoint: o/checkpoint_" in line, line


def test_restarted_run_names_its_restart_checkpoint(tmp_path):
    ok = run(["-grid_n", "48,40", "-steps", "10", "-output_dir", "o"] + QUIET, tmp_path)
    assert ok.returncode == 0, ok.stderr
    r = run(["-grid_n", "48,40", "-steps", "2000", "-dt", "4", "-force_dt", "-clamp", "false",
             "-restart", "latest", "-output_dir", "o"] + QUIET, tmp_path)
    assert r.returncode == 1
    assert "last good checkpoint: o/checkpoint_0000010.vtkhdf" in error_line(r)


def test_stiff_reaction_warns(tmp_path):
    """Barkley's deck: the diffusion bound at h = 0.5 is 0.0625, the reaction's 0.0294
    (eigenvalue -68 in the refractory strip A = 0, B = 1): dt 0.05 passes the diffusion check
    but gets the warning; the deck's 0.02 does not."""
    args = ["-model", "barkley", "-grid_n", "64,64", "-grid_L", "32", "-steps", "2",
            "-output_dir", "o"] + QUIET
    r = run(args + ["-dt", "0.05"], tmp_path)
    warnings = [l for l in r.stderr.splitlines() if "warning" in l]
    assert len(warnings) == 1, r.stderr
    assert "reaction's explicit stability bound 0.0294" in warnings[0] and "-dt 0.0" in warnings[0]
    r = run(args, tmp_path)
    assert r.returncode == 0 and "warning" not in r.stderr, r.stderr
    r = run(args + ["-dt", "0.05", "-integrator", "split"], tmp_path)
    assert "warning" not in r.stderr, r.stderr


@pytest.mark.parametrize("scheme", [[], ["-integrator", "split", "-dt", "1", "-split_ordering", "lie",
                                         "-split_reaction", "euler"]])
def test_nan_survives_the_clamp(scheme, tmp_path):
    """A checkpoint with one NaN cell, restarted under the clamped turing model: the clamp used
    to turn the NaN into 0 and the run ended with exit 0."""
    base = ["-grid_n", "32,32", "-output_dir", "o", "-checkpoint_keep", "10"] + QUIET
    assert run(base + ["-steps", "10"], tmp_path).returncode == 0
    ck = tmp_path / "o/checkpoint_0000010.vtkhdf"
    with h5py.File(ck, "r+") as f:
        a = f["VTKHDF/PointData/a"]
        v = a[...]
        v[0, 5, 7] = np.nan
        a[...] = v
    r = run(base + ["-steps", "30", "-restart", str(ck), "-nan_check_every", "5"] + scheme, tmp_path)
    assert r.returncode == 1, r.stdout[-1000:] + r.stderr[-1000:]
    assert "nan" in error_line(r).lower()


def test_expression_failing_later_leaves_output_intact(tmp_path):
    base = ["-grid_n", "32,32", "-output_dir", "o"] + QUIET
    assert run(base + ["-steps", "20", "-checkpoint_every", "10"], tmp_path).returncode == 0
    before = snapshot(tmp_path / "o")
    r = run(base + ["-steps", "40", "-source_a", "t > 5 ? log(-1) : 0"], tmp_path)
    assert r.returncode == 1, r.stdout[-1000:] + r.stderr[-1000:]
    error_line(r)
    assert snapshot(tmp_path / "o") == before


def can_mount(path, opts):
    path.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", opts, "tmpfs", str(path)], capture_output=True)
    return r.returncode == 0


@pytest.mark.parametrize("limit", ["inodes", "space"])
def test_directory_that_takes_no_new_files_exits_4_untouched(limit, tmp_path):
    """A full directory (no inodes left, or no space): options_used.yaml used to be overwritten
    and the run ended with exit 1; now nothing changes and the exit code is 4."""
    if os.geteuid() != 0:
        pytest.skip("needs root to mount a small tmpfs")
    d = tmp_path / "full"
    if not can_mount(d, "nr_inodes=8,size=1m" if limit == "inodes" else "size=64k"):
        pytest.skip("no permission to mount a tmpfs")
    try:
        (d / "options_used.yaml").write_text("# an earlier run's options\nsteps: 3\n")
        if limit == "inodes":
            k = 0
            while True:
                try:
                    (d / f"filler{k}").write_text("")
                except OSError:
                    break
                k += 1
        else:
            try:
                with open(d / "filler", "wb") as f:
                    while True:
                        f.write(b"\0" * 4096)
                        f.flush()
            except OSError:
                pass
        before = snapshot(d)
        r = run(["-grid_n", "32,32", "-steps", "5", "-output_dir", str(d)] + QUIET, tmp_path, 2)
        assert r.returncode == 4, r.stdout[-1000:] + r.stderr[-1000:]
        assert "options_used.yaml" in error_line(r)
        assert snapshot(d) == before
    finally:
        subprocess.run(["umount", str(d)])
